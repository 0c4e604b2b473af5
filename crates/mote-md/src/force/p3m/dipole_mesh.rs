//! The mesh part of P3M for point dipoles, with ik-differentiation
//! (Cerdà, Ballenegger, Lenz & Holm 2008, J. Chem. Phys. 129, 234104).
//!
//! The moments go to the mesh by the B-spline of order p: M_j = Σ_i μ_i
//! W(r_j − r_i), and with its transform M̂(k) the mesh's "charge" is
//! ρ̂ = −i D·M̂ (ρ = −∇·M), D(k) = k on the first Brillouin zone (zero on
//! the Nyquist plane). Writing S(k) = D(k)·M̂(k), the k-space energy is
//!
//!   U = (1/2V) Σ_k G_E(k) |S(k)|²,
//!
//! the field H = −∇φ and its gradient at the mesh points
//!
//!   Ĥ_a = −D_a G_E S/V,   (∂_b H_a)^ = −i D_a D_b G_F S/V,
//!
//! and at particle i, interpolated by the same weights, the torque
//! τ_i = μ_i × H(r_i) and the force F_i = ∇(μ_i·H)(r_i), i.e.
//! F_{i,b} = Σ_a μ_{i,a} ∂_b H_a. G_E and G_F are the optimal influence
//! functions for two and three derivatives ([`super::influence`]): the
//! energy and torques use the first, the forces the second, as in
//! Cerdà et al. and ESPResSo.
//!
//! The five real fields of the gradient and the three of H go through
//! four complex transforms and a half (two real fields per complex one:
//! the inverse transform of Â + iB̂, both Hermitian, is A + iB), the three
//! moment components through two (M_x + iM_y, M_z): seven 3-D FFTs a
//! force evaluation, where LAMMPS's `pppm/dipole` takes twelve.
//!
//! A dipole's energy with its own mesh image depends on where it sits in
//! its cell; its average over positions is μ·S·μ with
//! S_aa = (1/2V) Σ_k G_E D_a² Σ_m Û²(k_m) (ESPResSo's "average dipolar
//! self energy"), where the Ewald sum has μ·T·μ, T_aa = (2π/V) Σ_{k≠0}
//! e^{−k²/4α²} k_a²/k² (its own i = j terms, which its self energy
//! −(2α³/3√π)μ² offsets). The solver replaces the first by the second.

use glam::DVec3;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::FftDirection;

use super::grid::Grid;
use super::influence::{influence, rms_error, Axis, Kernel};

/// The mesh of a dipolar P3M solver and its buffers.
#[derive(Debug, Clone)]
pub struct DipoleMesh {
    pub grid: Grid,
    /// G_F and G_E, x-major; zero at k = 0.
    g_force: Vec<f64>,
    g_energy: Vec<f64>,
    /// The error functional of the forces on this mesh, aliases |m| ≤ 2.
    error_sum: f64,
    /// T_aa − S_aa: what replaces the mesh's average self energy of a
    /// dipole by the Ewald sum's (Gaussian units, per μ_a²).
    pub self_correction: DVec3,
    /// M_x + iM_y and M_z, then their transforms.
    moment_xy: Vec<Complex64>,
    moment_z: Vec<Complex64>,
    /// S(k) = D·M̂.
    divergence: Vec<Complex64>,
    /// The packed fields: ∂H (xx + i yy, zz + i xy, xz + i yz), then
    /// H_x + i H_y and H_z.
    packed: [Vec<Complex64>; 5],
}

/// What an evaluation leaves at each particle: the force and the field.
#[derive(Debug, Clone, Copy, Default)]
pub struct AtParticle {
    pub force: DVec3,
    pub field: DVec3,
}

impl DipoleMesh {
    /// A mesh of `dims` points over the box from `lo` with sides `cell`,
    /// assignment order `order`, splitting parameter α.
    pub fn new(dims: [usize; 3], order: usize, alpha: f64, lo: DVec3, cell: DVec3) -> Self {
        let (g_force, error_sum) = influence(dims, cell, order, alpha, Kernel::DipoleForce);
        let (g_energy, _) = influence(dims, cell, order, alpha, Kernel::DipoleEnergy);
        let grid = Grid::new(dims, order, lo, cell);
        let self_correction = ewald_self(cell, alpha) - mesh_self(&grid, &g_energy, order, alpha);
        Self {
            grid,
            g_force,
            g_energy,
            error_sum,
            self_correction,
            moment_xy: Vec::new(),
            moment_z: Vec::new(),
            divergence: Vec::new(),
            packed: Default::default(),
        }
    }

    /// The RMS force error of this mesh for N dipoles of random
    /// orientation with Σμ² = `m2` (Gaussian units; Cerdà et al. Eq. 38).
    pub fn estimated_error(&self, n: f64, m2: f64) -> f64 {
        rms_error(
            Kernel::DipoleForce,
            self.error_sum,
            n,
            m2,
            self.grid.volume(),
        )
    }

