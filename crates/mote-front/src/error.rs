//! Errors of the front: the engines' own, and bad requests.

use mote_io::{IoError, ParseError};

#[derive(Debug, thiserror::Error)]
pub enum FrontError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Md(#[from] mote_md::MdError),
    #[error(transparent)]
    Edmd(#[from] mote_edmd::EdmdError),
    #[error(transparent)]
    Render(#[from] mote_render::RenderError),
    /// A request that cannot be served (an unknown example, an option the
    /// scene's engine does not have, a missing run length), said in words.
    #[error("{0}")]
    Request(String),
    /// Rank 0 of a decomposed run failed while stepping (a file it could
    /// not write): the other ranks wait for it in a measurement it will
    /// never take, so the caller must end every rank (MPI_Abort).
    #[error(transparent)]
    Stranded(Box<FrontError>),
}

impl FrontError {
    pub fn request(message: impl Into<String>) -> Self {
        FrontError::Request(message.into())
    }

    /// Whether the other ranks of a decomposed run are left waiting
    /// ([`FrontError::Stranded`]).
    pub fn strands_ranks(&self) -> bool {
        matches!(self, FrontError::Stranded(_))
    }

    /// Whether the run went unstable (a non-finite number: the message
    /// names the step and the particle).
    pub fn is_unstable(&self) -> bool {
        matches!(self, FrontError::Md(mote_md::MdError::Unstable { .. }))
    }

    /// Whether the input is at fault (a scene's `file:line: message`, a
    /// request that cannot be served), not the run.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            FrontError::Parse(_)
                | FrontError::Request(_)
                | FrontError::Edmd(
                    mote_edmd::EdmdError::Scene { .. }
                        | mote_edmd::EdmdError::Io(IoError::Parse(_))
                )
                | FrontError::Md(mote_md::MdError::Parse(_) | mote_md::MdError::Length(_))
        )
    }
}

/// `return Err(FrontError::Request(format!(...)))`.
macro_rules! refuse {
    ($($arg:tt)*) => {
        return Err($crate::error::FrontError::Request(format!($($arg)*)))
    };
}
pub(crate) use refuse;
