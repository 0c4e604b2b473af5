//! Event-driven runs in mote's one loop: the engine as a [`Propagator`]
//! whose step is one output interval (it jumps from collision to collision
//! in between, equilibrating when primed), its table (observables.csv),
//! checkpoints that rebuild the system so a resumed run continues in the
//! same bits, and the summary's statistics ([`summarise`]). The run is
//! put together by mote-front's one run, as every engine's is.

use std::path::PathBuf;

use mote_io::checkpoint::Checkpoint;
use mote_io::csv::CsvWriter;
use mote_io::trajectory::Format;
use mote_run::{Columns, Observer, Propagator, Stopped};

use crate::scene::Scene;
use crate::system::{Boundary, SimBox, System};
use crate::theory;
use crate::vecd::to3;
use crate::EdmdError;

/// What a finished run reports.
#[derive(Debug, Clone, Default)]
pub struct Run {
    pub dimension: usize,
    pub n: usize,
    pub packing_fraction: f64,
    pub seed: u64,
    /// Pair collisions and wall collisions during the measured time.
    pub collisions: u64,
    pub wall_hits: u64,
    /// All events (including cell crossings and invalid ones), whole run.
    pub events: u64,
    pub simulated_time: f64,
    /// Wall-clock seconds of the event loop.
    pub wall_seconds: f64,
    /// Compressibility factor from the collision virial (periodic boxes).
    pub z: f64,
    /// Reference equation of state at this packing fraction (CS or Henderson).
    pub z_reference: f64,
    pub wall_pressure: f64,
    pub collision_rate: f64,
    pub mean_free_time: f64,
    pub temperature: f64,
    /// max |E(t) − E(0)| / E(0) at the outputs.
    pub energy_drift: f64,
    /// max over periodic axes of |P(end) − P(0)| / Σ m|v| (NaN without periodic axes).
    pub momentum_drift: f64,
    /// KS test of the final speeds against Maxwell–Boltzmann: (D_n, p).
    pub ks: (f64, f64),
    /// Final speeds.
    pub speeds: Vec<f64>,
    /// Final velocities (3 components, z = 0 for disks), kept for N ≤ 1000.
    pub final_velocities: Vec<[f64; 3]>,
    /// The state at the end (for a picture of it).
    pub final_frame: Option<mote_io::xyz::Frame>,
    pub outputs: Vec<PathBuf>,
}

/// What a checkpoint of an event-driven run carries beside positions and
/// velocities, as `carried` entries: radii (0), masses (1) and the run's
/// bookkeeping (2): E₀, P₀ (3 components), the momentum scale, the largest
/// energy drift so far, the events so far, the counters, and the time
/// measuring began.
mod carried {
    /// (name, index in checkpoints from before names)
    pub const RADII: (&str, usize) = ("radii", 0);
    pub const MASSES: (&str, usize) = ("masses", 1);
    pub const RUN: (&str, usize) = ("run", 2);
}

/// The bookkeeping of a run that a checkpoint carries.
#[derive(Debug, Clone, Copy)]
struct Ledger<const D: usize> {
    e0: f64,
    p0: [f64; D],
    pscale: f64,
    drift: f64,
    events: u64,
    /// Global time at which measuring began (the end of equilibration).
    t0: f64,
}

/// The system rebuilt from its state now, at local time 0 with its
/// counters shifted: every checkpoint rebuilds, so a run resumed from one
/// continues in exactly the bits of the run that wrote it.
fn rebuild<const D: usize>(sys: &System<D>) -> Result<System<D>, EdmdError> {
    let mut fresh = System::new(
        *sys.simbox(),
        sys.positions(),
        sys.velocities(),
        sys.radii(),
        sys.masses(),
    )?;
    let mut c = *sys.counters();
    c.since -= sys.time();
    fresh.set_counters(c);
    Ok(fresh)
}

