//! LAMMPS dump files in text ("atom"/"custom" style), as read by OVITO,
//! MDAnalysis and LAMMPS's own `read_dump`.
//!
//! Each frame is
//!
//! ```text
//! ITEM: TIMESTEP
//! 100
//! ITEM: NUMBER OF ATOMS
//! 2
//! ITEM: BOX BOUNDS pp pp ff
//! xlo xhi
//! ylo yhi
//! zlo zhi
//! ITEM: ATOMS id type x y z vx vy vz radius
//! 1 1 0.5 0.5 0.5 0 0 0 0.1
//! ...
//! ```
//!
//! A triclinic cell in LAMMPS's restricted form (a along x, b in the xy plane)
//! is written as `ITEM: BOX BOUNDS xy xz yz pp pp pp` with the bounding-box
//! bounds and tilt factors (LAMMPS manual, "Triclinic (non-orthogonal)
//! simulation boxes"). Species names become type numbers 1, 2, ... in order of
//! first appearance; the reader gives the type numbers back as species names.
//! The writer omits `ITEM: TIME` (MDAnalysis does not expect it); the reader
//! accepts it and fills [`Frame::time`].

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::xyz::Frame;
use crate::{IoError, ParseError};

/// One frame of a dump: the LAMMPS time step and the particles.
#[derive(Debug, Clone, PartialEq)]
pub struct DumpFrame {
    pub timestep: u64,
    pub frame: Frame,
}

/// Writes frames to a LAMMPS dump text file; flushes after every frame.
pub struct DumpWriter {
    path: PathBuf,
    out: BufWriter<File>,
    types: Vec<String>,
}

impl DumpWriter {
    pub fn create(path: &Path) -> Result<Self, IoError> {
        let file = File::create(path).map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            types: Vec::new(),
        })
    }

    /// Appends one frame at LAMMPS time step `timestep`.
    pub fn write(&mut self, timestep: u64, frame: &Frame) -> Result<(), IoError> {
        let types: Vec<usize> = frame
            .species
            .iter()
            .map(|s| match self.types.iter().position(|t| t == s) {
                Some(k) => k + 1,
                None => {
                    self.types.push(s.clone());
                    self.types.len()
                }
            })
            .collect();
        write_frame(&mut self.out, timestep, frame, &types)
            .and_then(|_| self.out.flush())
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::InvalidInput => IoError::Parse(ParseError::new(
                    self.path.display().to_string(),
                    0,
                    e.to_string(),
                )),
                _ => IoError::os(&self.path, e),
            })
    }

    /// Species names in type order (type k is `species_of_types()[k − 1]`).
    pub fn species_of_types(&self) -> &[String] {
        &self.types
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

fn pbc_flag(p: bool) -> &'static str {
    if p {
        "pp"
    } else {
        "ff"
    }
}

/// Writes one frame; `types[i]` is particle i's type number (1 if missing).
pub fn write_frame(
    out: &mut impl Write,
    timestep: u64,
    frame: &Frame,
    types: &[usize],
) -> std::io::Result<()> {
    let n = frame.positions.len();
    let c = &frame.cell;
    let o = frame.origin;
    let flags = format!(
        "{} {} {}",
        pbc_flag(frame.pbc[0]),
        pbc_flag(frame.pbc[1]),
        pbc_flag(frame.pbc[2])
    );
    writeln!(
        out,
        "ITEM: TIMESTEP\n{timestep}\nITEM: NUMBER OF ATOMS\n{n}"
    )?;
    let restricted = c[0][1] == 0.0 && c[0][2] == 0.0 && c[1][2] == 0.0;
    if !restricted {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "cell is not in LAMMPS's restricted triclinic form (a along x, b in the xy plane)",
        ));
    }
    let (lx, ly, lz) = (c[0][0], c[1][1], c[2][2]);
    let (xy, xz, yz) = (c[1][0], c[2][0], c[2][1]);
    if xy == 0.0 && xz == 0.0 && yz == 0.0 {
        writeln!(out, "ITEM: BOX BOUNDS {flags}")?;
        writeln!(out, "{:e} {:e}", o[0], o[0] + lx)?;
        writeln!(out, "{:e} {:e}", o[1], o[1] + ly)?;
        writeln!(out, "{:e} {:e}", o[2], o[2] + lz)?;
    } else {
        // Bounding box of the parallelepiped, as LAMMPS writes it.
        let xlo_b = o[0] + 0f64.min(xy).min(xz).min(xy + xz);
        let xhi_b = o[0] + lx + 0f64.max(xy).max(xz).max(xy + xz);
        let ylo_b = o[1] + 0f64.min(yz);
        let yhi_b = o[1] + ly + 0f64.max(yz);
        writeln!(out, "ITEM: BOX BOUNDS xy xz yz {flags}")?;
        writeln!(out, "{xlo_b:e} {xhi_b:e} {xy:e}")?;
        writeln!(out, "{ylo_b:e} {yhi_b:e} {xz:e}")?;
        writeln!(out, "{:e} {:e} {yz:e}", o[2], o[2] + lz)?;
    }
    writeln!(out, "ITEM: ATOMS id type x y z vx vy vz radius")?;
    for i in 0..n {
        let p = frame.positions[i];
        let v = frame.velocities.get(i).copied().unwrap_or([0.0; 3]);
        let r = frame.radii.get(i).copied().unwrap_or(0.0);
        let t = types.get(i).copied().unwrap_or(1);
        writeln!(
            out,
            "{} {t} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e} {:.6e}",
            i + 1,
            p[0],
            p[1],
            p[2],
            v[0],
            v[1],
            v[2],
            r
        )?;
    }
    Ok(())
}

