//! The mesh part of P3M for charges, with ik-differentiation (Hockney &
//! Eastwood §7-8; Deserno & Holm 1998, J. Chem. Phys. 109, 7678).
//!
//! The charges go to the mesh points by the B-spline of order p
//! ([`super::spline`]): Q_j = Σ_i q_i W(r_j − r_i); its transform Q̂(k) = Σ_j Q_j
//! e^{−ik·r_j} over the wave vectors k = 2π(n_x/L_x, n_y/L_y, n_z/L_z),
//! n_a ∈ [−M_a/2, M_a/2). With the influence function G(k), the k-space
//! energy is U = (1/2V) Σ_k G(k) |Q̂(k)|², the field at mesh point j
//! E_j = Σ_k (−i D(k) G(k) Q̂(k)/V) e^{ik·r_j}, with D(k) = k (zero on the
//! Nyquist plane of an even mesh, whose derivative has no sign), and the
//! force F_i = q_i Σ_j W(r_j − r_i) E_j, interpolated by the same weights:
//! Σ_i F_i = Σ_k (−iDG/V)|Q̂|² = 0, momentum is conserved to round-off.
//!
//! G is the optimal influence function for ik-differentiation, which
//! minimises the RMS force error against the Ewald sum (Deserno & Holm
//! Eq. 31 with Hockney & Eastwood's Eq. 8-22):
//!
//!   G(k) = D(k)·Σ_m Û²(k_m) R(k_m) / (|D(k)|² [Σ_m Û²(k_m)]²),
//!
//! k_m = k + 2π(m_x M_x/L_x, …) the aliases, Û(k) = Π_a sinc^p(k_a h_a/2)
//! the transform of the assignment, R(k) = 4π k e^{−k²/4α²}/k² the
//! reference force (Gaussian units; interactions multiply by their
//! constant). The same sums give the error functional
//!
//!   Q = (1/V) Σ_k [Σ_m |R(k_m)|² − (D·Σ_m Û² R)²/(|D|² (Σ_m Û²)²)],
//!
//! and the RMS force error of the mesh part ΔF = Σq² √(Q/(N V)) (Deserno
//! & Holm Eqs. 29–30): the estimate tuning uses.

use glam::DVec3;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::FftDirection;

