//! Particle–particle particle–mesh (P3M) forces and torques between point
//! dipoles in a periodic orthorhombic box, tin-foil boundaries (Cerdà,
//! Ballenegger, Lenz & Holm 2008, J. Chem. Phys. 129, 234104): the dipolar
//! Ewald sum of [`crate::force::ewald`] (Wang & Holm 2001, Eqs. 5–9) with
//! its k-space part on a mesh ([`super::dipole_mesh`]).
//!
//! U = k [½ Σ_{i≠j, r<r_c} ((μ_i·μ_j) B(r) − (μ_i·r)(μ_j·r) C(r))
//!     + U_mesh + Σ_i μ_i·(T − S)·μ_i − (2α³/3√π) Σ μ²],
//!
//! k = μ₀/4π, r = r_i − r_j, with B, C (and D for the force) the screened
//! pair functions of `screened.rs` (`DipolarScreened`); the real-space
//! force on i is (μ_i·μ_j) C r + [(μ_j·r) μ_i + (μ_i·r) μ_j] C
//! − (μ_i·r)(μ_j·r) D r and the field at i from j (μ_j·r) C r − μ_j B; the
//! torque is μ_i × H_i. T − S exchanges the mesh's average self energy for
//! the Ewald sum's ([`super::dipole_mesh`]). Mesh, order, α and r_c come
//! from the RMS force error asked for ([`super::tune`], Cerdà et al.'s
//! estimate for the mesh, Wang & Holm's Eq. 33 for the real space).
//!
//! On MPI ranks it decomposes as [`super::P3mCoulomb`] does: the real
//! space over the halo (the ghosts' moments forwarded with them), the mesh
//! made on every rank from every particle's position and moment gathered
//! in id order, so forces and torques are the same bits on any number of
//! ranks.

use glam::DVec3;

use super::dipole_mesh::{AtParticle, DipoleMesh};
use super::screened::DipolarScreened;
use super::tune::{self, Parameters, Request, Source};
use crate::boundary::Boundary;
use crate::force::{HaloReach, Interaction, Spin, State};
use crate::neighbor::{Copy4, GhostList};
use mote_geom::lanes::{self, Lanes};

const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Dipole–dipole forces and torques by P3M.
#[derive(Debug, Clone)]
pub struct P3mDipoles {
    /// μ₀/4π (1 in reduced units).
    pub k: f64,
    pub parameters: Parameters,
    list: GhostList,
    mesh: DipoleMesh,
    screened: DipolarScreened,
    /// The moment of each copy of the list.
    copy_moment: Vec<Copy4>,
    rows: Vec<AtParticle>,
    at_particle: Vec<AtParticle>,
    /// W = 3U of the last energy (NaN after a later force evaluation).
    virial: f64,
    /// The particles of the undivided system (as tuning saw them): a
    /// decomposed run gathers that many. Zero from [`P3mDipoles::new`],
    /// which then runs on one process only.
    total: usize,
}

/// What a real-space row adds up.
#[derive(Debug, Clone, Copy, Default)]
struct RowSum {
    force: DVec3,
    field: DVec3,
    /// Σ_j (μ_i·μ_j) B − (μ_i·r)(μ_j·r) C (each pair in two rows).
    energy: f64,
}

impl P3mDipoles {
    /// P3M with `parameters` in `boundary` (periodic on every axis), its
    /// real-space list with `skin`.
    pub fn new(k: f64, parameters: Parameters, skin: f64, boundary: &Boundary) -> Self {
        Self {
            k,
            parameters,
            list: GhostList::new(parameters.cutoff, skin),
            screened: DipolarScreened::new(parameters.alpha * parameters.cutoff),
            mesh: DipoleMesh::new(
                parameters.mesh,
                parameters.order,
                parameters.alpha,
                boundary.lo,
                boundary.lengths(),
            ),
            copy_moment: Vec::new(),
            rows: Vec::new(),
            at_particle: Vec::new(),
            virial: f64::NAN,
            total: 0,
        }
    }

