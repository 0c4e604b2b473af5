//! Domain decomposition: a Lennard-Jones liquid stepped on 2, 3, 4 and 6
//! ranks (threads of one process, `mote_run::comm::in_process`, which run
//! the very code `mpirun` runs) gives the same bits as one process, and
//! its checkpoints are one process's and resume on any number of ranks.

use std::sync::Arc;

use mote_md::force::LennardJones;
use mote_md::init::fcc;
use mote_md::particles::ParticleInit;
use mote_md::{DVec3, ForceField, Integrator, Observables, Particles, Simulation, Stepper, System};
use mote_run::comm::{in_process, Comm};
use mote_run::Propagator;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

const CUTOFF: f64 = 2.5;
const SKIN: f64 = 0.3;
const STEPS: usize = 300;

/// A hot fcc crystal in a box 8 × 6 × 5 cells (960 atoms, ρ = 0.8442,
/// kT = 3: it melts, so particles cross bricks and the list is rebuilt
/// many times).
fn crystal() -> System {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let (atoms, boundary) = fcc(
        [8, 6, 5],
        0.8442,
        DVec3::ZERO,
        3.0,
        &ParticleInit::default(),
        &mut rng,
    );
    let mut particles = Particles::default();
    for a in atoms {
        particles.push(a);
    }
    let mut sys = System::new(particles);
    sys.boundary = boundary;
    sys
}

fn simulation(system: System) -> Simulation {
    let forces = ForceField::new().with(LennardJones::new(1.0, 1.0, CUTOFF, true, SKIN));
    Simulation::new(system, forces, Stepper::new(Integrator::LeapFrog), 0.005, 1)
}

/// Steps `sim` STEPS times; returns the observables at the start and end.
fn run(sim: &mut Simulation) -> (Observables, Observables) {
    run_for(sim, STEPS)
}

/// Steps `sim` `steps` times; returns the observables at the start and end.
fn run_for(sim: &mut Simulation, steps: usize) -> (Observables, Observables) {
    sim.prime(&mut |_| {}).unwrap();
    let first = sim.measure();
    for _ in 0..steps {
        sim.advance().unwrap();
    }
    (first, sim.measure())
}

/// The whole system at the end: gathered at rank 0 of a decomposed run
/// (`None` on the others), or one process's own.
fn whole(sim: Simulation) -> Option<System> {
    match &sim.forces.domain {
        Some(d) => d.gather(&sim.system),
        None => Some(sim.system),
    }
}

/// What one rank of a decomposed run ends with: the whole system (at rank
/// 0), the observables, and the list builds.
fn decomposed(
    comm: Arc<dyn Comm>,
    grid: Option<[usize; 3]>,
) -> (Option<System>, Observables, Observables, u64) {
    let whole = crystal();
    let mut sim = simulation(whole);
    sim.decompose(comm, grid).unwrap();
    let (first, last) = run(&mut sim);
    let domain = sim.forces.domain.as_ref().unwrap();
    let migrated = domain.comm().sum(&[domain.migrated as f64])[0];
    assert!(migrated > 0.0, "no particle changed brick");
    (domain.gather(&sim.system), first, last, domain.builds)
}

