//! Random close packings by growing spheres: the Lubachevsky–Stillinger
//! algorithm in the Kansal–Torquato–Stillinger form (seed 003 §III.1 and its
//! KTS appendix; Skoge, Donev, Stillinger & Torquato, PRE 74, 041127 (2006)).
//!
//! Spheres (disks) move ballistically and grow as r_i(t) = r_i(0)(1 + δt)
//! (003 Eq. 17: size-proportional, so the size distribution is kept);
//! collisions are elastic in the frame of the growing surfaces (u_n → 2s −
//! u_n, see [`crate::system`]) and heat the system, so the velocities are
//! rescaled to the initial kinetic energy every `rescale_every` collisions
//! per particle. The user-facing rate is spheropack's
//!
//! Γ = (1/v_th) d⟨d⟩/dt,   v_th = √(kT/m),
//!
//! with ⟨d⟩ the arithmetic mean diameter (all masses equal, kT = m = 1, so
//! v_th = 1 at each rescale). The run is a sequence of *epochs*: a
//! [`System`] whose neighbour lists and cells are built for the radii at the
//! epoch's end (a growth of a few per cent), then a fresh system from the
//! synchronised state, with δ set again so that d⟨d⟩/dt = Γ v_th.
//!
//! The reduced pressure Z = PV/(N kT) is measured from the collision virial
//! over each rescaling window (Alder & Wainwright); Z → ∞ at jamming as
//! Z ≈ D/(1 − φ/φ_J).

use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::init::{ball_volume, normal, random_placement, thermal_velocities};
use crate::system::{Boundary, SimBox, System};
use crate::EdmdError;

mod propagator;

pub use mote_rcp::SizeSpec;

/// `n` diameters (any common scale) of `sizes`, drawn with `rng` where
/// random; a bidisperse set has its exact counts, the large first.
pub fn diameters(sizes: &SizeSpec, n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<f64> {
    match sizes {
        SizeSpec::Monodisperse => vec![1.0; n],
        SizeSpec::Bidisperse {
            ratio,
            large_fraction,
        } => {
            let large = (large_fraction * n as f64).round() as usize;
            (0..n)
                .map(|i| if i < large { *ratio } else { 1.0 })
                .collect()
        }
        SizeSpec::Lognormal { sigma } => {
            // number median D0 = d43·e^(−7σ²/2) (003 Eqs. 11–12), d43 = 1
            let d0 = (-3.5 * sigma * sigma).exp();
            (0..n).map(|_| d0 * (sigma * normal(rng)).exp()).collect()
        }
        SizeSpec::Radii(r) => r.iter().map(|r| 2.0 * r).collect(),
    }
}

/// The highest reduced pressure a packing can be grown to (see
/// [`PackSettings::check`]).
pub const MAX_REDUCED_PRESSURE: f64 = 1e14;

/// A packing setting out of its domain: the key as a scene spells it
/// (`rate`, `phi_start`, `phi`, `rescale_every`, `max_pressure`, `n`,
/// `jam_start`, `jam_step`, `jam_relax`), its value and why, so that the
/// caller can say where the value came from (a scene's line, an option).
#[derive(Debug, Clone, PartialEq)]
pub struct SettingError {
    pub key: &'static str,
    pub value: String,
    pub why: String,
}

impl std::fmt::Display for SettingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} = {}: {}", self.key, self.value, self.why)
    }
}

/// Settings of a packing run.
#[derive(Debug, Clone)]
pub struct PackSettings {
    /// Number of particles (ignored for [`SizeSpec::Radii`]).
    pub n: usize,
    pub sizes: SizeSpec,
    /// Γ = (1/v_th) d⟨d⟩/dt.
    pub rate: f64,
    /// Packing fraction of the random start (spheropack starts from points;
    /// any dilute start forgets itself long before jamming).
    pub phi_start: f64,
    /// Hard walls on these axes (periodic otherwise).
    pub walls: Vec<bool>,
    /// Stop when the reduced pressure exceeds this (1e12: jammed).
    pub max_pressure: f64,
    /// Stop at this packing fraction.
    pub target_phi: Option<f64>,
    /// Stop after this many pair collisions.
    pub max_collisions: Option<u64>,
    /// Stop after this wall-clock time.
    pub wall_clock: Option<Duration>,
    /// Collisions per particle between kinetic-energy rescalings (also the
    /// pressure window; 10 as in spheropack).
    pub rescale_every: f64,
    /// A quasi-static finish for jammed (isostatic) packings, or `None` for
    /// growth at Γ to the end.
    pub finish: Option<Finish>,
    pub seed: u64,
    /// Grow from these spheres instead of a random start (`n`, `sizes` and
    /// `phi_start` are then ignored).
    pub start: Option<PackStart>,
}