    /// Tuned for `request` (its accuracy in force units) and the moments
    /// `dipole` in `boundary`.
    pub fn tuned(
        k: f64,
        request: &Request,
        dipole: &[DVec3],
        boundary: &Boundary,
    ) -> Result<Self, String> {
        let m2: f64 = dipole.iter().map(|m| m.length_squared()).sum();
        let gaussian = Request {
            accuracy: request.accuracy / k,
            ..*request
        };
        let source = Source::Dipoles { m2 };
        let mut parameters = tune::tune(boundary.lengths(), dipole.len(), source, &gaussian)?;
        parameters.real_error *= k;
        let mut solver = Self::new(k, parameters, request.skin, boundary);
        solver.total = dipole.len();
        solver.parameters.kspace_error =
            k * solver.mesh.estimated_error(dipole.len().max(1) as f64, m2);
        Ok(solver)
    }

    /// "Dipolar by P3M: mesh …": for summaries.
    pub fn describe(&self) -> String {
        let p = &self.parameters;
        format!(
            "Dipolar by P3M: mesh {} × {} × {}, assignment order {}, α = {:.6}, real-space cut-off {:.6}; estimated RMS force error {:.3e} (real space {:.3e}, mesh {:.3e}).",
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

    /// Brings the list to `state` (counting a step when `step`; over the
    /// halo in a decomposed run) and the copies' moments with it.
    fn follow(&mut self, state: &State, step: bool) {
        match state.halo {
            Some(halo) => {
                self.list.follow_halo(halo, state.boundary);
                self.list
                    .gather_halo(state.dipole, &halo.moment, &mut self.copy_moment);
            }
            None => {
                if step {
                    self.list.update(state.position, state.boundary);
                } else {
                    self.list.refresh(state.position, state.boundary);
                }
                self.list.gather(state.dipole, &mut self.copy_moment);
            }
        }
    }

    /// Every particle's position and moment in id order, where the mesh is
    /// made from them: gathered to every rank in a decomposed run, `None`
    /// at one process (which has them).
    fn whole(&self, state: &State) -> Option<(Vec<DVec3>, Vec<DVec3>)> {
        let (halo, comm) = (state.halo?, state.comm?);
        let own = state.position.iter().zip(state.dipole).map(|(r, m)| {
            let (r, m) = (r.to_array(), m.to_array());
            [r[0], r[1], r[2], m[0], m[1], m[2]]
        });
        let all = crate::domain::gathered(own, halo, comm, self.total);
        Some(
            all.iter()
                .map(|v| (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5])))
                .unzip(),
        )
    }

    /// The real-space rows into `self.rows` (by row), and half the sum of
    /// their energies; Gaussian units.
    fn real_space(&mut self, energy: bool) -> f64 {
        let mut rows = std::mem::take(&mut self.rows);
        rows.resize(self.list.len(), AtParticle::default());
        let (list, moment, screened) = (&self.list, &self.copy_moment, &self.screened);
        let (alpha, rc2) = (self.parameters.alpha, self.parameters.cutoff.powi(2));
        let [u] = list.sum_rows(&mut rows, |r| {
            let s = if energy {
                row_lanes::<true>(list, moment, screened, r, alpha, rc2)
            } else {
                row_lanes::<false>(list, moment, screened, r, alpha, rc2)
            };
            (
                AtParticle {
                    force: s.force,
                    field: s.field,
                },
                [s.energy],
            )
        });
        self.rows = rows;
        0.5 * u
    }

    /// (2α³/3√π): the Ewald self energy per μ².
    fn self_coefficient(&self) -> f64 {
        2.0 * self.parameters.alpha.powi(3) / (3.0 * SQRT_PI)
    }

    /// Adds k F_i and, with `torque`, k μ_i × H_i.
    fn evaluate(&mut self, state: &State, force: &mut [DVec3], torque: Option<&mut [DVec3]>) {
        let n = force.len();
        if state.dipole.len() != n || (n == 0 && state.halo.is_none()) {
            return;
        }
        self.follow(state, true);
        self.real_space(false);
        let mut mesh = std::mem::take(&mut self.at_particle);
        mesh.resize(n, AtParticle::default());
        match self.whole(state) {
            Some((position, dipole)) => self.mesh.forces_and_fields_at(
                &position,
                &dipole,
                state.position,
                state.dipole,
                torque.is_some(),
                &mut mesh,
            ),
            None => self.mesh.forces_and_fields(
                state.position,
                state.dipole,
                torque.is_some(),
                &mut mesh,
            ),
        }
        let slot = &self.list.slot;
        for i in 0..n {
            force[i] += (self.rows[slot[i] as usize].force + mesh[i].force) * self.k;
        }
        if let Some(torque) = torque {
            // H_i = −∂U/∂μ_i: the pairs, the mesh, and the self terms.
            let own = 2.0 * self.self_coefficient();
            let exchange = self.mesh.self_correction * -2.0;
            for i in 0..n {
                let m = state.dipole[i];
                let h = self.rows[slot[i] as usize].field + mesh[i].field + m * own + m * exchange;
                torque[i] += m.cross(h) * self.k;
            }
        }
        self.at_particle = mesh;
        self.virial = f64::NAN;
    }
}

