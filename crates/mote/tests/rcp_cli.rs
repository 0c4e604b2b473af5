//! `mote rcp` as a drop-in for spherepack1d: published outputs (seed 003 help text and
//! shared/seeds/README.md), the help examples, and every documented input error with
//! its message and non-zero exit status.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn mote(args: &[&str], stdin: impl AsRef<[u8]>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .arg("rcp")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("mote runs");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(stdin.as_ref())
        .expect("write stdin");
    child.wait_with_output().expect("mote finishes")
}

fn ok(args: &[&str], stdin: &str) -> String {
    let out = mote(args, stdin);
    assert!(
        out.status.success(),
        "mote rcp {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

fn fails(args: &[&str], stdin: impl AsRef<[u8]>, message: &str) {
    let out = mote(args, stdin);
    assert_eq!(
        out.status.code(),
        Some(255),
        "mote rcp {args:?} should fail"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(message),
        "stderr of {args:?} was {err:?}, expected {message:?}"
    );
    assert!(out.stdout.is_empty() || !String::from_utf8_lossy(&out.stdout).contains('.'));
}

#[test]
fn published_lognormal_value() {
    assert_eq!(ok(&["-l", "--compat"], "2.0 0.5\n"), "0.829998\n");
    // default (accurate erfc) differs in the fifth decimal at sigma = 1.18
    assert_eq!(ok(&["-l"], "2.0 0.5\n"), "0.830022\n");
}

#[test]
fn published_monodisperse_value() {
    assert_eq!(ok(&["--compat"], ""), "0.643485\n");
    assert_eq!(ok(&[], ""), "0.643485\n");
    assert_eq!(ok(&["-s"], ""), "0.643500\n");
}

#[test]
fn help_examples_run() {
    let help = ok(&["-h"], "");
    assert!(help.contains("EXAMPLES") && help.contains("--compat"));
    assert_eq!(
        ok(&["-l", "-p", "2", "--compat"], "5.0 4.0 1.0\n3.0 2.0 1.0\n"),
        "0.741914\n"
    );
    let tri = ok(&["-d", "-p", "3"], "2.0 1.5\n3.0 2.5\n4.0 3.5\n");
    assert_eq!(tri, "0.670194\n");
    assert_eq!(ok(&["-di"], "3\n2.0 1.5\n3.0 2.5\n4.0 3.5\n"), tri);
    assert_eq!(ok(&["-p3"], "2.0 1.5\n3.0 2.5\n4.0 3.5\n"), tri);
    assert_eq!(ok(&["--help"], ""), help);
}

#[test]
fn options_like_getopt() {
    // -u: full lines also for p = 1; -w: sigma input; -s: analytic fit (003, Eq. 27).
    assert_eq!(ok(&["-lu", "--compat"], "2.0 0.5 1.0\n"), "0.829998\n");
    let sigma = (4.0f64).ln().sqrt().to_string();
    assert_eq!(ok(&["-w", "--compat"], &sigma), "0.829998\n");
    assert_eq!(ok(&["-ls", "--compat"], "2.0 0.5\n"), "0.830095\n");
    assert_eq!(ok(&["-w", "-s"], "0\n"), "0.643500\n");
    // -f 0: rods touch, φ = 1; -N attached and separate.
    assert_eq!(ok(&["-f", "0"], ""), "1.000000\n");
    assert_eq!(ok(&["-N2000"], ""), ok(&["-N", "2000"], ""));
    // -V and -v
    assert!(ok(&["-V"], "").contains("spherepack1d"));
    let v = ok(&["-v", "-l"], "2.0 0.5\n");
    assert!(v.starts_with(">>> Verbose mode <<<"));
    assert!(v.ends_with("Predicted maximum packing fraction:\n0.830022\n"));
}

#[test]
fn duplicate_diameters_are_merged() {
    let merged = ok(&["-p", "2"], "1.0 1.0\n2.0 1.0\n");
    assert_eq!(ok(&["-p", "3"], "1.0 0.5\n2.0 1.0\n1.0 0.5\n"), merged);
}

#[test]
fn no_fixed_maximum_for_n_and_p() {
    // spherepack1d stops at N = 100000 and p = 10000.
    assert_eq!(ok(&["-N", "200000"], ""), "0.643485\n");
    let mut data = String::new();
    for k in 0..10_001 {
        data.push_str(&format!("{} 1\n", 1.0 + k as f64 * 1e-3));
    }
    let phi: f64 = ok(&["-p", "10001", "-N", "4000"], &data)
        .trim()
        .parse()
        .unwrap();
    assert!(phi > 0.6435 && phi < 0.85, "{phi}");
}

#[test]
fn errors_on_options() {
    fails(
        &["-N", "1"],
        "",
        "Error: Number of rods needs to be at least 2.",
    );
    fails(&["-N", "abc"], "", "Error: -N needs an integer, got 'abc'.");
    fails(&["-N"], "", "Error: -N without integer.");
    fails(
        &["-p", "0"],
        "",
        "Error: Number of sphere populations needs to be at least 1.",
    );
    fails(
        &["-f", "-1"],
        "",
        "Error: the -f value needs to be non-negative",
    );
    fails(&["-x"], "", "Error: unknown option -x");
    fails(&["--frobnicate"], "", "Error: unknown option --frobnicate");
    fails(&["data.txt"], "", "Error: unexpected argument 'data.txt'");
    fails(
        &["-i", "-p", "2"],
        "",
        "Error: -i option has been chosen, which is not compatible",
    );
    fails(
        &["-s", "-p", "2"],
        "",
        "Error: -s option requires a single population.",
    );
    fails(
        &["-s", "-i"],
        "",
        "Error: -s option is not compatible with -i option",
    );
    fails(
        &["-s", "-u"],
        "",
        "Error: -s option is not compatible with -u option",
    );
}

#[test]
fn errors_on_input() {
    fails(&["-l"], "0.5 2.0\n", "Error: must have d43 >= d32 > 0.");
    fails(&["-l"], "-1 -2\n", "Error: must have d43 >= d32 > 0.");
    fails(
        &["-l", "-p", "2"],
        "2 1 1\n1 2 1\n",
        "Error: need 0 < d32 <= d43.",
    );
    fails(
        &["-l", "-p", "2"],
        "2 1 1\n2 1 -1\n",
        "Error: need non-negative values for the volume.",
    );
    fails(
        &["-l", "-p", "2"],
        "2 1 0\n3 1 0\n",
        "Error: One of the volumes must be greater than zero.",
    );
    fails(&["-w"], "-0.5\n", "Error: must have sigma >= 0.");
    fails(
        &["-w", "-p", "2"],
        "1 -1 1\n1 1 1\n",
        "Error: need sigma >= 0 and d43 > 0.",
    );
    fails(
        &["-w", "-p", "2"],
        "0 1 1\n1 1 1\n",
        "Error: need sigma >= 0 and d43 > 0.",
    );
    fails(
        &["-p", "2"],
        "0 1\n1 1\n",
        "Error: need strictly positive values for the diameter.",
    );
    fails(
        &["-p", "2"],
        "1 1\n2 -1\n",
        "Error: need non-negative values for the volume.",
    );
    fails(
        &["-p", "2"],
        "1 0\n2 0\n",
        "Error: One of the volumes must be greater than zero.",
    );
    fails(
        &["-p", "2"],
        "1 1\n",
        "Error: the input ended early: expected the diameter of population 2.",
    );
    fails(
        &["-p", "2"],
        "1 1\n2 x\n",
        "Error: standard input:2: 'x' is not a number (expected the volume of population 2).",
    );
    fails(
        &["-l"],
        "nan 1\n",
        "Error: standard input:1: d43 must be a finite number, got 'nan'.",
    );
    fails(
        &["-i"],
        "two\n",
        "Error: standard input:1: expected the number of populations as the first item of the input, found 'two'.",
    );
    // Bytes that are not UTF-8 are an item that is not a number (it was
    // an I/O error with exit status 1: found by fuzzing).
    fails(
        &["-p", "2"],
        b"1 1\n\n2 \xff\n",
        "Error: standard input:3: '\u{fffd}' is not a number (expected the volume of population 2).",
    );
    fails(
        &["-i"],
        "0\n",
        "Error: Number of sphere populations needs to be at least 1.",
    );
    fails(
        &["-i"],
        "",
        "Error: the input ended early: expected the number of populations.",
    );
}

#[test]
fn optimize_and_scan() {
    // Bidisperse 1:10 at N = 1000: the best mixture has most of the volume in the big spheres.
    let out = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "-q",
            "rcp",
            "optimize",
            "-N",
            "1000",
            "--max-evals",
            "120",
            "--file",
        ])
        .arg(write_tmp("bi.txt", "1 1\n10 1\n"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let phi: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("phi = "))
        .unwrap()
        .parse()
        .unwrap();
    assert!(phi > 0.78 && phi < 0.9, "{text}");
    assert!(text.contains("evaluations = "));

    let dir = std::env::temp_dir().join(format!("mote-rcp-scan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("s.csv");
    let png = dir.join("s.png");
    let out = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "-q",
            "rcp",
            "scan",
            "-w",
            "-N",
            "500",
            "--x",
            "vol2=0:1:4",
            "--y",
            "sigma1=0:1:3",
            "--file",
        ])
        .arg(write_tmp("two.txt", "1 0.1 1\n5 0.1 1\n"))
        .arg("--csv")
        .arg(&csv)
        .arg("--png")
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(table.lines().next(), Some("vol2,sigma1,phi"));
    assert_eq!(table.lines().count(), 1 + 12);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // a bad axis is an error with a message
    let out = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "rcp",
            "scan",
            "--x",
            "foo=1:2:3",
            "--y",
            "d1=1:2:2",
            "--csv",
        ])
        .arg(dir.join("bad.csv"))
        .arg("--file")
        .arg(write_tmp("one.txt", "1 1\n"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown parameter 'foo'"));
}

fn write_tmp(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("mote-rcp-in-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
