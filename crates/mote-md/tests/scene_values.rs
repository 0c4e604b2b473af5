//! Property test over scene values: valid values with up to two replaced
//! by numbers a careless or hostile user writes (huge, tiny, negative,
//! zero) give a built simulation or a
//! `file:line: message` error — never a panic — and a few steps of what
//! builds end in numbers or in the engine's instability report, never a
//! panic either.

use proptest::prelude::*;

use crate::common::hostile;

use mote_md::scene::Scene;

/// A scene whose numeric keys are filled from `v` (ten numbers).
fn scene(v: &[f64]) -> String {
    format!(
        "units = \"lj\"\nseed = 3\n[run]\ndt = {:?}\nsteps = 3\n\
         [box]\nlo = [0.0, 0.0, 0.0]\nhi = [{:?}, 6.0, 6.0]\nperiodic = [true, true, true]\n\
         [lennard_jones]\nepsilon = {:?}\nsigma = {:?}\ncutoff = {:?}\nskin = {:?}\n\
         [thermostat]\nkind = \"langevin\"\ngamma = {:?}\nkt = {:?}\n\
         [[random_box]]\nn = 20\nmin = [0.0, 0.0, 0.0]\nmax = [5.0, 5.0, 5.0]\nmass = {:?}\nradius = {:?}\n",
        v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]
    )
}

/// Values every key takes: dt, the box side, ε, σ, r_c, skin, γ, k_BT, mass, radius.
fn valid() -> Vec<std::ops::Range<f64>> {
    vec![
        0.001..0.005,
        5.8..8.0,
        0.5..2.0,
        0.8..1.2,
        2.0..2.5,
        0.1..0.4,
        0.1..2.0,
        0.1..2.0,
        0.5..2.0,
        0.0..0.5,
    ]
}

/// Valid values with up to two of them replaced by hostile ones.
fn values() -> impl Strategy<Value = Vec<f64>> {
    (
        valid(),
        prop::collection::vec((0..10usize, hostile()), 0..3),
    )
        .prop_map(|(mut v, bad)| {
            for (i, x) in bad {
                v[i] = x;
            }
            v
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn any_numbers_build_or_are_refused_at_a_line(v in values()) {
        let text = scene(&v);
        let t0 = std::time::Instant::now();
        let outcome = std::panic::catch_unwind(|| {
            let scene = Scene::parse(&text, "s.toml")?;
            let mut built = scene.build(&text, "s.toml", 3)?;
            let sim = &mut built.simulation;
            for _ in 0..3 {
                sim.stepper.step(&mut sim.system, &mut sim.forces, sim.dt);
            }
            Ok::<(), mote_io::ParseError>(())
        });
        // A cut-off and skin of 1e-300 once asked for 10⁹ cells (20 s a build).
        prop_assert!(t0.elapsed().as_secs_f64() < 5.0, "{:.1} s on\n{text}", t0.elapsed().as_secs_f64());
        match outcome {
            Err(_) => prop_assert!(false, "panicked on\n{text}"),
            Ok(Err(e)) => prop_assert!(e.to_string().starts_with("s.toml:"), "{e}"),
            Ok(Ok(())) => {}
        }
    }
}
