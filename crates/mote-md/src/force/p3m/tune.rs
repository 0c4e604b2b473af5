//! Choosing P3M's parameters from the RMS force error asked for, as
//! ESPResSo's tuning does (Deserno & Holm 1998, §4; Cerdà et al. 2008 for
//! dipoles): for each cut-off r_c and assignment order p, α makes the
//! real-space error δ/√2 (Kolafa & Perram 1992, Eq. 18 for charges; Wang &
//! Holm 2001, Eq. 33 for dipoles), and the mesh is the smallest whose
//! k-space error (the optimal-influence-function estimate of
//! [`super::influence`]) is at most δ/√2; of these, the cheapest by a cost
//! model of the three parts:
//!
//!   cost = c_pair N n_pairs + c_point N (2 p³) + c_fft n_fft M log₂ M,
//!
//! n_pairs = (4π/3)(r_c + skin)³ ρ the neighbours of a particle, M the mesh
//! points, n_fft the 3-D transforms of a force evaluation (3 for charges,
//! 7 for dipoles). The constants are the per-pair, per-assigned-point and
//! per-point-and-level costs measured on the molten-salt and dipolar-fluid
//! benchmarks (BENCHMARKS.md); they fix the choice, so a scene gives the
//! same parameters on every machine.

use glam::DVec3;

use super::influence::{kspace_error, Aliases, Kernel};
use super::spline::MAX_ORDER;
use crate::force::ewald::{charge_real_error, dipole_real_error, solve_alpha};

/// Seconds per mesh point and binary level of one 3-D transform.
const FFT_COST: f64 = 0.6e-9;

/// What the mesh carries: charges or point dipoles, with the sum of their
/// squares (Σq² or Σμ²) the error estimates scale with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    Charges { q2: f64 },
    Dipoles { m2: f64 },
}

impl Source {
    /// Σs², at least the smallest positive number.
    fn strength(self) -> f64 {
        match self {
            Source::Charges { q2 } => q2,
            Source::Dipoles { m2 } => m2,
        }
        .max(f64::MIN_POSITIVE)
    }

    /// The influence function whose error bounds the forces.
    pub fn kernel(self) -> Kernel {
        match self {
            Source::Charges { .. } => Kernel::Charge,
            Source::Dipoles { .. } => Kernel::DipoleForce,
        }
    }

    /// Seconds per listed pair of the real-space rows.
    fn pair_cost(self) -> f64 {
        match self {
            Source::Charges { .. } => 5.0e-9,
            Source::Dipoles { .. } => 12.0e-9,
        }
    }

    /// Seconds per mesh point a particle is assigned to or interpolated
    /// from (dipoles: three components out, nine back).
    fn point_cost(self) -> f64 {
        match self {
            Source::Charges { .. } => 1.9e-9,
            Source::Dipoles { .. } => 5.7e-9,
        }
    }

    /// 3-D transforms per force evaluation.
    fn transforms(self) -> f64 {
        match self {
            Source::Charges { .. } => 3.0,
            Source::Dipoles { .. } => 7.0,
        }
    }

    /// The real-space RMS force error of N sources in a box of `volume`.
    pub fn real_error(self, alpha: f64, cutoff: f64, volume: f64, n: f64) -> f64 {
        let l = volume.cbrt();
        match self {
            Source::Charges { .. } => charge_real_error(alpha, cutoff, l, n, self.strength()),
            Source::Dipoles { .. } => dipole_real_error(alpha, cutoff, l, n, self.strength()),
        }
    }
}

/// The largest mesh side tuning tries (512³ points are 2 GiB a buffer).
const MAX_MESH: usize = 512;

/// Mesh sizes with small prime factors (2, 3, 5), which rustfft transforms
/// fastest, and not multiples of 64: their lines lie a power of two of
/// kilobytes apart and fall into the same cache sets (64³ runs 25 %
/// slower than 60³, which has fewer points by a fifth).
fn nice_sizes() -> Vec<usize> {
    (4..=MAX_MESH)
        .filter(|&m| {
            let mut r = m;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1 && m % 2 == 0 && m % 64 != 0
        })
        .collect()
}

/// What a scene fixes; the rest is tuned.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Request {
    /// The RMS force error aimed at (Gaussian units: force over the
    /// Coulomb constant).
    pub accuracy: f64,
    pub cutoff: Option<f64>,
    pub skin: f64,
    pub mesh: Option<[usize; 3]>,
    pub order: Option<usize>,
}

/// P3M's parameters and their estimated errors (Gaussian units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parameters {
    pub mesh: [usize; 3],
    pub order: usize,
    pub alpha: f64,
    pub cutoff: f64,
    pub real_error: f64,
    pub kspace_error: f64,
}

impl Parameters {
    /// √(δ_real² + δ_k²).
    pub fn estimated_error(&self) -> f64 {
        self.real_error.hypot(self.kspace_error)
    }
}

/// The α at which the real-space error falls to `target`.
fn alpha_for(source: Source, target: f64, cutoff: f64, volume: f64, n: f64) -> f64 {
    solve_alpha(target, cutoff, |a| source.real_error(a, cutoff, volume, n))
}

/// The mesh of `scale` points along the longest side, the others in
/// proportion, each a nice size.
fn mesh_of(scale: usize, cell: DVec3, sizes: &[usize]) -> [usize; 3] {
    let longest = cell.max_element();
    [0, 1, 2].map(|a| {
        let want = (scale as f64 * cell[a] / longest).ceil() as usize;
        *sizes.iter().find(|&&m| m >= want).unwrap_or(&want)
    })
}

