//! Point-particle interactions between the bodies' centres of mass.
//!
//! A body carries its charge and its magnetic dipole at its centre of mass
//! (seed 000: the toner and carrier particles' charge q and moment j), so
//! the Coulomb and dipole–dipole forces between bodies are those of point
//! particles at the centres. [`AtCentres`] runs a point-particle
//! [`Interaction`] — the very kernel point particles use — on the centres
//! (mass, velocity, charge, world-frame dipole, angular velocity per body)
//! and adds each centre's force F and torque T to its body's wrench
//! dE(T, F): one Coulomb law ([`DirectCoulomb`], the tiled inverse-square
//! kernel) and one dipole–dipole law ([`DipoleDipole`](crate::force::dipolar::DipoleDipole),
//! its tiled all-pairs rows) for points and clumps alike.
//!
//! The bodies are in open space here, as the interactions below assume;
//! an interaction that carries contact histories does not belong on the
//! centres (its histories would advance by the step of the state, which
//! a body view gives as its `step.dt`, [`BodyView::step`]).

use std::f64::consts::PI;

use glam::DVec3;
use mote_geom::DE;

use super::interaction::{BodyInteraction, BodyView};
use crate::force::dipolar::DipoleDipole as PointDipoles;
use crate::force::{DirectCoulomb, Interaction, Spin, State};

/// A point-particle interaction acting between the bodies' centres.
#[derive(Debug, Clone)]
pub struct AtCentres<I> {
    pub inner: I,
    centres: Centres,
}

/// The bodies as point particles, refreshed before each evaluation, and
/// the force and torque on each.
#[derive(Debug, Clone, Default)]
struct Centres {
    mass: Vec<f64>,
    charge: Vec<f64>,
    force: Vec<DVec3>,
    torque: Vec<DVec3>,
}

impl Centres {
    /// Masses and charges from the templates; forces and torques zeroed.
    fn gather(&mut self, view: &BodyView<'_>) {
        let b = view.bodies;
        let n = b.len();
        self.mass.clear();
        self.mass.extend((0..n).map(|i| b.template(i).mass()));
        self.charge.clear();
        self.charge.extend((0..n).map(|i| b.template(i).charge));
        self.force.clear();
        self.force.resize(n, DVec3::ZERO);
        self.torque.clear();
        self.torque.resize(n, DVec3::ZERO);
    }
}

impl<I: Interaction> AtCentres<I> {
    /// `inner` between the bodies' centres.
    pub fn new(inner: I) -> Self {
        Self {
            inner,
            centres: Centres::default(),
        }
    }

    /// Evaluates the inner interaction on the centres at time `t`: forces
    /// (and torques, where it exerts any) into the scratch arrays.
    fn evaluate(&mut self, view: &BodyView<'_>, t: f64) {
        self.centres.gather(view);
        let b = view.bodies;
        let c = &mut self.centres;
        let state = State::new(&b.position, &b.velocity, &c.mass, t)
            .after(view.step.dt)
            .with_charges(&c.charge)
            .with_dipoles(&view.world.dipole);
        if self.inner.exerts_torques() {
            let spin = Spin {
                angular_velocity: &b.omega,
            };
            self.inner
                .add_forces_and_torques(&state, &spin, &mut c.force, &mut c.torque);
        } else {
            self.inner.add_forces(&state, &mut c.force);
        }
    }
}

impl<I: Interaction + Sync + 'static> BodyInteraction for AtCentres<I> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let t = view.step.time;
        self.evaluate(view, t);
        let c = &self.centres;
        for ((w, f), tq) in wrench.iter_mut().zip(&c.force).zip(&c.torque) {
            w.v += *f;
            w.omega += *tq;
        }
    }

    /// The inner interaction's virial at the centres, Σ (R_I − R_J)·F_IJ:
    /// the molecular virial of forces between centres (where the inner
    /// interaction computes it).
    fn virial(&mut self, view: &BodyView<'_>) -> Option<f64> {
        self.evaluate(view, view.step.time);
        self.inner.virial()
    }

    fn potential_energy(&mut self, view: &BodyView<'_>) -> f64 {
        let t = view.step.time;
        self.centres.gather(view);
        let b = view.bodies;
        let c = &self.centres;
        let state = State::new(&b.position, &b.velocity, &c.mass, t)
            .with_charges(&c.charge)
            .with_dipoles(&view.world.dipole);
        self.inner.potential_energy(&state)
    }
}