/// The system, clock offset, output index and ledger a checkpoint holds.
fn resumed<const D: usize>(
    cp: &Checkpoint,
    simbox: SimBox<D>,
) -> Result<(System<D>, f64, u64, Ledger<D>), EdmdError> {
    let bad = |what: &str| EdmdError::Invalid(format!("checkpoint: {what}"));
    let get = |(name, old): (&str, usize)| {
        cp.carried_list(name, old)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| bad("radii, masses or the run's ledger missing"))
    };
    let (radii, masses, run) = (
        get(carried::RADII)?,
        get(carried::MASSES)?,
        get(carried::RUN)?,
    );
    let n = cp.positions.len();
    if radii.len() != n || masses.len() != n || cp.velocities.len() != n || run.len() != 15 {
        return Err(bad("tables of different lengths"));
    }
    let cut = |v: &[f64; 3]| -> [f64; D] { std::array::from_fn(|d| v[d]) };
    let mut sys = System::new(
        simbox,
        cp.positions.iter().map(cut).collect(),
        cp.velocities.iter().map(cut).collect(),
        radii,
        masses,
    )?;
    let c = crate::system::Counters {
        collisions: run[7] as u64,
        wall_hits: run[8] as u64,
        rebuilds: run[9] as u64,
        invalid: run[10] as u64,
        virial: run[11],
        wall_impulse_sum: run[12],
        since: run[13],
    };
    sys.set_counters(c);
    let ledger = Ledger {
        e0: run[0],
        p0: std::array::from_fn(|d| run[1 + d]),
        pscale: run[4],
        drift: run[5],
        events: run[6] as u64,
        t0: run[14],
    };
    Ok((sys, cp.time, cp.step, ledger))
}

/// An event-driven system stepped from output to output.
pub struct EventDriven<const D: usize> {
    sys: System<D>,
    /// Global time of the system's clock zero (moved at every rebuild).
    t_offset: f64,
    /// Output intervals done.
    k: u64,
    interval: f64,
    /// Measured time after equilibration.
    time: f64,
    equilibrate: f64,
    resuming: bool,
    check_overlaps: bool,
    ledger: Ledger<D>,
}

/// One row of observables.csv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventSample {
    pub time: f64,
    pub collisions: u64,
    pub collision_rate: f64,
    pub mean_free_time: f64,
    pub temperature: f64,
    pub kinetic_energy: f64,
    pub energy_drift: f64,
    pub compressibility: f64,
    pub pressure: f64,
    pub wall_pressure: f64,
}

impl Columns for EventSample {
    const COLUMNS: &'static [(&'static str, &'static str)] = &[
        ("time", "t"),
        ("collisions", "1"),
        ("collision_rate", "1/t"),
        ("mean_free_time", "t"),
        ("temperature", "kT"),
        ("kinetic_energy", "E"),
        ("energy_drift", "1"),
        ("compressibility", "1"),
        ("pressure", "E/V"),
        ("wall_pressure", "E/V"),
    ];

    fn values(&self) -> Vec<f64> {
        vec![
            self.time,
            self.collisions as f64,
            self.collision_rate,
            self.mean_free_time,
            self.temperature,
            self.kinetic_energy,
            self.energy_drift,
            self.compressibility,
            self.pressure,
            self.wall_pressure,
        ]
    }
}

impl<const D: usize> EventDriven<D> {
    /// A fresh run of `scene` with `seed` (relative files under
    /// `scene_dir`), refused if it expects more than 10⁹ events unless
    /// `force`d ([`Scene::check_run_length`]): what `mote run` steps.
    pub fn new(
        scene: &Scene,
        seed: u64,
        scene_dir: &std::path::Path,
        force: bool,
    ) -> Result<Self, EdmdError> {
        let built = scene.build::<D>(seed, scene_dir)?;
        scene.check_run_length(&built, force)?;
        let pscale: f64 = built
            .velocities()
            .iter()
            .zip(built.masses())
            .map(|(v, m)| m * crate::vecd::dot(v, v).sqrt())
            .sum::<f64>()
            .max(f64::MIN_POSITIVE);
        let ledger = Ledger {
            e0: built.kinetic_energy(),
            p0: built.momentum(),
            pscale,
            drift: 0.0,
            events: 0,
            t0: 0.0,
        };
        Ok(Self::with_state(scene, built, 0.0, 0, ledger, false))
    }