/// The cheapest parameters meeting `request.accuracy` for `n` charges or
/// dipoles (`source`) in a periodic box of sides `cell`, or why there are
/// none.
pub fn tune(
    cell: DVec3,
    n: usize,
    source: Source,
    request: &Request,
) -> Result<Parameters, String> {
    let (volume, nf) = (cell.element_product(), n.max(1) as f64);
    let s2 = source.strength();
    let half = 0.5 * cell.min_element();
    let density = nf / volume;
    let spacing = density.powf(-1.0 / 3.0);
    // 2.5 to 5 particle spacings; in a box too small for those (sparse
    // sources), fractions of the largest cut-off the box allows.
    let cutoffs: Vec<f64> = match request.cutoff {
        Some(rc) => vec![rc],
        None => {
            let by_spacing: Vec<f64> = [2.5, 3.0, 3.5, 4.0, 5.0]
                .iter()
                .map(|f| f * spacing)
                .filter(|rc| rc + request.skin <= half)
                .collect();
            if by_spacing.is_empty() {
                [0.6, 0.8, 1.0]
                    .iter()
                    .map(|f| f * (half - request.skin))
                    .filter(|rc| *rc > 0.0)
                    .collect()
            } else {
                by_spacing
            }
        }
    };
    if cutoffs.is_empty() {
        return Err(format!(
            "the box (shortest side {}) leaves no room for a real-space cut-off beside the skin {}",
            2.0 * half,
            request.skin
        ));
    }
    let orders: Vec<usize> = match request.order {
        Some(p) => vec![p],
        None => (3..=MAX_ORDER).collect(),
    };
    let sizes = nice_sizes();
    let part = request.accuracy / std::f64::consts::SQRT_2;
    let mut best: Option<(f64, Parameters)> = None;
    // The cost of the real space and the assignment, and of the FFTs of a
    // mesh of `points`.
    let particle_cost = |cutoff: f64, order: usize| {
        let pairs = 4.0 / 3.0 * std::f64::consts::PI * (cutoff + request.skin).powi(3) * density;
        source.pair_cost() * nf * pairs + source.point_cost() * nf * 2.0 * (order as f64).powi(3)
    };
    let fft_cost = |mesh: [usize; 3]| {
        let points = mesh.iter().product::<usize>() as f64;
        FFT_COST * source.transforms() * points * points.log2()
    };
    // High orders first: they need the smallest meshes, so a good choice
    // is found early and larger meshes are not tried past its cost.
    for &order in orders.iter().rev() {
        for &cutoff in &cutoffs {
            let alpha = alpha_for(source, part, cutoff, volume, nf);
            let error = |mesh: [usize; 3]| {
                kspace_error(
                    source.kernel(),
                    mesh,
                    cell,
                    order,
                    alpha,
                    nf,
                    s2,
                    Aliases::Tuning,
                )
            };
            // What is left for the mesh before this choice costs more
            // than the best so far.
            let budget =
                best.as_ref().map_or(f64::INFINITY, |(c, _)| *c) - particle_cost(cutoff, order);
            if budget <= 0.0 {
                continue;
            }
            let mesh = match request.mesh {
                Some(mesh) => mesh,
                None => {
                    // The smallest scale whose mesh meets δ/√2 (the error
                    // falls as the mesh grows): doubling from the order up
                    // while the mesh's FFTs fit the budget, then bisection
                    // between the last two scales.
                    let affordable = |s: usize| fft_cost(mesh_of(s, cell, &sizes)) < budget;
                    let fits = |s: usize| error(mesh_of(s, cell, &sizes)) <= part;
                    let candidates: Vec<usize> = sizes
                        .iter()
                        .copied()
                        .filter(|&m| m >= order.max(4))
                        .take_while(|&s| affordable(s))
                        .collect();
                    if candidates.is_empty() {
                        continue;
                    }
                    let (mut lo, mut hi) = (0, 0);
                    let found = loop {
                        if fits(candidates[hi]) {
                            break true;
                        }
                        if hi + 1 == candidates.len() {
                            break false;
                        }
                        lo = hi + 1;
                        let want = 2 * candidates[hi];
                        hi = candidates
                            .iter()
                            .position(|&m| m >= want)
                            .unwrap_or(candidates.len() - 1);
                    };
                    if !found {
                        continue;
                    }
                    while lo < hi {
                        let mid = (lo + hi) / 2;
                        if fits(candidates[mid]) {
                            hi = mid;
                        } else {
                            lo = mid + 1;
                        }
                    }
                    mesh_of(candidates[lo], cell, &sizes)
                }
            };
            let cost = particle_cost(cutoff, order) + fft_cost(mesh);
            if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                let candidate = Parameters {
                    mesh,
                    order,
                    alpha,
                    cutoff,
                    real_error: source.real_error(alpha, cutoff, volume, nf),
                    // Tuning's estimate; the solver states the full one.
                    kspace_error: error(mesh),
                };
                best = Some((cost, candidate));
            }
        }
    }
    let (_, best) = best.ok_or_else(|| {
        format!(
            "no mesh up to {0}³ reaches the accuracy {1:e} with these cut-offs: ask for less, or a larger cutoff",
            sizes.last().copied().unwrap_or(0),
            request.accuracy
        )
    })?;
    Ok(best)
}