impl PackSettings {
    /// The domain of every setting, checked before anything is built (the
    /// one check of the packer, of `mote pack`'s options and of `[packing]`
    /// scenes, which add where a value came from).
    pub fn check(&self) -> Result<(), SettingError> {
        // as a user writes a number: -1, 0.05, 1e300 (not 301 digits)
        let written = |x: f64| {
            if x == 0.0 || (x.abs() >= 1e-4 && x.abs() < 1e15) {
                format!("{x}")
            } else {
                format!("{x:e}")
            }
        };
        let bad = |key: &'static str, value: f64, why: &str| SettingError {
            key,
            value: written(value),
            why: why.to_string(),
        };
        let n = match (&self.start, &self.sizes) {
            (Some(s), _) => s.radii.len(),
            (None, SizeSpec::Radii(r)) => r.len(),
            _ => self.n,
        };
        if n < 2 {
            return Err(SettingError {
                key: "n",
                value: n.to_string(),
                why: "need at least 2 particles".into(),
            });
        }
        // (a rate of 1.8e308 overflowed the growth of the radii)
        if !(self.rate > 0.0 && self.rate <= 1e3) {
            return Err(bad(
                "rate",
                self.rate,
                "the growth rate Γ must lie in (0, 10³] (spheropack grows at 10⁻³ … 1)",
            ));
        }
        if self.start.is_none() && !(self.phi_start > 0.0 && self.phi_start < 0.3) {
            return Err(bad(
                "phi_start",
                self.phi_start,
                "the starting packing fraction must lie in (0, 0.3)",
            ));
        }
        if let Some(t) = self.target_phi.filter(|_| self.start.is_none()) {
            if !(t > self.phi_start && t < 1.0) {
                return Err(bad(
                    "phi",
                    t,
                    &format!(
                        "the target packing fraction must lie between the start {} and 1",
                        self.phi_start
                    ),
                ));
            }
        }
        // Growing to jamming takes about 10·N/Γ pair collisions (measured:
        // 200 spheres took 1.7·10⁶ more at Γ = 0.001 than at 0.01); beyond
        // 10¹² — a day at 10⁷ a second — a rate is a slip, not a plan (a
        // rate of 1e-300 ran for ever).
        let collisions = 10.0 * n as f64 / self.rate;
        if collisions > 1e12 {
            return Err(bad(
                "rate",
                self.rate,
                &format!(
                    "growing {n} particles to jamming at this rate takes about {collisions:.0e} collisions \
                     (10·N/Γ; days at 10⁷ a second): give a rate of at least {:.0e}",
                    10.0 * n as f64 / 1e12
                ),
            ));
        }
        // (1e300 collisions a particle made one window run for ever)
        if !(self.rescale_every > 0.0 && self.rescale_every <= 1e4) {
            return Err(bad(
                "rescale_every",
                self.rescale_every,
                "the collisions per particle between rescalings must lie in (0, 10⁴]",
            ));
        }
        if self.max_pressure.is_nan() || self.max_pressure <= 1.0 {
            return Err(bad(
                "max_pressure",
                self.max_pressure,
                "the pressure threshold must exceed 1 (the ideal gas)",
            ));
        }
        // Z ≈ D/(relative gap): 10¹⁴ is a gap of 10⁻¹⁴ of a diameter, what
        // 64-bit positions resolve; a higher threshold is never reached
        // (1e300 ran the quasi-static finish for ever).
        if self.max_pressure > MAX_REDUCED_PRESSURE {
            return Err(bad(
                "max_pressure",
                self.max_pressure,
                "the reduced pressure cannot pass 10¹⁴ (gaps of 10⁻¹⁴ of a diameter are what 64-bit positions resolve)",
            ));
        }
        if let Some(f) = self.finish {
            if f.start_pressure.is_nan() || f.start_pressure <= 1.0 {
                return Err(bad(
                    "jam_start",
                    f.start_pressure,
                    "the quasi-static finish's start pressure must exceed 1",
                ));
            }
            // each cycle closes this fraction of the estimated gap, so the
            // cycles to jamming go as ln(Z_max/Z_start)/step (a step of
            // 2e-308 ran for ever)
            if !(f.step >= 1e-3 && f.step <= 0.5) {
                return Err(bad(
                    "jam_step",
                    f.step,
                    "the quasi-static finish's step must lie in [0.001, 0.5]",
                ));
            }
            if f.relax_windows < 1 {
                return Err(SettingError {
                    key: "jam_relax",
                    value: f.relax_windows.to_string(),
                    why: "the quasi-static finish needs at least 1 relaxation window".into(),
                });
            }
        }
        Ok(())
    }
}

/// A start given by the caller (a frame of a file): the box's side lengths,
/// positions measured from its lower corner, radii. Units are the caller's:
/// growth, pressure and every tolerance are relative, so the packing is the
/// same at any scale.
#[derive(Debug, Clone, PartialEq)]
pub struct PackStart {
    pub size: Vec<f64>,
    pub positions: Vec<Vec<f64>>,
    pub radii: Vec<f64>,
}

/// The quasi-static finish for jammed packings (the protocol of spheropack's
/// `Jammed` criterion): once a window's pressure passes `start_pressure`, the
/// radii alternate between `relax_windows` windows at fixed size (energy
/// conserved; the pressure spikes of fast-colliding clusters relax away and
/// Z becomes the equilibrium pressure) and a growth step of the relative size
/// `step`/Z, spread over the duration of one window. Near jamming
/// Z ≈ D/(1 − φ/φ_J), so 1/Z estimates the relative growth left and each step
/// closes the fraction `step` of it. The run stops when a relaxed window's Z
/// passes the pressure threshold: the pressure then spreads over the whole
/// contact network, which becomes isostatic (mean contact number 2D of the
/// non-rattlers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finish {
    pub start_pressure: f64,
    pub relax_windows: usize,
    pub step: f64,
}

impl Default for Finish {
    fn default() -> Self {
        Finish {
            start_pressure: 1e3,
            relax_windows: 4,
            step: 0.2,
        }
    }
}

impl Default for PackSettings {
    fn default() -> Self {
        PackSettings {
            n: 1000,
            sizes: SizeSpec::Monodisperse,
            rate: 0.01,
            phi_start: 0.1,
            walls: Vec::new(),
            max_pressure: 1e12,
            target_phi: None,
            max_collisions: None,
            wall_clock: None,
            rescale_every: 10.0,
            finish: None,
            seed: 1,
            start: None,
        }
    }
}

