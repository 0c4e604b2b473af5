//! The jamming finish towards vanishing pressure: energy minimisation at
//! fixed box by FIRE alternated with affine decompression, a decade of
//! pressure at a time down to the lowest pressure asked (O'Hern et al.
//! 2003's protocol), a chunk of minimiser steps at a time.
//!
//! FIRE (Bitzek et al., Phys. Rev. Lett. 97, 170201 (2006)) is damped
//! dynamics that mixes the velocity towards the force, v ← (1 − α) v +
//! α |v| F̂, speeding up while the power F·v stays positive and stopping
//! dead when it turns negative. A minimisation ends when the
//! root-mean-square net force is below the tolerance times the mean
//! contact force (or the floor the rounding of the positions sets,
//! ~50 ε L/δ̄; or when the best residual has not halved in 20 000 steps).
//! The barostat leaves a residual imbalance of a few per cent; at a true
//! minimum the spheres that carry no load lose their contacts, so rattlers
//! and the backbone's contact number are those of a mechanically stable
//! packing.
//!
//! Near jamming φ is linear in x = p^{2/3}, so each next φ comes from the
//! line through the last two minimised states (the first step takes the
//! slope of the barostat's last stages); a step that unjams the packing
//! (pressure below a thousandth of its aim) is undone and halved, at most
//! 20 times in all.

use glam::DVec3;

use super::{extrapolate, PairSums, Phase, SoftPacker, Stage, CHUNK};
use crate::boundary::Boundary;

/// Bitzek et al.'s parameters.
const N_MIN: u64 = 5;
const F_INC: f64 = 1.1;
const F_DEC: f64 = 0.5;
const ALPHA0: f64 = 0.1;
const F_ALPHA: f64 = 0.99;
/// Decompression steps undone before the finish gives up.
const MAX_FAILS: u32 = 20;
/// Steps in which the best residual must halve.
const STAGNATION: u64 = 20_000;

/// The finish in progress.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Jam {
    /// dφ/dx of the first decompression (x = p^{2/3}).
    pub slope: f64,
    /// Decompression steps undone so far.
    pub fails: u32,
    /// The decompression being tried, if one is.
    pub attempt: Option<Attempt>,
    /// The minimisation under way, if one is.
    pub fire: Option<Fire>,
}

/// A decompression step being tried: the state to go back to if it
/// unjams the packing, the minimised state it starts from, the pressure it
/// aims at and the step in φ.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Attempt {
    pub position: Vec<DVec3>,
    pub boundary: Boundary,
    pub last: Stage,
    pub aim: f64,
    pub dphi: f64,
}

/// FIRE's state between chunks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Fire {
    /// The first time step, and the one of now.
    pub dt0: f64,
    pub dt: f64,
    pub alpha: f64,
    /// Steps since the power was last negative.
    pub since_negative: u64,
    /// Steps of this minimisation.
    pub steps: u64,
    /// Residual force relative to the mean contact force.
    pub rel: f64,
    /// The best residual so far that halved the one before, and its step.
    pub best: f64,
    pub best_at: u64,
}

impl Jam {
    /// The finish after the barostat's `stages`: the first decompression
    /// takes the slope of the last three (3 without two).
    pub fn after(stages: &[Stage]) -> Jam {
        let last = &stages[stages.len().saturating_sub(3)..];
        Jam {
            slope: extrapolate(last).map_or(3.0, |(_, c)| c),
            fails: 0,
            attempt: None,
            fire: None,
        }
    }
}

/// The residual force relative to the mean contact force (Σ F·r ≈ F̄ d̄
/// per contact).
fn residual(force: &[DVec3], sums: &PairSums) -> f64 {
    let rms = (force.iter().map(|f| f.length_squared()).sum::<f64>() / force.len() as f64).sqrt();
    let mean_contact = sums.virial / sums.contacts.max(1) as f64;
    rms / mean_contact.max(1e-300)
}

/// The residual no minimiser gets below: positions carry ~ε L of
/// rounding, so overlaps δ carry a relative error ε L/δ and forces 3/2 of
/// it.
fn floor(side: f64, sums: &PairSums) -> f64 {
    let mean_overlap = sums.overlap / sums.contacts.max(1) as f64;
    50.0 * f64::EPSILON * side / mean_overlap.max(1e-300)
}

impl Fire {
    /// A minimisation from the spheres at rest.
    fn begin(p: &mut SoftPacker) -> Fire {
        p.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
        p.refresh_list();
        let sums = p.pair_forces_with(false);
        let dt0 = 0.1 / sums.stiffest.max(1e-300).sqrt();
        let rel = residual(&p.force, &sums);
        Fire {
            dt0,
            dt: dt0,
            alpha: ALPHA0,
            since_negative: 0,
            steps: 0,
            rel,
            best: rel,
            best_at: 0,
        }
    }

    /// Whether the minimisation goes on.
    fn going(&self, p: &SoftPacker, ftol: f64) -> bool {
        self.rel > ftol.max(floor(p.side(), &p.sums))
            && self.steps < p.settings.max_steps
            && self.steps - self.best_at < STAGNATION
    }

