//! `mote run`.

use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Scene file (.toml), MPPphys particle file, or `example:NAME`.
    pub input: String,
}

pub fn run(_global: &super::GlobalOpts, _args: RunArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not yet")
}
