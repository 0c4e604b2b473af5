//! A packing, stepped from outside (Python's `Packing`): the packer
//! `mote run` steps for a `[packing]` scene — growth one pressure window a
//! step, the soft method one chunk of 100 steps of its barostat or
//! minimiser — until it stops by itself (jammed, target φ, a budget, the
//! end of the finish).

use mote_edmd::pack::{Sample, Stop};
use mote_edmd::Packer;
use mote_io::xyz::Frame;
use mote_md::soft_pack::SoftPacker;
use mote_run::Propagator;

use super::Stepper;
use crate::error::FrontError;
use crate::{Engine, Input};

/// Disks (2-D) or spheres (3-D) growing to a packing, or soft spheres
/// pressed into one.
pub enum Packing {
    Disks(Stepper<Packer<2>>),
    Spheres(Stepper<Packer<3>>),
    Soft(Stepper<SoftPacker>),
}

/// The same expression on every method's stepper.
macro_rules! either {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Packing::Disks($s) => $e,
            Packing::Spheres($s) => $e,
            Packing::Soft($s) => $e,
        }
    };
}

/// The same expression on either growth stepper; `$soft` for the soft
/// method.
macro_rules! growth_or {
    ($self:expr, $s:ident => $e:expr, $soft:ident => $f:expr) => {
        match $self {
            Packing::Disks($s) => $e,
            Packing::Spheres($s) => $e,
            Packing::Soft($soft) => $f,
        }
    };
}

impl Packing {
    /// The packing `mote run` grows from a `[packing]` scene with `seed`
    /// (the scene's when `None`), with the seed it uses.
    pub fn build(input: &Input, seed: Option<u64>) -> Result<(Self, u64), FrontError> {
        if input.plist || input.engine()? != Engine::Packing {
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
            Packing::Spheres(_) | Packing::Soft(_) => 3,
        }
    }

    /// Advances `n` steps (pressure windows, or chunks of the soft
    /// method), or fewer where the packing stops;
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

    /// Steps taken (pressure windows, or chunks of the soft method).
    pub fn step(&self) -> u64 {
        either!(self, s => s.state.step())
    }

    /// The simulated time since the start.
    pub fn time(&self) -> f64 {
        either!(self, s => Propagator::time(&s.state))
    }

    /// Why the packing stopped, once it has: `pressure` (jammed),
    /// `target-phi`, `collisions`, `wall-clock`, `interrupted`; the soft
    /// method `done` (its finish over), `wall-clock`, `interrupted`.
    pub fn stopped(&self) -> Option<&'static str> {
        growth_or!(self,
            s => s.state.stopped().map(|stop: Stop| stop.name()),
            s => s.state.stopped().map(|stop| stop.name()))
    }

    /// The packing fraction now.
    pub fn phi(&self) -> f64 {
        growth_or!(self, s => s.state.system().packing_fraction(), s => s.state.phi())
    }

    /// The reduced pressure of the last window, or (soft method) P/K of
    /// the last held or minimised state; NaN before the first.
    pub fn pressure(&self) -> f64 {
        growth_or!(self, s => s.state.pressure(), s => {
            let (stages, finish) = (s.state.stages(), s.state.finish());
            finish.last().or(stages.last()).map_or(f64::NAN, |s| s.pressure)
        })
    }

    /// Pair collisions so far (`None` for the soft method, which has none).
    pub fn collisions(&self) -> Option<u64> {
        growth_or!(self, s => Some(s.state.collisions()), _s => None)
    }

    /// The columns of [`Packing::windows`], as packing.csv names them.
    pub fn columns(&self) -> [&'static str; 4] {
        match self {
            Packing::Soft(_) => crate::packing::soft::COLUMNS.map(|(name, _)| name),
            _ => ["collisions", "time", "phi", "pressure"],
        }
    }

    /// Every row packing.csv holds so far in the order of
    /// [`Packing::columns`]: the windows closed, or the soft method's held
    /// and minimised states.
    pub fn windows(&self) -> Vec<[f64; 4]> {
        let row = |s: &Sample| [s.collisions as f64, s.time, s.phi, s.pressure];
        growth_or!(self,
            s => s.state.windows().iter().map(row).collect(),
            s => crate::packing::soft::rows(&s.state))
    }

    /// The spheres now (disks with z = 0), as the packing file holds them.
    pub fn frame(&self) -> Frame {
        either!(self, s => s.state.frame().unwrap_or_default())
    }
}
