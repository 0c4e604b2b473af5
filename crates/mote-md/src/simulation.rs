//! The time-stepped propagator: fixed-step integrators, thermostats and
//! Brownian dynamics, stepped by mote's one loop ([`mote_run::Driver`]).

use crate::error::MdError;
use crate::force::ForceField;
use crate::integrate::Stepper;
use crate::observe::Observables;
use crate::particles::System;
use crate::thermostat::Thermostat;
use glam::DVec3;

pub use mote_run::scene::RunLength;

/// What a time-stepped run did.
pub type RunReport = mote_run::Report<Observables>;

/// The time-stepped propagator: the state, its forces, its integrator,
/// the thermostat or Brownian dynamics; moved by [`mote_run::Driver`].
pub struct Simulation {
    pub system: System,
    pub forces: ForceField,
    pub stepper: Stepper,
    pub dt: f64,
    /// Applied after every step (NVE when `None`).
    pub thermostat: Option<Thermostat>,
    /// The run's seed. Thermostat noise of step k comes from generators
    /// seeded by (seed, k) and the particles' ids
    /// ([`crate::thermostat::Noise`]), so a run resumed from a checkpoint,
    /// or decomposed, draws exactly the numbers the uninterrupted run would.
    pub seed: u64,
    /// Overdamped Brownian dynamics instead of the inertial `stepper`
    /// (004 Eqs. 14–16); its noise is counter-based like the thermostat's.
    pub brownian: Option<crate::brownian::BrownianStepper>,
    /// Particles entering and leaving ([`crate::flow`]), after the steps
    /// its `every` divides.
    pub flow: Option<crate::flow::Flow>,
    /// Total energy at the first measurement of the current run and the
    /// largest relative departure from it measured since.
    energy_watch: Option<(f64, f64)>,
    /// Wall time spent stepping in this run (the force field's
    /// [`Timing`](crate::force::timing::Timing) says how much of it went
    /// to each interaction and the neighbour list).
    pub stepping: std::time::Duration,
}

impl Simulation {
    /// Where this run's wall time `wall` went: each interaction, the
    /// neighbour list, the rest of the steps, and between the steps.
    pub fn breakdown(&self, wall: std::time::Duration) -> crate::force::timing::Breakdown {
        let names: Vec<&str> = self.forces.interactions.iter().map(|i| i.name()).collect();
        crate::force::timing::Breakdown::new(&names, &self.forces.timing, self.stepping, wall)
    }

    /// The simulation of `system` under `forces`, stepped by `stepper`.
    pub fn new(system: System, forces: ForceField, stepper: Stepper, dt: f64, seed: u64) -> Self {
        Simulation {
            system,
            forces,
            stepper,
            dt,
            thermostat: None,
            seed,
            brownian: None,
            flow: None,
            energy_watch: None,
            stepping: std::time::Duration::ZERO,
        }
    }

    /// Runs for `length` without observers, calling `progress(system)`
    /// after every step. On a non-finite position or velocity the run stops
    /// with [`MdError::Unstable`] naming the step and particle.
    pub fn run(
        &mut self,
        length: RunLength,
        mut progress: impl FnMut(&System),
    ) -> Result<RunReport, MdError> {
        let last = self.system.step
            + length
                .steps_from(self.system.time, self.dt)
                .map_err(MdError::Length)?;
        mote_run::Driver::new().run(self, |_| last, |s| progress(&s.system))
    }

