//! Fixed-step integrators of m ẍ = F(x, ẋ, t).
//!
//! - explicit Euler: x' = x + h v, v' = v + h a(x, v) — first order, not
//!   symplectic: orbits spiral outwards and energy grows without bound;
//! - semi-implicit (symplectic) Euler: v' = v + h a(x, v), x' = x + h v' — first order;
//! - classical Runge–Kutta (RK4) on (x, v) — fourth order, not symplectic;
//! - leap-frog as kick–drift–kick velocity Verlet: v½ = v + h/2 a(x),
//!   x' = x + h v½, v' = v½ + h/2 a(x') — second order, symplectic, time
//!   reversible, one force evaluation per step (MPPphys `LF`).
//!
//! For velocity-dependent forces (damping) leap-frog evaluates a(x', v½).
//!
//! When an interaction exerts torques (frictional contacts), leap-frog kicks
//! the angular velocities with α = τ/I alongside the velocities:
//! ω½ = ω + h/2 α, ω' = ω½ + h/2 α' (spheres: isotropic inertia, so ω is
//! constant in free flight, and a dipole moment m turns by the rotation
//! vector ω½ h in the drift). The other schemes
//! ignore torques; scenes with rotation require leap-frog.

use glam::DVec3;
use rayon::prelude::*;

use crate::force::{ForceField, Spin, State};
use crate::particles::System;

/// The integration scheme, selected by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrator {
    Euler,
    SymplecticEuler,
    Rk4,
    LeapFrog,
}

impl Integrator {
    /// Accepts mote's names and MPPphys' (`LF`, `RK4`, `euler`), case-insensitively.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name.to_ascii_lowercase().as_str() {
            "euler" | "explicit-euler" | "explicit_euler" => Integrator::Euler,
            "symplectic-euler"
            | "symplectic_euler"
            | "semi-implicit-euler"
            | "semi_implicit_euler" => Integrator::SymplecticEuler,
            "rk4" | "runge-kutta" => Integrator::Rk4,
            "lf" | "leapfrog" | "leap-frog" | "velocity-verlet" | "velocity_verlet" | "kdk" => {
                Integrator::LeapFrog
            }
            _ => return None,
        })
    }

    pub const NAMES: &'static str =
        "euler, symplectic-euler, rk4 (RK4), leapfrog (LF, velocity-verlet)";

    pub fn name(self) -> &'static str {
        match self {
            Integrator::Euler => "euler",
            Integrator::SymplecticEuler => "symplectic-euler",
            Integrator::Rk4 => "rk4",
            Integrator::LeapFrog => "leapfrog",
        }
    }

    /// Order of the global error in h.
    pub fn order(self) -> u32 {
        match self {
            Integrator::Euler | Integrator::SymplecticEuler => 1,
            Integrator::LeapFrog => 2,
            Integrator::Rk4 => 4,
        }
    }
}

/// Rotates vector m by the rotation vector θ (angle |θ|, axis θ/|θ|),
/// Rodrigues' formula m' = m cos θ + (k × m) sin θ + k (k·m)(1 − cos θ):
/// exact, so |m| is kept to round-off.
#[inline]
pub fn rotate(m: DVec3, theta: DVec3) -> DVec3 {
    let angle = theta.length();
    if angle == 0.0 {
        return m;
    }
    let k = theta / angle;
    let (sin, cos) = angle.sin_cos();
    m * cos + k.cross(m) * sin + k * (k.dot(m) * (1.0 - cos))
}

/// Particles per parallel task of the element-wise updates (each element
/// is computed alone, so every thread count gives the same bits).
const PER_TASK: usize = 4096;

/// v += a h for every particle.
fn kick(velocity: &mut [DVec3], acc: &[DVec3], h: f64) {
    velocity
        .par_iter_mut()
        .zip(acc)
        .with_min_len(PER_TASK)
        .for_each(|(v, a)| *v += *a * h);
}

/// An integrator with its scratch space (the state itself lives in [`System`]).
pub struct Stepper {
    pub scheme: Integrator,
    acc: Vec<DVec3>,
    x0: Vec<DVec3>,
    v0: Vec<DVec3>,
    xs: Vec<DVec3>,
    vs: Vec<DVec3>,
    dx: Vec<DVec3>,
    dv: Vec<DVec3>,
}

