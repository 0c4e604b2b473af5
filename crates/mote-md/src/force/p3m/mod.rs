//! Particle–particle particle–mesh (P3M) Coulomb forces in a periodic
//! orthorhombic box, tin-foil boundaries (Hockney & Eastwood, *Computer
//! Simulation Using Particles*, ch. 7–8; Deserno & Holm 1998, J. Chem.
//! Phys. 109, 7678): the Ewald sum of [`super::ewald`] with its k-space
//! part on a mesh and FFTs, O(N log N) instead of O(N^{3/2}).
//!
//! U = k_e [½ Σ_{i≠j, r<r_c} q_i q_j erfc(α r_ij)/r_ij + U_mesh
//!     − (α/√π) Σ q² − π Q²/(2Vα²)],
//!
//! the real-space pairs over a neighbour list of their own (the force on i
//! from j, q_i q_j [erfc(αr)/r + (2α/√π) e^{−α²r²}] r/r²), the mesh part
//! by [`mesh`], the self energy and the neutralising background as in the
//! Ewald sum (zero for a neutral system). The parameters (mesh, order,
//! α, r_c) come from the RMS force error asked for ([`tune`]).
//!
//! In a decomposed run (MPI ranks) the real space lists each rank's
//! particles over its halo, the ghosts' charges read from every
//! particle's (the scene's, by id); the mesh is replicated: every rank
//! gathers every particle's position in id order and makes the whole mesh
//! as one process does, so the forces are the same bits on any number of
//! ranks; the mesh energy and the background are counted at rank 0.
//!
//! Point dipoles have their own solver, [`P3mDipoles`] ([`dipolar`], its
//! mesh in [`dipole_mesh`]), on the same mesh geometry (`grid`: binning,
//! spreading, interpolation, FFTs), influence functions ([`influence`])
//! and tuning.

pub mod dipolar;
pub mod dipole_mesh;
mod fft;
mod grid;
pub mod influence;
pub mod mesh;
mod screened;
pub mod spline;
pub mod tune;

use glam::DVec3;

use super::{HaloReach, Interaction, State, Virial};
use crate::boundary::Boundary;
use crate::domain::Halo;
use crate::neighbor::{Copy4, GhostList};
pub use dipolar::P3mDipoles;
use mote_geom::lanes::{self, Lanes};
use mote_run::comm::Comm;
use screened::Screened;
pub use tune::{Parameters, Request, Source};

const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Coulomb forces by P3M.
#[derive(Debug, Clone)]
pub struct P3mCoulomb {
    /// Coulomb's constant k_e = 1/(4πε₀).
    pub k: f64,
    pub parameters: Parameters,
    list: GhostList,
    mesh: mesh::Mesh,
    /// erfc(αr) and the pair force within the cut-off as polynomials.
    screened: Screened,
    /// The charge of each copy of the list.
    copy_charge: Vec<f64>,
    /// Every particle's charge in id order (the undivided system's, as
    /// tuning saw it): what a decomposed run's ghosts and mesh read. Empty
    /// from [`P3mCoulomb::new`], which then runs on one process only.
    whole_charge: Vec<f64>,
    sorted_force: Vec<DVec3>,
    /// Of the last energy (NaN after a later force evaluation).
    virial: f64,
}

/// What a real-space row adds up: the force on its particle over its
/// charge, Σ (F/r) r² and Σ U (each pair counted in two rows).
#[derive(Debug, Clone, Copy, Default)]
struct RowSum {
    field: DVec3,
    virial: f64,
    energy: f64,
}

impl P3mCoulomb {
    /// Forgets the real-space list's build (the particles changed).
    pub fn forget_list(&mut self) {
        self.list.invalidate();
    }

    /// P3M with `parameters` in `boundary` (periodic on every axis), its
    /// real-space list with `skin`.
    pub fn new(k: f64, parameters: Parameters, skin: f64, boundary: &Boundary) -> Self {
        let cell = boundary.lengths();
        Self {
            k,
            parameters,
            list: GhostList::new(parameters.cutoff, skin),
            screened: Screened::new(parameters.alpha * parameters.cutoff),
            mesh: mesh::Mesh::new(
                parameters.mesh,
                parameters.order,
                parameters.alpha,
                boundary.lo,
                cell,
            ),
            copy_charge: Vec::new(),
            whole_charge: Vec::new(),
            sorted_force: Vec::new(),
            virial: f64::NAN,
        }
    }

