//! A packing as a [`Propagator`]: one step is one pressure window, so a
//! growing packing runs through the one run every engine shares — its
//! checkpoints, its observers, its progress and the live viewer.

use mote_run::Propagator;

use super::{Packer, Sample, Stop};
use crate::EdmdError;

impl<const D: usize> Propagator for Packer<D> {
    type Sample = Sample;
    type Error = EdmdError;

    /// Pressure windows closed.
    fn step(&self) -> u64 {
        self.history.len() as u64
    }

    fn time(&self) -> f64 {
        Packer::time(self)
    }

    /// Collisions to the next window's end; a signal ends the packing
    /// there (the packing so far is the run's result).
    fn advance(&mut self) -> Result<(), EdmdError> {
        Packer::advance(self)?;
        if self.stopped.is_none() && mote_io::system::stop_requested().is_some() {
            self.stop(Stop::Interrupted);
        }
        Ok(())
    }

    fn finished(&self) -> bool {
        self.stopped.is_some()
    }

    fn unstable(&self) -> Option<(usize, String)> {
        // Collisions are solved exactly; a window whose kinetic energy is
        // not finite is an error of `advance`.
        None
    }

    /// The last window's φ and reduced pressure (NaN before the first).
    fn measure(&mut self) -> Sample {
        Sample {
            collisions: self.collisions,
            time: Packer::time(self),
            phi: self.sys.packing_fraction(),
            pressure: self.last_pressure,
        }
    }

    fn save(&mut self, cp: &mut mote_io::checkpoint::Checkpoint) -> Result<(), EdmdError> {
        *cp = self.checkpoint()?.to_checkpoint(cp);
        Ok(())
    }

    fn frame(&self) -> Option<mote_io::xyz::Frame> {
        let mut f = crate::run::frame(&self.sys);
        f.time = Packer::time(self);
        Some(f)
    }

    fn change(&mut self, change: &mote_run::Change) -> Result<String, String> {
        Err(format!(
            "{}: a packing grows hard spheres at a set rate and has no time step, field, damping or thermostat to change",
            change.what()
        ))
    }
}
