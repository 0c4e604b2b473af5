//! Magnetic point dipoles: the dipole–dipole interaction (004 Eq. 8), the
//! Zeeman energy in an applied field (004 Eq. 10) and the Kelvin force of a
//! non-uniform field (004 Eqs. 4–5).
//!
//! With k = μ₀/(4π) and r = r_i − r_j, the pair energy is
//!
//! U_ij = k [ m_i·m_j / r³ − 3 (m_i·r)(m_j·r) / r⁵ ]           (004 Eq. 8)
//!
//! and its derivatives are, for the force on i (F_j = −F_i) and the torques
//! τ = m × B with B the field of the other dipole,
//!
//! F_i = k [ (3 m_i·m_j / r⁵ − 15 (m_i·r)(m_j·r) / r⁷) r + 3 ((m_j·r) m_i + (m_i·r) m_j) / r⁵ ],
//! τ_i = k [ 3 (m_j·r)(m_i × r) / r⁵ − m_i × m_j / r³ ],
//! τ_j = k [ 3 (m_i·r)(m_j × r) / r⁵ − m_j × m_i / r³ ],
//!
//! so that τ_i + τ_j + r × F_i = 0: total angular momentum is conserved.
//! (The seed's `ComputeDipole` has the force with the wrong sign on the
//! m_i·m_j term and a factor 10²¹ in place of units; its `torque` divides
//! −1/3 in integer arithmetic, which is 0. The formulas here are derived
//! from Eq. 8 and checked against finite differences of the energy.)
//!
//! Three ways to sum the pairs:
//!
//! - **all pairs** (open boundaries, no cut-off): exact; each pair is
//!   evaluated once, in tiles whose reactions are gathered in a fixed
//!   order (`tiled.rs`, as gravity does), so results are bit-identical for
//!   every thread count; past 65 536 particles each particle's row is
//!   summed over all others instead;
//! - **a spherical cut-off** r_c ≤ L/2 (periodic boxes: each pair's
//!   minimum image), through a full ghost list with SIMD rows
//!   (`listed.rs`; every thread count gives the same bits): an
//!   *approximation*. The dipolar sum converges only conditionally;
//!   truncating it at r_c amounts to a sphere of radius r_c around every
//!   dipole surrounded by vacuum, which leaves out the Lorentz field M/3 of
//!   the far dipoles and so underestimates magnetisation and susceptibility.
//!   The optional reaction field of a dielectric (here magnetic) continuum of
//!   permeability ε_RF beyond r_c (Barker & Watts, Mol. Phys. 26, 789 (1973);
//!   Neumann, Mol. Phys. 50, 841 (1983)) adds the pair term
//!   U_ij^RF = −k 2(ε_RF − 1)/(2ε_RF + 1) m_i·m_j / r_c³ for r < r_c
//!   (no force, torques m_i × c m_j); ε_RF = ∞ is the analogue of Ewald's
//!   tin-foil boundary. For precise periodic sums use Ewald summation
//!   (`force::ewald`). The cut-off is sharp: energy jumps when pairs cross
//!   it, as in LAMMPS' `lj/cut/dipole/cut`;
//! - optionally fused with a Lennard-Jones/WCA repulsion (004 Eq. 9) in the
//!   same pair loop, as LAMMPS' `lj/cut/dipole/cut` does: one neighbour
//!   list and one pass for both.
//!
//! Units: SI by default, with μ₀ from [`vacuum_permeability`]; the Zeeman
//! energy is U = −μ₀ m·H with H in A/m. In Lennard-Jones reduced units mote
//! takes μ₀ = 4π, i.e. k = μ₀/4π = 1 (the convention of LAMMPS and
//! ESPResSo): the coupling constant is then λ = m²/(σ³ k_BT) and a field
//! "B" = μ₀H enters as U = −m·B.
//!
//! The trait methods read the dipoles from [`State::dipole`] (the system's,
//! rotated with the particles); a state without dipoles gives no force.
//! [`DipoleDipole::energy`] and [`Zeeman::energy`] take them explicitly.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat3, DVec3};
use mote_geom::lanes::{Lane, V3};
use mote_geom::simd::{isa, Isa};
use rayon::prelude::*;

mod avx512;
mod listed;
mod portable;
mod tiled;

use super::whole::Whole;
use super::{HaloReach, Interaction, Spin, State, ViewerHooks, Virial};
use crate::boundary::Boundary;
use crate::domain::Halo;
use crate::neighbor::{Copy4, GhostList};
use crate::units::UnitSystem;

/// μ₀ in a unit system: SI 1.256 637 061 27 × 10⁻⁶ N/A² (CODATA 2022);
/// Lennard-Jones reduced units 4π (so that μ₀/4π = 1); none in astronomical
/// units, where magnetic dipoles make no sense.
pub fn vacuum_permeability(units: UnitSystem) -> Option<f64> {
    match units {
        UnitSystem::Si => Some(1.256_637_061_27e-6),
        UnitSystem::Lj => Some(4.0 * PI),
        UnitSystem::Astro => None,
    }
}

/// Something wrong with the settings of a dipolar interaction.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DipolarError {
    #[error("the dipolar cut-off {cutoff} must be at most half the shortest periodic box edge ({half_box}) for the minimum image")]
    CutoffTooLong { cutoff: f64, half_box: f64 },
    #[error("a periodic box needs a finite dipolar cut-off (or Ewald summation)")]
    PeriodicWithoutCutoff,
    #[error("{what} must be positive and finite, got {value}")]
    NotPositive { what: &'static str, value: f64 },
}

/// The field k [3 d (m·d)/r⁵ − m/r³] of a point dipole m at separation
/// d = r − r_m from it, with 1/r² = `inv_r2` (the field a torque
/// τ = μ × B and an induced moment see; its gradient gives the force of
/// [`dipole_pair`]).
#[inline(always)]
pub fn dipole_field(k: f64, m: DVec3, d: DVec3, inv_r2: f64) -> DVec3 {
    let inv_r3 = k * inv_r2 * inv_r2.sqrt();
    d * (3.0 * m.dot(d) * inv_r3 * inv_r2) - m * inv_r3
}

