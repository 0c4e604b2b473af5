//! The `[rigid]` scene format: the examples parse and build, errors carry
//! `file:line`, frames carry bodies. Whole runs are the front's
//! (mote-front's tests, `rigid_runs`).

use std::path::Path;

use mote_md::rigid::scene::{is_rigid_scene, RigidScene};

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
        "[rigid]\n[[rigid.template]]\nname = \"a\"\ngenerator = \"dumbbell\"\nradius = 1.0\ndistance = 1.5\ndensity = 1.0\n\n[[from_file]]\nfile = {:?}\n\n[run]\ndt = 0.1\nsteps = 1\n",
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
    // The first spelling, inside [rigid], is refused with the one every
    // engine uses, at its line.
    let old = text.replace("[[from_file]]", "[[rigid.from_file]]");
    let e = RigidScene::parse(&old, "s.toml")
        .unwrap()
        .build(&old, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 9, "{e}");
    assert!(e.to_string().contains("[[from_file]] file = "), "{e}");
    // (To the error of the template's integrated centre of mass.)
    let x = built.bodies.position[0];
    assert!(
        (x - glam::DVec3::new(0.0, 0.75, 0.0)).length() < 1e-5,
        "{x}"
    );
}

/// Found by the rigid scene property test: a placement region of 1.8e308
/// panicked in the uniform draw, a bead of 1 000 lobes would take most of
/// an hour to integrate and one of 10¹² lobes aborted asking for 40 TB; all
/// are refused at their table, at once.
#[test]
fn a_region_too_wide_to_draw_from_and_a_template_too_costly_are_refused() {
    let scene = |lobes: &str, hi: &str| {
        format!(
            "seed = 7\n[rigid]\n[[rigid.template]]\nname = \"bead\"\ngenerator = \"irregular\"\n\
             radius = 1e-3\nlobes = {lobes}\nseed = 1\ndensity = 2000.0\n\
             [[rigid.random]]\ntemplate = \"bead\"\nn = 3\nlo = [2e-3, 2e-3, 2e-3]\nhi = [{hi}, 9e-3, 9e-3]\n\
             [run]\ndt = 5e-6\nsteps = 1\n"
        )
    };
    let t0 = std::time::Instant::now();
    let text = scene("9", "1.7976931348623157e308");
    let e = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 10, "{e}");
    assert!(e.to_string().contains("wider than a placement"), "{e}");
    let text = scene("1000", "9e-3");
    let e = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .err()
        .unwrap();
    assert_eq!(e.line, 3, "{e}");
    assert!(
        e.to_string().contains("1001 spheres overlapping") && e.to_string().contains("minutes"),
        "{e}"
    );
    // 10¹² lobes asked for 40 TB before anything was checked
    let text = scene("1000000000000", "9e-3");
    let e = RigidScene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", None)
        .err()
        .unwrap();
    assert!(e.to_string().contains("at most 10000 spheres"), "{e}");
    assert!(t0.elapsed().as_secs_f64() < 5.0);
}

/// `[gravity]`, the point particles' table, between rigid bodies: two
/// irregular clumps feel Newton's law between their centres of mass,
/// F = G m₁m₂ d/|d|³ (002 Eq. 2, unsoftened), no torque, and the energy
/// is −G m₁m₂/|d| — the point particles' kernel, read from the same table.
#[test]
fn mutual_gravity_acts_between_the_bodies_centres() {
    let text = "seed = 3\n[gravity]\nG = 2.5\n[rigid]\n[[rigid.template]]\nname = \"a\"\ngenerator = \"irregular\"\nradius = 1.0\nlobes = 6\ndensity = 3.0\n\n[[rigid.template]]\nname = \"b\"\ngenerator = \"dumbbell\"\nradius = 0.7\ndistance = 0.9\ndensity = 1.5\n\n[[rigid.body]]\ntemplate = \"a\"\nposition = [0.3, -1.0, 0.2]\n\n[[rigid.body]]\ntemplate = \"b\"\nposition = [2.9, 1.4, -0.8]\nrotation = [0.2, 0.5, -0.1]\n\n[run]\ndt = 0.01\nsteps = 1\n";
    let built = RigidScene::parse(text, "g.toml")
        .unwrap()
        .build(text, "g.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut frbi = built.frbi;
    let bodies = built.bodies;
    let (m1, m2) = (bodies.template(0).mass(), bodies.template(1).mass());
    let d = bodies.position[0] - bodies.position[1];
    let r = d.length();
    let g = 2.5;
    let expected = -d * (g * m1 * m2 / (r * r * r));
    let w = frbi.wrenches(&bodies, 0.0, 0.0).to_vec();
    let close = |a: glam::DVec3, b: glam::DVec3| (a - b).length() <= 1e-13 * b.length();
    assert!(close(w[0].v, expected), "{} vs {expected}", w[0].v);
    assert!(close(w[1].v, -expected), "{}", w[1].v);
    assert_eq!(w[0].omega, glam::DVec3::ZERO);
    let energy = frbi.energies(&bodies).potential;
    let want = -g * m1 * m2 / r;
    assert!(
        (energy - want).abs() <= 1e-13 * want.abs(),
        "{energy} vs {want}"
    );
}