    /// Tuned for `request` (its accuracy in force units) and `charge` in
    /// `boundary`.
    pub fn tuned(
        k: f64,
        request: &Request,
        charge: &[f64],
        boundary: &Boundary,
    ) -> Result<Self, String> {
        let q2: f64 = charge.iter().map(|q| q * q).sum();
        let gaussian = Request {
            accuracy: request.accuracy / k,
            ..*request
        };
        let mut parameters = tune::tune(
            boundary.lengths(),
            charge.len(),
            Source::Charges { q2 },
            &gaussian,
        )?;
        parameters.real_error *= k;
        let mut solver = Self::new(k, parameters, request.skin, boundary);
        solver.whole_charge = charge.to_vec();
        // The estimate stated: with every alias G sums, on the mesh itself.
        solver.parameters.kspace_error =
            k * solver.mesh.estimated_error(charge.len().max(1) as f64, q2);
        Ok(solver)
    }

    /// Brings the list to `state` (counting a step when `step`; over the
    /// halo in a decomposed run) and the copies' charges with it.
    fn follow(&mut self, state: &State, step: bool) {
        self.copy_charge.clear();
        match state.halo {
            Some(halo) => {
                self.list.follow_halo(halo, state.boundary);
                let n = halo.id.len();
                let whole = &self.whole_charge;
                self.copy_charge.extend(self.list.particle.iter().map(|&i| {
                    let i = i as usize;
                    let id = if i < n {
                        halo.id[i]
                    } else {
                        halo.ghosts[i - n].id
                    };
                    whole[id as usize]
                }));
            }
            None => {
                if step {
                    self.list.update(state.position, state.boundary);
                } else {
                    self.list.refresh(state.position, state.boundary);
                }
                let q = state.charges();
                self.copy_charge
                    .extend(self.list.particle.iter().map(|&i| q[i as usize]));
            }
        }
    }

    /// Every particle's position and charge in id order, where the mesh
    /// is made from them: a decomposed run gathers them to every rank
    /// ([`whole_positions`]), one process has them.
    fn sources<'s>(
        whole_charge: &'s [f64],
        state: &'s State,
    ) -> (std::borrow::Cow<'s, [DVec3]>, &'s [f64]) {
        match (state.halo, state.comm) {
            (Some(halo), Some(comm)) => (
                whole_positions(state.position, halo, comm, whole_charge.len()).into(),
                whole_charge,
            ),
            _ => (state.position.into(), state.charges()),
        }
    }

    /// Whether this evaluation counts the terms of the whole system (the
    /// mesh energy, the background): at one process, or rank 0.
    fn counts_the_whole(state: &State) -> bool {
        state.comm.is_none_or(|c| c.rank() == 0)
    }

    /// The real-space rows into `sorted` (each row's force) and the halved
    /// sums of the virial and the energy, Gaussian units.
    fn rows(&self, sorted: &mut [DVec3], energy: bool) -> (f64, f64) {
        let (list, q) = (&self.list, &self.copy_charge);
        let (alpha, rc2) = (self.parameters.alpha, self.parameters.cutoff.powi(2));
        let [w, u] = list.sum_rows(sorted, |r| {
            let k = list.owner[r] as usize;
            let s = if energy {
                row_lanes::<true>(list, q, &self.screened, r, alpha, rc2)
            } else {
                row_lanes::<false>(list, q, &self.screened, r, alpha, rc2)
            };
            (s.field * q[k], [s.virial * q[k], s.energy * q[k]])
        });
        (0.5 * w, 0.5 * u)
    }

    /// −(α/√π) Σ q² over `charge` (this rank's) and, with the total
    /// charge Q (at one process or rank 0), the neutralising background
    /// −π Q²/(2Vα²).
    fn self_and_background(&self, charge: &[f64], total: Option<f64>) -> (f64, f64) {
        let alpha = self.parameters.alpha;
        let q2: f64 = charge.iter().map(|q| q * q).sum();
        let q = total.unwrap_or(0.0);
        let v = self.mesh.volume();
        (
            -alpha / SQRT_PI * q2,
            -std::f64::consts::PI * q * q / (2.0 * v * alpha * alpha),
        )
    }

    /// The mesh energy and virial and the total charge Q, where this
    /// evaluation counts them ([`P3mCoulomb::counts_the_whole`]); zeros
    /// and `None` at the other ranks, which still take part in the gather.
    fn whole_system_terms(&mut self, state: &State) -> (f64, [f64; 6], Option<f64>) {
        let (position, charge) = Self::sources(&self.whole_charge, state);
        if Self::counts_the_whole(state) {
            let (u, w) = self
                .mesh
                .energy_and_virial(&position, charge, self.parameters.alpha);
            (u, w, Some(charge.iter().sum()))
        } else {
            (0.0, [0.0; 6], None)
        }
    }

    /// "Coulomb by P3M: mesh 32 × 32 × 32, order 5, α = …": for summaries.
    pub fn describe(&self) -> String {
        let p = &self.parameters;
        format!(
            "Coulomb by P3M: mesh {} × {} × {}, assignment order {}, α = {:.6}, real-space cut-off {:.6}; estimated RMS force error {:.3e} (real space {:.3e}, mesh {:.3e}).",
            p.mesh[0],
            p.mesh[1],
            p.mesh[2],
            p.order,
            p.alpha,
            p.cutoff,
            p.estimated_error(),
            p.real_error,
            p.kspace_error
        )
    }
}

