//! An event-driven scene's run, stepped from outside (Python's
//! `HardSpheres`).

use mote_edmd::run::EventDriven;
use mote_io::xyz::Frame;
use mote_run::{Columns, Propagator};

use super::Stepper;
use crate::error::FrontError;
use crate::{Engine, Input};

/// Event-driven hard disks (2-D) or spheres (3-D), stepped an output
/// interval at a time: `mote run`'s propagator for the scene.
pub enum HardSpheres {
    Disks(Stepper<EventDriven<2>>),
    Spheres(Stepper<EventDriven<3>>),
}

/// The same expression on either dimension's stepper.
macro_rules! either {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            HardSpheres::Disks($s) => $e,
            HardSpheres::Spheres($s) => $e,
        }
    };
}

impl HardSpheres {
    /// The run `mote run` makes of an event-driven scene with `seed` (the
    /// scene's when `None`), returned with the seed it uses; refused, as
    /// `mote run` refuses it, if it expects more than 10⁹ events unless
    /// `force`d.
    pub fn build(input: &Input, seed: Option<u64>, force: bool) -> Result<(Self, u64), FrontError> {
        if input.plist || input.engine()? != Engine::EventDriven {
            return Err(FrontError::request(format!(
                "{}: not an event-driven scene (no [event_driven] table)",
                input.label
            )));
        }
        let scene = mote_edmd::Scene::parse(&input.text, &input.label)?;
        let (seed, _) = crate::seed::resolve(seed, scene.seed);
        let dir = input.folder();
        let every = 1;
        let run = if scene.spheres.dimension == 2 {
            HardSpheres::Disks(Stepper::new(
                EventDriven::new(&scene, seed, &dir, force)?,
                every,
            ))
        } else {
            HardSpheres::Spheres(Stepper::new(
                EventDriven::new(&scene, seed, &dir, force)?,
                every,
            ))
        };
        Ok((run, seed))
    }

    /// 2 for disks, 3 for spheres.
    pub fn dimension(&self) -> usize {
        match self {
            HardSpheres::Disks(_) => 2,
            HardSpheres::Spheres(_) => 3,
        }
    }

    /// Advances `n` output intervals (the run's steps), measuring each;
    /// `progress(interval, time)` after each.
    pub fn advance(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(u64, f64),
    ) -> Result<(), FrontError> {
        either!(self, s => s.advance(n, ends_run, &mut |p| progress(p.step(), p.time()))
            .map_err(FrontError::from))
    }

    /// Output intervals done.
    pub fn step(&self) -> u64 {
        either!(self, s => s.state.step())
    }

    /// The simulated time.
    pub fn time(&self) -> f64 {
        either!(self, s => s.state.time())
    }

    /// The interval at which the scene's run ends.
    pub fn last_step(&self) -> u64 {
        either!(self, s => s.state.last_step())
    }

    /// The particles now, in the scene's order (disks with z = 0), as the
    /// trajectory writes them.
    pub fn frame(&self) -> Frame {
        either!(self, s => s.state.frame().unwrap_or_default())
    }

    /// The names and units of the observables (the columns of
    /// observables.csv).
    pub fn columns(&self) -> &'static [(&'static str, &'static str)] {
        mote_edmd::run::EventSample::COLUMNS
    }

    /// The observables measured so far, one row each.
    pub fn samples(&self) -> Vec<Vec<f64>> {
        either!(self, s => s.samples().iter().map(|x| x.values()).collect())
    }
}
