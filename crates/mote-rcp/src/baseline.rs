//! The straightforward algorithm, as in spherepack1d: F inverted by 100 bisection steps
//! per rod, and gaps kept in a sorted array with linear search and insertion (O(N²) at
//! worst). Kept only as the baseline of the benchmark and as an oracle in tests.

use crate::distribution::SizeDistribution;
use crate::erfc::ErfcFlavour;

/// F⁻¹(y) by 100 bisection steps on [0, 10·1.5^k] (spherepack1d's `inverseF`).
pub fn inverse_cdf_bisection(dist: &SizeDistribution, y: f64, flavour: ErfcFlavour) -> f64 {
    dist.inverse_cdf_bisection(y, flavour)
}

/// The N rods by bisection.
pub fn rod_lengths_bisection(dist: &SizeDistribution, n: usize, flavour: ErfcFlavour) -> Vec<f64> {
    let nf = n as f64;
    (1..=n)
        .map(|i| {
            inverse_cdf_bisection(
                dist,
                (2.0 * nf - 2.0 * i as f64 + 1.0) / (2.0 * nf),
                flavour,
            )
        })
        .collect()
}

/// The packing with a sorted (decreasing) array of gaps: take the first, insert the two
/// new gaps at their place by linear search, shifting the rest.
pub fn pack_sorted_insertion(rods: &[f64], f: f64) -> f64 {
    let n = rods.len();
    // gaps[first..] is decreasing.
    let mut gaps: Vec<f64> = Vec::with_capacity(2 * n);
    gaps.push(f * rods[0]);
    let mut first = 0;
    for &l in &rods[1..] {
        let g = gaps[first];
        first += 1;
        let g1 = f * l;
        let g2 = if (2.0 * f + 1.0) * l >= g {
            g1
        } else {
            g - (f + 1.0) * l
        };
        for new in [g1, g2] {
            if gaps.len() == first || new <= *gaps.last().expect("non-empty") {
                gaps.push(new);
            } else {
                let at = first + gaps[first..].iter().position(|&x| x <= new).expect("found");
                gaps.insert(at, new);
            }
        }
    }
    let lt: f64 = rods.iter().sum();
    let gt: f64 = gaps[first..].iter().sum();
    lt / (lt + gt)
}

/// The whole baseline estimate: bisection rods, then sorted-insertion packing.
pub fn estimate(dist: &SizeDistribution, n: usize, f: f64, flavour: ErfcFlavour) -> f64 {
    pack_sorted_insertion(&rod_lengths_bisection(dist, n, flavour), f)
}