#[test]
fn a_decomposed_liquid_steps_as_one_process_does() {
    let mut one = simulation(crystal());
    let (first, last) = run(&mut one);
    assert!((last.kt - 1.7).abs() < 0.2, "kT = {}", last.kt);
    let p = &one.system.particles;
    let mut builds = None;
    for (ranks, grid) in [
        (2, None),
        (3, None),
        (4, None),
        (4, Some([1, 2, 2])),
        (6, None),
    ] {
        let out = in_process(ranks, |comm| decomposed(comm, grid));
        let (whole, f, l, b) = &out[0];
        let whole = whole.as_ref().expect("rank 0 gathers");
        let q = &whole.particles;
        assert_eq!(q.len(), p.len(), "{ranks} ranks, grid {grid:?}");
        // The same bits, particle by particle.
        assert_eq!(q.position, p.position, "{ranks} ranks, grid {grid:?}");
        assert_eq!(q.velocity, p.velocity, "{ranks} ranks, grid {grid:?}");
        assert_eq!(
            *b,
            *builds.get_or_insert(*b),
            "list builds on {ranks} ranks"
        );
        // Sums over the ranks: the same to round-off.
        for (a, e) in [(f, &first), (l, &last)] {
            assert!((a.potential - e.potential).abs() < 1e-11 * e.potential.abs());
            assert!((a.kinetic - e.kinetic).abs() < 1e-11 * e.kinetic);
            assert!((a.pressure - e.pressure).abs() < 1e-11 * e.pressure.abs());
            assert!((a.momentum - e.momentum).length() < 1e-10);
            assert_eq!(a.kt.to_bits() != 0, e.kt.to_bits() != 0);
        }
        // Every rank agrees on the sums, to the bit (NaN pressures too).
        for (_, f2, l2, _) in &out[1..] {
            assert_eq!(format!("{f2:?}"), format!("{f:?}"));
            assert_eq!(format!("{l2:?}"), format!("{l:?}"));
        }
    }
    // The run did what the test needs: the liquid moved through many
    // builds.
    let builds = builds.unwrap();
    assert!(builds > 10, "{builds} builds");
}

/// The state a checkpoint holds at `step`, taken by one process.
fn checkpoint_at(sim: &mut Simulation, step: usize) -> mote_io::checkpoint::Checkpoint {
    sim.prime(&mut |_| {}).unwrap();
    for _ in 0..step {
        sim.advance().unwrap();
    }
    let mut cp = mote_io::checkpoint::Checkpoint::default();
    sim.save(&mut cp).unwrap();
    cp
}

/// Puts a checkpoint's state into a freshly built simulation, as the
/// front's resume does.
fn resume(cp: &mote_io::checkpoint::Checkpoint) -> Simulation {
    restore(simulation(crystal()), cp)
}

/// A decomposed run's checkpoint is one process's, number for number; a
/// run resumed from it on another number of ranks ends where the
/// uninterrupted run of one process ends, to the bit.
#[test]
fn checkpoints_of_a_decomposed_run_resume_on_any_number_of_ranks() {
    const HALF: usize = STEPS / 2;
    let mut one = simulation(crystal());
    let plain = checkpoint_at(&mut one, HALF);
    for _ in HALF..STEPS {
        one.advance().unwrap();
    }
    let end = one.system.particles;
    let taken = in_process(2, |comm| {
        let mut sim = simulation(crystal());
        sim.decompose(comm, None).unwrap();
        checkpoint_at(&mut sim, HALF)
    });
    let cp = &taken[0];
    assert_eq!(cp.positions, plain.positions);
    assert_eq!(cp.velocities, plain.velocities);
    assert_eq!(cp.accelerations, plain.accelerations);
    assert_eq!(cp.carried, plain.carried);
    assert_eq!((cp.step, cp.time), (plain.step, plain.time));
    assert!(!cp.carried.is_empty(), "the list's build is carried");
    // Resumed on three ranks and on one process.
    for ranks in [1, 2, 3] {
        let out = in_process(ranks, |comm| {
            let mut sim = resume(cp);
            if ranks > 1 {
                sim.decompose(comm, None).unwrap();
            }
            sim.prime(&mut |_| {}).unwrap();
            for _ in HALF..STEPS {
                sim.advance().unwrap();
            }
            whole(sim)
        });
        let whole = out[0].as_ref().unwrap();
        let differ = (0..end.len())
            .filter(|&i| {
                whole.particles.position[i] != end.position[i]
                    || whole.particles.velocity[i] != end.velocity[i]
            })
            .count();
        let worst = (0..end.len())
            .map(|i| (whole.particles.position[i] - end.position[i]).length())
            .fold(0.0, f64::max);
        assert_eq!(
            differ, 0,
            "particles that differ, resumed on {ranks} ranks (by {worst} at most)"
        );
    }
}

