//! mote's one scene front: it reads what a run was given (scene file,
//! MPPphys particle file, `example:NAME`), picks the engine the scene
//! describes, applies the common run options to it, runs it and says what
//! happened. The binary `mote`, the Python API and the viewer all go
//! through [`run`]; they only parse their own arguments and report.
//!
//! Every common option either works for the scene's engine or is refused
//! with a message that says why ([`RunOptions`]); none is silently ignored.

mod checkpoints;
pub mod cpu;
pub mod engine;
pub mod error;
pub mod event_driven;
pub mod examples;
pub mod input;
pub mod lock;
pub mod packing;
mod particles;
mod rigid;
mod runner;
pub mod seed;
pub mod stepper;
pub mod terminal;

use std::path::PathBuf;

pub use engine::Engine;
pub use error::FrontError;
pub use input::Input;
pub use particles::resume_state;
pub use terminal::Terminal;

/// The options of `mote run`, common to every engine.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Scene file, particle file or `example:NAME` (absent with `resume`).
    pub input: Option<String>,
    /// Continue from this checkpoint.
    pub resume: Option<PathBuf>,
    /// Write a checkpoint every this many steps and at the end.
    pub checkpoint_every: Option<u64>,
    /// Run until this simulated time.
    pub until: Option<f64>,
    /// Run this many steps.
    pub steps: Option<u64>,
    /// Time step.
    pub dt: Option<f64>,
    /// Model of an MPPphys particle file: `nbody` or `springs` (default nbody).
    pub system: Option<String>,
    /// Integrator of a point-particle run.
    pub solver: Option<String>,
    /// Output folder.
    pub output: Option<PathBuf>,
    /// Ray-trace the final state into this PNG.
    pub picture: Option<PathBuf>,
    /// Trajectory format (`xyz`, `dump`, `gsd`, `vtk`), replacing the
    /// scene's `[output] trajectory_format`.
    pub trajectory_format: Option<String>,
    /// Seed (default: the scene's, else chosen and printed).
    pub seed: Option<u64>,
    /// Worker threads the caller asked for. The caller sets up the rayon
    /// pool; the opening line reports the pool's actual size.
    pub threads: Option<usize>,
    /// Run even where the run is longer than `mote_run::MAX_STEPS` steps.
    pub force: bool,
    /// The live viewer's tap (`mote view SCENE`): sees every step, hands
    /// back changes, may pause the run.
    pub live: mote_run::LiveSlot,
    /// The ranks of a run `mpirun` started on several (None: one process).
    pub ranks: Option<Ranks>,
}

/// The ranks of a decomposed run, seen from one of them.
#[derive(Clone)]
pub struct Ranks(pub std::sync::Arc<dyn mote_run::comm::Comm>);

impl Ranks {
    /// Whether this is rank 0, which writes the files and prints.
    pub fn is_root(&self) -> bool {
        self.0.rank() == 0
    }
}

impl std::fmt::Debug for Ranks {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "rank {} of {}", self.0.rank(), self.0.size())
    }
}

impl RunOptions {
    /// The trajectory format: `--trajectory-format` if given, else the
    /// scene's (`scene`).
    pub(crate) fn trajectory_format(
        &self,
        scene: mote_io::trajectory::Format,
    ) -> Result<mote_io::trajectory::Format, FrontError> {
        use mote_io::trajectory::Format;
        match &self.trajectory_format {
            None => Ok(scene),
            Some(f) => Format::named(f).ok_or_else(|| {
                FrontError::request(format!(
                    "--trajectory-format {f}: expected one of {}",
                    Format::NAMES
                ))
            }),
        }
    }

    /// Refuses the options an engine does not have, naming each and why.
    fn refuse(&self, engine: &str, refused: &[(bool, &str, &str)]) -> Result<(), FrontError> {
        let named: Vec<String> = refused
            .iter()
            .filter(|(given, _, _)| *given)
            .map(|(_, option, why)| format!("{option} ({why})"))
            .collect();
        if named.is_empty() {
            Ok(())
        } else {
            Err(FrontError::request(format!(
                "{}: option{} not available for {engine}: {}",
                self.input.as_deref().unwrap_or("the scene"),
                if named.len() == 1 { "" } else { "s" },
                named.join("; ")
            )))
        }
    }
}

