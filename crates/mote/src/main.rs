//! `mote`: the command-line program. Thin: parse, hand each part to its engine, report.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;
mod progress;

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
    /// Ray-traced pictures of a trajectory; see `mote render --help`.
    #[command(disable_help_flag = true, disable_version_flag = true)]
    Render {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Plot columns of an observables CSV; see `mote plot --help`.
    #[command(disable_help_flag = true, disable_version_flag = true)]
    Plot {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Random close packings by growing spheres (Lubachevsky–Stillinger); see `mote pack --help`.
    #[command(disable_help_flag = true, disable_version_flag = true)]
    Pack {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Event-driven hard spheres and disks (an alias of `mote run` kept for one release); see `mote edmd --help`.
    #[command(disable_help_flag = true, disable_version_flag = true)]
    Edmd {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => cmd::run::run(&cli.global, args),
        Command::Examples(args) => cmd::examples::run(&cli.global, args),
        Command::Rcp { args } => cmd::rcp::run(&cli.global, &args),
        Command::Edmd { args } => cmd::edmd::run(&cli.global, &args),
        Command::Pack { args } => cmd::pack::run(&cli.global, &args),
        Command::Render { args } => cmd::render::run(&cli.global, &args),
        Command::Plot { args } => cmd::plot::run(&cli.global, &args),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
