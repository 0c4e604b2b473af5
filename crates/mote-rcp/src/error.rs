//! Errors of the rod-packing estimator.

use thiserror::Error;

/// What can be wrong with a size distribution or a packing request.
///
/// The messages name the offending population (counted from 1, in input order)
/// and say what would be right.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RcpError {
    /// A distribution needs at least one population.
    #[error("the size distribution has no populations; give at least one")]
    NoPopulations,
    /// Every number must be finite.
    #[error("population {index}: {what} is {value}, which is not a finite number")]
    NotFinite {
        /// Population number, from 1.
        index: usize,
        /// Which quantity.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// Diameters (and d43, d32) must be strictly positive.
    #[error("population {index}: {what} is {value}; need a strictly positive value")]
    NonPositiveDiameter {
        /// Population number, from 1.
        index: usize,
        /// Which quantity (`diameter`, `d43`, `d32`).
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A lognormal population needs d32 ≤ d43 (003, Eq. 13: e^(σ²) = d43/d32 ≥ 1).
    #[error("population {index}: d32 = {d32} exceeds d43 = {d43}; need 0 < d32 <= d43")]
    D32AboveD43 {
        /// Population number, from 1.
        index: usize,
        /// Volume-weighted mean diameter.
        d43: f64,
        /// Surface-weighted mean diameter.
        d32: f64,
    },
    /// Log-widths are non-negative.
    #[error("population {index}: sigma = {sigma}; need sigma >= 0")]
    NegativeSigma {
        /// Population number, from 1.
        index: usize,
        /// The width given.
        sigma: f64,
    },
    /// Occluded volumes are non-negative.
    #[error("population {index}: volume = {volume}; need a non-negative volume")]
    NegativeVolume {
        /// Population number, from 1.
        index: usize,
        /// The volume given.
        volume: f64,
    },
    /// At least one population must have a positive volume.
    #[error("all occluded volumes are zero; at least one must be greater than zero")]
    NoPositiveVolume,
    /// The rod packing needs N ≥ 2 rods.
    #[error("{n} rods requested; the rod packing needs at least 2")]
    TooFewRods {
        /// The number requested.
        n: usize,
    },
    /// The gap fraction f must be finite and non-negative.
    #[error("gap fraction f = {f}; need a finite f >= 0 (0.7654 for spheres)")]
    BadGapFraction {
        /// The value given.
        f: f64,
    },
    /// Rods given to [`crate::pack_rods`] must be finite, non-negative and non-increasing.
    #[error("rod {index} has length {length}: rods must be finite, >= 0 and non-increasing")]
    BadRod {
        /// Rod number, from 1.
        index: usize,
        /// Its length.
        length: f64,
    },
    /// A design problem is ill-posed (see the message).
    #[error("{0}")]
    Design(String),
    /// The rods cannot resolve the distribution (see the message).
    #[error("{0}")]
    Unresolved(String),
}