/// Which stop criterion ended the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// Reduced pressure above the threshold: jammed.
    Pressure,
    /// The target packing fraction was reached.
    TargetPhi,
    /// The collision budget was spent.
    Collisions,
    /// The wall-clock limit passed.
    WallClock,
    /// A signal (SIGINT, SIGTERM) asked the run to stop.
    Interrupted,
}

impl Stop {
    /// Every stop, in the order of their codes in a checkpoint (1, 2, …).
    const ALL: [Stop; 5] = [
        Stop::Pressure,
        Stop::TargetPhi,
        Stop::Collisions,
        Stop::WallClock,
        Stop::Interrupted,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Stop::Pressure => "pressure",
            Stop::TargetPhi => "target-phi",
            Stop::Collisions => "collisions",
            Stop::WallClock => "wall-clock",
            Stop::Interrupted => "interrupted",
        }
    }
}

/// One pressure window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Pair collisions since the start.
    pub collisions: u64,
    /// Simulated time since the start.
    pub time: f64,
    /// Packing fraction at the end of the window.
    pub phi: f64,
    /// Reduced pressure Z = PV/(N kT) over the window.
    pub pressure: f64,
}

/// What a finished run reports.
#[derive(Debug, Clone)]
pub struct PackOutcome {
    pub stop: Stop,
    pub phi: f64,
    /// Reduced pressure of the last complete window (NaN if none).
    pub pressure: f64,
    pub collisions: u64,
    pub time: f64,
    /// Systems built (one per growth epoch).
    pub epochs: u64,
    pub history: Vec<Sample>,
}

/// A growing-sphere packing in progress.
pub struct Packer<const D: usize> {
    sys: System<D>,
    settings: PackSettings,
    /// Kinetic energy kept by the rescaling: D N kT/2 with kT = 1.
    ke_target: f64,
    /// Simulated time of earlier epochs.
    t_before: f64,
    collisions: u64,
    epochs: u64,
    // the current window
    win_virial: f64,
    win_time: f64,
    win_coll: u64,
    last_pressure: f64,
    history: Vec<Sample>,
    /// Growing, or where in the quasi-static finish.
    phase: Phase,
    /// Why the run ended, once it has.
    stopped: Option<Stop>,
    /// When the first step began (the wall-clock limit counts from it).
    started: Option<Instant>,
}

/// Where a packer stands between two steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Growing at the epoch's rate.
    Growing,
    /// In a cycle of the quasi-static finish: `relaxed` of its windows at
    /// fixed radii are closed; `rebuilt` when the system was rebuilt for
    /// the next (by a checkpoint, or a packer resumed from one), so the
    /// cycle does not rebuild it again.
    Finishing { relaxed: usize, rebuilt: bool },
}

/// Where a packing stands at a checkpoint. The system has just been rebuilt
/// (a new epoch), so a packer resumed from this state goes on from the
/// same bits as the run that wrote it.
#[derive(Debug, Clone, PartialEq)]
pub struct PackState {
    /// Box side lengths.
    pub size: Vec<f64>,
    pub positions: Vec<Vec<f64>>,
    pub velocities: Vec<Vec<f64>>,
    pub radii: Vec<f64>,
    /// Growth rate δ and horizon of the epoch the system was built for.
    pub delta: f64,
    pub horizon: f64,
    /// Taken in the quasi-static finish: the relaxation windows of the
    /// cycle closed by then (0 at the top of a cycle); `None` while growing.
    pub finishing: Option<usize>,
    /// Why the run had ended, if it had (a checkpoint of its last step).
    pub stopped: Option<Stop>,
    pub t_before: f64,
    pub collisions: u64,
    pub epochs: u64,
    pub win_virial: f64,
    pub win_time: f64,
    pub win_coll: u64,
    pub last_pressure: f64,
    pub history: Vec<Sample>,
}

impl PackState {
    /// Names of the carried lists of a packing's checkpoint (and their
    /// numbers in checkpoints from before names).
    const SIZE: (&str, usize) = ("box", 0);
    const RADII: (&str, usize) = ("radii", 1);
    const RUN: (&str, usize) = ("run", 2);
    const HISTORY: (&str, usize) = ("windows", 3);

    /// The state in `template` (options, input and seed already there):
    /// positions and velocities padded to 3 components, radii, box, the
    /// run's numbers, and the history of windows (4 numbers each).
    pub fn to_checkpoint(
        &self,
        template: &mote_io::checkpoint::Checkpoint,
    ) -> mote_io::checkpoint::Checkpoint {
        let pad = |v: &Vec<f64>| {
            let mut x = [0.0; 3];
            x[..v.len()].copy_from_slice(v);
            x
        };
        let run = vec![
            self.delta,
            self.horizon,
            self.finishing.map_or(0.0, |k| 1.0 + k as f64),
            self.t_before,
            self.collisions as f64,
            self.epochs as f64,
            self.win_virial,
            self.win_time,
            self.win_coll as f64,
            self.last_pressure,
            self.stopped
                .and_then(|stop| Stop::ALL.iter().position(|s| *s == stop))
                .map_or(0.0, |k| 1.0 + k as f64),
        ];
        let history = self
            .history
            .iter()
            .flat_map(|s| [s.collisions as f64, s.time, s.phi, s.pressure])
            .collect();
        mote_io::checkpoint::Checkpoint {
            time: self.t_before,
            step: self.history.len() as u64,
            positions: self.positions.iter().map(pad).collect(),
            velocities: self.velocities.iter().map(pad).collect(),
            carried: vec![
                (Self::SIZE.0.into(), self.size.clone()),
                (Self::RADII.0.into(), self.radii.clone()),
                (Self::RUN.0.into(), run),
                (Self::HISTORY.0.into(), history),
            ],
            ..template.clone()
        }
    }

