//! The page in a real browser: Debian's Chromium, headless, with WebGL2 on
//! SwiftShader (software). It loads a trajectory of 1000 spheres of two
//! species; the page's state (read from the DOM) holds all of them with no
//! console errors, playing advances the frame and the time,
//! and a screenshot shows the two species' colours. A live run, driven
//! through the DevTools protocol: its time advances on the page, and a
//! change of dt made on the page reaches the run and its observables
//! table, and the page shows the run going on. Skipped, with a
//! message, where no Chromium is installed (`.ci/run` installs Debian's
//! `chromium`; MOTE_CHROMIUM names another binary). MOTE_VIEW_SCREENSHOT=FILE
//! keeps the screenshot (docs/img/view.png is one).

use std::path::PathBuf;
use std::process::Command;

use mote_io::xyz::Frame;

mod cdp;
mod common;

fn chromium() -> Option<PathBuf> {
    if let Ok(p) = std::env::var("MOTE_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
        .into_iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
}

/// 1000 spheres on a 10³ grid, species A in the lower half (z < 5) and B
/// above, drifting along x over five frames.
fn frames() -> Vec<Frame> {
    (0..5)
        .map(|k| {
            let mut f = Frame {
                time: 0.25 * k as f64,
                cell: [[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]],
                ..Frame::default()
            };
            for i in 0..1000 {
                let (x, y, z) = (i % 10, (i / 10) % 10, i / 100);
                f.positions.push([
                    x as f64 + 0.5 + 0.1 * k as f64,
                    y as f64 + 0.5,
                    z as f64 + 0.5,
                ]);
                f.species.push(if z < 5 { "A" } else { "B" }.into());
                f.radii.push(0.45);
                f.velocities.push([0.4, 0.0, 0.0]);
            }
            f
        })
        .collect()
}

fn start() -> u16 {
    common::start("grid.xyz", frames())
}

/// Headless Chromium as the machine's notes say it runs here: as root
/// without the sandbox, off the network's background services, with a
/// fresh profile; WebGL2 by SwiftShader.
fn headless(browser: &PathBuf, extra: &[String], url: &str) -> std::process::Output {
    let profile = tempfile::tempdir().unwrap();
    let mut cmd = Command::new(browser);
    cmd.args(cdp::FLAGS)
        .arg("--virtual-time-budget=10000")
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(url);
    cmd.output().expect("chromium starts")
}

/// The JSON of the page's `#state` element in a dumped DOM.
fn page_state(dom: &str) -> serde_json::Value {
    let start = dom
        .find("<pre id=\"state\" hidden=\"\">")
        .expect("state element")
        + 26;
    let end = start + dom[start..].find("</pre>").unwrap();
    serde_json::from_str(
        &dom[start..end]
            .replace("&quot;", "\"")
            .replace("&amp;", "&"),
    )
    .unwrap()
}

#[test]
fn page_shows_and_plays_a_trajectory_in_chromium() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set MOTE_CHROMIUM)");
        return;
    };
    let port = start();
    // Play from the first frame to the last, then read the page's state.
    let out = headless(
        &browser,
        &["--dump-dom".into()],
        &format!("http://127.0.0.1:{port}/?play=1"),
    );
    let state = page_state(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(state["errors"], serde_json::json!([]), "{state}");
    assert_eq!(state["n"], 1000, "{state}");
    assert_eq!(state["frames"], 5);
    // Virtual time runs the animation only part of the way (the frames'
    // fetches are real time): playing must have moved it on from frame 0.
    let frame = state["frame"].as_u64().unwrap();
    assert!(frame >= 1, "playing did not advance: {state}");
    assert_eq!(state["time"], 0.25 * frame as f64);
    assert!(state["drawn"].as_u64().unwrap() > frame);

    // Clicking the middle of the view inspects the sphere under it.
    let out = headless(
        &browser,
        &["--dump-dom".into()],
        &format!("http://127.0.0.1:{port}/?pick=0.5,0.55"),
    );
    let state = page_state(&String::from_utf8_lossy(&out.stdout));
    assert!(state["picked"].is_u64(), "nothing picked: {state}");
    let species = state["inspected"]["species"].as_str().unwrap_or_default();
    assert!(species == "A" || species == "B", "{state}");
    assert_eq!(state["inspected"]["radius"], 0.45);

    // A screenshot of the first frame: the two species' colours.
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("page.png");
    headless(
        &browser,
        &[format!("--screenshot={}", shot.display())],
        &format!("http://127.0.0.1:{port}/"),
    );
    if let Ok(keep) = std::env::var("MOTE_VIEW_SCREENSHOT") {
        std::fs::copy(&shot, keep).unwrap();
    }
    let decoder = png::Decoder::new(std::fs::File::open(&shot).expect("a screenshot"));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels = buf[..info.buffer_size()].chunks(channels);
    let (mut red, mut blue, mut total) = (0usize, 0usize, 0usize);
    for p in pixels {
        let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
        total += 1;
        if r > 120 && g < 80 && b < 80 {
            red += 1;
        }
        if b > 100 && r < 70 && b > g {
            blue += 1;
        }
    }
    let (fr, fb) = (red as f64 / total as f64, blue as f64 / total as f64);
    println!(
        "screenshot: {:.1} % red (A), {:.1} % blue (B)",
        100.0 * fr,
        100.0 * fb
    );
    assert!(fr > 0.02 && fb > 0.02, "red {fr}, blue {fb}");
}