    /// Splits the run over `comm`'s ranks by spatial domain decomposition
    /// ([`crate::domain`]): this rank keeps the particles of its brick (of
    /// `grid` bricks, or the grid chosen from the box's shape). Refuses,
    /// naming it, what does not run decomposed yet.
    pub fn decompose(
        &mut self,
        comm: std::sync::Arc<dyn mote_run::comm::Comm>,
        grid: Option<[usize; 3]>,
    ) -> Result<(), String> {
        let ranks = comm.size();
        let not_yet = |what: &str| {
            Err(format!(
                "{what} does not run on {ranks} ranks yet: run it on one"
            ))
        };
        if self.flow.is_some() {
            return not_yet("inserting and removing particles");
        }
        if self.stepper.scheme != crate::Integrator::LeapFrog {
            return not_yet(&format!(
                "the {} integrator (leap-frog does)",
                self.stepper.scheme.name()
            ));
        }
        let reach = match self.forces.halo_reach() {
            Ok(reach) => reach,
            Err(names) => {
                return not_yet(&format!(
                    "{} (Lennard-Jones/WCA, cut-off dipoles, direct gravity, Coulomb direct, \
                     Coulomb and dipoles by Ewald or P3M, springs, granular contacts and walls, \
                     applied, uniform and electric fields and damping do)",
                    names.join(", ")
                ))
            }
        };
        let b = &self.system.boundary;
        let extent = self
            .system
            .particles
            .position
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(b.wrap(*r)), hi.max(b.wrap(*r)))
            });
        let mut domain = crate::domain::Domain::new(comm, b, extent, reach, grid)?;
        // A resumed run's lists: one build for all (a decomposed run's
        // lists are built together), the first restored.
        let restored = self
            .forces
            .interactions
            .iter_mut()
            .filter_map(|i| i.take_restored_list())
            .next();
        self.system = domain.scatter(&self.system, restored, &mut self.forces.interactions);
        self.forces.domain = Some(domain);
        Ok(())
    }

    /// Checks that the checkpoint stores the particles in the order this
    /// build does: both in the scene's, or both in the same space order.
    pub fn check_order(&self, cp: &mote_io::checkpoint::Checkpoint) -> Result<(), String> {
        let number = &self.system.number;
        crate::order::check_saved_order(cp, number, "particles", "[granular] order")
    }

    /// Makes the freshly built system hold the particles a checkpoint's
    /// flow state names ([`crate::flow::Flow::restore`]), before its
    /// positions and velocities are put in; nothing without a flow.
    pub fn restore_flow(&mut self, cp: &mote_io::checkpoint::Checkpoint) -> Result<(), String> {
        let carried = cp.carried.iter().find(|(k, _)| k == FLOW_KEY);
        match (&mut self.flow, carried) {
            (Some(flow), Some((_, state))) => {
                flow.restore(state, &mut self.system, &mut self.forces)
            }
            (None, None) => Ok(()),
            (Some(_), None) => Err("the checkpoint has no flow state, and the scene inserts or removes particles".into()),
            (None, Some(_)) => Err("the checkpoint has a flow state, and the scene neither inserts nor removes particles".into()),
        }
    }

    /// The number of particles of the run, on every rank of a decomposed
    /// one.
    pub fn particle_count(&self) -> usize {
        self.forces
            .domain
            .as_ref()
            .map_or(self.system.particles.len(), |d| d.total())
    }

    /// max |E(t) − E(0)| / |E(0)| over the instants measured in the
    /// current run (|E(t) − E(0)| when E(0) = 0).
    pub fn max_energy_error(&self) -> f64 {
        self.energy_watch.map_or(0.0, |w| w.1)
    }
}

impl mote_run::Propagator for Simulation {
    type Sample = Observables;
    type Error = MdError;

    fn step(&self) -> u64 {
        self.system.step
    }

    fn time(&self) -> f64 {
        self.system.time
    }

    fn prime(&mut self, _progress: &mut dyn FnMut(&Self)) -> Result<(), MdError> {
        if self.brownian.is_none() {
            self.stepper.prime(&mut self.system, &mut self.forces);
        }
        self.energy_watch = None;
        // The run's timing starts with its first step.
        self.forces.timing = Default::default();
        self.stepping = std::time::Duration::ZERO;
        Ok(())
    }

