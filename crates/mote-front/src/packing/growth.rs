//! A growing packing ([`mote_edmd::pack::Packer`]: Lubachevsky–Stillinger
//! growth of hard spheres, then the quasi-static finish) in the one run:
//! one step is one pressure window, so a packing has the checkpoints,
//! progress, live view and folder rules of every other run. The packing
//! itself (`packing.EXT`, `packing.pov`) is written when it ends, the
//! windows (`packing.csv`) as they close.

use std::cell::{Cell, OnceCell};
use std::path::{Path, PathBuf};

use mote_edmd::analyse::{bond_order, contacts, deepest_overlap};
use mote_edmd::pack::{PackState, Packer, Stop};
use mote_edmd::EdmdError;
use mote_io::checkpoint::Checkpoint;
use mote_io::csv::CsvWriter;
use mote_run::{Observer, Propagator, Report};

use super::PackRun;
use crate::error::{refuse, FrontError};
use crate::runner::{Done, EngineRun, RunFiles, SampleOf};
use crate::{Ending, Engine, Monitor};

/// What a finished packing leaves for a caller that reads it (Python).
#[derive(Debug, Clone)]
pub struct Grown {
    /// The final spheres and box.
    pub frame: mote_io::xyz::Frame,
    pub phi: f64,
    /// The reduced pressure of the last window.
    pub pressure: f64,
}

/// A packing by growth in the one run.
pub(crate) struct Growth<'a, const D: usize> {
    job: PackRun<'a>,
    /// Collisions when the run began (a resumed packing counts on).
    collisions0: Cell<u64>,
    /// The run's folder and provenance, once known: a signal that stops
    /// the driver between two windows still gets the packing so far
    /// written there.
    files: OnceCell<(PathBuf, mote_io::Provenance)>,
}

impl<'a, const D: usize> Growth<'a, D> {
    pub fn new(job: PackRun<'a>) -> Self {
        Growth {
            job,
            collisions0: Cell::new(0),
            files: OnceCell::new(),
        }
    }

    /// Writes the packing and its POV-Ray scene into `dir` (when the run
    /// writes files); returns the packing's path.
    fn write(
        &self,
        state: &Packer<D>,
        dir: &Path,
        provenance: &mote_io::Provenance,
    ) -> Result<Option<PathBuf>, FrontError> {
        let frame = state.frame().expect("a packing shows itself");
        self.job.write(&frame, dir, provenance)
    }
}

/// One row per pressure window: collisions, time, φ, reduced pressure.
struct WindowTable {
    csv: CsvWriter,
    path: PathBuf,
    /// Windows already written.
    written: usize,
}

impl<const D: usize> Observer<Packer<D>> for WindowTable {
    fn every(&self) -> u64 {
        1
    }

    fn observe(&mut self, state: &Packer<D>, _: &mote_edmd::pack::Sample) -> Result<(), EdmdError> {
        let windows = state.windows();
        for s in &windows[self.written.min(windows.len())..] {
            self.csv
                .row(&[s.collisions as f64, s.time, s.phi, s.pressure])?;
        }
        self.written = windows.len();
        Ok(())
    }

    fn files(&self) -> Vec<String> {
        vec![self.path.display().to_string()]
    }
}

/// Why a packing stopped, in words.
fn stopped_because(stop: Stop, max_pressure: f64) -> String {
    match stop {
        Stop::Pressure => format!("reduced pressure passed {max_pressure:e} (jammed)"),
        Stop::TargetPhi => "target packing fraction reached".to_string(),
        Stop::Collisions => "collision budget spent".to_string(),
        Stop::WallClock => "wall-clock limit reached".to_string(),
        Stop::Interrupted => "run was interrupted by a signal (not jammed)".to_string(),
    }
}