    /// S(k) = D·M̂(k) into `divergence`.
    fn assign(&mut self, position: &[DVec3], dipole: &[DVec3]) {
        self.grid.bin(position);
        let (mut xy, mut z) = (
            std::mem::take(&mut self.moment_xy),
            std::mem::take(&mut self.moment_z),
        );
        self.grid.spread_two(
            position,
            |i| {
                let m = dipole[i];
                [Complex64::new(m.x, m.y), Complex64::new(m.z, 0.0)]
            },
            &mut xy,
            &mut z,
        );
        self.grid.transform(&mut xy, FftDirection::Forward);
        self.grid.transform(&mut z, FftDirection::Forward);
        let mut divergence = std::mem::take(&mut self.divergence);
        divergence.resize(xy.len(), Complex64::default());
        let [mx, my, mz] = self.grid.dims;
        let [dx, dy, dz] = &self.grid.derivative;
        divergence
            .par_chunks_mut(mz)
            .enumerate()
            .for_each(|(line, s)| {
                let (ix, iy) = (line / my, line % my);
                // The line of −k: (−n_x, −n_y) and z reversed.
                let mirror = ((mx - ix) % mx * my + (my - iy) % my) * mz;
                let base = line * mz;
                for (iz, s) in s.iter_mut().enumerate() {
                    // M̂_x = (Z(k) + Z(−k)*)/2, M̂_y = (Z(k) − Z(−k)*)/2i.
                    let zk = xy[base + iz];
                    let zm = xy[mirror + (mz - iz) % mz].conj();
                    let m_x = (zk + zm) * 0.5;
                    let m_y = (zk - zm) * Complex64::new(0.0, -0.5);
                    *s = m_x * dx[ix] + m_y * dy[iy] + z[base + iz] * dz[iz];
                }
            });
        self.moment_xy = xy;
        self.moment_z = z;
        self.divergence = divergence;
    }

    /// The k-space energy (1/2V) Σ_k G_E |S|² (Gaussian units).
    pub fn energy(&mut self, position: &[DVec3], dipole: &[DVec3]) -> f64 {
        self.assign(position, dipole);
        let v = self.grid.volume();
        let (s, g) = (&self.divergence, &self.g_energy);
        let sum = in_fixed_blocks(s.len(), |range| {
            range.map(|idx| g[idx] * s[idx].norm_sqr()).sum::<f64>()
        });
        0.5 * sum / v
    }

    /// The mesh force on each dipole and, if `field`, the field at it, into
    /// `out` (overwritten; Gaussian units).
    pub fn forces_and_fields(
        &mut self,
        position: &[DVec3],
        dipole: &[DVec3],
        field: bool,
        out: &mut [AtParticle],
    ) {
        self.forces_and_fields_at(position, dipole, position, dipole, field, out);
    }

    /// [`DipoleMesh::forces_and_fields`] of the mesh made from the dipoles
    /// `source_dipole` at `source_position`, at the dipoles `dipole` at
    /// `position` (a decomposed run: every particle's moments, this rank's
    /// particles' forces).
    pub fn forces_and_fields_at(
        &mut self,
        source_position: &[DVec3],
        source_dipole: &[DVec3],
        position: &[DVec3],
        dipole: &[DVec3],
        field: bool,
        out: &mut [AtParticle],
    ) {
        self.assign(source_position, source_dipole);
        let v = self.grid.volume();
        let points = self.grid.points();
        let meshes = if field { 5 } else { 3 };
        for m in &mut self.packed[..meshes] {
            m.resize(points, Complex64::default());
        }
        let [_, my, mz] = self.grid.dims;
        let [dx, dy, dz] = &self.grid.derivative;
        let (s, gf, ge) = (&self.divergence, &self.g_force, &self.g_energy);
        let [p0, p1, p2, p3, p4] = &mut self.packed;
        let i = Complex64::i();
        p0.par_chunks_mut(mz)
            .zip(p1.par_chunks_mut(mz))
            .zip(p2.par_chunks_mut(mz))
            .enumerate()
            .for_each(|(line, ((xx_yy, zz_xy), xz_yz))| {
                let (kx, ky) = (dx[line / my], dy[line % my]);
                for iz in 0..mz {
                    let (idx, kz) = (line * mz + iz, dz[iz]);
                    // −i G_F S/V: times D_a D_b, the spectrum of ∂_b H_a.
                    let t = s[idx] * Complex64::new(0.0, -gf[idx] / v);
                    xx_yy[iz] = t * (kx * kx) + i * t * (ky * ky);
                    zz_xy[iz] = t * (kz * kz) + i * t * (kx * ky);
                    xz_yz[iz] = t * (kx * kz) + i * t * (ky * kz);
                }
            });
        if field {
            p3.par_chunks_mut(mz)
                .zip(p4.par_chunks_mut(mz))
                .enumerate()
                .for_each(|(line, (hxy, hz))| {
                    let (kx, ky) = (dx[line / my], dy[line % my]);
                    for iz in 0..mz {
                        let idx = line * mz + iz;
                        // −G_E S/V: times D_a, the spectrum of H_a.
                        let h = s[idx] * (-ge[idx] / v);
                        hxy[iz] = h * kx + i * h * ky;
                        hz[iz] = h * dz[iz];
                    }
                });
        }
        for m in 0..meshes {
            let mut mesh = std::mem::take(&mut self.packed[m]);
            self.grid.transform(&mut mesh, FftDirection::Inverse);
            self.packed[m] = mesh;
        }
        let force = |mu: DVec3, g: [Complex64; 3]| {
            let [xx_yy, zz_xy, xz_yz] = g;
            let (xx, yy, zz) = (xx_yy.re, xx_yy.im, zz_xy.re);
            let (xy, xz, yz) = (zz_xy.im, xz_yz.re, xz_yz.im);
            DVec3::new(
                mu.x * xx + mu.y * xy + mu.z * xz,
                mu.x * xy + mu.y * yy + mu.z * yz,
                mu.x * xz + mu.y * yz + mu.z * zz,
            )
        };
        let p = &self.packed;
        if field {
            self.grid.interpolate(
                position,
                [&p[0], &p[1], &p[2], &p[3], &p[4]],
                out,
                |i, [a, b, c, hxy, hz], o| {
                    *o = AtParticle {
                        force: force(dipole[i], [a, b, c]),
                        field: DVec3::new(hxy.re, hxy.im, hz.re),
                    }
                },
            );
        } else {
            self.grid
                .interpolate(position, [&p[0], &p[1], &p[2]], out, |i, g, o| {
                    *o = AtParticle {
                        force: force(dipole[i], g),
                        field: DVec3::ZERO,
                    }
                });
        }
    }
}

