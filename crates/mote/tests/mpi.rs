//! `mote run` across the ranks of `mpirun` (built with the `mpi` feature:
//! `cargo test -p mote --features mpi --test mpi`; `.ci/run` installs
//! OpenMPI and runs it). A Lennard-Jones liquid decomposed over 2, 3 and 4
//! ranks, a molten salt with P3M Coulomb and a dipolar fluid with P3M
//! dipoles on 2, 3 and 4, and a granular bed on 2 and 3, write the
//! trajectory of one process byte for byte; one rank
//! writes exactly what the plain build writes; what does not decompose yet
//! is refused, once, with its name.

use std::path::Path;
use std::process::{Command, Output};

/// A liquid of 1920 atoms that melts from a hot crystal: particles cross
/// bricks and the list is rebuilt dozens of times in 400 steps.
const LIQUID: &str = r#"
title = "LJ liquid on ranks"
units = "lj"
seed = 5

[run]
integrator = "leapfrog"
dt = 0.005
steps = 400

[lennard_jones]
cutoff = 2.5
shifted = true
skin = 0.3

[[fcc]]
cells = [10, 8, 6]
density = 0.8442
kt = 2.0

[output]
observables_every = 50
trajectory_every = 100
"#;

fn mpirun(ranks: usize, args: &[&str], dir: &Path) -> Output {
    Command::new("mpirun")
        .args(["--allow-run-as-root", "--oversubscribe", "-np"])
        .arg(ranks.to_string())
        .arg(env!("CARGO_BIN_EXE_mote"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("mpirun runs (OpenMPI: openmpi-bin)")
}

fn plain(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mote"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("mote runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The numbers of observables.csv, row by row.
fn table(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

#[test]
fn a_liquid_on_two_three_and_four_ranks_writes_one_process_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("lj.toml"), LIQUID).unwrap();
    let one = plain(&["run", "lj.toml", "-o", "one"], dir.path());
    assert!(one.status.success(), "{}", text(&one.stderr));
    let read = |run: &str, file: &str| std::fs::read(dir.path().join(run).join(file)).unwrap();
    // One rank is the plain build, every byte of every file.
    let solo = mpirun(1, &["run", "lj.toml", "-o", "solo"], dir.path());
    assert!(solo.status.success(), "{}", text(&solo.stderr));
    for file in ["trajectory.xyz", "observables.csv"] {
        assert!(
            read("one", file) == read("solo", file),
            "{file} on one rank"
        );
    }
    let expected = table(&dir.path().join("one/observables.csv"));
    for ranks in [2, 3, 4] {
        let run = format!("np{ranks}");
        let o = mpirun(ranks, &["run", "lj.toml", "-o", &run], dir.path());
        let stdout = text(&o.stdout);
        assert!(
            o.status.success(),
            "{ranks} ranks: {}{stdout}",
            text(&o.stderr)
        );
        // Rank 0 alone opens (on stderr), prints and writes.
        let opening = text(&o.stderr);
        assert_eq!(
            opening.matches(&format!("on {ranks} ranks")).count(),
            1,
            "{opening}"
        );
        assert_eq!(stdout.matches("Ran 400 steps").count(), 1, "{stdout}");
        assert!(
            stdout.contains("ghosts a rank at the last list build"),
            "{stdout}"
        );
        assert!(
            read("one", "trajectory.xyz") == read(&run, "trajectory.xyz"),
            "the trajectory on {ranks} ranks differs from one process's"
        );
        // Sums over the ranks: the same to round-off (added in another order).
        let got = table(&dir.path().join(&run).join("observables.csv"));
        assert_eq!(got.len(), expected.len());
        for (g, e) in got.iter().zip(&expected) {
            for (a, b) in g.iter().zip(e) {
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1e-3),
                    "{ranks} ranks: {a} against {b}"
                );
            }
        }
    }
}

/// A molten salt of 1024 ions, charges by P3M beside WCA cores, melting
/// from rock salt in a box long enough for four bricks along x.
const SALT: &str = r#"
title = "molten salt on ranks"
units = "lj"
seed = 3

[run]
integrator = "leapfrog"
dt = 0.002
steps = 100

[lennard_jones]
wca = true

[coulomb]
method = "p3m"
accuracy = 1e-3

[[fcc]]
cells = [8, 4, 4]
density = 0.25
kt = 1.0
charge = 1.0

[[fcc]]
cells = [8, 4, 4]
density = 0.25
kt = 1.0
origin = [1.2599210498948732, 0.0, 0.0]
charge = -1.0

[output]
observables_every = 25
trajectory_every = 50
"#;

/// A dipolar fluid of 512 particles turning as they move, dipoles by P3M
/// beside WCA cores, in a box long enough for four bricks along x.
const DIPOLAR_FLUID: &str = r#"
title = "dipolar fluid on ranks"
units = "lj"
seed = 4

