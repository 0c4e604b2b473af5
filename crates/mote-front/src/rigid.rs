//! Rigid clumps of spheres moved by the FRBI (`mote_md::rigid::scene`) in
//! the one run: the scene built with the options' time step and length,
//! the engine's table and the applications' (the toning nip's nip.csv,
//! mote-nip) added to it, the summary written.

use mote_io::checkpoint::Checkpoint;
use mote_io::trajectory::Format;
use mote_md::rigid::run::{RigidCsv, RigidDynamics};
use mote_md::rigid::scene::RigidScene;
use mote_md::MdError;
use mote_run::{Observer, Propagator, Report};

use crate::checkpoints::restore;
use crate::error::FrontError;
use crate::runner::{run_engine, Done, EngineRun, RunFiles, SampleOf};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    run_with(input, options, None, monitor)
}

/// Continues the rigid run a checkpoint came from, appending to its files.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let (input, options) = restore(cp, given)?;
    run_with(&input, &options, Some(cp), monitor)
}

fn run_with(
    input: &Input,
    options: &RunOptions,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    options.refuse(
        "rigid bodies",
        &[
            (
                options.solver.is_some(),
                "--solver",
                "rigid bodies are moved by the FRBI only",
            ),
            (options.system.is_some(), "--system", crate::WHY_NO_SYSTEM),
        ],
    )?;
    let mut scene = RigidScene::parse(&input.text, &input.label)?;
    scene
        .run
        .with_options(options.dt, options.steps, options.until);
    let format = options.trajectory_format(
        scene
            .output
            .trajectory_format(mote_io::Source::new(&input.label, &input.text))?,
    )?;
    let engine = RigidRun {
        scene,
        input: input.clone(),
        options: options.clone(),
        format,
        nip: None,
        walls: Vec::new(),
        pressure: false,
        without_virial: Vec::new(),
        dt: 0.0,
        last_step: 0,
    };
    run_engine(engine, input, options, resumed, monitor)
}

/// A rigid scene's part of the one run.
struct RigidRun {
    scene: RigidScene,
    input: Input,
    options: RunOptions,
    format: Format,
    /// The toning nip's probe and its schedule, where the scene has one.
    nip: Option<(mote_nip::NipProbe, u64)>,
    /// The names of the walls, for the table's force columns.
    walls: Vec<String>,
    /// Whether the table has the pressure (a periodic box, every
    /// interaction with a virial).
    pressure: bool,
    /// In a periodic box, the interactions without a virial.
    without_virial: Vec<String>,
    dt: f64,
    last_step: u64,
}

impl EngineRun for RigidRun {
    type State = RigidDynamics;
    const ENGINE: Engine = Engine::Rigid;
    const NAME: &'static str = "rigid";

    fn scene_seed(&self) -> Option<u64> {
        self.scene.seed
    }

    fn scene_dir(&self) -> Option<&String> {
        self.scene.output.dir.as_ref()
    }

    /// The scene built with the options' seed, time step and length.
    fn build(
        &mut self,
        seed: u64,
        resumed: Option<&Checkpoint>,
    ) -> Result<RigidDynamics, FrontError> {
        let (text, label) = (&self.input.text, &self.input.label);
        let options = &self.options;
        if let Some(cp) = resumed {
            self.scene.keep_order_of(cp);
        }
        let built = self.scene.build(text, label, Some(seed))?;
        self.nip = mote_nip::probe(&self.scene, text, label)?;
        if resumed.is_none() {
            mote_run::check_run_length(built.steps, built.dt, options.force)
                .map_err(|m| MdError::Length(format!("{label}: {m}")))?;
        }
        self.walls = built
            .contacts()
            .map(|c| c.walls.iter().map(|w| w.name.clone()).collect())
            .unwrap_or_default();
        (self.dt, self.last_step) = (built.dt, built.steps);
        let mut dynamics = RigidDynamics::new(built);
        if let Some(cp) = resumed {
            dynamics.resume(cp, label)?;
        }
        if dynamics.pressure_volume().is_some() {
            self.without_virial = dynamics.without_virial();
            self.pressure = self.without_virial.is_empty();
        }
        Ok(dynamics)
    }

