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
//! accepts it and fills [`Frame::time`]. It also reads the general
//! triclinic box `ITEM: BOX BOUNDS abc origin` (LAMMPS since 2023, OVITO):
//! one line per cell vector with the origin's component as a fourth number.
//!
//! Columns written: `id type x y z`, then `vx vy vz`, `radius`, `mass`,
//! `omegax omegay omegaz`, `mux muy muz`, `quatw quati quatj quatk` and `mol`
//! (rigid body) where the
//! frame has them; numbers with 11 significant digits, or in exact mode
//! ([`DumpWriter::exact`]) the shortest form that reads back bit for bit.

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
    exact: bool,
}

impl DumpWriter {
    pub fn create(path: &Path) -> Result<Self, IoError> {
        let file = File::create(path).map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            types: Vec::new(),
            exact: false,
        })
    }

    /// Opens an existing dump to append frames (a resumed run); species get
    /// type numbers in order of first appearance again.
    pub fn append(path: &Path) -> Result<Self, IoError> {
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            types: Vec::new(),
            exact: false,
        })
    }

    /// Writes every number so that it reads back bit for bit (for packings,
    /// whose contacts are gaps of 10⁻¹⁰ and less).
    pub fn exact(mut self) -> Self {
        self.exact = true;
        self
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
        write_frame_as(&mut self.out, timestep, frame, &types, self.exact)
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
    write_frame_as(out, timestep, frame, types, false)
}

