//! The one trajectory observer: every engine's run writes its frames
//! through it, in every format mote writes.

use std::path::Path;

use mote_io::trajectory::{Format, TrajectoryWriter};
use mote_io::{IoError, Provenance};

use crate::{Observer, Propagator};

/// Writes [`Propagator::frame`] every `every` steps, numbered by
/// [`Propagator::step`] (the output index of an event-driven run), in the
/// format of the file.
pub struct Trajectory {
    writer: TrajectoryWriter,
    every: u64,
}

impl Trajectory {
    /// Writes `path` in `format` every `every` steps; `append` continues
    /// the file of an interrupted run (trimmed back to its checkpoint).
    pub fn create(
        path: &Path,
        format: Format,
        provenance: Provenance,
        every: u64,
        append: bool,
    ) -> Result<Self, IoError> {
        let writer = if append {
            TrajectoryWriter::append(path, format, provenance, false)?
        } else {
            TrajectoryWriter::create(path, format, provenance, false)?
        };
        Ok(Self { writer, every })
    }
}

impl<P: Propagator> Observer<P> for Trajectory {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, state: &P, _: &P::Sample) -> Result<(), P::Error> {
        let Some(frame) = state.frame() else {
            return Ok(());
        };
        let written = self.writer.write(state.step(), &frame);
        // The frame was a transient copy: its pages go back at once.
        drop(frame);
        mote_io::system::release_free_memory();
        Ok(written?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }
}
