//! Timed runs for BENCHMARKS.md.
//!
//! `cargo run --release -p mote-edmd --example edmd_bench -- eos D N ETA T [EQUIL] [SEED]`
//!   monodisperse diameter 1, kT = 1, fcc/square start, periodic; prints
//!   collisions, CPU-side event-loop seconds, collisions per second, Z.
//! `cargo run --release -p mote-edmd --example edmd_bench -- cube NBS [FRAMES]`
//!   the seed-001 cube: prints the wall time per frame of 1/20 simulated time.
use mote_edmd::{Scene, System};
use std::path::Path;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    match a.get(1).map(String::as_str) {
        Some("eos") => {
            let dim: usize = a[2].parse().unwrap();
            let n: usize = a[3].parse().unwrap();
            let eta: f64 = a[4].parse().unwrap();
            let t: f64 = a[5].parse().unwrap();
            let eq: f64 = a.get(6).map(|s| s.parse().unwrap()).unwrap_or(0.0);
            let seed: u64 = a.get(7).map(|s| s.parse().unwrap()).unwrap_or(1);
            let text = format!(
                "[event_driven]\ndimension = {dim}\nn = {n}\npacking_fraction = {eta}\n\
                 [run]\nequilibrate = {eq}\nuntil = {}\n",
                eq + t
            );
            let scene = Scene::parse(&text, "bench").unwrap();
            if dim == 2 {
                run::<2>(&scene, seed, eq, t);
            } else {
                run::<3>(&scene, seed, eq, t);
            }
        }
        Some("cube") => {
            let nbs: usize = a[2].parse().unwrap();
            let frames: usize = a.get(3).map(|s| s.parse().unwrap()).unwrap_or(40);
            let r = 1.0 / ((30.0 * std::f64::consts::PI).powf(1.0 / 3.0) * nbs as f64);
            let text = format!(
                "[box]\nhi = [1.0, 1.0, 1.0]\nperiodic = [false, false, false]\n\
                 [event_driven]\nn = {}\nradius = {r}\nplacement = \"cubic\"\nspeed = 1.0\n",
                nbs * nbs * nbs
            );
            let scene = Scene::parse(&text, "cube").unwrap();
            let setup = Instant::now();
            let mut sys: System<3> = scene.build(1, Path::new(".")).unwrap();
            let setup = setup.elapsed().as_secs_f64();
            let start = Instant::now();
            let mut worst: f64 = 0.0;
            for f in 1..=frames {
                let t0 = Instant::now();
                sys.run_until(f as f64 / 20.0);
                let _pos = sys.positions(); // what a renderer would read
                worst = worst.max(t0.elapsed().as_secs_f64());
            }
            let el = start.elapsed().as_secs_f64();
            println!(
                "nbs={nbs} N={} setup={setup:.4}s frames={frames} mean_frame={:.6}s worst_frame={worst:.6}s collisions/frame={:.1} rebuilds/frame={:.1} shell={:.3}",
                sys.len(),
                el / frames as f64,
                sys.counters().collisions as f64 / frames as f64,
                sys.counters().rebuilds as f64 / frames as f64,
                sys.shell()
            );
        }
        _ => eprintln!("usage: edmd_bench eos D N ETA T [EQUIL] [SEED] | cube NBS [FRAMES]"),
    }
}

fn run<const D: usize>(scene: &Scene, seed: u64, eq: f64, t: f64) {
    let mut sys: System<D> = scene.build(seed, Path::new(".")).unwrap();
    let e0 = sys.kinetic_energy();
    sys.run_until(eq);
    sys.reset_counters();
    let start = Instant::now();
    sys.run_until(eq + t);
    let el = start.elapsed().as_secs_f64();
    let c = sys.counters();
    println!(
        "D={D} N={} eta={:.4} t={t} collisions={} rebuilds={} invalid={} loop_seconds={el:.3} coll_per_s={:.4e} ns_per_coll={:.1} Z={:.5} dE/E={:.2e}",
        sys.len(),
        sys.packing_fraction(),
        c.collisions,
        c.rebuilds,
        c.invalid,
        c.collisions as f64 / el,
        el * 1e9 / c.collisions as f64,
        sys.compressibility(),
        (sys.kinetic_energy() - e0) / e0
    );
    assert!(sys.find_overlap(1e-9).is_none());
}