/// [`write_frame`], with numbers that read back bit for bit if `exact`.
pub fn write_frame_as(
    out: &mut impl Write,
    timestep: u64,
    frame: &Frame,
    types: &[usize],
    exact: bool,
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
    let has = |len: usize| len == n && n > 0;
    let vec3s: [(&[[f64; 3]], &str); 3] = [
        (&frame.velocities, "vx vy vz"),
        (&frame.angular_velocities, "omegax omegay omegaz"),
        (&frame.dipoles, "mux muy muz"),
    ];
    let mut header = String::from("ITEM: ATOMS id type x y z");
    for (v, names) in &vec3s[..1] {
        if has(v.len()) {
            header = header + " " + names;
        }
    }
    for (len, name) in [(frame.radii.len(), "radius"), (frame.masses.len(), "mass")] {
        if has(len) {
            header = header + " " + name;
        }
    }
    for (v, names) in &vec3s[1..] {
        if has(v.len()) {
            header = header + " " + names;
        }
    }
    if has(frame.orientations.len()) {
        header += " quatw quati quatj quatk";
    }
    if has(frame.bodies.len()) {
        header += " mol";
    }
    writeln!(out, "{header}")?;
    let mut line = String::new();
    let num = |line: &mut String, x: f64| {
        use std::fmt::Write as _;
        let _ = if exact {
            write!(line, " {x:e}")
        } else {
            write!(line, " {x:.10e}")
        };
    };
    for i in 0..n {
        line.clear();
        let id = frame.ids.get(i).copied().unwrap_or(i as u64 + 1);
        let t = types.get(i).copied().unwrap_or(1);
        line += &format!("{id} {t}");
        for x in frame.positions[i] {
            num(&mut line, x);
        }
        if has(frame.velocities.len()) {
            for x in frame.velocities[i] {
                num(&mut line, x);
            }
        }
        for v in [&frame.radii, &frame.masses] {
            if has(v.len()) {
                num(&mut line, v[i]);
            }
        }
        for (v, _) in &vec3s[1..] {
            if has(v.len()) {
                for x in v[i] {
                    num(&mut line, x);
                }
            }
        }
        if has(frame.orientations.len()) {
            for x in frame.orientations[i] {
                num(&mut line, x);
            }
        }
        if has(frame.bodies.len()) {
            // LAMMPS molecule ids start at 1; 0 means "none".
            line += &format!(" {}", frame.bodies[i] + 1);
        }
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// The time step and byte range of every frame of dump text (a frame
/// starts at `ITEM: TIME` or `ITEM: TIMESTEP`): for keeping frames verbatim.
pub fn frame_spans(text: &str) -> Vec<(u64, std::ops::Range<usize>)> {
    let mut starts: Vec<(usize, u64)> = Vec::new();
    let mut at = 0;
    let mut pending: Option<usize> = None;
    let mut lines = text.split_inclusive('\n').peekable();
    while let Some(line) = lines.next() {
        let here = at;
        at += line.len();
        match line.trim() {
            "ITEM: TIME" => pending = Some(here),
            "ITEM: TIMESTEP" => {
                let step = lines
                    .peek()
                    .and_then(|l| l.trim().parse().ok())
                    .unwrap_or(0);
                starts.push((pending.take().unwrap_or(here), step));
            }
            _ => {}
        }
    }
    (0..starts.len())
        .map(|k| {
            let end = starts.get(k + 1).map_or(text.len(), |s| s.0);
            (starts[k].1, starts[k].0..end)
        })
        .collect()
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
        // Each atom is a line of its own: a count the rest of the file
        // cannot hold is refused before anything is reserved for it.
        let left = lines.len() - k;
        if n > left {
            return Err(err(
                at,
                format!("{n} atoms announced, but the file has only {left} lines left"),
            ));
        }
        let (at, l) = next(&mut k, "ITEM: BOX BOUNDS")?;
        let Some(rest) = l.strip_prefix("ITEM: BOX BOUNDS") else {
            return Err(err(
                at,
                format!("expected 'ITEM: BOX BOUNDS ...', found '{l}'"),
            ));
        };
        let words: Vec<&str> = rest.split_whitespace().collect();
        if words.len() >= 2 && words[..2] == ["abc", "origin"] {
            // General triclinic: "ax ay az ox" / "bx by bz oy" / "cx cy cz oz".
            let mut pbc = [true; 3];
            for (d, f) in words[2..].iter().take(3).enumerate() {
                pbc[d] = *f == "pp";
            }
            let mut cell = [[0.0f64; 3]; 3];
            let mut origin = [0.0f64; 3];
            for d in 0..3 {
                let (at, l) = next(&mut k, "a cell vector and origin component")?;
                let v: Result<Vec<f64>, _> = l.split_whitespace().map(str::parse).collect();
                match v {
                    Ok(v) if v.len() == 4 && v.iter().all(|x| x.is_finite()) => {
                        cell[d] = [v[0], v[1], v[2]];
                        origin[d] = v[3];
                    }
                    _ => return Err(err(
                        at,
                        "expected four finite numbers: a cell vector and a component of the origin"
                            .into(),
                    )),
                }
            }
            let frame = atoms(&mut k, &next, &err, n, cell, origin, pbc, time, timestep)?;
            frames.push(DumpFrame { timestep, frame });
            continue;
        }
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
            if v.iter().any(|x| !x.is_finite()) {
                return Err(err(at, "box bounds must be finite numbers".into()));
            }
            if v[0] > v[1] {
                return Err(err(
                    at,
                    format!("box bounds {} > {}: lo must not exceed hi", v[0], v[1]),
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
        let frame = atoms(&mut k, &next, &err, n, cell, origin, pbc, time, timestep)?;
        frames.push(DumpFrame { timestep, frame });
    }
    Ok(frames)
}

/// Reads `ITEM: ATOMS` and its n rows into a frame with the given box.
/// Positions are unwrapped, wrapped or scaled; rows come back in id order.
#[allow(clippy::too_many_arguments)]
fn atoms<'a>(
    k: &mut usize,
    next: &impl Fn(&mut usize, &str) -> Result<(usize, &'a str), ParseError>,
    err: &impl Fn(usize, String) -> ParseError,
    n: usize,
    cell: [[f64; 3]; 3],
    origin: [f64; 3],
    pbc: [bool; 3],
    time: Option<f64>,
    timestep: u64,
) -> Result<Frame, ParseError> {
    let (at, l) = next(k, "ITEM: ATOMS")?;
    let Some(cols) = l.strip_prefix("ITEM: ATOMS") else {
        return Err(err(at, format!("expected 'ITEM: ATOMS ...', found '{l}'")));
    };
    let cols: Vec<&str> = cols.split_whitespace().collect();
    let col = |c: &str| cols.iter().position(|x| *x == c);
    let triple = |a: &str, b: &str, c: &str| match (col(a), col(b), col(c)) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let (pos, scaled) = if let Some(p) = triple("x", "y", "z") {
        (p, false)
    } else if let Some(p) = triple("xu", "yu", "zu") {
        (p, false)
    } else if let Some(p) = triple("xs", "ys", "zs") {
        (p, true)
    } else {
        return Err(err(
            at,
            "no position columns (x y z, xu yu zu or xs ys zs)".into(),
        ));
    };
    let vel = triple("vx", "vy", "vz");
    let omega = triple("omegax", "omegay", "omegaz");
    let mu = triple("mux", "muy", "muz");
    let quat = match (col("quatw"), col("quati"), col("quatj"), col("quatk")) {
        (Some(w), Some(i), Some(j), Some(k)) => Some([w, i, j, k]),
        _ => None,
    };
    let (id_col, type_col) = (col("id"), col("type"));
    let (radius_col, diameter_col, mass_col, mol_col) =
        (col("radius"), col("diameter"), col("mass"), col("mol"));
    let mut rows: Vec<(u64, usize, usize)> = Vec::with_capacity(n);
    let mut frame = Frame {
        time: time.unwrap_or(timestep as f64),
        cell,
        origin,
        pbc,
        ..Frame::default()
    };
    for j in 0..n {
        let (at, l) = next(k, &format!("atom {} of {n}", j + 1))?;
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
        // nan and inf parse as f64 but are no atom's value.
        let num = |c: usize| match f[c].parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(err(
                at,
                format!("{} = {}: must be a finite number", cols[c], f[c]),
            )),
            Err(_) => Err(err(at, format!("'{}' is not a number", f[c]))),
        };
        let vec3 = |c: [usize; 3]| -> Result<[f64; 3], ParseError> {
            Ok([num(c[0])?, num(c[1])?, num(c[2])?])
        };
        let whole = |c: usize, what: &str| {
            f[c].parse::<u64>()
                .map_err(|_| err(at, format!("'{}' is not {what}", f[c])))
        };
        let mut p = vec3(pos)?;
        if scaled {
            p = [
                origin[0] + p[0] * cell[0][0] + p[1] * cell[1][0] + p[2] * cell[2][0],
                origin[1] + p[0] * cell[0][1] + p[1] * cell[1][1] + p[2] * cell[2][1],
                origin[2] + p[0] * cell[0][2] + p[1] * cell[1][2] + p[2] * cell[2][2],
            ];
        }
        frame.positions.push(p);
        frame
            .velocities
            .push(vel.map(vec3).transpose()?.unwrap_or([0.0; 3]));
        frame
            .species
            .push(type_col.map_or_else(|| "1".to_string(), |c| f[c].to_string()));
        let radius = match (radius_col, diameter_col) {
            (Some(c), _) => num(c)?,
            (None, Some(c)) => 0.5 * num(c)?,
            (None, None) => 0.0,
        };
        if radius < 0.0 {
            return Err(err(at, format!("radius {radius}: must not be negative")));
        }
        frame.radii.push(radius);
        if let Some(c) = mass_col {
            let m = num(c)?;
            if m <= 0.0 {
                return Err(err(at, format!("mass {m}: must be positive")));
            }
            frame.masses.push(m);
        }
        if let Some(c) = omega {
            frame.angular_velocities.push(vec3(c)?);
        }
        if let Some(c) = mu {
            frame.dipoles.push(vec3(c)?);
        }
        if let Some(c) = quat {
            frame
                .orientations
                .push([num(c[0])?, num(c[1])?, num(c[2])?, num(c[3])?]);
        }
        if let Some(c) = mol_col {
            let m = whole(c, "a molecule id")?;
            frame.bodies.push(m.saturating_sub(1));
        }
        let id = match id_col {
            Some(c) => whole(c, "an atom id")?,
            None => j as u64 + 1,
        };
        rows.push((id, j, at));
    }
    // Rows in id order; an id given twice is refused at its second line.
    rows.sort_by_key(|r| (r.0, r.2));
    if let Some(w) = rows.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(err(
            w[1].2,
            format!("atom id {} again (first on line {})", w[1].0, w[0].2 + 1),
        ));
    }
    let order: Vec<usize> = rows.iter().map(|r| r.1).collect();
    fn permute<T: Clone>(v: &mut Vec<T>, order: &[usize]) {
        if v.len() == order.len() {
            *v = order.iter().map(|&j| v[j].clone()).collect();
        }
    }
    permute(&mut frame.positions, &order);
    permute(&mut frame.velocities, &order);
    permute(&mut frame.species, &order);
    permute(&mut frame.radii, &order);
    permute(&mut frame.masses, &order);
    permute(&mut frame.angular_velocities, &order);
    permute(&mut frame.dipoles, &order);
    permute(&mut frame.bodies, &order);
    permute(&mut frame.orientations, &order);
    if id_col.is_some() {
        frame.ids = rows.iter().map(|r| r.0).collect();
    }
    Ok(frame)
}

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

    /// OVITO's (and LAMMPS 2023's) general triclinic box: cell vectors as
    /// rows with the origin's components; it used to be refused.
    #[test]
    fn reads_abc_origin_boxes() {
        let text = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\n\
                    ITEM: BOX BOUNDS abc origin pp pp ff\n\
                    2 0 0 -1\n0.5 3 0 -2\n0 0 4 0.5\n\
                    ITEM: ATOMS id type xs ys zs diameter\n1 1 0.5 0.5 0.5 0.25\n";
        let f = parse(text, "o.dump").unwrap().remove(0).frame;
        assert_eq!(f.cell, [[2.0, 0.0, 0.0], [0.5, 3.0, 0.0], [0.0, 0.0, 4.0]]);
        assert_eq!(f.origin, [-1.0, -2.0, 0.5]);
        assert_eq!(f.pbc, [true, true, false]);
        assert_eq!(f.positions, [[0.25, -0.5, 2.5]]);
        assert_eq!(f.radii, [0.125]);
        let bad = text.replace("0 0 4 0.5", "0 0 4");
        let e = parse(&bad, "o.dump").unwrap_err().to_string();
        assert!(
            e.starts_with("o.dump:8: expected four finite numbers"),
            "{e}"
        );
    }

    /// Exact mode: a packing's positions and radii come back bit for bit
    /// (11 digits left overlaps of 6e-8 in a jammed packing), with every
    /// optional column and the ids.
    #[test]
    fn exact_dumps_round_trip_every_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.dump");
        let f = Frame {
            positions: vec![[0.1 + 0.2, 1.0 / 3.0, 2f64.sqrt()], [1e-300, 0.7, 5e-324]],
            velocities: vec![[1.0 / 7.0, 0.0, -0.1], [0.0, 0.0, 0.0]],
            radii: vec![0.49999999999999994, 0.1 + 0.7],
            masses: vec![1.0 / 3.0, 2.0],
            ids: vec![5, 3],
            angular_velocities: vec![[0.3, 0.0, 0.1], [1.0, 2.0, 3.0]],
            dipoles: vec![[0.0, 0.6, 0.8], [1.0, 0.0, 0.0]],
            bodies: vec![0, 4],
            orientations: vec![[1.0, 0.0, 0.0, 0.0], [0.6, 0.0, 0.8, 1.0 / 3.0]],
            species: vec!["1".into(), "2".into()],
            ..frame([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        };
        let mut w = DumpWriter::create(&path).unwrap().exact();
        w.write(0, &f).unwrap();
        let back = read_frames(&path).unwrap().remove(0).frame;
        // Rows come back in id order (3 before 5).
        let mut want = f.clone();
        want.positions.swap(0, 1);
        want.velocities.swap(0, 1);
        want.radii.swap(0, 1);
        want.masses.swap(0, 1);
        want.ids.swap(0, 1);
        want.angular_velocities.swap(0, 1);
        want.dipoles.swap(0, 1);
        want.bodies.swap(0, 1);
        want.orientations.swap(0, 1);
        want.species.swap(0, 1);
        want.time = back.time;
        assert_eq!(back, want);
    }
}
