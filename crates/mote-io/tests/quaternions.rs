//! Body orientations in extended XYZ: written in OVITO's order (its
//! Orientation.X, .Y, .Z, .W) and said so on the line; read back as mote
//! holds them (w, x, y, z); files mote wrote before it said so (scalar
//! first) and files of other programs (OVITO's order) each read right; OVITO
//! itself reads the orientation mote wrote.

use mote_io::xyz::{parse_frames, write_frame, Frame};
use mote_io::Provenance;

/// A unit quaternion (w, x, y, z) with four different entries.
const Q: [f64; 4] = [0.5, 0.5, -0.5, 0.5];
const R: [f64; 4] = [0.9, 0.1, 0.3, -0.3];

fn frame() -> Frame {
    let norm = |q: [f64; 4]| {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.map(|x| x / n)
    };
    Frame {
        positions: vec![[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]],
        species: vec!["X".into(), "X".into()],
        orientations: vec![Q, norm(R)],
        cell: [[5.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 5.0]],
        pbc: [true; 3],
        ..Frame::default()
    }
}

fn written() -> String {
    let mut out = Vec::new();
    let provenance = Provenance {
        program: "mote 0.1.0".into(),
        scene: "q.toml".into(),
        seed: 1,
    };
    write_frame(&mut out, &frame(), &provenance).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn orientations_are_written_in_ovito_order_and_read_back() {
    let text = written();
    let comment = text.lines().nth(1).unwrap();
    assert!(comment.contains("quaternion_order=\"xyzw\""), "{comment}");
    let row: Vec<f64> = text
        .lines()
        .nth(2)
        .unwrap()
        .split_whitespace()
        .rev()
        .take(4)
        .map(|x| x.parse().unwrap())
        .collect();
    // The last four numbers of the first row: x, y, z, w (reversed here).
    assert_eq!(row, [Q[0], Q[3], Q[2], Q[1]]);
    let back = parse_frames(&text, "q.xyz").unwrap().remove(0);
    for (a, b) in back.orientations.iter().zip(&frame().orientations) {
        for k in 0..4 {
            assert!((a[k] - b[k]).abs() < 1e-9, "{a:?} against {b:?}");
        }
    }
}

#[test]
fn older_mote_files_and_other_programs_files_read_right() {
    let line = |comment: &str, q: [f64; 4]| {
        format!(
            "1\nLattice=\"5 0 0 0 5 0 0 0 5\" Properties=species:S:1:pos:R:3:orientation:R:4 pbc=\"T T T\"{comment}\nX 1 1 1 {} {} {} {}\n",
            q[0], q[1], q[2], q[3]
        )
    };
    // mote before the marker: scalar first.
    let old = parse_frames(&line(" program=\"mote 0.1.0\"", Q), "old.xyz").unwrap();
    assert_eq!(old[0].orientations[0], Q);
    // Another program (OVITO's order): x, y, z, w.
    let [w, x, y, z] = Q;
    let foreign = parse_frames(&line("", [x, y, z, w]), "ovito.xyz").unwrap();
    assert_eq!(foreign[0].orientations[0], Q);
    // Said explicitly, either way.
    let said = parse_frames(&line(" quaternion_order=\"wxyz\"", Q), "said.xyz").unwrap();
    assert_eq!(said[0].orientations[0], Q);
    let e = parse_frames(&line(" quaternion_order=\"zyxw\"", Q), "bad.xyz").unwrap_err();
    assert!(e.to_string().starts_with("bad.xyz:2:"), "{e}");
}

/// OVITO reads the orientation mote wrote as the same rotation: its W is
/// mote's w (skipped where OVITO cannot be imported).
#[test]
fn ovito_reads_the_orientation_mote_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("q.xyz");
    std::fs::write(&path, written()).unwrap();
    let script = format!(
        "from ovito.io import import_file\nq = import_file({:?}).compute().particles['Orientation'][...]\nprint(' '.join(repr(float(v)) for v in q[0]))",
        path.display().to_string()
    );
    let out = match std::process::Command::new("python3")
        .args(["-c", &script])
        .output()
    {
        Ok(o) if o.status.success() => o,
        Ok(o) => {
            eprintln!(
                "SKIP: OVITO not importable: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            return;
        }
        Err(e) => {
            eprintln!("SKIP: python3 not runnable ({e})");
            return;
        }
    };
    let xyzw: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(xyzw, [Q[1], Q[2], Q[3], Q[0]], "OVITO's X, Y, Z, W");
}
