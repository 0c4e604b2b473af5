//! Scene files: every example parses and builds, and bad input is reported
//! as `file:line: message`.

use mote_edmd::scene::{example, EXAMPLES};
use mote_edmd::{Scene, System};
use std::path::Path;

#[test]
fn every_example_builds_without_overlap() {
    for (name, text) in EXAMPLES {
        let scene = Scene::parse(text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        match scene.spheres.dimension {
            2 => {
                let s: System<2> = scene.build(1, Path::new(".")).unwrap();
                assert!(s.find_overlap(1e-12).is_none());
            }
            _ => {
                let s: System<3> = scene.build(1, Path::new(".")).unwrap();
                assert!(s.find_overlap(1e-12).is_none());
            }
        }
    }
}

#[test]
fn cube_example_has_the_seed_radius_and_packing_fraction() {
    // 001: r = w/((30π)^{1/3}·nbs), nbs = 10, so η = (4/3)π nbs³ r³ / w³ = 4/90
    let scene = Scene::parse(example("cube").unwrap(), "cube").unwrap();
    let s: System<3> = scene.build(1, Path::new(".")).unwrap();
    let r = 1.0 / ((30.0 * std::f64::consts::PI).powf(1.0 / 3.0) * 10.0);
    assert_eq!(s.len(), 1000);
    assert!((s.radius(0) - r).abs() < 1e-14);
    assert!((s.packing_fraction() - 4.0 / 90.0).abs() < 1e-12);
    // all speeds 1
    assert!(s.speeds().iter().all(|v| (v - 1.0).abs() < 1e-12));
}

fn scene_error(text: &str) -> (usize, String) {
    let e = Scene::parse(text, "bad.toml").expect_err(text).to_string();
    let rest = e.strip_prefix("bad.toml:").expect(&e);
    let (line, message) = rest.split_once(": ").expect(&e);
    (line.parse().expect(&e), message.to_string())
}

#[test]
fn errors_name_the_line() {
    let (line, msg) =
        scene_error("[event_driven]\ndimension = 3\nn = 10\npacking_fraction = 0.9\n");
    assert_eq!(line, 4);
    assert!(msg.contains("packing_fraction"), "{msg}");
    let (line, msg) = scene_error(
        "[event_driven]\ndimension = 3\nn = 10\npacking_fraction = 0.1\n[box]\nperiodic = [true, \"sticky\", true]\n",
    );
    assert_eq!(line, 6);
    assert!(
        msg.contains("invalid type: string \"sticky\", expected a boolean"),
        "{msg}"
    );
    let (line, msg) =
        scene_error("[event_driven]\ndimension = 4\nn = 10\npacking_fraction = 0.1\n");
    assert_eq!(line, 2);
    assert!(msg.contains("2 (disks) or 3"), "{msg}");
    let (line, msg) =
        scene_error("[event_driven]\nn = 10\npacking_fraction = 0.1\ntemprature = 1.0\n");
    assert_eq!(line, 4);
    assert!(msg.contains("temprature"), "{msg}");
    let (line, msg) = scene_error("[event_driven]\nn = 10\n[box]\nhi = [1.0, 2.0]\n");
    assert_eq!(line, 4);
    assert!(msg.contains("[box] hi must list 3 entries"), "{msg}");
    let (line, msg) =
        scene_error("[event_driven]\nn = 10\n[box]\nlo = [1.0, 0.0, 0.0]\nhi = [3.0, 3.0, 3.0]\n");
    assert_eq!(line, 4);
    assert!(msg.contains("from the origin"), "{msg}");
    // The first spellings inside [event_driven] are refused with the one
    // every engine uses (at the top level, the front refuses them).
    for (text, line, spelling) in [
        (
            "[event_driven]\nn = 10\nbox = [3.0, 3.0, 3.0]\n",
            3,
            "[box] hi = [lengths]",
        ),
        (
            "[event_driven]\nn = 10\npacking_fraction = 0.1\nboundary = \"wall\"\n",
            4,
            "[box] hi = [lengths]",
        ),
        (
            "[event_driven]\nfile = \"start.xyz\"\n",
            2,
            "[[from_file]] file = ",
        ),
    ] {
        let (at, msg) = scene_error(text);
        assert_eq!(at, line, "{text}: {msg}");
        assert!(msg.contains(spelling), "{msg}");
    }
    // A box too small for the spheres is refused at the key that set it.
    let text = "[event_driven]\nn = 20\npacking_fraction = 0.2876\nradius = 0.2\nsize_ratio = 1.25\nlarge_fraction = 0.25\nplacement = \"random\"\n";
    let e = Scene::parse(text, "small.toml")
        .unwrap()
        .build::<3>(5, std::path::Path::new("."))
        .unwrap_err();
    assert!(
        e.to_string().starts_with("small.toml:3: periodic box"),
        "{e}"
    );
    // Twenty spheres at a packing fraction of 1e-300 are placed at once
    // (the placement grid asked for 24 GB of empty cells).
    let t0 = std::time::Instant::now();
    let text = "[event_driven]\nn = 20\npacking_fraction = 1e-300\nplacement = \"random\"\n";
    let system = Scene::parse(text, "sparse.toml")
        .unwrap()
        .build::<3>(5, std::path::Path::new("."));
    assert!(system.is_ok() && t0.elapsed().as_secs_f64() < 2.0);
    let e = Scene::parse(
        "[event_driven]\nn = 10\npacking_fraction = 0.1\n[run]\nuntil = -1.0\n",
        "bad.toml",
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("bad.toml:5: "), "{e}");
}

#[test]
fn too_dense_random_placement_is_an_error_not_a_panic() {
    let scene = Scene::parse(
        "[event_driven]\nn = 500\npacking_fraction = 0.55\nplacement = \"random\"\n",
        "dense.toml",
    )
    .unwrap();
    let e = scene.build::<3>(1, Path::new(".")).unwrap_err();
    assert!(e.to_string().contains("random placement"), "{e}");
}

/// A run expected to take more than 10⁹ events is refused at its `until`
/// line unless forced (a mass of 10⁻³⁰⁰ asks for 10¹⁵² and never ended);
/// an ordinary run passes, and its estimate is within a few times the
/// events it takes.
#[test]
fn runs_of_more_than_a_billion_events_need_force() {
    let text = |mass: &str| {
        format!(
            "seed = 5\n[event_driven]\ndimension = 3\nn = 200\npacking_fraction = 0.3\nmass = {mass}\n\
             placement = \"random\"\n[run]\nuntil = 0.5\n"
        )
    };
    let scene = Scene::parse(&text("1e-300"), "s.toml").unwrap();
    let system = scene.build::<3>(5, Path::new(".")).unwrap();
    let e = scene.check_run_length(&system, false).unwrap_err();
    let message = e.to_string();
    assert!(message.starts_with("s.toml:9:"), "{message}");
    assert!(
        message.contains("--force") && message.contains("e152 events"),
        "{message}"
    );
    assert!(scene.check_run_length(&system, true).is_ok());

    let scene = Scene::parse(&text("1.0"), "s.toml").unwrap();
    let mut system = scene.build::<3>(5, Path::new(".")).unwrap();
    scene.check_run_length(&system, false).unwrap();
    let expected = system.expected_events(0.5);
    let events = system.run_until(0.5) as f64;
    assert!(
        events > expected / 3.0 && events < 3.0 * expected,
        "{events} events, {expected:.0} expected"
    );
}
