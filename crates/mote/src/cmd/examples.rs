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
    /// With --write: replace scene files there that differ from the examples.
    #[arg(long, requires = "write")]
    pub force: bool,
}

pub fn run(global: &super::GlobalOpts, args: ExamplesArgs) -> anyhow::Result<ExitCode> {
    let all = examples::all();
    if let Some(dir) = args.write {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        // Files there that differ (edited scenes, most likely) are kept
        // unless --force: nothing is written if one would be lost.
        let files: Vec<(PathBuf, &str)> = all
            .iter()
            .map(|e| (dir.join(format!("{}.toml", e.name)), e.text.as_str()))
            .collect();
        let differing: Vec<String> = files
            .iter()
            .filter(|(path, text)| {
                path.symlink_metadata().is_ok()
                    && std::fs::read(path).ok().as_deref() != Some(text.as_bytes())
            })
            .map(|(path, _)| path.display().to_string())
            .collect();
        if !differing.is_empty() && !args.force {
            anyhow::bail!(
                "{} file{} in {} differ{} from the examples and would be overwritten ({}); nothing written: \
                 give another folder, or --force to replace them",
                differing.len(),
                if differing.len() == 1 { "" } else { "s" },
                dir.display(),
                if differing.len() == 1 { "s" } else { "" },
                differing.join(", ")
            );
        }
        for (path, text) in &files {
            std::fs::write(path, text)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if !global.quiet {
            say!("wrote {} scene files to {}", all.len(), dir.display());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let width = all.iter().map(|e| e.name.len()).max().unwrap_or(0);
    for engine in Engine::ALL {
        say!("{}:", engine.title());
        for e in all.iter().filter(|e| e.engine == engine) {
            say!("  {:width$}  {}", e.name, e.description);
        }
        say!();
    }
    say!("run one with `mote run example:NAME`; copy them with `mote examples --write DIR`");
    Ok(ExitCode::SUCCESS)
}
