//! The viewer's server: loopback by default, the page and its script are
//! served, meta and frames carry the file's numbers, and no request reaches
//! a file (path traversal, unknown paths, bad frame numbers are 404).

use std::io::{Read, Write};
use std::net::TcpStream;

use mote_io::xyz::Frame;
use mote_view::bind;

use crate::common;

fn frames() -> Vec<Frame> {
    (0..3)
        .map(|k| Frame {
            time: 0.5 * k as f64,
            cell: [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
            species: vec!["Ar".into(), "He".into()],
            positions: vec![[1.0, 1.0, 1.0 + k as f64], [2.0, 3.0, 1.5]],
            velocities: vec![[3.0, 4.0, 0.0], [0.0, 0.0, -1.0]],
            radii: vec![0.5, 0.25],
            ..Frame::default()
        })
        .collect()
}

fn start() -> u16 {
    common::start("t.xyz", frames())
}

/// A raw HTTP/1.1 GET (the path is sent as given, `..` included):
/// status code and body.
fn get(port: u16, path: &str) -> (u16, Vec<u8>) {
    get_with(port, path, &format!("Host: localhost:{port}\r\n"))
}

/// A raw GET with the header lines `headers` (each ending in CRLF).
fn get_with(port: u16, path: &str, headers: &str) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\n{headers}Connection: close\r\n\r\n"
    )
    .unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&raw[..split]).to_string();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    let mut body = raw[split + 4..].to_vec();
    if head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        body = dechunk(&body);
    }
    (status, body)
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let line = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n = usize::from_str_radix(std::str::from_utf8(&b[..line]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[line + 2..line + 2 + n]);
        b = &b[line + 2 + n + 2..];
    }
}

#[test]
fn binds_to_loopback_unless_told_otherwise() {
    let (l, loopback) = bind("127.0.0.1", 0).unwrap();
    assert!(loopback && l.local_addr().unwrap().ip().is_loopback());
    let (_, any) = bind("0.0.0.0", 0).unwrap();
    assert!(!any, "0.0.0.0 is not loopback: the CLI warns");
    assert!(bind("localhost.example", 0).is_err());
}

#[test]
fn page_meta_and_frames() {
    let port = start();
    let (s, page) = get(port, "/");
    assert_eq!(s, 200);
    assert!(String::from_utf8_lossy(&page).contains("viewer.js"));
    let (s, js) = get(port, "/viewer.js");
    assert_eq!(s, 200);
    assert!(String::from_utf8_lossy(&js).contains("webgl2"));
    let (s, meta) = get(port, "/api/meta");
    assert_eq!(s, 200);
    let meta: serde_json::Value = serde_json::from_slice(&meta).unwrap();
    assert_eq!(meta["frames"], 3);
    assert_eq!(meta["time"][2], 1.0);
    assert_eq!(meta["species"], serde_json::json!(["Ar", "He"]));
    // Frame 2 coloured by speed: N, then (x, y, z, r) per particle, then speeds.
    let (s, bytes) = get(port, "/api/frame/2?color=speed");
    assert_eq!(s, 200);
    let f = |k: usize| f32::from_le_bytes(bytes[4 + 4 * k..8 + 4 * k].try_into().unwrap());
    assert_eq!(u32::from_le_bytes(bytes[..4].try_into().unwrap()), 2);
    assert_eq!(bytes.len(), 4 + 2 * 16 + 2 * 4);
    assert_eq!([f(0), f(1), f(2), f(3)], [1.0, 1.0, 3.0, 0.5]);
    assert_eq!([f(8), f(9)], [5.0, 1.0]);
    // The inspector's view of one particle.
    let (s, p) = get(port, "/api/particle/1/0");
    assert_eq!(s, 200);
    let p: serde_json::Value = serde_json::from_slice(&p).unwrap();
    assert_eq!(p["species"], "Ar");
    assert_eq!(p["position"], serde_json::json!([1.0, 1.0, 2.0]));
    assert_eq!(p["velocity"], serde_json::json!([3.0, 4.0, 0.0]));
    assert_eq!(p["radius"], 0.5);
    assert_eq!(get(port, "/api/particle/1/2").0, 404);
    let (_, species) = get(port, "/api/frame/0");
    let g = |k: usize| f32::from_le_bytes(species[4 + 4 * k..8 + 4 * k].try_into().unwrap());
    assert_eq!([g(8), g(9)], [0.0, 1.0]);
}

#[test]
fn no_request_reaches_a_file() {
    let port = start();
    for path in [
        "/../Cargo.toml",
        "/../../../../etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/api/frame/../../Cargo.toml",
        "/assets/index.html",
        "/src/lib.rs",
        "/api/frame/7",
        "/api/frame/-1",
        "/api/frame/0?color=mass",
        "/api/particle/0/../../../etc/passwd",
        "/api/particle/9/0",
    ] {
        let (s, body) = get(port, path);
        assert_eq!(s, 404, "{path}: {}", String::from_utf8_lossy(&body));
        let text = String::from_utf8_lossy(&body);
        assert!(
            !text.contains("[package]") && !text.contains("root:"),
            "{path}"
        );
    }
}

/// The doors: a `Host` that is not the server's own (DNS rebinding: a
/// site's name pointed at 127.0.0.1) and a foreign `Origin` are refused
/// before anything is answered; the server's own names are let in.
#[test]
fn foreign_hosts_and_origins_are_refused() {
    let port = start();
    for host in [
        format!("Host: evil.example:{port}\r\n"),
        format!("Host: 127.0.0.1.nip.io:{port}\r\n"),
        format!("Host: 127.0.0.1:{}\r\n", port.wrapping_add(1)),
        String::new(),
    ] {
        for path in ["/", "/api/meta", "/api/frame/0"] {
            let (status, body) = get_with(port, path, &host);
            assert_eq!(status, 403, "{host:?} {path}");
            assert!(String::from_utf8_lossy(&body).contains("own address"));
        }
    }
    for own in [
        format!("Host: 127.0.0.1:{port}\r\n"),
        format!("Host: localhost:{port}\r\n"),
        format!("Host: [::1]:{port}\r\n"),
        format!("Host: 127.0.0.1:{port}\r\nOrigin: http://localhost:{port}\r\n"),
    ] {
        assert_eq!(get_with(port, "/api/meta", &own).0, 200, "{own:?}");
    }
    for origin in [
        "https://evil.example".to_string(),
        "null".to_string(),
        format!("http://evil.example:{port}"),
    ] {
        let headers = format!("Host: 127.0.0.1:{port}\r\nOrigin: {origin}\r\n");
        assert_eq!(get_with(port, "/api/meta", &headers).0, 403, "{origin}");
    }
}

/// Indices out of range are 404 with what there is, in every API path.
#[test]
fn out_of_range_indices_are_not_found() {
    let port = start();
    for path in [
        "/api/track/2",
        "/api/track/18446744073709551615",
        "/api/particle/0/2",
        "/api/particle/3/0",
        "/api/frame/3",
    ] {
        let (status, body) = get(port, path);
        assert_eq!(status, 404, "{path}: {}", String::from_utf8_lossy(&body));
    }
    assert_eq!(get(port, "/api/track/1").0, 200);
}
