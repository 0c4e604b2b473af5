//! Frames per second of the page with 10⁵ spheres (slow, `--ignored`;
//! BENCHMARKS.md): 10⁵ spheres of radius 0.5 at random in a box of 50,
//! the page at 1000 × 700 in headless Chromium (WebGL2 on SwiftShader),
//! driven through
//! the DevTools protocol so that the page's clock is real time. Prints the
//! time to the first frame, and redraws per second at full resolution and
//! while the camera moves (level of detail).
//!
//!     cargo test --release -p mote-view --test view render_cost:: -- --ignored --nocapture

use std::time::Duration;

use mote_io::xyz::Frame;
use rand::{Rng, SeedableRng};

#[allow(dead_code)] // the screenshot helper is the live browser test's
use crate::cdp;
use crate::common;

#[test]
#[ignore]
fn redraws_per_second_at_100000_spheres() {
    let browser = std::env::var("MOTE_CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let n = 100_000;
    let frame = Frame {
        cell: [[50.0, 0.0, 0.0], [0.0, 50.0, 0.0], [0.0, 0.0, 50.0]],
        species: vec!["A".into(); n],
        positions: (0..n)
            .map(|_| [0.0; 3].map(|_: f64| rng.gen::<f64>() * 50.0))
            .collect(),
        radii: vec![0.5; n],
        ..Frame::default()
    };
    let port = common::start("big.xyz", vec![frame]);
    // Browser start to the first frame drawn, three times.
    let mut loads = Vec::new();
    for _ in 0..3 {
        let t0 = std::time::Instant::now();
        let mut page = cdp::Browser::open(
            std::path::Path::new(&browser),
            &format!("http://127.0.0.1:{port}/"),
        );
        let s = page.state_when(Duration::from_secs(120), |s| s["loadMs"].is_number());
        loads.push((
            t0.elapsed().as_secs_f64(),
            s["loadMs"].as_f64().unwrap() / 1000.0,
        ));
    }
    let count = 10;
    let mut page = cdp::Browser::open(
        std::path::Path::new(&browser),
        &format!("http://127.0.0.1:{port}/?bench={count}"),
    );
    let state = page.state_when(Duration::from_secs(600), |s| s["movingFps"].is_number());
    println!(
        "10^5 spheres, 1000 x 700: first frame drawn (browser start, page's own) {loads:.2?} s; \
         {:.2} redraws/s in full, {:.2} while moving (points: {}); errors {}",
        state["fps"].as_f64().unwrap_or(f64::NAN),
        state["movingFps"].as_f64().unwrap_or(f64::NAN),
        state["lod"],
        state["errors"]
    );
}