use super::fft::Fft3;
use super::spline::{sinc, stencil, Stencil, MAX_ORDER};

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;
const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Aliases summed along each axis in G and the error functional (|m| ≤ 2:
/// the next ones are damped by e^{−(2πM·3/L)²/4α²} and Û²).
const ALIASES: i64 = 2;

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

/// Aliases along one axis in Σ_m Û² (Û² falls as 1/m^{2p}).
const SINC_ALIASES: i64 = 100;

/// The sums over aliases of one axis, at each of its mesh indices.
struct Axis {
    /// D_a(n): k_a on the first Brillouin zone, 0 on the Nyquist plane.
    derivative: Vec<f64>,
    /// Σ_m Û_a²(k_{a,m}) over all aliases that matter.
    sinc_sum: Vec<f64>,
    /// Per alias |m| ≤ ALIASES: k_{a,m}, Û_a², e^{−k_{a,m}²/4α²}.
    alias: Vec<[(f64, f64, f64); (2 * ALIASES + 1) as usize]>,
}

impl Axis {
    fn new(m: usize, length: f64, order: usize, alpha: f64) -> Self {
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
fn signed_index(n: usize, m: usize) -> i64 {
    let (n, m) = (n as i64, m as i64);
    if n < (m + 1) / 2 {
        n
    } else {
        n - m
    }
}

/// D_a at index n of an axis of m points and length L: 2π n'/L, n' the
/// signed index, and 0 on the Nyquist plane of an even mesh.
fn derivative_at(n: usize, m: usize, length: f64) -> f64 {
    let signed = signed_index(n, m);
    if m.is_multiple_of(2) && signed == -(m as i64) / 2 {
        0.0
    } else {
        TWO_PI * signed as f64 / length
    }
}

/// The optimal influence function on the whole mesh (x-major), and the
/// error functional Q·V with every alias G sums (see [`kspace_error`]),
/// from the same sums. G is even
/// in each of n_x, n_y, n_z (n → −n takes the aliases m → −m), so it is
/// computed on one octant, 0 ≤ n_a ≤ M_a/2, and mirrored: exactly even,
/// as the field's transform must be to come back real.
fn influence(dims: [usize; 3], cell: DVec3, order: usize, alpha: f64) -> (Vec<f64>, f64) {
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
            let (g, e) = influence_at(&axes, n, Aliases::Full);
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
fn influence_at(axes: &[Axis; 3], n: [usize; 3], aliases: Aliases) -> (f64, f64) {
    if n == [0, 0, 0] {
        return (0.0, 0.0);
    }
    let d = DVec3::new(
        axes[0].derivative[n[0]],
        axes[1].derivative[n[1]],
        axes[2].derivative[n[2]],
    );
    let m = aliases.range();
    let (ax, ay, az) = (
        &axes[0].alias[n[0]][m.clone()],
        &axes[1].alias[n[1]][m.clone()],
        &axes[2].alias[n[2]][m],
    );
    // N = Σ_m Û² D·R(k_m)/4π and Σ_m |R(k_m)|²/16π².
    let (mut numerator, mut reference) = (0.0, 0.0);
    for &(kx, ux, ex) in ax {
        for &(ky, uy, ey) in ay {
            let (uxy, exy) = (ux * uy, ex * ey);
            for &(kz, uz, ez) in az {
                let k2 = kx * kx + ky * ky + kz * kz;
                let e = exy * ez;
                numerator += uxy * uz * (d.x * kx + d.y * ky + d.z * kz) * e / k2;
                reference += e * e / k2;
            }
        }
    }
    let sum_u2 = axes[0].sinc_sum[n[0]] * axes[1].sinc_sum[n[1]] * axes[2].sinc_sum[n[2]];
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return (0.0, FOUR_PI * FOUR_PI * reference);
    }
    let g = FOUR_PI * numerator / (d2 * sum_u2 * sum_u2);
    let lost = FOUR_PI * FOUR_PI * (reference - numerator * numerator / (d2 * sum_u2 * sum_u2));
    (g, lost)
}

/// Tuning sums meshes up to this many points a side in full, larger ones
/// by a mesh of the same spacing this long ([`kspace_error`]).
const TUNING_SIDE: usize = 48;

/// The RMS force error of the mesh part for N charges with Σq² = `q2` in a
/// box `cell`, Gaussian units (Deserno & Holm Eq. 30).
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
pub fn kspace_error(
    dims: [usize; 3],
    cell: DVec3,
    order: usize,
    alpha: f64,
    n: f64,
    q2: f64,
    aliases: Aliases,
) -> f64 {
    let longest = *dims.iter().max().unwrap_or(&1);
    let qv = if aliases == Aliases::Tuning && longest > TUNING_SIDE {
        let scale = TUNING_SIDE as f64 / longest as f64;
        let small = dims.map(|m| ((m as f64 * scale).round() as usize).max(order + 1));
        let box_small = DVec3::new(
            cell.x * small[0] as f64 / dims[0] as f64,
            cell.y * small[1] as f64 / dims[1] as f64,
            cell.z * small[2] as f64 / dims[2] as f64,
        );
        let points = |d: [usize; 3]| d.iter().product::<usize>() as f64;
        error_sum(small, box_small, order, alpha, aliases) * points(dims) / points(small)
    } else {
        error_sum(dims, cell, order, alpha, aliases)
    };
    let v = cell.element_product();
    q2 * (qv.max(0.0) / (n * v * v)).sqrt()
}

/// Q·V: Deserno & Holm's error functional without its 1/V, over one octant.
fn error_sum(dims: [usize; 3], cell: DVec3, order: usize, alpha: f64, aliases: Aliases) -> f64 {
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
                    sum += wx * wy * wz * influence_at(&axes, [ix, iy, iz], aliases).1;
                }
            }
            sum
        })
        .collect::<Vec<_>>()
        .iter()
        .sum()
}

