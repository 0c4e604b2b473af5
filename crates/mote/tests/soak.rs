//! Soak runs (issue 23): a 10⁶-particle run for an hour (or
//! `MOTE_SOAK_SECONDS`) with its resident memory sampled every 5 s from
//! /proc; the run is then ended with SIGTERM, which must end it cleanly
//! (exit 143). After the first minute the resident memory must not grow:
//! the median of the last five minutes may exceed the median of the
//! second minute by at most 2 % + 16 MiB (medians, because writing a
//! trajectory frame holds its text for a moment: a spike, not growth).
//! The samples go to stdout (and to `MOTE_SOAK_LOG` when set), with the
//! bytes per particle.
//!
//! `cargo test --release -p mote --test cli soak:: -- --ignored --nocapture`
//! (two runs of an hour each; `MOTE_SOAK_THREADS` sets `--threads`, 1 by
//! default).

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Resident memory (VmRSS) of a process in bytes, if it still runs.
fn resident(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Soaks `scene` (in bench/), first running `bed` (in bench/, when given)
/// into `soak-bed/` beside a copy of the scene, whose `[[from_file]]`
/// starts from that bed's last frame.
fn soak(scene: &str, particles: u64, bed: Option<&str>) {
    let seconds: u64 = std::env::var("MOTE_SOAK_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600);
    let threads = std::env::var("MOTE_SOAK_THREADS").unwrap_or_else(|_| "1".into());
    let out = tempfile::tempdir().unwrap();
    let bench = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench");
    let scene = out.path().join(scene);
    std::fs::copy(bench.join(scene.file_name().unwrap()), &scene).unwrap();
    if let Some(bed) = bed {
        let made = Command::new(env!("CARGO_BIN_EXE_mote"))
            .args(["-q", "--threads", &threads, "run"])
            .arg(bench.join(bed))
            .arg("-o")
            .arg(out.path().join("soak-bed"))
            .output()
            .unwrap();
        assert!(
            made.status.success(),
            "{bed}: {}",
            String::from_utf8_lossy(&made.stderr)
        );
    }
    let run = out.path().join("run");
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["-q", "--threads", &threads, "run"])
        .arg(&scene)
        .arg("-o")
        .arg(&run)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let start = Instant::now();
    let mut samples: Vec<(f64, u64)> = Vec::new();
    let mut log = std::env::var("MOTE_SOAK_LOG")
        .ok()
        .map(|p| std::fs::File::create(p).unwrap());
    while start.elapsed() < Duration::from_secs(seconds) {
        std::thread::sleep(Duration::from_secs(5));
        if let Ok(Some(status)) = child.try_wait() {
            panic!("{}: ended early with {status}", scene.display());
        }
        if let Some(rss) = resident(pid) {
            let t = start.elapsed().as_secs_f64();
            samples.push((t, rss));
            if let Some(f) = log.as_mut() {
                writeln!(f, "{t:.0} {rss}").unwrap();
            }
        }
    }
    Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .unwrap();
    let status = child.wait_with_output().unwrap();
    assert_eq!(
        status.status.code(),
        Some(143),
        "SIGTERM must end the run cleanly: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let rows = std::fs::read_to_string(run.join("observables.csv"))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .count()
        .saturating_sub(1);
    let median = |from: f64, to: f64| -> u64 {
        let mut v: Vec<u64> = samples
            .iter()
            .filter(|(t, _)| *t >= from && *t < to)
            .map(|s| s.1)
            .collect();
        v.sort_unstable();
        *v.get(v.len() / 2).expect("samples in the window")
    };
    let end = seconds as f64;
    let second_minute = median(60.0, 120.0);
    let last = median((end - 300.0).max(120.0), end + 10.0);
    let peak = samples.iter().map(|s| s.1).max().unwrap();
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    println!(
        "{}: {seconds} s, {rows} observable rows, resident (medians) {:.1} MiB in the second minute, {:.1} MiB in the last five; peak {:.1} MiB; {:.0} bytes per particle",
        scene.display(),
        mib(second_minute),
        mib(last),
        mib(peak),
        last as f64 / particles as f64
    );
    let allowed = second_minute + second_minute / 50 + 16 * 1024 * 1024;
    assert!(
        last <= allowed,
        "resident memory grew from {:.1} to {:.1} MiB",
        mib(second_minute),
        mib(last)
    );
}

#[test]
#[ignore = "an hour: the 10^6-atom LJ soak"]
fn lennard_jones_million_soak() {
    soak("soak-lj.toml", 1_000_188, None);
}

#[test]
#[ignore = "an hour: the 10^6-sphere granular soak"]
fn granular_million_soak() {
    soak("soak-granular.toml", 1_000_000, Some("soak-bed.toml"));
}
