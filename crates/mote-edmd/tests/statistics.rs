//! Statistical physics: Maxwell–Boltzmann speeds (KS test), equations of
//! state (Carnahan–Starling, Henderson) and the Enskog collision rate.
//!
//! Each comparison prints its numbers (run with `--nocapture`). Tolerances:
//! the issue asks for 1 % (EOS) and 2 % (Enskog); each test also asserts that
//! its own standard error (from 10 independent time blocks) is at most a
//! quarter of the tolerance, so a pass is a ≥ 4σ statement, not luck.

use mote_edmd::{scene::example, theory, Scene, System};
use std::path::Path;

/// Compressibility factor: mean and standard error over `blocks` windows of
/// length `tau` after `equil`.
fn z_blocks<const D: usize>(
    sys: &mut System<D>,
    equil: f64,
    blocks: usize,
    tau: f64,
) -> (f64, f64) {
    sys.run_until(equil);
    let mut z = Vec::new();
    for _ in 0..blocks {
        sys.reset_counters();
        let t = sys.time() + tau;
        sys.run_until(t);
        z.push(sys.compressibility());
    }
    let m = z.iter().sum::<f64>() / blocks as f64;
    let var = z.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (blocks as f64 - 1.0);
    (m, (var / blocks as f64).sqrt())
}

fn eos_check(dim: usize, n: usize, eta: f64, equil: f64, blocks: usize, tau: f64) {
    let text = format!(
        "[event_driven]\ndimension = {dim}\nn = {n}\npacking_fraction = {eta}\ntemperature = 1.0\n"
    );
    let scene = Scene::parse(&text, "test").unwrap();
    let (z, se, reference, name) = if dim == 3 {
        let mut sys: System<3> = scene.build(42, Path::new(".")).unwrap();
        let (z, se) = z_blocks(&mut sys, equil, blocks, tau);
        assert!(sys.find_overlap(1e-9).is_none());
        (z, se, theory::carnahan_starling(eta), "Carnahan-Starling")
    } else {
        let mut sys: System<2> = scene.build(42, Path::new(".")).unwrap();
        let (z, se) = z_blocks(&mut sys, equil, blocks, tau);
        assert!(sys.find_overlap(1e-9).is_none());
        (z, se, theory::henderson(eta), "Henderson")
    };
    let dev = (z - reference) / reference;
    println!(
        "D={dim} N={n} eta={eta}: Z = {z:.4} ± {se:.4} (s.e.), {name} {reference:.4}, deviation {:+.3} %",
        100.0 * dev
    );
    assert!(
        se / reference < 0.0025,
        "standard error {se} too large for a 1 % test"
    );
    assert!(dev.abs() < 0.01, "Z = {z} vs {reference}");
}

#[test]
fn spheres_follow_carnahan_starling_small() {
    for eta in [0.2, 0.3, 0.4] {
        eos_check(3, 1372, eta, 5.0, 10, 6.0);
    }
}

#[test]
#[ignore = "N = 4000 version of the issue's check; ~1 min"]
fn spheres_follow_carnahan_starling_n4000() {
    for eta in [0.2, 0.3, 0.4] {
        eos_check(3, 4000, eta, 10.0, 10, 5.0);
    }
}

#[test]
fn disks_follow_henderson() {
    for eta in [0.3, 0.5] {
        eos_check(2, 1600, eta, 5.0, 10, 10.0);
    }
}

#[test]
#[ignore = "N = 10⁴ disks; ~1 min"]
fn disks_follow_henderson_large() {
    for eta in [0.3, 0.5] {
        eos_check(2, 10_000, eta, 10.0, 10, 5.0);
    }
}

/// Collision rate per particle at η = 0.05 against Enskog,
/// Γ = 4 n σ² √(π kT/m) g(σ).
#[test]
fn collision_rate_matches_enskog_at_low_density() {
    let eta = 0.05;
    let scene = Scene::parse(
        &format!("[event_driven]\ndimension = 3\nn = 4000\npacking_fraction = {eta}\ntemperature = 1.0\n"),
        "test",
    )
    .unwrap();
    let mut sys: System<3> = scene.build(5, Path::new(".")).unwrap();
    sys.run_until(10.0);
    let mut rates = Vec::new();
    for _ in 0..10 {
        sys.reset_counters();
        let t = sys.time() + 10.0;
        sys.run_until(t);
        rates.push(sys.collision_rate());
    }
    let m = rates.iter().sum::<f64>() / 10.0;
    let se = (rates.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 90.0).sqrt();
    let n_density = sys.len() as f64 / sys.simbox().volume();
    let enskog = theory::enskog_rate(3, n_density, 1.0, sys.temperature(), 1.0, eta);
    let dev = (m - enskog) / enskog;
    println!(
        "eta={eta}: collision rate {m:.5} ± {se:.5} per particle per unit time, Enskog {enskog:.5}, deviation {:+.3} %, mean free time {:.4}",
        100.0 * dev,
        1.0 / m
    );
    assert!(se / enskog < 0.005);
    assert!(dev.abs() < 0.02);
}

/// 002 §4.9: N = 250 disks, all speeds 1, box 7.5 × 5; after t = 20
/// (≈ 70 collisions per particle) the speeds pass a KS test against
/// f(v) = 2v exp(−v²) (b = 1), and the initial state fails it.
#[test]
fn disk_speeds_relax_to_maxwell_boltzmann() {
    let scene = Scene::parse(example("maxwell2d").unwrap(), "maxwell2d").unwrap();
    let mut sys: System<2> = scene.build(2024, Path::new(".")).unwrap();
    let (d0, p0) = theory::ks_test(&sys.speeds(), |v| theory::maxwell2d_cdf(v, 1.0));
    sys.run_until(20.0);
    let per_particle = 2.0 * sys.counters().collisions as f64 / sys.len() as f64;
    let (d, p) = theory::ks_test(&sys.speeds(), |v| theory::maxwell2d_cdf(v, 1.0));
    // pool 20 snapshots 1 time unit apart for a sharper (but correlated) look
    let mut pooled = Vec::new();
    for k in 1..=20 {
        sys.run_until(20.0 + k as f64);
        pooled.extend(sys.speeds());
    }
    let (dp, _) = theory::ks_test(&pooled, |v| theory::maxwell2d_cdf(v, 1.0));
    println!(
        "2-D MB: initial D = {d0:.3} p = {p0:.2e}; after {per_particle:.0} collisions/particle D = {d:.4} p = {p:.3}; \
         20 pooled snapshots D = {dp:.4}"
    );
    assert!(p0 < 1e-10);
    assert!(p > 0.01, "KS p-value {p}");
    // pooled snapshots: sup-distance below the 1 % critical value for N = 250
    assert!(dp < 1.63 / (250f64).sqrt());
}

#[test]
fn kolmogorov_distribution_values() {
    // textbook critical values: Q(1.36) = 0.049, Q(1.63) = 0.0098
    assert!((theory::kolmogorov_q(1.358) - 0.05).abs() < 1e-3);
    assert!((theory::kolmogorov_q(1.628) - 0.01).abs() < 1e-3);
    assert!((theory::erf(1.0) - 0.8427007929).abs() < 1e-7);
}
