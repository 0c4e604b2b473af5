//! Particles coming and going (`[[insert]]`, `[[outlet]]`): rates held,
//! no overlap at insertion, exact mass balance, contact histories that
//! follow their particles through a removal, and refusals.

use mote_md::scene::Scene;
use mote_md::{DVec3, Simulation};
use mote_run::Propagator;

/// Grains poured into a closed box at 3000 a second (two sizes), taken
/// out where they reach the left half of the floor; the right half piles
/// up under the stream.
const POUR: &str = r#"
[run]
integrator = "leapfrog"
dt = 2e-5

[field]
g = [0.0, 0.0, -9.81]

[granular]
young = 5e6
poisson = 0.3
restitution = 0.5
friction = 0.5

[[wall]]
kind = "box"
name = "bin"
lo = [0.0, 0.0, 0.0]
hi = [0.03, 0.03, 0.08]

[[insert]]
name = "feed"
lo = [0.001, 0.001, 0.05]
hi = [0.029, 0.029, 0.075]
rate = 3000.0
radius = 0.0008
sizes = "bi:1.5:0.3"
density = 2500.0
velocity = [0.0, 0.0, -0.3]
velocity_spread = 0.05
charge = 1e-12
every = 100

[[outlet]]
name = "drain"
lo = [-1.0, -1.0, -1.0]
hi = [0.012, 1.0, 0.004]
every = 100
"#;

fn build(text: &str, seed: u64) -> Simulation {
    Scene::parse(text, "pour.toml")
        .unwrap()
        .build(text, "pour.toml", seed)
        .unwrap()
        .simulation
}

/// The pairs (i, j) of `sim`'s particles that overlap, and the particles
/// that cut into the bin's walls, among those with ids ≥ `from`.
fn overlaps_of_new(sim: &Simulation, from: u64) -> Vec<(u64, u64)> {
    let s = &sim.system;
    let p = &s.particles;
    let (lo, hi) = (DVec3::ZERO, DVec3::new(0.03, 0.03, 0.08));
    let mut bad = Vec::new();
    for i in (0..p.len()).filter(|&i| s.id[i] >= from) {
        let (x, r) = (p.position[i], p.radius[i]);
        if (x - r).cmplt(lo).any() || (x + r).cmpgt(hi).any() {
            bad.push((s.id[i], u64::MAX));
        }
        for j in 0..p.len() {
            let reach = r + p.radius[j];
            if j != i && p.position[j].distance_squared(x) < reach * reach {
                bad.push((s.id[i], s.id[j]));
            }
        }
    }
    bad
}

#[test]
fn a_stream_holds_its_rate_lands_clear_and_balances_in_out_and_held() {
    let mut sim = build(POUR, 7);
    sim.prime(&mut |_| {}).unwrap();
    let rate = 3000.0;
    let mut next_new = 0;
    let mut events = 0;
    let mut removed_seen = 0;
    for _ in 0..20_000 {
        let before = sim.system.particles.len();
        sim.advance().unwrap();
        let step = sim.system.step;
        if !step.is_multiple_of(100) {
            assert_eq!(
                sim.system.particles.len(),
                before,
                "no event at step {step}"
            );
            continue;
        }
        events += 1;
        // Nothing inserted overlaps a particle or a wall.
        let bad = overlaps_of_new(&sim, next_new);
        assert!(bad.is_empty(), "step {step}: overlaps {bad:?}");
        next_new = sim.system.id.last().map_or(0, |id| id + 1);
        let flow = sim.flow.as_ref().unwrap();
        let (feed, drain) = (&flow.inserters[0].stream, &flow.outlets[0]);
        // The count owed by the time: ⌊ṅ t⌋, exactly.
        assert_eq!(
            feed.inserted,
            (rate * sim.system.time).floor() as u64,
            "t = {}",
            sim.system.time
        );
        // In − out = held, in number and in mass.
        let held = sim.system.particles.len() as u64;
        assert_eq!(feed.inserted - drain.removed, held, "step {step}");
        let mass: f64 = sim.system.particles.mass.iter().sum();
        assert!(
            (feed.mass - drain.mass - mass).abs() <= 1e-12 * feed.mass,
            "step {step}: {} − {} against {mass}",
            feed.mass,
            drain.mass
        );
        // The charge out is the removed particles'.
        let q = drain.removed as f64 * 1e-12;
        assert!(
            (drain.charge - q).abs() <= 1e-12 * q,
            "{} against {q}",
            drain.charge
        );
        // Each departure is a particle that was in the drain's region.
        for d in &flow.departed {
            assert!(d.position.x < 0.012 && d.position.z < 0.004, "{d:?}");
        }
        removed_seen += flow.departed.len() as u64;
        // Ids increase along the particles.
        assert!(sim.system.id.windows(2).all(|w| w[0] < w[1]));
    }
    let flow = sim.flow.as_ref().unwrap();
    assert_eq!(events, 200);
    // The run is long enough to hold the rate to 1 % and to drain.
    let t = sim.system.time;
    let held = flow.inserters[0].stream.inserted as f64 / (rate * t);
    assert!((held - 1.0).abs() < 0.01, "{held}");
    assert_eq!(flow.inserters[0].stream.most_behind, 0);
    assert!(removed_seen > 100, "{removed_seen} removed");
    assert_eq!(removed_seen, flow.outlets[0].removed);
    // Both sizes came.
    let large = (sim.system.particles.radius.iter())
        .filter(|r| **r > 0.001)
        .count();
    let n = sim.system.particles.len();
    assert!(large > n / 10 && large < n / 2, "{large} of {n} large");
}