/// 300 glass beads settling in a box (the settling example, smaller), for
/// as long as the test watches.
const SETTLING: &str = r#"
units = "si"
[run]
integrator = "leapfrog"
dt = 5e-5
steps = 1000000000
[field]
g = [0.0, 0.0, -9.81]
[granular]
young = 1e6
poisson = 0.3
restitution = 0.5
friction = 0.5
[[wall]]
kind = "box"
name = "box"
lo = [0.0, 0.0, 0.0]
hi = [0.03, 0.03, 0.06]
[[cloud]]
n = 300
min = [0.0, 0.0, 0.0]
max = [0.03, 0.03, 0.05]
radius = 0.002
density = 2500.0
[output]
observables_every = 50
trajectory_every = 0
"#;

#[test]
fn a_live_run_advances_and_takes_a_change_from_the_page() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set MOTE_CHROMIUM)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("settling.toml");
    std::fs::write(&scene, SETTLING).unwrap();
    let out = dir.path().join("out");
    // The run starts paused: the page changes dt, then lets it run.
    let session = mote_view::live::Session::new("settling.toml".into(), out.clone(), true);
    let options = mote_front::RunOptions {
        input: Some(scene.display().to_string()),
        output: Some(out.clone()),
        seed: Some(5),
        ..Default::default()
    };
    mote_view::live::spawn_run(options, &session, mote_view::live::ending).unwrap();
    let port = common::start_app(std::sync::Arc::new(mote_view::App::Live(session.clone())));
    let mut page = cdp::Browser::open(
        &browser,
        &format!(
            "http://127.0.0.1:{port}/?set=dt:0.000025&run=1&color=speed&token={}",
            session.token
        ),
    );
    let limit = std::time::Duration::from_secs(60);
    let state = page.state_when(limit, |s| {
        s["loaded"].as_u64().unwrap_or(0) >= 3 && s["time"].as_f64().unwrap_or(0.0) > 0.0
    });
    assert_eq!(state["errors"], serde_json::json!([]), "{state}");
    assert_eq!(state["live"], true);
    assert_eq!(state["n"], 300, "{state}");
    // The box wall: six planes, each drawn as its face (four lines).
    assert_eq!(state["walls"], 24, "{state}");
    assert!(
        state["time"].as_f64().unwrap() > 0.0,
        "time did not advance: {state}"
    );
    let log = state["log"].to_string();
    assert!(
        log.contains("step 0") && log.contains("dt 0.00005 → 0.000025"),
        "{state}"
    );
    // The run really steps with the new dt: t = 2.5e-5 · step (summed:
    // round-off grows with the steps).
    let later = page.state_when(limit, |s| s["step"].as_u64().unwrap_or(0) > 200);
    let (step, snap) = (later["step"].as_u64().unwrap(), session.snapshot());
    assert!(step > 200, "{later}");
    assert_eq!(later["paused"], false, "{later}");
    assert!(
        (snap.time - 2.5e-5 * snap.step as f64).abs() < 1e-9,
        "{}",
        snap.time
    );
    // The page's plot follows the observables table, event included.
    let plotted = page.state_when(limit, |s| s["rows"].as_u64().unwrap_or(0) >= 3);
    assert!(
        plotted["events"][0]
            .as_str()
            .unwrap()
            .contains("dt 0.00005 → 0.000025"),
        "{plotted}"
    );
    let table = std::fs::read_to_string(out.join("observables.csv")).unwrap();
    assert!(
        table.contains("# event: step 0, t = 0: dt 0.00005 → 0.000025"),
        "{table}"
    );
    // MOTE_VIEW_LIVE_SCREENSHOT=FILE keeps a picture of the live page
    // (docs/img/view-live.png is one): a particle picked, plots filled.
    if let Ok(keep) = std::env::var("MOTE_VIEW_LIVE_SCREENSHOT") {
        page.eval("inspect(pickAt(canvas.clientWidth / 2, canvas.clientHeight / 2))");
        page.state_when(limit, |s| s["tracked"].as_u64().unwrap_or(0) >= 20);
        std::fs::write(keep, page.screenshot()).unwrap();
    }
    mote_io::system::request_stop(15);
}

