//! Size distributions and the rod-packing estimator of random close packing.
//!
//! The estimator is the 1-D algorithm of Farr & Groot (J. Chem. Phys. 131, 244104
//! (2009)) as applied to lognormal distributions and their mixtures by Farr (2013,
//! seed 003): a sphere size distribution P3 ([`SizeDistribution`], sums of
//! [`Population`]s) is mapped to a rod-length distribution P1 (003, Eq. 18) whose
//! cumulative F is known in closed form (003, Eqs. 25–26, 34–37); N rods
//! L_i = F⁻¹((2N − 2i + 1)/(2N)) are packed on a periodic line, longest first into the
//! largest gap, with gaps at least f times the shorter neighbour ([`RodPacker`]); the
//! length fraction they fill estimates the random close packing fraction.
//!
//! ```
//! use mote_rcp::{ErfcFlavour, Population, RodPacking, SizeDistribution};
//! // spherepack1d -l with d43 = 2.0, d32 = 0.5 prints 0.829998 (003, help text).
//! let dist = SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap();
//! let est = RodPacking::default().erfc(ErfcFlavour::AbramowitzStegun).estimate(&dist).unwrap();
//! assert_eq!(format!("{:.6}", est.phi), "0.829998");
//! ```
//!
//! The work is O(N log N) for the packing and about one evaluation of F per rod for
//! the inversion (Newton's method with the density P1, swept along the monotone
//! targets); monodisperse mixtures are inverted in closed form.

mod distribution;
mod erfc;
mod error;
mod fit;
mod packing;
pub mod resolution;
mod sizes;

pub mod design;
pub mod heatmap;

#[doc(hidden)]
pub mod baseline;

pub use distribution::{CdfPoint, Population, SizeDistribution};
pub use erfc::{erf_as7126, ErfcFlavour};
pub use error::RcpError;
pub use fit::{lognormal_fit, MONODISPERSE_FIT};
pub use packing::{pack_rods, Packing, RodPacker, SPHERE_GAP_FRACTION};
pub use resolution::Checked;
pub use sizes::SizeSpec;

/// Default number of rods (spherepack1d's default).
pub const DEFAULT_RODS: usize = 16_000;

/// Settings of the rod-packing estimate: number of rods N, gap fraction f and erfc
/// flavour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodPacking {
    /// Number of rods N ≥ 2 (default 16000).
    pub rods: usize,
    /// Gap fraction f ≥ 0 (default 0.7654, spheres).
    pub gap_fraction: f64,
    /// erfc used in F for lognormal populations.
    pub erfc: ErfcFlavour,
}

impl Default for RodPacking {
    fn default() -> Self {
        RodPacking {
            rods: DEFAULT_RODS,
            gap_fraction: SPHERE_GAP_FRACTION,
            erfc: ErfcFlavour::Accurate,
        }
    }
}

impl RodPacking {
    /// With N rods.
    pub fn rods(mut self, n: usize) -> Self {
        self.rods = n;
        self
    }

    /// With gap fraction f.
    pub fn gap_fraction(mut self, f: f64) -> Self {
        self.gap_fraction = f;
        self
    }

    /// With an erfc flavour.
    pub fn erfc(mut self, flavour: ErfcFlavour) -> Self {
        self.erfc = flavour;
        self
    }

    /// The estimate of the random close packing fraction of `dist`.
    pub fn estimate(&self, dist: &SizeDistribution) -> Result<Packing, RcpError> {
        self.estimate_with_progress(dist, |_| {})
    }

    /// As [`estimate`](Self::estimate), calling `progress(rods_done)` every 2¹⁶ rods and
    /// at the end. Rods are generated and packed in one pass, without storing them.
    pub fn estimate_with_progress(
        &self,
        dist: &SizeDistribution,
        mut progress: impl FnMut(usize),
    ) -> Result<Packing, RcpError> {
        packing::check_gap_fraction(self.gap_fraction)?;
        if self.rods < 2 {
            return Err(RcpError::TooFewRods { n: self.rods });
        }
        // Pre-allocate at most 2^24 slots; absurd N then fails by running long, not at once.
        let mut packer = RodPacker::with_capacity(self.gap_fraction, self.rods.min(1 << 24));
        dist.for_each_rod(self.rods, self.erfc, |l| {
            packer.push(l);
            if packer.len() & 0xffff == 0 {
                progress(packer.len());
            }
        });
        progress(packer.len());
        Ok(packer.finish())
    }
}
