//! Forces and torques on rigid bodies: the [`BodyInteraction`] trait and the
//! world-frame view of the bodies it reads.
//!
//! Each interaction adds, per body, the wrench `dE(T, F)` — torque about the
//! body's centre of mass and force on it (seed 000: "a force (on its center
//! of mass) and a torque (around its center of mass)"). The integrator calls
//! every interaction once per step, at t + Δt/2, with a [`BodyView`] that
//! holds the sphere centres `x + cₖ * r` and dipoles `j * r` in the world
//! frame (seed 000, FBI step 3), so a contact model (Hertz spheres, walls)
//! can loop over spheres without touching the algebra.

use glam::DVec3;
use mote_geom::{rotation_matrix, DE};
use rayon::prelude::*;

use super::bodies::RigidBodies;
use super::free8::{world8, LANES};
use crate::force::StepParameters;

/// A source of forces and torques on bodies; one virtual call per step.
/// Interactions that carry state from step to step (contact histories,
/// held long-range forces, neighbour lists) change it through `&mut self`:
/// the integrator owns them, and callers read them back by type
/// ([`crate::rigid::Frbi::find`]).
pub trait BodyInteraction: AsAny + Send + Sync {
    /// A short name for reports.
    fn name(&self) -> &str;

    /// Adds to `wrench[i]` the torque (about the centre of mass, in `omega`)
    /// and force (in `v`) on body i at the view's time.
    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]);

    /// The potential energy at the view's time (zero for dissipative forces).
    fn potential_energy(&mut self, _view: &BodyView<'_>) -> f64 {
        0.0
    }

    /// The molecular virial W = Σ_{I<J} (R_I − R_J)·F_IJ of the forces at
    /// the view's placement and time: R the body centres (the minimum
    /// image of the pair), F_IJ the force body J exerts on body I — the
    /// body-centre virial of LAMMPS's `fix rigid`, so that a periodic box
    /// has the pressure P = (Σ_I M_I V_I² + W)/3V. A force from outside
    /// (gravity, fields, drag; walls, by LAMMPS's fix convention) adds 0;
    /// `None` where the interaction cannot give it (the pressure column is
    /// then left out, and the summary says why).
    fn virial(&mut self, _view: &BodyView<'_>) -> Option<f64> {
        None
    }
    /// How it sums, with the parameters it chose (a tuned long-range
    /// solver's), for the run's summary; `None` for most.
    fn describe(&self) -> Option<String> {
        None
    }
    /// The live viewer's hooks (steering the fields it owns), where this
    /// interaction has any.
    fn viewer_mut(&mut self) -> Option<&mut dyn crate::viewer::ViewerHooks> {
        None
    }

    /// Bodies came or went (`rigid::flow`): `kept` says, per sphere of
    /// the bodies before (body by body, in order), which stayed (`None`:
    /// all did); new bodies' spheres follow the kept ones. An interaction
    /// that carries state per sphere or body keeps that of those that
    /// stayed, renumbered; the others carry nothing and need not hear of it.
    fn bodies_changed(&mut self, _kept: Option<&[bool]>) {}

    /// What this interaction carries from one evaluation to the next
    /// (contact histories), as plain numbers for checkpoints; empty if nothing.
    fn carried_state(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Restores what [`BodyInteraction::carried_state`] gave, before the
    /// first evaluation of a resumed run.
    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        if state.is_empty() {
            Ok(())
        } else {
            Err(format!("{} carries no state", self.name()))
        }
    }
}

/// A body interaction as `Any`, so that its owner can be asked for one of
/// a given type (the contact model's wall forces, say).
pub trait AsAny {
    fn as_any(&self) -> &dyn std::any::Any;
}

