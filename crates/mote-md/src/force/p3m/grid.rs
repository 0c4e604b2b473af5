//! The mesh of a P3M solver as geometry: where a particle's stencil falls,
//! spreading values of the particles onto the mesh points and reading
//! mesh values back at the particles, both by the B-spline weights of
//! [`super::spline`], and the mesh's FFTs.
//!
//! Spreading runs in tasks that own runs of x planes and add the particles
//! whose stencils reach them, particles by their stencil's first plane and
//! in index order within one: each mesh point sums its particles in one
//! order whatever the number of threads.

use glam::DVec3;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::FftDirection;

use super::fft::Fft3;
use super::influence::derivative_at;
use super::spline::{stencil, Stencil, MAX_ORDER};

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

/// A value a particle spreads: a real one (a charge) fills the real parts
/// alone, a complex one (two moment components) both.
pub trait Spread: Copy + Send + Sync {
    /// Adds `self` × `w` to the mesh point `c`.
    fn add_to(self, c: &mut Complex64, w: f64);
    /// `self` × `w`.
    fn scaled(self, w: f64) -> Self;
}

impl Spread for f64 {
    #[inline(always)]
    fn add_to(self, c: &mut Complex64, w: f64) {
        c.re += self * w;
    }
    #[inline(always)]
    fn scaled(self, w: f64) -> Self {
        self * w
    }
}

impl Spread for Complex64 {
    #[inline(always)]
    fn add_to(self, c: &mut Complex64, w: f64) {
        *c += self * w;
    }
    #[inline(always)]
    fn scaled(self, w: f64) -> Self {
        self * w
    }
}

/// A particle's stencils along the three axes and their wrapped indices.
struct Footprint {
    stencil: [Stencil; 3],
    index: [[usize; MAX_ORDER]; 3],
}

/// A periodic mesh over an orthorhombic box, its FFTs and the particles'
/// binning.
#[derive(Debug, Clone)]
pub struct Grid {
    pub dims: [usize; 3],
    pub order: usize,
    /// The box's lower corner and sides.
    lo: DVec3,
    pub cell: DVec3,
    fft: Fft3,
    /// D_a at each index of each axis (k_a, zero on the Nyquist plane).
    pub derivative: [Vec<f64>; 3],
    /// Particles by the first x plane of their stencil, and where each
    /// plane's begin.
    by_plane: Vec<u32>,
    plane_start: Vec<u32>,
}

