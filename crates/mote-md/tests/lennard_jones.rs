//! Lennard-Jones fluids: neighbour lists against brute force, energy
//! conservation, the equation of state of Johnson, Zollweg & Gubbins (1993).

use crate::common;

use common::*;
use mote_md::neighbor::VerletList;
use mote_md::{Boundary, DVec3, Observables};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Every pair within r_c + skin is in the Verlet list, and no other, for
/// periodic, partly periodic and open boxes, with particles clustered and spread.
#[test]
fn verlet_list_never_misses_a_pair() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    for periodic in [
        [true, true, true],
        [true, false, true],
        [false, false, false],
    ] {
        for n in [10usize, 400, 2000] {
            let l = DVec3::new(9.0, 7.5, 11.0);
            let b = Boundary {
                lo: DVec3::ZERO,
                hi: l,
                periodic,
            };
            let pos: Vec<DVec3> = (0..n)
                .map(|k| {
                    let u = DVec3::new(rng.gen(), rng.gen(), rng.gen());
                    // Half the particles crowd into a corner.
                    if k % 2 == 0 {
                        u * l
                    } else {
                        u * 1.5
                    }
                })
                .collect();
            let mut list = VerletList::new(1.1, 0.3);
            list.build(&pos, &b);
            let mut half = VerletList::half(1.1, 0.3);
            half.build(&pos, &b);
            let reach2 = 1.4f64 * 1.4;
            for i in 0..n {
                let mut brute: Vec<u32> = (0..n)
                    .filter(|&j| {
                        j != i && b.minimum_image(pos[j] - pos[i]).length_squared() < reach2
                    })
                    .map(|j| j as u32)
                    .collect();
                brute.sort_unstable();
                assert_eq!(
                    list.of(i),
                    &brute[..],
                    "{periodic:?}, N = {n}, particle {i}"
                );
            }
        }
    }
}

fn lj_fluid(kt: f64, thermostat: &str, steps: u64, dt: f64, cells: usize) -> String {
    format!(
        r#"
units = "lj"
seed = 11
[run]
integrator = "leapfrog"
dt = {dt}
steps = {steps}
[lennard_jones]
cutoff = 2.5
shifted = true
[[fcc]]
cells = [{cells}, {cells}, {cells}]
density = 0.8442
kt = {kt}
{thermostat}
"#
    )
}

/// (drift, fluctuation) of the total energy per particle of an LJ liquid
/// (melting from fcc at T* = 1.44, ρ* = 0.8442, shifted potential cut at
/// 2.5σ, dt = 0.005) over `n` steps: drift = |mean of the last fifth − mean
/// of the first fifth|, fluctuation = max |E − E0|. The force jumps at the
/// cut-off make the energy fluctuate by ~1e-4 ε (3× less at dt/2: measured)
/// without a trend.
fn nve_drift(n: u64, cells: usize) -> (f64, f64) {
    let mut sim = build(&lj_fluid(1.44, "", 0, 0.005, cells)).simulation;
    let np = sim.system.particles.len() as f64;
    let e0 = Observables::measure(&sim.system, &mut sim.forces).total_energy();
    let mut series = Vec::new();
    steps(&mut sim, n, |s| {
        if s.system.step % 20 == 0 {
            series.push((Observables::measure(&s.system, &mut s.forces).total_energy() - e0) / np);
        }
    });
    let fifth = series.len() / 5;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let drift = (mean(&series[series.len() - fifth..]) - mean(&series[..fifth])).abs();
    let swing = series.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    let p: DVec3 = sim.system.particles.velocity.iter().copied().sum();
    assert!(p.length() < 1e-10, "total momentum {p}");
    (drift, swing)
}

#[test]
fn lj_nve_conserves_energy() {
    let (drift, swing) = nve_drift(4000, 4);
    assert!(drift < 1e-4, "drift {drift:.2e} ε per particle");
    assert!(swing < 5e-4, "fluctuation {swing:.2e} ε per particle");
}

