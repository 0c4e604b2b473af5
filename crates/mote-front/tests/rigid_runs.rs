//! Whole rigid runs through the front, as `mote run` makes them: the
//! magnet example keeps its momentum, a run's last frame starts a new
//! scene, the toning nip example writes nip.csv (mote-nip's observer).

use std::path::Path;

use mote_front::{Input, RunOptions, Silent};
use mote_md::rigid::scene::RigidScene;

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/rigid")
        .join(name);
    std::fs::read_to_string(p).unwrap()
}

/// Runs `text` (named `name`) into `dir` with `options`.
fn run(name: &str, text: &str, dir: &Path, options: RunOptions) -> mote_front::Outcome {
    let input = Input::scene(name, name, text);
    let options = RunOptions {
        output: Some(dir.to_path_buf()),
        ..options
    };
    let outcome =
        mote_front::run_input(&input, &options, &mut Silent).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        matches!(outcome.ending, mote_front::Ending::Finished),
        "{:?}",
        outcome.ending
    );
    outcome
}

#[test]
fn magnet_example_runs() {
    let text = example("magnet-in-field.toml");
    let dir = tempfile::tempdir().unwrap();
    run(
        "magnet-in-field.toml",
        &text,
        dir.path(),
        RunOptions::default(),
    );
    let table = mote_io::csv::read_table(&dir.path().join("observables.csv")).unwrap();
    assert!((table.column("time").unwrap().last().unwrap() - 200.0).abs() < 1e-9);
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
        run(
            "s.toml",
            &text,
            dir.path(),
            RunOptions {
                trajectory_format: Some(format.extension().replace("pvd", "vtk")),
                seed: Some(1),
                ..RunOptions::default()
            },
        );
        let file = dir.path().join(name);
        let frames = mote_io::trajectory::read_frames(&file).unwrap();
        let last = frames.last().unwrap();
        assert!(last.time > 0.0);
        let again = without_random(&text).replace(
            "[rigid.fields]",
            &format!(
                "[[from_file]]\nfile = {:?}\n\n[rigid.fields]",
                file.display().to_string()
            ),
        );
        let built = RigidScene::parse(&again, "again.toml")
            .unwrap()
            .build(&again, "again.toml", None)
            .unwrap_or_else(|e| panic!("{e}"));
        // Body after body in the scene's numbering (both are stored in
        // space order, each of its own positions).
        let kinds = |b: &mote_md::rigid::bodies::RigidBodies| {
            let rows = b.rows_by_number().unwrap_or_else(|| (0..b.len()).collect());
            rows.iter().map(|&i| b.kind[i]).collect::<Vec<_>>()
        };
        assert_eq!(kinds(&built.bodies), kinds(&original.bodies), "{name}");
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
fn toning_nip_example_runs_and_writes_nip_csv() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        "toning-nip.toml",
        &example("toning-nip.toml"),
        dir.path(),
        RunOptions {
            steps: Some(40),
            ..RunOptions::default()
        },
    );
    assert!(o.summary[0].contains("800 rigid bodies"), "{:?}", o.summary);
    // The frames are in the periodic box: whole bodies moved into it.
    let frames = mote_io::trajectory::read_frames(&dir.path().join("trajectory.xyz")).unwrap();
    let f = frames.last().unwrap();
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

