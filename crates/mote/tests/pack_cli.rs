//! `mote pack` and `mote pack analyse` from the command line: outputs, the
//! summary, and errors for bad input.

use std::process::Command;

fn mote() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mote"))
}

#[test]
fn packs_writes_and_analyses() {
    let dir = tempfile::tempdir().unwrap();
    // The output folder does not exist yet: mote pack makes it.
    let xyz = dir.path().join("out/packing.xyz");
    let out = mote()
        .args([
            "pack",
            "--n",
            "300",
            "--rate",
            "0.3",
            "--seed",
            "2",
            "--max-pressure",
            "1e9",
            "--tol",
            "1e-7",
            "-o",
        ])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("300 spheres: phi = 0.6"), "{text}");
    assert!(text.contains("stopped because the reduced pressure passed"));
    assert!(text.contains("No overlaps"), "{text}");
    assert!(text.contains("rattlers"));
    // the three files, with provenance
    let x = std::fs::read_to_string(&xyz).unwrap();
    assert!(x.starts_with("300\n") && x.contains("radius:R:1") && x.contains("seed=2"));
    let csv = std::fs::read_to_string(dir.path().join("out/packing.csv")).unwrap();
    assert!(csv.starts_with("# program=") && csv.contains("collisions,time,phi,pressure"));
    let last: Vec<f64> = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(last[3] > 1e9, "final pressure {}", last[3]);
    let pov = std::fs::read_to_string(dir.path().join("out/packing.pov")).unwrap();
    assert!(pov.contains("sphere"));
    // analyse reads it back: same φ as the summary printed
    let out = mote()
        .args(["pack", "analyse"])
        .arg(&xyz)
        .arg("--gr")
        .arg(dir.path().join("gr.csv"))
        .arg("--picture")
        .arg(dir.path().join("analysed.png"))
        .output()
        .unwrap();
    let a = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{a}");
    let png = std::fs::read(dir.path().join("analysed.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // read back from the file (exact numbers, periodic box from pbc="T T T"),
    // the contacts at a gap of 1e-7 are those of the packing in memory
    let out = mote()
        .args(["pack", "analyse", "--tol", "1e-7"])
        .arg(&xyz)
        .output()
        .unwrap();
    let tight = String::from_utf8_lossy(&out.stdout);
    let z_summary = text.split("backbone mean contact number ").nth(1).unwrap()[..6].to_string();
    let rattlers = text
        .split("1e-7: ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    assert!(
        tight.contains(&format!("{rattlers} rattlers"))
            && tight.contains(&format!("backbone mean {z_summary}")),
        "{tight}\n{text}"
    );
    let phi_summary = text.split("phi = ").nth(1).unwrap()[..6].to_string();
    assert!(
        a.contains(&format!("packing fraction      {phi_summary}")),
        "{a}\n{text}"
    );
    assert!(a.contains("Q6"));
    let gr = std::fs::read_to_string(dir.path().join("gr.csv")).unwrap();
    assert!(gr.lines().count() > 100);
}

#[test]
fn disks_with_a_picture() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("p.png");
    let out = mote()
        .args([
            "pack",
            "--dim",
            "2",
            "--n",
            "200",
            "--dist",
            "bi:1.4:0.5",
            "--rate",
            "0.3",
            "--max-pressure",
            "1e6",
            "--no-jam",
            "--seed",
            "1",
            "--picture",
        ])
        .arg(&png)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("200 disks"), "{text}");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn bad_input_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let radii = dir.path().join("radii.txt");
    std::fs::write(&radii, "# radii\n0.5\n0.6\nabc\n").unwrap();
    let out = mote()
        .args(["pack", "--dist"])
        .arg(format!("file:{}", radii.display()))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("radii.txt:4: `abc` is not a number"), "{err}");
    assert!(!err.contains("panicked"));
    for args in [
        vec!["pack", "--dist", "gauss:1"],
        vec!["pack", "--rate", "-1"],
        vec!["pack", "--dim", "4"],
        vec!["pack", "--walls", "q"],
        vec!["pack", "--n", "10"],
        vec!["pack", "analyse", "/nonexistent/file.xyz"],
    ] {
        let out = mote().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.trim().is_empty(), "{args:?}");
    }
    let out = mote().args(["pack", "--help"]).output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("--rate"));
}