/// The Bussi thermostat holds the temperature it is given.
#[test]
fn bussi_thermostat_reaches_its_temperature() {
    let text = lj_fluid(
        2.0,
        "[thermostat]\nkind = \"bussi\"\nkt = 0.9\ntau = 0.1",
        0,
        0.005,
        4,
    );
    let mut sim = build(&text).simulation;
    let mut sum = 0.0;
    let mut count = 0.0;
    for k in 0..1500 {
        mote_run::Propagator::advance(&mut sim).unwrap();
        if k >= 500 {
            sum += Observables::measure(&sim.system, &mut sim.forces).kt;
            count += 1.0;
        }
    }
    let mean = sum / count;
    assert!((mean - 0.9).abs() < 0.02, "mean kT {mean}");
}

/// NVE drift over 10⁵ steps (slow: `cargo test --release -- --ignored`).
#[test]
#[ignore]
fn lj_nve_drift_over_1e5_steps() {
    let (drift, swing) = nve_drift(100_000, 4);
    assert!(
        drift < 1e-4,
        "drift {drift:.2e} ε per particle over 1e5 steps"
    );
    assert!(swing < 5e-4, "fluctuation {swing:.2e}");
}

/// Forces, energy and virial of LJ by brute force: every pair and every
/// periodic image within the cut-off (so boxes shorter than 2 r_c count the
/// same particle several times, as the ghost list must).
fn lj_brute(
    pos: &[DVec3],
    b: &Boundary,
    lj: &mote_md::force::LennardJones,
) -> (Vec<DVec3>, f64, f64) {
    let l = b.hi - b.lo;
    let reach = |axis: usize| {
        if b.periodic[axis] {
            (lj.cutoff / l[axis]).ceil() as i32 + 1
        } else {
            0
        }
    };
    let (nx, ny, nz) = (reach(0), reach(1), reach(2));
    let (s2, e) = (lj.sigma * lj.sigma, lj.epsilon);
    let mut force = vec![DVec3::ZERO; pos.len()];
    let (mut energy, mut virial) = (0.0, 0.0);
    for i in 0..pos.len() {
        for j in 0..pos.len() {
            for a in -nx..=nx {
                for c in -ny..=ny {
                    for d in -nz..=nz {
                        let shift = DVec3::new(a as f64, c as f64, d as f64) * l;
                        if i == j && shift == DVec3::ZERO {
                            continue;
                        }
                        let r = pos[i] - pos[j] - shift;
                        let r2 = r.length_squared();
                        if r2 >= lj.cutoff * lj.cutoff {
                            continue;
                        }
                        let s6 = (s2 / r2).powi(3);
                        let f_over_r = 24.0 * e * (2.0 * s6 * s6 - s6) / r2;
                        force[i] += r * f_over_r;
                        // Each pair is met from both ends: halve.
                        energy += 0.5 * (4.0 * e * (s6 * s6 - s6) - lj.shift());
                        virial += 0.5 * f_over_r * r2;
                    }
                }
            }
        }
    }
    (force, energy, virial)
}

/// A simple-cubic lattice of `n³` sites filling `l`, each site moved by up
/// to ±0.1 of the spacing per axis (no two particles closer than 0.8 of it).
fn jittered(n: usize, l: DVec3, rng: &mut Xoshiro256PlusPlus) -> Vec<DVec3> {
    let a = l / n as f64;
    let mut pos = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let u = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5;
                pos.push((DVec3::new(i as f64, j as f64, k as f64) + 0.5 + 0.2 * u) * a);
            }
        }
    }
    pos
}

fn lj_through_list(
    lj: &mut mote_md::force::LennardJones,
    pos: &[DVec3],
    b: &Boundary,
) -> (Vec<DVec3>, f64, f64) {
    use mote_md::{Interaction, State};
    let zero = vec![DVec3::ZERO; pos.len()];
    let mass = vec![1.0; pos.len()];
    let state = State::new(pos, &zero, &mass, 0.0).in_box(b);
    let mut force = vec![DVec3::ZERO; pos.len()];
    lj.add_forces(&state, &mut force);
    // The virial comes with the energy (the stepping pass sums forces only).
    assert!(lj.virial().unwrap().is_nan());
    let energy = lj.potential_energy(&state);
    let virial = lj.virial().unwrap();
    (force, energy, virial)
}

