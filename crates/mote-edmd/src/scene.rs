//! Scene settings (the TOML a user writes), built into a [`System`]; the
//! run itself is in [`crate::run`].
//!
//! Every key is documented in docs/edmd.md. Errors in a scene file come back
//! as `file:line: message` ([`EdmdError::Scene`]).

use std::path::Path;

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;

use crate::init::{
    ball_volume, fixed_speed_velocities, lattice, min_pair_distance, random_placement,
    thermal_velocities,
};

use mote_run::scene::{BoxTable, OutputTable, RunTable};
use toml::Spanned;

use crate::system::{Boundary, SimBox, System};
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

/// An event-driven scene: the envelope every engine shares (`title`,
/// `seed`, `[run]`, `[output]`, `[box]`, `[[from_file]]`) and the hard
/// spheres or disks of `[event_driven]`. What fixes the particles: `n`
/// (with `packing_fraction` and/or `[box]`), `[[event_driven.particles]]`,
/// or `[[from_file]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// One line saying what the scene shows (listed by `mote examples`).
    pub title: Option<String>,
    /// Random seed (the command line's `--seed` wins).
    pub seed: Option<u64>,
    /// `[run]`: `until` and `equilibrate` (the time-stepped keys are refused).
    #[serde(default)]
    pub run: RunTable,
    /// `[output]`: the files, as for every engine (`interval` and the
    /// files on or off; the step counts are refused).
    #[serde(default)]
    pub output: OutputTable,
    /// `[box]`, as every engine spells it (`lo` must be the origin).
    #[serde(rename = "box")]
    bounds: Option<Spanned<BoxTable>>,
    /// `[[from_file]]`, as every engine spells it: one file, and `frame`
    /// to pick one (negative counts from the end).
    #[serde(default)]
    from_file: Vec<FileStart>,
    /// `[event_driven]`: what the spheres are and how they start.
    #[serde(rename = "event_driven")]
    pub spheres: Spheres,
    /// Box lengths per axis, from `[box] hi`.
    #[serde(skip)]
    pub box_size: Option<Vec<f64>>,
    /// Walls or periodic faces per axis, from `[box] periodic`.
    #[serde(skip)]
    pub boundary: BoundarySpec,
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
    /// Initial state from a frame of a trajectory file (.xyz, .dump,
    /// .gsd, .vtu/.vtp/.pvd), relative to the scene file: `[[from_file]]`.
    #[serde(skip)]
    pub file: Option<String>,
    /// The frame of `file` (default the last).
    #[serde(skip)]
    pub file_frame: Option<i64>,
    /// Where the scene names the file (scene file, line), for messages
    /// about the file that are not about one of its own lines.
    #[serde(skip)]
    file_named_at: Option<(String, usize)>,
    /// Where the scene sets the box and the particles (`[box] hi`, else
    /// `packing_fraction`, else `n`), for messages about the state they
    /// make (a box too small for the spheres, say).
    #[serde(skip)]
    state_named_at: Option<(String, usize)>,
    /// Where the scene sets the run's end (`until`, else the state's line),
    /// for a run too long to start without `--force`.
    #[serde(skip)]
    until_named_at: Option<(String, usize)>,
}

/// `[event_driven]`: the hard spheres or disks. Every key is optional;
/// what fixes the particles is checked with the rest of the scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spheres {
    /// 2 (disks) or 3 (spheres). Default 3.
    #[serde(default = "default_dim")]
    pub dimension: usize,
    /// Number of particles (with `placement`).
    pub n: Option<usize>,
    /// Packing fraction η = Σ v_i / V; sets the box (cube/square) when
    /// `[box] hi` is missing, or the radius when both `hi` and `n` are given.
    pub packing_fraction: Option<f64>,
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
    /// Explicit particles.
    pub particles: Option<Vec<ParticleSpec>>,
    /// Check for overlaps at every output (exact, O(N)); default true.
    #[serde(default = "yes")]
    pub check_overlaps: bool,
    /// The first spellings of the box and the initial file, and the keys
    /// every engine shares, read only to be refused with the spelling
    /// every engine uses ([`Spheres::refuse_misplaced`]).
    #[serde(rename = "box")]
    old_box: Option<Spanned<toml::Value>>,
    #[serde(rename = "boundary")]
    old_boundary: Option<Spanned<toml::Value>>,
    #[serde(rename = "file")]
    old_file: Option<Spanned<toml::Value>>,
    #[serde(rename = "seed")]
    shared_seed: Option<Spanned<toml::Value>>,
    #[serde(rename = "title")]
    shared_title: Option<Spanned<toml::Value>>,
}

