//! Property test over rigid scene values, as `scene_values` does for point
//! particles: valid values with up to two replaced by numbers a careless or
//! hostile user writes give bodies that step, or a `file:line: message`
//! error — never a panic — within a few seconds. It found a placement
//! region of 1.8e308 panicking in the uniform draw, 1 000 lobes taking most
//! of an hour to integrate and 10¹² lobes aborting on 40 TB (all refused at
//! their table now; tests in `rigid_scene`).

use proptest::prelude::*;

use crate::common::hostile;

use mote_md::rigid::run::RigidDynamics;
use mote_md::rigid::scene::RigidScene;
use mote_run::Propagator;

/// dt, radius, density, young, poisson, restitution, friction, g_z,
/// box side, placement top, body count, lobes.
fn valid() -> Vec<std::ops::Range<f64>> {
    vec![
        2e-6..8e-6,
        0.8e-3..1.2e-3,
        1000.0..3000.0,
        5e6..2e7,
        0.2..0.4,
        0.2..0.8,
        0.3..0.6,
        -12.0..-8.0,
        11e-3..14e-3,
        8e-3..10e-3,
        3.0..12.0,
        3.0..9.0,
    ]
}

/// The lobe count's own hostile values: none, negative, huge (refused),
/// and a few hundred (refused by its cost; between 40 and 150 a build is
/// legitimately slow, up to a minute, and not for a property test).
fn hostile_lobes() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(1e300),
        Just(1e12),
        Just(1000.0),
        Just(1.0),
        0.0..12.0f64,
    ]
}

fn values() -> impl Strategy<Value = Vec<f64>> {
    (
        valid(),
        prop::collection::vec((0..11usize, hostile()), 0..3),
        prop::option::of(hostile_lobes()),
    )
        .prop_map(|(mut v, bad, lobes)| {
            for (i, x) in bad {
                v[i] = x;
            }
            if let Some(l) = lobes {
                v[11] = l;
            }
            v
        })
}

/// An integer key: the nearest integer where TOML holds one, else the
/// float itself (refused by type).
fn int(x: f64) -> String {
    if x.abs() < 9e18 {
        format!("{}", x.round() as i64)
    } else {
        format!("{x:?}")
    }
}

fn scene(v: &[f64]) -> String {
    format!(
        "seed = 7\n[rigid]\n\
         [[rigid.template]]\nname = \"bead\"\ngenerator = \"irregular\"\nradius = {:?}\nlobes = {}\nseed = 1\ndensity = {:?}\n\
         [[rigid.random]]\ntemplate = \"bead\"\nn = {}\nlo = [2e-3, 2e-3, 2e-3]\nhi = [{:?}, {:?}, {:?}]\n\
         [rigid.fields]\ngravity = [0.0, 0.0, {:?}]\n\
         [rigid.contacts]\nyoung = {:?}\npoisson = {:?}\nrestitution = {:?}\nfriction = {:?}\n\
         [[rigid.wall]]\nkind = \"box\"\nname = \"box\"\nlo = [0.0, 0.0, 0.0]\nhi = [{:?}, {:?}, 30e-3]\n\
         [run]\ndt = {:?}\nsteps = 3\n",
        v[1], int(v[11]), v[2], int(v[10]), v[9], v[9], v[9], v[7], v[3], v[4], v[5], v[6], v[8], v[8], v[0]
    )
}

proptest! {
    // 64 scenes in the suite (each integrates its template: ~0.13 s a
    // scene); MOTE_RIGID_CASES=1000 for a longer search.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("MOTE_RIGID_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64),
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_numbers_step_or_are_refused_at_a_line(v in values()) {
        let text = scene(&v);
        let t0 = std::time::Instant::now();
        let outcome = std::panic::catch_unwind(|| {
            let scene = RigidScene::parse(&text, "s.toml")?;
            let built = scene.build(&text, "s.toml", Some(7))?;
            let mut dynamics = RigidDynamics::new(built);
            for _ in 0..3 {
                // a state that went non-finite is reported, not a panic
                if dynamics.advance().is_err() || dynamics.unstable().is_some() {
                    break;
                }
            }
            Ok::<(), mote_io::ParseError>(())
        });
        prop_assert!(t0.elapsed().as_secs_f64() < 5.0, "{:.1} s on\n{text}", t0.elapsed().as_secs_f64());
        match outcome {
            Err(_) => prop_assert!(false, "panicked on\n{text}"),
            Ok(Err(e)) => prop_assert!(e.to_string().starts_with("s.toml:"), "{e}\non\n{text}"),
            Ok(Ok(())) => {}
        }
    }
}