/// Reads every frame of a LAMMPS dump text file. Columns are found by name
/// (`id`, `type`, `x y z` or `xu yu zu` or scaled `xs ys zs`, optional `vx vy vz`,
/// `radius`); particles are returned in `id` order. Errors name `file:line`.
pub fn read_frames(path: &Path) -> Result<Vec<DumpFrame>, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    parse(&text, &name).map_err(IoError::from)
}

/// Parses dump text; `name` is used in error messages.
pub fn parse(text: &str, name: &str) -> Result<Vec<DumpFrame>, ParseError> {
    let lines: Vec<&str> = text.lines().collect();
    let err = |k: usize, m: String| ParseError::new(name, k + 1, m);
    let mut k = 0;
    let mut frames = Vec::new();
    let next = |k: &mut usize, what: &str| -> Result<(usize, &str), ParseError> {
        let at = *k;
        let l = lines
            .get(at)
            .ok_or_else(|| ParseError::new(name, at + 1, format!("file ends; expected {what}")))?;
        *k += 1;
        Ok((at, l.trim()))
    };
    while k < lines.len() {
        if lines[k].trim().is_empty() {
            k += 1;
            continue;
        }
        let mut time = None;
        let (at, l) = next(&mut k, "ITEM: TIMESTEP")?;
        let (at, l) = if l == "ITEM: TIME" {
            let (a2, v) = next(&mut k, "the time")?;
            time = Some(
                v.parse::<f64>()
                    .map_err(|_| err(a2, format!("'{v}' is not a time")))?,
            );
            next(&mut k, "ITEM: TIMESTEP")?
        } else {
            (at, l)
        };
        if l != "ITEM: TIMESTEP" {
            return Err(err(at, format!("expected 'ITEM: TIMESTEP', found '{l}'")));
        }
        let (at, v) = next(&mut k, "the time step")?;
        let timestep: u64 = v
            .parse()
            .map_err(|_| err(at, format!("'{v}' is not a time step (a whole number)")))?;
        let (at, l) = next(&mut k, "ITEM: NUMBER OF ATOMS")?;
        if l != "ITEM: NUMBER OF ATOMS" {
            return Err(err(
                at,
                format!("expected 'ITEM: NUMBER OF ATOMS', found '{l}'"),
            ));
        }
        let (at, v) = next(&mut k, "the number of atoms")?;
        let n: usize = v
            .parse()
            .map_err(|_| err(at, format!("'{v}' is not a number of atoms")))?;
        let (at, l) = next(&mut k, "ITEM: BOX BOUNDS")?;
        let Some(rest) = l.strip_prefix("ITEM: BOX BOUNDS") else {
            return Err(err(
                at,
                format!("expected 'ITEM: BOX BOUNDS ...', found '{l}'"),
            ));
        };
        let words: Vec<&str> = rest.split_whitespace().collect();
        let triclinic = words.len() >= 3 && words[..3] == ["xy", "xz", "yz"];
        let flags = if triclinic { &words[3..] } else { &words[..] };
        let mut pbc = [true; 3];
        for (d, f) in flags.iter().take(3).enumerate() {
            pbc[d] = *f == "pp";
        }
        let mut b = [[0.0f64; 3]; 3];
        for row in b.iter_mut() {
            let (at, l) = next(&mut k, "a line of box bounds")?;
            let v: Result<Vec<f64>, _> = l.split_whitespace().map(str::parse).collect();
            let v = v.map_err(|_| err(at, "expected box bounds: lo hi [tilt]".into()))?;
            let want = if triclinic { 3 } else { 2 };
            if v.len() != want {
                return Err(err(
                    at,
                    format!(
                        "expected {want} numbers (lo hi{})",
                        if triclinic { " tilt" } else { "" }
                    ),
                ));
            }
            row[..want].copy_from_slice(&v);
        }
        let (xy, xz, yz) = if triclinic {
            (b[0][2], b[1][2], b[2][2])
        } else {
            (0.0, 0.0, 0.0)
        };
        let xlo = b[0][0] - 0f64.min(xy).min(xz).min(xy + xz);
        let xhi = b[0][1] - 0f64.max(xy).max(xz).max(xy + xz);
        let ylo = b[1][0] - 0f64.min(yz);
        let yhi = b[1][1] - 0f64.max(yz);
        let (zlo, zhi) = (b[2][0], b[2][1]);
        let cell = [
            [xhi - xlo, 0.0, 0.0],
            [xy, yhi - ylo, 0.0],
            [xz, yz, zhi - zlo],
        ];
        let origin = [xlo, ylo, zlo];
        let (at, l) = next(&mut k, "ITEM: ATOMS")?;
        let Some(cols) = l.strip_prefix("ITEM: ATOMS") else {
            return Err(err(at, format!("expected 'ITEM: ATOMS ...', found '{l}'")));
        };
        let cols: Vec<&str> = cols.split_whitespace().collect();
        let col = |c: &str| cols.iter().position(|x| *x == c);
        let (pos, scaled) = if let (Some(x), Some(y), Some(z)) = (col("x"), col("y"), col("z")) {
            ([x, y, z], false)
        } else if let (Some(x), Some(y), Some(z)) = (col("xu"), col("yu"), col("zu")) {
            ([x, y, z], false)
        } else if let (Some(x), Some(y), Some(z)) = (col("xs"), col("ys"), col("zs")) {
            ([x, y, z], true)
        } else {
            return Err(err(
                at,
                "no position columns (x y z, xu yu zu or xs ys zs)".into(),
            ));
        };
        let vel = match (col("vx"), col("vy"), col("vz")) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            _ => None,
        };
        let (id_col, type_col, rad_col) = (col("id"), col("type"), col("radius"));
        let mut rows: Vec<(u64, Frame1)> = Vec::with_capacity(n);
        for j in 0..n {
            let (at, l) = next(&mut k, &format!("atom {} of {n}", j + 1))?;
            let f: Vec<&str> = l.split_whitespace().collect();
            if f.len() < cols.len() {
                return Err(err(
                    at,
                    format!(
                        "{} values, but ITEM: ATOMS names {} columns",
                        f.len(),
                        cols.len()
                    ),
                ));
            }
            let num = |c: usize| {
                f[c].parse::<f64>()
                    .map_err(|_| err(at, format!("'{}' is not a number", f[c])))
            };
            let mut p = [num(pos[0])?, num(pos[1])?, num(pos[2])?];
            if scaled {
                p = [
                    origin[0] + p[0] * cell[0][0] + p[1] * cell[1][0] + p[2] * cell[2][0],
                    origin[1] + p[1] * cell[1][1] + p[2] * cell[2][1],
                    origin[2] + p[2] * cell[2][2],
                ];
            }
            let v = match vel {
                Some(c) => [num(c[0])?, num(c[1])?, num(c[2])?],
                None => [0.0; 3],
            };
            let id = match id_col {
                Some(c) => f[c]
                    .parse::<u64>()
                    .map_err(|_| err(at, format!("'{}' is not an atom id", f[c])))?,
                None => j as u64 + 1,
            };
            let species = type_col.map_or_else(|| "1".to_string(), |c| f[c].to_string());
            let radius = match rad_col {
                Some(c) => num(c)?,
                None => 0.0,
            };
            rows.push((id, (species, p, v, radius)));
        }
        rows.sort_by_key(|r| r.0);
        let mut frame = Frame {
            time: time.unwrap_or(timestep as f64),
            cell,
            origin,
            pbc,
            ..Frame::default()
        };
        for (_, (s, p, v, r)) in rows {
            frame.species.push(s);
            frame.positions.push(p);
            frame.velocities.push(v);
            frame.radii.push(r);
        }
        frames.push(DumpFrame { timestep, frame });
    }
    Ok(frames)
}

