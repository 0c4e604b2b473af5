//! Event-driven hard spheres and disks (`mote_edmd::run::EventDriven`)
//! in the one run.

use std::path::PathBuf;

use mote_edmd::run::EventDriven;
use mote_edmd::Scene;
use mote_io::checkpoint::Checkpoint;
use mote_io::trajectory::Format;
use mote_run::{Observer, Report};

use crate::checkpoints::{hex, unhex};
use crate::error::{refuse, FrontError};
use crate::runner::{run_engine, Done, EngineRun, RunFiles, SampleOf};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

/// The words of the old `mote edmd` command, kept as an alias for one
/// release: `--time` is the measured time after `equilibrate` (where
/// `--until` is the end time), and `--no-output` writes no files.
#[derive(Debug, Clone, Default)]
pub struct EdmdWords {
    pub time: Option<f64>,
    pub no_output: bool,
}

pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    run_with(input, options, &EdmdWords::default(), monitor)
}

/// Continues the event-driven run a checkpoint came from, appending to its
/// files: the same scene, seed, end time, output folder and checkpoint
/// schedule.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let get = |k: &str| cp.option(k).map(str::to_string);
    let input = Input {
        name: get("name").unwrap_or_else(|| "run".into()),
        label: cp.input_label.clone(),
        text: cp.input_text.clone(),
        plist: false,
    };
    let options = RunOptions {
        resume: given.resume.clone(),
        checkpoint_every: get("checkpoint-every").and_then(|v| v.parse().ok()),
        output: given
            .output
            .clone()
            .or_else(|| get("output").map(PathBuf::from)),
        picture: given.picture.clone(),
        trajectory_format: get("trajectory-format"),
        seed: Some(cp.seed),
        threads: given.threads,
        ..RunOptions::default()
    };
    // The measured time, bit for bit (not recomputed from an end time).
    let words = EdmdWords {
        time: get("time").map(|v| unhex(&v)).transpose()?,
        no_output: false,
    };
    run_events(&input, &options, &words, Some(cp), monitor)
}

/// Runs an event-driven scene; `words` are the old command's options.
pub fn run_with(
    input: &Input,
    options: &RunOptions,
    words: &EdmdWords,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let engine = input.engine()?;
    if engine != Engine::EventDriven {
        refuse!(
            "{}: a scene of {}, not of hard spheres (no [event_driven] table): run it with `mote run`",
            input.label,
            engine.title()
        );
    }
    run_events(input, options, words, None, monitor)
}

fn run_events(
    input: &Input,
    options: &RunOptions,
    words: &EdmdWords,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    const WHY_NO_STEP: &str =
        "event-driven dynamics jumps from collision to collision, with no time step";
    options.refuse(
        "event-driven hard spheres",
        &[
            (options.dt.is_some(), "--dt", WHY_NO_STEP),
            (options.steps.is_some(), "--steps", WHY_NO_STEP),
            (options.solver.is_some(), "--solver", crate::WHY_NO_SOLVER),
            (options.system.is_some(), "--system", crate::WHY_NO_SYSTEM),
        ],
    )?;
    let mut scene = Scene::parse(&input.text, &input.label)?;
    if let Some(t) = options.until {
        if !(t.is_finite() && t > scene.equilibrate) {
            refuse!(
                "--until {t}: must be a time after the scene's equilibration ({})",
                scene.equilibrate
            );
        }
        scene.time = t - scene.equilibrate;
    }
    if let Some(t) = words.time {
        if !(t >= 0.0 && t.is_finite()) {
            refuse!("--time {t}: must be a non-negative number");
        }
        scene.time = t;
    }
    if let (Some(t), Some(_)) = (&scene.trajectory, &options.trajectory_format) {
        // The file keeps its name; the extension says the format.
        let format = options.trajectory_format(mote_io::trajectory::Format::Xyz)?;
        let renamed = std::path::Path::new(t).with_extension(format.extension());
        scene.trajectory = Some(renamed.to_string_lossy().into_owned());
    }
    if words.no_output {
        scene.trajectory = None;
        scene.observables = None;
        scene.histogram = None;
    }
    let scene_dir = input.folder();
    match scene.spheres.dimension {
        2 => run_engine(
            EventRun::<2>::new(scene, scene_dir, words, options, input),
            input,
            options,
            resumed,
            monitor,
        ),
        _ => run_engine(
            EventRun::<3>::new(scene, scene_dir, words, options, input),
            input,
            options,
            resumed,
            monitor,
        ),
    }
}

/// An event-driven scene's part of the one run.
struct EventRun<const D: usize> {
    scene: Scene,
    /// The folder the scene's own relative paths resolve against.
    scene_dir: PathBuf,
    no_output: bool,
    force: bool,
    label: String,
}

impl<const D: usize> EventRun<D> {
    fn new(
        scene: Scene,
        scene_dir: PathBuf,
        words: &EdmdWords,
        options: &RunOptions,
        input: &Input,
    ) -> Self {
        EventRun {
            scene,
            scene_dir,
            no_output: words.no_output,
            force: options.force,
            label: input.label.clone(),
        }
    }
}

impl<const D: usize> EngineRun for EventRun<D> {
    type State = EventDriven<D>;
    const ENGINE: Engine = Engine::EventDriven;
    const NAME: &'static str = "event-driven";

    fn scene_seed(&self) -> Option<u64> {
        self.scene.seed
    }

    fn scene_dir(&self) -> Option<&String> {
        self.scene.output.dir.as_ref()
    }