/// Thermostats on ranks: Langevin's noise comes from each particle's id
/// and the step, so a decomposed run is one process's to the bit; Bussi
/// rescales by the kinetic energy summed over the ranks (in rank order):
/// the same to round-off.
#[test]
fn thermostatted_liquids_decompose() {
    use mote_md::thermostat::Thermostat;
    for (thermostat, exact) in [
        (
            Thermostat::Langevin {
                kt: 1.0,
                gamma: 2.0,
            },
            true,
        ),
        (Thermostat::Bussi { kt: 1.0, tau: 0.1 }, false),
    ] {
        let run = |comm: Option<Arc<dyn Comm>>| {
            let mut sim = simulation(crystal());
            sim.thermostat = Some(thermostat);
            if let Some(comm) = comm {
                sim.decompose(comm, None).unwrap();
            }
            run(&mut sim);
            whole(sim)
        };
        let one = run(None).unwrap();
        let three = in_process(3, |comm| run(Some(comm))).remove(0).unwrap();
        let (p, q) = (&one.particles, &three.particles);
        let worst = (0..p.len())
            .map(|i| (p.position[i] - q.position[i]).length())
            .fold(0.0, f64::max);
        if exact {
            assert!(
                p.position == q.position && p.velocity == q.velocity,
                "{thermostat:?}: by {worst}"
            );
        } else {
            assert!(worst > 0.0 && worst < 1e-9, "{thermostat:?}: by {worst}");
        }
        // The thermostat acted: the liquid ends at kT ≈ 1, where without
        // one it ends near kT = 1.7 (the crystal started at 3).
        let kt = (0..p.len())
            .map(|i| p.mass[i] * p.velocity[i].length_squared())
            .sum::<f64>()
            / (3.0 * p.len() as f64);
        assert!((kt - 1.0).abs() < 0.15, "{thermostat:?}: kT = {kt}");
    }
}

/// The simulation of scene `text`, split over `comm`'s ranks (bricks
/// `grid`) where one is given.
fn on_ranks(text: &str, comm: Option<Arc<dyn Comm>>, grid: Option<[usize; 3]>) -> Simulation {
    let mut sim = crate::common::build(text).simulation;
    if let Some(comm) = comm {
        sim.decompose(comm, grid).unwrap();
    }
    sim
}

/// The dipolar LJ fluid of `bench/dipole3d.toml`, smaller: LJ and point
/// dipoles in one cut-off pair loop, the particles turning (leap-frog
/// with rotation), the ghosts' moments forwarded with their positions.
const DIPOLAR: &str = r#"
units = "lj"
seed = 98934

[run]
integrator = "leapfrog"
dt = 0.005
steps = 300

[lennard_jones]
cutoff = 2.5
shifted = false
skin = 0.3

[dipolar]
cutoff = 2.5
skin = 0.3
random_orientation = true

[[fcc]]
cells = [6, 6, 6]
density = 0.8442
kt = 1.44
radius = 0.5
dipole = [0.0, 0.0, 0.75]
"#;

/// A dipolar fluid on 3 ranks turns and moves as in one process, to the
/// bit: positions, velocities, moments and angular velocities.
#[test]
fn a_decomposed_dipolar_fluid_steps_as_one_process_does() {
    let run = |comm: Option<Arc<dyn Comm>>| {
        let mut sim = on_ranks(DIPOLAR, comm, None);
        assert!(sim.forces.exerts_torques());
        let (first, last) = run(&mut sim);
        (whole(sim), first, last)
    };
    let (one, first, last) = run(None);
    let one = one.unwrap();
    let (three, f3, l3) = in_process(3, |comm| run(Some(comm))).remove(0);
    let (p, q) = (&one.particles, &three.unwrap().particles);
    assert!(p.position == q.position, "positions");
    assert!(p.velocity == q.velocity, "velocities");
    assert!(p.dipole == q.dipole, "moments");
    assert!(
        p.angular_velocity == q.angular_velocity,
        "angular velocities"
    );
    // The dipoles turned, and the energies agree to round-off.
    let turned = (0..p.len())
        .filter(|&i| p.angular_velocity[i] != DVec3::ZERO)
        .count();
    assert!(turned == p.len(), "{turned} of {} turned", p.len());
    for (a, e) in [(&f3, &first), (&l3, &last)] {
        assert!((a.potential - e.potential).abs() < 1e-11 * e.potential.abs());
        assert!((a.kinetic - e.kinetic).abs() < 1e-11 * e.kinetic);
    }
}

