//! Newton's cradle (002 §4.8) exact to 1e-12: the built-in example scenes.

use mote_edmd::{scene::example, Scene, System};
use std::path::Path;

fn run(name: &str, t: f64) -> System<3> {
    let scene = Scene::parse(example(name).unwrap(), name).unwrap();
    let mut sys: System<3> = scene.build(1, Path::new(".")).unwrap();
    sys.run_until(t);
    assert!(sys.find_overlap(1e-12).is_none());
    sys
}

fn vx(sys: &System<3>) -> Vec<f64> {
    (0..sys.len()).map(|i| sys.velocity(i)[0]).collect()
}

fn assert_close(got: &[f64], want: &[f64]) {
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= 1e-12, "got {got:?}, want {want:?}");
    }
}

#[test]
fn one_ball_in_one_ball_out() {
    // ball 1 strikes at t = 3; ball 5 reaches the wall at t = 6.5
    let sys = run("cradle", 5.0);
    assert_close(&vx(&sys), &[0.0, 0.0, 0.0, 0.0, 1.0]);
    assert_eq!(sys.counters().collisions, 4);
    // all other velocity components stay zero
    for i in 0..5 {
        assert_eq!(&sys.velocity(i)[1..], &[0.0, 0.0]);
    }
    // a full period later (ball 5 back, wall, ball 1 back out and in): period 14
    let sys = run("cradle", 19.0);
    assert_close(&vx(&sys), &[0.0, 0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn two_balls_in_two_balls_out() {
    let sys = run("cradle-two", 4.5);
    assert_close(&vx(&sys), &[0.0, 0.0, 0.0, 1.0, 1.0]);
}

#[test]
fn symmetric_strike_reflects_both() {
    let sys = run("cradle-symmetric", 2.5);
    assert_close(&vx(&sys), &[-1.0, 0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn heavy_first_ball_sends_a_train() {
    let sys = run("cradle-heavy", 3.5);
    let want = [1.0 / 81.0, 4.0 / 81.0, 4.0 / 27.0, 4.0 / 9.0, 4.0 / 3.0];
    assert_close(&vx(&sys), &want);
    let p: f64 = sys.momentum()[0];
    assert!((p - 2.0).abs() < 1e-12);
    assert!((sys.kinetic_energy() - 1.0).abs() < 1e-12);
}
