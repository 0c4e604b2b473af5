//! `mote run`: any scene of any engine, a particle file or a built-in
//! example, through the one front (`mote_front::run`).

use std::path::PathBuf;
use std::process::ExitCode;

use mote_front::{Ending, RunOptions};

use mote_front::Terminal;

#[derive(clap::Args, Debug, Clone)]
#[command(allow_negative_numbers = true)]
pub struct RunArgs {
    /// Scene file (.toml), MPPphys particle file (.plist or any other name), or `example:NAME`.
    #[arg(required_unless_present = "resume")]
    pub input: Option<String>,
    /// Continue a run from its checkpoint, bit for bit as if it had not stopped.
    #[arg(long, value_name = "CHECKPOINT", conflicts_with_all = ["input", "until", "steps", "dt", "solver", "output"])]
    pub resume: Option<PathBuf>,
    /// Write DIR/checkpoint.mote every N steps and at the end (atomically).
    #[arg(long, value_name = "N")]
    pub checkpoint_every: Option<u64>,
    /// Run until this simulated time (overrides the scene).
    #[arg(long, value_name = "T", conflicts_with = "steps")]
    pub until: Option<f64>,
    /// Run this many steps (overrides the scene).
    #[arg(long, value_name = "N")]
    pub steps: Option<u64>,
    /// Time step (overrides the scene or the particle file's `dt`).
    #[arg(long, value_name = "DT")]
    pub dt: Option<f64>,
    /// Model of an MPPphys particle file (default nbody).
    #[arg(long, value_name = "MODEL", value_parser = super::choices::plist_system())]
    pub system: Option<String>,
    /// Integrator (any case; MPPphys' LF and RK4 too).
    #[arg(long, value_name = "NAME", ignore_case = true, value_parser = super::choices::solver())]
    pub solver: Option<String>,
    /// Folder for the output files (default: the scene's, or out/NAME).
    #[arg(long, short = 'o', value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Ray-trace the final state into this PNG (1920×1080, shadows, box drawn).
    #[arg(long, value_name = "FILE.png")]
    pub picture: Option<PathBuf>,
    /// Trajectory format (overrides the scene's [output] trajectory_format).
    #[arg(long, value_name = "FORMAT", conflicts_with = "resume", value_parser = super::choices::trajectory_format())]
    pub trajectory_format: Option<String>,
    /// Run even if the run takes more than 10⁹ steps (refused otherwise as
    /// a likely mistyped time step or end time).
    #[arg(long)]
    pub force: bool,
}

impl RunArgs {
    pub fn options(self, global: &super::GlobalOpts) -> RunOptions {
        RunOptions {
            input: self.input,
            resume: self.resume,
            checkpoint_every: self.checkpoint_every,
            until: self.until,
            steps: self.steps,
            dt: self.dt,
            system: self.system,
            solver: self.solver,
            output: self.output,
            picture: self.picture,
            trajectory_format: self.trajectory_format,
            seed: global.seed,
            threads: global.threads,
            force: self.force,
            live: Default::default(),
            ranks: None,
        }
    }
}

pub fn run(global: &super::GlobalOpts, args: RunArgs) -> anyhow::Result<ExitCode> {
    #[cfg(feature = "mpi")]
    let mpi = crate::ranks::Mpi::start()?;
    #[allow(unused_mut)]
    let mut options = args.options(global);
    #[cfg(feature = "mpi")]
    {
        options.ranks = mpi.ranks.clone().map(mote_front::Ranks);
    }
    // Rank 0 of several prints; the others keep quiet and exit alike.
    let root = options.ranks.as_ref().is_none_or(|r| r.is_root());
    let mut terminal = Terminal::new(global.quiet || !root);
    match mote_front::run(&options, &mut terminal) {
        Ok(outcome) if root => Ok(report(&outcome, global.quiet)),
        Ok(outcome) => Ok(exit_code(&outcome.ending)),
        Err(e) if options.ranks.is_none() => Err(e.into()),
        Err(e) => {
            if root {
                tell!("error: {e}");
                if e.strands_ranks() {
                    // The others wait for rank 0 mid-run.
                    #[cfg(feature = "mpi")]
                    mpi.abort(1);
                }
            }
            Ok(ExitCode::FAILURE)
        }
    }
}

/// The exit status of a run that ended so ([`report`]'s, unprinted).
fn exit_code(ending: &Ending) -> ExitCode {
    match ending {
        Ending::Finished => ExitCode::SUCCESS,
        Ending::Unstable(_) => ExitCode::from(3),
        Ending::Interrupted { signal, .. } => ExitCode::from((128 + signal).clamp(0, 255) as u8),
    }
}

/// Prints a run's summary (unless quiet) and gives its exit status: 3 for
/// a run that went unstable, whose files are kept; 128 + the signal's
/// number (130 for SIGINT, 143 for SIGTERM) for a run a signal stopped.
pub fn report(outcome: &mote_front::Outcome, quiet: bool) -> ExitCode {
    match &outcome.ending {
        Ending::Finished => {
            if !quiet {
                for line in &outcome.summary {
                    say!("{line}");
                }
            }
            exit_code(&outcome.ending)
        }
        Ending::Unstable(message) => {
            tell!("error: {message}");
            tell!(
                "the files written up to that point are kept in {}",
                outcome.dir.display()
            );
            exit_code(&outcome.ending)
        }
        Ending::Interrupted { message, .. } => {
            tell!("{message}");
            tell!(
                "the files are flushed in {}{}",
                outcome.dir.display(),
                if outcome.dir.join("checkpoint.mote").exists() {
                    "; continue with `mote run --resume` on its checkpoint.mote"
                } else {
                    ""
                }
            );
            exit_code(&outcome.ending)
        }
    }
}