    /// The run a checkpoint of `scene`'s run holds: its (rebuilt)
    /// system, clock offset, output index and ledger, so it continues in
    /// the bits of the run that wrote it.
    pub fn resume(
        scene: &Scene,
        seed: u64,
        scene_dir: &std::path::Path,
        cp: &Checkpoint,
    ) -> Result<Self, EdmdError> {
        let built = scene.build::<D>(seed, scene_dir)?;
        let (sys, t_offset, k, ledger) = resumed(cp, *built.simbox())?;
        Ok(Self::with_state(scene, sys, t_offset, k, ledger, true))
    }

    fn with_state(
        scene: &Scene,
        sys: System<D>,
        t_offset: f64,
        k: u64,
        ledger: Ledger<D>,
        resuming: bool,
    ) -> Self {
        EventDriven {
            sys,
            t_offset,
            k,
            interval: scene
                .output_interval
                .unwrap_or(scene.time / 100.0)
                .max(1e-300),
            time: scene.time,
            equilibrate: scene.equilibrate,
            resuming,
            check_overlaps: scene.spheres.check_overlaps,
            ledger,
        }
    }

    /// The system as it is (each particle at its own time: see
    /// [`System::position`]).
    pub fn system(&self) -> &System<D> {
        &self.sys
    }

    /// The global time now.
    pub fn now(&self) -> f64 {
        self.t_offset + self.sys.time()
    }

    /// The first output index k at which t0 + k·interval reaches the end
    /// (at least 1: a run of zero length still writes its one row).
    pub fn last_step(&self) -> u64 {
        let (t0, iv) = (self.ledger.t0, self.interval);
        let end = t0 + self.time;
        let mut k = ((self.time / iv).ceil() as u64).max(1);
        while k > 1 && t0 + (k - 1) as f64 * iv >= end {
            k -= 1;
        }
        while t0 + k as f64 * iv < end {
            k += 1;
        }
        k
    }
}

impl<const D: usize> Propagator for EventDriven<D> {
    type Sample = EventSample;
    type Error = EdmdError;

    fn step(&self) -> u64 {
        self.k
    }

    fn time(&self) -> f64 {
        self.now()
    }

    /// Equilibration (not measured, no output) in 20 chunks, then the
    /// collision counters start from zero.
    fn prime(&mut self, progress: &mut dyn FnMut(&Self)) -> Result<(), EdmdError> {
        if self.resuming {
            return Ok(());
        }
        let chunks = 20;
        for c in 1..=chunks {
            if self.equilibrate <= 0.0 {
                break;
            }
            self.ledger.events += self
                .sys
                .run_until(self.equilibrate * c as f64 / chunks as f64);
            progress(self);
            if let Some(signal) = mote_io::system::stop_requested() {
                return Err(EdmdError::Interrupted {
                    signal,
                    time: self.sys.time(),
                });
            }
        }
        self.sys.reset_counters();
        self.ledger.t0 = self.sys.time();
        Ok(())
    }

    fn advance(&mut self) -> Result<(), EdmdError> {
        self.k += 1;
        let l = &mut self.ledger;
        let target = (l.t0 + self.k as f64 * self.interval).min(l.t0 + self.time);
        l.events += self.sys.run_until(target - self.t_offset);
        let e = self.sys.kinetic_energy();
        l.drift = l.drift.max(((e - l.e0) / l.e0).abs());
        if self.check_overlaps {
            if let Some((i, j, gap)) = self.sys.find_overlap(1e-9) {
                return Err(EdmdError::Invalid(format!(
                    "overlap at t = {}: particles {i} and {j} (distance/contact − 1 = {gap:.3e})",
                    self.now()
                )));
            }
        }
        Ok(())
    }

    fn frame(&self) -> Option<mote_io::xyz::Frame> {
        let mut f = frame(&self.sys);
        f.time = self.now();
        Some(f)
    }

    fn change(&mut self, change: &mote_run::Change) -> Result<String, String> {
        Err(format!(
            "{}: the event-driven engine predicts collisions exactly and has no time step, field, damping or thermostat to change",
            change.what()
        ))
    }

    fn unstable(&self) -> Option<(usize, String)> {
        // Collisions are solved exactly; overlaps are checked in `advance`.
        None
    }

