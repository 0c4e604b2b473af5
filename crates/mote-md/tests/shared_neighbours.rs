//! The force field's shared half neighbour list: granular contacts read it
//! through the step's `State` and give the same forces, bit for bit, as
//! through a list of their own. Cut-off dipoles (like Lennard-Jones) run
//! their SIMD rows over a ghost list of their own and do not widen the
//! shared list.

use mote_md::force::dipolar::DipoleDipole;
use mote_md::force::granular::{ContactLaw, Damping, GranularContacts, Material};
use mote_md::force::{ForceField, Interaction, Spin, State};

use mote_md::{Boundary, DVec3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const L: f64 = 12.0;

fn law() -> ContactLaw {
    let glass = Material {
        young: 1e5,
        poisson: 0.3,
    };
    ContactLaw::new(glass, glass, 0.7, 0.4, Damping::Exact, true)
}

/// Positions, velocities, radii, masses, dipole moments.
type Spheres = (Vec<DVec3>, Vec<DVec3>, Vec<f64>, Vec<f64>, Vec<DVec3>);

/// 600 spheres of radius 0.45–0.55 in a periodic cube, some touching.
fn particles() -> Spheres {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let n = 600;
    let mut u = |a: f64, b: f64| rng.gen_range(a..b);
    let pos: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(u(0.0, L), u(0.0, L), u(0.0, L)))
        .collect();
    let vel: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)))
        .collect();
    let radius: Vec<f64> = (0..n).map(|_| u(0.45, 0.55)).collect();
    let mass = vec![1.0; n];
    let dipole: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)))
        .collect();
    (pos, vel, radius, mass, dipole)
}

#[test]
fn granular_contacts_read_the_shared_list_beside_dipoles_on_their_ghost_list() {
    let (pos, vel, radius, mass, dipole) = particles();
    let n = pos.len();
    let omega = vec![DVec3::new(0.0, 0.0, 0.5); n];
    let boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(L));
    let spin = Spin {
        angular_velocity: &omega,
    };
    let granular = || GranularContacts::new(law(), 0.55, 0.2);
    let dipoles = || DipoleDipole::cut_off(1.0, 2.5, 0.3, boundary).unwrap();

    // Each interaction through its own list (no list in the state).
    let state = State::new(&pos, &vel, &mass, 0.0)
        .with_radii(&radius)
        .with_dipoles(&dipole)
        .in_box(&boundary);
    let (mut f_own, mut t_own) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    let (mut g, mut d) = (granular(), dipoles());
    g.add_forces_and_torques(&state, &spin, &mut f_own, &mut t_own);
    d.add_forces_and_torques(&state, &spin, &mut f_own, &mut t_own);
    assert_eq!((g.list.builds, d.list.builds), (1, 1));

    // Both in one force field.
    let mut ff = ForceField::new().with(granular()).with(dipoles());
    let (mut f, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    ff.add_forces_and_torques(&state, &spin, &mut f, &mut t);
    assert_eq!(f, f_own);
    assert_eq!(t, t_own);

    let shared = ff.neighbours().expect("a shared list");
    assert_eq!(shared.builds, 1);
    // Its reach is the contacts' alone, 2·0.55 + 0.2: the dipoles' rows
    // run over their own ghost list (a full list with periodic images).
    assert_eq!(shared.cutoff, 1.1);
    assert!((shared.cutoff + shared.skin - 1.3).abs() < 1e-12);
    // Energies through the shared list, as through the own ones.
    let (u, _) = ff.potential_energy(&state);
    assert_eq!(u, g.potential_energy(&state) + d.potential_energy(&state));
}
