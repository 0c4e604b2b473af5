//! The terminal face of a run: the opening line on stderr and an indicatif
//! progress bar that appears once a run has taken a second.

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
            eprintln!("{line}");
        }
        self.started = Instant::now();
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
