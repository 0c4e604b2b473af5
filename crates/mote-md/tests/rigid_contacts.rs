//! Hertz–Mindlin contacts between rigid clumps and with walls
//! (`rigid::contacts`): conservation in the elastic limit, the coefficient
//! of restitution of a sphere on a plane, and clumps at rest in a box
//! carrying their weight on the walls.

use glam::DVec3;
use mote_geom::{from_axis_angle, DE, E};
use mote_md::force::granular::{ContactLaw, Damping, Material, Wall};
use mote_md::rigid::{
    BodyTemplate, Frbi, Gravity, Integration, IrregularClump, RigidBodies, RigidContacts,
};

const MAT: Material = Material {
    young: 1.0e5,
    poisson: 0.3,
};

fn law(e: f64, mu: f64) -> ContactLaw {
    ContactLaw::new(MAT, MAT, e, mu, Damping::Exact, false)
}

/// Two irregular clumps and a plain sphere (a one-sphere template) meeting
/// off-centre with spin; elastic (e = 1, no damping) and frictionless.
fn collision() -> RigidBodies {
    let gen = IrregularClump::default();
    let mut b = RigidBodies::new();
    let ta = BodyTemplate::new(&gen.generate(11), Integration::default()).unwrap();
    let tb = BodyTemplate::new(&gen.generate(12), Integration::default()).unwrap();
    let ts = BodyTemplate::sphere(0.6, 1.0).unwrap();
    let (ka, kb, ks) = (b.add_template(ta), b.add_template(tb), b.add_template(ts));
    b.push(
        ka,
        E::new(
            from_axis_angle(DVec3::new(1.0, 2.0, 0.5), 0.7),
            DVec3::new(-2.0, 0.3, 0.0),
        ),
        DE::new(DVec3::new(0.3, -0.2, 0.5), DVec3::new(1.0, 0.0, 0.05)),
    );
    b.push(
        kb,
        E::new(
            from_axis_angle(DVec3::new(-1.0, 0.2, 1.5), 2.9),
            DVec3::new(2.0, -0.2, 0.2),
        ),
        DE::new(DVec3::new(-0.4, 0.1, 0.2), DVec3::new(-1.0, 0.02, 0.0)),
    );
    b.push(
        ks,
        E::new(DVec3::ZERO, DVec3::new(0.1, 2.6, -0.1)),
        DE::new(DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, -1.3, 0.0)),
    );
    b
}

/// Elastic limit: total linear and angular momentum are kept to rounding
/// (the contact forces and torques cancel pairwise and the integrator keeps
/// momenta of interacting bodies to rounding); the total energy, kinetic
/// plus Hertz elastic, stays within 1e-5 of its initial value during the
/// contacts (measured 3.9e-6) and returns to it within 1e-6 after they end
/// (measured 6e-8; dt = 1e-4, a few hundred steps per contact). Momenta:
/// |ΔP| < 1e-12 Σ m|v| (measured 1.2e-15), |ΔL| < 1e-11 of max(|L|, 3 Σ m|v|)
/// (measured 2e-12).
#[test]
fn elastic_collision_conserves_momenta_and_energy() {
    let mut b = collision();
    let contacts = RigidContacts::new(law(1.0, 0.0), law(1.0, 0.0), vec![], 0.3);
    let mut f = Frbi::new().with(contacts);
    let o0 = b.observables();
    let e0 = f.energies(&b).total();
    let dt = 1e-4;
    let mut max_dev = 0.0f64;
    let mut touched = 0usize;
    for _ in 0..40_000 {
        f.step(&mut b, dt);
        let e = f.energies(&b).total();
        max_dev = max_dev.max((e - e0).abs() / e0);
        touched = touched.max(f.find::<RigidContacts>().unwrap().contact_counts().0);
    }
    assert!(touched > 0, "the bodies never touched");
    assert_eq!(
        f.find::<RigidContacts>().unwrap().contact_counts().0,
        0,
        "still in contact at the end"
    );
    let o = b.observables();
    let p_scale = (0..b.len())
        .map(|i| b.template(i).mass() * b.velocity[i].length())
        .sum::<f64>();
    let dp = (o.linear_momentum - o0.linear_momentum).length() / p_scale;
    let l_scale = o0.angular_momentum.length().max(p_scale * 3.0);
    let dl = (o.angular_momentum - o0.angular_momentum).length() / l_scale;
    let de = (f.energies(&b).total() - e0).abs() / e0;
    println!("dp {dp:.2e} dL {dl:.2e} max dE {max_dev:.2e} final dE {de:.2e} contacts {touched}");
    assert!(dp < 1e-12, "linear momentum drift {dp:e}");
    assert!(dl < 1e-11, "angular momentum drift {dl:e}");
    assert!(max_dev < 1e-5, "energy error during contact {max_dev:e}");
    assert!(de < 1e-6, "energy error after contact {de:e}");
}