/// `examples/ferrofluid.toml`, smaller: Brownian dynamics of WCA dipoles
/// with a reaction field in an applied field.
const FERROFLUID: &str = r#"
units = "lj"
seed = 4

[run]
dt = 0.002
steps = 300

[box]
lo = [0.0, 0.0, 0.0]
hi = [16.284, 16.284, 16.284]

[dipolar]
cutoff = 4.0
reaction_field = "conducting"
wca = { epsilon = 1.0, sigma = 1.0 }
random_orientation = true

[magnetic_field]
h = [0.0, 0.0, 0.09189]

[brownian]
kt = 1.0
translational = 1.0
rotational = 0.3333333333333333

[[lattice]]
n = [6, 6, 6]
spacing = [2.714, 2.714, 2.714]
origin = [1.357, 1.357, 1.357]
radius = 0.5
dipole = [0.0, 0.0, 1.7320508075688772]
"#;

/// Brownian dynamics on ranks: each particle's noise comes from its id and
/// the step, so 3 ranks give one process's bits.
#[test]
fn a_decomposed_ferrofluid_diffuses_as_one_process_does() {
    let run = |comm: Option<Arc<dyn Comm>>| {
        let mut sim = on_ranks(FERROFLUID, comm, None);
        assert!(sim.brownian.is_some());
        run(&mut sim);
        whole(sim)
    };
    let one = run(None).unwrap();
    let three = in_process(3, |comm| run(Some(comm))).remove(0).unwrap();
    let (p, q) = (&one.particles, &three.particles);
    assert!(p.position == q.position, "positions");
    assert!(p.dipole == q.dipole, "moments");
    // The noise moved every particle off its lattice site.
    let start = crate::common::build(FERROFLUID).simulation.system;
    let moved = (0..p.len())
        .filter(|&i| (p.position[i] - start.particles.position[i]).length() > 1e-3)
        .count();
    assert_eq!(moved, p.len());
}

/// Spheres falling onto a floor in a box periodic across: Hertz–Mindlin
/// contacts with friction and rolling resistance (their histories) and
/// the floor's, under gravity.
const GRANULAR: &str = include_str!("data/granular-bed.toml");

/// A granular bed on 2, 3 and 4 ranks lands as in one process, to the
/// bit: the contacts' histories travel with their particles, every
/// contact is evaluated from its lower id's side wherever it is, and each
/// particle adds its contacts in its partners' order.
#[test]
fn a_decomposed_granular_bed_settles_as_one_process_does() {
    let run = |comm: Option<Arc<dyn Comm>>, grid: Option<[usize; 3]>| {
        let mut sim = on_ranks(GRANULAR, comm, grid);
        let (first, last) = run_for(&mut sim, 1200);
        // The touching pairs, each counted on one rank.
        let granular = sim
            .forces
            .interactions
            .iter()
            .find(|i| i.name() == "granular")
            .unwrap();
        let counts = match &sim.forces.domain {
            Some(d) => {
                let rows = granular.carried_rows(&d.halo().id).unwrap();
                let contacts = (rows.rows.len() / rows.width) as f64;
                d.comm().sum(&[contacts, d.migrated as f64])
            }
            None => vec![(granular.carried_state().len() / 8) as f64, 0.0],
        };
        (whole(sim), first, last, counts)
    };
    let (one, first, last, counts) = run(None, None);
    let p = &one.unwrap().particles;
    // The bed formed: many contacts, the floor's among them.
    assert!(counts[0] > 200.0, "{} contacts", counts[0]);
    assert!(last.wall_forces[0].1.z < -0.1 * p.mass.iter().sum::<f64>() * 200.0);
    for (ranks, grid) in [(2, None), (3, None), (4, Some([2, 2, 1]))] {
        let (q, f, l, c) = in_process(ranks, |comm| run(Some(comm), grid)).remove(0);
        let q = &q.unwrap().particles;
        let what = format!("{ranks} ranks, grid {grid:?}");
        assert!(c[1] > 0.0, "{what}: no particle changed rank");
        assert_eq!(c[0], counts[0], "{what}: contacts");
        assert!(p.position == q.position, "{what}: positions");
        assert!(p.velocity == q.velocity, "{what}: velocities");
        assert!(p.angular_velocity == q.angular_velocity, "{what}: spins");
        for (a, e) in [(&f, &first), (&l, &last)] {
            assert!((a.potential - e.potential).abs() <= 1e-11 * e.potential.abs());
            assert!((a.kinetic - e.kinetic).abs() <= 1e-11 * e.kinetic);
            let (fa, fe) = (a.wall_forces[0].1, e.wall_forces[0].1);
            assert!((fa - fe).length() <= 1e-11 * fe.length(), "{what}: floor");
        }
    }
}

