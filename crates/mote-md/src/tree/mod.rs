//! The octree shared by range queries and Barnes–Hut multipole sums.
//!
//! - [`Octree`]: particles sorted along the Morton curve, cells as ranges
//!   of that order; [`Octree::within`] lists the particles in a sphere.
//! - [`Multipole`]: monopole, dipole and quadrupole of a cell's point
//!   sources and point dipoles, with potential and gradient.
//! - [`BarnesHut`]: the group-wise tree walk with opening angle θ, shared by
//!   [`TreeGravity`] and [`TreeCoulomb`] (interactions for a `ForceField`).
//! - [`PlummerSphere`]: initial states (Aarseth, Hénon & Wielen 1974).

#[cfg(target_arch = "x86_64")]
mod avx512;
mod barnes_hut;
mod coulomb;
mod gravity;
pub(crate) mod morton;
mod multipole;
mod octree;
mod plummer;

pub use barnes_hut::{BarnesHut, WalkCounts};
pub use coulomb::TreeCoulomb;
pub use gravity::{direct_field, TreeGravity};
pub use multipole::Multipole;
pub use octree::{Node, Octree};
pub use plummer::PlummerSphere;

/// Statistics of sampled relative force errors |F_tree − F_exact| / |F_exact|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceError {
    /// Number of particles sampled.
    pub samples: usize,
    pub median: f64,
    /// 99th percentile.
    pub p99: f64,
    pub max: f64,
    /// Root mean square.
    pub rms: f64,
}

impl ForceError {
    /// Statistics of the given relative errors (nearest-rank percentiles).
    pub fn from_samples(mut errors: Vec<f64>) -> Self {
        let n = errors.len();
        if n == 0 {
            return Self {
                samples: 0,
                median: 0.0,
                p99: 0.0,
                max: 0.0,
                rms: 0.0,
            };
        }
        errors.sort_by(f64::total_cmp);
        let rank = |p: f64| errors[(((p * n as f64).ceil() as usize).max(1) - 1).min(n - 1)];
        Self {
            samples: n,
            median: rank(0.5),
            p99: rank(0.99),
            max: errors[n - 1],
            rms: (errors.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt(),
        }
    }
}

impl std::fmt::Display for ForceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "relative force error over {} particles: median {:.2e}, 99% {:.2e}, max {:.2e}, rms {:.2e}",
            self.samples, self.median, self.p99, self.max, self.rms
        )
    }
}
