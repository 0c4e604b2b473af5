//! `mote view`: a trajectory in the browser (crates/mote-view). Serves on
//! 127.0.0.1 and a free port unless told otherwise, prints the address, and
//! runs until Ctrl-C.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{anyhow, bail};

/// Shows a trajectory (extended XYZ, LAMMPS dump, GSD, VTU, PVD) on a local web page.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  mote view out/settling/trajectory.xyz\n  mote view traj.dump --port 8080 --open"
)]
pub struct ViewArgs {
    /// The trajectory file.
    file: PathBuf,
    /// Address to listen on (default 127.0.0.1: this machine only; anything
    /// else lets other machines see the page, with a warning).
    #[arg(long, value_name = "IP", default_value = "127.0.0.1")]
    bind: String,
    /// Port (default: a free one).
    #[arg(long, default_value_t = 0)]
    port: u16,
    /// Open the page in the default browser.
    #[arg(long)]
    open: bool,
}

pub fn run(global: &super::GlobalOpts, a: ViewArgs) -> anyhow::Result<ExitCode> {
    let frames = mote_io::trajectory::read_frames(&a.file).map_err(|e| anyhow!("{e}"))?;
    if frames.is_empty() {
        bail!("{}: no frames", a.file.display());
    }
    let label = a
        .file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| a.file.display().to_string());
    let trajectory = Arc::new(mote_view::Trajectory::new(label, frames));
    let (listener, loopback) = mote_view::bind(&a.bind, a.port).map_err(|m| anyhow!(m))?;
    if !loopback {
        eprintln!(
            "warning: listening on {}: other machines on the network can see this page",
            a.bind
        );
    }
    let addr = listener.local_addr()?;
    let host = if addr.ip().is_unspecified() {
        "127.0.0.1".to_string()
    } else {
        addr.ip().to_string()
    };
    let url = if addr.is_ipv6() {
        format!("http://[{host}]:{}/", addr.port())
    } else {
        format!("http://{host}:{}/", addr.port())
    };
    if !global.quiet {
        println!(
            "mote view {}: {} frames, {} particles in the first; open {url} (Ctrl-C ends)",
            a.file.display(),
            trajectory.frames.len(),
            trajectory.frames[0].positions.len()
        );
    }
    // The page is flushed before anything waits.
    use std::io::Write;
    std::io::stdout().flush().ok();
    if a.open {
        if let Err(e) = std::process::Command::new("xdg-open").arg(&url).spawn() {
            eprintln!("warning: could not open a browser ({e}); open {url} yourself");
        }
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    runtime.block_on(mote_view::serve(listener, trajectory, async {
        tokio::signal::ctrl_c().await.ok();
    }))?;
    Ok(ExitCode::SUCCESS)
}
