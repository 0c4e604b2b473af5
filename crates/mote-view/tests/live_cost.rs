//! What watching costs a run (slow, `--ignored`; BENCHMARKS.md): the
//! settling example (10⁴ spheres) run for 2000 steps alone, then with a
//! client that takes every frame it can (as a page on a fast GPU would).
//! Prints steps per second of both and the frames delivered.
//!
//!     cargo test --release -p mote-view --test view live_cost:: -- --ignored --nocapture

use std::sync::Arc;
use std::time::{Duration, Instant};

use mote_view::live::{self, Session};
use mote_view::App;
use tungstenite::Message;

use crate::common;

fn run(watched: bool) -> (f64, u64) {
    let dir = tempfile::tempdir().unwrap();
    let session = Session::new("settling".into(), dir.path().to_path_buf(), watched);
    let options = mote_front::RunOptions {
        input: Some("example:settling".into()),
        steps: Some(2000),
        output: Some(dir.path().to_path_buf()),
        seed: Some(1),
        ..Default::default()
    };
    let port = common::start_app(Arc::new(App::Live(session.clone())));
    let mut frames = 0;
    let mut ws = None;
    if watched {
        let (mut w, _) = tungstenite::connect(format!(
            "ws://127.0.0.1:{port}/api/live?token={}",
            session.token
        ))
        .unwrap();
        w.send(Message::Text(r#"{"do":"resume"}"#.into())).unwrap();
        ws = Some(w);
    }
    let t0 = Instant::now();
    let handle = live::spawn_run(options, &session, live::ending).unwrap();
    if let Some(w) = ws.as_mut() {
        w.get_ref();
        while session.snapshot().ended.is_none() {
            if let Ok(Message::Binary(_)) = w.read() {
                frames += 1;
                w.send(Message::Text(r#"{"do":"ready"}"#.into())).unwrap();
            }
        }
    }
    handle.join().unwrap();
    let secs = t0.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_millis(100));
    (2000.0 / secs, frames)
}

#[test]
#[ignore]
fn what_watching_costs_the_settling_example() {
    let mut alone = Vec::new();
    let mut watched = Vec::new();
    for _ in 0..3 {
        alone.push(run(false).0);
        watched.push(run(true));
    }
    alone.sort_by(f64::total_cmp);
    watched.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!(
        "settling, 2000 steps: alone {:.0} steps/s (median of 3), watched {:.0} steps/s with {} frames delivered; ratio {:.3}",
        alone[1],
        watched[1].0,
        watched[1].1,
        watched[1].0 / alone[1]
    );
}