/// Coulomb's law between the bodies' charges at their centres (all pairs,
/// open space): `Fᵢ = k Σⱼ qᵢqⱼ (xᵢ − xⱼ)/|xᵢ − xⱼ|³`, k = 1/(4πε₀) in SI;
/// no torque.
pub type Coulomb = AtCentres<DirectCoulomb>;

impl Coulomb {
    /// Coulomb's law with constant `k`, unsoftened.
    pub fn coulomb(k: f64) -> Self {
        AtCentres::new(DirectCoulomb::new(k, 0.0))
    }
}

/// The magnetic dipole–dipole interaction between the bodies' moments
/// (all pairs, open space) with k = μ₀/4π (1e-7 in SI):
/// `U = k [mᵢ·mⱼ/r³ − 3(mᵢ·r)(mⱼ·r)/r⁵]` (004 Eq. 8), forces and torques
/// `Tᵢ = mᵢ × Bⱼ(xᵢ)` that keep the total angular momentum.
pub type DipoleDipole = AtCentres<PointDipoles>;

impl DipoleDipole {
    /// Dipole–dipole forces and torques with k = μ₀/4π.
    pub fn dipoles(k: f64) -> Self {
        AtCentres::new(PointDipoles::all_pairs(4.0 * PI * k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::dipolar::dipole_pair;
    use crate::rigid::{dumbbell, BodyTemplate, Frbi, Integration, RigidBodies};
    use mote_geom::E;

    /// Two charged, magnetised dumbbells: each body's wrench is the point
    /// law at the centres — Coulomb's k q₁q₂ d/|d|³ plus the dipole pair's
    /// force (004 Eq. 8) in the force, the dipole pair's torque in the
    /// torque — and the energy is the pair's.
    #[test]
    fn the_wrench_is_the_point_law_at_the_centres() {
        let mut bodies = RigidBodies::new();
        let moments = [DVec3::new(0.3, 1.0, 0.2), DVec3::new(-0.5, 0.2, 0.9)];
        let charges = [0.5, -0.8];
        let places = [DVec3::new(-1.1, 0.2, 0.0), DVec3::new(0.9, -0.3, 0.4)];
        for ((q, m), x) in charges.iter().zip(moments).zip(places) {
            let mut spec = dumbbell(0.3, 0.5, 1.0);
            spec.charge = *q;
            spec.dipole = m;
            let t = BodyTemplate::new(&spec, Integration::default()).unwrap();
            let kind = bodies.add_template(t);
            bodies.push(kind, E::new(DVec3::ZERO, x), DE::ZERO);
        }
        let (k_e, k_m) = (2.0, 0.7);
        let mut frbi = Frbi::new()
            .with(Coulomb::coulomb(k_e))
            .with(DipoleDipole::dipoles(k_m));
        let w = frbi.wrenches(&bodies, 0.0, 0.0).to_vec();
        let d = places[0] - places[1];
        let r2 = d.length_squared();
        let coulomb = d * (k_e * charges[0] * charges[1] / (r2 * r2.sqrt()));
        let (u, f, ti, tj) = dipole_pair(k_m, d, 1.0 / r2, moments[0], moments[1]);
        let close = |a: DVec3, b: DVec3| (a - b).length() <= 1e-13 * b.length().max(1.0);
        assert!(close(w[0].v, coulomb + f), "{} vs {}", w[0].v, coulomb + f);
        assert!(close(w[1].v, -(coulomb + f)), "{}", w[1].v);
        assert!(close(w[0].omega, ti), "{} vs {ti}", w[0].omega);
        assert!(close(w[1].omega, tj), "{} vs {tj}", w[1].omega);
        let energy = frbi.energies(&bodies).potential;
        let expected = k_e * charges[0] * charges[1] / r2.sqrt() + u;
        assert!(
            (energy - expected).abs() <= 1e-13 * expected.abs(),
            "{energy} vs {expected}"
        );
    }
}