/// The toning nip with its conducting planes summed by P3M on the doubled
/// cell (`[rigid.planes] method = "p3m"`): the tuned mesh is told in the
/// summary, and the run follows the Ewald one — its charges' forces agree
/// to the accuracy asked for (δ = 10⁻¹¹ N, the toner feels ~10⁻⁸ N), so
/// over 40 steps the energies differ by less than N δ times the bodies'
/// spacing (800 bodies in 9.3·10⁻¹² m³: 2.3·10⁻⁵ m).
#[test]
fn toning_nip_runs_with_p3m_between_the_planes() {
    let ewald_text = example("toning-nip.toml");
    assert!(ewald_text.contains("[rigid.planes]\n"));
    let p3m_text = ewald_text.replace("[rigid.planes]\n", "[rigid.planes]\nmethod = \"p3m\"\n");
    let energies = |name: &str, text: &str| {
        let dir = tempfile::tempdir().unwrap();
        let o = run(
            name,
            text,
            dir.path(),
            RunOptions {
                steps: Some(40),
                ..RunOptions::default()
            },
        );
        let table = mote_io::csv::read_table(&dir.path().join("observables.csv")).unwrap();
        let potential = table.column("potential_energy").unwrap().to_vec();
        (o.summary, potential)
    };
    let (said, with_p3m) = energies("nip-p3m.toml", &p3m_text);
    assert!(
        said.iter().any(|l| l
            .starts_with("Between conducting planes, on the doubled cell: Coulomb by P3M: mesh")),
        "{said:?}"
    );
    let (said, with_ewald) = energies("nip-ewald.toml", &ewald_text);
    assert!(
        said.iter()
            .any(|l| l.starts_with("Coulomb between conducting planes by Ewald")),
        "{said:?}"
    );
    let bound = 800.0 * 1.0e-11 * 2.3e-5;
    for (a, b) in with_p3m.iter().zip(&with_ewald) {
        println!("U: P3M {a:e}, Ewald {b:e}, difference {:e}", a - b);
        assert!((a - b).abs() <= bound, "P3M {a} against Ewald {b}");
    }
}

/// The development itself: 10⁴ steps (0.5 ms; about a minute in release):
/// toner develops onto the image, hardly onto the background.
/// `cargo test --release -p mote-front --test front rigid_runs::toning_nip -- --ignored --nocapture`
#[test]
#[ignore]
fn toning_nip_develops_the_image_not_the_background() {
    let dir = tempfile::tempdir().unwrap();
    run(
        "toning-nip.toml",
        &example("toning-nip.toml"),
        dir.path(),
        RunOptions {
            steps: Some(10_000),
            ..RunOptions::default()
        },
    );
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
fn toner_on_shell(volts: f64, planes: &str) -> f64 {
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
{planes}

[box]
lo = [0.0, 0.0, 0.0]
hi = [1.0e-4, 1.0e-4, 2.5e-4]
periodic = [true, true, false]

[rigid.contacts]
young = 5.0e6
restitution = 0.3
friction = 0.3
adhesion = 5.0e-4

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
    run("toner.toml", &text, dir.path(), RunOptions::default());
    let frames = mote_io::trajectory::read_frames(&dir.path().join("trajectory.xyz")).unwrap();
    frames.last().unwrap().positions[0][2]
}

/// The same toner with the planes summed by P3M and its cut-off tuned
/// (one charge in the doubled cell: the box, not the charges' spacing,
/// sets the cut-off and skin): it crosses to the belt at 1000 V and lands
/// where the Ewald run lands.
#[test]
fn a_lone_toner_between_planes_by_p3m_follows_ewald() {
    let ewald = toner_on_shell(-1000.0, "r_cut = 4.0e-5");
    let p3m = toner_on_shell(-1000.0, "method = \"p3m\"");
    println!("z: Ewald {ewald:e}, P3M {p3m:e}");
    assert!(
        p3m < 5.0e-6,
        "by P3M the toner did not reach the belt: z = {p3m}"
    );
    assert!(
        (p3m - ewald).abs() < 1e-3 * ewald.abs(),
        "{p3m} against {ewald}"
    );
}

#[test]
fn toner_leaves_the_shell_when_the_field_beats_adhesion() {
    let held = toner_on_shell(-500.0, "r_cut = 4.0e-5");
    assert!(
        held > 2.45e-4,
        "at 500 V the toner left the shell: z = {held}"
    );
    let moved = toner_on_shell(-1000.0, "r_cut = 4.0e-5");
    assert!(
        moved < 5.0e-6,
        "at 1000 V the toner did not reach the belt: z = {moved}"
    );
}
