//! Ewald summation for point charges and point dipoles in a periodic box
//! (orthorhombic, sides L_x, L_y, L_z; cubic by default) with tin-foil
//! (conducting) boundary conditions.
//!
//! Gaussian form (prefactor 1; interactions multiply by the unit system's
//! constant, 1/(4πε₀) or μ₀/4π). With splitting parameter α,
//! k = 2π(n_x/L_x, n_y/L_y, n_z/L_z), A(k) = exp(−k²/4α²)/k², V = L_x L_y L_z (Frenkel & Smit, *Understanding
//! Molecular Simulation*, §12.1; dipoles after Wang & Holm 2001, J. Chem.
//! Phys. 115, 6351, Eqs. 5–9):
//!
//! - charges: U = ½ Σ_{i,j,n}' q_i q_j erfc(α r)/r + (2π/V) Σ_{k≠0} A |S(k)|²
//!   − (α/√π) Σ q² − π Q²/(2Vα²), S(k) = Σ q_j e^{ik·r_j}, Q = Σ q (the last
//!   term is the neutralising background, zero for neutral systems);
//! - dipoles: U = ½ Σ' [(μ_i·μ_j) B(r) − (μ_i·r)(μ_j·r) C(r)]
//!   + (2π/V) Σ_{k≠0} A |Σ_j (μ_j·k) e^{ik·r_j}|² − (2α³/3√π) Σ μ²,
//!     B = [erfc(αr) + (2αr/√π) e^{−α²r²}]/r³,
//!     C = [3 erfc(αr) + (2αr/√π)(3 + 2α²r²) e^{−α²r²}]/r⁵,
//!     D = [15 erfc(αr) + (2αr/√π)(15 + 10α²r² + 4α⁴r⁴) e^{−α²r²}]/r⁷,
//!
//! with r = r_i − r_j + (n_x L_x, n_y L_y, n_z L_z) and the prime omitting i = j at n = 0. Forces are
//! −∂U/∂r_i, dipole fields H_i = −∂U/∂μ_i and torques τ_i = μ_i × H_i.
//!
//! Parameters from a requested RMS force error δ (Kolafa & Perram 1992,
//! Mol. Simul. 9, 351, Eqs. 18 and 32, in LAMMPS' form; for dipoles Wang &
//! Holm 2001, Eqs. 38 and 46): for charges, with Q₂ = Σ q²,
//! δ_real = 2 Q₂ e^{−α²r_c²}/√(N r_c L³) = δ/√2 fixes α for the given cut-off r_c,
//! and the smallest integer n_max (k-vectors |k| ≤ k_max = 2π n_max/L) with
//! δ_k = (2 Q₂ α/L) (π n_max N)^{−1/2} e^{−(π n_max/αL)²} ≤ δ/√2; for dipoles,
//! with M₂ = Σ μ², a = α r_c,
//! δ_real = M₂ (N V α⁴ r_c⁹)^{−1/2} [13/6 C² + 2/15 D² − 13/15 C D]^{1/2} e^{−a²},
//! C = 4a⁴ + 6a² + 3, D = 8a⁶ + 20a⁴ + 30a² + 15, and
//! δ_k = (8π M₂ α/V) [2π n_max³/(15 N)]^{1/2} e^{−(π n_max/αL)²}. In a
//! box that is not cubic, L in these estimates is V^{1/3} and the k-vectors
//! fill the sphere |k| ≤ k_max.
//!
//! The real-space sum runs over all pairs and the periodic images within
//! r_c (O(N²); fine up to a few thousand particles). The k-space sum is
//! parallel over k-vectors (structure factors) and over particles (forces),
//! each sum in a fixed order: results do not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::whole::Whole;
use super::{HaloReach, Interaction, Spin, State, Virial};

/// erfc of musl/fdlibm (relative error below 1e-15 on the whole line), the
/// one erfc of the workspace; about 30× faster than the series and continued
/// fraction this module had, inside the real-space pair loop.
use libm::erfc;

const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Ewald parameters for a periodic box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ewald {
    /// Box sides (L_x, L_y, L_z); positions need not be wrapped.
    pub cell: DVec3,
    /// Splitting parameter α.
    pub alpha: f64,
    /// Real-space cut-off r_c.
    pub r_cut: f64,
    /// k-vectors with 0 < |k| ≤ k_max = 2π n_max/V^{1/3}.
    pub n_max: i32,
    /// Estimated RMS force error of the real-space sum (Kolafa–Perram).
    pub real_error: f64,
    /// Estimated RMS force error of the k-space sum.
    pub kspace_error: f64,
}

/// Kolafa–Perram RMS real-space force error for charges (L³ = V).
pub(crate) fn charge_real_error(alpha: f64, rc: f64, l: f64, n: f64, q2: f64) -> f64 {
    2.0 * q2 * (-(alpha * rc).powi(2)).exp() / (n * rc * l.powi(3)).sqrt()
}