    fn advance(&mut self) -> Result<(), MdError> {
        let since = std::time::Instant::now();
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
            let domain = self.forces.domain.as_ref();
            // The particles' ids, where particles come and go.
            let ids = std::mem::take(&mut self.system.id);
            let noise = crate::thermostat::Noise {
                seed: self.seed,
                step: self.system.step,
                ids: domain.map_or(&ids, |d| &d.halo().id),
                comm: domain.map(|d| d.comm()),
            };
            t.apply(&mut self.system, self.dt, &noise);
            self.system.id = ids;
        }
        if let Some(flow) = self
            .flow
            .as_mut()
            .filter(|f| self.system.step.is_multiple_of(f.every))
        {
            flow.apply(&mut self.system, &mut self.forces, self.seed);
        }
        self.stepping += since.elapsed();
        Ok(())
    }

    /// The particle with a non-finite position or velocity, by its id; in a
    /// decomposed run, the one of least id among those found on every rank
    /// (its id: its index in the undivided system).
    fn unstable(&self) -> Option<(usize, String)> {
        let p = &self.system.particles;
        let found = first_non_finite(&[&p.position, &p.velocity]).map(|(column, i)| {
            let what = ["a non-finite position", "a non-finite velocity"][column];
            (i, format!("{what} ({} / {})", p.position[i], p.velocity[i]))
        });
        let Some(domain) = &self.forces.domain else {
            // Named by its number (its index unless particles came and
            // went, or are stored in space order).
            return found.map(|(i, what)| (self.system.number_of(i) as usize, what));
        };
        let found = found.map(|(i, what)| (domain.halo().id[i] as usize, what));
        let least = -domain
            .comm()
            .max(found.as_ref().map_or(f64::NEG_INFINITY, |f| -(f.0 as f64)));
        if least == f64::INFINITY {
            return None;
        }
        let id = least as usize;
        let (_, what) = found.filter(|f| f.0 == id).unwrap_or_else(|| {
            (
                id,
                "a non-finite position or velocity (on another rank)".into(),
            )
        });
        Some((self.system.number_of_id(id as u64) as usize, what))
    }

    fn most(&self, x: f64) -> f64 {
        self.forces.domain.as_ref().map_or(x, |d| d.comm().max(x))
    }

    fn measure(&mut self) -> Observables {
        let obs = Observables::measure(&self.system, &mut self.forces);
        let e = obs.total_energy();
        let (e0, worst) = self.energy_watch.unwrap_or((e, 0.0));
        let err = if e0 != 0.0 {
            (e - e0).abs() / e0.abs()
        } else {
            (e - e0).abs()
        };
        self.energy_watch = Some((e0, worst.max(err)));
        obs
    }

    /// In a decomposed run, the whole system gathered at rank 0 in id
    /// order (`None` on the other ranks, which must call it alike).
    fn frame(&self) -> Option<mote_io::xyz::Frame> {
        match &self.forces.domain {
            Some(domain) => domain
                .gather(&self.system)
                .map(|whole| crate::output::frame_of(&whole)),
            None => Some(crate::output::frame_of(&self.system)),
        }
    }

    /// F = m a from the accelerations leap-frog carries (the integrators
    /// that carry none give none).
    fn forces(&self) -> Vec<[f64; 3]> {
        let sys = &self.system;
        if self.forces.domain.is_some() {
            // A rank's own, not the frame's (the live viewer, which reads
            // them, does not run decomposed).
            return Vec::new();
        }
        let forces: Vec<[f64; 3]> = (sys.carried_acceleration.iter())
            .zip(&sys.particles.mass)
            .map(|(a, m)| (*a * *m).to_array())
            .collect();
        // In the frame's order: the scene's.
        match sys.rows_by_number() {
            Some(rows) => crate::order::gathered(&forces, &rows),
            None => forces,
        }
    }

    fn walls(&self) -> Vec<mote_run::WallGeometry> {
        let t = self.system.time;
        self.forces
            .interactions
            .iter()
            .filter_map(|i| i.viewer())
            .flat_map(|v| v.walls(t))
            .collect()
    }

    /// Δt and the temperature are the simulation's; fields and damping go to
    /// the interaction that owns them.
    fn change(&mut self, change: &mote_run::Change) -> Result<String, String> {
        use mote_run::Change;
        match change {
            Change::Dt(dt) => {
                let text = format!("dt {} → {dt}", self.dt);
                self.dt = *dt;
                Ok(text)
            }
            Change::Temperature(kt) => {
                let old = if let Some(bd) = &mut self.brownian {
                    std::mem::replace(&mut bd.kt, *kt)
                } else {
                    match &mut self.thermostat {
                        Some(
                            Thermostat::Langevin { kt: t, .. } | Thermostat::Bussi { kt: t, .. },
                        ) => std::mem::replace(t, *kt),
                        None => {
                            return Err(
                                "the temperature: the run has no thermostat (constant energy)"
                                    .into(),
                            )
                        }
                    }
                };
                Ok(format!("temperature kT {old} → {kt}"))
            }
            other => self
                .forces
                .interactions
                .iter_mut()
                .find_map(|i| i.viewer_mut().and_then(|v| v.steer(other)))
                .unwrap_or_else(|| Err(format!("{}: the scene has none", other.what()))),
        }
    }

    /// Positions, velocities, the accelerations leap-frog carries (and the
    /// angular ones with ω when the particles turn), and what each
    /// interaction carries (contact histories, lists) under its name.
    fn save(&mut self, cp: &mut mote_io::checkpoint::Checkpoint) -> Result<(), MdError> {
        if let Some(domain) = &self.forces.domain {
            // The whole state at rank 0, in one process's form: a run
            // resumes from it on any number of ranks, or on one process.
            let whole = domain.gather(&self.system);
            let lists = domain.carried_state();
            // Every rank's rows of what the interactions carry per
            // particle, at rank 0 in one process's order.
            let rows: Vec<Option<Vec<f64>>> = self
                .forces
                .interactions
                .iter()
                .map(|i| {
                    let mine = i.carried_rows(&domain.halo().id)?;
                    let all = domain.comm().gather(&mine.rows);
                    let mut rows: Vec<&[f64]> =
                        all.iter().flat_map(|r| r.chunks(mine.width)).collect();
                    rows.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
                    Some(
                        mine.head
                            .iter()
                            .chain(rows.into_iter().flatten())
                            .copied()
                            .collect(),
                    )
                })
                .collect();
            let Some(whole) = whole else {
                return Ok(());
            };
            let keys = self.forces.carried_keys();
            let carried: Vec<(String, Vec<f64>)> = keys
                .into_iter()
                .zip(&self.forces.interactions)
                .zip(rows)
                .map(|((key, i), rows)| match (rows, i.halo_reach()) {
                    (Some(rows), _) => (key, rows),
                    (None, Some(r)) if r != crate::force::HaloReach::NONE => {
                        (key, lists.clone().unwrap_or_default())
                    }
                    _ => (key, i.carried_state()),
                })
                .filter(|(_, v)| !v.is_empty())
                .collect();
            write_state(&whole, carried, cp);
            return Ok(());
        }
        let sys = &self.system;
        let keys = self.forces.carried_keys();
        let mut carried: Vec<(String, Vec<f64>)> = keys
            .into_iter()
            .zip(&self.forces.interactions)
            .map(|(key, i)| (key, i.carried_state()))
            .filter(|(_, v)| !v.is_empty())
            .collect();
        if let Some(flow) = &self.flow {
            carried.push((FLOW_KEY.to_string(), flow.carried_state(sys)));
        }
        write_state(sys, carried, cp);
        Ok(())
    }
}

