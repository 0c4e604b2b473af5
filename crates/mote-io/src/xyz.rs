//! Extended XYZ trajectories, as read and written by ASE and OVITO.
//!
//! Each frame is a count line, a comment line of `key=value` pairs
//! (`Lattice="ax ay az bx by bz cx cy cz"`, `Properties=name:type:count:…`,
//! `Time=`, `pbc=`, the provenance), then one line per particle whose
//! columns the `Properties` key names.
//!
//! mote writes `species:S:1:pos:R:3:velo:R:3:radius:R:1:id:I:1`, then
//! `masses:R:1:momenta:R:3` where masses are known (ASE takes velocities
//! from momenta and masses, not from `velo`, which OVITO reads), then
//! `omega`, `dipole`, `orientation` (x, y, z, w, OVITO's order, with
//! `quaternion_order="xyzw"` on the comment line) and `body` where present. A periodic box whose lower
//! corner is not the origin is written shifted to it (ASE ignores
//! `Origin=`), with the shift in `Shift="x y z"`; mote adds it back on
//! reading. Open boxes, and exact files (whose numbers must read back bit
//! for bit, which a shift would spoil), keep their positions and declare
//! the corner in `Origin=` (OVITO's key).
//!
//! The reader takes what others write: any `Properties` in any order
//! (unknown columns skipped), plain XYZ (symbol x y z) when there is none,
//! and momenta converted to velocities with the masses column or, failing
//! that, the standard atomic weights of the species ([`crate::elements`])
//! — never taken as velocities.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{IoError, ParseError, Provenance};

/// One frame of particles as plain data. Per-particle vectors other than
/// `positions` may be empty (not known).
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
    pub masses: Vec<f64>,
    /// Identifiers (empty: 1, 2, … in order).
    pub ids: Vec<u64>,
    pub angular_velocities: Vec<[f64; 3]>,
    pub dipoles: Vec<[f64; 3]>,
    /// The rigid body each sphere belongs to.
    pub bodies: Vec<u64>,
    /// Orientations as unit quaternions (w, x, y, z) (rigid bodies: each
    /// sphere carries its body's).
    pub orientations: Vec<[f64; 4]>,
}