    fn observers(
        &self,
        d: &RigidDynamics,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<RigidDynamics>>>, FrontError> {
        let mut observers: Vec<Box<dyn Observer<RigidDynamics>>> =
            vec![Box::new(RigidCsv::create(
                &files.dir.join("observables.csv"),
                &files.provenance,
                &self.walls,
                self.scene.output.observables_every().max(1),
                self.pressure,
                d.flow.as_ref(),
                files.append,
            )?)];
        if let Some(flow) = d.flow.as_ref().filter(|f| !f.outlets.is_empty()) {
            observers.push(Box::new(mote_md::output::OutflowCsv::create(
                &files.dir.join("outflow.csv"),
                &files.provenance,
                mote_md::UnitSystem::Si,
                &flow.outlets,
                flow.every,
                files.append,
            )?));
        }
        if let Some((probe, every)) = &self.nip {
            observers.push(Box::new(mote_nip::NipCsv::create(
                &files.dir.join("nip.csv"),
                &files.provenance,
                probe.clone(),
                *every,
                files.append,
            )?));
        }
        Ok(observers)
    }

    fn trajectory(&self) -> Result<Option<(String, Format, u64)>, FrontError> {
        Ok(crate::runner::scene_trajectory(
            self.scene.output.trajectory_every(),
            self.format,
        ))
    }

    fn checkpoint_options(&self, _: &RigidDynamics) -> Vec<(String, String)> {
        Vec::new()
    }

    fn last_step(&self, _: &RigidDynamics) -> u64 {
        self.last_step
    }

    fn opening(&self, _: &RigidDynamics) -> String {
        format!(
            "rigid clumps (FRBI) with dt = {}, {} steps",
            mote_io::system::human_number(self.dt),
            self.last_step
        )
    }

    fn ending(&self, _: &mut Self::State, e: MdError) -> Result<Ending, FrontError> {
        md_ending(e)
    }

    fn summary(
        &self,
        d: &RigidDynamics,
        report: &Report<SampleOf<Self>>,
        done: &Done,
    ) -> Result<Vec<String>, FrontError> {
        let b = &d.bodies;
        let last = &report.last;
        let mut summary = vec![format!(
            "mote run {}: {} rigid bodies ({} spheres), FRBI with dt = {}, {} steps to t = {:.6e} in {:.3} s of wall time, {}. \
             Final kinetic energy {:.6e}, potential {:.6e}; momentum {}, angular momentum {}. {}",
            done.input.label,
            b.len(),
            (0..b.len()).map(|i| b.template(i).sphere_count()).sum::<usize>(),
            mote_io::system::human_number(self.dt),
            self.last_step,
            d.time(),
            report.wall.as_secs_f64(),
            crate::seed_phrase(done.seed, done.chosen),
            last.kinetic_energy(),
            last.potential_energy,
            vector(last.linear_momentum),
            vector(last.angular_momentum),
            d.frbi.breakdown(d.stepping, report.wall).sentence(),
        )];
        for (name, f) in &last.wall_forces {
            summary.push(format!("  force on wall {name}: {f}"));
        }
        summary.extend(d.frbi.descriptions());
        if let Some(flow) = &d.flow {
            summary.push(flow.summary(b.len()));
        }
        if self.pressure {
            summary.push(format!(
                "Pressure {:.6e} at the end (molecular virial: the bodies' centres, as LAMMPS's fix rigid).",
                last.pressure
            ));
        } else if !self.without_virial.is_empty() {
            summary.push(crate::no_pressure_column(&self.without_virial));
        }
        summary.push(format!("Output: {}", report.files.join(", ")));
        Ok(summary)
    }
}

/// How a time-stepped run that stopped with `e` ended: unstable or
/// interrupted (its files kept), or an error.
pub(crate) fn md_ending(e: MdError) -> Result<Ending, FrontError> {
    match e {
        e @ MdError::Unstable { .. } => Ok(Ending::Unstable(e.to_string())),
        e @ MdError::Interrupted { signal, .. } => Ok(Ending::Interrupted {
            signal,
            message: e.to_string(),
        }),
        e => Err(e.into()),
    }
}

/// `[x, y, z]` with each component as [`mote_io::system::human_number`]
/// writes it (`6.4e-32`, not 32 zeros and the digits).
fn vector(v: glam::DVec3) -> String {
    let n = mote_io::system::human_number;
    format!("[{}, {}, {}]", n(v.x), n(v.y), n(v.z))
}
