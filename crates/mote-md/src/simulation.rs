//! The single run loop of the time-stepped engine.

use std::time::{Duration, Instant};

use crate::error::MdError;
use crate::force::ForceField;
use crate::integrate::Stepper;
use crate::observe::Observables;
use crate::particles::System;
use crate::thermostat::Thermostat;
use rand_xoshiro::Xoshiro256PlusPlus;

/// How long to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunLength {
    /// A number of steps.
    Steps(u64),
    /// Until the simulated time reaches T (the last step may end at most
    /// one step after T only by round-off: steps = ⌈(T − t)/Δt⌉).
    Until(f64),
}

impl RunLength {
    /// Number of steps from time `t` with step `dt`.
    pub fn steps_from(self, t: f64, dt: f64) -> u64 {
        match self {
            RunLength::Steps(n) => n,
            RunLength::Until(end) => {
                let n = (end - t) / dt;
                if n <= 0.0 {
                    0
                } else {
                    (n - 1e-9 * n.max(1.0)).ceil() as u64
                }
            }
        }
    }
}

/// Something that samples the run on a schedule (writers, recorders).
pub trait Observer {
    /// Sample when the step number is a multiple of this (≥ 1); the first
    /// and the last step of a run are always sampled.
    fn every(&self) -> u64;
    /// Samples the state; `obs` holds the whole-system observables of this instant.
    fn observe(&mut self, sys: &System, obs: &Observables) -> Result<(), MdError>;
    /// Files this observer wrote, for the report.
    fn files(&self) -> Vec<String> {
        Vec::new()
    }
    /// Called just before [`Observer::observe`] with the force field, for
    /// observers that record what interactions carry from step to step
    /// (checkpoints of contact histories).
    fn observe_forces(&mut self, forces: &ForceField) {
        let _ = forces;
    }
    /// Whether to sample the step at which a signal stops the run (true
    /// for checkpoints; false for tables and trajectories, whose files a
    /// resumed run then continues as if never interrupted).
    fn at_interruption(&self) -> bool {
        false
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    pub steps: u64,
    pub wall: Duration,
    pub initial: Observables,
    pub last: Observables,
    /// max |E(t) − E(0)| / |E(0)| over the sampled instants.
    pub max_energy_error: f64,
    pub files: Vec<String>,
}

/// A run: the state, its forces, its integrator and its observers.
pub struct Simulation {
    pub system: System,
    pub forces: ForceField,
    pub stepper: Stepper,
    pub dt: f64,
    pub observers: Vec<Box<dyn Observer>>,
    /// Applied after every step (NVE when `None`).
    pub thermostat: Option<Thermostat>,
    /// The run's seed. Thermostat noise of step k comes from a generator
    /// seeded by (seed, k) ([`Simulation::noise`]), so a run resumed from a
    /// checkpoint draws exactly the numbers the uninterrupted run would.
    pub seed: u64,
    /// Hand the starting state to the observers (false when resuming: the
    /// interrupted run already wrote it).
    pub sample_at_start: bool,
    /// Overdamped Brownian dynamics instead of the inertial `stepper`
    /// (004 Eqs. 14–16); its noise is counter-based like the thermostat's.
    pub brownian: Option<crate::brownian::BrownianStepper>,
}

impl Simulation {
    /// Runs for `length`, calling `progress(system)` after every step.
    /// On a non-finite position or velocity the run stops with
    /// [`MdError::Unstable`] naming the step and particle; what the observers
    /// wrote until then stays on disk.
    pub fn run(
        &mut self,
        length: RunLength,
        mut progress: impl FnMut(&System),
    ) -> Result<RunReport, MdError> {
        let start = Instant::now();
        let steps = length.steps_from(self.system.time, self.dt);
        let first_step = self.system.step;
        if self.brownian.is_none() {
            self.stepper.prime(&mut self.system, &mut self.forces);
        }
        let initial = Observables::measure(&self.system, &mut self.forces);
        let e0 = initial.total_energy();
        let mut max_err: f64 = 0.0;
        let mut last = initial.clone();
        if self.sample_at_start {
            self.sample(true, &initial)?;
        }
        for k in 1..=steps {
            if let Some(bd) = &mut self.brownian {
                let index = self.system.step + 1;
                bd.step(
                    &mut self.system,
                    &mut self.forces,
                    self.dt,
                    index,
                    self.seed,
                );
            } else {
                self.stepper
                    .step(&mut self.system, &mut self.forces, self.dt);
            }
            if let Some(t) = self.thermostat {
                let mut rng = self.noise(self.system.step);
                t.apply(&mut self.system, self.dt, &mut rng);
            }
            self.check_finite()?;
            // Schedules count absolute steps, so a resumed run samples
            // exactly where the uninterrupted one would.
            let step = self.system.step;
            let last_step = k == steps;
            let due = last_step
                || self
                    .observers
                    .iter()
                    .any(|o| step.is_multiple_of(o.every().max(1)));
            if due {
                last = Observables::measure(&self.system, &mut self.forces);
                let err = if e0 != 0.0 {
                    (last.total_energy() - e0).abs() / e0.abs()
                } else {
                    (last.total_energy() - e0).abs()
                };
                max_err = max_err.max(err);
                self.sample(last_step, &last)?;
            }
            progress(&self.system);
            if let Some(signal) = mote_io::system::stop_requested() {
                if !last_step {
                    for o in &mut self.observers {
                        if o.at_interruption() && !step.is_multiple_of(o.every().max(1)) {
                            o.observe_forces(&self.forces);
                            o.observe(&self.system, &last)?;
                        }
                    }
                    return Err(MdError::Interrupted {
                        signal,
                        step,
                        time: self.system.time,
                    });
                }
            }
        }
        Ok(RunReport {
            steps: self.system.step - first_step,
            wall: start.elapsed(),
            initial,
            last,
            max_energy_error: max_err,
            files: self.observers.iter().flat_map(|o| o.files()).collect(),
        })
    }

    /// The random stream of step `step`: xoshiro256++ seeded (through
    /// SplitMix64) from the run's seed and the step number.
    pub fn noise(&self, step: u64) -> Xoshiro256PlusPlus {
        use rand::SeedableRng;
        Xoshiro256PlusPlus::seed_from_u64(
            self.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(17),
        )
    }

    /// Hands the state to the observers due at this step (all of them when `always`).
    fn sample(&mut self, always: bool, obs: &Observables) -> Result<(), MdError> {
        let step = self.system.step;
        for o in &mut self.observers {
            if always || step.is_multiple_of(o.every().max(1)) {
                o.observe_forces(&self.forces);
                o.observe(&self.system, obs)?;
            }
        }
        Ok(())
    }

    fn check_finite(&self) -> Result<(), MdError> {
        let p = &self.system.particles;
        for i in 0..p.len() {
            let bad = if !p.position[i].is_finite() {
                Some("a non-finite position")
            } else if !p.velocity[i].is_finite() {
                Some("a non-finite velocity")
            } else {
                None
            };
            if let Some(what) = bad {
                return Err(MdError::Unstable {
                    step: self.system.step,
                    time: self.system.time,
                    particle: i,
                    what: format!("{what} ({} / {})", p.position[i], p.velocity[i]),
                });
            }
        }
        Ok(())
    }
}
