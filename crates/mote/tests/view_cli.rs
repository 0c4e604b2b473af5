//! `mote view` from the command line: a trajectory that cannot be read is
//! refused at once with `file:line: message` and a non-zero exit; a good one
//! is served on 127.0.0.1 and the printed address answers.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};

#[test]
fn unreadable_trajectory_is_refused_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.xyz");
    std::fs::write(
        &bad,
        "2\nLattice=\"1 0 0 0 1 0 0 0 1\"\nH 0 0 0\nH 0 zero 0\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["view", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.xyz:4"), "{err}");
    let missing = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["view", "no-such-file.xyz"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("no-such-file.xyz"));
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
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["view", good.to_str().unwrap()])
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
        .trim_end_matches('/')
        .parse()
        .unwrap();
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        s,
        "GET /api/meta HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut reply = String::new();
    s.read_to_string(&mut reply).unwrap();
    child.kill().ok();
    child.wait().ok();
    assert!(reply.starts_with("HTTP/1.1 200"), "{reply}");
    assert!(reply.contains("\"frames\":1"), "{reply}");
}
