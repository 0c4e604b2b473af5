//! Criterion benchmarks of the granular kernels: `cargo bench -p mote-md --bench granular`.

use criterion::{criterion_group, criterion_main, Criterion};

fn placeholder(_c: &mut Criterion) {}

criterion_group!(benches, placeholder);
criterion_main!(benches);
