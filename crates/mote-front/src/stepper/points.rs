//! A time-stepped scene's run (point particles: gravity, springs,
//! Lennard-Jones, granular, dipoles, Brownian dynamics), stepped from
//! outside (Python's `Simulation`), with its particle arrays open to
//! reading and writing.

use glam::DVec3;
use mote_io::checkpoint::Checkpoint;
use mote_io::xyz::Frame;
use mote_md::scene::Scene;
use mote_md::Simulation;
use mote_run::Propagator;

use super::Stepper;
use crate::error::FrontError;
use crate::{Engine, Input};

/// The run of a time-stepped scene.
pub struct Points {
    stepper: Stepper<Simulation>,
    /// Scene label and text, kept for checkpoints and the scene's length.
    label: String,
    text: String,
    /// Positions after the last step, to see writes from outside (which
    /// make the carried accelerations stale).
    seen: Vec<DVec3>,
    /// The folder the run writes its files to, held while it lives.
    folder: Option<crate::lock::RunFolder>,
}

/// A per-particle vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vectors {
    Position,
    Velocity,
    AngularVelocity,
    Dipole,
}

/// A per-particle number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalars {
    Mass,
    Radius,
    Charge,
}

/// The observables of one instant, as Python's `Simulation.observables`
/// names them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointSample {
    pub time: f64,
    pub kinetic: f64,
    pub potential: f64,
    pub rotational: f64,
    pub kt: f64,
    pub pressure: f64,
    pub momentum: DVec3,
    pub angular_momentum: DVec3,
    pub magnetisation: DVec3,
}

impl Points {
    /// The run `mote run` makes of a time-stepped scene with `seed` (the
    /// scene's when `None`); other engines' scenes and particle files are
    /// refused with the way to run them. With `output`, the run takes that
    /// folder as `mote run` takes its own (locked and marked) and writes
    /// there what `mote run` writes as it goes: observables.csv and the
    /// trajectory on the scene's `[output]` schedules.
    pub fn build(
        input: &Input,
        seed: Option<u64>,
        output: Option<&std::path::Path>,
    ) -> Result<Self, FrontError> {
        if input.plist {
            return Err(FrontError::request(format!(
                "{}: an MPPphys particle file: run it with mote.run()",
                input.label
            )));
        }
        match input.engine()? {
            Engine::Particles => {}
            other => {
                return Err(FrontError::request(format!(
                    "{}: a {} scene: mote.Simulation steps time-stepped scenes; run this one with mote.run()",
                    input.label,
                    other.title()
                )))
            }
        }
        Self::from_text(&input.text, &input.label, seed, output)
    }

    fn from_text(
        text: &str,
        label: &str,
        seed: Option<u64>,
        output: Option<&std::path::Path>,
    ) -> Result<Self, FrontError> {
        Self::resuming(text, label, seed, output, None)
    }

    /// [`Points::from_text`], readied to resume `cp` where one is given.
    fn resuming(
        text: &str,
        label: &str,
        seed: Option<u64>,
        output: Option<&std::path::Path>,
        cp: Option<&Checkpoint>,
    ) -> Result<Self, FrontError> {
        let mut scene = Scene::parse(text, label)?;
        if let Some(cp) = cp {
            scene.keep_order_of(cp);
        }
        let (seed, _) = crate::seed::resolve(seed, scene.seed);
        let built = scene.build(text, label, seed)?;
        if built.simulation.flow.is_some() {
            // The views are mote's arrays, which insertion reallocates.
            return Err(FrontError::request(format!(
                "{label}: particles that come and go ([[insert]], [[outlet]]) change the arrays \
                 mote.Simulation shows as views; run this scene with mote.run()"
            )));
        }
        if built.simulation.dt <= 0.0 {
            return Err(FrontError::request(format!(
                "{label}: no time step ([run] dt)"
            )));
        }
        let mut stepper = Stepper::new(built.simulation, scene.output.observables_every());
        let folder = match output {
            None => None,
            Some(dir) => {
                let folder = crate::lock::RunFolder::claim(dir, label, text, None)?;
                let format = scene
                    .output
                    .trajectory_format(mote_io::Source::new(label, text))?;
                let files = crate::runner::RunFiles {
                    dir: dir.to_path_buf(),
                    provenance: crate::provenance(label, seed),
                    append: false,
                };
                let observers = crate::particles::table_observers(
                    &scene,
                    &stepper.state,
                    &built.probes,
                    &files,
                )?;
                for o in observers {
                    stepper.observe_with(o);
                }
                if let Some(spec) =
                    crate::runner::scene_trajectory(scene.output.trajectory_every(), format)
                {
                    stepper
                        .observe_with(Box::new(crate::runner::trajectory_observer(&spec, &files)?));
                }
                Some(folder)
            }
        };
        Ok(Points {
            stepper,
            label: label.to_string(),
            text: text.to_string(),
            seen: Vec::new(),
            folder,
        })
    }