[run]
integrator = "leapfrog"
dt = 0.002
steps = 100

[lennard_jones]
wca = true

[dipolar]
method = "p3m"
accuracy = 1e-3
random_orientation = true

[[fcc]]
cells = [8, 4, 4]
density = 0.7
kt = 1.0
radius = 0.5
dipole = [0.0, 0.0, 1.2]

[output]
observables_every = 25
trajectory_every = 50
"#;

/// A spring lattice with diagonals shaken by a Langevin bath, long
/// enough along x for four bricks.
const SPRINGS: &str = include_str!("../../mote-md/tests/data/spring-lattice.toml");

/// P3M on ranks: the real space over each rank's halo, the mesh made on
/// every rank from every particle (gathered in id order), so the forces —
/// and the trajectory — are one process's, byte for byte, on 2, 3 and 4
/// ranks; the energies (summed over the ranks) to round-off. For charges
/// (a molten salt) and for dipoles (a dipolar fluid, with torques); the
/// same for a salt by Ewald (every rank gathering every particle for the
/// structure factors) and for springs across bricks (the far end's motion
/// from the halo).
#[test]
fn p3m_ewald_and_springs_on_two_three_and_four_ranks_write_one_process_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let ewald_salt = SALT
        .replace("method = \"p3m\"", "method = \"ewald\"")
        .replace("cells = [8, 4, 4]", "cells = [4, 4, 4]");
    let springs = format!("{SPRINGS}\n[output]\nobservables_every = 25\ntrajectory_every = 50\n");
    for (name, scene, said) in [
        ("salt", SALT, "Coulomb by P3M: mesh"),
        ("fluid", DIPOLAR_FLUID, "Dipolar by P3M: mesh"),
        ("ewald", ewald_salt.as_str(), "steps"),
        ("springs", springs.as_str(), "steps"),
    ] {
        let file = format!("{name}.toml");
        std::fs::write(dir.path().join(&file), scene).unwrap();
        let one_dir = format!("{name}-one");
        let one = plain(&["run", &file, "-o", &one_dir], dir.path());
        assert!(one.status.success(), "{}", text(&one.stderr));
        assert!(text(&one.stdout).contains(said), "{}", text(&one.stdout));
        let read = |run: &str, f: &str| std::fs::read(dir.path().join(run).join(f)).unwrap();
        let expected = table(&dir.path().join(&one_dir).join("observables.csv"));
        for ranks in [2, 3, 4] {
            let run = format!("{name}-np{ranks}");
            let o = mpirun(ranks, &["run", &file, "-o", &run], dir.path());
            assert!(
                o.status.success(),
                "{name} on {ranks} ranks: {}{}",
                text(&o.stderr),
                text(&o.stdout)
            );
            assert!(
                read(&one_dir, "trajectory.xyz") == read(&run, "trajectory.xyz"),
                "{name}: the trajectory on {ranks} ranks differs from one process's"
            );
            let got = table(&dir.path().join(&run).join("observables.csv"));
            assert_eq!(got.len(), expected.len());
            for (g, e) in got.iter().zip(&expected) {
                for (a, b) in g.iter().zip(e) {
                    assert!(
                        (a - b).abs() <= 1e-9 * b.abs().max(1e-3),
                        "{name} on {ranks} ranks: {a} against {b}"
                    );
                }
            }
        }
    }
}

/// A cloud collapsing under gravity with Coulomb's law between its
/// charges (the open-space sums, every rank summing its own particles'
/// rows over all, gathered in id order): the same trajectory byte for byte
/// on 2, 3 and 4 ranks, and one process's (whose pair-symmetric sums run
/// in another order) to round-off.
#[test]
fn open_space_sums_write_the_same_trajectory_on_two_three_and_four_ranks() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "{}\n[output]\nobservables_every = 20\ntrajectory_every = 50\n",
        include_str!("../../mote-md/tests/data/collapsing-cloud.toml")
    );
    std::fs::write(dir.path().join("cloud.toml"), scene).unwrap();
    let one = plain(&["run", "cloud.toml", "-o", "one"], dir.path());
    assert!(one.status.success(), "{}", text(&one.stderr));
    let read = |run: &str| std::fs::read(dir.path().join(run).join("trajectory.xyz")).unwrap();
    let expected = table(&dir.path().join("one").join("observables.csv"));
    for ranks in [2, 3, 4] {
        let run = format!("np{ranks}");
        let o = mpirun(ranks, &["run", "cloud.toml", "-o", &run], dir.path());
        assert!(o.status.success(), "{ranks} ranks: {}", text(&o.stderr));
        if ranks > 2 {
            assert!(read("np2") == read(&run), "{ranks} ranks against 2");
        }
        let got = table(&dir.path().join(&run).join("observables.csv"));
        assert_eq!(got.len(), expected.len());
        for (g, e) in got.iter().zip(&expected) {
            // Round-off against the row's largest number (the momentum's
            // components are round-off themselves).
            let scale = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in g.iter().zip(e) {
                assert!(
                    (a - b).abs() <= 1e-10 * scale,
                    "{ranks} ranks: {a} against {b}"
                );
            }
        }
    }
}

