//! Granular contacts checked against analytic results: restitution of a
//! head-on Hertz impact, the sliding oblique impact, rolling resistance,
//! the weight of a settled bed on its walls, conservation of momentum, and
//! neighbour lists against brute force.

use mote_md::force::granular::{
    ContactLaw, Damping, GranularContacts, GranularWalls, Material, Wall,
};
use mote_md::force::{ForceField, UniformField};
use mote_md::neighbor::VerletList;
use mote_md::particles::ParticleInit;
use mote_md::{Boundary, DVec3, Integrator, Observables, Particles, Stepper, System};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const RHO: f64 = 2500.0;

fn sphere(position: DVec3, velocity: DVec3, radius: f64) -> ParticleInit {
    ParticleInit {
        position,
        velocity,
        mass: RHO * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
        radius,
        ..Default::default()
    }
}

fn glass() -> Material {
    Material {
        young: 1e7,
        poisson: 0.3,
    }
}

/// Runs until `done` or `max_steps`.
fn run(
    sys: &mut System,
    ff: &mut ForceField,
    dt: f64,
    max_steps: usize,
    mut done: impl FnMut(&System) -> bool,
) {
    let mut stepper = Stepper::new(Integrator::LeapFrog);
    for _ in 0..max_steps {
        stepper.step(sys, ff, dt);
        if done(sys) {
            return;
        }
    }
    panic!("did not finish in {max_steps} steps");
}

/// Hertz contact time t_c ≈ 2.87 (m*²/(R* E*² v))^{1/5}.
fn contact_time(m_eff: f64, r_eff: f64, e_star: f64, v: f64) -> f64 {
    2.87 * (m_eff * m_eff / (r_eff * e_star * e_star * v)).powf(0.2)
}

/// Leap-frog evaluates the damping at the half-step velocity, an O(dt)
/// error in e; 1000 steps per contact keep it below 0.3 % at e = 0.1.
const STEPS_PER_CONTACT: f64 = 1000.0;

/// The largest radius (the contact list's reach is twice it).
fn r_max(radius: &[f64]) -> f64 {
    radius.iter().cloned().fold(0.0, f64::max)
}

#[test]
fn head_on_impact_gives_back_the_restitution() {
    let r = 1e-3;
    let v = 0.5;
    for limit_damping in [false, true] {
        for e in [0.1, 0.3, 0.5, 0.7, 0.9] {
            let law = ContactLaw::new(glass(), glass(), e, 0.5, Damping::Exact, limit_damping);
            let mut p = Particles::default();
            p.push(sphere(
                DVec3::new(-1.01 * r, 0.0, 0.0),
                DVec3::new(v, 0.0, 0.0),
                r,
            ));
            p.push(sphere(
                DVec3::new(1.01 * r, 0.0, 0.0),
                DVec3::new(-v, 0.0, 0.0),
                r,
            ));
            let m = p.mass[0];
            let tc = contact_time(m / 2.0, r / 2.0, law.e_star, 2.0 * v);
            let mut ff =
                ForceField::new().with(GranularContacts::new(law, r_max(&p.radius), 0.2 * r));
            let mut sys = System::new(p);
            let dt = tc / STEPS_PER_CONTACT;
            run(&mut sys, &mut ff, dt, 100_000, |s| {
                let gap = s.particles.position[1].x - s.particles.position[0].x;
                gap > 2.02 * r
            });
            let u = sys.particles.velocity[1].x - sys.particles.velocity[0].x;
            let measured = u / (2.0 * v);
            assert!(
                (measured - e).abs() < 0.01 * e,
                "e {e} (limit_damping {limit_damping}): measured {measured}"
            );
        }
    }
}

