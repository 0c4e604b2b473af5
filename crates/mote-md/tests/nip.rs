//! The toning nip's observables (rigid/nip.rs) on placed bodies whose
//! answers are known, and the example scene: it builds, runs a few steps
//! and writes nip.csv; an ignored test runs it long enough to develop.

use std::f64::consts::PI;
use std::path::Path;

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::nip::NipProbe;
use mote_md::rigid::scene::{run_rigid_scene, RigidRun};
use mote_md::rigid::{BodyTemplate, RigidBodies};

/// A one-sphere template ([`BodyTemplate::sphere`]) with a charge.
fn sphere(radius: f64, density: f64, charge: f64) -> std::sync::Arc<BodyTemplate> {
    let mut t = BodyTemplate::sphere(radius, density).unwrap();
    std::sync::Arc::get_mut(&mut t).unwrap().charge = charge;
    t
}

#[test]
fn probe_counts_developed_toner_and_the_brush() {
    let mut b = RigidBodies::new();
    let carrier = b.add_template(sphere(2.0, 1.0, 0.0));
    let toner = b.add_template(sphere(0.5, 3.0, -0.1));
    let at = |x: f64, y: f64, z: f64| E::new(DVec3::ZERO, DVec3::new(x, y, z));
    // Box 20 × 10, belt at z = 1, shell at z = 15; image [2, 8) moving at 1.
    // Toner touching the belt: two on the image (x = 3, 7.5 at t = 0.5,
    // i.e. 2.5 and 7 in the belt's frame), one on the background; one
    // floating.
    for (x, z) in [(3.0, 1.5), (7.5, 1.52), (15.0, 1.5), (5.0, 6.0)] {
        b.push(toner, at(x, 5.0, z), DE::ZERO);
    }
    // A chain of three carriers hanging from the shell across the periodic
    // boundary in x (touching only through it), a bridge of four reaching
    // the belt at x = 12, and a lone carrier in the middle.
    for (x, z) in [(0.5, 13.0), (19.6, 9.1), (0.5, 5.2)] {
        b.push(carrier, at(x, 5.0, z), DE::ZERO);
    }
    for z in [13.0, 9.0, 5.0, 2.0] {
        b.push(carrier, at(12.0, 5.0, z), DE::ZERO);
    }
    b.push(carrier, at(5.5, 5.0, 9.0), DE::ZERO);
    b.time = 0.5;
    let probe = NipProbe {
        toner,
        carrier,
        belt: 1.0,
        shell: 15.0,
        lo: DVec3::ZERO,
        hi: DVec3::new(20.0, 10.0, 15.0),
        patches: vec![[2.0, 8.0]],
        speed: 1.0,
        contrast: 0.02,
    };
    let s = probe.measure(&b);
    assert_eq!(s.developed, 3);
    let m = 3.0 * 4.0 / 3.0 * PI * 0.125;
    let (a_image, a_back) = (6.0 * 10.0, 14.0 * 10.0);
    assert!((s.mass_image - 2.0 * m / a_image).abs() < 1e-3 * s.mass_image);
    assert!((s.mass_background - m / a_back).abs() < 1e-3 * s.mass_background);
    assert!((s.charge_image + 0.2 / a_image).abs() < 1e-12);
    assert!((s.neutralised - 0.2 / a_image / 0.02).abs() < 1e-12);
    // Clusters: the chain, the bridge, the lone carrier.
    assert_eq!(s.chains, 3, "{s:?}");
    assert_eq!(s.bridges, 1, "{s:?}");
    // Reach of the two clusters at the shell: the chain's lowest sphere
    // bottom is 5.2 − 2, the bridge's 2 − 2.
    let expected = ((15.0 - 3.2) + (15.0 - 0.0)) / 2.0;
    assert!((s.brush_height - expected).abs() < 1e-12, "{s:?}");
    let solids = 4.0 * 4.0 / 3.0 * PI * 0.125 + 8.0 * 4.0 / 3.0 * PI * 8.0;
    let free = 1.0 - solids / (200.0 * 14.0);
    assert!(
        (s.free_volume - free).abs() < 1e-3,
        "{} against {free}",
        s.free_volume
    );
}

fn example() -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/rigid/toning-nip.toml"),
    )
    .unwrap()
}