/// Energy, force on i, torque on i and torque on j of one dipole pair at
/// separation d = r_i − r_j with 1/r² = `inv_r2`, for prefactor k = μ₀/4π
/// (004 Eq. 8): the one dipole pair law of mote, used by point particles
/// (all pairs, cut-off, the magnetisation) and rigid bodies (permanent and
/// induced moments) alike.
#[inline(always)]
pub fn dipole_pair(
    k: f64,
    d: DVec3,
    inv_r2: f64,
    mi: DVec3,
    mj: DVec3,
) -> (f64, DVec3, DVec3, DVec3) {
    let inv_r = inv_r2.sqrt();
    let inv_r3 = k * inv_r * inv_r2;
    let inv_r5 = inv_r3 * inv_r2;
    let mi_r = mi.dot(d);
    let mj_r = mj.dot(d);
    let mimj = mi.dot(mj);
    let energy = mimj * inv_r3 - 3.0 * mi_r * mj_r * inv_r5;
    let radial = 3.0 * mimj * inv_r5 - 15.0 * mi_r * mj_r * inv_r5 * inv_r2;
    let force = d * radial + (mi * mj_r + mj * mi_r) * (3.0 * inv_r5);
    let mi_x_mj = mi.cross(mj);
    let torque_i = mi.cross(d) * (3.0 * mj_r * inv_r5) - mi_x_mj * inv_r3;
    let torque_j = mj.cross(d) * (3.0 * mi_r * inv_r5) + mi_x_mj * inv_r3;
    (energy, force, torque_i, torque_j)
}

/// [`dipole_field`] of a lane of moments at a lane of separations, each
/// lane its operations in its order: every lane gets the scalar law's bits.
#[inline(always)]
pub fn dipole_field_lanes<L: Lane>(k: f64, m: V3<L>, d: V3<L>, inv_r2: L) -> V3<L> {
    let inv_r3 = inv_r2 * k * inv_r2.sqrt();
    let along = m.dot(d) * 3.0 * inv_r3 * inv_r2;
    d.scale(along).sub(m.scale(inv_r3))
}

/// The force on i of [`dipole_pair`], lane by lane in its operations and
/// their order (the scalar law's bits in every lane).
#[inline(always)]
pub fn dipole_pair_force_lanes<L: Lane>(
    k: f64,
    d: V3<L>,
    inv_r2: L,
    mi: V3<L>,
    mj: V3<L>,
) -> V3<L> {
    let inv_r3 = inv_r2.sqrt() * k * inv_r2;
    let inv_r5 = inv_r3 * inv_r2;
    let (mi_r, mj_r, mimj) = (mi.dot(d), mj.dot(d), mi.dot(mj));
    let radial = mimj * 3.0 * inv_r5 - mi_r * 15.0 * mj_r * inv_r5 * inv_r2;
    d.scale(radial)
        .add(mi.scale(mj_r).add(mj.scale(mi_r)).scale(inv_r5 * 3.0))
}

/// The Lennard-Jones part fused into the dipolar pair loop (004 Eq. 9 when
/// cut at 2^{1/6} σ and shifted: WCA).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairRepulsion {
    pub epsilon: f64,
    pub sigma: f64,
    pub cutoff: f64,
    /// Subtract U(r_c) so the energy is continuous at the cut-off.
    pub shifted: bool,
}

impl PairRepulsion {
    /// Weeks–Chandler–Andersen: shifted LJ cut at its minimum 2^{1/6} σ.
    pub fn wca(epsilon: f64, sigma: f64) -> Self {
        Self {
            epsilon,
            sigma,
            cutoff: 2f64.powf(1.0 / 6.0) * sigma,
            shifted: true,
        }
    }

    /// Full Lennard-Jones cut (unshifted, LAMMPS' `lj/cut`) at `cutoff`.
    pub fn lennard_jones(epsilon: f64, sigma: f64, cutoff: f64) -> Self {
        Self {
            epsilon,
            sigma,
            cutoff,
            shifted: false,
        }
    }

    fn shift(&self) -> f64 {
        if self.shifted {
            let s6 = (self.sigma / self.cutoff).powi(6);
            4.0 * self.epsilon * (s6 * s6 - s6)
        } else {
            0.0
        }
    }
}

/// Pair parameters copied into the hot loops.
#[derive(Debug, Clone, Copy)]
struct Kernel {
    /// μ₀/4π.
    k: f64,
    /// Dipolar cut-off squared (∞ for all pairs).
    rc2: f64,
    /// Reaction-field coefficient k 2(ε_RF − 1)/(2ε_RF + 1)/r_c³.
    rf: f64,
    /// LJ: 4ε, σ², r_c², shift (r_c² = 0 when absent).
    lj4e: f64,
    lj_s2: f64,
    lj_rc2: f64,
    lj_shift: f64,
}

impl Kernel {
    /// (energy, force on i, torque on i, torque on j, virial r·F) of a pair.
    #[inline(always)]
    fn pair(&self, d: DVec3, r2: f64, mi: DVec3, mj: DVec3) -> (f64, DVec3, DVec3, DVec3, f64) {
        let mut u = 0.0;
        let mut f = DVec3::ZERO;
        let mut ti = DVec3::ZERO;
        let mut tj = DVec3::ZERO;
        let mut w = 0.0;
        let inv_r2 = 1.0 / r2;
        if r2 < self.rc2 {
            let (e, fd, a, b) = dipole_pair(self.k, d, inv_r2, mi, mj);
            u = e;
            f = fd;
            ti = a;
            tj = b;
            if self.rf != 0.0 {
                let mi_x_mj = mi.cross(mj);
                u -= self.rf * mi.dot(mj);
                ti += mi_x_mj * self.rf;
                tj -= mi_x_mj * self.rf;
            }
            w = fd.dot(d);
        }
        if r2 < self.lj_rc2 {
            let s2 = self.lj_s2 * inv_r2;
            let s6 = s2 * s2 * s2;
            let f_over_r = 6.0 * self.lj4e * s6 * (2.0 * s6 - 1.0) * inv_r2;
            u += self.lj4e * (s6 * s6 - s6) - self.lj_shift;
            f += d * f_over_r;
            w += f_over_r * r2;
        }
        (u, f, ti, tj, w)
    }

