//! A live tap on a run (what `mote view SCENE` uses): it sees frames, its
//! changes reach the next step, and the observables table records each as
//! an event.

use std::sync::{Arc, Mutex};

use mote_front::{Input, RunOptions, Silent};
use mote_run::{Change, FieldKind, Live, LiveSlot, Shown};

const SCENE: &str = r#"
title = "two particles falling under damping and a thermostat"
[run]
integrator = "leapfrog"
dt = 0.001
steps = 40
[field]
g = [0.0, 0.0, -1.0]
[damping]
gamma = 0.5
[thermostat]
kind = "langevin"
gamma = 1.0
kt = 0.1
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 1.0
[output]
observables_every = 10
trajectory_every = 0
"#;

#[derive(Default)]
struct Seen {
    frames: Vec<(u64, f64, usize)>,
    /// The forces shown with each frame.
    forces: Vec<Vec<[f64; 3]>>,
    answers: Vec<(u64, Result<String, String>)>,
}

/// Records every frame it is shown and asks for `changes` once, at step
/// `at`.
struct Tap {
    seen: Arc<Mutex<Seen>>,
    at: u64,
    changes: Vec<Change>,
}

impl Tap {
    fn slot(at: u64, changes: Vec<Change>) -> (Arc<Mutex<Seen>>, LiveSlot) {
        let seen = Arc::new(Mutex::new(Seen::default()));
        let tap = Tap {
            seen: seen.clone(),
            at,
            changes,
        };
        (seen, LiveSlot::new(Box::new(tap)))
    }
}

impl Live for Tap {
    fn between(
        &mut self,
        step: u64,
        time: f64,
        frame: &mut dyn FnMut() -> Option<Shown>,
    ) -> Vec<Change> {
        let shown = frame().expect("the engine shows its particles");
        let mut seen = self.seen.lock().unwrap();
        seen.frames.push((step, time, shown.frame.positions.len()));
        seen.forces.push(shown.forces);
        drop(seen);
        if step == self.at {
            std::mem::take(&mut self.changes)
        } else {
            Vec::new()
        }
    }

    fn answer(&mut self, step: u64, _time: f64, _change: &Change, a: &Result<String, String>) {
        self.seen.lock().unwrap().answers.push((step, a.clone()));
    }
}

#[test]
fn changes_reach_the_next_step_and_are_recorded_as_events() {
    let dir = tempfile::tempdir().unwrap();
    let (seen, live) = Tap::slot(
        20,
        vec![
            Change::Dt(0.002),
            Change::Field {
                kind: FieldKind::Gravity,
                value: [0.0, 0.0, -2.0],
            },
            Change::Damping(0.25),
            Change::Temperature(0.2),
            Change::Field {
                kind: FieldKind::Magnetic,
                value: [1.0, 0.0, 0.0],
            },
        ],
    );
    let options = RunOptions {
        output: Some(dir.path().to_path_buf()),
        seed: Some(3),
        live,
        ..RunOptions::default()
    };
    let input = Input::scene("live", "live.toml", SCENE);
    mote_front::run_input(&input, &options, &mut Silent).unwrap();
    let seen = seen.lock().unwrap();
    // Prime, every step (20 of 0.001 and 20 of 0.002), and step 20 again
    // after its changes.
    assert_eq!(seen.frames.len(), 42);
    assert_eq!(seen.frames[0], (0, 0.0, 2));
    let (step, t, _) = seen.frames[41];
    assert_eq!(step, 40);
    assert!((t - 0.06).abs() < 1e-12, "t = {t}");
    // F = m g at rest after priming (m = 1, g = −1 along z); after the
    // change the shown force has the new gravity (damping −γ v beside it).
    assert_eq!(seen.forces[0], vec![[0.0, 0.0, -1.0]; 2]);
    let last = seen.forces[41][0];
    assert!(last[2] < -1.5 && last[2] > -2.5, "{last:?}");
    let ok: Vec<&String> = seen
        .answers
        .iter()
        .filter_map(|(_, a)| a.as_ref().ok())
        .collect();
    assert_eq!(
        ok,
        [
            "dt 0.001 → 0.002",
            "gravity g (0, 0, -1) → (0, 0, -2)",
            "damping γ 0.5 → 0.25",
            "temperature kT 0.1 → 0.2",
        ]
    );
    let refused = seen.answers[4].1.as_ref().unwrap_err();
    assert!(
        refused.contains("magnetic field: the scene has none"),
        "{refused}"
    );
    let csv = std::fs::read_to_string(dir.path().join("observables.csv")).unwrap();
    let events: Vec<&str> = csv.lines().filter(|l| l.starts_with("# event:")).collect();
    assert_eq!(events.len(), 4, "{csv}");
    assert!(
        events[0].starts_with("# event: step 20, t = 0.0200"),
        "{}",
        events[0]
    );
    assert!(events[0].ends_with(": dt 0.001 → 0.002"), "{}", events[0]);
    // The events sit after the row of step 20 and before the row of step 30.
    let lines: Vec<&str> = csv.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("# event:"))
        .unwrap();
    assert!(
        lines[at - 1].starts_with("2.0000000000000"),
        "{}",
        lines[at - 1]
    );
    assert!(
        lines[at + 4].starts_with("4.0000000000000"),
        "{}",
        lines[at + 4]
    );
}

