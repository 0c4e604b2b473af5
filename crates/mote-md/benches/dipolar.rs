//! Criterion benchmarks of the dipolar kernels: `cargo bench -p mote-md --bench dipolar`.
//!
//! - `lj_dipole_fluid/32000`: one leap-frog step (with rotation) of the
//!   dipolar LJ fluid of ../shared/bench/lammps.dipole3d.in — fcc ρ* = 0.8442,
//!   20³ cells, |μ| = 0.75 random, LJ and dipoles cut at 2.5 σ, skin 0.3,
//!   T* = 1.44 — on one thread, beside LAMMPS' `lj/cut/dipole/cut`;
//!   µs per atom-step = time per step / 32000 × 10⁶;
//! - `seed_1000_dipoles_50_steps`: the seed's timing (004 §6: 1000 dipoles,
//!   50 steps) with the exact all-pairs sum and WCA, on 1 and 2 threads.

use std::f64::consts::PI;

use criterion::{criterion_group, criterion_main, Criterion};
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

/// The LAMMPS dipole3d fluid: 4 n³ atoms on an fcc lattice at ρ* = 0.8442.
pub fn lj_dipole_fluid(cells: usize) -> (System, ForceField) {
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
    let sd = (1.44f64).sqrt();
    for k in 0..cells {
        for j in 0..cells {
            for i in 0..cells {
                for b in basis {
                    let r = (DVec3::new(i as f64, j as f64, k as f64) + b) * a;
                    let v = DVec3::new(
                        rng.sample(rand_distr::StandardNormal),
                        rng.sample(rand_distr::StandardNormal),
                        rng.sample(rand_distr::StandardNormal),
                    ) * sd;
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

fn fluid(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut group = c.benchmark_group("lj_dipole_fluid");
    group.sample_size(10);
    let (mut sys, mut ff) = lj_dipole_fluid(20);
    let mut stepper = Stepper::new(Integrator::LeapFrog);
    pool.install(|| {
        for _ in 0..20 {
            stepper.step(&mut sys, &mut ff, 0.005);
        }
    });
    group.bench_function("32000", |b| {
        b.iter(|| pool.install(|| stepper.step(&mut sys, &mut ff, 0.005)))
    });
    group.finish();
}

/// 1000 dipoles at volume fraction 0.05 in an open cluster (no cut-off).
fn seed_timing(c: &mut Criterion) {
    let mut group = c.benchmark_group("seed_1000_dipoles_50_steps");
    group.sample_size(10);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let mut p = Particles::default();
    let side = 10usize;
    for i in 0..1000 {
        let r = DVec3::new(
            (i % side) as f64,
            ((i / side) % side) as f64,
            (i / 100) as f64,
        ) * 2.2;
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
        group.bench_function(format!("{threads}-threads"), |b| {
            b.iter(|| {
                pool.install(|| {
                    let mut sys = start.clone();
                    let mut ff = ForceField::new().with(
                        DipoleDipole::all_pairs(4.0 * PI)
                            .with_repulsion(PairRepulsion::wca(1.0, 1.0))
                            .unwrap(),
                    );
                    let mut stepper = Stepper::new(Integrator::LeapFrog);
                    for _ in 0..50 {
                        stepper.step(&mut sys, &mut ff, 0.002);
                    }
                    sys
                })
            })
        });
    }
    group.finish();
}

criterion_group!(benches, fluid, seed_timing);
criterion_main!(benches);
