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
    // The frame lists the bodies by their scene numbers (the bodies are
    // stored in space order: row k is body number_of(k)).
    assert!((0..b.len()).any(|k| b.number_of(k) != k as u64));
    let row_of: std::collections::HashMap<u64, usize> =
        (0..b.len()).map(|k| (b.number_of(k), k)).collect();
    assert!(
        f.bodies.windows(2).all(|w| w[0] <= w[1]),
        "spheres body after body in the scene's numbering"
    );
    let mut next = vec![0usize; b.position.len()];
    for i in 0..n {
        let k = row_of[&f.bodies[i]];
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

/// `[dipolar] method = "ewald"`, the point particles' table, between rigid
/// bodies in a periodic cube: eight magnetised one-sphere bodies get the
/// forces, torques and energy eight point dipoles at their centres get from
/// the same table — one Ewald dipole sum for points and clumps.
#[test]
fn ewald_dipoles_between_bodies_are_the_point_particles() {
    use glam::DVec3;
    use mote_md::force::{Spin, State};
    use mote_md::scene::Scene;
    let places = [
        [0.4, 0.7, 1.1],
        [2.9, 0.3, 4.6],
        [5.1, 2.2, 0.9],
        [1.7, 3.8, 2.5],
        [4.2, 4.9, 5.3],
        [0.8, 5.6, 3.9],
        [3.3, 1.9, 2.8],
        [5.7, 4.1, 1.6],
    ];
    let moments = [
        [0.3, -0.8, 0.5],
        [-0.6, 0.1, 0.9],
        [1.0, 0.4, -0.2],
        [0.0, 0.7, 0.7],
        [-0.4, -0.4, 0.8],
        [0.9, -0.3, 0.1],
        [0.2, 1.1, -0.5],
        [-0.7, 0.6, 0.3],
    ];
    let envelope = "[box]\nhi = [6.0, 6.0, 6.0]\n\n[dipolar]\nmethod = \"ewald\"\nmu0 = 2.0\naccuracy = 1e-6\n\n[run]\ndt = 0.01\nsteps = 1\n";
    let mut points = envelope.to_string();
    let mut rigid = format!("{envelope}\n[rigid]\n");
    for (k, (x, m)) in places.iter().zip(moments).enumerate() {
        points += &format!(
            "\n[[particle]]\nposition = {x:?}\nmass = 1.0\nradius = 0.3\ndipole = {m:?}\n"
        );
        rigid += &format!(
            "\n[[rigid.template]]\nname = \"t{k}\"\ngenerator = \"sphere\"\nradius = 0.3\ndensity = 1.0\ndipole = {m:?}\n\n[[rigid.body]]\ntemplate = \"t{k}\"\nposition = {x:?}\n"
        );
    }
    let mut sim = Scene::parse(&points, "points.toml")
        .and_then(|s| s.build(&points, "points.toml", 1))
        .unwrap_or_else(|e| panic!("{e}"))
        .simulation;
    let p = &sim.system.particles;
    let state = State::new(&p.position, &p.velocity, &p.mass, 0.0).with_dipoles(&p.dipole);
    let spin = Spin {
        angular_velocity: &p.angular_velocity,
    };
    let n = places.len();
    let (mut force, mut torque) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    sim.forces
        .add_forces_and_torques(&state, &spin, &mut force, &mut torque);
    let point_energy = sim.forces.potential_energy(&state).0;

    let built = RigidScene::parse(&rigid, "rigid.toml")
        .unwrap()
        .build(&rigid, "rigid.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut frbi = built.frbi;
    let w = frbi.wrenches(&built.bodies, 0.0, 0.0).to_vec();
    let scale = force.iter().map(|f| f.length()).fold(0.0, f64::max);
    assert!(scale > 0.0 && point_energy != 0.0, "the dipoles interact");
    // The bodies are stored in space order: body row i is scene body
    // number_of(i), the point particle of that row.
    assert_eq!(w.len(), n);
    for (i, w) in w.iter().enumerate() {
        let k = built.bodies.number_of(i) as usize;
        assert!(
            (w.v - force[k]).length() <= 1e-12 * scale,
            "force {k}: {} vs {}",
            w.v,
            force[k]
        );
        assert!(
            (w.omega - torque[k]).length() <= 1e-12 * scale,
            "torque {k}: {} vs {}",
            w.omega,
            torque[k]
        );
    }
    let energy = frbi.energies(&built.bodies).potential;
    assert!(
        (energy - point_energy).abs() <= 1e-12 * point_energy.abs(),
        "{energy} vs {point_energy}"
    );
}

/// `[[rigid.random]]` over a whole periodic axis keeps the bodies'
/// bounding spheres apart through the box's faces too (they overlapped
/// there, and the overlapping carriers of a nip shot off at 10⁷ m/s).
#[test]
fn random_bodies_do_not_overlap_through_periodic_faces() {
    let text = r#"
[rigid]
[[rigid.template]]
name = "ball"
generator = "sphere"
radius = 1.0
density = 1.0
[[rigid.random]]
template = "ball"
n = 60
lo = [0.0, 0.0, 0.0]
hi = [12.0, 12.0, 12.0]
[box]
lo = [0.0, 0.0, 0.0]
hi = [12.0, 12.0, 12.0]
periodic = [true, true, false]
[run]
dt = 0.01
steps = 1
"#;
    let built = RigidScene::parse(text, "r.toml")
        .unwrap()
        .build(text, "r.toml", Some(3))
        .unwrap();
    let x = &built.bodies.position;
    assert_eq!(x.len(), 60);
    for i in 0..x.len() {
        for j in 0..i {
            let mut d = x[i] - x[j];
            for a in 0..2 {
                d[a] -= 12.0 * (d[a] / 12.0).round();
            }
            assert!(d.length() >= 2.0, "bodies {i} and {j} overlap: {d}");
        }
    }
}

/// `[rigid.roller] cutoff`: taken in the flowing nip's scene; one longer
/// than half the shorter period (the minimum image) is refused at the
/// roller's line.
#[test]
fn a_roller_cutoff_past_half_a_period_is_refused_at_its_line() {
    let text = example("toning-nip-flow.toml");
    let with = |rc: &str| text.replace("iterations = 2", &format!("iterations = 2\ncutoff = {rc}"));
    let ok = with("5.9e-5");
    RigidScene::parse(&ok, "nip.toml")
        .unwrap()
        .build(&ok, "nip.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    for bad in ["6.1e-5", "0.0", "-1e-5"] {
        let text = with(bad);
        let e = RigidScene::parse(&text, "nip.toml")
            .unwrap()
            .build(&text, "nip.toml", None)
            .err()
            .unwrap();
        let line = text.lines().position(|l| l == "[rigid.roller]").unwrap() + 1;
        assert_eq!(e.line, line, "{e}");
        assert!(
            e.to_string()
                .contains("cutoff must be > 0 and at most half the shorter period"),
            "{e}"
        );
    }
}
