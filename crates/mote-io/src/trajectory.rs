//! Trajectories in any of mote's formats behind one writer and one reader:
//! extended XYZ, LAMMPS dump, GSD, and VTK (a `.pvd` collection of `.vtp`
//! poly data, which OVITO and ParaView read as particles). Engines take the
//! format from `[output] trajectory_format` or a file's extension.

use std::path::{Path, PathBuf};

use crate::gsd::GsdWriter;
use crate::lammps_dump::DumpWriter;
use crate::vtu::PvdWriter;
use crate::xyz::{Frame, XyzWriter};
use crate::{IoError, ParseError, Provenance};

/// A trajectory file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    /// Extended XYZ (ASE, OVITO).
    #[default]
    Xyz,
    /// LAMMPS dump text (LAMMPS `read_dump`, OVITO, MDAnalysis).
    Dump,
    /// HOOMD-blue's GSD (HOOMD, OVITO, MDAnalysis, `gsd`).
    Gsd,
    /// VTK: `.vtp` poly data per frame listed in a `.pvd` (ParaView, OVITO).
    Vtk,
}

impl Format {
    /// The names `trajectory_format` accepts.
    pub const NAMES: &'static str = "xyz, dump, gsd, vtk";

    /// A format by name (`xyz`, `dump`, `gsd`, `vtk`, or an extension).
    pub fn named(name: &str) -> Option<Self> {
        Some(match name.to_ascii_lowercase().as_str() {
            "xyz" | "extxyz" => Format::Xyz,
            "dump" | "lammps" | "lammpstrj" => Format::Dump,
            "gsd" => Format::Gsd,
            "vtk" | "vtp" | "pvd" | "paraview" => Format::Vtk,
            _ => return None,
        })
    }

    /// The format of a file by its extension.
    pub fn of_path(path: &Path) -> Option<Self> {
        Self::named(path.extension()?.to_str()?)
    }

    /// The extension of its (main) file.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Xyz => "xyz",
            Format::Dump => "dump",
            Format::Gsd => "gsd",
            Format::Vtk => "pvd",
        }
    }
}

/// Writes frames in one format.
pub enum TrajectoryWriter {
    Xyz(XyzWriter),
    Dump(DumpWriter),
    Gsd(GsdWriter),
    Vtk(PvdWriter),
}

impl TrajectoryWriter {
    /// A new file; `exact`: numbers that read back bit for bit (all
    /// formats but VTK, whose ASCII numbers are exact anyway).
    pub fn create(
        path: &Path,
        format: Format,
        provenance: Provenance,
        exact: bool,
    ) -> Result<Self, IoError> {
        let w = match format {
            Format::Xyz => TrajectoryWriter::Xyz(XyzWriter::create(path, provenance)?),
            Format::Dump => TrajectoryWriter::Dump(DumpWriter::create(path)?),
            Format::Gsd => TrajectoryWriter::Gsd(GsdWriter::create(path)?),
            Format::Vtk => TrajectoryWriter::Vtk(PvdWriter::create(path, provenance)?.poly_data()),
        };
        Ok(if exact { w.exact() } else { w })
    }

    /// Continues a file an interrupted run wrote (frames past its
    /// checkpoint already dropped, see [`keep_until`]).
    pub fn append(
        path: &Path,
        format: Format,
        provenance: Provenance,
        exact: bool,
    ) -> Result<Self, IoError> {
        let w = match format {
            Format::Xyz => TrajectoryWriter::Xyz(XyzWriter::append(path, provenance)?),
            Format::Dump => TrajectoryWriter::Dump(DumpWriter::append(path)?),
            Format::Gsd => TrajectoryWriter::Gsd(GsdWriter::append(path)?),
            Format::Vtk => TrajectoryWriter::Vtk(PvdWriter::append(path, provenance)?.poly_data()),
        };
        Ok(if exact { w.exact() } else { w })
    }

    /// The writer in exact mode (VTK is always exact).
    fn exact(self) -> Self {
        match self {
            TrajectoryWriter::Xyz(w) => TrajectoryWriter::Xyz(w.exact()),
            TrajectoryWriter::Dump(w) => TrajectoryWriter::Dump(w.exact()),
            TrajectoryWriter::Gsd(w) => TrajectoryWriter::Gsd(w.exact()),
            vtk @ TrajectoryWriter::Vtk(_) => vtk,
        }
    }

    /// Appends the frame of step `step`.
    pub fn write(&mut self, step: u64, frame: &Frame) -> Result<(), IoError> {
        match self {
            TrajectoryWriter::Xyz(w) => w.write(frame),
            TrajectoryWriter::Dump(w) => w.write(step, frame),
            TrajectoryWriter::Gsd(w) => w.write(step, frame),
            TrajectoryWriter::Vtk(w) => w.write(frame).map(|_| ()),
        }
    }

    /// The file (for VTK, the collection).
    pub fn path(&self) -> PathBuf {
        match self {
            TrajectoryWriter::Xyz(w) => w.path().to_path_buf(),
            TrajectoryWriter::Dump(w) => w.path().to_path_buf(),
            TrajectoryWriter::Gsd(w) => w.path().to_path_buf(),
            TrajectoryWriter::Vtk(w) => w.pvd_path(),
        }
    }
}

