//! Packings by growing spheres (Lubachevsky–Stillinger on the event-driven
//! engine, `mote_edmd::pack`): one run for both ways in, the options of
//! `mote pack` and a scene's `[packing]` table under `mote run`.
//!
//! The packing is written as extended XYZ with every number exact
//! (`packing.xyz`), with φ and the reduced pressure per growth window
//! (`packing.csv`) and a POV-Ray scene (`packing.pov`) beside it.

use std::path::{Path, PathBuf};
use std::time::Duration;

use std::cell::RefCell;

use mote_edmd::pack::{Finish, PackSettings, SizeSpec};
use mote_io::checkpoint::Checkpoint;
use mote_io::trajectory::Format;
use serde::{Deserialize, Serialize};

use crate::error::{refuse, FrontError};
use crate::{Ending, Input, Monitor, Outcome, RunOptions};

/// The methods of [`crate::runner::EngineRun`] both packing methods take
/// from their request ([`PackRun`], `self.job`): its seed and folder, its
/// files (the packing is written once, at its end: no trajectory), its
/// checkpoints' options, its opening line; a packing ends when it stops
/// by itself, not at a step.
macro_rules! pack_run_methods {
    () => {
        fn scene_seed(&self) -> Option<u64> {
            self.job.scene_seed
        }

        fn seed_chosen(&self) -> bool {
            self.job.seed_chosen
        }

        fn scene_dir(&self) -> Option<&String> {
            self.job.scene_dir.as_ref()
        }

        fn writes_files(&self) -> bool {
            self.job.writes
        }

        fn trajectory(
            &self,
        ) -> Result<Option<(String, mote_io::trajectory::Format, u64)>, FrontError> {
            Ok(None)
        }

        fn checkpoint_options(&self, _: &Self::State) -> Vec<(String, String)> {
            self.job.checkpoint_options()
        }

        fn last_step(&self, _: &Self::State) -> u64 {
            u64::MAX
        }

        fn headline(&self, label: &str, state: &Self::State) -> String {
            match &self.job.headline {
                Some(h) => h.clone(),
                None => format!("mote run {label}: {}", self.opening(state)),
            }
        }
    };
}

mod growth;
pub(crate) mod soft;

pub use growth::Grown;
use growth::Growth;
use soft::Soft;

/// What a packing is asked for, by either way in. The keys of a scene's
/// `[packing]` table; `mote pack` spells them as options (`--dim` for
/// `dimension`, `--no-jam` for `jam = false`, `-` for `_`).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PackingSpec {
    /// Number of particles (ignored with `dist = "file:PATH"`).
    pub n: usize,
    /// 3 (spheres) or 2 (disks).
    pub dimension: usize,
    /// `mono`, `bi:RATIO:FRACTION`, `lognormal:SIGMA` or `file:PATH` (one
    /// radius per line, relative to the scene's folder).
    pub dist: String,
    /// Growth rate Γ = (1/v_th) d⟨d⟩/dt.
    pub rate: f64,
    /// Stop when the reduced pressure PV/(NkT) passes this.
    pub max_pressure: f64,
    /// Stop at this packing fraction.
    pub phi: Option<f64>,
    /// Stop after this many pair collisions.
    pub max_collisions: Option<u64>,
    /// Stop after this many seconds of wall-clock time.
    pub time_limit: Option<f64>,
    /// Hard walls on these axes (`"z"`, `"xyz"`); periodic elsewhere.
    pub walls: String,
    /// Collisions per particle between rescalings and pressure windows.
    pub rescale_every: f64,
    /// The quasi-static finish that jams the packing (false: grow at Γ to
    /// the pressure threshold, spheropack's `Pressure` criterion).
    pub jam: bool,
    /// The finish starts when the pressure passes this.
    pub jam_start: f64,
    /// Fraction of the estimated gap to jamming closed per finishing step.
    pub jam_step: f64,
    /// Relaxation windows at fixed size between finishing steps.
    pub jam_relax: usize,
    /// Packing fraction of the random start.
    pub phi_start: f64,
    /// Relative gap tolerance of contacts in the summary (default
    /// 1000/max_pressure).
    pub tol: Option<f64>,
    /// Grow from the last frame of this trajectory (`.xyz`, `.dump`,
    /// `.gsd`, `.vtp`/`.vtu`/`.pvd`, relative to the scene's folder): its
    /// positions, radii and orthogonal box (`n`, `dist` and `phi_start` are
    /// then ignored).
    pub start: Option<String>,
    /// `hard` (growth on the event-driven engine) or `soft` (the SP
    /// method: Hertzian spheres under a barostat, [`mote_md::soft_pack`]).
    pub method: String,
    /// Soft method: the lowest pressure P/K; the barostat holds 10⁻² …
    /// 10⁻⁴, the jamming finish minimises on down to this.
    pub min_pressure: f64,
}