/// A browser without WebGL2 gets one line that says so (it said "null"
/// from the first call on the missing context).
#[test]
fn a_browser_without_webgl2_is_told_why() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set MOTE_CHROMIUM)");
        return;
    };
    let port = start();
    let out = headless(
        &browser,
        &[
            "--dump-dom".into(),
            "--disable-webgl".into(),
            "--disable-webgl2".into(),
        ],
        &format!("http://127.0.0.1:{port}/"),
    );
    let dom = String::from_utf8_lossy(&out.stdout);
    let state = page_state(&dom);
    let errors: Vec<String> = state["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap_or("").to_string())
        .collect();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].contains("no WebGL2 context"), "{errors:?}");
}

/// The page plots first the column its table names (a Brownian run's
/// `# plot: potential_energy`), else the total energy.
#[test]
fn the_page_plots_first_what_the_run_names() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no Chromium (install Debian's chromium, or set MOTE_CHROMIUM)");
        return;
    };
    for (named, plotted) in [
        (Some("potential_energy"), "potential_energy"),
        (None, "total_energy"),
    ] {
        let table = mote_view::table::Table {
            columns: ["time", "kinetic_energy", "potential_energy", "total_energy"]
                .map(String::from)
                .to_vec(),
            rows: vec![vec![0.0, 1.0, -2.0, -1.0], vec![1.0, 0.5, -2.5, -2.0]],
            events: Vec::new(),
            plot: named.map(String::from),
        };
        let app = mote_view::App::file(
            mote_view::Trajectory::new("grid.xyz".into(), frames()),
            Some(table),
        );
        let port = common::start_app(app);
        let out = headless(
            &browser,
            &["--dump-dom".into()],
            &format!("http://127.0.0.1:{port}/"),
        );
        let state = page_state(&String::from_utf8_lossy(&out.stdout));
        assert_eq!(state["errors"], serde_json::json!([]), "{state}");
        assert_eq!(state["plotted"], plotted, "{state}");
    }
}
