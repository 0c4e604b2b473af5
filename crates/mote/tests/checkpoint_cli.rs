//! Checkpoints: a run killed with SIGKILL and resumed from its last
//! checkpoint ends in the same state, bit for bit, as an uninterrupted run
//! (thermostat noise and leap-frog's carried accelerations of a
//! velocity-dependent force included).

use std::path::Path;

use mote_io::checkpoint::Checkpoint;
use std::process::Command;
use std::time::{Duration, Instant};

const SCENE: &str = r#"
title = "LJ liquid with a Bussi thermostat (checkpoint test)"
units = "lj"
seed = 3
[run]
integrator = "leapfrog"
dt = 0.005
steps = 3000
[lennard_jones]
cutoff = 2.5
[[fcc]]
cells = [4, 4, 4]
density = 0.8
kt = 1.5
[thermostat]
kind = "bussi"
kt = 1.0
tau = 0.2
[damping]
gamma = 0.01
[output]
observables_every = 100
trajectory_every = 500
"#;

fn mote(args: &[&str], dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Waits (up to two minutes) until a running job's checkpoint has reached `step`.
fn wait_for_checkpoint(path: &Path, step: u64) {
    let start = Instant::now();
    while !mote_io::checkpoint::read(path).is_ok_and(|cp| cp.step >= step) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no checkpoint of step {step} appeared"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// A run (`args` plus `-o whole`) to its end, the same run (`-o cut`)
/// killed with SIGKILL once its checkpoint reached `kill_from`, then
/// resumed: returns the whole run's last checkpoint, the killed run's
/// checkpoint at the kill, and the resumed run's last checkpoint.
fn whole_killed_resumed(
    dir: &Path,
    args: &[&str],
    kill_from: u64,
) -> (Checkpoint, Checkpoint, Checkpoint) {
    let with_out = |out: &'static str| {
        let mut v: Vec<&str> = args.to_vec();
        v.extend(["-q", "-o", out]);
        v
    };
    let o = mote(&with_out("whole"), dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = mote_io::checkpoint::read(&dir.join("whole/checkpoint.mote")).unwrap();

    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(with_out("cut"))
        .current_dir(dir)
        .spawn()
        .unwrap();
    let cp_path = dir.join("cut/checkpoint.mote");
    wait_for_checkpoint(&cp_path, kill_from);
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let at_kill = mote_io::checkpoint::read(&cp_path).unwrap();
    assert!(
        at_kill.step < whole.step,
        "finished before it could be killed"
    );

    let o = mote(
        &[
            "run",
            "--resume",
            "cut/checkpoint.mote",
            "--threads",
            "1",
            "-q",
        ],
        dir,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed = mote_io::checkpoint::read(&cp_path).unwrap();
    (whole, at_kill, resumed)
}

/// Whether `file` is byte for byte the same in the whole and the resumed run.
fn same_file(dir: &Path, file: &str) -> bool {
    std::fs::read(dir.join("whole").join(file)).unwrap()
        == std::fs::read(dir.join("cut").join(file)).unwrap()
}

fn state(path: &Path) -> (u64, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let cp = mote_io::checkpoint::read(path).unwrap();
    (cp.step, cp.positions, cp.velocities)
}

#[test]
fn killed_run_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lj.toml"), SCENE).unwrap();
    let o = mote(
        &[
            "run",
            "lj.toml",
            "--threads",
            "1",
            "-q",
            "-o",
            "whole",
            "--checkpoint-every",
            "200",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = state(&dir.path().join("whole/checkpoint.mote"));
    assert_eq!(whole.0, 3000);

    // The same run, killed once a checkpoint past the start exists.
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "run",
            "lj.toml",
            "--threads",
            "1",
            "-q",
            "-o",
            "cut",
            "--checkpoint-every",
            "200",
        ])
        .current_dir(dir.path())
        .spawn()
        .unwrap();
    let cp_path = dir.path().join("cut/checkpoint.mote");
    wait_for_checkpoint(&cp_path, 400);
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let at_kill = state(&cp_path).0;
    assert!(
        at_kill < 3000,
        "the run finished before it could be killed (step {at_kill})"
    );

    let o = mote(
        &[
            "run",
            "--resume",
            "cut/checkpoint.mote",
            "--threads",
            "1",
            "-q",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed = state(&cp_path);
    assert_eq!(resumed.0, 3000);
    let bits = |v: &Vec<[f64; 3]>| {
        v.iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect::<Vec<u64>>()
    };
    assert_eq!(
        bits(&resumed.1),
        bits(&whole.1),
        "positions differ (killed at step {at_kill})"
    );
    assert_eq!(bits(&resumed.2), bits(&whole.2), "velocities differ");
    // The observables continue without a repeated or missing row.
    let t = mote_io::csv::read_table(&dir.path().join("cut/observables.csv")).unwrap();
    let steps = t.column("step").unwrap();
    assert!(steps.windows(2).all(|w| w[1] > w[0]), "{steps:?}");
    assert_eq!(*steps.last().unwrap(), 3000.0);
    // The thermostat of the scene acted: the liquid started at kT = 1.5.
    let kt = t.column("kT").unwrap();
    let late: f64 = kt[kt.len() - 10..].iter().sum::<f64>() / 10.0;
    assert!((late - 1.0).abs() < 0.1, "kT at the end {late}");
}

const GRANULAR: &str = r#"
title = "spheres falling into a box (checkpoint test: contact histories and spins)"
units = "si"
seed = 5
[run]
integrator = "leapfrog"
dt = 5e-5
steps = 4000
[field]
g = [0.0, 0.0, -9.81]
[granular]
young = 1e6
poisson = 0.3
restitution = 0.5
friction = 0.5
rolling_friction = 0.02
[[wall]]
kind = "box"
lo = [0.0, 0.0, 0.0]
hi = [0.03, 0.03, 0.05]
[[cloud]]
n = 400
min = [0.0, 0.0, 0.0]
max = [0.03, 0.03, 0.05]
radius = 0.0015
spread = 0.2
density = 2500.0
[output]
observables_every = 100
trajectory_every = 0
"#;

/// The carried states as bits (NaN, the unused first slot, equals itself).
fn carried_bits(carried: &[(String, Vec<f64>)]) -> Vec<(String, Vec<u64>)> {
    carried
        .iter()
        .map(|(k, v)| (k.clone(), v.iter().map(|x| x.to_bits()).collect()))
        .collect()
}

/// A granular run killed mid-way resumes bit for bit: the checkpoint holds
/// the angular velocities and the contact histories of pairs and walls.
#[test]
fn killed_granular_run_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("g.toml"), GRANULAR).unwrap();
    let args = [
        "run",
        "g.toml",
        "--threads",
        "1",
        "--checkpoint-every",
        "100",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 1500);
    assert_eq!(whole.step, 4000);
    assert!(!whole.angular.is_empty() && !whole.carried.is_empty());
    assert!(
        at_kill.carried.iter().any(|(_, v)| v.len() > 1),
        "no contact history at the kill"
    );
    // Histories are kept under their interaction's name, not its position.
    let names: Vec<&str> = whole.carried.iter().map(|(k, _)| k.as_str()).collect();
    assert!(names.contains(&"granular"), "{names:?}");
    assert_eq!(resumed.step, 4000);
    let bits = |v: &[[f64; 3]]| {
        v.iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect::<Vec<u64>>()
    };
    assert_eq!(
        bits(&resumed.positions),
        bits(&whole.positions),
        "positions differ (killed at {})",
        at_kill.step
    );
    assert_eq!(
        bits(&resumed.velocities),
        bits(&whole.velocities),
        "velocities differ"
    );
    assert_eq!(resumed.angular, whole.angular, "spins differ");
    assert_eq!(
        carried_bits(&resumed.carried),
        carried_bits(&whole.carried),
        "contact histories differ"
    );
}

/// Grains poured into a bin at 4000 a second and drained through half its
/// floor (`[[insert]]`, `[[outlet]]`): particles come and go between
/// checkpoints.
const POURED: &str = r#"
title = "a stream into a drained bin (checkpoint test: particles come and go)"
seed = 5
[run]
integrator = "leapfrog"
dt = 2e-5
steps = 6000
[field]
g = [0.0, 0.0, -9.81]
[granular]
young = 5e6
poisson = 0.3
restitution = 0.5
friction = 0.5
[[wall]]
kind = "box"
name = "bin"
lo = [0.0, 0.0, 0.0]
hi = [0.03, 0.03, 0.06]
[[insert]]
name = "feed"
lo = [0.001, 0.001, 0.03]
hi = [0.029, 0.029, 0.055]
rate = 4000.0
radius = 0.0008
sizes = "lognormal:0.15"
density = 2500.0
velocity = [0.0, 0.0, -0.5]
velocity_spread = 0.05
species = "Si"
every = 50
[[outlet]]
name = "drain"
hi = [0.015, 1.0, 0.003]
every = 50
[output]
observables_every = 100
trajectory_every = 500
"#;

/// A run whose particles come and go, killed mid-way, resumes bit for
/// bit: the checkpoint names the particles by id with the inserter and
/// size of each inserted one, and the counts in and out; the resumed
/// run's observables, outflow table and trajectory are byte for byte
/// those of the uninterrupted run.
#[test]
fn a_killed_run_with_inflow_and_outflow_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.toml"), POURED).unwrap();
    let args = [
        "run",
        "p.toml",
        "--threads",
        "1",
        "--checkpoint-every",
        "100",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 3000);
    assert_eq!(whole.step, 6000);
    assert!(
        at_kill.positions.len() > 100 && at_kill.positions.len() != whole.positions.len(),
        "{} particles at the kill, {} at the end",
        at_kill.positions.len(),
        whole.positions.len()
    );
    assert_eq!(resumed.step, 6000);
    a_flow_resumed_as_it_ran(dir.path(), &whole, &at_kill, &resumed, 50);
}

/// A resumed run with inserters and outlets ended where the
/// uninterrupted one did: state, carried state (the flow's ledger among
/// them) and files, byte for byte; more than `left` rows of outflow.csv.
fn a_flow_resumed_as_it_ran(
    dir: &Path,
    whole: &Checkpoint,
    at_kill: &Checkpoint,
    resumed: &Checkpoint,
    left: usize,
) {
    assert_eq!(
        resumed.positions, whole.positions,
        "positions differ (killed at {})",
        at_kill.step
    );
    assert_eq!(resumed.velocities, whole.velocities, "velocities differ");
    assert_eq!(resumed.angular, whole.angular, "spins or placements differ");
    assert_eq!(
        carried_bits(&resumed.carried),
        carried_bits(&whole.carried),
        "carried states differ"
    );
    let outflow = std::fs::read_to_string(dir.join("whole/outflow.csv")).unwrap();
    assert!(
        outflow.lines().filter(|l| !l.starts_with('#')).count() > left,
        "too few left"
    );
    // The charge column's unit is the unit system's (C in SI, the reduced
    // charge in LJ units), not a word.
    let units = outflow.lines().find(|l| l.starts_with("# units:")).unwrap();
    let charge = units.split(',').nth(5).unwrap();
    assert!(charge == "C" || charge.starts_with("(4*pi*eps0"), "{units}");
    for file in ["observables.csv", "outflow.csv", "trajectory.xyz"] {
        assert!(
            same_file(dir, file),
            "{file} differs after the resume (killed at {})",
            at_kill.step
        );
    }
}

const RIGID: &str = r#"
title = "clumps falling into a pile (checkpoint test: rigid bodies, contact histories)"
seed = 11
[rigid]
[[rigid.template]]
name = "bead"
generator = "irregular"
radius = 1.0e-3
lobes = 9
seed = 1
density = 2500.0
[[rigid.template]]
name = "ball"
generator = "sphere"
radius = 0.8e-3
density = 2500.0
[[rigid.random]]
template = "bead"
n = 24
lo = [1.2e-3, 1.2e-3, 1.2e-3]
hi = [8.8e-3, 8.8e-3, 8.8e-3]
speed = 0.3
[[rigid.random]]
template = "ball"
n = 12
lo = [1.2e-3, 1.2e-3, 1.2e-3]
hi = [8.8e-3, 8.8e-3, 8.8e-3]
speed = 0.3
[rigid.fields]
gravity = [0.0, 0.0, -200.0]
[rigid.contacts]
young = 1.0e7
poisson = 0.3
restitution = 0.2
friction = 0.5
rolling_friction = 0.01
[[rigid.wall]]
kind = "box"
name = "box"
lo = [0.0, 0.0, 0.0]
hi = [10e-3, 10e-3, 10e-3]
[run]
dt = 5.0e-6
steps = 20000
[output]
observables_every = 50
trajectory_every = 1000
"#;

/// A rigid run killed mid-way resumes bit for bit: the checkpoint holds the
/// bodies' placements (rotation vectors), velocities and spins, and the
/// contact histories between spheres of different bodies and with the
/// walls; the resumed run's observables and trajectory are byte for byte
/// those of an uninterrupted run.
#[test]
fn killed_rigid_run_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("r.toml"), RIGID).unwrap();
    let args = [
        "run",
        "r.toml",
        "--threads",
        "1",
        "--checkpoint-every",
        "100",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 6000);
    assert_eq!(whole.step, 20000);
    assert_eq!(whole.option("engine"), Some("rigid"));
    assert_eq!(whole.positions.len(), 36);
    assert!(
        at_kill.carried.iter().any(|(_, v)| v.len() > 2),
        "no contact history at the kill"
    );
    assert_eq!(resumed.step, 20000);
    assert_eq!(
        resumed.positions, whole.positions,
        "positions differ (killed at {})",
        at_kill.step
    );
    assert_eq!(resumed.velocities, whole.velocities, "velocities differ");
    assert_eq!(resumed.angular, whole.angular, "placements or spins differ");
    assert_eq!(
        carried_bits(&resumed.carried),
        carried_bits(&whole.carried),
        "contact histories differ"
    );
    for file in ["observables.csv", "trajectory.xyz"] {
        assert!(
            same_file(dir.path(), file),
            "{file} differs after the resume (killed at {})",
            at_kill.step
        );
    }
}

