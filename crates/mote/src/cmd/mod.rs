//! One module per subcommand.

use std::process::ExitCode;

pub mod choices;
pub mod edmd;
pub mod examples;
pub mod pack;
pub mod plot;
pub mod rcp;
pub mod render;
pub mod run;
pub mod view;

/// Parses a subcommand's own words with clap (`name` heads its usage). On
/// `--help`, `--version` or a usage error it prints clap's message and
/// gives the exit status: 0 for help and version, 2 for a usage error.
pub fn parse_words<T: clap::Parser>(name: &str, args: &[String]) -> Result<T, ExitCode> {
    T::try_parse_from(std::iter::once(name.to_string()).chain(args.iter().cloned())).map_err(|e| {
        if let Err(io) = e.print() {
            mote_front::terminal::stream_failed("standard output", &io);
        }
        if e.use_stderr() {
            ExitCode::from(2)
        } else {
            ExitCode::SUCCESS
        }
    })
}

/// Options every subcommand understands.
#[derive(clap::Args, Debug, Clone)]
pub struct GlobalOpts {
    /// Print nothing but errors (no progress bar, no summary).
    #[arg(long, short = 'q', global = true)]
    pub quiet: bool,
    /// Number of worker threads (default: all cores).
    #[arg(long, global = true, value_name = "N")]
    pub threads: Option<usize>,
    /// Seed of the random number generator (default: chosen and printed).
    #[arg(long, global = true, value_name = "N")]
    pub seed: Option<u64>,
}

impl GlobalOpts {
    /// The thread pool the command runs in (`--threads`, default all
    /// cores). The whole command runs on one of its workers, so a parallel
    /// loop is started from inside the pool: with one thread it runs
    /// inline, without handing work to another thread and back (two
    /// context switches per loop, thousands per second in a stepped run).
    pub fn threads(&self) -> anyhow::Result<rayon::ThreadPool> {
        let mut builder = rayon::ThreadPoolBuilder::new();
        if let Some(n) = self.threads.or_else(threads_per_rank) {
            builder = builder.num_threads(n.max(1));
        }
        builder.build().map_err(|e| {
            let n = self.threads.map_or("the".to_string(), |n| n.to_string());
            anyhow::anyhow!("cannot set up {n} threads: {e}")
        })
    }
}

/// Under `mpirun` with several ranks on this machine, the cores shared
/// out among them (OpenMPI's `OMPI_COMM_WORLD_LOCAL_SIZE`, MPICH's
/// `MPI_LOCALNRANKS`): each rank's threads would otherwise take every core.
fn threads_per_rank() -> Option<usize> {
    if !cfg!(feature = "mpi") {
        return None;
    }
    let local: usize = ["OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse().ok())?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    (local > 1).then(|| (cores / local).max(1))
}
