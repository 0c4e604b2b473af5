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
    /// Initial state from a frame of a trajectory file (.xyz, .dump,
    /// .gsd, .vtu/.vtp/.pvd), relative to the scene file: `[[from_file]]`.
    #[serde(skip)]
    pub file: Option<String>,
    /// `[[from_file]]`, as every engine spells it: one file, and `frame`
    /// to pick one (negative counts from the end).
    #[serde(default)]
    from_file: Vec<FileStart>,
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

/// `[[from_file]]` in an event-driven scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileStart {
    file: String,
    frame: Option<i64>,
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
    /// Write the trajectory (default true).
    #[serde(default = "yes")]
    pub trajectory: bool,
    /// Its format: `xyz` (default), `dump`, `gsd` or `vtk`; the file is
    /// `trajectory.<xyz|dump|gsd|pvd>`.
    pub trajectory_format: Option<String>,
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
            trajectory_format: None,
            histogram: true,
            observables_every: None,
            trajectory_every: None,
        }
    }
}

/// The keys of `[event_driven]`: what the hard spheres or disks are and
/// how they start. Everything else a scene says is shared by every engine.
pub const EVENT_DRIVEN_KEYS: &[&str] = &[
    "dimension",
    "n",
    "packing_fraction",
    "box",
    "boundary",
    "radius",
    "mass",
    "large_fraction",
    "size_ratio",
    "placement",
    "temperature",
    "speed",
    "particles",
    "file",
    "check_overlaps",
];

/// `[box]` as every engine spells it: `hi` (and `lo`, which must be the
/// origin: hard spheres live in [0, L); without `hi`, `packing_fraction`
/// sets a cube), `periodic` per axis (default all; a non-periodic axis has
/// hard walls), each with the line it is on.
struct BoxTable {
    lo: Option<(Vec<f64>, usize)>,
    hi: Option<(Vec<f64>, usize)>,
    periodic: Option<(Vec<bool>, usize)>,
}

