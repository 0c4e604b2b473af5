//! A rigid scene's run (clumps of overlapping spheres moved by the FRBI),
//! stepped from outside (Python's `RigidSimulation`), with its bodies'
//! arrays open to reading and writing.

use glam::DVec3;
use mote_io::checkpoint::Checkpoint;
use mote_io::xyz::Frame;
use mote_md::rigid::run::{sphere_frame, RigidDynamics};
use mote_md::rigid::scene::RigidScene;
use mote_run::Propagator;

use super::Stepper;
use crate::error::FrontError;
use crate::Engine;

/// The run of a rigid scene.
pub struct Rigid {
    stepper: Stepper<RigidDynamics>,
    label: String,
    /// The scene text and seed, for checkpoints.
    text: String,
    seed: u64,
    /// Whether the run measures the pressure (`mote run`'s column): a box
    /// periodic on every axis and a virial from every interaction.
    pressure: bool,
}

/// A per-body vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyVectors {
    /// The centre of mass.
    Position,
    Velocity,
    /// The angular velocity ω.
    Omega,
    /// The rotation vector r = n·tan(φ/2) of the body's placement.
    Rotation,
}

/// The observables of the bodies at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidObservables {
    pub time: f64,
    pub translational: f64,
    pub rotational: f64,
    pub potential: f64,
    pub momentum: DVec3,
    pub angular_momentum: DVec3,
    /// P = (Σ M V² + W)/3V, where the run measures it
    /// ([`Rigid::measures_pressure`]).
    pub pressure: Option<f64>,
}

impl Rigid {
    /// The run `mote run` makes of a rigid scene (text labelled `label`)
    /// with `seed` (the scene's when `None`).
    pub fn build(text: &str, label: &str, seed: Option<u64>) -> Result<Self, FrontError> {
        if Engine::read(label, text)? != Engine::Rigid {
            return Err(FrontError::request(format!(
                "{label}: not a rigid scene (no [rigid] table): use mote.Simulation or mote.run"
            )));
        }
        Self::build_scene(RigidScene::parse(text, label)?, text, label, seed)
    }

    /// The run of a parsed rigid scene.
    fn build_scene(
        scene: RigidScene,
        text: &str,
        label: &str,
        seed: Option<u64>,
    ) -> Result<Self, FrontError> {
        let built = scene.build(text, label, seed)?;
        if built.flow.is_some() {
            // The views are mote's arrays, which insertion reallocates.
            return Err(FrontError::request(format!(
                "{label}: bodies that come and go ([[insert]], [[outlet]]) change the arrays \
                 mote.RigidSimulation shows as views; run this scene with mote.run()"
            )));
        }
        let every = scene.output.observables_every().max(1);
        let seed = built.seed;
        let mut dynamics = RigidDynamics::new(built);
        let pressure = dynamics.pressure_volume().is_some() && dynamics.without_virial().is_empty();
        Ok(Rigid {
            stepper: Stepper::new(dynamics, every),
            label: label.into(),
            text: text.into(),
            seed,
            pressure,
        })
    }

    /// The run a checkpoint of a rigid run holds: bodies, spins and contact
    /// histories, ready to go on bit for bit.
    pub fn resume(cp: &Checkpoint, path: &str) -> Result<Self, FrontError> {
        if cp.option("engine") != Some("rigid") {
            return Err(FrontError::request(format!(
                "{path}: not a checkpoint of a rigid run"
            )));
        }
        let (text, label) = (&cp.input_text, &cp.input_label);
        // A checkpoint written before bodies were stored in space order
        // resumes in the scene's.
        let mut scene = RigidScene::parse(text, label)?;
        scene.keep_order_of(cp);
        let mut run = Self::build_scene(scene, text, label, Some(cp.seed))?;
        let state = &mut run.stepper.state;
        if let Some(dt) = cp.option("dt").and_then(mote_io::checkpoint::unhex) {
            state.dt = dt;
        }
        state.resume(cp, &cp.input_label)?;
        // The checkpoint's run already measured its start.
        run.stepper.mark_started();
        Ok(run)
    }

    /// A checkpoint of now, which [`Rigid::resume`] continues bit for bit.
    pub fn checkpoint(&mut self) -> Result<Checkpoint, FrontError> {
        self.stepper.prepare()?;
        let mut cp = Checkpoint {
            program: format!("mote {} (Python)", env!("CARGO_PKG_VERSION")),
            seed: self.seed,
            options: vec![
                ("engine".into(), "rigid".into()),
                ("name".into(), "python".into()),
                ("output".into(), ".".into()),
            ],
            input_label: self.label.clone(),
            input_text: self.text.clone(),
            ..Default::default()
        };
        self.stepper.state.save(&mut cp)?;
        Ok(cp)
    }

    fn dynamics(&self) -> &RigidDynamics {
        &self.stepper.state
    }

    /// Advances `n` steps; `ends_run` samples the last as `mote run` does
    /// its last step; `progress(step, time)` every 16 steps.
    pub fn advance(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(u64, f64),
    ) -> Result<(), FrontError> {
        Ok(self.stepper.advance_every_16(n, ends_run, progress)?)
    }

    /// Whether the samples have the pressure: as `mote run`'s table, in a
    /// box periodic on every axis where every interaction gives a virial.
    pub fn measures_pressure(&self) -> bool {
        self.pressure
    }

    /// The steps from now to the scene's end.
    pub fn scene_steps(&self) -> u64 {
        let d = self.dynamics();
        d.last_step.saturating_sub(d.step)
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    pub fn time(&self) -> f64 {
        self.dynamics().bodies.time
    }

    pub fn dt(&self) -> f64 {
        self.dynamics().dt
    }

    pub fn set_dt(&mut self, dt: f64) {
        self.stepper.state.dt = dt;
    }

    /// Steps taken.
    pub fn step(&self) -> u64 {
        self.dynamics().step
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.dynamics().bodies.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Each body's scene number, in the order of the arrays: the bodies
    /// are stored in space order unless the scene says `[rigid] order =
    /// "file"` (then row i is body i).
    pub fn numbers(&self) -> Vec<u64> {
        let b = &self.dynamics().bodies;
        (0..b.len()).map(|i| b.number_of(i)).collect()
    }

    /// A per-body vector array; its memory stays where it is for the life
    /// of the run.
    pub fn vectors(&self, which: BodyVectors) -> &[DVec3] {
        let b = &self.dynamics().bodies;
        match which {
            BodyVectors::Position => &b.position,
            BodyVectors::Velocity => &b.velocity,
            BodyVectors::Omega => &b.omega,
            BodyVectors::Rotation => &b.rotation,
        }
    }

    /// The bodies' masses (their templates').
    pub fn masses(&self) -> Vec<f64> {
        let b = &self.dynamics().bodies;
        (0..b.len()).map(|i| b.template(i).mass()).collect()
    }

    /// The spheres in the world, with the body of each.
    pub fn spheres(&self) -> Frame {
        sphere_frame(&self.dynamics().bodies)
    }

    /// The observables measured so far.
    pub fn samples(&self) -> Vec<RigidObservables> {
        self.stepper
            .samples()
            .iter()
            .map(|o| RigidObservables {
                time: o.time,
                translational: o.translational_energy,
                rotational: o.rotational_energy,
                potential: o.potential_energy,
                momentum: o.linear_momentum,
                angular_momentum: o.angular_momentum,
                pressure: self.pressure.then_some(o.pressure),
            })
            .collect()
    }
}
