//! VTU files as meshio writes them (fixtures from tests/data/make_fixtures.py):
//! binary, zlib-compressed by default, and uncompressed binary. Before,
//! mote read ASCII arrays only and refused meshio's default.

use std::path::Path;

#[test]
fn reads_meshio_binary_and_compressed_vtu() {
    for file in ["meshio_default.vtu", "meshio_uncompressed.vtu"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file);
        let f = mote_io::vtu::read_vtu(&path).unwrap();
        assert_eq!(
            f.positions,
            [[0.0, 0.0, 0.0], [1.0, 2.0, 3.5], [-0.25, 0.5, 1e-3]],
            "{file}"
        );
        assert_eq!(f.radii, [0.5, 0.25, 0.125], "{file}");
        assert!(f.velocities.is_empty(), "{file}");
        assert_eq!(f.species, ["X", "X", "X"], "{file}");
    }
}

/// A corrupted compressed array is a message naming the array's line.
#[test]
fn broken_binary_arrays_are_named() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshio_default.vtu");
    let text = std::fs::read_to_string(path).unwrap();
    let at = text.find("eJ").unwrap();
    let broken = format!("{}AAAA{}", &text[..at], &text[at + 4..]);
    let e = mote_io::vtu::parse_vtu(&broken, "b.vtu")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("b.vtu:") && e.contains("DataArray 'Points'"),
        "{e}"
    );
}