/// Two spheres leaning on each other on a floor, and a third far off in
/// an outlet: taken out at the first event, it leaves the pair's motion,
/// whose friction carries a shear history, bit for bit as in the scene
/// without it (the history follows the pair's ids through the removal).
/// Stored as the scene gives them, so that the far one is row 0.
#[test]
fn a_removal_leaves_the_other_contacts_and_their_histories_as_they_were() {
    let pair = r#"
[run]
integrator = "leapfrog"
dt = 1e-5

[field]
g = [0.0, 0.0, -9.81]

[granular]
young = 1e6
poisson = 0.3
restitution = 0.5
friction = 0.5
skin = 0.001
order = "file"   # the far one stays particle 0

[[wall]]
kind = "plane"
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[particle]]
position = [0.0, 0.0, 0.002]
radius = 0.002
density = 2500.0

[[particle]]
position = [0.0025, 0.0, 0.0051]
radius = 0.002
density = 2500.0
"#;
    let far = "\n[[particle]]\nposition = [0.5, 0.5, 0.5]\nvelocity = [0.0, 0.0, 9.81e-3]\nradius = 0.002\ndensity = 2500.0\n";
    let outlet = "\n[[outlet]]\nlo = [0.4, 0.4, 0.4]\nevery = 50\n";
    // The far sphere first: the pair are particles 1 and 2.
    let with = format!(
        "{}{far}{}{outlet}",
        &pair[..pair.find("[[particle]]").unwrap()],
        &pair[pair.find("[[particle]]").unwrap()..]
    );
    let mut a = build(&with, 3);
    let mut b = build(pair, 3);
    assert_eq!(a.system.particles.len(), 3);
    a.prime(&mut |_| {}).unwrap();
    b.prime(&mut |_| {}).unwrap();
    for step in 1..=3000 {
        a.advance().unwrap();
        b.advance().unwrap();
        if step == 50 {
            // The pair touches as the far one leaves.
            let p = &b.system.particles;
            assert!(p.position[0].distance(p.position[1]) < 0.004);
        }
        if step >= 50 {
            assert_eq!(a.system.id, [1, 2]);
            assert_eq!(
                a.system.particles.position, b.system.particles.position,
                "step {step}"
            );
            assert_eq!(
                a.system.particles.angular_velocity,
                b.system.particles.angular_velocity
            );
        }
    }
    // The upper sphere slides and rolls off the lower.
    let p = &b.system.particles;
    assert!(
        p.position[1].x - p.position[0].x > 0.0035,
        "{:?}",
        p.position
    );
}