    #[inline(always)]
    fn reach2(&self) -> f64 {
        self.rc2.max(self.lj_rc2)
    }
}

/// Dipole–dipole interaction (004 Eq. 8) between all particles with a
/// non-zero moment, optionally with a fused LJ/WCA repulsion (004 Eq. 9).
#[derive(Debug, Clone)]
pub struct DipoleDipole {
    /// μ₀ (see [`vacuum_permeability`]).
    pub mu0: f64,
    /// Dipolar cut-off r_c (∞: all pairs, open boundaries only).
    pub cutoff: f64,
    /// Permeability ε_RF of the continuum beyond r_c (1: plain truncation,
    /// ∞: conducting, the analogue of tin-foil Ewald).
    pub reaction_field: f64,
    pub repulsion: Option<PairRepulsion>,
    pub boundary: Boundary,
    /// Full list over sorted copies and periodic ghosts (cut-off mode only).
    pub list: GhostList,
    virial: f64,
    /// The moments of the list's copies (cut-off mode).
    moment: Vec<Copy4>,
    /// Force and torque of each row of the list (cut-off mode).
    sorted: Vec<(DVec3, DVec3)>,
    /// Structure-of-arrays copies for the all-pairs loop, padded with
    /// zeros to a multiple of 8.
    soa: Soa,
    /// Scratch of the all-pairs tiles (`tiled.rs`).
    tiles: Vec<tiled::TileRow>,
    /// The row kernels' instruction set.
    isa: Isa,
    /// Run the cut-off rows one neighbour at a time (the reference the
    /// eight-lane rows are tested against).
    reference_rows: bool,
}

#[derive(Debug, Clone, Default)]
struct Soa {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    mx: Vec<f64>,
    my: Vec<f64>,
    mz: Vec<f64>,
}

impl DipoleDipole {
    /// Every pair, no cut-off: for open boundaries (clusters, chains, the
    /// seed's test cases). Exact.
    pub fn all_pairs(mu0: f64) -> Self {
        Self {
            mu0,
            cutoff: f64::INFINITY,
            reaction_field: 1.0,
            repulsion: None,
            boundary: Boundary::open(),
            list: GhostList::new(0.0, 0.0),
            virial: 0.0,
            moment: Vec::new(),
            sorted: Vec::new(),
            soa: Soa::default(),
            tiles: Vec::new(),
            isa: isa(),
            reference_rows: false,
        }
    }