/// The p mesh indices of a stencil, wrapped onto the mesh of m points.
#[inline]
fn wrapped(s: &Stencil, p: usize, m: usize) -> [usize; MAX_ORDER] {
    let mut out = [0; MAX_ORDER];
    let mut i = s.first.rem_euclid(m as i64) as usize;
    for o in out.iter_mut().take(p) {
        *o = i;
        i += 1;
        if i == m {
            i = 0;
        }
    }
    out
}

/// The mesh of a P3M solver and its buffers.
#[derive(Debug, Clone)]
pub struct Mesh {
    pub dims: [usize; 3],
    pub order: usize,
    /// The box's lower corner and sides.
    lo: DVec3,
    cell: DVec3,
    fft: Fft3,
    /// D_a at each index of each axis.
    derivative: [Vec<f64>; 3],
    /// G(k), x-major; zero at k = 0.
    influence: Vec<f64>,
    /// Deserno & Holm's Q·V on this mesh, aliases |m| ≤ 2.
    error_sum: f64,
    /// The assigned charges, then their transform.
    charge: Vec<Complex64>,
    /// E_x + i E_y and E_z, in k-space and then on the mesh.
    field_xy: Vec<Complex64>,
    field_z: Vec<Complex64>,
    /// Particles by the first x plane of their stencil, and where each
    /// plane's begin.
    by_plane: Vec<u32>,
    plane_start: Vec<u32>,
}

impl Mesh {
    /// A mesh of `dims` points over the box from `lo` with sides `cell`,
    /// assignment order `order`, splitting parameter α.
    pub fn new(dims: [usize; 3], order: usize, alpha: f64, lo: DVec3, cell: DVec3) -> Self {
        let (influence, error_sum) = influence(dims, cell, order, alpha);
        let derivative = [0, 1, 2].map(|a| {
            (0..dims[a])
                .map(|n| derivative_at(n, dims[a], cell[a]))
                .collect()
        });
        Self {
            dims,
            order,
            lo,
            cell,
            fft: Fft3::new(dims),
            derivative,
            influence,
            error_sum,
            charge: Vec::new(),
            field_xy: Vec::new(),
            field_z: Vec::new(),
            by_plane: Vec::new(),
            plane_start: Vec::new(),
        }
    }

    /// The RMS force error of this mesh for N charges with Σq² = `q2`
    /// (Gaussian units): [`kspace_error`] with every alias, from the sums
    /// that made G.
    pub fn estimated_error(&self, n: f64, q2: f64) -> f64 {
        let v = self.volume();
        q2 * (self.error_sum.max(0.0) / (n * v * v)).sqrt()
    }

    /// The box volume V.
    pub fn volume(&self) -> f64 {
        self.cell.element_product()
    }

    /// Position in mesh spacings from the box's corner.
    #[inline]
    fn mesh_coordinates(&self, r: DVec3) -> DVec3 {
        (r - self.lo) / self.cell
            * DVec3::new(
                self.dims[0] as f64,
                self.dims[1] as f64,
                self.dims[2] as f64,
            )
    }