fn charge_kspace_error(alpha: f64, nmax: i32, l: f64, n: f64, q2: f64) -> f64 {
    let k = nmax as f64;
    2.0 * q2 * alpha / l / (std::f64::consts::PI * k * n).sqrt()
        * (-(std::f64::consts::PI * k / (alpha * l)).powi(2)).exp()
}

pub(crate) fn dipole_real_error(alpha: f64, rc: f64, l: f64, n: f64, m2: f64) -> f64 {
    let a2 = (alpha * rc).powi(2);
    let c = 4.0 * a2 * a2 + 6.0 * a2 + 3.0;
    let d = 8.0 * a2 * a2 * a2 + 20.0 * a2 * a2 + 30.0 * a2 + 15.0;
    let shape = (13.0 / 6.0 * c * c + 2.0 / 15.0 * d * d - 13.0 / 15.0 * c * d).sqrt();
    m2 / (n * l.powi(3) * alpha.powi(4) * rc.powi(9)).sqrt() * shape * (-a2).exp()
}

fn dipole_kspace_error(alpha: f64, nmax: i32, l: f64, n: f64, m2: f64) -> f64 {
    let k = nmax as f64;
    let pi = std::f64::consts::PI;
    8.0 * pi * m2 * alpha / l.powi(3)
        * (2.0 * pi * k.powi(3) / (15.0 * n)).sqrt()
        * (-(pi * k / (alpha * l)).powi(2)).exp()
}