    /// Pairs closer than `cutoff`, found through a ghost list with `skin`
    /// (each periodic image within the cut-off, which r_c ≤ L/2 makes the
    /// minimum image; an approximation for periodic systems: see the
    /// module page).
    pub fn cut_off(
        mu0: f64,
        cutoff: f64,
        skin: f64,
        boundary: Boundary,
    ) -> Result<Self, DipolarError> {
        for (what, value) in [("mu0", mu0), ("the dipolar cut-off", cutoff)] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(DipolarError::NotPositive { what, value });
            }
        }
        let mut s = Self::all_pairs(mu0);
        s.cutoff = cutoff;
        s.boundary = boundary;
        s.list = GhostList::new(cutoff, skin);
        s.check_box(cutoff)?;
        Ok(s)
    }

    /// Adds a conducting (ε_RF = ∞) or permeable reaction field beyond the cut-off.
    pub fn with_reaction_field(mut self, permeability: f64) -> Self {
        self.reaction_field = permeability;
        self
    }

    /// Fuses a LJ/WCA repulsion into the pair loop.
    pub fn with_repulsion(mut self, repulsion: PairRepulsion) -> Result<Self, DipolarError> {
        if self.cutoff.is_finite() {
            self.check_box(repulsion.cutoff)?;
            self.list.cutoff = self.cutoff.max(repulsion.cutoff);
        }
        self.repulsion = Some(repulsion);
        Ok(self)
    }

    fn check_box(&self, cutoff: f64) -> Result<(), DipolarError> {
        let l = self.boundary.lengths();
        let mut half_box = f64::INFINITY;
        for k in 0..3 {
            if self.boundary.periodic[k] {
                half_box = half_box.min(0.5 * l[k]);
            }
        }
        if cutoff > half_box {
            return Err(DipolarError::CutoffTooLong { cutoff, half_box });
        }
        if !cutoff.is_finite() && self.boundary.is_periodic() {
            return Err(DipolarError::PeriodicWithoutCutoff);
        }
        Ok(())
    }

    /// Uses the AVX-512 rows where the CPU has them (the default) or the
    /// portable ones; for tests that compare the two.
    #[doc(hidden)]
    pub fn set_simd(&mut self, on: bool) {
        self.isa = if on { isa() } else { Isa::Portable };
    }

    /// Runs the cut-off rows one neighbour at a time, the reference of
    /// both eight-lane kernels; for tests.
    #[doc(hidden)]
    pub fn set_reference_rows(&mut self, on: bool) {
        self.reference_rows = on;
    }

    fn kernel(&self) -> Kernel {
        let k = self.mu0 / (4.0 * PI);
        let rf = if self.cutoff.is_finite() && self.reaction_field != 1.0 {
            let e = self.reaction_field;
            let factor = if e.is_infinite() {
                1.0
            } else {
                2.0 * (e - 1.0) / (2.0 * e + 1.0)
            };
            k * factor / self.cutoff.powi(3)
        } else {
            0.0
        };
        let (lj4e, lj_s2, lj_rc2, lj_shift) = match self.repulsion {
            Some(r) => (
                4.0 * r.epsilon,
                r.sigma * r.sigma,
                r.cutoff * r.cutoff,
                r.shift(),
            ),
            None => (0.0, 1.0, 0.0, 0.0),
        };
        Kernel {
            k,
            rc2: self.cutoff * self.cutoff,
            rf,
            lj4e,
            lj_s2,
            lj_rc2,
            lj_shift,
        }
    }

    /// Adds forces and torques at positions `pos` with moments `dipoles`
    /// (in this interaction's box); returns the virial Σ r_ij·F_ij of all
    /// pairs in open space, and NaN with a cut-off, whose stepping pass
    /// leaves the virial out (the energy's pass measures it: [`Interaction::virial`]).
    pub fn forces_and_torques(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) -> f64 {
        let boundary = self.boundary;
        self.forces_in(pos, dipoles, &boundary, None, force, torque)
    }

    /// [`Self::forces_and_torques`] in `boundary`.
    fn forces_in(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        boundary: &Boundary,
        halo: Option<&Halo>,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) -> f64 {
        assert_eq!(pos.len(), dipoles.len(), "one dipole per particle");
        self.virial = if self.cutoff.is_finite() {
            // The stepping pass sums forces and torques only; the virial is
            // measured with the energy, which `Observables::measure` asks
            // for first. Until then it is not a number, never a stale one.
            self.cut_off_rows(pos, dipoles, boundary, halo, true, false);
            self.add_sorted(force, torque);
            f64::NAN
        } else {
            self.all_pairs_forces(pos, dipoles, force, torque)
        };
        self.virial
    }

    /// The potential energy at positions `pos` with moments `dipoles` (in
    /// this interaction's box).
    pub fn energy(&mut self, pos: &[DVec3], dipoles: &[DVec3]) -> f64 {
        let boundary = self.boundary;
        self.energy_in(pos, dipoles, &boundary, None)
    }

    fn energy_in(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        boundary: &Boundary,
        halo: Option<&Halo>,
    ) -> f64 {
        assert_eq!(pos.len(), dipoles.len(), "one dipole per particle");
        if self.cutoff.is_finite() {
            let (virial, energy) = self.cut_off_rows(pos, dipoles, boundary, halo, false, true);
            self.virial = virial;
            return energy;
        }
        let kern = self.kernel();
        let n = pos.len();
        let per_i: Vec<f64> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|i| {
                let mut u = 0.0;
                for j in i + 1..n {
                    let d = pos[i] - pos[j];
                    let r2 = d.length_squared();
                    if r2 > 0.0 {
                        u += kern.pair(d, r2, dipoles[i], dipoles[j]).0;
                    }
                }
                u
            })
            .collect();
        per_i.iter().sum()
    }

    /// All pairs: each pair once in tiles with reactions (`tiled.rs`) up
    /// to [`tiled::TILED_MAX`] particles, beyond that each particle's row
    /// over all others (every pair twice). Either way the same bits for
    /// every thread count. Positions and moments are copied into separate
    /// arrays so that the inner loop vectorises; with AVX-512, 8 partners
    /// per instruction.
    fn all_pairs_forces(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) -> f64 {
        let isa = self.isa;
        self.all_pairs_forces_with(pos, dipoles, force, torque, isa, true)
    }

    fn all_pairs_forces_with(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
        isa: Isa,
        tiled: bool,
    ) -> f64 {
        let n = pos.len();
        self.load(pos, dipoles);
        if tiled && n <= tiled::TILED_MAX {
            return self.tiled_forces(n, force, torque, isa);
        }
        let kern = self.kernel();
        let soa = &self.soa;
        let virials: Vec<f64> = force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .enumerate()
            .with_min_len(16)
            .map(|(i, (f, t))| {
                let (fi, ti, w) = match isa {
                    // SAFETY: the CPU supports AVX-512F (`isa`); the arrays have length ≥ n.
                    #[cfg(target_arch = "x86_64")]
                    Isa::Avx512 => unsafe { avx512::all_pairs_row(&kern, soa, i, n) },
                    Isa::Portable => all_pairs_row(&kern, soa, i, n),
                };
                *f += fi;
                *t += ti;
                w
            })
            .collect();
        0.5 * virials.iter().sum::<f64>()
    }
}

impl DipoleDipole {
    /// Copies positions and moments into the structure-of-arrays scratch,
    /// padded to a multiple of the lanes with zero moments.
    fn load(&mut self, pos: &[DVec3], dipoles: &[DVec3]) {
        let n = pos.len();
        let npad = n.div_ceil(LANES) * LANES;
        let s = &mut self.soa;
        for (v, c) in [
            (&mut s.x, 0),
            (&mut s.y, 1),
            (&mut s.z, 2),
            (&mut s.mx, 3),
            (&mut s.my, 4),
            (&mut s.mz, 5),
        ] {
            v.clear();
            v.extend((0..n).map(|i| if c < 3 { pos[i][c] } else { dipoles[i][c - 3] }));
            v.resize(npad, 0.0);
        }
    }