impl Default for PackingSpec {
    fn default() -> Self {
        Self {
            n: 1000,
            dimension: 3,
            dist: "mono".into(),
            rate: 0.01,
            max_pressure: 1e12,
            phi: None,
            max_collisions: None,
            time_limit: None,
            walls: String::new(),
            rescale_every: 10.0,
            jam: true,
            jam_start: 1e3,
            jam_step: 0.2,
            jam_relax: 4,
            phi_start: 0.1,
            tol: None,
            start: None,
            method: "hard".into(),
            min_pressure: 1e-8,
        }
    }
}

/// How a packing is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Lubachevsky–Stillinger growth of hard spheres (event-driven).
    Hard,
    /// Soft Hertzian spheres under a barostat, the target pressure stepped
    /// down to `min_pressure` (time-stepped), φ extrapolated to P = 0.
    Soft { min_pressure: f64 },
}

/// How a request names a key in its messages: as `mote pack` options or
/// as `[packing]` keys of a scene (with the line they are on).
#[derive(Debug, Clone, Copy)]
pub enum Naming<'a> {
    Options,
    Scene(mote_io::Source<'a>),
}

impl Naming<'_> {
    /// `--dim 4` or `file.toml:3: [packing] dimension = 4`; `quoted` for
    /// a string value (`walls = "q"` in a scene).
    fn said(&self, key: &str, value: impl std::fmt::Display, quoted: bool) -> String {
        match self {
            Naming::Options => {
                let option = match key {
                    "dimension" => "dim".to_string(),
                    k => k.replace('_', "-"),
                };
                format!("--{option} {value}")
            }
            Naming::Scene(src) => {
                let q = if quoted { "\"" } else { "" };
                format!(
                    "{}:{}: [packing] {key} = {q}{value}{q}",
                    src.file,
                    src.key_line(key)
                )
            }
        }
    }
}

impl Naming<'_> {
    /// An engine error where the packer refused a setting (its domain, or
    /// too few particles for the distribution), said as the request spelled
    /// the key; any other error as it is.
    pub fn locate(&self, e: FrontError) -> FrontError {
        match e {
            FrontError::Edmd(mote_edmd::EdmdError::Setting(s)) => {
                FrontError::request(format!("{}: {}", self.said(s.key, &s.value, false), s.why))
            }
            other => other,
        }
    }
}

impl PackingSpec {
    /// The method, or a message naming the bad key as the request spelled
    /// it; the soft method packs spheres in a periodic box from a random
    /// start.
    pub fn method(&self, naming: Naming) -> Result<Method, FrontError> {
        let said = |key: &str, value: &dyn std::fmt::Display| {
            naming.said(key, value, matches!(key, "method" | "walls" | "start"))
        };
        match self.method.as_str() {
            "hard" => Ok(Method::Hard),
            "soft" => {
                if !(self.min_pressure >= 1e-12 && self.min_pressure <= 1e-2) {
                    refuse!(
                        "{}: the soft method's lowest pressure P/K must lie in [1e-12, 1e-2]",
                        said("min_pressure", &self.min_pressure)
                    );
                }
                if self.dimension != 3 {
                    refuse!(
                        "{}: the soft method packs spheres (dimension 3)",
                        said("method", &self.method)
                    );
                }
                if !self.walls.is_empty() {
                    refuse!(
                        "{}: the soft method packs in a periodic box (no walls)",
                        said("walls", &self.walls)
                    );
                }
                if let Some(start) = &self.start {
                    refuse!(
                        "{}: the soft method starts from a random state (start is for growth)",
                        said("start", start)
                    );
                }
                Ok(Method::Soft {
                    min_pressure: self.min_pressure,
                })
            }
            other => refuse!("{}: use hard or soft", said("method", &other)),
        }
    }