/// A sphere-template body dropped without gravity at 1 m/s onto a plane
/// comes back with the asked coefficient of restitution within 1 %.
#[test]
fn sphere_body_bounces_with_restitution() {
    for e in [0.3, 0.6, 0.9] {
        let mut b = RigidBodies::new();
        let k = b.add_template(BodyTemplate::sphere(0.5, 1.0).unwrap());
        b.push(
            k,
            E::new(DVec3::ZERO, DVec3::new(0.0, 0.0, 0.6)),
            DE::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0)),
        );
        let wall = Wall::plane("floor", DVec3::ZERO, DVec3::Z);
        let contacts = RigidContacts::new(law(e, 0.5), law(e, 0.5), vec![wall], 0.2);
        let mut f = Frbi::new().with(contacts);
        let dt = 2e-5;
        while b.time < 0.5 {
            f.step(&mut b, dt);
        }
        assert_eq!(f.find::<RigidContacts>().unwrap().contact_counts().1, 0);
        let back = b.velocity[0].z;
        println!("e {e}: {back}");
        assert!((back / e - 1.0).abs() < 0.01, "e {e}: rebound {back}");
        assert!(b.velocity[0].x.abs() < 1e-14 && b.omega[0].length() < 1e-12);
    }
}

/// 27 irregular clumps and plain spheres settle under gravity in a closed
/// box with friction (e = 0.3, μ = 0.5, dt = 5e-4); by t = 45 they are at
/// rest (kinetic energy below 1e-8 M g, in units g = 1, clump radius 1),
/// and the walls carry their weight: the force on the walls averaged over
/// the next 5 time units equals M g within 0.1 % (measured: 4e-10), its
/// horizontal part vanishes to 0.1 % of M g.
#[test]
fn settled_clumps_rest_on_the_walls() {
    let g = 1.0;
    let gen = IrregularClump {
        lobes: 6,
        ..IrregularClump::default()
    };
    let mut b = RigidBodies::new();
    let kinds: Vec<u32> = (0..3)
        .map(|s| {
            b.add_template(
                BodyTemplate::new(&gen.generate(100 + s), Integration::default()).unwrap(),
            )
        })
        .collect();
    let ks = b.add_template(BodyTemplate::sphere(0.8, 1.0).unwrap());
    let mut n = 0;
    for iz in 0..3 {
        for iy in 0..3 {
            for ix in 0..3 {
                let x = DVec3::new(
                    1.6 + 2.7 * ix as f64,
                    1.6 + 2.7 * iy as f64,
                    1.6 + 2.7 * iz as f64,
                );
                let k = if n % 5 == 4 { ks } else { kinds[n % 3] };
                let r = from_axis_angle(
                    DVec3::new(0.3 + ix as f64, 1.0, iz as f64 - 1.5),
                    0.4 * n as f64,
                );
                b.push(
                    k,
                    E::new(r, x),
                    DE::new(
                        DVec3::ZERO,
                        DVec3::new(0.1 * (n % 3) as f64 - 0.1, 0.0, 0.0),
                    ),
                );
                n += 1;
            }
        }
    }
    let walls = Wall::closed_box("box", DVec3::ZERO, DVec3::new(8.6, 8.6, 20.0));
    // No rolling resistance: with rolling_friction = 0.1 the pile keeps a
    // residual motion (KE ~ 1e-5 M g d, not decaying; see docs/rigid.md).
    let cl = law(0.3, 0.5);
    let contacts = RigidContacts::new(cl, cl, walls, 0.3);
    let mut f = Frbi::new()
        .with(Gravity {
            g: DVec3::new(0.0, 0.0, -g),
        })
        .with(contacts);
    let dt = 5e-4;
    let weight = b.total_mass() * g;
    let mut steps = 0;
    while b.time < 45.0 {
        f.step(&mut b, dt);
        steps += 1;
    }
    let ke = b.observables().kinetic_energy();
    // average over the next 5 time units
    let mut sum = DVec3::ZERO;
    let mut floor = 0.0;
    let m = 10000;
    for _ in 0..m {
        f.step(&mut b, dt);
        let wf = f.find::<RigidContacts>().unwrap().wall_forces();
        sum += wf.iter().map(|(_, w)| *w).sum::<DVec3>();
        floor += wf[4].1.z;
    }
    let avg = sum / m as f64;
    println!(
        "steps {steps} KE {ke:e} weight {weight} wall force {avg} floor {} max v {}",
        floor / m as f64,
        b.velocity.iter().map(|v| v.length()).fold(0.0, f64::max)
    );
    assert!(ke < 1e-8 * weight, "not at rest: KE {ke:e}");
    assert!(
        ((-avg.z) / weight - 1.0).abs() < 1e-3,
        "wall force {avg} vs weight {weight}"
    );
    assert!(avg.x.abs() < 1e-3 * weight && avg.y.abs() < 1e-3 * weight);
}

