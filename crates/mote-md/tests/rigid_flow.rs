//! Rigid clumps coming and going (`[[insert]] clump = ...`, `[[outlet]]`
//! in a rigid scene): rates held, no sphere of a new clump touching
//! another body or a wall, exact mass balance, random orientations,
//! contact histories that follow their bodies through a removal, and a
//! resumed run that is the uninterrupted one bit for bit.

use mote_geom::rotation_matrix;
use mote_io::checkpoint::Checkpoint;
use mote_md::rigid::run::RigidDynamics;
use mote_md::rigid::scene::RigidScene;
use mote_md::DVec3;
use mote_run::Propagator;

/// Trimers and balls poured into a closed box at 400 and 200 a second,
/// taken out where their centres reach the left half of the floor.
const POUR: &str = r#"
seed = 5

[rigid]

[[rigid.template]]
name = "trimer"
generator = "trimer"
distance = 1.2e-3
radius = 1.0e-3
density = 2500.0
charge = 1e-12

[[rigid.template]]
name = "ball"
generator = "sphere"
radius = 1.2e-3
density = 2500.0

[rigid.fields]
gravity = [0.0, 0.0, -9.81]

[rigid.contacts]
young = 1.0e7
poisson = 0.3
restitution = 0.3
friction = 0.5

[[rigid.wall]]
kind = "box"
name = "bin"
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.06]

[[insert]]
name = "trimers"
clump = "trimer"
lo = [0.002, 0.002, 0.035]
hi = [0.018, 0.018, 0.055]
rate = 400.0
velocity = [0.0, 0.0, -0.2]
velocity_spread = 0.02
every = 200

[[insert]]
name = "balls"
clump = "ball"
lo = [0.002, 0.002, 0.035]
hi = [0.018, 0.018, 0.055]
rate = 200.0

[[outlet]]
name = "drain"
lo = [-1.0, -1.0, -1.0]
hi = [0.008, 1.0, 0.004]

[run]
dt = 5.0e-6
until = 0.2
"#;

fn build(text: &str) -> RigidDynamics {
    let scene = RigidScene::parse(text, "pour.toml").unwrap();
    RigidDynamics::new(scene.build(text, "pour.toml", None).unwrap())
}

/// Every sphere of `d` as (body id, centre, radius).
fn spheres(d: &RigidDynamics) -> Vec<(u64, DVec3, f64)> {
    let b = &d.bodies;
    let mut out = Vec::new();
    for i in 0..b.len() {
        let t = b.template(i);
        let m = rotation_matrix(b.rotation[i]);
        for (c, r) in t.centres.iter().zip(&t.radii) {
            out.push((b.id_of(i), b.position[i] + m * *c, *r));
        }
    }
    out
}

/// The spheres of bodies with ids ≥ `from` that overlap a sphere of
/// another body or cut into the bin.
fn overlaps_of_new(d: &RigidDynamics, from: u64) -> Vec<(u64, u64)> {
    let all = spheres(d);
    let (lo, hi) = (DVec3::ZERO, DVec3::new(0.02, 0.02, 0.06));
    let mut bad = Vec::new();
    for &(id, x, r) in all.iter().filter(|s| s.0 >= from) {
        if (x - r).cmplt(lo).any() || (x + r).cmpgt(hi).any() {
            bad.push((id, u64::MAX));
        }
        for &(other, y, s) in &all {
            if other != id && x.distance(y) < r + s {
                bad.push((id, other));
            }
        }
    }
    bad
}

