//! GSD, HOOMD-blue's General Simulation Data format (file layer 2.1, the
//! `hoomd` schema 1.4), read by HOOMD-blue, OVITO, MDAnalysis and the `gsd`
//! Python package. No Rust crate implements it; this follows the published
//! layout (gsd.readthedocs.io, "File layer" and "HOOMD schema").
//!
//! A file is a 256-byte header (magic 0x65DF65DF65DF65DF, the locations
//! and capacities of the index and the name list, application, schema and
//! versions), data chunks, an index of 32-byte entries (frame, N, location,
//! M, name id, type, flags) sorted by frame then name id and ended by the
//! first entry at location 0, and a name list of 0-terminated names (the
//! id of a name is its place in the list). Frames are appended: data at the
//! end of the file, then their index entries into the free slots of the
//! index (a block twice as large is written at the end when it fills), then
//! the header, so a run killed mid-frame leaves every earlier frame whole.
//!
//! Each frame holds the schema's `configuration/step`, `configuration/box`
//! (L_x, L_y, L_z, xy, xz, yz), `particles/N`, `position`, `velocity`,
//! `typeid`, `types`, `mass`, `diameter` and `body` (where known), all in
//! f32 as the schema says, with positions relative to the box centre
//! (HOOMD's boxes are centred on the origin). mote's own keys, which other
//! readers show as logged quantities: `log/mote/time`, `log/mote/origin`,
//! `log/mote/cell`, `log/mote/pbc`, and in exact files
//! `log/particles/mote_position`, `mote_velocity`, `mote_radius` and
//! `mote_mass` in f64, so that mote reads its packings back bit for bit.

use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::xyz::Frame;
use crate::{IoError, ParseError};

const MAGIC: u64 = 0x65DF_65DF_65DF_65DF;
const HEADER_SIZE: u64 = 256;
const ENTRY_SIZE: u64 = 32;
const NAME_SIZE: u64 = 64;

/// `gsd_make_version`: major in the high 16 bits.
const fn version(major: u32, minor: u32) -> u32 {
    (major << 16) | minor
}

/// Chunk data types of the file layer (`gsd_type`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(u8)]
enum Kind {
    U8 = 1,
    U32 = 3,
    U64 = 4,
    I8 = 5,
    I32 = 7,
    F32 = 9,
    F64 = 10,
}

/// Bytes per element of a type id (0: unknown).
fn size_of(kind: u8) -> u64 {
    match kind {
        1 | 5 | 11 => 1,
        2 | 6 => 2,
        3 | 7 | 9 => 4,
        4 | 8 | 10 => 8,
        _ => 0,
    }
}

/// One index entry.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    frame: u64,
    n: u64,
    location: i64,
    m: u32,
    id: u16,
    kind: u8,
}

impl Entry {
    fn bytes(&self) -> [u8; 32] {
        let mut b = [0u8; 32];
        b[0..8].copy_from_slice(&self.frame.to_le_bytes());
        b[8..16].copy_from_slice(&self.n.to_le_bytes());
        b[16..24].copy_from_slice(&self.location.to_le_bytes());
        b[24..28].copy_from_slice(&self.m.to_le_bytes());
        b[28..30].copy_from_slice(&self.id.to_le_bytes());
        b[30] = self.kind;
        b
    }

    fn parse(b: &[u8]) -> Self {
        let u64_at = |k: usize| u64::from_le_bytes(b[k..k + 8].try_into().unwrap_or([0; 8]));
        Self {
            frame: u64_at(0),
            n: u64_at(8),
            location: u64_at(16) as i64,
            m: u32::from_le_bytes(b[24..28].try_into().unwrap_or([0; 4])),
            id: u16::from_le_bytes([b[28], b[29]]),
            kind: b[30],
        }
    }
}

/// A chunk to write: name, type, rows, columns, little-endian bytes.
struct Chunk {
    name: String,
    kind: Kind,
    n: u64,
    m: u32,
    data: Vec<u8>,
}

