//! P3M Coulomb against the Ewald sum: energies and forces of random
//! charges to the accuracy asked for, the measured RMS force error beside
//! the estimate across orders and meshes, a rock-salt crystal's Madelung
//! energy and pressure, momentum, and the same bits on any thread count.

use mote_md::force::ewald::Ewald;
use mote_md::force::p3m::influence::{kspace_error, Aliases, Kernel};
use mote_md::force::p3m::{P3mCoulomb, Parameters, Request};
use mote_md::{Boundary, DVec3, Interaction, State};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// `n` charges ±1 (neutral) placed at random in a box of sides `cell`.
fn random_charges(n: usize, cell: DVec3, seed: u64) -> (Vec<DVec3>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pos = (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * cell)
        .collect();
    let q = (0..n)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    (pos, q)
}

/// Energy and forces of P3M (Coulomb constant 1).
fn p3m(p3m: &mut P3mCoulomb, pos: &[DVec3], q: &[f64], boundary: &Boundary) -> (f64, Vec<DVec3>) {
    let v = vec![DVec3::ZERO; pos.len()];
    let m = vec![1.0; pos.len()];
    let state = State::new(pos, &v, &m, 0.0)
        .with_charges(q)
        .in_box(boundary);
    let mut f = vec![DVec3::ZERO; pos.len()];
    p3m.add_forces(&state, &mut f);
    (p3m.potential_energy(&state), f)
}