/// Number rates held exactly at every event, no new clump touching
/// anything, in − out = held in number and mass, ids increasing.
#[test]
fn clumps_come_at_their_rates_clear_of_everything_and_balance() {
    let mut d = build(POUR);
    assert_eq!(d.bodies.len(), 0, "the scene places no bodies");
    let mut next = 0;
    let mut orientations = Vec::new();
    while d.step < d.last_step {
        d.advance().unwrap();
        if !d.step.is_multiple_of(200) {
            continue;
        }
        let t = d.bodies.time;
        let flow = d.flow.as_ref().unwrap();
        let (trimers, balls) = (&flow.inserters[0].stream, &flow.inserters[1].stream);
        assert_eq!(trimers.inserted, (400.0 * t).floor() as u64, "t = {t}");
        assert_eq!(balls.inserted, (200.0 * t).floor() as u64, "t = {t}");
        assert_eq!(overlaps_of_new(&d, next), vec![], "step {}", d.step);
        let drain = &flow.outlets[0];
        let held = d.bodies.len() as u64;
        assert_eq!(trimers.inserted + balls.inserted - drain.removed, held);
        let mass: f64 = (0..d.bodies.len())
            .map(|i| d.bodies.template(i).mass())
            .sum();
        let m_in = trimers.mass + balls.mass;
        assert!((m_in - drain.mass - mass).abs() <= 1e-12 * m_in);
        assert!(d.bodies.id.windows(2).all(|w| w[0] < w[1]));
        for i in 0..d.bodies.len() {
            if d.bodies.id[i] >= next && d.bodies.kind[i] == flow.inserters[0].kind {
                orientations.push(rotation_matrix(d.bodies.rotation[i]) * DVec3::X);
            }
        }
        next = d.bodies.id.last().map_or(next, |id| id + 1);
    }
    let flow = d.flow.as_ref().unwrap();
    assert_eq!(flow.inserters[0].stream.inserted, 80);
    assert!(flow.outlets[0].removed > 0, "nothing reached the drain");
    assert!((flow.outlets[0].charge - 1e-12 * count_trimers_out(&d)).abs() < 1e-24);
    // The trimers' axes, uniform on the sphere: each component's mean
    // within four standard errors of 0, its square's of 1/3.
    let n = orientations.len() as f64;
    assert_eq!(n, 80.0);
    for a in 0..3 {
        let mean = orientations.iter().map(|u| u[a]).sum::<f64>() / n;
        let square = orientations.iter().map(|u| u[a] * u[a]).sum::<f64>() / n;
        assert!(
            mean.abs() < 4.0 * (1.0 / 3.0 / n).sqrt(),
            "axis {a}: {mean}"
        );
        assert!(
            (square - 1.0 / 3.0).abs() < 4.0 * (4.0 / 45.0 / n).sqrt(),
            "{square}"
        );
    }
}

/// The trimers the drain took (the balls carry no charge).
fn count_trimers_out(d: &RigidDynamics) -> f64 {
    let flow = d.flow.as_ref().unwrap();
    let trimer = flow.inserters[0].kind;
    let held = (0..d.bodies.len())
        .filter(|&i| d.bodies.kind[i] == trimer)
        .count();
    (flow.inserters[0].stream.inserted - held as u64) as f64
}

/// Two clumps sliding on the floor and on each other (histories with the
/// wall and between them), and a third far off that an outlet takes out
/// at the first event: the two move after it exactly as in the scene
/// without the third, their histories carried under their new numbers.
#[test]
fn histories_follow_their_bodies_through_a_removal() {
    let pair = r#"
[rigid]

[[rigid.template]]
name = "trimer"
generator = "trimer"
distance = 1.2e-3
radius = 1.0e-3
density = 2500.0

[rigid.fields]
gravity = [0.0, 0.0, -9.81]

[rigid.contacts]
young = 1.0e7
poisson = 0.3
restitution = 0.3
friction = 0.5

[[rigid.wall]]
kind = "plane"
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#;
    let bodies = r#"
[[rigid.body]]
template = "trimer"
position = [0.0, 0.0, 0.000999]
velocity = [0.05, 0.0, 0.0]

[[rigid.body]]
template = "trimer"
position = [0.0, 0.0, 0.002997]
velocity = [-0.05, 0.02, 0.0]
"#;
    let far = r#"
[[rigid.body]]
template = "trimer"
position = [0.5, 0.0, 0.000999]
"#;
    let tail = "\n[run]\ndt = 5.0e-6\nsteps = 600\n";
    let outlet = "\n[[outlet]]\nlo = [0.4, -1.0, -1.0]\nevery = 100\n";
    let with_far = format!("{pair}{far}{bodies}{outlet}{tail}");
    let without = format!("{pair}{bodies}{tail}");
    let mut a = build(&with_far);
    let mut b = build(&without);
    assert_eq!(a.bodies.len(), 3);
    for _ in 0..100 {
        a.advance().unwrap();
        b.advance().unwrap();
    }
    assert_eq!(a.bodies.len(), 2, "the far one left");
    let (contacts, walls) = b.contacts().unwrap().contact_counts();
    assert!(contacts > 0 && walls > 0, "{contacts} {walls}");
    for _ in 0..500 {
        a.advance().unwrap();
        b.advance().unwrap();
    }
    for i in 0..2 {
        assert_eq!(a.bodies.position[i], b.bodies.position[i], "body {i}");
        assert_eq!(a.bodies.omega[i], b.bodies.omega[i], "body {i}");
    }
}