fn chunk<T: Copy>(name: &str, kind: Kind, m: u32, values: &[T], le: fn(T) -> Vec<u8>) -> Chunk {
    let data: Vec<u8> = values.iter().flat_map(|&v| le(v)).collect();
    Chunk {
        name: name.to_string(),
        kind,
        n: (values.len() / m as usize) as u64,
        m,
        data,
    }
}

fn f32s(name: &str, m: u32, v: &[f64]) -> Chunk {
    chunk(name, Kind::F32, m, v, |x| (x as f32).to_le_bytes().to_vec())
}

fn f64s(name: &str, m: u32, v: &[f64]) -> Chunk {
    chunk(name, Kind::F64, m, v, |x| x.to_le_bytes().to_vec())
}

/// Writes frames to a GSD file (hoomd schema).
pub struct GsdWriter {
    path: PathBuf,
    file: File,
    index_location: u64,
    index_capacity: u64,
    entries: u64,
    namelist_location: u64,
    namelist_capacity: u64,
    names: Vec<String>,
    end: u64,
    frame: u64,
    exact: bool,
}

impl GsdWriter {
    /// A new file with room for 128 index entries and 1 kB of names.
    pub fn create(path: &Path) -> Result<Self, IoError> {
        let os = |e| IoError::os(path, e);
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .map_err(os)?;
        let mut w = Self {
            path: path.to_path_buf(),
            file,
            index_location: HEADER_SIZE,
            index_capacity: 128,
            entries: 0,
            namelist_location: HEADER_SIZE + 128 * ENTRY_SIZE,
            namelist_capacity: 1024,
            names: Vec::new(),
            end: HEADER_SIZE + 128 * ENTRY_SIZE + 1024,
            frame: 0,
            exact: false,
        };
        let zeros = vec![0u8; (w.end - HEADER_SIZE) as usize];
        w.at(HEADER_SIZE, &zeros).map_err(os)?;
        w.header().map_err(os)?;
        Ok(w)
    }