/// Puts a checkpoint's state into the simulation of scene `text`.
fn resume_scene(text: &str, cp: &mote_io::checkpoint::Checkpoint) -> Simulation {
    restore(crate::common::build(text).simulation, cp)
}

/// Puts a checkpoint's state into `sim`, as the front's resume does
/// (the particles' order checked; positions, velocities, spins, the
/// carried accelerations and what each interaction carries, by its key).
fn restore(mut sim: Simulation, cp: &mote_io::checkpoint::Checkpoint) -> Simulation {
    let sys = &mut sim.system;
    sys.time = cp.time;
    sys.step = cp.step;
    for (i, (r, v)) in cp.positions.iter().zip(&cp.velocities).enumerate() {
        sys.particles.position[i] = DVec3::from(*r);
        sys.particles.velocity[i] = DVec3::from(*v);
    }
    sys.carried_acceleration = cp.accelerations.iter().map(|a| DVec3::from(*a)).collect();
    sys.carried_angular_acceleration.clear();
    for (i, a) in cp.angular.iter().enumerate() {
        sys.particles.angular_velocity[i] = DVec3::new(a[0], a[1], a[2]);
        sys.carried_angular_acceleration
            .push(DVec3::new(a[3], a[4], a[5]));
    }
    sim.check_order(cp).unwrap();
    let keys = sim.forces.carried_keys();
    for (key, values) in &cp.carried {
        if key == mote_md::simulation::ORDER_KEY {
            continue;
        }
        let k = keys.iter().position(|x| x == key).unwrap();
        sim.forces.interactions[k]
            .restore_carried_state(values)
            .unwrap();
    }
    sim
}

/// A granular bed's checkpoint written on 2 ranks is one process's (the
/// contact histories of spheres and of the floor among it) and resumes
/// on 1 and 3 ranks to the end of the uninterrupted run, to the bit.
#[test]
fn a_granular_checkpoint_of_two_ranks_resumes_on_one_and_three() {
    const HALF: usize = 600;
    let mut one = crate::common::build(GRANULAR).simulation;
    let plain = checkpoint_at(&mut one, HALF);
    for _ in HALF..2 * HALF {
        one.advance().unwrap();
    }
    let end = one.system.particles;
    let taken = in_process(2, |comm| {
        checkpoint_at(&mut on_ranks(GRANULAR, Some(comm), None), HALF)
    });
    let cp = &taken[0];
    assert_eq!(cp.positions, plain.positions);
    assert_eq!(cp.angular, plain.angular);
    let carried = |c: &mote_io::checkpoint::Checkpoint, key: &str| {
        let v = &c.carried.iter().find(|k| k.0 == key).unwrap().1;
        // Past the head (NaN, which no comparison equals).
        v[1..].to_vec()
    };
    for key in ["granular", "walls"] {
        let rows = carried(cp, key);
        assert!(rows.len() > 50, "{key}: {} numbers", rows.len());
        assert_eq!(rows, carried(&plain, key), "{key}");
    }
    for ranks in [1, 3] {
        let out = in_process(ranks, |comm| {
            let mut sim = resume_scene(GRANULAR, cp);
            if ranks > 1 {
                sim.decompose(comm, None).unwrap();
            }
            sim.prime(&mut |_| {}).unwrap();
            for _ in HALF..2 * HALF {
                sim.advance().unwrap();
            }
            whole(sim)
        });
        let q = &out[0].as_ref().unwrap().particles;
        assert!(q.position == end.position, "positions, resumed on {ranks}");
        assert!(
            q.angular_velocity == end.angular_velocity,
            "spins, resumed on {ranks}"
        );
    }
}

