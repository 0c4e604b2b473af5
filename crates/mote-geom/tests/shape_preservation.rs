//! The seed's shape-preservation claim (seed 000): "computing the product of
//! any huge number of instances of E will give a result that represents an
//! Euclidean transformation with the same precision as each factor" — the
//! distance between two transformed points stays what it was to 1e-12
//! relative after composing 10⁵ (default) or 10⁷ (ignored) random
//! placements, a quarter of them rotations within 1e-2…1e-12 of π.

use std::f64::consts::PI;

use glam::DVec3;
use mote_geom::{from_axis_angle, E};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn random_placement(rng: &mut Xoshiro256PlusPlus) -> E {
    let z: f64 = rng.gen_range(-1.0..1.0);
    let p: f64 = rng.gen_range(0.0..2.0 * PI);
    let s = (1.0 - z * z).sqrt();
    let n = DVec3::new(s * p.cos(), s * p.sin(), z);
    let phi = match rng.gen_range(0..8) {
        0 | 1 => PI - 10f64.powf(-rng.gen_range(2.0..12.0)),
        2 => PI,
        _ => rng.gen_range(0.0..PI),
    };
    let a = DVec3::new(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    );
    E::new(from_axis_angle(n, phi), a)
}

/// Returns the worst relative distance error over the run, checked every
/// 1000 factors, for the pairs of points of a unit tetrahedron.
fn compose_many(n: usize, seed: u64) -> f64 {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pts = [
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(-0.5, 0.0, 0.0),
        DVec3::new(0.0, 0.8, 0.1),
        DVec3::new(0.1, 0.3, 0.8),
    ];
    let mut g = E::IDENTITY;
    let mut worst: f64 = 0.0;
    for k in 0..n {
        g = g * random_placement(&mut rng);
        if k % 1000 == 999 || k == n - 1 {
            for i in 0..4 {
                for j in 0..i {
                    let d0 = (pts[i] - pts[j]).length();
                    let d = (g.apply_point(pts[i]) - g.apply_point(pts[j])).length();
                    worst = worst.max((d - d0).abs() / d0);
                }
            }
        }
    }
    // The rotation part alone: how far from orthogonal (rounding in the
    // point positions above grows with |a| instead, ~|a|·1e-16).
    let m = g.matrix();
    let ortho = (m.transpose() * m - glam::DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |w, x| w.max(x.abs()));
    eprintln!(
        "{n} placements: worst relative distance error {worst:.2e}, |a| = {:.1}, |MᵀM − 1|max = {ortho:.1e}",
        g.a.length()
    );
    assert!(ortho < 1e-14);
    worst
}

#[test]
fn shape_preserved_1e5() {
    assert!(compose_many(100_000, 1) < 1e-12);
}

#[test]
#[ignore = "10⁷ factors, about a second in release; run with --ignored"]
fn shape_preserved_1e7() {
    assert!(compose_many(10_000_000, 2) < 1e-12);
}
