//! One module per subcommand.

pub mod edmd;
pub mod examples;
pub mod pack;
pub mod plot;
pub mod rcp;
pub mod render;
pub mod run;

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
    /// These options joined with the same options given after a subcommand
    /// that parses its own words (`mote render ... --threads 1`).
    pub fn merged(&self, after: &GlobalOpts) -> GlobalOpts {
        GlobalOpts {
            quiet: self.quiet || after.quiet,
            threads: after.threads.or(self.threads),
            seed: after.seed.or(self.seed),
        }
    }

    /// Sets up the global rayon pool with the requested thread count.
    pub fn init_threads(&self) -> anyhow::Result<()> {
        if let Some(n) = self.threads {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build_global()
                .map_err(|e| anyhow::anyhow!("cannot set up {n} threads: {e}"))?;
        }
        Ok(())
    }
}