#[test]
fn flows_are_refused_where_they_cannot_run() {
    let base = "[run]\ndt = 1e-4\nintegrator = \"leapfrog\"\n[[particle]]\nposition = [0.0, 0.0, 0.0]\nradius = 0.001\n";
    let cases = [
        ("[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, -1.0]\nrate = 1.0\nradius = 0.1\ndensity = 1.0\n", 7, "lo < hi"),
        ("[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nrate = 1.0\nmass_rate = 2.0\nradius = 0.1\ndensity = 1.0\n", 7, "not both"),
        ("[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nradius = 0.1\ndensity = 1.0\n", 7, "give rate"),
        ("[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nrate = 1.0\nradius = 0.1\ndensity = 1.0\nsizes = \"tri\"\n", 7, "unknown size distribution"),
        ("[[outlet]]\npoint = [0.0, 0.0, 0.0]\n", 7, "give a region"),
        ("[[outlet]]\nhi = [1.0, 1.0, 1.0]\nevery = 10\n[[outlet]]\nlo = [2.0, 2.0, 2.0]\nevery = 20\n", 10, "share one interval"),
        ("[[outlet]]\nhi = [1.0, 1.0, 1.0]\n[gravity]\nG = 1.0\n", 7, "cannot come and go under gravity"),
    ];
    for (extra, line, words) in cases {
        let text = format!("{base}{extra}");
        let scene = Scene::parse(&text, "s.toml").unwrap();
        let e = match scene.build(&text, "s.toml", 1) {
            Err(e) => e,
            Ok(_) => panic!("{extra} must be refused"),
        };
        assert_eq!(e.line, line, "{e}");
        assert!(e.message.contains(words), "{e}");
    }
    // New spheres are kept clear by radii: particles without one refuse.
    let text = format!("{base}[[insert]]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\nrate = 1.0\nradius = 0.1\ndensity = 1.0\n")
        .replace("radius = 0.001\n", "");
    let e = Scene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", 1)
        .err()
        .unwrap();
    assert!(e.message.contains("particles have none"), "{e}");
    // RK4 cannot carry new particles.
    let text = "[run]\ndt = 1e-4\nintegrator = \"rk4\"\n[[particle]]\nposition = [0.0, 0.0, 0.0]\nradius = 0.001\n[[outlet]]\nhi = [1.0, 1.0, 1.0]\n";
    let e = Scene::parse(text, "s.toml")
        .unwrap()
        .build(text, "s.toml", 1)
        .err()
        .unwrap();
    assert!(e.message.contains("leapfrog"), "{e}");
}

/// A lid (a plane wall with `travel`) brings a loose bed of 400 spheres
/// from a solid fraction of 0.2 to 0.55 (a free volume of 45 %), then
/// stops: the bed is held below it, its spheres rearranged rather than
/// crushed, and the lid bears the bed's load.
#[test]
fn a_lid_compresses_a_bed_to_a_set_free_volume_and_stays() {
    let scene = r#"
[run]
integrator = "leapfrog"
dt = 4e-6

[field]
g = [0.0, 0.0, -9.81]

[granular]
young = 5e6
poisson = 0.3
restitution = 0.3
friction = 0.1

[[wall]]
kind = "box"
name = "bin"
lo = [0.0, 0.0, 0.0]
hi = [0.01, 0.01, 0.0105]

[[wall]]
kind = "plane"
name = "lid"
point = [0.0, 0.0, 0.0105]
normal = [0.0, 0.0, -1.0]
velocity = [0.0, 0.0, -0.05]
travel = 0.0066920

[[cloud]]
n = 400
min = [0.0, 0.0, 0.0]
max = [0.01, 0.01, 0.0104]
radius = 0.0005
density = 2500.0
"#;
    let mut sim = build(scene, 2);
    sim.prime(&mut |_| {}).unwrap();
    let v = 4.0 / 3.0 * std::f64::consts::PI * 0.0005f64.powi(3);
    let h = 0.0105 - 0.0066920;
    let solid = 400.0 * v / (1e-4 * h);
    assert!((solid - 0.55).abs() < 1e-4, "{solid}");
    // 0.134 s of travel, then 0.03 s at rest.
    for _ in 0..41_000 {
        sim.advance().unwrap();
    }
    let p = &sim.system.particles;
    let top = (0..p.len())
        .map(|i| p.position[i].z + p.radius[i])
        .fold(0.0, f64::max);
    let deepest = |i: usize| -> f64 {
        let mut d: f64 = 0.0;
        for j in 0..p.len() {
            if j != i {
                d = d.max(p.radius[i] + p.radius[j] - p.position[i].distance(p.position[j]));
            }
        }
        d
    };
    let overlap = (0..p.len()).map(deepest).fold(0.0, f64::max);
    assert!(
        top < h + 0.1 * 0.0005,
        "a sphere above the lid: {top} against {h}"
    );
    assert!(overlap < 0.1 * 0.0005, "overlap {overlap}");
    let obs = mote_md::Observables::measure(&sim.system, &mut sim.forces);
    let lid = obs.wall_forces.iter().find(|w| w.0 == "lid").unwrap().1;
    let weight = 400.0 * 2500.0 * v * 9.81;
    assert!(
        lid.z > 0.1 * weight,
        "the lid bears {} of the weight {weight}",
        lid.z
    );
}

