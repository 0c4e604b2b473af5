//! Barnes–Hut gravity against the direct sum on Plummer spheres.
//!
//! Error measure: for each sampled particle the relative force error
//! |a_tree − a_direct| / |a_direct|; we report the median, the 99th
//! percentile and the maximum over the sample.

use mote_md::force::{DirectGravity, Interaction, State};
use mote_md::tree::{PlummerSphere, TreeGravity};
use mote_md::DVec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn plummer(n: usize, seed: u64) -> (Vec<DVec3>, Vec<DVec3>, Vec<f64>) {
    let sphere = PlummerSphere {
        n,
        mass: 1.0,
        radius: 1.0,
        g: 1.0,
        max_radius: Some(20.0),
    };
    let (pos, vel) = sphere.sample(&mut Xoshiro256PlusPlus::seed_from_u64(seed));
    (pos, vel, vec![1.0 / n as f64; n])
}

fn state<'a>(pos: &'a [DVec3], vel: &'a [DVec3], mass: &'a [f64]) -> State<'a> {
    State::new(pos, vel, mass, 0.0)
}

/// θ = 0.5 meets 1e-3 at the 99th percentile, and the error falls with θ.
#[test]
fn force_error_is_small_and_falls_with_theta() {
    let (pos, vel, mass) = plummer(20_000, 7);
    let s = state(&pos, &vel, &mass);
    let mut last = f64::INFINITY;
    for theta in [1.0, 0.7, 0.5, 0.35, 0.25] {
        let mut tree = TreeGravity::new(1.0, 0.01, theta);
        let err = tree.sampled_error(&s, 10);
        let c = tree.counts();
        println!(
            "θ = {theta}: {err}; interactions per particle: {:.0} particle, {:.0} cell",
            c.particle as f64 / pos.len() as f64,
            c.cell as f64 / pos.len() as f64
        );
        if theta == 0.5 {
            assert!(err.p99 < 1e-3, "θ = 0.5: {err}");
        }
        assert!(
            err.median < last,
            "θ = {theta}: median {} after {last}",
            err.median
        );
        last = err.median;
    }
}

/// θ = 0 opens every cell: the direct sum, up to summation order.
#[test]
fn theta_zero_is_the_direct_sum() {
    let (pos, vel, mass) = plummer(3000, 3);
    let s = state(&pos, &vel, &mass);
    let mut tree = TreeGravity::new(1.0, 0.01, 0.0);
    let err = tree.sampled_error(&s, 1);
    assert!(err.max < 1e-13, "{err}");
    assert_eq!(tree.counts().cell, 0);
    let u_tree = tree.potential_energy(&s);
    let u_direct = DirectGravity::new(1.0, 0.01).potential_energy(&s);
    assert!(
        ((u_tree - u_direct) / u_direct).abs() < 1e-13,
        "{u_tree} vs {u_direct}"
    );
}

/// The tree potential energy at θ = 0.5 matches the direct sum, and both
/// match the Plummer model's −3π/32 G M²/a within sampling noise.
#[test]
fn potential_energy_matches_direct_sum_and_model() {
    let (pos, vel, mass) = plummer(20_000, 11);
    let s = state(&pos, &vel, &mass);
    let u_tree = TreeGravity::new(1.0, 0.01, 0.5).potential_energy(&s);
    let u_direct = DirectGravity::new(1.0, 0.01).potential_energy(&s);
    let rel = ((u_tree - u_direct) / u_direct).abs();
    println!("U tree {u_tree:.8}, direct {u_direct:.8}, relative difference {rel:.2e}");
    assert!(rel < 1e-4, "{rel:e}");
    let model = -3.0 * std::f64::consts::PI / 32.0;
    // Softening 0.01 and the cut at 20 a shift U by ~1e-3; sampling noise
    // for N = 2·10⁴ is ~1 %.
    assert!(
        ((u_direct - model) / model).abs() < 0.03,
        "{u_direct} vs {model}"
    );
}

/// Forces are bit-identical on 1 and 2 threads.
#[test]
fn forces_do_not_depend_on_the_thread_count() {
    let (pos, vel, mass) = plummer(30_000, 5);
    let run = |threads: usize| {
        mote_testkit::on_threads(threads, || {
            let s = state(&pos, &vel, &mass);
            let mut tree = TreeGravity::new(1.0, 0.01, 0.5);
            let mut f = vec![DVec3::ZERO; pos.len()];
            tree.add_forces(&s, &mut f);
            let u = tree.potential_energy(&s);
            (f, u)
        })
    };
    let (f1, u1) = run(1);
    let (f2, u2) = run(2);
    let (f3, u3) = run(3);
    assert!(f1 == f2 && f1 == f3, "forces differ between thread counts");
    assert_eq!(u1.to_bits(), u2.to_bits());
    assert_eq!(u1.to_bits(), u3.to_bits());
}

/// The tree does not conserve momentum exactly (forces are not pairwise):
/// the total force stays at the level of the force error.
#[test]
fn total_force_is_small() {
    let (pos, vel, mass) = plummer(20_000, 13);
    let s = state(&pos, &vel, &mass);
    let mut f = vec![DVec3::ZERO; pos.len()];
    TreeGravity::new(1.0, 0.01, 0.5).add_forces(&s, &mut f);
    let total: DVec3 = f.iter().copied().sum();
    let scale: f64 = f.iter().map(|v| v.length()).sum();
    println!("|Σ F| / Σ |F| = {:.2e}", total.length() / scale);
    assert!(total.length() < 1e-4 * scale);
}
