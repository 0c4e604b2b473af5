//! `mote edmd`: event-driven hard spheres and disks (crate `mote-edmd`).
//!
//! An alias of `mote run` for event-driven scenes, kept for one release:
//! it parses the old words (`--time`, `--out-dir`, `--no-output`, `--list`)
//! and runs the scene through the same front, so both give the same output.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use mote_edmd::scene::{example, EXAMPLES};
use mote_front::event_driven::EdmdWords;
use mote_front::{Input, RunOptions};

use crate::progress::Terminal;

/// Event-driven molecular dynamics of hard spheres (3-D) and disks (2-D).
///
/// SCENE is a TOML scene file (keys in docs/edmd.md) or `example:NAME`, one of
/// cube, cradle, cradle-two, cradle-symmetric, cradle-heavy, maxwell2d, eos.
/// Outputs (extended XYZ, CSV) go next to the scene file, or to the current
/// folder for examples, unless --out-dir is given.
#[derive(Parser, Debug)]
#[command(name = "mote edmd", version)]
struct Args {
    /// Scene file or `example:NAME`.
    #[arg(value_name = "SCENE")]
    scene: Option<String>,
    /// List the built-in examples and exit.
    #[arg(long)]
    list: bool,
    /// Simulated time to run (overrides the scene's `time`).
    #[arg(long, value_name = "T")]
    time: Option<f64>,
    /// Folder for the output files.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// Write no trajectory, observables or histogram files.
    #[arg(long)]
    no_output: bool,
    /// Seed of the random number generator (default: the scene's, else chosen and printed).
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Print nothing but errors.
    #[arg(long, short = 'q')]
    quiet: bool,
    /// Accepted for symmetry with other commands; the event loop is serial.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
}

pub fn run(global: &super::GlobalOpts, args: &[String]) -> anyhow::Result<ExitCode> {
    let args = match super::parse_words::<Args>("mote edmd", args) {
        Ok(a) => a,
        Err(code) => return Ok(code),
    };
    let global = global.merged(&super::GlobalOpts {
        quiet: args.quiet,
        threads: args.threads,
        seed: args.seed,
    });
    if args.list {
        for (name, text) in EXAMPLES {
            println!(
                "example:{name:<18} {}",
                mote_front::examples::description(text)
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(scene_arg) = args.scene.as_deref() else {
        anyhow::bail!("no scene given: `mote edmd SCENE` (a .toml file or example:NAME; `mote edmd --list` lists the examples)");
    };
    let input = if let Some(name) = scene_arg.strip_prefix("example:") {
        let text = example(name).with_context(|| {
            let names: Vec<&str> = EXAMPLES.iter().map(|(n, _)| *n).collect();
            format!("unknown example `{name}`; known: {}", names.join(", "))
        })?;
        Input::scene(name, scene_arg, text)
    } else {
        Input::read(scene_arg)?
    };
    // The old command's default: outputs beside the scene file, or in the
    // current folder for examples; a scene's own [output] dir wins over both.
    let scene_names_dir =
        mote_edmd::Scene::parse(&input.text, &input.label).is_ok_and(|s| s.output.dir.is_some());
    let output = args.out_dir.clone().or_else(|| {
        (!scene_names_dir).then(|| {
            Path::new(scene_arg)
                .parent()
                .filter(|p| !p.as_os_str().is_empty() && !scene_arg.starts_with("example:"))
                .map(Path::to_path_buf)
                .unwrap_or_else(|| PathBuf::from("."))
        })
    });
    let options = RunOptions {
        input: Some(scene_arg.to_string()),
        output,
        seed: global.seed,
        threads: global.threads,
        ..RunOptions::default()
    };
    let words = EdmdWords {
        time: args.time,
        no_output: args.no_output,
    };
    let mut terminal = Terminal::new(global.quiet);
    let outcome = mote_front::event_driven::run_with(&input, &options, &words, &mut terminal)?;
    Ok(super::run::report(&outcome, global.quiet))
}
