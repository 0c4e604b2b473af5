//! A full disk and an unwritable output folder end every engine's run with
//! a message naming the file and the reason, never a panic (issue 23).
//!
//! A full disk is `/dev/full` (every write fails with ENOSPC) behind a
//! symbolic link with an output file's name; an unwritable folder is one
//! under `/sys`, which even root cannot create. The test machines run as
//! root, which ignores read-only permissions, and mounting a small tmpfs
//! needs rights a test suite should not assume.

use std::path::Path;
use std::process::{Command, Output};

fn mote() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mote"))
}

fn have_dev_full() -> bool {
    if Path::new("/dev/full").exists() {
        true
    } else {
        eprintln!("skipped: no /dev/full on this machine");
        false
    }
}

/// A refusal: exit status 1 or 2 (not a panic's 101 or a signal), and the
/// message names `what` and `why`.
fn assert_refused(out: &Output, what: &str, why: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "{:?}: {err}",
        out.status
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains(what) && err.contains(why), "{err}");
}

/// An output folder whose file `name` is the full device.
fn full_folder(name: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/full", dir.path().join(name)).unwrap();
    dir
}

const FULL: &str = "No space left on device";

#[test]
fn a_full_disk_ends_a_time_stepped_run_with_the_file_named() {
    if !have_dev_full() {
        return;
    }
    for file in ["trajectory.xyz", "observables.csv"] {
        let dir = full_folder(file);
        let out = mote()
            .args(["-q", "run", "example:sun-earth", "-o"])
            .arg(dir.path())
            .output()
            .unwrap();
        assert_refused(&out, file, FULL);
    }
    // The same with checkpoints on: the run stops at the first write that
    // fails, and a checkpoint, if one was written, is whole.
    let dir = full_folder("trajectory.xyz");
    let out = mote()
        .args([
            "-q",
            "run",
            "example:sun-earth",
            "--checkpoint-every",
            "10",
            "-o",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_refused(&out, "trajectory.xyz", FULL);
    let cp = dir.path().join("checkpoint.mote");
    if cp.exists() {
        mote_io::checkpoint::read(&cp).unwrap();
    }
}

#[test]
fn a_full_disk_ends_rigid_event_driven_and_packing_runs() {
    if !have_dev_full() {
        return;
    }
    let dir = full_folder("observables.csv");
    let out = mote()
        .args([
            "-q",
            "run",
            "example:magnet-in-field",
            "--steps",
            "50",
            "-o",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_refused(&out, "observables.csv", FULL);
    let dir = full_folder("observables.csv");
    let out = mote()
        .args(["-q", "edmd", "example:cube", "--out-dir"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_refused(&out, "observables.csv", FULL);
    let dir = full_folder("packing.xyz");
    let out = mote()
        .args(["-q", "pack", "--n", "100", "--phi", "0.3", "-o"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_refused(&out, "packing.xyz", FULL);
}

#[test]
fn an_output_folder_that_cannot_be_made_is_named() {
    if !Path::new("/sys/kernel").exists() {
        eprintln!("skipped: no /sys on this machine");
        return;
    }
    let out = mote()
        .args(["-q", "run", "example:sun-earth", "-o", "/sys/mote-out"])
        .output()
        .unwrap();
    assert_refused(&out, "/sys/mote-out", "");
    let out = mote()
        .args(["-q", "edmd", "example:cube", "--out-dir", "/sys/mote-out"])
        .output()
        .unwrap();
    assert_refused(&out, "/sys/mote-out", "");
    let out = mote()
        .args([
            "-q",
            "pack",
            "--n",
            "100",
            "--phi",
            "0.3",
            "-o",
            "/sys/mote-out/p",
        ])
        .output()
        .unwrap();
    assert_refused(&out, "/sys/mote-out", "");
}

/// Output into a closed pipe ends the program by SIGPIPE, as `head` expects
/// of a Unix filter, not with a panic (found piping `mote pack analyse`
/// into `head`).
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = mote()
        .args(["examples"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // the reader goes away at once
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let status = child.wait().unwrap();
    assert!(!err.contains("panicked"), "{err}");
    use std::os::unix::process::ExitStatusExt;
    // Either it wrote everything before the pipe closed, or SIGPIPE ended it.
    assert!(
        status.success() || status.signal() == Some(13),
        "{status:?}: {err}"
    );
}

/// A full stdout or stderr (`> /dev/full`) ends mote with one line saying
/// which stream failed and exit status 1, never a panic; a run still writes
/// all its files first (found with `mote --help > /dev/full`).
#[test]
fn a_full_stdout_or_stderr_ends_with_a_message_and_status_1() {
    if !have_dev_full() {
        return;
    }
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out_arg = out.display().to_string();
    let cases: [&[&str]; 5] = [
        &["--help"],
        &["--version"],
        &["examples"],
        &["run", "--help"],
        &["run", "example:sun-earth", "--steps", "20", "-o", &out_arg],
    ];
    for args in cases {
        let o = mote().args(args).stdout(full()).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            err.contains("mote: cannot write to standard output: No space left on device"),
            "{args:?}: {err}"
        );
    }
    let table = std::fs::read_to_string(out.join("observables.csv")).unwrap();
    // Its header and the rows of steps 0, 10 and 20: the whole table.
    assert_eq!(
        table.lines().filter(|l| !l.starts_with('#')).count(),
        4,
        "{table}"
    );
    // stderr full: the opening line fails; the run completes, status 1.
    let o = mote()
        .args(["run", "example:sun-earth", "--steps", "20", "-o", &out_arg])
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("Ran 20 steps"));
    // A usage error keeps its own status (2), whatever stderr does.
    let o = mote().args(["--bogus"]).stderr(full()).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// A run whose files cannot fit on the disk is refused before it starts
/// (4000 atoms written every step for 9·10⁸ steps: 43 TB at least), and
/// nothing is made.
#[test]
fn a_run_that_cannot_fit_on_the_disk_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "units = \"lj\"\n[run]\ndt = 0.005\nsteps = 900000000\n\
        [lennard_jones]\ncutoff = 2.5\n[[fcc]]\ncells = [10, 10, 10]\ndensity = 0.8\n\
        [output]\ntrajectory_every = 1\n";
    std::fs::write(dir.path().join("big.toml"), scene).unwrap();
    let o = mote()
        .args(["run", "big.toml", "-o", "out"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the run writes at least 43.2 TB into out"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
}
