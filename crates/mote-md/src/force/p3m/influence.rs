//! The optimal influence functions of P3M with ik-differentiation and the
//! RMS force error they leave (Hockney & Eastwood Eq. 8-22; Deserno & Holm
//! 1998, J. Chem. Phys. 109, 7678, Eqs. 29–31 for charges; Cerdà,
//! Ballenegger, Lenz & Holm 2008, J. Chem. Phys. 129, 234104, Eqs. 28–38
//! for dipoles).
//!
//! A law whose force takes n derivatives of the Ewald potential's smooth
//! part φ(k) = 4π e^{−k²/4α²}/k² (n = 1 charges; n = 2 the dipole energy,
//! field and torque; n = 3 the dipole force) is best approximated on the
//! mesh, in the least-squares sense over particle positions, by
//!
//!   G_n(k) = 4π Σ_m Û²(k_m) (D·k_m)ⁿ e^{−k_m²/4α²}/k_m²
//!            / (|D|^{2n} [Σ_m Û²(k_m)]²),
//!
//! k_m = k + 2π(m_x M_x/L_x, …) the aliases, Û(k) = Π_a sinc^p(k_a h_a/2)
//! the transform of the assignment, D(k) = k on the first Brillouin zone
//! (zero on the Nyquist plane of an even mesh, whose derivative has no
//! sign). Without aliasing (Û = 1, D = k) it is the Ewald kernel. The
//! same sums give the error functional
//!
//!   Q_n = Σ_k [16π² Σ_m e^{−k_m²/2α²} k_m^{2(n−2)}
//!              − (4π Σ_m Û² (D·k_m)ⁿ e^{−k_m²/4α²}/k_m²)²/(|D|^{2n} (Σ_m Û²)²)],
//!
//! and the RMS force error of the mesh part is ΔF = Σq² √(Q_1/N)/V for
//! charges (Deserno & Holm Eq. 30) and ΔF = (1/3) Σμ² √(Q_3/N)/V for
//! dipoles of random orientation (Cerdà et al. Eq. 38), Gaussian units.

use glam::DVec3;
use rayon::prelude::*;

use super::spline::sinc;

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;
const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Aliases summed along each axis in G and the error functional (|m| ≤ 2:
/// the next ones are damped by e^{−(2πM·3/L)²/4α²} and Û²).
const ALIASES: i64 = 2;

/// Aliases along one axis in Σ_m Û² (Û² falls as 1/m^{2p}).
const SINC_ALIASES: i64 = 100;

/// What the influence function serves: the number of derivatives of the
/// potential in the force it approximates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// Charges: the field, one derivative.
    Charge,
    /// Dipoles' energy, field and torques: two.
    DipoleEnergy,
    /// Dipoles' forces: three.
    DipoleForce,
}

impl Kernel {
    fn power(self) -> i32 {
        match self {
            Kernel::Charge => 1,
            Kernel::DipoleEnergy => 2,
            Kernel::DipoleForce => 3,
        }
    }

    /// ΔF = prefactor · Σs² √(Q/N)/V (s a charge or a dipole moment).
    fn error_prefactor(self) -> f64 {
        match self {
            Kernel::Charge => 1.0,
            Kernel::DipoleEnergy | Kernel::DipoleForce => 1.0 / 3.0,
        }
    }
}

/// How many aliases the error functional sums.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aliases {
    /// |m| ≤ 2 along each axis, as G.
    Full,
    /// |m| ≤ 1: a fifth of the work, for the many meshes tuning tries
    /// (it agrees with the full sum to 1e-4 on the meshes tested).
    Tuning,
}

impl Aliases {
    /// The slots of [`Axis::alias`] summed.
    fn range(self) -> std::ops::Range<usize> {
        match self {
            Aliases::Full => 0..(2 * ALIASES + 1) as usize,
            Aliases::Tuning => (ALIASES - 1) as usize..(ALIASES + 2) as usize,
        }
    }
}

/// The sums over aliases of one axis, at each of its mesh indices.
pub(super) struct Axis {
    /// D_a(n): k_a on the first Brillouin zone, 0 on the Nyquist plane.
    pub derivative: Vec<f64>,
    /// Σ_m Û_a²(k_{a,m}) over all aliases that matter.
    pub sinc_sum: Vec<f64>,
    /// Per alias |m| ≤ ALIASES: k_{a,m}, Û_a², e^{−k_{a,m}²/4α²}.
    alias: Vec<[(f64, f64, f64); (2 * ALIASES + 1) as usize]>,
}

