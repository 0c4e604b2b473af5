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
        }
    }
}

impl crate::Monitor for Terminal {
    fn start(&mut self, line: &str) {
        if !self.quiet {
            tell(format_args!("{line}"));
        }
        self.started = Instant::now();
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
