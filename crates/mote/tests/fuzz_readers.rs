//! Byte-mutation fuzzing of every text reader, on stable Rust: valid inputs
//! (written by mote's own writers where it has them) are mutated at random
//! (bytes replaced by ones parsers care about, inserted, deleted, lines
//! doubled or dropped) and handed to the reader, which must answer Ok or a
//! `file:line` error: never panic, never take more than a second. A short
//! run belongs to the suite; the long one is
//! `cargo test --release -p mote --test cli fuzz_readers:: -- --ignored --nocapture`.
//! `mote rcp`'s standard input is fuzzed through the program itself (its
//! reader is the command's): every mutated input must end in under five
//! seconds with status 0 or spherepack1d's 255 and no panic.

use std::path::Path;
use std::time::{Duration, Instant};

use mote_io::checkpoint::Checkpoint;
use mote_io::xyz::Frame;
use mote_io::Provenance;
use mote_md::scene::Scene;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Bytes that steer parsers: digits, signs, exponents, brackets, quotes,
/// separators, line ends, letters of inf/nan, and a byte that is not UTF-8.
const INTERESTING: &[u8] = b"0123456789-+.eE[]{}=\",# \n\tinfaxyzF\xff";

fn mutate(seed: &[u8], rng: &mut Xoshiro256PlusPlus) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..rng.gen_range(1..=4) {
        let at = rng.gen_range(0..=b.len());
        match rng.gen_range(0..5) {
            0 if at < b.len() => b[at] = INTERESTING[rng.gen_range(0..INTERESTING.len())],
            1 => b.insert(at, INTERESTING[rng.gen_range(0..INTERESTING.len())]),
            2 if at < b.len() => {
                b.remove(at);
            }
            3 => {
                // Double or drop the line around `at`.
                let start = b[..at]
                    .iter()
                    .rposition(|c| *c == b'\n')
                    .map_or(0, |k| k + 1);
                let end = b[at..]
                    .iter()
                    .position(|c| *c == b'\n')
                    .map_or(b.len(), |k| at + k + 1);
                let line = b[start..end].to_vec();
                if rng.gen_bool(0.5) {
                    b.splice(start..start, line);
                } else {
                    b.drain(start..end);
                }
            }
            _ => b.truncate(at),
        }
    }
    b
}

/// Feeds `count` mutations of `seed` to `read`; returns how many it tried.
fn fuzz(name: &str, seed: &[u8], count: usize, mut read: impl FnMut(&[u8])) -> usize {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x5eed ^ name.len() as u64);
    for k in 0..count {
        let input = mutate(seed, &mut rng);
        let start = Instant::now();
        read(&input);
        let took = start.elapsed();
        assert!(
            took < Duration::from_secs(1),
            "{name}: input {k} took {took:?}:\n{}",
            String::from_utf8_lossy(&input)
        );
    }
    count
}

