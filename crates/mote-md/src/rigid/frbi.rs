//! The Fast Rigid Bodies Integrator (seed 000, "Time stepping algorithm for
//! Par" and "Fast Rigid Bodies Integrator (FBI) for the many-body system").
//!
//! One step of length Δt: every body `freeStep(Δt/2)`; forces and torques
//! from all interactions once, at t + Δt/2; every body `react(dE(T·Δt,
//! F·Δt))`; every body `freeStep(Δt/2)`. Like the explicit midpoint method
//! it needs one force evaluation per step, and Δt may change from step to
//! step.

use glam::DVec3;
use mote_geom::{compose_rotations, rotation_matrix, DMat3, Inertia, DE};
use rayon::prelude::*;

use super::bodies::RigidBodies;
use super::contacts::RigidContacts;
use super::free8::{free_step8, react8, Group, LANES};
use super::interaction::{BodyInteraction, BodyView, WorldFrame};
use crate::force::timing::builds;
use crate::force::StepParameters;

/// How the centre of mass moves in a free step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FreeFlight {
    /// The centre of mass moves on a straight line, `x += v Δt`, while the
    /// body turns about it by `exp(dE(ω_c, 0)·Δt)`. This is the free motion
    /// of a rigid body; it is the default.
    #[default]
    Straight,
    /// The seed's literal update `g = E(r, 0) ∘ exp(h_c·Δt) ∘ E(0, x)`: the
    /// body follows the screw motion of the whole velocity `h_c = dE(ω_c, v)`,
    /// so the centre of mass moves on a helical arc whose chord is v·Δt
    /// turned by about |ω|Δt/2 about ω. Step after step this turns the
    /// path of a spinning, moving body by an angle ∝ Δt (a first-order error
    /// in position, measured in `tests/rigid_free_flight.rs`); kept for
    /// comparison with the seed.
    Screw,
}

/// How the angular velocity is updated at the end of a free step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpinUpdate {
    /// The seed's `h := h_c + Δh`: ω is extrapolated linearly through the
    /// midpoint value. The angular momentum of a free body is then kept only
    /// to O(Δt²) per step, which shows as the seed's "L_y … with an obvious
    /// constant trend" (a drift ∝ Δt), and precession rates are first order
    /// (tests/rigid_top.rs).
    Seed,
    /// `ω := I_new⁻¹ * (I * ω)` with `I_new = I₀ ∘ g_new`: the angular
    /// momentum about the centre of mass is carried through the free step
    /// exactly (to rounding); the placement update is the seed's. Precession
    /// rates become second order and the total angular momentum of
    /// interacting bodies is kept to rounding. The default.
    #[default]
    KeepMomentum,
}

/// `freeStep(Δt)` of seed 000 for one body, mutating its placement
/// `E(r, x)` and angular velocity ω (v does not change in free flight):
///
/// `τ := Δt/2`, `g_c := exp(h·τ)`, `I := I₀ ∘ g`, `I_c := I ∘ g_c`,
/// `Δh := I⁻¹ * (I * h − I_c * h)`, `h_c := h + Δh`,
/// `g := E(r, 0) ∘ exp(h_c·Δt) ∘ E(0, x)`, `h := h_c + Δh`.
///
/// The linear part of Δh is `v·μ − v·μ = 0`, so the linear momentum of a
/// free body is kept exactly.
#[inline]
#[allow(clippy::too_many_arguments)] // the body's state, spelled out for SoA callers
pub fn free_step(
    inertia0: &Inertia,
    rotation: &mut DVec3,
    position: &mut DVec3,
    omega: &mut DVec3,
    velocity: DVec3,
    dt: f64,
    flight: FreeFlight,
    spin: SpinUpdate,
) {
    // I = I₀ ∘ g acts as ω ↦ P (J ⊙ Pᵀω) with P = R(r)·A, A the template's
    // principal axes (columns) and J its moments; I_c = I ∘ g_c uses
    // R(r_c)·P. The same algebra as `Inertia::rotated`, with one rotation
    // matrix per placement instead of three vector rotations per use.
    let a = DMat3::from_cols(inertia0.axes[0], inertia0.axes[1], inertia0.axes[2]);
    let j = DVec3::from(inertia0.moments);
    let j_inv = DVec3::ONE / j;
    let tau = 0.5 * dt;
    let w = *omega;
    let p = matrix(*rotation) * a;
    let apply = |p: &DMat3, d: DVec3, x: DVec3| *p * (d * (p.transpose() * x));
    let l = apply(&p, j, w);
    let r_c = DE::exp_rotation(w, tau);
    let p_c = matrix(r_c) * p;
    let dl = l - apply(&p_c, j, w);
    let dw = apply(&p, j_inv, dl);
    let w_c = w + dw;
    match flight {
        FreeFlight::Straight => {
            *rotation = compose_rotations(*rotation, DE::exp_rotation(w_c, dt));
            *position += velocity * dt;
        }
        FreeFlight::Screw => {
            let g = DE::new(w_c, velocity).exp(dt);
            *rotation = compose_rotations(*rotation, g.r);
            *position += g.a;
        }
    }
    *omega = match spin {
        SpinUpdate::Seed => w_c + dw,
        SpinUpdate::KeepMomentum => apply(&(matrix(*rotation) * a), j_inv, l),
    };
}