/// Row r eight neighbours at a time on [`Lanes`]: the screened pair lane
/// by lane (tested against `row_reference`); lanes beyond the cut-off
/// (and the row's padding) evaluate the pair at the cut-off and are
/// multiplied by zero.
#[inline]
fn row_lanes<const ENERGY: bool>(
    list: &GhostList,
    moment: &[Copy4],
    screened: &DipolarScreened,
    r: usize,
    alpha: f64,
    rc2: f64,
) -> RowSum {
    let k = list.owner[r] as usize;
    let (records, moments) = (Copy4::records(&list.position), Copy4::records(moment));
    let [xi, yi, zi, _] = list.position[k].0;
    let [mix, miy, miz, _] = moment[k].0;
    let (mx, my, mz) = (Lanes::splat(mix), Lanes::splat(miy), Lanes::splat(miz));
    let zero = Lanes::splat(0.0);
    let (mut fx, mut fy, mut fz) = (zero, zero, zero);
    let (mut hx, mut hy, mut hz, mut u) = (zero, zero, zero, zero);
    lanes::in_eights(list.row(r), k as u32, |index, pad| {
        let [xj, yj, zj] = lanes::gather_xyz(records, index);
        let [njx, njy, njz] = lanes::gather_xyz(moments, index);
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
        let inv_r2 = Lanes::splat(1.0) / r2;
        let inv_r3 = inv_r2 / distance * inside;
        let x = distance * alpha;
        let (b, c) = screened.bc_lanes(x);
        let b = b * inv_r3;
        let c = c * inv_r3 * inv_r2;
        let d = screened.d_lanes(x) * inv_r3 * inv_r2 * inv_r2;
        let mir = mx * dx + my * dy + mz * dz;
        let mjr = njx * dx + njy * dy + njz * dz;
        let mm = mx * njx + my * njy + mz * njz;
        let radial = mm * c - d * mir * mjr;
        let (cj, ci) = (mjr * c, mir * c);
        fx = fx + dx * radial + mx * cj + njx * ci;
        fy = fy + dy * radial + my * cj + njy * ci;
        fz = fz + dz * radial + mz * cj + njz * ci;
        hx = hx + dx * cj - njx * b;
        hy = hy + dy * cj - njy * b;
        hz = hz + dz * cj - njz * b;
        if ENERGY {
            u = u + mm * b - mir * cj;
        }
    });
    RowSum {
        force: DVec3::new(fx.sum(), fy.sum(), fz.sum()),
        field: DVec3::new(hx.sum(), hy.sum(), hz.sum()),
        energy: u.sum(),
    }
}

/// Row r one neighbour at a time with libm's erfc and exp (Wang & Holm's
/// B, C, D written out): the reference [`row_lanes`] is tested against.
#[cfg(test)]
fn row_reference(list: &GhostList, moment: &[Copy4], r: usize, alpha: f64, rc2: f64) -> RowSum {
    let k = list.owner[r] as usize;
    let xi = list.at(k);
    let vec = |c: &Copy4| DVec3::new(c.0[0], c.0[1], c.0[2]);
    let mi = vec(&moment[k]);
    let mut s = RowSum::default();
    for &j in list.row(r) {
        let j = j as usize;
        let d = xi - list.at(j);
        let r2 = d.length_squared();
        if r2 >= rc2 {
            continue;
        }
        let mj = vec(&moment[j]);
        let rr = r2.sqrt();
        let a2 = alpha * alpha;
        let e = libm::erfc(alpha * rr);
        let g = 2.0 * alpha * rr / SQRT_PI * (-a2 * r2).exp();
        let b = (e + g) / (r2 * rr);
        let c = (3.0 * e + g * (3.0 + 2.0 * a2 * r2)) / (r2 * r2 * rr);
        let dd = (15.0 * e + g * (15.0 + 10.0 * a2 * r2 + 4.0 * a2 * a2 * r2 * r2))
            / (r2 * r2 * r2 * rr);
        let (mir, mjr, mm) = (mi.dot(d), mj.dot(d), mi.dot(mj));
        s.force += d * (mm * c - dd * mir * mjr) + (mi * mjr + mj * mir) * c;
        s.field += d * (c * mjr) - mj * b;
        s.energy += mm * b - mir * mjr * c;
    }
    s
}