/// Clumps of [`RIGID`] with balls poured in from above and bodies taken
/// out at a corner of the floor: a killed run resumes bit for bit, its
/// checkpoint naming the bodies by id with the inserter of each, its
/// observables, outflow table and trajectory byte for byte the
/// uninterrupted run's.
#[test]
fn a_killed_rigid_run_with_inflow_and_outflow_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = RIGID.replace(
        "[run]",
        r#"[[insert]]
clump = "ball"
lo = [1.2e-3, 1.2e-3, 7.5e-3]
hi = [8.8e-3, 8.8e-3, 8.8e-3]
rate = 2000.0
velocity = [0.0, 0.0, -0.5]
every = 100
[[outlet]]
name = "corner"
lo = [-1.0, -1.0, -1.0]
hi = [4e-3, 4e-3, 2e-3]
[run]"#,
    );
    std::fs::write(dir.path().join("r.toml"), scene).unwrap();
    let args = [
        "run",
        "r.toml",
        "--threads",
        "1",
        "--checkpoint-every",
        "100",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 8000);
    assert_eq!(whole.step, 20000);
    assert!(
        at_kill.positions.len() > 36 && at_kill.positions.len() != whole.positions.len(),
        "{} bodies at the kill, {} at the end",
        at_kill.positions.len(),
        whole.positions.len()
    );
    assert_eq!(resumed.step, 20000);
    a_flow_resumed_as_it_ran(dir.path(), &whole, &at_kill, &resumed, 10);
}