    /// The state a checkpoint written by [`PackState::to_checkpoint`] holds,
    /// for a packing of `dimension`.
    pub fn from_checkpoint(
        cp: &mote_io::checkpoint::Checkpoint,
        dimension: usize,
    ) -> Result<Self, EdmdError> {
        let bad = |m: &str| EdmdError::Invalid(format!("checkpoint of a packing: {m}"));
        let list = |(name, old): (&str, usize)| cp.carried_list(name, old).unwrap_or(&[]);
        let run = list(Self::RUN);
        let history = list(Self::HISTORY);
        let (size, radii) = (list(Self::SIZE), list(Self::RADII));
        let n = cp.positions.len();
        // Checkpoints before the run's stop was recorded have 10 numbers.
        if !(run.len() == 10 || run.len() == 11)
            || history.len() % 4 != 0
            || size.len() != dimension
            || radii.len() != n
            || cp.velocities.len() != n
        {
            return Err(bad("its lists have the wrong lengths"));
        }
        let count = |x: f64| -> Result<u64, EdmdError> {
            if x >= 0.0 && x.fract() == 0.0 && x < 2f64.powi(53) {
                Ok(x as u64)
            } else {
                Err(bad("a count is not a whole number"))
            }
        };
        let cut = |v: &[f64; 3]| v[..dimension].to_vec();
        Ok(PackState {
            size: size.to_vec(),
            positions: cp.positions.iter().map(cut).collect(),
            velocities: cp.velocities.iter().map(cut).collect(),
            radii: radii.to_vec(),
            delta: run[0],
            horizon: run[1],
            finishing: match count(run[2])? {
                0 => None,
                k => Some(k as usize - 1),
            },
            stopped: match count(run.get(10).copied().unwrap_or(0.0))? {
                0 => None,
                k => Some(
                    *Stop::ALL
                        .get(k as usize - 1)
                        .ok_or_else(|| bad("an unknown stop"))?,
                ),
            },
            t_before: run[3],
            collisions: count(run[4])?,
            epochs: count(run[5])?,
            win_virial: run[6],
            win_time: run[7],
            win_coll: count(run[8])?,
            last_pressure: run[9],
            history: history
                .chunks(4)
                .map(|c| {
                    Ok(Sample {
                        collisions: count(c[0])?,
                        time: c[1],
                        phi: c[2],
                        pressure: c[3],
                    })
                })
                .collect::<Result<_, EdmdError>>()?,
        })
    }
}

/// Checkpoints of a packing: `save` is called with [`Packer::checkpoint`]
/// every `every` pressure windows (growing or in the finish) and when a
/// signal stops the run.
pub struct PackCheckpoints<'a> {
    pub every: u64,
    pub save: &'a mut dyn FnMut(&PackState) -> Result<(), EdmdError>,
}

/// Periodic lengths per largest diameter the event system needs (three
/// cells of the shell factor's floor, 1.05).
const MIN_CELLS: f64 = 3.15;

/// φ a growth of `sizes` is expected to jam at, a little above it: the rod
/// estimate of `mote rcp` (10⁴ rods, milliseconds) + 0.01 for spheres of a
/// known distribution, else 0.70 (spheres) or 0.86 (disks).
fn jamming_estimate<const D: usize>(sizes: &SizeSpec) -> f64 {
    let fallback = if D == 2 { 0.86 } else { 0.70 };
    if D != 3 {
        return fallback;
    }
    sizes
        .rcp_distribution()
        .and_then(|dist| {
            mote_rcp::RodPacking::default()
                .rods(10_000)
                .estimate(&dist)
                .ok()
        })
        .map_or(fallback, |p| p.phi + 0.01)
}

/// Relative growth of the radii over one epoch: lists are built for radii
/// this much larger, so a bigger step costs more neighbours per list.
fn epoch_growth(phi: f64, dim: usize) -> f64 {
    let dense = if dim == 2 { 0.6 } else { 0.45 };
    if phi < dense {
        0.08
    } else {
        0.02
    }
}

