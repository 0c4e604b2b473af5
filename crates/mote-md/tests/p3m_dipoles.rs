//! Dipolar P3M against the dipolar Ewald sum: forces, torques and energies
//! of random dipoles to the accuracy asked for, the measured RMS force
//! error beside Cerdà et al.'s estimate across orders and meshes, the
//! energy of a ferromagnetic dipolar crystal, momentum, and the same bits
//! on any thread count.

use mote_md::force::ewald::Ewald;
use mote_md::force::p3m::influence::{kspace_error, Aliases, Kernel};
use mote_md::force::p3m::{P3mDipoles, Parameters, Request};
use mote_md::force::Spin;
use mote_md::{Boundary, DVec3, Interaction, State};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// `n` unit dipoles of random orientation at random places in a box of
/// sides `cell`.
fn random_dipoles(n: usize, cell: DVec3, seed: u64) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pos = (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * cell)
        .collect();
    let mu = (0..n)
        .map(|_| {
            let u: f64 = 2.0 * rng.gen::<f64>() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * rng.gen::<f64>();
            let s = (1.0 - u * u).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), u)
        })
        .collect();
    (pos, mu)
}

/// Energy, forces and torques of P3M (k = 1).
fn p3m(
    solver: &mut P3mDipoles,
    pos: &[DVec3],
    mu: &[DVec3],
    boundary: &Boundary,
) -> (f64, Vec<DVec3>, Vec<DVec3>) {
    let n = pos.len();
    let (v, m) = (vec![DVec3::ZERO; n], vec![1.0; n]);
    let state = State::new(pos, &v, &m, 0.0)
        .with_dipoles(mu)
        .in_box(boundary);
    let (mut f, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    let omega = vec![DVec3::ZERO; n];
    let spin = Spin {
        angular_velocity: &omega,
    };
    solver.add_forces_and_torques(&state, &spin, &mut f, &mut t);
    (solver.potential_energy(&state), f, t)
}

/// Energy, forces and torques of an Ewald sum converged far past P3M's
/// accuracy (cubic boxes).
fn ewald(pos: &[DVec3], mu: &[DVec3], side: f64) -> (f64, Vec<DVec3>, Vec<DVec3>) {
    let e = Ewald::for_dipoles(side, 0.5 * side, 1e-9, mu);
    let n = pos.len();
    let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    let u = e.dipoles(pos, mu, &mut f, &mut h);
    let t = mu.iter().zip(&h).map(|(m, h)| m.cross(*h)).collect();
    (u, f, t)
}

fn rms_difference(a: &[DVec3], b: &[DVec3]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).length_squared())
        .sum();
    (s / a.len() as f64).sqrt()
}

#[test]
fn tuned_forces_and_torques_meet_the_accuracy_asked_for() {
    let side = 10.0;
    let cell = DVec3::splat(side);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, mu) = random_dipoles(400, cell, 7);
    let (u_ref, f_ref, t_ref) = ewald(&pos, &mu, side);
    for accuracy in [1e-2, 1e-3, 1e-4] {
        let request = Request {
            accuracy,
            skin: 0.3,
            ..Request::default()
        };
        let mut solver = P3mDipoles::tuned(1.0, &request, &mu, &boundary).unwrap();
        let (u, f, t) = p3m(&mut solver, &pos, &mu, &boundary);
        let (error, torque_error) = (rms_difference(&f, &f_ref), rms_difference(&t, &t_ref));
        let p = solver.parameters;
        println!(
            "δ = {accuracy:e}: {:?} order {} α {:.4} r_c {:.3}: estimate {:.3e} (real {:.3e}, mesh {:.3e}), measured {error:.3e}, torques {torque_error:.3e}; U {u:.10} vs Ewald {u_ref:.10}",
            p.mesh,
            p.order,
            p.alpha,
            p.cutoff,
            p.estimated_error(),
            p.real_error,
            p.kspace_error,
        );
        assert!(p.estimated_error() <= accuracy);
        let ratio = error / p.estimated_error();
        assert!(
            (0.5..=2.0).contains(&ratio),
            "measured {error:e}, estimate {:e}",
            p.estimated_error()
        );
        assert!(torque_error < accuracy, "torques {torque_error:e}");
        assert!((u - u_ref).abs() < accuracy * pos.len() as f64);
    }
}