/// Irregular clumps pressed into one another in a periodic cube, at rest:
/// the molecular virial of the contacts gives the pressure of the
/// body-centre ensemble, P = W/3V = −dU/dV for the Hertz energy U when
/// the body centres and the box are scaled together (orientations kept;
/// central differences, h = 1e-6). At rest nothing but the elastic law
/// acts (no damping, no tangential history), so the two agree to the
/// differences' error.
#[test]
fn the_contact_virial_is_the_volume_derivative_of_the_energy() {
    let side = 6.4;
    let gen = IrregularClump::default();
    let templates: Vec<_> = (0..3)
        .map(|k| BodyTemplate::new(&gen.generate(30 + k), Integration::default()).unwrap())
        .collect();
    let pressed = |scale: f64| {
        let mut b = RigidBodies::new();
        let kinds: Vec<u32> = templates
            .iter()
            .map(|t| b.add_template(t.clone()))
            .collect();
        let mut n = 0;
        for ix in 0..4 {
            for iy in 0..4 {
                for iz in 0..4 {
                    let x = DVec3::new(ix as f64, iy as f64, iz as f64) * (side / 4.0)
                        + DVec3::new(0.1, 0.2, 0.3);
                    let r =
                        from_axis_angle(DVec3::new(1.0, n as f64, 2.0 - iz as f64), 0.7 * n as f64);
                    b.push(kinds[n % 3], E::new(r, x * scale), DE::default());
                    n += 1;
                }
            }
        }
        let box_ = mote_md::boundary::Boundary::periodic(DVec3::ZERO, DVec3::splat(side * scale));
        let contacts =
            RigidContacts::new(law(0.5, 0.5), law(0.5, 0.5), vec![], 0.3).with_boundary(box_);
        (b, Frbi::new().with(contacts), box_.volume())
    };
    let (b, mut f, volume) = pressed(1.0);
    let w = f.virial(&b).unwrap();
    // Many contacts press: a force pass of a copy counts them.
    let (mut moved, mut g, _) = pressed(1.0);
    g.step(&mut moved, 1e-12);
    let touching = g.find::<RigidContacts>().unwrap().contact_counts().0;
    assert!(touching > 20, "only {touching} contacts");
    let h = 1e-6;
    let energy = |s: f64| {
        let (b, mut f, v) = pressed(s);
        (f.energies(&b).potential, v)
    };
    let ((u_plus, v_plus), (u_minus, v_minus)) = (energy(1.0 + h), energy(1.0 - h));
    let from_energy = -(u_plus - u_minus) / (v_plus - v_minus);
    let from_virial = w / (3.0 * volume);
    println!("{touching} contacts: P = {from_virial:e} by the virial, {from_energy:e} by -dU/dV");
    assert!(
        from_virial > 0.0,
        "pressed clumps push outwards: P = {from_virial}"
    );
    assert!(
        (from_virial - from_energy).abs() < 1e-6 * from_virial,
        "virial {from_virial:e} against -dU/dV {from_energy:e}"
    );
}

/// 800 trimers (2400 spheres: two blocks of pairs, three of spheres
/// against the floor) falling onto a floor in a box periodic in x and y
/// (bodies crossing its sides, contacts between bodies and with the
/// floor): the contact section's blocks run on any number of threads and
/// the wrenches are summed in pair order, so 1, 2 and 3 threads give the
/// same bits.
#[test]
fn clumps_on_a_floor_give_the_same_bits_on_any_number_of_threads() {
    use mote_md::rigid::run::RigidDynamics;
    use mote_md::rigid::scene::RigidScene;
    use mote_run::Propagator;
    let text = r#"
seed = 7
[rigid]
[[rigid.template]]
name = "trimer"
generator = "trimer"
radius = 0.5
distance = 0.5
mass = 1.5
[[rigid.lattice]]
template = "trimer"
n = 800
lo = [0.0, 0.0, 0.6]
hi = [19.0, 19.0, 12.0]
spacing = 1.9
random_orientation = true
[rigid.fields]
gravity = [0.0, 0.0, -10.0]
[rigid.contacts]
young = 136500.0
poisson = 0.3
restitution = 0.5
friction = 0.5
[[rigid.wall]]
kind = "plane"
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[box]
hi = [19.0, 19.0, 30.0]
periodic = [true, true, false]
[run]
dt = 5e-4
steps = 300
"#;
    let run = |threads: usize| {
        mote_testkit::on_threads(threads, || {
            let built = RigidScene::parse(text, "floor.toml")
                .unwrap()
                .build(text, "floor.toml", None)
                .unwrap();
            let mut run = RigidDynamics::new(built);
            run.prime(&mut |_| {}).unwrap();
            for _ in 0..300 {
                run.advance().unwrap();
            }
            let contacts = run.contacts().unwrap();
            let (pairs, walls) = contacts.contact_counts();
            assert!(
                pairs > 100 && walls > 10,
                "{pairs} pairs, {walls} on the floor"
            );
            // The summary names the contacts' list builds beside their share.
            let builds = contacts.list_builds();
            let summary = run.frbi.breakdown(run.stepping, run.stepping).sentence();
            assert!(
                builds > 1 && summary.contains(&format!("contacts (list: {builds} builds) ")),
                "{summary}"
            );
            (run.bodies.position.clone(), run.bodies.velocity.clone())
        })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}