#[test]
fn sliding_oblique_impact_matches_the_rigid_body_result() {
    // Sliding throughout the impact when v_t > (7/2) μ (1 + e) v_n: the
    // tangential impulse is μ times the normal one, m(1 + e) v_n, so
    // v_t' = v_t − μ(1 + e)v_n and R ω' = (5/2) μ (1 + e) v_n.
    let r = 1e-3;
    let (vn, vt, mu, e) = (0.5, 2.0, 0.3, 0.5);
    // A stiff material keeps the overlap, and so the change of lever arm
    // R − δ/2 the torque acts through, below 0.3 %.
    let stiff = Material {
        young: 1e9,
        poisson: 0.3,
    };
    let law = ContactLaw::new(stiff, stiff, e, mu, Damping::Exact, true);
    let mut p = Particles::default();
    p.push(sphere(
        DVec3::new(0.0, 0.0, 1.01 * r),
        DVec3::new(vt, 0.0, -vn),
        r,
    ));
    let m = p.mass[0];
    let walls = GranularWalls::new(
        law,
        vec![Wall::plane("floor", DVec3::ZERO, DVec3::Z)],
        p.len(),
    );
    let mut ff = ForceField::new().with(walls);
    let mut sys = System::new(p);
    let dt = contact_time(m, r, law.e_star, vn) / 400.0;
    run(&mut sys, &mut ff, dt, 100_000, |s| {
        s.particles.position[0].z > 1.02 * r
    });
    let v = sys.particles.velocity[0];
    let w = sys.particles.angular_velocity[0];
    let expect_vt = vt - mu * (1.0 + e) * vn;
    let expect_spin = 2.5 * mu * (1.0 + e) * vn / r;
    assert!(
        (v.z / vn - e).abs() < 0.01 * e,
        "normal restitution {}",
        v.z / vn
    );
    assert!(
        (v.x - expect_vt).abs() < 0.01 * expect_vt,
        "v_t' {} expected {expect_vt}",
        v.x
    );
    // Rolling in +x on a floor below spins about +y.
    assert!(
        (w.y - expect_spin).abs() < 0.01 * expect_spin,
        "ω' {} expected {expect_spin}",
        w.y
    );
    // Tangential restitution of the contact point, −(v_t' − Rω')/v_t.
    let et = (v.x - r * w.y) / vt;
    let expect_et = 1.0 - 3.5 * mu * (1.0 + e) * vn / vt;
    assert!(
        (et - expect_et).abs() < 0.01,
        "e_t {et} expected {expect_et}"
    );
}

#[test]
fn rolling_resistance_decelerates_at_five_sevenths_mu_r_g() {
    let r: f64 = 5e-3;
    let g = 9.81;
    let mu_r = 0.05;
    let mut law = ContactLaw::new(glass(), glass(), 0.5, 0.5, Damping::Exact, false);
    law.rolling_friction = mu_r;
    let mut p = Particles::default();
    let m = RHO * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    // Start at the static overlap δ₀ = (m g / ((4/3) E* √R))^{2/3}.
    let delta0 = (m * g / (4.0 / 3.0 * law.e_star * r.sqrt())).powf(2.0 / 3.0);
    let v0 = 0.2;
    let mut s = sphere(
        DVec3::new(0.0, 0.0, r - delta0),
        DVec3::new(v0, 0.0, 0.0),
        r,
    );
    s.angular_velocity = DVec3::new(0.0, v0 / r, 0.0);
    p.push(s);
    let walls = GranularWalls::new(
        law,
        vec![Wall::plane("floor", DVec3::ZERO, DVec3::Z)],
        p.len(),
    );
    let mut ff = ForceField::new().with(walls).with(UniformField {
        g: DVec3::new(0.0, 0.0, -g),
    });
    let mut sys = System::new(p);
    let dt = 1e-5;
    let mut stepper = Stepper::new(Integrator::LeapFrog);
    // Let the rolling spring load up, then fit v(t) over 0.1 s.
    for _ in 0..5_000 {
        stepper.step(&mut sys, &mut ff, dt);
    }
    let (t1, v1) = (sys.time, sys.particles.velocity[0].x);
    for _ in 0..10_000 {
        stepper.step(&mut sys, &mut ff, dt);
    }
    let (t2, v2) = (sys.time, sys.particles.velocity[0].x);
    let decel = -(v2 - v1) / (t2 - t1);
    let expect = 5.0 / 7.0 * mu_r * g;
    assert!(
        (decel - expect).abs() < 0.02 * expect,
        "deceleration {decel} expected {expect}"
    );
}

