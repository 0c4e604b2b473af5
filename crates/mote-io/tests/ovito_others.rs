//! Files OVITO 3.17 writes (fixtures from tests/data/make_fixtures.py), for
//! a periodic cell whose corner is (−1, 0.5, 2): extended XYZ with
//! `Origin=` and no species, a LAMMPS dump with `BOX BOUNDS abc origin`
//! (refused before), and a LAMMPS data file with an `avec bvec cvec` box
//! (read as a zero box before). Positions, velocities, radii (OVITO's f32),
//! types and the box come back.

use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

const POSITIONS: [[f64; 3]; 3] = [[0.0, 1.0, 2.5], [1.5, 2.25, 3.0], [2.5, 5.0, 7.5]];
const VELOCITIES: [[f64; 3]; 3] = [[0.5, 0.0, -0.25], [0.0, 1.0, 0.0], [0.125, 0.0, 2.0]];
const CELL: [[f64; 3]; 3] = [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]];
const ORIGIN: [f64; 3] = [-1.0, 0.5, 2.0];
/// OVITO keeps radii in f32.
const RADII: [f64; 3] = [0.5, 0.25, 0.7500000256];

#[test]
fn ovito_xyz_and_dump_come_back() {
    let xyz = mote_io::xyz::read_frames(&data("ovito.xyz"))
        .unwrap()
        .remove(0);
    let dump = mote_io::lammps_dump::read_frames(&data("ovito.dump"))
        .unwrap()
        .remove(0)
        .frame;
    for (what, f) in [("xyz", &xyz), ("dump", &dump)] {
        assert_eq!(f.positions, POSITIONS, "{what}");
        assert_eq!(f.velocities, VELOCITIES, "{what}");
        assert_eq!(f.radii, RADII, "{what}");
        assert_eq!(
            (f.cell, f.origin, f.pbc),
            (CELL, ORIGIN, [true; 3]),
            "{what}"
        );
    }
    assert_eq!(dump.species, ["1", "2", "1"]);
    assert_eq!(dump.ids, [1, 2, 3]);
}

#[test]
fn ovito_data_file_keeps_its_box() {
    let d = mote_io::lammps_data::read(&data("ovito.data")).unwrap();
    assert_eq!(d.lo, ORIGIN);
    assert_eq!(d.hi, [3.0, 5.5, 8.0]);
    let pos: Vec<[f64; 3]> = d.atoms.iter().map(|a| a.position).collect();
    let vel: Vec<[f64; 3]> = d.atoms.iter().map(|a| a.velocity).collect();
    let kinds: Vec<u32> = d.atoms.iter().map(|a| a.kind).collect();
    assert_eq!(pos, POSITIONS);
    assert_eq!(vel, VELOCITIES);
    assert_eq!(kinds, [1, 2, 1]);
}