/// Sends signal `name` ("INT", "TERM") to process `pid` through the shell's
/// built-in `kill` (a fresh Debian has `sh`, not always procps' `kill`).
fn send_signal(pid: u32, name: &str) {
    let sent = Command::new("sh")
        .args(["-c", &format!("kill -{name} {pid}")])
        .status()
        .unwrap();
    assert!(sent.success(), "could not send SIG{name} to {pid}");
}

/// Sends `signal` (by name, e.g. "INT") to a run once its checkpoint has
/// reached `from_step`; returns the run's exit code.
fn signal_when_checkpointed(
    child: &mut std::process::Child,
    checkpoint: &Path,
    from_step: u64,
    signal: &str,
) -> Option<i32> {
    wait_for_checkpoint(checkpoint, from_step);
    send_signal(child.id(), signal);
    child.wait().unwrap().code()
}

/// Ctrl-C (SIGINT) ends a point-particle run after its current step with
/// exit status 130 and a checkpoint of that step; resumed, the run ends in
/// the bits of an uninterrupted one, and the observables are those of an
/// uninterrupted run, byte for byte (no row at the interrupted step).
#[test]
fn sigint_stops_cleanly_with_a_last_checkpoint_and_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lj.toml"), SCENE).unwrap();
    let args = |out: &'static str| {
        vec![
            "run",
            "lj.toml",
            "--threads",
            "1",
            "-q",
            "-o",
            out,
            "--checkpoint-every",
            "200",
        ]
    };
    let o = mote(&args("whole"), dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = state(&dir.path().join("whole/checkpoint.mote"));

    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(args("cut"))
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let cp_path = dir.path().join("cut/checkpoint.mote");
    let code = signal_when_checkpointed(&mut child, &cp_path, 400, "INT");
    let at_stop = state(&cp_path).0;
    assert!(at_stop < 3000, "finished before the signal");
    assert_eq!(code, Some(130), "exit status after SIGINT");

    let o = mote(
        &[
            "run",
            "--resume",
            "cut/checkpoint.mote",
            "--threads",
            "1",
            "-q",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed = state(&cp_path);
    assert_eq!(resumed, whole, "stopped at step {at_stop}");
    let a = std::fs::read(dir.path().join("whole/observables.csv")).unwrap();
    let b = std::fs::read(dir.path().join("cut/observables.csv")).unwrap();
    assert!(a == b, "observables differ (stopped at step {at_stop})");
}

/// SIGTERM ends a rigid run with exit status 143 and a checkpoint; SIGTERM
/// ends an event-driven run with 143 and its files flushed and readable.
#[test]
fn sigterm_stops_rigid_and_event_driven_runs_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("r.toml"), RIGID).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "run",
            "r.toml",
            "--threads",
            "1",
            "-q",
            "-o",
            "cut",
            "--checkpoint-every",
            "1000",
        ])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let cp_path = dir.path().join("cut/checkpoint.mote");
    let code = signal_when_checkpointed(&mut child, &cp_path, 1000, "TERM");
    assert_eq!(code, Some(143), "exit status after SIGTERM");
    let cp = mote_io::checkpoint::read(&cp_path).unwrap();
    assert!(cp.step >= 1000 && cp.step < 20000, "step {}", cp.step);
    let o = mote(
        &[
            "run",
            "--resume",
            "cut/checkpoint.mote",
            "--threads",
            "1",
            "-q",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(mote_io::checkpoint::read(&cp_path).unwrap().step, 20000);

    // Hard spheres: no checkpoints, files flushed.
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["run", "example:eos", "--until", "400", "-q", "-o", "hs"])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let csv = dir.path().join("hs/observables.csv");
    let start = Instant::now();
    while mote_io::csv::read_table(&csv).map_or(true, |t| t.rows.len() < 2) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no rows appeared"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    send_signal(child.id(), "TERM");
    assert_eq!(child.wait().unwrap().code(), Some(143));
    let t = mote_io::csv::read_table(&csv).unwrap();
    assert!(
        t.rows.len() >= 2 && t.rows.len() < 380,
        "{} rows",
        t.rows.len()
    );
}