/// Energy and forces of an Ewald sum converged far past P3M's accuracy.
fn ewald(pos: &[DVec3], q: &[f64], cell: DVec3) -> (f64, Vec<DVec3>) {
    let e = Ewald::for_charges_in(cell, 0.5 * cell.min_element(), 1e-9, q);
    let mut f = vec![DVec3::ZERO; pos.len()];
    let u = e.charges(pos, q, Some(&mut f));
    (u, f)
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
fn tuned_forces_meet_the_accuracy_asked_for() {
    // An orthorhombic box: the mesh follows the sides.
    let cell = DVec3::new(10.0, 12.0, 8.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, q) = random_charges(400, cell, 7);
    let (u_ref, f_ref) = ewald(&pos, &q, cell);
    for accuracy in [1e-3, 1e-4, 1e-5] {
        let request = Request {
            accuracy,
            skin: 0.3,
            ..Request::default()
        };
        let mut solver = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
        let (u, f) = p3m(&mut solver, &pos, &q, &boundary);
        let error = rms_difference(&f, &f_ref);
        let p = solver.parameters;
        println!(
            "δ = {accuracy:e}: {:?} order {} α {:.4} r_c {:.3}: estimate {:.3e}, measured {error:.3e}; U {u:.10} vs Ewald {u_ref:.10}",
            p.mesh,
            p.order,
            p.alpha,
            p.cutoff,
            p.estimated_error()
        );
        // The tuner's promise is the estimate; the estimate is an RMS over
        // random configurations, and this one's measured error is within
        // the factor 2 of it that the issue asks for.
        assert!(p.estimated_error() <= accuracy);
        let ratio = error / p.estimated_error();
        assert!(
            (0.5..=2.0).contains(&ratio),
            "measured {error:e}, estimate {:e}",
            p.estimated_error()
        );
        // The energy's error per particle is of the order of the force's
        // times a spacing.
        assert!((u - u_ref).abs() < accuracy * pos.len() as f64);
    }
}

/// Deserno & Holm's estimate of the mesh part against the measured error
/// (real space converged: α small against the cut-off), across orders
/// and meshes: within a factor 2, as the issue asks. Order 1 is the
/// "coarse lattice of sources" of seed 000 (each cell's charges lumped on
/// its lattice point; docs/toning-nip.md compares it with P3M).
#[test]
fn mesh_error_matches_the_estimate_across_orders_and_meshes() {
    let cell = DVec3::splat(10.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, q) = random_charges(300, cell, 11);
    let (_, f_ref) = ewald(&pos, &q, cell);
    let (alpha, cutoff) = (0.9, 4.5);
    let n = pos.len() as f64;
    for order in [1, 2, 3, 5, 7] {
        for m in [8, 16, 32] {
            let parameters = Parameters {
                mesh: [m; 3],
                order,
                alpha,
                cutoff,
                real_error: 0.0,
                kspace_error: kspace_error(
                    Kernel::Charge,
                    [m; 3],
                    cell,
                    order,
                    alpha,
                    n,
                    n,
                    Aliases::Full,
                ),
            };
            let mut solver = P3mCoulomb::new(1.0, parameters, 0.3, &boundary);
            let (_, f) = p3m(&mut solver, &pos, &q, &boundary);
            let measured = rms_difference(&f, &f_ref);
            let ratio = measured / parameters.kspace_error;
            println!("order {order} mesh {m}³: estimate {:.3e}, measured {measured:.3e}, ratio {ratio:.2}", parameters.kspace_error);
            if measured > 1e-8 {
                assert!(
                    (0.5..=2.0).contains(&ratio),
                    "order {order}, mesh {m}: ratio {ratio}"
                );
            }
        }
    }
}

/// Rock salt, nearest-neighbour distance a: U = −M N q²/(2a) with the
/// Madelung constant M = 1.747564594633 (N ions), and the pressure of the
/// static crystal P = U/(3V) (the virial of a 1/r law is W = U).
#[test]
fn rock_salt_madelung_energy_and_pressure() {
    let (cells, a) = (4, 1.0);
    let side = 2.0 * a * cells as f64;
    let cell = DVec3::splat(side);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (mut pos, mut q) = (vec![], vec![]);
    let sites = 2 * cells;
    for i in 0..sites {
        for j in 0..sites {
            for k in 0..sites {
                pos.push(DVec3::new(i as f64, j as f64, k as f64) * a + DVec3::splat(0.25));
                q.push(if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 });
            }
        }
    }
    let n = pos.len() as f64;
    let madelung = -1.747_564_594_633 * n / (2.0 * a);
    let request = Request {
        accuracy: 1e-6,
        skin: 0.2,
        ..Request::default()
    };
    let mut solver = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
    let (u, f) = p3m(&mut solver, &pos, &q, &boundary);
    println!("{}", solver.describe());
    println!(
        "U = {u:.12}, Madelung {madelung:.12}, virial {:.12}",
        solver.virial().unwrap()
    );
    assert!(
        ((u - madelung) / madelung).abs() < 1e-6,
        "U = {u}, expected {madelung}"
    );
    // Every ion sits at a centre of symmetry: no force.
    assert!(
        f.iter().all(|f| f.length() < 1e-5),
        "{:?}",
        f.iter().map(|f| f.length()).fold(0.0, f64::max)
    );
    let w = solver.virial().unwrap();
    assert!(((w - u) / u).abs() < 1e-5, "W = {w}, U = {u}");
    let v = vec![DVec3::ZERO; pos.len()];
    let m = vec![1.0; pos.len()];
    let state = State::new(&pos, &v, &m, 0.0)
        .with_charges(&q)
        .in_box(&boundary);
    let tensor = solver.virial_tensor(&state).unwrap();
    for axis in 0..3 {
        assert!(
            (tensor.0[axis] - u / 3.0).abs() < 1e-5 * u.abs(),
            "{:?}",
            tensor.0
        );
    }
    for off in 3..6 {
        assert!(tensor.0[off].abs() < 1e-6 * u.abs(), "{:?}", tensor.0);
    }
}

