//! `mote view` from the command line: a trajectory that cannot be read is
//! reported with `file:line: message` in the terminal and on the page, and
//! the exit is non-zero; a good one is served on 127.0.0.1 and the printed
//! address answers; a live run goes on with no page open and Ctrl-C ends
//! it and the server cleanly, its files kept.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};

/// Starts `mote view ARGS`; the child and the port it printed.
fn start(args: &[&str]) -> (std::process::Child, u16) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .arg("view")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no address in {line:?}"));
    let port: u16 = url
        .trim_start_matches("http://127.0.0.1:")
        .split('/')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    (child, port)
}

fn get(port: u16, path: &str) -> String {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut reply = String::new();
    s.read_to_string(&mut reply).unwrap();
    reply
}

/// Sends SIGINT (what Ctrl-C sends) and waits for the exit.
fn interrupt(mut child: std::process::Child) -> (std::process::ExitStatus, String) {
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status, err)
}

#[test]
fn unreadable_trajectory_is_shown_in_the_terminal_and_on_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.xyz");
    std::fs::write(
        &bad,
        "2\nLattice=\"1 0 0 0 1 0 0 0 1\"\nH 0 0 0\nH 0 zero 0\n",
    )
    .unwrap();
    let (child, port) = start(&[bad.to_str().unwrap()]);
    let meta = get(port, "/api/meta");
    assert!(
        meta.contains("\"error\":") && meta.contains("bad.xyz:4"),
        "{meta}"
    );
    let (status, err) = interrupt(child);
    assert_eq!(status.code(), Some(1));
    assert!(err.contains("bad.xyz:4"), "{err}");
    let (child, port) = start(&["no-such-file.xyz"]);
    assert!(get(port, "/api/meta").contains("no-such-file.xyz"));
    let (status, err) = interrupt(child);
    assert_eq!(status.code(), Some(1));
    assert!(err.contains("no-such-file.xyz"), "{err}");
}

#[test]
fn serves_on_loopback_and_prints_the_address() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.xyz");
    std::fs::write(
        &good,
        "2\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3\nH 1 1 1\nO 2 2 2\n",
    )
    .unwrap();
    let (child, port) = start(&[good.to_str().unwrap()]);
    let reply = get(port, "/api/meta");
    let (status, _) = interrupt(child);
    assert_eq!(status.code(), Some(0));
    assert!(reply.starts_with("HTTP/1.1 200"), "{reply}");
    assert!(reply.contains("\"frames\":1"), "{reply}");
}

#[test]
fn ctrl_c_ends_a_live_run_and_the_server_keeping_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("fall.toml");
    std::fs::write(
        &scene,
        "[run]\nintegrator = \"leapfrog\"\ndt = 1e-4\nsteps = 100000000\n\
         [field]\ng = [0.0, 0.0, -1.0]\n[[particle]]\nposition = [0.0, 0.0, 0.0]\n\
         [output]\nobservables_every = 100\ntrajectory_every = 0\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let (child, port) = start(&[scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let meta = get(port, "/api/meta");
    assert!(meta.contains("\"live\":true"), "{meta}");
    // No page is open: the run goes on by itself.
    let table = out.join("observables.csv");
    let rows = || {
        std::fs::read_to_string(&table)
            .map(|t| t.lines().filter(|l| !l.starts_with('#')).count())
            .unwrap_or(0)
    };
    let t0 = std::time::Instant::now();
    while rows() < 10 && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(rows() >= 10, "the run did not go on without a page");
    let (status, err) = interrupt(child);
    assert_eq!(status.code(), Some(0), "{err}");
    assert!(
        err.contains("stopped") || err.contains("interrupt"),
        "{err}"
    );
    let kept = rows();
    assert!(kept >= 10);
    let last = std::fs::read_to_string(&table).unwrap();
    assert!(last.ends_with('\n'), "the table ends in a whole row");
}

/// A packing is watched live as any run is (it steps one pressure window
/// at a time through the same loop): the page's session is live, the
/// windows' table grows with no page open, and Ctrl-C ends it with the
/// packing so far written.
#[test]
fn a_growing_packing_is_watched_live() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("grow.toml");
    std::fs::write(
        &scene,
        "seed = 2\n[packing]\nn = 3000\nrate = 0.001\nmax_pressure = 1e12\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let (child, port) = start(&[scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let meta = get(port, "/api/meta");
    assert!(meta.contains("\"live\":true"), "{meta}");
    let table = out.join("packing.csv");
    let rows = || {
        std::fs::read_to_string(&table)
            .map(|t| t.lines().filter(|l| !l.starts_with('#')).count())
            .unwrap_or(0)
    };
    let t0 = std::time::Instant::now();
    // the header and three windows
    while rows() < 4 && t0.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(rows() >= 4, "the packing did not grow without a page");
    let (status, err) = interrupt(child);
    assert_eq!(status.code(), Some(0), "{err}");
    let frames = mote_io::xyz::read_frames(&out.join("packing.xyz")).unwrap();
    assert_eq!(frames.last().unwrap().positions.len(), 3000, "{err}");
}

/// A soft packing (the SP method's barostat) runs live too; Ctrl-C
/// writes the spheres so far.
#[test]
fn a_soft_packing_is_watched_live() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("soft.toml");
    std::fs::write(&scene, "seed = 2\n[packing]\nmethod = \"soft\"\nn = 2000\n").unwrap();
    let out = dir.path().join("out");
    let (child, port) = start(&[scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let meta = get(port, "/api/meta");
    assert!(meta.contains("\"live\":true"), "{meta}");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let (status, err) = interrupt(child);
    assert_eq!(status.code(), Some(0), "{err}");
    assert!(err.contains("the packing so far is written"), "{err}");
    let frames = mote_io::xyz::read_frames(&out.join("packing.xyz")).unwrap();
    assert_eq!(frames.last().unwrap().positions.len(), 2000, "{err}");
}