    /// The engine's settings, or a message naming the bad key as the
    /// request spelled it. Relative radii files resolve against `base`.
    pub fn settings(
        &self,
        seed: u64,
        naming: Naming,
        base: &Path,
    ) -> Result<PackSettings, FrontError> {
        let said = |key: &str, value: &dyn std::fmt::Display| {
            naming.said(key, value, matches!(key, "dist" | "walls" | "start"))
        };
        if self.dimension != 2 && self.dimension != 3 {
            refuse!("{}: must be 2 or 3", said("dimension", &self.dimension));
        }
        // Positions, velocities, radii, times, event, cell and neighbour
        // entries: at least 300 bytes a sphere.
        mote_io::system::check_fits(
            &format!("{}: the packing", said("n", &self.n)),
            self.n as f64 * 300.0,
        )
        .map_err(FrontError::request)?;
        let start = match &self.start {
            Some(file) => Some(
                read_start(&base.join(file), self.dimension)
                    .map_err(|e| FrontError::request(format!("{}: {e}", said("start", &file))))?,
            ),
            None => None,
        };
        let sizes = match self.dist.strip_prefix("file:") {
            Some(p) => SizeSpec::Radii(read_radii(&base.join(p))?),
            None => SizeSpec::parse(&self.dist)
                .map_err(|e| FrontError::request(format!("{}: {e}", said("dist", &self.dist))))?,
        };
        let axes = &"xyz"[..self.dimension];
        let mut walls = vec![false; self.dimension];
        for c in self.walls.chars() {
            let Some(k) = axes.find(c) else {
                refuse!(
                    "{}: `{c}` is not an axis of {axes}",
                    said("walls", &self.walls)
                );
            };
            walls[k] = true;
        }
        if let Some(t) = self.time_limit {
            if !(t > 0.0 && t.is_finite()) {
                refuse!(
                    "{}: must be a positive number of seconds",
                    said("time_limit", &t)
                );
            }
        }
        if let Some(t) = self.tol {
            if !(t >= 0.0 && t.is_finite()) {
                refuse!("{}: must be a non-negative number", said("tol", &t));
            }
        }
        let settings = PackSettings {
            n: self.n,
            sizes,
            rate: self.rate,
            phi_start: self.phi_start,
            walls,
            max_pressure: self.max_pressure,
            target_phi: self.phi,
            max_collisions: self.max_collisions,
            wall_clock: self.time_limit.map(Duration::from_secs_f64),
            rescale_every: self.rescale_every,
            finish: self.jam.then_some(Finish {
                start_pressure: self.jam_start,
                relax_windows: self.jam_relax,
                step: self.jam_step,
            }),
            seed,
            start,
        };
        // The engine's one check of every value, said where it came from.
        settings
            .check()
            .map_err(|e| naming.locate(mote_edmd::EdmdError::Setting(e).into()))?;
        Ok(settings)
    }
}

/// The start of a packing from a trajectory's last frame: positions from
/// the box's lower corner, radii, side lengths.
fn read_start(path: &Path, dimension: usize) -> Result<mote_edmd::pack::PackStart, String> {
    let frames = mote_io::trajectory::read_frames(path).map_err(|e| e.to_string())?;
    let f = mote_io::trajectory::pick(&frames, None, path)?;
    let n = f.positions.len();
    if f.radii.len() != n || n == 0 {
        return Err(format!("{}: the frame gives no radii", path.display()));
    }
    let c = f.cell;
    let skew = (0..3).any(|i| (0..3).any(|j| i != j && c[i][j] != 0.0));
    let size: Vec<f64> = (0..dimension).map(|d| c[d][d]).collect();
    if skew || size.iter().any(|l| *l <= 0.0) {
        return Err(format!(
            "{}: the frame's box must be orthogonal with positive sides (cell {c:?})",
            path.display()
        ));
    }
    Ok(mote_edmd::pack::PackStart {
        size,
        positions: f
            .positions
            .iter()
            .map(|p| (0..dimension).map(|d| p[d] - f.origin[d]).collect())
            .collect(),
        radii: f.radii.clone(),
    })
}

