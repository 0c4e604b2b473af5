//! Packings by growing spheres (Lubachevsky–Stillinger on the event-driven
//! engine, `mote_edmd::pack`): one run for both ways in, the options of
//! `mote pack` and a scene's `[packing]` table under `mote run`.
//!
//! The packing is written as extended XYZ with every number exact
//! (`packing.xyz`), with φ and the reduced pressure per growth window
//! (`packing.csv`) and a POV-Ray scene (`packing.pov`) beside it.

use std::path::{Path, PathBuf};
use std::time::Duration;

use mote_edmd::analyse::{bond_order, contacts, deepest_overlap};
use mote_edmd::pack::{Finish, PackCheckpoints, PackSettings, PackState, Packer, SizeSpec, Stop};
use mote_io::checkpoint::Checkpoint;
use serde::{Deserialize, Serialize};

use crate::error::{refuse, FrontError};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

mod soft;

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

/// Where a packing goes: the XYZ file (the CSV and POV-Ray scene go beside
/// it, same stem), a picture, checkpoints; and the checkpoint it resumes.
#[derive(Debug, Clone, Default)]
pub struct PackFiles {
    pub xyz: Option<PathBuf>,
    pub picture: Option<PathBuf>,
    pub checkpoints: Option<PackCheckpointFile>,
    /// Continue this checkpoint's packing (the CSV is trimmed back to it
    /// and appended to).
    pub resume: Option<Checkpoint>,
}

impl PackFiles {
    /// The packing's path without its extension (the CSV and POV-Ray
    /// scene go beside it), its folder made; `None` without `xyz`.
    fn stem(&self) -> Result<Option<Stem>, FrontError> {
        if let Some(dir) = self.xyz.as_ref().and_then(|p| p.parent()) {
            if !dir.as_os_str().is_empty() {
                std::fs::create_dir_all(dir).map_err(|e| mote_io::IoError::os(dir, e))?;
            }
        }
        Ok(self.xyz.as_ref().map(|p| Stem(p.with_extension(""))))
    }

    /// Writes the packing (the format follows the extension: .xyz, .dump,
    /// .gsd, .pvd, in numbers that read back bit for bit), its POV-Ray
    /// scene and the picture, as asked.
    fn write(
        &self,
        frame: &mote_io::xyz::Frame,
        provenance: &mote_io::Provenance,
    ) -> Result<(), FrontError> {
        if let Some(path) = &self.xyz {
            use mote_io::trajectory::{Format, TrajectoryWriter};
            let format: Format = crate::written_format(path)?;
            TrajectoryWriter::create(path, format, provenance.clone(), true)?.write(0, frame)?;
            write_pov(frame, &Stem(path.with_extension("")).with("pov"))?;
        }
        if let Some(p) = &self.picture {
            mote_render::frame::picture(frame, p, 800, 800)?;
        }
        Ok(())
    }
}

/// Checkpoints of a packing: every `every` pressure windows to `path`, with
/// the options and input of `template` (see [`checkpoint_template`]).
#[derive(Debug, Clone)]
pub struct PackCheckpointFile {
    pub every: u64,
    pub path: PathBuf,
    pub template: Checkpoint,
}