impl<T: std::any::Any> AsAny for T {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The spheres and dipoles of all bodies in the world frame: scratch space
/// the integrator refreshes before each force evaluation.
#[derive(Clone, Debug, Default)]
pub struct WorldFrame {
    /// Sphere centres `x + cₖ * r`, body by body.
    pub sphere_centre: Vec<DVec3>,
    pub sphere_radius: Vec<f64>,
    /// The body each sphere belongs to.
    pub sphere_body: Vec<u32>,
    /// Spheres of body i are `sphere_start[i]..sphere_start[i + 1]`.
    pub sphere_start: Vec<u32>,
    /// Magnetic dipoles `j * r`.
    pub dipole: Vec<DVec3>,
}

impl WorldFrame {
    /// Recomputes everything from the bodies' placements (parallel over
    /// bodies for large systems; the result does not depend on threads).
    pub fn update(&mut self, bodies: &RigidBodies) {
        let n = bodies.len();
        if self.sphere_start.len() != n + 1 || self.sphere_body.is_empty() && n > 0 {
            self.sphere_start.clear();
            self.sphere_body.clear();
            self.sphere_radius.clear();
            let mut k = 0u32;
            for i in 0..n {
                self.sphere_start.push(k);
                let t = bodies.template(i);
                k += t.sphere_count() as u32;
                self.sphere_radius.extend_from_slice(&t.radii);
                self.sphere_body
                    .resize(self.sphere_body.len() + t.sphere_count(), i as u32);
            }
            self.sphere_start.push(k);
            self.sphere_centre.resize(k as usize, DVec3::ZERO);
        }
        self.dipole.resize(n, DVec3::ZERO);
        let fill = |i: usize, centres: &mut [DVec3], dipole: &mut DVec3| {
            let t = bodies.template(i);
            let m = rotation_matrix(bodies.rotation[i]);
            let x = bodies.position[i];
            for (c, b) in centres.iter_mut().zip(&t.centres) {
                *c = x + m * *b;
            }
            *dipole = m * t.dipole;
        };
        let starts = &self.sphere_start;
        // Blocks of bodies with their spheres; in a block, eight bodies of
        // one template at a time on the vector lanes, the others one by one.
        let block = |(c, (centres, dipoles)): (usize, (&mut [DVec3], &mut [DVec3]))| {
            let first = c * WORLD_BLOCK;
            let base = starts[first] as usize;
            let spheres = |i: usize, j: usize| starts[i] as usize - base..starts[j] as usize - base;
            let mut i = first;
            while i < first + dipoles.len() {
                let group = i + LANES <= first + dipoles.len()
                    && bodies.kind[i..i + LANES]
                        .iter()
                        .all(|&k| k == bodies.kind[i]);
                if group {
                    let t = bodies.template(i);
                    let d = &mut dipoles[i - first..i - first + LANES];
                    if world8(
                        bodies.rotation[i..i + LANES].try_into().expect("eight"),
                        bodies.position[i..i + LANES].try_into().expect("eight"),
                        &t.centres,
                        t.dipole,
                        &mut centres[spheres(i, i + LANES)],
                        d.try_into().expect("eight"),
                    ) {
                        i += LANES;
                        continue;
                    }
                }
                fill(i, &mut centres[spheres(i, i + 1)], &mut dipoles[i - first]);
                i += 1;
            }
        };
        let mut rest: &mut [DVec3] = &mut self.sphere_centre;
        let mut parts = Vec::with_capacity(n.div_ceil(WORLD_BLOCK));
        for c in 0..n.div_ceil(WORLD_BLOCK) {
            let (i, j) = (c * WORLD_BLOCK, ((c + 1) * WORLD_BLOCK).min(n));
            let (head, tail) = rest.split_at_mut((starts[j] - starts[i]) as usize);
            parts.push(head);
            rest = tail;
        }
        if n >= 4096 {
            parts
                .into_par_iter()
                .zip(self.dipole.par_chunks_mut(WORLD_BLOCK))
                .enumerate()
                .for_each(block);
        } else {
            parts
                .into_iter()
                .zip(self.dipole.chunks_mut(WORLD_BLOCK))
                .enumerate()
                .for_each(block);
        }
    }
}

/// Bodies per block of the world-frame update.
const WORLD_BLOCK: usize = 256;

/// What an interaction sees: the bodies and their world-frame spheres.
#[derive(Clone, Copy)]
pub struct BodyView<'a> {
    pub bodies: &'a RigidBodies,
    pub world: &'a WorldFrame,
    /// The time of the evaluation and the time since the previous one, by
    /// which contact histories advance (ξ += v_t dt): the step length
    /// within a step, 0 where a state is only measured — the parameters
    /// point particles' interactions read from their [`State`](crate::force::State).
    pub step: StepParameters,
}

impl<'a> BodyView<'a> {
    /// The bodies as they are, measured rather than stepped: at their
    /// time, no time since a previous evaluation (histories do not advance).
    pub fn measured(bodies: &'a RigidBodies, world: &'a WorldFrame) -> Self {
        BodyView {
            bodies,
            world,
            step: StepParameters {
                time: bodies.time,
                dt: 0.0,
            },
        }
    }

    /// The velocity of the material point `p` of body i: `v + ω × (p − x)`.
    #[inline]
    pub fn point_velocity(&self, i: usize, p: DVec3) -> DVec3 {
        self.bodies.velocity[i] + self.bodies.omega[i].cross(p - self.bodies.position[i])
    }

    /// The wrench of a force `f` applied at the point `p` of body i:
    /// `dE((p − x) × f, f)` (for contact models).
    #[inline]
    pub fn wrench_at(&self, i: usize, p: DVec3, f: DVec3) -> DE {
        DE::new((p - self.bodies.position[i]).cross(f), f)
    }
}