/// Reads one radius per line (`#` starts a comment); errors as `file:line: ...`.
fn read_radii(path: &Path) -> Result<Vec<f64>, FrontError> {
    let text = std::fs::read_to_string(path).map_err(|e| mote_io::IoError::os(path, e))?;
    let at = |line: usize, message: String| {
        FrontError::request(format!("{}:{line}: {message}", path.display()))
    };
    let mut radii = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let r: f64 = body.parse().map_err(|_| {
            at(
                k + 1,
                format!("`{body}` is not a number (one radius per line)"),
            )
        })?;
        if !(r > 0.0 && r.is_finite()) {
            return Err(at(k + 1, format!("radius {r} must be positive and finite")));
        }
        radii.push(r);
    }
    if radii.len() < 2 {
        refuse!(
            "{}: needs at least 2 radii, found {}",
            path.display(),
            radii.len()
        );
    }
    Ok(radii)
}

/// The packing file of a run folder, `DIR/packing.EXT` in `format`: where
/// `mote pack -o DIR` and a `[packing]` scene under `mote run` put it.
pub fn packing_file(dir: &Path, format: mote_io::trajectory::Format) -> PathBuf {
    dir.join(format!("packing.{}", format.extension()))
}

/// The format a packing's folder `dir` names by its extension, as a
/// packing file did before folders (`-o p.gsd`): such a name is refused
/// with the new spelling, not made into a folder. `None` for a folder's
/// name (or a folder that exists).
pub fn named_like_a_file(dir: &Path) -> Option<mote_io::trajectory::Format> {
    mote_io::trajectory::Format::of_path(dir).filter(|_| !dir.is_dir())
}

/// The options of `mote pack` as the text of a `[packing]` scene (what its
/// checkpoints record as their input).
pub fn spec_scene_text(spec: &PackingSpec, seed: u64) -> Result<String, FrontError> {
    #[derive(Serialize)]
    struct Scene<'a> {
        seed: u64,
        packing: &'a PackingSpec,
    }
    toml::to_string(&Scene {
        seed,
        packing: spec,
    })
    .map_err(|e| FrontError::request(format!("the packing options as a scene: {e}")))
}

/// What a packing run did: the summary lines, how it ended, and the
/// packing itself.
#[derive(Debug, Clone)]
pub struct Packed {
    pub summary: Vec<String>,
    pub ending: Ending,
    /// The final spheres and box.
    pub frame: mote_io::xyz::Frame,
    pub phi: f64,
    /// The reduced pressure of the last window.
    pub pressure: f64,
}

/// What `mote pack` and Python's `mote.pack` ask for besides the packing.
#[derive(Debug, Clone)]
pub struct PackRequest {
    /// The packing's folder (DIR/packing.EXT with its CSV, POV-Ray scene
    /// and checkpoints); without one nothing is written.
    pub output: Option<PathBuf>,
    /// The packing file's format.
    pub format: Format,
    pub picture: Option<PathBuf>,
    /// Steps between checkpoints (pressure windows; chunks of 100 steps
    /// for the soft method), needs `output`.
    pub checkpoint_every: Option<u64>,
    pub seed: u64,
    /// The seed was drawn for this packing (none was given).
    pub seed_chosen: bool,
}