/// What a packing's checkpoint records besides its state: the input as a
/// `[packing]` scene (`label`, `text`), the seed, the schedule, where the
/// packing goes and the folder its relative paths start from.
pub fn checkpoint_template(
    label: &str,
    text: &str,
    seed: u64,
    every: u64,
    xyz: &Path,
    base: &Path,
) -> Checkpoint {
    // Relative paths are kept from the folder the run started in.
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    Checkpoint {
        program: format!("mote {}", env!("CARGO_PKG_VERSION")),
        seed,
        options: vec![
            ("engine".into(), "packing".into()),
            ("checkpoint-every".into(), every.to_string()),
            ("output".into(), absolute(xyz).display().to_string()),
            ("base".into(), absolute(base).display().to_string()),
        ],
        input_label: label.to_string(),
        input_text: text.to_string(),
        ..Checkpoint::default()
    }
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

/// Grows the packing `settings` describe, writes `files` and says what it
/// found (φ, pressure, why it stopped, contacts, order, overlaps). A
/// signal stops it at the end of the current window with the packing so
/// far written; an overlap beyond round-off is an error.
pub fn pack(
    dimension: usize,
    method: Method,
    settings: PackSettings,
    tol: Option<f64>,
    files: &PackFiles,
    provenance: &mote_io::Provenance,
    monitor: &mut dyn Monitor,
) -> Result<Packed, FrontError> {
    match (method, dimension) {
        (Method::Soft { min_pressure }, _) => {
            soft::pack_soft(settings, min_pressure, files, provenance, monitor)
        }
        (Method::Hard, 2) => pack_dim::<2>(settings, tol, files, provenance, monitor),
        (Method::Hard, _) => pack_dim::<3>(settings, tol, files, provenance, monitor),
    }
}

fn pack_dim<const D: usize>(
    settings: PackSettings,
    tol: Option<f64>,
    files: &PackFiles,
    provenance: &mote_io::Provenance,
    monitor: &mut dyn Monitor,
) -> Result<Packed, FrontError> {
    let max_pressure = settings.max_pressure;
    let mut packer = match &files.resume {
        Some(cp) => Packer::<D>::resume(settings, &PackState::from_checkpoint(cp, D)?)?,
        None => Packer::<D>::new(settings)?,
    };
    let stem = files.stem()?;
    let mut csv = match (&stem, &files.resume) {
        (Some(s), Some(cp)) => {
            let path = s.with("csv");
            crate::checkpoints::trim_table(&path, u64::MAX, cp.time)?;
            Some(mote_io::csv::CsvWriter::append(&path, 4)?)
        }
        (Some(s), None) => Some(mote_io::csv::CsvWriter::create(
            &s.with("csv"),
            provenance,
            &["collisions", "time", "phi", "pressure"].map(String::from),
            &["", "", "", ""].map(String::from),
        )?),
        (None, _) => None,
    };
    let mut save = |state: &PackState| -> Result<(), mote_edmd::EdmdError> {
        if let Some(c) = &files.checkpoints {
            mote_io::checkpoint::write(&c.path, &state.to_checkpoint(&c.template))?;
        }
        Ok(())
    };
    let mut checkpoints = files.checkpoints.as_ref().map(|c| PackCheckpoints {
        every: c.every,
        save: &mut save,
    });
    let cpu0 = crate::cpu::cpu_seconds();
    let collisions0 = packer.collisions();
    let mut csv_err = None;
    let outcome = packer.run_with(
        |s| {
            if let Some(w) = csv.as_mut() {
                if let Err(e) = w.row(&[s.collisions as f64, s.time, s.phi, s.pressure]) {
                    csv_err.get_or_insert(e);
                }
            }
            // Progress: log10 of the pressure towards the threshold.
            let f = (s.pressure.max(1.0).log10() / max_pressure.log10()).clamp(0.0, 1.0);
            monitor.progress(
                (f * 1000.0) as u64,
                1000,
                &format!(
                    "phi {:.5}  Z {:.3e}  {} collisions",
                    s.phi, s.pressure, s.collisions
                ),
            );
        },
        checkpoints.as_mut(),
    )?;
    monitor.finish();
    if let Some(e) = csv_err {
        return Err(e.into());
    }
    let cpu = crate::cpu::cpu_seconds() - cpu0;
    let sys = packer.system();
    let simbox = *sys.simbox();
    let (pos, radii) = (sys.positions(), sys.radii());
    let overlap = deepest_overlap(&simbox, &pos, &radii);
    let frame = mote_edmd::scene::frame(sys);
    files.write(&frame, provenance)?;
    let tol = tol.unwrap_or(1e3 / max_pressure);
    let c = contacts(&simbox, &pos, &radii, tol);
    let (q, _) = bond_order(&simbox, &pos, &radii, 1.2);
    let stop = match outcome.stop {
        Stop::Pressure => format!("reduced pressure passed {max_pressure:e} (jammed)"),
        Stop::TargetPhi => "target packing fraction reached".to_string(),
        Stop::Collisions => "collision budget spent".to_string(),
        Stop::WallClock => "wall-clock limit reached".to_string(),
        Stop::Interrupted => "run was interrupted by a signal (not jammed)".to_string(),
    };
    let mut summary = vec![
        format!(
            "{} {}: phi = {:.6}, reduced pressure Z = {:.3e}, stopped because the {stop}.",
            sys.len(),
            if D == 2 { "disks" } else { "spheres" },
            outcome.phi,
            outcome.pressure
        ),
        format!(
            "{} collisions{} in {:.2} s CPU ({:.3e} per CPU-second), {} growth epochs.",
            outcome.collisions,
            if collisions0 > 0 {
                format!(" ({} since the checkpoint)", outcome.collisions - collisions0)
            } else {
                String::new()
            },
            cpu,
            (outcome.collisions - collisions0) as f64 / cpu.max(1e-9),
            outcome.epochs
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
    if let Some(o) = &files.xyz {
        summary.push(format!("Wrote {} (+ .csv, .pov).", o.display()));
    }
    if let Some((i, j, g)) = overlap {
        if g <= -1e-9 {
            refuse!(
                "particles {i} and {j} overlap by {:.3e} of their contact distance",
                -g
            );
        }
    }
    let ending = match (outcome.stop, mote_io::system::stop_requested()) {
        (Stop::Interrupted, Some(signal)) => Ending::Interrupted {
            signal,
            message: format!("interrupted by signal {signal}; the packing so far is written"),
        },
        _ => Ending::Finished,
    };
    Ok(Packed {
        summary,
        ending,
        frame,
        phi: outcome.phi,
        pressure: outcome.pressure,
    })
}

/// A packing's path without its extension, to which the CSV and POV-Ray
/// files add theirs (`pack.0.1.xyz` gives `pack.0.1.csv`, where
/// `with_extension` would give `pack.0.csv`).
struct Stem(PathBuf);

impl Stem {
    fn with(&self, extension: &str) -> PathBuf {
        let mut name = self.0.clone().into_os_string();
        name.push(".");
        name.push(extension);
        PathBuf::from(name)
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

/// A packing scene: `title`, `seed`, `[packing]` and `[output] dir`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct PackingScene {
    #[allow(dead_code)]
    title: Option<String>,
    seed: Option<u64>,
    packing: PackingSpec,
    #[serde(default)]
    output: PackingOutput,
    /// Read only to be refused with the reason.
    run: Option<toml::Value>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct PackingOutput {
    dir: Option<String>,
}

/// `mote run` on a scene with a `[packing]` table: the packing goes to
/// `DIR/packing.xyz` (or the format of `--trajectory-format`; with .csv
/// and .pov beside it).
pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    const WHY_NO_TIME: &str =
        "a packing grows until it jams; bound it with [packing] phi, max_pressure, max_collisions or time_limit";
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
    let scene: PackingScene = toml::from_str(&input.text)
        .map_err(|e| FrontError::Parse(source.parser_error(e.span(), e.message())))?;
    if scene.run.is_some() {
        refuse!(
            "{}:{}: [run] has nothing to set for a packing: {WHY_NO_TIME}",
            source.file,
            source.key_line("run")
        );
    }
    let dir = input.output_dir(options.output.as_ref(), scene.output.dir.as_ref());
    let base = input.folder();
    let (seed, chosen) = crate::seed::resolve(options.seed, scene.seed);
    let spec = &scene.packing;
    let settings = spec.settings(seed, Naming::Scene(source), &base)?;
    let method = spec.method(Naming::Scene(source))?;
    let xyz = packing_file(
        &dir,
        options.trajectory_format(mote_io::trajectory::Format::Xyz)?,
    );
    let _folder = crate::lock::RunFolder::fresh(&dir, &input.label, &input.text)?;
    let how = match method {
        Method::Hard => format!("by growth (rate {}", spec.rate),
        Method::Soft { min_pressure } => {
            format!("by the soft method (down to P/K = {min_pressure:e}")
        }
    };
    monitor.start(&format!(
        "mote run {}: packing {} {} {how}, {}), {}, {}",
        input.label,
        spec.n,
        if spec.dimension == 2 {
            "disks"
        } else {
            "spheres"
        },
        spec.dist,
        crate::seed_phrase(seed, chosen),
        crate::threads_phrase()
    ));
    let files = PackFiles {
        checkpoints: options.checkpoint_every.map(|every| PackCheckpointFile {
            every,
            path: dir.join("checkpoint.mote"),
            template: checkpoint_template(&input.label, &input.text, seed, every, &xyz, &base),
        }),
        xyz: Some(xyz),
        picture: options.picture.clone(),
        resume: None,
    };
    packed_outcome(
        Naming::Scene(source),
        &input.label,
        seed,
        spec,
        method,
        settings,
        &files,
        dir,
        monitor,
    )
}

/// Packs and says what `mote run` says of it.
#[allow(clippy::too_many_arguments)]
fn packed_outcome(
    naming: Naming,
    label: &str,
    seed: u64,
    spec: &PackingSpec,
    method: Method,
    settings: PackSettings,
    files: &PackFiles,
    dir: PathBuf,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let provenance = crate::provenance(label, seed);
    let packed = pack(
        spec.dimension,
        method,
        settings,
        spec.tol,
        files,
        &provenance,
        monitor,
    )
    .map_err(|e| naming.locate(e))?;
    Ok(Outcome {
        engine: Engine::Packing,
        seed,
        dir,
        summary: packed.summary,
        ending: packed.ending,
    })
}

/// Continues the packing a checkpoint came from (by `mote pack` or a
/// `[packing]` scene): the same settings, seed, files and checkpoint
/// schedule; the CSV is trimmed back to the checkpoint and the packing is
/// written at the end as an uninterrupted run would have.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let option = |k: &str| {
        cp.option(k).ok_or_else(|| {
            FrontError::request(format!("the packing checkpoint has no option '{k}'"))
        })
    };
    let source = mote_io::Source::new(&cp.input_label, &cp.input_text);
    let scene: PackingScene = toml::from_str(&cp.input_text)
        .map_err(|e| FrontError::Parse(source.parser_error(e.span(), e.message())))?;
    let every: u64 = option("checkpoint-every")?
        .parse()
        .map_err(|_| FrontError::request("checkpoint-every is not a whole number"))?;
    let xyz = PathBuf::from(option("output")?);
    let base = PathBuf::from(option("base")?);
    let seed = cp.seed;
    let spec = &scene.packing;
    let settings = spec.settings(seed, Naming::Scene(source), &base)?;
    let method = spec.method(Naming::Scene(source))?;
    let dir = xyz
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    let _lock = crate::lock::FolderLock::take(&dir)?;
    monitor.start(&format!(
        "mote run --resume: packing {} from window {} ({} collisions), seed {seed}",
        cp.input_label,
        cp.step,
        cp.carried
            .iter()
            .find(|(k, _)| *k == 2)
            .and_then(|(_, run)| run.get(4))
            .copied()
            .unwrap_or(0.0)
    ));
    let path = given
        .resume
        .clone()
        .unwrap_or_else(|| dir.join("checkpoint.mote"));
    let files = PackFiles {
        xyz: Some(xyz),
        picture: given.picture.clone(),
        checkpoints: Some(PackCheckpointFile {
            every,
            path,
            template: checkpoint_template(
                &cp.input_label,
                &cp.input_text,
                seed,
                every,
                &PathBuf::from(option("output")?),
                &base,
            ),
        }),
        resume: Some(cp.clone()),
    };
    packed_outcome(
        Naming::Scene(source),
        &cp.input_label,
        seed,
        spec,
        method,
        settings,
        &files,
        dir,
        monitor,
    )
}
