//! A GSD file written by the `gsd` package (HOOMD-blue's schema; fixture
//! made by tests/data/make_fixtures.py): mote reads its box, types,
//! positions, velocities, diameters and masses, and takes what frame 1
//! leaves out from frame 0, as the schema says. Before, GSD was an
//! "unknown trajectory format".

use std::path::Path;

#[test]
fn reads_what_the_gsd_package_writes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gsd_hoomd.gsd");
    let frames = mote_io::gsd::read_frames(&path).unwrap();
    assert_eq!(frames.len(), 2);
    let (a, b) = (&frames[0], &frames[1]);
    assert_eq!(a.cell, [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]]);
    // HOOMD's box is centred on the origin.
    assert_eq!(a.origin, [-2.0, -2.5, -3.0]);
    assert_eq!(a.pbc, [true; 3]);
    assert_eq!(a.species, ["A", "B", "A"]);
    assert_eq!(
        a.positions,
        [[-1.5, 0.5, 2.0], [0.25, -2.0, -2.5], [1.0, 1.0, 1.0]]
    );
    assert_eq!(
        a.velocities,
        [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, -3.0]]
    );
    assert_eq!(a.radii, [0.5, 0.25, 1.0]);
    assert_eq!(a.masses, [1.0, 2.0, 4.0]);
    assert_eq!((a.time, b.time), (0.0, 10.0));
    assert_eq!(
        b.positions,
        [[-1.25, 0.5, 2.0], [0.25, -1.75, -2.5], [1.0, 1.0, 1.25]]
    );
    assert_eq!(
        (&b.species, &b.radii, &b.masses),
        (&a.species, &a.radii, &a.masses)
    );
}
