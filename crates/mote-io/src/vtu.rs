//! VTK XML unstructured grids (`.vtu`) or poly data (`.vtp`, which OVITO
//! reads as particles), one per frame, and the ParaView collection (`.pvd`)
//! that lists them with their times.
//!
//! Particles are points with one `VTK_VERTEX` cell (a vertex in `.vtp`) each,
//! so that ParaView shows them directly (Point Gaussian or Glyph filters use the `radius` array). Point
//! data: `radius`, `Velocity` (3 components; OVITO's name), `type` (species index from 0,
//! names as NUL-terminated bytes in the field data `species`). Field data: `TIME`, `cell` (9 values,
//! rows a, b, c), `origin`, `pbc`. Arrays are ASCII in the shortest form that
//! reads back bit for bit, so files are readable and
//! [`read_vtu`] can read them back; meshio and VTK read them as well.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::xyz::Frame;
use crate::{IoError, ParseError, Provenance};

/// Writes one frame as a `.vtu` file.
pub fn write_vtu(path: &Path, frame: &Frame, provenance: &Provenance) -> Result<(), IoError> {
    write_as(path, frame, provenance, false)
}

/// Writes one frame as a `.vtp` file (poly data of vertices: OVITO's particles).
pub fn write_vtp(path: &Path, frame: &Frame, provenance: &Provenance) -> Result<(), IoError> {
    write_as(path, frame, provenance, true)
}

fn write_as(
    path: &Path,
    frame: &Frame,
    provenance: &Provenance,
    poly: bool,
) -> Result<(), IoError> {
    let file = File::create(path).map_err(|e| IoError::os(path, e))?;
    let mut out = BufWriter::new(file);
    write_to(&mut out, frame, provenance, poly)
        .and_then(|_| out.flush())
        .map_err(|e| IoError::os(path, e))
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "- -")
}