/// Cerdà et al.'s estimate of the mesh part against the measured error
/// (real space converged: α small against the cut-off), across orders
/// and meshes: within a factor 2, as the issue asks.
#[test]
fn mesh_error_matches_the_estimate_across_orders_and_meshes() {
    let side = 10.0;
    let cell = DVec3::splat(side);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, mu) = random_dipoles(300, cell, 11);
    let (_, f_ref, _) = ewald(&pos, &mu, side);
    let (alpha, cutoff) = (0.9, 4.5);
    let n = pos.len() as f64;
    for order in [2, 3, 5, 7] {
        for m in [8, 16, 32] {
            let estimate = kspace_error(
                Kernel::DipoleForce,
                [m; 3],
                cell,
                order,
                alpha,
                n,
                n,
                Aliases::Full,
            );
            let parameters = Parameters {
                mesh: [m; 3],
                order,
                alpha,
                cutoff,
                real_error: 0.0,
                kspace_error: estimate,
            };
            let mut solver = P3mDipoles::new(1.0, parameters, 0.3, &boundary);
            let (_, f, _) = p3m(&mut solver, &pos, &mu, &boundary);
            let measured = rms_difference(&f, &f_ref);
            let ratio = measured / estimate;
            println!("order {order} mesh {m}³: estimate {estimate:.3e}, measured {measured:.3e}, ratio {ratio:.2}");
            if measured > 1e-7 {
                assert!(
                    (0.5..=2.0).contains(&ratio),
                    "order {order}, mesh {m}: ratio {ratio}"
                );
            }
        }
    }
}

/// A ferromagnetic simple-cubic crystal, lattice constant a, every μ
/// along z, tin-foil boundaries: the dipoles within any sphere leave no
/// field at its centre (cubic symmetry) and the conducting surroundings
/// no depolarising field, so each site feels the Lorentz field
/// (4π/3) μ/a³ and U = −½ Σ μ·H = −(2π/3) N μ²/a³. No forces, no
/// torques: what P3M leaves (the crystal sits off the mesh points) is
/// within a few times its estimated RMS error.
#[test]
fn ferromagnetic_crystal_has_the_lorentz_energy() {
    let (cells, a) = (6, 1.0);
    let side = a * cells as f64;
    let cell = DVec3::splat(side);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let mut pos = vec![];
    for i in 0..cells {
        for j in 0..cells {
            for k in 0..cells {
                pos.push((DVec3::new(i as f64, j as f64, k as f64) + 0.3) * a);
            }
        }
    }
    let mu = vec![DVec3::Z; pos.len()];
    let n = pos.len() as f64;
    let lorentz = -2.0 * std::f64::consts::PI / 3.0 * n / a.powi(3);
    let (u_ewald, _, _) = ewald(&pos, &mu, side);
    let request = Request {
        accuracy: 1e-5,
        skin: 0.2,
        ..Request::default()
    };
    let mut solver = P3mDipoles::tuned(1.0, &request, &mu, &boundary).unwrap();
    let (u, f, t) = p3m(&mut solver, &pos, &mu, &boundary);
    println!("{}", solver.describe());
    println!("U = {u:.12}, Ewald {u_ewald:.12}, −(2π/3)N μ²/a³ = {lorentz:.12}");
    assert!(
        ((u_ewald - lorentz) / lorentz).abs() < 1e-8,
        "Ewald {u_ewald}"
    );
    assert!(
        ((u - lorentz) / lorentz).abs() < 1e-5,
        "U = {u}, expected {lorentz}"
    );
    let largest = |v: &[DVec3]| v.iter().map(|x| x.length()).fold(0.0, f64::max);
    let bound = 3.0 * solver.parameters.estimated_error();
    assert!(largest(&f) < bound, "force {}", largest(&f));
    assert!(largest(&t) < bound, "torque {}", largest(&t));
    // W = 3U.
    let w = solver.virial().unwrap();
    assert!((w - 3.0 * u).abs() < 1e-12 * u.abs());
}

