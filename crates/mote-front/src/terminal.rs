//! The terminal face of a run: the opening line on stderr and an indicatif
//! progress bar that appears once a run has taken a second; and lines to
//! stdout and stderr that never panic.
//!
//! `println!` panics when stdout is full (`> /dev/full`). Lines go through
//! [`say`] (stdout) and [`tell`] (stderr) instead: a failed write is
//! remembered, the command goes on (a run's files are still completed),
//! and the program ends with a one-line message and exit status 1
//! ([`stream_failure`]).

use std::fmt::Arguments;
use std::io::Write;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Shows a run's progress on stderr, or nothing when quiet.
pub struct Terminal {
    quiet: bool,
    bar: ProgressBar,
    started: Instant,
    shown: bool,
    /// No step reported since the opening line: the next report starts
    /// the rate and ETA.
    awaiting_first: bool,
}

impl Terminal {
    pub fn new(quiet: bool) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            let bar = ProgressBar::with_draw_target(Some(1), ProgressDrawTarget::hidden());
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {pos}/{len}  {msg}  {per_sec}  ETA {eta}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar
        };
        Terminal {
            quiet,
            bar,
            started: Instant::now(),
            shown: false,
            awaiting_first: true,
        }
    }
}

impl crate::Monitor for Terminal {
    fn start(&mut self, line: &str) {
        if !self.quiet {
            tell(format_args!("{line}"));
        }
        self.started = Instant::now();
        self.awaiting_first = true;
    }

    fn note(&mut self, line: &str) {
        if !self.quiet {
            tell(format_args!("{line}"));
        }
    }

    fn progress(&mut self, done: u64, total: u64, note: &str) {
        if self.quiet {
            return;
        }
        if !self.shown && self.started.elapsed() > Duration::from_secs(1) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        self.bar.set_length(total);
        self.bar.set_position(done);
        if self.awaiting_first {
            // The rate and ETA count from this step: not the time since
            // the bar was made (a rigid scene builds its bodies after the
            // opening line), nor the steps a resumed run starts at.
            self.bar.reset_eta();
            self.awaiting_first = false;
        }
        self.bar.set_message(note.to_string());
    }

    fn finish(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// The first failed write to stdout or stderr: which, and why.
static FAILED: OnceLock<String> = OnceLock::new();

/// Remembers that writing to `stream` ("standard output", "standard
/// error") failed, for [`stream_failure`]; the first failure is kept.
pub fn stream_failed(stream: &str, why: &dyn std::fmt::Display) {
    let _ = FAILED.set(format!("cannot write to {stream}: {why}"));
}

/// Writes one line to stdout; a failure is remembered.
pub fn say(args: Arguments) {
    if let Err(e) = writeln!(std::io::stdout().lock(), "{args}") {
        stream_failed("standard output", &e);
    }
}

/// Writes one line to stderr; a failure is remembered.
pub fn tell(args: Arguments) {
    if let Err(e) = writeln!(std::io::stderr().lock(), "{args}") {
        stream_failed("standard error", &e);
    }
}

/// Flushes stdout (what is still buffered goes out now) and returns the
/// first failed write, if any.
pub fn stream_failure() -> Option<&'static str> {
    if let Err(e) = std::io::stdout().flush() {
        stream_failed("standard output", &e);
    }
    FAILED.get().map(String::as_str)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Monitor;

    /// Steps 10 at a time every 2 ms after `first` (≈ 5000 steps/s), and
    /// returns the rate the bar shows.
    fn rate_after(setup: Duration, first: u64) -> f64 {
        let mut t = Terminal::new(false);
        t.start("a run");
        // what a run does between its opening line and its first step
        // (a rigid scene builds its bodies there)
        std::thread::sleep(setup);
        t.progress(first, first + 100_000, "");
        for k in 1..=60 {
            std::thread::sleep(Duration::from_millis(2));
            t.progress(first + 10 * k, first + 100_000, "");
        }
        t.bar.per_sec()
    }

    /// The rate and ETA count the steps of this run from its first one: not
    /// the time a scene took to build (rigid runs showed a rate diluted by
    /// it), nor the steps a resumed run's checkpoint had done already.
    #[test]
    fn the_rate_counts_this_runs_steps_from_the_first() {
        let plain = rate_after(Duration::ZERO, 0);
        let slow_build = rate_after(Duration::from_millis(600), 0);
        let resumed = rate_after(Duration::ZERO, 1_000_000);
        for (what, rate) in [("slow build", slow_build), ("resumed", resumed)] {
            assert!(
                rate > plain / 4.0 && rate < plain * 4.0,
                "{what}: {rate:.0} steps/s against {plain:.0}"
            );
        }
        // 5000 steps/s, less where sleeping 2 ms takes longer
        assert!(plain > 200.0 && plain < 10_000.0, "{plain:.0} steps/s");
    }
}
