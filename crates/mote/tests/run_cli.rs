//! `mote run` and `mote examples` end to end: outputs, and bad input.

use std::path::Path;
use std::process::{Command, Output};

fn mote(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("mote runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn example_runs_and_writes_headed_files() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &[
            "run",
            "example:sun-earth",
            "--steps",
            "200",
            "--seed",
            "42",
            "-o",
            "se",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("Ran 200 steps"), "{stdout}");
    let csv = std::fs::read_to_string(dir.path().join("se/observables.csv")).unwrap();
    let first = csv.lines().next().unwrap();
    assert!(
        first.contains("mote 0.1.0")
            && first.contains("example:sun-earth")
            && first.contains("seed=42"),
        "{first}"
    );
    let table = mote_io::csv::read_table(&dir.path().join("se/observables.csv")).unwrap();
    let t = table.column("time").unwrap();
    assert_eq!(*t.last().unwrap(), 100.0); // 200 steps of 0.5 d
    let frames = mote_io::xyz::read_frames(&dir.path().join("se/trajectory.xyz")).unwrap();
    assert_eq!(frames.len(), 11); // steps 0, 20, ..., 200
    assert_eq!(frames[0].positions.len(), 2);
}

/// A run that conserves no energy names what the viewer plots first:
/// Brownian dynamics the potential energy (the viewer plotted the total);
/// a Newtonian run names nothing, and the total energy is plotted.
#[test]
fn a_brownian_run_names_its_first_plot() {
    let dir = tempfile::tempdir().unwrap();
    for (example, plot) in [
        ("example:ferrofluid", Some("# plot: potential_energy")),
        ("example:sun-earth", None),
    ] {
        let o = mote(&["run", example, "--steps", "50", "-o", "f"], dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        let csv = std::fs::read_to_string(dir.path().join("f/observables.csv")).unwrap();
        let comment = csv.lines().find(|l| l.starts_with("# plot:"));
        assert_eq!(comment, plot, "{example}");
        // the table still reads: the comment is skipped
        let table = mote_io::csv::read_table(&dir.path().join("f/observables.csv")).unwrap();
        assert!(!table.rows.is_empty());
        std::fs::remove_dir_all(dir.path().join("f")).unwrap();
    }
}

#[test]
fn until_overrides_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &["run", "example:sun-earth", "--until", "10", "-q", "-o", "x"],
        dir.path(),
    );
    assert!(o.status.success());
    assert!(
        o.stdout.is_empty() && o.stderr.is_empty(),
        "--quiet printed something"
    );
    let table = mote_io::csv::read_table(&dir.path().join("x/observables.csv")).unwrap();
    assert_eq!(*table.column("time").unwrap().last().unwrap(), 10.0);
}