/// An event-driven run killed with SIGKILL resumes from its last checkpoint
/// (written every 3 output intervals, where the run rebuilds its lists and
/// queue from the synchronized state) and writes observables.csv byte for
/// byte as the uninterrupted run with the same schedule does.
#[test]
fn killed_event_driven_run_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "run",
        "example:eos",
        "--until",
        "30",
        "--seed",
        "3",
        "--checkpoint-every",
        "3",
    ];
    let (whole, at_kill, _) = whole_killed_resumed(dir.path(), &args, 6);
    assert_eq!(whole.option("engine"), Some("event-driven"));
    assert!(
        same_file(dir.path(), "observables.csv"),
        "observables differ after the resume (killed at output {})",
        at_kill.step
    );
}

/// Two runs writing into one folder: the second is refused while the first
/// runs (its process named); the lock goes with the first run, also when a
/// signal stops it, and a lock left by a killed run is taken over.
#[test]
fn a_second_run_into_a_busy_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut first = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["run", "example:eos", "--until", "400", "-q", "-o", "busy"])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let lock = dir.path().join("busy/.mote.lock");
    let start = Instant::now();
    while !lock.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no lock appeared"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let o = mote(
        &[
            "run",
            "example:sun-earth",
            "--steps",
            "5",
            "-q",
            "-o",
            "busy",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!(
            "busy: another mote run (process {}) is writing into this folder",
            first.id()
        )),
        "{err}"
    );
    send_signal(first.id(), "TERM");
    assert_eq!(first.wait().unwrap().code(), Some(143));
    assert!(!lock.exists(), "the lock outlived its run");

    // A lock whose process is gone is taken over.
    std::fs::write(&lock, "4000000000").unwrap();
    let o = mote(
        &[
            "run",
            "example:sun-earth",
            "--steps",
            "5",
            "-q",
            "-o",
            "busy",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!lock.exists());
}

