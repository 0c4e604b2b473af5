//! The Lennard-Jones pair potential and its purely repulsive WCA form.
//!
//! U(r) = 4ε [(σ/r)¹² − (σ/r)⁶] − U(r_c) for r < r_c (shifted, or unshifted
//! with the tail corrections of Allen & Tildesley §2.8 available for the
//! energy and pressure), 0 beyond. WCA (Weeks–Chandler–Andersen, the
//! repulsion of 004 Eq. 9) is the shifted potential cut at its minimum
//! r_c = 2^{1/6} σ. The force on i from j is F_i = 24ε [2(σ/r)¹² − (σ/r)⁶] (r_i − r_j)/r².

use glam::DVec3;
use rayon::prelude::*;

use super::{Interaction, State};
use crate::boundary::Boundary;
use crate::neighbor::VerletList;

/// Lennard-Jones between all particles, through a Verlet list.
#[derive(Debug, Clone)]
pub struct LennardJones {
    pub epsilon: f64,
    pub sigma: f64,
    pub cutoff: f64,
    /// Subtract U(r_c) so the energy is continuous at the cut-off.
    pub shifted: bool,
    pub boundary: Boundary,
    pub list: VerletList,
    virial: f64,
    /// One force buffer per block of particles (see `add_forces`).
    buffers: Vec<Vec<DVec3>>,
}

impl LennardJones {
    pub fn new(
        epsilon: f64,
        sigma: f64,
        cutoff: f64,
        shifted: bool,
        skin: f64,
        boundary: Boundary,
    ) -> Self {
        Self {
            epsilon,
            sigma,
            cutoff,
            shifted,
            boundary,
            list: VerletList::half(cutoff, skin),
            virial: 0.0,
            buffers: Vec::new(),
        }
    }

    /// WCA: shifted LJ cut at 2^{1/6} σ.
    pub fn wca(epsilon: f64, sigma: f64, skin: f64, boundary: Boundary) -> Self {
        Self::new(
            epsilon,
            sigma,
            2f64.powf(1.0 / 6.0) * sigma,
            true,
            skin,
            boundary,
        )
    }

    /// U(r_c), the shift.
    pub fn shift(&self) -> f64 {
        if self.shifted {
            let s6 = (self.sigma / self.cutoff).powi(6);
            4.0 * self.epsilon * (s6 * s6 - s6)
        } else {
            0.0
        }
    }

    /// Tail corrections per particle for a homogeneous fluid of number
    /// density ρ beyond r_c (g(r) = 1): energy
    /// u_tail = (8/3)πρεσ³[(1/3)(σ/r_c)⁹ − (σ/r_c)³] and pressure
    /// p_tail = (16/3)πρ²εσ³[(2/3)(σ/r_c)⁹ − (σ/r_c)³] (Allen & Tildesley Eq. 2.143).
    pub fn tail_corrections(&self, density: f64) -> (f64, f64) {
        let (e, s) = (self.epsilon, self.sigma);
        let sr3 = (s / self.cutoff).powi(3);
        let sr9 = sr3 * sr3 * sr3;
        let pi = std::f64::consts::PI;
        let u = 8.0 / 3.0 * pi * density * e * s.powi(3) * (sr9 / 3.0 - sr3);
        let p = 16.0 / 3.0 * pi * density * density * e * s.powi(3) * (2.0 / 3.0 * sr9 - sr3);
        (u, p)
    }

    /// (force over r, energy) of a pair at squared distance r² < r_c².
    #[inline(always)]
    fn pair(&self, r2: f64) -> (f64, f64) {
        let s2 = self.sigma * self.sigma / r2;
        let s6 = s2 * s2 * s2;
        let f = 24.0 * self.epsilon * s6 * (2.0 * s6 - 1.0) / r2;
        (f, 4.0 * self.epsilon * (s6 * s6 - s6))
    }
}

impl Interaction for LennardJones {
    fn name(&self) -> &'static str {
        "lennard_jones"
    }

    /// Each pair once (half list, Newton's third law). The particles are cut
    /// into as many contiguous blocks as there are threads; each block adds
    /// its pairs' forces into a buffer of its own, and the buffers are summed
    /// in block order: the same bits for the same thread count.
    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let pos = state.position;
        let n = pos.len();
        self.list.update(pos, &self.boundary);
        let rc2 = self.cutoff * self.cutoff;
        let image = self.boundary.image();
        let blocks = rayon::current_num_threads().clamp(1, n.max(1));
        let per_block = n.div_ceil(blocks);
        self.buffers.resize_with(blocks, Vec::new);
        let mut buffers = std::mem::take(&mut self.buffers);
        let this = &*self;
        let virials: Vec<f64> = buffers
            .par_iter_mut()
            .enumerate()
            .map(|(b, buf)| {
                buf.clear();
                buf.resize(n, DVec3::ZERO);
                let mut w = 0.0;
                for i in b * per_block..((b + 1) * per_block).min(n) {
                    let ri = pos[i];
                    let mut fi = DVec3::ZERO;
                    for &j in this.list.of(i) {
                        let j = j as usize;
                        let d = image.apply(ri - pos[j]);
                        let r2 = d.length_squared();
                        if r2 < rc2 {
                            let (f_over_r, _) = this.pair(r2);
                            let f = d * f_over_r;
                            fi += f;
                            buf[j] -= f;
                            w += f_over_r * r2;
                        }
                    }
                    buf[i] += fi;
                }
                w
            })
            .collect();
        force
            .par_iter_mut()
            .enumerate()
            .with_min_len(1024)
            .for_each(|(i, f)| {
                for buf in &buffers {
                    *f += buf[i];
                }
            });
        self.buffers = buffers;
        self.virial = virials.iter().sum::<f64>();
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        let pos = state.position;
        self.list.update(pos, &self.boundary);
        let rc2 = self.cutoff * self.cutoff;
        let shift = self.shift();
        let this = &*self;
        let image = self.boundary.image();
        let per_i: Vec<f64> = (0..pos.len())
            .into_par_iter()
            .with_min_len(512)
            .map(|i| {
                let mut u = 0.0;
                for &j in this.list.of(i) {
                    let r2 = image.apply(pos[i] - pos[j as usize]).length_squared();
                    if r2 < rc2 {
                        u += this.pair(r2).1 - shift;
                    }
                }
                u
            })
            .collect();
        per_i.iter().sum::<f64>()
    }

    fn virial(&self) -> f64 {
        self.virial
    }
}
