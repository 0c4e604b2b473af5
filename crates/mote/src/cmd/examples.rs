//! `mote examples`: list the built-in examples or write them out to edit.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;

use crate::examples;

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
    for e in &all {
        println!("{:width$}  {}", e.name, examples::title(&e.text));
    }
    println!("\nrun one with `mote run example:NAME`; copy them with `mote examples --write DIR`");
    println!("event-driven hard-sphere examples: `mote edmd --list`");
    Ok(ExitCode::SUCCESS)
}