fn write_to(
    out: &mut impl Write,
    frame: &Frame,
    prov: &Provenance,
    poly: bool,
) -> std::io::Result<()> {
    let n = frame.positions.len();
    let kind = if poly { "PolyData" } else { "UnstructuredGrid" };
    let mut names: Vec<&str> = Vec::new();
    let types: Vec<usize> = frame
        .species
        .iter()
        .map(|s| {
            names.iter().position(|t| t == s).unwrap_or_else(|| {
                names.push(s);
                names.len() - 1
            })
        })
        .collect();
    writeln!(out, "<?xml version=\"1.0\"?>")?;
    // The provenance comment comes after the root tag: OVITO recognises
    // the file by the VTKFile tag on its second line.
    writeln!(
        out,
        "<VTKFile type=\"{kind}\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(out, "<!-- {} -->", xml_escape(&prov.line()))?;
    writeln!(out, "<{kind}>")?;
    if poly {
        writeln!(out, "<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\">")?;
    } else {
        writeln!(out, "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">")?;
    }
    writeln!(out, "<PointData Scalars=\"radius\" Vectors=\"Velocity\">")?;
    writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">"
    )?;
    for i in 0..n {
        writeln!(out, "{:e}", frame.radii.get(i).copied().unwrap_or(0.0))?;
    }
    writeln!(out, "</DataArray>")?;
    writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"Velocity\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for i in 0..n {
        let v = frame.velocities.get(i).copied().unwrap_or([0.0; 3]);
        writeln!(out, "{:e} {:e} {:e}", v[0], v[1], v[2])?;
    }
    writeln!(out, "</DataArray>")?;
    writeln!(
        out,
        "<DataArray type=\"Int32\" Name=\"type\" format=\"ascii\">"
    )?;
    for i in 0..n {
        writeln!(out, "{}", types.get(i).copied().unwrap_or(0))?;
    }
    writeln!(out, "</DataArray>")?;
    // What the frame has besides: masses, spins, dipoles, ids, and a rigid
    // body's index and orientation per sphere, so that a run restarts from
    // its own .vtp as from its .xyz (orientations in OVITO's order x y z w).
    let has = |len: usize| len == n && n > 0;
    let array = |out: &mut dyn Write,
                 ty: &str,
                 name: &str,
                 k: usize,
                 rows: &mut dyn Iterator<Item = String>|
     -> std::io::Result<()> {
        writeln!(
            out,
            "<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{k}\" format=\"ascii\">"
        )?;
        for row in rows {
            writeln!(out, "{row}")?;
        }
        writeln!(out, "</DataArray>")
    };
    let vec3 = |v: &[f64; 3]| format!("{:e} {:e} {:e}", v[0], v[1], v[2]);
    if has(frame.masses.len()) {
        array(
            out,
            "Float64",
            "mass",
            1,
            &mut frame.masses.iter().map(|m| format!("{m:e}")),
        )?;
    }
    if has(frame.angular_velocities.len()) {
        array(
            out,
            "Float64",
            "AngularVelocity",
            3,
            &mut frame.angular_velocities.iter().map(vec3),
        )?;
    }
    if has(frame.dipoles.len()) {
        array(
            out,
            "Float64",
            "Dipole",
            3,
            &mut frame.dipoles.iter().map(vec3),
        )?;
    }
    if has(frame.ids.len()) {
        array(
            out,
            "Int64",
            "id",
            1,
            &mut frame.ids.iter().map(|i| i.to_string()),
        )?;
    }
    if has(frame.bodies.len()) {
        array(
            out,
            "Int64",
            "body",
            1,
            &mut frame.bodies.iter().map(|b| b.to_string()),
        )?;
    }
    if has(frame.orientations.len()) {
        array(
            out,
            "Float64",
            "Orientation",
            4,
            &mut frame
                .orientations
                .iter()
                .map(|q| format!("{:e} {:e} {:e} {:e}", q[1], q[2], q[3], q[0])),
        )?;
    }
    writeln!(out, "</PointData>")?;
    writeln!(out, "<Points>")?;
    writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for p in &frame.positions {
        writeln!(out, "{:e} {:e} {:e}", p[0], p[1], p[2])?;
    }
    writeln!(out, "</DataArray>")?;
    writeln!(out, "</Points>")?;
    writeln!(out, "{}", if poly { "<Verts>" } else { "<Cells>" })?;
    writeln!(
        out,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )?;
    for i in 0..n {
        writeln!(out, "{i}")?;
    }
    writeln!(out, "</DataArray>")?;
    writeln!(
        out,
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    for i in 0..n {
        writeln!(out, "{}", i + 1)?;
    }
    writeln!(out, "</DataArray>")?;
    if poly {
        writeln!(out, "</Verts>")?;
    } else {
        writeln!(
            out,
            "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
        )?;
        for _ in 0..n {
            writeln!(out, "1")?;
        }
        writeln!(out, "</DataArray>")?;
        writeln!(out, "</Cells>")?;
    }
    writeln!(out, "</Piece>")?;
    // Field data after the piece: OVITO does not recognise a file that
    // opens with it.
    writeln!(out, "<FieldData>")?;
    writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"TIME\" NumberOfTuples=\"1\" format=\"ascii\">{:e}</DataArray>",
        frame.time
    )?;
    let c = frame.cell;
    write!(
        out,
        "<DataArray type=\"Float64\" Name=\"cell\" NumberOfComponents=\"9\" NumberOfTuples=\"1\" format=\"ascii\">"
    )?;
    for row in c {
        for v in row {
            write!(out, "{v:e} ")?;
        }
    }
    writeln!(out, "</DataArray>")?;
    let o = frame.origin;
    writeln!(
        out,
        "<DataArray type=\"Float64\" Name=\"origin\" NumberOfComponents=\"3\" NumberOfTuples=\"1\" format=\"ascii\">{:e} {:e} {:e}</DataArray>",
        o[0], o[1], o[2]
    )?;
    writeln!(
        out,
        "<DataArray type=\"Int32\" Name=\"pbc\" NumberOfComponents=\"3\" NumberOfTuples=\"1\" format=\"ascii\">{} {} {}</DataArray>",
        frame.pbc[0] as i32, frame.pbc[1] as i32, frame.pbc[2] as i32
    )?;
    // Species names as NUL-terminated bytes (meshio reads no String arrays).
    let mut bytes: Vec<u8> = Vec::new();
    for s in &names {
        bytes.extend(s.bytes());
        bytes.push(0);
    }
    writeln!(
        out,
        "<DataArray type=\"UInt8\" Name=\"species\" NumberOfTuples=\"{}\" format=\"ascii\">",
        bytes.len()
    )?;
    for b in bytes {
        write!(out, "{b} ")?;
    }
    writeln!(out, "\n</DataArray>")?;
    writeln!(out, "</FieldData>")?;
    writeln!(out, "</{kind}>")?;
    writeln!(out, "</VTKFile>")?;
    Ok(())
}