    /// Opens a file mote wrote to append frames (a resumed run).
    pub fn append(path: &Path) -> Result<Self, IoError> {
        let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
        let name = path.display().to_string();
        let layout = Layout::parse(&bytes, &name)?;
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            index_location: layout.index_location,
            index_capacity: layout.index_capacity,
            entries: layout.entries.len() as u64,
            namelist_location: layout.namelist_location,
            namelist_capacity: layout.namelist_capacity,
            frame: layout.entries.last().map_or(0, |e| e.frame + 1),
            names: layout.names,
            end: bytes.len() as u64,
            exact: false,
        })
    }

    /// Also stores positions, velocities, radii and masses in f64, which
    /// mote reads back bit for bit (packings).
    pub fn exact(mut self) -> Self {
        self.exact = true;
        self
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    fn at(&mut self, offset: u64, bytes: &[u8]) -> std::io::Result<()> {
        self.file.seek(SeekFrom::Start(offset))?;
        self.file.write_all(bytes)
    }

    fn header(&mut self) -> std::io::Result<()> {
        let mut h = Vec::with_capacity(HEADER_SIZE as usize);
        for v in [
            MAGIC,
            self.index_location,
            self.index_capacity,
            self.namelist_location,
            self.namelist_capacity / NAME_SIZE,
        ] {
            h.extend_from_slice(&v.to_le_bytes());
        }
        h.extend_from_slice(&version(1, 4).to_le_bytes());
        h.extend_from_slice(&version(2, 1).to_le_bytes());
        let mut text = |s: &str| {
            let mut field = [0u8; 64];
            field[..s.len().min(63)].copy_from_slice(&s.as_bytes()[..s.len().min(63)]);
            h.extend_from_slice(&field);
        };
        text(&format!("mote {}", env!("CARGO_PKG_VERSION")));
        text("hoomd");
        h.resize(HEADER_SIZE as usize, 0);
        self.at(0, &h)
    }

    /// The id of a name, added to the name list if new.
    fn id(&mut self, name: &str) -> std::io::Result<u16> {
        if let Some(k) = self.names.iter().position(|n| n == name) {
            return Ok(k as u16);
        }
        let used: u64 = self.names.iter().map(|n| n.len() as u64 + 1).sum();
        let add = name.len() as u64 + 1;
        self.names.push(name.to_string());
        if used + add < self.namelist_capacity {
            let mut b = name.as_bytes().to_vec();
            b.push(0);
            self.at(self.namelist_location + used, &b)?;
        } else {
            // A new, larger name list at the end of the file.
            let capacity = ((used + add) * 2).div_ceil(NAME_SIZE) * NAME_SIZE;
            let mut b = Vec::with_capacity(capacity as usize);
            for n in &self.names {
                b.extend_from_slice(n.as_bytes());
                b.push(0);
            }
            b.resize(capacity as usize, 0);
            let at = self.end;
            self.at(at, &b)?;
            self.end += capacity;
            self.namelist_location = at;
            self.namelist_capacity = capacity;
        }
        Ok((self.names.len() - 1) as u16)
    }

    /// Appends one frame at time step `step`.
    pub fn write(&mut self, step: u64, frame: &Frame) -> Result<(), IoError> {
        let chunks = chunks(step, frame, self.exact)
            .map_err(|m| IoError::Parse(ParseError::new(self.path.display().to_string(), 0, m)))?;
        self.write_chunks(chunks)
            .and_then(|_| self.file.flush())
            .map_err(|e| IoError::os(&self.path, e))
    }

    fn write_chunks(&mut self, chunks: Vec<Chunk>) -> std::io::Result<()> {
        let mut entries = Vec::with_capacity(chunks.len());
        for c in chunks {
            let id = self.id(&c.name)?;
            let location = self.end;
            self.at(location, &c.data)?;
            self.end += c.data.len() as u64;
            entries.push(Entry {
                frame: self.frame,
                n: c.n,
                location: location as i64,
                m: c.m,
                id,
                kind: c.kind as u8,
            });
        }
        entries.sort_by_key(|e| e.id);
        let bytes: Vec<u8> = entries.iter().flat_map(|e| e.bytes()).collect();
        let used = self.entries;
        let k = entries.len() as u64;
        // One free slot stays zero: the first entry at location 0 ends the index.
        if used + k < self.index_capacity {
            self.at(self.index_location + used * ENTRY_SIZE, &bytes)?;
        } else {
            let capacity = ((used + k) * 2).max(128);
            let mut all = vec![0u8; (used * ENTRY_SIZE) as usize];
            self.file
                .seek(SeekFrom::Start(self.index_location))
                .and_then(|_| self.file.read_exact(&mut all))?;
            all.extend_from_slice(&bytes);
            all.resize((capacity * ENTRY_SIZE) as usize, 0);
            let at = self.end;
            self.at(at, &all)?;
            self.end += capacity * ENTRY_SIZE;
            self.index_location = at;
            self.index_capacity = capacity;
        }
        self.entries += k;
        self.frame += 1;
        self.header()
    }
}

