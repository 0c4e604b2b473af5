//! LAMMPS dump and VTU/PVD round trips, and the check that ASE, MDAnalysis
//! and meshio read mote's files (bench/check_formats.py).

#[allow(unused_imports)]
use mote_io::{lammps_dump, vtu, xyz, IoError, ParseError, Provenance};

use std::path::Path;

use mote_io::xyz::{read_frames, Frame, XyzWriter};

fn frame() -> Frame {
    Frame {
        time: 2.0,
        cell: [[5.0, 0.0, 0.0], [0.0, 6.0, 0.0], [0.0, 0.0, 7.0]],
        origin: [0.0, -1.0, 1.0],
        pbc: [true, true, true],
        species: vec!["Fe".into(), "O".into()], // ASE wants chemical symbols
        positions: vec![[1.0, 2.0, 3.0], [4.5, 4.0, 7.5]],
        velocities: vec![[0.1, 0.2, 0.3], [-1.0, 0.0, 1.0]],
        radii: vec![0.5, 0.75],
        masses: vec![55.845, 15.999],
        ..Default::default()
    }
}

/// XYZ → dump → VTU → back: every format gives the same particles and box.
#[test]
fn the_three_trajectory_formats_agree() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let f = frame();
    let mut x = XyzWriter::create(&d.join("t.xyz"), Provenance::default()).unwrap();
    x.write(&f).unwrap();
    let from_xyz = read_frames(&d.join("t.xyz")).unwrap().remove(0);
    let mut w = lammps_dump::DumpWriter::create(&d.join("t.dump")).unwrap();
    w.write(3, &from_xyz).unwrap();
    let from_dump = lammps_dump::read_frames(&d.join("t.dump"))
        .unwrap()
        .remove(0)
        .frame;
    vtu::write_vtu(&d.join("t.vtu"), &from_dump, &Provenance::default()).unwrap();
    let from_vtu = vtu::read_vtu(&d.join("t.vtu")).unwrap();
    for g in [&from_xyz, &from_dump, &from_vtu] {
        assert_eq!(g.cell, f.cell);
        assert_eq!(g.origin, f.origin);
        assert_eq!(g.positions, f.positions);
        assert_eq!(g.radii, f.radii);
    }
    assert!(matches!(
        lammps_dump::read_frames(Path::new("/nonexistent/x.dump")),
        Err(IoError::Os { .. })
    ));
}

/// Writes two frames in every format, then lets `bench/check_formats.py` read
/// them with ASE (XYZ), MDAnalysis (dump and GSD), the `gsd` package and
/// meshio (VTU). Skips, with a message, where Python or those packages are
/// missing.
#[test]
fn other_programs_read_the_same_positions_and_box() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut x = XyzWriter::create(&d.join("t.xyz"), Provenance::default()).unwrap();
    let mut w = lammps_dump::DumpWriter::create(&d.join("t.dump")).unwrap();
    let mut g = mote_io::gsd::GsdWriter::create(&d.join("t.gsd")).unwrap();
    let mut json = String::from("[");
    for k in 0..2 {
        let mut f = frame();
        f.time = k as f64;
        for p in &mut f.positions {
            p[0] += 0.25 * k as f64;
        }
        x.write(&f).unwrap();
        w.write(k, &f).unwrap();
        g.write(k, &f).unwrap();
        vtu::write_vtu(&d.join("t.vtu"), &f, &Provenance::default()).unwrap();
        vtu::write_vtp(&d.join("t.vtp"), &f, &Provenance::default()).unwrap();
        let rows = |v: &[[f64; 3]]| {
            let r: Vec<String> = v
                .iter()
                .map(|p| format!("[{:e},{:e},{:e}]", p[0], p[1], p[2]))
                .collect();
            format!("[{}]", r.join(","))
        };
        if k > 0 {
            json.push(',');
        }
        json.push_str(&format!(
            "{{\"positions\":{},\"velocities\":{},\"cell\":{},\"origin\":[{:e},{:e},{:e}]}}",
            rows(&f.positions),
            rows(&f.velocities),
            rows(&f.cell),
            f.origin[0],
            f.origin[1],
            f.origin[2]
        ));
    }
    json.push(']');
    std::fs::write(d.join("expected.json"), json).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/check_formats.py");
    let out = match std::process::Command::new("python3")
        .arg(&script)
        .arg(d)
        .output()
    {
        Ok(o) => o,
        Err(e) => {
            eprintln!("SKIP: python3 not runnable ({e})");
            return;
        }
    };
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => {
            eprintln!("{text}");
            assert!(text.contains("all formats agree"), "{text}")
        }
        Some(77) => eprintln!("{text}"),
        _ => panic!("bench/check_formats.py failed:\n{text}"),
    }
}