/// The opening tag of `<DataArray ... Name="name" ...>`, the text up to
/// `</DataArray>`, and the line where the array starts.
fn array<'a>(text: &'a str, name: &str) -> Option<(usize, &'a str, &'a str)> {
    let key = format!("Name=\"{name}\"");
    let at = text.find(&key)?;
    let tag_start = text[..at].rfind('<')?;
    let open = at + text[at..].find('>')? + 1;
    let line = text[..at].matches('\n').count() + 1;
    let tag = &text[tag_start..open];
    if tag.ends_with("/>") {
        // `<DataArray ... format="appended" offset="N"/>`: no body.
        return Some((line, tag, ""));
    }
    let close = open + text[open..].find("</DataArray>")?;
    Some((line, tag, &text[open..close]))
}

/// The value of `key="value"` in a tag.
fn attribute<'a>(tag: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!(" {key}=\"");
    let s = tag.find(&pat)? + pat.len();
    Some(&tag[s..s + tag[s..].find('"')?])
}

/// Standard base64 (RFC 4648), whitespace ignored.
fn base64(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let chars: Vec<u8> = text.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    let mut out = Vec::with_capacity(chars.len() / 4 * 3);
    for group in chars.chunks(4) {
        let pad = group.iter().rev().take_while(|&&c| c == b'=').count();
        if group.len() < 2 || pad > 2 {
            return None;
        }
        let mut n = 0u32;
        for (k, &c) in group.iter().enumerate() {
            let v = if c == b'=' { 0 } else { value(c)? };
            n |= v << (18 - 6 * k);
        }
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..group.len() - 1 - pad.min(group.len() - 1)]);
    }
    Some(out)
}

/// How a file's binary arrays are compressed (`compressor` of `<VTKFile>`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Compressor {
    None,
    Zlib,
    Lz4,
}

/// The appended block of a file (`<AppendedData>`): the bytes after its
/// `_` marker, raw or base64 text.
struct Appended<'a> {
    data: &'a [u8],
    raw: bool,
}

/// How binary arrays are laid out: header word size (`header_type`) and
/// compressor.
#[derive(Clone, Copy)]
struct Layout {
    header: usize,
    compressor: Compressor,
}

impl Layout {
    fn word(&self, b: &[u8], k: usize) -> Option<usize> {
        let mut v = [0u8; 8];
        v[..self.header].copy_from_slice(b.get(k * self.header..(k + 1) * self.header)?);
        usize::try_from(u64::from_le_bytes(v)).ok()
    }

    /// Header words of an array: 1 (the byte count), or for compressed
    /// arrays 3 + the number of blocks (blocks, block size, last block
    /// size, compressed sizes), from the first word.
    fn words(&self, first: usize) -> usize {
        match self.compressor {
            Compressor::None => 1,
            _ => first.saturating_add(3),
        }
    }

    /// The data of an array from its header and the bytes that follow it.
    fn data(&self, head: &[u8], data: &[u8]) -> Result<Vec<u8>, String> {
        let bad = || "header shorter than it says".to_string();
        let first = self.word(head, 0).ok_or_else(bad)?;
        if self.compressor == Compressor::None {
            return data.get(..first).map(<[u8]>::to_vec).ok_or_else(|| {
                format!("binary array of {} bytes, header says {first}", data.len())
            });
        }
        let blocks = first;
        let block_size = self.word(head, 1).ok_or_else(bad)?;
        let last_size = self.word(head, 2).ok_or_else(bad)?;
        let mut out = Vec::new();
        let mut at = 0usize;
        for k in 0..blocks {
            let csize = self.word(head, 3 + k).ok_or_else(bad)?;
            let end = at.checked_add(csize).filter(|&e| e <= data.len());
            let block = end
                .map(|e| &data[at..e])
                .ok_or_else(|| "compressed block past the end of the array".to_string())?;
            at += csize;
            let size = if k + 1 == blocks && last_size > 0 {
                last_size
            } else {
                block_size
            };
            match self.compressor {
                Compressor::Zlib => {
                    // At most the block's size: a corrupt block cannot
                    // inflate without bound.
                    let z = flate2::read::ZlibDecoder::new(block);
                    std::io::Read::read_to_end(&mut std::io::Read::take(z, size as u64), &mut out)
                        .map_err(|e| format!("zlib: {e}"))?;
                }
                Compressor::Lz4 => {
                    // A block is never larger than the header's block size:
                    // a corrupt header cannot ask for more.
                    if size > block.len().saturating_mul(255).saturating_add(16) {
                        return Err(format!("an LZ4 block of {csize} bytes cannot hold {size}"));
                    }
                    let start = out.len();
                    out.resize(start + size, 0);
                    let n = lz4_flex::block::decompress_into(block, &mut out[start..])
                        .map_err(|e| format!("lz4: {e}"))?;
                    out.truncate(start + n);
                }
                Compressor::None => unreachable!(),
            }
        }
        Ok(out)
    }