const PACKING: &str = "[packing]\nn = 400\nmax_pressure = 1e8\n";

/// A packing killed with SIGKILL resumes from its last checkpoint to the
/// bits of an uninterrupted run: the packing, its CSV of windows and the
/// last checkpoint, byte for byte. Ctrl-C ends one with 130 and a last
/// checkpoint, from which it goes on to a jammed packing (not bit for bit:
/// the checkpoint at the signal rebuilds the system where the uninterrupted
/// run did not).
#[test]
fn killed_packing_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.toml"), PACKING).unwrap();
    let args = ["--seed", "3", "run", "p.toml", "--checkpoint-every", "10"];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 20);
    assert!(at_kill.step >= 20 && at_kill.step < whole.step);
    // The state, bit for bit (the options name each run's own folder).
    let bits = |c: &Checkpoint| {
        (
            c.step,
            c.time.to_bits(),
            c.positions.clone(),
            c.velocities.clone(),
            carried_bits(&c.carried),
        )
    };
    assert!(
        bits(&resumed) == bits(&whole),
        "killed at window {}",
        at_kill.step
    );
    for file in ["packing.xyz", "packing.csv"] {
        assert!(same_file(dir.path(), file), "{file} differs");
    }

    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args([
            "-q",
            "--seed",
            "3",
            "run",
            "p.toml",
            "--checkpoint-every",
            "10",
            "-o",
            "int",
        ])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let cp_path = dir.path().join("int/checkpoint.mote");
    let code = signal_when_checkpointed(&mut child, &cp_path, 20, "INT");
    assert_eq!(code, Some(130), "exit status after SIGINT");
    let at_stop = mote_io::checkpoint::read(&cp_path).unwrap();
    assert!(at_stop.step < whole.step, "finished before the signal");
    let o = mote(
        &["run", "--resume", "int/checkpoint.mote", "-q"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = mote(&["pack", "analyse", "int/packing.xyz"], dir.path());
    let summary = String::from_utf8_lossy(&o.stdout);
    // Jammed, and no overlap beyond round-off.
    let value = |key: &str| -> Option<f64> {
        let line = summary.lines().find(|l| l.starts_with(key))?;
        line.split_whitespace().last()?.parse().ok()
    };
    assert!(value("packing fraction").unwrap() > 0.63, "{summary}");
    let overlap = value("deepest overlap");
    assert!(
        overlap.map_or(summary.contains("overlaps              none"), |g| g
            > -1e-12),
        "{summary}"
    );
}

/// `mote pack` runs through the same loop: a packing written as GSD, killed
/// after a checkpoint, resumes with `mote run --resume` into its folder and
/// format, and ends with the uninterrupted run's packing and windows, byte
/// for byte.
#[test]
fn a_killed_mote_pack_resumes_in_its_format() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--seed",
        "3",
        "pack",
        "--n",
        "400",
        "--max-pressure",
        "1e8",
        "--format",
        "gsd",
        "--checkpoint-every",
        "10",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 20);
    assert!(at_kill.step >= 20 && at_kill.step < whole.step);
    assert_eq!(resumed.step, whole.step);
    for file in ["packing.gsd", "packing.csv"] {
        assert!(same_file(dir.path(), file), "{file} differs");
    }
}

