//! Errors of readers and writers.

use std::fmt;
use std::path::PathBuf;

/// A problem at a known place in an input file: displayed as `file:line: message`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct ParseError {
    /// The file (or a pseudo-name such as `<stdin>` or `example:sun-earth`).
    pub file: String,
    /// One-based line number; 0 when the problem concerns the whole file.
    pub line: usize,
    /// What is wrong, and what would be right.
    pub message: String,
}

impl ParseError {
    pub fn new(file: impl Into<String>, line: usize, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            line,
            message: message.into(),
        }
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: {}", self.file, self.line, self.message)
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

/// Errors of mote-io: a parse error or an operating-system error on a named file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// The cause is part of the message (and not chained as a source, so
    /// that `{:#}` does not print it twice).
    #[error("{path}: {cause}")]
    Os {
        path: PathBuf,
        cause: std::io::Error,
    },
}

impl IoError {
    pub fn os(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Os {
            path: path.into(),
            cause: source,
        }
    }
}
