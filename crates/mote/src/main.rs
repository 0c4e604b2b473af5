//! `mote`: the command-line program. Thin: parse, hand each part to its engine, report.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[macro_use]
mod out;
mod cmd;
#[cfg(feature = "mpi")]
mod ranks;

/// mote — many-particle simulation toolkit.
#[derive(Parser, Debug)]
#[command(name = "mote", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(flatten)]
    global: cmd::GlobalOpts,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene file, an MPPphys particle file or a built-in example (`example:NAME`).
    Run(cmd::run::RunArgs),
    /// List the built-in examples, or write their scene files to a folder.
    Examples(cmd::examples::ExamplesArgs),
    /// Random close packing fraction by the rod-packing estimator (drop-in for spherepack1d).
    #[command(disable_help_flag = true, disable_version_flag = true)]
    Rcp {
        /// spherepack1d-style options; see `mote rcp -h`.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Ray-traced pictures of a trajectory (extended XYZ, LAMMPS dump, VTU, PVD).
    Render(cmd::render::RenderArgs),
    /// Plot columns of an observables CSV (PNG or SVG).
    Plot(cmd::plot::PlotArgs),
    /// Show a trajectory, or run a scene live, on a local web page (WebGL2; 127.0.0.1 unless --bind).
    View(cmd::view::ViewArgs),
    /// Random close packings by growing spheres (Lubachevsky–Stillinger); `mote pack analyse FILE` analyses one.
    ///
    /// Grows hard spheres (3-D) or disks (2-D) with spheropack's growth rate
    /// Γ = (1/v_th) d⟨d⟩/dt. Near jamming (pressure above --jam-start) it
    /// alternates relaxation at fixed size with small growth steps, so the final
    /// packing is jammed and isostatic (spheropack's `Jammed` protocol; --no-jam
    /// grows at Γ to the end). Stops when the reduced pressure passes
    /// --max-pressure (jammed), at --phi, after --max-collisions or --time-limit,
    /// whichever comes first, and says which.
    Pack(cmd::pack::PackArgs),
    /// Event-driven hard spheres and disks (an alias of `mote run` kept for one release).
    ///
    /// SCENE is a TOML scene file (keys in docs/edmd.md) or `example:NAME`, one of
    /// cube, cradle, cradle-two, cradle-symmetric, cradle-heavy, maxwell2d, eos.
    /// Outputs go next to the scene file, or to the current folder for examples,
    /// unless --out-dir is given or the scene names its [output] dir.
    Edmd(cmd::edmd::EdmdArgs),
}

/// SIGINT and SIGTERM during `mote run` (and its alias `mote edmd`),
/// `mote pack` and `mote view`: the first asks the run to stop after its current step or
/// window (files flushed, a last checkpoint where checkpoints are on, the
/// packing so far written; exit 128 + the signal's number); a second one
/// ends the program at once. Other subcommands keep the default: a signal
/// ends them at once.
fn stop_cleanly_on_signals() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    use signal_hook::flag;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    let asked = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        // Registration fails only for forbidden signals; these two are not.
        let _ = flag::register_conditional_shutdown(signal, 128 + signal, Arc::clone(&asked));
        let _ = flag::register_usize(
            signal,
            Arc::clone(mote_io::system::stop_flag()),
            signal as usize,
        );
        let _ = flag::register(signal, Arc::clone(&asked));
    }
}

/// Output into a closed pipe (`mote pack analyse F | head`) ends the
/// program as it ends every Unix filter, by SIGPIPE, instead of a panic
/// from `println!` (Rust ignores SIGPIPE by default).
fn end_quietly_on_closed_pipes() {
    #[cfg(unix)]
    // SAFETY: restoring a signal's default disposition before any thread
    // is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    end_quietly_on_closed_pipes();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help, version, or a usage error: clap's text, then its status
        // (or 1 where the text could not be written).
        Err(e) => {
            let what = if e.use_stderr() {
                "standard error"
            } else {
                "standard output"
            };
            if let Err(io) = e.print() {
                mote_front::terminal::stream_failed(what, &io);
            }
            return ended(ExitCode::from(e.exit_code().clamp(0, 255) as u8));
        }
    };
    if matches!(
        cli.command,
        Command::Run(_) | Command::Edmd(_) | Command::Pack(_) | Command::View(_)
    ) {
        stop_cleanly_on_signals();
    }
    if let Some(ranks) = launched_on_ranks() {
        let why = if !cfg!(feature = "mpi") {
            "this mote was built without MPI: build it with `cargo build --release --features mpi`"
        } else if !matches!(cli.command, Command::Run(_)) {
            "only `mote run` runs on several ranks"
        } else {
            ""
        };
        if !why.is_empty() {
            // Said once, by rank 0.
            let rank = ["OMPI_COMM_WORLD_RANK", "PMI_RANK"]
                .iter()
                .find_map(|v| std::env::var(v).ok());
            if rank.as_deref().unwrap_or("0") == "0" {
                tell!("error: started on {ranks} ranks, but {why}");
            }
            return ended(ExitCode::FAILURE);
        }
    }
    let global = cli.global;
    let pool = global.threads();
    let command = move || match cli.command {
        Command::Run(args) => cmd::run::run(&global, args),
        Command::Examples(args) => cmd::examples::run(&global, args),
        Command::Rcp { args } => cmd::rcp::run(&global, &args),
        Command::Edmd(args) => cmd::edmd::run(&global, args),
        Command::Pack(args) => cmd::pack::run(&global, args),
        Command::Render(args) => cmd::render::run(&global, args),
        Command::Plot(args) => cmd::plot::run(&global, args),
        Command::View(args) => cmd::view::run(&global, args),
    };
    // A SIMD level forced by MOTE_SIMD that this CPU or build lacks is
    // refused before anything runs (not quietly replaced).
    let result = mote_geom::simd::requested()
        .map_err(anyhow::Error::msg)
        .and(pool)
        .and_then(|pool| pool.install(command));
    ended(match result {
        Ok(code) => code,
        Err(err) => {
            tell!("error: {err:#}");
            ExitCode::FAILURE
        }
    })
}

/// The number of ranks `mpirun` started this process among, where more
/// than one (OpenMPI's `OMPI_COMM_WORLD_SIZE`, MPICH's `PMI_SIZE`): each
/// would otherwise run the whole command on its own, into the same files.
fn launched_on_ranks() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse::<usize>().ok())
        .filter(|&n| n > 1)
}

/// The exit status: `code`, or 1 with a one-line message (if stderr can
/// still take it) where writing to stdout or stderr failed.
fn ended(code: ExitCode) -> ExitCode {
    match mote_front::terminal::stream_failure() {
        Some(why) if code == ExitCode::SUCCESS => {
            let line = format!("mote: {why}\n");
            let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
            ExitCode::FAILURE
        }
        _ => code,
    }
}