    /// The bytes of an appended array stored raw at the start of `bytes`.
    fn raw(&self, bytes: &[u8]) -> Result<Vec<u8>, String> {
        let first = self
            .word(bytes, 0)
            .ok_or("appended array past the end of the file")?;
        let words = self.words(first);
        if self.compressor != Compressor::None && first > bytes.len() {
            return Err(format!(
                "a header of {first} compressed blocks in {} bytes",
                bytes.len()
            ));
        }
        let size = words * self.header;
        let head = bytes
            .get(..size)
            .ok_or("appended header past the end of the file")?;
        self.data(head, &bytes[size..])
    }

    /// The bytes of a base64 array (inline `format="binary"`, or appended
    /// with `encoding="base64"`): header and data encoded together or
    /// separately (VTK does both).
    fn base64(&self, body: &str) -> Result<Vec<u8>, String> {
        let chars: String = body.chars().filter(|c| !c.is_whitespace()).collect();
        let bad = || "bad base64".to_string();
        let first =
            base64(chars.get(..(self.header.div_ceil(3) * 4)).ok_or_else(bad)?).ok_or_else(bad)?;
        let blocks = self.word(&first, 0).ok_or_else(bad)?;
        if self.compressor != Compressor::None && blocks > chars.len() {
            return Err(format!(
                "a header of {blocks} compressed blocks in {} characters",
                chars.len()
            ));
        }
        let size = self.words(blocks) * self.header;
        let head_chars = size.div_ceil(3) * 4;
        let separate = chars.as_bytes().get(head_chars.wrapping_sub(1)) == Some(&b'=');
        let (head, data) = if separate {
            let head = base64(chars.get(..head_chars).ok_or_else(bad)?).ok_or_else(bad)?;
            let data = base64(&chars[head_chars..]).ok_or_else(bad)?;
            (head, data)
        } else {
            let all = base64(&chars).ok_or_else(bad)?;
            if all.len() < size {
                return Err("binary array shorter than its header".into());
            }
            (all[..size].to_vec(), all[size..].to_vec())
        };
        self.data(&head, &data)
    }
}

/// Little-endian values of a VTK type as f64.
fn decode(bytes: &[u8], kind: &str) -> Option<Vec<f64>> {
    macro_rules! each {
        ($t:ty) => {
            bytes
                .chunks_exact(std::mem::size_of::<$t>())
                .map(|b| <$t>::from_le_bytes(b.try_into().unwrap_or_default()) as f64)
                .collect()
        };
    }
    Some(match kind {
        "Float64" => each!(f64),
        "Float32" => each!(f32),
        "Int8" => each!(i8),
        "UInt8" => each!(u8),
        "Int16" => each!(i16),
        "UInt16" => each!(u16),
        "Int32" => each!(i32),
        "UInt32" => each!(u32),
        "Int64" => each!(i64),
        "UInt64" => each!(u64),
        _ => return None,
    })
}