    /// One FIRE step.
    fn step(&mut self, p: &mut SoftPacker) {
        let power: f64 = p
            .force
            .iter()
            .zip(&p.velocity)
            .map(|(f, v)| f.dot(*v))
            .sum();
        if power > 0.0 {
            let fnorm = p
                .force
                .iter()
                .map(|f| f.length_squared())
                .sum::<f64>()
                .sqrt();
            let vnorm = p
                .velocity
                .iter()
                .map(|v| v.length_squared())
                .sum::<f64>()
                .sqrt();
            for (v, f) in p.velocity.iter_mut().zip(&p.force) {
                *v = (1.0 - self.alpha) * *v + self.alpha * vnorm * *f / fnorm.max(1e-300);
            }
            self.since_negative += 1;
            if self.since_negative > N_MIN {
                self.dt = (self.dt * F_INC).min(10.0 * self.dt0);
                self.alpha *= F_ALPHA;
            }
        } else {
            p.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
            self.since_negative = 0;
            self.dt *= F_DEC;
            self.alpha = ALPHA0;
        }
        let dt = self.dt;
        for i in 0..p.position.len() {
            p.velocity[i] += 0.5 * dt * p.force[i] / p.mass[i];
            p.position[i] += dt * p.velocity[i];
        }
        p.refresh_list();
        let sums = p.pair_forces_with(false);
        for i in 0..p.position.len() {
            p.velocity[i] += 0.5 * dt * p.force[i] / p.mass[i];
        }
        self.steps += 1;
        p.steps += 1;
        self.rel = residual(&p.force, &sums);
        if self.rel < 0.5 * self.best {
            (self.best, self.best_at) = (self.rel, self.steps);
        }
    }
}

/// Up to [`CHUNK`] steps of the finish; when a minimisation ends there,
/// its state is recorded and the next decompression (or the end) chosen.
pub(super) fn advance(p: &mut SoftPacker, mut jam: Jam) -> Phase {
    let Some(settings) = p.settings.finish else {
        return Phase::Over;
    };
    let (lowest, ftol) = (settings.lowest, settings.force_tolerance);
    let mut fire = match jam.fire.take() {
        Some(fire) => fire,
        None => {
            if let Some(last) = p.finish.last().copied() {
                if !(last.pressure > 1.5 * lowest && jam.fails < MAX_FAILS) {
                    return Phase::Over;
                }
                let attempt = jam
                    .attempt
                    .get_or_insert_with(|| decompression(p, &last, jam.slope, lowest, jam.fails));
                let scale = (attempt.last.phi / (attempt.last.phi - attempt.dphi)).cbrt();
                p.dilate(scale);
            }
            Fire::begin(p)
        }
    };
    for _ in 0..CHUNK {
        if !fire.going(p, ftol) {
            break;
        }
        fire.step(p);
    }
    if fire.going(p, ftol) {
        jam.fire = Some(fire);
        return Phase::Jam(Box::new(jam));
    }
    // The minimisation has ended.
    p.last_floor = floor(p.side(), &p.sums);
    p.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
    let converged = fire.rel <= ftol.max(p.last_floor);
    let Some(attempt) = jam.attempt.take() else {
        let first = record(p, fire.steps, f64::NAN, converged);
        p.finish.push(first);
        return if first.pressure > 0.0 {
            Phase::Jam(Box::new(jam))
        } else {
            Phase::Over
        };
    };
    let now = record(p, fire.steps, attempt.aim, converged);
    if now.pressure > 1e-3 * attempt.aim {
        p.finish.push(now);
        return Phase::Jam(Box::new(jam));
    }
    // Unjammed: back to the saved state, half the step.
    p.position.clone_from(&attempt.position);
    p.boundary = attempt.boundary;
    p.reference.clear();
    jam.fails += 1;
    if jam.fails >= MAX_FAILS {
        return Phase::Over;
    }
    jam.attempt = Some(Attempt {
        dphi: 0.5 * attempt.dphi,
        ..attempt
    });
    Phase::Jam(Box::new(jam))
}

/// The next decompression from minimised state `last`: aimed a decade of
/// pressure lower (not below `lowest`), the step in φ from the line in
/// x = p^{2/3} through the last two states (`slope` for the first), halved
/// for every step undone so far.
fn decompression(p: &SoftPacker, last: &Stage, slope: f64, lowest: f64, fails: u32) -> Attempt {
    let aim = (last.pressure / 10.0).max(lowest);
    let x = |p: f64| p.powf(2.0 / 3.0);
    let k = p.finish.len();
    let c = match k {
        1 => slope,
        _ => {
            let prev = p.finish[k - 2];
            (last.phi - prev.phi) / (x(last.pressure) - x(prev.pressure))
        }
    };
    let c = if c.is_finite() && c > 0.0 { c } else { slope };
    Attempt {
        position: p.position.clone(),
        boundary: p.boundary,
        last: *last,
        aim,
        dphi: c * (x(last.pressure) - x(aim)) / 2f64.powi(fails as i32),
    }
}

/// The minimised state of now, as a stage of the finish.
fn record(p: &mut SoftPacker, steps: u64, target: f64, converged: bool) -> Stage {
    let (pressure, z) = p.at_rest();
    Stage {
        target,
        pressure,
        phi: p.phi(),
        z,
        steps,
        total: p.steps,
        time: p.time,
        converged,
    }
}