/// A soft packing (`--method soft`) killed in its jamming finish resumes
/// bit for bit: the checkpoint holds the minimiser's and the
/// decompression's state, and the resumed run ends in the whole run's
/// packing and table.
#[test]
fn a_killed_soft_packing_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--seed",
        "3",
        "pack",
        "--method",
        "soft",
        "--n",
        "300",
        "--min-pressure",
        "1e-7",
        "--checkpoint-every",
        "20",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 300);
    assert!(at_kill.step >= 300 && at_kill.step < whole.step);
    assert!(
        at_kill.carried.iter().any(|(k, _)| k == "barostat_end"),
        "killed before the finish"
    );
    assert_eq!(resumed.step, whole.step);
    for file in ["packing.xyz", "packing.csv"] {
        assert!(same_file(dir.path(), file), "{file} differs");
    }
}

/// The toning nip killed mid-way resumes bit for bit: the checkpoint holds
/// the Coulomb forces held between Ewald sums (`every = 5`), and the resume
/// trims nip.csv as well as observables.csv and the trajectory.
#[test]
fn killed_toning_nip_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "run",
        "example:toning-nip",
        "--steps",
        "600",
        "--checkpoint-every",
        "100",
        "--threads",
        "1",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 200);
    assert_eq!(resumed.step, whole.step);
    assert!(
        at_kill
            .carried
            .iter()
            .any(|(_, v)| v.len() > 1 && v.len() % 4 == 1),
        "no held Coulomb forces in the checkpoint"
    );
    for file in ["observables.csv", "nip.csv", "trajectory.xyz"] {
        assert!(
            same_file(dir.path(), file),
            "{file} differs (killed at {})",
            at_kill.step
        );
    }
}

