//! A mass on a damped spring (002 Eq. 3) against the analytic solutions of
//! the under-, critically and over-damped oscillator.

use crate::common;

use common::*;

/// Particle 0 fixed at the origin, particle 1 (mass m) on a spring of rest
/// length 1 along x, displaced by q0, free along x only.
fn oscillator(m: f64, d: f64, c: f64, q0: f64) -> mote_md::Simulation {
    let text = format!(
        r#"
[run]
integrator = "rk4"
dt = 1e-3
[[particle]]
position = [0.0, 0.0, 0.0]
free = [false, false, false]
[[particle]]
position = [1.0, 0.0, 0.0]
displacement = [{q0}, 0.0, 0.0]
mass = {m}
free = [true, false, false]
[[spring]]
pairs = [[0, 1]]
stiffness = {d}
damping = {c}
"#
    );
    build(&text).simulation
}

/// q(t) of m q̈ + c q̇ + D q = 0 with q(0) = q0, q̇(0) = 0.
fn analytic(m: f64, d: f64, c: f64, q0: f64, t: f64) -> f64 {
    let gamma = c / (2.0 * m);
    let w0 = (d / m).sqrt();
    if (gamma - w0).abs() < 1e-12 * w0 {
        (q0 + gamma * q0 * t) * (-gamma * t).exp()
    } else if gamma < w0 {
        let w = (w0 * w0 - gamma * gamma).sqrt();
        (-gamma * t).exp() * (q0 * (w * t).cos() + gamma * q0 / w * (w * t).sin())
    } else {
        let s = (gamma * gamma - w0 * w0).sqrt();
        let (r1, r2) = (-gamma + s, -gamma - s);
        let a = -r2 * q0 / (r1 - r2);
        let b = r1 * q0 / (r1 - r2);
        a * (r1 * t).exp() + b * (r2 * t).exp()
    }
}

#[test]
fn damped_oscillator_matches_analytic_solutions() {
    let (m, d, q0): (f64, f64, f64) = (2.0, 50.0, 0.1);
    let critical = 2.0 * (m * d).sqrt();
    for (regime, c) in [
        ("underdamped", 0.1 * critical),
        ("critically damped", critical),
        ("overdamped", 3.0 * critical),
    ] {
        let mut sim = oscillator(m, d, c, q0);
        let mut worst = 0.0f64;
        steps(&mut sim, 10_000, |s| {
            let q = s.system.particles.position[1].x - 1.0;
            worst = worst.max((q - analytic(m, d, c, q0, s.system.time)).abs());
        });
        assert!(worst < 1e-7, "{regime}: max error {worst:.3e}");
        let p = &sim.system.particles;
        assert_eq!(p.position[0], mote_md::DVec3::ZERO, "the fixed end moved");
        assert_eq!(p.position[1].y, 0.0);
    }
}

/// An undamped spring conserves energy; leap-frog keeps it bounded.
#[test]
fn undamped_spring_conserves_energy() {
    let mut sim = oscillator(1.0, 10.0, 0.0, 0.2);
    sim.stepper = mote_md::Stepper::new(mote_md::Integrator::LeapFrog);
    let e0 = mote_md::Observables::measure(&sim.system, &mut sim.forces).total_energy();
    let mut worst = 0.0f64;
    steps(&mut sim, 20_000, |s| worst = worst.max(energy_error(s, e0)));
    // Leap-frog's energy error on an oscillator is ≈ (ωh)²/4 ≈ 2.5e-6 here.
    assert!(worst < 5e-6, "{worst:.3e}");
}