    fn measure(&mut self) -> EventSample {
        let sys = &self.sys;
        let e = sys.kinetic_energy();
        let e0 = self.ledger.e0;
        let measured = self.now() - self.ledger.t0 > 0.0;
        let or_nan = |x: f64| if measured { x } else { f64::NAN };
        EventSample {
            time: self.now(),
            collisions: sys.counters().collisions,
            collision_rate: or_nan(sys.collision_rate()),
            mean_free_time: or_nan(sys.mean_free_time()),
            temperature: sys.temperature(),
            kinetic_energy: e,
            energy_drift: (e - e0) / e0,
            compressibility: or_nan(sys.compressibility()),
            pressure: or_nan(sys.pressure()),
            wall_pressure: sys.wall_pressure(),
        }
    }

    /// Rebuilds the system from its state now (so the resumed run and this
    /// one go on from the same bits), then records it with the ledger.
    fn save(&mut self, cp: &mut Checkpoint) -> Result<(), EdmdError> {
        self.t_offset += self.sys.time();
        self.sys = rebuild(&self.sys)?;
        let (sys, ledger) = (&self.sys, self.ledger);
        let c = sys.counters();
        let mut run = vec![ledger.e0];
        run.extend(to3(&ledger.p0));
        run.extend([
            ledger.pscale,
            ledger.drift,
            ledger.events as f64,
            c.collisions as f64,
            c.wall_hits as f64,
            c.rebuilds as f64,
            c.invalid as f64,
            c.virial,
            c.wall_impulse_sum,
            c.since,
            ledger.t0,
        ]);
        cp.time = self.t_offset;
        cp.step = self.k;
        cp.positions = sys.positions().iter().map(to3).collect();
        cp.velocities = sys.velocities().iter().map(to3).collect();
        cp.carried = vec![
            (carried::RADII.0.into(), sys.radii()),
            (carried::MASSES.0.into(), sys.masses()),
            (carried::RUN.0.into(), run),
        ];
        Ok(())
    }
}

impl From<Stopped> for EdmdError {
    fn from(s: Stopped) -> Self {
        match s {
            Stopped::Interrupted { signal, time, .. } => EdmdError::Interrupted { signal, time },
            Stopped::Unstable {
                time,
                particle,
                what,
                ..
            } => EdmdError::Invalid(format!("at t = {time}: particle {particle}: {what}")),
        }
    }
}

/// observables.csv of an event-driven run.
struct EventCsv(CsvWriter);

impl<const D: usize> Observer<EventDriven<D>> for EventCsv {
    fn every(&self) -> u64 {
        1
    }

    fn observe(&mut self, _: &EventDriven<D>, s: &EventSample) -> Result<(), EdmdError> {
        Ok(self.0.row(&s.values())?)
    }
}

/// The tables an event-driven run writes as it goes, each output
/// interval: the scene's `observables` (in `base`); with `append`, onto
/// the file of the run being resumed. (The trajectory is the run's own:
/// `mote_run::Trajectory` of [`Propagator::frame`].)
pub fn file_observers<const D: usize>(
    scene: &Scene,
    base: &std::path::Path,
    provenance: &mote_io::Provenance,
    append: bool,
) -> Result<Vec<Box<dyn Observer<EventDriven<D>>>>, EdmdError> {
    let mut observers: Vec<Box<dyn Observer<EventDriven<D>>>> = Vec::new();
    if let Some(f) = &scene.observables {
        let path = base.join(f);
        let cols: Vec<String> = EventSample::COLUMNS.iter().map(|c| c.0.into()).collect();
        let units: Vec<String> = EventSample::COLUMNS.iter().map(|c| c.1.into()).collect();
        observers.push(Box::new(EventCsv(if append {
            CsvWriter::append(&path, cols.len())?
        } else {
            CsvWriter::create(&path, provenance, &cols, &units)?
        })));
    }
    Ok(observers)
}

/// The trajectory format of an event-driven scene's `trajectory` file,
/// by its extension (extended XYZ for one that names none).
pub fn trajectory_format(file: &str) -> Format {
    Format::of_path(std::path::Path::new(file)).unwrap_or_default()
}

