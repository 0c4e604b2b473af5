//! Errors of the time-stepped engine.

use mote_io::{IoError, ParseError};

#[derive(Debug, thiserror::Error)]
pub enum MdError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error(transparent)]
    Io(#[from] IoError),
    /// The run produced a non-finite number; the state before it was written.
    #[error("the run went unstable at step {step} (t = {time}): particle {particle} has {what}")]
    Unstable {
        step: u64,
        time: f64,
        particle: usize,
        what: String,
    },
    /// A signal asked the run to stop; it stopped after a whole step, with
    /// its files flushed and, where checkpoints are on, a checkpoint of
    /// that step written.
    #[error("the run was interrupted by signal {signal} after step {step} (t = {time})")]
    Interrupted { signal: i32, step: u64, time: f64 },
    /// A run length that is no count of steps (`until` with `dt = 1e-300`).
    #[error("{0}")]
    Length(String),
}
