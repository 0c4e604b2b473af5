//! `mote render` and `mote plot` from the command line: pictures are written,
//! frames are numbered, bad input is `file:line: message` with a non-zero exit.
//!
//! NOTE: these tests are `#[ignore]`d until the two subcommands are wired into
//! `main.rs`; then remove the `#[ignore = ...]` lines (or run with `--ignored`).

use std::path::Path;
use std::process::{Command, Output};

fn mote(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(args)
        .output()
        .expect("mote runs")
}

fn write_xyz(path: &Path, frames: usize) {
    let mut s = String::new();
    for f in 0..frames {
        s.push_str("3\n");
        s.push_str(&format!(
            "Lattice=\"4 0 0 0 4 0 0 0 4\" Origin=\"0 0 0\" \
             Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1 Time={f} pbc=\"T T T\"\n"
        ));
        s.push_str("A 1 1 1 1 0 0 0.5\nB 2 2 2 0 2 0 0.7\nA 3 1 2.5 0 0 3 0.4\n");
    }
    std::fs::write(path, s).unwrap();
}

/// Width and height from a PNG's IHDR chunk (bytes 16..24).
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[1..4], b"PNG");
    let be = |k: usize| u32::from_be_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
    (be(16), be(20))
}

#[test]
fn render_writes_a_picture_of_the_asked_size() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("t.xyz");
    write_xyz(&xyz, 2);
    let out = dir.path().join("a.png");
    let o = mote(&[
        "render",
        xyz.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "320x200",
        "--color-by",
        "speed",
        "--shadows",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(png_size(&out), (320, 200));
}

#[test]
fn render_all_numbers_frames_and_writes_pov() {
    let dir = tempfile::tempdir().unwrap();
    let xyz = dir.path().join("t.xyz");
    write_xyz(&xyz, 3);
    let out = dir.path().join("movie.png");
    let pov = dir.path().join("movie.pov");
    let o = mote(&[
        "render",
        xyz.to_str().unwrap(),
        "--all",
        "-o",
        out.to_str().unwrap(),
        "--size",
        "64x48",
        "--anaglyph",
        "--pov",
        pov.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for k in 0..3 {
        assert!(dir.path().join(format!("movie_{k:05}.png")).exists());
        let p = std::fs::read_to_string(dir.path().join(format!("movie_{k:05}.pov"))).unwrap();
        assert_eq!(p.matches("sphere {").count(), 3);
    }
}

#[test]
fn render_reports_bad_input_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.xyz");
    std::fs::write(&bad, "2\ncomment\nA 0 0 0 0 0 0 1\nA 1 x 0 0 0 0 1\n").unwrap();
    let out = dir.path().join("x.png");
    let o = mote(&["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.xyz:4:"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let good = dir.path().join("t.xyz");
    write_xyz(&good, 1);
    for (args, msg) in [
        (vec!["--frame", "5"], "has 1 frames"),
        (
            vec!["--color-by", "charge"],
            "invalid value 'charge' for '--color-by <Q>'",
        ),
        (vec!["--color-by", "spin"], "has no column for it"),
        (vec!["--size", "12"], "WIDTHxHEIGHT"),
        (vec!["--view", "0,0,0"], "non-zero direction"),
    ] {
        let mut a = vec![
            "render",
            good.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend(args);
        let o = mote(&a);
        assert!(!o.status.success(), "{a:?} should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(msg), "{a:?}: {err}");
    }
    let jpg = dir.path().join("x.jpg");
    let o = mote(&[
        "render",
        good.to_str().unwrap(),
        "-o",
        jpg.to_str().unwrap(),
    ]);
    assert!(!o.status.success() && !jpg.exists());
    assert!(String::from_utf8_lossy(&o.stderr).contains("ending in .png"));
    let o = mote(&["render", "--help"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("--anaglyph"));
}

#[test]
fn plot_uses_units_from_the_header() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("e.csv");
    let mut s = String::from("# program=\"mote\" scene=\"t\" seed=1\n# units: s,J,J\n");
    s.push_str("time,kinetic_energy,total_energy\n");
    for k in 1..50 {
        let t = k as f64 * 0.1;
        s.push_str(&format!("{t},{},{}\n", t.sin().powi(2) + 0.1, 2.0));
    }
    std::fs::write(&csv, s).unwrap();
    let svg = dir.path().join("e.svg");
    let o = mote(&[
        "plot",
        csv.to_str().unwrap(),
        "--x",
        "time",
        "--y",
        "kinetic_energy",
        "--y",
        "total_energy",
        "--logy",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("time [s]") && text.contains("total_energy [J]"));
    let o = mote(&["plot", csv.to_str().unwrap(), "--y", "nope", "-o", "x.png"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no column 'nope'"));
}
