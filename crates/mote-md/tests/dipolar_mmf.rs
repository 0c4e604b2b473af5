//! Validation (ignored: a few CPU-minutes): the magnetisation curve of an
//! interacting ferrofluid against the second-order modified mean-field
//! theory (MMF2) of Ivanov & Kuznetsova, PRE 64, 041405 (2001).
//!
//! ESPResSo's ferrofluid tutorial (part 3): N = 1000 WCA spheres (σ = ε = 1),
//! volume fraction φ = 0.0262, coupling λ = μ₀m²/(4πσ³k_BT) = 3 at k_BT = 1,
//! so χ_L = 8λφ = 0.629. Here: overdamped Brownian dynamics (ξ_t = ξ_r = 1,
//! h = 0.001), dipoles summed by minimum image with a cut-off r_c = 7 σ (skin
//! 1.5 σ: Brownian steps would rebuild a thin-skinned list every few steps) and a
//! conducting reaction field (ε_RF = ∞, the cut-off analogue of the tin-foil
//! Ewald sum the tutorial and MMF2 assume). The Zeeman energy is −m·H with
//! α = mH/k_BT. Statistical errors from block averages (12 blocks of 1 τ after 3 τ of equilibration,
//! τ = time unit σ²ξ_t/k_BT).
//!
//! `cargo test -p mote-md --test md dipolar_mmf:: -- --ignored --nocapture`

use std::f64::consts::PI;

use mote_md::brownian::{BrownianStepper, Friction};
use mote_md::force::dipolar::{DipoleDipole, PairRepulsion, Zeeman};
use mote_md::magnetic::{
    clusters, langevin, langevin_susceptibility, mmf2_magnetisation, reduced_magnetisation,
    BondCriterion, ClusterStatistics,
};
use mote_md::particles::{ParticleInit, Particles};
use mote_md::{Boundary, DVec3, ForceField, System};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const N: usize = 1000;
const PHI: f64 = 0.0262;
const LAMBDA: f64 = 3.0;

fn ferrofluid(seed: u64) -> System {
    let l = (N as f64 * PI / 6.0 / PHI).cbrt();
    let boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(l));
    let m = LAMBDA.sqrt();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut pos: Vec<DVec3> = Vec::new();
    while pos.len() < N {
        let r = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * l;
        if pos
            .iter()
            .all(|q| boundary.minimum_image(*q - r).length() > 1.0)
        {
            pos.push(r);
        }
    }
    let mut p = Particles::default();
    for r in pos {
        let z: f64 = rng.gen_range(-1.0..1.0);
        let phi: f64 = rng.gen_range(0.0..2.0 * PI);
        let s = (1.0 - z * z).sqrt();
        p.push(ParticleInit {
            position: r,
            radius: 0.5,
            dipole: DVec3::new(s * phi.cos(), s * phi.sin(), z) * m,
            ..Default::default()
        });
    }
    let mut sys = System::new(p);
    sys.boundary = boundary;
    sys
}

#[test]
#[ignore = "validation, a few CPU-minutes"]
fn magnetisation_curve_follows_mmf2() {
    let chi_l = langevin_susceptibility(LAMBDA, PHI);
    let h = 0.001;
    println!("χ_L = {chi_l:.4}");
    println!("  α    M/Ms (sim)        Langevin   MMF2     (sim−MMF2)/σ   ⟨cluster⟩_w  bonded");
    for (case, alpha) in [0.5, 1.0, 2.0, 4.0, 8.0].into_iter().enumerate() {
        let mut sys = ferrofluid(10 + case as u64);
        let mut ff = ForceField::new()
            .with(
                DipoleDipole::cut_off(4.0 * PI, 7.0, 1.5, sys.boundary)
                    .unwrap()
                    .with_reaction_field(f64::INFINITY)
                    .with_repulsion(PairRepulsion::wca(1.0, 1.0))
                    .unwrap(),
            )
            .with(Zeeman::uniform(1.0, DVec3::Z * (alpha / LAMBDA.sqrt())));
        let mut bd = BrownianStepper::new(
            1.0,
            Friction::Uniform {
                translational: 1.0,
                rotational: 1.0,
            },
        );
        for _ in 0..(3.0 / h) as u64 {
            let k = sys.step + 1;
            bd.step(&mut sys, &mut ff, h, k, 2024);
        }
        let (every, block) = (50u64, 1000u64);
        let mut blocks = Vec::new();
        let (mut sum, mut count) = (0.0, 0);
        let mut weight_size = 0.0;
        let mut bonded = 0.0;
        let criterion = BondCriterion::head_to_tail(1.0, 1.0, 4.0 * PI);
        let steps = (12.0 / h) as u64;
        for s in 1..=steps {
            let k = sys.step + 1;
            bd.step(&mut sys, &mut ff, h, k, 2024);
            if s % every == 0 {
                sum += reduced_magnetisation(&sys.particles.dipole, DVec3::Z);
                count += 1;
            }
            if s % block == 0 {
                blocks.push(sum / count as f64);
                (sum, count) = (0.0, 0);
                let stats = ClusterStatistics::of(&clusters(
                    &sys.particles.position,
                    &sys.particles.dipole,
                    &sys.boundary,
                    &criterion,
                ));
                weight_size += stats.weight_mean_size;
                bonded += stats.fraction_bonded;
            }
        }
        let nb = blocks.len() as f64;
        let mean = blocks.iter().sum::<f64>() / nb;
        let err = (blocks.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (nb - 1.0) / nb).sqrt();
        let mmf = mmf2_magnetisation(alpha, chi_l);
        println!(
            "{alpha:4}  {mean:.4} ± {err:.4}   {:.4}     {mmf:.4}   {:+.1}          {:.2}        {:.3}",
            langevin(alpha),
            (mean - mmf) / err,
            weight_size / nb,
            bonded / nb
        );
        assert!(
            mean > langevin(alpha),
            "α = {alpha}: below the Langevin curve"
        );
        assert!(
            (mean - mmf).abs() < 4.0 * err + 0.02 * mmf,
            "α = {alpha}: {mean} ± {err} vs MMF2 {mmf}"
        );
    }
}