/// The bed of [`GRANULAR`] in open space, closed by a box of walls: the
/// slabs are cut over the particles' extent.
fn walled_bed() -> String {
    let bed = GRANULAR
        .replace(
            "[box]\nlo = [0.0, 0.0, 0.0]\nhi = [0.024, 0.024, 0.06]\nperiodic = [true, true, false]\n",
            "",
        )
        .replace(
            "kind = \"plane\"\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]",
            "kind = \"box\"\nname = \"box\"\nlo = [0.0, 0.0, 0.0]\nhi = [0.024, 0.024, 0.06]",
        );
    assert!(!bed.contains("[box]") && bed.contains("kind = \"box\""));
    bed
}

/// A bed settling across the cut of 2 bricks (in a box of walls, open
/// space around it) leaves the upper one empty; the cut shifts to keep
/// the halves even, and the trajectory stays one process's to the bit.
#[test]
fn the_cut_follows_a_settling_bed() {
    let bed = walled_bed();
    let run = |comm: Option<Arc<dyn Comm>>, balance: f64| {
        let mut sim = on_ranks(&bed, comm, None);
        if let Some(domain) = sim.forces.domain.as_mut() {
            assert_eq!(domain.bricks.dims, [1, 1, 2]);
            domain.balance = balance;
        }
        run_for(&mut sim, 2400);
        let spread = sim.forces.domain.as_ref().map(|d| {
            let n = d.comm().gather(&[sim.system.particles.len() as f64]);
            let most = n.iter().map(|v| v[0]).fold(0.0, f64::max);
            (most * n.len() as f64 / d.total() as f64, d.shifts)
        });
        (whole(sim), spread)
    };
    let one = run(None, 0.0).0.unwrap();
    for balance in [0.0, 1.1] {
        let (two, spread) = in_process(2, |comm| run(Some(comm), balance)).remove(0);
        let two = two.unwrap();
        assert!(
            two.particles.position == one.particles.position,
            "balance {balance}"
        );
        assert!(
            two.particles.velocity == one.particles.velocity,
            "balance {balance}"
        );
        let (imbalance, shifts) = spread.unwrap();
        if balance == 0.0 {
            assert_eq!(shifts, 0);
            assert!(imbalance > 1.3, "unbalanced: {imbalance}");
        } else {
            assert!(shifts > 0);
            assert!(imbalance < 1.1 + 0.05, "balanced: {imbalance}");
        }
    }
}

/// A molten salt by Ewald beside WCA cores: 512 ions melting from rock
/// salt in a cubic box, driven by an applied electric field.
const EWALD_SALT: &str = r#"
units = "lj"
seed = 3

[run]
integrator = "leapfrog"
dt = 0.002
steps = 60

[lennard_jones]
wca = true

[coulomb]
method = "ewald"
accuracy = 1e-3

[electric_field]
e = [0.5, 0.0, 0.0]

[[fcc]]
cells = [4, 4, 4]
density = 0.25
kt = 1.0
charge = 1.0

[[fcc]]
cells = [4, 4, 4]
density = 0.25
kt = 1.0
origin = [1.2599210498948732, 0.0, 0.0]
charge = -1.0
"#;

