//! Scene settings (the `[edmd]` TOML a user writes) and the one run loop.
//!
//! Every key is documented in docs/edmd.md. Errors in a scene file come back
//! as `file:line: message` ([`EdmdError::Scene`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;

use crate::init::{
    ball_volume, fixed_speed_velocities, lattice, min_pair_distance, random_placement,
    thermal_velocities,
};
use mote_io::checkpoint::Checkpoint;

use crate::system::{Boundary, SimBox, System};
use crate::theory;
use crate::vecd::to3;
use crate::EdmdError;

/// How the initial positions are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Placement {
    /// fcc in 3-D (4 sites per cubic cell), square in 2-D.
    #[default]
    Fcc,
    /// Simple cubic / square lattice.
    Cubic,
    /// Random sequential placement without overlap (up to η ≈ 0.35 in 3-D,
    /// 0.5 in 2-D).
    Random,
}

/// One particle given explicitly.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    pub position: Vec<f64>,
    #[serde(default)]
    pub velocity: Vec<f64>,
    pub radius: Option<f64>,
    pub mass: Option<f64>,
}

/// Per-axis boundary: one word for all axes or a list.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum BoundarySpec {
    All(Boundary),
    PerAxis(Vec<Boundary>),
}

impl Default for BoundarySpec {
    fn default() -> Self {
        BoundarySpec::All(Boundary::Periodic)
    }
}

/// The settings of an event-driven run. All keys are optional except what
/// fixes the particles: `n` (with `packing_fraction` and/or `box`),
/// `[[particles]]`, or `file`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// One line saying what the scene shows (listed by `mote examples`).
    pub title: Option<String>,
    /// 2 (disks) or 3 (spheres). Default 3.
    #[serde(default = "default_dim")]
    pub dimension: usize,
    /// Number of particles (with `placement`).
    pub n: Option<usize>,
    /// Packing fraction η = Σ v_i / V; sets the box (cube/square) when `box`
    /// is missing, or the radius when both `box` and `n` are given.
    pub packing_fraction: Option<f64>,
    /// Box lengths per axis.
    #[serde(rename = "box")]
    pub box_size: Option<Vec<f64>>,
    /// "periodic" or "wall", or one per axis.
    #[serde(default)]
    pub boundary: BoundarySpec,
    /// Particle radius (default 0.5, i.e. diameter 1).
    pub radius: Option<f64>,
    /// Particle mass (default 1).
    pub mass: Option<f64>,
    /// Bidisperse mixtures: fraction of large particles and their size ratio.
    pub large_fraction: Option<f64>,
    pub size_ratio: Option<f64>,
    #[serde(default)]
    pub placement: Placement,
    /// k_B T of Maxwell–Boltzmann initial velocities (default 1).
    pub temperature: Option<f64>,
    /// Instead of `temperature`: all speeds equal to this, random directions.
    pub speed: Option<f64>,
    /// Random seed (the command line's `--seed` wins).
    pub seed: Option<u64>,
    /// `[run]`: the length of the run, as for every engine.
    #[serde(default)]
    pub run: RunSection,
    /// `[output]`: the files, as for every engine.
    #[serde(default)]
    pub output: OutputSection,
    /// Deprecated top-level keys of the first scene format, kept for one
    /// release; [`Scene::parse`] turns them into the fields below and a note.
    #[serde(rename = "time")]
    legacy_time: Option<f64>,
    #[serde(rename = "equilibrate")]
    legacy_equilibrate: Option<f64>,
    #[serde(rename = "output_interval")]
    legacy_output_interval: Option<f64>,
    #[serde(rename = "trajectory")]
    legacy_trajectory: Option<String>,
    #[serde(rename = "observables")]
    legacy_observables: Option<String>,
    #[serde(rename = "histogram")]
    legacy_histogram: Option<String>,
    /// Simulated time measured (after `equilibrate`); from `[run] until`
    /// (default equilibrate + 10).
    #[serde(skip)]
    pub time: f64,
    /// Simulated time run first, without measuring.
    #[serde(skip)]
    pub equilibrate: f64,
    /// Time between output rows and frames (default time/100).
    #[serde(skip)]
    pub output_interval: Option<f64>,
    /// Extended XYZ trajectory file, in the output folder.
    #[serde(skip)]
    pub trajectory: Option<String>,
    /// CSV of observables per output interval, in the output folder.
    #[serde(skip)]
    pub observables: Option<String>,
    /// CSV of the speed histogram at the end, beside Maxwell–Boltzmann.
    #[serde(skip)]
    pub histogram: Option<String>,
    /// What the scene should say differently (deprecated keys), for the summary.
    #[serde(skip)]
    pub notes: Vec<String>,
    /// Explicit particles.
    pub particles: Option<Vec<ParticleSpec>>,
    /// Initial state from the last frame of an extended XYZ file.
    pub file: Option<String>,
    /// Check for overlaps at every output (exact, O(N)); default true.
    #[serde(default = "yes")]
    pub check_overlaps: bool,
}

