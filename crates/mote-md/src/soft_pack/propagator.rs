//! A soft packing as a [`Propagator`]: one step is one chunk
//! ([`super::CHUNK`] steps of the dynamics or the minimiser), so the SP
//! method runs through the one run every engine shares — its checkpoints,
//! observers, progress and the live viewer.

use mote_io::checkpoint::Checkpoint;
use mote_run::Propagator;

use super::{SoftPacker, SoftStop};
use crate::MdError;

/// The packing's state at a chunk's end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftSample {
    /// Steps of the dynamics and the minimiser so far.
    pub steps: u64,
    pub time: f64,
    pub phi: f64,
    /// The reduced pressure P/K of the last force pass, kinetic part
    /// included: (Σ mv² + Σ F·r)/3V.
    pub pressure: f64,
}

impl Propagator for SoftPacker {
    type Sample = SoftSample;
    type Error = MdError;

    /// Chunks taken.
    fn step(&self) -> u64 {
        self.chunks
    }

    fn time(&self) -> f64 {
        self.time
    }

    /// One chunk; a signal ends the packing there (the packing so far is
    /// the run's result).
    fn advance(&mut self) -> Result<(), MdError> {
        SoftPacker::advance(self);
        if self.stopped.is_none() && mote_io::system::stop_requested().is_some() {
            self.stop(SoftStop::Interrupted);
        }
        Ok(())
    }

    fn finished(&self) -> bool {
        self.stopped.is_some()
    }

    fn unstable(&self) -> Option<(usize, String)> {
        let bad = |r: &glam::DVec3| !r.is_finite();
        self.position
            .iter()
            .position(bad)
            .map(|i| (i, format!("position {}", self.position[i])))
            .or_else(|| {
                self.velocity
                    .iter()
                    .position(bad)
                    .map(|i| (i, format!("velocity {}", self.velocity[i])))
            })
    }

    fn measure(&mut self) -> SoftSample {
        SoftSample {
            steps: self.steps,
            time: self.time,
            phi: self.phi(),
            pressure: (self.kinetic2() + self.sums.virial) / (3.0 * self.boundary.volume()),
        }
    }

    fn save(&mut self, cp: &mut Checkpoint) -> Result<(), MdError> {
        SoftPacker::save(self, cp);
        Ok(())
    }

    /// The spheres in the box, positions from its lower corner.
    fn frame(&self) -> Option<mote_io::xyz::Frame> {
        let side = self.side();
        let lo = self.boundary.lo;
        Some(mote_io::xyz::Frame {
            time: self.time,
            cell: [[side, 0.0, 0.0], [0.0, side, 0.0], [0.0, 0.0, side]],
            origin: [0.0; 3],
            pbc: [true; 3],
            species: vec!["H".to_string(); self.radius.len()],
            positions: self
                .position
                .iter()
                .map(|r| (self.boundary.wrap(*r) - lo).to_array())
                .collect(),
            radii: self.radius.clone(),
            ..mote_io::xyz::Frame::default()
        })
    }

    fn forces(&self) -> Vec<[f64; 3]> {
        self.force.iter().map(|f| f.to_array()).collect()
    }

    fn change(&mut self, change: &mote_run::Change) -> Result<String, String> {
        Err(format!(
            "{}: a soft packing follows its barostat and minimiser; it has no time step, field, damping or thermostat to change",
            change.what()
        ))
    }
}
