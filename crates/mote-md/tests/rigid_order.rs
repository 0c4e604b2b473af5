//! Rigid bodies stored in space order (`[rigid] order`, default `space`):
//! the scene's numbering kept for frames, the viewer's forces, bodies
//! taken out, and checkpoints that name the order they store.

use mote_io::checkpoint::Checkpoint;
use mote_md::rigid::run::RigidDynamics;
use mote_md::rigid::scene::RigidScene;
use mote_run::Propagator;

/// Trimers dropped at random into a box, the left half of its floor an
/// outlet.
fn scene(order: &str, seed: u64) -> String {
    format!(
        r#"
seed = {seed}
[rigid]
order = "{order}"

[[rigid.template]]
name = "trimer"
generator = "trimer"
distance = 1.2e-3
radius = 1.0e-3
density = 2500.0

[[rigid.random]]
template = "trimer"
n = 60
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.02]

[rigid.fields]
gravity = [0.0, 0.0, -9.81]

[rigid.contacts]
young = 1.0e7
poisson = 0.3
restitution = 0.3
friction = 0.5

[[rigid.wall]]
kind = "box"
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.02]

[[outlet]]
lo = [-1.0, -1.0, -1.0]
hi = [0.01, 1.0, 0.003]
every = 50

[run]
dt = 5.0e-6
steps = 4000
"#
    )
}

fn build(order: &str, seed: u64) -> RigidDynamics {
    let text = scene(order, seed);
    let scene = RigidScene::parse(&text, "drop.toml").unwrap_or_else(|e| panic!("{e}"));
    RigidDynamics::new(scene.build(&text, "drop.toml", None).unwrap())
}

/// Stored apart, the two orders write the same frame to the bit; after
/// 4000 steps of falling, colliding trimers and bodies leaving through the
/// outlet they differ only by the order of their sums (round-off), take
/// out the same bodies by the same numbers, and the viewer's forces come
/// in the frame's order.
#[test]
fn space_order_keeps_the_scenes_numbering() {
    let (mut space, mut file) = (build("space", 3), build("file", 3));
    let n = space.bodies.len();
    let mut numbers: Vec<u64> = (0..n).map(|i| space.bodies.number_of(i)).collect();
    assert_ne!(
        numbers,
        (0..n as u64).collect::<Vec<_>>(),
        "stored as given"
    );
    numbers.sort_unstable();
    assert_eq!(numbers, (0..n as u64).collect::<Vec<_>>());
    assert!(file.bodies.number.is_empty());
    assert_eq!(space.sphere_frame(), file.sphere_frame());

    let (mut left_space, mut left_file) = (Vec::new(), Vec::new());
    while space.step < space.last_step {
        space.advance().unwrap();
        file.advance().unwrap();
        for (d, left) in [(&space, &mut left_space), (&file, &mut left_file)] {
            left.extend(d.flow.as_ref().unwrap().departed.iter().map(|b| b.id));
        }
    }
    // Each event's bodies in the scene's numbering, in either order.
    assert!(left_file.len() > 1, "{} bodies left", left_file.len());
    assert_eq!(left_space, left_file, "the same bodies left, listed alike");

    let (a, b) = (space.sphere_frame(), file.sphere_frame());
    assert_eq!(a.bodies, b.bodies);
    let worst = (a.positions.iter().zip(&b.positions))
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f64::max);
    // The trimers fall some 2 mm in 0.02 s, those at the bottom onto the
    // floor and each other: a body mistaken for another would be
    // millimetres off. Round-off grows through the collisions (1.2e-12 m
    // here, seed 3), far below a micrometre.
    assert!(worst < 1e-9, "the orders part by {worst} m");
    let (fa, fb) = (space.forces(), file.forces());
    assert_eq!(fa.len(), a.positions.len());
    let scale = fb.iter().map(|f| f[2].abs()).fold(0.0, f64::max);
    for (p, q) in fa.iter().zip(&fb) {
        assert!(
            (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-9 * scale),
            "{p:?} against {q:?}"
        );
    }
}

/// A checkpoint names the order its bodies are stored in, and a build that
/// stores them in another refuses it, never reading one body's state into
/// another; a checkpoint of a mote that kept the scene's order resumes in
/// that order, as the front readies the scene for it.
#[test]
fn a_checkpoint_in_another_order_is_refused() {
    let saved = |mut d: RigidDynamics| {
        let mut cp = Checkpoint::default();
        d.save(&mut cp).unwrap();
        cp
    };
    let (space, file) = (saved(build("space", 3)), saved(build("file", 3)));
    assert!(build("space", 3).resume(&space, "drop.toml").is_ok());
    assert!(build("file", 3).resume(&file, "drop.toml").is_ok());
    let refused = |order: &str, seed: u64, cp: &Checkpoint| {
        build(order, seed)
            .resume(cp, "drop.toml")
            .unwrap_err()
            .to_string()
    };
    let e = refused("space", 3, &file);
    assert!(
        e.starts_with("drop.toml: checkpoint: the checkpoint stores the bodies in the scene's order, and this build in space order"),
        "{e}"
    );
    let e = refused("file", 3, &space);
    assert!(
        e.contains("in space order, and this build in the scene's"),
        "{e}"
    );
    // Other bodies, another order.
    let e = refused("space", 4, &space);
    assert!(e.contains("another space order"), "{e}");

    let text = scene("space", 3);
    let resumed = |cp: &Checkpoint| {
        let mut scene = RigidScene::parse(&text, "drop.toml").unwrap();
        scene.keep_order_of(cp);
        let mut d = RigidDynamics::new(scene.build(&text, "drop.toml", None).unwrap());
        d.resume(cp, "drop.toml").map(|_| d)
    };
    let d = resumed(&file).unwrap();
    assert!(d.bodies.number.is_empty(), "resumed in the scene's order");
    let d = resumed(&space).unwrap();
    assert!(!d.bodies.number.is_empty());
}

/// `[rigid] order` takes `space` or `file`, and says so at its line.
#[test]
fn an_unknown_order_is_refused_at_its_line() {
    let text = scene("morton", 3);
    let e = RigidScene::parse(&text, "drop.toml").err().unwrap();
    assert_eq!(e.line, 4, "{e}");
    assert!(e.to_string().contains("expected `space` or `file`"), "{e}");
}