fn frame() -> Frame {
    Frame {
        time: 1.5,
        cell: [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
        origin: [0.0; 3],
        pbc: [true, true, false],
        species: vec!["A".into(), "B".into(), "A".into()],
        positions: vec![[0.5, 0.5, 0.5], [1.5, 2.0, 3.0], [3.5, 0.25, 1.0]],
        velocities: vec![[0.1, 0.0, -0.2], [0.0, 0.0, 0.0], [1e-3, 2.0, 0.5]],
        radii: vec![0.5, 0.25, 0.5],
        ..Default::default()
    }
}

fn provenance() -> Provenance {
    Provenance {
        program: "mote".into(),
        scene: "fuzz".into(),
        seed: 1,
    }
}

/// Every reader, `count` mutated inputs each; returns the total tried.
fn fuzz_all(count: usize) -> usize {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("input");
    let lossy = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    let through_file = |b: &[u8], read: &dyn Fn(&Path)| {
        std::fs::write(&file, b).unwrap();
        read(&file);
    };
    let mut tried = 0;

    // Scene TOML, parsed and built (the sun-earth example and a granular box).
    for (name, text) in [
        (
            "scene sun-earth",
            include_str!("../../../examples/sun-earth.toml"),
        ),
        (
            "scene rotating-drum",
            include_str!("../../../examples/rotating-drum.toml"),
        ),
        (
            "scene chute-flow",
            include_str!("../../../examples/chute-flow.toml"),
        ),
    ] {
        tried += fuzz(name, text.as_bytes(), count, |b| {
            let t = lossy(b);
            if let Ok(scene) = Scene::parse(&t, "fuzz.toml") {
                let _ = scene.build(&t, "fuzz.toml", 1);
            }
        });
    }
    // MPPphys particle file.
    let plist = "# two bodies\nk2 2.959122082855911e-4\ndt 0.5\npos 0 0 0 0 1 0 0.01 1 1 0\npos 1 1 0 0 3e-6 0 0.001\nvel 1 0 0.0172 0\nvfix 0 1 1 1\ns 0 100 0.5\nsl 0 1 0 1.0\n";
    tried += fuzz("plist", plist.as_bytes(), count, |b| {
        let _ = mote_io::plist::parse(&lossy(b), "fuzz.plist");
    });
    // LAMMPS data file (atom_style sphere) and dump.
    let data = "LAMMPS data\n\n3 atoms\n1 atom types\n\n0 4 xlo xhi\n0 4 ylo yhi\n0 4 zlo zhi\n\nAtoms # sphere\n\n1 1 1.0 2500 0.5 0.5 0.5\n2 1 0.5 2500 1.5 2.0 3.0\n3 1 1.0 2500 3.5 0.25 1.0\n\nVelocities\n\n1 0.1 0 -0.2 0 0 0\n2 0 0 0 0 0 0\n3 0.001 2 0.5 0 0 0\n";
    tried += fuzz("lammps data", data.as_bytes(), count, |b| {
        let _ = mote_io::lammps_data::parse(&lossy(b), "fuzz.data");
    });
    let mut dump = Vec::new();
    mote_io::lammps_dump::write_frame(&mut dump, 10, &frame(), &[1, 2, 1]).unwrap();
    tried += fuzz("lammps dump", &dump, count, |b| {
        let _ = mote_io::lammps_dump::parse(&lossy(b), "fuzz.dump");
    });
    // VTU (ASCII, as mote writes it).
    let vtu_path = dir.path().join("seed.vtu");
    mote_io::vtu::write_vtu(&vtu_path, &frame(), &provenance()).unwrap();
    let vtu = std::fs::read(&vtu_path).unwrap();
    tried += fuzz("vtu", &vtu, count, |b| {
        let _ = mote_io::vtu::parse_vtu(&lossy(b), "fuzz.vtu");
    });
    // VTU as meshio writes it: base64 + zlib.
    let meshio = include_bytes!("../../mote-io/tests/data/meshio_default.vtu");
    tried += fuzz("binary vtu", meshio, count, |b| {
        let _ = mote_io::vtu::parse_vtu(&lossy(b), "fuzz.vtu");
    });
    // VTP as VTK/ParaView write it: appended raw bytes, zlib and LZ4.
    for (name, seed) in [
        (
            "appended zlib vtp",
            &include_bytes!("../../mote-io/tests/data/vtk_raw_zlib.vtp")[..],
        ),
        (
            "appended lz4 vtp",
            &include_bytes!("../../mote-io/tests/data/vtk_raw_lz4.vtp")[..],
        ),
    ] {
        tried += fuzz(name, seed, count, |b| {
            let _ = mote_io::vtu::parse_vtu_bytes(b, "fuzz.vtp");
        });
    }
    // GSD (binary: mutated bytes, never a panic or a huge allocation).
    let gsd_path = dir.path().join("seed.gsd");
    let mut g = mote_io::gsd::GsdWriter::create(&gsd_path).unwrap();
    g.write(0, &frame()).unwrap();
    g.write(1, &frame()).unwrap();
    drop(g);
    let gsd = std::fs::read(&gsd_path).unwrap();
    tried += fuzz("gsd", &gsd, count, |b| {
        let _ = mote_io::gsd::parse(b, "fuzz.gsd");
    });
    // Extended XYZ, CSV and checkpoints, through files.
    let mut xyz = Vec::new();
    mote_io::xyz::write_frame(&mut xyz, &frame(), &provenance()).unwrap();
    tried += fuzz("xyz", &xyz, count, |b| {
        through_file(b, &|p| {
            let _ = mote_io::xyz::read_frames(p);
        })
    });
    let csv = b"# mote fuzz\n# units: t,E\ntime,kinetic_energy\n0,1.5\n1,1.25e-3\n2,nan\n";
    tried += fuzz("csv", csv, count, |b| {
        through_file(b, &|p| {
            let _ = mote_io::csv::read_table(p);
        })
    });
    let cp_path = dir.path().join("seed.mote");
    let cp = Checkpoint {
        program: "mote".into(),
        seed: 7,
        options: vec![("engine".into(), "rigid".into())],
        input_label: "fuzz".into(),
        input_text: "[run]\ndt = 0.1\n".into(),
        time: 0.5,
        step: 5,
        positions: frame().positions,
        velocities: frame().velocities,
        accelerations: frame().velocities,
        angular: vec![[1.0; 6]; 3],
        carried: vec![("granular".into(), vec![1.0, 2.0, f64::NAN])],
    };
    mote_io::checkpoint::write(&cp_path, &cp).unwrap();
    let cp_text = std::fs::read(&cp_path).unwrap();
    tried += fuzz("checkpoint", &cp_text, count, |b| {
        through_file(b, &|p| {
            let _ = mote_io::checkpoint::read(p);
        })
    });
    tried
}

/// `mote rcp ARGS` with `input` on its standard input: the status, or a
/// failure when it panics or runs past five seconds.
fn rcp_with(args: &[&str], input: &[u8]) -> Result<i32, String> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_mote"))
        .arg("rcp")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A reader may stop before the end of the input: a broken pipe is fine.
    let _ = child.stdin.take().unwrap().write_all(input);
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            return match status.code() {
                Some(c @ (0 | 255)) if !err.contains("panicked") => Ok(c),
                _ => Err(format!("{status}: {err}")),
            };
        }
        if start.elapsed() > Duration::from_secs(5) {
            child.kill().unwrap();
            return Err("ran past five seconds".into());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Mutated size distributions on `mote rcp`'s standard input, in each of
/// its input styles.
fn fuzz_rcp(count: usize) -> usize {
    let seeds: [(&[&str], &[u8]); 4] = [
        (
            &["-d", "-p", "3", "-N", "20000"],
            b"1.0 0.5\n2.0 0.3\n0.5 0.2\n",
        ),
        (
            &["-l", "-i", "-N", "20000"],
            b"2\n2.0 1.5 0.6\n1.0 0.9 0.4\n",
        ),
        (&["-w", "-N", "20000"], b"0.25\n"),
        (
            &["-d", "-i", "-u", "-N", "20000"],
            b"3\n1 0.2\n2 0.5\n4 0.3\n",
        ),
    ];
    let mut tried = 0;
    let mut errors = 0;
    for (k, (args, seed)) in seeds.iter().enumerate() {
        assert_eq!(
            rcp_with(args, seed),
            Ok(0),
            "the seed input {k} must be valid"
        );
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x4c9 + k as u64);
        for _ in 0..count {
            let input = mutate(seed, &mut rng);
            match rcp_with(args, &input) {
                Ok(c) => errors += usize::from(c != 0),
                Err(e) => panic!(
                    "mote rcp {}: {e}\ninput:\n{}",
                    args.join(" "),
                    String::from_utf8_lossy(&input)
                ),
            }
            tried += 1;
        }
    }
    println!("rcp: {tried} mutated inputs, {errors} refused with a message, none panicked or hung");
    tried
}

#[test]
fn readers_survive_mutated_inputs() {
    let tried = fuzz_all(400) + fuzz_rcp(100);
    println!("{tried} mutated inputs, no panic, none over a second");
}

#[test]
#[ignore = "long fuzz run"]
fn readers_survive_many_mutated_inputs() {
    let tried = fuzz_all(50_000) + fuzz_rcp(5_000);
    println!("{tried} mutated inputs, no panic, none over a second");
}
