//! `mote view`: a trajectory, or a run in progress, in the browser
//! (crates/mote-view). Serves on 127.0.0.1 and a free port unless told
//! otherwise, prints the address, and runs until Ctrl-C. Input that cannot
//! be read is reported in the terminal and on the page (exit 1 at the end).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use anyhow::anyhow;
use mote_front::{Input, RunOptions};
use mote_view::live::{self, Session};
use mote_view::App;

/// Shows a trajectory (extended XYZ, LAMMPS dump, GSD, VTU, PVD) or runs a
/// scene live on a local web page.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  mote view out/settling/trajectory.xyz\n  \
mote view example:ferrofluid        (runs it; pause, change the field, dt, ...)\n  \
mote view traj.dump --port 8080 --open")]
pub struct ViewArgs {
    /// A trajectory file, or a scene file, particle file or example:NAME to
    /// run live.
    input: String,
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
    /// Live runs: output folder (default: the scene's, else out/NAME).
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Live runs: run until this simulated time.
    #[arg(long, value_name = "T")]
    until: Option<f64>,
    /// Live runs: run this many steps.
    #[arg(long, value_name = "N", conflicts_with = "until")]
    steps: Option<u64>,
    /// Live runs: time step.
    #[arg(long, value_name = "DT")]
    dt: Option<f64>,
    /// Live runs: start paused (the page's play button starts the run).
    #[arg(long)]
    paused: bool,
}

/// A trajectory by its extension; anything else is a scene to run.
fn is_trajectory(input: &str) -> bool {
    !input.starts_with("example:")
        && mote_io::trajectory::Format::of_path(Path::new(input)).is_some()
}

fn file_name(input: &str) -> String {
    Path::new(input)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| input.to_string())
}

/// The trajectory's frames and its folder's observables.csv.
fn file_app(input: &str) -> Result<(Arc<App>, String), String> {
    let path = Path::new(input);
    let frames = mote_io::trajectory::read_frames(path).map_err(|e| e.to_string())?;
    if frames.is_empty() {
        return Err(format!("{input}: no frames"));
    }
    let table = path
        .parent()
        .map(|d| d.join("observables.csv"))
        .filter(|p| p.exists())
        .and_then(|p| mote_view::table::Table::read(&p).ok());
    let line = format!(
        "{} frames, {} particles in the first",
        frames.len(),
        frames[0].positions.len()
    );
    let t = mote_view::Trajectory::new(file_name(input), frames);
    Ok((App::file(t, table), line))
}

/// Starts the run in a thread of its own; the page watches it through the
/// session.
fn live_app(
    global: &super::GlobalOpts,
    a: &ViewArgs,
) -> Result<(Arc<App>, String, std::thread::JoinHandle<()>), String> {
    let input = Input::read(&a.input).map_err(|e| e.to_string())?;
    let dir = input.run_dir(a.output.as_ref());
    let session = Session::new(input.label.clone(), dir.clone(), a.paused);
    let options = RunOptions {
        input: Some(a.input.clone()),
        until: a.until,
        steps: a.steps,
        dt: a.dt,
        output: Some(dir.clone()),
        seed: global.seed,
        threads: global.threads,
        ..RunOptions::default()
    };
    let quiet = global.quiet;
    let run = live::spawn_run(options, &session, move |result| {
        match result {
            Ok(outcome) => {
                super::run::report(outcome, quiet);
            }
            Err(e) => tell!("error: {e}"),
        }
        live::ending(result)
    })
    .map_err(|e| e.to_string())?;
    let line = format!("running live, files in {}", dir.display());
    Ok((Arc::new(App::Live(session)), line, run))
}

pub fn run(global: &super::GlobalOpts, a: ViewArgs) -> anyhow::Result<ExitCode> {
    let (listener, loopback) = mote_view::bind(&a.bind, a.port).map_err(|m| anyhow!(m))?;
    if !loopback {
        tell!(
            "warning: listening on {}: other machines on the network can see this page",
            a.bind
        );
    }
    let made = if is_trajectory(&a.input) {
        file_app(&a.input).map(|(app, line)| (app, line, None))
    } else {
        live_app(global, &a).map(|(app, line, run)| (app, line, Some(run)))
    };
    let mut failed = false;
    let (app, line, run) = made.unwrap_or_else(|message| {
        tell!("error: {message}");
        failed = true;
        let app = Arc::new(App::Failed {
            label: file_name(&a.input),
            message,
        });
        (app, "cannot be shown (the page says why)".into(), None)
    });
    let addr = listener.local_addr()?;
    let host = if addr.ip().is_unspecified() {
        "127.0.0.1".to_string()
    } else {
        addr.ip().to_string()
    };
    // A live run's page carries the run's token (mote_view::doors).
    let query = match &*app {
        App::Live(session) => format!("?token={}", session.token),
        _ => String::new(),
    };
    let url = if addr.is_ipv6() {
        format!("http://[{host}]:{}/{query}", addr.port())
    } else {
        format!("http://{host}:{}/{query}", addr.port())
    };
    if !global.quiet || failed {
        say!("mote view {}: {line}; open {url} (Ctrl-C ends)", a.input);
    }
    // The address is flushed before anything waits.
    use std::io::Write;
    std::io::stdout().flush().ok();
    if a.open {
        if let Err(e) = std::process::Command::new("xdg-open").arg(&url).spawn() {
            tell!("warning: could not open a browser ({e}); open {url} yourself");
        }
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    // Ctrl-C (SIGINT) or SIGTERM sets the stop flag: the run ends after its
    // step (files flushed), then the server.
    runtime.block_on(mote_view::serve(listener, app, async {
        while mote_io::system::stop_requested().is_none() {
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }))?;
    if let Some(run) = run {
        run.join().ok();
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
