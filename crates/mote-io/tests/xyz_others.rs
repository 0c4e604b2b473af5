//! XYZ files written by other programs (fixtures in tests/data, made by
//! ASE 3.29 with `make_fixtures.py`), and the findings of issue 22 about
//! mote's own XYZ: each test failed before the reader went by `Properties`.

use std::path::{Path, PathBuf};

use mote_io::xyz::{parse_frames, read_frames, Frame, XyzWriter};
use mote_io::Provenance;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

const POSITIONS: [[f64; 3]; 4] = [
    [0.5, 1.0, 1.5],
    [2.25, 0.125, 3.0],
    [3.5, 4.75, 5.5],
    [1.0, 2.0, 0.25],
];
const VELOCITIES: [[f64; 3]; 4] = [
    [0.01, -0.02, 0.03],
    [0.0, 0.5, -0.25],
    [-0.125, 0.0, 0.0625],
    [0.3, 0.2, 0.1],
];

fn species() -> Vec<String> {
    ["Ar", "Ar", "Ar", "Fe"].map(String::from).to_vec()
}

/// ASE's default extended XYZ (species and positions only) and its plain
/// XYZ: both were refused ("expected: species x y z vx vy vz radius").
#[test]
fn ase_default_and_plain_xyz_are_read() {
    for file in ["ase_default.extxyz", "ase_plain.xyz"] {
        let f = read_frames(&data(file)).unwrap().remove(0);
        assert_eq!(f.positions, POSITIONS, "{file}");
        assert_eq!(f.species, species(), "{file}");
        assert!(f.velocities.is_empty() && f.radii.is_empty(), "{file}");
        assert_eq!(f.pbc, [false; 3], "{file}");
    }
}

/// ASE writes momenta, not velocities: they are divided by the standard
/// atomic weights (Ar 39.948, Fe 55.845), never taken as velocities (which
/// made argon 39.9× too fast).
#[test]
fn ase_momenta_become_velocities() {
    let f = read_frames(&data("ase_momenta.extxyz")).unwrap().remove(0);
    assert_eq!(f.positions, POSITIONS);
    assert_eq!(f.cell, [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]]);
    assert_eq!(f.pbc, [true; 3]);
    for (v, want) in f.velocities.iter().zip(VELOCITIES) {
        for d in 0..3 {
            // ASE writes momenta with 8 decimals.
            assert!((v[d] - want[d]).abs() < 1e-9, "{v:?} against {want:?}");
        }
    }
}

/// Momenta of particles that are not chemical elements, with no masses
/// column: a message naming the line, not a guess.
#[test]
fn momenta_without_masses_are_refused() {
    let text = "2\nProperties=species:S:1:pos:R:3:momenta:R:3\nAr 0 0 0 1 0 0\nB0 1 1 1 0 1 0\n";
    let err = parse_frames(text, "m.xyz").unwrap_err().to_string();
    assert!(err.starts_with("m.xyz:4:") && err.contains("'B0'"), "{err}");
    // With a masses column they convert, whatever the species.
    let text = "1\nProperties=species:S:1:masses:R:1:pos:R:3:momenta:R:3\nB0 2 0 0 0 1 0 4\n";
    let f = parse_frames(text, "m.xyz").unwrap().remove(0);
    assert_eq!(f.velocities, [[0.5, 0.0, 2.0]]);
}

/// Columns in any order and subset (OVITO writes `pos` and `radius`
/// without species; unknown columns are skipped), atomic numbers as
/// species, and lines that do not match `Properties` named.
#[test]
fn properties_in_any_order() {
    let text = "2\nProperties=radius:R:1:charge:R:1:pos:R:3:Z:I:1 Time=3\n\
                0.5 -1 1 2 3 26\n0.25 1 4 5 6 8\n";
    let f = parse_frames(text, "o.xyz").unwrap().remove(0);
    assert_eq!(f.positions, [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    assert_eq!(f.radii, [0.5, 0.25]);
    assert_eq!(f.species, ["Fe", "O"]);
    assert_eq!(f.time, 3.0);
    let short = "1\nProperties=pos:R:3:radius:R:1\n1 2 3\n";
    let err = parse_frames(short, "s.xyz").unwrap_err().to_string();
    assert!(
        err.starts_with("s.xyz:3:") && err.contains("pos×3 radius×1"),
        "{err}"
    );
    let no_pos = "1\nProperties=species:S:1:radius:R:1\nAr 1\n";
    let err = parse_frames(no_pos, "p.xyz").unwrap_err().to_string();
    assert!(
        err.starts_with("p.xyz:2:") && err.contains("position"),
        "{err}"
    );
}

fn frame() -> Frame {
    Frame {
        time: 0.5,
        cell: [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]],
        origin: [-1.0, -1.5, -2.0],
        pbc: [true, true, false],
        species: vec!["X".into(), "X".into()],
        positions: vec![[-0.75, 0.5, 1.0], [0.5, -1.25, -1.75]],
        velocities: vec![[1.0, 2.0, 3.0], [-0.5, 0.0, 0.25]],
        radii: vec![0.5, 0.25],
        masses: vec![2.0, 4.0],
        ids: vec![7, 9],
        angular_velocities: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
        dipoles: vec![[0.0, 1.0, 0.0], [0.0, 0.0, -1.0]],
        bodies: vec![0, 0],
        orientations: vec![[1.0, 0.0, 0.0, 0.0], [0.5, -0.5, 0.5, 0.5]],
    }
}

/// Everything mote writes comes back: ids, masses, spins, dipoles, bodies;
/// a periodic box off the origin is written shifted to it (`Shift=`), so
/// that ASE's cell holds the particles, and shifted back on reading.
#[test]
fn mote_frames_round_trip_with_every_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("all.xyz");
    let f = frame();
    // Every number of this frame has fewer than 11 digits, so the
    // default format keeps them all.
    XyzWriter::create(&path, Provenance::default())
        .unwrap()
        .write(&f)
        .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("Shift=\"-1 -1.5 -2\""), "{text}");
    assert!(text.contains("velo:R:3") && text.contains("masses:R:1:momenta:R:3"));
    // In the file, positions lie in the cell [0, L).
    let line = text.lines().nth(2).unwrap();
    assert!(
        line.starts_with("X 2.5000000000e-1 2.0000000000e0 3.0000000000e0"),
        "{line}"
    );
    assert_eq!(read_frames(&path).unwrap().remove(0), f);
    // Exact files are not shifted: bit for bit comes first.
    let exact = dir.path().join("exact.xyz");
    let awkward = Frame {
        positions: vec![[0.1 + 0.2, 1e-300, -1.0 / 3.0], [5e-324, 7.0, 0.1]],
        ..f.clone()
    };
    XyzWriter::create(&exact, Provenance::default())
        .unwrap()
        .exact()
        .write(&awkward)
        .unwrap();
    let text = std::fs::read_to_string(&exact).unwrap();
    assert!(text.contains("Origin=\"-1 -1.5 -2\"") && !text.contains("Shift"));
    assert_eq!(read_frames(&exact).unwrap().remove(0), awkward);
}
