//! The soft method ([`mote_md::soft_pack`]: Hertzian spheres under a
//! barostat, the target pressure stepped down a decade at a time, then the
//! jamming finish) in the one run: one step is a chunk of the dynamics or
//! the minimiser, so a soft packing has the checkpoints, progress, live
//! view and folder rules of every other run. φ at each held pressure and
//! each minimised state goes to `packing.csv` as it is reached; the
//! spheres at the lowest pressure (overlapping by ~p^{2/3} of a diameter)
//! are the packing, written at the end with their contacts, rattlers and
//! backbone in the summary.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use mote_edmd::analyse::{contacts, stable_contacts, Contacts};
use mote_edmd::pack::SizeSpec;
use mote_io::checkpoint::Checkpoint;
use mote_io::csv::CsvWriter;
use mote_md::boundary::Boundary;
use mote_md::soft_pack::{
    extrapolate, FinishSettings, SoftPackSettings, SoftPacker, SoftSample, SoftStop, Stage,
};
use mote_md::MdError;
use mote_run::{Observer, Propagator, Report};

use super::{Grown, Naming, PackRun, PackingSpec};
use crate::error::FrontError;
use crate::runner::{Done, EngineRun, RunFiles, SampleOf};
use crate::{Ending, Engine, Monitor};

/// The barostat holds 10⁻² … 10⁻⁴ (the SP method proper); the jamming
/// finish minimises its way on down to the lowest pressure asked.
const LOWEST_HELD: f64 = 1e-4;
/// The finish's minimisations end at this residual force, relative to the
/// mean contact force.
const FORCE_TOLERANCE: f64 = 1e-10;

/// A packing by the soft method in the one run.
pub(crate) struct Soft<'a> {
    job: PackRun<'a>,
    min_pressure: f64,
    /// The run's folder and provenance, once known: a signal still gets
    /// the packing so far written there.
    files: OnceCell<(PathBuf, mote_io::Provenance)>,
}

impl<'a> Soft<'a> {
    pub fn new(job: PackRun<'a>, min_pressure: f64) -> Self {
        Soft {
            job,
            min_pressure,
            files: OnceCell::new(),
        }
    }
}

/// The soft packer's settings for what `spec` asks (down to
/// `min_pressure`) with `seed`; messages name keys as `naming` does,
/// radii files resolve against `base`.
pub(crate) fn settings(
    spec: &PackingSpec,
    naming: Naming,
    base: &Path,
    seed: u64,
    min_pressure: f64,
) -> Result<SoftPackSettings, FrontError> {
    use rand::SeedableRng;
    let settings = spec.settings(seed, naming, base)?;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(settings.seed);
    let n = match &settings.sizes {
        SizeSpec::Radii(r) => r.len(),
        _ => settings.n,
    };
    Ok(SoftPackSettings {
        diameters: mote_edmd::pack::diameters(&settings.sizes, n, &mut rng),
        phi_start: settings.phi_start,
        pressures: SoftPackSettings::decades(min_pressure.max(LOWEST_HELD)),
        tolerance: 0.02,
        max_steps: 2_000_000,
        seed: settings.seed,
        finish: (min_pressure < LOWEST_HELD).then_some(FinishSettings {
            lowest: min_pressure,
            force_tolerance: FORCE_TOLERANCE,
        }),
        wall_clock: settings.wall_clock,
    })
}

/// The columns of a soft packing's table (packing.csv).
pub(crate) const COLUMNS: [(&str, &str); 4] = [
    ("steps", ""),
    ("phi", ""),
    ("pressure", "K"),
    ("minimised", ""),
];

/// The rows of a soft packing's table so far, in [`COLUMNS`]: the steps
/// so far, φ and P/K of each held pressure (minimised 0), then of each
/// minimised state of the finish (1).
pub(crate) fn rows(state: &SoftPacker) -> Vec<[f64; 4]> {
    let row = |s: &Stage, minimised: f64| [s.total as f64, s.phi, s.pressure, minimised];
    let held = state.stages().iter().map(|s| row(s, 0.0));
    held.chain(state.finish().iter().map(|s| row(s, 1.0)))
        .collect()
}