/// The ghost-list LJ gives the forces, energy and virial of the brute-force
/// sum over images: periodic, walled on one axis, open, and a box shorter
/// than two cut-offs (several images of one particle in reach).
#[test]
fn lj_forces_match_brute_force_over_images() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let cases = [
        (DVec3::splat(7.0), [true, true, true], 6usize),
        (DVec3::new(7.0, 8.0, 6.5), [true, false, true], 6),
        (DVec3::splat(6.0), [false, false, false], 5),
        (DVec3::new(3.2, 4.0, 3.6), [true, true, true], 3),
    ];
    for (l, periodic, n) in cases {
        let b = Boundary {
            lo: DVec3::new(-1.0, 0.5, 2.0),
            hi: DVec3::new(-1.0, 0.5, 2.0) + l,
            periodic,
        };
        let pos: Vec<DVec3> = jittered(n, l, &mut rng).iter().map(|p| *p + b.lo).collect();
        for shifted in [true, false] {
            let mut lj = mote_md::force::LennardJones::new(1.0, 1.0, 2.5, shifted, 0.3);
            let (f, u, w) = lj_through_list(&mut lj, &pos, &b);
            let (fb, ub, wb) = lj_brute(&pos, &b, &lj);
            let scale = fb.iter().fold(0.0f64, |a, f| a.max(f.length()));
            for i in 0..pos.len() {
                let err = (f[i] - fb[i]).length() / scale;
                assert!(
                    err < 1e-12,
                    "{periodic:?} L = {l}: particle {i}: {} vs {}",
                    f[i],
                    fb[i]
                );
            }
            assert!(
                (u - ub).abs() < 1e-11 * ub.abs().max(1.0),
                "energy {u} vs {ub}"
            );
            assert!(
                (w - wb).abs() < 1e-11 * wb.abs().max(1.0),
                "virial {w} vs {wb}"
            );
        }
    }
}

/// The AVX-512 rows (where the CPU has them) and the lane rows agree with
/// the one-neighbour-at-a-time reference to round-off, and two threads
/// give the bits of one.
#[test]
fn lj_rows_agree_across_kernels_and_threads() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let l = DVec3::splat(9.0);
    let b = Boundary {
        lo: DVec3::ZERO,
        hi: l,
        periodic: [true; 3],
    };
    let pos = jittered(9, l, &mut rng);
    use mote_md::force::lennard_jones::Rows;
    let run = |rows: Rows, threads: usize| {
        mote_testkit::on_threads(threads, || {
            let mut lj = mote_md::force::LennardJones::new(1.0, 1.0, 2.5, true, 0.3);
            lj.set_rows(rows);
            lj_through_list(&mut lj, &pos, &b)
        })
    };
    let (fp, up, wp) = run(Rows::Reference, 1);
    let scale = fp.iter().fold(0.0f64, |a, f| a.max(f.length()));
    for rows in [Rows::Avx512, Rows::Lanes] {
        let (f1, u1, w1) = run(rows, 1);
        let (f2, u2, w2) = run(rows, 2);
        assert_eq!(f1, f2, "{rows:?}: forces differ between 1 and 2 threads");
        assert_eq!((u1.to_bits(), w1.to_bits()), (u2.to_bits(), w2.to_bits()));
        for i in 0..pos.len() {
            assert!(
                (f1[i] - fp[i]).length() < 1e-13 * scale,
                "{rows:?}: particle {i}"
            );
        }
        assert!((u1 - up).abs() < 1e-12 * up.abs(), "{rows:?}: energy");
        assert!((w1 - wp).abs() < 1e-12 * wp.abs(), "{rows:?}: virial");
    }
}

