//! `mote rcp` (placeholder until its crate lands).

use std::process::ExitCode;

pub fn run(_global: &super::GlobalOpts, _args: &[String]) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`mote rcp` is not built yet")
}