impl Axis {
    pub fn new(m: usize, length: f64, order: usize, alpha: f64) -> Self {
        let p2 = 2 * order as i32;
        let (mut derivative, mut sinc_sum, mut alias) = (vec![], vec![], vec![]);
        for n in 0..m {
            let signed = signed_index(n, m);
            derivative.push(derivative_at(n, m, length));
            let u2 = |a: i64| {
                sinc(std::f64::consts::PI * (signed + a * m as i64) as f64 / m as f64).powi(p2)
            };
            sinc_sum.push((-SINC_ALIASES..=SINC_ALIASES).map(u2).sum());
            let mut row = [(0.0, 0.0, 0.0); (2 * ALIASES + 1) as usize];
            for (slot, a) in row.iter_mut().zip(-ALIASES..=ALIASES) {
                let km = TWO_PI * (signed + a * m as i64) as f64 / length;
                *slot = (km, u2(a), (-km * km / (4.0 * alpha * alpha)).exp());
            }
            alias.push(row);
        }
        Self {
            derivative,
            sinc_sum,
            alias,
        }
    }
}

/// n ∈ [0, M) as the signed index in [−M/2, M/2).
pub(super) fn signed_index(n: usize, m: usize) -> i64 {
    let (n, m) = (n as i64, m as i64);
    if n < (m + 1) / 2 {
        n
    } else {
        n - m
    }
}

/// D_a at index n of an axis of m points and length L: 2π n'/L, n' the
/// signed index, and 0 on the Nyquist plane of an even mesh.
pub(super) fn derivative_at(n: usize, m: usize, length: f64) -> f64 {
    let signed = signed_index(n, m);
    if m.is_multiple_of(2) && signed == -(m as i64) / 2 {
        0.0
    } else {
        TWO_PI * signed as f64 / length
    }
}

/// The optimal influence function of `kernel` on the whole mesh
/// (x-major), and the error functional Q with every alias G sums (see
/// [`kspace_error`]), from the same sums. G is even in each of n_x, n_y,
/// n_z (n → −n takes the aliases m → −m), so it is computed on one
/// octant, 0 ≤ n_a ≤ M_a/2, and mirrored: exactly even, as the field's
/// transform must be to come back real.
pub(super) fn influence(
    dims: [usize; 3],
    cell: DVec3,
    order: usize,
    alpha: f64,
    kernel: Kernel,
) -> (Vec<f64>, f64) {
    let axes = [0, 1, 2].map(|a| Axis::new(dims[a], cell[a], order, alpha));
    let half = dims.map(|m| m / 2 + 1);
    let octant: Vec<(f64, f64)> = (0..half[0] * half[1] * half[2])
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let n = [
                i / (half[1] * half[2]),
                (i / half[2]) % half[1],
                i % half[2],
            ];
            let (g, e) = influence_at(&axes, n, kernel, Aliases::Full);
            // The points off a symmetry plane stand for two along that axis.
            let weight: f64 = (0..3)
                .map(|a| {
                    if n[a] != 0 && 2 * n[a] != dims[a] {
                        2.0
                    } else {
                        1.0
                    }
                })
                .product();
            (g, weight * e)
        })
        .collect();
    let error = octant.iter().map(|(_, e)| e).sum();
    let fold = |i: usize, m: usize| i.min(m - i);
    let [_, my, mz] = dims;
    let g = (0..dims.iter().product::<usize>())
        .into_par_iter()
        .with_min_len(4096)
        .map(|idx| {
            let (ix, iy, iz) = (idx / (my * mz), (idx / mz) % my, idx % mz);
            let (fx, fy, fz) = (fold(ix, dims[0]), fold(iy, my), fold(iz, mz));
            octant[(fx * half[1] + fy) * half[2] + fz].0
        })
        .collect();
    (g, error)
}

/// G and the error summand at one mesh point.
fn influence_at(axes: &[Axis; 3], n: [usize; 3], kernel: Kernel, aliases: Aliases) -> (f64, f64) {
    if n == [0, 0, 0] {
        return (0.0, 0.0);
    }
    let d = DVec3::new(
        axes[0].derivative[n[0]],
        axes[1].derivative[n[1]],
        axes[2].derivative[n[2]],
    );
    let power = kernel.power();
    let m = aliases.range();
    let (ax, ay, az) = (
        &axes[0].alias[n[0]][m.clone()],
        &axes[1].alias[n[1]][m.clone()],
        &axes[2].alias[n[2]][m],
    );
    // N = Σ_m Û² (D·k_m)ⁿ e/k_m² and Σ_m e² k_m^{2(n−2)} (the reference
    // force's square over 16π²).
    let (mut numerator, mut reference) = (0.0, 0.0);
    for &(kx, ux, ex) in ax {
        for &(ky, uy, ey) in ay {
            let (uxy, exy) = (ux * uy, ex * ey);
            for &(kz, uz, ez) in az {
                let k2 = kx * kx + ky * ky + kz * kz;
                let e = exy * ez;
                let dk = d.x * kx + d.y * ky + d.z * kz;
                numerator += uxy * uz * dk.powi(power) * e / k2;
                reference += e * e * k2.powi(power - 2);
            }
        }
    }
    let sum_u2 = axes[0].sinc_sum[n[0]] * axes[1].sinc_sum[n[1]] * axes[2].sinc_sum[n[2]];
    let d2n = d.length_squared().powi(power);
    if d2n == 0.0 {
        return (0.0, FOUR_PI * FOUR_PI * reference);
    }
    let g = FOUR_PI * numerator / (d2n * sum_u2 * sum_u2);
    let lost = FOUR_PI * FOUR_PI * (reference - numerator * numerator / (d2n * sum_u2 * sum_u2));
    (g, lost)
}