/// Every particle's position in id order, at every rank ([`gathered`]).
fn whole_positions(position: &[DVec3], halo: &Halo, comm: &dyn Comm, total: usize) -> Vec<DVec3> {
    crate::domain::gathered(position.iter().map(|r| r.to_array()), halo, comm, total)
        .into_iter()
        .map(DVec3::from_array)
        .collect()
}

/// The pair of unit charges at distance² r² (within the cut-off): F/r =
/// ψ(αr)/r³ ([`screened`]), and erfc(αr)/r when `energy`.
#[inline]
fn screened_pair(screened: &Screened, alpha: f64, r2: f64, energy: bool) -> (f64, f64) {
    let r = r2.sqrt();
    let x = alpha * r;
    let u = if energy { screened.erfc(x) / r } else { 0.0 };
    (screened.psi(x) / (r2 * r), u)
}

/// Row r: Σ_j q_j ψ(αr) r/r³ and its virial and energy (Σ_j q_j
/// erfc(αr)/r) sums, all over the charge q_i of the row's particle, one
/// neighbour at a time: the reference [`row_lanes`] is tested against.
#[cfg(test)]
fn row_reference(
    list: &GhostList,
    q: &[f64],
    screened: &Screened,
    r: usize,
    alpha: f64,
    rc2: f64,
    energy: bool,
) -> RowSum {
    let xi = list.at(list.owner[r] as usize);
    let mut s = RowSum::default();
    for &j in list.row(r) {
        let j = j as usize;
        let d = xi - list.at(j);
        let r2 = d.length_squared();
        if r2 >= rc2 {
            continue;
        }
        let (f_over_r, u) = screened_pair(screened, alpha, r2, energy);
        let f_over_r = q[j] * f_over_r;
        s.field += d * f_over_r;
        s.virial += f_over_r * r2;
        if energy {
            s.energy += q[j] * u;
        }
    }
    s
}

impl Interaction for P3mCoulomb {
    fn name(&self) -> &'static str {
        "coulomb"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        self.follow(state, true);
        let mut sorted = std::mem::take(&mut self.sorted_force);
        sorted.resize(state.position.len(), DVec3::ZERO);
        self.rows(&mut sorted, false);
        for f in &mut sorted {
            *f *= self.k;
        }
        self.list.scatter_add(&sorted, force);
        self.sorted_force = sorted;
        let (source_position, source_charge) = Self::sources(&self.whole_charge, state);
        self.mesh.add_forces_at(
            &source_position,
            source_charge,
            state.position,
            state.charges(),
            self.k,
            force,
        );
        self.virial = f64::NAN;
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        self.follow(state, false);
        let mut sorted = std::mem::take(&mut self.sorted_force);
        sorted.resize(state.position.len(), DVec3::ZERO);
        let (w_real, u_real) = self.rows(&mut sorted, true);
        self.sorted_force = sorted;
        let (u_mesh, w_mesh, whole) = self.whole_system_terms(state);
        let (u_self, u_background) = self.self_and_background(state.charges(), whole);
        self.virial = self.k * (w_real + w_mesh[0] + w_mesh[1] + w_mesh[2] + 3.0 * u_background);
        self.k * (u_real + u_mesh + u_self + u_background)
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    /// The real-space pairs' r ⊗ F, the mesh's strain derivative and the
    /// background's isotropic part.
    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        self.follow(state, false);
        let (list, q, screened) = (&self.list, &self.copy_charge, &self.screened);
        let (alpha, rc2) = (self.parameters.alpha, self.parameters.cutoff.powi(2));
        let mut rows = vec![(); list.len()];
        let real = list.sum_rows(&mut rows, |r| {
            let k = list.owner[r] as usize;
            let xi = list.at(k);
            let mut w = Virial::default();
            for &j in list.row(r) {
                let d = xi - list.at(j as usize);
                let r2 = d.length_squared();
                if r2 < rc2 {
                    let (f_over_r, _) = screened_pair(screened, alpha, r2, false);
                    w += Virial::central(d, q[k] * q[j as usize] * f_over_r);
                }
            }
            ((), w.0)
        });
        let (_, mesh, whole) = self.whole_system_terms(state);
        let (_, background) = self.self_and_background(state.charges(), whole);
        let w = Virial(real).scaled(0.5) + Virial(mesh) + Virial::isotropic(background);
        Some(w.scaled(self.k))
    }

    /// Decomposed over ranks when tuned for a scene's charges: the real
    /// space over the halo, the mesh made on every rank from every
    /// particle (gathered in id order), the forces of this rank's.
    fn halo_reach(&self) -> Option<HaloReach> {
        (!self.whole_charge.is_empty()).then_some(HaloReach {
            cutoff: self.list.cutoff,
            skin: self.list.skin,
            every: self.list.every,
            moments: false,
            motion: false,
        })
    }

    fn take_restored_list(&mut self) -> Option<(u64, Vec<DVec3>)> {
        self.list.take_restored()
    }

    /// The neighbour list's build, as Lennard-Jones carries it.
    fn carried_state(&self) -> Vec<f64> {
        self.list.carried_state()
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        self.list.restore(state)
    }

    fn describe(&self) -> Option<String> {
        Some(P3mCoulomb::describe(self))
    }
}