/// The chunks of one frame.
fn chunks(step: u64, f: &Frame, exact: bool) -> Result<Vec<Chunk>, String> {
    let n = f.positions.len();
    let c = f.cell;
    if c[0][1] != 0.0 || c[0][2] != 0.0 || c[1][2] != 0.0 {
        return Err("the cell is not in HOOMD's form (a along x, b in the xy plane)".into());
    }
    let (lx, ly, lz) = (c[0][0], c[1][1], c[2][2]);
    let tilt = |t: f64, l: f64| if l != 0.0 { t / l } else { 0.0 };
    let boxv = [
        lx,
        ly,
        lz,
        tilt(c[1][0], ly),
        tilt(c[2][0], lz),
        tilt(c[2][1], lz),
    ];
    // HOOMD's box is centred on the origin.
    let centre: Vec<f64> = (0..3)
        .map(|d| f.origin[d] + 0.5 * (c[0][d] + c[1][d] + c[2][d]))
        .collect();
    let flat = |v: &[[f64; 3]]| -> Vec<f64> { v.iter().flatten().copied().collect() };
    let relative: Vec<f64> = f
        .positions
        .iter()
        .flat_map(|p| (0..3).map(move |d| p[d]).zip(0..3))
        .map(|(x, d)| x - centre[d])
        .collect();
    let mut types: Vec<String> = Vec::new();
    let typeid: Vec<u32> = (0..n)
        .map(|i| {
            let s = f.species.get(i).map_or("X", String::as_str);
            (match types.iter().position(|t| t == s) {
                Some(k) => k,
                None => {
                    types.push(s.to_string());
                    types.len() - 1
                }
            }) as u32
        })
        .collect();
    if types.is_empty() {
        types.push("X".into());
    }
    let width = types.iter().map(|t| t.len() + 1).max().unwrap_or(2);
    let mut type_bytes = Vec::new();
    for t in &types {
        let mut row = t.as_bytes().to_vec();
        row.resize(width, 0);
        type_bytes.extend(row.into_iter().map(|b| b as i8));
    }
    let has = |len: usize| len == n && n > 0;
    let mut out = vec![
        chunk("configuration/step", Kind::U64, 1, &[step], |x| {
            x.to_le_bytes().to_vec()
        }),
        chunk("configuration/dimensions", Kind::U8, 1, &[3u8], |x| vec![x]),
        f32s("configuration/box", 1, &boxv),
        chunk("particles/N", Kind::U32, 1, &[n as u32], |x| {
            x.to_le_bytes().to_vec()
        }),
        f32s("particles/position", 3, &relative),
        chunk("particles/typeid", Kind::U32, 1, &typeid, |x| {
            x.to_le_bytes().to_vec()
        }),
        chunk(
            "particles/types",
            Kind::I8,
            width as u32,
            &type_bytes,
            |x| vec![x as u8],
        ),
        f64s("log/mote/time", 1, &[f.time]),
        f64s("log/mote/origin", 3, &f.origin),
        f64s("log/mote/cell", 3, &flat(&c)),
        chunk("log/mote/pbc", Kind::U8, 3, &f.pbc.map(u8::from), |x| {
            vec![x]
        }),
    ];
    if has(f.velocities.len()) {
        out.push(f32s("particles/velocity", 3, &flat(&f.velocities)));
    }
    if has(f.masses.len()) {
        out.push(f32s("particles/mass", 1, &f.masses));
    }
    if has(f.radii.len()) {
        let d: Vec<f64> = f.radii.iter().map(|r| 2.0 * r).collect();
        out.push(f32s("particles/diameter", 1, &d));
    }
    if has(f.orientations.len()) {
        let q: Vec<f64> = f.orientations.iter().flatten().copied().collect();
        out.push(f32s("particles/orientation", 4, &q));
    }
    if has(f.bodies.len()) {
        let b: Vec<i32> = f.bodies.iter().map(|&b| b as i32).collect();
        out.push(chunk("particles/body", Kind::I32, 1, &b, |x| {
            x.to_le_bytes().to_vec()
        }));
    }
    if exact && n > 0 {
        out.push(f64s("log/particles/mote_position", 3, &flat(&f.positions)));
        if has(f.velocities.len()) {
            out.push(f64s("log/particles/mote_velocity", 3, &flat(&f.velocities)));
        }
        if has(f.radii.len()) {
            out.push(f64s("log/particles/mote_radius", 1, &f.radii));
        }
        if has(f.masses.len()) {
            out.push(f64s("log/particles/mote_mass", 1, &f.masses));
        }
    }
    Ok(out)
}