/// Contacts (overlaps) of the spheres at `position` in `boundary`.
fn overlaps(position: &[glam::DVec3], radius: &[f64], boundary: &Boundary) -> Contacts {
    let (simbox, pos) = in_box(position, boundary);
    contacts(&simbox, &pos, radius, 0.0)
}

/// The periodic box of the event-driven analysis, and the positions from
/// its lower corner.
fn in_box(
    position: &[glam::DVec3],
    boundary: &Boundary,
) -> (mote_edmd::system::SimBox<3>, Vec<[f64; 3]>) {
    let simbox = mote_edmd::system::SimBox::<3> {
        size: boundary.lengths().to_array(),
        boundary: [mote_edmd::system::Boundary::Periodic; 3],
    };
    let lo = boundary.lo;
    let pos = position
        .iter()
        .map(|r| (boundary.wrap(*r) - lo).to_array())
        .collect();
    (simbox, pos)
}

/// The table of [`rows`], a row as each state is reached.
struct StageTable {
    csv: CsvWriter,
    path: PathBuf,
    /// Rows already written.
    written: usize,
}

impl Observer<SoftPacker> for StageTable {
    fn every(&self) -> u64 {
        1
    }

    fn observe(&mut self, state: &SoftPacker, _: &SoftSample) -> Result<(), MdError> {
        let rows = rows(state);
        for row in &rows[self.written.min(rows.len())..] {
            self.csv.row(row)?;
        }
        self.written = rows.len();
        Ok(())
    }

    fn files(&self) -> Vec<String> {
        vec![self.path.display().to_string()]
    }
}

/// The summary's line of a held or minimised state: P/K, φ, z and its
/// steps (named `steps`), and `unconverged` where it did not converge.
fn stage_line(s: &Stage, steps: &str, unconverged: &str) -> String {
    format!(
        "  P/K = {:.3e}  phi = {:.6}  z = {:.4}  ({} {steps}{})",
        s.pressure,
        s.phi,
        s.z,
        s.steps,
        if s.converged { "" } else { unconverged }
    )
}

/// φ_J of the last three states of `stages`, if there are two.
fn phi_j(stages: &[Stage]) -> Option<f64> {
    extrapolate(&stages[stages.len().saturating_sub(3)..]).map(|(phi_j, _)| phi_j)
}