/// Ctrl-C during a packing stops it at the end of the current window and
/// still writes the packing so far (exit 130), not jammed and saying so.
#[test]
fn sigint_writes_the_packing_so_far() {
    let dir = tempfile::tempdir().unwrap();
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "pack", "--n", "20000", "--rate", "0.0005", "--seed", "3", "-o", "p",
        ])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    // The shell's built-in kill (a fresh Debian has sh, not always procps).
    let sent = std::process::Command::new("sh")
        .args(["-c", &format!("kill -INT {}", child.id())])
        .status()
        .unwrap();
    assert!(sent.success());
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(130), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("interrupted by a signal (not jammed)"),
        "{stdout}"
    );
    let frames = mote_io::xyz::read_frames(&dir.path().join("p/packing.xyz")).unwrap();
    assert_eq!(frames.last().unwrap().positions.len(), 20000);
}

/// A `[packing]` scene under `mote run` is the same run as `mote pack` with
/// the same settings spelled as options: the same packing, bit for bit, in
/// DIR/packing.xyz with its CSV and POV-Ray scene beside it; bad keys are
/// named at their line, and options without meaning for a packing refused.
#[test]
fn a_packing_scene_runs_through_mote_run_as_mote_pack_does() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("p.toml");
    std::fs::write(
        &scene,
        "title = \"test packing\"\nseed = 4\n\n[packing]\nn = 200\ndimension = 2\ndist = \"bi:1.4:0.5\"\nrate = 0.3\nmax_pressure = 1e8\n",
    )
    .unwrap();
    let run = mote()
        .arg("run")
        .arg(&scene)
        .arg("-o")
        .arg(dir.path().join("run"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(text.contains("200 disks: phi = 0.8"), "{text}");
    for f in ["packing.xyz", "packing.csv", "packing.pov"] {
        assert!(dir.path().join("run").join(f).exists(), "{f}");
    }
    let pack = mote()
        .args([
            "pack",
            "--n",
            "200",
            "--dim",
            "2",
            "--dist",
            "bi:1.4:0.5",
            "--rate",
            "0.3",
            "--max-pressure",
            "1e8",
            "--seed",
            "4",
            "-o",
        ])
        .arg(dir.path().join("pack"))
        .output()
        .unwrap();
    assert!(pack.status.success());
    let frame = |sub: &str| {
        let frames = mote_io::xyz::read_frames(&dir.path().join(sub).join("packing.xyz")).unwrap();
        let f = frames.last().unwrap().clone();
        let bits: Vec<u64> = f
            .positions
            .iter()
            .flatten()
            .chain(&f.radii)
            .map(|x| x.to_bits())
            .collect();
        bits
    };
    assert_eq!(frame("run"), frame("pack"), "the two ways in differ");

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[packing]\nn = 100\ndimension = 4\n").unwrap();
    let out = mote().arg("run").arg(&bad).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("bad.toml:3: [packing] dimension = 4: must be 2 or 3"),
        "{err}"
    );
    std::fs::write(&bad, "[packing]\nn = 100\nrat = 1\n").unwrap();
    let out = mote().arg("run").arg(&bad).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml:3: unknown field `rat`"), "{err}");
    let out = mote()
        .arg("run")
        .arg(&scene)
        .args(["--steps", "10"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("option not available for packings: --steps (a packing grows until it jams"),
        "{err}"
    );
}

/// A jammed packing written in each format (`--format`, numbers exact) starts an event-driven run with no overlap: 11 digits in
/// a LAMMPS dump used to leave overlaps of 6e-8, which `mote edmd` refused.
#[test]
fn a_jammed_packing_in_every_format_starts_an_event_driven_run() {
    let dir = tempfile::tempdir().unwrap();
    for (format, ext) in [
        ("xyz", "xyz"),
        ("dump", "dump"),
        ("gsd", "gsd"),
        ("vtk", "pvd"),
    ] {
        let out = mote()
            .args([
                "-q",
                "pack",
                "--n",
                "200",
                "--rate",
                "0.3",
                "--seed",
                "4",
                "--max-pressure",
                "1e10",
                "--format",
                format,
                "-o",
            ])
            .arg(dir.path().join(format!("jammed-{ext}")))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let scene = dir.path().join(format!("from_{ext}.toml"));
        std::fs::write(
            &scene,
            // The initial file as every engine spells it.
            format!(
                "[[from_file]]\nfile = \"jammed-{ext}/packing.{ext}\"\n\n[event_driven]\ntemperature = 1.0\n[run]\nuntil = 0.01\n[output]\ntrajectory = false\nhistogram = false\n"
            ),
        )
        .unwrap();
        let out = mote()
            .args(["-q", "edmd"])
            .arg(&scene)
            .args(["--out-dir"])
            .arg(dir.path().join(format!("run_{ext}")))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{ext}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    // A frame the file lacks, or a file that is missing, is named at the
    // scene's line.
    for (key, name) in [("frame = 7", "jammed-gsd/packing.gsd"), ("", "absent.gsd")] {
        let scene = dir.path().join("bad.toml");
        std::fs::write(
            &scene,
            format!("title = \"bad\"\n[[from_file]]\nfile = \"{name}\"\n{key}\n[event_driven]\ntemperature = 1.0\n"),
        )
        .unwrap();
        let out = mote().args(["-q", "edmd"]).arg(&scene).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains("bad.toml:2: "), "{err}");
        assert!(err.contains(name), "{err}");
    }
}

/// A packing grows from a file's spheres (`--start`, `[packing] start`):
/// the same spheres, the file's box, denser at the end; a missing file is
/// named with the option or the scene line.
#[test]
fn a_packing_grows_from_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let dilute = dir.path().join("dilute/packing.gsd");
    let out = mote()
        .args([
            "-q",
            "--seed",
            "2",
            "pack",
            "--n",
            "200",
            "--dist",
            "lognormal:0.1",
            "--phi",
            "0.3",
            "--format",
            "gsd",
            "-o",
        ])
        .arg(dir.path().join("dilute"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first = mote_io::trajectory::read_frames(&dilute)
        .unwrap()
        .pop()
        .unwrap();
    let denser = dir.path().join("denser/packing.xyz");
    let out = mote()
        .args(["-q", "pack", "--start"])
        .arg(&dilute)
        .args(["--phi", "0.5", "-o"])
        .arg(dir.path().join("denser"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let last = mote_io::trajectory::read_frames(&denser)
        .unwrap()
        .pop()
        .unwrap();
    assert_eq!(last.positions.len(), 200);
    assert_eq!(last.cell, first.cell);
    // Every radius grew by the same factor: the size distribution is kept.
    let g = last.radii[0] / first.radii[0];
    assert!(g > 1.1, "{g}");
    for (a, b) in last.radii.iter().zip(&first.radii) {
        assert!((a / b - g).abs() < 1e-9 * g, "{a} {b} {g}");
    }
    let volume: f64 = last
        .radii
        .iter()
        .map(|r| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
        .sum();
    let phi = volume / (last.cell[0][0] * last.cell[1][1] * last.cell[2][2]);
    assert!((phi - 0.5).abs() < 1e-9, "{phi}");
    // The scene key, relative to the scene file.
    let scene = dir.path().join("grow.toml");
    std::fs::write(
        &scene,
        "[packing]\nstart = \"dilute/packing.gsd\"\nphi = 0.4\n",
    )
    .unwrap();
    let out = mote()
        .args(["-q", "run"])
        .arg(&scene)
        .arg("-o")
        .arg(dir.path().join("grown"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::write(&scene, "[packing]\nphi = 0.4\nstart = \"absent.xyz\"\n").unwrap();
    let out = mote().args(["-q", "run"]).arg(&scene).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("grow.toml:3: [packing] start = \"absent.xyz\""),
        "{err}"
    );
    let out = mote()
        .args(["-q", "pack", "--start", "absent.xyz"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("--start absent.xyz"),
        "{err}"
    );
}

/// `--method soft` (the SP method): the barostat's stages, the jamming
/// finish and both extrapolations in the summary, the packing and its CSV
/// written, the same run as a `[packing]` scene; what it cannot do is
/// refused with the rule.
#[test]
fn the_soft_method_packs_and_says_what_it_found() {
    let dir = tempfile::tempdir().unwrap();
    // A name with dots: the folder is soft.n400, not soft.
    let xyz = dir.path().join("soft.n400/packing.xyz");
    let out = mote()
        .args(["--seed", "4", "pack", "--method", "soft", "-n", "400", "-o"])
        .arg(dir.path().join("soft.n400"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for needle in [
        "400 spheres by the soft (SP) method",
        "Barostat extrapolated to zero pressure",
        "Jamming finish",
        "Finish extrapolated to zero pressure: phi_J = 0.6",
        "(isostatic 6)",
    ] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    let frames = mote_io::trajectory::read_frames(&xyz).unwrap();
    assert_eq!(frames[0].radii.len(), 400);
    let csv = std::fs::read_to_string(dir.path().join("soft.n400/packing.csv")).unwrap();
    assert!(dir.path().join("soft.n400/packing.pov").exists());
    assert!(csv.contains("steps,phi,pressure,minimised"), "{csv}");
    // one row per stage, steps counted to that stage: rising, and the last
    // row's count is the summary's total
    let steps: Vec<u64> = csv
        .lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| l.split(',').next().unwrap().parse::<f64>().unwrap() as u64)
        .collect();
    assert!(
        steps.len() > 3 && steps.windows(2).all(|w| w[0] < w[1]),
        "{csv}"
    );
    let total = format!("method: {} steps in", steps.last().unwrap());
    assert!(text.contains(&total), "{total}: {text}");
    // The same packing from a scene under `mote run`.
    std::fs::write(
        dir.path().join("soft.toml"),
        "seed = 4\n[packing]\nmethod = \"soft\"\nn = 400\n",
    )
    .unwrap();
    let run = mote()
        .arg("run")
        .arg(dir.path().join("soft.toml"))
        .arg("-o")
        .arg(dir.path().join("run"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let again = mote_io::trajectory::read_frames(&dir.path().join("run/packing.xyz")).unwrap();
    assert_eq!(again[0].positions, frames[0].positions);
    for (args, why) in [
        (
            &["--method", "squishy"][..],
            "invalid value 'squishy' for '--method <METHOD>'",
        ),
        (
            &["--method", "soft", "--dim", "2"][..],
            "packs spheres (dimension 3)",
        ),
        (
            &["--method", "soft", "--walls", "z"][..],
            "periodic box (no walls)",
        ),
        (
            &["--method", "soft", "--min-pressure", "0"][..],
            "must lie in [1e-12, 1e-2]",
        ),
    ] {
        let out = mote().arg("pack").args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(why),
            "{args:?}: {err}"
        );
    }
    std::fs::write(
        dir.path().join("bad.toml"),
        "[packing]\nmethod = \"soft\"\nn = 400\nwalls = \"x\"\n",
    )
    .unwrap();
    let out = mote()
        .arg("run")
        .arg(dir.path().join("bad.toml"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml:4: [packing] walls = \"x\""), "{err}");
}

/// Degenerate packings: spheres of no size are refused at once (they made
/// `analyse` build 2³⁰ cells and grow memory at 1 GB/s); a box of 1e300
/// around real spheres is analysed in a moment (at most four cells a
/// sphere).
#[test]
fn analyse_refuses_spheres_of_no_size_and_survives_a_huge_box() {
    let dir = tempfile::tempdir().unwrap();
    let frame = |side: &str, radius: &str| {
        let mut s = format!(
            "1000\nLattice=\"{side} 0 0 0 {side} 0 0 0 {side}\" Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T T\"\n"
        );
        for k in 0..1000 {
            s += &format!("A {} {} {} {radius}\n", k % 10, (k / 10) % 10, k / 100);
        }
        s
    };
    for (name, side, radius) in [("zero.xyz", "10", "0"), ("huge.xyz", "1e300", "0.5")] {
        std::fs::write(dir.path().join(name), frame(side, radius)).unwrap();
    }
    let start = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["pack", "analyse", "zero.xyz"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("sphere 0 has radius 0"), "{err}");
    let o = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["pack", "analyse", "huge.xyz"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("packing fraction      0.000000"));
    assert!(start.elapsed().as_secs_f64() < 20.0);
}

/// `-o` names the packing's folder as `mote run -o` names a run's: a
/// packing file named as before is refused with the new spelling, a format
/// mote does not write or a picture that is not PNG before anything is
/// packed (`-o x.pdf` wrote extended XYZ under that name).
#[test]
fn packing_folders_and_formats_are_refused_before_anything_is_packed() {
    let dir = tempfile::tempdir().unwrap();
    for (args, why) in [
        (
            ["-o", "x.xyz"],
            "-o x.xyz: -o names the packing's folder, as `mote run -o` names a run's; \
             the packing goes to DIR/packing.xyz: give -o x",
        ),
        (
            ["-o", "p.gsd"],
            "the packing goes to DIR/packing.gsd: give -o p --format gsd",
        ),
        (
            ["--format", "pdf"],
            "invalid value 'pdf' for '--format <FORMAT>'",
        ),
        (["--picture", "x.jpg"], "pictures are written as PNG"),
    ] {
        let o = mote()
            .args(["pack", "--n", "50", "--max-pressure", "1e3"])
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert_ne!(o.status.code(), Some(0), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(why) && !err.contains("mote pack: "), "{err}");
        assert!(!dir.path().join(args[1]).exists());
    }
    let o = mote()
        .args([
            "run",
            "example:sun-earth",
            "--steps",
            "2",
            "--picture",
            "x.pdf",
            "-o",
            "o",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(!dir.path().join("o").exists(), "refused before the run");
}
