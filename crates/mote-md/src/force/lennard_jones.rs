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
            list: VerletList::new(cutoff, skin),
            virial: 0.0,
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

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let pos = state.position;
        self.list.update(pos, &self.boundary);
        let rc2 = self.cutoff * self.cutoff;
        let this = &*self;
        let image = self.boundary.image();
        let virials: Vec<f64> = force
            .par_chunks_mut(512)
            .enumerate()
            .map(|(chunk, fs)| {
                let mut w = 0.0;
                for (k, f) in fs.iter_mut().enumerate() {
                    let i = chunk * 512 + k;
                    let ri = pos[i];
                    let mut fi = DVec3::ZERO;
                    for &j in this.list.of(i) {
                        let d = image.apply(ri - pos[j as usize]);
                        let r2 = d.length_squared();
                        if r2 < rc2 {
                            let (f_over_r, _) = this.pair(r2);
                            fi += d * f_over_r;
                            w += f_over_r * r2;
                        }
                    }
                    *f += fi;
                }
                w
            })
            .collect();
        // Each pair was visited from both ends.
        self.virial = 0.5 * virials.iter().sum::<f64>();
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
        0.5 * per_i.iter().sum::<f64>()
    }

    fn virial(&self) -> f64 {
        self.virial
    }
}