/// The spelling of the box every engine uses.
pub const BOX_SPELLING: &str = "the box is a table of its own, spelled as every engine spells it: [box] hi = [lengths], periodic = [true/false per axis] (false: hard walls)";
/// The spelling of a start from a file every engine uses.
pub const FILE_SPELLING: &str = "a scene starts from a file as every engine spells it: [[from_file]] file = \"...\" (frame = N picks a frame)";

impl Spheres {
    /// Refuses the first spellings of the box and the initial file, and
    /// the shared keys, inside `[event_driven]`, at their line.
    fn refuse_misplaced(&self, src: &mote_io::Source) -> Result<(), mote_io::ParseError> {
        let shared = "is shared by every engine: give it at the top level, outside [event_driven]";
        for (key, value, why) in [
            ("box", &self.old_box, BOX_SPELLING),
            ("boundary", &self.old_boundary, BOX_SPELLING),
            ("file", &self.old_file, FILE_SPELLING),
            ("seed", &self.shared_seed, shared),
            ("title", &self.shared_title, shared),
        ] {
            if let Some(v) = value {
                return Err(src.error(v.span(), format!("`{key}` {why}")));
            }
        }
        Ok(())
    }
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

/// Per-axis boundary: one for all axes or a list.
#[derive(Debug, Clone)]
pub enum BoundarySpec {
    All(Boundary),
    PerAxis(Vec<Boundary>),
}

impl Default for BoundarySpec {
    fn default() -> Self {
        BoundarySpec::All(Boundary::Periodic)
    }
}

/// `[[from_file]]` in an event-driven scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileStart {
    file: String,
    frame: Option<i64>,
}