/// Drops the frames whose `configuration/step` is past `step` from the
/// index (their data stays, unreferenced), so that [`GsdWriter::append`]
/// continues after the last frame kept: a run resumed from a checkpoint.
pub fn keep_until_step(path: &Path, step: u64) -> Result<(), IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    let layout = Layout::parse(&bytes, &path.display().to_string())?;
    let step_id = layout.names.iter().position(|n| n == "configuration/step");
    let step_of = |f: u64| -> u64 {
        layout
            .entries
            .iter()
            .find(|e| e.frame == f && Some(e.id as usize) == step_id)
            .map_or(0, |e| {
                values(&bytes, e).0.first().copied().unwrap_or(0.0) as u64
            })
    };
    let first_dropped = layout
        .entries
        .iter()
        .map(|e| e.frame)
        .find(|&f| step_of(f) > step);
    let Some(first_dropped) = first_dropped else {
        return Ok(());
    };
    let kept = layout
        .entries
        .iter()
        .take_while(|e| e.frame < first_dropped)
        .count() as u64;
    let zeros = vec![0u8; ((layout.entries.len() as u64 - kept) * ENTRY_SIZE) as usize];
    let mut file = OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| IoError::os(path, e))?;
    file.seek(SeekFrom::Start(layout.index_location + kept * ENTRY_SIZE))
        .and_then(|_| file.write_all(&zeros))
        .map_err(|e| IoError::os(path, e))
}

/// Header, index and names of a file in memory.
struct Layout {
    index_location: u64,
    index_capacity: u64,
    namelist_location: u64,
    namelist_capacity: u64,
    entries: Vec<Entry>,
    names: Vec<String>,
}

impl Layout {
    fn parse(bytes: &[u8], name: &str) -> Result<Self, ParseError> {
        let bad = |m: String| ParseError::new(name, 0, m);
        if bytes.len() < HEADER_SIZE as usize {
            return Err(bad(format!(
                "{} bytes: too short for a GSD header (256)",
                bytes.len()
            )));
        }
        let u64_at = |k: usize| u64::from_le_bytes(bytes[k..k + 8].try_into().unwrap_or([0; 8]));
        if u64_at(0) != MAGIC {
            return Err(bad(
                "not a GSD file (no magic number 0x65DF65DF65DF65DF)".into()
            ));
        }
        let gsd_version = u32::from_le_bytes(bytes[44..48].try_into().unwrap_or([0; 4]));
        let v1 = gsd_version < version(2, 0);
        let (index_location, index_capacity) = (u64_at(8), u64_at(16));
        let (namelist_location, namelist_capacity) =
            (u64_at(24), u64_at(32).saturating_mul(NAME_SIZE));
        let len = bytes.len() as u64;
        let inside = |at: u64, size: u64| at.checked_add(size).is_some_and(|end| end <= len);
        if !inside(index_location, index_capacity.saturating_mul(ENTRY_SIZE))
            || !inside(namelist_location, namelist_capacity)
        {
            return Err(bad(
                "the header points past the end of the file (truncated?)".into(),
            ));
        }
        let mut entries = Vec::new();
        for k in 0..index_capacity {
            let at = (index_location + k * ENTRY_SIZE) as usize;
            let e = Entry::parse(&bytes[at..at + ENTRY_SIZE as usize]);
            if e.location == 0 {
                break;
            }
            let size = size_of(e.kind)
                .checked_mul(e.n)
                .and_then(|s| s.checked_mul(u64::from(e.m)));
            // An unknown type has size 0 and would pass the bounds check.
            if e.location < 0
                || size_of(e.kind) == 0
                || size.is_none_or(|s| !inside(e.location as u64, s))
            {
                return Err(bad(format!(
                    "index entry {k} points past the end of the file (truncated?) or has an unknown type"
                )));
            }
            entries.push(e);
        }
        let list =
            &bytes[namelist_location as usize..(namelist_location + namelist_capacity) as usize];
        let mut names = Vec::new();
        if v1 {
            for seg in list.chunks(NAME_SIZE as usize) {
                if seg[0] == 0 {
                    break;
                }
                let end = seg.iter().position(|&b| b == 0).unwrap_or(seg.len());
                names.push(String::from_utf8_lossy(&seg[..end]).into_owned());
            }
        } else {
            for s in list.split(|&b| b == 0) {
                if s.is_empty() {
                    break;
                }
                names.push(String::from_utf8_lossy(s).into_owned());
            }
        }
        Ok(Self {
            index_location,
            index_capacity,
            namelist_location,
            namelist_capacity,
            entries,
            names,
        })
    }
}