/// The matrix of `x ↦ x * r` (`mote_geom::rotate`):
/// `((1 − r²)·1 + 2 r rᵀ + 2 [r]ₓ) / (1 + r²)`.
#[inline(always)]
fn matrix(r: DVec3) -> DMat3 {
    let rr = r.dot(r);
    if rr > 1e100 {
        return rotation_matrix(r);
    }
    let s = 1.0 / (1.0 + rr);
    let c = (1.0 - rr) * s;
    let t = 2.0 * s;
    let (x, y, z) = (r.x, r.y, r.z);
    DMat3::from_cols(
        DVec3::new(c + t * x * x, t * (x * y + z), t * (x * z - y)),
        DVec3::new(t * (x * y - z), c + t * y * y, t * (y * z + x)),
        DVec3::new(t * (x * z + y), t * (y * z - x), c + t * z * z),
    )
}

/// `react(h̃)` of seed 000: `Δh := I⁻¹ h̃`, `h := h + Δh`, where
/// `h̃ = dE(T·Δt, F·Δt)` is the momentum a wrench gives in Δt and
/// `I = I₀ ∘ g` the inertia at the current placement.
#[inline]
pub fn react(
    inertia0: &Inertia,
    rotation: DVec3,
    omega: &mut DVec3,
    velocity: &mut DVec3,
    impulse: DE,
) {
    let a = DMat3::from_cols(inertia0.axes[0], inertia0.axes[1], inertia0.axes[2]);
    let p = matrix(rotation) * a;
    let j_inv = DVec3::ONE / DVec3::from(inertia0.moments);
    *omega += p * (j_inv * (p.transpose() * impulse.omega));
    *velocity += impulse.v * (1.0 / inertia0.mass);
}

/// Bodies at or above this count are stepped in parallel (each body's
/// update is independent, so the result does not depend on threads).
const PARALLEL_BODIES: usize = 2048;

/// One block's (index, ((rotation vectors, positions), angular velocities)).
type BodyBlock<'a> = (usize, ((&'a mut [DVec3], &'a mut [DVec3]), &'a mut [DVec3]));

/// Bodies per parallel block of the free steps (a multiple of
/// [`LANES`]).
const BODY_BLOCK: usize = 256;

/// The many-body integrator: owns the interactions, the free-flight rule and
/// scratch space (world frame, wrenches); the state is the [`RigidBodies`].
pub struct Frbi {
    pub flight: FreeFlight,
    pub spin: SpinUpdate,
    interactions: Vec<Box<dyn BodyInteraction>>,
    world: WorldFrame,
    wrench: Vec<DE>,
    /// Wall time of each interaction's wrench passes.
    pub timing: crate::force::timing::Timing,
}

/// Energies of the bodies at their current state.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BodyEnergies {
    pub kinetic: f64,
    pub potential: f64,
}

impl BodyEnergies {
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential
    }
}

impl Default for Frbi {
    fn default() -> Self {
        Self::new()
    }
}

impl Frbi {
    pub fn new() -> Self {
        Frbi {
            flight: FreeFlight::default(),
            spin: SpinUpdate::default(),
            interactions: Vec::new(),
            world: WorldFrame::default(),
            wrench: Vec::new(),
            timing: Default::default(),
        }
    }

    /// The seed's algorithm to the letter: screw-motion free flight and the
    /// seed's spin update (for comparison with its figure).
    pub fn seed_literal() -> Self {
        let mut f = Self::new();
        f.flight = FreeFlight::Screw;
        f.spin = SpinUpdate::Seed;
        f
    }

    pub fn with(mut self, interaction: impl BodyInteraction + 'static) -> Self {
        self.push(Box::new(interaction));
        self
    }

    pub fn push(&mut self, interaction: Box<dyn BodyInteraction>) {
        self.interactions.push(interaction);
    }

    pub fn interactions(&self) -> &[Box<dyn BodyInteraction>] {
        &self.interactions
    }