/// A run stopped at a checkpoint and resumed from it, bodies having come
/// and gone before and after, ends where the uninterrupted run does, bit
/// for bit.
#[test]
fn a_resumed_pour_is_the_uninterrupted_one() {
    let short = POUR.replace("until = 0.2", "until = 0.15");
    let mut whole = build(&short);
    let mut first = build(&short);
    let mut cp = Checkpoint::default();
    while first.step < 16000 {
        first.advance().unwrap();
    }
    first.save(&mut cp).unwrap();
    drop(first);
    let mut resumed = build(&short);
    resumed.resume(&cp, "pour.toml").unwrap();
    while whole.step < whole.last_step {
        whole.advance().unwrap();
    }
    while resumed.step < whole.last_step {
        resumed.advance().unwrap();
    }
    let flow = whole.flow.as_ref().unwrap();
    assert!(flow.outlets[0].removed > 0, "nothing left before the end");
    assert_eq!(resumed.bodies.id, whole.bodies.id);
    assert_eq!(resumed.bodies.position, whole.bodies.position);
    assert_eq!(resumed.bodies.rotation, whole.bodies.rotation);
    assert_eq!(resumed.bodies.omega, whole.bodies.omega);
    assert_eq!(
        resumed.flow.as_ref().unwrap().columns(),
        flow.columns(),
        "the counts"
    );
}

/// A rigid stream names its template and takes nothing the template
/// says; a point-particle scene has no templates to name.
#[test]
fn streams_of_clumps_are_refused_at_their_line_when_misspelled() {
    let refused = |text: &str| match RigidScene::parse(text, "r.toml") {
        Ok(scene) => scene.build(text, "r.toml", None).err().unwrap().to_string(),
        Err(e) => e.to_string(),
    };
    let e = refused(&POUR.replace("clump = \"ball\"", "clump = \"ball\"\nradius = 1e-3"));
    assert!(
        e.starts_with("r.toml:45: [[insert]] balls: radius: a clump's size"),
        "{e}"
    );
    let e = refused(&POUR.replace("clump = \"ball\"\n", ""));
    assert!(
        e.contains("[[insert]] balls: give the template the stream makes"),
        "{e}"
    );
    let e = refused(&POUR.replace("clump = \"ball\"", "clump = \"bead\""));
    assert!(e.contains("unknown template 'bead'"), "{e}");
    let points = "[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nrate = 1.0\nclump = \"ball\"\n[run]\ndt = 0.1\nsteps = 1\n";
    let e = mote_md::scene::Scene::parse(points, "p.toml")
        .unwrap()
        .build(points, "p.toml", 1)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.starts_with("p.toml:1: [[insert]] insert0: clump names a rigid template"),
        "{e}"
    );
}

/// In a periodic box, after the first body left, a frame names each
/// sphere's body by its id and moves every body whole into the box.
#[test]
fn frames_of_a_periodic_run_name_the_bodies_by_id() {
    let text = r#"
[rigid]

[[rigid.template]]
name = "trimer"
generator = "trimer"
distance = 1.2e-3
radius = 1.0e-3
density = 2500.0

[rigid.contacts]
young = 1.0e7
poisson = 0.3
restitution = 0.3
friction = 0.5

[box]
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.02]
periodic = [true, true, true]

[[rigid.body]]
template = "trimer"
position = [0.001, 0.01, 0.01]

[[rigid.body]]
template = "trimer"
position = [0.019, 0.01, 0.005]
velocity = [10.0, 0.0, 0.0]

[[outlet]]
lo = [-1.0, -1.0, 0.008]
hi = [0.002, 1.0, 1.0]
every = 10

[run]
dt = 1.0e-5
steps = 20
"#;
    let mut d = build(text);
    for _ in 0..20 {
        d.advance().unwrap();
    }
    assert_eq!(d.bodies.id, vec![1], "the first left, the second stayed");
    assert!(
        d.bodies.position[0].x > 0.02,
        "it crossed the periodic face"
    );
    let frame = d.sphere_frame();
    assert_eq!(frame.bodies, vec![1, 1, 1]);
    let centre = frame.positions.iter().map(|p| p[0]).sum::<f64>() / 3.0;
    assert!((0.0..0.02).contains(&centre), "{centre}");
}
