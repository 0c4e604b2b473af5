//! One validation path: a run-length value given as an option (the command
//! line's `--dt`, `--until`, `--steps`, which Python's `mote.run(dt=...,
//! until=..., steps=...)` fills the same way) and the same value written
//! in the scene's `[run]` are refused alike or taken alike, for every
//! engine that takes them; values from the hostile set (zero, negative,
//! tiny, huge, NaN, infinite) and ordinary ones. A Python dict is the
//! scene's TOML (`dict_to_toml`), so it takes the scene's path.

use mote_front::{Input, RunOptions, Silent};

/// A point-particle scene (two bodies under gravity), a rigid one (a
/// free three-sphere body) and an event-driven one; `{run}` is their
/// `[run]` table's body.
const POINTS: &str =
    "seed = 1\n[run]\nintegrator = \"leapfrog\"\n{run}\n[gravity]\nsoftening = 0.0\n\
    [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\n\
    [[particle]]\nposition = [1.0, 0.0, 0.0]\nvelocity = [0.0, 1.0, 0.0]\nmass = 1e-6\n";
const RIGID: &str = "seed = 1\n[rigid]\n[[rigid.template]]\nname = \"bead\"\n\
    spheres = [[0.0, 0.0, 0.0, 1.0], [0.8, 0.3, 0.0, 0.6], [-0.2, 0.7, 0.5, 0.5]]\ndensity = 1.0\n\
    [[rigid.body]]\ntemplate = \"bead\"\nposition = [1.0, 2.0, 3.0]\nomega = [0.5, -0.3, 0.8]\n[run]\n{run}\n";
const HARD_SPHERES: &str =
    "seed = 1\n[box]\nhi = [1.0, 1.0, 1.0]\n[event_driven]\ndimension = 3\nn = 27\n\
    radius = 0.05\nplacement = \"cubic\"\nspeed = 1.0\n[run]\n{run}\n[output]\ninterval = 0.05\n";

/// The value as TOML writes it (`nan`, `inf`, `-inf`).
fn toml(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:?}")
    }
}

/// Whether the run was taken (it ran, stably or not) or refused, and the
/// message.
fn outcome(template: &str, run: &str, options: RunOptions) -> (bool, String) {
    let text = template.replace("{run}", run);
    let dir = tempfile::tempdir().unwrap();
    let input = Input::scene("s.toml", "s.toml", &text);
    let options = RunOptions {
        output: Some(dir.path().to_path_buf()),
        ..options
    };
    match mote_front::run_input(&input, &options, &mut Silent) {
        Ok(o) => (true, format!("{:?}", o.ending)),
        Err(e) => (false, e.to_string()),
    }
}

const HOSTILE: [f64; 9] = [
    0.0,
    -1.0,
    1e-300,
    f64::MIN_POSITIVE,
    1e300,
    f64::MAX,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];

fn assert_alike(what: &str, scene: (bool, String), option: (bool, String)) {
    assert_eq!(
        scene.0,
        option.0,
        "{what}: the scene {} it ({}), the option {} it ({})",
        if scene.0 { "took" } else { "refused" },
        scene.1,
        if option.0 { "took" } else { "refused" },
        option.1
    );
}

#[test]
fn a_time_step_is_refused_or_taken_alike_as_option_and_scene_key() {
    for template in [POINTS, RIGID] {
        for dt in HOSTILE.into_iter().chain([0.001, 0.01]) {
            let scene = outcome(
                template,
                &format!("dt = {}\nsteps = 10", toml(dt)),
                RunOptions::default(),
            );
            let option = outcome(
                template,
                "dt = 0.01\nsteps = 10",
                RunOptions {
                    dt: Some(dt),
                    ..RunOptions::default()
                },
            );
            let engine = &template[template.find('[').unwrap()..][..8];
            assert_alike(&format!("{engine}… dt = {dt:e}"), scene, option);
        }
    }
}

#[test]
fn an_end_time_is_refused_or_taken_alike_as_option_and_scene_key() {
    for (template, dt) in [
        (POINTS, "dt = 0.01\n"),
        (RIGID, "dt = 0.01\n"),
        (HARD_SPHERES, ""),
    ] {
        for until in HOSTILE.into_iter().chain([0.05, 0.2]) {
            let scene = outcome(
                template,
                &format!("{dt}until = {}", toml(until)),
                RunOptions::default(),
            );
            let option = outcome(
                template,
                &format!("{dt}until = 0.1"),
                RunOptions {
                    until: Some(until),
                    ..RunOptions::default()
                },
            );
            let engine = &template[template.find('[').unwrap()..][..8];
            assert_alike(&format!("{engine}… until = {until:e}"), scene, option);
        }
    }
}