    /// The folder the run writes to, if it writes files.
    pub fn output(&self) -> Option<&std::path::Path> {
        self.folder.as_ref().map(|f| f.dir.as_path())
    }

    /// The box: lower and upper corners and which axes are periodic
    /// (corners at ∓∞ on the axes of an open box).
    pub fn boundary(&self) -> (DVec3, DVec3, [bool; 3]) {
        let b = &self.sim().system.boundary;
        (b.lo, b.hi, b.periodic)
    }

    /// The run a checkpoint of a time-stepped run holds, ready to go on bit
    /// for bit.
    pub fn resume(cp: &Checkpoint, path: &str) -> Result<Self, FrontError> {
        if cp.option("engine").is_some_and(|e| e != "particles") {
            return Err(FrontError::request(format!(
                "{path}: a checkpoint of a {} run: resume it with mote.run(resume=...)",
                cp.option("engine").unwrap_or_default()
            )));
        }
        let mut run = Self::resuming(
            &cp.input_text,
            &cp.input_label,
            Some(cp.seed),
            None,
            Some(cp),
        )?;
        if let Some(dt) = cp.option("dt").and_then(mote_io::checkpoint::unhex) {
            run.sim_mut().dt = dt;
        }
        crate::resume_state(cp, run.sim_mut(), &cp.input_label)?;
        // The checkpoint's run already measured its start.
        run.stepper.mark_started();
        run.seen
            .clone_from(&run.stepper.state.system.particles.position);
        Ok(run)
    }

    /// A checkpoint of now, which [`Points::resume`] and `mote run
    /// --resume` continue bit for bit.
    pub fn checkpoint(&mut self) -> Result<Checkpoint, FrontError> {
        self.prepare()?;
        let mut cp = Checkpoint {
            program: format!("mote {} (Python)", env!("CARGO_PKG_VERSION")),
            seed: self.sim().seed,
            options: vec![
                ("name".into(), "python".into()),
                ("plist".into(), "false".into()),
                ("total-steps".into(), self.sim().system.step.to_string()),
                ("dt".into(), mote_io::checkpoint::hex(self.sim().dt)),
                ("output".into(), ".".into()),
            ],
            input_label: self.label.clone(),
            input_text: self.text.clone(),
            ..Checkpoint::default()
        };
        self.sim_mut().save(&mut cp)?;
        Ok(cp)
    }

    fn sim(&self) -> &Simulation {
        &self.stepper.state
    }

    fn sim_mut(&mut self) -> &mut Simulation {
        &mut self.stepper.state
    }

    /// Starts the run on the first call, and primes it again after its
    /// particles were moved from outside.
    fn prepare(&mut self) -> Result<(), FrontError> {
        if !self.seen.is_empty() && self.seen != self.sim().system.particles.position {
            let sys = &mut self.sim_mut().system;
            sys.carried_acceleration.clear();
            sys.carried_angular_acceleration.clear();
            // the first forces of the moved particles
            self.stepper.state.prime(&mut |_| {})?;
        }
        Ok(self.stepper.prepare()?)
    }

