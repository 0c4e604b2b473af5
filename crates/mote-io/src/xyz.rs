//! Extended XYZ trajectories, as read by ASE and OVITO.
//!
//! Each frame is a count line, a comment line of `key=value` pairs
//! (`Lattice="ax ay az bx by bz cx cy cz"`, `Origin="x y z"`,
//! `Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1`, `Time=`, `pbc=`,
//! and the provenance), then one line per particle.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{IoError, ParseError, Provenance};

/// One frame of particles as plain data.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    /// Simulated time of the frame.
    pub time: f64,
    /// Cell vectors a, b, c (rows) and the cell origin.
    pub cell: [[f64; 3]; 3],
    pub origin: [f64; 3],
    /// Periodicity per axis.
    pub pbc: [bool; 3],
    /// Chemical or type name per particle (no spaces).
    pub species: Vec<String>,
    pub positions: Vec<[f64; 3]>,
    pub velocities: Vec<[f64; 3]>,
    pub radii: Vec<f64>,
}

impl Frame {
    /// A cell enclosing all positions with their radii (for open systems),
    /// padded by `pad` on every side.
    pub fn bounding_cell(
        positions: &[[f64; 3]],
        radii: &[f64],
        pad: f64,
    ) -> ([[f64; 3]; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (p, r) in positions
            .iter()
            .zip(radii.iter().chain(std::iter::repeat(&0.0)))
        {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d] - r);
                hi[d] = hi[d].max(p[d] + r);
            }
        }
        if positions.is_empty() {
            lo = [0.0; 3];
            hi = [1.0; 3];
        }
        let mut cell = [[0.0; 3]; 3];
        for d in 0..3 {
            let len = (hi[d] - lo[d]).max(f64::MIN_POSITIVE) + 2.0 * pad;
            cell[d][d] = len;
            lo[d] -= pad;
        }
        (cell, lo)
    }
}

/// Writes frames to an extended XYZ file; flushes after every frame.
pub struct XyzWriter {
    path: PathBuf,
    out: BufWriter<File>,
    provenance: Provenance,
    exact: bool,
}

impl XyzWriter {
    pub fn create(path: &Path, provenance: Provenance) -> Result<Self, IoError> {
        let file = File::create(path).map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            provenance,
            exact: false,
        })
    }

    /// Opens an existing trajectory to append frames (a resumed run).
    pub fn append(path: &Path, provenance: Provenance) -> Result<Self, IoError> {
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            provenance,
            exact: false,
        })
    }

    /// Writes every number so that it reads back bit for bit (shortest
    /// round-trip form; up to 17 digits) instead of 11 digits for positions
    /// and velocities and 7 for radii: for packings, whose contacts are
    /// gaps of 10⁻¹⁰ and less.
    pub fn exact(mut self) -> Self {
        self.exact = true;
        self
    }

    pub fn write(&mut self, frame: &Frame) -> Result<(), IoError> {
        write_frame_as(&mut self.out, frame, &self.provenance, self.exact)
            .and_then(|_| self.out.flush())
            .map_err(|e| IoError::os(&self.path, e))
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

fn flag(b: bool) -> char {
    if b {
        'T'
    } else {
        'F'
    }
}

/// Writes one frame in extended XYZ.
pub fn write_frame(
    out: &mut impl Write,
    frame: &Frame,
    provenance: &Provenance,
) -> std::io::Result<()> {
    write_frame_as(out, frame, provenance, false)
}

/// Writes one frame in extended XYZ; `exact`: numbers that read back bit
/// for bit (see [`XyzWriter::exact`]).
pub fn write_frame_as(
    out: &mut impl Write,
    frame: &Frame,
    provenance: &Provenance,
    exact: bool,
) -> std::io::Result<()> {
    let n = frame.positions.len();
    let c = &frame.cell;
    writeln!(out, "{n}")?;
    writeln!(
        out,
        "Lattice=\"{} {} {} {} {} {} {} {} {}\" Origin=\"{} {} {}\" \
         Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1 Time={} pbc=\"{} {} {}\" {}",
        c[0][0],
        c[0][1],
        c[0][2],
        c[1][0],
        c[1][1],
        c[1][2],
        c[2][0],
        c[2][1],
        c[2][2],
        frame.origin[0],
        frame.origin[1],
        frame.origin[2],
        frame.time,
        flag(frame.pbc[0]),
        flag(frame.pbc[1]),
        flag(frame.pbc[2]),
        provenance.line()
    )?;
    for i in 0..n {
        let p = frame.positions[i];
        let v = frame.velocities.get(i).copied().unwrap_or([0.0; 3]);
        let r = frame.radii.get(i).copied().unwrap_or(0.0);
        let s = frame.species.get(i).map(String::as_str).unwrap_or("X");
        if exact {
            writeln!(
                out,
                "{s} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
                p[0], p[1], p[2], v[0], v[1], v[2], r
            )?;
        } else {
            writeln!(
                out,
                "{s} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e} {:.6e}",
                p[0], p[1], p[2], v[0], v[1], v[2], r
            )?;
        }
    }
    Ok(())
}

/// Reads all frames written by [`XyzWriter`] (the columns species, pos, velo, radius).
pub fn read_frames(path: &Path) -> Result<Vec<Frame>, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    let lines: Vec<&str> = text.lines().collect();
    let mut frames = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        if lines[k].trim().is_empty() {
            k += 1;
            continue;
        }
        let n: usize = lines[k]
            .trim()
            .parse()
            .map_err(|_| ParseError::new(&name, k + 1, "expected the particle count of a frame"))?;
        let comment = lines
            .get(k + 1)
            .ok_or_else(|| ParseError::new(&name, k + 2, "frame ends before its comment line"))?;
        let mut frame = Frame {
            time: key_value(comment, "Time")
                .and_then(|s| s.parse().ok())
                .unwrap_or(0.0),
            ..Frame::default()
        };
        if let Some(l) = key_value(comment, "Lattice") {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            if v.len() == 9 {
                frame.cell = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
            }
        }
        if let Some(flags) = key_value(comment, "pbc") {
            let v: Vec<bool> = flags
                .split_whitespace()
                .map(|s| matches!(s, "T" | "t" | "True" | "true" | "1"))
                .collect();
            if v.len() == 3 {
                frame.pbc = [v[0], v[1], v[2]];
            }
        }
        if let Some(o) = key_value(comment, "Origin") {
            let v: Vec<f64> = o
                .split_whitespace()
                .filter_map(|s| s.parse().ok())
                .collect();
            if v.len() == 3 {
                frame.origin = [v[0], v[1], v[2]];
            }
        }
        for j in 0..n {
            let ln = k + 2 + j;
            let line = lines.get(ln).ok_or_else(|| {
                ParseError::new(
                    &name,
                    ln + 1,
                    format!("frame announces {n} particles but the file ends"),
                )
            })?;
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() < 8 {
                return Err(ParseError::new(
                    &name,
                    ln + 1,
                    "expected: species x y z vx vy vz radius",
                )
                .into());
            }
            let num = |s: &str| {
                s.parse::<f64>()
                    .map_err(|_| ParseError::new(&name, ln + 1, format!("'{s}' is not a number")))
            };
            frame.species.push(f[0].to_string());
            frame.positions.push([num(f[1])?, num(f[2])?, num(f[3])?]);
            frame.velocities.push([num(f[4])?, num(f[5])?, num(f[6])?]);
            frame.radii.push(num(f[7])?);
        }
        frames.push(frame);
        k += 2 + n;
    }
    Ok(frames)
}

