//! LAMMPS data files: the header (atom count, box bounds), `Masses`,
//! `Atoms` and `Velocities`. Atom styles (named by the comment after
//! `Atoms`, as LAMMPS' `write_data` and OVITO write it):
//!
//! | style | columns |
//! |---|---|
//! | `atomic` | id type x y z |
//! | `charge` | id type q x y z |
//! | `molecular`, `bond`, `angle` | id mol type x y z |
//! | `full` | id mol type q x y z |
//! | `sphere` | id type diameter density x y z |
//!
//! each optionally followed by three image flags. `Bonds` (`id type i j`)
//! are read with their `Bond Coeffs` of style harmonic (`type K r0`,
//! E = K (r − r₀)²), which a scene makes springs; angles, dihedrals and
//! impropers are refused (mote has no such forces, and would drop them).
//! Without the comment a row
//! of 5 (or 8) values is `atomic` and one of 7 (or 10) `sphere`; other
//! widths are refused with a message asking for the style. `Velocities`
//! rows are `id vx vy vz`, with `wx wy wz` for spheres. mote's boxes are
//! orthorhombic: tilt factors (`xy xz yz`) other than zero and general
//! triclinic cells (`avec bvec cvec`) that are not axis-aligned are refused
//! at their line, never read as a zero box.

use std::collections::HashMap;
use std::path::Path;

use crate::ParseError;

/// One atom of a data file (fields a style lacks are 0, or `None`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SphereAtom {
    pub id: u64,
    pub kind: u32,
    /// Sphere style: diameter and density.
    pub diameter: f64,
    pub density: f64,
    /// From `Masses` for the point styles (0 where none is given).
    pub mass: f64,
    pub charge: f64,
    pub molecule: Option<u64>,
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
}

/// An atom style mote reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AtomStyle {
    Atomic,
    Charge,
    Molecular,
    Full,
    #[default]
    Sphere,
}

impl AtomStyle {
    /// A style by its LAMMPS name.
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "atomic" => AtomStyle::Atomic,
            "charge" => AtomStyle::Charge,
            "molecular" | "bond" | "angle" => AtomStyle::Molecular,
            "full" => AtomStyle::Full,
            "sphere" => AtomStyle::Sphere,
            _ => return None,
        })
    }

    /// Values of a row without image flags.
    fn width(self) -> usize {
        match self {
            AtomStyle::Atomic => 5,
            AtomStyle::Charge | AtomStyle::Molecular => 6,
            AtomStyle::Full | AtomStyle::Sphere => 7,
        }
    }
}

/// The first words of LAMMPS data file section headers.
const SECTIONS: &[&str] = &[
    "Atoms",
    "Velocities",
    "Masses",
    "Ellipsoids",
    "Lines",
    "Triangles",
    "Bodies",
    "Bonds",
    "Angles",
    "Dihedrals",
    "Impropers",
    "Pair",
    "PairIJ",
    "Bond",
    "Angle",
    "Dihedral",
    "Improper",
    "BondBond",
    "BondAngle",
    "MiddleBondTorsion",
    "EndBondTorsion",
    "AngleTorsion",
    "AngleAngleTorsion",
    "BondBond13",
    "AngleAngle",
    "Atom",
];

/// The contents of a data file, atoms in the file's order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DataFile {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Whether the header gave the bounds of each axis.
    pub bounded: [bool; 3],
    pub style: AtomStyle,
    pub atoms: Vec<SphereAtom>,
    /// Names of atom types from `Atom Type Labels` (LAMMPS 2022 and later).
    pub type_labels: HashMap<u32, String>,
    /// The `Bonds`, their atoms as indices into `atoms`.
    pub bonds: Vec<Bond>,
}

/// A harmonic bond: E = K (r − r₀)² between two atoms (LAMMPS
/// `bond_style harmonic`; its `K` includes the ½).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bond {
    /// The bond type.
    pub kind: u32,
    /// The two atoms, as indices into [`DataFile::atoms`].
    pub atoms: [usize; 2],
    /// K of `Bond Coeffs` (energy per length squared).
    pub k: f64,
    /// r₀ of `Bond Coeffs`.
    pub r0: f64,
}

/// Reads a data file from disk.
pub fn read(path: &Path) -> Result<DataFile, ParseError> {
    read_as(path, None)
}