/// One rule for every time-stepped engine: `--until T` (or a scene's
/// `[run] until`) runs to the first step at or past T, ⌈T/Δt⌉ steps
/// (rigid runs took round(T/Δt) and stopped short of T for 0.0322/0.001);
/// the event-driven engine ends at T itself; a count of steps no run can
/// take is refused, and more than 10⁹ steps needs --force.
#[test]
fn every_engine_runs_to_the_first_step_at_or_past_until() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let o = mote(args, dir.path());
        let text =
            String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
        (o.status.code(), text)
    };
    // Point particles: 1.2 / 0.5 → 3 steps, t = 1.5; 1.0 / 0.5 → 2.
    let (code, out) = run(&[
        "run",
        "example:sun-earth",
        "--dt",
        "0.5",
        "--until",
        "1.2",
        "-o",
        "p",
    ]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("Ran 3 steps to t = 1.500000e0"), "{out}");
    let (_, out) = run(&[
        "run",
        "example:sun-earth",
        "--dt",
        "0.5",
        "--until",
        "1",
        "-o",
        "p",
    ]);
    assert!(out.contains("Ran 2 steps to t = 1.000000e0"), "{out}");
    // Rigid clumps, from the command line and from the scene.
    let (code, out) = run(&[
        "run",
        "example:magnet-in-field",
        "--dt",
        "0.001",
        "--until",
        "0.0322",
        "-o",
        "r",
    ]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("33 steps to t = 3.300000e-2"), "{out}");
    let scene = include_str!("../../../examples/rigid/magnet-in-field.toml")
        .replace("dt = 0.01\nsteps = 20000", "dt = 0.01\nuntil = 0.322");
    std::fs::write(dir.path().join("magnet.toml"), scene).unwrap();
    let (code, out) = run(&["run", "magnet.toml", "-o", "r"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("33 steps to t = 3.300000e-1"), "{out}");
    // Event-driven: the run ends at T.
    let (code, out) = run(&["run", "example:cradle", "--until", "0.7", "-o", "e"]);
    assert_eq!(code, Some(0), "{out}");
    let table = mote_io::csv::read_table(&dir.path().join("e/observables.csv")).unwrap();
    assert_eq!(*table.column("time").unwrap().last().unwrap(), 0.7);
    // Counts no run can take, and runs past 10⁹ steps.
    for engine in ["example:sun-earth", "example:magnet-in-field"] {
        let (code, out) = run(&["run", engine, "--dt", "1e-300", "--until", "1.2", "-o", "x"]);
        assert_eq!(code, Some(1), "{out}");
        assert!(
            out.contains("not a number of steps a run can take"),
            "{out}"
        );
        let (code, out) = run(&["run", engine, "--dt", "1e-9", "--until", "1.2", "-o", "x"]);
        assert_eq!(code, Some(1), "{out}");
        assert!(
            out.contains("1199999999 steps") && out.contains("--force"),
            "{out}"
        );
    }
    // The same from a scene: its line is named, the numbers as people
    // write them (not 301 digits of 1e300).
    std::fs::write(
        dir.path().join("far.toml"),
        "[run]\nintegrator = \"leapfrog\"\ndt = 0.01\nuntil = 1e300\n[[particle]]\nposition = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let (code, out) = run(&["run", "far.toml", "-o", "x"]);
    assert_eq!(code, Some(1), "{out}");
    assert!(
        out.contains("far.toml:4: until 1e300 from t = 0 with dt = 0.01: not a number of steps"),
        "{out}"
    );
    let (code, out) = run(&[
        "run",
        "example:sun-earth",
        "--dt",
        "1e-9",
        "--until",
        "1.2",
        "-o",
        "x",
    ]);
    assert_eq!(code, Some(1));
    assert!(out.contains("steps of dt = 1e-9:"), "{out}");
}

/// `mote examples` lists every engine's examples under a heading each,
/// and every example, written out, runs through `mote run` (a few steps,
/// or a short time for the event-driven ones).
#[test]
fn examples_are_listed_and_written_and_each_one_runs() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(&["examples"], dir.path());
    let list = String::from_utf8_lossy(&o.stdout);
    for name in [
        "sun-earth",
        "circumbinary",
        "choreography-9",
        "planetary-ring",
        "double-pendulum",
        "membrane",
        "cantilever",
        "settling",
        "column-collapse",
        "rotating-drum",
        "chute-flow",
        "plummer",
        "ferrofluid",
        "magnet-in-field",
        "clumps-settling",
        "chains-rotating-field",
        "cube",
        "cradle-heavy",
        "maxwell2d",
        "eos",
        "rcp",
    ] {
        assert!(list.contains(name), "{name} missing from {list}");
    }
    for heading in [
        "point particles",
        "rigid clumps of spheres",
        "hard spheres and disks",
        "packings by growing spheres",
    ] {
        assert!(list.contains(heading), "{heading} missing from {list}");
    }
    let o = mote(&["examples", "--write", "scenes"], dir.path());
    assert!(o.status.success());
    // Writing again leaves unchanged files be; an edited scene is kept
    // (nothing written, its name in the message) unless --force.
    let o = mote(&["examples", "--write", "scenes"], dir.path());
    assert!(o.status.success());
    let edited = dir.path().join("scenes/sun-earth.toml");
    let original = std::fs::read_to_string(&edited).unwrap();
    std::fs::write(&edited, "# my edit\n").unwrap();
    let o = mote(&["examples", "--write", "scenes"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("sun-earth.toml") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&edited).unwrap(), "# my edit\n");
    let o = mote(&["examples", "--write", "scenes", "--force"], dir.path());
    assert!(o.status.success());
    assert_eq!(std::fs::read_to_string(&edited).unwrap(), original);
    let mut engines = std::collections::HashSet::new();
    for entry in std::fs::read_dir(dir.path().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let engine = mote_front::Engine::of_scene(&text);
        engines.insert(format!("{engine:?}"));
        if engine == mote_front::Engine::Packing {
            // A packing has no run length; a small quick one stands in.
            let small = text
                .replace("n = 2000", "n = 100")
                .replace("rate = 0.01", "rate = 0.3");
            assert_ne!(
                small,
                text,
                "{}: the packing example changed",
                path.display()
            );
            std::fs::write(&path, small).unwrap();
        }
        let length = match engine {
            mote_front::Engine::EventDriven => {
                let table: toml::Table = text.parse().unwrap();
                let equilibrate = table
                    .get("run")
                    .and_then(|r| r.get("equilibrate"))
                    .and_then(|v| v.as_float())
                    .unwrap_or(0.0);
                ["--until".to_string(), format!("{}", equilibrate + 0.05)]
            }
            mote_front::Engine::Packing => ["--seed".to_string(), "1".to_string()],
            _ => ["--steps".to_string(), "3".to_string()],
        };
        let o = mote(
            &[
                "run",
                path.to_str().unwrap(),
                &length[0],
                &length[1],
                "-q",
                "-o",
                "o",
            ],
            dir.path(),
        );
        assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
    }
    assert_eq!(engines.len(), 4, "{engines:?}");
}

