//! The `[rigid]` scene format: the examples parse and build, the magnet
//! example runs and keeps its momentum, errors carry `file:line`, and an
//! ignored test runs any scene named by `MOTE_RIGID_SCENE` (for examples
//! and benchmarks before `mote run` routes to the runner).

use std::path::Path;

use mote_md::rigid::scene::{is_rigid_scene, run_rigid_scene, RigidRun, RigidScene};

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/rigid")
        .join(name);
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn examples_build() {
    for name in [
        "magnet-in-field.toml",
        "clumps-settling.toml",
        "chains-rotating-field.toml",
        "toning-nip.toml",
    ] {
        let text = example(name);
        assert!(is_rigid_scene(&text));
        let scene = RigidScene::parse(&text, name).unwrap_or_else(|e| panic!("{e}"));
        let built = scene
            .build(&text, name, None)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(!built.bodies.is_empty());
    }
    let bench = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/clump.toml"),
    )
    .unwrap();
    let built = RigidScene::parse(&bench, "clump.toml")
        .unwrap()
        .build(&bench, "clump.toml", None)
        .unwrap();
    assert_eq!(built.bodies.len(), 4608);
}

#[test]
fn magnet_example_runs() {
    let text = example("magnet-in-field.toml");
    let dir = tempfile::tempdir().unwrap();
    let r = run_rigid_scene(
        &text,
        "magnet-in-field.toml",
        &RigidRun {
            out_dir: Some(dir.path().to_path_buf()),
            ..RigidRun::default()
        },
        |_, _, _| {},
    )
    .unwrap();
    assert_eq!(r.steps, 20000);
    assert!((r.time - 200.0).abs() < 1e-9);
    let table = mote_io::csv::read_table(&dir.path().join("observables.csv")).unwrap();
    let e = table.column("total_energy").unwrap();
    let px = table.column("px").unwrap();
    let ly = table.column("Ly").unwrap();
    let spread = |v: &[f64]| {
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    println!(
        "energy spread {:e} px spread {:e} ly spread {:e}",
        spread(&e),
        spread(&px),
        spread(&ly)
    );
    assert!(spread(&px) < 1e-13);
    assert!(spread(&ly) < 1e-10);
    assert!(spread(&e) < 1e-2 * e[0].abs().max(1.0));
}

#[test]
fn errors_name_the_line() {
    let text = "seed = 1\n[rigid]\n[[rigid.template]]\nname = \"a\"\ngenerator = \"sphere\"\nradius = 1.0\ndensity = 1.0\n\n[[rigid.body]]\ntemplate = \"b\"\nposition = [0, 0, 0]\n\n[run]\ndt = 0.1\nsteps = 1\n";
    let e = RigidScene::parse(text, "s.toml")
        .unwrap()
        .build(text, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 9, "{e}");
    assert!(e.to_string().starts_with("s.toml:9:"), "{e}");
    let bad = text.replace("density = 1.0", "density = 1.0\ncolour = 3");
    let e = RigidScene::parse(&bad, "s.toml").err().unwrap();
    assert_eq!(e.line, 8, "{e}");
    let walls = text
        .replace("template = \"b\"", "template = \"a\"")
        .replace(
            "[run]",
            "[[rigid.wall]]\nkind = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n\n[run]",
        );
    let e = RigidScene::parse(&walls, "s.toml")
        .unwrap()
        .build(&walls, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 13, "{e}");
}

/// `MOTE_RIGID_SCENE=file [MOTE_RIGID_OUT=dir] cargo test --release --test
/// rigid_scene run_scene_file -- --ignored --nocapture`
#[test]
#[ignore]
fn run_scene_file() {
    let Ok(path) = std::env::var("MOTE_RIGID_SCENE") else {
        return;
    };
    let text = std::fs::read_to_string(&path).unwrap();
    let out = std::env::var("MOTE_RIGID_OUT").ok();
    let r = run_rigid_scene(
        &text,
        &path,
        &RigidRun {
            out_dir: out.as_deref().map(std::path::PathBuf::from),
            ..RigidRun::default()
        },
        |_, _, _| {},
    )
    .unwrap_or_else(|e| panic!("{e}"));
    println!(
        "{} bodies, {} spheres, {} steps, t = {}, {:.3} s wall, {:.4} µs per body-step\nKE {:e} PE {:e} P {} L {}",
        r.bodies,
        r.spheres,
        r.steps,
        r.time,
        r.wall_seconds,
        r.wall_seconds * 1e6 / (r.bodies as f64 * r.steps as f64),
        r.kinetic_energy,
        r.potential_energy,
        r.linear_momentum,
        r.angular_momentum
    );
    for (name, f) in r.wall_forces {
        println!("wall {name}: {f}");
    }
}

/// Trajectory frames carry each sphere's body and that body's orientation
/// as a unit quaternion (1, r)/√(1 + r²) of its rotation vector r: rotating
/// the template's sphere centres by it and adding the body's position gives
/// the spheres' world positions written beside it.
#[test]
fn frames_carry_bodies_and_orientations() {
    let text = example("clumps-settling.toml");
    let built = RigidScene::parse(&text, "clumps-settling.toml")
        .unwrap()
        .build(&text, "clumps-settling.toml", None)
        .unwrap();
    let b = &built.bodies;
    let f = mote_md::rigid::scene::sphere_frame(b);
    let n = f.positions.len();
    assert_eq!((f.bodies.len(), f.orientations.len()), (n, n));
    let mut next = vec![0usize; b.position.len()];
    for i in 0..n {
        let k = f.bodies[i] as usize;
        let [w, x, y, z] = f.orientations[i];
        assert!(((w * w + x * x + y * y + z * z) - 1.0).abs() < 1e-14);
        let q = glam::DQuat::from_xyzw(x, y, z, w);
        let t = &b.templates[b.kind[k] as usize];
        let offset = q * t.centres[next[k]];
        next[k] += 1;
        let want = b.position[k] + offset;
        let got = glam::DVec3::from(f.positions[i]);
        assert!(
            (got - want).length() < 1e-12 * (1.0 + want.length()),
            "sphere {i}: {got} vs {want}"
        );
    }
}

/// The scene text without its `[[rigid.random]]` tables.
fn without_random(text: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for line in text.lines() {
        if line.starts_with('[') {
            skip = line.starts_with("[[rigid.random]]");
        }
        if !skip {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// A rigid run's last frame, in each format that keeps radii and body ids,
/// starts a new scene: every body comes back as the template it was, with
/// its spheres where the file has them and their velocities.
#[test]
fn bodies_start_from_a_rigid_runs_frame() {
    let text = example("clumps-settling.toml")
        .replace("until = 0.5", "steps = 60")
        .replace("trajectory_every = 400", "trajectory_every = 60");
    let original = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .unwrap();
    for (format, name) in [
        (mote_io::trajectory::Format::Xyz, "trajectory.xyz"),
        (mote_io::trajectory::Format::Dump, "trajectory.dump"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        run_rigid_scene(
            &text,
            "s.toml",
            &RigidRun {
                out_dir: Some(dir.path().to_path_buf()),
                trajectory_format: Some(format),
                ..RigidRun::default()
            },
            |_, _, _| {},
        )
        .unwrap();
        let file = dir.path().join(name);
        let frames = mote_io::trajectory::read_frames(&file).unwrap();
        let last = frames.last().unwrap();
        assert!(last.time > 0.0);
        let again = without_random(&text).replace(
            "[rigid.fields]",
            &format!(
                "[[rigid.from_file]]\nfile = {:?}\n\n[rigid.fields]",
                file.display().to_string()
            ),
        );
        let built = RigidScene::parse(&again, "again.toml")
            .unwrap()
            .build(&again, "again.toml", None)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(built.bodies.kind, original.bodies.kind, "{name}");
        let frame = mote_md::rigid::run::sphere_frame(&built.bodies);
        let scale = 40e-3;
        for (a, b) in frame.positions.iter().zip(&last.positions) {
            for d in 0..3 {
                assert!((a[d] - b[d]).abs() < 1e-10 * scale, "{name}: {a:?} {b:?}");
            }
        }
        let speed = last
            .velocities
            .iter()
            .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(speed > 0.0);
        for (a, b) in frame.velocities.iter().zip(&last.velocities) {
            for d in 0..3 {
                assert!((a[d] - b[d]).abs() < 1e-9 * speed, "{name}: {a:?} {b:?}");
            }
        }
    }
}

#[test]
fn a_file_whose_bodies_fit_no_template_names_the_scene_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("f.xyz");
    std::fs::write(
        &file,
        "2\nProperties=species:S:1:pos:R:3:radius:R:1:body:I:1\nX 0 0 0 1.0 0\nX 3 0 0 1.0 0\n",
    )
    .unwrap();
    let text = format!(
        "[rigid]\n[[rigid.template]]\nname = \"a\"\ngenerator = \"dumbbell\"\nradius = 1.0\ndistance = 1.5\ndensity = 1.0\n\n[[rigid.from_file]]\nfile = {:?}\n\n[run]\ndt = 0.1\nsteps = 1\n",
        file.display().to_string()
    );
    let e = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 9, "{e}");
    assert!(
        e.to_string().contains("body 0") && e.to_string().contains("misses by"),
        "{e}"
    );
    // Moved to the dumbbell's distance, the spheres are one body of it.
    std::fs::write(
        &file,
        "2\nProperties=species:S:1:pos:R:3:radius:R:1:body:I:1\nX 0 0 0 1.0 0\nX 0 1.5 0 1.0 0\n",
    )
    .unwrap();
    let built = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .unwrap();
    assert_eq!(built.bodies.len(), 1);
    // (To the error of the template's integrated centre of mass.)
    let x = built.bodies.position[0];
    assert!(
        (x - glam::DVec3::new(0.0, 0.75, 0.0)).length() < 1e-5,
        "{x}"
    );
}
