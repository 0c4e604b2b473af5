//! Conservation laws and fixed degrees of freedom.

use crate::common;

use common::*;
use mote_md::{DVec3, Observables};

const CLUSTER: &str = r#"
units = "lj"
seed = 7
[run]
integrator = "leapfrog"
dt = 1e-3
[gravity]
softening = 0.05
[[random_box]]
n = 300
min = [-1.0, -1.0, -1.0]
max = [1.0, 1.0, 1.0]
velocity_sigma = 0.3
mass = 0.01
"#;

/// An isolated gravitating cluster conserves total momentum to 1e-12 of Σ m|v|.
#[test]
fn isolated_cluster_conserves_momentum_and_angular_momentum() {
    let mut sim = build(CLUSTER).simulation;
    let start = Observables::measure(&sim.system, &mut sim.forces);
    let scale: f64 = {
        let p = &sim.system.particles;
        (0..p.len())
            .map(|i| p.mass[i] * p.velocity[i].length())
            .sum()
    };
    let l_scale: f64 = {
        let p = &sim.system.particles;
        (0..p.len())
            .map(|i| p.mass[i] * p.position[i].length() * p.velocity[i].length())
            .sum()
    };
    let mut worst_p = 0.0f64;
    let mut worst_l = 0.0f64;
    steps(&mut sim, 2000, |s| {
        if s.system.step % 50 == 0 {
            let now = Observables::measure(&s.system, &mut s.forces);
            worst_p = worst_p.max((now.momentum - start.momentum).length() / scale);
            worst_l =
                worst_l.max((now.angular_momentum - start.angular_momentum).length() / l_scale);
        }
    });
    assert!(
        worst_p < 1e-12,
        "momentum changed by {worst_p:.3e} of Σ m|v|"
    );
    assert!(worst_l < 1e-12, "angular momentum changed by {worst_l:.3e}");
}

/// The same run on 1 and 2 threads gives bit-identical states.
#[test]
fn thread_count_does_not_change_results() {
    let run = |threads: usize| {
        mote_testkit::on_threads(threads, || {
            let mut sim = build(CLUSTER).simulation;
            steps(&mut sim, 50, |_| {});
            sim.system.particles.position.clone()
        })
    };
    assert_eq!(run(1), run(2));
}

/// A particle with `free = [false, false, false]` (MPPphys `vfix 0 0 0`) never
/// moves, even while everything around it falls onto it.
#[test]
fn fixed_particle_never_moves() {
    let text = format!("{CLUSTER}\n[[particle]]\nposition = [0.3, -0.2, 0.1]\nvelocity = [1.0, 1.0, 1.0]\nmass = 5.0\nfree = [false, false, false]\n");
    let mut sim = build(&text).simulation;
    let k = 0; // [[particle]] tables come first
    let start = sim.system.particles.position[k];
    assert_eq!(sim.system.particles.velocity[k], DVec3::ZERO);
    steps(&mut sim, 500, |s| {
        assert_eq!(s.system.particles.position[k], start);
    });
    // Others did move.
    assert!(
        sim.system.particles.position[1] != build(&text).simulation.system.particles.position[1]
    );
}

/// A particle fixed along z only (`vfix 1 1 0`) stays in its plane.
#[test]
fn fixed_axis_stays_fixed() {
    let text = format!("{CLUSTER}\n[[particle]]\nposition = [0.0, 0.0, 0.7]\nvelocity = [0.1, 0.0, 0.5]\nmass = 0.01\nfree = [true, true, false]\n");
    let mut sim = build(&text).simulation;
    steps(&mut sim, 500, |s| {
        assert_eq!(s.system.particles.position[0].z, 0.7)
    });
    assert!(sim.system.particles.position[0].x > 0.0);
}
