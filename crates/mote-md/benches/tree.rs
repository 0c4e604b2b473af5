//! Barnes–Hut tree gravity on a Plummer sphere (G = M = a = 1, ε = 0.01,
//! θ = 0.5, radii ≤ 20: the set-up of ../shared/bench/tree_bench.py).
//!
//! - `cargo bench -p mote-md --bench tree`: criterion, force evaluation at
//!   N = 10⁴ and 10⁵ on 1 and 2 threads.
//! - `… --bench tree -- --plain N STEPS [THREADS]`: leap-frog steps (one tree
//!   build and force evaluation each, dt = 1e-3, as REBOUND's step), printing
//!   the median wall time and the CPU time per step; bench/tree.sh runs this
//!   beside REBOUND.

use criterion::{BenchmarkId, Criterion};
use mote_md::force::{Interaction, State};
use mote_md::tree::{PlummerSphere, TreeGravity};
use mote_md::DVec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::time::Instant;

fn plummer(n: usize) -> (Vec<DVec3>, Vec<DVec3>, Vec<f64>) {
    let sphere = PlummerSphere {
        n,
        mass: 1.0,
        radius: 1.0,
        g: 1.0,
        max_radius: Some(20.0),
    };
    let (pos, vel) = sphere.sample(&mut Xoshiro256PlusPlus::seed_from_u64(1));
    (pos, vel, vec![1.0 / n as f64; n])
}

fn criterion_benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("tree_gravity");
    group.sample_size(10);
    for n in [10_000usize, 100_000] {
        let (pos, vel, mass) = plummer(n);
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut tree = TreeGravity::new(1.0, 0.01, 0.5);
            let mut force = vec![DVec3::ZERO; n];
            group.bench_with_input(
                BenchmarkId::new(format!("{threads}-threads"), n),
                &n,
                |b, _| {
                    b.iter(|| {
                        pool.install(|| {
                            let state = State::new(&pos, &vel, &mass, 0.0);
                            tree.add_forces(&state, &mut force)
                        })
                    })
                },
            );
        }
    }
    group.finish();
}

/// User + system CPU seconds of this process so far (from /proc/self/stat,
/// clock ticks of 1/100 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |k: usize| f.get(k).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of stat(5) are the 12th and 13th after the ')'.
    (tick(11) + tick(12)) / 100.0
}

fn plain(n: usize, steps: usize, threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let (mut pos, mut vel, mass) = plummer(n);
    let mut tree = TreeGravity::new(1.0, 0.01, 0.5);
    let mut force = vec![DVec3::ZERO; n];
    let dt = 1e-3;
    let mut eval = |pos: &[DVec3], vel: &[DVec3], force: &mut Vec<DVec3>| {
        force.iter_mut().for_each(|f| *f = DVec3::ZERO);
        let state = State::new(pos, vel, &mass, 0.0);
        pool.install(|| tree.add_forces(&state, force));
    };
    eval(&pos, &vel, &mut force); // warm-up
    let mut walls = Vec::new();
    let cpu0 = cpu_seconds();
    for _ in 0..steps {
        let t0 = Instant::now();
        // Leap-frog drift–kick–drift, one force evaluation per step (REBOUND's "leapfrog").
        for (r, v) in pos.iter_mut().zip(&vel) {
            *r += *v * (0.5 * dt);
        }
        eval(&pos, &vel, &mut force);
        for ((v, f), m) in vel.iter_mut().zip(&force).zip(&mass) {
            *v += *f / *m * dt;
        }
        for (r, v) in pos.iter_mut().zip(&vel) {
            *r += *v * (0.5 * dt);
        }
        walls.push(t0.elapsed().as_secs_f64());
    }
    let cpu = (cpu_seconds() - cpu0) / steps as f64;
    walls.sort_by(f64::total_cmp);
    let counts = tree.counts();
    println!(
        "mote tree N={n} theta=0.5 threads={threads} steps={steps}  wall median {:.4e} s/step  cpu {:.4e} s/step  {:.0} particle + {:.0} cell interactions per particle",
        walls[walls.len() / 2],
        cpu,
        counts.particle as f64 / n as f64,
        counts.cell as f64 / n as f64,
    );
}

/// Build and walk timed apart (wall, one thread), for leaf and group sizes.
fn split(n: usize, leaf: usize, group: usize) {
    let (pos, _, mass) = plummer(n);
    let mut bh = mote_md::tree::BarnesHut::new(0.5, 0.01);
    bh.dipoles = false;
    bh.tree.leaf_size = leaf;
    bh.group_size = group;
    for _ in 0..3 {
        let t0 = Instant::now();
        bh.build(&pos, &mass);
        let t1 = Instant::now();
        bh.evaluate(false);
        let t2 = Instant::now();
        println!(
            "leaf {leaf}, group {group}: build {:.3} s, walk {:.3} s, {:.0} + {:.0} interactions per particle",
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            bh.counts.particle as f64 / n as f64,
            bh.counts.cell as f64 / n as f64,
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(k) = args.iter().position(|a| a == "--split") {
        let n = args
            .get(k + 1)
            .and_then(|s| s.parse::<f64>().ok())
            .unwrap_or(1e5);
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build_global()
            .unwrap();
        let arg = |j: usize, d: usize| args.get(k + j).and_then(|s| s.parse().ok()).unwrap_or(d);
        split(n as usize, arg(2, 16), arg(3, 64));
        return;
    }
    if let Some(k) = args.iter().position(|a| a == "--plain") {
        let num = |j: usize, default: usize| {
            args.get(k + j)
                .and_then(|s| s.parse::<f64>().ok())
                .map_or(default, |v| v as usize)
        };
        let n = num(1, 100_000);
        let steps = num(2, 10);
        match args.get(k + 3).and_then(|s| s.parse::<usize>().ok()) {
            Some(t) => plain(n, steps, t),
            None => {
                plain(n, steps, 1);
                plain(n, steps, 2);
            }
        }
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    criterion_benches(&mut c);
    c.final_summary();
}