/// The toning nip with P3M between its planes (`[rigid.planes] method =
/// "p3m"`) resumes bit for bit too: the checkpoint holds the P3M
/// real-space list's build beside the held forces, so the resumed run
/// sums its pairs in the same order.
#[test]
fn killed_toning_nip_with_p3m_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let example = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/rigid/toning-nip.toml"
    );
    let text = std::fs::read_to_string(example)
        .unwrap()
        .replace("[rigid.planes]\n", "[rigid.planes]\nmethod = \"p3m\"\n");
    assert!(text.contains("method = \"p3m\""));
    std::fs::write(dir.path().join("nip-p3m.toml"), text).unwrap();
    let args = [
        "run",
        "nip-p3m.toml",
        "--steps",
        "600",
        "--checkpoint-every",
        "100",
        "--threads",
        "1",
    ];
    let (whole, at_kill, resumed) = whole_killed_resumed(dir.path(), &args, 200);
    assert_eq!(resumed.step, whole.step);
    // [length of the held part, the held part, the list's build].
    assert!(
        at_kill.carried.iter().any(|(_, v)| {
            let held = v.first().copied().unwrap_or(0.0) as usize;
            held % 4 == 1 && v.len() > 1 + held + 1
        }),
        "no P3M list in the checkpoint"
    );
    for file in ["observables.csv", "nip.csv", "trajectory.xyz"] {
        assert!(
            same_file(dir.path(), file),
            "{file} differs (killed at {})",
            at_kill.step
        );
    }
}