/// The value of `key=value` or `key="quoted value"` in a comment line.
fn key_value<'a>(comment: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!("{key}=");
    let mut start = 0;
    while let Some(pos) = comment[start..].find(&pat) {
        let at = start + pos;
        let before_ok = at == 0 || comment.as_bytes()[at - 1] == b' ';
        let rest = &comment[at + pat.len()..];
        if before_ok {
            return if let Some(stripped) = rest.strip_prefix('"') {
                stripped.find('"').map(|end| &stripped[..end])
            } else {
                Some(rest.split_whitespace().next().unwrap_or(""))
            };
        }
        start = at + pat.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.xyz");
        let prov = Provenance {
            program: "mote test".into(),
            scene: "unit".into(),
            seed: 7,
        };
        let mut w = XyzWriter::create(&path, prov).unwrap();
        let frame = Frame {
            time: 1.5,
            cell: [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]],
            origin: [-1.0, 0.0, 0.5],
            pbc: [true, false, false],
            species: vec!["A".into(), "B".into()],
            positions: vec![[0.1, 0.2, 0.3], [-1.25, 2.5, 1e-7]],
            velocities: vec![[1.0, 0.0, 0.0], [0.0, -2.0, 3.0]],
            radii: vec![0.5, 0.25],
        };
        w.write(&frame).unwrap();
        w.write(&Frame {
            time: 2.5,
            ..frame.clone()
        })
        .unwrap();
        let back = read_frames(&path).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].time, 2.5);
        assert_eq!(back[0].cell, frame.cell);
        assert_eq!(back[0].origin, frame.origin);
        for (a, b) in back[0].positions.iter().zip(&frame.positions) {
            for d in 0..3 {
                assert!((a[d] - b[d]).abs() <= 1e-10 * b[d].abs().max(1e-300));
            }
        }
        assert_eq!(back[0].species, frame.species);
        assert_eq!(back[0].pbc, frame.pbc);
        // exact mode: every number reads back bit for bit
        let exact = dir.path().join("exact.xyz");
        let prov = Provenance {
            program: "mote test".into(),
            scene: "unit".into(),
            seed: 7,
        };
        let awkward = Frame {
            positions: vec![
                [0.1 + 0.2, 1.0 / 3.0, -2.0f64.sqrt()],
                [1e-300, 5e-324, 7.0],
            ],
            radii: vec![0.49999999999999994, std::f64::consts::PI],
            pbc: [true, true, true],
            ..frame.clone()
        };
        XyzWriter::create(&exact, prov)
            .unwrap()
            .exact()
            .write(&awkward)
            .unwrap();
        let back = read_frames(&exact).unwrap();
        assert_eq!(back[0].positions, awkward.positions);
        assert_eq!(back[0].radii, awkward.radii);
        assert_eq!(back[0].pbc, [true, true, true]);
    }

    #[test]
    fn truncated_file_names_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.xyz");
        std::fs::write(&path, "3\ncomment\nA 0 0 0 0 0 0 1\n").unwrap();
        let err = read_frames(&path).unwrap_err().to_string();
        assert!(err.contains("bad.xyz:4:"), "{err}");
    }
}
