//! Benchmark scene for BENCHMARKS: N random spheres (radius 0.5, number
//! density giving a packing fraction of 0.3, overlaps allowed) in a cube, drawn
//! at 1920×1080 with shadows; optionally also written as a POV-Ray scene of the
//! identical spheres, camera and light.
//!
//! `cargo run --release -p mote-render --example render_bench -- N THREADS out.png [out.pov]`

use std::time::Instant;

use glam::Vec3;
use mote_render::{camera::DEFAULT_VIEW, Camera, Cell, RenderOptions, Renderer, Scene};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: render_bench N THREADS out.png [out.pov]");
        std::process::exit(2);
    }
    let n: usize = args[1].parse().expect("N");
    let threads: usize = args[2].parse().expect("THREADS");
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .expect("thread pool");
    let r = 0.5f32;
    let side = (n as f32 * 4.0 / 3.0 * std::f32::consts::PI * r.powi(3) / 0.3).cbrt();
    let mut st = 2024u64;
    let mut rnd = move || {
        st = st
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((st >> 40) as f32) / (1u64 << 24) as f32
    };
    let mut scene = Scene::new();
    for _ in 0..n {
        let c = Vec3::new(rnd(), rnd(), rnd()) * side;
        let col = mote_render::ColorMap::Viridis.at(c.z / side);
        scene.add_sphere(c, r, col);
    }
    scene.cell = Some(Cell {
        origin: Vec3::ZERO,
        edges: [Vec3::X * side, Vec3::Y * side, Vec3::Z * side],
    });
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, DEFAULT_VIEW, 30.0, 1920, 1080);
    let opts = RenderOptions {
        shadows: true,
        ..RenderOptions::default()
    };
    let t0 = Instant::now();
    let renderer = Renderer::new(&scene);
    let t1 = Instant::now();
    let img = renderer.render(&cam, &opts);
    let t2 = Instant::now();
    img.write_png(std::path::Path::new(&args[3])).expect("png");
    let t3 = Instant::now();
    println!(
        "n={n} threads={threads} bvh={:.3}s render={:.3}s png={:.3}s total={:.3}s",
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        (t3 - t2).as_secs_f64(),
        (t3 - t0).as_secs_f64()
    );
    if let Some(pov) = args.get(4) {
        mote_render::pov::write_pov(std::path::Path::new(pov), &scene, &cam, &opts).expect("pov");
    }
}
