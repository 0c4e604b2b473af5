//! Circular choreographies (002 §4.3, Eq. 16, Table 1).

use crate::common;

use common::*;
use mote_md::init::choreography_speed;

/// N = 2…9 equal masses on a circle at the speed of Eq. 16 keep the radius
/// within 1 % for one orbit.
#[test]
fn rings_hold_their_radius_for_one_orbit() {
    for n in 2..=9 {
        let text = format!(
            r#"
units = "astro"
[run]
integrator = "rk4"
dt = 0.1
[gravity]
[[ring]]
n = {n}
orbit_radius = 1.0
speed = "choreography"
mass = 1.0
"#
        );
        let mut sim = build(&text).simulation;
        let k2 = mote_md::UnitSystem::Astro.gravitational_constant();
        let v = choreography_speed(n, k2, 1.0);
        assert!((sim.system.particles.velocity[0].length() - v).abs() < 1e-15);
        let period = 2.0 * std::f64::consts::PI / v;
        sim.dt = period / 4000.0;
        let mut worst = 0.0f64;
        steps(&mut sim, 4000, |s| {
            for r in &s.system.particles.position {
                worst = worst.max((r.length() - 1.0).abs());
            }
        });
        assert!(worst < 0.01, "N = {n}: radius strayed by {worst:.3e}");
        // After one period each body is back at its start (to 1 % of R).
        let back = (sim.system.particles.position[0] - mote_md::DVec3::X).length();
        assert!(
            back < 0.01,
            "N = {n}: body 0 is {back:.3e} from its start after one period"
        );
    }
}

/// With a wrong speed (10 % slow) the ring does not hold: the test above can fail.
#[test]
fn a_wrong_speed_breaks_the_ring() {
    let k2 = mote_md::UnitSystem::Astro.gravitational_constant();
    let v = 0.9 * choreography_speed(4, k2, 1.0);
    let text = format!(
        r#"
units = "astro"
[run]
integrator = "rk4"
dt = 0.1
[gravity]
[[ring]]
n = 4
orbit_radius = 1.0
speed = {v}
mass = 1.0
"#
    );
    let mut sim = build(&text).simulation;
    let period = 2.0 * std::f64::consts::PI / v;
    sim.dt = period / 4000.0;
    let mut worst = 0.0f64;
    steps(&mut sim, 4000, |s| {
        worst = worst.max((s.system.particles.position[0].length() - 1.0).abs())
    });
    assert!(worst > 0.05, "{worst}");
}