/// The α ∈ (0, 100/r_c] at which the decreasing `error(α)` falls to
/// `accuracy` (bisection on a log scale).
pub(crate) fn solve_alpha(accuracy: f64, rc: f64, error: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (1e-3 / rc, 100.0 / rc);
    if error(lo) <= accuracy {
        return lo;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if error(mid) > accuracy {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

impl Ewald {
    fn with_errors(
        cell: DVec3,
        rc: f64,
        accuracy: f64,
        real: impl Fn(f64) -> f64,
        kspace: impl Fn(f64, i32) -> f64,
    ) -> Self {
        assert!(
            cell.min_element() > 0.0 && rc > 0.0 && accuracy > 0.0,
            "Ewald: box sides, r_c and accuracy must be positive"
        );
        // Each part gets δ/√2, so that √(δ_real² + δ_k²) ≤ δ.
        let part = accuracy / std::f64::consts::SQRT_2;
        let alpha = solve_alpha(part, rc, &real);
        let mut n_max = 1;
        while kspace(alpha, n_max) > part && n_max < 1000 {
            n_max += 1;
        }
        Self {
            cell,
            alpha,
            r_cut: rc,
            n_max,
            real_error: real(alpha),
            kspace_error: kspace(alpha, n_max),
        }
    }

    /// Parameters for `charge` in a cubic box of side L with real-space
    /// cut-off r_c (L/2 is a good default) and requested RMS force error
    /// `accuracy` (in units of charge²/length², Gaussian prefactor 1).
    pub fn for_charges(box_length: f64, r_cut: f64, accuracy: f64, charge: &[f64]) -> Self {
        Self::for_charges_in(DVec3::splat(box_length), r_cut, accuracy, charge)
    }

    /// [`Ewald::for_charges`] in a box of sides `cell`.
    pub fn for_charges_in(cell: DVec3, r_cut: f64, accuracy: f64, charge: &[f64]) -> Self {
        let n = charge.len().max(1) as f64;
        let q2: f64 = charge.iter().map(|q| q * q).sum();
        let q2 = q2.max(f64::MIN_POSITIVE);
        let l = cell.element_product().cbrt();
        Self::with_errors(
            cell,
            r_cut,
            accuracy,
            |a| charge_real_error(a, r_cut, l, n, q2),
            |a, k| charge_kspace_error(a, k, l, n, q2),
        )
    }

    /// Parameters for point dipoles `dipole` in a cubic box (accuracy in
    /// units of μ²/length⁴).
    pub fn for_dipoles(box_length: f64, r_cut: f64, accuracy: f64, dipole: &[DVec3]) -> Self {
        let n = dipole.len().max(1) as f64;
        let m2: f64 = dipole.iter().map(|m| m.length_squared()).sum();
        let m2 = m2.max(f64::MIN_POSITIVE);
        Self::with_errors(
            DVec3::splat(box_length),
            r_cut,
            accuracy,
            |a| dipole_real_error(a, r_cut, box_length, n, m2),
            |a, k| dipole_kspace_error(a, k, box_length, n, m2),
        )
    }

    /// The box volume V.
    fn volume(&self) -> f64 {
        self.cell.element_product()
    }

    /// The largest |k| summed, 2π n_max/V^{1/3}.
    fn k_max(&self) -> f64 {
        2.0 * std::f64::consts::PI * self.n_max as f64 / self.volume().cbrt()
    }

    /// The largest index along each axis, ⌊k_max L_a/2π⌋.
    fn axis_max(&self) -> [i32; 3] {
        let scale = self.k_max() / (2.0 * std::f64::consts::PI) * (1.0 + 1e-12);
        [0, 1, 2].map(|a| (scale * self.cell[a]).floor() as i32)
    }

    /// The phase table's half width: the largest index on any axis.
    fn table_max(&self) -> i32 {
        self.axis_max().into_iter().max().unwrap_or(0)
    }

    /// 2π/L_a per axis.
    fn tau(&self) -> DVec3 {
        2.0 * std::f64::consts::PI / self.cell
    }

    /// Estimated total RMS force error √(δ_real² + δ_k²).
    pub fn estimated_error(&self) -> f64 {
        self.real_error.hypot(self.kspace_error)
    }

    /// Half of the k-vectors (n_x > 0, or n_x = 0 < n_y, or n_x = n_y = 0 < n_z)
    /// with |k| ≤ k_max, as integer triples.
    fn half_kvectors(&self) -> Vec<[i32; 3]> {
        let [mx, my, mz] = self.axis_max();
        let (tau, k2max) = (self.tau(), self.k_max().powi(2) * (1.0 + 1e-12));
        let mut out = Vec::new();
        for nx in 0..=mx {
            for ny in -my..=my {
                for nz in -mz..=mz {
                    let positive = nx > 0 || (nx == 0 && (ny > 0 || (ny == 0 && nz > 0)));
                    let k = DVec3::new(nx as f64, ny as f64, nz as f64) * tau;
                    if positive && k.length_squared() <= k2max {
                        out.push([nx, ny, nz]);
                    }
                }
            }
        }
        out
    }

    /// e^{i 2π m x_a/L_a} for m = −M..=M (M the largest index on any axis)
    /// and each axis a, per particle, as (cos, sin) pairs: index
    /// [(i · 3 + a) · (2M + 1) + m + M].
    fn phases(&self, position: &[DVec3]) -> Vec<(f64, f64)> {
        let m = self.table_max() as usize;
        let w = 2 * m + 1;
        let mut out = vec![(1.0, 0.0); position.len() * 3 * w];
        let tau = self.tau();
        out.par_chunks_mut(3 * w)
            .zip(position.par_iter())
            .for_each(|(row, r)| {
                for a in 0..3 {
                    let (s, c) = (tau[a] * r[a]).sin_cos();
                    let axis = &mut row[a * w..(a + 1) * w];
                    for k in 1..=m {
                        let (pc, ps) = axis[m + k - 1];
                        let next = (pc * c - ps * s, pc * s + ps * c);
                        axis[m + k] = next;
                        axis[m - k] = (next.0, -next.1);
                    }
                }
            });
        out
    }

    /// Structure factors S(k) = Σ_j w_j(k) e^{ik·r_j} over `kv`, and the
    /// phases e^{ik·r_j} are returned through `phase_of`.
    fn kspace<W>(&self, position: &[DVec3], kv: &[[i32; 3]], weight: W) -> KSpace
    where
        W: Fn(usize, DVec3) -> f64 + Sync,
    {
        let ph = self.phases(position);
        let m = self.table_max();
        let w = (2 * m + 1) as usize;
        let tau = self.tau();
        let n = position.len();
        let kvec: Vec<DVec3> = kv
            .iter()
            .map(|nk| DVec3::new(nk[0] as f64, nk[1] as f64, nk[2] as f64) * tau)
            .collect();
        // Particle by particle into per-block sums (each particle's phases
        // and the block's S(k) stay in cache), blocks added in order: the
        // same bits for every thread count.
        let partial: Vec<Vec<(f64, f64)>> = (0..n.div_ceil(STRUCTURE_BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut s = vec![(0.0, 0.0); kv.len()];
                for j in b * STRUCTURE_BLOCK..n.min((b + 1) * STRUCTURE_BLOCK) {
                    each_phase(&ph, j, w, m, kv, |idx, c, sn| {
                        let q = weight(j, kvec[idx]);
                        s[idx].0 += q * c;
                        s[idx].1 += q * sn;
                    });
                }
                s
            })
            .collect();
        let mut structure = vec![(0.0, 0.0); kv.len()];
        for p in &partial {
            for (t, x) in structure.iter_mut().zip(p) {
                t.0 += x.0;
                t.1 += x.1;
            }
        }
        KSpace {
            phases: ph,
            structure,
        }
    }

    /// A(k) = exp(−k²/4α²)/k² and k of a half-space vector.
    fn damping(&self, nk: &[i32; 3]) -> (f64, DVec3) {
        let k = DVec3::new(nk[0] as f64, nk[1] as f64, nk[2] as f64) * self.tau();
        let k2 = k.length_squared();
        ((-k2 / (4.0 * self.alpha * self.alpha)).exp() / k2, k)
    }

    /// Image offsets (n_x L_x, n_y L_y, n_z L_z) within reach of the
    /// cut-off for a minimum-image separation.
    fn images(&self) -> Vec<DVec3> {
        let l = self.cell;
        let reach = [0, 1, 2].map(|a| (self.r_cut / l[a] + 0.5).ceil() as i32);
        let mut out = Vec::new();
        for a in -reach[0]..=reach[0] {
            for b in -reach[1]..=reach[1] {
                for c in -reach[2]..=reach[2] {
                    out.push(DVec3::new(a as f64, b as f64, c as f64) * l);
                }
            }
        }
        out
    }

    fn minimum_image(&self, d: DVec3) -> DVec3 {
        let l = self.cell;
        d - (d / l).round() * l
    }

    /// Energy of point charges; forces are added to `force` if given.
    pub fn charges(&self, position: &[DVec3], charge: &[f64], force: Option<&mut [DVec3]>) -> f64 {
        self.charges_of(position, charge, Share::Whole, force)
    }

    /// [`Ewald::charges`] for `share` of the particles: the forces of its
    /// rows (`force[p]` for row p) and its part of the energy — the real
    /// space of its rows (each pair half at each end) and their self
    /// energy, with the reciprocal-space energy and the neutralising
    /// background where it counts the whole system. The structure factors
    /// are summed over every particle in index order, so each row's force
    /// has one process's bits.
    pub fn charges_of(
        &self,
        position: &[DVec3],
        charge: &[f64],
        share: Share,
        force: Option<&mut [DVec3]>,
    ) -> f64 {
        let (alpha, rc2) = (self.alpha, self.r_cut * self.r_cut);
        let near = RealSpace::new(self, position);
        let v = self.volume();
        let rows = share.rows(position.len());
        // Real space, parallel over i, each pair seen from both ends.
        let real: Vec<(f64, DVec3)> = (0..rows.len())
            .into_par_iter()
            .map(|p| {
                let i = rows.at(p);
                let mut u = 0.0;
                let mut f = DVec3::ZERO;
                near.visit(self, position, i, |j, r, r2| {
                    if r2 >= rc2 {
                        return;
                    }
                    let rr = r2.sqrt();
                    let e = erfc(alpha * rr);
                    let qq = charge[i] * charge[j];
                    u += 0.5 * qq * e / rr;
                    let g = 2.0 * alpha / SQRT_PI * (-alpha * alpha * r2).exp();
                    f += r * (qq * (e / rr + g) / r2);
                });
                (u, f)
            })
            .collect();
        let kv = self.half_kvectors();
        let ks = self.kspace(position, &kv, |j, _| charge[j]);
        let mut u_k = 0.0;
        for (nk, s) in kv.iter().zip(&ks.structure) {
            let (a, _) = self.damping(nk);
            u_k += a * (s.0 * s.0 + s.1 * s.1);
        }
        u_k *= 4.0 * std::f64::consts::PI / v;
        let q2: f64 = (0..rows.len())
            .map(|p| charge[rows.at(p)] * charge[rows.at(p)])
            .sum();
        let (u_k, q_total) = match share.counts_the_whole() {
            true => (u_k, charge.iter().sum()),
            false => (0.0, 0.0),
        };
        let u_self = -alpha / SQRT_PI * q2
            - std::f64::consts::PI * q_total * q_total / (2.0 * v * alpha * alpha);
        if let Some(force) = force {
            let (m, w) = (self.table_max(), (2 * self.table_max() + 1) as usize);
            let damp: Vec<(f64, DVec3)> = kv.iter().map(|nk| self.damping(nk)).collect();
            force.par_iter_mut().enumerate().for_each(|(p, fi)| {
                let i = rows.at(p);
                let mut f = DVec3::ZERO;
                each_phase(&ks.phases, i, w, m, &kv, |idx, c, sn| {
                    let (s, (a, k)) = (ks.structure[idx], damp[idx]);
                    f += k * (a * (sn * s.0 - c * s.1));
                });
                *fi += real[p].1 + f * (8.0 * std::f64::consts::PI * charge[i] / v);
            });
        }
        real.iter().map(|r| r.0).sum::<f64>() + u_k + u_self
    }

    /// The virial tensor W_αβ = −∂U/∂ε_αβ of point charges (positions and
    /// box strained together, α fixed), in the units of [`Ewald::charges`]:
    /// real space Σ_pairs q_i q_j [erfc(αr)/r + (2α/√π) e^{−α²r²}] r_α r_β/r²,
    /// reciprocal space Σ_k U_k [δ_αβ − 2 (1/k² + 1/4α²) k_α k_β]
    /// (Essmann et al. 1995, J. Chem. Phys. 103, 8577, Eq. 2.4, with U_k
    /// the energy of the pair ±k), and the neutralising background's
    /// U_bg δ_αβ. Its trace is U, to the accuracy of the sums.
    pub fn charges_virial(&self, position: &[DVec3], charge: &[f64]) -> Virial {
        let n = position.len();
        let (alpha, rc2) = (self.alpha, self.r_cut * self.r_cut);
        let near = RealSpace::new(self, position);
        let real: Vec<Virial> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut w = Virial::default();
                near.visit(self, position, i, |j, r, r2| {
                    if r2 >= rc2 {
                        return;
                    }
                    let rr = r2.sqrt();
                    let g = 2.0 * alpha / SQRT_PI * (-alpha * alpha * r2).exp();
                    let qq = charge[i] * charge[j];
                    w += Virial::central(r, 0.5 * qq * (erfc(alpha * rr) / rr + g) / r2);
                });
                w
            })
            .collect();
        let v = self.volume();
        let kv = self.half_kvectors();
        let ks = self.kspace(position, &kv, |j, _| charge[j]);
        let mut w: Virial = real.into_iter().sum();
        for (nk, s) in kv.iter().zip(&ks.structure) {
            let (a, k) = self.damping(nk);
            let u_k = 4.0 * std::f64::consts::PI / v * a * (s.0 * s.0 + s.1 * s.1);
            let b = 2.0 * (1.0 / k.length_squared() + 0.25 / (alpha * alpha));
            w += Virial::isotropic(u_k) + Virial::central(k, -u_k * b);
        }
        let q_total: f64 = charge.iter().sum();
        let u_background = -std::f64::consts::PI * q_total * q_total / (2.0 * v * alpha * alpha);
        w + Virial::isotropic(u_background)
    }

    /// Energy of point dipoles; forces and fields H_i = −∂U/∂μ_i are added
    /// to `force` and `field` (torques are μ_i × H_i).
    pub fn dipoles(
        &self,
        position: &[DVec3],
        dipole: &[DVec3],
        force: &mut [DVec3],
        field: &mut [DVec3],
    ) -> f64 {
        self.dipoles_of(position, dipole, Share::Whole, force, field)
    }

    /// [`Ewald::dipoles`] for `share` of the particles, as
    /// [`Ewald::charges_of`]: its rows' forces and fields (`force[p]`,
    /// `field[p]` for row p), its part of the energy.
    pub fn dipoles_of(
        &self,
        position: &[DVec3],
        dipole: &[DVec3],
        share: Share,
        force: &mut [DVec3],
        field: &mut [DVec3],
    ) -> f64 {
        let (alpha, rc2) = (self.alpha, self.r_cut * self.r_cut);
        let a2 = alpha * alpha;
        let near = RealSpace::new(self, position);
        let v = self.volume();
        let pi = std::f64::consts::PI;
        let rows = share.rows(position.len());
        let real: Vec<(f64, DVec3, DVec3)> = (0..rows.len())
            .into_par_iter()
            .map(|p| {
                let i = rows.at(p);
                let (mut u, mut f, mut h) = (0.0, DVec3::ZERO, DVec3::ZERO);
                let mi = dipole[i];
                near.visit(self, position, i, |j, r, r2| {
                    let mj = dipole[j];
                    if r2 >= rc2 {
                        return;
                    }
                    let rr = r2.sqrt();
                    let e = erfc(alpha * rr);
                    let g = 2.0 * alpha * rr / SQRT_PI * (-a2 * r2).exp();
                    let b = (e + g) / (r2 * rr);
                    let c = (3.0 * e + g * (3.0 + 2.0 * a2 * r2)) / (r2 * r2 * rr);
                    let dd = (15.0 * e + g * (15.0 + 10.0 * a2 * r2 + 4.0 * a2 * a2 * r2 * r2))
                        / (r2 * r2 * r2 * rr);
                    let (mir, mjr, mm) = (mi.dot(r), mj.dot(r), mi.dot(mj));
                    u += 0.5 * (mm * b - mir * mjr * c);
                    f += r * (mm * c - dd * mir * mjr) + (mi * mjr + mj * mir) * c;
                    h += r * (c * mjr) - mj * b;
                });
                (u, f, h)
            })
            .collect();
        let kv = self.half_kvectors();
        let ks = self.kspace(position, &kv, |j, k| dipole[j].dot(k));
        let damp: Vec<(f64, DVec3)> = kv.iter().map(|nk| self.damping(nk)).collect();
        let mut u_k = 0.0;
        for (s, (a, _)) in ks.structure.iter().zip(&damp) {
            u_k += a * (s.0 * s.0 + s.1 * s.1);
        }
        u_k *= 4.0 * pi / v;
        if !share.counts_the_whole() {
            u_k = 0.0;
        }
        let m2: f64 = (0..rows.len())
            .map(|p| dipole[rows.at(p)].length_squared())
            .sum();
        let self_coeff = 2.0 * alpha * a2 / (3.0 * SQRT_PI);
        let u_self = -self_coeff * m2;
        let (m, w) = (self.table_max(), (2 * self.table_max() + 1) as usize);
        force
            .par_iter_mut()
            .zip(field.par_iter_mut())
            .enumerate()
            .for_each(|(p, (fi, hi))| {
                let i = rows.at(p);
                let (mut f, mut h) = (DVec3::ZERO, DVec3::ZERO);
                each_phase(&ks.phases, i, w, m, &kv, |idx, c, sn| {
                    let (s, (a, k)) = (ks.structure[idx], damp[idx]);
                    f += k * (a * dipole[i].dot(k) * (sn * s.0 - c * s.1));
                    h -= k * (a * (c * s.0 + sn * s.1));
                });
                *fi += real[p].1 + f * (8.0 * pi / v);
                *hi += real[p].2 + h * (8.0 * pi / v) + dipole[i] * (2.0 * self_coeff);
            });
        real.iter().map(|r| r.0).sum::<f64>() + u_k + u_self
    }
}

/// Which particles an Ewald evaluation is for: all (one process), or a
/// rank's (their indices in the whole system, gathered to every rank in
/// id order by [`crate::domain::gathered`]), one of which counts the
/// whole system's terms.
#[derive(Debug, Clone, Copy)]
pub enum Share<'a> {
    Whole,
    Rows {
        rows: &'a [usize],
        counts_the_whole: bool,
    },
}

