//! What `mote run` was given: a scene file, an MPPphys particle file, a
//! built-in example, or a scene text handed over by the Python API.

use std::path::{Path, PathBuf};

use crate::engine::Engine;
use crate::error::{refuse, FrontError};
use crate::examples;

/// The input text and the names it goes by.
#[derive(Debug, Clone)]
pub struct Input {
    /// Short name: the file stem or the example's name (`out/NAME`).
    pub name: String,
    /// How messages and output headers name it: the path or `example:NAME`.
    pub label: String,
    pub text: String,
    /// An MPPphys particle file rather than a TOML scene.
    pub plist: bool,
}

/// What a file given to `mote run` is when it is a frame or trajectory of
/// particles rather than something to run: by its extension, or by its
/// first lines (an extended-XYZ header, a LAMMPS dump's `ITEM:` lines, a
/// LAMMPS data file's header).
fn trajectory_kind(extension: Option<&str>, text: Option<&str>) -> Option<&'static str> {
    if let Some(e) = extension {
        return match e.to_ascii_lowercase().as_str() {
            "xyz" | "extxyz" => Some("an extended XYZ trajectory"),
            "dump" | "lammpstrj" => Some("a LAMMPS dump"),
            "data" | "lmp" => Some("a LAMMPS data file"),
            "gsd" => Some("a GSD trajectory"),
            "vtu" | "vtp" | "pvd" => Some("a VTK file"),
            _ => None,
        };
    }
    let mut lines = text?.lines();
    let first = lines.next()?.trim();
    let second = lines.next().unwrap_or("");
    if first.starts_with("ITEM: TIMESTEP") {
        Some("a LAMMPS dump")
    } else if first.parse::<u64>().is_ok() && second.contains("Properties=") {
        Some("an extended XYZ trajectory")
    } else if text?
        .lines()
        .take(20)
        .any(|l| l.trim_end().ends_with("atoms"))
        && text?
            .lines()
            .take(40)
            .any(|l| l.trim_end().ends_with("xlo xhi"))
    {
        Some("a LAMMPS data file")
    } else {
        None
    }
}

/// A particle file given to `mote run` as if it were a scene is refused
/// with what to do instead (it was read as an MPPphys file, whose first
/// keyword then failed on line 1).
fn refuse_trajectory(
    spec: &str,
    extension: Option<&str>,
    text: Option<&str>,
) -> Result<(), FrontError> {
    if let Some(kind) = trajectory_kind(extension, text) {
        let look = if kind == "a LAMMPS data file" {
            String::new()
        } else {
            format!(
                ", or look at it with `mote view {spec}` or `mote render {spec} -o picture.png`"
            )
        };
        refuse!(
            "{spec}: this is {kind}, not something to run: start a scene from it with [[from_file]] file = \"{spec}\" (docs/scene-format.md){look}"
        );
    }
    Ok(())
}

impl Input {
    /// Reads `spec`: `example:NAME`, a `.toml` scene file, or any other file
    /// as an MPPphys particle file (trajectories and data files of other
    /// formats are refused with what to do).
    pub fn read(spec: &str) -> Result<Input, FrontError> {
        if let Some(name) = spec.strip_prefix("example:") {
            let Some(e) = examples::find(name) else {
                let names: Vec<String> = examples::all().into_iter().map(|e| e.name).collect();
                refuse!(
                    "no example called '{name}'; the examples are: {}",
                    names.join(", ")
                );
            };
            return Ok(Input {
                name: name.to_string(),
                label: spec.to_string(),
                text: e.text,
                plist: false,
            });
        }
        let path = Path::new(spec);
        refuse_trajectory(spec, path.extension().and_then(|e| e.to_str()), None)?;
        let text = std::fs::read_to_string(path).map_err(|e| mote_io::IoError::os(path, e))?;
        refuse_trajectory(spec, None, Some(&text))?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "run".into());
        let plist = path.extension().and_then(|e| e.to_str()) != Some("toml");
        Ok(Input {
            name,
            label: spec.to_string(),
            text,
            plist,
        })
    }

    /// A scene given as text (`label` names it in messages).
    pub fn scene(name: &str, label: &str, text: &str) -> Input {
        Input {
            name: name.to_string(),
            label: label.to_string(),
            text: text.to_string(),
            plist: false,
        }
    }

    /// The folder relative file names in the scene resolve against: the
    /// scene file's, or the working folder for examples and texts.
    pub fn folder(&self) -> PathBuf {
        if self.label.starts_with("example:") {
            return PathBuf::from(".");
        }
        Path::new(&self.label)
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."))
    }

    /// The output folder: `-o`, else the scene's `[output] dir`, else
    /// `out/<name>`.
    pub fn output_dir(&self, option: Option<&PathBuf>, scene: Option<&String>) -> PathBuf {
        option
            .cloned()
            .or_else(|| scene.map(PathBuf::from))
            .unwrap_or_else(|| PathBuf::from("out").join(&self.name))
    }

    /// The folder a run of this input writes to: `option`, else the
    /// scene's `[output] dir` (every engine's scene names it there), else
    /// `out/<name>` — known before the run starts (the live viewer follows
    /// the run's table there).
    pub fn run_dir(&self, option: Option<&PathBuf>) -> PathBuf {
        let scene = (!self.plist)
            .then(|| toml::from_str::<toml::Table>(&self.text).ok())
            .flatten()
            .and_then(|t| t.get("output")?.get("dir")?.as_str().map(str::to_string));
        self.output_dir(option, scene.as_ref())
    }

    /// The engine that runs this input, after the scene envelope's check
    /// ([`Engine::read`]).
    pub fn engine(&self) -> Result<Engine, FrontError> {
        if self.plist {
            Ok(Engine::Particles)
        } else {
            Engine::read(&self.label, &self.text)
        }
    }
}
