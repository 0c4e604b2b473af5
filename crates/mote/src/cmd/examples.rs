//! `mote examples`: list the built-in examples of every engine, grouped, or
//! write their scene files out to edit.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use mote_front::{examples, Engine};

#[derive(clap::Args, Debug)]
pub struct ExamplesArgs {
    /// Write every example's scene file into this folder.
    #[arg(long, value_name = "DIR")]
    pub write: Option<PathBuf>,
}

pub fn run(global: &super::GlobalOpts, args: ExamplesArgs) -> anyhow::Result<ExitCode> {
    let all = examples::all();
    if let Some(dir) = args.write {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        for e in &all {
            let path = dir.join(format!("{}.toml", e.name));
            std::fs::write(&path, &e.text)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if !global.quiet {
            println!("wrote {} scene files to {}", all.len(), dir.display());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let width = all.iter().map(|e| e.name.len()).max().unwrap_or(0);
    for engine in Engine::ALL {
        println!("{}:", engine.title());
        for e in all.iter().filter(|e| e.engine == engine) {
            println!("  {:width$}  {}", e.name, e.description);
        }
        println!();
    }
    println!("run one with `mote run example:NAME`; copy them with `mote examples --write DIR`");
    Ok(ExitCode::SUCCESS)
}