/// ik-differentiation with one assignment for the charges and the forces
/// conserves momentum: Σ F = Σ_k (−iDG/V)|Q̂|² = 0 to round-off.
#[test]
fn mesh_forces_conserve_momentum() {
    let cell = DVec3::new(9.0, 9.0, 11.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, q) = random_charges(500, cell, 3);
    let request = Request {
        accuracy: 1e-4,
        skin: 0.3,
        ..Request::default()
    };
    let mut solver = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
    let (_, f) = p3m(&mut solver, &pos, &q, &boundary);
    let total: DVec3 = f.iter().sum();
    let scale: f64 = f.iter().map(|f| f.length()).sum();
    assert!(
        total.length() < 1e-12 * scale,
        "Σ F = {total}, Σ|F| = {scale}"
    );
}

#[test]
fn forces_are_the_same_bits_on_any_thread_count() {
    let cell = DVec3::splat(12.0);
    let boundary = Boundary::periodic(DVec3::ZERO, cell);
    let (pos, q) = random_charges(2000, cell, 5);
    let request = Request {
        accuracy: 1e-4,
        skin: 0.3,
        ..Request::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut solver = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
            p3m(&mut solver, &pos, &q, &boundary)
        })
    };
    let one = run(1);
    for threads in [2, 3] {
        let other = run(threads);
        assert_eq!(one.0.to_bits(), other.0.to_bits());
        assert!(one
            .1
            .iter()
            .zip(&other.1)
            .all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits)));
    }
}

/// A molten salt from a scene (`[coulomb] method = "p3m"` beside WCA
/// cores, 216 ions melting from rock salt): its tuned parameters are told,
/// the pressure has its virial, and energy is conserved over 400 steps:
/// the error, set by the time step (at 1e-7 it is the same to two digits),
/// stays within 5e-5 of the kinetic energy; at the end, the melt's forces
/// by P3M tuned to 10⁻⁴ against a converged Ewald sum.
#[test]
fn molten_salt_scene_conserves_energy() {
    let text = r#"
units = "lj"
[run]
integrator = "leapfrog"
dt = 0.001
[lennard_jones]
wca = true
[coulomb]
method = "p3m"
accuracy = 1e-5
[[fcc]]
cells = [3, 3, 3]
density = 0.25
kt = 0.5
charge = 1.0
[[fcc]]
cells = [3, 3, 3]
density = 0.25
kt = 0.5
origin = [1.2599210498948732, 0.0, 0.0]
charge = -1.0
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
        said.len() == 1 && said[0].starts_with("Coulomb by P3M: mesh"),
        "{said:?}"
    );
    let first = mote_md::Observables::measure(&sim.system, &mut sim.forces);
    assert!(first.pressure.is_finite(), "P = {}", first.pressure);
    let e0 = first.total_energy();
    let mut worst: f64 = 0.0;
    crate::common::steps(sim, 400, |sim| {
        let o = mote_md::Observables::measure(&sim.system, &mut sim.forces);
        worst = worst.max((o.total_energy() - e0).abs());
    });
    println!("{}: |ΔE| ≤ {worst:.3e}, K = {:.3}", said[0], first.kinetic);
    assert!(worst < 5e-5 * first.kinetic, "energy drifts by {worst:e}");
    // The melt's configuration against Ewald: P3M tuned to δ = 1e-4 meets
    // it on this liquid as on random charges.
    let (pos, q) = (
        sim.system.particles.position.clone(),
        sim.system.particles.charge.clone(),
    );
    let boundary = sim.system.boundary;
    let cell = boundary.lengths();
    let (u_ref, f_ref) = ewald(&pos, &q, cell);
    let request = Request {
        accuracy: 1e-4,
        skin: 0.3,
        ..Request::default()
    };
    let mut solver = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
    let (u, f) = p3m(&mut solver, &pos, &q, &boundary);
    let error = rms_difference(&f, &f_ref);
    let estimate = solver.parameters.estimated_error();
    println!("melt: measured {error:.3e}, estimate {estimate:.3e}; U {u:.8} vs Ewald {u_ref:.8}");
    assert!(
        (0.5..=2.0).contains(&(error / estimate)),
        "{error:e} vs {estimate:e}"
    );
    assert!((u - u_ref).abs() < 1e-4 * pos.len() as f64);
}