/// The keys of `[event_driven]`: what the hard spheres or disks are and
/// how they start. Everything else a scene says is shared by every engine.
pub const EVENT_DRIVEN_KEYS: &[&str] = &[
    "dimension",
    "n",
    "packing_fraction",
    "radius",
    "mass",
    "large_fraction",
    "size_ratio",
    "placement",
    "temperature",
    "speed",
    "particles",
    "check_overlaps",
];

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
    mote_io::Source::new("", text).key_line(key)
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
        let source = mote_io::Source::new(file, text);
        source.finite_numbers()?;
        let mut scene: Scene =
            toml::from_str(text).map_err(|e| source.parser_error(e.span(), e.message()))?;
        scene.spheres.refuse_misplaced(&source)?;
        if let Some(b) = scene.bounds.take() {
            scene.apply_box(&b, &source)?;
        }
        scene.resolve(text, file)?;
        scene.validate(text, file)?;
        Ok(scene)
    }

    /// Sets the box lengths and walls from `[box]`, checked against the
    /// dimension: hard spheres live in [0, L), so `lo` is the origin or
    /// left out; a non-periodic axis has hard walls.
    fn apply_box(
        &mut self,
        table: &Spanned<BoxTable>,
        src: &mote_io::Source,
    ) -> Result<(), mote_io::ParseError> {
        let d = self.spheres.dimension;
        let b = table.get_ref();
        if d == 2 || d == 3 {
            b.axes(*src, d)?;
        }
        if let Some(hi) = &b.hi {
            if hi.get_ref().iter().any(|x| !(*x > 0.0 && x.is_finite())) {
                return Err(src.error(
                    hi.span(),
                    format!("[box] hi must list {d} positive lengths (dimension = {d})"),
                ));
            }
        }
        if let Some(lo) = &b.lo {
            if lo.get_ref().iter().any(|x| *x != 0.0) {
                return Err(src.error(
                    lo.span(),
                    format!("[box] lo: hard spheres live in a box from the origin: lo = {:?} (or leave it out)", vec![0.0; d]),
                ));
            }
        }
        self.box_size = b.hi.as_ref().map(|hi| hi.get_ref().clone());
        self.boundary = BoundarySpec::PerAxis(
            b.periodic(d)
                .iter()
                .map(|p| {
                    if *p {
                        Boundary::Periodic
                    } else {
                        Boundary::Wall
                    }
                })
                .collect(),
        );
        Ok(())
    }

    /// Fills the run length and files from `[run]` and `[output]`.
    fn resolve(&mut self, text: &str, file: &str) -> Result<(), EdmdError> {
        let source = mote_io::Source::new(file, text);
        let err = |key: &str, message: String| EdmdError::Scene {
            file: file.to_string(),
            line: key_line(text, key),
            message,
        };
        self.file_named_at = Some((file.to_string(), key_line(text, "from_file")));
        let said = |key: &str| {
            text.lines().any(|l| {
                l.trim_start()
                    .strip_prefix(key)
                    .is_some_and(|r| r.trim_start().starts_with('='))
            })
        };
        let state_key = ["hi", "packing_fraction", "n"]
            .into_iter()
            .find(|k| said(k))
            .unwrap_or("n");
        self.state_named_at = Some((file.to_string(), key_line(text, state_key)));
        let end_key = if said("until") { "until" } else { state_key };
        self.until_named_at = Some((file.to_string(), key_line(text, end_key)));
        match self.from_file.as_slice() {
            [] => {}
            [start] => {
                self.file = Some(start.file.clone());
                self.file_frame = start.frame;
            }
            _ => {
                return Err(err(
                    "from_file",
                    "an event-driven scene starts from one file: one [[from_file]]".into(),
                ))
            }
        }
        const NO_STEP: &str =
            "event-driven dynamics jumps from collision to collision, with no time step";
        self.run.refuse(
            source,
            &[
                ("dt", &format!("{NO_STEP}: give [run] until = (end time)")),
                (
                    "steps",
                    &format!("{NO_STEP}: give [run] until = (end time)"),
                ),
                (
                    "integrator",
                    "collisions are predicted exactly; there is no integrator to choose",
                ),
                (
                    "centre_of_mass",
                    "hard spheres keep the frame they are placed in",
                ),
            ],
        )?;
        let stepped = format!("{NO_STEP}: give [output] interval = (simulated time)");
        self.output.refuse(
            source,
            &[
                ("observables_every", &stepped),
                ("trajectory_every", &stepped),
                (
                    "inspect",
                    "it adds columns of point particles to a time-stepped run's table",
                ),
                (
                    "pressure_tensor",
                    "hard spheres' pressure is the collision virial, in the summary (Z = PV/NkT)",
                ),
            ],
        )?;
        self.equilibrate = self.run.equilibrate.as_ref().map_or(0.0, |e| e.value);
        self.time = match &self.run.until {
            Some(until) => {
                // After the equilibration, as `--until` must be: the same
                // value is taken or refused by either way in.
                if !(until.value > self.equilibrate && until.value.is_finite()) {
                    return Err(until
                        .error(
                            source,
                            format!(
                                "[run] until = {} must be a time after equilibrate = {}",
                                until.value, self.equilibrate
                            ),
                        )
                        .into());
                }
                until.value - self.equilibrate
            }
            None => DEFAULT_TIME,
        };
        let o = &self.output;
        self.output_interval = o.interval.as_ref().map(|i| i.value);
        let format = o.trajectory_format(source)?;
        self.trajectory = o
            .writes(&o.trajectory)
            .then(|| format!("trajectory.{}", format.extension()));
        self.observables = o
            .writes(&o.observables)
            .then(|| "observables.csv".to_string());
        self.histogram = o.writes(&o.histogram).then(|| "speeds.csv".to_string());
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
        if self.spheres.dimension != 2 && self.spheres.dimension != 3 {
            return Err(err(
                "dimension",
                format!(
                    "dimension = {} is not supported; use 2 (disks) or 3 (spheres)",
                    self.spheres.dimension
                ),
            ));
        }
        if let Some(eta) = self.spheres.packing_fraction {
            let max = if self.spheres.dimension == 3 {
                0.74
            } else {
                0.9069
            };
            if !(eta > 0.0 && eta < max) {
                return Err(err(
                    "packing_fraction",
                    format!("packing_fraction = {eta} must lie in (0, {max})"),
                ));
            }
        }
        for (key, v) in [
            ("radius", self.spheres.radius),
            ("mass", self.spheres.mass),
            ("temperature", self.spheres.temperature),
            ("speed", self.spheres.speed),
            ("size_ratio", self.spheres.size_ratio),
        ] {
            if let Some(x) = v {
                if !(x > 0.0 && x.is_finite()) {
                    return Err(err(key, format!("{key} = {x} must be positive")));
                }
            }
        }
        if let Some(f) = self.spheres.large_fraction {
            if !(0.0..=1.0).contains(&f) {
                return Err(err(
                    "large_fraction",
                    format!("large_fraction = {f} must lie in [0, 1]"),
                ));
            }
        }
        if !(self.time >= 0.0 && self.time.is_finite()) {
            return Err(err(
                "until",
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
                    "interval",
                    format!("the output interval {dt} must be positive"),
                ));
            }
        }
        let sources = self.spheres.n.is_some() as u8
            + self.spheres.particles.is_some() as u8
            + self.file.is_some() as u8;
        if sources != 1 {
            return Err(err(
                "n",
                "give exactly one of `n` (with packing_fraction and/or box), `[[particles]]` or `file`".into(),
            ));
        }
        if self.spheres.n == Some(0) {
            return Err(err("n", "n must be at least 1".into()));
        }
        if let Some(n) = self.spheres.n {
            // Positions, velocities, radii, times, event, cell and
            // neighbour entries: at least 300 bytes a particle.
            mote_io::system::check_fits(&format!("n = {n}"), n as f64 * 300.0)
                .map_err(|m| err("n", m))?;
        }
        if self.spheres.n.is_some()
            && self.box_size.is_none()
            && self.spheres.packing_fraction.is_none()
        {
            return Err(err(
                "n",
                "with `n`, give `packing_fraction` or `box` (or both)".into(),
            ));
        }
        if let Some(ps) = &self.spheres.particles {
            for (k, p) in ps.iter().enumerate() {
                if p.position.len() != self.spheres.dimension
                    || !(p.velocity.is_empty() || p.velocity.len() == self.spheres.dimension)
                {
                    return Err(err(
                        "particles",
                        format!(
                            "particle {k}: position and velocity need {} components",
                            self.spheres.dimension
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

    /// Refuses, unless `force`d, a run whose events the system expects
    /// ([`System::expected_events`]) over the scene's equilibration and
    /// measured time exceed [`mote_run::MAX_STEPS`]: an event is the
    /// event-driven engine's step, and so many are most likely a mass,
    /// temperature, size ratio or end time mistyped (a mass of 10⁻³⁰⁰
    /// asks for 10¹⁵⁰ events and would never end).
    pub fn check_run_length<const D: usize>(
        &self,
        system: &System<D>,
        force: bool,
    ) -> Result<(), EdmdError> {
        let events = system.expected_events(self.equilibrate + self.time);
        if force || events <= mote_run::MAX_STEPS as f64 {
            return Ok(());
        }
        let message = format!(
            "the run to t = {} would take about {events:.1e} events (collisions and neighbour-list \
             renewals at the speeds and sizes the scene gives): more than {}, which is most likely \
             a mass, temperature, size ratio or end time mistyped; give --force to run them",
            self.equilibrate + self.time,
            mote_run::MAX_STEPS
        );
        Err(match &self.until_named_at {
            Some((file, line)) => EdmdError::Scene {
                file: file.clone(),
                line: *line,
                message,
            },
            None => EdmdError::Invalid(message),
        })
    }

    /// Builds the initial system with the given seed. `base` is the folder
    /// relative file names resolve against.
    pub fn build<const D: usize>(&self, seed: u64, base: &Path) -> Result<System<D>, EdmdError> {
        assert_eq!(
            D, self.spheres.dimension,
            "build::<D> must match the scene's dimension"
        );
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let boundary = self.boundaries::<D>();
        let periodic = boundary.map(|b| b == Boundary::Periodic);
        let mass = self.spheres.mass.unwrap_or(1.0);
        let (size, pos, radii, masses, given_vel): Initial<D> = if let Some(ps) =
            &self.spheres.particles
        {
            let mut size = [0.0; D];
            size.copy_from_slice(&self.box_size.as_ref().expect("validated")[..D]);
            let r0 = self.spheres.radius.unwrap_or(0.5);
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
            // A message about the file as a whole points at the scene line
            // that names it; one about a line of the file names that line.
            let at = |message: String| match &self.file_named_at {
                Some((file, line)) => EdmdError::Scene {
                    file: file.clone(),
                    line: *line,
                    message,
                },
                None => EdmdError::Invalid(message),
            };
            let frames = mote_io::trajectory::read_frames(&path).map_err(|e| match e {
                mote_io::IoError::Parse(p) if p.line > 0 => EdmdError::Io(p.into()),
                other => at(other.to_string()),
            })?;
            let fr = mote_io::trajectory::pick(&frames, self.file_frame, &path).map_err(at)?;
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
                vec![self.spheres.radius.unwrap_or(0.5); n]
            };
            let v0: Vec<[f64; D]> = vel;
            let has_v = v0.iter().any(|v| v.iter().any(|x| *x != 0.0));
            let masses = if fr.masses.len() == n && self.spheres.mass.is_none() {
                fr.masses.clone()
            } else {
                vec![mass; n]
            };
            (
                size,
                pos,
                radii,
                masses,
                if has_v { Some(v0) } else { None },
            )
        } else {
            let n = self.spheres.n.expect("validated");
            // radii: monodisperse or bidisperse
            let ratio = self.spheres.size_ratio.unwrap_or(1.0);
            let n_large = (self.spheres.large_fraction.unwrap_or(0.0) * n as f64).round() as usize;
            let shape: Vec<f64> = (0..n)
                .map(|i| if i < n_large { ratio } else { 1.0 })
                .collect();
            let shape_vol: f64 = shape.iter().map(|s| ball_volume(D, *s)).sum();
            let (size, r0) = match (&self.box_size, self.spheres.packing_fraction) {
                (Some(b), Some(eta)) => {
                    let mut size = [0.0; D];
                    size.copy_from_slice(&b[..D]);
                    let vol: f64 = size.iter().product();
                    (size, (eta * vol / shape_vol).powf(1.0 / D as f64))
                }
                (Some(b), None) => {
                    let mut size = [0.0; D];
                    size.copy_from_slice(&b[..D]);
                    (size, self.spheres.radius.unwrap_or(0.5))
                }
                (None, Some(eta)) => {
                    let r0 = self.spheres.radius.unwrap_or(0.5);
                    let vol = shape_vol * r0.powi(D as i32) / eta;
                    ([vol.powf(1.0 / D as f64); D], r0)
                }
                (None, None) => unreachable!("validated"),
            };
            let radii: Vec<f64> = shape.iter().map(|s| s * r0).collect();
            let pos = match self.spheres.placement {
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
                if let Some(s) = self.spheres.speed {
                    fixed_speed_velocities::<D, _>(pos.len(), s, &mut rng)
                } else {
                    thermal_velocities::<D, _>(
                        &masses,
                        self.spheres.temperature.unwrap_or(1.0),
                        &mut rng,
                    )
                }
            }
        };
        System::new(SimBox { size, boundary }, pos, vel, radii, masses).map_err(|e| {
            match (e, &self.state_named_at) {
                (EdmdError::Invalid(message), Some((file, line))) => EdmdError::Scene {
                    file: file.clone(),
                    line: *line,
                    message,
                },
                (e, _) => e,
            }
        })
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

pub use crate::run::{frame, Run};

#[cfg(test)]
mod tests {
    use super::*;

    const SYSTEM: &str = "[event_driven]\ndimension = 3\nn = 500\npacking_fraction = 0.2\n";

    /// `[run]` and `[output]` set the measured time, the equilibration
    /// and the files.
    #[test]
    fn the_shared_sections_set_the_run_and_its_files() {
        let s = Scene::parse(
            &format!("{SYSTEM}[run]\nuntil = 6.0\nequilibrate = 2.0\n[output]\ninterval = 0.5\ntrajectory = false\nhistogram = false\n"),
            "new.toml",
        )
        .unwrap();
        assert_eq!((s.equilibrate, s.time), (2.0, 4.0));
        assert_eq!(s.output_interval, Some(0.5));
        assert_eq!(s.observables.as_deref(), Some("observables.csv"));
        assert_eq!(
            (s.trajectory.as_deref(), s.histogram.as_deref()),
            (None, None)
        );
        assert_eq!(
            (s.spheres.dimension, s.spheres.n, s.spheres.packing_fraction),
            (3, Some(500), Some(0.2))
        );
    }

    /// Errors inside `[event_driven]` name their line; the first
    /// spellings of the box and the file, and the shared keys, are refused
    /// there with the spelling every engine uses.
    #[test]
    fn errors_inside_event_driven_name_their_line() {
        let e = |text: &str| Scene::parse(text, "bad.toml").unwrap_err().to_string();
        assert_eq!(
            e(&format!("{SYSTEM}placement = \"hexagonal\"\n")),
            "bad.toml:5: unknown variant `hexagonal`, expected one of `fcc`, `cubic`, `random`"
        );
        assert_eq!(
            e(&format!("{SYSTEM}seed = 3\n")),
            "bad.toml:5: `seed` is shared by every engine: give it at the top level, outside [event_driven]"
        );
        assert!(e(&format!("{SYSTEM}\ndensity = 3\n"))
            .starts_with("bad.toml:6: unknown field `density`, expected one of `dimension`, `n`,"));
        assert_eq!(
            e(&format!("{SYSTEM}box = [10.0, 10.0, 10.0]\n")),
            format!("bad.toml:5: `box` {BOX_SPELLING}")
        );
        assert_eq!(
            e(&format!("{SYSTEM}file = \"start.xyz\"\n")),
            format!("bad.toml:5: `file` {FILE_SPELLING}")
        );
        assert_eq!(
            e(&format!("{SYSTEM}[box]\nhi = [1.0, 1.0]\n")),
            "bad.toml:6: [box] hi must list 3 entries, one per axis (found 2)"
        );
        assert_eq!(
            e(&format!("{SYSTEM}[box]\nlo = [1.0, 0.0, 0.0]\nhi = [9.0, 9.0, 9.0]\n")),
            "bad.toml:6: [box] lo: hard spheres live in a box from the origin: lo = [0.0, 0.0, 0.0] (or leave it out)"
        );
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
    fn time_stepped_keys_are_refused_with_the_reason() {
        let text = format!("{SYSTEM}[run]\ndt = 0.1\n");
        let e = Scene::parse(&text, "stepped.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "stepped.toml:6: [run] dt: event-driven dynamics jumps from collision to collision, with no time step: give [run] until = (end time)"
        );
        let text = format!("{SYSTEM}[output]\ntrajectory_every = 10\n");
        let e = Scene::parse(&text, "stepped.toml").unwrap_err().to_string();
        assert!(
            e.starts_with("stepped.toml:6: [output] trajectory_every: event-driven dynamics jumps from collision to collision, with no time step: give [output] interval"),
            "{e}"
        );
        let text = format!("{SYSTEM}[run]\nuntil = 1.0\nequilibrate = 2.0\n");
        let e = Scene::parse(&text, "early.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "early.toml:6: [run] until = 1 must be a time after equilibrate = 2"
        );
    }
}