/// `[run]` of an event-driven scene: the keys every engine shares that
/// apply without a time step.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RunSection {
    /// End time of the run, equilibration included (default equilibrate + 10).
    pub until: Option<f64>,
    /// Simulated time run first, without measuring (default 0).
    pub equilibrate: Option<f64>,
    /// Keys of the time-stepped engines, read only to be refused with the reason.
    dt: Option<toml::Value>,
    steps: Option<toml::Value>,
    integrator: Option<toml::Value>,
}

/// `[output]` of an event-driven scene. Files go to `dir` (default
/// `out/<scene name>`) under the names every engine uses.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    pub dir: Option<String>,
    /// Simulated time between rows of observables.csv and frames of
    /// trajectory.xyz (default a hundredth of the measured time).
    pub interval: Option<f64>,
    /// Write observables.csv (default true).
    #[serde(default = "yes")]
    pub observables: bool,
    /// Write trajectory.xyz (default true).
    #[serde(default = "yes")]
    pub trajectory: bool,
    /// Write speeds.csv, the speed histogram at the end (default true).
    #[serde(default = "yes")]
    pub histogram: bool,
    /// Keys of the time-stepped engines, read only to be refused with the reason.
    observables_every: Option<toml::Value>,
    trajectory_every: Option<toml::Value>,
}

impl Default for OutputSection {
    fn default() -> Self {
        Self {
            dir: None,
            interval: None,
            observables: true,
            trajectory: true,
            histogram: true,
            observables_every: None,
            trajectory_every: None,
        }
    }
}

/// Measured time of a scene that gives no length.
const DEFAULT_TIME: f64 = 10.0;

fn default_dim() -> usize {
    3
}
fn yes() -> bool {
    true
}

/// Line where `key = ` is first set, or 1.
fn key_line(text: &str, key: &str) -> usize {
    for (k, l) in text.lines().enumerate() {
        let t = l.trim_start();
        if let Some(rest) = t.strip_prefix(key) {
            if rest.trim_start().starts_with('=') {
                return k + 1;
            }
        }
        if t.starts_with("[[") && t.contains(key) {
            return k + 1;
        }
    }
    1
}

/// The built-in examples: name → scene text (the files under examples/edmd/).
pub const EXAMPLES: &[(&str, &str)] = &[
    ("cube", include_str!("../../../examples/edmd/cube.toml")),
    ("cradle", include_str!("../../../examples/edmd/cradle.toml")),
    (
        "cradle-two",
        include_str!("../../../examples/edmd/cradle-two.toml"),
    ),
    (
        "cradle-symmetric",
        include_str!("../../../examples/edmd/cradle-symmetric.toml"),
    ),
    (
        "cradle-heavy",
        include_str!("../../../examples/edmd/cradle-heavy.toml"),
    ),
    (
        "maxwell2d",
        include_str!("../../../examples/edmd/maxwell2d.toml"),
    ),
    ("eos", include_str!("../../../examples/edmd/eos.toml")),
];

/// The scene text of a built-in example.
pub fn example(name: &str) -> Option<&'static str> {
    EXAMPLES.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

impl Scene {
    /// Parses a scene; `file` names it in error messages.
    pub fn parse(text: &str, file: &str) -> Result<Self, EdmdError> {
        let scene: Scene = toml::from_str(text).map_err(|e| EdmdError::Scene {
            file: file.to_string(),
            line: e
                .span()
                .map_or(1, |s| mote_io::Source::new(file, text).line_of(s.start)),
            message: e.message().trim().to_string(),
        })?;
        let mut scene = scene;
        scene.resolve(text, file)?;
        scene.validate(text, file)?;
        Ok(scene)
    }