/// Reads every frame of a GSD file in the hoomd schema (written by mote,
/// HOOMD-blue, the `gsd` package or OVITO). Chunks a frame lacks are taken
/// from frame 0, as the schema says. Without mote's keys the box is
/// periodic and centred on the origin, and positions are HOOMD's f32.
pub fn read_frames(path: &Path) -> Result<Vec<Frame>, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    Ok(parse(&bytes, &path.display().to_string())?)
}

/// Parses the bytes of a GSD file called `name`.
pub fn parse(bytes: &[u8], name: &str) -> Result<Vec<Frame>, ParseError> {
    let layout = Layout::parse(bytes, name)?;
    if layout.entries.windows(2).any(|w| w[1].frame < w[0].frame) {
        return Err(ParseError::new(name, 0, "the index is not sorted by frame"));
    }
    let chunks: HashMap<(u64, u16), Entry> = layout
        .entries
        .iter()
        .map(|e| ((e.frame, e.id), *e))
        .collect();
    let mut frames: Vec<u64> = layout.entries.iter().map(|e| e.frame).collect();
    frames.dedup();
    frames
        .into_iter()
        .map(|k| frame(bytes, &layout, &chunks, k, name))
        .collect()
}

/// The values of a chunk as f64 (any numeric type), with its columns.
fn values(bytes: &[u8], e: &Entry) -> (Vec<f64>, u32) {
    let size = size_of(e.kind) as usize;
    let start = e.location as usize;
    let count = (e.n * u64::from(e.m)) as usize;
    let v = (0..count)
        .map(|k| {
            let b = &bytes[start + k * size..start + (k + 1) * size];
            match e.kind {
                1 | 11 => f64::from(b[0]),
                2 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                3 => f64::from(u32::from_le_bytes(b.try_into().unwrap_or([0; 4]))),
                4 => u64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f64,
                5 => f64::from(b[0] as i8),
                6 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                7 => f64::from(i32::from_le_bytes(b.try_into().unwrap_or([0; 4]))),
                8 => i64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f64,
                9 => f64::from(f32::from_le_bytes(b.try_into().unwrap_or([0; 4]))),
                _ => f64::from_le_bytes(b.try_into().unwrap_or([0; 8])),
            }
        })
        .collect();
    (v, e.m)
}

