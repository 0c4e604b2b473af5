//! `mote edmd`: event-driven hard spheres and disks (crate `mote-edmd`).
//!
//! An alias of `mote run` for event-driven scenes, kept for one release:
//! it parses the old words (`--time`, `--out-dir`, `--no-output`, `--list`)
//! and runs the scene through the same front, so both give the same output.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use mote_edmd::scene::{example, EXAMPLES};
use mote_front::event_driven::EdmdWords;
use mote_front::{Input, RunOptions};

use mote_front::Terminal;

/// The old command's words (its help text is the `Edmd` variant's in main.rs).
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct EdmdArgs {
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
}

pub fn run(global: &super::GlobalOpts, args: EdmdArgs) -> anyhow::Result<ExitCode> {
    if args.list {
        for (name, text) in EXAMPLES {
            say!(
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
