//! `mote pack`: random close packings by growing spheres (Lubachevsky–Stillinger).

use std::process::ExitCode;

use super::GlobalOpts;

pub fn run(_global: &GlobalOpts, _args: &[String]) -> anyhow::Result<ExitCode> {
    anyhow::bail!("mote pack is not built yet")
}
