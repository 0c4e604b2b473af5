//! The Lennard-Jones pair potential and its purely repulsive WCA form.
//!
//! U(r) = 4ε [(σ/r)¹² − (σ/r)⁶] − U(r_c) for r < r_c (shifted, or unshifted
//! with the tail corrections of Allen & Tildesley §2.8 available for the
//! energy and pressure), 0 beyond. WCA (Weeks–Chandler–Andersen, the
//! repulsion of 004 Eq. 9) is the shifted potential cut at its minimum
//! r_c = 2^{1/6} σ. The force on i from j is F_i = 24ε [2(σ/r)¹² − (σ/r)⁶] (r_i − r_j)/r².
//!
//! The pair loop runs over a [`GhostList`]: a full list (each pair seen from
//! both sides) over cell-sorted copies with periodic images as ghosts, so a
//! row sums the force on one particle from plain coordinate differences and
//! writes nothing else. Rows go eight neighbours at a time: with AVX-512
//! where the CPU has it (`avx512.rs`, 1/r² from `vrcp14pd` and two Newton
//! steps), else on [`Lanes`] (every CPU: AVX2 on the x86-64-v3 build, NEON
//! on aarch64); the one-neighbour-at-a-time loop [`row_reference`] is what
//! both are tested against, to a few ulp. Rows are summed in fixed blocks,
//! so every thread count gives the same bits.

use super::{HaloReach, Interaction, State, Virial};
use crate::neighbor::{Copy4, GhostList};
use glam::DVec3;
use mote_geom::lanes::{self, Lanes};

#[cfg(target_arch = "x86_64")]
mod avx512;

/// Lennard-Jones between all particles, through a Verlet list.
#[derive(Debug, Clone)]
pub struct LennardJones {
    pub epsilon: f64,
    pub sigma: f64,
    pub cutoff: f64,
    /// Subtract U(r_c) so the energy is continuous at the cut-off.
    pub shifted: bool,
    pub list: GhostList,
    virial: f64,
    /// Force on the particle of each row (see [`GhostList`]).
    sorted_force: Vec<DVec3>,
    rows: Rows,
}

/// The row kernels of [`LennardJones`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows {
    /// Eight neighbours at a time in AVX-512 registers (where the CPU has it).
    Avx512,
    /// Eight neighbours at a time on [`Lanes`] (every CPU).
    Lanes,
    /// One neighbour at a time: the reference the others are tested against.
    Reference,
}

impl Rows {
    /// The fastest the CPU (and `MOTE_SIMD`) allows.
    pub fn fastest() -> Self {
        if mote_geom::simd::has_avx512() {
            Rows::Avx512
        } else {
            Rows::Lanes
        }
    }
}

/// The constants of a row kernel: with s⁶ = (σ²/r²)³,
/// F/r = (48ε s⁶ − 24ε) s⁶ / r² and U = 4ε s⁶ (s⁶ − 1) − U(r_c).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Coefficients {
    pub cutoff2: f64,
    pub sigma2: f64,
    pub eps48: f64,
    pub eps24: f64,
    pub eps4: f64,
    pub shift: f64,
}

/// What a row adds up: the force on its particle, Σ (F/r) r² and Σ U over
/// its neighbours (each pair is in two rows, so the last two count twice).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct RowSum {
    pub force: DVec3,
    pub virial: f64,
    pub energy: f64,
}

impl LennardJones {
    /// LJ cut at `cutoff` (shifted or not) through a list with `skin`; the
    /// box comes with each step's [`State`].
    pub fn new(epsilon: f64, sigma: f64, cutoff: f64, shifted: bool, skin: f64) -> Self {
        Self {
            epsilon,
            sigma,
            cutoff,
            shifted,
            list: GhostList::new(cutoff, skin),
            virial: 0.0,
            sorted_force: Vec::new(),
            rows: Rows::fastest(),
        }
    }

    /// WCA: shifted LJ cut at 2^{1/6} σ.
    pub fn wca(epsilon: f64, sigma: f64, skin: f64) -> Self {
        Self::new(epsilon, sigma, 2f64.powf(1.0 / 6.0) * sigma, true, skin)
    }