/// Packs what `spec` asks for, as `mote pack` (`label`, the command as
/// given) and Python do, through the one run (checkpoints, folder,
/// progress as `mote run` has them); then
/// what it found (φ, pressure, why it stopped, contacts, order, overlaps).
/// A signal stops it at the end of the current window with the packing so
/// far written; an overlap beyond round-off is an error.
pub fn pack(
    spec: &PackingSpec,
    label: &str,
    request: &PackRequest,
    monitor: &mut dyn Monitor,
) -> Result<Packed, FrontError> {
    spec.method(Naming::Options)?;
    let seed = request.seed;
    let input = Input {
        name: "pack".into(),
        label: label.to_string(),
        text: spec_scene_text(spec, seed)?,
        plist: false,
    };
    let options = RunOptions {
        output: request.output.clone(),
        checkpoint_every: request.checkpoint_every,
        picture: request.picture.clone(),
        seed: Some(seed),
        ..RunOptions::default()
    };
    let grown = RefCell::new(None);
    let packing = PackRun {
        spec,
        naming: Naming::Options,
        base: PathBuf::from("."),
        scene_seed: Some(seed),
        seed_chosen: request.seed_chosen,
        scene_dir: None,
        format: request.format,
        writes: request.output.is_some(),
        headline: Some(format!("mote pack: {label}")),
        grown: &grown,
    };
    let outcome = packing.run(&input, &options, None, monitor);
    monitor.finish();
    packed(outcome?, grown)
}

/// How a packing a signal stopped ended: its packing so far is written.
fn interrupted(signal: i32) -> Ending {
    Ending::Interrupted {
        signal,
        message: format!("interrupted by signal {signal}; the packing so far is written"),
    }
}

/// A packing's outcome with the packing it left.
fn packed(outcome: Outcome, grown: RefCell<Option<Grown>>) -> Result<Packed, FrontError> {
    let Some(grown) = grown.into_inner() else {
        return Err(FrontError::request(match outcome.ending {
            Ending::Interrupted { message, .. } => message,
            _ => "the packing ended without a result".into(),
        }));
    };
    Ok(Packed {
        summary: outcome.summary,
        ending: outcome.ending,
        frame: grown.frame,
        phi: grown.phi,
        pressure: grown.pressure,
    })
}

/// A packing request on its way through the one run, whichever its
/// method: what both ways in (`mote pack`, a `[packing]` scene, a resumed
/// checkpoint) say of the files and messages.
pub(crate) struct PackRun<'a> {
    pub spec: &'a PackingSpec,
    /// How messages name the request's keys.
    pub naming: Naming<'a>,
    /// The folder the request's relative paths (`start`, `dist = "file:"`)
    /// resolve against.
    pub base: PathBuf,
    pub scene_seed: Option<u64>,
    /// The seed was drawn for this run (no `--seed`).
    pub seed_chosen: bool,
    pub scene_dir: Option<String>,
    /// The packing file's format.
    pub format: Format,
    /// Whether it writes files (`mote pack` without `-o` writes none).
    pub writes: bool,
    /// The opening line's start where the request is not a scene under
    /// `mote run` (`mote pack: LABEL`).
    pub headline: Option<String>,
    /// The result, once the packing has ended.
    pub grown: &'a RefCell<Option<Grown>>,
}

impl PackRun<'_> {
    /// The packing through the one run, by its method (growth in its
    /// dimension, or the soft method).
    fn run(
        self,
        input: &Input,
        options: &RunOptions,
        resumed: Option<&Checkpoint>,
        monitor: &mut dyn Monitor,
    ) -> Result<Outcome, FrontError> {
        macro_rules! through {
            ($engine:expr) => {
                crate::runner::run_engine($engine, input, options, resumed, monitor)
            };
        }
        match (self.spec.method(self.naming)?, self.spec.dimension) {
            (Method::Soft { min_pressure }, _) => through!(Soft::new(self, min_pressure)),
            (Method::Hard, 2) => through!(Growth::<2>::new(self)),
            (Method::Hard, 3) => through!(Growth::<3>::new(self)),
            (Method::Hard, d) => refuse!(
                "{}: must be 2 or 3",
                self.naming.said("dimension", d, false)
            ),
        }
    }

    /// What a packing's checkpoints record beyond the run's: the folder
    /// the request's relative paths resolve from on resume, and the
    /// packing file's format.
    fn checkpoint_options(&self) -> Vec<(String, String)> {
        let base = std::path::absolute(&self.base).unwrap_or_else(|_| self.base.clone());
        vec![
            ("base".into(), base.display().to_string()),
            ("packing-format".into(), self.format.extension().into()),
        ]
    }

    /// Writes the packing `frame` (every number exact in the format of
    /// its extension) and its POV-Ray scene into `dir`, when the run
    /// writes files; returns the packing's path.
    fn write(
        &self,
        frame: &mote_io::xyz::Frame,
        dir: &Path,
        provenance: &mote_io::Provenance,
    ) -> Result<Option<PathBuf>, FrontError> {
        if !self.writes {
            return Ok(None);
        }
        let path = packing_file(dir, self.format);
        use mote_io::trajectory::TrajectoryWriter;
        TrajectoryWriter::create(&path, self.format, provenance.clone(), true)?.write(0, frame)?;
        write_pov(frame, &dir.join("packing.pov"))?;
        Ok(Some(path))
    }

    /// The packing's table, `packing.csv` with its columns (name, unit),
    /// started or (a resumed run) continued.
    fn table(
        &self,
        files: &crate::runner::RunFiles,
        columns: &[(&str, &str)],
    ) -> Result<(mote_io::csv::CsvWriter, PathBuf), FrontError> {
        use mote_io::csv::CsvWriter;
        let path = files.dir.join("packing.csv");
        let csv = if files.append {
            CsvWriter::append(&path, columns.len())?
        } else {
            let (names, units): (Vec<String>, Vec<String>) = columns
                .iter()
                .map(|(name, unit)| (name.to_string(), unit.to_string()))
                .unzip();
            CsvWriter::create(&path, &files.provenance, &names, &units)?
        };
        Ok((csv, path))
    }
}

