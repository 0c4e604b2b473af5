//! The live socket: frames go out only as fast as the page takes them
//! (dropped, not queued), changes and pause reach the run, and a client
//! that stops reading holds the server's memory bounded.

use std::net::TcpStream;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use mote_io::xyz::Frame;
use mote_run::{Change, Shown};
use mote_view::live::Session;
use mote_view::App;
use tungstenite::{Message, WebSocket};

use crate::common;

/// A stand-in for a run: `n` particles moving along x, stepping `h`
/// (changed by `Change::Dt`) for ever; the changes it took are recorded.
fn fake_run(session: &Arc<Session>, n: usize, taken: Arc<Mutex<Vec<Change>>>) {
    let mut tap = session.tap();
    std::thread::spawn(move || {
        let (mut h, mut t) = (0.01, 0.0);
        let mut step = 0;
        loop {
            loop {
                let changes = tap.between(step, t, &mut || {
                    let frame = Frame {
                        time: t,
                        species: vec!["A".into(); n],
                        positions: (0..n).map(|i| [i as f64 + t, 0.0, 0.0]).collect(),
                        velocities: vec![[1.0, 0.0, 0.0]; n],
                        radii: vec![0.5; n],
                        ..Frame::default()
                    };
                    Some(Shown {
                        frame,
                        forces: vec![[0.0, 0.0, -1.0]; n],
                        walls: Vec::new(),
                    })
                });
                if changes.is_empty() {
                    break;
                }
                for c in changes {
                    let answer = match c {
                        Change::Dt(new) => {
                            let text = format!("dt {h} → {new}");
                            h = new;
                            Ok(text)
                        }
                        ref other => Err(format!("{} cannot be changed", other.what())),
                    };
                    tap.answer(step, t, &c, &answer);
                    taken.lock().unwrap().push(c);
                }
            }
            step += 1;
            t += h;
            if n > 1000 {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
    });
}

/// Serves a live session of `n` particles; the session, the changes its
/// run took, and the port.
fn start(n: usize) -> (Arc<Session>, Arc<Mutex<Vec<Change>>>, u16) {
    let dir = tempfile::tempdir().unwrap().keep();
    let session = Session::new("fake".into(), dir, false);
    let taken = Arc::new(Mutex::new(Vec::new()));
    fake_run(&session, n, taken.clone());
    let port = common::start_app(Arc::new(App::Live(session.clone())));
    (session, taken, port)
}

/// The page's socket to the run, with the run's token.
fn connect(
    port: u16,
    session: &Session,
) -> WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>> {
    let url = format!("ws://127.0.0.1:{port}/api/live?token={}", session.token);
    let (ws, _) = tungstenite::connect(url).unwrap();
    ws
}

/// Reads until a frame (its head and its bytes) comes: head and byte count.
fn next_frame(
    ws: &mut WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>,
) -> (serde_json::Value, usize) {
    let mut head = None;
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => {
                let v: serde_json::Value = serde_json::from_str(&t).unwrap();
                if v["type"] == "frame" {
                    head = Some(v);
                }
            }
            Message::Binary(b) => return (head.expect("a head before the bytes"), b.len()),
            _ => {}
        }
    }
}

fn send(ws: &mut WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>, json: &str) {
    ws.send(Message::Text(json.into())).unwrap();
}