/// A few hundred spheres dropped into a box settle; the walls then carry
/// their weight.
#[test]
fn settled_bed_weighs_on_its_walls() {
    let r = 2e-3;
    let (lx, ly, lz) = (0.03, 0.03, 0.06);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut p = Particles::default();
    // A loose simple-cubic stack with jitter, so nothing overlaps at the start.
    let a = 2.4 * r;
    let mut z = r * 1.2;
    while z < lz - r && p.len() < 400 {
        let mut y = r * 1.2;
        while y < ly - r {
            let mut x = r * 1.2;
            while x < lx - r {
                let jitter = DVec3::new(rng.gen(), rng.gen(), 0.0) * 0.1 * r;
                p.push(sphere(DVec3::new(x, y, z) + jitter, DVec3::ZERO, r));
                x += a;
            }
            y += a;
        }
        z += a;
    }
    let n = p.len();
    let m = p.mass[0];
    let g = 9.81;
    let mat = Material {
        young: 1e6,
        poisson: 0.3,
    };
    let law = ContactLaw::new(mat, mat, 0.3, 0.5, Damping::Exact, false);
    let walls = GranularWalls::new(
        law,
        Wall::closed_box("box", DVec3::ZERO, DVec3::new(lx, ly, lz)),
        p.len(),
    );
    let contacts = GranularContacts::new(law, r_max(&p.radius), 0.2 * r);
    let mut ff = ForceField::new()
        .with(contacts)
        .with(walls)
        .with(UniformField {
            g: DVec3::new(0.0, 0.0, -g),
        });
    let mut sys = System::new(p);
    let dt = 5e-5;
    let mut stepper = Stepper::new(Integrator::LeapFrog);
    for _ in 0..12_000 {
        stepper.step(&mut sys, &mut ff, dt);
    }
    // Average the vertical wall force over a further window.
    let mut fz = 0.0;
    let window = 2_000;
    for _ in 0..window {
        stepper.step(&mut sys, &mut ff, dt);
        fz += ff_wall_force_z(&ff);
    }
    fz /= window as f64;
    let weight = n as f64 * m * g;
    let obs = Observables::measure(&sys, &mut ff);
    assert!(
        obs.kinetic < 1e-6 * weight * lz,
        "bed not at rest: K = {}",
        obs.kinetic
    );
    assert!(
        ((fz - weight) / weight).abs() < 1e-3,
        "walls carry {fz} N, weight {weight} N ({n} spheres)"
    );
}

fn ff_wall_force_z(ff: &ForceField) -> f64 {
    ff.interactions
        .iter()
        .filter_map(|i| i.viewer())
        .flat_map(|v| v.wall_forces())
        .map(|(_, f)| -f.z)
        .sum::<f64>()
}

#[test]
fn colliding_cloud_conserves_momentum_and_angular_momentum() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut p = Particles::default();
    for _ in 0..200 {
        let r = 1e-3 * (0.7 + 0.6 * rng.gen::<f64>());
        let x = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.03;
        let v = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5;
        let mut s = sphere(x, v, r);
        s.angular_velocity = (DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5) * 100.0;
        p.push(s);
    }
    let law = ContactLaw::new(glass(), glass(), 0.5, 0.4, Damping::Exact, false);
    let mut ff = ForceField::new().with(GranularContacts::new(law, r_max(&p.radius), 2e-4));
    let mut sys = System::new(p);
    let before = Observables::measure(&sys, &mut ff);
    let mut stepper = Stepper::new(Integrator::LeapFrog);
    for _ in 0..3000 {
        stepper.step(&mut sys, &mut ff, 2e-6);
    }
    let after = Observables::measure(&sys, &mut ff);
    let p_scale = sys
        .particles
        .velocity
        .iter()
        .zip(&sys.particles.mass)
        .map(|(v, m)| v.length() * m)
        .sum::<f64>();
    assert!((after.momentum - before.momentum).length() < 1e-13 * p_scale);
    let l_scale = p_scale * 0.03;
    assert!(
        (after.angular_momentum - before.angular_momentum).length() < 1e-12 * l_scale,
        "ΔL = {}",
        (after.angular_momentum - before.angular_momentum).length() / l_scale
    );
    assert!(
        after.total_energy() < before.total_energy(),
        "collisions must dissipate"
    );
}