fn numbers(
    text: &str,
    appended: Option<&Appended>,
    fname: &str,
    name: &str,
) -> Result<Vec<f64>, ParseError> {
    let (line, tag, body) = array(text, name)
        .ok_or_else(|| ParseError::new(fname, 0, format!("no DataArray named '{name}'")))?;
    let err = |m: String| ParseError::new(fname, line, format!("DataArray '{name}': {m}"));
    let format = attribute(tag, "format").unwrap_or("ascii");
    if format == "ascii" {
        return body
            .split_whitespace()
            .map(|w| {
                w.parse::<f64>()
                    .map_err(|_| err(format!("'{w}' is not a number")))
            })
            .collect();
    }
    if !matches!(format, "binary" | "appended") {
        return Err(err(format!(
            "format '{format}' is not read (ascii, binary and appended are)"
        )));
    }
    let file = &text[text.find("<VTKFile").unwrap_or(0)..];
    let file_tag = &file[..file.find('>').unwrap_or(file.len())];
    if attribute(file_tag, "byte_order") == Some("BigEndian") {
        return Err(err("big-endian files are not read".into()));
    }
    let layout = Layout {
        header: match attribute(file_tag, "header_type") {
            Some("UInt64") => 8,
            _ => 4,
        },
        compressor: match attribute(file_tag, "compressor") {
            None | Some("") => Compressor::None,
            Some("vtkZLibDataCompressor") => Compressor::Zlib,
            Some("vtkLZ4DataCompressor") => Compressor::Lz4,
            Some(other) => {
                return Err(err(format!(
                    "compressor {other} is not read (zlib and LZ4 are)"
                )))
            }
        },
    };
    let kind = attribute(tag, "type").unwrap_or("Float64");
    let bytes = if format == "binary" {
        layout.base64(body)
    } else {
        let a = appended
            .ok_or_else(|| err("format 'appended' but the file has no <AppendedData>".into()))?;
        let offset = attribute(tag, "offset")
            .and_then(|o| o.trim().parse::<usize>().ok())
            .ok_or_else(|| err("an appended array needs offset=\"N\"".into()))?;
        let at = a
            .data
            .get(offset..)
            .ok_or_else(|| err(format!("offset {offset} past the end of the appended data")))?;
        if a.raw {
            layout.raw(at)
        } else {
            std::str::from_utf8(at)
                .map_err(|_| "base64 appended data is not text".to_string())
                .and_then(|t| layout.base64(t.split('<').next().unwrap_or(t)))
        }
    }
    .map_err(err)?;
    decode(&bytes, kind).ok_or_else(|| err(format!("type {kind} is not read")))
}

/// Splits a VTK XML file into its text and its appended block, if any.
fn split_appended<'a>(
    bytes: &'a [u8],
    name: &str,
) -> Result<(&'a str, Option<Appended<'a>>), ParseError> {
    let find = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).position(|w| w == needle);
    let not_text = |upto: usize| {
        let line = bytes[..upto].iter().filter(|&&b| b == b'\n').count() + 1;
        ParseError::new(
            name,
            line,
            "not UTF-8 text (a VTK XML file is text up to <AppendedData>)",
        )
    };
    let Some(start) = find(bytes, b"<AppendedData") else {
        let text = std::str::from_utf8(bytes).map_err(|e| not_text(e.valid_up_to()))?;
        return Ok((text, None));
    };
    let head_end = start + find(&bytes[start..], b">").ok_or_else(|| not_text(start))? + 1;
    let text = std::str::from_utf8(&bytes[..head_end]).map_err(|e| not_text(e.valid_up_to()))?;
    let tag = &text[start..];
    let raw = match attribute(tag, "encoding") {
        Some("raw") => true,
        Some("base64") | None => false,
        Some(other) => {
            let line = text.matches('\n').count() + 1;
            return Err(ParseError::new(
                name,
                line,
                format!("AppendedData encoding '{other}' is not read (raw and base64 are)"),
            ));
        }
    };
    // The data start after the `_` that follows the tag.
    let marker = find(&bytes[head_end..], b"_").map(|k| head_end + k + 1);
    let data = match marker {
        Some(k) => &bytes[k..],
        None => &[][..],
    };
    Ok((text, Some(Appended { data, raw })))
}

/// Reads a `.vtu` written by [`write_vtu`] back into a frame.
pub fn read_vtu(path: &Path) -> Result<Frame, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    parse_vtu_bytes(&bytes, &name).map_err(IoError::from)
}

/// Parses `.vtu` text; `name` is used in error messages.
pub fn parse_vtu(text: &str, name: &str) -> Result<Frame, ParseError> {
    parse_vtu_bytes(text.as_bytes(), name)
}

