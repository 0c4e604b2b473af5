//! The one run: every time-stepped and event-driven scene goes through
//! [`run_engine`], which owns what a run needs besides its engine — the
//! seed, the output folder (claimed, marked, trimmed back to a resumed
//! checkpoint), the trajectory in every format, checkpoints and their
//! common options, the driver with the live viewer's tap, the opening
//! line and progress, the picture of the final state and how the run
//! ended. An engine brings what only it knows through [`EngineRun`]: its
//! propagator, its tables, what its checkpoints add, its summary.

use std::path::{Path, PathBuf};

use mote_io::checkpoint::Checkpoint;
use mote_io::trajectory::Format;
use mote_io::Provenance;
use mote_run::{Driver, Observer, Propagator, Report};

use crate::checkpoints::trim_outputs;
use crate::error::{self, FrontError};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

/// Where a run writes its files.
pub(crate) struct RunFiles {
    pub dir: PathBuf,
    pub provenance: Provenance,
    /// Continue the files of the run being resumed (trimmed back to its
    /// checkpoint), rather than start them.
    pub append: bool,
}

/// The sample of an engine's propagator.
pub(crate) type SampleOf<E> = <<E as EngineRun>::State as Propagator>::Sample;

/// What an engine brings to the one run.
pub(crate) trait EngineRun {
    /// What the driver steps.
    type State: Propagator + 'static;
    /// The engine, for the outcome.
    const ENGINE: Engine;
    /// The engine's name in its checkpoints (`engine = ...`).
    const NAME: &'static str;

    /// The scene's seed, if it names one.
    fn scene_seed(&self) -> Option<u64>;
    /// Whether the scene's seed was chosen for it (`mote pack` without
    /// `--seed` writes the seed it drew into the scene it runs), so the
    /// opening line says so.
    fn seed_chosen(&self) -> bool {
        false
    }
    /// The scene's `[output] dir`, if it names one.
    fn scene_dir(&self) -> Option<&String>;
    /// The propagator, ready to step: built from the scene with `seed`,
    /// or put in the state of the checkpoint `resumed`. Bad input is
    /// refused here, before the run touches the disk.
    fn build(&mut self, seed: u64, resumed: Option<&Checkpoint>)
        -> Result<Self::State, FrontError>;
    /// Refuses a run that cannot go into `dir` (files larger than its
    /// disk), checked before the folder is made.
    fn check_folder(&self, _state: &Self::State, _dir: &Path) -> Result<(), FrontError> {
        Ok(())
    }
    /// Whether the run writes files at all (a run that does not takes no
    /// folder).
    fn writes_files(&self) -> bool {
        true
    }
    /// The tables the engine writes as the run goes (observables.csv and
    /// the like); the trajectory is the run's ([`EngineRun::trajectory`]).
    fn observers(
        &self,
        state: &Self::State,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<Self::State>>>, FrontError>;
    /// The steps between the samples of each table [`EngineRun::observers`]
    /// writes: what the other ranks of a decomposed run follow.
    fn table_every(&self) -> Vec<u64> {
        Vec::new()
    }
    /// The trajectory's file name in the run folder, its format and the
    /// steps between frames; `None` writes none.
    fn trajectory(&self) -> Result<Option<(String, Format, u64)>, FrontError>;
    /// What this engine's checkpoints record beyond the run's common
    /// options (engine, name, schedule, folder, trajectory format).
    fn checkpoint_options(&self, state: &Self::State) -> Vec<(String, String)>;
    /// The step at which the run ends.
    fn last_step(&self, state: &Self::State) -> u64;
    /// What the opening line says after `mote run LABEL: ` (size, method,
    /// length), before the seed and threads.
    fn opening(&self, state: &Self::State) -> String;
    /// The opening line before the seed and threads: `mote run LABEL: `
    /// and [`EngineRun::opening`].
    fn headline(&self, label: &str, state: &Self::State) -> String {
        format!("mote run {label}: {}", self.opening(state))
    }
    /// Shows progress (called after every step and while priming).
    fn progress(&self, state: &Self::State, last_step: u64, monitor: &mut dyn Monitor) {
        let step = state.step();
        if step.is_multiple_of(16) || step == last_step {
            monitor.progress(step, last_step, &format!("t = {:.6e}", state.time()));
        }
    }
    /// How a run that stopped with `e` ended: unstable or interrupted
    /// (the files so far kept), or an error.
    fn ending(
        &self,
        state: &mut Self::State,
        e: <Self::State as Propagator>::Error,
    ) -> Result<Ending, FrontError>;
    /// How a run that reached its end ended (a packing a signal stopped
    /// says so here).
    fn ended(&self, _state: &Self::State) -> Ending {
        Ending::Finished
    }
    /// The lines that close a finished run.
    fn summary(
        &self,
        state: &Self::State,
        report: &Report<SampleOf<Self>>,
        done: &Done,
    ) -> Result<Vec<String>, FrontError>;
}

/// What the run knows at its end, for the summary.
pub(crate) struct Done<'a> {
    pub input: &'a Input,
    pub seed: u64,
    /// Whether the seed was chosen (the scene and options named none).
    pub chosen: bool,
    pub files: &'a RunFiles,
    /// CPU seconds of the process during the run.
    pub cpu: f64,
}