fn frame(
    bytes: &[u8],
    layout: &Layout,
    chunks: &HashMap<(u64, u16), Entry>,
    k: u64,
    name: &str,
) -> Result<Frame, ParseError> {
    let find = |chunk: &str| -> Option<&Entry> {
        let id = layout.names.iter().position(|n| n == chunk)? as u16;
        chunks.get(&(k, id)).or_else(|| chunks.get(&(0, id)))
    };
    let get = |chunk: &str| find(chunk).map(|e| values(bytes, e));
    let bad = |m: String| ParseError::new(name, 0, format!("frame {k}: {m}"));
    let n = get("particles/N").map_or(0, |(v, _)| v.first().copied().unwrap_or(0.0) as usize);
    let rows = |chunk: &str, m: u32| -> Result<Option<Vec<f64>>, ParseError> {
        match get(chunk) {
            None => Ok(None),
            Some((v, cols)) if cols == m && v.len() == n * m as usize => Ok(Some(v)),
            Some((v, cols)) => Err(bad(format!(
                "{chunk} has {} values in {cols} columns, expected {n} × {m}",
                v.len()
            ))),
        }
    };
    let triples =
        |v: Vec<f64>| -> Vec<[f64; 3]> { v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect() };
    let mut f = Frame {
        time: get("log/mote/time")
            .and_then(|(v, _)| v.first().copied())
            .or_else(|| get("configuration/step").and_then(|(v, _)| v.first().copied()))
            .unwrap_or(0.0),
        pbc: [true; 3],
        ..Frame::default()
    };
    let boxv = get("configuration/box").map_or(vec![1.0, 1.0, 1.0, 0.0, 0.0, 0.0], |(v, _)| v);
    if boxv.len() != 6 {
        return Err(bad(format!(
            "configuration/box has {} values, not 6",
            boxv.len()
        )));
    }
    let (lx, ly, lz) = (boxv[0], boxv[1], boxv[2]);
    f.cell = [
        [lx, 0.0, 0.0],
        [boxv[3] * ly, ly, 0.0],
        [boxv[4] * lz, boxv[5] * lz, lz],
    ];
    if let Some(v) = rows_any(get("log/mote/cell"), 9) {
        f.cell = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
    }
    let c = f.cell;
    f.origin = [0, 1, 2].map(|d| -0.5 * (c[0][d] + c[1][d] + c[2][d]));
    if let Some(v) = rows_any(get("log/mote/origin"), 3) {
        f.origin = [v[0], v[1], v[2]];
    }
    if let Some(v) = rows_any(get("log/mote/pbc"), 3) {
        f.pbc = [v[0] != 0.0, v[1] != 0.0, v[2] != 0.0];
    }
    let centre = [0, 1, 2].map(|d| f.origin[d] + 0.5 * (c[0][d] + c[1][d] + c[2][d]));
    f.positions = match rows("log/particles/mote_position", 3)? {
        Some(v) => triples(v),
        None if n == 0 => Vec::new(),
        None => rows("particles/position", 3)?
            .map(|v| {
                triples(v)
                    .into_iter()
                    .map(|p| [p[0] + centre[0], p[1] + centre[1], p[2] + centre[2]])
                    .collect()
            })
            .ok_or_else(|| bad(format!("{n} particles but no particles/position")))?,
    };
    if let Some(v) = rows("log/particles/mote_velocity", 3)?.or(rows("particles/velocity", 3)?) {
        f.velocities = triples(v);
    }
    if let Some(v) = rows("log/particles/mote_radius", 1)? {
        f.radii = v;
    } else if let Some(v) = rows("particles/diameter", 1)? {
        f.radii = v.iter().map(|d| 0.5 * d).collect();
    }
    if let Some(v) = rows("log/particles/mote_mass", 1)?.or(rows("particles/mass", 1)?) {
        f.masses = v;
    }
    if let Some(v) = rows("particles/orientation", 4)? {
        f.orientations = v.chunks(4).map(|q| [q[0], q[1], q[2], q[3]]).collect();
    }
    if let Some(v) = rows("particles/body", 1)? {
        if v.iter().any(|&b| b >= 0.0) {
            f.bodies = v.iter().map(|&b| b.max(0.0) as u64).collect();
        }
    }
    let types: Vec<String> = match find("particles/types") {
        Some(e) => {
            let start = e.location as usize;
            let width = e.m as usize;
            (0..e.n as usize)
                .map(|t| {
                    let row = &bytes[start + t * width..start + (t + 1) * width];
                    let end = row.iter().position(|&b| b == 0).unwrap_or(width);
                    String::from_utf8_lossy(&row[..end]).into_owned()
                })
                .collect()
        }
        None => vec!["A".into()],
    };
    let typeid = rows("particles/typeid", 1)?.unwrap_or_else(|| vec![0.0; n]);
    f.species = typeid
        .iter()
        .map(|&t| {
            types
                .get(t as usize)
                .cloned()
                .ok_or_else(|| bad(format!("type id {t} but only {} types", types.len())))
        })
        .collect::<Result<_, _>>()?;
    Ok(f)
}