/// An event-driven scene run by `mote run` writes the same files, byte for
/// byte, as by the old `mote edmd` (same seed, same simulated time).
#[test]
fn event_driven_scene_runs_through_mote_run_as_through_mote_edmd() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &[
            "run",
            "example:maxwell2d",
            "--until",
            "3",
            "--seed",
            "99",
            "-o",
            "run",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(summary.contains("250 disks"), "{summary}");
    let o = mote(
        &[
            "edmd",
            "example:maxwell2d",
            "--time",
            "3",
            "--seed",
            "99",
            "--out-dir",
            "edmd",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for file in ["trajectory.xyz", "observables.csv", "speeds.csv"] {
        let a = std::fs::read(dir.path().join("run").join(file)).unwrap();
        let b = std::fs::read(dir.path().join("edmd").join(file)).unwrap();
        assert!(a.len() > 100, "{file} is nearly empty");
        assert_eq!(a, b, "{file} differs between mote run and mote edmd");
    }
}

/// Options an engine does not have are refused, each named with the
/// reason, and nothing runs; none is silently ignored.
#[test]
fn options_an_engine_lacks_are_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &["run", "example:cradle", "--dt", "0.1", "--steps", "4"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("--dt (event-driven dynamics jumps from collision to collision")
            && err.contains("--steps ("),
        "{err}"
    );
    let o = mote(
        &["run", "example:magnet-in-field", "--solver", "rk4"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("--solver (rigid bodies are moved by the FRBI only)"),
        "{err}"
    );
    let o = mote(
        &[
            "run",
            "example:sun-earth",
            "--system",
            "springs",
            "--steps",
            "2",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--system chooses the model of an MPPphys particle file"));
    assert!(
        !dir.path().join("out").exists(),
        "a refused run wrote files"
    );
}

/// An option that replaces a scene's value is named where that value is
/// refused (the scene has no line for it): a granular scene stepped with
/// another integrator than leap-frog.
#[test]
fn a_refused_option_value_is_named_not_a_line_of_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &["run", "example:settling", "--solver", "rk4", "--steps", "2"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("example:settling: --solver rk4: [granular] contacts turn the spheres"),
        "{err}"
    );
    assert!(
        !dir.path().join("out").exists(),
        "a refused run wrote files"
    );
}

/// A rigid run honours --dt, --steps, --seed, -o and --picture, and a
/// scene without a seed gets one chosen and printed.
#[test]
fn rigid_run_takes_the_common_options() {
    let dir = tempfile::tempdir().unwrap();
    let scene = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/rigid/magnet-in-field.toml"
    ))
    .unwrap()
    .replace("seed = 1\n", "");
    std::fs::write(dir.path().join("m.toml"), scene).unwrap();
    let o = mote(
        &[
            "run",
            "m.toml",
            "--dt",
            "0.002",
            "--steps",
            "7",
            "-o",
            "m",
            "--picture",
            "m.png",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("(chosen)") && err.contains("dt = 0.002"),
        "{err}"
    );
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(summary.contains("7 steps to t = 1.400000e-2"), "{summary}");
    let t = mote_io::csv::read_table(&dir.path().join("m/observables.csv")).unwrap();
    let time = t.column("time").unwrap();
    let last = *time.last().unwrap();
    assert!((last - 7.0 * 0.002).abs() < 1e-15, "last row at t = {last}");
    let png = std::fs::read(dir.path().join("m.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn plist_file_runs_with_system_and_solver() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("data.plist"),
        "pos 0 0.0 0.0 0.0 1.0 0.0 0.1 1.0 1.0 0.0\npos 1 1.0 0.0 0.0 3e-6 0.0 0.03 0.3 0.3 1.0\nvel 1 0.0 0.0172 0.0\nvfix 0 1 1 0\nvfix 1 1 1 0\nk2 2.9584e-4\ndt 0.03\n",
    )
    .unwrap();
    let o = mote(
        &[
            "run",
            "data.plist",
            "--system",
            "nbody",
            "--solver",
            "RK4",
            "--until",
            "3",
            "-o",
            "p",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = mote(&["run", "data.plist"], dir.path());
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no run length"), "{}", stderr(&o));
}

#[test]
fn malformed_scene_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.toml"),
        "units = \"astro\"\n[run]\ndt = 0.1\nintegrater = \"rk4\"\n",
    )
    .unwrap();
    let o = mote(&["run", "bad.toml", "--steps", "1"], dir.path());
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("bad.toml:4:") && e.contains("integrater"), "{e}");

    std::fs::write(
        dir.path().join("bad2.toml"),
        "[run]\ndt = 0.1\nintegrator = \"verlet9\"\n[[particle]]\nposition = [0, 0, 0]\n",
    )
    .unwrap();
    let e = stderr(&mote(&["run", "bad2.toml", "--steps", "1"], dir.path()));
    assert!(
        e.contains("bad2.toml:3: unknown integrator 'verlet9'"),
        "{e}"
    );

    std::fs::write(dir.path().join("bad3.toml"), "[run]\ndt = 0.1\n[[particle]]\nposition = [0, 0, 0]\n\n[[spring]]\npairs = [[0, 5]]\nstiffness = 1.0\n").unwrap();
    let e = stderr(&mote(&["run", "bad3.toml", "--steps", "1"], dir.path()));
    assert!(e.contains("bad3.toml:6: spring pair [0, 5]"), "{e}");

    std::fs::write(
        dir.path().join("bad4.toml"),
        "[run]\ndt = 0.1\n[[particle]]\nposition = [0, 0]\n",
    )
    .unwrap();
    let e = stderr(&mote(&["run", "bad4.toml", "--steps", "1"], dir.path()));
    assert!(e.contains("bad4.toml:4:"), "{e}");
}

#[test]
fn malformed_plist_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.plist"),
        "pos 0 0 0 0 1 0 0\n# fine\nvel 0 1 one 0\n",
    )
    .unwrap();
    let o = mote(&["run", "bad.plist", "--steps", "1"], dir.path());
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("bad.plist:3: the velocity of 'vel' must be a number, found 'one'"),
        "{e}"
    );
    assert!(!e.contains("panicked"), "{e}");
}