/// Parses a `.vtu` or `.vtp` file's bytes: ASCII, inline binary (base64)
/// and appended (raw or base64) arrays, uncompressed or compressed with
/// zlib or LZ4 (the VTK and ParaView writers' choices); `name` is used in
/// error messages.
pub fn parse_vtu_bytes(bytes: &[u8], name: &str) -> Result<Frame, ParseError> {
    let (text, appended) = split_appended(bytes, name)?;
    let appended = appended.as_ref();
    if !text.contains("<VTKFile")
        || !(text.contains("UnstructuredGrid") || text.contains("PolyData"))
    {
        return Err(ParseError::new(
            name,
            1,
            "not a VTK XML UnstructuredGrid or PolyData file",
        ));
    }
    let pts = numbers(text, appended, name, "Points")?;
    if pts.len() % 3 != 0 {
        return Err(ParseError::new(
            name,
            0,
            "Points: count not a multiple of 3",
        ));
    }
    let n = pts.len() / 3;
    let mut frame = Frame {
        positions: pts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        ..Frame::default()
    };
    let check = |v: &Vec<f64>, what: &str, k: usize| {
        if v.len() == k {
            Ok(())
        } else {
            Err(ParseError::new(
                name,
                0,
                format!("{what} has {} values, expected {k}", v.len()),
            ))
        }
    };
    // Radii, velocities and types where the file has them.
    let optional = |array: &str| match numbers(text, appended, name, array) {
        Err(e) if e.message.starts_with("no DataArray") => Ok(None),
        other => other.map(Some),
    };
    if let Some(r) = optional("radius")? {
        check(&r, "radius", n)?;
        frame.radii = r;
    }
    if let Some(v) = optional("Velocity")?.or(optional("velocity")?) {
        check(&v, "velocity", 3 * n)?;
        frame.velocities = v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    }
    if let Some(m) = optional("mass")? {
        check(&m, "mass", n)?;
        frame.masses = m;
    }
    let triples = |v: Vec<f64>| v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    if let Some(w) = optional("AngularVelocity")? {
        check(&w, "AngularVelocity", 3 * n)?;
        frame.angular_velocities = triples(w);
    }
    if let Some(d) = optional("Dipole")? {
        check(&d, "Dipole", 3 * n)?;
        frame.dipoles = triples(d);
    }
    if let Some(i) = optional("id")? {
        check(&i, "id", n)?;
        frame.ids = i.iter().map(|&x| x as u64).collect();
    }
    if let Some(b) = optional("body")? {
        check(&b, "body", n)?;
        frame.bodies = b.iter().map(|&x| x as u64).collect();
    }
    if let Some(q) = optional("Orientation")? {
        check(&q, "Orientation", 4 * n)?;
        // OVITO's order x y z w, kept (w, x, y, z) in a frame
        frame.orientations = q.chunks(4).map(|c| [c[3], c[0], c[1], c[2]]).collect();
    }
    if let Ok(t) = numbers(text, appended, name, "TIME") {
        frame.time = t.first().copied().unwrap_or(0.0);
    }
    if let Ok(c) = numbers(text, appended, name, "cell") {
        check(&c, "cell", 9)?;
        frame.cell = [[c[0], c[1], c[2]], [c[3], c[4], c[5]], [c[6], c[7], c[8]]];
    }
    if let Ok(o) = numbers(text, appended, name, "origin") {
        check(&o, "origin", 3)?;
        frame.origin = [o[0], o[1], o[2]];
    }
    if let Ok(p) = numbers(text, appended, name, "pbc") {
        check(&p, "pbc", 3)?;
        frame.pbc = [p[0] != 0.0, p[1] != 0.0, p[2] != 0.0];
    }
    let species: Vec<String> = match numbers(text, appended, name, "species") {
        Ok(bytes) => bytes
            .split(|b| *b == 0.0)
            .filter(|s| !s.is_empty())
            .map(|s| s.iter().map(|&b| b as u8 as char).collect())
            .collect(),
        Err(_) => Vec::new(),
    };
    let types = optional("type")?.unwrap_or_else(|| vec![0.0; n]);
    check(&types, "type", n)?;
    frame.species = types
        .iter()
        .map(|&t| {
            species.get(t as usize).cloned().unwrap_or_else(|| {
                if species.is_empty() {
                    "X".to_string()
                } else {
                    format!("{t}")
                }
            })
        })
        .collect();
    Ok(frame)
}