impl<const D: usize> EngineRun for Growth<'_, D> {
    type State = Packer<D>;
    const ENGINE: Engine = Engine::Packing;
    const NAME: &'static str = "packing";

    pack_run_methods!();

    fn build(&mut self, seed: u64, resumed: Option<&Checkpoint>) -> Result<Packer<D>, FrontError> {
        let g = &*self;
        let settings = g.job.spec.settings(seed, g.job.naming, &g.job.base)?;
        let packer = match resumed {
            Some(cp) => PackState::from_checkpoint(cp, D)
                .and_then(|state| Packer::<D>::resume(settings, &state)),
            None => Packer::<D>::new(settings),
        }
        .map_err(|e| g.job.naming.locate(e.into()))?;
        g.collisions0.set(packer.collisions());
        Ok(packer)
    }

    fn observers(
        &self,
        state: &Packer<D>,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<Packer<D>>>>, FrontError> {
        let _ = self
            .files
            .set((files.dir.clone(), files.provenance.clone()));
        if !self.job.writes {
            return Ok(Vec::new());
        }
        let (csv, path) = self.job.table(
            files,
            &[
                ("collisions", ""),
                ("time", ""),
                ("phi", ""),
                ("pressure", ""),
            ],
        )?;
        Ok(vec![Box::new(WindowTable {
            csv,
            path,
            written: state.windows().len(),
        })])
    }

    fn opening(&self, state: &Packer<D>) -> String {
        let spec = self.job.spec;
        format!(
            "packing {} {} by growth (rate {}, {})",
            state.system().len(),
            if D == 2 { "disks" } else { "spheres" },
            spec.rate,
            spec.dist
        )
    }

    fn progress(&self, state: &Packer<D>, _: u64, monitor: &mut dyn Monitor) {
        // log10 of the pressure towards the threshold
        let Some(s) = state.windows().last() else {
            return;
        };
        let max_pressure = self.job.spec.max_pressure;
        let f = (s.pressure.max(1.0).log10() / max_pressure.log10()).clamp(0.0, 1.0);
        monitor.progress(
            (f * 1000.0) as u64,
            1000,
            &format!(
                "phi {:.5}  Z {:.3e}  {} collisions",
                s.phi, s.pressure, s.collisions
            ),
        );
    }

    fn ending(&self, state: &mut Packer<D>, e: EdmdError) -> Result<Ending, FrontError> {
        match e {
            EdmdError::Interrupted { signal, .. } => {
                if let Some((dir, provenance)) = self.files.get() {
                    self.write(state, dir, provenance)?;
                }
                Ok(super::interrupted(signal))
            }
            e => Err(self.job.naming.locate(e.into())),
        }
    }

    fn ended(&self, state: &Packer<D>) -> Ending {
        match (state.stopped(), mote_io::system::stop_requested()) {
            (Some(Stop::Interrupted), Some(signal)) => super::interrupted(signal),
            _ => Ending::Finished,
        }
    }

    fn summary(
        &self,
        state: &Packer<D>,
        _: &Report<SampleOf<Self>>,
        done: &Done,
    ) -> Result<Vec<String>, FrontError> {
        let spec = self.job.spec;
        let sys = state.system();
        let simbox = *sys.simbox();
        let (pos, radii) = (sys.positions(), sys.radii());
        let overlap = deepest_overlap(&simbox, &pos, &radii);
        let written = self.write(state, &done.files.dir, &done.files.provenance)?;
        let tol = spec.tol.unwrap_or(1e3 / spec.max_pressure);
        let c = contacts(&simbox, &pos, &radii, tol);
        let (q, _) = bond_order(&simbox, &pos, &radii, 1.2);
        let stop = state.stopped().unwrap_or(Stop::Interrupted);
        let (phi, pressure) = (sys.packing_fraction(), state.pressure());
        let collisions = state.collisions();
        let collisions0 = self.collisions0.get();
        let cpu = done.cpu;
        let mut summary = vec![
            format!(
                "{} {}: phi = {phi:.6}, reduced pressure Z = {pressure:.3e}, stopped because the {}.",
                sys.len(),
                if D == 2 { "disks" } else { "spheres" },
                stopped_because(stop, spec.max_pressure)
            ),
            format!(
                "{collisions} collisions{} in {cpu:.2} s CPU ({:.3e} per CPU-second), {} growth epochs.",
                if collisions0 > 0 {
                    format!(" ({} since the checkpoint)", collisions - collisions0)
                } else {
                    String::new()
                },
                (collisions - collisions0) as f64 / cpu.max(1e-9),
                state.epochs()
            ),
            format!(
                "Contacts at relative gap {:e}: {} rattlers (< {} contacts), backbone mean contact number {:.4} (isostatic {}); {} = {:.4}.",
                tol,
                c.rattlers(),
                D + 1,
                c.backbone_z,
                2 * D,
                if D == 2 { "|psi6|" } else { "Q6" },
                q
            ),
            match overlap {
                None => "No overlaps (exact check over all pairs that can touch).".to_string(),
                Some((_, _, g)) if g > -1e-12 => format!(
                    "No overlaps beyond round-off (exact check over all pairs that can touch; deepest |r|/sigma - 1 = {g:.1e})."
                ),
                Some((i, j, g)) => format!("OVERLAP: particles {i} and {j}, |r|/sigma - 1 = {g:.3e}."),
            },
        ];
        if let Some(path) = written {
            summary.push(format!("Wrote {} (+ .csv, .pov).", path.display()));
        }
        if let Some((i, j, g)) = overlap {
            if g <= -1e-9 {
                refuse!(
                    "particles {i} and {j} overlap by {:.3e} of their contact distance",
                    -g
                );
            }
        }
        *self.job.grown.borrow_mut() = Some(Grown {
            frame: state.frame().expect("a packing shows itself"),
            phi,
            pressure,
        });
        Ok(summary)
    }
}