    /// Q_j = Σ_i q_i W(r_j − r_i) into `charge`, then transformed.
    ///
    /// Tasks own runs of x planes and add the particles whose stencils
    /// reach them, particles by their stencil's first plane and in index
    /// order within one: each mesh point sums its particles in one order
    /// whatever the number of threads.
    fn assign(&mut self, position: &[DVec3], charge: &[f64]) {
        let [mx, my, mz] = self.dims;
        let p = self.order;
        // Bin the particles by their stencil's first x plane.
        let first: Vec<usize> = position
            .par_iter()
            .map(|r| {
                let u = self.mesh_coordinates(*r);
                stencil(p, u.x).first.rem_euclid(mx as i64) as usize
            })
            .collect();
        self.plane_start.clear();
        self.plane_start.resize(mx + 1, 0);
        for &f in &first {
            self.plane_start[f + 1] += 1;
        }
        for x in 0..mx {
            self.plane_start[x + 1] += self.plane_start[x];
        }
        let mut next = self.plane_start.clone();
        self.by_plane.resize(position.len(), 0);
        for (i, &f) in first.iter().enumerate() {
            self.by_plane[next[f] as usize] = i as u32;
            next[f] += 1;
        }
        let mut charge_mesh = std::mem::take(&mut self.charge);
        charge_mesh.clear();
        charge_mesh.resize(mx * my * mz, Complex64::default());
        let plane = my * mz;
        // Slabs as thick as the stencil: a particle reaches two at most.
        let planes_per_task = p.max(2);
        let this = &*self;
        let (by_plane, plane_start) = (&this.by_plane, &this.plane_start);
        charge_mesh
            .par_chunks_mut(plane * planes_per_task)
            .enumerate()
            .for_each(|(task, slab)| {
                let lo_plane = task * planes_per_task;
                let planes = slab.len() / plane;
                // First planes from lo − p + 1 to the slab's last, in order.
                let back = (p - 1).min(mx - planes);
                for step in 0..back + planes {
                    let bin = (lo_plane + mx + step - back) % mx;
                    let members =
                        &by_plane[plane_start[bin] as usize..plane_start[bin + 1] as usize];
                    for &i in members {
                        let i = i as usize;
                        let u = this.mesh_coordinates(position[i]);
                        let (sx, sy, sz) = (stencil(p, u.x), stencil(p, u.y), stencil(p, u.z));
                        let (wx, wy, wz) = (
                            wrapped(&sx, p, mx),
                            wrapped(&sy, p, my),
                            wrapped(&sz, p, mz),
                        );
                        let q = charge[i];
                        for (a, &x) in wx[..p].iter().enumerate() {
                            // The plane within this slab, if it is one.
                            let Some(local) = x.checked_sub(lo_plane).filter(|l| *l < planes)
                            else {
                                continue;
                            };
                            let qx = q * sx.weight[a];
                            for (b, &y) in wy[..p].iter().enumerate() {
                                let qxy = qx * sy.weight[b];
                                let row =
                                    &mut slab[local * plane + y * mz..local * plane + (y + 1) * mz];
                                for (c, &z) in wz[..p].iter().enumerate() {
                                    row[z].re += qxy * sz.weight[c];
                                }
                            }
                        }
                    }
                }
            });
        self.fft.transform(&mut charge_mesh, FftDirection::Forward);
        self.charge = charge_mesh;
    }

    /// The k-space energy and its virial tensor entries (xx, yy, zz, xy,
    /// xz, yz): W_αβ = (1/2V) Σ_k G|Q̂|² [δ_αβ − 2 (1/k² + 1/4α²) k_α k_β]
    /// (the strain derivative of the energy, as for the Ewald sum).
    pub fn energy_and_virial(
        &mut self,
        position: &[DVec3],
        charge: &[f64],
        alpha: f64,
    ) -> (f64, [f64; 6]) {
        self.assign(position, charge);
        let v = self.cell.element_product();
        let [_, my, mz] = self.dims;
        let k_of =
            |a: usize, n: usize| TWO_PI * signed_index(n, self.dims[a]) as f64 / self.cell[a];
        let mut u = 0.0;
        let mut w = [0.0; 6];
        for (idx, (q, g)) in self.charge.iter().zip(&self.influence).enumerate() {
            if *g == 0.0 {
                continue;
            }
            let (ix, iy, iz) = (idx / (my * mz), (idx / mz) % my, idx % mz);
            let k = DVec3::new(k_of(0, ix), k_of(1, iy), k_of(2, iz));
            let e = 0.5 * g * q.norm_sqr() / v;
            let b = 2.0 * (1.0 / k.length_squared() + 0.25 / (alpha * alpha));
            u += e;
            w[0] += e * (1.0 - b * k.x * k.x);
            w[1] += e * (1.0 - b * k.y * k.y);
            w[2] += e * (1.0 - b * k.z * k.z);
            w[3] -= e * b * k.x * k.y;
            w[4] -= e * b * k.x * k.z;
            w[5] -= e * b * k.y * k.z;
        }
        (u, w)
    }