/// The trajectory a scene's `[output]` asks for: `trajectory.EXT` in
/// `format` every `every` steps, none where `every` is 0.
pub(crate) fn scene_trajectory(every: u64, format: Format) -> Option<(String, Format, u64)> {
    (every > 0).then(|| (format!("trajectory.{}", format.extension()), format, every))
}

/// The trajectory observer of `spec` (file name in the run folder,
/// format, steps between frames).
pub(crate) fn trajectory_observer(
    spec: &(String, Format, u64),
    files: &RunFiles,
) -> Result<mote_run::Trajectory, FrontError> {
    let (name, format, every) = spec;
    Ok(mote_run::Trajectory::create(
        &files.dir.join(name),
        *format,
        files.provenance.clone(),
        *every,
        files.append,
    )?)
}

/// The observers of an engine's run (its tables and trajectory).
type Observers<E> = Vec<Box<dyn Observer<<E as EngineRun>::State>>>;

/// Claims the run's folder (checked against the disk first, trimmed back
/// to a resumed checkpoint) and opens its tables and trajectory.
fn take_folder<E: EngineRun>(
    engine: &E,
    state: &E::State,
    input: &Input,
    options: &RunOptions,
    resumed: Option<&Checkpoint>,
    files: &RunFiles,
    trajectory: &Option<(String, Format, u64)>,
) -> Result<(Option<crate::lock::RunFolder>, Observers<E>), FrontError> {
    if resumed.is_none() && !options.force {
        engine.check_folder(state, &files.dir)?;
    }
    let folder = if engine.writes_files() || options.checkpoint_every.is_some() || resumed.is_some()
    {
        Some(crate::lock::RunFolder::claim(
            &files.dir,
            &input.label,
            &input.text,
            resumed.zip(options.resume.as_deref()),
        )?)
    } else {
        None
    };
    if let Some(cp) = resumed {
        trim_outputs(&files.dir, cp.step, cp.time)?;
    }
    let mut observers = engine.observers(state, files)?;
    if let Some(spec) = trajectory {
        observers.push(Box::new(trajectory_observer(spec, files)?));
    }
    Ok((folder, observers))
}