impl EngineRun for Soft<'_> {
    type State = SoftPacker;
    const ENGINE: Engine = Engine::Packing;
    const NAME: &'static str = "packing";

    pack_run_methods!();

    fn build(&mut self, seed: u64, resumed: Option<&Checkpoint>) -> Result<SoftPacker, FrontError> {
        let job = &self.job;
        let settings = settings(job.spec, job.naming, &job.base, seed, self.min_pressure)?;
        match resumed {
            Some(cp) => SoftPacker::resume(settings, cp),
            None => SoftPacker::new(settings),
        }
        .map_err(FrontError::request)
    }

    fn observers(
        &self,
        state: &SoftPacker,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<SoftPacker>>>, FrontError> {
        let _ = self
            .files
            .set((files.dir.clone(), files.provenance.clone()));
        if !self.job.writes {
            return Ok(Vec::new());
        }
        let (csv, path) = self.job.table(files, &COLUMNS)?;
        Ok(vec![Box::new(StageTable {
            csv,
            path,
            written: rows(state).len(),
        })])
    }

    fn opening(&self, state: &SoftPacker) -> String {
        format!(
            "packing {} spheres by the soft method (down to P/K = {:e}, {})",
            state.radius.len(),
            self.min_pressure,
            self.job.spec.dist
        )
    }

    fn progress(&self, state: &SoftPacker, _: u64, monitor: &mut dyn Monitor) {
        let held = state.settings().pressures.len() as u64;
        let finish_decades = (LOWEST_HELD / self.min_pressure).log10().ceil().max(0.0) as u64;
        let (stages, finish) = (state.stages(), state.finish());
        let done = (stages.len() + finish.len()) as u64;
        let text = match (finish.last(), stages.last()) {
            (Some(s), _) => format!("jamming finish: phi {:.5}  P/K {:.2e}", s.phi, s.pressure),
            (None, Some(s)) => format!("barostat: phi {:.5}  P/K {:.2e}", s.phi, s.pressure),
            (None, None) => format!("barostat: phi {:.5}", state.phi()),
        };
        monitor.progress(
            done.min(held + finish_decades),
            held + finish_decades,
            &text,
        );
    }

    fn ending(&self, state: &mut SoftPacker, e: MdError) -> Result<Ending, FrontError> {
        match e {
            MdError::Interrupted { signal, .. } => {
                if let (Some((dir, provenance)), Some(frame)) = (self.files.get(), state.frame()) {
                    self.job.write(&frame, dir, provenance)?;
                }
                Ok(super::interrupted(signal))
            }
            e => Err(self.job.naming.locate(e.into())),
        }
    }

    fn ended(&self, state: &SoftPacker) -> Ending {
        match (state.stopped(), mote_io::system::stop_requested()) {
            (Some(SoftStop::Interrupted), Some(signal)) => super::interrupted(signal),
            _ => Ending::Finished,
        }
    }

    fn summary(
        &self,
        state: &SoftPacker,
        _: &Report<SampleOf<Self>>,
        done: &Done,
    ) -> Result<Vec<String>, FrontError> {
        let frame = state.frame().expect("a packing shows itself");
        let written = self
            .job
            .write(&frame, &done.files.dir, &done.files.provenance)?;
        let (stages, finish) = (state.stages(), state.finish());
        let n = state.radius.len();
        let mut summary = vec![format!(
            "{n} spheres by the soft (SP) method: {} steps in {:.2} s CPU. Barostat (Hertz, radial dissipation, Stokes friction): pressure P/K, packing fraction, overlapping neighbours per sphere:",
            state.steps, done.cpu
        )];
        for s in stages {
            summary.push(stage_line(s, "steps", ", NOT held: step budget spent"));
        }
        let barostat_phi_j = phi_j(stages);
        if let (Some(phi_j), Some((position, boundary))) = (barostat_phi_j, state.barostat_end()) {
            let before = overlaps(position, &state.radius, boundary);
            summary.push(format!(
                "Barostat extrapolated to zero pressure (phi = phi_J + c p^(2/3)): phi_J = {phi_j:.6}; backbone z = {:.4} with {} rattlers (< 4 contacts, recursively).",
                before.backbone_z,
                before.rattlers()
            ));
        }
        let finish_phi_j = phi_j(finish);
        if !finish.is_empty() {
            summary.push("Jamming finish (FIRE energy minimisation at fixed box, decompressed a decade of pressure at a time):".into());
            for s in finish {
                summary.push(stage_line(s, "FIRE steps", ", residual force above 1e-10"));
            }
            if let Some(phi_j) = finish_phi_j {
                summary.push(format!(
                    "Finish extrapolated to zero pressure: phi_J = {phi_j:.6}."
                ));
            }
        }
        let (simbox, pos) = in_box(&state.position, &state.boundary);
        let counted = contacts(&simbox, &pos, &state.radius, 0.0);
        let strict = stable_contacts(&simbox, &pos, &state.radius, 0.0);
        summary.push(format!(
            "Contacts (overlaps) at the end: {} rattlers ({:.2} %) by count (< 4 contacts, recursively), backbone z = {:.4}; with force balance (contacts not all in one hemisphere): {} rattlers, backbone z = {:.4} (isostatic 6).",
            counted.rattlers(),
            100.0 * counted.rattlers() as f64 / n as f64,
            counted.backbone_z,
            strict.rattlers(),
            strict.backbone_z
        ));
        match state.stopped() {
            Some(SoftStop::WallClock) => {
                summary.push("Stopped at the wall-clock limit (time_limit).".into())
            }
            Some(SoftStop::Interrupted) => {
                summary.push("Stopped by a signal: the packing so far.".into())
            }
            _ => {}
        }
        if let Some(path) = written {
            summary.push(format!("Wrote {} (+ .csv, .pov).", path.display()));
        }
        let last = finish.last().or(stages.last());
        *self.job.grown.borrow_mut() = Some(Grown {
            frame,
            phi: finish_phi_j.or(barostat_phi_j).unwrap_or(state.phi()),
            pressure: last.map_or(f64::NAN, |s| s.pressure),
        });
        Ok(summary)
    }
}
