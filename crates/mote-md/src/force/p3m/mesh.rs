//! The mesh part of P3M for charges, with ik-differentiation (Hockney &
//! Eastwood §7-8; Deserno & Holm 1998, J. Chem. Phys. 109, 7678).
//!
//! The charges go to the mesh points by the B-spline of order p
//! ([`super::spline`]): Q_j = Σ_i q_i W(r_j − r_i); its transform Q̂(k) = Σ_j Q_j
//! e^{−ik·r_j} over the wave vectors k = 2π(n_x/L_x, n_y/L_y, n_z/L_z),
//! n_a ∈ [−M_a/2, M_a/2). With the influence function G(k) (the optimal
//! one of [`super::influence`] for charges), the k-space energy is
//! U = (1/2V) Σ_k G(k) |Q̂(k)|², the field at mesh point j
//! E_j = Σ_k (−i D(k) G(k) Q̂(k)/V) e^{ik·r_j}, with D(k) = k (zero on the
//! Nyquist plane of an even mesh), and the force F_i = q_i Σ_j W(r_j − r_i) E_j,
//! interpolated by the same weights: Σ_i F_i = Σ_k (−iDG/V)|Q̂|² = 0,
//! momentum is conserved to round-off.

use glam::DVec3;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::FftDirection;

use super::grid::Grid;
use super::influence::{influence, rms_error, Kernel};

/// The mesh of a P3M solver for charges and its buffers.
#[derive(Debug, Clone)]
pub struct Mesh {
    pub grid: Grid,
    /// G(k), x-major; zero at k = 0.
    influence: Vec<f64>,
    /// The error functional Q on this mesh, aliases |m| ≤ 2.
    error_sum: f64,
    /// The assigned charges, then their transform.
    charge: Vec<Complex64>,
    /// E_x + i E_y and E_z, in k-space and then on the mesh.
    field_xy: Vec<Complex64>,
    field_z: Vec<Complex64>,
}

impl Mesh {
    /// A mesh of `dims` points over the box from `lo` with sides `cell`,
    /// assignment order `order`, splitting parameter α.
    pub fn new(dims: [usize; 3], order: usize, alpha: f64, lo: DVec3, cell: DVec3) -> Self {
        let (influence, error_sum) = influence(dims, cell, order, alpha, Kernel::Charge);
        Self {
            grid: Grid::new(dims, order, lo, cell),
            influence,
            error_sum,
            charge: Vec::new(),
            field_xy: Vec::new(),
            field_z: Vec::new(),
        }
    }

    /// The RMS force error of this mesh for N charges with Σq² = `q2`
    /// (Gaussian units): [`super::influence::kspace_error`] with every
    /// alias, from the sums that made G.
    pub fn estimated_error(&self, n: f64, q2: f64) -> f64 {
        rms_error(Kernel::Charge, self.error_sum, n, q2, self.volume())
    }

    /// The box volume V.
    pub fn volume(&self) -> f64 {
        self.grid.volume()
    }

    /// Q_j = Σ_i q_i W(r_j − r_i) into `charge`, then transformed.
    fn assign(&mut self, position: &[DVec3], charge: &[f64]) {
        self.grid.bin(position);
        let mut mesh = std::mem::take(&mut self.charge);
        self.grid.spread(position, |i| charge[i], &mut mesh);
        self.grid.transform(&mut mesh, FftDirection::Forward);
        self.charge = mesh;
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
        let v = self.volume();
        let mut u = 0.0;
        let mut w = [0.0; 6];
        for (idx, (q, g)) in self.charge.iter().zip(&self.influence).enumerate() {
            if *g == 0.0 {
                continue;
            }
            let k = self.grid.wave_vector(idx);
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
        self.add_forces_at(position, charge, position, charge, scale, force);
    }

    /// The field of the charges `source_charge` at `source_position`,
    /// `scale` q E(r) on the charges `charge` at `position`, added to
    /// `force` (a decomposed run: every particle's charge, this rank's
    /// particles' forces).
    pub fn add_forces_at(
        &mut self,
        source_position: &[DVec3],
        source_charge: &[f64],
        position: &[DVec3],
        charge: &[f64],
        scale: f64,
        force: &mut [DVec3],
    ) {
        self.assign(source_position, source_charge);
        let v = self.volume();
        let [_, my, mz] = self.grid.dims;
        let n = self.charge.len();
        self.field_xy.resize(n, Complex64::default());
        self.field_z.resize(n, Complex64::default());
        let [dx, dy, dz] = &self.grid.derivative;
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
        self.grid
            .transform(&mut self.field_xy, FftDirection::Inverse);
        self.grid
            .transform(&mut self.field_z, FftDirection::Inverse);
        self.grid.interpolate(
            position,
            [&self.field_xy, &self.field_z],
            force,
            |i, [xy, z], f| *f += DVec3::new(xy.re, xy.im, z.re) * (scale * charge[i]),
        );
    }
}
