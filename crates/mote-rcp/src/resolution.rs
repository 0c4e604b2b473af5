//! Whether N rods resolve a size distribution.
//!
//! The estimate packs N rods at the quantiles of the rod-length distribution
//! F (003, Eq. 24). Population i contributes rods in proportion to
//! a_i⟨D²⟩_i ∝ v_i/d32_i (003, Eqs. 15–18): of two equal volumes of spheres
//! 10⁵ apart in size the large ones get 10⁻⁵ of the rods, none of the 16 000
//! by default, and the estimate is that of the small spheres alone (0.643485
//! where 0.783 is right). A distribution wide enough that its largest sizes
//! lie beyond the last quantile is cut off likewise (a lognormal of σ = 8
//! gave 0.69 where the estimate tends to 1). Both are caught here: a
//! population with less than one rod is refused before packing, and the
//! estimate is compared with one from N/8 rods — a smooth distribution
//! converges as the rods grow (σ = 1 moves by 2·10⁻⁴ from 2 000 rods to
//! 16 000, about four times its remaining error), one the rods cannot
//! resolve jumps (σ = 5: 0.07).

use crate::distribution::{Population, SizeDistribution};
use crate::error::RcpError;
use crate::{ErfcFlavour, RodPacking};

/// The estimate moves by more than this from N/8 rods to N: refused.
pub const UNRESOLVED: f64 = 0.02;

/// The estimate moves by more than this from N/8 rods to N: a note says
/// the third decimal may be off.
pub const ROUGH: f64 = 1e-3;

/// The expected number of the `n` rods each population contributes,
/// n·(v_i/d32_i)/Σ_j (v_j/d32_j), in logarithms so that sizes 10³⁰⁰ apart
/// give 10⁻³⁰⁰, not 0/0.
pub fn rods_per_population(populations: &[Population], n: usize) -> Vec<f64> {
    let log_share: Vec<f64> = populations
        .iter()
        .map(|p| {
            if p.volume() > 0.0 {
                p.volume().ln() - p.d32().ln()
            } else {
                f64::NEG_INFINITY
            }
        })
        .collect();
    let top = log_share.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let total: f64 = log_share.iter().map(|l| (l - top).exp()).sum();
    log_share
        .iter()
        .map(|l| n as f64 * (l - top).exp() / total)
        .collect()
}

/// Refuses a distribution with a population (of positive volume) that the
/// `n` rods do not see: less than one rod among the populations within a
/// factor of two of its size (d32), so that many close sizes sharing the
/// rods pass (10⁴ populations from 1 to 11 with 4 000 rods) and a size far
/// from the others with no rod of its own does not.
pub fn check_every_population_seen(dist: &SizeDistribution, n: usize) -> Result<(), RcpError> {
    let pops = dist.populations();
    let rods = rods_per_population(pops, n);
    let mut by_size: Vec<(f64, f64)> = pops
        .iter()
        .map(|p| p.d32())
        .zip(rods.iter().cloned())
        .collect();
    by_size.sort_by(|a, b| a.0.total_cmp(&b.0));
    let sizes: Vec<f64> = by_size.iter().map(|x| x.0).collect();
    // prefix sums of the rods in size order
    let mut prefix = vec![0.0];
    for (_, r) in &by_size {
        prefix.push(prefix.last().unwrap() + r);
    }
    let near = |d: f64| {
        let lo = sizes.partition_point(|&s| s < 0.5 * d);
        let hi = sizes.partition_point(|&s| s <= 2.0 * d);
        prefix[hi] - prefix[lo]
    };
    for (k, (p, own)) in pops.iter().zip(&rods).enumerate() {
        let seen = near(p.d32());
        if p.volume() > 0.0 && seen < 1.0 {
            let needed = 10.0 * n as f64 / seen;
            let remedy = if needed <= 1e10 {
                format!("give -N {needed:.0} or more (ten rods for it)")
            } else {
                format!(
                    "no number of rods mote can pack reaches it (ten rods for it need N ≈ {needed:.1e}); \
                     a population's share of the rods goes as its volume over its diameter"
                )
            };
            return Err(RcpError::Unresolved(format!(
                "population {} (d43 = {}, volume {}) gets {own:.2e} of the {n} rods ({seen:.2e} with \
                 the sizes within a factor of two of it), so the estimate would be that of the others \
                 alone; {remedy}",
                k + 1,
                p.d43(),
                p.volume()
            )));
        }
    }
    Ok(())
}