impl Stepper {
    pub fn new(scheme: Integrator) -> Self {
        Self {
            scheme,
            acc: Vec::new(),
            x0: Vec::new(),
            v0: Vec::new(),
            xs: Vec::new(),
            vs: Vec::new(),
            dx: Vec::new(),
            dv: Vec::new(),
        }
    }

    fn eval(
        ff: &mut ForceField,
        sys: &System,
        x: &[DVec3],
        v: &[DVec3],
        t: f64,
        dt: f64,
        acc: &mut Vec<DVec3>,
    ) {
        acc.resize(x.len(), DVec3::ZERO);
        let state = State::of(sys, x, v, t, dt);
        ff.accelerations(&state, &sys.particles.mobility, acc);
    }

    /// Accelerations and angular accelerations at the system's own positions
    /// and velocities, `dt` after the previous evaluation.
    fn eval_rotating(
        ff: &mut ForceField,
        sys: &System,
        t: f64,
        dt: f64,
        acc: &mut Vec<DVec3>,
        alpha: &mut Vec<DVec3>,
    ) {
        let p = &sys.particles;
        acc.resize(p.len(), DVec3::ZERO);
        alpha.resize(p.len(), DVec3::ZERO);
        let state = State::of(sys, &p.position, &p.velocity, t, dt);
        let spin = Spin {
            angular_velocity: &p.angular_velocity,
        };
        ff.accelerations_and_angular(&state, &spin, p, acc, alpha);
    }

    /// Leap-frog (KDK) with rotation: velocities and angular velocities are
    /// kicked together.
    fn leapfrog_rotating(sys: &mut System, ff: &mut ForceField, t: f64, h: f64) {
        let mut acc = std::mem::take(&mut sys.carried_acceleration);
        let mut alpha = std::mem::take(&mut sys.carried_angular_acceleration);
        let n = sys.particles.len();
        if acc.len() != n || alpha.len() != n {
            ff.before_forces(sys);
            Self::eval_rotating(ff, sys, t, 0.0, &mut acc, &mut alpha);
        }
        let half = 0.5 * h;
        {
            let p = &mut sys.particles;
            (&mut p.velocity, &mut p.position)
                .into_par_iter()
                .zip(&acc)
                .with_min_len(PER_TASK)
                .for_each(|((v, x), a)| {
                    *v += *a * half;
                    *x += *v * h;
                });
            (&mut p.angular_velocity, &mut p.dipole)
                .into_par_iter()
                .zip(&alpha)
                .with_min_len(PER_TASK)
                .for_each(|((w, m), a)| {
                    *w += *a * half;
                    if *m != DVec3::ZERO {
                        *m = rotate(*m, *w * h);
                    }
                });
        }
        // A decomposed run's particles may migrate here: `acc` and
        // `alpha` are overwritten whole by the evaluation.
        ff.before_forces(sys);
        Self::eval_rotating(ff, sys, t + h, h, &mut acc, &mut alpha);
        let p = &mut sys.particles;
        kick(&mut p.velocity, &acc, half);
        kick(&mut p.angular_velocity, &alpha, half);
        sys.carried_acceleration = acc;
        sys.carried_angular_acceleration = alpha;
    }

    /// Evaluates the forces leap-frog will start from, if none are carried,
    /// and carries them. The first step would evaluate exactly these, so the
    /// trajectory does not change; what does is that the virial and the
    /// dipoles that observables read before the first step are those of the
    /// initial state, not of no evaluation at all (P(0) = ρkT, U_dd(0) = 0).
    /// Other schemes evaluate inside each step and are left alone.
    pub fn prime(&mut self, sys: &mut System, ff: &mut ForceField) {
        if self.scheme != Integrator::LeapFrog
            || sys.carried_acceleration.len() == sys.particles.len()
        {
            return;
        }
        let t = sys.time;
        let mut acc = std::mem::take(&mut sys.carried_acceleration);
        if ff.exerts_torques() {
            let mut alpha = std::mem::take(&mut sys.carried_angular_acceleration);
            ff.before_forces(sys);
            Self::eval_rotating(ff, sys, t, 0.0, &mut acc, &mut alpha);
            sys.carried_angular_acceleration = alpha;
        } else {
            ff.before_forces(sys);
            Self::eval(
                ff,
                sys,
                &sys.particles.position,
                &sys.particles.velocity,
                t,
                0.0,
                &mut acc,
            );
        }
        sys.carried_acceleration = acc;
    }