    /// All pairs on ranks: the forces and torques on `rows` of the whole
    /// (`pos`, `dipoles`: every particle in id order), each row over every
    /// partner in id order — the row kernel one process uses beyond the
    /// tiles' reach — so a row's bits do not depend on the rank count.
    fn all_pairs_rows(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        rows: &[usize],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let n = pos.len();
        self.load(pos, dipoles);
        let (kern, soa, isa) = (self.kernel(), &self.soa, self.isa);
        let virials: Vec<f64> = force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .zip(rows)
            .with_min_len(16)
            .map(|((f, t), &i)| {
                let (fi, ti, w) = match isa {
                    // SAFETY: the CPU supports AVX-512F (`isa`); the arrays have length ≥ n.
                    #[cfg(target_arch = "x86_64")]
                    Isa::Avx512 => unsafe { avx512::all_pairs_row(&kern, soa, i, n) },
                    Isa::Portable => all_pairs_row(&kern, soa, i, n),
                };
                *f += fi;
                *t += ti;
                w
            })
            .collect();
        // This rank's share of the virial, as its rows give it.
        self.virial = 0.5 * virials.iter().sum::<f64>();
    }

    /// ½ Σ_{i ∈ rows} Σ_{j≠i} U_ij over the whole: a rank's share of the
    /// all-pairs energy.
    fn all_pairs_energy_rows(&self, pos: &[DVec3], dipoles: &[DVec3], rows: &[usize]) -> f64 {
        let kern = self.kernel();
        let per_i: Vec<f64> = rows
            .par_iter()
            .with_min_len(16)
            .map(|&i| {
                let mut u = 0.0;
                for j in (0..pos.len()).filter(|&j| j != i) {
                    let d = pos[i] - pos[j];
                    let r2 = d.length_squared();
                    if r2 > 0.0 {
                        u += kern.pair(d, r2, dipoles[i], dipoles[j]).0;
                    }
                }
                0.5 * u
            })
            .collect();
        per_i.iter().sum()
    }

    /// The whole system where this is a decomposed run of all pairs: the
    /// rank's share is then evaluated row by row ([`Whole`]).
    fn whole_on_ranks(&self, state: &State) -> Option<(Whole<DVec3>, Vec<usize>)> {
        if self.cutoff.is_finite() || state.halo.is_none() || state.comm.is_none() {
            return None;
        }
        let mut whole = Whole::dipoles(state);
        let (rows, _) = whole.rows.take()?;
        Some((whole, rows))
    }
}

/// Lanes of the all-pairs inner loop: independent partial sums, so that
/// the loop vectorises (floating-point sums are not reassociated by the
/// compiler) and the result is the same on every CPU.
const LANES: usize = 8;

/// Force and torque on particle i from the first n others, and its share
/// of the virial: branch-free lanes, the self pair masked by r² = 0, the
/// partial sums of the lanes added in a fixed order.
#[inline(always)]
fn all_pairs_row(kern: &Kernel, s: &Soa, i: usize, n: usize) -> (DVec3, DVec3, f64) {
    let (xi, yi, zi) = (s.x[i], s.y[i], s.z[i]);
    let (ax, ay, az) = (s.mx[i], s.my[i], s.mz[i]);
    let k = kern.k;
    let mut acc = [[0.0f64; LANES]; 7];
    let full = n - n % LANES;
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn lane(
        kern: &Kernel,
        k: f64,
        dx: f64,
        dy: f64,
        dz: f64,
        a: (f64, f64, f64),
        b: (f64, f64, f64),
    ) -> [f64; 7] {
        let (ax, ay, az) = a;
        let (bx, by, bz) = b;
        let r2 = dx * dx + dy * dy + dz * dz;
        let inv_r2 = if r2 > 0.0 { 1.0 / r2 } else { 0.0 };
        let inv_r3 = k * inv_r2 * inv_r2.sqrt();
        let inv_r5 = inv_r3 * inv_r2;
        let a_r = ax * dx + ay * dy + az * dz;
        let b_r = bx * dx + by * dy + bz * dz;
        let ab = ax * bx + ay * by + az * bz;
        let c = 3.0 * inv_r5;
        let radial = c * ab - 5.0 * c * a_r * b_r * inv_r2;
        // LJ repulsion, masked to r² < r_c² (r_c² = 0 when absent).
        let s2 = kern.lj_s2 * inv_r2;
        let s6 = s2 * s2 * s2;
        let lj = if r2 < kern.lj_rc2 {
            6.0 * kern.lj4e * s6 * (2.0 * s6 - 1.0) * inv_r2
        } else {
            0.0
        };
        let gx = dx * (radial + lj) + c * (ax * b_r + bx * a_r);
        let gy = dy * (radial + lj) + c * (ay * b_r + by * a_r);
        let gz = dz * (radial + lj) + c * (az * b_r + bz * a_r);
        // τ_i = m_i × B_j, B_j = k (3 (m_j·r) r / r⁵ − m_j / r³).
        let bfx = c * b_r * dx - inv_r3 * bx;
        let bfy = c * b_r * dy - inv_r3 * by;
        let bfz = c * b_r * dz - inv_r3 * bz;
        [
            gx,
            gy,
            gz,
            ay * bfz - az * bfy,
            az * bfx - ax * bfz,
            ax * bfy - ay * bfx,
            gx * dx + gy * dy + gz * dz,
        ]
    }
    let a = (ax, ay, az);
    for j0 in (0..full).step_by(LANES) {
        let x: &[f64; LANES] = s.x[j0..j0 + LANES].try_into().unwrap();
        let y: &[f64; LANES] = s.y[j0..j0 + LANES].try_into().unwrap();
        let z: &[f64; LANES] = s.z[j0..j0 + LANES].try_into().unwrap();
        let mx: &[f64; LANES] = s.mx[j0..j0 + LANES].try_into().unwrap();
        let my: &[f64; LANES] = s.my[j0..j0 + LANES].try_into().unwrap();
        let mz: &[f64; LANES] = s.mz[j0..j0 + LANES].try_into().unwrap();
        for l in 0..LANES {
            let v = lane(
                kern,
                k,
                xi - x[l],
                yi - y[l],
                zi - z[l],
                a,
                (mx[l], my[l], mz[l]),
            );
            for q in 0..7 {
                acc[q][l] += v[q];
            }
        }
    }
    for j in full..n {
        let v = lane(
            kern,
            k,
            xi - s.x[j],
            yi - s.y[j],
            zi - s.z[j],
            a,
            (s.mx[j], s.my[j], s.mz[j]),
        );
        for q in 0..7 {
            acc[q][j - full] += v[q];
        }
    }
    let sum = |q: usize| acc[q].iter().sum::<f64>();
    (
        DVec3::new(sum(0), sum(1), sum(2)),
        DVec3::new(sum(3), sum(4), sum(5)),
        sum(6),
    )
}

