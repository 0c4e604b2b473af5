//! Helpers shared by the physics tests.
#![allow(dead_code)]

use mote_md::scene::{Built, Scene};
use mote_md::{Observables, RunLength, Simulation};

/// Builds a scene from TOML text (seed 1).
pub fn build(text: &str) -> Built {
    let scene = Scene::parse(text, "test.toml").unwrap_or_else(|e| panic!("{e}"));
    scene
        .build(text, "test.toml", 1)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Steps `sim` n times, calling `f` after each step.
pub fn steps(sim: &mut Simulation, n: u64, mut f: impl FnMut(&mut Simulation)) {
    for _ in 0..n {
        sim.stepper.step(&mut sim.system, &mut sim.forces, sim.dt);
        f(sim);
    }
}

/// Relative energy error |E − E0|/|E0| at the current state.
pub fn energy_error(sim: &mut Simulation, e0: f64) -> f64 {
    let e = Observables::measure(&sim.system, &mut sim.forces).total_energy();
    ((e - e0) / e0).abs()
}

pub fn run_until(sim: &mut Simulation, t: f64) {
    sim.run(RunLength::Until(t), |_| {}).unwrap();
}

/// A number a careless or hostile user might write in a scene, for the
/// property tests over scene values (`scene_values`, `rigid_scene_values`).
pub use mote_testkit::hostile;