/// The statistics of a finished run, and the speed histogram when asked.
///
/// The histogram goes to `base`, with `provenance`.
pub fn summarise<const D: usize>(
    p: &EventDriven<D>,
    scene: &Scene,
    seed: u64,
    base: &std::path::Path,
    provenance: &mote_io::Provenance,
    wall_seconds: f64,
) -> Result<Run, EdmdError> {
    let sys = &p.sys;
    let n = sys.len();
    let c = *sys.counters();
    let mut result = Run {
        dimension: D,
        n,
        packing_fraction: sys.packing_fraction(),
        seed,
        collisions: c.collisions,
        wall_hits: c.wall_hits,
        events: p.ledger.events,
        simulated_time: scene.time,
        wall_seconds,
        ..Run::default()
    };
    let all_periodic = sys
        .simbox()
        .boundary
        .iter()
        .all(|b| *b == Boundary::Periodic);
    result.z = if all_periodic {
        sys.compressibility()
    } else {
        f64::NAN
    };
    result.z_reference = if D == 3 {
        theory::carnahan_starling(result.packing_fraction)
    } else {
        theory::henderson(result.packing_fraction)
    };
    result.wall_pressure = sys.wall_pressure();
    result.collision_rate = sys.collision_rate();
    result.mean_free_time = sys.mean_free_time();
    result.temperature = sys.temperature();
    result.energy_drift = p.ledger.drift;
    let p1 = sys.momentum();
    // momentum is conserved along periodic axes only (walls take it up)
    result.momentum_drift = (0..D)
        .filter(|&d| sys.simbox().boundary[d] == Boundary::Periodic)
        .map(|d| (p1[d] - p.ledger.p0[d]).abs())
        .fold(f64::NAN, f64::max)
        / p.ledger.pscale;
    // KS against Maxwell–Boltzmann with b² = <v²>·2/D (equal masses)
    let speeds = sys.speeds();
    let v2 = speeds.iter().map(|v| v * v).sum::<f64>() / n as f64;
    let b2 = 2.0 * v2 / D as f64;
    result.ks = if D == 2 {
        theory::ks_test(&speeds, |v| theory::maxwell2d_cdf(v, b2))
    } else {
        theory::ks_test(&speeds, |v| theory::maxwell3d_cdf(v, b2))
    };
    if let Some(f) = &scene.histogram {
        let vmax = 4.0 * b2.sqrt();
        let bins = ((n as f64).sqrt() as usize).clamp(5, 100);
        let h = theory::histogram(&speeds, vmax, bins);
        let cols = vec![
            "v".to_string(),
            "density".to_string(),
            "maxwell_boltzmann".to_string(),
        ];
        let mut w = mote_io::csv::CsvWriter::create(&base.join(f), provenance, &cols, &[])?;
        let dv = vmax / bins as f64;
        for (k, hk) in h.iter().enumerate() {
            let v = (k as f64 + 0.5) * dv;
            let f = if D == 2 {
                2.0 * v / b2 * (-v * v / b2).exp()
            } else {
                4.0 / std::f64::consts::PI.sqrt() * v * v / b2.powf(1.5) * (-v * v / b2).exp()
            };
            w.row(&[v, *hk, f])?;
        }
        result.outputs.push(w.path().to_path_buf());
    }
    result.speeds = speeds;
    let mut last = frame(sys);
    last.time = p.now();
    result.final_frame = Some(last);
    if n <= 1000 {
        result.final_velocities = sys.velocities().iter().map(to3).collect();
    }
    for f in [&scene.trajectory, &scene.observables]
        .into_iter()
        .flatten()
    {
        result.outputs.push(base.join(f));
    }
    Ok(result)
}

/// The current state as a mote-io frame (z = 0 for disks).
pub fn frame<const D: usize>(sys: &System<D>) -> mote_io::xyz::Frame {
    let mut cell = [[0.0; 3]; 3];
    let mut pbc = [false; 3];
    for d in 0..3 {
        cell[d][d] = if d < D { sys.simbox().size[d] } else { 0.0 };
        pbc[d] = d < D && sys.simbox().boundary[d] == Boundary::Periodic;
    }
    if D == 2 {
        cell[2][2] = 2.0 * sys.max_radius();
    }
    let n = sys.len();
    mote_io::xyz::Frame {
        time: sys.time(),
        cell,
        origin: [0.0; 3],
        pbc,
        species: vec!["H".to_string(); n],
        positions: sys.positions().iter().map(to3).collect(),
        velocities: sys.velocities().iter().map(to3).collect(),
        radii: sys.radii().to_vec(),
        masses: sys.masses(),
        ..mote_io::xyz::Frame::default()
    }
}