    /// Advances the system by one step h.
    pub fn step(&mut self, sys: &mut System, ff: &mut ForceField, h: f64) {
        let t = sys.time;
        match self.scheme {
            Integrator::Euler | Integrator::SymplecticEuler => {
                let mut acc = std::mem::take(&mut self.acc);
                Self::eval(
                    ff,
                    sys,
                    &sys.particles.position,
                    &sys.particles.velocity,
                    t,
                    h,
                    &mut acc,
                );
                let explicit = self.scheme == Integrator::Euler;
                let p = &mut sys.particles;
                for i in 0..p.len() {
                    // Explicit: x moves with the old v; semi-implicit: with the new.
                    let v_old = p.velocity[i];
                    p.velocity[i] += acc[i] * h;
                    p.position[i] += if explicit { v_old } else { p.velocity[i] } * h;
                }
                self.acc = acc;
                sys.carried_acceleration.clear();
            }
            Integrator::LeapFrog if ff.exerts_torques() => Self::leapfrog_rotating(sys, ff, t, h),
            Integrator::LeapFrog => {
                // a(x) of the previous step's end is carried in the system
                // (and in checkpoints), so it is evaluated once per step.
                let mut acc = std::mem::take(&mut sys.carried_acceleration);
                if acc.len() != sys.particles.len() {
                    ff.before_forces(sys);
                    Self::eval(
                        ff,
                        sys,
                        &sys.particles.position,
                        &sys.particles.velocity,
                        t,
                        0.0,
                        &mut acc,
                    );
                }
                let half = 0.5 * h;
                {
                    let p = &mut sys.particles;
                    (&mut p.velocity, &mut p.position)
                        .into_par_iter()
                        .zip(&acc)
                        .with_min_len(PER_TASK)
                        .for_each(|((v, x), a)| {
                            *v += *a * half;
                            *x += *v * h;
                        });
                }
                // A decomposed run's particles may migrate here: `acc` is
                // overwritten whole by the evaluation.
                ff.before_forces(sys);
                Self::eval(
                    ff,
                    sys,
                    &sys.particles.position,
                    &sys.particles.velocity,
                    t + h,
                    h,
                    &mut acc,
                );
                kick(&mut sys.particles.velocity, &acc, half);
                sys.carried_acceleration = acc;
            }
            Integrator::Rk4 => self.rk4(sys, ff, h),
        }
        sys.wrap_positions();
        sys.time = t + h;
        sys.step += 1;
    }

    /// Classical RK4 on y = (x, v), y' = (v, a(x, v, t)).
    fn rk4(&mut self, sys: &mut System, ff: &mut ForceField, h: f64) {
        let n = sys.particles.len();
        let t = sys.time;
        self.x0.clone_from(&sys.particles.position);
        self.v0.clone_from(&sys.particles.velocity);
        self.dx.clear();
        self.dx.resize(n, DVec3::ZERO);
        self.dv.clear();
        self.dv.resize(n, DVec3::ZERO);
        self.xs.clone_from(&self.x0);
        self.vs.clone_from(&self.v0);
        let mut acc = std::mem::take(&mut self.acc);
        // Stage weights: k1 and k4 count 1/6, k2 and k3 count 2/6; the next
        // stage is evaluated at y0 + c·h·k with c = ½, ½, 1.
        for (stage, (weight, c_next)) in [(1.0, 0.5), (2.0, 0.5), (2.0, 1.0), (1.0, 0.0)]
            .into_iter()
            .enumerate()
        {
            // Each stage is ts − (previous stage's time) after the last
            // evaluation: 0, h/2, 0, h/2, so histories advance h a step.
            let ts = t + h * [0.0, 0.5, 0.5, 1.0][stage];
            let dt = h * [0.0, 0.5, 0.0, 0.5][stage];
            Self::eval(ff, sys, &self.xs, &self.vs, ts, dt, &mut acc);
            for i in 0..n {
                let kx = self.vs[i];
                let kv = acc[i];
                self.dx[i] += kx * weight;
                self.dv[i] += kv * weight;
                if stage < 3 {
                    self.xs[i] = self.x0[i] + kx * (c_next * h);
                    self.vs[i] = self.v0[i] + kv * (c_next * h);
                }
            }
        }
        let p = &mut sys.particles;
        for i in 0..n {
            p.position[i] = self.x0[i] + self.dx[i] * (h / 6.0);
            p.velocity[i] = self.v0[i] + self.dv[i] * (h / 6.0);
        }
        self.acc = acc;
        sys.carried_acceleration.clear();
    }
}