impl<'a> Share<'a> {
    fn rows(self, n: usize) -> Rows<'a> {
        match self {
            Share::Whole => Rows::All(n),
            Share::Rows { rows, .. } => Rows::Some(rows),
        }
    }

    fn counts_the_whole(self) -> bool {
        match self {
            Share::Whole => true,
            Share::Rows {
                counts_the_whole, ..
            } => counts_the_whole,
        }
    }
}

/// The rows of an evaluation: 0..n, or the listed particles.
#[derive(Clone, Copy)]
enum Rows<'a> {
    All(usize),
    Some(&'a [usize]),
}

impl Rows<'_> {
    fn len(self) -> usize {
        match self {
            Rows::All(n) => n,
            Rows::Some(rows) => rows.len(),
        }
    }

    /// The particle of row p.
    #[inline]
    fn at(self, p: usize) -> usize {
        match self {
            Rows::All(_) => p,
            Rows::Some(rows) => rows[p],
        }
    }
}

/// The real-space pairs: linked cells when r_c ≤ L_a/2 on every axis (then
/// only a pair's minimum image can lie within r_c: in one of the three
/// cells around a particle's along an axis of three cells or more, in any
/// along the others), otherwise every pair with every image in reach.
struct RealSpace {
    images: Vec<DVec3>,
    /// Cells per axis (0: no cells).
    dims: [usize; 3],
    /// Particles of cell c are `order[start[c]..start[c + 1]]`, in index order.
    start: Vec<u32>,
    order: Vec<u32>,
    cell_of: Vec<[usize; 3]>,
}