/// Row r eight neighbours at a time on [`Lanes`] (every CPU): the pair of
/// [`screened_pair`] lane by lane (tested against `row_reference`), its series' coefficients gathered per lane; lanes
/// beyond the cut-off (and the row's padding) evaluate the pair at the
/// cut-off and are multiplied by zero.
#[inline]
fn row_lanes<const ENERGY: bool>(
    list: &GhostList,
    q: &[f64],
    screened: &Screened,
    r: usize,
    alpha: f64,
    rc2: f64,
) -> RowSum {
    let k = list.owner[r] as usize;
    let records = Copy4::records(&list.position);
    let [xi, yi, zi, _] = list.position[k].0;
    let zero = Lanes::splat(0.0);
    let (mut fx, mut fy, mut fz, mut w, mut u) = (zero, zero, zero, zero, zero);
    lanes::in_eights(list.row(r), k as u32, |index, pad| {
        let [xj, yj, zj] = lanes::gather_xyz(records, index);
        let (dx, dy, dz) = (
            Lanes::splat(xi) - xj,
            Lanes::splat(yi) - yj,
            Lanes::splat(zi) - zj,
        );
        let d2 = dx * dx + dy * dy + dz * dz;
        let inside = (d2 + pad).select_within(rc2, 1.0, 0.0);
        // Outside lanes at the cut-off: every lane indexes the series.
        let r2 = d2.zip(inside, |d2, m| if m > 0.0 { d2 } else { rc2 });
        let distance = r2.sqrt();
        let x = distance * alpha;
        let qj = Lanes(index.map(|j| q[j as usize]));
        let weight = qj * inside;
        let f = screened.psi_lanes(x) / (r2 * distance) * weight;
        fx = fx + f * dx;
        fy = fy + f * dy;
        fz = fz + f * dz;
        w = w + f * r2;
        if ENERGY {
            u = u + screened.erfc_lanes(x) / distance * weight;
        }
    });
    RowSum {
        field: DVec3::new(fx.sum(), fy.sum(), fz.sum()),
        virial: w.sum(),
        energy: u.sum(),
    }
}

/// Uniform numbers in [0, 1) from `seed` (Knuth's MMIX generator): the
/// row tests' particles.
#[cfg(test)]
pub(super) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight-lane rows against the one-neighbour-at-a-time reference.
    #[test]
    fn lane_rows_match_the_reference() {
        let cell = DVec3::splat(9.0);
        let boundary = Boundary::periodic(DVec3::ZERO, cell);
        let n = 600;
        let mut next = uniform(12345);
        let pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(next(), next(), next()) * cell)
            .collect();
        let q: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let request = Request {
            accuracy: 1e-5,
            skin: 0.3,
            ..Request::default()
        };
        let mut p3m = P3mCoulomb::tuned(1.0, &request, &q, &boundary).unwrap();
        let v = vec![DVec3::ZERO; n];
        let m = vec![1.0; n];
        let state = State::new(&pos, &v, &m, 0.0)
            .with_charges(&q)
            .in_box(&boundary);
        p3m.follow(&state, false);
        let (alpha, rc2) = (p3m.parameters.alpha, p3m.parameters.cutoff.powi(2));
        for r in 0..p3m.list.len() {
            let a = row_lanes::<true>(&p3m.list, &p3m.copy_charge, &p3m.screened, r, alpha, rc2);
            let b = row_reference(
                &p3m.list,
                &p3m.copy_charge,
                &p3m.screened,
                r,
                alpha,
                rc2,
                true,
            );
            let scale = b.field.length().max(1.0);
            assert!(
                (a.field - b.field).length() < 1e-13 * scale,
                "row {r}: {:?} vs {:?}",
                a.field,
                b.field
            );
            assert!((a.energy - b.energy).abs() < 1e-13 * b.energy.abs().max(1.0));
            assert!((a.virial - b.virial).abs() < 1e-13 * b.virial.abs().max(1.0));
        }
    }
}