impl BoxTable {
    /// Sets the scene's box lengths and walls from the table, checked
    /// against its dimension.
    fn apply(self, scene: &mut Scene, source: &mote_io::Source) -> Result<(), EdmdError> {
        let d = scene.dimension;
        let at = |line: usize, message: String| EdmdError::Scene {
            file: source.file.to_string(),
            line,
            message,
        };
        if let Some((hi, line)) = &self.hi {
            if hi.len() != d || hi.iter().any(|x| !(*x > 0.0 && x.is_finite())) {
                return Err(at(
                    *line,
                    format!("[box] hi must list {d} positive lengths (dimension = {d})"),
                ));
            }
        }
        if let Some((lo, line)) = self.lo {
            if lo.len() != d || lo.iter().any(|x| *x != 0.0) {
                return Err(at(
                    line,
                    format!("[box] lo: hard spheres live in a box from the origin: lo = {:?} (or leave it out)", vec![0.0; d]),
                ));
            }
        }
        let periodic = match self.periodic {
            Some((p, line)) if p.len() != d => {
                return Err(at(line, format!("[box] periodic must list {d} entries")))
            }
            Some((p, _)) => p,
            None => vec![true; d],
        };
        scene.box_size = self.hi.map(|(hi, _)| hi);
        scene.boundary = BoundarySpec::PerAxis(
            periodic
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
}

/// Takes the `[box]` table out of the scene (before the hard-sphere keys
/// are lifted to the top level, where the first format had a `box` list).
fn take_box_table(
    root: &mut toml_edit::Table,
    source: &mote_io::Source,
) -> Result<Option<BoxTable>, EdmdError> {
    if !root.get("box").is_some_and(|b| b.is_table()) {
        return Ok(None);
    }
    let item = root.remove("box").expect("checked");
    let table = item.as_table().expect("checked");
    let line_of =
        |span: Option<std::ops::Range<usize>>| span.map_or(1, |s| source.line_of(s.start));
    let at = |line: usize, message: String| EdmdError::Scene {
        file: source.file.to_string(),
        line,
        message,
    };
    let numbers = |key: &str| -> Result<Option<(Vec<f64>, usize)>, EdmdError> {
        let Some(v) = table.get(key) else {
            return Ok(None);
        };
        let line = line_of(v.span());
        let list = v
            .as_array()
            .and_then(|a| {
                a.iter()
                    .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                    .collect::<Option<Vec<f64>>>()
            })
            .ok_or_else(|| at(line, format!("[box] {key} must be a list of numbers")))?;
        Ok(Some((list, line)))
    };
    for (key, v) in table.iter() {
        if !["lo", "hi", "periodic"].contains(&key) {
            return Err(at(
                line_of(v.span()),
                format!("unknown key `{key}` in [box]; it takes lo, hi, periodic"),
            ));
        }
    }
    let hi = numbers("hi")?;
    let periodic = match table.get("periodic") {
        None => None,
        Some(v) => {
            let line = line_of(v.span());
            let list = v
                .as_array()
                .and_then(|a| a.iter().map(|x| x.as_bool()).collect::<Option<Vec<bool>>>())
                .ok_or_else(|| at(line, "[box] periodic must be a list of true/false".into()))?;
            Some((list, line))
        }
    };
    Ok(Some(BoxTable {
        lo: numbers("lo")?,
        hi,
        periodic,
    }))
}

/// The first spellings of the box (`box = [lengths]`, `boundary`) and of
/// the initial file (`file`) are refused with the ones every engine uses.
fn refuse_old_spellings(
    root: &toml_edit::Table,
    source: &mote_io::Source,
) -> Result<(), EdmdError> {
    for (key, spelling) in [
        ("box", "the box is a table of its own, spelled as every engine spells it: [box] hi = [lengths], periodic = [true/false per axis] (false: hard walls)"),
        ("boundary", "the box is a table of its own, spelled as every engine spells it: [box] hi = [lengths], periodic = [true/false per axis] (false: hard walls)"),
        ("file", "a scene starts from a file as every engine spells it: [[from_file]] file = \"...\" (frame = N picks a frame)"),
    ] {
        if let Some((k, item)) = root.get_key_value(key) {
            let span = k.span().or_else(|| item.span());
            return Err(EdmdError::Scene {
                file: source.file.to_string(),
                line: span.map_or(1, |s| source.line_of(s.start)),
                message: format!("`{key}`: {spelling}"),
            });
        }
    }
    Ok(())
}

/// Where a scene gave its hard-sphere keys.
enum Hoisted {
    /// In `[event_driven]` (or nowhere).
    Table,
    /// At the top level, as the first scene format did (deprecated).
    TopLevel(Vec<String>),
}

/// Lifts the keys of `[event_driven]` to the top level, where [`Scene`]
/// reads them; the items keep their spans, so errors still name the line
/// in the file. Top-level hard-sphere keys beside an `[event_driven]`
/// table, and keys the table does not know, are refused at their line.
fn hoist_event_driven(
    root: &mut toml_edit::Table,
    source: &mote_io::Source,
) -> Result<Hoisted, EdmdError> {
    let refuse = |item: &toml_edit::Item, key: &toml_edit::Key, message: String| {
        let span = key.span().or_else(|| item.span());
        EdmdError::Scene {
            file: source.file.to_string(),
            line: span.map_or(1, |s| source.line_of(s.start)),
            message,
        }
    };
    let top_level: Vec<String> = EVENT_DRIVEN_KEYS
        .iter()
        .filter(|k| root.contains_key(k))
        .map(|k| k.to_string())
        .collect();
    let Some(item) = root.remove("event_driven") else {
        return Ok(if top_level.is_empty() {
            Hoisted::Table
        } else {
            Hoisted::TopLevel(top_level)
        });
    };
    if let Some(k) = top_level.first() {
        let (key, item) = root.get_key_value(k).expect("listed above");
        return Err(refuse(
            item,
            key,
            format!("`{k}` belongs in [event_driven], which this scene also has: move it there"),
        ));
    }
    let Some(table) = item.into_table().ok() else {
        return Err(EdmdError::Scene {
            file: source.file.to_string(),
            line: source.key_line("event_driven"),
            message: "`event_driven` must be a table: [event_driven]".into(),
        });
    };
    for (key, item) in table.iter() {
        if !EVENT_DRIVEN_KEYS.contains(&key) {
            let k = table.key(key).expect("iterated");
            let shared = ["title", "seed", "run", "output"].contains(&key);
            let hint = if shared {
                format!("`{key}` is shared by every engine: give it at the top level, outside [event_driven]")
            } else {
                format!(
                    "unknown key `{key}` in [event_driven]; it takes {}",
                    EVENT_DRIVEN_KEYS.join(", ")
                )
            };
            return Err(refuse(item, k, hint));
        }
    }
    for (key, item) in table {
        root.insert(&key, item);
    }
    Ok(Hoisted::Table)
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
        let at = |span: Option<std::ops::Range<usize>>, message: &str| EdmdError::Scene {
            file: file.to_string(),
            line: span.map_or(1, |s| source.line_of(s.start)),
            message: message.trim().to_string(),
        };
        source.finite_numbers().map_err(|e| EdmdError::Scene {
            file: file.to_string(),
            line: e.line,
            message: e.message.clone(),
        })?;
        let document = toml_edit::ImDocument::parse(text).map_err(|e| at(e.span(), e.message()))?;
        let mut root = document.into_table();
        let shared_box = take_box_table(&mut root, &source)?;
        let hoisted = hoist_event_driven(&mut root, &source)?;
        refuse_old_spellings(&root, &source)?;
        let mut scene: Scene = toml_edit::de::from_document(toml_edit::DocumentMut::from(root))
            .map_err(|e| at(e.span(), e.message()))?;
        if let Some(b) = shared_box {
            b.apply(&mut scene, &source)?;
        }
        if let Hoisted::TopLevel(keys) = hoisted {
            scene.notes.push(format!(
                "note: the hard-sphere keys at the top level (`{}`) are deprecated and go in one release: move them into [event_driven] (see docs/edmd.md)",
                keys.join("`, `")
            ));
        }
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
        let end_key = ["until", "time"]
            .into_iter()
            .find(|k| said(k))
            .unwrap_or(state_key);
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
                    // After the equilibration, as `--until` must be: the
                    // same value is taken or refused by either way in.
                    if !(until > self.equilibrate && until.is_finite()) {
                        return Err(err(
                            "until",
                            format!(
                                "[run] until = {until} must be a time after equilibrate = {}",
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
            let format = match &o.trajectory_format {
                None => mote_io::trajectory::Format::Xyz,
                Some(f) => mote_io::trajectory::Format::named(f).ok_or_else(|| {
                    err(
                        "trajectory_format",
                        format!(
                            "trajectory_format '{f}' is not one of {}",
                            mote_io::trajectory::Format::NAMES
                        ),
                    )
                })?,
            };
            self.trajectory = o
                .trajectory
                .then(|| format!("trajectory.{}", format.extension()));
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
                vec![self.radius.unwrap_or(0.5); n]
            };
            let v0: Vec<[f64; D]> = vel;
            let has_v = v0.iter().any(|v| v.iter().any(|x| *x != 0.0));
            let masses = if fr.masses.len() == n && self.mass.is_none() {
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
    const TOP_LEVEL: &str = "dimension = 3\nn = 500\npacking_fraction = 0.2\n";

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
            &format!("{TOP_LEVEL}equilibrate = 2.0\ntime = 4.0\noutput_interval = 0.5\nobservables = \"observables.csv\"\n"),
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
        assert_eq!(old.notes.len(), 3, "{:?}", old.notes);
        assert!(old.notes[0].contains("(`dimension`, `n`, `packing_fraction`)"));
        assert!(old.notes[1].contains("[run] until = 6, equilibrate = 2"));
    }

    /// `[event_driven]` and the first format's top-level keys describe the
    /// same spheres; errors inside the table name their line in the file.
    #[test]
    fn event_driven_table_and_top_level_keys_give_the_same_spheres() {
        let table = Scene::parse(SYSTEM, "table.toml").unwrap();
        let top = Scene::parse(TOP_LEVEL, "top.toml").unwrap();
        for s in [&table, &top] {
            assert_eq!(
                (s.dimension, s.n, s.packing_fraction),
                (3, Some(500), Some(0.2))
            );
        }
        assert!(table.notes.is_empty());
        assert_eq!(top.notes.len(), 1);
        let e = |text: &str| Scene::parse(text, "bad.toml").unwrap_err().to_string();
        assert_eq!(
            e(&format!("{SYSTEM}placement = \"hexagonal\"\n")),
            "bad.toml:5: unknown variant `hexagonal`, expected one of `fcc`, `cubic`, `random`"
        );
        assert_eq!(
            e(&format!("seed = 3\nn = 10\n{SYSTEM}")),
            "bad.toml:2: `n` belongs in [event_driven], which this scene also has: move it there"
        );
        assert_eq!(
            e(&format!("{SYSTEM}seed = 3\n")),
            "bad.toml:5: `seed` is shared by every engine: give it at the top level, outside [event_driven]"
        );
        assert!(e(&format!("{SYSTEM}\ndensity = 3\n")).starts_with(
            "bad.toml:6: unknown key `density` in [event_driven]; it takes dimension, n,"
        ));
        assert_eq!(
            e("seed = 1\nevent_driven = 3\n"),
            "bad.toml:2: `event_driven` must be a table: [event_driven]"
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
    fn mixing_old_keys_and_shared_sections_is_refused_at_the_old_key() {
        let text = format!("{TOP_LEVEL}time = 4.0\n[run]\nuntil = 5.0\n");
        let e = Scene::parse(&text, "mixed.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "mixed.toml:4: `time` (deprecated) and [run] cannot be mixed: move it into [run] (see docs/edmd.md)"
        );
        let text = format!("{SYSTEM}[run]\ndt = 0.1\n");
        let e = Scene::parse(&text, "stepped.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "stepped.toml:6: `dt` is for time-stepped engines; event-driven dynamics jumps from collision to collision, with no time step: give [run] until = (end time)"
        );
        let text = format!("{SYSTEM}[run]\nuntil = 1.0\nequilibrate = 2.0\n");
        let e = Scene::parse(&text, "early.toml").unwrap_err().to_string();
        assert_eq!(
            e,
            "early.toml:6: [run] until = 1 must be a time after equilibrate = 2"
        );
    }
}