/// Tuning sums meshes up to this many points a side in full, larger ones
/// by a mesh of the same spacing this long ([`kspace_error`]).
const TUNING_SIDE: usize = 48;

/// ΔF from Q for N sources with Σs² = `s2` in a box of volume V.
pub(super) fn rms_error(kernel: Kernel, q: f64, n: f64, s2: f64, volume: f64) -> f64 {
    kernel.error_prefactor() * s2 * (q.max(0.0) / n).sqrt() / volume
}

/// The RMS force error of the mesh part of `kernel` for N sources with
/// Σs² = `s2` (charges q or dipole moments μ) in a box `cell`, Gaussian
/// units (Deserno & Holm Eq. 30; Cerdà et al. Eq. 38).
///
/// The summand is even in each of n_x, n_y, n_z (n → −n takes the
/// aliases m → −m), so the sum runs over one octant, 0 ≤ n_a ≤ M_a/2,
/// the points off a symmetry plane counted twice along that axis.
///
/// With [`Aliases::Tuning`], a mesh longer than 48 points (`TUNING_SIDE`)
/// is summed on a mesh of the same spacing h and at most that many points
/// a side, in a box shrunk to match, and the sum scaled by the ratio of
/// the points: the summand depends on k, h and α alone, and the two sums
/// are Riemann sums of one integral over the Brillouin zone, one on a
/// finer grid of k (they agree to 10⁻⁴ on 60³ to 120³, tested to 1 %).
#[allow(clippy::too_many_arguments)]
pub fn kspace_error(
    kernel: Kernel,
    dims: [usize; 3],
    cell: DVec3,
    order: usize,
    alpha: f64,
    n: f64,
    s2: f64,
    aliases: Aliases,
) -> f64 {
    let longest = *dims.iter().max().unwrap_or(&1);
    let q = if aliases == Aliases::Tuning && longest > TUNING_SIDE {
        let scale = TUNING_SIDE as f64 / longest as f64;
        let small = dims.map(|m| ((m as f64 * scale).round() as usize).max(order + 1));
        let box_small = DVec3::new(
            cell.x * small[0] as f64 / dims[0] as f64,
            cell.y * small[1] as f64 / dims[1] as f64,
            cell.z * small[2] as f64 / dims[2] as f64,
        );
        let points = |d: [usize; 3]| d.iter().product::<usize>() as f64;
        error_sum(kernel, small, box_small, order, alpha, aliases) * points(dims) / points(small)
    } else {
        error_sum(kernel, dims, cell, order, alpha, aliases)
    };
    rms_error(kernel, q, n, s2, cell.element_product())
}

/// Q over one octant.
fn error_sum(
    kernel: Kernel,
    dims: [usize; 3],
    cell: DVec3,
    order: usize,
    alpha: f64,
    aliases: Aliases,
) -> f64 {
    let axes = [0, 1, 2].map(|a| Axis::new(dims[a], cell[a], order, alpha));
    // The octant's indices along an axis and their multiplicities.
    let half = |m: usize| -> Vec<(usize, f64)> {
        (0..=m / 2)
            .map(|i| {
                let mirrored = i != 0 && 2 * i != m;
                (i, if mirrored { 2.0 } else { 1.0 })
            })
            .collect()
    };
    let (hx, hy, hz) = (half(dims[0]), half(dims[1]), half(dims[2]));
    hx.par_iter()
        .map(|&(ix, wx)| {
            let mut sum = 0.0;
            for &(iy, wy) in &hy {
                for &(iz, wz) in &hz {
                    sum += wx * wy * wz * influence_at(&axes, [ix, iy, iz], kernel, aliases).1;
                }
            }
            sum
        })
        .collect::<Vec<_>>()
        .iter()
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tuning's estimate (aliases |m| ≤ 1, a large mesh summed on a
    /// smaller one of the same spacing) against the full sum.
    #[test]
    fn tuning_estimate_is_close_to_the_full_one() {
        let cell = DVec3::new(40.0, 40.0, 30.0);
        for kernel in [Kernel::Charge, Kernel::DipoleForce] {
            for (dims, order, alpha) in [
                ([96, 96, 72], 5, 1.0),
                ([60, 60, 45], 3, 0.7),
                ([120, 120, 90], 7, 1.4),
            ] {
                let error = |aliases| {
                    kspace_error(kernel, dims, cell, order, alpha, 1000.0, 1000.0, aliases)
                };
                let (full, tuning) = (error(Aliases::Full), error(Aliases::Tuning));
                let ratio = tuning / full;
                println!("{kernel:?} {dims:?} order {order}: tuning / full = {ratio:.4}");
                assert!(
                    (ratio - 1.0).abs() < 0.02,
                    "{kernel:?} {dims:?} order {order}: {tuning:e} vs {full:e}"
                );
            }
        }
    }
}