/// The values of an optional chunk if it has `len` of them.
fn rows_any(chunk: Option<(Vec<f64>, u32)>, len: usize) -> Option<Vec<f64>> {
    chunk.map(|(v, _)| v).filter(|v| v.len() == len)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(t: f64) -> Frame {
        Frame {
            time: t,
            cell: [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]],
            origin: [-1.0, 0.0, 2.0],
            pbc: [true, true, false],
            species: vec!["Ar".into(), "Fe".into(), "Ar".into()],
            positions: vec![
                [0.1 + 0.2, 1.0 / 3.0, 2.5],
                [-0.5, 4.0, 7.0],
                [2.0, 2.0, 2.0],
            ],
            velocities: vec![[0.1, 0.0, 0.0], [0.0, -1.0 / 7.0, 0.0], [0.0, 0.0, 3.0]],
            radii: vec![0.5, 0.25, 1.0 / 3.0],
            masses: vec![1.0, 2.0, 3.0],
            bodies: vec![0, 0, 1],
            orientations: vec![
                [1.0, 0.0, 0.0, 0.0],
                [0.5, 0.5, -0.5, 0.5],
                [0.0, 1.0, 0.0, 0.0],
            ],
            ..Frame::default()
        }
    }

    /// 300 frames (the index outgrows its first block twice), exact and
    /// f32, then appended to after reopening.
    #[test]
    fn frames_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        for exact in [true, false] {
            let path = dir.path().join(format!("t{exact}.gsd"));
            let mut w = GsdWriter::create(&path).unwrap();
            if exact {
                w = w.exact();
            }
            for k in 0..200 {
                w.write(k, &frame(k as f64 * 0.5)).unwrap();
            }
            drop(w);
            let mut w = GsdWriter::append(&path).unwrap();
            if exact {
                w = w.exact();
            }
            for k in 200..300 {
                w.write(k, &frame(k as f64 * 0.5)).unwrap();
            }
            let back = read_frames(&path).unwrap();
            assert_eq!(back.len(), 300);
            for (k, b) in back.iter().enumerate() {
                let want = frame(k as f64 * 0.5);
                assert_eq!(b.time, want.time);
                assert_eq!(
                    (b.cell, b.origin, b.pbc),
                    (want.cell, want.origin, want.pbc)
                );
                assert_eq!(b.species, want.species);
                assert_eq!(b.bodies, want.bodies);
                assert_eq!(b.orientations, want.orientations);
                if exact {
                    assert_eq!(b.positions, want.positions);
                    assert_eq!(b.velocities, want.velocities);
                    assert_eq!(b.radii, want.radii);
                    assert_eq!(b.masses, want.masses);
                } else {
                    // f32 in the file: relative to the box centre (1, 2.5, 5).
                    for (p, q) in b.positions.iter().zip(&want.positions) {
                        for d in 0..3 {
                            assert!((p[d] - q[d]).abs() < 1e-6, "{p:?} {q:?}");
                        }
                    }
                    for (r, s) in b.radii.iter().zip(&want.radii) {
                        assert!((r - s).abs() < 1e-7);
                    }
                }
            }
        }
    }

    #[test]
    fn bad_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.gsd");
        std::fs::write(&path, b"not a gsd file at all").unwrap();
        let e = read_frames(&path).unwrap_err().to_string();
        assert!(e.contains("bad.gsd") && e.contains("too short"), "{e}");
        let good = dir.path().join("good.gsd");
        GsdWriter::create(&good)
            .unwrap()
            .write(0, &frame(0.0))
            .unwrap();
        let mut bytes = std::fs::read(&good).unwrap();
        bytes.truncate(bytes.len() - 100);
        std::fs::write(&path, &bytes).unwrap();
        let e = read_frames(&path).unwrap_err().to_string();
        assert!(e.contains("bad.gsd") && e.contains("truncated"), "{e}");
        // An index entry of unknown type (0) claiming 2⁶⁰ rows: refused,
        // not allocated.
        let mut typeless = std::fs::read(&good).unwrap();
        let at = u64::from_le_bytes(typeless[8..16].try_into().unwrap()) as usize;
        typeless[at + 8..at + 16].copy_from_slice(&(1u64 << 60).to_le_bytes());
        typeless[at + 30] = 0;
        let e = parse(&typeless, "t.gsd").unwrap_err().to_string();
        assert!(e.contains("unknown type"), "{e}");
        bytes[0] = 0;
        let e = parse(&bytes, "x.gsd").unwrap_err().to_string();
        assert!(e.contains("magic"), "{e}");
    }
}