    fn build(
        &mut self,
        seed: u64,
        resumed: Option<&Checkpoint>,
    ) -> Result<Self::State, FrontError> {
        Ok(match resumed {
            Some(cp) => EventDriven::resume(&self.scene, seed, &self.scene_dir, cp)?,
            None => EventDriven::new(&self.scene, seed, &self.scene_dir, self.force)?,
        })
    }

    fn writes_files(&self) -> bool {
        !self.no_output
    }

    fn observers(
        &self,
        _: &Self::State,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<Self::State>>>, FrontError> {
        Ok(mote_edmd::run::file_observers(
            &self.scene,
            &files.dir,
            &files.provenance,
            files.append,
        )?)
    }

    fn trajectory(&self) -> Result<Option<(String, Format, u64)>, FrontError> {
        // A frame every output interval (the propagator's step).
        Ok(self
            .scene
            .trajectory
            .as_ref()
            .map(|t| (t.clone(), mote_edmd::run::trajectory_format(t), 1)))
    }

    fn checkpoint_options(&self, _: &Self::State) -> Vec<(String, String)> {
        // The measured time, so a resumed run ends where this one would.
        vec![("time".into(), hex(self.scene.time))]
    }

    fn last_step(&self, state: &Self::State) -> u64 {
        state.last_step()
    }

    fn opening(&self, _: &Self::State) -> String {
        format!(
            "event-driven hard {}, simulated time {} after {} of equilibration",
            if D == 2 { "disks" } else { "spheres" },
            self.scene.time,
            self.scene.equilibrate,
        )
    }

    fn progress(&self, state: &Self::State, _: u64, monitor: &mut dyn Monitor) {
        // Thousandths of the simulated time, equilibration included.
        let total = (self.scene.equilibrate + self.scene.time).max(1e-300);
        let f = (state.now() / total).clamp(0.0, 1.0);
        monitor.progress((f * 1000.0) as u64, 1000, "");
    }

    fn ending(&self, _: &mut Self::State, e: mote_edmd::EdmdError) -> Result<Ending, FrontError> {
        match e {
            mote_edmd::EdmdError::Interrupted { signal, .. } => Ok(Ending::Interrupted {
                signal,
                message: e.to_string(),
            }),
            // refused before it started, at a line of the scene
            e @ mote_edmd::EdmdError::Scene { .. } => Err(e.into()),
            e => Err(FrontError::request(format!(
                "{}: run stopped: {e}",
                self.label
            ))),
        }
    }

    fn summary(
        &self,
        state: &Self::State,
        report: &Report<SampleOf<Self>>,
        done: &Done,
    ) -> Result<Vec<String>, FrontError> {
        let r = mote_edmd::run::summarise(
            state,
            &self.scene,
            done.seed,
            &done.files.dir,
            &done.files.provenance,
            report.wall.as_secs_f64(),
        )?;
        Ok(summary(&r, &self.scene, done.cpu))
    }
}

/// The paragraph that ends an event-driven run, then the final speeds of
/// small systems (Newton's cradles) and the files written.
fn summary(r: &mote_edmd::Run, scene: &Scene, cpu: f64) -> Vec<String> {
    let rate = if cpu > 0.05 {
        format!("{:.3e}", r.collisions as f64 / cpu)
    } else {
        "(too short to time)".to_string()
    };
    let mut s = format!(
        "{} {} (packing fraction {:.4}, seed {}): simulated t = {} after {} of equilibration with {} pair collisions and {} wall collisions \
         ({} events in all) in {:.3} s CPU / {:.3} s wall, {} collisions per CPU-second. ",
        r.n,
        if r.dimension == 2 { "disks" } else { "spheres" },
        r.packing_fraction,
        r.seed,
        r.simulated_time,
        scene.equilibrate,
        r.collisions,
        r.wall_hits,
        r.events,
        cpu,
        r.wall_seconds,
        rate
    );
    if r.z.is_finite() {
        s += &format!(
            "Compressibility factor Z = {:.4} ({} {:.4}, {:+.2} %). ",
            r.z,
            if r.dimension == 2 {
                "Henderson"
            } else {
                "Carnahan-Starling"
            },
            r.z_reference,
            100.0 * (r.z - r.z_reference) / r.z_reference
        );
    }
    if r.wall_pressure.is_finite() {
        s += &format!("Wall pressure {:.4e}. ", r.wall_pressure);
    }
    if r.collisions > 0 {
        s += &format!(
            "Collision rate {:.4} per particle per unit time (mean free time {:.4e}). ",
            r.collision_rate, r.mean_free_time
        );
    }
    s += &format!(
        "kT = {:.6}; energy drift {:.1e}",
        r.temperature, r.energy_drift
    );
    if r.momentum_drift.is_finite() {
        s += &format!(", momentum drift {:.1e}", r.momentum_drift);
    }
    s += &format!(
        "; speeds vs Maxwell-Boltzmann: KS D = {:.4}, p = {:.3}.",
        r.ks.0, r.ks.1
    );
    let mut lines = vec![s];
    if r.n <= 10 {
        let v: Vec<String> = r.speeds.iter().map(|x| format!("{x:.12}")).collect();
        lines.push(format!("final speeds: {}", v.join(" ")));
        if !r.final_velocities.is_empty() {
            let v: Vec<String> = r
                .final_velocities
                .iter()
                .map(|v| format!("{:+.12}", v[0]))
                .collect();
            lines.push(format!("final x-velocities: {}", v.join(" ")));
        }
    }
    for p in &r.outputs {
        lines.push(format!("wrote {}", p.display()));
    }
    lines
}