impl Frame {
    /// A cell enclosing all positions with their radii (for open systems),
    /// padded by `pad` on every side. An axis along which nothing extends
    /// (a planar system, one particle) gets the largest extent of the
    /// others, or 1 where there is none, with the particles in its middle:
    /// a cell of 2.2e-308 is no box a reader can use.
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
        let widest = (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
        let mut cell = [[0.0; 3]; 3];
        for d in 0..3 {
            let mut len = hi[d] - lo[d];
            if len <= 0.0 {
                len = if widest > 0.0 { widest } else { 1.0 };
                lo[d] -= 0.5 * len;
            }
            cell[d][d] = len + 2.0 * pad;
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

/// One number: shortest round-trip form when `exact`, else `digits`
/// significant digits in scientific notation.
fn number(out: &mut String, x: f64, exact: bool, digits: usize) {
    use std::fmt::Write as _;
    let _ = if exact {
        write!(out, " {x:e}")
    } else {
        write!(out, " {x:.digits$e}", digits = digits - 1)
    };
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
    let has = |len: usize| len == n && n > 0;
    let (velocities, masses) = (has(frame.velocities.len()), has(frame.masses.len()));
    let mut properties = String::from("species:S:1:pos:R:3");
    if velocities {
        properties += ":velo:R:3";
    }
    if has(frame.radii.len()) {
        properties += ":radius:R:1";
    }
    properties += ":id:I:1";
    if masses {
        properties += ":masses:R:1";
        if velocities {
            properties += ":momenta:R:3";
        }
    }
    for (len, name) in [
        (frame.angular_velocities.len(), ":omega:R:3"),
        (frame.dipoles.len(), ":dipole:R:3"),
        (frame.orientations.len(), ":orientation:R:4"),
        (frame.bodies.len(), ":body:I:1"),
    ] {
        if has(len) {
            properties += name;
        }
    }
    // A periodic cell is written from the origin (ASE ignores `Origin=`),
    // unless every number must read back bit for bit.
    let shift = if !exact && frame.pbc.iter().any(|&p| p) && frame.origin != [0.0; 3] {
        Some(frame.origin)
    } else {
        None
    };
    let corner = match shift {
        Some(o) => format!("Shift=\"{} {} {}\"", o[0], o[1], o[2]),
        None => format!(
            "Origin=\"{} {} {}\"",
            frame.origin[0], frame.origin[1], frame.origin[2]
        ),
    };
    // Quaternions in OVITO's order (its Orientation.X, .Y, .Z, .W), said
    // on the line so no reader has to guess.
    let order = if has(frame.orientations.len()) {
        " quaternion_order=\"xyzw\""
    } else {
        ""
    };
    writeln!(out, "{n}")?;
    writeln!(
        out,
        "Lattice=\"{} {} {} {} {} {} {} {} {}\" {corner} Properties={properties} Time={} pbc=\"{} {} {}\"{order} {}",
        c[0][0],
        c[0][1],
        c[0][2],
        c[1][0],
        c[1][1],
        c[1][2],
        c[2][0],
        c[2][1],
        c[2][2],
        frame.time,
        flag(frame.pbc[0]),
        flag(frame.pbc[1]),
        flag(frame.pbc[2]),
        provenance.line()
    )?;
    let mut line = String::new();
    for i in 0..n {
        line.clear();
        line += frame.species.get(i).map(String::as_str).unwrap_or("X");
        let mut p = frame.positions[i];
        if let Some(o) = shift {
            for d in 0..3 {
                p[d] -= o[d];
            }
        }
        for x in p {
            number(&mut line, x, exact, 11);
        }
        if velocities {
            for x in frame.velocities[i] {
                number(&mut line, x, exact, 11);
            }
        }
        if has(frame.radii.len()) {
            number(&mut line, frame.radii[i], exact, 7);
        }
        let id = frame.ids.get(i).copied().unwrap_or(i as u64 + 1);
        line += &format!(" {id}");
        if masses {
            let m = frame.masses[i];
            number(&mut line, m, exact, 11);
            if velocities {
                for x in frame.velocities[i] {
                    number(&mut line, m * x, exact, 11);
                }
            }
        }
        for (v, present) in [
            (
                &frame.angular_velocities,
                has(frame.angular_velocities.len()),
            ),
            (&frame.dipoles, has(frame.dipoles.len())),
        ] {
            if present {
                for x in v[i] {
                    number(&mut line, x, exact, 11);
                }
            }
        }
        if has(frame.orientations.len()) {
            let [w, x, y, z] = frame.orientations[i];
            for q in [x, y, z, w] {
                number(&mut line, q, exact, 11);
            }
        }
        if has(frame.bodies.len()) {
            line += &format!(" {}", frame.bodies[i]);
        }
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// A column group of `Properties=`: its name, type letter and width.
#[derive(Debug, Clone, PartialEq)]
struct Column {
    name: String,
    kind: char,
    count: usize,
}

/// What mote does with a column, by its (case-insensitive) name.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Species,
    AtomicNumber,
    Position,
    Velocity,
    Momentum,
    Radius,
    Mass,
    Id,
    Omega,
    Dipole,
    Orientation,
    Body,
    Skip,
}

impl Column {
    fn role(&self) -> Role {
        let name = self.name.to_ascii_lowercase();
        let (s, r, i) = (self.kind == 'S', self.kind == 'R', self.kind == 'I');
        let three = self.count == 3;
        match name.as_str() {
            "species" | "element" | "symbol" | "symbols" | "type" | "particle type"
                if self.count == 1 && (s || i) =>
            {
                Role::Species
            }
            "z" | "numbers" if i && self.count == 1 => Role::AtomicNumber,
            "pos" | "position" | "positions" if r && three => Role::Position,
            "velo" | "vel" | "velocity" | "velocities" if r && three => Role::Velocity,
            "momenta" | "momentum" if r && three => Role::Momentum,
            "radius" | "radii" if r && self.count == 1 => Role::Radius,
            "mass" | "masses" if r && self.count == 1 => Role::Mass,
            "id" | "ids" | "identifier" | "particle identifier" if i && self.count == 1 => Role::Id,
            "omega" | "angular_velocity" | "angular_velocities" | "angular velocity"
                if r && three =>
            {
                Role::Omega
            }
            "dipole" | "dipoles" | "dipole orientation" | "mu" if r && three => Role::Dipole,
            "orientation" | "orientations" | "quaternion" if r && self.count == 4 => {
                Role::Orientation
            }
            "body" | "body_id" | "molecule" | "molecule identifier" if i && self.count == 1 => {
                Role::Body
            }
            _ => Role::Skip,
        }
    }
}

/// The columns of a `Properties=` value (`name:type:count:…`).
fn columns(spec: &str) -> Result<Vec<Column>, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    if !parts.len().is_multiple_of(3) || parts.is_empty() {
        return Err(format!(
            "Properties=\"{spec}\" is not a list of name:type:count triples"
        ));
    }
    parts
        .chunks(3)
        .map(|t| {
            let kind = match t[1] {
                "S" | "R" | "I" | "L" => t[1].chars().next().unwrap_or('S'),
                k => {
                    return Err(format!(
                        "column '{}' has unknown type '{k}' (S, R, I or L)",
                        t[0]
                    ))
                }
            };
            let count: usize =
                t[2].parse().ok().filter(|&c| c > 0).ok_or_else(|| {
                    format!("column '{}' has width '{}', not a count", t[0], t[2])
                })?;
            Ok(Column {
                name: t[0].to_string(),
                kind,
                count,
            })
        })
        .collect()
}

/// Reads all frames of an extended or plain XYZ file.
pub fn read_frames(path: &Path) -> Result<Vec<Frame>, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    Ok(parse_frames(&text, &path.display().to_string())?)
}

/// Parses the frames of XYZ text from the file called `name`.
pub fn parse_frames(text: &str, name: &str) -> Result<Vec<Frame>, ParseError> {
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
            .map_err(|_| ParseError::new(name, k + 1, "expected the particle count of a frame"))?;
        let comment = lines
            .get(k + 1)
            .ok_or_else(|| ParseError::new(name, k + 2, "frame ends before its comment line"))?;
        frames.push(parse_frame(&lines, k, n, comment, name)?);
        k += 2 + n;
    }
    Ok(frames)
}

/// Three numbers of a quoted key (`Origin="x y z"`).
fn triple(comment: &str, key: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = key_value(comment, key)?
        .split_whitespace()
        .filter_map(|s| s.parse().ok())
        .collect();
    (v.len() == 3).then(|| [v[0], v[1], v[2]])
}

/// The frame whose count line is line k (0-based) of `lines`.
/// The order of an `orientation` column's four numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum QuaternionOrder {
    /// (x, y, z, w): OVITO's Orientation.X, .Y, .Z, .W, what mote writes
    /// (saying so with `quaternion_order="xyzw"`).
    Xyzw,
    /// (w, x, y, z): scalar first, as mote wrote before it said which.
    Wxyz,
}

