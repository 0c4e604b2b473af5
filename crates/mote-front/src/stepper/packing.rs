//! A growing packing, stepped from outside (Python's `Packing`): the
//! packer `mote run` steps for a `[packing]` scene, one pressure window a
//! step, until it stops by itself (jammed, target φ, a budget).

use mote_edmd::pack::{Sample, Stop};
use mote_edmd::Packer;
use mote_io::xyz::Frame;
use mote_run::Propagator;

use super::Stepper;
use crate::error::FrontError;
use crate::{Engine, Input};

/// Disks (2-D) or spheres (3-D) growing to a packing.
pub enum Packing {
    Disks(Stepper<Packer<2>>),
    Spheres(Stepper<Packer<3>>),
}

/// The same expression on either dimension's stepper.
macro_rules! either {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Packing::Disks($s) => $e,
            Packing::Spheres($s) => $e,
        }
    };
}

impl Packing {
    /// The packing `mote run` grows from a `[packing]` scene with `seed`
    /// (the scene's when `None`), with the seed it uses.
    pub fn build(input: &Input, seed: Option<u64>) -> Result<(Self, u64), FrontError> {
        if input.plist || input.engine() != Engine::Packing {
            return Err(FrontError::request(format!(
                "{}: not a packing scene (no [packing] table)",
                input.label
            )));
        }
        crate::packing::scene_packer(input, seed)
    }

    /// 2 for disks, 3 for spheres.
    pub fn dimension(&self) -> usize {
        match self {
            Packing::Disks(_) => 2,
            Packing::Spheres(_) => 3,
        }
    }

    /// Advances `n` pressure windows, or fewer where the packing stops;
    /// `progress(window, time)` after each.
    pub fn advance(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(u64, f64),
    ) -> Result<(), FrontError> {
        either!(self, s => s.advance(n, ends_run, &mut |p| progress(p.step(), p.time()))
            .map_err(FrontError::from))
    }

    /// Pressure windows closed.
    pub fn step(&self) -> u64 {
        either!(self, s => s.state.step())
    }

    /// The simulated time since the start.
    pub fn time(&self) -> f64 {
        either!(self, s => Propagator::time(&s.state))
    }

    /// Why the packing stopped, once it has: `pressure` (jammed),
    /// `target-phi`, `collisions`, `wall-clock`, `interrupted`.
    pub fn stopped(&self) -> Option<&'static str> {
        either!(self, s => s.state.stopped().map(|stop: Stop| stop.name()))
    }

    /// The packing fraction now.
    pub fn phi(&self) -> f64 {
        either!(self, s => s.state.system().packing_fraction())
    }

    /// The reduced pressure of the last window (NaN before the first).
    pub fn pressure(&self) -> f64 {
        either!(self, s => s.state.pressure())
    }

    /// Pair collisions so far.
    pub fn collisions(&self) -> u64 {
        either!(self, s => s.state.collisions())
    }

    /// The columns of [`Packing::windows`], as packing.csv names them.
    pub const WINDOW_COLUMNS: [&'static str; 4] = ["collisions", "time", "phi", "pressure"];

    /// Every window closed so far, one row each in the order of
    /// [`Packing::WINDOW_COLUMNS`].
    pub fn windows(&self) -> Vec<[f64; 4]> {
        let row = |s: &Sample| [s.collisions as f64, s.time, s.phi, s.pressure];
        either!(self, s => s.state.windows().iter().map(row).collect())
    }

    /// The spheres now (disks with z = 0), as the packing file holds them.
    pub fn frame(&self) -> Frame {
        either!(self, s => s.state.frame().unwrap_or_default())
    }
}