    /// Adds the mesh forces, `scale` q_i E(r_i) (Gaussian field times
    /// `scale`), to `force`.
    pub fn add_forces(
        &mut self,
        position: &[DVec3],
        charge: &[f64],
        scale: f64,
        force: &mut [DVec3],
    ) {
        self.assign(position, charge);
        let v = self.cell.element_product();
        let [_, my, mz] = self.dims;
        let n = self.charge.len();
        self.field_xy.resize(n, Complex64::default());
        self.field_z.resize(n, Complex64::default());
        let (dx, dy, dz) = (
            &self.derivative[0],
            &self.derivative[1],
            &self.derivative[2],
        );
        let (q, g) = (&self.charge, &self.influence);
        self.field_xy
            .par_chunks_mut(mz)
            .zip(self.field_z.par_chunks_mut(mz))
            .enumerate()
            .for_each(|(line, (xy, z))| {
                let (ix, iy) = (line / my, line % my);
                for iz in 0..mz {
                    let idx = line * mz + iz;
                    // −i D G Q̂ / V per component.
                    let s = q[idx] * (g[idx] / v);
                    let minus_i = Complex64::new(s.im, -s.re);
                    let (ex, ey, ez) = (minus_i * dx[ix], minus_i * dy[iy], minus_i * dz[iz]);
                    xy[iz] = ex + Complex64::new(-ey.im, ey.re);
                    z[iz] = ez;
                }
            });
        self.fft
            .transform(&mut self.field_xy, FftDirection::Inverse);
        self.fft.transform(&mut self.field_z, FftDirection::Inverse);
        let p = self.order;
        let this = &*self;
        force
            .par_iter_mut()
            .with_min_len(256)
            .enumerate()
            .for_each(|(i, f)| {
                let u = this.mesh_coordinates(position[i]);
                let (sx, sy, sz) = (stencil(p, u.x), stencil(p, u.y), stencil(p, u.z));
                let mut e = DVec3::ZERO;
                let [mx, my, mz] = this.dims;
                let (wx, wy, wz) = (
                    wrapped(&sx, p, mx),
                    wrapped(&sy, p, my),
                    wrapped(&sz, p, mz),
                );
                for (a, &x) in wx[..p].iter().enumerate() {
                    let mut ex = DVec3::ZERO;
                    for (b, &y) in wy[..p].iter().enumerate() {
                        let base = (x * my + y) * mz;
                        let mut ey = DVec3::ZERO;
                        for (c, &z) in wz[..p].iter().enumerate() {
                            let (xy, zz) = (this.field_xy[base + z], this.field_z[base + z]);
                            ey += DVec3::new(xy.re, xy.im, zz.re) * sz.weight[c];
                        }
                        ex += ey * sy.weight[b];
                    }
                    e += ex * sx.weight[a];
                }
                *f += e * (scale * charge[i]);
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tuning's estimate (aliases |m| ≤ 1, a large mesh summed on a
    /// smaller one of the same spacing) against the full sum.
    #[test]
    fn tuning_estimate_is_close_to_the_full_one() {
        let cell = DVec3::new(40.0, 40.0, 30.0);
        for (dims, order, alpha) in [
            ([96, 96, 72], 5, 1.0),
            ([60, 60, 45], 3, 0.7),
            ([120, 120, 90], 7, 1.4),
        ] {
            let full = kspace_error(dims, cell, order, alpha, 1000.0, 1000.0, Aliases::Full);
            let tuning = kspace_error(dims, cell, order, alpha, 1000.0, 1000.0, Aliases::Tuning);
            let ratio = tuning / full;
            println!("{dims:?} order {order}: tuning / full = {ratio:.4}");
            assert!(
                (ratio - 1.0).abs() < 0.02,
                "{dims:?} order {order}: {tuning:e} vs {full:e}"
            );
        }
    }
}