/// Drops the frames after time `t` (step `step` for dumps and GSD, whose
/// frames carry steps) from a trajectory, keeping the rest byte for byte:
/// what a run resumed from a checkpoint at (step, t) continues.
pub fn keep_until(path: &Path, format: Format, step: u64, t: f64) -> Result<(), IoError> {
    match format {
        Format::Xyz | Format::Dump => {
            let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
            let spans = if format == Format::Xyz {
                crate::xyz::frame_spans(&text)
                    .into_iter()
                    .map(|(time, r)| (time <= t, r))
                    .collect::<Vec<_>>()
            } else {
                crate::lammps_dump::frame_spans(&text)
                    .into_iter()
                    .map(|(s, r)| (s <= step, r))
                    .collect()
            };
            let kept: String = spans
                .into_iter()
                .filter(|(keep, _)| *keep)
                .map(|(_, r)| &text[r])
                .collect();
            std::fs::write(path, kept).map_err(|e| IoError::os(path, e))
        }
        Format::Gsd => crate::gsd::keep_until_step(path, step),
        Format::Vtk => PvdWriter::append(path, Provenance::default())?.keep_until(t),
    }
}

/// Frame `frame` of `frames` (default the last; negative counts from the
/// end), or a message naming the file and how many frames it has.
pub fn pick<'a>(frames: &'a [Frame], frame: Option<i64>, path: &Path) -> Result<&'a Frame, String> {
    let k = match frame {
        None => frames.len() as i64 - 1,
        Some(f) if f < 0 => frames.len() as i64 + f,
        Some(f) => f,
    };
    usize::try_from(k)
        .ok()
        .and_then(|k| frames.get(k))
        .ok_or_else(|| {
            format!(
                "{}: no frame {} among its {} frames",
                path.display(),
                frame.unwrap_or(-1),
                frames.len()
            )
        })
}

/// Every frame of a trajectory, by its extension: `.xyz`/`.extxyz`,
/// `.dump`/`.lammpstrj`, `.gsd`, `.vtu`/`.vtp` (one frame), `.pvd`.
pub fn read_frames(path: &Path) -> Result<Vec<Frame>, IoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    Ok(match ext.as_str() {
        "xyz" | "extxyz" => crate::xyz::read_frames(path)?,
        "dump" | "lammpstrj" => crate::lammps_dump::read_frames(path)?
            .into_iter()
            .map(|d| d.frame)
            .collect(),
        "gsd" => crate::gsd::read_frames(path)?,
        "vtu" | "vtp" => vec![crate::vtu::read_vtu(path)?],
        "pvd" => crate::vtu::read_pvd(path)?
            .into_iter()
            .map(|(_, p)| crate::vtu::read_vtu(&p))
            .collect::<Result<_, _>>()?,
        _ => {
            return Err(ParseError::new(
                path.display().to_string(),
                0,
                "unknown trajectory format; expected .xyz, .extxyz, .dump, .lammpstrj, .gsd, .vtu, .vtp or .pvd",
            )
            .into())
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(t: f64) -> Frame {
        Frame {
            time: t,
            cell: [[3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0]],
            pbc: [true; 3],
            species: vec!["X".into(), "X".into()],
            positions: vec![[0.5, 1.0 / 3.0, 2.0], [t, 1.0, 2.5]],
            velocities: vec![[0.1, 0.2, 0.3], [0.0, 0.0, 1.0]],
            radii: vec![0.5, 0.25],
            masses: vec![1.0, 1.0],
            ..Frame::default()
        }
    }

    /// Every format: four frames written, the last two dropped as after a
    /// checkpoint at step 1 (t = 1), two more appended; the reader by
    /// extension gives frames 0, 1, 2', 3' exactly (VTK: 17 digits).
    #[test]
    fn every_format_writes_trims_appends_and_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        for format in [Format::Xyz, Format::Dump, Format::Gsd, Format::Vtk] {
            let path = dir.path().join(format!("t.{}", format.extension()));
            let mut w =
                TrajectoryWriter::create(&path, format, Provenance::default(), true).unwrap();
            for k in 0..4 {
                w.write(k, &frame(k as f64)).unwrap();
            }
            drop(w);
            keep_until(&path, format, 1, 1.0).unwrap();
            let mut w =
                TrajectoryWriter::append(&path, format, Provenance::default(), true).unwrap();
            for k in 2..4 {
                w.write(k, &frame(k as f64 + 0.5)).unwrap();
            }
            let back = read_frames(&path).unwrap();
            let times: Vec<f64> = [0.0, 1.0, 2.5, 3.5].to_vec();
            assert_eq!(back.len(), 4, "{format:?}");
            for (b, t) in back.iter().zip(times) {
                let want = frame(t);
                assert_eq!(b.positions, want.positions, "{format:?} at {t}");
                assert_eq!(b.radii, want.radii, "{format:?} at {t}");
                if format != Format::Dump {
                    assert_eq!(b.time, t, "{format:?}");
                }
            }
            assert_eq!(Format::of_path(&path), Some(format));
        }
    }
}