impl Grid {
    /// A mesh of `dims` points over the box from `lo` with sides `cell`,
    /// assignment order `order`.
    pub fn new(dims: [usize; 3], order: usize, lo: DVec3, cell: DVec3) -> Self {
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
            by_plane: Vec::new(),
            plane_start: Vec::new(),
        }
    }

    /// The box volume V.
    pub fn volume(&self) -> f64 {
        self.cell.element_product()
    }

    /// Number of mesh points.
    pub fn points(&self) -> usize {
        self.dims.iter().product()
    }

    /// The three indices of mesh point `idx` (x-major).
    #[inline]
    pub fn indices(&self, idx: usize) -> [usize; 3] {
        let [_, my, mz] = self.dims;
        [idx / (my * mz), (idx / mz) % my, idx % mz]
    }

    /// The wave vector of mesh point `idx`, 2π n'/L with signed indices.
    #[inline]
    pub fn wave_vector(&self, idx: usize) -> DVec3 {
        let n = self.indices(idx);
        let k = |a: usize| {
            2.0 * std::f64::consts::PI * super::influence::signed_index(n[a], self.dims[a]) as f64
                / self.cell[a]
        };
        DVec3::new(k(0), k(1), k(2))
    }

    /// Transforms `data` in place (unnormalised).
    pub fn transform(&mut self, data: &mut Vec<Complex64>, direction: FftDirection) {
        self.fft.transform(data, direction);
    }

    #[inline]
    fn footprint(&self, r: DVec3) -> Footprint {
        let u = (r - self.lo) / self.cell
            * DVec3::new(
                self.dims[0] as f64,
                self.dims[1] as f64,
                self.dims[2] as f64,
            );
        let p = self.order;
        let stencil = [stencil(p, u.x), stencil(p, u.y), stencil(p, u.z)];
        let index = [0, 1, 2].map(|a| wrapped(&stencil[a], p, self.dims[a]));
        Footprint { stencil, index }
    }

    /// Sorts the particles by the first x plane of their stencils, for
    /// [`Grid::spread`].
    pub fn bin(&mut self, position: &[DVec3]) {
        let mx = self.dims[0];
        let p = self.order;
        let first: Vec<usize> = position
            .par_iter()
            .map(|r| {
                let u = (r.x - self.lo.x) / self.cell.x * mx as f64;
                stencil(p, u).first.rem_euclid(mx as i64) as usize
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
    }

    /// Σ_i v_i W(r_j − r_i) at every mesh point j into `mesh` (overwritten),
    /// v_i = `value(i)`; the particles binned for `position` by
    /// [`Grid::bin`].
    pub fn spread<V: Spread>(
        &self,
        position: &[DVec3],
        value: impl Fn(usize) -> V + Sync,
        mesh: &mut Vec<Complex64>,
    ) {
        self.clear(mesh);
        let slab = self.slab_points();
        mesh.par_chunks_mut(slab)
            .enumerate()
            .for_each(|(task, a)| self.spread_slab(position, |i| [value(i)], task, [a]));
    }

    /// [`Grid::spread`] of two values a particle into two meshes, in one
    /// pass (one stencil a particle for both).
    pub fn spread_two<V: Spread>(
        &self,
        position: &[DVec3],
        value: impl Fn(usize) -> [V; 2] + Sync,
        first: &mut Vec<Complex64>,
        second: &mut Vec<Complex64>,
    ) {
        self.clear(first);
        self.clear(second);
        let slab = self.slab_points();
        first
            .par_chunks_mut(slab)
            .zip(second.par_chunks_mut(slab))
            .enumerate()
            .for_each(|(task, (a, b))| self.spread_slab(position, &value, task, [a, b]));
    }

    /// `mesh` zeroed at every point.
    fn clear(&self, mesh: &mut Vec<Complex64>) {
        mesh.clear();
        mesh.resize(self.points(), Complex64::default());
    }

    /// Mesh points per spreading task: slabs of x planes as thick as the
    /// stencil (a particle reaches two at most).
    fn slab_points(&self) -> usize {
        self.order.max(2) * self.dims[1] * self.dims[2]
    }

    /// Task `task`'s slab of each of K meshes: the particles whose
    /// stencils reach it, by their stencil's first plane from lo − p + 1
    /// to the slab's last, in index order within a plane.
    fn spread_slab<V: Spread, const K: usize>(
        &self,
        position: &[DVec3],
        value: impl Fn(usize) -> [V; K],
        task: usize,
        mut slabs: [&mut [Complex64]; K],
    ) {
        let [mx, my, mz] = self.dims;
        let p = self.order;
        assert_eq!(self.by_plane.len(), position.len(), "binned for these");
        let plane = my * mz;
        let lo_plane = task * p.max(2);
        let planes = slabs[0].len() / plane;
        let (by_plane, plane_start) = (&self.by_plane, &self.plane_start);
        let back = (p - 1).min(mx - planes);
        for step in 0..back + planes {
            let bin = (lo_plane + mx + step - back) % mx;
            let members = &by_plane[plane_start[bin] as usize..plane_start[bin + 1] as usize];
            for &i in members {
                let i = i as usize;
                let at = self.footprint(position[i]);
                let [sx, sy, sz] = &at.stencil;
                let [wx, wy, wz] = &at.index;
                let v = value(i);
                for (a, &x) in wx[..p].iter().enumerate() {
                    // The plane within this slab, if it is one.
                    let Some(local) = x.checked_sub(lo_plane).filter(|l| *l < planes) else {
                        continue;
                    };
                    for (b, &y) in wy[..p].iter().enumerate() {
                        let w = sx.weight[a] * sy.weight[b];
                        let start = local * plane + y * mz;
                        for (slab, v) in slabs.iter_mut().zip(v) {
                            let vxy = v.scaled(w);
                            let row = &mut slab[start..start + mz];
                            for (c, &z) in wz[..p].iter().enumerate() {
                                vxy.add_to(&mut row[z], sz.weight[c]);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Σ_j W(r_j − r_i) X_j of each of the K meshes X at every particle
    /// i, handed with i and `out[i]` to `each`.
    pub fn interpolate<T: Send, const K: usize>(
        &self,
        position: &[DVec3],
        meshes: [&[Complex64]; K],
        out: &mut [T],
        each: impl Fn(usize, [Complex64; K], &mut T) + Sync,
    ) {
        let p = self.order;
        let [_, my, mz] = self.dims;
        out.par_iter_mut()
            .with_min_len(256)
            .enumerate()
            .for_each(|(i, o)| {
                let at = self.footprint(position[i]);
                let [sx, sy, sz] = &at.stencil;
                let [wx, wy, wz] = &at.index;
                let mut sum = [Complex64::default(); K];
                for (a, &x) in wx[..p].iter().enumerate() {
                    let mut sum_x = [Complex64::default(); K];
                    for (b, &y) in wy[..p].iter().enumerate() {
                        let base = (x * my + y) * mz;
                        let mut sum_y = [Complex64::default(); K];
                        for (c, &z) in wz[..p].iter().enumerate() {
                            let w = sz.weight[c];
                            for (s, mesh) in sum_y.iter_mut().zip(&meshes) {
                                *s += mesh[base + z] * w;
                            }
                        }
                        for (s, v) in sum_x.iter_mut().zip(sum_y) {
                            *s += v * sy.weight[b];
                        }
                    }
                    for (s, v) in sum.iter_mut().zip(sum_x) {
                        *s += v * sx.weight[a];
                    }
                }
                each(i, sum, o);
            });
    }
}