#[test]
fn what_does_not_decompose_yet_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let gravity = "title = \"g\"\nunits = \"lj\"\n[run]\ndt = 0.01\nsteps = 5\n\
                   [gravity]\nmethod = \"tree\"\nsoftening = 0.1\n\
                   [[particle]]\nposition = [0, 0, 0]\n[[particle]]\nposition = [1, 0, 0]\n";
    std::fs::write(dir.path().join("g.toml"), gravity).unwrap();
    let o = mpirun(2, &["run", "g.toml", "-o", "g"], dir.path());
    let stderr = text(&o.stderr);
    assert!(!o.status.success());
    assert_eq!(
        stderr.matches("does not run on 2 ranks yet").count(),
        1,
        "{stderr}"
    );
    assert!(stderr.contains("gravity"), "{stderr}");
    let o = mpirun(2, &["examples"], dir.path());
    assert!(!o.status.success());
    let stderr = text(&o.stderr);
    assert_eq!(
        stderr
            .matches("only `mote run` runs on several ranks")
            .count(),
        1,
        "{stderr}"
    );
    for (example, what) in [
        ("example:cube", "an event-driven scene"),
        ("example:clumps-settling", "rigid clumps"),
        ("example:membrane", "the particle inspector"),
    ] {
        let o = mpirun(2, &["run", example, "-o", "x"], dir.path());
        let stderr = text(&o.stderr);
        assert!(!o.status.success(), "{example} ran on 2 ranks");
        assert!(stderr.contains(what), "{example}: {stderr}");
        assert!(stderr.contains("does not run on 2 ranks yet"), "{stderr}");
    }
}

/// Spheres falling onto a floor in a box periodic across: Hertz–Mindlin
/// contacts with friction and rolling resistance, and the floor's.
const BED: &str = include_str!("../../mote-md/tests/data/granular-bed.toml");

/// A granular bed with a wall on 2 and 3 ranks writes one process's
/// trajectory byte for byte, and the floor's load to round-off.
#[test]
fn a_granular_bed_on_two_and_three_ranks_writes_one_process_trajectory() {
    let dir = tempfile::tempdir().unwrap();
    let bed = format!("{BED}\n[output]\nobservables_every = 100\ntrajectory_every = 500\n");
    std::fs::write(dir.path().join("bed.toml"), bed).unwrap();
    let args = |out: &'static str| ["run", "bed.toml", "--steps", "1500", "-o", out, "-q"];
    let one = plain(&args("one"), dir.path());
    assert!(one.status.success(), "{}", text(&one.stderr));
    let read = |run: &str| std::fs::read(dir.path().join(run).join("trajectory.xyz")).unwrap();
    let expected = table(&dir.path().join("one/observables.csv"));
    let floor = expected[0].len() - 1;
    assert!(
        expected.last().unwrap()[floor] < -0.5,
        "the bed rests on the floor"
    );
    for ranks in [2, 3] {
        let run = if ranks == 2 { "np2" } else { "np3" };
        let o = mpirun(ranks, &args(run), dir.path());
        assert!(o.status.success(), "{ranks} ranks: {}", text(&o.stderr));
        assert!(
            read("one") == read(run),
            "the bed on {ranks} ranks differs from one process's"
        );
        let got = table(&dir.path().join(run).join("observables.csv"));
        for (g, e) in got.iter().zip(&expected) {
            let (a, b) = (g[floor], e[floor]);
            assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-3), "{a} against {b}");
        }
    }
}