    /// Fills the run length and files from `[run]` and `[output]`, or from
    /// the deprecated top-level keys (with a note each); the two together
    /// are refused.
    fn resolve(&mut self, text: &str, file: &str) -> Result<(), EdmdError> {
        let has_table = |name: &str| {
            text.parse::<toml::Table>()
                .is_ok_and(|t| t.contains_key(name))
        };
        let err = |key: &str, message: String| EdmdError::Scene {
            file: file.to_string(),
            line: key_line(text, key),
            message,
        };
        let stepped = [
            ("dt", self.run.dt.is_some(), "[run] until = (end time)"),
            (
                "steps",
                self.run.steps.is_some(),
                "[run] until = (end time)",
            ),
            (
                "integrator",
                self.run.integrator.is_some(),
                "nothing: collisions are predicted exactly",
            ),
            (
                "observables_every",
                self.output.observables_every.is_some(),
                "[output] interval = (simulated time)",
            ),
            (
                "trajectory_every",
                self.output.trajectory_every.is_some(),
                "[output] interval = (simulated time)",
            ),
        ];
        if let Some((key, _, instead)) = stepped.iter().find(|(_, given, _)| *given) {
            return Err(err(
                key,
                format!("`{key}` is for time-stepped engines; event-driven dynamics jumps from collision to collision, with no time step: give {instead}"),
            ));
        }
        let old_run = [
            ("time", self.legacy_time.is_some()),
            ("equilibrate", self.legacy_equilibrate.is_some()),
        ];
        let old_output = [
            ("output_interval", self.legacy_output_interval.is_some()),
            ("trajectory", self.legacy_trajectory.is_some()),
            ("observables", self.legacy_observables.is_some()),
            ("histogram", self.legacy_histogram.is_some()),
        ];
        for (table, keys) in [("run", &old_run[..]), ("output", &old_output[..])] {
            if let Some((key, _)) = keys.iter().find(|(_, given)| *given) {
                if has_table(table) {
                    return Err(err(
                        key,
                        format!("`{key}` (deprecated) and [{table}] cannot be mixed: move it into [{table}] (see docs/edmd.md)"),
                    ));
                }
            }
        }
        if old_run.iter().any(|(_, given)| *given) {
            self.equilibrate = self.legacy_equilibrate.unwrap_or(0.0);
            self.time = self.legacy_time.unwrap_or(DEFAULT_TIME);
            let mut keys = Vec::new();
            if let Some(t) = self.legacy_time {
                keys.push(format!("until = {}", self.equilibrate + t));
            }
            if let Some(e) = self.legacy_equilibrate {
                keys.push(format!("equilibrate = {e}"));
            }
            self.notes.push(format!(
                "note: top-level `time` and `equilibrate` are deprecated and go in one release: write [run] {}",
                keys.join(", ")
            ));
        } else {
            self.equilibrate = self.run.equilibrate.unwrap_or(0.0);
            self.time = match self.run.until {
                Some(until) => {
                    if !(until >= self.equilibrate && until.is_finite()) {
                        return Err(err(
                            "until",
                            format!(
                                "[run] until = {until} must be a time at or after equilibrate = {}",
                                self.equilibrate
                            ),
                        ));
                    }
                    until - self.equilibrate
                }
                None => DEFAULT_TIME,
            };
        }
        if old_output.iter().any(|(_, given)| *given) {
            self.output_interval = self.legacy_output_interval;
            self.trajectory = self.legacy_trajectory.clone();
            self.observables = self.legacy_observables.clone();
            self.histogram = self.legacy_histogram.clone();
            let named: Vec<&str> = old_output
                .iter()
                .filter(|(_, given)| *given)
                .map(|(k, _)| *k)
                .collect();
            self.notes.push(format!(
                "note: top-level `{}` {} deprecated and go{} in one release: write [output] interval = ... and switch observables.csv, trajectory.xyz, speeds.csv on or off there (see docs/edmd.md)",
                named.join("`, `"),
                if named.len() == 1 { "is" } else { "are" },
                if named.len() == 1 { "es" } else { "" },
            ));
        } else {
            let o = &self.output;
            self.output_interval = o.interval;
            self.trajectory = o.trajectory.then(|| "trajectory.xyz".to_string());
            self.observables = o.observables.then(|| "observables.csv".to_string());
            self.histogram = o.histogram.then(|| "speeds.csv".to_string());
        }
        Ok(())
    }