impl RealSpace {
    fn new(ewald: &Ewald, position: &[DVec3]) -> Self {
        let l = ewald.cell;
        let dims = [0, 1, 2].map(|a| ((l[a] / ewald.r_cut).floor() as usize).max(1));
        let minimum_image_suffices = (0..3).all(|a| ewald.r_cut <= 0.5 * l[a]);
        if !minimum_image_suffices || position.len() < 64 {
            return Self {
                images: ewald.images(),
                dims: [0; 3],
                start: Vec::new(),
                order: Vec::new(),
                cell_of: Vec::new(),
            };
        }
        let cell_of: Vec<[usize; 3]> = position
            .iter()
            .map(|p| {
                [0, 1, 2].map(|a| {
                    let u = p[a] / l[a];
                    (((u - u.floor()) * dims[a] as f64) as usize).min(dims[a] - 1)
                })
            })
            .collect();
        let flat = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        let mut start = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for c in &cell_of {
            start[flat(*c) + 1] += 1;
        }
        for k in 1..start.len() {
            start[k] += start[k - 1];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; position.len()];
        for (i, c) in cell_of.iter().enumerate() {
            let slot = &mut fill[flat(*c)];
            order[*slot as usize] = i as u32;
            *slot += 1;
        }
        Self {
            images: Vec::new(),
            dims,
            start,
            order,
            cell_of,
        }
    }