/// A neighbour at no distance (two particles on one spot) gives a force
/// that is not a number on the lane rows, as on the reference, so the run
/// stops as unstable instead of leaving the pair out.
#[test]
fn coincident_particles_are_not_left_out_by_the_lane_rows() {
    use mote_md::force::lennard_jones::Rows;
    let b = Boundary {
        lo: DVec3::ZERO,
        hi: DVec3::splat(6.0),
        periodic: [true; 3],
    };
    let mut pos: Vec<DVec3> = (0..11)
        .map(|i| DVec3::new(0.5 + 0.5 * i as f64, 3.0, 3.0))
        .collect();
    pos.push(pos[4]);
    for rows in [Rows::Reference, Rows::Lanes] {
        let mut lj = mote_md::force::LennardJones::new(1.0, 1.0, 2.5, true, 0.3);
        lj.set_rows(rows);
        let (f, _, _) = lj_through_list(&mut lj, &pos, &b);
        assert!(
            !f[4].is_finite() && !f[11].is_finite(),
            "{rows:?}: {:?}",
            f[4]
        );
    }
}

/// `[lennard_jones]` beside a cut-off `[dipolar]` runs in the dipolar pair
/// loop (one interaction, one pass over the pairs, as LAMMPS's
/// `lj/cut/dipole/cut`): its forces, torques and energy are the sums of the
/// two laws run apart, to round-off.
#[test]
fn lennard_jones_beside_dipoles_runs_in_their_pair_loop() {
    let scene = |tables: &str| {
        format!(
            "units = \"lj\"\nseed = 9\n[run]\ndt = 0.002\n{tables}\
             [[fcc]]\ncells = [4, 4, 4]\ndensity = 0.8\nkt = 1.0\ndipole = [0.0, 0.0, 1.2]\n"
        )
    };
    let lj = "[lennard_jones]\ncutoff = 2.5\nshifted = false\nrebuild_every = 20\n";
    let dipolar = "[dipolar]\ncutoff = 2.5\nrandom_orientation = true\n";
    let measure = |text: &str| {
        let mut built = common::build(text);
        let sim = &mut built.simulation;
        let n = sim.system.particles.len();
        // Off the lattice (where LJ forces cancel by symmetry), the same
        // way in every build.
        for (i, x) in sim.system.particles.position.iter_mut().enumerate() {
            let k = i as f64;
            *x += 0.08 * DVec3::new((1.3 * k).sin(), (2.1 * k).cos(), (0.7 * k).sin());
        }
        let p = &sim.system.particles;
        let state = mote_md::force::State::of(&sim.system, &p.position, &p.velocity, 0.0, 0.0);
        let spin = mote_md::force::Spin {
            angular_velocity: &p.angular_velocity,
        };
        let (mut f, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        sim.forces
            .add_forces_and_torques(&state, &spin, &mut f, &mut t);
        let count = sim.forces.interactions.len();
        let u = Observables::measure(&sim.system, &mut sim.forces).potential;
        (f, t, u, count)
    };
    let (f, t, u, count) = measure(&scene(&format!("{lj}{dipolar}")));
    let (f_lj, _, u_lj, _) = measure(&scene(lj));
    let (f_d, t_d, u_d, _) = measure(&scene(dipolar));
    assert_eq!(count, 1, "one interaction for both laws");
    let scale = f_lj.iter().map(|x| x.length()).fold(0.0, f64::max);
    assert!(scale > 1.0, "LJ forces off the lattice: {scale}");
    for i in 0..f.len() {
        assert!(
            (f[i] - f_lj[i] - f_d[i]).length() < 1e-11 * scale,
            "force {i}: {} against {} + {}",
            f[i],
            f_lj[i],
            f_d[i]
        );
        assert!((t[i] - t_d[i]).length() < 1e-11 * scale, "torque {i}");
    }
    assert!(
        (u - u_lj - u_d).abs() < 1e-11 * u.abs(),
        "{u} against {u_lj} + {u_d}"
    );
}
