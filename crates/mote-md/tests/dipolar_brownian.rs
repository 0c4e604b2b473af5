//! Overdamped Brownian dynamics (004 Eqs. 14–16 with thermal noise):
//! free dipoles in a field magnetise as the Langevin function, orientations
//! decorrelate as exp(−2 D_r t), positions spread as 6 D_t t, and a run is
//! the same for every thread count.
//!
//! Reduced units: k_BT = 1, |m| = 1, μ₀ = 1 in the Zeeman energy (so
//! ξ = μ₀ m H / k_BT = H), ξ_t = ξ_r = 1 (D_t = D_r = 1) unless stated.

use std::f64::consts::PI;

use mote_md::brownian::{BrownianStepper, Friction};
use mote_md::force::dipolar::{DipoleDipole, PairRepulsion, Zeeman};
use mote_md::magnetic::{langevin, reduced_magnetisation, OrientationCorrelation};
use mote_md::particles::{ParticleInit, Particles};
use mote_md::{DVec3, ForceField, System};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// n unit dipoles, isotropic orientations, at the origin (they do not interact).
fn free_dipoles(n: usize, seed: u64) -> System {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut p = Particles::default();
    for _ in 0..n {
        // Uniform on the sphere: z = cos θ uniform, φ uniform.
        let z: f64 = rng.gen_range(-1.0..1.0);
        let phi: f64 = rng.gen_range(0.0..2.0 * PI);
        let s = (1.0 - z * z).sqrt();
        p.push(ParticleInit {
            radius: 0.5,
            dipole: DVec3::new(s * phi.cos(), s * phi.sin(), z),
            ..Default::default()
        });
    }
    System::new(p)
}

fn stepper(kt: f64, xi_t: f64, xi_r: f64) -> BrownianStepper {
    BrownianStepper::new(
        kt,
        Friction::Uniform {
            translational: xi_t,
            rotational: xi_r,
        },
    )
}

/// ⟨cos θ⟩ = L(ξ) within 2 % for ξ = 0.5 … 10. Steps are chosen so that the
/// drift per step ξ D_r h ≤ 0.005 (the O(h) bias of Euler–Maruyama) and the
/// run lengths so that the statistical error (printed) is a fraction of
/// the tolerance.
#[test]
fn free_dipoles_magnetise_as_the_langevin_function() {
    let n = 4000;
    // (ξ, step h, equilibration time, sampling time)
    let cases: [(f64, f64, f64, f64); 5] = [
        (0.5, 0.01, 3.0, 70.0),
        (1.0, 0.005, 3.0, 30.0),
        (2.0, 0.0025, 2.0, 8.0),
        (5.0, 0.001, 1.0, 3.0),
        (10.0, 0.0005, 1.0, 2.0),
    ];
    let mut worst: f64 = 0.0;
    for (case, &(xi, h, t_eq, t_run)) in cases.iter().enumerate() {
        let mut sys = free_dipoles(n, 100 + case as u64);
        let mut ff = ForceField::new().with(Zeeman::uniform(1.0, DVec3::Z * xi));
        let mut bd = stepper(1.0, 1.0, 1.0);
        let eq_steps = (t_eq / h).round() as u64;
        let run_steps = (t_run / h).round() as u64;
        for _ in 0..eq_steps {
            let k = sys.step + 1;
            bd.step(&mut sys, &mut ff, h, k, 42);
        }
        // Block averages over blocks of length 1 (≥ 2 relaxation times
        // 1/(2 D_r)) give the statistical error.
        let every = ((0.05 / h).round() as u64).max(1);
        let block_len = (1.0 / h).round() as u64;
        let mut blocks: Vec<f64> = Vec::new();
        let (mut sum, mut count) = (0.0, 0);
        for s in 1..=run_steps {
            let k = sys.step + 1;
            bd.step(&mut sys, &mut ff, h, k, 42);
            if s % every == 0 {
                sum += reduced_magnetisation(&sys.particles.dipole, DVec3::Z);
                count += 1;
            }
            if s % block_len == 0 {
                blocks.push(sum / count as f64);
                (sum, count) = (0.0, 0);
            }
        }
        let nb = blocks.len() as f64;
        let mean = blocks.iter().sum::<f64>() / nb;
        let var = blocks.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (nb - 1.0);
        let err = (var / nb).sqrt();
        let l = langevin(xi);
        let rel = (mean - l) / l;
        println!(
            "ξ = {xi:5}: M/Ms = {mean:.5} ± {err:.5}, L(ξ) = {l:.5}, deviation {:+.2} % ({:.1} σ)",
            100.0 * rel,
            (mean - l) / err
        );
        worst = worst.max(rel.abs());
        assert!(rel.abs() < 0.02, "ξ = {xi}: M/Ms = {mean} ± {err}, L = {l}");
        // Moments keep their length: rotations, not projections.
        for m in &sys.particles.dipole {
            assert!((m.length() - 1.0).abs() < 1e-12);
        }
    }
    println!("worst relative deviation from L(ξ): {:.2} %", 100.0 * worst);
}

