//! Property tests of Mutze's Euclidean algebra (seed 000): group axioms, the
//! consistency of the rotation-vector product with its action, exp and log,
//! and the adjoint action.

use std::f64::consts::PI;

use mote_geom::{compose_rotations, rotate, Act, Inertia, Point, DE, E};
use proptest::prelude::*;

const PTS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.3, -2.0, 0.7],
    [-1.5, 0.4, 2.5],
];

fn v3(a: [f64; 3]) -> glam::DVec3 {
    glam::DVec3::from_array(a)
}

/// Two placements are the same transformation: they move four affinely
/// independent points to the same places (rotation vectors near π are
/// ill-conditioned as numbers, the transformation is not).
fn same_transformation(g: E, h: E, tol: f64) -> Result<(), TestCaseError> {
    for p in PTS {
        let (a, b) = (g.apply_point(v3(p)), h.apply_point(v3(p)));
        let scale = 1.0 + a.length().max(b.length());
        prop_assert!(
            (a - b).length() <= tol * scale,
            "{g:?} vs {h:?}: point {p:?} -> {a} vs {b}"
        );
    }
    Ok(())
}

fn unit_vector() -> impl Strategy<Value = glam::DVec3> {
    (0.0..1.0f64, 0.0..1.0f64).prop_map(|(u, w)| {
        let z = 2.0 * u - 1.0;
        let s = (1.0 - z * z).sqrt();
        let phi = 2.0 * PI * w;
        glam::DVec3::new(s * phi.cos(), s * phi.sin(), z)
    })
}

/// Rotation angles in [0, π], with a quarter of them within 1e-12…1e-2 of
/// π and some exactly π (r = n·tan(π/2) ≈ n·1.6e16) or exactly 0.
fn angle() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => 0.0..PI,
        2 => (2.0..12.0f64).prop_map(|k| PI - 10f64.powf(-k)),
        1 => Just(PI),
        1 => Just(0.0),
    ]
}

fn rotation() -> impl Strategy<Value = glam::DVec3> {
    (unit_vector(), angle()).prop_map(|(n, phi)| mote_geom::from_axis_angle(n, phi))
}

fn vector(scale: f64) -> impl Strategy<Value = glam::DVec3> {
    (-scale..scale, -scale..scale, -scale..scale).prop_map(|(x, y, z)| glam::DVec3::new(x, y, z))
}

fn placement() -> impl Strategy<Value = E> {
    (rotation(), vector(5.0)).prop_map(|(r, a)| E::new(r, a))
}

fn velocity() -> impl Strategy<Value = DE> {
    (vector(2.0), vector(3.0)).prop_map(|(w, v)| DE::new(w, v))
}

