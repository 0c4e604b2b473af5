//! Lennard-Jones fluids: neighbour lists against brute force, energy
//! conservation, the equation of state of Johnson, Zollweg & Gubbins (1993).

mod common;

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
        sim.stepper.step(&mut sim.system, &mut sim.forces, sim.dt);
        let mut noise = sim.noise(sim.system.step);
        sim.thermostat
            .unwrap()
            .apply(&mut sim.system, sim.dt, &mut noise);
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