/// Free rotational diffusion: C(t) = ⟨u(0)·u(t)⟩ = exp(−2 D_r t), here with
/// D_r = k_BT/ξ_r = 0.5; the fitted D_r agrees within 4 % (≈ 3.5 σ).
/// Translation: ⟨|Δr|²⟩ = 6 D_t t with D_t = k_BT/ξ_t = 2.
#[test]
fn orientations_decorrelate_as_exp_minus_2_dr_t() {
    let n = 10000;
    let (kt, xi_t, xi_r) = (1.0, 0.5, 2.0);
    let (d_t, d_r) = (kt / xi_t, kt / xi_r);
    let h: f64 = 0.002;
    let mut sys = free_dipoles(n, 9);
    let mut ff = ForceField::new();
    let mut bd = stepper(kt, xi_t, xi_r);
    let c = OrientationCorrelation::start(&sys.particles.dipole);
    let r0 = sys.particles.position.clone();
    let checkpoints = [0.1, 0.25, 0.5, 1.0];
    let mut next = 0;
    let total = (1.0 / h).round() as u64;
    for s in 1..=total {
        let k = sys.step + 1;
        bd.step(&mut sys, &mut ff, h, k, 7);
        let t = s as f64 * h;
        if next < checkpoints.len() && (t - checkpoints[next]).abs() < 0.5 * h {
            let value = c.value(&sys.particles.dipole);
            let expected = (-2.0 * d_r * t).exp();
            // Variance of u(0)·u(t) for free diffusion: 1/3 + (2/3) e^{−6 D_r t} − e^{−4 D_r t}.
            let var = 1.0 / 3.0 + 2.0 / 3.0 * (-6.0 * d_r * t).exp() - (-4.0 * d_r * t).exp();
            let sigma = (var / n as f64).sqrt();
            let d_fit = -value.ln() / (2.0 * t);
            println!("t = {t:4}: C = {value:.5}, exp(−2 D_r t) = {expected:.5} (σ = {sigma:.5}), fitted D_r = {d_fit:.4} (exact {d_r})");
            assert!(
                (value - expected).abs() < 4.0 * sigma,
                "t = {t}: C = {value}, expected {expected} ± {sigma}"
            );
            if t <= 0.5 {
                assert!((d_fit / d_r - 1.0).abs() < 0.04, "t = {t}: D_r = {d_fit}");
            }
            next += 1;
        }
    }
    let msd = (0..n)
        .map(|i| (sys.particles.position[i] - r0[i]).length_squared())
        .sum::<f64>()
        / n as f64;
    let expected = 6.0 * d_t * 1.0;
    // Relative standard deviation of the mean of χ²₃ · 2Dt: √(2/3)/√N.
    let sigma = expected * (2.0f64 / 3.0).sqrt() / (n as f64).sqrt();
    println!("MSD(t = 1) = {msd:.4}, 6 D_t t = {expected} (σ = {sigma:.4})");
    assert!((msd - expected).abs() < 4.0 * sigma);
}

/// Interacting dipoles (all pairs + WCA) with a field: the same seed gives
/// the same bits on 1, 2 and 3 threads, and a different seed differs.
#[test]
fn brownian_runs_are_independent_of_the_thread_count() {
    let build = || {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let mut p = Particles::default();
        for i in 0..600 {
            let r = DVec3::new((i % 10) as f64, ((i / 10) % 10) as f64, (i / 100) as f64) * 1.3;
            let m = DVec3::new(
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
            )
            .normalize()
                * 1.2;
            p.push(ParticleInit {
                position: r,
                radius: 0.5,
                dipole: m,
                ..Default::default()
            });
        }
        System::new(p)
    };
    let run = |threads: usize, seed: u64| {
        mote_testkit::on_threads(threads, || {
            let mut sys = build();
            let mut ff = ForceField::new()
                .with(
                    DipoleDipole::all_pairs(4.0 * PI)
                        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
                        .unwrap(),
                )
                .with(Zeeman::uniform(1.0, DVec3::new(0.0, 0.0, 2.0)));
            let mut bd = BrownianStepper::new(
                1.0,
                Friction::Stokes {
                    viscosity: 1.0 / (3.0 * PI),
                },
            );
            for _ in 0..50 {
                let k = sys.step + 1;
                bd.step(&mut sys, &mut ff, 1e-4, k, seed);
            }
            sys
        })
    };
    let one = run(1, 5);
    for threads in [2, 3] {
        let other = run(threads, 5);
        assert_eq!(
            one.particles.position, other.particles.position,
            "{threads} threads"
        );
        assert_eq!(
            one.particles.dipole, other.particles.dipole,
            "{threads} threads"
        );
    }
    assert_ne!(one.particles.position, run(2, 6).particles.position);
}