/// Reads a data file whose `Atoms` section may not name its style
/// (MDAnalysis writes none): `style` is taken then.
pub fn read_as(path: &Path, style: Option<AtomStyle>) -> Result<DataFile, ParseError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| ParseError::new(&name, 0, format!("cannot read the data file: {e}")))?;
    parse_as(&text, &name, style)
}

/// Parses the text of a data file; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<DataFile, ParseError> {
    parse_as(text, file, None)
}

/// [`parse`], with the style for an `Atoms` section that names none.
pub fn parse_as(
    text: &str,
    file: &str,
    default_style: Option<AtomStyle>,
) -> Result<DataFile, ParseError> {
    let err = |line: usize, msg: String| ParseError::new(file, line, msg);
    let mut data = DataFile::default();
    let mut expected: Option<usize> = None;
    let mut section = "";
    let mut style: Option<AtomStyle> = default_style;
    let mut masses: HashMap<u32, f64> = HashMap::new();
    let mut general = [[0.0f64; 3]; 4];
    let mut general_given = 0;
    let lines = text.lines().enumerate().skip(1); // the first line is a title
    let mut ids = HashMap::new();
    // `N atom types` of the header: types outside 1..=N are refused.
    let mut declared_types: Option<u64> = None;
    // `N bonds`, `N bond types`; the Bonds section's line; each bond's
    // (type, atom ids, line) until the atoms and coefficients are known.
    let (mut declared_bonds, mut declared_bond_types) = (None::<u64>, None::<u64>);
    let mut bonds_at: Option<usize> = None;
    let mut bond_rows: Vec<(u32, [u64; 2], usize)> = Vec::new();
    let mut bond_coeffs: HashMap<u32, (f64, f64)> = HashMap::new();
    for (k, raw) in lines {
        let line_no = k + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        // nan and inf parse as f64 but are no atom's or box's value.
        let num = |w: &str| -> Result<f64, ParseError> {
            match w.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                Ok(_) => Err(err(line_no, format!("'{w}': must be a finite number"))),
                Err(_) => Err(err(line_no, format!("'{w}' is not a number"))),
            }
        };
        // Section headers stand alone on their line (type labels, which
        // may start rows of Masses, are not among them).
        if SECTIONS.contains(&words[0]) {
            section = match words[0] {
                "Atoms" => {
                    if let Some(name) = raw.split('#').nth(1).map(str::trim) {
                        if !name.is_empty() {
                            style = Some(AtomStyle::named(name).ok_or_else(|| {
                                err(
                                    line_no,
                                    format!("Atoms are '{name}': mote reads the styles atomic, charge, molecular, full and sphere"),
                                )
                            })?);
                        }
                    }
                    "atoms"
                }
                "Velocities" => "velocities",
                "Masses" => "masses",
                "Bonds" => {
                    bonds_at.get_or_insert(line_no);
                    "bonds"
                }
                "Bond" if words.get(1) == Some(&"Coeffs") => {
                    let style = raw.split('#').nth(1).map(str::trim).unwrap_or("");
                    if !style.is_empty() && style != "harmonic" {
                        return Err(err(
                            line_no,
                            format!("Bond Coeffs # {style}: mote makes bonds springs, and reads bond style harmonic (K r0) only"),
                        ));
                    }
                    "bond coeffs"
                }
                // What mote would drop: refused, never read as if absent.
                "Angles" | "Dihedrals" | "Impropers" => {
                    return Err(err(
                        line_no,
                        format!(
                            "{}: mote has no {} forces and would drop them; remove the section \
                             (Bonds are read, as springs)",
                            words[0],
                            words[0].to_ascii_lowercase().trim_end_matches('s')
                        ),
                    ))
                }
                "Ellipsoids" | "Lines" | "Triangles" | "Bodies" => {
                    return Err(err(
                        line_no,
                        format!(
                            "{}: extended particles are not read by mote (they would be dropped)",
                            words[0]
                        ),
                    ))
                }
                "Atom" if words.get(1..3) == Some(&["Type", "Labels"][..]) => "labels",
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
            ("", [n, "atom", "types"]) => {
                declared_types =
                    Some(n.parse().map_err(|_| {
                        err(line_no, format!("'{n}' is not a number of atom types"))
                    })?)
            }
            ("", [n, "bonds"]) => {
                declared_bonds = Some(
                    n.parse()
                        .map_err(|_| err(line_no, format!("'{n}' is not a number of bonds")))?,
                )
            }
            ("", [n, "bond", "types"]) => {
                declared_bond_types =
                    Some(n.parse().map_err(|_| {
                        err(line_no, format!("'{n}' is not a number of bond types"))
                    })?)
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
                if data.lo[k] > data.hi[k] {
                    return Err(err(
                        line_no,
                        format!("{axis_lo} {lo} > its hi {hi}: lo must not exceed hi"),
                    ));
                }
                data.bounded[k] = true;
            }
            ("", [a, b, c, "xy", "xz", "yz"]) => {
                let tilt = [num(a)?, num(b)?, num(c)?];
                if tilt != [0.0; 3] {
                    return Err(err(
                        line_no,
                        "a triclinic box (tilt factors xy xz yz not 0): mote's boxes are orthorhombic".into(),
                    ));
                }
            }
            ("", [x, y, z, which @ ("avec" | "bvec" | "cvec")]) => {
                let row = match *which {
                    "avec" => 0,
                    "bvec" => 1,
                    _ => 2,
                };
                general[row] = [num(x)?, num(y)?, num(z)?];
                general_given += 1;
                let axis_aligned = (0..3).all(|d| d == row || general[row][d] == 0.0);
                if !axis_aligned {
                    return Err(err(
                        line_no,
                        format!("a general triclinic box ({which} not along its axis): mote's boxes are orthorhombic"),
                    ));
                }
            }
            ("", [x, y, z, "abc", "origin"]) => {
                general[3] = [num(x)?, num(y)?, num(z)?];
                general_given += 1;
            }
            ("", _) => {}
            ("labels", [t, label, ..]) => {
                let t: u32 = t
                    .parse()
                    .map_err(|_| err(line_no, format!("'{t}' is not an atom type")))?;
                data.type_labels.insert(t, label.to_string());
            }
            ("masses", [t, m, ..]) => {
                // A type number, or a label defined above.
                let t: u32 = match t.parse() {
                    Ok(t) => t,
                    Err(_) => {
                        *data
                            .type_labels
                            .iter()
                            .find(|(_, l)| l.as_str() == *t)
                            .ok_or_else(|| err(line_no, format!("'{t}' is not an atom type")))?
                            .0
                    }
                };
                masses.insert(t, num(m)?);
            }
            ("atoms", w) => {
                let style = match style {
                    Some(s) => s,
                    None => {
                        let inferred = match w.len() {
                            5 | 8 => AtomStyle::Atomic,
                            7 | 10 => AtomStyle::Sphere,
                            n => {
                                return Err(err(
                                    line_no,
                                    format!("an atom row of {n} values, and no style after 'Atoms #': name it (atomic, charge, molecular, full or sphere)"),
                                ))
                            }
                        };
                        *style.insert(inferred)
                    }
                };
                let width = style.width();
                if w.len() != width && w.len() != width + 3 {
                    return Err(err(
                        line_no,
                        format!(
                            "an atom row of style {style:?} needs {width} values (or {} with image flags), found {}",
                            width + 3,
                            w.len()
                        ),
                    ));
                }
                let whole = |w: &str, what: &str| -> Result<u64, ParseError> {
                    w.parse()
                        .map_err(|_| err(line_no, format!("'{w}' is not {what}")))
                };
                let id = whole(w[0], "an atom id")?;
                let mut atom = SphereAtom {
                    id,
                    ..SphereAtom::default()
                };
                let xyz = |at: usize| -> Result<[f64; 3], ParseError> {
                    Ok([num(w[at])?, num(w[at + 1])?, num(w[at + 2])?])
                };
                let kind_at = match style {
                    AtomStyle::Molecular | AtomStyle::Full => {
                        atom.molecule = Some(whole(w[1], "a molecule id")?);
                        2
                    }
                    _ => 1,
                };
                let kind = whole(w[kind_at], "an atom type")?;
                if let Some(n) = declared_types {
                    if kind == 0 || kind > n {
                        return Err(err(
                            line_no,
                            format!("atom type {kind}: the header declares types 1 to {n}"),
                        ));
                    }
                }
                atom.kind = u32::try_from(kind)
                    .map_err(|_| err(line_no, format!("atom type {kind} is too large")))?;
                match style {
                    AtomStyle::Atomic => atom.position = xyz(2)?,
                    AtomStyle::Charge => {
                        atom.charge = num(w[2])?;
                        atom.position = xyz(3)?;
                    }
                    AtomStyle::Molecular => atom.position = xyz(3)?,
                    AtomStyle::Full => {
                        atom.charge = num(w[3])?;
                        atom.position = xyz(4)?;
                    }
                    AtomStyle::Sphere => {
                        atom.diameter = num(w[2])?;
                        atom.density = num(w[3])?;
                        atom.position = xyz(4)?;
                        if atom.diameter <= 0.0 || atom.density <= 0.0 {
                            return Err(err(
                                line_no,
                                "diameter and density must be positive".into(),
                            ));
                        }
                    }
                }
                if ids.insert(id, data.atoms.len()).is_some() {
                    return Err(err(line_no, format!("atom id {id} appears twice")));
                }
                data.atoms.push(atom);
            }
            ("bonds", w) => {
                let [_, kind, a, b] = w else {
                    return Err(err(line_no, "a bond row needs id type atom1 atom2".into()));
                };
                let whole = |w: &str, what: &str| -> Result<u64, ParseError> {
                    w.parse()
                        .map_err(|_| err(line_no, format!("'{w}' is not {what}")))
                };
                let kind = whole(kind, "a bond type")?;
                if kind == 0 || declared_bond_types.is_some_and(|n| kind > n) {
                    return Err(err(
                        line_no,
                        format!(
                            "bond type {kind}: the header declares types 1 to {}",
                            declared_bond_types.unwrap_or(0)
                        ),
                    ));
                }
                let kind = u32::try_from(kind)
                    .map_err(|_| err(line_no, format!("bond type {kind} is too large")))?;
                let atoms = [whole(a, "an atom id")?, whole(b, "an atom id")?];
                if atoms[0] == atoms[1] {
                    return Err(err(line_no, format!("bond of atom {a} with itself")));
                }
                bond_rows.push((kind, atoms, line_no));
            }
            ("bond coeffs", w) => {
                let [kind, k, r0] = w else {
                    return Err(err(
                        line_no,
                        "a Bond Coeffs row of style harmonic needs type K r0".into(),
                    ));
                };
                let kind: u32 = kind
                    .parse()
                    .map_err(|_| err(line_no, format!("'{kind}' is not a bond type")))?;
                let (k, r0) = (num(k)?, num(r0)?);
                if k < 0.0 || r0 < 0.0 {
                    return Err(err(line_no, "K and r0 must not be negative".into()));
                }
                bond_coeffs.insert(kind, (k, r0));
            }
            ("velocities", w) => {
                let sphere = style == Some(AtomStyle::Sphere);
                let need = if sphere { 7 } else { 4 };
                if w.len() < need {
                    return Err(err(
                        line_no,
                        if sphere {
                            "a velocity row needs id vx vy vz wx wy wz".into()
                        } else {
                            "a velocity row needs id vx vy vz".into()
                        },
                    ));
                }
                let id: u64 = w[0]
                    .parse()
                    .map_err(|_| err(line_no, format!("'{}' is not an atom id", w[0])))?;
                let &i = ids
                    .get(&id)
                    .ok_or_else(|| err(line_no, format!("velocity of unknown atom {id}")))?;
                data.atoms[i].velocity = [num(w[1])?, num(w[2])?, num(w[3])?];
                if sphere {
                    data.atoms[i].angular_velocity = [num(w[4])?, num(w[5])?, num(w[6])?];
                }
            }
            _ => {}
        }
    }
    for (kind, ids_of, line) in bond_rows {
        let &(k, r0) = bond_coeffs.get(&kind).ok_or_else(|| {
            err(
                line,
                format!("bond type {kind} has no Bond Coeffs (K r0 of style harmonic) in the file: mote makes each bond a spring of stiffness 2K and rest length r0"),
            )
        })?;
        let index = |id: u64| {
            ids.get(&id)
                .copied()
                .ok_or_else(|| err(line, format!("bond of unknown atom {id}")))
        };
        data.bonds.push(Bond {
            kind,
            atoms: [index(ids_of[0])?, index(ids_of[1])?],
            k,
            r0,
        });
    }
    if let Some(n) = declared_bonds {
        if n != data.bonds.len() as u64 {
            return Err(err(
                bonds_at.unwrap_or(0),
                format!(
                    "the header declares {n} bonds, the file lists {}",
                    data.bonds.len()
                ),
            ));
        }
    }
    if general_given > 0 {
        if general_given != 4 {
            return Err(err(
                0,
                "a general triclinic box needs avec, bvec, cvec and abc origin".into(),
            ));
        }
        let origin = general[3];
        for (d, edge) in general[..3].iter().enumerate() {
            data.lo[d] = origin[d];
            data.hi[d] = origin[d] + edge[d];
            data.bounded[d] = true;
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
    data.style = style.unwrap_or_default();
    for a in &mut data.atoms {
        a.mass = masses.get(&a.kind).copied().unwrap_or(0.0);
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

    /// The point styles with their masses and velocities; triclinic boxes
    /// refused at their line; OVITO's axis-aligned general box read (it
    /// used to give a zero box).
    #[test]
    fn reads_common_styles_and_refuses_tilted_boxes() {
        let head = "title\n\n2 atoms\n2 atom types\n\n-1 1 xlo xhi\n0 2 ylo yhi\n0 3 zlo zhi\n\nMasses\n\n1 39.948\n2 4.0\n\n";
        for (style, rows) in [
            ("atomic", "1 1 0.5 0.5 0.5\n2 2 0.25 1 2 0 0 0\n"),
            ("charge", "1 1 -1 0.5 0.5 0.5\n2 2 1 0.25 1 2\n"),
            ("full", "1 7 1 -1 0.5 0.5 0.5\n2 7 2 1 0.25 1 2\n"),
        ] {
            let text =
                format!("{head}Atoms # {style}\n\n{rows}\nVelocities\n\n1 1 2 3\n2 0 0 -1\n");
            let d = parse(&text, "s.data").unwrap();
            assert_eq!((d.lo, d.hi), ([-1.0, 0.0, 0.0], [1.0, 2.0, 3.0]), "{style}");
            assert_eq!(d.atoms[1].position, [0.25, 1.0, 2.0], "{style}");
            assert_eq!((d.atoms[0].mass, d.atoms[1].mass), (39.948, 4.0), "{style}");
            assert_eq!(d.atoms[0].velocity, [1.0, 2.0, 3.0], "{style}");
            assert_eq!(d.atoms[1].kind, 2, "{style}");
            if style != "atomic" {
                assert_eq!(d.atoms[0].charge, -1.0, "{style}");
            }
        }
        let tilted = TEXT.replace("0 0.15 zlo zhi\n", "0 0.15 zlo zhi\n0.01 0 0 xy xz yz\n");
        let e = parse(&tilted, "t.data").unwrap_err();
        assert_eq!(e.line, 9);
        assert!(e.message.contains("triclinic"), "{}", e.message);
        let general = "title\n\n1 atoms\n1 atom types\n\n2 0 0 avec\n0 3 0 bvec\n0 0 4 cvec\n-1 -1 -1 abc origin\n\nAtoms # atomic\n\n1 1 0 0 0\n";
        let d = parse(general, "g.data").unwrap();
        assert_eq!((d.lo, d.hi), ([-1.0; 3], [1.0, 2.0, 3.0]));
        let skew = general.replace("0 3 0 bvec", "1 3 0 bvec");
        let e = parse(&skew, "g.data").unwrap_err();
        assert_eq!(e.line, 7);
        let labelled = "t\n\n2 atoms\n2 atom types\n\nAtom Type Labels\n\n1 Ar\n2 Fe\n\nMasses\n\nAr 39.948\n2 55.845\n\nAtoms # atomic\n\n1 1 0 0 0\n2 2 1 1 1\n";
        let d = parse(labelled, "l.data").unwrap();
        assert_eq!(d.type_labels[&1], "Ar");
        assert_eq!((d.atoms[0].mass, d.atoms[1].mass), (39.948, 55.845));
        let unnamed = "title\n\n1 atoms\n\nAtoms\n\n1 1 7 0 0 0\n";
        let e = parse(unnamed, "u.data").unwrap_err();
        assert!(e.message.contains("name it"), "{}", e.message);
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