impl<const D: usize> Packer<D> {
    /// A dilute random start: diameters from the distribution, scaled so that
    /// the box (a cube of side L) holds them at `phi_start`, with L chosen
    /// so that the mean diameter is about 1 at jamming.
    pub fn new(settings: PackSettings) -> Result<Self, EdmdError> {
        let invalid = |m: String| EdmdError::Invalid(m);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(settings.seed);
        let n = match (&settings.start, &settings.sizes) {
            (Some(s), _) => s.radii.len(),
            (None, SizeSpec::Radii(r)) => r.len(),
            _ => settings.n,
        };
        settings.check().map_err(EdmdError::Setting)?;
        let mut walls = [false; D];
        for (k, w) in settings.walls.iter().enumerate().take(D) {
            walls[k] = *w;
        }
        let boundary = walls.map(|w| {
            if w {
                Boundary::Wall
            } else {
                Boundary::Periodic
            }
        });
        let phi_guess = if D == 2 { 0.84 } else { 0.64 };
        let (simbox, pos, radii) = match &settings.start {
            Some(start) => Self::given_start(start, boundary, settings.target_phi)?,
            None => {
                let d = diameters(&settings.sizes, n, &mut rng);
                if let Some(k) = d.iter().position(|x| !(*x > 0.0 && x.is_finite())) {
                    return Err(invalid(format!(
                        "radius {} (particle {k}) must be positive and finite",
                        d[k] / 2.0
                    )));
                }
                // box for ⟨d⟩ ≈ 1 near jamming
                let mean_d = d.iter().sum::<f64>() / n as f64;
                let vol: f64 = d.iter().map(|x| ball_volume(D, 0.5 * x / mean_d)).sum();
                let side = (vol / phi_guess).powf(1.0 / D as f64);
                let scale = (settings.phi_start / phi_guess).powf(1.0 / D as f64) / mean_d;
                let radii: Vec<f64> = d.iter().map(|x| 0.5 * x * scale).collect();
                let simbox = SimBox {
                    size: [side; D],
                    boundary,
                };
                let pos =
                    random_placement(&radii, simbox.size, walls.map(|w| !w), &mut rng, 100_000)
                        .ok_or_else(|| invalid("could not place the particles at random".into()))?;
                (simbox, pos, radii)
            }
        };
        // The largest diameter when grown to jamming, against the box: the
        // event system needs each periodic length to exceed 3.15 largest
        // diameters at the end of its last epoch (2 % ahead of the radii),
        // so a run that cannot finish is refused now, not when it gets there.
        let phi_now = radii.iter().map(|r| ball_volume(D, *r)).sum::<f64>() / simbox.volume();
        let phi_end = settings
            .target_phi
            .unwrap_or_else(|| jamming_estimate::<D>(&settings.sizes));
        let growth = (phi_end / phi_now).powf(1.0 / D as f64) * (1.0 + epoch_growth(phi_end, D));
        let side = (0..D)
            .filter(|&d| boundary[d] == Boundary::Periodic)
            .map(|d| simbox.size[d])
            .fold(f64::INFINITY, f64::min);
        let largest = 2.0 * radii.iter().cloned().fold(0.0, f64::max) * growth;
        if largest * MIN_CELLS > side {
            return Err(EdmdError::Setting(SettingError {
                key: "n",
                value: n.to_string(),
                why: format!(
                "{n} particles are too few for this size distribution: grown to φ ≈ {phi_end:.3} the largest diameter would be {:.3} of the periodic box side, and the event system needs less than 1/{MIN_CELLS} (try about {:.0} particles, or a narrower distribution)",
                largest / side,
                (n as f64 * (largest * MIN_CELLS / side).powi(D as i32)).ceil()
            ),
            }));
        }
        let masses = vec![1.0; n];
        let vel = thermal_velocities::<D, _>(&masses, 1.0, &mut rng);
        let ke_target = 0.5 * D as f64 * n as f64;
        let sys = Self::epoch(simbox, pos, vel, radii, masses, &settings)?;
        Ok(Packer {
            sys,
            settings,
            ke_target,
            t_before: 0.0,
            collisions: 0,
            epochs: 1,
            win_virial: 0.0,
            win_time: 0.0,
            win_coll: 0,
            last_pressure: f64::NAN,
            history: Vec::new(),
            phase: Phase::Growing,
            stopped: None,
            started: None,
        })
    }