fn close_de(a: DE, b: DE, tol: f64) -> Result<(), TestCaseError> {
    let scale = 1.0 + a.omega.length() + a.v.length();
    prop_assert!(
        (a.omega - b.omega).length() <= tol * scale && (a.v - b.v).length() <= tol * scale,
        "{a:?} vs {b:?}"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn associativity(g1 in placement(), g2 in placement(), g3 in placement()) {
        same_transformation((g1 * g2) * g3, g1 * (g2 * g3), 1e-13)?;
    }

    #[test]
    fn unit_and_inverse(g in placement()) {
        same_transformation(g * E::IDENTITY, g, 1e-15)?;
        same_transformation(E::IDENTITY * g, g, 1e-15)?;
        same_transformation(g * g.inverse(), E::IDENTITY, 1e-14)?;
        same_transformation(g.inverse() * g, E::IDENTITY, 1e-14)?;
    }

    /// `x * (r₁ ∘ r₂) = (x * r₁) * r₂` (seed 000).
    #[test]
    fn rotation_product_consistent(r1 in rotation(), r2 in rotation(), x in vector(3.0)) {
        let a = rotate(x, compose_rotations(r1, r2));
        let b = rotate(rotate(x, r1), r2);
        prop_assert!((a - b).length() <= 1e-14 * (1.0 + x.length()), "{a} vs {b}");
        // and the action is a rotation: it keeps lengths
        prop_assert!((rotate(x, r1).length() - x.length()).abs() <= 1e-15 * (1.0 + x.length()));
    }

    /// `(y ∘ g₁) ∘ g₂ = y ∘ (g₁ ∘ g₂)` for points (the Erlangen property).
    #[test]
    fn point_action(g1 in placement(), g2 in placement(), y in vector(3.0)) {
        let a = Point(y).act(g1).act(g2).0;
        let b = Point(y).act(g1 * g2).0;
        prop_assert!((a - b).length() <= 1e-13 * (1.0 + a.length()));
    }

    /// `exp(log g) = g` for every g, rotations by π included.
    #[test]
    fn exp_of_log(g in placement()) {
        same_transformation(g.log().exp(1.0), g, 1e-13)?;
    }

    /// `exp(hτ) ∘ exp(hτ') = exp(h(τ + τ'))`.
    #[test]
    fn one_parameter_subgroup(h in velocity(), t1 in -2.0..2.0f64, t2 in -2.0..2.0f64) {
        same_transformation(h.exp(t1) * h.exp(t2), h.exp(t1 + t2), 1e-13)?;
    }

    /// `log(exp(hτ)) = hτ` while |ω|τ < π.
    #[test]
    fn log_of_exp(h in velocity(), t in 0.0..1.0f64) {
        prop_assume!(h.omega.length() * t < 3.1);
        close_de(h.exp(t).log(), h * t, 1e-12)?;
    }

    /// exp is the flow of the field y ↦ v + ω × y: compare with RK4.
    #[test]
    fn exp_is_the_flow(h in velocity(), y0 in vector(2.0)) {
        let n = 2000;
        let dt = 1.0 / n as f64;
        let f = |y: glam::DVec3| h.v + h.omega.cross(y);
        let mut y = y0;
        for _ in 0..n {
            let k1 = f(y);
            let k2 = f(y + 0.5 * dt * k1);
            let k3 = f(y + 0.5 * dt * k2);
            let k4 = f(y + dt * k3);
            y += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        let e = h.exp(1.0).apply_point(y0);
        prop_assert!((e - y).length() <= 1e-10 * (1.0 + y.length()), "{e} vs {y}");
    }

    /// The adjoint action: `exp(h ∘ g) = g⁻¹ ∘ exp(h) ∘ g`, it is an action,
    /// and it respects the Lie bracket.
    #[test]
    fn adjoint_action(h in velocity(), k in velocity(), g1 in placement(), g2 in placement()) {
        same_transformation(h.act(g1).exp(1.0), g1.inverse() * h.exp(1.0) * g1, 1e-12)?;
        close_de(h.act(g1).act(g2), h.act(g1 * g2), 1e-12)?;
        close_de(h.bracket(k).act(g1), h.act(g1).bracket(k.act(g1)), 1e-11)?;
    }

    /// The co-adjoint action keeps the pairing: ⟨p ∘ g, h ∘ g⟩ = ⟨p, h⟩
    /// (power and kinetic energy do not depend on the frame).
    #[test]
    fn coadjoint_pairing(h in velocity(), p in velocity(), g in placement()) {
        let a = p.act_momentum(g).pair(h.act(g));
        let b = p.pair(h);
        prop_assert!((a - b).abs() <= 1e-11 * (1.0 + a.abs()));
    }

    /// `I⁻¹ * (I * h) = h`; `(I ∘ g) * (h ∘ g) = (I * h) ∘ g` for rotations.
    #[test]
    fn inertia(h in velocity(), r in rotation(), m in (0.1..5.0f64, 0.1..5.0f64, 0.1..5.0f64, 0.1..5.0f64)) {
        let axes = [glam::DVec3::X, glam::DVec3::Y, glam::DVec3::Z]
            .map(|a| rotate(a, glam::DVec3::new(0.3, -0.2, 0.5)));
        let i = Inertia::new([m.0, m.1, m.2], axes, m.3);
        close_de(i.inverse() * (i * h), h, 1e-14)?;
        let g = E::rotation(r);
        close_de(i.act(g) * h.act(g), (i * h).act(g), 1e-13)?;
    }
}

/// `exp(dE(ω, v)·τ) = E(ω·τ/2, v·τ) + O(τ²)` and `log E(r, x) = dE(2r, x) +
/// O(|r|²)` (seed 000).
#[test]
fn first_order_forms() {
    let h = DE::new(
        glam::DVec3::new(0.3, -1.2, 0.8),
        glam::DVec3::new(1.0, 2.0, -0.5),
    );
    for tau in [1e-2, 1e-3, 1e-4] {
        let g = h.exp(tau);
        let err = (g.r - h.omega * tau / 2.0).length() + (g.a - h.v * tau).length();
        assert!(err < 2.0 * tau * tau, "τ={tau}: {err}");
        let l = E::new(h.omega * tau, h.v * tau).log();
        let err = (l.omega - 2.0 * h.omega * tau).length() + (l.v - h.v * tau).length();
        assert!(err < 5.0 * tau * tau, "τ={tau}: {err}");
    }
}

/// The ε rule: two rotations by π/2 about the same axis multiply to a
/// rotation by π (s = 1 − 1 = 0 exactly) and still act correctly.
#[test]
fn epsilon_rule_at_pi() {
    let r = glam::DVec3::Z; // tan(π/4) = 1: a quarter turn about z
    let rr = compose_rotations(r, r);
    assert!(rr.is_finite());
    let x = rotate(glam::DVec3::X, rr);
    assert!((x + glam::DVec3::X).length() < 1e-11, "{x}");
    let back = compose_rotations(rr, -r);
    assert!((rotate(glam::DVec3::Y, back) - rotate(glam::DVec3::Y, r)).length() < 1e-11);
}

/// The seed prints the action of E on dE as `dE(ω * r, v * r + (ω * r) × x)`.
/// With the seed's point action and exp that sign carries a rotation about
/// the origin to a rotation about −x, not x; `DE::act` uses `x × (ω * r)`.
/// This test documents the difference with one example.
#[test]
fn printed_sign_of_the_adjoint_action() {
    let h = DE::new(glam::DVec3::Z, glam::DVec3::ZERO); // spin about the origin
    let g = E::translation(glam::DVec3::X); // move by x̂
    let moved = h.act(g);
    // the spin now turns about x̂: x̂ itself stays put
    assert!(
        moved
            .exp(0.7)
            .apply_point(glam::DVec3::X)
            .distance(glam::DVec3::X)
            < 1e-15
    );
    let w = rotate(h.omega, g.r);
    let printed = DE::new(w, rotate(h.v, g.r) + w.cross(g.a));
    assert!(
        printed
            .exp(0.7)
            .apply_point(-glam::DVec3::X)
            .distance(-glam::DVec3::X)
            < 1e-15
    );
}