/// Runs own their folders: a checkpoint left in a folder by an older run is
/// refused once a newer run has written there (nothing trimmed); a copy of a
/// checkpoint resumes in its run's folder, saying where, and is refused once
/// another run owns that folder (no two runs spliced into one table).
#[test]
fn a_checkpoint_resumes_only_into_its_own_runs_files() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let o = mote(args, dir.path());
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let first = [
        "--seed",
        "1",
        "run",
        "example:sun-earth",
        "--steps",
        "200",
        "--checkpoint-every",
        "100",
        "-q",
        "-o",
        "f",
    ];
    assert_eq!(run(&first).0, Some(0));
    std::fs::copy(
        dir.path().join("f/checkpoint.mote"),
        dir.path().join("copy.mote"),
    )
    .unwrap();

    // The copy goes on in f, and says so.
    let (code, err) = run(&["run", "--resume", "copy.mote"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("continuing the run in its folder"), "{err}");
    assert!(err.contains("/f"), "{err}");

    // A newer run (another seed, no checkpoints) takes the folder.
    let second = [
        "--seed",
        "2",
        "run",
        "example:sun-earth",
        "--steps",
        "50",
        "-q",
        "-o",
        "f",
    ];
    assert_eq!(run(&second).0, Some(0));
    let table = std::fs::read(dir.path().join("f/observables.csv")).unwrap();
    for checkpoint in ["f/checkpoint.mote", "copy.mote"] {
        let (code, err) = run(&["run", "--resume", checkpoint]);
        assert_eq!(code, Some(1), "{checkpoint}: {err}");
        assert!(err.contains("cannot resume into"), "{err}");
        assert!(err.contains("holds the files of run"), "{err}");
        assert_eq!(
            std::fs::read(dir.path().join("f/observables.csv")).unwrap(),
            table,
            "the newer run's table was changed"
        );
    }
}

/// Two runs started together into one folder: never both run (the lock is
/// taken atomically), and the table that is left is one run's, whole.
#[test]
fn two_runs_started_together_never_both_write_one_folder() {
    let dir = tempfile::tempdir().unwrap();
    for trial in 0..4 {
        let out = format!("race{trial}");
        let spawn = || {
            Command::new(env!("CARGO_BIN_EXE_mote"))
                .args(["run", "example:eos", "--until", "200", "-q", "-o", &out])
                .current_dir(dir.path())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (spawn(), spawn());
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let ok = [&a, &b].iter().filter(|o| o.status.success()).count();
        assert_eq!(
            ok,
            1,
            "trial {trial}: {} / {}",
            String::from_utf8_lossy(&a.stderr),
            String::from_utf8_lossy(&b.stderr)
        );
        let loser = if a.status.success() { &b } else { &a };
        assert!(String::from_utf8_lossy(&loser.stderr).contains("is writing into this folder"));
        let table = std::fs::read_to_string(dir.path().join(&out).join("observables.csv")).unwrap();
        let rows: Vec<&str> = table.lines().filter(|l| !l.starts_with('#')).collect();
        let width = rows[0].split(',').count();
        assert!(
            rows.iter().all(|r| r.split(',').count() == width),
            "a torn row"
        );
    }
}