/// The POV-Ray scene of a packing, framed and lit as the pictures are.
fn write_pov(frame: &mote_io::xyz::Frame, path: &Path) -> Result<(), FrontError> {
    use mote_render::frame::{default_radius, scene_from_frame, ColorBy};
    let (scene, _) = scene_from_frame(
        frame,
        &ColorBy::Species,
        mote_render::ColorMap::Viridis,
        default_radius(frame),
    )?;
    let Some((lo, hi)) = scene.bounds() else {
        refuse!("{}: nothing to draw", path.display());
    };
    let cam = mote_render::Camera::frame(lo, hi, mote_render::camera::DEFAULT_VIEW, 30.0, 800, 800);
    let opts = mote_render::RenderOptions {
        shadows: true,
        ..mote_render::RenderOptions::default()
    };
    mote_render::pov::write_pov(path, &scene, &cam, &opts)?;
    Ok(())
}

/// A packing scene: `title`, `seed`, `[packing]` and `[output]` (`dir`,
/// `trajectory_format`); the envelope's other keys are refused with the
/// reason.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct PackingScene {
    #[allow(dead_code)]
    title: Option<String>,
    seed: Option<u64>,
    packing: PackingSpec,
    #[serde(default)]
    output: mote_run::scene::OutputTable,
    /// Read only to be refused with the reason.
    #[serde(default)]
    run: mote_run::scene::RunTable,
}

/// Why a packing takes no run length.
const WHY_NO_TIME: &str =
    "a packing grows until it jams; bound it with [packing] phi, max_pressure, max_collisions or time_limit";

impl PackingScene {
    /// The scene of `source`, its errors at their line.
    fn parse(source: mote_io::Source) -> Result<Self, FrontError> {
        let scene: Self = toml::from_str(source.text)
            .map_err(|e| FrontError::Parse(source.parser_error(e.span(), e.message())))?;
        let run_keys = [
            "integrator",
            "dt",
            "steps",
            "until",
            "equilibrate",
            "centre_of_mass",
        ];
        let refused: Vec<(&str, &str)> = run_keys.iter().map(|k| (*k, WHY_NO_TIME)).collect();
        scene.run.refuse(source, &refused)?;
        const FILES: &str = "a packing writes packing.xyz (with .csv and .pov beside it); [output] takes dir and trajectory_format";
        let output_keys = [
            "observables_every",
            "trajectory_every",
            "interval",
            "observables",
            "trajectory",
            "histogram",
            "inspect",
            "pressure_tensor",
        ];
        let refused: Vec<(&str, &str)> = output_keys.iter().map(|k| (*k, FILES)).collect();
        scene.output.refuse(source, &refused)?;
        scene.output.trajectory_format(source)?;
        Ok(scene)
    }
}

