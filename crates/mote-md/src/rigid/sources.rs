//! Force and torque sources on rigid bodies: homogeneous external fields,
//! gravity, air drag, Coulomb forces between conducting planes and the
//! latent image (seed 000, FBI step 3: "electric,
//! magnetic, and elastic contributions … If there are external electric and
//! magnetic fields, these add to the force and torque on p in a
//! straightforward manner").

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

use glam::DVec3;
use mote_geom::DE;
use rayon::prelude::*;

use super::interaction::{BodyInteraction, BodyView};
use crate::force::latent::LatentImage;
use crate::force::slab::ConductingPlanes;
use crate::viewer::ViewerHooks;

/// A homogeneous field as a function of time.
#[derive(Clone)]
pub enum Field {
    Constant(DVec3),
    /// `offset + amplitude·(cos(2πft + phase)·u + sin(2πft + phase)·(n × u))`:
    /// a field of magnitude `amplitude` turning about the unit axis n with
    /// frequency f (Hz), pointing along the unit vector u ⊥ n at t = 0 (for
    /// phase 0).
    Rotating {
        offset: DVec3,
        amplitude: f64,
        axis: DVec3,
        start: DVec3,
        frequency: f64,
        phase: f64,
    },
    /// Any function of time.
    Custom(Arc<dyn Fn(f64) -> DVec3 + Send + Sync>),
}

impl fmt::Debug for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Field::Constant(v) => write!(f, "Constant({v})"),
            Field::Rotating {
                amplitude,
                axis,
                frequency,
                ..
            } => write!(f, "Rotating({amplitude} about {axis} at {frequency} Hz)"),
            Field::Custom(_) => write!(f, "Custom"),
        }
    }
}

impl Field {
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        match self {
            Field::Constant(v) => *v,
            Field::Rotating {
                offset,
                amplitude,
                axis,
                start,
                frequency,
                phase,
            } => {
                let (s, c) = (2.0 * PI * frequency * t + phase).sin_cos();
                *offset + *amplitude * (c * *start + s * axis.cross(*start))
            }
            Field::Custom(f) => f(t),
        }
    }

    pub fn zero() -> Field {
        Field::Constant(DVec3::ZERO)
    }
}

/// Homogeneous external electric field E(t) and magnetic field B(t) acting
/// on each body's charge q and dipole j: `F = q E`, `T = (j * r) × B`;
/// potential energy `−q E·x − (j * r)·B`. A homogeneous B exerts no force on
/// a dipole. Fields are taken at the time the integrator asks for,
/// t + Δt/2 in the FRBI.
#[derive(Clone, Debug)]
pub struct ExternalFields {
    pub electric: Field,
    pub magnetic: Field,
}

impl BodyInteraction for ExternalFields {
    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    fn name(&self) -> &str {
        "external fields"
    }

    /// A force from outside: no virial (LAMMPS's fix convention).
    fn virial(&mut self, _view: &BodyView<'_>) -> Option<f64> {
        Some(0.0)
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let t = view.step.time;
        let (e, b) = (self.electric.at(t), self.magnetic.at(t));
        let bodies = view.bodies;
        for (i, w) in wrench.iter_mut().enumerate() {
            let q = bodies.template(i).charge;
            w.v += q * e;
            w.omega += view.world.dipole[i].cross(b);
        }
    }

    fn potential_energy(&mut self, view: &BodyView<'_>) -> f64 {
        let t = view.step.time;
        let (e, b) = (self.electric.at(t), self.magnetic.at(t));
        let bodies = view.bodies;
        (0..bodies.len())
            .map(|i| {
                -bodies.template(i).charge * e.dot(bodies.position[i]) - view.world.dipole[i].dot(b)
            })
            .sum()
    }
}

impl ViewerHooks for ExternalFields {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        use mote_run::FieldKind;
        let mote_run::Change::Field { kind, value } = change else {
            return None;
        };
        let (field, symbol) = match kind {
            FieldKind::Electric => (&mut self.electric, "E"),
            FieldKind::Magnetic => (&mut self.magnetic, "B"),
            FieldKind::Gravity => return None,
        };
        let Field::Constant(old) = *field else {
            return Some(Err(format!(
                "the {} varies in time: only a constant one can be set",
                kind.name()
            )));
        };
        let new = DVec3::from(*value);
        *field = Field::Constant(new);
        Some(Ok(format!(
            "{} {symbol} {} → {}",
            kind.name(),
            crate::force::vector_text(old),
            crate::force::vector_text(new)
        )))
    }
}

/// Uniform gravity: `F = m g`, potential `−m g·x`.
#[derive(Clone, Copy, Debug)]
pub struct Gravity {
    pub g: DVec3,
}

impl BodyInteraction for Gravity {
    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    fn name(&self) -> &str {
        "gravity"
    }