/// ik-differentiation with one assignment for the moments and the forces
/// conserves momentum: Σ F = Σ_k (−i D G_F/V)|D·M̂|² = 0 to round-off.
#[test]
fn forces_conserve_momentum() {
    let cell = DVec3::new(9.0, 9.0, 11.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, mu) = random_dipoles(500, cell, 3);
    let request = Request {
        accuracy: 1e-3,
        skin: 0.3,
        ..Request::default()
    };
    let mut solver = P3mDipoles::tuned(1.0, &request, &mu, &boundary).unwrap();
    let (_, f, _) = p3m(&mut solver, &pos, &mu, &boundary);
    let total: DVec3 = f.iter().sum();
    let scale: f64 = f.iter().map(|f| f.length()).sum();
    assert!(
        total.length() < 1e-12 * scale,
        "Σ F = {total}, Σ|F| = {scale}"
    );
}

#[test]
fn forces_and_torques_are_the_same_bits_on_any_thread_count() {
    let cell = DVec3::splat(12.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, mu) = random_dipoles(1500, cell, 5);
    let request = Request {
        accuracy: 1e-3,
        skin: 0.3,
        ..Request::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut solver = P3mDipoles::tuned(1.0, &request, &mu, &boundary).unwrap();
            p3m(&mut solver, &pos, &mu, &boundary)
        })
    };
    let bits = |v: &[DVec3]| -> Vec<[u64; 3]> {
        v.iter().map(|x| x.to_array().map(f64::to_bits)).collect()
    };
    let one = run(1);
    for threads in [2, 3] {
        let other = run(threads);
        assert_eq!(one.0.to_bits(), other.0.to_bits());
        assert_eq!(bits(&one.1), bits(&other.1));
        assert_eq!(bits(&one.2), bits(&other.2));
    }
}

/// A dense dipolar fluid from a scene (`[dipolar] method = "p3m"` beside
/// WCA cores, 256 particles with λ = μ² = 2.25 melting from fcc, turning
/// as they go): its tuned parameters are told, the pressure has its
/// virial, and energy is conserved over 300 steps of leap-frog with
/// rotation.
#[test]
fn dipolar_fluid_scene_conserves_energy() {
    let text = r#"
units = "lj"
seed = 5
[run]
integrator = "leapfrog"
dt = 0.001
[lennard_jones]
wca = true
[dipolar]
method = "p3m"
accuracy = 1e-4
random_orientation = true
[[fcc]]
cells = [4, 4, 4]
density = 0.8
kt = 1.0
radius = 0.5
dipole = [0.0, 0.0, 1.5]
"#;
    let mut built = crate::common::build(text);
    let sim = &mut built.simulation;
    let said: Vec<String> = sim
        .forces
        .interactions
        .iter()
        .filter_map(|i| i.describe())
        .collect();
    assert!(
        said.len() == 1 && said[0].starts_with("Dipolar by P3M: mesh"),
        "{said:?}"
    );
    let first = mote_md::Observables::measure(&sim.system, &mut sim.forces);
    assert!(first.pressure.is_finite(), "P = {}", first.pressure);
    let e0 = first.total_energy();
    let mut worst: f64 = 0.0;
    crate::common::steps(sim, 300, |sim| {
        let o = mote_md::Observables::measure(&sim.system, &mut sim.forces);
        worst = worst.max((o.total_energy() - e0).abs());
    });
    println!(
        "{}: |ΔE| ≤ {worst:.3e}, K = {:.3}, U = {:.3}",
        said[0], first.kinetic, first.potential
    );
    assert!(worst < 1e-3 * first.kinetic, "energy drifts by {worst:e}");
}
