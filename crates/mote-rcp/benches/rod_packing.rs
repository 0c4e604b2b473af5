//! Rod-packing estimate: the fast path (Newton sweep / closed-form inverse + heap/FIFO
//! packing) against the straightforward algorithm of spherepack1d (100 bisection steps
//! per rod + sorted-array insertion, O(N²) at worst), in the same run.
//!
//! cargo bench -p mote-rcp --bench rod_packing

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mote_rcp::{baseline, ErfcFlavour, Population, RodPacking, SizeDistribution};
use std::hint::black_box;
use std::time::Duration;

fn cases() -> Vec<(&'static str, SizeDistribution)> {
    vec![
        (
            "lognormal_d43_2_d32_0.5",
            SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap(),
        ),
        (
            "tridisperse_2_3_4",
            SizeDistribution::new([
                Population::monodisperse(2.0, 1.5),
                Population::monodisperse(3.0, 2.5),
                Population::monodisperse(4.0, 3.5),
            ])
            .unwrap(),
        ),
        (
            "three_lognormals",
            SizeDistribution::new([
                Population::lognormal(1.0, 0.3, 1.0),
                Population::lognormal(3.0, 0.5, 1.0),
                Population::lognormal(10.0, 0.8, 1.0),
            ])
            .unwrap(),
        ),
    ]
}

fn small(c: &mut Criterion) {
    let mut g = c.benchmark_group("rcp");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for (name, d) in cases() {
        for n in [16_000usize, 100_000] {
            g.bench_with_input(BenchmarkId::new(format!("fast/{name}"), n), &n, |b, &n| {
                b.iter(|| {
                    RodPacking::default()
                        .rods(n)
                        .estimate(black_box(&d))
                        .unwrap()
                        .phi
                })
            });
            g.bench_with_input(
                BenchmarkId::new(format!("baseline/{name}"), n),
                &n,
                |b, &n| {
                    b.iter(|| baseline::estimate(black_box(&d), n, 0.7654, ErfcFlavour::Accurate))
                },
            );
        }
    }
    g.finish();
}

fn large(c: &mut Criterion) {
    let mut g = c.benchmark_group("rcp_large");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for (name, d) in cases() {
        for n in [1_000_000usize, 10_000_000] {
            g.bench_with_input(BenchmarkId::new(format!("fast/{name}"), n), &n, |b, &n| {
                b.iter(|| {
                    RodPacking::default()
                        .rods(n)
                        .estimate(black_box(&d))
                        .unwrap()
                        .phi
                })
            });
        }
    }
    g.finish();
}

/// The packing alone on fixed rods: heap/FIFO against sorted insertion.
fn packing_only(c: &mut Criterion) {
    let mut g = c.benchmark_group("packing_only");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    let d = SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap();
    for n in [16_000usize, 100_000] {
        let rods = d.rod_lengths(n, ErfcFlavour::Accurate).unwrap();
        g.bench_with_input(BenchmarkId::new("heap_fifo", n), &rods, |b, r| {
            b.iter(|| mote_rcp::pack_rods(black_box(r), 0.7654).unwrap().phi)
        });
        g.bench_with_input(BenchmarkId::new("sorted_insertion", n), &rods, |b, r| {
            b.iter(|| baseline::pack_sorted_insertion(black_box(r), 0.7654))
        });
    }
    g.finish();
}

criterion_group!(benches, small, packing_only, large);
criterion_main!(benches);