impl QuaternionOrder {
    /// `quaternion_order` on the comment line if given; else a file mote
    /// wrote (`program="mote ..."`) before it gave one is scalar first,
    /// and any other is OVITO's order.
    fn of(comment: &str) -> Result<Self, String> {
        match key_value(comment, "quaternion_order") {
            Some("xyzw") => Ok(Self::Xyzw),
            Some("wxyz") => Ok(Self::Wxyz),
            Some(other) => Err(format!(
                "quaternion_order=\"{other}\": expected \"xyzw\" or \"wxyz\""
            )),
            None if key_value(comment, "program").is_some_and(|p| p.starts_with("mote ")) => {
                Ok(Self::Wxyz)
            }
            None => Ok(Self::Xyzw),
        }
    }
}

fn parse_frame(
    lines: &[&str],
    k: usize,
    n: usize,
    comment: &str,
    name: &str,
) -> Result<Frame, ParseError> {
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
        if v.len() != 9 || v.iter().any(|x| !x.is_finite()) {
            return Err(ParseError::new(
                name,
                k + 2,
                format!("Lattice=\"{l}\" needs nine finite numbers (three cell vectors)"),
            ));
        }
        frame.cell = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
        // ASE's convention: a lattice without pbc is periodic.
        frame.pbc = [true; 3];
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
    let shift = triple(comment, "Shift");
    if let Some(o) = shift.or_else(|| triple(comment, "Origin")) {
        frame.origin = o;
    }
    let cols = match key_value(comment, "Properties") {
        Some(spec) => columns(spec).map_err(|m| ParseError::new(name, k + 2, m))?,
        // Plain XYZ: a symbol and three coordinates (further columns ignored).
        None => columns("species:S:1:pos:R:3").unwrap_or_default(),
    };
    let plain = key_value(comment, "Properties").is_none();
    let order = QuaternionOrder::of(comment).map_err(|m| ParseError::new(name, k + 2, m))?;
    let roles: Vec<Role> = cols.iter().map(Column::role).collect();
    if !roles.contains(&Role::Position) {
        return Err(ParseError::new(
            name,
            k + 2,
            "Properties has no position column (pos:R:3)",
        ));
    }
    let width: usize = cols.iter().map(|c| c.count).sum();
    let mut momenta: Vec<[f64; 3]> = Vec::new();
    // Ids seen in this frame, with their line: one given twice is refused.
    let mut seen = std::collections::HashMap::new();
    for j in 0..n {
        let ln = k + 2 + j;
        let line = lines.get(ln).ok_or_else(|| {
            ParseError::new(
                name,
                ln + 1,
                format!("frame announces {n} particles but the file ends"),
            )
        })?;
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < width || (!plain && f.len() > width) {
            let expected: Vec<String> = cols
                .iter()
                .map(|c| format!("{}×{}", c.name, c.count))
                .collect();
            return Err(ParseError::new(
                name,
                ln + 1,
                format!(
                    "{} columns where Properties names {width}: {}",
                    f.len(),
                    expected.join(" ")
                ),
            ));
        }
        // nan and inf parse as f64 but are no particle's value.
        let num = |s: &str| match s.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(ParseError::new(
                name,
                ln + 1,
                format!("'{s}': must be a finite number"),
            )),
            Err(_) => Err(ParseError::new(
                name,
                ln + 1,
                format!("'{s}' is not a number"),
            )),
        };
        let int = |s: &str| {
            s.parse::<i64>()
                .map_err(|_| ParseError::new(name, ln + 1, format!("'{s}' is not an integer")))
        };
        let mut at = 0;
        for (c, role) in cols.iter().zip(&roles) {
            let v = &f[at..at + c.count];
            at += c.count;
            let vec3 = |v: &[&str]| -> Result<[f64; 3], ParseError> {
                Ok([num(v[0])?, num(v[1])?, num(v[2])?])
            };
            match role {
                Role::Species => frame.species.push(v[0].to_string()),
                Role::AtomicNumber => {
                    let z = int(v[0])?;
                    let symbol = usize::try_from(z)
                        .ok()
                        .and_then(|z| crate::elements::ELEMENTS.get(z))
                        .ok_or_else(|| {
                            ParseError::new(name, ln + 1, format!("atomic number {z} is not 0…118"))
                        })?
                        .0;
                    frame.species.push(symbol.to_string());
                }
                Role::Position => frame.positions.push(vec3(v)?),
                Role::Velocity => frame.velocities.push(vec3(v)?),
                Role::Momentum => momenta.push(vec3(v)?),
                Role::Radius => {
                    let r = num(v[0])?;
                    if r < 0.0 {
                        return Err(ParseError::new(
                            name,
                            ln + 1,
                            format!("radius {r}: must not be negative"),
                        ));
                    }
                    frame.radii.push(r);
                }
                Role::Mass => {
                    let m = num(v[0])?;
                    if m < 0.0 {
                        return Err(ParseError::new(
                            name,
                            ln + 1,
                            format!("mass {m}: must not be negative"),
                        ));
                    }
                    frame.masses.push(m);
                }
                Role::Id => {
                    let id = int(v[0])?;
                    let id = u64::try_from(id).map_err(|_| {
                        ParseError::new(name, ln + 1, format!("id {id} is negative"))
                    })?;
                    if let Some(first) = seen.insert(id, ln) {
                        return Err(ParseError::new(
                            name,
                            ln + 1,
                            format!("id {id} again (first on line {})", first + 1),
                        ));
                    }
                    frame.ids.push(id);
                }
                Role::Omega => frame.angular_velocities.push(vec3(v)?),
                Role::Dipole => frame.dipoles.push(vec3(v)?),
                Role::Orientation => {
                    let q = [num(v[0])?, num(v[1])?, num(v[2])?, num(v[3])?];
                    frame.orientations.push(match order {
                        QuaternionOrder::Xyzw => [q[3], q[0], q[1], q[2]],
                        QuaternionOrder::Wxyz => q,
                    })
                }
                Role::Body => {
                    let b = int(v[0])?;
                    frame.bodies.push(u64::try_from(b).map_err(|_| {
                        ParseError::new(name, ln + 1, format!("body {b} is negative"))
                    })?);
                }
                Role::Skip => {}
            }
        }
    }
    if let Some(o) = shift {
        for p in &mut frame.positions {
            for d in 0..3 {
                p[d] += o[d];
            }
        }
    }
    // Momenta give velocities only where the file has none, divided by
    // the masses column or the species' standard atomic weights.
    if frame.velocities.is_empty() && !momenta.is_empty() {
        for (i, p) in momenta.iter().enumerate() {
            let m = match frame.masses.get(i) {
                Some(&m) => m,
                None => {
                    let s = frame.species.get(i).map(String::as_str).unwrap_or("");
                    crate::elements::standard_mass(s).ok_or_else(|| {
                        ParseError::new(
                            name,
                            k + 3 + i,
                            format!(
                                "momenta need masses: '{s}' is not a chemical symbol and the file has no masses column"
                            ),
                        )
                    })?
                }
            };
            if m.is_nan() || m <= 0.0 {
                return Err(ParseError::new(
                    name,
                    k + 3 + i,
                    format!("mass {m} cannot turn momenta into velocities"),
                ));
            }
            frame.velocities.push([p[0] / m, p[1] / m, p[2] / m]);
        }
    }
    Ok(frame)
}