/// A resolved estimate and, where it may be off in its third decimal, a
/// note saying by how much it moved from N/8 rods.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    pub phi: f64,
    pub note: Option<String>,
}

impl RodPacking {
    /// The estimate with its resolution checked: every population seen
    /// ([`check_every_population_seen`]), a packing fraction in (0, 1), and
    /// the estimate from N/8 rods (fast erfc; ≤ 1/8 more work) within
    /// [`UNRESOLVED`] of it — a note beyond [`ROUGH`].
    pub fn checked_estimate(
        &self,
        dist: &SizeDistribution,
        progress: impl FnMut(usize),
    ) -> Result<Checked, RcpError> {
        check_every_population_seen(dist, self.rods)?;
        let phi = self.estimate_with_progress(dist, progress)?.phi;
        let too_wide = |what: String| {
            RcpError::Unresolved(format!(
                "{what}: the distribution is wider than {} rods resolve (or than a 64-bit float \
                 holds); give more rods (-N) or a narrower distribution",
                self.rods
            ))
        };
        if !(phi > 0.0 && phi <= 1.0) {
            return Err(too_wide(format!("the estimate came out as {phi}")));
        }
        let coarse_rods = self.rods / 8;
        if coarse_rods < 2 {
            return Ok(Checked { phi, note: None });
        }
        let coarse = self
            .rods(coarse_rods)
            .erfc(ErfcFlavour::Accurate)
            .estimate(dist)?
            .phi;
        let moved = (phi - coarse).abs();
        if moved.is_nan() || moved > UNRESOLVED {
            return Err(too_wide(format!(
                "the estimate is {phi:.6} from {} rods and {coarse:.6} from {coarse_rods}",
                self.rods
            )));
        }
        let note = (moved > ROUGH).then(|| {
            format!(
                "note: the estimate may be off in its third decimal: it moved by {moved:.1e} from \
                 {coarse_rods} rods to {}; more rods (-N) narrow it",
                self.rods
            )
        });
        Ok(Checked { phi, note })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two(ratio: f64) -> SizeDistribution {
        SizeDistribution::new([
            Population::monodisperse(1.0, 0.5),
            Population::monodisperse(ratio, 0.5),
        ])
        .unwrap()
    }

    /// Two equal volumes 10⁵ apart: the large spheres get 0.16 of 16 000
    /// rods and are refused; with 10⁷ rods they are seen, and the estimate
    /// is the mixture's (0.783), not the small spheres' (0.643).
    #[test]
    fn a_population_without_rods_is_refused() {
        let e = RodPacking::default()
            .checked_estimate(&two(1e5), |_| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains("population 2") && e.contains("-N 1"), "{e}");
        let far = RodPacking::default()
            .checked_estimate(&two(1e300), |_| {})
            .unwrap_err()
            .to_string();
        assert!(far.contains("no number of rods"), "{far}");
        let seen = RodPacking::default()
            .rods(10_000_000)
            .checked_estimate(&two(1e5), |_| {})
            .unwrap();
        assert!((seen.phi - 0.783).abs() < 0.001, "{seen:?}");
        let near = RodPacking::default()
            .checked_estimate(&two(10.0), |_| {})
            .unwrap();
        assert_eq!(near.note, None);
        assert!((near.phi - 0.757901).abs() < 1e-6);
        let close = SizeDistribution::new(
            (0..10_001).map(|k| Population::monodisperse(1.0 + k as f64 * 1e-3, 1.0)),
        )
        .unwrap();
        assert!(check_every_population_seen(&close, 4000).is_ok());
    }

    /// Lognormals: σ = 1 passes quietly, σ = 3 with a note, σ = 6, 8 and
    /// 20 (0.889, 0.694, 0.000000 before) are refused.
    #[test]
    fn a_distribution_wider_than_the_rods_resolve_is_refused() {
        let at = |sigma: f64| {
            RodPacking::default()
                .checked_estimate(&SizeDistribution::lognormal(sigma).unwrap(), |_| {})
        };
        let narrow = at(1.0).unwrap();
        assert!(narrow.note.is_none() && (narrow.phi - 0.80135).abs() < 1e-4);
        let wide = at(3.0).unwrap();
        assert!(wide.note.as_deref().unwrap_or("").contains("third decimal"));
        for sigma in [6.0, 8.0, 20.0] {
            let e = at(sigma).unwrap_err().to_string();
            assert!(e.contains("more rods"), "σ = {sigma}: {e}");
        }
    }
}