impl Interaction for DipoleDipole {
    fn name(&self) -> &'static str {
        "dipole_dipole"
    }

    /// Forces alone (the torques are dropped); integrators that rotate
    /// call `add_forces_and_torques` instead.
    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        if state.dipole.len() == state.position.len() {
            let mut torque = vec![DVec3::ZERO; force.len()];
            if let Some((whole, rows)) = self.whole_on_ranks(state) {
                self.all_pairs_rows(&whole.position, &whole.value, &rows, force, &mut torque);
                return;
            }
            self.forces_in(
                state.position,
                state.dipole,
                state.boundary,
                state.halo,
                force,
                &mut torque,
            );
        }
    }

    fn exerts_torques(&self) -> bool {
        true
    }

    /// With a cut-off: its ghost list over the halo, the moments
    /// forwarded. All pairs (open space): every rank gathers every
    /// particle's position and moment in id order ([`Whole`]) and sums its
    /// own particles' rows over all of them; no ghosts.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(match self.cutoff.is_finite() {
            true => HaloReach {
                cutoff: self.list.cutoff,
                skin: self.list.skin,
                every: self.list.every,
                moments: true,
                motion: false,
            },
            false => HaloReach::NONE,
        })
    }

    fn take_restored_list(&mut self) -> Option<(u64, Vec<DVec3>)> {
        self.list.take_restored()
    }

    fn add_forces_and_torques(
        &mut self,
        state: &State,
        _spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        if state.dipole.len() == state.position.len() {
            if let Some((whole, rows)) = self.whole_on_ranks(state) {
                self.all_pairs_rows(&whole.position, &whole.value, &rows, force, torque);
                return;
            }
            self.forces_in(
                state.position,
                state.dipole,
                state.boundary,
                state.halo,
                force,
                torque,
            );
        }
    }

    /// Σ_{i<j} U_ij (0 for a state without dipoles; on ranks of all
    /// pairs, this rank's share ½ Σ_{i own} Σ_{j≠i} U_ij).
    fn potential_energy(&mut self, state: &State) -> f64 {
        if state.dipole.len() == state.position.len() {
            if let Some((whole, rows)) = self.whole_on_ranks(state) {
                return self.all_pairs_energy_rows(&whole.position, &whole.value, &rows);
            }
            self.energy_in(state.position, state.dipole, state.boundary, state.halo)
        } else {
            0.0
        }
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    /// With a cut-off (the only case a periodic box has): ½ Σ_rows Σ_j
    /// r ⊗ F by the portable pair law, the fused LJ/WCA part included.
    /// All pairs (open space, no pressure): `None`.
    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        if !self.cutoff.is_finite() {
            return None;
        }
        if state.dipole.len() != state.position.len() {
            return Some(Virial::default());
        }
        self.follow(
            state.position,
            state.dipole,
            state.boundary,
            state.halo,
            false,
        );
        let list = &self.list;
        let (kern, moment) = (self.kernel(), &self.moment);
        let xyz = |c: &Copy4| DVec3::new(c.0[0], c.0[1], c.0[2]);
        let mut rows = vec![(); list.len()];
        let w = list.sum_rows(&mut rows, |r| {
            let k = list.owner[r] as usize;
            let (ri, mi) = (list.at(k), xyz(&moment[k]));
            let mut w = Virial::default();
            for &j in list.row(r) {
                let d = ri - list.at(j as usize);
                let r2 = d.length_squared();
                if r2 < kern.reach2() {
                    let (_, f, _, _, _) = kern.pair(d, r2, mi, xyz(&moment[j as usize]));
                    w += Virial::pair(d, f);
                }
            }
            ((), w.0)
        });
        Some(Virial(w).scaled(0.5))
    }

    /// The ghost list's build (see [`GhostList::carried_state`]): rows are
    /// summed eight neighbours at a time, skin pairs included as zeros, so
    /// the bits of a force depend on when the list was built.
    fn carried_state(&self) -> Vec<f64> {
        self.list.carried_state()
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        self.list.restore(state)
    }
}

/// An applied magnetic field H(r, t) (A/m in SI).
#[derive(Clone)]
pub enum AppliedField {
    /// Constant and uniform.
    Uniform(DVec3),
    /// Uniform, rotating about `axis` with angular frequency ω:
    /// H(t) = H₀ (e₁ cos(ωt + φ) + e₂ sin(ωt + φ)) with (e₁, e₂, axis)
    /// right-handed, so the field turns counter-clockwise about the axis.
    Rotating {
        amplitude: f64,
        angular_frequency: f64,
        axis: DVec3,
        phase: f64,
    },
    /// Uniform, any function of time.
    TimeDependent(Arc<dyn Fn(f64) -> DVec3 + Send + Sync>),
    /// H(r) = H₀ + G r with G_ab = ∂H_a/∂r_b. A field in a current-free region is curl-free
    /// (G symmetric) and, outside magnetised matter, divergence-free (tr G = 0).
    LinearGradient { h0: DVec3, gradient: DMat3 },
    /// The field of a point dipole s at p (a small permanent magnet):
    /// H = (1/4π) [3 (s·d) d / d⁵ − s / d³], d = r − p.
    PointDipole { position: DVec3, moment: DVec3 },
}