    /// The packer a checkpoint's state continues (`settings` those of the
    /// run that wrote it).
    pub fn resume(settings: PackSettings, state: &PackState) -> Result<Self, EdmdError> {
        let invalid = |m: &str| EdmdError::Invalid(format!("checkpoint of a packing: {m}"));
        let phase = match (state.finishing, settings.finish) {
            (None, _) => Phase::Growing,
            (Some(k), Some(f)) if k <= f.relax_windows => Phase::Finishing {
                relaxed: k,
                rebuilt: true,
            },
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "taken further into a finish cycle than its settings' relaxation windows",
                ))
            }
            (Some(_), None) => {
                return Err(invalid(
                    "taken in the quasi-static finish, for settings without one",
                ))
            }
        };
        let n = state.radii.len();
        if state.size.len() != D
            || state.positions.len() != n
            || state.velocities.len() != n
            || state
                .positions
                .iter()
                .chain(&state.velocities)
                .any(|v| v.len() != D)
        {
            return Err(invalid("arrays of the wrong length for this dimension"));
        }
        let mut size = [0.0; D];
        size.copy_from_slice(&state.size);
        let mut walls = [false; D];
        for (k, w) in settings.walls.iter().enumerate().take(D) {
            walls[k] = *w;
        }
        let simbox = SimBox {
            size,
            boundary: walls.map(|w| {
                if w {
                    Boundary::Wall
                } else {
                    Boundary::Periodic
                }
            }),
        };
        let array = |v: &Vec<f64>| {
            let mut x = [0.0; D];
            x.copy_from_slice(v);
            x
        };
        let sys = System::with_growth(
            simbox,
            state.positions.iter().map(array).collect(),
            state.velocities.iter().map(array).collect(),
            state.radii.clone(),
            vec![1.0; n],
            state.delta,
            state.horizon,
        )?;
        Ok(Packer {
            sys,
            settings,
            ke_target: 0.5 * D as f64 * n as f64,
            t_before: state.t_before,
            collisions: state.collisions,
            epochs: state.epochs,
            win_virial: state.win_virial,
            win_time: state.win_time,
            win_coll: state.win_coll,
            last_pressure: state.last_pressure,
            history: state.history.clone(),
            phase,
            stopped: state.stopped,
            started: None,
        })
    }

    /// The state of a system just rebuilt (see [`PackState`]).
    fn state(&self, delta: f64, horizon: f64) -> PackState {
        let sys = &self.sys;
        PackState {
            size: sys.simbox().size.to_vec(),
            positions: sys.positions().iter().map(|x| x.to_vec()).collect(),
            velocities: sys.velocities().iter().map(|x| x.to_vec()).collect(),
            radii: sys.radii(),
            delta,
            horizon,
            finishing: match self.phase {
                Phase::Growing => None,
                Phase::Finishing { relaxed, .. } => Some(relaxed),
            },
            // A signal or the wall clock ends this run, not the packing:
            // a run resumed from here goes on.
            stopped: self
                .stopped
                .filter(|s| !matches!(s, Stop::Interrupted | Stop::WallClock)),
            t_before: self.t_before,
            collisions: self.collisions,
            epochs: self.epochs,
            win_virial: self.win_virial,
            win_time: self.win_time,
            win_coll: self.win_coll,
            last_pressure: self.last_pressure,
            history: self.history.clone(),
        }
    }

    /// The state to checkpoint now: the system is rebuilt first (a new
    /// epoch while growing; at fixed radii in the finish, unless it just
    /// was), so that a packer resumed from it goes on from the same bits
    /// as this one. Taking a checkpoint therefore changes the run's later
    /// bits (as a rebuild does) but not its physics.
    pub fn checkpoint(&mut self) -> Result<PackState, EdmdError> {
        match self.phase {
            Phase::Growing => {
                let (delta, horizon) = self.new_epoch()?;
                Ok(self.state(delta, horizon))
            }
            Phase::Finishing { relaxed, rebuilt } => {
                if !rebuilt {
                    self.restart(0.0, f64::INFINITY)?;
                    self.phase = Phase::Finishing {
                        relaxed,
                        rebuilt: true,
                    };
                }
                Ok(self.state(0.0, f64::INFINITY))
            }
        }
    }

    /// The box, positions and radii of a given start, checked: finite,
    /// positive, inside the box, a target φ above the start's.
    #[allow(clippy::type_complexity)]
    fn given_start(
        start: &PackStart,
        boundary: [Boundary; D],
        target_phi: Option<f64>,
    ) -> Result<(SimBox<D>, Vec<[f64; D]>, Vec<f64>), EdmdError> {
        let invalid = |m: String| EdmdError::Invalid(m);
        if start.size.len() < D || start.size[..D].iter().any(|l| !(*l > 0.0 && l.is_finite())) {
            return Err(invalid(format!(
                "the start's box {:?} needs {D} positive side lengths",
                start.size
            )));
        }
        if start.positions.len() != start.radii.len() {
            return Err(invalid("the start has as many positions as radii".into()));
        }
        let mut size = [0.0; D];
        size.copy_from_slice(&start.size[..D]);
        let simbox = SimBox { size, boundary };
        let mut pos = Vec::with_capacity(start.radii.len());
        for (k, (p, r)) in start.positions.iter().zip(&start.radii).enumerate() {
            if !(*r > 0.0 && r.is_finite()) {
                return Err(invalid(format!(
                    "radius {r} (particle {k}) must be positive and finite"
                )));
            }
            let mut x = [0.0; D];
            for d in 0..D {
                let v = p.get(d).copied().unwrap_or(f64::NAN);
                if !v.is_finite() {
                    return Err(invalid(format!(
                        "particle {k}: position {p:?} is not finite"
                    )));
                }
                // Periodic axes wrap; walls must hold the sphere.
                x[d] = match boundary[d] {
                    Boundary::Periodic => v.rem_euclid(size[d]),
                    Boundary::Wall => v,
                };
            }
            pos.push(x);
        }
        let phi = start.radii.iter().map(|r| ball_volume(D, *r)).sum::<f64>() / simbox.volume();
        if let Some(t) = target_phi {
            if !(t > phi && t < 1.0) {
                return Err(invalid(format!(
                    "target packing fraction {t} must lie between the start's {phi:.6} and 1"
                )));
            }
        }
        Ok((simbox, pos, start.radii.clone()))
    }

    /// A system growing at d⟨d⟩/dt = Γ v_th (v_th = 1) from the given state,
    /// valid for one epoch of growth.
    fn epoch(
        simbox: SimBox<D>,
        pos: Vec<[f64; D]>,
        vel: Vec<[f64; D]>,
        radii: Vec<f64>,
        masses: Vec<f64>,
        settings: &PackSettings,
    ) -> Result<System<D>, EdmdError> {
        let n = radii.len() as f64;
        let mean_d = 2.0 * radii.iter().sum::<f64>() / n;
        let delta = settings.rate / mean_d;
        let phi = radii.iter().map(|r| ball_volume(D, *r)).sum::<f64>() / simbox.volume();
        let horizon = epoch_growth(phi, D) / delta;
        System::with_growth(simbox, pos, vel, radii, masses, delta, horizon)
    }

    pub fn system(&self) -> &System<D> {
        &self.sys
    }

    /// Pair collisions so far.
    pub fn collisions(&self) -> u64 {
        self.collisions
    }

    /// Time at which the packing fraction reaches `phi` in the current
    /// system's clock.
    fn time_of_phi(&self, phi: f64) -> f64 {
        let g_now = self.sys.growth_factor();
        let g = g_now * (phi / self.sys.packing_fraction()).powf(1.0 / D as f64);
        (g - 1.0) / self.sys.growth_rate()
    }

    fn harvest(&mut self) {
        let c = *self.sys.counters();
        self.win_virial += c.virial;
        self.win_coll += c.collisions;
        self.win_time += self.sys.time() - c.since;
        self.collisions += c.collisions;
        self.sys.reset_counters();
    }

    /// A fresh system from the synchronised state growing at Γ for one
    /// epoch.
    fn new_epoch(&mut self) -> Result<(f64, f64), EdmdError> {
        let n = self.sys.len() as f64;
        let mean_d = 2.0 * self.sys.radii().iter().sum::<f64>() / n;
        let delta = self.settings.rate / mean_d;
        let horizon = epoch_growth(self.sys.packing_fraction(), D) / delta;
        self.restart(delta, horizon)?;
        Ok((delta, horizon))
    }

    /// A fresh system from the synchronised state with growth rate δ
    /// (relative to the current radii) valid up to `horizon`.
    fn restart(&mut self, delta: f64, horizon: f64) -> Result<(), EdmdError> {
        self.harvest();
        self.sys.synchronize();
        self.t_before += self.sys.time();
        let sys = &self.sys;
        let next = System::with_growth(
            *sys.simbox(),
            sys.positions(),
            sys.velocities(),
            sys.radii(),
            sys.masses(),
            delta,
            horizon,
        )?;
        self.sys = next;
        self.epochs += 1;
        Ok(())
    }

    /// Ends the current pressure window: Z = 1 + Σ r·Δp / (2 K t) with K the
    /// window's mean, a sample, and the kinetic energy rescaled.
    fn close_window(&mut self) -> Result<(f64, f64), EdmdError> {
        let ke_end = self.sys.kinetic_energy();
        if !ke_end.is_finite() || ke_end <= 0.0 {
            return Err(EdmdError::Invalid(format!(
                "kinetic energy {ke_end} after {} collisions: the run went unstable",
                self.collisions
            )));
        }
        let ke = 0.5 * (self.ke_target + ke_end);
        let z = 1.0 + self.win_virial / (2.0 * ke * self.win_time);
        self.last_pressure = z;
        let sample = Sample {
            collisions: self.collisions,
            time: self.t_before + self.sys.time(),
            phi: self.sys.packing_fraction(),
            pressure: z,
        };
        self.history.push(sample);
        if (ke_end / self.ke_target - 1.0).abs() > 1e-12 {
            self.sys.scale_velocities((self.ke_target / ke_end).sqrt());
        }
        let t = self.win_time;
        self.win_virial = 0.0;
        self.win_time = 0.0;
        self.win_coll = 0;
        Ok((z, t))
    }

    /// Collisions in a pressure window: `rescale_every` per particle.
    fn window(&self) -> u64 {
        ((self.settings.rescale_every * self.sys.len() as f64).round() as u64).max(1)
    }

    /// Whether the wall-clock limit has passed.
    fn out_of_time(&self, start: Instant) -> bool {
        self.settings
            .wall_clock
            .is_some_and(|limit| start.elapsed() >= limit)
    }

    /// One window of growth: collisions (new epochs as the old run out)
    /// until the window closes, the target φ is reached, or a limit
    /// passes; the finish begins when the window's pressure passes its
    /// start.
    fn grow_window(&mut self, start: Instant) -> Result<Option<Stop>, EdmdError> {
        let window = self.window();
        loop {
            let mut want = window - self.win_coll;
            if let Some(budget) = self.settings.max_collisions {
                if self.collisions >= budget {
                    return Ok(Some(Stop::Collisions));
                }
                want = want.min(budget - self.collisions);
            }
            let t_target = match self.settings.target_phi {
                Some(p) => self.time_of_phi(p),
                None => f64::INFINITY,
            };
            let horizon = self.sys.horizon();
            let t_end = t_target.min(horizon);
            let Some(done) = self.collisions_within(want, t_end, start) else {
                self.harvest();
                return Ok(Some(Stop::WallClock));
            };
            if !done {
                // nothing more before t_end (or no events at all)
                if t_end.is_finite() {
                    self.sys.run_until(t_end);
                }
                if t_target <= horizon {
                    self.harvest();
                    return Ok(Some(Stop::TargetPhi));
                }
                self.new_epoch()?;
                continue;
            }
            self.harvest();
            if self.win_coll < window {
                // the collision budget cut the window short
                continue;
            }
            let (z, _) = self.close_window()?;
            if z > self.settings.max_pressure {
                return Ok(Some(Stop::Pressure));
            }
            if let Some(f) = self.settings.finish {
                if z > f.start_pressure {
                    self.phase = Phase::Finishing {
                        relaxed: 0,
                        rebuilt: false,
                    };
                    return Ok(None);
                }
            }
            return Ok(self.out_of_time(start).then_some(Stop::WallClock));
        }
    }

    /// One window of the quasi-static finish ([`Finish`]): a cycle's
    /// windows at fixed radii (the system rebuilt for them at the cycle's
    /// top), and after the last of them the growth step of the cycle, or
    /// the stop when the relaxed pressure passes the threshold.
    fn finish_window(&mut self, f: Finish, start: Instant) -> Result<Option<Stop>, EdmdError> {
        let Phase::Finishing { relaxed, rebuilt } = self.phase else {
            unreachable!("a finish window while growing");
        };
        let window = self.window();
        if relaxed == 0 && !rebuilt {
            self.restart(0.0, f64::INFINITY)?;
        }
        let mut want = window;
        if let Some(budget) = self.settings.max_collisions {
            if self.collisions >= budget {
                return Ok(Some(Stop::Collisions));
            }
            want = want.min(budget - self.collisions);
        }
        if self.collisions_within(want, f64::INFINITY, start).is_none() {
            self.harvest();
            return Ok(Some(Stop::WallClock));
        }
        self.harvest();
        if self.win_coll < window {
            // the budget is spent (or no collision is left at all)
            return Ok(Some(Stop::Collisions));
        }
        let (z, t_w) = self.close_window()?;
        let relaxed = relaxed + 1;
        self.phase = Phase::Finishing {
            relaxed,
            rebuilt: false,
        };
        if self.out_of_time(start) {
            return Ok(Some(Stop::WallClock));
        }
        if relaxed < f.relax_windows {
            return Ok(None);
        }
        if z > self.settings.max_pressure {
            return Ok(Some(Stop::Pressure));
        }
        if !(z > 1.0 && t_w > 0.0) {
            return Ok(Some(Stop::Collisions));
        }
        // grow by step/Z over one window's duration
        let delta = f.step / (z * t_w);
        self.restart(delta, t_w)?;
        let Some(done) = self.collisions_within(10 * window, t_w, start) else {
            self.harvest();
            return Ok(Some(Stop::WallClock));
        };
        if !done {
            self.sys.run_until(t_w);
        }
        self.harvest();
        self.win_virial = 0.0;
        self.win_time = 0.0;
        self.win_coll = 0;
        self.phase = Phase::Finishing {
            relaxed: 0,
            rebuilt: false,
        };
        Ok(None)
    }

    /// [`System::run_collisions_until`] that gives up at the wall-clock
    /// limit, checked every 4096 events (a window of 10⁴ collisions per
    /// particle ran minutes past `time_limit` when the clock was read only
    /// between windows): `None` when the limit came first. The events are
    /// those of the unchecked run.
    fn collisions_within(&mut self, count: u64, t_end: f64, start: Instant) -> Option<bool> {
        let Some(limit) = self.settings.wall_clock else {
            return Some(self.sys.run_collisions_until(count, t_end));
        };
        let target = self.sys.counters().collisions + count;
        let mut events: u32 = 0;
        while self.sys.counters().collisions < target {
            if !self.sys.step(t_end) {
                return Some(false);
            }
            events = events.wrapping_add(1);
            if events.is_multiple_of(4096) && start.elapsed() >= limit {
                return None;
            }
        }
        Some(true)
    }

    /// One step of the packing: collisions until the next pressure window
    /// closes (a window of `rescale_every` collisions per particle, growing
    /// or in the finish), or until the run ends ([`Packer::stopped`]);
    /// nothing once it has.
    pub fn advance(&mut self) -> Result<(), EdmdError> {
        if self.stopped.is_some() {
            return Ok(());
        }
        let start = *self.started.get_or_insert_with(Instant::now);
        self.stopped = match (self.phase, self.settings.finish) {
            (Phase::Finishing { .. }, Some(f)) => self.finish_window(f, start)?,
            _ => self.grow_window(start)?,
        };
        Ok(())
    }

    /// Why the run ended, once it has.
    pub fn stopped(&self) -> Option<Stop> {
        self.stopped
    }

    /// Ends the run early (a signal): [`Packer::advance`] then does nothing.
    pub fn stop(&mut self, why: Stop) {
        self.stopped.get_or_insert(why);
    }

    /// Pressure windows closed: the packing's steps.
    pub fn windows(&self) -> &[Sample] {
        &self.history
    }

    /// Simulated time since the start.
    pub fn time(&self) -> f64 {
        self.t_before + self.sys.time()
    }

    /// The reduced pressure of the last window (NaN before the first).
    pub fn pressure(&self) -> f64 {
        self.last_pressure
    }

    /// Growth epochs (systems built) so far.
    pub fn epochs(&self) -> u64 {
        self.epochs
    }

    /// What the run did: every particle brought to the present, the stop
    /// (interrupted if none fired), φ, the last window's pressure.
    pub fn outcome(&mut self) -> PackOutcome {
        self.sys.synchronize();
        PackOutcome {
            stop: self.stopped.unwrap_or(Stop::Interrupted),
            phi: self.sys.packing_fraction(),
            pressure: self.last_pressure,
            collisions: self.collisions,
            time: self.time(),
            epochs: self.epochs,
            history: self.history.clone(),
        }
    }

    /// Runs until a stop criterion fires; `progress` sees every pressure
    /// window.
    pub fn run(&mut self, progress: impl FnMut(&Sample)) -> Result<PackOutcome, EdmdError> {
        self.run_with(progress, None)
    }

    /// [`Packer::run`] with checkpoints: one every `every` windows, and one
    /// when a signal stops the run.
    pub fn run_with(
        &mut self,
        mut progress: impl FnMut(&Sample),
        mut cps: Option<&mut PackCheckpoints>,
    ) -> Result<PackOutcome, EdmdError> {
        while self.stopped.is_none() {
            let seen = self.history.len();
            self.advance()?;
            for s in &self.history[seen..] {
                progress(s);
            }
            if self.stopped.is_some() {
                break;
            }
            let signal = mote_io::system::stop_requested().is_some();
            if let Some(c) = cps.as_mut() {
                if signal || (self.history.len() as u64).is_multiple_of(c.every.max(1)) {
                    let state = self.checkpoint()?;
                    (c.save)(&state)?;
                }
            }
            if signal {
                self.stop(Stop::Interrupted);
            }
        }
        Ok(self.outcome())
    }
}