    /// Calls `pair(j, r, r²)` for every j ≠ i (and every image of i itself)
    /// that may lie within r_c, with r = r_i − r_j (the image's separation).
    #[inline]
    fn visit(
        &self,
        ewald: &Ewald,
        position: &[DVec3],
        i: usize,
        mut pair: impl FnMut(usize, DVec3, f64),
    ) {
        if self.dims[0] == 0 {
            for (j, pj) in position.iter().enumerate() {
                let d0 = ewald.minimum_image(position[i] - *pj);
                for img in &self.images {
                    let r = d0 + *img;
                    let r2 = r.length_squared();
                    if !(i == j && r2 == 0.0) {
                        pair(j, r, r2);
                    }
                }
            }
            return;
        }
        let d = self.dims;
        let c = self.cell_of[i];
        // Along an axis of three or more cells the neighbours lie in the
        // cell and the two beside it; along one of fewer, in any cell.
        let offsets = |a: usize| -> &'static [usize] {
            match d[a] {
                1 => &[0],
                2 => &[0, 1],
                _ => &[usize::MAX, 0, 1],
            }
        };
        let wrap = |a: usize, o: usize| (c[a] + if o == usize::MAX { d[a] - 1 } else { o }) % d[a];
        for &ox in offsets(0) {
            let cx = wrap(0, ox);
            for &oy in offsets(1) {
                let cy = wrap(1, oy);
                for &oz in offsets(2) {
                    let cz = wrap(2, oz);
                    let cell = (cx * d[1] + cy) * d[2] + cz;
                    for &j in &self.order[self.start[cell] as usize..self.start[cell + 1] as usize]
                    {
                        let j = j as usize;
                        if j != i {
                            let r = ewald.minimum_image(position[i] - position[j]);
                            pair(j, r, r.length_squared());
                        }
                    }
                }
            }
        }
    }
}