impl RunOptions {
    /// Refuses values no engine can run: a time step or an end time that is
    /// not a positive finite number, zero steps between checkpoints.
    pub fn check_values(&self) -> Result<(), FrontError> {
        let input = self.input.as_deref().unwrap_or("the scene");
        for (option, value) in [("--dt", self.dt), ("--until", self.until)] {
            if let Some(v) = value {
                if !(v > 0.0 && v.is_finite()) {
                    error::refuse!("{input}: {option} {v}: must be a positive, finite number");
                }
            }
        }
        if self.checkpoint_every == Some(0) {
            error::refuse!("{input}: --checkpoint-every 0: must be at least 1 step");
        }
        if let Some(p) = &self.picture {
            check_picture_path(p)?;
        }
        Ok(())
    }
}

/// A picture is written as PNG: a path naming another format (`x.pdf`,
/// `x.jpg`) is refused before anything runs, not filled with PNG bytes.
pub fn check_picture_path(path: &std::path::Path) -> Result<(), FrontError> {
    let png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        error::refuse!(
            "{}: pictures are written as PNG: give a name ending in .png",
            path.display()
        );
    }
    Ok(())
}

/// The format of a packing or trajectory file named `path`, by its
/// extension; an extension that names no format mote writes is refused
/// (rather than written as extended XYZ under that name).
pub fn written_format(path: &std::path::Path) -> Result<mote_io::trajectory::Format, FrontError> {
    mote_io::trajectory::Format::of_path(path).ok_or_else(|| {
        FrontError::request(format!(
            "{}: the format follows the extension: .xyz (extended XYZ), .dump (LAMMPS), \
             .gsd (HOOMD) or .pvd/.vtp (VTK)",
            path.display()
        ))
    })
}

/// What a caller shows while a run goes: the opening line and progress.
pub trait Monitor {
    /// The line that opens a run: what it is, its size, its seed.
    fn start(&mut self, line: &str);
    /// `done` of `total` units (steps, or thousandths of the simulated
    /// time), with a short note such as the current time.
    fn progress(&mut self, done: u64, total: u64, note: &str);
    /// A line to show before the run opens (where a resumed run goes on).
    fn note(&mut self, _line: &str) {}
    /// The run has ended (successfully or not).
    fn finish(&mut self) {}
}

/// A monitor that shows nothing.
pub struct Silent;

impl Monitor for Silent {
    fn start(&mut self, _line: &str) {}
    fn progress(&mut self, _done: u64, _total: u64, _note: &str) {}
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// It ran to the end.
    Finished,
    /// It went unstable (a non-finite number); the message names the step
    /// and the particle, and the files written so far are kept.
    Unstable(String),
    /// A signal (SIGINT, SIGTERM) stopped it cleanly: files flushed, a
    /// final checkpoint written where checkpoints are on.
    Interrupted { signal: i32, message: String },
}

/// What a run did: the summary lines to print, where the files went, how
/// it ended.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub engine: Engine,
    pub seed: u64,
    pub dir: PathBuf,
    pub summary: Vec<String>,
    pub ending: Ending,
}

/// Runs what `options` describe with the engine its scene asks for.
pub fn run(options: &RunOptions, monitor: &mut dyn Monitor) -> Result<Outcome, FrontError> {
    check_ranks(options, None)?;
    if let Some(path) = &options.resume {
        // Checkpoints name their engine (point particles' older ones do not).
        let cp = mote_io::checkpoint::read(path)?;
        let engine = match cp.option("engine") {
            Some("rigid") => Engine::Rigid,
            Some("event-driven") => Engine::EventDriven,
            Some("packing") => Engine::Packing,
            _ => Engine::Particles,
        };
        check_ranks(options, Some(engine))?;
        let mut options = options.clone();
        let (dir, elsewhere) = lock::resume_folder(&cp, path);
        if elsewhere {
            monitor.note(&format!(
                "{}: continuing the run in its folder {}",
                path.display(),
                dir.display()
            ));
        }
        options.output = Some(dir);
        let options = &options;
        let result = match engine {
            Engine::Rigid => rigid::resume(&cp, options, monitor),
            Engine::EventDriven => event_driven::resume(&cp, options, monitor),
            Engine::Packing => packing::resume(&cp, options, monitor),
            Engine::Particles => particles::run(None, options, monitor),
        };
        monitor.finish();
        return result;
    }
    let Some(spec) = options.input.as_deref() else {
        error::refuse!("no input: give a scene file, a particle file or example:NAME");
    };
    let input = Input::read(spec)?;
    run_input(&input, options, monitor)
}