#[test]
fn toning_nip_example_runs_and_writes_nip_csv() {
    let dir = tempfile::tempdir().unwrap();
    let r = run_rigid_scene(
        &example(),
        "toning-nip.toml",
        &RigidRun {
            out_dir: Some(dir.path().to_path_buf()),
            steps: Some(40),
            ..RigidRun::default()
        },
        |_, _, _| {},
    )
    .unwrap();
    assert_eq!(r.bodies, 800);
    // The frames are in the periodic box: whole bodies moved into it.
    let f = &r.final_frame;
    assert_eq!(f.pbc, [true, true, false]);
    assert!((f.cell[0][0] - 3.0e-4).abs() < 1e-15 && (f.cell[2][2] - 2.58e-4).abs() < 1e-15);
    assert!(f.positions.iter().all(|p| (-2e-5..3.2e-4).contains(&p[0])));
    let table = mote_io::csv::read_table(&dir.path().join("nip.csv")).unwrap();
    let free = table.column("free_volume").unwrap();
    assert!((0.45..0.55).contains(&free[0]), "free volume {}", free[0]);
    for c in ["developed", "brush_height", "chains"] {
        assert!(table.column(c).unwrap().iter().all(|v| v.is_finite()));
    }
}

/// The development itself: 10⁴ steps (0.5 ms; about a minute in release):
/// toner develops onto the image, hardly onto the background.
/// `cargo test --release -p mote-md --test md nip:: -- --ignored --nocapture`
#[test]
#[ignore]
fn toning_nip_develops_the_image_not_the_background() {
    let dir = tempfile::tempdir().unwrap();
    run_rigid_scene(
        &example(),
        "toning-nip.toml",
        &RigidRun {
            out_dir: Some(dir.path().to_path_buf()),
            steps: Some(10_000),
            ..RigidRun::default()
        },
        |_, _, _| {},
    )
    .unwrap();
    let table = mote_io::csv::read_table(&dir.path().join("nip.csv")).unwrap();
    let image = *table.column("mass_per_area_image").unwrap().last().unwrap();
    let back = *table
        .column("mass_per_area_background")
        .unwrap()
        .last()
        .unwrap();
    println!("M/A image {image:e} kg/m², background {back:e} kg/m²");
    assert!(image > 1e-3, "M/A on the image {image}");
    assert!(
        back < 0.1 * image,
        "background {back} against image {image}"
    );
}

/// One toner particle resting on the shell, held by DMT adhesion
/// (2πwR = 12.6 nN) and its image (kq²/(2R)² = 5.9 nN); the bias pulls it
/// towards the belt with qV/h. It stays at 500 V (12.8 nN) and leaves for
/// the belt at 1000 V (25.6 nN): transfer when the field wins.
fn toner_on_shell(volts: f64) -> f64 {
    let text = format!(
        r#"
[rigid]
[[rigid.template]]
name = "toner"
generator = "sphere"
radius = 4.0e-6
density = 1200.0
charge = -6.4e-15

[[rigid.body]]
template = "toner"
position = [5.0e-5, 5.0e-5, 2.46008e-4]   # pressed 8 nm into the shell

[rigid.fields]
drag = {{ viscosity = 1.8e-5 }}

[rigid.planes]
coulomb = 8.9875517923e9
potential = [0.0, {volts}]
accuracy = 1.0e-13
r_cut = 4.0e-5

[rigid.contacts]
young = 5.0e6
restitution = 0.3
friction = 0.3
adhesion = 5.0e-4
periodic = [true, true, false]
box_lo = [0.0, 0.0, 0.0]
box_hi = [1.0e-4, 1.0e-4, 2.5e-4]

[[rigid.wall]]
kind = "plane"
name = "shell"
point = [0.0, 0.0, 2.5e-4]
normal = [0.0, 0.0, -1.0]

[[rigid.wall]]
kind = "plane"
name = "belt"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[run]
dt = 5.0e-8
steps = 3000
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let r = run_rigid_scene(
        &text,
        "toner.toml",
        &RigidRun {
            out_dir: Some(dir.path().to_path_buf()),
            ..RigidRun::default()
        },
        |_, _, _| {},
    )
    .unwrap();
    r.final_frame.positions[0][2]
}

#[test]
fn toner_leaves_the_shell_when_the_field_beats_adhesion() {
    let held = toner_on_shell(-500.0);
    assert!(
        held > 2.45e-4,
        "at 500 V the toner left the shell: z = {held}"
    );
    let moved = toner_on_shell(-1000.0);
    assert!(
        moved < 5.0e-6,
        "at 1000 V the toner did not reach the belt: z = {moved}"
    );
}