/// A mass rate: by each event the stream has made the fewest spheres
/// whose mass reaches ṁ t (lognormal sizes, so one sphere's mass at most
/// over); a volume fraction alone fills its region to just under it at
/// every event, and no further while nothing leaves.
#[test]
fn a_mass_rate_and_a_fill_to_a_volume_fraction_are_met() {
    let scene = r#"
[run]
integrator = "leapfrog"
dt = 1e-5

[granular]
young = 5e6
poisson = 0.3
restitution = 0.5
friction = 0.5

[box]
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.02]
periodic = [true, true, true]

[[insert]]
name = "stream"
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.01]
mass_rate = 0.002
radius = 0.0005
sizes = "lognormal:0.2"
density = 2500.0
every = 20

[[insert]]
name = "fill"
lo = [0.0, 0.0, 0.012]
hi = [0.02, 0.02, 0.02]
volume_fraction = 0.3
radius = 0.0004
density = 1000.0
attempts = 5000
"#;
    let mut sim = build(scene, 4);
    sim.prime(&mut |_| {}).unwrap();
    let largest = 2500.0 * 4.0 / 3.0
        * std::f64::consts::PI
        * (0.0005f64 * (-3.5f64 * 0.04 + 0.8).exp()).powi(3);
    let fill_volume = 0.02 * 0.02 * 0.008;
    let one = 4.0 / 3.0 * std::f64::consts::PI * 0.0004f64.powi(3);
    let mut filled_count = 0;
    for _ in 0..2000 {
        sim.advance().unwrap();
        if !sim.system.step.is_multiple_of(20) {
            continue;
        }
        let flow = sim.flow.as_ref().unwrap();
        let (stream, fill) = (&flow.inserters[0].stream, &flow.inserters[1].stream);
        let owed = 0.002 * sim.system.time;
        assert!(
            stream.mass >= owed && stream.mass < owed + largest,
            "{} against {owed}",
            stream.mass
        );
        let solid = fill.inserted as f64 * one / fill_volume;
        assert!(solid <= 0.3 && solid > 0.3 - one / fill_volume, "{solid}");
        if filled_count == 0 {
            filled_count = fill.inserted;
        }
        assert_eq!(fill.inserted, filled_count, "the filled region took more");
    }
    let sizes = &sim.system.particles.radius;
    let spread = sizes.iter().filter(|r| **r > 0.00045).count();
    assert!(spread > 10, "lognormal sizes: {spread}");
}

/// Through a face (lo = hi on one axis): every new sphere is centred on
/// it, clear of the others, at the rate; a face has no volume to fill.
#[test]
fn a_stream_through_a_face_lands_on_it() {
    let scene = r#"
[run]
integrator = "leapfrog"
dt = 1e-5

[granular]
young = 5e6
poisson = 0.3
restitution = 0.5
friction = 0.5

[box]
lo = [0.0, 0.0, 0.0]
hi = [0.02, 0.02, 0.02]
periodic = [true, true, true]

[[insert]]
lo = [0.0, 0.0, 0.015]
hi = [0.02, 0.02, 0.015]
rate = 20000.0
radius = 0.0005
density = 2500.0
velocity = [0.0, 0.0, -2.0]
every = 50
"#;
    let mut sim = build(scene, 9);
    sim.prime(&mut |_| {}).unwrap();
    let mut next_new = 0;
    for _ in 0..1000 {
        sim.advance().unwrap();
        if !sim.system.step.is_multiple_of(50) {
            continue;
        }
        let s = &sim.system;
        let new: Vec<usize> = (0..s.id.len()).filter(|&i| s.id[i] >= next_new).collect();
        // ⌊ṅ t⌋ by the (summed, so rounded) time: ten an event, give or
        // take the one a rounding moves.
        let inserted = sim.flow.as_ref().unwrap().inserters[0].stream.inserted;
        assert_eq!(inserted, (20000.0 * s.time).floor() as u64);
        assert!(
            (9..=11).contains(&new.len()),
            "step {}: {}",
            s.step,
            new.len()
        );
        for &i in &new {
            assert_eq!(s.particles.position[i].z, 0.015);
        }
        next_new = s.id.last().map_or(0, |id| id + 1);
        let p = &s.particles;
        for &i in &new {
            for j in 0..p.len() {
                let d = s
                    .boundary
                    .minimum_image(p.position[i] - p.position[j])
                    .length();
                assert!(j == i || d >= 0.001, "{i} and {j} at {d}");
            }
        }
    }
    let text = scene.replace("every = 50\n", "every = 50\nvolume_fraction = 0.2\n");
    let e = Scene::parse(&text, "s.toml")
        .unwrap()
        .build(&text, "s.toml", 1)
        .err()
        .unwrap();
    assert!(e.message.contains("no volume to fill"), "{e}");
}