#[test]
fn a_step_count_is_refused_or_taken_alike_as_option_and_scene_key() {
    for template in [POINTS, RIGID] {
        for steps in [0u64, 1, 10, 2_000_000_000, u64::MAX / 2] {
            let scene = outcome(
                template,
                &format!("dt = 1e-9\nsteps = {steps}"),
                RunOptions::default(),
            );
            let option = outcome(
                template,
                "dt = 1e-9\nsteps = 10",
                RunOptions {
                    steps: Some(steps),
                    ..RunOptions::default()
                },
            );
            let engine = &template[template.find('[').unwrap()..][..8];
            assert_alike(&format!("{engine}… steps = {steps}"), scene, option);
        }
    }
}

/// Every engine reads the one `[run]` table: a key an engine cannot take
/// is refused at its line with the reason, not read as something else
/// nor passed over.
#[test]
fn a_run_key_an_engine_cannot_take_is_refused_at_its_line() {
    let refused = |template: &str, run: &str| {
        let (taken, message) = outcome(template, run, RunOptions::default());
        assert!(!taken, "{run}: {message}");
        message
    };
    let line = |template: &str| template.lines().position(|l| l == "[run]").unwrap() + 2;
    let m = refused(RIGID, "integrator = \"rk4\"\ndt = 0.01\nsteps = 3");
    assert_eq!(
        m,
        format!(
            "s.toml:{}: [run] integrator: rigid bodies are moved by the FRBI only",
            line(RIGID)
        )
    );
    let m = refused(HARD_SPHERES, "dt = 0.01\nuntil = 1.0");
    assert!(
        m.starts_with(&format!(
            "s.toml:{}: [run] dt: event-driven dynamics jumps from collision to collision",
            line(HARD_SPHERES)
        )),
        "{m}"
    );
    let m = refused(POINTS, "dt = 0.01\nsteps = 3\nequilibrate = 1.0");
    assert!(
        m.starts_with(&format!(
            "s.toml:{}: [run] equilibrate: point particles are measured from the first step",
            line(POINTS) + 3
        )),
        "{m}"
    );
    let m = refused(RIGID, "dt = 0.01\nsteps = 3\nuntil = 1.0");
    assert_eq!(
        m,
        format!(
            "s.toml:{}: [run] takes steps or until, not both",
            line(RIGID) + 2
        )
    );
}

/// Every engine reads the one `[output]` table: the step counts of the
/// time-stepped engines, the time interval and file switches of the
/// event-driven one, a packing's folder and format; a key an engine cannot
/// take is refused at its line with the reason.
#[test]
fn an_output_key_an_engine_cannot_take_is_refused_at_its_line() {
    let refused = |text: &str| {
        let (taken, message) = outcome(text, "", RunOptions::default());
        assert!(!taken, "{text}: {message}");
        message
    };
    let line_of =
        |text: &str, key: &str| text.lines().position(|l| l.starts_with(key)).expect(key) + 1;
    let points = POINTS.replace("{run}", "dt = 0.01\nsteps = 3\n[output]\ninterval = 0.5");
    let m = refused(&points);
    assert!(
        m.starts_with(&format!(
            "s.toml:{}: [output] interval: a time-stepped run counts steps",
            line_of(&points, "interval")
        )),
        "{m}"
    );
    let hard = HARD_SPHERES
        .replace("{run}", "until = 0.5")
        .replace("[output]\n", "[output]\nobservables_every = 5\n");
    let m = refused(&hard);
    assert!(
        m.starts_with(&format!(
            "s.toml:{}: [output] observables_every: event-driven dynamics jumps",
            line_of(&hard, "observables_every")
        )),
        "{m}"
    );
    let rigid = RIGID.replace(
        "{run}",
        "dt = 0.01\nsteps = 3\n[output]\ninspect = [\"z[0]\"]",
    );
    let m = refused(&rigid);
    assert!(
        m.starts_with(&format!(
            "s.toml:{}: [output] inspect: it names point particles",
            line_of(&rigid, "inspect")
        )),
        "{m}"
    );
    let packing = "seed = 1\n[packing]\nn = 100\n[output]\ninterval = 1.0\n";
    assert!(
        refused(packing).starts_with("s.toml:5: [output] interval: a packing writes packing.xyz")
    );
    let packing = "seed = 1\n[packing]\nn = 100\n[run]\nuntil = 1.0\n";
    assert!(refused(packing).starts_with("s.toml:5: [run] until: a packing grows until it jams"));
}