/// Σ over 0..n of what `block` sums over fixed blocks of indices, block
/// after block: the same bits on any number of threads.
fn in_fixed_blocks<T>(n: usize, block: impl Fn(std::ops::Range<usize>) -> T + Sync) -> T
where
    T: Send + std::ops::Add<Output = T> + Default,
{
    const BLOCK: usize = 4096;
    let sums: Vec<T> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| block(b * BLOCK..((b + 1) * BLOCK).min(n)))
        .collect();
    sums.into_iter().fold(T::default(), |a, b| a + b)
}

/// S_aa = (1/2V) Σ_k G_E D_a² Σ_m Û²(k_m): the mesh energy of a unit
/// dipole along axis a with itself, averaged over its position in a cell.
fn mesh_self(grid: &Grid, g_energy: &[f64], order: usize, alpha: f64) -> DVec3 {
    let axes = [0, 1, 2].map(|a| Axis::new(grid.dims[a], grid.cell[a], order, alpha));
    let [dx, dy, dz] = &grid.derivative;
    let sum = in_fixed_blocks(g_energy.len(), |range| {
        range
            .map(|idx| {
                let [ix, iy, iz] = grid.indices(idx);
                let u2 = axes[0].sinc_sum[ix] * axes[1].sinc_sum[iy] * axes[2].sinc_sum[iz];
                DVec3::new(dx[ix] * dx[ix], dy[iy] * dy[iy], dz[iz] * dz[iz]) * (g_energy[idx] * u2)
            })
            .fold(DVec3::ZERO, |a, b| a + b)
    });
    sum * (0.5 / grid.volume())
}

/// T_aa = (2π/V) Σ_{k≠0} e^{−k²/4α²} k_a²/k²: the Ewald sum's own k-space
/// energy of a unit dipole along axis a, summed to |k| = 12.5 α
/// (e^{−k²/4α²} < 10⁻¹⁶ beyond).
fn ewald_self(cell: DVec3, alpha: f64) -> DVec3 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let k_max = 12.5 * alpha;
    let n_max = [0, 1, 2].map(|a| (k_max * cell[a] / two_pi).ceil() as i64);
    let unit = DVec3::new(two_pi / cell.x, two_pi / cell.y, two_pi / cell.z);
    let sum = (-n_max[0]..=n_max[0])
        .into_par_iter()
        .map(|nx| {
            let mut s = DVec3::ZERO;
            for ny in -n_max[1]..=n_max[1] {
                for nz in -n_max[2]..=n_max[2] {
                    if nx == 0 && ny == 0 && nz == 0 {
                        continue;
                    }
                    let k = DVec3::new(nx as f64, ny as f64, nz as f64) * unit;
                    let k2 = k.length_squared();
                    if k2 > k_max * k_max {
                        continue;
                    }
                    s += k * k * ((-k2 / (4.0 * alpha * alpha)).exp() / k2);
                }
            }
            s
        })
        .collect::<Vec<_>>()
        .into_iter()
        .fold(DVec3::ZERO, |a, b| a + b);
    sum * (two_pi / cell.element_product())
}