    /// Runs `rows` (AVX-512 falls back to lanes on a CPU without it); for
    /// tests that compare the kernels.
    #[doc(hidden)]
    pub fn set_rows(&mut self, rows: Rows) {
        self.rows = match rows {
            Rows::Avx512 => Rows::fastest(),
            other => other,
        };
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

    fn coefficients(&self) -> Coefficients {
        Coefficients {
            cutoff2: self.cutoff * self.cutoff,
            sigma2: self.sigma * self.sigma,
            eps48: 48.0 * self.epsilon,
            eps24: 24.0 * self.epsilon,
            eps4: 4.0 * self.epsilon,
            shift: self.shift(),
        }
    }

    /// Brings the list to `state`: over the halo in a decomposed run, else
    /// over the particles and their images (counting a step when `step`).
    fn follow(&mut self, state: &State, step: bool) {
        match state.halo {
            Some(halo) => {
                self.list.follow_halo(halo, state.boundary);
            }
            None if step => {
                self.list.update(state.position, state.boundary);
            }
            None => {
                self.list.refresh(state.position, state.boundary);
            }
        }
    }

    /// Runs every row into `sorted_force` and returns the halved sums of
    /// the virial and the energy (both zero unless `energy`).
    fn rows(&self, sorted_force: &mut [DVec3], energy: bool) -> (f64, f64) {
        let list = &self.list;
        let c = self.coefficients();
        let kernel = self.rows;
        let [w, u] = list.sum_rows(sorted_force, |r| {
            let s = row(list, r, &c, energy, kernel);
            (s.force, [s.virial, s.energy])
        });
        (0.5 * w, 0.5 * u)
    }
}

/// The sums of row r, by `kernel`.
#[inline]
fn row(list: &GhostList, r: usize, c: &Coefficients, energy: bool, kernel: Rows) -> RowSum {
    let (k, neighbours) = (list.owner[r] as usize, list.row(r));
    match kernel {
        #[cfg(target_arch = "x86_64")]
        Rows::Avx512 => {
            // SAFETY: `Rows::Avx512` is chosen only where AVX-512F exists;
            // every listed neighbour and k itself index the coordinates.
            unsafe { avx512::row(k, neighbours, &list.position, c, energy) }
        }
        Rows::Reference => row_reference(k, neighbours, &list.position, c, energy),
        _ if energy => row_lanes::<true>(k, neighbours, &list.position, c),
        _ => row_lanes::<false>(k, neighbours, &list.position, c),
    }
}

/// One row, eight neighbours at a time on [`Lanes`]: the pair law of
/// [`row_reference`] lane by lane, each pair's force the same bits; the
/// row's sums go lane by lane, then over the lanes in order. Lanes filled
/// past the row's end sit at r² = ∞ and add nothing; a neighbour at no
/// distance is inside the cut-off and gives a non-finite force, as it must.
#[inline]
fn row_lanes<const ENERGY: bool>(
    k: usize,
    row: &[u32],
    position: &[Copy4],
    c: &Coefficients,
) -> RowSum {
    let records = Copy4::records(position);
    let [xi, yi, zi, _] = position[k].0;
    let zero = Lanes::splat(0.0);
    let (mut fx, mut fy, mut fz, mut w, mut u) = (zero, zero, zero, zero, zero);
    // The law inlined into the row's loop (its sums then stay in
    // registers): 6 % of the LJ melt on an AVX2 CPU. The larger dipolar
    // and P3M rows lost a third the same way, so they keep their calls.
    lanes::in_eights(
        row,
        k as u32,
        #[inline(always)]
        |index, pad| {
            let [xj, yj, zj] = lanes::gather_xyz(records, index);
            let (dx, dy, dz) = (
                Lanes::splat(xi) - xj,
                Lanes::splat(yi) - yj,
                Lanes::splat(zi) - zj,
            );
            let d2 = dx * dx + dy * dy + dz * dz;
            let r2 = d2 + pad;
            let inside = r2.select_below(c.cutoff2, 1.0, 0.0);
            let inv = Lanes::splat(1.0) / r2;
            let s2 = inv * c.sigma2;
            let s6 = s2 * s2 * s2;
            let f = inv * s6 * (s6 * c.eps48 - c.eps24) * inside;
            fx = fx + f * dx;
            fy = fy + f * dy;
            fz = fz + f * dz;
            if ENERGY {
                w = w + f * d2;
                u = u + (s6 * (s6 * c.eps4 - c.eps4) - c.shift) * inside;
            }
        },
    );
    RowSum {
        force: DVec3::new(fx.sum(), fy.sum(), fz.sum()),
        virial: w.sum(),
        energy: u.sum(),
    }
}

/// One row, one neighbour at a time, without branches on the distance:
/// the reference of the other kernels.
#[inline]
fn row_reference(
    k: usize,
    row: &[u32],
    position: &[Copy4],
    c: &Coefficients,
    energy: bool,
) -> RowSum {
    let [xi, yi, zi, _] = position[k].0;
    let mut s = RowSum::default();
    for &j in row {
        let [xj, yj, zj, _] = position[j as usize].0;
        let d = DVec3::new(xi - xj, yi - yj, zi - zj);
        let r2 = d.length_squared();
        let inside = r2 < c.cutoff2;
        let inv = 1.0 / if inside { r2 } else { 1.0 };
        let s2 = c.sigma2 * inv;
        let s6 = s2 * s2 * s2;
        let f_over_r = if inside {
            inv * s6 * (c.eps48 * s6 - c.eps24)
        } else {
            0.0
        };
        s.force += d * f_over_r;
        s.virial += f_over_r * r2;
        if energy && inside {
            s.energy += s6 * (c.eps4 * s6 - c.eps4) - c.shift;
        }
    }
    s
}

impl Interaction for LennardJones {
    fn name(&self) -> &'static str {
        "lennard_jones"
    }

    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach {
            cutoff: self.cutoff,
            skin: self.list.skin,
            every: self.list.every,
            moments: false,
            motion: false,
        })
    }

    fn take_restored_list(&mut self) -> Option<(u64, Vec<DVec3>)> {
        self.list.take_restored()
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let pos = state.position;
        self.follow(state, true);
        let mut sorted = std::mem::take(&mut self.sorted_force);
        sorted.resize(pos.len(), DVec3::ZERO);
        self.rows(&mut sorted, false);
        // The stepping pass sums forces only (the virial's sums cost 7 % of
        // the LJ melt); the virial is measured with the energy, which
        // `Observables::measure` asks for first. Until then it is not a
        // number, never a stale one.
        self.virial = f64::NAN;
        self.list.scatter_add(&sorted, force);
        self.sorted_force = sorted;
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        self.follow(state, false);
        // The virial comes with the energy, so a pressure measured before
        // the first step (no force evaluation yet) is right too.
        let mut sorted = std::mem::take(&mut self.sorted_force);
        sorted.resize(state.position.len(), DVec3::ZERO);
        let (virial, energy) = self.rows(&mut sorted, true);
        self.sorted_force = sorted;
        self.virial = virial;
        energy
    }

    /// The virial at the last [`Interaction::potential_energy`] (NaN
    /// after a force evaluation that came later).
    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    /// W_αβ = ½ Σ_rows Σ_j (F/r) r_α r_β over the full list, by the
    /// portable pair law (a measurement, not a step: no SIMD kernel).
    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        self.follow(state, false);
        let (list, c) = (&self.list, self.coefficients());
        let mut rows = vec![(); list.len()];
        let w = list.sum_rows(&mut rows, |r| {
            let xi = list.at(list.owner[r] as usize);
            let mut w = Virial::default();
            for &j in list.row(r) {
                let d = xi - list.at(j as usize);
                let r2 = d.length_squared();
                if r2 < c.cutoff2 {
                    let inv = 1.0 / r2;
                    let s6 = (c.sigma2 * inv).powi(3);
                    w += Virial::central(d, inv * s6 * (c.eps48 * s6 - c.eps24));
                }
            }
            ((), w.0)
        });
        Some(Virial(w).scaled(0.5))
    }

    /// The neighbour list's build (see [`GhostList::carried_state`]): rows
    /// are summed eight neighbours at a time, skin pairs included as zeros,
    /// so the bits of a force depend on when the list was built.
    fn carried_state(&self) -> Vec<f64> {
        self.list.carried_state()
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        self.list.restore(state)
    }
}