    /// A force from outside: no virial (LAMMPS's fix convention).
    fn virial(&mut self, _view: &BodyView<'_>) -> Option<f64> {
        Some(0.0)
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        for (i, w) in wrench.iter_mut().enumerate() {
            w.v += view.bodies.template(i).mass() * self.g;
        }
    }

    fn potential_energy(&mut self, view: &BodyView<'_>) -> f64 {
        let b = view.bodies;
        (0..b.len())
            .map(|i| -b.template(i).mass() * self.g.dot(b.position[i]))
            .sum()
    }
}

impl ViewerHooks for Gravity {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        let mote_run::Change::Field {
            kind: mote_run::FieldKind::Gravity,
            value,
        } = change
        else {
            return None;
        };
        let g = DVec3::from(*value);
        let text = format!(
            "gravity g {} → {}",
            crate::force::vector_text(self.g),
            crate::force::vector_text(g)
        );
        self.g = g;
        Some(Ok(text))
    }
}

/// Air drag on the sphere of equal volume (radius R): Stokes
/// `F = −6πηR(v − u)` plus Newton's quadratic drag
/// `−½ ρ_air C_d πR² |v − u|(v − u)`, and the rotational Stokes torque
/// `T = −8πηR³ ω` (u: the wind). Either part is switched off by a zero
/// coefficient.
#[derive(Clone, Copy, Debug)]
pub struct AirDrag {
    /// Dynamic viscosity η (air: 1.8e-5 Pa s).
    pub viscosity: f64,
    /// Air density (1.2 kg/m³) for the quadratic part.
    pub air_density: f64,
    /// Drag coefficient C_d of the quadratic part (sphere: ≈ 0.47).
    pub drag_coefficient: f64,
    pub wind: DVec3,
}

impl BodyInteraction for AirDrag {
    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    fn name(&self) -> &str {
        "air drag"
    }

    /// A force from outside: no virial (LAMMPS's fix convention).
    fn virial(&mut self, _view: &BodyView<'_>) -> Option<f64> {
        Some(0.0)
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let b = view.bodies;
        for (i, w) in wrench.iter_mut().enumerate() {
            let r = b.template(i).equivalent_radius;
            let u = b.velocity[i] - self.wind;
            let lin = 6.0 * PI * self.viscosity * r;
            let quad = 0.5 * self.air_density * self.drag_coefficient * PI * r * r * u.length();
            w.v -= (lin + quad) * u;
            w.omega -= 8.0 * PI * self.viscosity * r * r * r * b.omega[i];
        }
    }
}

impl ViewerHooks for AirDrag {
    /// Damping sets the viscosity η of the Stokes parts.
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        let mote_run::Change::Damping(eta) = change else {
            return None;
        };
        let text = format!("air viscosity η {} → {eta}", self.viscosity);
        self.viscosity = *eta;
        Some(Ok(text))
    }
}

/// Bodies at or above this count use rayon for the per-body sums.
const PARALLEL_PAIRS: usize = 256;

fn for_each_body(n: usize, wrench: &mut [DE], f: impl Fn(usize) -> DE + Sync + Send) {
    if n >= PARALLEL_PAIRS {
        wrench
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, w)| *w += f(i));
    } else {
        for (i, w) in wrench.iter_mut().enumerate() {
            *w += f(i);
        }
    }
}

/// Coulomb forces between the bodies' charges (at their centres of mass)
/// between two conducting planes z = z₀ and z = z₀ + h, periodic along
/// them: every image and the bias field ([`ConductingPlanes`], Ewald or
/// P3M on the doubled cell). Replaces the open-space Coulomb law ([`DirectCoulomb`](crate::force::DirectCoulomb)), which knows no planes.
///
/// With `every` = n > 1 the charges' forces on one another (with their
/// images) are summed at every n-th evaluation and held in between (a
/// zero-order hold: the slow long-range part on a coarser clock than the
/// contacts); the bias field acts at every step.
#[derive(Debug)]
pub struct PlaneCoulomb {
    pub planes: ConductingPlanes,
    /// The height z₀ of the first plane.
    pub z0: f64,
    pub every: u64,
    held: HeldForces,
}

/// The last sum of the charges' forces on one another, per body.
#[derive(Debug, Default)]
struct HeldForces {
    calls: u64,
    force: Vec<(usize, DVec3)>,
}

impl PlaneCoulomb {
    pub fn new(planes: ConductingPlanes, z0: f64, every: u64) -> Self {
        PlaneCoulomb {
            planes,
            z0,
            every: every.max(1),
            held: Default::default(),
        }
    }
}