#[test]
fn unstable_run_stops_naming_step_and_particle_and_keeps_files() {
    let dir = tempfile::tempdir().unwrap();
    // The stiff double pendulum blows up at dt = 0.05 (it needs ~1e-3).
    let o = mote(
        &[
            "run",
            "example:double-pendulum",
            "--dt",
            "0.05",
            "--until",
            "1000",
            "-o",
            "dp",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("went unstable at step") && e.contains("particle"),
        "{e}"
    );
    assert!(e.contains("kept in dp"), "{e}");
    let table = mote_io::csv::read_table(&dir.path().join("dp/observables.csv")).unwrap();
    assert!(
        table.rows.len() > 1,
        "the observables written before the blow-up are kept"
    );
    assert!(table.rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
}

/// ASE reads the trajectory back with the same positions, radii and time
/// (skipped with a message when Python or ASE is missing).
#[test]
fn ase_reads_the_trajectory() {
    let ok = Command::new("python3")
        .args(["-c", "import ase"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("skipped: python3 with ASE is not available (pip install ase)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &[
            "run",
            "example:circumbinary",
            "--steps",
            "80",
            "-q",
            "-o",
            "cb",
        ],
        dir.path(),
    );
    assert!(o.status.success());
    let script = "import sys\nfrom ase.io import read\nfs = read(sys.argv[1], index=':')\nf = fs[-1]\nprint(len(fs), repr(float(f.info['Time'])), ' '.join(repr(float(x)) for x in f.get_positions().ravel()), ' '.join(repr(float(x)) for x in f.arrays['radius']))";
    let path = dir.path().join("cb/trajectory.xyz");
    let out = Command::new("python3")
        .args(["-c", script, path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut words = text.split_whitespace();
    let frames: usize = words.next().unwrap().parse().unwrap();
    let time: f64 = words.next().unwrap().parse().unwrap();
    let ours = mote_io::xyz::read_frames(&path).unwrap();
    assert_eq!(frames, ours.len());
    let last = ours.last().unwrap();
    assert_eq!(time, last.time);
    let ase_values: Vec<f64> = words.map(|w| w.parse().unwrap()).collect();
    let mine: Vec<f64> = last
        .positions
        .iter()
        .flatten()
        .copied()
        .chain(last.radii.iter().copied())
        .collect();
    assert_eq!(ase_values, mine);
}

/// `--picture` ray-traces the final state into a 1920×1080 PNG.
#[test]
fn picture_of_the_final_state() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &[
            "run",
            "example:membrane",
            "--steps",
            "5",
            "-q",
            "-o",
            "m",
            "--picture",
            "m.png",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(dir.path().join("m.png")).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), (1920, 1080));
}

/// A scene with a `[rigid]` table runs the rigid-body engine (FRBI).
#[test]
fn rigid_scene_runs_through_mote_run() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/rigid/magnet-in-field.toml"
    );
    let o = mote(&["run", scene, "-q", "-o", "rigid"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let t = mote_io::csv::read_table(&dir.path().join("rigid/observables.csv")).unwrap();
    // A free body in a homogeneous field keeps its linear momentum.
    let px = t.column("px").unwrap();
    assert!(px.len() > 10);
    assert!(px
        .iter()
        .all(|p| (p - px[0]).abs() <= 1e-12 * px[0].abs().max(1.0)));
}

/// Rigid bodies in a box periodic on every axis have a pressure column:
/// at the start, before any contact, the ideal gas of the bodies' centres,
/// P = Σ M V²/3V = 2 E_trans/3V; once they collide, the contacts' virial
/// adds to it. A box with walls (not periodic everywhere) has no such
/// column, and the scene's pressure tensor is refused saying what there is.
#[test]
fn rigid_bodies_in_a_periodic_box_have_a_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "seed = 5\n[rigid]\n[[rigid.template]]\nname = \"trimer\"\ngenerator = \"trimer\"\nradius = 0.5\ndistance = 0.5\nmass = 1.5\n\
        [[rigid.lattice]]\ntemplate = \"trimer\"\nn = 64\nlo = [0.0, 0.0, 0.0]\nhi = [8.0, 8.0, 8.0]\nspacing = 2.05\n\
        random_orientation = true\nspeed = 2.0\n\
        [box]\nlo = [0.0, 0.0, 0.0]\nhi = [8.2, 8.2, 8.2]\nperiodic = [true, true, true]\n\
        [rigid.contacts]\nyoung = 136500.0\npoisson = 0.3\nrestitution = 0.9\nfriction = 0.3\n\
        [run]\ndt = 5e-4\nsteps = 4000\n[output]\nobservables_every = 200\n";
    std::fs::write(dir.path().join("gas.toml"), scene).unwrap();
    let o = mote(&["run", "gas.toml", "-q", "-o", "gas"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let t = mote_io::csv::read_table(&dir.path().join("gas/observables.csv")).unwrap();
    let p = t.column("pressure").unwrap();
    let kt = t.column("translational_energy").unwrap();
    let volume = 8.2f64.powi(3);
    let ideal = 2.0 * kt[0] / (3.0 * volume);
    assert!(
        (p[0] - ideal).abs() <= 1e-12 * ideal,
        "{} against {ideal}",
        p[0]
    );
    assert!(p.iter().all(|p| p.is_finite() && *p > 0.0), "{p:?}");
    // the contacts press: some row differs from its ideal gas
    assert!(
        (0..p.len()).any(|i| (p[i] - 2.0 * kt[i] / (3.0 * volume)).abs() > 1e-6 * p[i]),
        "no contact ever pressed: {p:?}"
    );
    let settling = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/rigid/clumps-settling.toml"
    );
    let o = mote(
        &["run", settling, "--steps", "2", "-q", "-o", "walls"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let t = mote_io::csv::read_table(&dir.path().join("walls/observables.csv")).unwrap();
    assert!(t.column("pressure").is_none());
    let tensor = scene.replace(
        "observables_every = 200",
        "observables_every = 200\npressure_tensor = true",
    );
    std::fs::write(dir.path().join("tensor.toml"), tensor).unwrap();
    let o = mote(&["run", "tensor.toml", "-q", "-o", "tensor"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("the scalar pressure only"),
        "{}",
        stderr(&o)
    );
}

/// Charged rigid bodies in a periodic box take the point particles'
/// `[coulomb]` table between their centres: a static rock-salt crystal of
/// 64 single-sphere bodies under Ewald has the Madelung energy
/// U = −(N/2) M k q²/a (M = 1.747564594633, NaCl) and the pressure
/// P = U/(3V) (the Coulomb virial W = U of charges in a periodic box).
#[test]
fn charged_bodies_in_a_periodic_box_have_the_madelung_energy_and_its_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = String::from(
        "seed = 1\n[rigid]\n\
         [[rigid.template]]\nname = \"plus\"\nspheres = [[0.0, 0.0, 0.0, 0.2]]\ndensity = 1.0\ncharge = 1.0\n\
         [[rigid.template]]\nname = \"minus\"\nspheres = [[0.0, 0.0, 0.0, 0.2]]\ndensity = 1.0\ncharge = -1.0\n",
    );
    // Rock salt of side 2a (a = 1) as eight simple-cubic sublattices of
    // spacing 2, two sites per axis each: 64 ions in a box of side 4.
    for (x, y, z) in [
        (0, 0, 0),
        (1, 1, 0),
        (1, 0, 1),
        (0, 1, 1),
        (1, 0, 0),
        (0, 1, 0),
        (0, 0, 1),
        (1, 1, 1),
    ] {
        let template = if (x + y + z) % 2 == 0 {
            "plus"
        } else {
            "minus"
        };
        let lo = [x, y, z].map(|c| c as f64 + 0.5);
        scene += &format!(
            "[[rigid.lattice]]\ntemplate = \"{template}\"\nn = 8\nlo = {lo:?}\nhi = {:?}\nspacing = 2.0\n",
            lo.map(|c| c + 2.0)
        );
    }
    scene += "[box]\nlo = [0.0, 0.0, 0.0]\nhi = [4.0, 4.0, 4.0]\nperiodic = [true, true, true]\n\
              [coulomb]\nmethod = \"ewald\"\nk = 1.0\naccuracy = 1e-7\n\
              [rigid.contacts]\nyoung = 1e5\npoisson = 0.3\nrestitution = 0.9\nfriction = 0.3\n\
              [run]\ndt = 1e-3\nsteps = 20\n[output]\nobservables_every = 10\n";
    std::fs::write(dir.path().join("salt.toml"), &scene).unwrap();
    let o = mote(&["run", "salt.toml", "-q", "-o", "salt"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let t = mote_io::csv::read_table(&dir.path().join("salt/observables.csv")).unwrap();
    let u = t.column("potential_energy").unwrap();
    let p = t.column("pressure").unwrap();
    let madelung = -32.0 * 1.747_564_594_633;
    let volume = 64.0;
    for (u, p) in u.iter().zip(p) {
        assert!(
            (u - madelung).abs() <= 1e-6 * madelung.abs(),
            "U = {u} against {madelung}"
        );
        let expected = u / (3.0 * volume);
        assert!(
            (p - expected).abs() <= 1e-6 * expected.abs(),
            "P = {p} against U/3V = {expected}"
        );
    }
    // The same table between open-space sums and a periodic box is refused.
    let open = scene.replace("method = \"ewald\"\nk = 1.0\naccuracy = 1e-7", "k = 1.0");
    std::fs::write(dir.path().join("open.toml"), &open).unwrap();
    let o = mote(&["run", "open.toml", "-q", "-o", "open"], dir.path());
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("sums over open space: a periodic box needs method = \"ewald\""),
        "{}",
        stderr(&o)
    );
    // The first spelling of the laws between centres, in [rigid.fields]
    // (summed over open space, even in a periodic box), is refused with
    // the point particles' tables that replaced it.
    let fields = scene.replace(
        "[coulomb]\nmethod = \"ewald\"\nk = 1.0\naccuracy = 1e-7\n",
        "[rigid.fields]\ncoulomb = 1.0\n",
    );
    std::fs::write(dir.path().join("fields.toml"), &fields).unwrap();
    let o = mote(&["run", "fields.toml", "-q", "-o", "fields"], dir.path());
    assert!(!o.status.success());
    let line = fields.lines().position(|l| l == "[rigid.fields]").unwrap() + 1;
    assert!(
        stderr(&o).contains(&format!(
            "fields.toml:{line}: [rigid.fields] coulomb: Coulomb's law between the bodies is the point particles' table, [coulomb] k = ..."
        )),
        "{}",
        stderr(&o)
    );
    let dipoles = fields.replace("coulomb = 1.0", "dipole_dipole = 1.0");
    std::fs::write(dir.path().join("dipoles.toml"), &dipoles).unwrap();
    let o = mote(&["run", "dipoles.toml", "-q", "-o", "dipoles"], dir.path());
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains(&format!(
            "dipoles.toml:{line}: [rigid.fields] dipole_dipole: the dipoles' law between the bodies is the point particles' table, [dipolar] mu0 = 4π k"
        )),
        "{}",
        stderr(&o)
    );
}

/// A granular run's observables give the kinetic energy whole and split
/// into its translational part (what LAMMPS's `ke` reports) and its
/// rotational part, with the units in the header, as rigid runs do.
#[test]
fn granular_observables_split_translation_and_rotation() {
    let dir = tempfile::tempdir().unwrap();
    let o = mote(
        &[
            "run",
            "example:rotating-drum",
            "--steps",
            "2500",
            "-q",
            "-o",
            "drum",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let t = mote_io::csv::read_table(&dir.path().join("drum/observables.csv")).unwrap();
    let k = t.column("kinetic_energy").unwrap();
    let kt = t.column("translational_energy").unwrap();
    let kr = t.column("rotational_energy").unwrap();
    assert!(k.len() >= 2);
    for i in 0..k.len() {
        assert!(
            (kt[i] + kr[i] - k[i]).abs() <= 1e-12 * k[i].abs().max(1e-300),
            "row {i}: {} + {} ≠ {}",
            kt[i],
            kr[i],
            k[i]
        );
        assert!(kr[i] >= 0.0 && kt[i] >= 0.0);
    }
    let last = k.len() - 1;
    assert!(
        kr[last] > 0.0,
        "the grains roll: rotational energy {}",
        kr[last]
    );
    let header = std::fs::read_to_string(dir.path().join("drum/observables.csv")).unwrap();
    assert!(header.contains("translational_energy"));
}

/// Negative numbers on the command line are values, not flags: each is
/// refused with what it must be (exit 1), never "unexpected argument".
#[test]
fn negative_numbers_are_refused_as_values() {
    let dir = tempfile::tempdir().unwrap();
    for (args, says) in [
        (
            &["run", "example:sun-earth", "--until", "-1"][..],
            "--until -1: must be a positive, finite number",
        ),
        (
            &["run", "example:sun-earth", "--dt", "-0.5", "--steps", "2"][..],
            "--dt -0.5: must be a positive, finite number",
        ),
        (
            &["run", "example:magnet-in-field", "--until", "-3"][..],
            "--until -3: must be a positive, finite number",
        ),
        (
            &["edmd", "example:cube", "--time", "-5"][..],
            "--time -5: must be a non-negative number",
        ),
        (
            &["pack", "--rate", "-1"][..],
            "--rate -1: the growth rate Γ must lie in (0, 10³]",
        ),
    ] {
        let o = mote(args, dir.path());
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        let err = stderr(&o);
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    }
}

/// Requests larger than the machine are refused at once with both numbers
/// (exit 1, no abort, no endless run): a hard-sphere scene, a packing and
/// a rod packing.
#[test]
fn requests_too_large_for_the_machine_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("hs.toml"),
        "[event_driven]\ndimension = 3\nn = 100000000000\npacking_fraction = 0.3\n",
    )
    .unwrap();
    let o = mote(&["run", "hs.toml"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("hs.toml:3: n = 100000000000 needs at least 30.0 TB, and this machine has"),
        "{err}"
    );
    std::fs::write(
        dir.path().join("rig.toml"),
        "[rigid]\n[[rigid.template]]\nname = \"b\"\ngenerator = \"sphere\"\nradius = 1.0\ndensity = 1.0\n\
         [[rigid.random]]\ntemplate = \"b\"\nn = 100000000000\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\n\
         [run]\ndt = 0.01\nsteps = 1\n",
    )
    .unwrap();
    let o = mote(&["run", "rig.toml", "-q"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("rig.toml:7: 100000000000 bodies of 1 spheres needs at least 14.0 TB"),
        "{}",
        stderr(&o)
    );
    let o = mote(&["pack", "--n", "100000000000"], dir.path());
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("--n 100000000000: the packing needs at least 30.0 TB"),
        "{}",
        stderr(&o)
    );
    let o = Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(["rcp", "-l", "-N", "99999999999"])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut c| {
            use std::io::Write;
            c.stdin.take().unwrap().write_all(b"2 0.5\n")?;
            c.wait_with_output()
        })
        .unwrap();
    assert!(!o.status.success());
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(
        text.contains("-N 99999999999: the rod packing needs at least 800.0 GB"),
        "{text}"
    );
}

/// `[output] trajectory_format` picks the file and its format; each reads
/// back with the frames the XYZ has; a name it does not know is refused at
/// its line.
#[test]
fn trajectory_format_chooses_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let base = include_str!("../../../examples/sun-earth.toml");
    let mut frames_of = Vec::new();
    for (format, file) in [
        ("xyz", "trajectory.xyz"),
        ("dump", "trajectory.dump"),
        ("gsd", "trajectory.gsd"),
        ("vtk", "trajectory.pvd"),
    ] {
        let scene = dir.path().join(format!("{format}.toml"));
        std::fs::write(
            &scene,
            base.replace(
                "trajectory_every = 20",
                &format!("trajectory_every = 20\ntrajectory_format = \"{format}\""),
            ),
        )
        .unwrap();
        let out = format!("out_{format}");
        let o = mote(
            &[
                "-q",
                "run",
                scene.to_str().unwrap(),
                "--steps",
                "100",
                "-o",
                &out,
            ],
            dir.path(),
        );
        assert!(o.status.success(), "{format}: {}", stderr(&o));
        let frames = mote_io::trajectory::read_frames(&dir.path().join(&out).join(file)).unwrap();
        frames_of.push((format, frames));
    }
    let (_, xyz) = &frames_of[0];
    assert_eq!(xyz.len(), 6);
    for (format, frames) in &frames_of[1..] {
        assert_eq!(frames.len(), xyz.len(), "{format}");
        for (a, b) in frames.iter().zip(xyz) {
            // GSD keeps f32 positions (about 1e-7 of an AU here).
            for (p, q) in a.positions.iter().zip(&b.positions) {
                for d in 0..3 {
                    assert!((p[d] - q[d]).abs() < 1e-6, "{format}: {p:?} {q:?}");
                }
            }
        }
    }
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        base.replace(
            "trajectory_every = 20",
            "trajectory_every = 20\ntrajectory_format = \"hdf5\"",
        ),
    )
    .unwrap();
    let o = mote(
        &["-q", "run", bad.to_str().unwrap(), "--steps", "10"],
        dir.path(),
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("bad.toml:32:") && e.contains("'hdf5' is not one of xyz, dump, gsd, vtk"),
        "{e}"
    );
}

/// `--trajectory-format` replaces the scene's, for every engine, and a
/// resumed run keeps the format of the run it continues.
#[test]
fn trajectory_format_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    // Event-driven runs have no steps: they get a time instead.
    for (example, length) in [
        ("example:sun-earth", ["--steps", "40"]),
        ("example:magnet-in-field", ["--steps", "40"]),
        ("example:cradle", ["--until", "1"]),
    ] {
        let out = format!("out_{}", &example[8..]);
        let mut args = vec![
            "-q",
            "run",
            example,
            "--trajectory-format",
            "gsd",
            "-o",
            &out,
        ];
        args.extend(length);
        let o = mote(&args, dir.path());
        assert!(o.status.success(), "{example}: {}", stderr(&o));
        let path = dir.path().join(&out).join("trajectory.gsd");
        let frames = mote_io::trajectory::read_frames(&path).unwrap();
        assert!(!frames.is_empty(), "{example}");
    }
    let o = mote(
        &[
            "-q",
            "run",
            "example:sun-earth",
            "--trajectory-format",
            "hdf5",
            "--steps",
            "5",
        ],
        dir.path(),
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("invalid value 'hdf5' for '--trajectory-format <FORMAT>'")
            && stderr(&o).contains("possible values: xyz, dump, gsd, vtk"),
        "{}",
        stderr(&o)
    );
    // A checkpointed run in GSD, resumed: the GSD goes on (no XYZ appears).
    let o = mote(
        &[
            "-q",
            "run",
            "example:sun-earth",
            "--trajectory-format",
            "gsd",
            "--steps",
            "60",
            "--checkpoint-every",
            "20",
            "-o",
            "cp",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = mote(&["-q", "run", "--resume", "cp/checkpoint.mote"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!dir.path().join("cp/trajectory.xyz").exists());
    let frames = mote_io::trajectory::read_frames(&dir.path().join("cp/trajectory.gsd")).unwrap();
    assert_eq!(frames.len(), 4, "steps 0, 20, 40, 60");
}

/// A trajectory or data file given to `mote run` is said to be one, with
/// what to do instead (it was read as an MPPphys particle file and failed
/// on its first line): by its extension, or by its first lines when the
/// name says nothing.
#[test]
fn a_trajectory_given_to_run_is_named_with_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let xyz =
        "1\nLattice=\"5 0 0 0 5 0 0 0 5\" Properties=species:S:1:pos:R:3 pbc=\"T T T\"\nX 1 1 1\n";
    let dump = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 5\n0 5\n0 5\nITEM: ATOMS id type x y z\n1 1 1 1 1\n";
    let data = "LAMMPS data file\n\n1 atoms\n1 atom types\n\n0 5 xlo xhi\n0 5 ylo yhi\n0 5 zlo zhi\n\nAtoms # atomic\n\n1 1 1 1 1\n";
    for (name, text, kind) in [
        ("frames.xyz", xyz, "an extended XYZ trajectory"),
        ("frames", xyz, "an extended XYZ trajectory"),
        ("last", dump, "a LAMMPS dump"),
        ("bed.data", data, "a LAMMPS data file"),
        ("bed", data, "a LAMMPS data file"),
    ] {
        std::fs::write(dir.path().join(name), text).unwrap();
        let o = mote(&["run", name], dir.path());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert!(
            err.contains(&format!("{name}: this is {kind}")) && err.contains("[[from_file]]"),
            "{name}: {err}"
        );
        assert_eq!(
            err.contains("mote view"),
            kind != "a LAMMPS data file",
            "{name}: {err}"
        );
    }
    // An MPPphys particle file of any name still runs.
    std::fs::write(
        dir.path().join("two.txt"),
        "pos 0 0.0 0.0 0.0 1.0 0.0 0.1 1.0 1.0 0.0\npos 1 1.0 0.0 0.0 3e-6 0.0 0.03 0.3 0.3 1.0\nvel 1 0.0 0.0172 0.0\nk2 2.9584e-4\ndt 0.03\n",
    )
    .unwrap();
    let o = mote(&["run", "two.txt", "--steps", "2", "-o", "p"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The opening line names the SIMD level; `MOTE_SIMD` forces one, and a
/// level the CPU lacks or a name that is none is refused before anything
/// runs (never quietly replaced by another).
#[test]
#[cfg(target_arch = "x86_64")]
fn the_simd_level_is_named_and_a_forced_one_the_cpu_lacks_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = |level: &str| {
        Command::new(env!("CARGO_BIN_EXE_mote"))
            .args(["run", "example:sun-earth", "--steps", "2", "-o", "se"])
            .env("MOTE_SIMD", level)
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let o = run("avx2");
    assert!(o.status.success(), "{}", stderr(&o));
    // The opening line goes to stderr with the progress.
    let opening = stderr(&o);
    assert!(
        opening.contains("AVX2 + FMA (portable kernels)"),
        "{opening}"
    );
    let o = run("sse9");
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("MOTE_SIMD=sse9: expected avx512, avx2 or portable"));
    let o = run("avx512");
    if std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
    {
        assert!(stderr(&o).contains("AVX-512"), "{}", stderr(&o));
    } else {
        assert_eq!(o.status.code(), Some(1));
        assert!(
            stderr(&o).contains("MOTE_SIMD=avx512: this CPU lacks it"),
            "{}",
            stderr(&o)
        );
    }
}

/// A run with its observables switched off still ends its summary at its
/// last step: the end time and the energy there (it said "Ran 10 steps to
/// t = 0" and a drift of 0, the first step's numbers).
#[test]
fn a_run_without_observables_reports_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "units = \"lj\"\n[run]\ndt = 0.01\nsteps = 10\n[gravity]\nG = 1.0\n\
                 [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\n\
                 [[particle]]\nposition = [1.0, 0.0, 0.0]\nvelocity = [0.0, 0.7, 0.0]\nmass = 0.001\n\
                 [output]\nobservables_every = 0\ntrajectory_every = 0\n";
    std::fs::write(dir.path().join("quiet.toml"), scene).unwrap();
    let o = mote(&["run", "quiet.toml", "-o", "quiet"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string() + &stderr(&o);
    assert!(out.contains("Ran 10 steps to t = 1.000000e-1 tau"), "{out}");
    assert!(!out.contains("relative drift 0.000e0 at the end"), "{out}");
}
