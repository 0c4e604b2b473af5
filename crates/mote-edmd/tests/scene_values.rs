//! Property test over event-driven scene values: valid values with up to
//! two replaced by numbers a careless or hostile user writes give a system
//! that runs, or a `file:line: message` error — never a panic — within a
//! few seconds.
//!
//! Ignored for now: it found a box too small for the spheres refused
//! without a line and 24 GB asked for empty placement cells (both fixed,
//! with tests in `scene.rs`), and then a case that runs for more than ten
//! minutes, not yet found (issue 37). Run it with
//! `cargo test -p mote-edmd --test edmd scene_values:: -- --ignored`.

use proptest::prelude::*;

use mote_edmd::scene::Scene;
use mote_edmd::EdmdError;

/// n, packing_fraction, radius, mass, temperature, size_ratio, large_fraction.
fn valid() -> Vec<std::ops::Range<f64>> {
    vec![
        20.0..60.0,
        0.05..0.3,
        0.2..1.0,
        0.5..2.0,
        0.5..2.0,
        1.0..1.4,
        0.0..0.5,
    ]
}

fn hostile() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(1e-300),
        Just(1e300),
        Just(f64::MIN_POSITIVE),
        Just(f64::MAX),
        -1e3..1e3f64,
    ]
}

fn values() -> impl Strategy<Value = Vec<f64>> {
    (valid(), prop::collection::vec((0..7usize, hostile()), 0..3)).prop_map(|(mut v, bad)| {
        for (i, x) in bad {
            v[i] = x;
        }
        v
    })
}

fn scene(v: &[f64]) -> String {
    // `n` is an integer key: written as the nearest integer where TOML
    // holds one, else as the float itself (refused by type).
    let n = if v[0].abs() < 9e18 {
        format!("{}", v[0].round() as i64)
    } else {
        format!("{:?}", v[0])
    };
    format!(
        "seed = 5\n[event_driven]\ndimension = 3\nn = {n}\npacking_fraction = {:?}\nradius = {:?}\nmass = {:?}\n\
         temperature = {:?}\nsize_ratio = {:?}\nlarge_fraction = {:?}\nplacement = \"random\"\n\
         [run]\nuntil = 0.5\n",
        v[1], v[2], v[3], v[4], v[5], v[6]
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    #[ignore = "a case runs for more than ten minutes (issue 37)"]
    fn any_numbers_run_or_are_refused_at_a_line(v in values()) {
        let text = scene(&v);
        let t0 = std::time::Instant::now();
        let outcome = std::panic::catch_unwind(|| {
            let scene = Scene::parse(&text, "s.toml")?;
            let mut system = scene.build::<3>(5, std::path::Path::new("."))?;
            system.run_until(0.5);
            Ok::<(), EdmdError>(())
        });
        prop_assert!(t0.elapsed().as_secs_f64() < 5.0, "{:.1} s on\n{text}", t0.elapsed().as_secs_f64());
        match outcome {
            Err(_) => prop_assert!(false, "panicked on\n{text}"),
            Ok(Err(e)) => prop_assert!(e.to_string().starts_with("s.toml:"), "{e}\non\n{text}"),
            Ok(Ok(())) => {}
        }
    }
}