impl std::fmt::Debug for AppliedField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AppliedField::Uniform(h) => write!(f, "Uniform({h})"),
            AppliedField::Rotating {
                amplitude,
                angular_frequency,
                axis,
                phase,
            } => write!(f, "Rotating {{ amplitude: {amplitude}, angular_frequency: {angular_frequency}, axis: {axis}, phase: {phase} }}"),
            AppliedField::TimeDependent(_) => write!(f, "TimeDependent(fn)"),
            AppliedField::LinearGradient { h0, gradient } => write!(f, "LinearGradient {{ h0: {h0}, gradient: {gradient} }}"),
            AppliedField::PointDipole { position, moment } => write!(f, "PointDipole {{ position: {position}, moment: {moment} }}"),
        }
    }
}

impl AppliedField {
    /// H at position r and time t.
    pub fn at(&self, r: DVec3, t: f64) -> DVec3 {
        match self {
            AppliedField::Uniform(h) => *h,
            AppliedField::Rotating {
                amplitude,
                angular_frequency,
                axis,
                phase,
            } => {
                let (e1, e2) = rotation_plane(*axis);
                let (s, c) = (angular_frequency * t + phase).sin_cos();
                (e1 * c + e2 * s) * *amplitude
            }
            AppliedField::TimeDependent(h) => h(t),
            AppliedField::LinearGradient { h0, gradient } => *h0 + *gradient * r,
            AppliedField::PointDipole { position, moment } => {
                let d = r - *position;
                let inv_r2 = 1.0 / d.length_squared();
                let inv_r3 = inv_r2 * inv_r2.sqrt() / (4.0 * PI);
                (d * (3.0 * moment.dot(d) * inv_r2) - *moment) * inv_r3
            }
        }
    }

    /// Whether H is the same everywhere (then it exerts no force).
    pub fn is_uniform(&self) -> bool {
        matches!(
            self,
            AppliedField::Uniform(_)
                | AppliedField::Rotating { .. }
                | AppliedField::TimeDependent(_)
        )
    }

    /// (energy, force, torque) on moment m at r, time t, for μ₀.
    #[inline]
    fn zeeman(&self, mu0: f64, r: DVec3, m: DVec3, t: f64) -> (f64, DVec3, DVec3) {
        match self {
            AppliedField::PointDipole { position, moment } => {
                // U = −μ₀ m·H is the pair energy of m and the source s (Eq. 8).
                let d = r - *position;
                let (u, f, tau, _) =
                    dipole_pair(mu0 / (4.0 * PI), d, 1.0 / d.length_squared(), m, *moment);
                (u, f, tau)
            }
            AppliedField::LinearGradient { gradient, .. } => {
                let h = self.at(r, t);
                // F = −∇U = μ₀ ∇(m·H) = μ₀ Gᵀ m (the Kelvin force, 004 Eq. 5).
                (
                    -mu0 * m.dot(h),
                    gradient.transpose() * m * mu0,
                    m.cross(h) * mu0,
                )
            }
            _ => {
                let h = self.at(r, t);
                (-mu0 * m.dot(h), DVec3::ZERO, m.cross(h) * mu0)
            }
        }
    }
}

/// An orthonormal pair (e₁, e₂) with e₁ × e₂ = axis/|axis|; for the z axis, (x, y).
fn rotation_plane(axis: DVec3) -> (DVec3, DVec3) {
    let n = axis.normalize();
    let e1 = if n.x.abs() < 0.9 {
        (DVec3::X - n * n.x).normalize()
    } else {
        (DVec3::Y - n * n.y).normalize()
    };
    (e1, n.cross(e1))
}

/// The Zeeman interaction of every dipole with an applied field
/// (004 Eq. 10): U_i = −μ₀ m_i·H(r_i, t), torque τ_i = μ₀ m_i × H, and in a
/// non-uniform field the force F_i = μ₀ ∇(m_i·H) (004 Eq. 5).
#[derive(Debug, Clone)]
pub struct Zeeman {
    pub mu0: f64,
    pub field: AppliedField,
}

impl Zeeman {
    pub fn new(mu0: f64, field: AppliedField) -> Self {
        Self { mu0, field }
    }

    /// A uniform constant field H.
    pub fn uniform(mu0: f64, h: DVec3) -> Self {
        Self::new(mu0, AppliedField::Uniform(h))
    }

    /// Adds forces and torques at time t.
    pub fn forces_and_torques(
        &self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        t: f64,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let uniform = self.field.is_uniform();
        let h = self.field.at(DVec3::ZERO, t);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
            .for_each(|(i, (f, tau))| {
                let m = dipoles[i];
                if uniform {
                    *tau += m.cross(h) * self.mu0;
                } else if m != DVec3::ZERO {
                    let (_, fi, ti) = self.field.zeeman(self.mu0, pos[i], m, t);
                    *f += fi;
                    *tau += ti;
                }
            });
    }

    /// Σ_i −μ₀ m_i·H(r_i, t).
    pub fn energy(&self, pos: &[DVec3], dipoles: &[DVec3], t: f64) -> f64 {
        (0..pos.len())
            .filter(|&i| dipoles[i] != DVec3::ZERO)
            .map(|i| self.field.zeeman(self.mu0, pos[i], dipoles[i], t).0)
            .sum()
    }
}

impl Interaction for Zeeman {
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        Some(self)
    }

    /// A force and torque on each dipole alone.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach::NONE)
    }

    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    /// Not part of the pressure (see [`Interaction::virial`]).
    fn virial(&self) -> Option<f64> {
        Some(0.0)
    }

    fn virial_tensor(&mut self, _: &State) -> Option<Virial> {
        Some(Virial::default())
    }

    fn name(&self) -> &'static str {
        "zeeman"
    }

    /// The gradient force alone (none in a uniform field).
    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        if !self.field.is_uniform() && state.dipole.len() == state.position.len() {
            let mut torque = vec![DVec3::ZERO; force.len()];
            self.forces_and_torques(
                state.position,
                state.dipole,
                state.step.time,
                force,
                &mut torque,
            );
        }
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
        if state.dipole.len() == state.position.len() {
            self.forces_and_torques(state.position, state.dipole, state.step.time, force, torque);
        }
    }

    /// Σ_i −μ₀ m_i·H(r_i, t) (0 for a state without dipoles).
    fn potential_energy(&mut self, state: &State) -> f64 {
        if state.dipole.len() == state.position.len() {
            self.energy(state.position, state.dipole, state.step.time)
        } else {
            0.0
        }
    }
}