/// Every touching pair is in the list, for polydisperse spheres in periodic
/// and open boxes, while the particles move and the list is rebuilt.
#[test]
fn neighbour_list_never_misses_a_contact() {
    for periodic in [true, false] {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let l = 1.0;
        let n = 600;
        let radius: Vec<f64> = (0..n).map(|_| 0.01 + 0.04 * rng.gen::<f64>()).collect();
        let mut pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * l)
            .collect();
        let boundary = if periodic {
            Boundary::periodic(DVec3::ZERO, DVec3::splat(l))
        } else {
            Boundary::open()
        };
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let skin = 0.02;
        let mut list = VerletList::half(2.0 * r_max, skin);
        for step in 0..50 {
            list.update(&pos, &boundary);
            let image = boundary.image();
            for i in 0..n {
                for j in i + 1..n {
                    let d = image.apply(pos[i] - pos[j]).length();
                    if d < radius[i] + radius[j] {
                        assert!(
                            list.of(i).contains(&(j as u32)),
                            "step {step}: pair ({i}, {j}) missing (periodic {periodic})"
                        );
                    }
                }
            }
            for r in pos.iter_mut() {
                *r += (DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5) * 0.006;
                if periodic {
                    *r = boundary.wrap(*r);
                }
            }
        }
        assert!(list.builds > 1, "the list must have been rebuilt");
    }
}

#[test]
fn granular_scene_errors_name_their_line() {
    use mote_md::scene::Scene;
    let base = "[run]\ndt = 1e-5\nsteps = 1\n[[particle]]\nposition = [0.0, 0.0, 0.01]\nradius = 0.001\ndensity = 2500.0\n";
    let cases = [
        ("[[wall]]\nkind = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n", 8, "needs a [granular]"),
        ("[granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\n[[wall]]\nkind = \"cone\"\n", 13, "unknown wall kind"),
        ("[granular]\nyoung = 1e6\npoisson = 0.7\nrestitution = 0.5\nfriction = 0.5\n", 8, "poisson"),
        ("[granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\ndamping = \"magic\"\n", 8, "unknown damping"),
    ];
    for (extra, line, words) in cases {
        let text = format!("{base}{extra}");
        let scene = Scene::parse(&text, "s.toml").unwrap();
        let e = match scene.build(&text, "s.toml", 1) {
            Err(e) => e,
            Ok(_) => panic!("{extra} must be rejected"),
        };
        assert_eq!(e.line, line, "{e}");
        assert!(e.message.contains(words), "{e}");
    }
    // A good scene builds, with rotation-aware contacts and a wall.
    let good = format!("{base}[granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\n[[wall]]\nkind = \"box\"\nlo = [-0.1, -0.1, 0.0]\nhi = [0.1, 0.1, 0.1]\n");
    let built = Scene::parse(&good, "s.toml")
        .unwrap()
        .build(&good, "s.toml", 1)
        .unwrap();
    assert!(built.simulation.forces.exerts_torques());
    let m = built.simulation.system.particles.mass[0];
    assert!((m - 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * 1e-9).abs() < 1e-15);
}