#[test]
fn a_rigid_run_takes_a_new_field() {
    let dir = tempfile::tempdir().unwrap();
    // B = (0, 0, 2) at step 10, and a temperature the rigid engine lacks.
    let (seen, live) = Tap::slot(
        10,
        vec![
            Change::Field {
                kind: FieldKind::Magnetic,
                value: [0.0, 0.0, 2.0],
            },
            Change::Temperature(1.0),
        ],
    );
    let options = RunOptions {
        output: Some(dir.path().to_path_buf()),
        steps: Some(20),
        live,
        ..RunOptions::default()
    };
    let input = Input::read("example:magnet-in-field").unwrap();
    mote_front::run_input(&input, &options, &mut Silent).unwrap();
    let seen = seen.lock().unwrap();
    assert_eq!(seen.frames.len(), 22);
    assert_eq!(seen.frames[0].2, 3, "the body's three spheres");
    assert_eq!(
        seen.answers[0].1.as_deref(),
        Ok("magnetic field B (0, 1, 0) → (0, 0, 2)")
    );
    let refused = seen.answers[1].1.as_ref().unwrap_err();
    assert!(
        refused.contains("temperature: the scene has none"),
        "{refused}"
    );
    // The force on the body (a uniform B exerts none on a dipole), shown
    // for each of its three spheres once it has stepped.
    assert_eq!(seen.forces[5], vec![[0.0; 3]; 3]);
    let csv = std::fs::read_to_string(dir.path().join("observables.csv")).unwrap();
    assert_eq!(csv.matches("# event: step 10").count(), 1, "{csv}");
}

#[test]
fn a_rigid_run_shows_the_force_on_each_sphere_s_body() {
    let dir = tempfile::tempdir().unwrap();
    let (seen, live) = Tap::slot(u64::MAX, Vec::new());
    let options = RunOptions {
        output: Some(dir.path().to_path_buf()),
        steps: Some(2),
        live,
        ..RunOptions::default()
    };
    let input = Input::read("example:clumps-settling").unwrap();
    mote_front::run_input(&input, &options, &mut Silent).unwrap();
    let seen = seen.lock().unwrap();
    // Before the first step no force was evaluated; after it every sphere
    // shows its body's: m g for the free bodies placed apart, plus contact
    // forces for those touching another or a wall.
    assert!(seen.forces[0].is_empty());
    let forces = &seen.forces[1];
    let dir_frame = mote_io::trajectory::read_frames(&dir.path().join("trajectory.xyz")).unwrap();
    let frame = &dir_frame[0];
    assert_eq!(forces.len(), frame.positions.len());
    let mut body_mass = std::collections::HashMap::new();
    for (b, m) in frame.bodies.iter().zip(&frame.masses) {
        *body_mass.entry(*b).or_insert(0.0) += m;
    }
    let falling = frame
        .bodies
        .iter()
        .zip(forces)
        .filter(|(b, f)| {
            let w = -9.81 * body_mass[b];
            f[0] == 0.0 && f[1] == 0.0 && ((f[2] - w) / w).abs() < 1e-12
        })
        .count();
    assert!(
        falling > forces.len() / 2,
        "{falling} of {} spheres show m g",
        forces.len()
    );
}