/// A dipolar fluid by Ewald beside WCA cores, turning as it moves.
const EWALD_DIPOLES: &str = r#"
units = "lj"
seed = 4

[run]
integrator = "leapfrog"
dt = 0.002
steps = 60

[lennard_jones]
wca = true

[dipolar]
method = "ewald"
accuracy = 1e-3
random_orientation = true

[[fcc]]
cells = [4, 4, 4]
density = 0.7
kt = 1.0
radius = 0.5
dipole = [0.0, 0.0, 1.2]
"#;

/// Ewald sums on ranks: every rank gathers every particle in id order,
/// sums the structure factors as one process does and evaluates its own
/// particles, so charges and dipoles on 2 and 3 ranks move and turn as in
/// one process, to the bit; the energies (each rank's share, summed) to
/// round-off.
#[test]
fn ewald_sums_on_ranks_step_as_one_process_does() {
    for scene in [EWALD_SALT, EWALD_DIPOLES] {
        let run = |comm: Option<Arc<dyn Comm>>| {
            let mut sim = on_ranks(scene, comm, None);
            let (first, last) = run_for(&mut sim, 60);
            (whole(sim), first, last)
        };
        let (one, first, last) = run(None);
        let one = one.unwrap();
        for ranks in [2, 3] {
            let (many, f, l) = in_process(ranks, |comm| run(Some(comm))).remove(0);
            let (p, q) = (&one.particles, &many.unwrap().particles);
            assert!(p.position == q.position, "{ranks} ranks: positions");
            assert!(p.velocity == q.velocity, "{ranks} ranks: velocities");
            assert!(p.dipole == q.dipole, "{ranks} ranks: moments");
            for (a, e) in [(&f, &first), (&l, &last)] {
                assert!(
                    (a.potential - e.potential).abs() < 1e-11 * e.potential.abs(),
                    "{ranks} ranks: U = {} against {}",
                    a.potential,
                    e.potential
                );
                assert!((a.pressure - e.pressure).abs() < 1e-10 * e.pressure.abs().max(1.0));
            }
        }
        // The particles moved, and the long-range energy is not nothing.
        let start = crate::common::build(scene).simulation.system;
        assert!(one.particles.position != start.particles.position);
        assert!(first.potential.abs() > 1.0, "U = {}", first.potential);
    }
}

/// A 3-D spring lattice (with diagonals) shaken by a Langevin bath in a
/// box periodic on every axis and long enough for bricks along x.
const SPRING_LATTICE: &str = include_str!("data/spring-lattice.toml");

/// Springs on ranks: each rank evaluates the springs with an end of its
/// own, the other end's motion from the halo, so a lattice on 2 and 3
/// ranks moves as in one process, to the bit, and its energy (each spring
/// at its first end's rank) and pressure agree to round-off.
#[test]
fn springs_across_bricks_pull_as_in_one_process() {
    let run = |comm: Option<Arc<dyn Comm>>| {
        let mut sim = on_ranks(SPRING_LATTICE, comm, None);
        let (first, last) = run_for(&mut sim, 400);
        (whole(sim), first, last)
    };
    let (one, first, last) = run(None);
    let one = one.unwrap();
    for ranks in [2, 3] {
        let (many, f, l) = in_process(ranks, |comm| run(Some(comm))).remove(0);
        let (p, q) = (&one.particles, &many.unwrap().particles);
        assert!(p.position == q.position, "{ranks} ranks: positions");
        assert!(p.velocity == q.velocity, "{ranks} ranks: velocities");
        for (a, e) in [(&f, &first), (&l, &last)] {
            assert!(
                (a.potential - e.potential).abs() <= 1e-11 * e.potential.abs().max(1e-9),
                "{ranks} ranks: U = {} against {}",
                a.potential,
                e.potential
            );
            assert!((a.pressure - e.pressure).abs() <= 1e-10 * e.pressure.abs().max(1e-6));
        }
    }
    // The bath stretched the springs.
    assert!(last.potential > 1.0, "U = {}", last.potential);
}