/// The contact loop's blocks depend on N, never on the thread count: a
/// dense, spinning cloud of 8200 spheres (two blocks) gives the same bits
/// on one thread and on three.
#[test]
fn contacts_are_thread_count_independent() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let mut p = Particles::default();
    let side = 21;
    for k in 0..8200 {
        let cell = DVec3::new(
            (k % side) as f64,
            ((k / side) % side) as f64,
            (k / (side * side)) as f64,
        );
        let jitter = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2e-4;
        let r = 1e-3 * (0.95 + 0.1 * rng.gen::<f64>());
        let v = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5;
        let mut s = sphere(cell * 2e-3 + jitter, v * 0.1, r);
        s.angular_velocity = (DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5) * 100.0;
        p.push(s);
    }
    let law = ContactLaw::new(glass(), glass(), 0.5, 0.4, Damping::Exact, false);
    let start = System::new(p);
    let on = |threads: usize| {
        mote_testkit::on_threads(threads, || {
            let mut sys = start.clone();
            let mut ff = ForceField::new().with(GranularContacts::new(
                law,
                r_max(&sys.particles.radius),
                2e-4,
            ));
            let mut stepper = Stepper::new(Integrator::LeapFrog);
            for _ in 0..20 {
                stepper.step(&mut sys, &mut ff, 2e-6);
            }
            let bits = |v: &[DVec3]| {
                v.iter()
                    .flat_map(|a| a.to_array())
                    .map(f64::to_bits)
                    .collect::<Vec<_>>()
            };
            (
                bits(&sys.particles.position),
                bits(&sys.particles.velocity),
                bits(&sys.particles.angular_velocity),
            )
        })
    };
    let one = on(1);
    assert!(one == on(3), "one and three threads differ");
}

/// A granular scene stores its particles in space order (`[granular]
/// order`, default `space`) and still speaks the scene's numbering: the
/// frame, a probe and a spring name the same particles as with `order =
/// "file"`, and a run differs only by the order of its sums (round-off).
#[test]
fn space_order_keeps_the_scenes_numbering() {
    use mote_md::scene::Scene;
    use mote_run::Propagator;
    let scene = |order: &str| {
        format!(
            "[run]\nintegrator = \"leapfrog\"\ndt = 2e-5\nsteps = 1500\n\
             [field]\ng = [0.0, 0.0, -9.81]\n\
             [granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\norder = \"{order}\"\n\
             [[wall]]\nkind = \"box\"\nlo = [0.0, 0.0, 0.0]\nhi = [0.02, 0.02, 0.02]\n\
             [[cloud]]\nn = 150\nmin = [0.0, 0.0, 0.0]\nmax = [0.02, 0.02, 0.008]\nradius = 0.001\n\
             density = 2500.0\n\
             [[spring]]\npairs = [[0, 7], [3, 120]]\nstiffness = 50.0\n\
             [output]\ninspect = [\"z[7]\", \"vx[120]\"]\n"
        )
    };
    let build = |order: &str| {
        let text = scene(order);
        Scene::parse(&text, "s.toml")
            .unwrap()
            .build(&text, "s.toml", 5)
            .unwrap()
    };
    let (mut space, mut file) = (build("space"), build("file"));
    let sys = &space.simulation.system;
    let mut numbers: Vec<u64> = (0..150).map(|i| sys.number_of(i)).collect();
    assert_ne!(
        numbers,
        (0..150).collect::<Vec<u64>>(),
        "the cloud is stored as given"
    );
    numbers.sort_unstable();
    assert_eq!(numbers, (0..150).collect::<Vec<u64>>());
    assert!(file.simulation.system.number.is_empty());
    // Stored apart, written alike: the same frame to the bit.
    let frame = |b: &mote_md::scene::Built| mote_md::output::frame_of(&b.simulation.system);
    assert_eq!(frame(&space), frame(&file));
    space.simulation.prime(&mut |_| {}).unwrap();
    file.simulation.prime(&mut |_| {}).unwrap();
    for _ in 0..1500 {
        space.simulation.advance().unwrap();
        file.simulation.advance().unwrap();
    }
    let (a, b) = (frame(&space), frame(&file));
    let moved = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max));
    let worst = moved.fold(0.0, f64::max);
    // The cloud falls 4 mm onto the floor and the spheres collide; the
    // springs (ω = √(k/μ) ≈ 3100 /s for the pair's reduced mass, some
    // fifteen periods in 0.03 s) pull the same pairs, or the runs would
    // part by millimetres.
    assert!(worst < 1e-12, "the orders part by {worst} m");
    let touching = a.positions.iter().filter(|p| p[2] < 0.001).count();
    assert!(touching > 10, "{touching} spheres press on the floor");
    // The live viewer's forces come in the frame's order too.
    let (fa, fb) = (space.simulation.forces(), file.simulation.forces());
    let scale = fb.iter().map(|f| f[2].abs()).fold(0.0, f64::max);
    for (p, q) in fa.iter().zip(&fb) {
        assert!(
            (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-9 * scale),
            "{p:?} against {q:?}"
        );
    }
    // A probe reads the particle the scene numbers, in either order.
    for (p, q) in space.probes.iter().zip(&file.probes) {
        assert_eq!(p.particle, q.particle);
        let (x, y) = (
            p.read(&space.simulation.system),
            q.read(&file.simulation.system),
        );
        assert!((x - y).abs() < 1e-12, "{}: {x} against {y}", p.label());
    }
    assert_eq!(
        space.probes[0].read(&space.simulation.system),
        a.positions[7][2]
    );
}

