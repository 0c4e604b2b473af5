//! `mote edmd` end to end: examples run and report physics, outputs carry
//! provenance, scene errors are `file:line: message` with a non-zero exit.

use std::process::Command;

fn mote() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mote"))
}

#[test]
fn help_lists_the_examples() {
    let out = mote().args(["edmd", "--help"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("example:NAME") && text.contains("maxwell2d"),
        "{text}"
    );
    let out = mote().args(["edmd", "--list"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["cube", "cradle", "maxwell2d"] {
        assert!(text.contains(&format!("example:{name}")), "{text}");
    }
}

#[test]
fn cradle_passes_the_ball_through() {
    let out = mote()
        .args(["edmd", "example:cradle", "--no-output", "--time", "5"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("final x-velocities: +0.000000000000 +0.000000000000 +0.000000000000 +0.000000000000 +1.000000000000"),
        "{text}"
    );
    assert!(text.contains("4 pair collisions"), "{text}");
}

#[test]
fn maxwell2d_writes_trajectory_csv_and_histogram_with_the_seed() {
    let dir = tempfile::tempdir().unwrap();
    let out = mote()
        .args([
            "edmd",
            "example:maxwell2d",
            "--seed",
            "99",
            "--time",
            "10",
            "--out-dir",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("seed 99"), "{text}");
    // the summary's KS p-value: Maxwell–Boltzmann is not rejected at 1 %
    let p: f64 = text
        .split("p = ")
        .nth(1)
        .and_then(|s| {
            s.trim_end_matches(|c: char| !c.is_ascii_digit())
                .split_whitespace()
                .next()
        })
        .map(|s| s.trim_end_matches('.').parse().unwrap())
        .unwrap();
    assert!(p > 0.01, "{text}");
    let frames = mote_io::xyz::read_frames(&dir.path().join("trajectory.xyz")).unwrap();
    assert_eq!(frames.len(), 101);
    assert_eq!(frames[0].positions.len(), 250);
    assert!(frames
        .iter()
        .all(|f| f.positions.iter().all(|p| p[2] == 0.0)));
    let xyz = std::fs::read_to_string(dir.path().join("trajectory.xyz")).unwrap();
    assert!(xyz.lines().nth(1).unwrap().contains("seed=99"));
    let table = mote_io::csv::read_table(&dir.path().join("observables.csv")).unwrap();
    let e = table.column("kinetic_energy").unwrap();
    assert!(
        e.iter().all(|x| (x - 125.0).abs() < 1e-10),
        "energy 250·½·1² conserved"
    );
    let csv = std::fs::read_to_string(dir.path().join("observables.csv")).unwrap();
    assert!(csv.starts_with("# ") && csv.lines().next().unwrap().contains("seed=99"));
    let hist = mote_io::csv::read_table(&dir.path().join("speeds.csv")).unwrap();
    let dens = hist.column("density").unwrap();
    let dv = hist.column("v").unwrap()[1] - hist.column("v").unwrap()[0];
    let total: f64 = dens.iter().sum::<f64>() * dv;
    assert!((total - 1.0).abs() < 0.01, "histogram normalised: {total}");
}

#[test]
fn same_seed_same_result() {
    let run = || {
        let out = mote()
            .args([
                "edmd",
                "example:cube",
                "--no-output",
                "--time",
                "0.2",
                "--seed",
                "5",
            ])
            .output()
            .unwrap();
        assert!(out.status.success());
        let t = String::from_utf8_lossy(&out.stdout).to_string();
        // drop the timing part
        t.split(" in ").next().unwrap().to_string() + t.split("Wall pressure").nth(1).unwrap_or("")
    };
    assert_eq!(run(), run());
}

#[test]
fn scene_file_runs_and_errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("eos.toml");
    std::fs::write(
        &good,
        "# small hard-sphere fluid\nseed = 3\n[event_driven]\ndimension = 3\nn = 500\npacking_fraction = 0.2\n[run]\nequilibrate = 2.0\nuntil = 6.0\n",
    )
    .unwrap();
    let out = mote().arg("edmd").arg(&good).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Compressibility factor Z"), "{text}");
    assert!(dir.path().join("observables.csv").exists(), "{text}");

    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[event_driven]\ndimension = 3\nn = 500\npacking_fraction = 0.2\n[run]\nuntil = \"long\"\n",
    )
    .unwrap();
    let out = mote().arg("edmd").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("{}:6: ", bad.display())), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    // The first format's top-level keys are refused at their line with
    // the spelling that replaced them.
    let old = dir.path().join("old.toml");
    std::fs::write(
        &old,
        "dimension = 3\nn = 500\npacking_fraction = 0.2\ntime = 4.0\n",
    )
    .unwrap();
    let out = mote().arg("edmd").arg(&old).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!(
            "{}:1: `dimension` says what the hard spheres are: it goes in [event_driven]",
            old.display()
        )),
        "{err}"
    );

    let out = mote().args(["edmd", "example:nope"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown example"));

    let out = mote().args(["edmd", "--bogus"]).output().unwrap();
    assert!(!out.status.success());
}