/// Runs `engine`'s scene, or continues it from `resumed`.
pub(crate) fn run_engine<E: EngineRun>(
    mut engine: E,
    input: &Input,
    options: &RunOptions,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    // On several ranks rank 0 alone takes the folder and writes; the
    // others follow its observers' schedule (their measurements and
    // frames are collective) and write nothing.
    let ranks = options.ranks.as_ref().filter(|r| r.0.size() > 1);
    let root = ranks.is_none_or(|r| r.is_root());
    let (mut seed, chosen) = crate::seed::resolve(options.seed, engine.scene_seed());
    if let Some(r) = ranks.filter(|_| chosen) {
        // A seed chosen from the clock is rank 0's on every rank (each
        // rank builds the whole scene from it), in two exact halves.
        let halves =
            r.0.broadcast(&[(seed >> 32) as f64, (seed & 0xFFFF_FFFF) as f64]);
        seed = ((halves[0] as u64) << 32) | halves[1] as u64;
    }
    let chosen = chosen || engine.seed_chosen();
    let dir = input.output_dir(options.output.as_ref(), engine.scene_dir());
    let mut state = engine.build(seed, resumed)?;
    let files = RunFiles {
        dir,
        provenance: crate::provenance(&input.label, seed),
        append: resumed.is_some(),
    };
    let trajectory = engine.trajectory()?;
    let mut driver = Driver::new();
    driver.sample_at_start = !files.append;
    driver.live = options.live.clone().take();
    let folder = if root {
        let setup = take_folder(
            &engine,
            &state,
            input,
            options,
            resumed,
            &files,
            &trajectory,
        );
        if let Some(r) = ranks {
            // Every rank learns whether rank 0 could start, so none waits
            // for it in a measurement it never takes.
            r.0.max(if setup.is_ok() { 0.0 } else { 1.0 });
        }
        let (folder, observers) = setup?;
        driver.observers = observers;
        folder
    } else {
        let failed = ranks.is_some_and(|r| r.0.max(0.0) > 0.0);
        if failed {
            error::refuse!("rank 0 could not start the run (its message says why)");
        }
        driver.observers = engine
            .table_every()
            .into_iter()
            .map(|every| mote_run::Follower {
                every,
                frames: false,
            })
            .chain(trajectory.iter().map(|t| mote_run::Follower {
                every: t.2,
                frames: true,
            }))
            .map(|f| Box::new(f) as Box<dyn Observer<E::State>>)
            .collect();
        None
    };
    if let Some(every) = options.checkpoint_every {
        let format = trajectory.as_ref().map_or(Format::Xyz, |t| t.1);
        let options = [
            ("engine", E::NAME.to_string()),
            ("name", input.name.clone()),
            ("plist", input.plist.to_string()),
            ("checkpoint-every", every.to_string()),
            ("output", files.dir.display().to_string()),
            ("trajectory-format", format.extension().to_string()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .chain(engine.checkpoint_options(&state))
        .chain(folder.iter().flat_map(|f| f.checkpoint_options()))
        .collect();
        driver.checkpoints = Some(mote_run::Checkpoints {
            writes: root,
            every: every.max(1),
            path: files.dir.join("checkpoint.mote"),
            template: Checkpoint {
                program: files.provenance.program.clone(),
                seed,
                options,
                input_label: input.label.clone(),
                input_text: input.text.clone(),
                ..Checkpoint::default()
            },
        });
    }
    let last_step = engine.last_step(&state);
    monitor.start(&format!(
        "{}, {}, {}",
        engine.headline(&input.label, &state),
        crate::seed_phrase(seed, chosen),
        crate::threads_phrase(),
    ));
    let cpu0 = crate::cpu::cpu_seconds();
    let result = driver.run(
        &mut state,
        |_| last_step,
        |s| engine.progress(s, last_step, monitor),
    );
    let cpu = crate::cpu::cpu_seconds() - cpu0;
    let mut outcome = Outcome {
        engine: E::ENGINE,
        seed,
        dir: files.dir.clone(),
        summary: Vec::new(),
        ending: Ending::Finished,
    };
    match result {
        Ok(report) => {
            let done = Done {
                input,
                seed,
                chosen,
                files: &files,
                cpu,
            };
            outcome.summary = engine.summary(&state, &report, &done)?;
            outcome.ending = engine.ended(&state);
            if let (Some(png), Some(frame)) = (&options.picture, state.frame()) {
                mote_render::frame::picture(&frame, png, 1920, 1080)?;
                outcome
                    .summary
                    .push(format!("Picture of the final state: {}.", png.display()));
            }
        }
        Err(e) => {
            outcome.ending = engine.ending(&mut state, e).map_err(|e| {
                // Every rank stops together on instability and signals;
                // what else ends a run is rank 0's alone.
                if ranks.is_some() {
                    FrontError::Stranded(Box::new(e))
                } else {
                    e
                }
            })?
        }
    }
    Ok(outcome)
}