struct KSpace {
    phases: Vec<(f64, f64)>,
    structure: Vec<(f64, f64)>,
}

/// Particles per block of the structure-factor sums.
const STRUCTURE_BLOCK: usize = 128;

/// Calls `f(index, cos, sin)` with e^{ik·r_j} = Π_a e^{i 2π n_a x_a/L_a}
/// for each k-vector of `kv` in order, from the per-axis phases; the
/// product of the x and y phases is kept while (n_x, n_y) repeats (the
/// half-space list runs n_z innermost), so each k costs one complex product.
#[inline]
fn each_phase(
    ph: &[(f64, f64)],
    j: usize,
    w: usize,
    m: i32,
    kv: &[[i32; 3]],
    mut f: impl FnMut(usize, f64, f64),
) {
    let row = &ph[j * 3 * w..(j + 1) * 3 * w];
    let at = |a: usize, n: i32| row[a * w + (n + m) as usize];
    let (mut last, mut xy) = ((i32::MIN, i32::MIN), (1.0, 0.0));
    for (idx, nk) in kv.iter().enumerate() {
        if (nk[0], nk[1]) != last {
            let (x, y) = (at(0, nk[0]), at(1, nk[1]));
            xy = (x.0 * y.0 - x.1 * y.1, x.0 * y.1 + x.1 * y.0);
            last = (nk[0], nk[1]);
        }
        let z = at(2, nk[2]);
        f(idx, xy.0 * z.0 - xy.1 * z.1, xy.0 * z.1 + xy.1 * z.0);
    }
}

/// Coulomb interaction of point charges in a cubic periodic box by Ewald
/// summation: U and F are those of [`Ewald::charges`] times `k`, with the
/// charges of the step's [`State`].
#[derive(Debug, Clone)]
pub struct EwaldCoulomb {
    pub ewald: Ewald,
    /// Coulomb constant of the unit system.
    pub k: f64,
    /// The energy of the last force evaluation, which is its virial.
    last_energy: f64,
}

impl EwaldCoulomb {
    /// α and n_max from the requested RMS force error `accuracy` (in force
    /// units, i.e. including `k`) for these charges.
    pub fn new(k: f64, charge: &[f64], box_length: f64, r_cut: f64, accuracy: f64) -> Self {
        let ewald = Ewald::for_charges(box_length, r_cut, accuracy / k.abs(), charge);
        Self {
            ewald,
            k,
            last_energy: 0.0,
        }
    }
}

impl Interaction for EwaldCoulomb {
    fn name(&self) -> &'static str {
        "coulomb"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let mut f = vec![DVec3::ZERO; force.len()];
        let u = self.evaluate(state, Some(&mut f));
        self.last_energy = self.k * u;
        for (a, b) in force.iter_mut().zip(&f) {
            *a += *b * self.k;
        }
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        self.k * self.evaluate(state, None)
    }

    /// Decomposed over ranks: every rank gathers every particle's position
    /// and charge in id order and sums the structure factors over them as
    /// one process does, then the real space and forces of its own
    /// particles; no ghosts.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach::NONE)
    }

    /// W = U: the tin-foil Ewald energy of charges is homogeneous of degree
    /// −1 in all lengths (box included; the neutralising background's
    /// −πQ²/(2Vα²) too, α scaling as 1/L), so W = −dU/dλ at λ = 1 = U,
    /// and the Coulomb pressure is U/(3V) (Allen & Tildesley, 2nd ed., §5.5).
    fn virial(&self) -> Option<f64> {
        Some(self.last_energy)
    }

    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        let whole = Whole::charges(state);
        let w = match whole.counts_the_whole() {
            true => self.ewald.charges_virial(&whole.position, &whole.value),
            false => Virial::default(),
        };
        Some(w.scaled(self.k))
    }
}

impl EwaldCoulomb {
    /// The energy of this evaluation's share (Gaussian units), the forces
    /// of its particles into `force`.
    fn evaluate(&self, state: &State, force: Option<&mut [DVec3]>) -> f64 {
        let whole = Whole::charges(state);
        self.ewald
            .charges_of(&whole.position, &whole.value, whole.share(), force)
    }
}

/// How an Ewald sum reads the whole: its share of it.
impl<T: Copy> Whole<T> {
    fn share(&self) -> Share<'_> {
        match &self.rows {
            None => Share::Whole,
            Some((rows, counts_the_whole)) => Share::Rows {
                rows,
                counts_the_whole: *counts_the_whole,
            },
        }
    }

    fn counts_the_whole(&self) -> bool {
        self.share().counts_the_whole()
    }
}

