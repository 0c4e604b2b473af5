//! The state of many rigid bodies as a structure of arrays (seed 000: a
//! body is `Par(σ, g, h)` — template σ, placement g = E(r, x), velocity
//! h = dE(ω, v)), and its observables.

use std::sync::Arc;

use glam::DVec3;
use mote_geom::{rotate, Inertia, DE, E};

use super::template::BodyTemplate;

/// Rigid bodies: per body the template index, the placement `E(r, x)` (r:
/// rotation vector from the template's initial frame, x: centre of mass) and
/// the velocity `dE(ω, v)` about the centre of mass, both in the master
/// frame.
#[derive(Clone, Debug, Default)]
pub struct RigidBodies {
    pub templates: Vec<Arc<BodyTemplate>>,
    /// Index into `templates`.
    pub kind: Vec<u32>,
    /// Rotation vector r of the placement.
    pub rotation: Vec<DVec3>,
    /// Centre of mass x (translation of the placement).
    pub position: Vec<DVec3>,
    /// Angular velocity ω.
    pub omega: Vec<DVec3>,
    /// Velocity v of the centre of mass.
    pub velocity: Vec<DVec3>,
    pub time: f64,
    /// Each body's id where bodies come and go (`rigid::flow`): increasing
    /// along the bodies, a removed body's never reused. Empty: the index.
    pub id: Vec<u64>,
    /// The scene's number of the body with id k, where the bodies are
    /// stored in space order ([`RigidBodies::to_space_order`]): files, messages
    /// and Python show it. Empty: every body's number is its id; ids past
    /// its end (bodies inserted during the run) are their own numbers too.
    pub number: Arc<[u64]>,
}

/// Observables of a set of bodies (momenta about the master frame's origin).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BodyObservables {
    pub translational_energy: f64,
    pub rotational_energy: f64,
    /// Σ m v.
    pub linear_momentum: DVec3,
    /// Σ (I ω + x × m v).
    pub angular_momentum: DVec3,
}

impl BodyObservables {
    pub fn kinetic_energy(&self) -> f64 {
        self.translational_energy + self.rotational_energy
    }
}

impl RigidBodies {
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers a template; returns its index for [`RigidBodies::push`].
    pub fn add_template(&mut self, t: Arc<BodyTemplate>) -> u32 {
        if let Some(k) = self.templates.iter().position(|s| Arc::ptr_eq(s, &t)) {
            return k as u32;
        }
        self.templates.push(t);
        (self.templates.len() - 1) as u32
    }

    /// Adds a body of template `kind` at placement `g` with velocity `h`.
    pub fn push(&mut self, kind: u32, g: E, h: DE) -> usize {
        assert!(
            (kind as usize) < self.templates.len(),
            "unknown template {kind}"
        );
        self.kind.push(kind);
        self.rotation.push(g.r);
        self.position.push(g.a);
        self.omega.push(h.omega);
        self.velocity.push(h.v);
        self.kind.len() - 1
    }

    /// The id of body i ([`RigidBodies::id`]).
    pub fn id_of(&self, i: usize) -> u64 {
        self.id.get(i).copied().unwrap_or(i as u64)
    }

    /// The scene's number of body i ([`RigidBodies::number`]).
    pub fn number_of(&self, i: usize) -> u64 {
        let id = self.id_of(i);
        self.number.get(id as usize).copied().unwrap_or(id)
    }

    /// The rows in the order of the bodies' scene numbers, or `None`
    /// where that is the rows' own order (no space order).
    pub fn rows_by_number(&self) -> Option<Vec<usize>> {
        if self.number.is_empty() {
            return None;
        }
        let mut rows: Vec<usize> = (0..self.len()).collect();
        rows.sort_unstable_by_key(|&i| self.number_of(i));
        Some(rows)
    }

    /// Stores the bodies in space order ([`crate::order::space_order`] of
    /// their centres on cells one largest bounding diameter wide), the
    /// scene's numbering kept in [`RigidBodies::number`]. Done once, where
    /// the scene has placed its bodies and before they get ids.
    pub fn to_space_order(&mut self) {
        use crate::order::{gathered, space_order};
        assert!(self.id.is_empty(), "bodies are ordered before they get ids");
        let radius: Vec<f64> = (0..self.len())
            .map(|i| self.template(i).props.bounding_radius)
            .collect();
        let order = space_order(&self.position, &radius);
        self.kind = gathered(&self.kind, &order);
        self.rotation = gathered(&self.rotation, &order);
        self.position = gathered(&self.position, &order);
        self.omega = gathered(&self.omega, &order);
        self.velocity = gathered(&self.velocity, &order);
        self.number = order.iter().map(|&k| k as u64).collect();
    }

    /// Keeps the bodies with `keep[i]`, in order.
    pub fn retain(&mut self, keep: &[bool]) {
        use crate::domain::retain;
        retain(&mut self.kind, keep);
        retain(&mut self.rotation, keep);
        retain(&mut self.position, keep);
        retain(&mut self.omega, keep);
        retain(&mut self.velocity, keep);
        if !self.id.is_empty() {
            retain(&mut self.id, keep);
        }
    }

    pub fn len(&self) -> usize {
        self.kind.len()
    }

    pub fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    #[inline]
    pub fn template(&self, i: usize) -> &BodyTemplate {
        &self.templates[self.kind[i] as usize]
    }

    #[inline]
    pub fn placement(&self, i: usize) -> E {
        E::new(self.rotation[i], self.position[i])
    }

    #[inline]
    pub fn velocity_of(&self, i: usize) -> DE {
        DE::new(self.omega[i], self.velocity[i])
    }

    /// `I₀ ∘ g`: the inertia of body i in the master frame.
    #[inline]
    pub fn inertia(&self, i: usize) -> Inertia {
        self.template(i).inertia.rotated(self.rotation[i])
    }

    /// The magnetic dipole `j * r` of body i in the master frame.
    #[inline]
    pub fn dipole(&self, i: usize) -> DVec3 {
        rotate(self.template(i).dipole, self.rotation[i])
    }

    /// The angular velocity in the body's initial frame, `ω * (−r)`.
    #[inline]
    pub fn body_omega(&self, i: usize) -> DVec3 {
        rotate(self.omega[i], -self.rotation[i])
    }

    /// The momentum `I * h = dE(L_cm, p)` of body i (L about its centre).
    #[inline]
    pub fn momentum(&self, i: usize) -> DE {
        self.inertia(i) * self.velocity_of(i)
    }

    /// Kinetic energies and total momenta.
    pub fn observables(&self) -> BodyObservables {
        let mut o = BodyObservables::default();
        for i in 0..self.len() {
            let inertia = self.inertia(i);
            let m = inertia.mass;
            let (w, v) = (self.omega[i], self.velocity[i]);
            let l = inertia.angular(w);
            o.translational_energy += 0.5 * m * v.length_squared();
            o.rotational_energy += 0.5 * w.dot(l);
            o.linear_momentum += m * v;
            o.angular_momentum += l + self.position[i].cross(m * v);
        }
        o
    }

    pub fn total_mass(&self) -> f64 {
        (0..self.len()).map(|i| self.template(i).mass()).sum()
    }
}