/// Refuses on several ranks what does not run decomposed yet: resuming,
/// checkpoints, the live viewer, and every engine but point particles.
fn check_ranks(options: &RunOptions, engine: Option<Engine>) -> Result<(), FrontError> {
    let Some(ranks) = options.ranks.as_ref().filter(|r| r.0.size() > 1) else {
        return Ok(());
    };
    let input = options.input.as_deref().unwrap_or("the run");
    let n = ranks.0.size();
    let why = if options.live.is_set() {
        Some("the live viewer".to_string())
    } else {
        match engine {
            Some(Engine::Rigid) => Some("a scene of rigid clumps ([rigid])".to_string()),
            Some(Engine::EventDriven) => Some(
                "an event-driven scene (docs/parallel.md says how it would decompose)".to_string(),
            ),
            Some(Engine::Packing) => Some("a packing".to_string()),
            _ => None,
        }
    };
    match why {
        Some(what) => {
            error::refuse!("{input}: {what} does not run on {n} ranks yet: run it on one")
        }
        None => Ok(()),
    }
}

/// Runs an input already read (a scene text from Python, say).
pub fn run_input(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    options.check_values()?;
    let engine = input.engine()?;
    check_ranks(options, Some(engine))?;
    let result = match engine {
        Engine::Particles => particles::run(Some(input.clone()), options, monitor),
        Engine::Rigid => rigid::run(input, options, monitor),
        Engine::EventDriven => event_driven::run(input, options, monitor),
        Engine::Packing => packing::run(input, options, monitor),
    };
    monitor.finish();
    result
}

/// Why `--solver` means nothing to the event-driven engines.
const WHY_NO_SOLVER: &str = "collisions are predicted exactly; there is no integrator to choose";
/// Why `--system` means nothing to a TOML scene.
const WHY_NO_SYSTEM: &str = "it chooses the model of an MPPphys particle file";

/// Refuses a SIMD level `MOTE_SIMD` forces that this CPU or build lacks
/// (callers check once, before anything runs; the kernels would fall back
/// to the widest level without a word).
pub fn check_simd_request() -> Result<(), FrontError> {
    mote_geom::simd::requested()
        .map(|_| ())
        .map_err(FrontError::Request)
}

/// What a run's summary says when a periodic box has no pressure column:
/// the interactions `without` a virial, named.
fn no_pressure_column<S: AsRef<str>>(without: &[S]) -> String {
    let one = without.len() == 1;
    format!(
        "No pressure column: {} do{} not compute {} virial.",
        without
            .iter()
            .map(|w| w.as_ref())
            .collect::<Vec<_>>()
            .join(", "),
        if one { "es" } else { "" },
        if one { "its" } else { "their" }
    )
}

/// "1 thread, AVX-512" / "2 threads, AVX2 + FMA (portable kernels)": the
/// threads and the SIMD level the kernels run at (`MOTE_SIMD` forces one).
fn threads_phrase() -> String {
    let n = rayon::current_num_threads();
    format!(
        "{n} thread{}, {}",
        if n == 1 { "" } else { "s" },
        mote_geom::simd::isa().name()
    )
}

/// ", seed 7" or ", seed 7 (chosen)".
fn seed_phrase(seed: u64, chosen: bool) -> String {
    format!("seed {seed}{}", if chosen { " (chosen)" } else { "" })
}

/// The provenance every output file of this run starts with.
fn provenance(label: &str, seed: u64) -> mote_io::Provenance {
    mote_io::Provenance {
        program: format!("mote {}", env!("CARGO_PKG_VERSION")),
        scene: label.to_string(),
        seed,
    }
}
