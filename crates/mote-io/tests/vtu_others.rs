//! VTU files as meshio writes them (fixtures from tests/data/make_fixtures.py):
//! binary, zlib-compressed by default, and uncompressed binary. Before,
//! mote read ASCII arrays only and refused meshio's default. VTP files as
//! VTK 9.7's XML writer (ParaView's) writes them: appended raw (ParaView's
//! default) or base64 (VTK's), uncompressed, zlib or LZ4.

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

#[test]
fn reads_vtk_appended_raw_base64_zlib_and_lz4() {
    for file in [
        "vtk_raw_zlib.vtp",
        "vtk_raw.vtp",
        "vtk_base64_zlib.vtp",
        "vtk_raw_lz4.vtp",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file);
        let f = mote_io::vtu::read_vtu(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(
            f.positions,
            [[0.0, 0.0, 0.0], [1.0, 2.0, 3.5], [-0.25, 0.5, 1e-3]],
            "{file}"
        );
        assert_eq!(f.radii, [0.5, 0.25, 0.125], "{file}");
        // Float32 in the file; these values are exact in it.
        assert_eq!(
            f.velocities,
            [[1.0, 0.0, -0.5], [0.0, 2.0, 0.0], [0.25, 0.0, 4.0]],
            "{file}"
        );
    }
}

/// Appended data cut short, or a block table that asks for more than the
/// file holds, is a message naming the array, never a panic.
#[test]
fn broken_appended_data_is_named() {
    for file in ["vtk_raw_zlib.vtp", "vtk_raw.vtp", "vtk_raw_lz4.vtp"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file);
        let bytes = std::fs::read(path).unwrap();
        let marker = bytes
            .windows(13)
            .position(|w| w == b"<AppendedData")
            .unwrap();
        let start = marker + bytes[marker..].iter().position(|&b| b == b'_').unwrap() + 1;
        // Cut inside the Points array, then garble the first header.
        for cut in [start + 100, start + 2] {
            let e = mote_io::vtu::parse_vtu_bytes(&bytes[..cut], "b.vtp")
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("b.vtp:") && e.contains("DataArray"),
                "{file}: {e}"
            );
        }
        let mut garbled = bytes.clone();
        for b in &mut garbled[start..start + 4] {
            *b = 0xff;
        }
        let e = mote_io::vtu::parse_vtu_bytes(&garbled, "b.vtp")
            .unwrap_err()
            .to_string();
        assert!(e.contains("DataArray 'radius'"), "{file}: {e}");
    }
}