/// `mote run` on a scene with a `[packing]` table: the packing goes to
/// `DIR/packing.xyz` (or the format of `--trajectory-format`; with .csv
/// and .pov beside it).
pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    options.refuse(
        "packings",
        &[
            (options.dt.is_some(), "--dt", WHY_NO_TIME),
            (options.steps.is_some(), "--steps", WHY_NO_TIME),
            (options.until.is_some(), "--until", WHY_NO_TIME),
            (options.solver.is_some(), "--solver", crate::WHY_NO_SOLVER),
            (options.system.is_some(), "--system", crate::WHY_NO_SYSTEM),
        ],
    )?;
    let source = mote_io::Source::new(&input.label, &input.text);
    source.finite_numbers().map_err(FrontError::Parse)?;
    let scene = PackingScene::parse(source)?;
    let spec = &scene.packing;
    let format = options.trajectory_format(scene.output.trajectory_format(source)?)?;
    let grown = RefCell::new(None);
    PackRun {
        spec,
        naming: Naming::Scene(source),
        base: input.folder(),
        scene_seed: scene.seed,
        seed_chosen: false,
        scene_dir: scene.output.dir.clone(),
        format,
        writes: true,
        headline: None,
        grown: &grown,
    }
    .run(input, options, None, monitor)
}

/// The packer a `[packing]` scene starts (Python's `Packing`): the settings and seed `mote run` would use (`seed`
/// replaces the scene's), in the scene's dimension; with the seed used.
pub(crate) fn scene_packer(
    input: &Input,
    seed: Option<u64>,
) -> Result<(crate::stepper::Packing, u64), FrontError> {
    let source = mote_io::Source::new(&input.label, &input.text);
    source.finite_numbers().map_err(FrontError::Parse)?;
    let scene = PackingScene::parse(source)?;
    let spec = &scene.packing;
    let naming = Naming::Scene(source);
    let (seed, _) = crate::seed::resolve(seed, scene.seed);
    if let Method::Soft { min_pressure } = spec.method(naming)? {
        let settings = soft::settings(spec, naming, &input.folder(), seed, min_pressure)?;
        let packer = mote_md::soft_pack::SoftPacker::new(settings).map_err(FrontError::request)?;
        return Ok((
            crate::stepper::Packing::Soft(crate::stepper::Stepper::new(packer, 1)),
            seed,
        ));
    }
    let settings = spec.settings(seed, naming, &input.folder())?;
    let locate = |e: mote_edmd::EdmdError| naming.locate(e.into());
    let packer = match spec.dimension {
        2 => crate::stepper::Packing::Disks(crate::stepper::Stepper::new(
            mote_edmd::Packer::new(settings).map_err(locate)?,
            1,
        )),
        _ => crate::stepper::Packing::Spheres(crate::stepper::Stepper::new(
            mote_edmd::Packer::new(settings).map_err(locate)?,
            1,
        )),
    };
    Ok((packer, seed))
}

/// Continues the packing a checkpoint came from (by `mote pack` or a
/// `[packing]` scene): the same request, seed, folder and checkpoint
/// schedule; the CSV is trimmed back to the checkpoint and the packing is
/// written at the end as an uninterrupted run would have.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    if cp.option("name").is_none() {
        refuse!(
            "this packing checkpoint was written by an older mote, before packings ran through the loop every run shares; start the packing again"
        );
    }
    let (input, options) = crate::checkpoints::restore(cp, given)?;
    let source = mote_io::Source::new(&input.label, &input.text);
    let scene = PackingScene::parse(source)?;
    let format = cp
        .option("packing-format")
        .and_then(Format::named)
        .unwrap_or(Format::Xyz);
    let grown = RefCell::new(None);
    PackRun {
        spec: &scene.packing,
        naming: Naming::Scene(source),
        base: cp
            .option("base")
            .map(PathBuf::from)
            .unwrap_or_else(|| input.folder()),
        scene_seed: scene.seed,
        seed_chosen: false,
        scene_dir: scene.output.dir.clone(),
        format,
        writes: true,
        headline: Some(format!(
            "mote run --resume: packing {} from window {}",
            input.label, cp.step
        )),
        grown: &grown,
    }
    .run(&input, &options, Some(cp), monitor)
}
