//! Criterion benchmarks of the rigid kernels: `cargo bench -p mote-md --bench rigid`.

use criterion::{criterion_group, criterion_main, Criterion};

fn placeholder(_c: &mut Criterion) {}

criterion_group!(benches, placeholder);
criterion_main!(benches);