/// A run on three ranks stopped by a signal (mpirun hands it to every
/// rank) writes one checkpoint of the whole state; resumed on two ranks
/// it ends in the one-process run's trajectory, byte for byte.
#[test]
fn a_run_stopped_on_three_ranks_resumes_on_two() {
    let dir = tempfile::tempdir().unwrap();
    let long = LIQUID
        .replace("steps = 400", "steps = 20000")
        .replace("cells = [10, 8, 6]", "cells = [6, 6, 6]")
        .replace("trajectory_every = 100", "trajectory_every = 500");
    std::fs::write(dir.path().join("long.toml"), long).unwrap();
    let whole = plain(&["run", "long.toml", "-o", "whole", "-q"], dir.path());
    assert!(whole.status.success(), "{}", text(&whole.stderr));

    let child = Command::new("mpirun")
        .args(["--allow-run-as-root", "--oversubscribe", "-np", "3"])
        .arg(env!("CARGO_BIN_EXE_mote"))
        .args(["run", "long.toml", "-o", "cut", "--checkpoint-every", "200"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mpirun runs");
    let cp = dir.path().join("cut/checkpoint.mote");
    let start = std::time::Instant::now();
    while mote_io::checkpoint::read(&cp).map_or(true, |c| c.step < 400) {
        assert!(start.elapsed().as_secs() < 120, "no checkpoint at step 400");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let term = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(term.success());
    let stopped = child.wait_with_output().unwrap();
    assert!(!stopped.status.success(), "it finished before the signal");
    let at_stop = mote_io::checkpoint::read(&cp).unwrap();
    assert!(at_stop.step < 20000, "it finished before the signal");
    assert!(
        text(&stopped.stderr).contains("interrupted by signal"),
        "{}",
        text(&stopped.stderr)
    );

    let resumed = mpirun(2, &["run", "--resume", "cut/checkpoint.mote"], dir.path());
    assert!(resumed.status.success(), "{}", text(&resumed.stderr));
    let read = |run: &str| std::fs::read(dir.path().join(run).join("trajectory.xyz")).unwrap();
    assert!(
        read("whole") == read("cut"),
        "the run stopped at step {} on 3 ranks and resumed on 2 is not the whole run",
        at_stop.step
    );
}

/// `[parallel] grid` cuts the box as given; a grid that does not fit the
/// ranks is refused at its line.
#[test]
fn the_scene_can_choose_the_bricks() {
    let dir = tempfile::tempdir().unwrap();
    let with_grid = |grid: &str| format!("{LIQUID}\n[parallel]\ngrid = {grid}\n");
    std::fs::write(dir.path().join("grid.toml"), with_grid("[1, 2, 2]")).unwrap();
    std::fs::write(dir.path().join("bad.toml"), with_grid("[3, 1, 1]")).unwrap();
    // One process reads the table and ignores it.
    let one = plain(&["run", "grid.toml", "-o", "one", "-q"], dir.path());
    assert!(one.status.success(), "{}", text(&one.stderr));
    let o = mpirun(4, &["run", "grid.toml", "-o", "grid"], dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("on 4 ranks (1 × 2 × 2 bricks)"),
        "{}",
        text(&o.stderr)
    );
    let read = |run: &str| std::fs::read(dir.path().join(run).join("trajectory.xyz")).unwrap();
    assert!(
        read("one") == read("grid"),
        "the trajectory on a 1 × 2 × 2 grid"
    );
    let o = mpirun(2, &["run", "bad.toml", "-o", "bad"], dir.path());
    let stderr = text(&o.stderr);
    assert!(!o.status.success());
    let line = LIQUID.lines().count() + 2;
    assert!(
        stderr.contains(&format!(
            "bad.toml:{line}: [parallel] grid: a grid of 3×1×1 bricks for 2 ranks"
        )),
        "{stderr}"
    );
}

/// A scene without a seed on several ranks: the seed rank 0 chose from the
/// clock is every rank's (each builds the scene from it), so the run is one
/// process's with that seed.
#[test]
fn a_chosen_seed_is_every_ranks() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["run", "example:ferrofluid", "--steps", "200"];
    let o = mpirun(2, &[&args[..], &["-o", "ranks"]].concat(), dir.path());
    let opening = text(&o.stderr);
    assert!(o.status.success(), "{opening}");
    let seed = opening
        .split("seed ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .expect("the opening names the seed");
    assert!(opening.contains("(chosen)"), "{opening}");
    let one = plain(
        &[&["--seed", seed], &args[..], &["-o", "one", "-q"]].concat(),
        dir.path(),
    );
    assert!(one.status.success(), "{}", text(&one.stderr));
    let read = |run: &str| std::fs::read(dir.path().join(run).join("trajectory.xyz")).unwrap();
    assert!(read("one") == read("ranks"), "seed {seed}");
}

/// A run that goes unstable on ranks ends every rank at one step, with
/// the message printed once and exit status 3, the files kept.
#[test]
fn an_unstable_run_ends_every_rank_with_one_message() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("hot.toml"),
        LIQUID.replace("dt = 0.005", "dt = 0.5"),
    )
    .unwrap();
    let o = mpirun(3, &["run", "hot.toml", "-o", "hot"], dir.path());
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{stderr}");
    assert_eq!(stderr.matches("error:").count(), 1, "{stderr}");
    assert!(stderr.contains("non-finite"), "{stderr}");
    assert!(dir.path().join("hot/observables.csv").exists());
}