/// The key under which a checkpoint carries the flow's state
/// ([`crate::flow::Flow::carried_state`]) beside the interactions'.
pub const FLOW_KEY: &str = "flow";

/// The checkpoint's key of the particles' scene numbers, by id, where they
/// are stored in space order ([`crate::particles::System::number`]).
pub const ORDER_KEY: &str = "order";

/// Puts `sys` and what its interactions carry into `cp`: positions,
/// velocities, the accelerations leap-frog carries (and the angular ones
/// with ω when the particles turn).
fn write_state(
    sys: &System,
    carried: Vec<(String, Vec<f64>)>,
    cp: &mut mote_io::checkpoint::Checkpoint,
) {
    let p = &sys.particles;
    cp.angular = p
        .angular_velocity
        .iter()
        .zip(&sys.carried_angular_acceleration)
        .map(|(w, a)| [w.x, w.y, w.z, a.x, a.y, a.z])
        .collect();
    cp.carried = carried;
    if !sys.number.is_empty() {
        let number = sys.number.iter().map(|&k| k as f64).collect();
        cp.carried.push((ORDER_KEY.to_string(), number));
    }
    cp.time = sys.time;
    cp.step = sys.step;
    cp.positions = p.position.iter().map(|r| r.to_array()).collect();
    cp.velocities = p.velocity.iter().map(|v| v.to_array()).collect();
    cp.accelerations = sys
        .carried_acceleration
        .iter()
        .map(|a| a.to_array())
        .collect();
}

/// The first (column, particle) whose vector is not finite. A branch-free
/// pass first (x·0 is 0 for finite x and NaN otherwise, so the sum is NaN
/// exactly when some component is not finite), the search only then: the
/// check costs one streaming read per step.
pub(crate) fn first_non_finite(columns: &[&[DVec3]]) -> Option<(usize, usize)> {
    let poisoned = columns
        .iter()
        .flat_map(|c| c.iter())
        .fold(DVec3::ZERO, |acc, v| acc + *v * 0.0);
    if poisoned.is_finite() {
        return None;
    }
    columns
        .iter()
        .enumerate()
        .find_map(|(k, c)| c.iter().position(|v| !v.is_finite()).map(|i| (k, i)))
}

impl From<mote_run::Stopped> for MdError {
    fn from(s: mote_run::Stopped) -> Self {
        match s {
            mote_run::Stopped::Unstable {
                step,
                time,
                particle,
                what,
            } => MdError::Unstable {
                step,
                time,
                particle,
                what,
            },
            mote_run::Stopped::Interrupted { signal, step, time } => {
                MdError::Interrupted { signal, step, time }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_non_finite_component_of_any_column() {
        let a = vec![DVec3::ONE; 5];
        let mut b = vec![DVec3::splat(1e308); 5];
        assert_eq!(first_non_finite(&[&a, &b]), None);
        b[3].y = f64::NAN;
        b[4].z = f64::INFINITY;
        assert_eq!(first_non_finite(&[&a, &b]), Some((1, 3)));
        let mut c = a.clone();
        c[2].x = f64::NEG_INFINITY;
        assert_eq!(first_non_finite(&[&c, &b]), Some((0, 2)));
    }
}