/// A checkpoint names the order its particles are stored in, and a build
/// that stores them in another refuses it, never reading one particle's
/// state into another; a checkpoint of a mote that kept the scene's order
/// resumes in that order.
#[test]
fn a_checkpoint_in_another_order_is_refused() {
    use mote_md::scene::Scene;
    use mote_run::Propagator;
    let scene = |order: &str, n: usize| {
        format!(
            "[run]\nintegrator = \"leapfrog\"\ndt = 2e-5\nsteps = 10\n\
             [granular]\nyoung = 1e6\npoisson = 0.3\nrestitution = 0.5\nfriction = 0.5\norder = \"{order}\"\n\
             [[cloud]]\nn = {n}\nmin = [0.0, 0.0, 0.0]\nmax = [0.02, 0.02, 0.02]\nradius = 0.001\ndensity = 2500.0\n"
        )
    };
    let build = |order: &str, seed: u64| {
        let text = scene(order, 60);
        let scene = Scene::parse(&text, "s.toml").unwrap();
        scene.build(&text, "s.toml", seed).unwrap().simulation
    };
    let saved = |mut sim: mote_md::Simulation| {
        let mut cp = mote_io::checkpoint::Checkpoint::default();
        sim.save(&mut cp).unwrap();
        cp
    };
    let (space, file) = (saved(build("space", 1)), saved(build("file", 1)));
    assert!(build("space", 1).check_order(&space).is_ok());
    assert!(build("file", 1).check_order(&file).is_ok());
    let e = build("space", 1).check_order(&file).unwrap_err();
    assert!(
        e.contains("the scene's order, and this build in space order"),
        "{e}"
    );
    let e = build("file", 1).check_order(&space).unwrap_err();
    assert!(
        e.contains("in space order, and this build in the scene's"),
        "{e}"
    );
    // Another cloud, another order.
    let e = build("space", 2).check_order(&space).unwrap_err();
    assert!(e.contains("another space order"), "{e}");
    // A checkpoint that names no order (written before granular scenes
    // were stored in space order) resumes in the scene's order, as the
    // front readies the scene for it.
    let text = scene("space", 60);
    let mut resuming = Scene::parse(&text, "s.toml").unwrap();
    resuming.keep_order_of(&file);
    let sim = resuming.build(&text, "s.toml", 1).unwrap().simulation;
    assert!(sim.system.number.is_empty());
    assert!(sim.check_order(&file).is_ok());
    let mut resuming = Scene::parse(&text, "s.toml").unwrap();
    resuming.keep_order_of(&space);
    let sim = resuming.build(&text, "s.toml", 1).unwrap().simulation;
    assert!(sim.check_order(&space).is_ok() && !sim.system.number.is_empty());
}