/// Writes a series of frames as `DIR/STEM_00000.vtu`, ... plus `DIR/STEM.pvd`
/// listing them with their times. The `.pvd` is rewritten (to a temporary file,
/// then renamed) after every frame, so a run that stops early leaves a valid
/// series of what it wrote.
pub struct PvdWriter {
    dir: PathBuf,
    stem: String,
    provenance: Provenance,
    entries: Vec<(f64, String)>,
    /// Frames as `.vtp` poly data rather than `.vtu` grids.
    poly: bool,
}

impl PvdWriter {
    /// `pvd_path` is the collection file, e.g. `out/traj.pvd`; frames go beside it.
    pub fn create(pvd_path: &Path, provenance: Provenance) -> Result<Self, IoError> {
        let w = Self::create_empty(pvd_path, provenance)?;
        w.write_pvd()?;
        Ok(w)
    }

    fn create_empty(pvd_path: &Path, provenance: Provenance) -> Result<Self, IoError> {
        let dir = pvd_path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf();
        let stem = pvd_path
            .file_stem()
            .and_then(|s| s.to_str())
            .ok_or_else(|| {
                IoError::Parse(ParseError::new(
                    pvd_path.display().to_string(),
                    0,
                    "a .pvd file name is needed",
                ))
            })?
            .to_string();
        Ok(Self {
            dir,
            stem,
            provenance,
            entries: Vec::new(),
            poly: false,
        })
    }

    /// Frames as `.vtp` poly data (OVITO's particles) instead of `.vtu`.
    pub fn poly_data(mut self) -> Self {
        self.poly = true;
        self
    }

    /// Continues an existing collection (a resumed run): its data sets are
    /// kept and new frames numbered after them.
    pub fn append(pvd_path: &Path, provenance: Provenance) -> Result<Self, IoError> {
        let mut w = Self::create_empty(pvd_path, provenance)?;
        for (t, f) in read_pvd(pvd_path)? {
            let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
            w.poly |= f.extension().is_some_and(|e| e == "vtp");
            w.entries.push((t, name.unwrap_or_default()));
        }
        Ok(w)
    }

    /// Keeps the data sets up to time `t` (and deletes the files of the
    /// rest): the frames of a run resumed from a checkpoint at t.
    pub fn keep_until(&mut self, t: f64) -> Result<(), IoError> {
        for (_, f) in self.entries.iter().filter(|(s, _)| *s > t) {
            let _ = std::fs::remove_file(self.dir.join(f));
        }
        self.entries.retain(|(s, _)| *s <= t);
        self.write_pvd()
    }

    /// Writes the next frame and updates the collection; returns the frame's path.
    pub fn write(&mut self, frame: &Frame) -> Result<PathBuf, IoError> {
        let ext = if self.poly { "vtp" } else { "vtu" };
        let file = format!("{}_{:05}.{ext}", self.stem, self.entries.len());
        let path = self.dir.join(&file);
        write_as(&path, frame, &self.provenance, self.poly)?;
        self.entries.push((frame.time, file));
        self.write_pvd()?;
        Ok(path)
    }