#[test]
fn frames_follow_the_page_and_changes_and_pause_reach_the_run() {
    let (session, taken, port) = start(10);
    let mut ws = connect(port, &session);
    let (head, bytes) = next_frame(&mut ws);
    assert_eq!(head["count"], 10);
    assert_eq!(bytes, 4 + 20 * 10);
    // Not ready: no frame comes however long the run goes.
    let step0 = head["step"].as_u64().unwrap();
    std::thread::sleep(Duration::from_millis(200));
    send(&mut ws, r#"{"do":"ready"}"#);
    let (head, _) = next_frame(&mut ws);
    let step1 = head["step"].as_u64().unwrap();
    assert!(
        step1 > step0 + 10,
        "frames were dropped: steps {step0} → {step1}"
    );

    send(&mut ws, r#"{"do":"set","what":"dt","value":0.5}"#);
    send(
        &mut ws,
        r#"{"do":"set","what":"field","kind":"gravity","vector":[0,0,-1]}"#,
    );
    send(&mut ws, r#"{"do":"set","what":"pressure","value":1}"#);
    let mut log = Vec::new();
    let mut errors = Vec::new();
    let t0 = Instant::now();
    while (log.len() < 2 || errors.is_empty()) && t0.elapsed() < Duration::from_secs(10) {
        if let Message::Text(t) = ws.read().unwrap() {
            let v: serde_json::Value = serde_json::from_str(&t).unwrap();
            if v["type"] == "error" {
                errors.push(v["message"].as_str().unwrap().to_string());
            }
            for l in v["log"].as_array().into_iter().flatten() {
                log.push(l.as_str().unwrap().to_string());
            }
        }
    }
    assert!(log[0].ends_with("dt 0.01 → 0.5"), "{log:?}");
    assert!(
        log[1].contains("not changed: the gravity cannot be changed"),
        "{log:?}"
    );
    assert!(errors[0].contains("set pressure"), "{errors:?}");
    assert_eq!(taken.lock().unwrap()[0], Change::Dt(0.5));

    send(&mut ws, r#"{"do":"pause"}"#);
    std::thread::sleep(Duration::from_millis(300));
    let held = session.snapshot();
    assert!(held.paused);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        session.snapshot().step,
        held.step,
        "a paused run does not step"
    );
    // Changes made while paused apply at once.
    send(&mut ws, r#"{"do":"set","what":"dt","value":0.25}"#);
    let t0 = Instant::now();
    while taken.lock().unwrap().len() < 3 && t0.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(taken.lock().unwrap()[2], Change::Dt(0.25));
    assert_eq!(session.snapshot().step, held.step);
    send(&mut ws, r#"{"do":"resume"}"#);
    std::thread::sleep(Duration::from_millis(300));
    assert!(session.snapshot().step > held.step, "resumed");
    // The page goes away; the run goes on.
    drop(ws);
    let s = session.snapshot().step;
    std::thread::sleep(Duration::from_millis(300));
    assert!(session.snapshot().step > s);
}

/// Resident memory of this process in bytes, after handing freed heap
/// pages back (frames freed by another thread's arena would count
/// otherwise, and the test measures what is held, not the allocator's
/// slack).
fn resident() -> u64 {
    mote_io::system::release_free_memory();
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: u64 = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

#[test]
fn a_client_that_stops_reading_holds_memory_bounded() {
    // 10⁵ particles: a frame is 2 MB on the wire and about 7 MB in memory.
    let (session, _, port) = start(100_000);
    // Frames as fast as the page takes them, whatever they cost the run.
    session.set_frame_share(1.0);
    let mut stuck = connect(port, &session);
    // It asks for frames again and again but reads nothing.
    for _ in 0..200 {
        send(&mut stuck, r#"{"do":"ready"}"#);
    }
    // A page that reads a frame every 20 ms or so keeps frames coming.
    let mut slow = connect(port, &session);
    let _ = next_frame(&mut slow);
    let before = resident();
    let t0 = Instant::now();
    let mut steps = Vec::new();
    while t0.elapsed() < Duration::from_secs(4) {
        std::thread::sleep(Duration::from_millis(20));
        send(&mut slow, r#"{"do":"ready"}"#);
        steps.push(next_frame(&mut slow).0["step"].as_u64().unwrap());
    }
    let grown = resident() as f64 - before as f64;
    let made = session.snapshot().serial;
    eprintln!(
        "{} frames read by the slow page of {made} made; resident memory grew by {:.1} MB",
        steps.len(),
        grown / 1e6
    );
    assert!(steps.windows(2).all(|w| w[1] > w[0]));
    // Had the stuck client's frames been queued, it would hold every frame
    // made (2 MB each on the wire).
    assert!(made >= 40, "only {made} frames made");
    assert!(
        grown < 60e6,
        "resident memory grew by {:.0} MB",
        grown / 1e6
    );
    drop(stuck);
}

/// The live socket's doors: without the run's token, with a wrong one, from
/// another page's origin or to a foreign host name, the handshake is
/// refused (403) and the run sees nothing; the page's own origin with the
/// token gets frames.
#[test]
fn the_live_socket_needs_the_token_and_the_pages_own_origin() {
    use tungstenite::client::IntoClientRequest;
    let (session, _, port) = start(10);
    let attempt = |path: String, extra: &[(&'static str, String)]| {
        let mut request = format!("ws://127.0.0.1:{port}{path}")
            .into_client_request()
            .unwrap();
        for (name, value) in extra {
            request.headers_mut().insert(*name, value.parse().unwrap());
        }
        match tungstenite::connect(request) {
            Ok(_) => 101,
            Err(tungstenite::Error::Http(r)) => r.status().as_u16(),
            Err(e) => panic!("{e}"),
        }
    };
    let with = format!("/api/live?token={}", session.token);
    let wrong = format!("/api/live?token={}", mote_view::doors::new_token());
    assert_eq!(attempt("/api/live".into(), &[]), 403);
    assert_eq!(attempt(wrong, &[]), 403);
    assert_eq!(
        attempt(with.clone(), &[("origin", "http://evil.example".into())]),
        403
    );
    assert_eq!(
        attempt(with.clone(), &[("host", format!("evil.example:{port}"))]),
        403
    );
    assert_eq!(
        attempt(with, &[("origin", format!("http://127.0.0.1:{port}"))]),
        101
    );
    let mut ws = connect(port, &session);
    assert_eq!(next_frame(&mut ws).0["count"], 10);
}