    /// Advances `n` steps; `ends_run` samples the last as `mote run` does
    /// its last step; `progress(step, time)` every 16 steps.
    pub fn advance(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(u64, f64),
    ) -> Result<(), FrontError> {
        self.prepare()?;
        let result = self.stepper.advance_every_16(n, ends_run, progress);
        self.seen
            .clone_from(&self.stepper.state.system.particles.position);
        Ok(result?)
    }

    /// The steps from now to the end the scene gives (`[run] steps` more,
    /// or to the first step at or past `until`), if it gives one.
    pub fn scene_steps(&self) -> Result<Option<u64>, FrontError> {
        let scene = Scene::parse(&self.text, &self.label)?;
        let src = mote_io::Source::new(&self.label, &self.text);
        let length = scene.run.length(src)?;
        let sys = &self.sim().system;
        length
            .map(|l| l.steps_from(sys.time, self.sim().dt))
            .transpose()
            .map_err(FrontError::request)
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    pub fn time(&self) -> f64 {
        self.sim().system.time
    }

    pub fn set_time(&mut self, t: f64) {
        self.sim_mut().system.time = t;
    }

    pub fn dt(&self) -> f64 {
        self.sim().dt
    }

    pub fn set_dt(&mut self, dt: f64) {
        self.sim_mut().dt = dt;
    }

    /// Steps taken.
    pub fn step(&self) -> u64 {
        self.sim().system.step
    }

    pub fn seed(&self) -> u64 {
        self.sim().seed
    }

    pub fn len(&self) -> usize {
        self.sim().system.particles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn species(&self) -> &[String] {
        &self.sim().system.species
    }

    /// The scene's number of each row (0 from the first): the rows' own
    /// order unless the particles are stored in space order.
    pub fn numbers(&self) -> Vec<u64> {
        let sys = &self.sim().system;
        (0..sys.particles.len()).map(|i| sys.number_of(i)).collect()
    }

    /// A per-particle vector array. Its memory stays where it is for the
    /// life of the run (a time-stepped system keeps its particles).
    pub fn vectors(&self, which: Vectors) -> &[DVec3] {
        let p = &self.sim().system.particles;
        match which {
            Vectors::Position => &p.position,
            Vectors::Velocity => &p.velocity,
            Vectors::AngularVelocity => &p.angular_velocity,
            Vectors::Dipole => &p.dipole,
        }
    }

    /// The same, to write into (the next step sees the writes).
    pub fn vectors_mut(&mut self, which: Vectors) -> &mut [DVec3] {
        let p = &mut self.sim_mut().system.particles;
        match which {
            Vectors::Position => &mut p.position,
            Vectors::Velocity => &mut p.velocity,
            Vectors::AngularVelocity => &mut p.angular_velocity,
            Vectors::Dipole => &mut p.dipole,
        }
    }

    /// A per-particle number array (memory as for [`Points::vectors`]).
    pub fn scalars(&self, which: Scalars) -> &[f64] {
        let p = &self.sim().system.particles;
        match which {
            Scalars::Mass => &p.mass,
            Scalars::Radius => &p.radius,
            Scalars::Charge => &p.charge,
        }
    }

    /// The particles now as a trajectory frame (pictures).
    pub fn frame(&self) -> Frame {
        mote_md::output::frame_of(&self.sim().system)
    }

    /// The observables measured so far.
    pub fn samples(&self) -> Vec<PointSample> {
        self.stepper
            .samples()
            .iter()
            .map(|o| PointSample {
                time: o.time,
                kinetic: o.kinetic,
                potential: o.potential,
                rotational: o.rotational,
                kt: o.kt,
                pressure: o.pressure,
                momentum: o.momentum,
                angular_momentum: o.angular_momentum,
                magnetisation: o.magnetisation,
            })
            .collect()
    }
}
