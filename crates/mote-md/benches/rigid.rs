//! Criterion benchmarks of the rigid-body integrator (FRBI, seed 000):
//! `cargo bench -p mote-md --bench rigid`.
//!
//! - `frbi_fields/10000`: one step of 10⁴ random 10-sphere clumps (8 shared
//!   templates) under a rotating magnetic field, an electric field, gravity
//!   and air drag — no contacts, no pair forces. Throughput = body-steps.
//! - `frbi_dipolar/1000`: one step of 10³ magnetised charged clumps with
//!   all-pairs Coulomb and dipole–dipole forces and torques.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::{
    AirDrag, BodyTemplate, Coulomb, DipoleDipole, ExternalFields, Field, Frbi, Gravity,
    Integration, IrregularClump, RigidBodies,
};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn clumps(n: usize) -> RigidBodies {
    let gen = IrregularClump {
        radius: 40e-6,
        density: 5000.0,
        ..IrregularClump::default()
    };
    let mut b = RigidBodies::new();
    let kinds: Vec<u32> = (0..8)
        .map(|s| {
            let mut spec = gen.generate(s);
            spec.dipole = DVec3::new(0.0, 0.0, 2e-8);
            spec.charge = 1e-14;
            b.add_template(BodyTemplate::new(&spec, Integration::default()).unwrap())
        })
        .collect();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let side = (n as f64).cbrt().ceil() as usize;
    for i in 0..n {
        let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
        let pos = DVec3::new(x as f64, y as f64, z as f64) * 200e-6;
        let r = DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let w = DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ) * 100.0;
        b.push(kinds[i % 8], E::new(r, pos), DE::new(w, DVec3::ZERO));
    }
    b
}

fn fields() -> Frbi {
    Frbi::new()
        .with(ExternalFields {
            electric: Field::Constant(DVec3::new(0.0, 0.0, 1e5)),
            magnetic: Field::Rotating {
                offset: DVec3::ZERO,
                amplitude: 0.05,
                axis: DVec3::Z,
                start: DVec3::X,
                frequency: 50.0,
                phase: 0.0,
            },
        })
        .with(Gravity {
            g: DVec3::new(0.0, 0.0, -9.81),
        })
        .with(AirDrag {
            viscosity: 1.8e-5,
            air_density: 1.2,
            drag_coefficient: 0.47,
            wind: DVec3::ZERO,
        })
}

fn bench_fields(c: &mut Criterion) {
    let mut g = c.benchmark_group("frbi_fields");
    for n in [1000usize, 10_000] {
        let mut b = clumps(n);
        let mut f = fields();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| f.step(&mut b, 1e-6))
        });
    }
    g.finish();
}

fn bench_dipolar(c: &mut Criterion) {
    let mut g = c.benchmark_group("frbi_dipolar");
    g.sample_size(20);
    let n = 1000;
    let mut b = clumps(n);
    let mut f = fields()
        .with(Coulomb::coulomb(8.9875517923e9))
        .with(DipoleDipole::dipoles(1e-7));
    g.throughput(Throughput::Elements(n as u64));
    g.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
        bench.iter(|| f.step(&mut b, 1e-6))
    });
    g.finish();
}

criterion_group!(benches, bench_fields, bench_dipolar);
criterion_main!(benches);