    /// The collection file's path.
    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.stem))
    }

    fn write_pvd(&self) -> Result<(), IoError> {
        let path = self.pvd_path();
        let tmp = self.dir.join(format!(".{}.pvd.tmp", self.stem));
        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(&format!(
            "<!-- {} -->\n",
            xml_escape(&self.provenance.line())
        ));
        s.push_str("<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
        for (t, f) in &self.entries {
            s.push_str(&format!(
                "<DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                xml_escape(f)
            ));
        }
        s.push_str("</Collection>\n</VTKFile>\n");
        std::fs::write(&tmp, s).map_err(|e| IoError::os(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| IoError::os(&path, e))
    }
}

/// Reads a `.pvd` collection: (time, path of the data set) in file order, paths
/// relative to the collection's folder resolved.
pub fn read_pvd(path: &Path) -> Result<Vec<(f64, PathBuf)>, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let Some(at) = line.find("<DataSet") else {
            continue;
        };
        let attr = |key: &str| -> Option<&str> {
            let pat = format!("{key}=\"");
            let s = at + line[at..].find(&pat)? + pat.len();
            let e = s + line[s..].find('"')?;
            Some(&line[s..e])
        };
        let t = attr("timestep")
            .and_then(|t| t.parse::<f64>().ok())
            .ok_or_else(|| ParseError::new(&name, k + 1, "DataSet without a numeric timestep"))?;
        let f =
            attr("file").ok_or_else(|| ParseError::new(&name, k + 1, "DataSet without a file"))?;
        out.push((t, dir.join(f)));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(t: f64) -> Frame {
        Frame {
            time: t,
            cell: [[2.0, 0.0, 0.0], [0.5, 3.0, 0.0], [0.0, 0.0, 4.0]],
            origin: [-1.0, 0.0, 0.5],
            pbc: [true, false, true],
            species: vec!["A".into(), "Bb".into(), "A".into()],
            positions: vec![[0.1, 0.2, 0.3], [-1.25, 2.5, 1e-7], [1.0 / 3.0, 0.0, 0.0]],
            velocities: vec![[1.0, 0.0, 0.0], [0.0, -2.0, 3.0], [0.0; 3]],
            radii: vec![0.5, 0.25, 0.5],
            ..Default::default()
        }
    }

    /// A rigid run's frame — each sphere's body, orientation, mass, spin —
    /// and dipoles and ids come back from a .vtp bit for bit, so a run
    /// restarts from its own VTK file as from its XYZ (they were dropped).
    #[test]
    fn bodies_orientations_masses_and_spins_round_trip() {
        let mut f = frame(1.5);
        f.masses = vec![1.0, 2.0 / 3.0, 1e-20];
        f.angular_velocities = vec![[0.1, -0.2, 0.3], [0.0; 3], [1e10, 0.0, -1.0 / 7.0]];
        f.dipoles = vec![[0.0, 0.0, 1.0], [0.5, 0.5, 0.0], [0.0; 3]];
        f.ids = vec![7, 8, 9];
        f.bodies = vec![0, 0, 1];
        let c = (0.5f64).sqrt();
        f.orientations = vec![[c, c, 0.0, 0.0], [c, c, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.vtp");
        write_vtp(&path, &f, &Provenance::default()).unwrap();
        let back = read_vtu(&path).unwrap();
        assert_eq!(back.masses, f.masses);
        assert_eq!(back.angular_velocities, f.angular_velocities);
        assert_eq!(back.dipoles, f.dipoles);
        assert_eq!(back.ids, f.ids);
        assert_eq!(back.bodies, f.bodies);
        assert_eq!(back.orientations, f.orientations);
        assert_eq!(back.positions, f.positions);
        // OVITO's order in the file: x y z w
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("Name=\"Orientation\" NumberOfComponents=\"4\""));
        assert!(text.contains(&format!("{c:e} 0e0 0e0 {c:e}")), "{text}");
    }

    #[test]
    fn series_round_trips_through_pvd_and_vtu() {
        let dir = tempfile::tempdir().unwrap();
        let pvd = dir.path().join("traj.pvd");
        let mut w = PvdWriter::create(&pvd, Provenance::default()).unwrap();
        assert!(read_pvd(&pvd).unwrap().is_empty());
        for k in 0..3 {
            w.write(&frame(0.5 * k as f64)).unwrap();
        }
        let list = read_pvd(&pvd).unwrap();
        assert_eq!(list.len(), 3);
        assert_eq!(list[2].0, 1.0);
        assert!(list[1].1.ends_with("traj_00001.vtu"));
        let back = read_vtu(&list[2].1).unwrap();
        let f = frame(1.0);
        // Positions are written with 17 significant digits: exact round trip.
        assert_eq!(back.positions, f.positions);
        assert_eq!(back.velocities, f.velocities);
        assert_eq!(back.radii, f.radii);
        assert_eq!(back.cell, f.cell);
        assert_eq!(back.origin, f.origin);
        assert_eq!(back.pbc, f.pbc);
        assert_eq!(back.species, f.species);
        assert_eq!(back.time, 1.0);
    }

    #[test]
    fn bad_vtu_is_named() {
        let e = parse_vtu(
            "<VTKFile type=\"UnstructuredGrid\">\n<DataArray Name=\"Points\">\n1 2 x\n</DataArray>",
            "p.vtu",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("p.vtu:2:") && e.contains("'x'"), "{e}");
        let e = parse_vtu("hello", "h.vtu").unwrap_err().to_string();
        assert_eq!(
            e,
            "h.vtu:1: not a VTK XML UnstructuredGrid or PolyData file"
        );
    }
}