    /// The wrenches of the last step (at its midpoint), one per body.
    pub fn last_wrenches(&self) -> &[DE] {
        &self.wrench
    }

    /// The first interaction of type `T` (the contact model, say), to
    /// read what it measured.
    pub fn find<T: BodyInteraction + 'static>(&self) -> Option<&T> {
        self.interactions
            .iter()
            .find_map(|it| (**it).as_any().downcast_ref::<T>())
    }

    /// What the interactions that describe themselves say
    /// ([`BodyInteraction::describe`]), in order.
    pub fn descriptions(&self) -> Vec<String> {
        self.interactions
            .iter()
            .filter_map(|i| i.describe())
            .collect()
    }

    /// The interactions, to change their settings between steps.
    pub fn interactions_mut(&mut self) -> &mut [Box<dyn BodyInteraction>] {
        &mut self.interactions
    }

    /// Every body `freeStep(dt)`: eight bodies at a time through
    /// [`free8`](super::free8) (the same bits as [`free_step`]), the last
    /// few one by one; blocks of bodies in parallel when there are many.
    pub fn free_all(&self, b: &mut RigidBodies, dt: f64) {
        let (flight, spin) = (self.flight, self.spin);
        let templates = &b.templates;
        let kind = &b.kind;
        let velocity = &b.velocity;
        let block = |(c, ((r, x), w)): BodyBlock<'_>| {
            let first = c * BODY_BLOCK;
            let inertia = |i: usize| &templates[kind[i] as usize].inertia;
            let groups = r.len() / LANES;
            for g in 0..groups {
                let at = g * LANES;
                let lanes = at..at + LANES;
                let mut group = Group {
                    inertia: std::array::from_fn(|l| inertia(first + at + l)),
                    rotation: (&mut r[lanes.clone()]).try_into().expect("eight"),
                    position: (&mut x[lanes.clone()]).try_into().expect("eight"),
                    omega: (&mut w[lanes]).try_into().expect("eight"),
                    velocity: velocity[first + at..first + at + LANES]
                        .try_into()
                        .expect("eight"),
                };
                free_step8(&mut group, dt, flight, spin);
            }
            for k in groups * LANES..r.len() {
                let i = first + k;
                free_step(
                    inertia(i),
                    &mut r[k],
                    &mut x[k],
                    &mut w[k],
                    velocity[i],
                    dt,
                    flight,
                    spin,
                );
            }
        };
        if b.len() >= PARALLEL_BODIES {
            b.rotation
                .par_chunks_mut(BODY_BLOCK)
                .zip(b.position.par_chunks_mut(BODY_BLOCK))
                .zip(b.omega.par_chunks_mut(BODY_BLOCK))
                .enumerate()
                .for_each(block);
        } else {
            b.rotation
                .chunks_mut(BODY_BLOCK)
                .zip(b.position.chunks_mut(BODY_BLOCK))
                .zip(b.omega.chunks_mut(BODY_BLOCK))
                .enumerate()
                .for_each(block);
        }
    }

    /// Where a run's wall time `wall` went, `stepping` of it in steps:
    /// each interaction, the rest of the steps (the free flight, the
    /// kick), and between the steps.
    pub fn breakdown(
        &self,
        stepping: std::time::Duration,
        wall: std::time::Duration,
    ) -> crate::force::timing::Breakdown {
        // The contacts search with a list of their own: its builds are
        // named beside their share, as the shared list's are.
        let names: Vec<String> = (self.interactions.iter())
            .map(|i| match i.as_any().downcast_ref::<RigidContacts>() {
                Some(c) => format!("{} (list: {})", i.name(), builds(c.list_builds())),
                None => i.name().to_string(),
            })
            .collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        crate::force::timing::Breakdown::new(&names, &self.timing, stepping, wall)
    }

    /// The wrenches `dE(T, F)` of all interactions on all bodies at time
    /// `t`, `dt` after the previous evaluation (also refreshes the world
    /// frame).
    pub fn wrenches(&mut self, b: &RigidBodies, t: f64, dt: f64) -> &[DE] {
        self.world.update(b);
        self.wrench.clear();
        self.wrench.resize(b.len(), DE::ZERO);
        let view = BodyView {
            bodies: b,
            world: &self.world,
            step: StepParameters { time: t, dt },
        };
        for (k, it) in self.interactions.iter_mut().enumerate() {
            let since = std::time::Instant::now();
            it.add_wrenches(&view, &mut self.wrench);
            self.timing.interaction(k, since);
        }
        &self.wrench
    }

    /// One FRBI step of length `dt` (seed 000): free(dt/2), forces at
    /// t + dt/2, react, free(dt/2). `dt` may differ from step to step.
    pub fn step(&mut self, b: &mut RigidBodies, dt: f64) {
        self.free_all(b, 0.5 * dt);
        let t_mid = b.time + 0.5 * dt;
        self.wrenches(b, t_mid, dt);
        let wrench = &self.wrench;
        let templates = &b.templates;
        let kind = &b.kind;
        let rotation = &b.rotation;
        let kick = |(c, (w, v)): (usize, (&mut [DVec3], &mut [DVec3]))| {
            let first = c * BODY_BLOCK;
            let inertia = |i: usize| &templates[kind[i] as usize].inertia;
            let groups = w.len() / LANES;
            for g in 0..groups {
                let (at, i) = (g * LANES, first + g * LANES);
                react8(
                    std::array::from_fn(|l| inertia(i + l)),
                    rotation[i..i + LANES].try_into().expect("eight"),
                    (&mut w[at..at + LANES]).try_into().expect("eight"),
                    (&mut v[at..at + LANES]).try_into().expect("eight"),
                    &std::array::from_fn(|l| wrench[i + l] * dt),
                );
            }
            for k in groups * LANES..w.len() {
                let i = first + k;
                react(
                    inertia(i),
                    rotation[i],
                    &mut w[k],
                    &mut v[k],
                    wrench[i] * dt,
                );
            }
        };
        if b.len() >= PARALLEL_BODIES {
            b.omega
                .par_chunks_mut(BODY_BLOCK)
                .zip(b.velocity.par_chunks_mut(BODY_BLOCK))
                .enumerate()
                .for_each(kick);
        } else {
            b.omega
                .chunks_mut(BODY_BLOCK)
                .zip(b.velocity.chunks_mut(BODY_BLOCK))
                .enumerate()
                .for_each(kick);
        }
        self.free_all(b, 0.5 * dt);
        b.time += dt;
    }

    /// Bodies came or went ([`BodyInteraction::bodies_changed`], `kept`
    /// per sphere of the bodies before): every interaction hears of it,
    /// and the world frame is laid out afresh.
    pub fn bodies_changed(&mut self, kept: Option<&[bool]>) {
        self.world = WorldFrame::default();
        for it in &mut self.interactions {
            it.bodies_changed(kept);
        }
    }

    /// The keys of the interactions' carried state in checkpoints: their
    /// names, a repeated one numbered (`mote_io::checkpoint::carried_keys`).
    fn carried_keys(&self) -> Vec<String> {
        mote_io::checkpoint::carried_keys(self.interactions.iter().map(|it| it.name()))
    }

    /// What the interactions carry from step to step (contact histories),
    /// by interaction name; interactions that carry nothing are left out.
    pub fn carried_state(&self) -> Vec<(String, Vec<f64>)> {
        self.carried_keys()
            .into_iter()
            .zip(&self.interactions)
            .map(|(key, it)| (key, it.carried_state()))
            .filter(|(_, v)| !v.is_empty())
            .collect()
    }

    /// Gives each interaction back what [`Frbi::carried_state`] took, found
    /// by name.
    pub fn restore_carried_state(
        &mut self,
        cp: &mote_io::checkpoint::Checkpoint,
    ) -> Result<(), String> {
        for (k, values) in mote_io::checkpoint::match_carried(cp, &self.carried_keys())? {
            self.interactions[k].restore_carried_state(values)?;
        }
        Ok(())
    }

    /// The molecular virial of every interaction at the bodies' current
    /// time ([`BodyInteraction::virial`]), or the names of those that
    /// cannot give one.
    pub fn virial(&mut self, b: &RigidBodies) -> Result<f64, Vec<String>> {
        self.world.update(b);
        let view = BodyView::measured(b, &self.world);
        let mut total = 0.0;
        let mut without = Vec::new();
        for it in self.interactions.iter_mut() {
            match it.virial(&view) {
                Some(w) => total += w,
                None => without.push(it.name().to_string()),
            }
        }
        if without.is_empty() {
            Ok(total)
        } else {
            Err(without)
        }
    }

    /// Kinetic and potential energy at the bodies' current time.
    pub fn energies(&mut self, b: &RigidBodies) -> BodyEnergies {
        self.world.update(b);
        let view = BodyView::measured(b, &self.world);
        let potential = self
            .interactions
            .iter_mut()
            .map(|it| it.potential_energy(&view))
            .sum();
        BodyEnergies {
            kinetic: b.observables().kinetic_energy(),
            potential,
        }
    }
}
