//! LAMMPS data files of granular spheres (`atom_style sphere`): the header
//! (atom count, box bounds) and the `Atoms # sphere` section, whose rows are
//! `id type diameter density x y z` (optionally followed by image flags).
//! Other sections (Velocities, ...) are read where mote uses them:
//! `Velocities` rows `id vx vy vz wx wy wz`.

use std::path::Path;

use crate::ParseError;

/// One sphere of a data file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereAtom {
    pub id: u64,
    pub kind: u32,
    pub diameter: f64,
    pub density: f64,
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
}

/// The contents of a data file, atoms in the file's order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DataFile {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub atoms: Vec<SphereAtom>,
}

/// Reads a data file from disk.
pub fn read(path: &Path) -> Result<DataFile, ParseError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| ParseError::new(&name, 0, format!("cannot read the data file: {e}")))?;
    parse(&text, &name)
}

/// Parses the text of a data file; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<DataFile, ParseError> {
    let err = |line: usize, msg: String| ParseError::new(file, line, msg);
    let mut data = DataFile::default();
    let mut expected: Option<usize> = None;
    let mut section = "";
    let lines = text.lines().enumerate().skip(1); // the first line is a title
    let mut ids = std::collections::HashMap::new();
    for (k, raw) in lines {
        let line_no = k + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let num = |w: &str| -> Result<f64, ParseError> {
            w.parse::<f64>()
                .map_err(|_| err(line_no, format!("'{w}' is not a number")))
        };
        // Section headers stand alone on their line.
        if words[0]
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic())
        {
            section = match words[0] {
                "Atoms" => {
                    if let Some(style) = raw.split('#').nth(1) {
                        let style = style.trim();
                        if !style.is_empty() && style != "sphere" {
                            return Err(err(
                                line_no,
                                format!("Atoms are '{style}': mote reads atom_style sphere (id type diameter density x y z)"),
                            ));
                        }
                    }
                    "atoms"
                }
                "Velocities" => "velocities",
                _ => "other",
            };
            continue;
        }
        match (section, words.as_slice()) {
            ("", [n, "atoms"]) => {
                expected = Some(
                    n.parse()
                        .map_err(|_| err(line_no, format!("'{n}' is not an atom count")))?,
                )
            }
            ("", [lo, hi, axis_lo, _]) if axis_lo.ends_with("lo") => {
                let k = match *axis_lo {
                    "xlo" => 0,
                    "ylo" => 1,
                    "zlo" => 2,
                    other => return Err(err(line_no, format!("unknown bound '{other}'"))),
                };
                data.lo[k] = num(lo)?;
                data.hi[k] = num(hi)?;
            }
            ("", _) => {}
            ("atoms", w) => {
                if w.len() < 7 {
                    return Err(err(
                        line_no,
                        format!(
                            "an atom row needs 7 values (id type diameter density x y z), found {}",
                            w.len()
                        ),
                    ));
                }
                let id: u64 = w[0]
                    .parse()
                    .map_err(|_| err(line_no, format!("'{}' is not an atom id", w[0])))?;
                let kind: u32 = w[1]
                    .parse()
                    .map_err(|_| err(line_no, format!("'{}' is not an atom type", w[1])))?;
                let atom = SphereAtom {
                    id,
                    kind,
                    diameter: num(w[2])?,
                    density: num(w[3])?,
                    position: [num(w[4])?, num(w[5])?, num(w[6])?],
                    velocity: [0.0; 3],
                    angular_velocity: [0.0; 3],
                };
                if atom.diameter <= 0.0 || atom.density <= 0.0 {
                    return Err(err(line_no, "diameter and density must be positive".into()));
                }
                if ids.insert(id, data.atoms.len()).is_some() {
                    return Err(err(line_no, format!("atom id {id} appears twice")));
                }
                data.atoms.push(atom);
            }
            ("velocities", w) => {
                if w.len() < 7 {
                    return Err(err(
                        line_no,
                        "a velocity row needs id vx vy vz wx wy wz".into(),
                    ));
                }
                let id: u64 = w[0]
                    .parse()
                    .map_err(|_| err(line_no, format!("'{}' is not an atom id", w[0])))?;
                let &i = ids
                    .get(&id)
                    .ok_or_else(|| err(line_no, format!("velocity of unknown atom {id}")))?;
                data.atoms[i].velocity = [num(w[1])?, num(w[2])?, num(w[3])?];
                data.atoms[i].angular_velocity = [num(w[4])?, num(w[5])?, num(w[6])?];
            }
            _ => {}
        }
    }
    if let Some(n) = expected {
        if n != data.atoms.len() {
            return Err(err(
                0,
                format!(
                    "the header says {n} atoms, the Atoms section has {}",
                    data.atoms.len()
                ),
            ));
        }
    }
    if data.atoms.is_empty() {
        return Err(err(0, "no Atoms section".into()));
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "title\n\n2 atoms\n1 atom types\n\n0 0.1 xlo xhi\n0 0.1 ylo yhi\n0 0.15 zlo zhi\n\nAtoms # sphere\n\n1 1 0.004 2500 0.01 0.02 0.03\n2 1 0.004 2500 0.05 0.05 0.05\n";

    #[test]
    fn reads_spheres_and_box() {
        let d = parse(TEXT, "t").unwrap();
        assert_eq!(d.atoms.len(), 2);
        assert_eq!(d.hi, [0.1, 0.1, 0.15]);
        assert_eq!(d.atoms[1].position, [0.05, 0.05, 0.05]);
        assert_eq!(d.atoms[0].diameter, 0.004);
    }

    #[test]
    fn bad_rows_name_their_line() {
        let bad = TEXT.replace(
            "2 1 0.004 2500 0.05 0.05 0.05",
            "2 1 0.004 x 0.05 0.05 0.05",
        );
        let e = parse(&bad, "cloud").unwrap_err();
        assert_eq!((e.file.as_str(), e.line), ("cloud", 13));
        let short = TEXT
            .replace("3 atoms", "2 atoms")
            .replace("2 atoms", "3 atoms");
        assert!(parse(&short, "cloud")
            .unwrap_err()
            .message
            .contains("header says 3"));
    }
}
