//! Conservation laws and the absence of overlaps over many collisions
//! (issue 4: energy and momentum to 1e-12 relative, no overlap ever).

use mote_edmd::{Scene, System};
use std::path::Path;

fn rel_momentum_change<const D: usize>(p0: [f64; D], sys: &System<D>) -> f64 {
    let p1 = sys.momentum();
    let scale: f64 = sys
        .velocities()
        .iter()
        .zip(sys.masses())
        .map(|(v, m)| m * v.iter().map(|x| x * x).sum::<f64>().sqrt())
        .sum();
    (0..D).map(|d| (p1[d] - p0[d]).abs()).fold(0.0, f64::max) / scale
}

/// Bidisperse spheres (size ratio 1.4, masses ∝ volume, so mass ratio 2.74)
/// in a periodic box at η = 0.4: 10⁶ collisions.
#[test]
fn spheres_conserve_energy_and_momentum_over_a_million_collisions() {
    let scene = Scene::parse(
        "[event_driven]\ndimension = 3\nn = 1000\npacking_fraction = 0.40\nlarge_fraction = 0.5\nsize_ratio = 1.4\ntemperature = 1.0\n",
        "test",
    )
    .unwrap();
    let mut sys: System<3> = scene.build(7, Path::new(".")).unwrap();
    let e0 = sys.kinetic_energy();
    let p0 = sys.momentum();
    let mut max_de: f64 = 0.0;
    for _ in 0..10 {
        sys.run_collisions(100_000);
        max_de = max_de.max(((sys.kinetic_energy() - e0) / e0).abs());
        assert!(
            sys.find_overlap(1e-9).is_none(),
            "overlap at t = {}",
            sys.time()
        );
    }
    let dp = rel_momentum_change(p0, &sys);
    println!(
        "10^6 collisions, t = {:.3}: max |dE/E| = {max_de:.2e}, |dP|/sum m|v| = {dp:.2e}",
        sys.time()
    );
    assert!(sys.counters().collisions >= 1_000_000);
    assert!(max_de < 1e-12, "energy drift {max_de:e}");
    assert!(dp < 1e-12, "momentum drift {dp:e}");
    assert!(sys.find_overlap_all_pairs(1e-9).is_none());
}

/// Disks with a wall on y and periodic x: energy conserved, and the
/// x-momentum (the periodic axis) too.
#[test]
fn disks_with_walls_conserve_energy_and_periodic_momentum() {
    let scene = Scene::parse(
        "[event_driven]\ndimension = 2\nn = 2000\npacking_fraction = 0.6\nplacement = \"cubic\"\nlarge_fraction = 0.3\nsize_ratio = 1.2\n[box]\nperiodic = [true, false]\n",
        "test",
    )
    .unwrap();
    let mut sys: System<2> = scene.build(11, Path::new(".")).unwrap();
    let e0 = sys.kinetic_energy();
    let px0 = sys.momentum()[0];
    for _ in 0..5 {
        sys.run_collisions(100_000);
        assert!(
            sys.find_overlap(1e-9).is_none(),
            "overlap at t = {}",
            sys.time()
        );
    }
    let de = ((sys.kinetic_energy() - e0) / e0).abs();
    let scale: f64 = sys
        .velocities()
        .iter()
        .zip(sys.masses())
        .map(|(v, m)| m * (v[0] * v[0] + v[1] * v[1]).sqrt())
        .sum();
    let dpx = (sys.momentum()[0] - px0).abs() / scale;
    println!(
        "disks: |dE/E| = {de:.2e}, |dPx|/sum m|v| = {dpx:.2e}, wall hits = {}",
        sys.counters().wall_hits
    );
    assert!(sys.counters().wall_hits > 0);
    assert!(de < 1e-12);
    assert!(dpx < 1e-12);
    assert!(sys.find_overlap_all_pairs(1e-9).is_none());
}

/// The same seed gives the same trajectory, bit for bit.
#[test]
fn runs_are_reproducible() {
    let scene = Scene::parse(
        "[event_driven]\ndimension = 3\nn = 500\npacking_fraction = 0.3\n",
        "test",
    )
    .unwrap();
    let run = || {
        let mut s: System<3> = scene.build(3, Path::new(".")).unwrap();
        s.run_until(5.0);
        (s.positions(), s.velocities(), s.counters().collisions)
    };
    assert_eq!(run(), run());
}
