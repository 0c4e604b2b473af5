//! The readers are bounded and strict (issue 37, part 2): a count in a
//! header reserves nothing the file cannot hold, and duplicated ids,
//! inverted boxes, undeclared types, negative radii and non-finite numbers
//! are refused at their line with `file:line: why`.

use std::time::Instant;

use mote_io::{lammps_data, lammps_dump, xyz};

const DUMP: &str = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\n\
ITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n\
ITEM: ATOMS id type x y z radius\n1 1 1 1 1 0.5\n2 1 2 2 2 0.5\n";

/// `text` refused at `line` with a message containing `why`.
fn refused<T: std::fmt::Debug>(result: Result<T, mote_io::ParseError>, line: usize, why: &str) {
    let e = result.expect_err("refused").to_string();
    assert!(e.contains(&format!("t:{line}: ")), "{e}");
    assert!(e.contains(why), "{e}");
}

#[test]
fn dump_counts_and_rows_are_checked() {
    assert_eq!(lammps_dump::parse(DUMP, "t").unwrap().len(), 1);
    for count in ["2000000000", "18446744073709551615"] {
        let start = Instant::now();
        let text = DUMP.replace("ATOMS\n2\n", &format!("ATOMS\n{count}\n"));
        refused(lammps_dump::parse(&text, "t"), 4, "lines left");
        assert!(start.elapsed().as_secs_f64() < 0.5);
    }
    refused(
        lammps_dump::parse(&DUMP.replace("2 1 2 2 2", "1 1 2 2 2"), "t"),
        11,
        "atom id 1 again (first on line 10)",
    );
    refused(
        lammps_dump::parse(&DUMP.replace("0 10\n0 10\n0 10", "0 10\n5 -5\n0 10"), "t"),
        7,
        "lo must not exceed hi",
    );
    for bad in ["nan", "inf", "-inf"] {
        refused(
            lammps_dump::parse(&DUMP.replace("2 1 2 2 2", &format!("2 1 2 {bad} 2")), "t"),
            11,
            "y = ",
        );
    }
    refused(
        lammps_dump::parse(&DUMP.replace("2 2 0.5", "2 2 -1"), "t"),
        11,
        "radius -1: must not be negative",
    );
}

const XYZ: &str = "2\nProperties=species:S:1:pos:R:3:radius:R:1:id:I:1\n\
A 0 0 0 0.5 1\nA 1 1 1 0.5 2\n";

#[test]
fn xyz_rows_are_checked() {
    assert_eq!(xyz::parse_frames(XYZ, "t").unwrap().len(), 1);
    let start = Instant::now();
    refused(
        xyz::parse_frames(&XYZ.replacen("2\n", "2000000000\n", 1), "t"),
        5,
        "announces 2000000000 particles",
    );
    assert!(start.elapsed().as_secs_f64() < 0.5);
    refused(
        xyz::parse_frames(&XYZ.replace("1 1 1 0.5", "1 1 1 -1"), "t"),
        4,
        "radius -1: must not be negative",
    );
    for bad in ["nan", "inf"] {
        refused(
            xyz::parse_frames(&XYZ.replace("A 1 1 1", &format!("A 1 {bad} 1")), "t"),
            4,
            "must be a finite number",
        );
    }
    refused(
        xyz::parse_frames(&XYZ.replace("0.5 2\n", "0.5 1\n"), "t"),
        4,
        "id 1 again (first on line 3)",
    );
}

const DATA: &str = "title\n\n2 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n\
Masses\n\n1 1.0\n\nAtoms # atomic\n\n1 1 0.1 0.1 0.1\n2 1 0.5 0.5 0.5\n";

#[test]
fn data_types_and_boxes_are_checked() {
    assert_eq!(lammps_data::parse(DATA, "t").unwrap().atoms.len(), 2);
    refused(
        lammps_data::parse(&DATA.replace("2 1 0.5", "2 3 0.5"), "t"),
        17,
        "atom type 3: the header declares types 1 to 1",
    );
    refused(
        lammps_data::parse(&DATA.replace("2 1 0.5", "2 0 0.5"), "t"),
        17,
        "atom type 0",
    );
    refused(
        lammps_data::parse(&DATA.replace("0 1 ylo", "1 0 ylo"), "t"),
        7,
        "lo must not exceed hi",
    );
    refused(
        lammps_data::parse(&DATA.replace("0.5 0.5 0.5", "0.5 nan 0.5"), "t"),
        17,
        "must be a finite number",
    );
}

/// Bonds are read with their harmonic coefficients; what mote would drop
/// (bonds without coefficients, another bond style, angles) is refused at
/// its line, never dropped without a word.
#[test]
fn data_bonds_are_read_and_other_topology_refused() {
    let header = |t: &str| DATA.replace("1 atom types\n", &format!("1 atom types\n{t}"));
    let bonded = header("1 bonds\n1 bond types\n")
        + "\nBond Coeffs # harmonic\n\n1 50.0 0.8\n\nBonds\n\n1 1 2 1\n";
    let d = lammps_data::parse(&bonded, "t").unwrap();
    assert_eq!(d.bonds.len(), 1);
    let b = d.bonds[0];
    assert_eq!((b.kind, b.k, b.r0), (1, 50.0, 0.8));
    assert_eq!(
        [d.atoms[b.atoms[0]].id, d.atoms[b.atoms[1]].id],
        [2, 1],
        "atoms by id"
    );
    let no_coeffs = header("1 bonds\n1 bond types\n") + "\nBonds\n\n1 1 1 2\n";
    refused(
        lammps_data::parse(&no_coeffs, "t"),
        23,
        "has no Bond Coeffs",
    );
    let fene = bonded.replace("# harmonic", "# fene");
    refused(
        lammps_data::parse(&fene, "t"),
        21,
        "bond style harmonic (K r0) only",
    );
    let unknown = bonded.replace("1 1 2 1\n", "1 1 2 7\n");
    refused(
        lammps_data::parse(&unknown, "t"),
        27,
        "bond of unknown atom 7",
    );
    let miscounted = bonded.replace("1 bonds", "2 bonds");
    refused(lammps_data::parse(&miscounted, "t"), 25, "declares 2 bonds");
    let angles = header("") + "\nAngles\n\n1 1 1 2 1\n";
    refused(
        lammps_data::parse(&angles, "t"),
        19,
        "Angles: mote has no angle forces",
    );
}