/// The byte range of every frame of XYZ text, with its `Time=` (0 where
/// absent): for keeping frames verbatim.
pub fn frame_spans(text: &str) -> Vec<(f64, std::ops::Range<usize>)> {
    let mut spans = Vec::new();
    let mut offsets = Vec::new();
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        offsets.push((at, line));
        at += line.len();
    }
    let mut k = 0;
    while k < offsets.len() {
        let (start, line) = offsets[k];
        let Ok(n) = line.trim().parse::<usize>() else {
            k += 1;
            continue;
        };
        let time = offsets
            .get(k + 1)
            .and_then(|(_, c)| key_value(c.trim_end(), "Time"))
            .and_then(|s| s.parse().ok())
            .unwrap_or(0.0);
        let end = offsets.get(k + 2 + n).map_or(text.len(), |(e, _)| *e);
        spans.push((time, start..end));
        k += 2 + n;
    }
    spans
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

    /// A planar system's cell has a usable thickness: the widest extent,
    /// the plane in its middle; one point gets a unit cell around it.
    #[test]
    fn flat_and_single_point_cells_have_a_size() {
        let (cell, origin) = Frame::bounding_cell(&[[0.0, 0.0, 2.0], [4.0, 1.0, 2.0]], &[], 0.0);
        assert_eq!([cell[0][0], cell[1][1], cell[2][2]], [4.0, 1.0, 4.0]);
        assert_eq!(origin, [0.0, 0.0, 0.0]);
        let (cell, origin) = Frame::bounding_cell(&[[1.0, 1.0, 1.0]], &[], 0.5);
        assert_eq!([cell[0][0], cell[1][1], cell[2][2]], [2.0, 2.0, 2.0]);
        assert_eq!(origin, [0.0, 0.0, 0.0]);
    }

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
            ..Default::default()
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