type Frame1 = (String, [f64; 3], [f64; 3], f64);

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(cell: [[f64; 3]; 3]) -> Frame {
        Frame {
            time: 0.0,
            cell,
            origin: [-1.0, 0.5, 2.0],
            pbc: [true, true, false],
            species: vec!["Fe".into(), "O".into(), "Fe".into()],
            positions: vec![[0.1, 0.2, 0.3], [-0.75, 2.5, 3.0], [1.0, 1.0, 1e-9]],
            velocities: vec![[1.0, 0.0, 0.0], [0.0, -2.0, 3.0], [0.5, 0.5, 0.5]],
            radii: vec![0.5, 0.25, 0.5],
            ..Default::default()
        }
    }

    #[test]
    fn orthogonal_and_triclinic_frames_round_trip() {
        for cell in [
            [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]],
            [[2.0, 0.0, 0.0], [0.5, 3.0, 0.0], [-0.25, 0.75, 4.0]],
        ] {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("t.dump");
            let mut w = DumpWriter::create(&path).unwrap();
            let f = frame(cell);
            w.write(0, &f).unwrap();
            w.write(100, &f).unwrap();
            assert_eq!(w.species_of_types(), ["Fe", "O"]);
            let back = read_frames(&path).unwrap();
            assert_eq!(back.len(), 2);
            assert_eq!(back[1].timestep, 100);
            let b = &back[0].frame;
            for (got, want) in b.cell.iter().flatten().zip(cell.iter().flatten()) {
                assert!((got - want).abs() < 1e-12, "{:?}", b.cell);
            }
            for (got, want) in b.origin.iter().zip(&f.origin) {
                assert!((got - want).abs() < 1e-12);
            }
            assert_eq!(b.pbc, [true, true, false]);
            assert_eq!(b.species, ["1", "2", "1"]);
            for (a, c) in b.positions.iter().zip(&f.positions) {
                for d in 0..3 {
                    assert!((a[d] - c[d]).abs() <= 1e-10 * c[d].abs().max(1e-300));
                }
            }
            assert_eq!(b.velocities, f.velocities);
            assert_eq!(b.radii, f.radii);
        }
    }

    #[test]
    fn reads_lammps_variants_and_names_bad_lines() {
        // Scaled coordinates, shuffled ids, ITEM: TIME, no velocities.
        let text = "ITEM: TIME\n0.5\nITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n2\n\
                    ITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n-5 5\n\
                    ITEM: ATOMS id type xs ys zs\n2 1 0.5 0.5 0.5\n1 2 0.1 0.2 0.3\n";
        let f = parse(text, "v.dump").unwrap();
        assert_eq!(f[0].timestep, 7);
        assert_eq!(f[0].frame.time, 0.5);
        assert_eq!(
            f[0].frame.positions,
            vec![[1.0, 2.0, -2.0], [5.0, 5.0, 0.0]]
        );
        assert_eq!(f[0].frame.species, ["2", "1"]);
        let bad = "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n\
                   0 1\n0 1\n0 1\nITEM: ATOMS id type x y z\n1 1 0 0 0\n2 1 0 zero 0\n";
        let e = parse(bad, "bad.dump").unwrap_err().to_string();
        assert_eq!(e, "bad.dump:11: 'zero' is not a number");
        let short = &bad[..bad.find("2 1 0 zero").unwrap()];
        let e = parse(short, "short.dump").unwrap_err().to_string();
        assert!(e.starts_with("short.dump:11: file ends"), "{e}");
        // A cell not in LAMMPS's form is refused with a message, not a panic.
        let dir = tempfile::tempdir().unwrap();
        let mut w = DumpWriter::create(&dir.path().join("x.dump")).unwrap();
        let e = w
            .write(
                0,
                &frame([[1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            )
            .unwrap_err()
            .to_string();
        assert!(e.contains("restricted triclinic"), "{e}");
    }
}