    /// Reads and parses a scene file.
    pub fn read(path: &Path) -> Result<Self, EdmdError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| EdmdError::Io(mote_io::IoError::os(path, e)))?;
        Self::parse(&text, &path.display().to_string())
    }

    fn validate(&self, text: &str, file: &str) -> Result<(), EdmdError> {
        let err = |key: &str, message: String| EdmdError::Scene {
            file: file.to_string(),
            line: key_line(text, key),
            message,
        };
        if self.dimension != 2 && self.dimension != 3 {
            return Err(err(
                "dimension",
                format!(
                    "dimension = {} is not supported; use 2 (disks) or 3 (spheres)",
                    self.dimension
                ),
            ));
        }
        if let Some(b) = &self.box_size {
            if b.len() != self.dimension || b.iter().any(|x| !(*x > 0.0 && x.is_finite())) {
                return Err(err(
                    "box",
                    format!("box must list {} positive lengths", self.dimension),
                ));
            }
        }
        if let BoundarySpec::PerAxis(v) = &self.boundary {
            if v.len() != self.dimension {
                return Err(err(
                    "boundary",
                    format!(
                        "boundary must list {} entries (\"periodic\" or \"wall\")",
                        self.dimension
                    ),
                ));
            }
        }
        if let Some(eta) = self.packing_fraction {
            let max = if self.dimension == 3 { 0.74 } else { 0.9069 };
            if !(eta > 0.0 && eta < max) {
                return Err(err(
                    "packing_fraction",
                    format!("packing_fraction = {eta} must lie in (0, {max})"),
                ));
            }
        }
        for (key, v) in [
            ("radius", self.radius),
            ("mass", self.mass),
            ("temperature", self.temperature),
            ("speed", self.speed),
            ("size_ratio", self.size_ratio),
        ] {
            if let Some(x) = v {
                if !(x > 0.0 && x.is_finite()) {
                    return Err(err(key, format!("{key} = {x} must be positive")));
                }
            }
        }
        if let Some(f) = self.large_fraction {
            if !(0.0..=1.0).contains(&f) {
                return Err(err(
                    "large_fraction",
                    format!("large_fraction = {f} must lie in [0, 1]"),
                ));
            }
        }
        if !(self.time >= 0.0 && self.time.is_finite()) {
            return Err(err(
                if self.legacy_time.is_some() {
                    "time"
                } else {
                    "until"
                },
                format!("the measured time {} must be ≥ 0", self.time),
            ));
        }
        if !(self.equilibrate >= 0.0 && self.equilibrate.is_finite()) {
            return Err(err(
                "equilibrate",
                format!("equilibrate = {} must be ≥ 0", self.equilibrate),
            ));
        }
        if let Some(dt) = self.output_interval {
            if dt.is_nan() || dt <= 0.0 {
                return Err(err(
                    if self.legacy_output_interval.is_some() {
                        "output_interval"
                    } else {
                        "interval"
                    },
                    format!("the output interval {dt} must be positive"),
                ));
            }
        }
        let sources =
            self.n.is_some() as u8 + self.particles.is_some() as u8 + self.file.is_some() as u8;
        if sources != 1 {
            return Err(err(
                "n",
                "give exactly one of `n` (with packing_fraction and/or box), `[[particles]]` or `file`".into(),
            ));
        }
        if self.n == Some(0) {
            return Err(err("n", "n must be at least 1".into()));
        }
        if let Some(n) = self.n {
            // Positions, velocities, radii, times, event, cell and
            // neighbour entries: at least 300 bytes a particle.
            mote_io::system::check_fits(&format!("n = {n}"), n as f64 * 300.0)
                .map_err(|m| err("n", m))?;
        }
        if self.n.is_some() && self.box_size.is_none() && self.packing_fraction.is_none() {
            return Err(err(
                "n",
                "with `n`, give `packing_fraction` or `box` (or both)".into(),
            ));
        }
        if let Some(ps) = &self.particles {
            for (k, p) in ps.iter().enumerate() {
                if p.position.len() != self.dimension
                    || !(p.velocity.is_empty() || p.velocity.len() == self.dimension)
                {
                    return Err(err(
                        "particles",
                        format!(
                            "particle {k}: position and velocity need {} components",
                            self.dimension
                        ),
                    ));
                }
            }
            if self.box_size.is_none() {
                return Err(err("particles", "explicit particles need a `box`".into()));
            }
        }
        Ok(())
    }

    fn boundaries<const D: usize>(&self) -> [Boundary; D] {
        match &self.boundary {
            BoundarySpec::All(b) => [*b; D],
            BoundarySpec::PerAxis(v) => {
                let mut o = [Boundary::Periodic; D];
                o.copy_from_slice(&v[..D]);
                o
            }
        }
    }

    /// Builds the initial system with the given seed. `base` is the folder
    /// relative file names resolve against.
    pub fn build<const D: usize>(&self, seed: u64, base: &Path) -> Result<System<D>, EdmdError> {
        assert_eq!(
            D, self.dimension,
            "build::<D> must match the scene's dimension"
        );
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let boundary = self.boundaries::<D>();
        let periodic = boundary.map(|b| b == Boundary::Periodic);
        let mass = self.mass.unwrap_or(1.0);
        let (size, pos, radii, masses, given_vel): Initial<D> = if let Some(ps) = &self.particles {
            let mut size = [0.0; D];
            size.copy_from_slice(&self.box_size.as_ref().expect("validated")[..D]);
            let r0 = self.radius.unwrap_or(0.5);
            let pos = ps.iter().map(|p| vec_d::<D>(&p.position)).collect();
            let vel = ps
                .iter()
                .map(|p| {
                    if p.velocity.is_empty() {
                        [0.0; D]
                    } else {
                        vec_d::<D>(&p.velocity)
                    }
                })
                .collect();
            let radii = ps.iter().map(|p| p.radius.unwrap_or(r0)).collect();
            let masses = ps.iter().map(|p| p.mass.unwrap_or(mass)).collect();
            (size, pos, radii, masses, Some(vel))
        } else if let Some(f) = &self.file {
            let path = base.join(f);
            let frames = mote_io::xyz::read_frames(&path)?;
            let fr = frames
                .last()
                .ok_or_else(|| EdmdError::Invalid(format!("{}: no frames", path.display())))?;
            let mut size = [0.0; D];
            for d in 0..D {
                size[d] = fr.cell[d][d];
            }
            if let Some(b) = &self.box_size {
                size.copy_from_slice(&b[..D]);
            }
            let pos = fr
                .positions
                .iter()
                .map(|p| {
                    let mut x = [0.0; D];
                    for d in 0..D {
                        x[d] = p[d] - fr.origin[d];
                    }
                    x
                })
                .collect();
            let vel = fr.velocities.iter().map(|v| vec_d::<D>(&v[..D])).collect();
            let n = fr.positions.len();
            let radii = if fr.radii.len() == n {
                fr.radii.clone()
            } else {
                vec![self.radius.unwrap_or(0.5); n]
            };
            let v0: Vec<[f64; D]> = vel;
            let has_v = v0.iter().any(|v| v.iter().any(|x| *x != 0.0));
            (
                size,
                pos,
                radii,
                vec![mass; n],
                if has_v { Some(v0) } else { None },
            )
        } else {
            let n = self.n.expect("validated");
            // radii: monodisperse or bidisperse
            let ratio = self.size_ratio.unwrap_or(1.0);
            let n_large = (self.large_fraction.unwrap_or(0.0) * n as f64).round() as usize;
            let shape: Vec<f64> = (0..n)
                .map(|i| if i < n_large { ratio } else { 1.0 })
                .collect();
            let shape_vol: f64 = shape.iter().map(|s| ball_volume(D, *s)).sum();
            let (size, r0) = match (&self.box_size, self.packing_fraction) {
                (Some(b), Some(eta)) => {
                    let mut size = [0.0; D];
                    size.copy_from_slice(&b[..D]);
                    let vol: f64 = size.iter().product();
                    (size, (eta * vol / shape_vol).powf(1.0 / D as f64))
                }
                (Some(b), None) => {
                    let mut size = [0.0; D];
                    size.copy_from_slice(&b[..D]);
                    (size, self.radius.unwrap_or(0.5))
                }
                (None, Some(eta)) => {
                    let r0 = self.radius.unwrap_or(0.5);
                    let vol = shape_vol * r0.powi(D as i32) / eta;
                    ([vol.powf(1.0 / D as f64); D], r0)
                }
                (None, None) => unreachable!("validated"),
            };
            let radii: Vec<f64> = shape.iter().map(|s| s * r0).collect();
            let pos = match self.placement {
                Placement::Random => random_placement::<D, _>(&radii, size, periodic, &mut rng, 100_000)
                    .ok_or_else(|| {
                        EdmdError::Invalid(format!(
                            "random placement of {n} particles failed at packing fraction {:.4}; use placement = \"fcc\" for dense states",
                            radii.iter().map(|r| ball_volume(D, *r)).sum::<f64>() / size.iter().product::<f64>()
                        ))
                    })?,
                p => {
                    let mut pos = lattice::<D>(n, size, p == Placement::Fcc);
                    if boundary.contains(&Boundary::Wall) || p == Placement::Cubic {
                        // center the lattice sites in their cells
                        let sc = lattice::<D>(n, size, false);
                        if p == Placement::Cubic {
                            pos = sc;
                        }
                        let mut m = [0.0f64; D];
                        for q in &pos {
                            for d in 0..D {
                                m[d] = m[d].max(q[d]);
                            }
                        }
                        let mut lo = [f64::INFINITY; D];
                        for q in &pos {
                            for d in 0..D {
                                lo[d] = lo[d].min(q[d]);
                            }
                        }
                        for q in pos.iter_mut() {
                            for d in 0..D {
                                if !periodic[d] {
                                    q[d] += 0.5 * (size[d] - m[d] - lo[d]);
                                }
                            }
                        }
                    }
                    let dmin = min_pair_distance(&pos, size, periodic);
                    let dmax = 2.0 * radii.iter().cloned().fold(0.0, f64::max);
                    if dmin < dmax {
                        return Err(EdmdError::Invalid(format!(
                            "the lattice does not fit: nearest sites {dmin:.4} apart, particles {dmax:.4} wide; lower n or packing_fraction"
                        )));
                    }
                    pos
                }
            };
            let masses = radii
                .iter()
                .map(|r| mass * (r / r0).powi(D as i32))
                .collect();
            (size, pos, radii, masses, None)
        };
        let vel = match given_vel {
            Some(v) => v,
            None => {
                if let Some(s) = self.speed {
                    fixed_speed_velocities::<D, _>(pos.len(), s, &mut rng)
                } else {
                    thermal_velocities::<D, _>(&masses, self.temperature.unwrap_or(1.0), &mut rng)
                }
            }
        };
        System::new(SimBox { size, boundary }, pos, vel, radii, masses)
    }
}

