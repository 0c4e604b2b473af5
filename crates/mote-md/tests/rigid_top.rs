//! Torque-free rigid bodies under the FRBI (seed 000): the precession of a
//! symmetric top at ω₃(I₃ − I₁)/I₁, and the intermediate-axis (Dzhanibekov)
//! flip of an asymmetric top while rotation about the major and minor axes
//! stays stable.

use std::f64::consts::PI;

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::{
    BodyTemplate, ClumpSpec, Frbi, MassErrors, MassProperties, RigidBodies, SpinUpdate,
};

/// A body with given principal moments about the initial frame's axes.
fn body(moments: [f64; 3], omega_body: DVec3) -> RigidBodies {
    let spec = ClumpSpec {
        centres: vec![DVec3::ZERO],
        radii: vec![1.0],
        density: 1.0,
        youngs_modulus: 0.0,
        poisson_ratio: 0.0,
        charge: 0.0,
        dipole: DVec3::ZERO,
    };
    let props = MassProperties {
        volume: 1.0,
        mass: 1.0,
        centre: DVec3::ZERO,
        moments,
        axes: [DVec3::X, DVec3::Y, DVec3::Z],
        area: 0.0,
        bounding_radius: 1.0,
        errors: MassErrors::default(),
    };
    let t = BodyTemplate::with_properties(&spec, props).unwrap();
    let mut b = RigidBodies::new();
    let k = b.add_template(t);
    // a tilted start, so body and master frames differ
    let g = E::rotation(mote_geom::from_axis_angle(
        DVec3::new(1.0, 2.0, -0.5).normalize(),
        0.9,
    ));
    b.push(
        k,
        g,
        DE::new(
            mote_geom::rotate(omega_body, g.r),
            DVec3::new(0.1, 0.0, 0.0),
        ),
    );
    b
}

/// Rate of the body-frame ω about e₃, by unwrapping its azimuth.
fn precession_rate(dt: f64, t_end: f64, spin: SpinUpdate) -> f64 {
    let (i1, i3) = (1.0, 1.5);
    let w3 = 2.0;
    let mut b = body([i1, i1, i3], DVec3::new(0.3, 0.0, w3));
    let mut frbi = Frbi::new();
    frbi.spin = spin;
    let steps = (t_end / dt).round() as usize;
    let mut total = 0.0;
    let mut last = 0.0f64;
    for _ in 0..steps {
        frbi.step(&mut b, dt);
        let w = b.body_omega(0);
        let phi = w.y.atan2(w.x);
        let mut d = phi - last;
        if d > PI {
            d -= 2.0 * PI;
        } else if d < -PI {
            d += 2.0 * PI;
        }
        total += d;
        last = phi;
    }
    total / (steps as f64 * dt)
}

#[test]
fn symmetric_top_precession() {
    let exact = 2.0 * (1.5 - 1.0) / 1.0; // ω₃(I₃ − I₁)/I₁
    let mut fine = Vec::new();
    for spin in [SpinUpdate::KeepMomentum, SpinUpdate::Seed] {
        let mut errs = Vec::new();
        for dt in [1e-3, 5e-4, 2.5e-4] {
            let rate = precession_rate(dt, 4.0 * PI, spin);
            let rel = (rate - exact).abs() / exact;
            eprintln!("{spin:?} dt = {dt:.1e}: rate {rate:.12} exact {exact} rel err {rel:.2e}");
            errs.push(rel);
        }
        let order = (errs[0] / errs[2]).log2() / 2.0;
        eprintln!("{spin:?}: observed order {order:.2}");
        fine.push((spin, order));
    }
    // a fine step for each: the seed's update is first order in the rate
    for (spin, dt) in [(SpinUpdate::KeepMomentum, 2.5e-4), (SpinUpdate::Seed, 2e-5)] {
        let rate = precession_rate(dt, 4.0 * PI, spin);
        let rel = (rate - exact).abs() / exact;
        eprintln!("{spin:?} fine dt = {dt:.1e}: rel err {rel:.2e}");
        assert!(rel < 1e-6, "{spin:?}: {rel:.2e} at dt = {dt}");
    }
    let _ = fine;
}

/// Largest |ω_b − ω_b(0)| component off the spin axis, and the smallest
/// spin component, over a run.
fn spin_about(axis: usize, t_end: f64) -> (f64, f64) {
    let eps = 1e-3;
    let mut w0 = DVec3::splat(eps);
    w0[axis] = 1.0;
    let mut b = body([1.0, 2.0, 3.0], w0);
    let mut frbi = Frbi::seed_literal();
    let dt = 1e-3;
    let (mut off, mut min_spin) = (0.0f64, f64::INFINITY);
    for _ in 0..(t_end / dt) as usize {
        frbi.step(&mut b, dt);
        let w = b.body_omega(0);
        for k in 0..3 {
            if k != axis {
                off = off.max(w[k].abs());
            }
        }
        min_spin = min_spin.min(w[axis]);
    }
    (off, min_spin)
}

#[test]
fn dzhanibekov_flip() {
    let (off_min, spin_min) = spin_about(0, 60.0);
    let (off_int, spin_int) = spin_about(1, 60.0);
    let (off_max, spin_max) = spin_about(2, 60.0);
    eprintln!("minor axis: max off-axis {off_min:.2e}, min spin {spin_min:.4}");
    eprintln!("intermediate axis: max off-axis {off_int:.2e}, min spin {spin_int:.4}");
    eprintln!("major axis: max off-axis {off_max:.2e}, min spin {spin_max:.4}");
    // about the intermediate axis the spin reverses
    assert!(spin_int < -0.9, "no flip: min spin {spin_int}");
    // about the minor and major axes it stays, perturbations stay small
    assert!(spin_min > 0.99 && off_min < 1e-2);
    assert!(spin_max > 0.99 && off_max < 1e-2);
}

/// Torque-free: linear momentum is kept exactly; energy to O(dt²); the
/// angular momentum exactly with `KeepMomentum` and with a drift ∝ dt with
/// the seed's spin update.
#[test]
fn free_body_conservation() {
    let run = |spin: SpinUpdate, dt: f64| {
        let mut b = body([1.0, 2.0, 3.0], DVec3::new(0.4, 1.0, -0.7));
        let o0 = b.observables();
        let mut frbi = Frbi::new();
        frbi.spin = spin;
        for _ in 0..(20.0 / dt).round() as usize {
            frbi.step(&mut b, dt);
        }
        let o = b.observables();
        assert_eq!(o.linear_momentum, o0.linear_momentum);
        let de = (o.kinetic_energy() - o0.kinetic_energy()).abs() / o0.kinetic_energy();
        let dl = (o.angular_momentum - o0.angular_momentum).length() / o0.angular_momentum.length();
        eprintln!("{spin:?} free asymmetric body, t = 20, dt = {dt}: |ΔE|/E = {de:.2e}, |ΔL|/|L| = {dl:.2e}");
        (de, dl)
    };
    // rounding only: at most 1e-15 relative per step (2·10⁴ steps)
    let (de, dl) = run(SpinUpdate::KeepMomentum, 1e-3);
    assert!(de < 1e-5 && dl < 2e-11);
    let (de1, dl1) = run(SpinUpdate::Seed, 2e-3);
    let (de2, dl2) = run(SpinUpdate::Seed, 1e-3);
    let order = (dl1 / dl2).log2();
    eprintln!("Seed: |ΔL| order {order:.2}");
    assert!(de1 < 1e-5 && de2 < 1e-5);
    assert!((0.8..1.2).contains(&order));
}