/// A spring stretched past the halo on ranks: its end's force is not
/// silently dropped — the state goes non-finite at that particle, and
/// every rank stops there (one process runs it).
#[test]
fn a_spring_longer_than_the_halo_stops_the_run_on_ranks() {
    let scene = r#"
units = "lj"
[run]
integrator = "leapfrog"
dt = 0.01
steps = 5
[box]
lo = [0.0, 0.0, 0.0]
hi = [18.0, 5.0, 5.0]
[[particle]]
position = [1.0, 2.5, 2.5]
[[particle]]
position = [13.0, 2.5, 2.5]
[[spring]]
pairs = [[0, 1]]
stiffness = 0.01
rest_length = 1.0
"#;
    let step = |comm: Option<Arc<dyn Comm>>| {
        let mut sim = on_ranks(scene, comm, Some([2, 1, 1]));
        sim.prime(&mut |_| {}).unwrap();
        sim.advance().unwrap();
        sim.unstable()
    };
    assert_eq!(step(None), None, "one process runs it");
    for unstable in in_process(2, |comm| step(Some(comm))) {
        let (id, what) = unstable.expect("every rank stops");
        assert_eq!(id, 0, "{what}");
    }
}

/// A cold cloud collapsing under its own gravity in open space, its
/// charges repelling by Coulomb's law: the open-space sums over all pairs.
const SELF_GRAVITATING: &str = include_str!("data/collapsing-cloud.toml");

/// Open-space sums on ranks (gravity, Coulomb's law, dipoles all pairs):
/// every rank gathers every particle in id order and sums the pull of all
/// of them on each of its own, row by row,
/// so a particle's force does not depend on the rank count — on 2, 3 and
/// 4 ranks the cloud collapses to the same bits — and agrees with one
/// process's pair-symmetric sums (another order) to round-off; the
/// energy (each rank's share, summed) too.
#[test]
fn open_space_sums_on_ranks_step_alike_on_any_rank_count() {
    let run = |comm: Option<Arc<dyn Comm>>| {
        let mut sim = on_ranks(SELF_GRAVITATING, comm, None);
        let (first, last) = run_for(&mut sim, 200);
        (whole(sim), first, last)
    };
    let (one, first, last) = run(None);
    let one = one.unwrap();
    let mut two = None;
    for ranks in [2, 3, 4] {
        let (many, f, l) = in_process(ranks, |comm| run(Some(comm))).remove(0);
        let many = many.unwrap();
        let (p, q) = (&one.particles, &many.particles);
        let scale = p.position.iter().map(|r| r.length()).fold(0.0, f64::max);
        for (a, b) in p.position.iter().zip(&q.position) {
            assert!(
                (*a - *b).length() < 1e-11 * scale,
                "{ranks} ranks: {a} against one process's {b}"
            );
        }
        for (a, e) in [(&f, &first), (&l, &last)] {
            assert!(
                (a.potential - e.potential).abs() < 1e-12 * e.potential.abs(),
                "{ranks} ranks: U = {} against {}",
                a.potential,
                e.potential
            );
            let (a, e) = (a.total_energy(), e.total_energy());
            assert!(
                (a - e).abs() < 1e-12 * e.abs(),
                "{ranks} ranks: E = {a} against {e}"
            );
        }
        match &two {
            None => two = Some(many),
            Some(two) => {
                let (p, q) = (&two.particles, &many.particles);
                assert!(p.position == q.position, "{ranks} ranks: positions");
                assert!(p.velocity == q.velocity, "{ranks} ranks: velocities");
                assert!(p.dipole == q.dipole, "{ranks} ranks: moments");
            }
        }
    }
    // The moments turned.
    let start = crate::common::build(SELF_GRAVITATING).simulation.system;
    assert!(one.particles.dipole != start.particles.dipole);
    // The cloud fell in: its potential energy deepened by a sixth, the
    // energy gone into motion.
    assert!(
        last.potential < 1.15 * first.potential && last.kinetic > 0.1 * first.potential.abs(),
        "{first:?} → {last:?}"
    );
}