impl PlaneCoulomb {
    /// The charged bodies' indices, positions relative to the first plane
    /// and charges.
    fn charged(&self, view: &BodyView<'_>) -> (Vec<usize>, Vec<DVec3>, Vec<f64>) {
        let b = view.bodies;
        let index: Vec<usize> = (0..b.len())
            .filter(|&i| b.template(i).charge != 0.0)
            .collect();
        let shift = DVec3::new(0.0, 0.0, self.z0);
        let position = index.iter().map(|&i| b.position[i] - shift).collect();
        let charge = index.iter().map(|&i| b.template(i).charge).collect();
        (index, position, charge)
    }

    /// The z-forces (F₀, F_h) on the two planes (Maxwell stress with lateral
    /// modes up to `k_max`).
    pub fn plane_forces(&self, view: &BodyView<'_>, k_max: f64) -> [f64; 2] {
        let (_, position, charge) = self.charged(view);
        self.planes.plane_forces(&position, &charge, k_max)
    }
}

impl BodyInteraction for PlaneCoulomb {
    fn name(&self) -> &str {
        "Coulomb between conducting planes"
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let (index, position, charge) = self.charged(view);
        let held = &mut self.held;
        if held.calls.is_multiple_of(self.every) || held.force.len() != index.len() {
            let mut force = vec![DVec3::ZERO; index.len()];
            self.planes.add_forces(&position, &charge, &mut force);
            let bias = self.planes.bias_field();
            held.force = index
                .iter()
                .zip(&force)
                .zip(&charge)
                .map(|((&i, f), q)| (i, *f - *q * bias))
                .collect();
        }
        held.calls += 1;
        let bias = self.planes.bias_field();
        for ((i, f), q) in held.force.iter().zip(&charge) {
            wrench[*i].v += *f + *q * bias;
        }
    }

    fn potential_energy(&mut self, view: &BodyView<'_>) -> f64 {
        let (_, position, charge) = self.charged(view);
        self.planes.evaluate(&position, &charge, None).total()
    }

    fn describe(&self) -> Option<String> {
        Some(self.planes.describe())
    }

    /// The held forces belong to the bodies that were there: the next
    /// evaluation sums afresh, on a list built afresh.
    fn bodies_changed(&mut self, _kept: Option<&[bool]>) {
        self.held.force.clear();
        self.planes.forget_list();
    }

    /// The held forces and the evaluation count (so that a resumed run
    /// refreshes them at the same steps): [calls, (body, fx, fy, fz)…];
    /// with P3M, [the length of that, that, the P3M list's build].
    fn carried_state(&self) -> Vec<f64> {
        let mut out = Vec::new();
        if self.every > 1 {
            let held = &self.held;
            out.push(held.calls as f64);
            for (i, f) in &held.force {
                out.extend([*i as f64, f.x, f.y, f.z]);
            }
        }
        if self.planes.ewald().is_some() {
            return out;
        }
        let list = self.planes.carried_state();
        let mut tagged = vec![out.len() as f64];
        tagged.extend(out);
        tagged.extend(list);
        tagged
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        let state = if self.planes.ewald().is_none() && !state.is_empty() {
            let held = state[0] as usize;
            if state[0] != held as f64 || 1 + held > state.len() {
                return Err(format!(
                    "{}: a carried state of {} numbers does not fit",
                    self.name(),
                    state.len()
                ));
            }
            self.planes.restore_carried_state(&state[1 + held..])?;
            &state[1..1 + held]
        } else {
            state
        };
        if state.is_empty() {
            return Ok(());
        }
        if self.every == 1 || state.len() % 4 != 1 {
            return Err(format!(
                "{}: a held state of {} numbers does not fit",
                self.name(),
                state.len()
            ));
        }
        let held = &mut self.held;
        held.calls = state[0] as u64;
        held.force = state[1..]
            .chunks(4)
            .map(|c| (c[0] as usize, DVec3::new(c[1], c[2], c[3])))
            .collect();
        Ok(())
    }
}

/// The latent image's field ([`LatentImage`]) on the bodies' charges:
/// `F = q E(x − vt, z − z₀)`, the belt's conductor at z = z₀. The field
/// moves with the belt, so it has no time-independent potential: its work
/// is not in the energy.
#[derive(Clone, Debug)]
pub struct LatentField {
    pub image: LatentImage,
    /// The height z₀ of the belt's conducting plane.
    pub z0: f64,
}

impl BodyInteraction for LatentField {
    fn name(&self) -> &str {
        "latent image"
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let t = view.step.time;
        let b = view.bodies;
        for_each_body(b.len(), wrench, |i| {
            let q = b.template(i).charge;
            if q == 0.0 {
                return DE::ZERO;
            }
            let x = b.position[i];
            let (ex, ez) = self.image.field(x.x, x.z - self.z0, t);
            DE::new(DVec3::ZERO, q * DVec3::new(ex, 0.0, ez))
        });
    }
}
