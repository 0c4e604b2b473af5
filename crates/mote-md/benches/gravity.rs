//! Direct-summation gravity kernel: pair interactions per second.
//! `cargo bench -p mote-md --bench gravity`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mote_md::force::{DirectGravity, Interaction, State};
use mote_md::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn cloud(n: usize) -> (Vec<DVec3>, Vec<DVec3>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let pos = (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
        .collect();
    (pos, vec![DVec3::ZERO; n], vec![1.0 / n as f64; n])
}

fn gravity(c: &mut Criterion) {
    let mut group = c.benchmark_group("direct_gravity");
    group.sample_size(10);
    for n in [4096usize, 16384] {
        let (pos, vel, mass) = cloud(n);
        // Throughput in unordered pairs N(N−1)/2, REBOUND's convention.
        group.throughput(Throughput::Elements((n * (n - 1) / 2) as u64));
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut g = DirectGravity::new(1.0, 0.01);
            let mut force = vec![DVec3::ZERO; n];
            group.bench_with_input(
                BenchmarkId::new(format!("{threads}-threads"), n),
                &n,
                |b, _| {
                    b.iter(|| {
                        pool.install(|| {
                            let state = State::new(&pos, &vel, &mass, 0.0);
                            g.add_forces(&state, &mut force)
                        })
                    })
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, gravity);
criterion_main!(benches);