/// The forces a run gives after particles came and went are those a
/// force field built afresh gives the same particles, bit for bit, for
/// every interaction that lets particles come and go without carrying a
/// history (Lennard-Jones, uniform and electric fields, damping): nothing
/// stale of the particles that left, nothing missing of those that came.
#[test]
fn after_particles_come_and_go_the_forces_are_a_fresh_force_fields() {
    let scene = r#"
units = "lj"
[run]
integrator = "leapfrog"
dt = 0.004

[lennard_jones]
cutoff = 2.5
skin = 0.3

[field]
g = [0.0, 0.0, -0.1]

[electric_field]
e = [0.05, 0.0, 0.0]

[damping]
gamma = 0.01

[[fcc]]
cells = [5, 5, 5]
density = 0.3
kt = 1.0
charge = 0.5
radius = 0.5

[[insert]]
lo = [0.0, 0.0, 0.0]
hi = [11.0, 11.0, 2.0]
rate = 400.0
radius = 0.5
density = 1.9
charge = -0.5
attempts = 1000
every = 25

[[outlet]]
lo = [-1.0, -1.0, 4.0]
hi = [100.0, 100.0, 5.0]
every = 25
"#;
    let mut sim = build(scene, 5);
    sim.prime(&mut |_| {}).unwrap();
    for _ in 0..400 {
        sim.advance().unwrap();
    }
    let flow = sim.flow.as_ref().unwrap();
    let (came, went) = (flow.inserters[0].stream.inserted, flow.outlets[0].removed);
    assert!(came > 20 && went > 20, "{came} came, {went} went");
    assert!(s_finite(&sim));
    let mut fresh = build(scene, 5).forces;
    let s = &sim.system;
    let p = &s.particles;
    let state = mote_md::State::of(s, &p.position, &p.velocity, s.time, 0.0);
    let (mut ours, mut theirs) = (vec![DVec3::ZERO; p.len()], vec![DVec3::ZERO; p.len()]);
    sim.forces.accelerations(&state, &p.mobility, &mut ours);
    fresh.accelerations(&state, &p.mobility, &mut theirs);
    assert_eq!(ours, theirs);
}

fn s_finite(sim: &Simulation) -> bool {
    let p = &sim.system.particles;
    p.position.iter().chain(&p.velocity).all(|v| v.is_finite())
}

/// Stored in space order, a particle that leaves is named in outflow.csv
/// by the scene's number: the scene's first particle, far off in an
/// outlet, is stored last and leaves as particle 0; the event lists the
/// particles that leave by those numbers, not as they are stored.
#[test]
fn a_departure_in_space_order_is_named_by_the_scenes_number() {
    use mote_md::output::Departures;
    use mote_run::Propagator;
    let scene = "[run]\nintegrator = \"leapfrog\"\ndt = 1e-5\n\
        [granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\n\
        [[particle]]\nposition = [0.5, 0.5, 0.5]\nradius = 0.002\ndensity = 2500.0\n\
        [[particle]]\nposition = [0.0, 0.0, 0.002]\nradius = 0.002\ndensity = 2500.0\n\
        [[particle]]\nposition = [0.01, 0.0, 0.002]\nradius = 0.002\ndensity = 2500.0\n\
        [[particle]]\nposition = [0.45, 0.45, 0.45]\nradius = 0.002\ndensity = 2500.0\n\
        [[outlet]]\nlo = [0.4, 0.4, 0.4]\nevery = 50\n";
    let mut sim = build(scene, 1);
    let numbers: Vec<u64> = (0..4).map(|i| sim.system.number_of(i)).collect();
    assert_eq!(
        numbers,
        [1, 2, 3, 0],
        "the far ones are stored last, 3 first"
    );
    sim.prime(&mut |_| {}).unwrap();
    for _ in 0..50 {
        sim.advance().unwrap();
    }
    let gone: Vec<u64> = sim.departed().iter().map(|d| d.id).collect();
    assert_eq!(gone, [0, 3]);
    assert_eq!(sim.system.particles.len(), 2);
    let frame = mote_md::output::frame_of(&sim.system);
    assert_eq!(frame.ids, [2, 3]);
    assert_eq!(frame.positions[0][0], 0.0);
}