/// Dipole–dipole interaction of point dipoles in a cubic periodic box by
/// Ewald summation (tin-foil), with forces and torques τ = μ × H. The
/// dipoles come from [`State::dipole`]; the last ones seen are kept for
/// [`Interaction::potential_energy`] and for `add_forces` calls without a spin.
#[derive(Debug, Clone)]
pub struct EwaldDipoles {
    pub ewald: Ewald,
    /// μ₀/4π (or 1 in reduced units).
    pub k: f64,
    /// The energy of the last force evaluation (a third of its virial).
    last_energy: f64,
}

impl EwaldDipoles {
    /// Parameters tuned for `dipole` (the initial moments; the sums read
    /// the moments of each evaluation from [`State::dipole`]).
    pub fn new(k: f64, dipole: &[DVec3], box_length: f64, r_cut: f64, accuracy: f64) -> Self {
        let ewald = Ewald::for_dipoles(box_length, r_cut, accuracy / k.abs(), dipole);
        Self {
            ewald,
            k,
            last_energy: 0.0,
        }
    }
}

impl Interaction for EwaldDipoles {
    fn name(&self) -> &'static str {
        "dipolar"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let n = force.len();
        if state.dipole.len() != n {
            return;
        }
        let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let u = self.evaluate(state, &mut f, &mut h);
        self.last_energy = self.k * u;
        for (a, b) in force.iter_mut().zip(&f) {
            *a += *b * self.k;
        }
    }

    /// Decomposed as [`EwaldCoulomb`]: positions and moments gathered in
    /// id order to every rank, the forces and torques of its own.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach::NONE)
    }

    fn exerts_torques(&self) -> bool {
        true
    }

    fn add_forces_and_torques(
        &mut self,
        state: &State,
        _spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let n = force.len();
        if state.dipole.len() != n {
            return;
        }
        let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let u = self.evaluate(state, &mut f, &mut h);
        self.last_energy = self.k * u;
        for i in 0..n {
            force[i] += f[i] * self.k;
            torque[i] += state.dipole[i].cross(h[i]) * self.k;
        }
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        let n = state.position.len();
        if state.dipole.len() != n {
            return 0.0;
        }
        let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        self.k * self.evaluate(state, &mut f, &mut h)
    }

    /// W = 3U: the tin-foil Ewald energy of fixed dipoles is homogeneous of
    /// degree −3 in all lengths, so W = −dU/dλ at λ = 1 = 3U.
    fn virial(&self) -> Option<f64> {
        Some(3.0 * self.last_energy)
    }
}

impl EwaldDipoles {
    /// The energy of this evaluation's share (reduced units), the forces
    /// and fields of its particles into `force` and `field`.
    fn evaluate(&self, state: &State, force: &mut [DVec3], field: &mut [DVec3]) -> f64 {
        let whole = Whole::dipoles(state);
        self.ewald
            .dipoles_of(&whole.position, &whole.value, whole.share(), force, field)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfc_matches_tabulated_values() {
        // Abramowitz & Stegun Table 7.1 and high-precision values.
        for (x, v) in [
            (0.0, 1.0),
            (0.5, 0.479_500_122_186_953_5),
            (1.0, 0.157_299_207_050_285_1),
            (2.0, 4.677_734_981_047_266e-3),
            (2.9, 4.109_787_809_945_886e-5),
            (3.0, 2.209_049_699_858_544e-5),
            (4.0, 1.541_725_790_028_002e-8),
            (6.0, 2.151_973_671_249_892e-17),
        ] {
            let e = erfc(x);
            assert!(((e - v) / v).abs() < 1e-13, "erfc({x}) = {e}, expected {v}");
        }
    }

    /// W_aa = −∂U/∂ε_aa by central differences of the energy of the
    /// strained box (α and the k-index set fixed), for a neutral and a
    /// charged set of charges in an orthorhombic box; the trace is U.
    #[test]
    fn charge_virial_is_the_strain_derivative_of_the_energy() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(17);
        let cell = DVec3::new(5.0, 6.0, 7.0);
        let position: Vec<DVec3> = (0..40)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * cell)
            .collect();
        let neutral: Vec<f64> = (0..40)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let charged: Vec<f64> = (0..40).map(|i| 0.5 + (i % 3) as f64).collect();
        for charge in [neutral, charged] {
            let ewald = Ewald::for_charges_in(cell, 2.4, 1e-10, &charge);
            let u = ewald.charges(&position, &charge, None);
            let w = ewald.charges_virial(&position, &charge);
            assert!(
                (w.trace() - u).abs() < 1e-7 * u.abs(),
                "tr W {} vs U {u}",
                w.trace()
            );
            let eps = 1e-5;
            for a in 0..3 {
                let strained = |e: f64| {
                    let mut stretched = ewald;
                    stretched.cell[a] *= 1.0 + e;
                    let mut p = position.clone();
                    p.iter_mut().for_each(|r| r[a] *= 1.0 + e);
                    stretched.charges(&p, &charge, None)
                };
                let derivative = -(strained(eps) - strained(-eps)) / (2.0 * eps);
                assert!(
                    (w.0[a] - derivative).abs() < 1e-6 * u.abs(),
                    "axis {a}: W {} against −dU/dε {derivative}",
                    w.0[a]
                );
            }
        }
    }
}