impl ViewerHooks for Zeeman {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        let mote_run::Change::Field {
            kind: mote_run::FieldKind::Magnetic,
            value,
        } = change
        else {
            return None;
        };
        let AppliedField::Uniform(h) = self.field else {
            return Some(Err(
                "the applied magnetic field rotates or has a gradient: only a constant, uniform one can be set"
                    .into(),
            ));
        };
        let new = DVec3::from(*value);
        self.field = AppliedField::Uniform(new);
        Some(Ok(format!(
            "magnetic field H {} → {}",
            crate::force::vector_text(h),
            crate::force::vector_text(new)
        )))
    }
}

#[cfg(test)]
mod kernel_tests {
    use super::*;

    fn cloud(n: usize) -> (Vec<DVec3>, Vec<DVec3>) {
        let pos = (0..n)
            .map(|k| {
                let t = k as f64;
                DVec3::new(
                    (1.7 * t).sin(),
                    (2.3 * t).cos(),
                    (0.61 * t).sin() * (0.37 * t).cos(),
                ) * 4.0
                    + DVec3::new(0.013 * t, 0.0, 0.0)
            })
            .collect();
        let dip = (0..n)
            .map(|k| {
                let t = k as f64;
                DVec3::new((0.9 * t).cos(), (1.1 * t).sin(), 0.5 + (0.3 * t).sin())
            })
            .collect();
        (pos, dip)
    }

    type Sums = (Vec<DVec3>, Vec<DVec3>, f64);

    fn run(dd: &mut DipoleDipole, pos: &[DVec3], dip: &[DVec3], isa: Isa, tiled: bool) -> Sums {
        let n = pos.len();
        let (mut f, mut t) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let w = dd.all_pairs_forces_with(pos, dip, &mut f, &mut t, isa, tiled);
        (f, t, w)
    }

    /// The all-pairs kernels — tiled with reactions (each pair once) and
    /// rows (each pair twice), AVX-512 and portable — agree with the
    /// portable rows (forces, torques and virial to 1e-12 of the largest),
    /// with and without WCA, for particle counts that leave a partial last
    /// block (7, 203) and need several tiles and column blocks (1100).
    #[test]
    fn every_kernel_agrees_with_the_scalar_reference() {
        let mut isas = vec![Isa::Portable];
        if isa() != Isa::Portable {
            isas.push(isa());
        }
        for n in [7, 203, 1100] {
            let (pos, dip) = cloud(n);
            for wca in [false, true] {
                let mut dd = DipoleDipole::all_pairs(4.0 * PI);
                if wca {
                    dd = dd.with_repulsion(PairRepulsion::wca(1.0, 1.0)).unwrap();
                }
                let (f0, t0, w0) = run(&mut dd, &pos, &dip, Isa::Portable, false);
                let close = |a: &[DVec3], b: &[DVec3], what: &str| {
                    let scale = a.iter().map(|v| v.length()).fold(0.0, f64::max);
                    let worst = a
                        .iter()
                        .zip(b)
                        .map(|(x, y)| (*x - *y).length())
                        .fold(0.0, f64::max);
                    assert!(
                        worst <= 1e-12 * scale,
                        "{what} (n {n}, wca {wca}): worst difference {worst:e} of {scale:e}"
                    );
                };
                for &isa in &isas {
                    for tiled in [false, true] {
                        let (f1, t1, w1) = run(&mut dd, &pos, &dip, isa, tiled);
                        let what = format!("{isa:?}, tiled {tiled}");
                        close(&f0, &f1, &format!("forces, {what}"));
                        close(&t0, &t1, &format!("torques, {what}"));
                        assert!(
                            (w0 - w1).abs() <= 1e-12 * w0.abs().max(1.0),
                            "{what}: virial {w0} vs {w1}"
                        );
                    }
                }
            }
        }
    }

    /// Tiles give the same bits on one thread and on three, and conserve
    /// momentum and angular momentum pair by pair (Σ F = 0 and
    /// Σ (τ + r × F) = 0 to round-off).
    #[test]
    fn tiles_are_thread_count_independent_and_conserve_momenta() {
        let (pos, dip) = cloud(1100);
        let mut dd = DipoleDipole::all_pairs(4.0 * PI)
            .with_repulsion(PairRepulsion::wca(1.0, 1.0))
            .unwrap();
        let mut on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| run(&mut dd, &pos, &dip, isa(), true))
        };
        let (f1, t1, w1) = on(1);
        let (f3, t3, w3) = on(3);
        let bits = |v: &[DVec3]| {
            v.iter()
                .flat_map(|a| a.to_array())
                .map(f64::to_bits)
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&f1), bits(&f3));
        assert_eq!(bits(&t1), bits(&t3));
        assert_eq!(w1.to_bits(), w3.to_bits());
        let total: DVec3 = f1.iter().copied().sum();
        let spin: DVec3 = (0..pos.len()).map(|i| t1[i] + pos[i].cross(f1[i])).sum();
        let scale: f64 = f1
            .iter()
            .zip(&pos)
            .map(|(f, r)| f.length() * (1.0 + r.length()))
            .sum();
        assert!(total.length() < 1e-13 * scale, "Σ F = {total}");
        assert!(spin.length() < 1e-13 * scale, "Σ (τ + r × F) = {spin}");
    }
}
