//! Timed runs (ignored; figures for BENCHMARKS.md), one thread unless stated:
//! `cargo test --release -p mote-md --test md dipolar_perf:: -- --ignored --nocapture --test-threads 1`
//!
//! - the dipolar LJ fluid of ../shared/bench/lammps.dipole3d.in (32000
//!   atoms, fcc ρ* = 0.8442, |μ| = 0.75, LJ + dipoles cut at 2.5, skin 0.3,
//!   leap-frog with rotation, h = 0.005, 100 steps): CPU-µs per atom-step
//!   beside LAMMPS' `lj/cut/dipole/cut`;
//! - the seed's timing (004 §6): 1000 dipoles, 50 steps, all pairs exact
//!   (median and best of seven runs).

use std::f64::consts::PI;
use std::time::Instant;

use mote_md::force::dipolar::{DipoleDipole, PairRepulsion};
use mote_md::particles::{ParticleInit, Particles};
use mote_md::{Boundary, DVec3, ForceField, Integrator, Stepper, System};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn random_unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    let z: f64 = rng.gen_range(-1.0..1.0);
    let phi: f64 = rng.gen_range(0.0..2.0 * PI);
    let s = (1.0 - z * z).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn lj_dipole_fluid(cells: usize) -> (System, ForceField) {
    let a = (4.0f64 / 0.8442).cbrt();
    let l = a * cells as f64;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(98934);
    let mut p = Particles::default();
    let basis = [
        DVec3::ZERO,
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(0.5, 0.0, 0.5),
        DVec3::new(0.0, 0.5, 0.5),
    ];
    let sd = 1.44f64.sqrt();
    for k in 0..cells {
        for j in 0..cells {
            for i in 0..cells {
                for b in basis {
                    let r = (DVec3::new(i as f64, j as f64, k as f64) + b) * a;
                    let v = DVec3::new(
                        rng.gen::<f64>() - 0.5,
                        rng.gen::<f64>() - 0.5,
                        rng.gen::<f64>() - 0.5,
                    ) * (sd * 12f64.sqrt());
                    p.push(ParticleInit {
                        position: r,
                        velocity: v,
                        radius: 0.5,
                        dipole: random_unit(&mut rng) * 0.75,
                        ..Default::default()
                    });
                }
            }
        }
    }
    let mut sys = System::new(p);
    sys.boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(l));
    sys.to_centre_of_mass_frame();
    let dd = DipoleDipole::cut_off(4.0 * PI, 2.5, 0.3, sys.boundary)
        .unwrap()
        .with_repulsion(PairRepulsion::lennard_jones(1.0, 1.0, 2.5))
        .unwrap();
    (sys, ForceField::new().with(dd))
}

fn cpu_seconds() -> f64 {
    // utime + stime of this process from /proc/self/stat (clock ticks of 1/100 s).
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |k: usize| f.get(k).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0) / 100.0;
    tick(11) + tick(12)
}

/// 100 steps of the 32000-atom fluid on `threads` threads (after one
/// step that builds the list): CPU and wall µs per atom-step.
fn lj_dipole_fluid_32000(threads: usize) {
    mote_testkit::on_threads(threads, || {
        let (mut sys, mut ff) = lj_dipole_fluid(20);
        let mut stepper = Stepper::new(Integrator::LeapFrog);
        stepper.step(&mut sys, &mut ff, 0.005);
        let (c0, w0) = (cpu_seconds(), Instant::now());
        let steps = 100;
        for _ in 0..steps {
            stepper.step(&mut sys, &mut ff, 0.005);
        }
        let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        let n = sys.particles.len() as f64;
        println!("dipolar LJ fluid, N = {n}, {steps} steps, {threads} thread(s): {cpu:.2} CPU-s, {wall:.2} wall-s: {:.3} CPU-µs per atom-step ({:.3} wall)", cpu / (n * steps as f64) * 1e6, wall / (n * steps as f64) * 1e6);
    });
}

#[test]
#[ignore = "timing"]
fn lj_dipole_fluid_32000_one_thread() {
    lj_dipole_fluid_32000(1);
}

#[test]
#[ignore = "timing"]
fn lj_dipole_fluid_32000_two_threads() {
    lj_dipole_fluid_32000(2);
}

#[test]
#[ignore = "timing"]
fn seed_timing_1000_dipoles_50_steps() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let mut p = Particles::default();
    for i in 0..1000 {
        let r = DVec3::new((i % 10) as f64, ((i / 10) % 10) as f64, (i / 100) as f64) * 2.2;
        p.push(ParticleInit {
            position: r,
            radius: 0.5,
            dipole: random_unit(&mut rng),
            ..Default::default()
        });
    }
    let start = System::new(p);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        // Seven runs, alternating with nothing: the median and the best.
        let mut walls: Vec<f64> = (0..7)
            .map(|_| {
                pool.install(|| {
                    let mut sys = start.clone();
                    let mut ff = ForceField::new().with(
                        DipoleDipole::all_pairs(4.0 * PI)
                            .with_repulsion(PairRepulsion::wca(1.0, 1.0))
                            .unwrap(),
                    );
                    let mut stepper = Stepper::new(Integrator::LeapFrog);
                    let w0 = Instant::now();
                    for _ in 0..50 {
                        stepper.step(&mut sys, &mut ff, 0.002);
                    }
                    w0.elapsed().as_secs_f64() * 1e3
                })
            })
            .collect();
        walls.sort_by(f64::total_cmp);
        println!(
            "1000 dipoles, all pairs, 50 steps, {threads} thread(s): median {:.1} ms wall, best {:.1} ms (7 runs)",
            walls[3], walls[0]
        );
    }
}