impl Interaction for P3mDipoles {
    fn name(&self) -> &'static str {
        "dipolar"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        self.evaluate(state, force, None);
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
        self.evaluate(state, force, Some(torque));
    }

    fn potential_energy(&mut self, state: &State) -> f64 {
        let n = state.position.len();
        if state.dipole.len() != n || (n == 0 && state.halo.is_none()) {
            return 0.0;
        }
        self.follow(state, false);
        let u_real = self.real_space(true);
        // The mesh energy is the whole system's: counted at rank 0 (every
        // rank takes part in the gather).
        let u_mesh = match self.whole(state) {
            Some((position, dipole)) => match state.comm.map(|c| c.rank()) {
                Some(0) => self.mesh.energy(&position, &dipole),
                _ => 0.0,
            },
            None => self.mesh.energy(state.position, state.dipole),
        };
        let (own, exchange) = (self.self_coefficient(), self.mesh.self_correction);
        let u_self: f64 = state
            .dipole
            .iter()
            .map(|m| (*m * *m).dot(exchange) - own * m.length_squared())
            .sum();
        let u = self.k * (u_real + u_mesh + u_self);
        self.virial = 3.0 * u;
        u
    }

    /// W = 3U: the tin-foil Ewald energy of fixed dipoles is homogeneous of
    /// degree −3 in all lengths, so W = −dU/dλ at λ = 1 = 3U; P3M stands
    /// for that sum to the accuracy asked for.
    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    /// Decomposed over ranks when tuned for a scene's dipoles: the real
    /// space over the halo (the ghosts' moments forwarded with them), the
    /// mesh made on every rank from every particle's position and moment
    /// (gathered in id order), the forces and torques of this rank's.
    fn halo_reach(&self) -> Option<HaloReach> {
        (self.total > 0).then_some(HaloReach {
            cutoff: self.list.cutoff,
            skin: self.list.skin,
            every: self.list.every,
            moments: true,
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
        Some(P3mDipoles::describe(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight-lane rows against the one-neighbour-at-a-time reference
    /// with libm's erfc and exp.
    #[test]
    fn lane_rows_match_the_reference() {
        let cell = DVec3::splat(9.0);
        let boundary = Boundary::periodic(DVec3::ZERO, cell);
        let n = 500;
        let mut next = super::super::uniform(987654);
        let pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(next(), next(), next()) * cell)
            .collect();
        let mu: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 2.0)
            .collect();
        let request = Request {
            accuracy: 1e-5,
            skin: 0.3,
            ..Request::default()
        };
        let mut p3m = P3mDipoles::tuned(1.0, &request, &mu, &boundary).unwrap();
        let (v, m) = (vec![DVec3::ZERO; n], vec![1.0; n]);
        let state = State::new(&pos, &v, &m, 0.0)
            .with_dipoles(&mu)
            .in_box(&boundary);
        p3m.follow(&state, false);
        let (alpha, rc2) = (p3m.parameters.alpha, p3m.parameters.cutoff.powi(2));
        for r in 0..p3m.list.len() {
            let (list, moment) = (&p3m.list, &p3m.copy_moment);
            let a = row_lanes::<true>(list, moment, &p3m.screened, r, alpha, rc2);
            let b = row_reference(list, moment, r, alpha, rc2);
            let close = |x: DVec3, y: DVec3| (x - y).length() <= 1e-12 * y.length().max(1.0);
            assert!(
                close(a.force, b.force),
                "row {r}: {:?} vs {:?}",
                a.force,
                b.force
            );
            assert!(
                close(a.field, b.field),
                "row {r}: {:?} vs {:?}",
                a.field,
                b.field
            );
            assert!((a.energy - b.energy).abs() <= 1e-12 * b.energy.abs().max(1.0));
        }
    }
}