/// Box, positions, radii, masses and (if given) velocities.
type Initial<const D: usize> = (
    [f64; D],
    Vec<[f64; D]>,
    Vec<f64>,
    Vec<f64>,
    Option<Vec<[f64; D]>>,
);

fn vec_d<const D: usize>(v: &[f64]) -> [f64; D] {
    let mut x = [0.0; D];
    x.copy_from_slice(&v[..D]);
    x
}

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

/// Output destinations and provenance.
pub struct Outputs {
    /// Folder the output files go to.
    pub base: PathBuf,
    /// Folder the scene's own relative paths (`file = ...`) resolve against.
    pub scene_dir: PathBuf,
    pub provenance: mote_io::Provenance,
    /// Write a checkpoint every this many output intervals, from this
    /// template (input, seed, options); the state is added at each write.
    pub checkpoints: Option<(u64, PathBuf, Checkpoint)>,
    /// Continue this checkpoint's run, appending to the files.
    pub resume: Option<Checkpoint>,
}

/// What a checkpoint of an event-driven run carries beside positions and
/// velocities, as `carried` entries: radii (0), masses (1) and the run's
/// bookkeeping (2): E₀, P₀ (3 components), the momentum scale, the largest
/// energy drift so far, the events so far, the counters, and the time
/// measuring began.
mod carried {
    pub const RADII: usize = 0;
    pub const MASSES: usize = 1;
    pub const RUN: usize = 2;
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

fn write_checkpoint<const D: usize>(
    (path, template): (&Path, &Checkpoint),
    sys: &System<D>,
    time: f64,
    k: u64,
    ledger: Ledger<D>,
) -> Result<(), EdmdError> {
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
    let cp = Checkpoint {
        time,
        step: k,
        positions: sys.positions().iter().map(to3).collect(),
        velocities: sys.velocities().iter().map(to3).collect(),
        carried: vec![
            (carried::RADII, sys.radii()),
            (carried::MASSES, sys.masses()),
            (carried::RUN, run),
        ],
        ..template.clone()
    };
    Ok(mote_io::checkpoint::write(path, &cp)?)
}

/// The system, clock offset, output index and ledger a checkpoint holds.
fn resumed<const D: usize>(
    cp: &Checkpoint,
    simbox: SimBox<D>,
) -> Result<(System<D>, f64, u64, Ledger<D>), EdmdError> {
    let bad = |what: &str| EdmdError::Invalid(format!("checkpoint: {what}"));
    let get = |k: usize| {
        cp.carried
            .iter()
            .find(|(i, _)| *i == k)
            .map(|(_, v)| v.clone())
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

/// Runs a scene: builds the system, equilibrates, runs `time` with outputs
/// every `output_interval`; calls `progress(fraction)` now and then.
pub fn run_scene<const D: usize>(
    scene: &Scene,
    seed: u64,
    out: &Outputs,
    mut progress: impl FnMut(f64),
) -> Result<Run, EdmdError> {
    let built = scene.build::<D>(seed, &out.scene_dir)?;
    // A resumed run starts from its checkpoint's (rebuilt) system, clock
    // offset, output index and ledger; a fresh one from the scene.
    let (mut sys, mut t_offset, k_done, ledger) = match &out.resume {
        Some(cp) => resumed(cp, *built.simbox())?,
        None => {
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
            (built, 0.0, 0, ledger)
        }
    };
    let resuming = out.resume.is_some();
    let n = sys.len();
    let (e0, p0, pscale) = (ledger.e0, ledger.p0, ledger.pscale);
    let interval = scene
        .output_interval
        .unwrap_or(scene.time / 100.0)
        .max(1e-300);
    let mut xyz = match &scene.trajectory {
        Some(f) if resuming => Some(mote_io::xyz::XyzWriter::append(
            &out.base.join(f),
            out.provenance.clone(),
        )?),
        Some(f) => Some(mote_io::xyz::XyzWriter::create(
            &out.base.join(f),
            out.provenance.clone(),
        )?),
        None => None,
    };
    let cols: Vec<String> = [
        "time",
        "collisions",
        "collision_rate",
        "mean_free_time",
        "temperature",
        "kinetic_energy",
        "energy_drift",
        "compressibility",
        "pressure",
        "wall_pressure",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let units: Vec<String> = ["t", "1", "1/t", "t", "kT", "E", "1", "1", "E/V", "E/V"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut csv = match &scene.observables {
        Some(f) if resuming => Some(mote_io::csv::CsvWriter::append(
            &out.base.join(f),
            cols.len(),
        )?),
        Some(f) => Some(mote_io::csv::CsvWriter::create(
            &out.base.join(f),
            &out.provenance,
            &cols,
            &units,
        )?),
        None => None,
    };
    let mut result = Run {
        dimension: D,
        n,
        packing_fraction: sys.packing_fraction(),
        seed,
        ..Run::default()
    };
    let start = Instant::now();
    let total = scene.equilibrate + scene.time;
    let mut events = ledger.events;
    // equilibration, in chunks for progress
    let chunks = 20;
    for k in 1..=chunks {
        if scene.equilibrate <= 0.0 || resuming {
            break;
        }
        events += sys.run_until(scene.equilibrate * k as f64 / chunks as f64);
        progress(sys.time() / total.max(1e-300));
        if let Some(signal) = mote_io::system::stop_requested() {
            return Err(EdmdError::Interrupted {
                signal,
                time: sys.time(),
            });
        }
    }
    let t0 = if resuming {
        ledger.t0
    } else {
        sys.reset_counters();
        sys.time()
    };
    let mut drift: f64 = ledger.drift;
    // Times in the files are global: the clock offset of the last rebuild
    // plus the system's own (the offset is 0 in a run without checkpoints).
    let mut write =
        |sys: &mut System<D>, drift: &mut f64, t_offset: f64| -> Result<(), EdmdError> {
            let e = sys.kinetic_energy();
            *drift = drift.max(((e - e0) / e0).abs());
            if let Some(w) = xyz.as_mut() {
                let mut f = frame(sys);
                f.time = t_offset + sys.time();
                w.write(&f)?;
            }
            if let Some(c) = csv.as_mut() {
                let dt = t_offset + sys.time() - t0;
                let (rate, mft, z, p) = if dt > 0.0 {
                    (
                        sys.collision_rate(),
                        sys.mean_free_time(),
                        sys.compressibility(),
                        sys.pressure(),
                    )
                } else {
                    (f64::NAN, f64::NAN, f64::NAN, f64::NAN)
                };
                c.row(&[
                    t_offset + sys.time(),
                    sys.counters().collisions as f64,
                    rate,
                    mft,
                    sys.temperature(),
                    e,
                    (e - e0) / e0,
                    z,
                    p,
                    sys.wall_pressure(),
                ])?;
            }
            if scene.check_overlaps {
                if let Some((i, j, gap)) = sys.find_overlap(1e-9) {
                    return Err(EdmdError::Invalid(format!(
                    "overlap at t = {}: particles {i} and {j} (distance/contact − 1 = {gap:.3e})",
                    sys.time()
                )));
                }
            }
            Ok(())
        };
    if !resuming {
        write(&mut sys, &mut drift, t_offset)?;
    }
    let mut k = k_done + 1;
    loop {
        let target = (t0 + k as f64 * interval).min(t0 + scene.time);
        events += sys.run_until(target - t_offset);
        write(&mut sys, &mut drift, t_offset)?;
        progress((t_offset + sys.time()) / total.max(1e-300));
        if target >= t0 + scene.time {
            break;
        }
        let signal = mote_io::system::stop_requested();
        if let Some((every, path, template)) = &out.checkpoints {
            if k % (*every).max(1) == 0 || signal.is_some() {
                t_offset += sys.time();
                sys = rebuild(&sys)?;
                let ledger = Ledger {
                    e0,
                    p0,
                    pscale,
                    drift,
                    events,
                    t0,
                };
                write_checkpoint((path, template), &sys, t_offset, k, ledger)?;
            }
        }
        if let Some(signal) = signal {
            // The writers flush as they drop.
            return Err(EdmdError::Interrupted {
                signal,
                time: t_offset + sys.time(),
            });
        }
        k += 1;
    }
    result.wall_seconds = start.elapsed().as_secs_f64();
    let c = *sys.counters();
    result.collisions = c.collisions;
    result.wall_hits = c.wall_hits;
    result.events = events;
    result.simulated_time = scene.time;
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
    result.energy_drift = drift;
    let p1 = sys.momentum();
    // momentum is conserved along periodic axes only (walls take it up)
    result.momentum_drift = (0..D)
        .filter(|&d| sys.simbox().boundary[d] == Boundary::Periodic)
        .map(|d| (p1[d] - p0[d]).abs())
        .fold(f64::NAN, f64::max)
        / pscale;
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
        let mut w =
            mote_io::csv::CsvWriter::create(&out.base.join(f), &out.provenance, &cols, &[])?;
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
    let mut last = frame(&sys);
    last.time = t_offset + sys.time();
    result.final_frame = Some(last);
    if n <= 1000 {
        result.final_velocities = sys.velocities().iter().map(to3).collect();
    }
    for f in [&scene.trajectory, &scene.observables]
        .into_iter()
        .flatten()
    {
        result.outputs.push(out.base.join(f));
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SYSTEM: &str = "dimension = 3\nn = 500\npacking_fraction = 0.2\n";

    /// The shared `[run]`/`[output]` sections and the first format's
    /// top-level keys describe the same run; only the old keys carry notes.
    #[test]
    fn shared_sections_and_deprecated_keys_give_the_same_run() {
        let new = Scene::parse(
            &format!("{SYSTEM}[run]\nuntil = 6.0\nequilibrate = 2.0\n[output]\ninterval = 0.5\ntrajectory = false\nhistogram = false\n"),
            "new.toml",
        )
        .unwrap();
        let old = Scene::parse(
            &format!("{SYSTEM}equilibrate = 2.0\ntime = 4.0\noutput_interval = 0.5\nobservables = \"observables.csv\"\n"),
            "old.toml",
        )
        .unwrap();
        for s in [&new, &old] {
            assert_eq!((s.equilibrate, s.time), (2.0, 4.0));
            assert_eq!(s.output_interval, Some(0.5));
            assert_eq!(s.observables.as_deref(), Some("observables.csv"));
            assert_eq!(
                (s.trajectory.as_deref(), s.histogram.as_deref()),
                (None, None)
            );
        }
        assert!(new.notes.is_empty());
        assert_eq!(old.notes.len(), 2, "{:?}", old.notes);
        assert!(old.notes[0].contains("[run] until = 6, equilibrate = 2"));
    }

    #[test]
    fn defaults_write_every_file_for_ten_time_units() {
        let s = Scene::parse(SYSTEM, "s.toml").unwrap();
        assert_eq!(
            (s.equilibrate, s.time, s.output_interval),
            (0.0, 10.0, None)
        );
        assert_eq!(s.trajectory.as_deref(), Some("trajectory.xyz"));
        assert_eq!(s.observables.as_deref(), Some("observables.csv"));
        assert_eq!(s.histogram.as_deref(), Some("speeds.csv"));
    }

    #[test]
    fn mixing_old_keys_and_shared_sections_is_refused_at_the_old_key() {
        let text = format!("{SYSTEM}time = 4.0\n[run]\nuntil = 5.0\n");
        let e = Scene::parse(&text, "mixed.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "mixed.toml:4: `time` (deprecated) and [run] cannot be mixed: move it into [run] (see docs/edmd.md)"
        );
        let text = format!("{SYSTEM}[run]\ndt = 0.1\n");
        let e = Scene::parse(&text, "stepped.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "stepped.toml:5: `dt` is for time-stepped engines; event-driven dynamics jumps from collision to collision, with no time step: give [run] until = (end time)"
        );
        let text = format!("{SYSTEM}[run]\nuntil = 1.0\nequilibrate = 2.0\n");
        let e = Scene::parse(&text, "early.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "early.toml:5: [run] until = 1 must be a time at or after equilibrate = 2"
        );
    }
}
