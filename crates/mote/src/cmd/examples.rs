//! `mote examples`.

use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct ExamplesArgs {}

pub fn run(_global: &super::GlobalOpts, _args: ExamplesArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not yet")
}
