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
}
