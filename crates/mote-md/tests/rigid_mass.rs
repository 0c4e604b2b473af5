//! Mass properties of sphere unions by randomised quasi-Monte Carlo (seed
//! 000, "By stochastic integration we find the volume V, the mass m = ρV,
//! the center of mass x, … the moments of inertia"), against analytic
//! values: a sphere, two overlapping spheres (lens formula) and dumbbells.

use std::f64::consts::PI;

use glam::DVec3;
use mote_md::rigid::{
    dumbbell, mass_properties, principal, BodyTemplate, ClumpSpec, Integration, IrregularClump,
    TemplateError,
};

fn two_spheres(r1: f64, r2: f64, d: f64, density: f64) -> ClumpSpec {
    ClumpSpec {
        centres: vec![DVec3::ZERO, DVec3::new(d, 0.0, 0.0)],
        radii: vec![r1, r2],
        density,
        youngs_modulus: 0.0,
        poisson_ratio: 0.0,
        charge: 0.0,
        dipole: DVec3::ZERO,
    }
}

/// Reference by 1-D Gauss–Legendre quadrature of the axially symmetric
/// union of two spheres on the x axis (centres 0 and d): the cross-section
/// at x is a disk of radius ρ(x) = max of the two spheres' disks; the
/// integrals are split where ρ has kinks. Returns (V, x_c, I_axis, I_perp)
/// for unit density.
fn axisymmetric_reference(r1: f64, r2: f64, d: f64) -> (f64, f64, f64, f64) {
    let rho2 = |x: f64| {
        let a = (r1 * r1 - x * x).max(0.0);
        let b = (r2 * r2 - (x - d) * (x - d)).max(0.0);
        a.max(b)
    };
    // kink where both disks are equal: x² − r1² = (x − d)² − r2²
    let xk = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
    let mut breaks = vec![-r1, d - r2, xk, r1, d + r2];
    breaks.sort_by(f64::total_cmp);
    let lo = (-r1).min(d - r2);
    let hi = r1.max(d + r2);
    breaks.retain(|&b| b >= lo && b <= hi);
    breaks.dedup();
    // 20-point Gauss–Legendre on each of 200 sub-intervals per piece
    let (gx, gw) = gauss_legendre(20);
    let integrate = |f: &dyn Fn(f64) -> f64| {
        let mut s = 0.0;
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            let m = 200;
            let h = (b - a) / m as f64;
            for k in 0..m {
                let (c, half) = (a + (k as f64 + 0.5) * h, 0.5 * h);
                for (x, wt) in gx.iter().zip(&gw) {
                    s += wt * half * f(c + half * x);
                }
            }
        }
        s
    };
    let v = integrate(&|x| PI * rho2(x));
    let xc = integrate(&|x| PI * rho2(x) * x) / v;
    let i_axis = integrate(&|x| 0.5 * PI * rho2(x) * rho2(x));
    let i_perp = integrate(&|x| PI * rho2(x) * (0.25 * rho2(x) + (x - xc) * (x - xc)));
    (v, xc, i_axis, i_perp)
}

fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// |estimate − exact| within 4 standard errors (plus rounding).
fn within(what: &str, est: f64, exact: f64, sigma: f64) {
    let dev = (est - exact).abs();
    let tol = 4.0 * sigma + 1e-12 * exact.abs();
    eprintln!(
        "{what}: estimate {est:.12e} exact {exact:.12e} |dev| {dev:.2e} stated σ {sigma:.2e} (rel σ {:.1e})",
        sigma / exact.abs()
    );
    assert!(
        dev <= tol,
        "{what}: {est} vs {exact}: |dev| {dev:.3e} > 4σ = {:.3e}",
        4.0 * sigma
    );
}

#[test]
fn single_sphere_is_exact() {
    let (r, rho) = (0.7, 2500.0);
    let t = BodyTemplate::sphere(r, rho).unwrap();
    let p = t.props;
    let v = 4.0 / 3.0 * PI * r * r * r;
    within("sphere volume", p.volume, v, p.errors.volume);
    within("sphere mass", p.mass, rho * v, rho * p.errors.volume);
    for k in 0..3 {
        within(
            "sphere moment",
            p.moments[k],
            0.4 * rho * v * r * r,
            p.errors.moments[k],
        );
    }
    within("sphere area", p.area, 4.0 * PI * r * r, p.errors.area);
    assert!(p.centre.length() < 1e-15);
    assert!((p.bounding_radius - r).abs() < 1e-15);
    assert_eq!(p.errors.volume, 0.0, "no overlap, no sampling error");
}

#[test]
fn two_overlapping_spheres_lens() {
    let (r1, r2, d) = (1.0, 0.6, 1.1);
    let p = mass_properties(&two_spheres(r1, r2, d, 1.0), Integration::default());
    // lens volume: π (r1 + r2 − d)² (d² + 2d(r1 + r2) − 3(r1 − r2)²) / (12 d)
    let lens = PI * (r1 + r2 - d).powi(2) * (d * d + 2.0 * d * (r1 + r2) - 3.0 * (r1 - r2).powi(2))
        / (12.0 * d);
    let v = 4.0 / 3.0 * PI * (r1.powi(3) + r2.powi(3)) - lens;
    within("lens union volume", p.volume, v, p.errors.volume);
    let (vq, xc, ia, ip) = axisymmetric_reference(r1, r2, d);
    assert!(
        (vq - v).abs() < 1e-12 * v,
        "quadrature reference {vq} vs lens formula {v}"
    );
    within("lens union centre x", p.centre.x, xc, p.errors.centre);
    assert!(p.centre.y.abs() <= 4.0 * p.errors.centre + 1e-15);
    within("lens union I_axis", p.moments[0], ia, p.errors.moments[0]);
    within("lens union I_perp", p.moments[1], ip, p.errors.moments[1]);
    within("lens union I_perp", p.moments[2], ip, p.errors.moments[2]);
    assert!(
        p.axes[0].x.abs() > 1.0 - 1e-9,
        "symmetry axis along x: {:?}",
        p.axes
    );
    // area: caps cut off (cap height h = r − distance to the cut plane)
    let xk = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
    let area = 2.0 * PI * r1 * (r1 + xk) + 2.0 * PI * r2 * (r2 + (d - xk));
    within("lens union area", p.area, area, p.errors.area);
    assert!(p.errors.volume / v < 1e-3, "stated error is useful");
}

#[test]
fn dumbbells() {
    // disjoint: exact parallel-axis values, no sampling
    let (r, d, rho) = (0.5, 1.5, 3.0);
    let p = mass_properties(&dumbbell(r, d, rho), Integration::default());
    let ms = rho * 4.0 / 3.0 * PI * r.powi(3);
    within(
        "disjoint dumbbell mass",
        p.mass,
        2.0 * ms,
        p.errors.volume * rho,
    );
    within(
        "disjoint dumbbell I_axis",
        p.moments[0],
        2.0 * 0.4 * ms * r * r,
        p.errors.moments[0],
    );
    let ip = 2.0 * (0.4 * ms * r * r + ms * 0.25 * d * d);
    within(
        "disjoint dumbbell I_perp",
        p.moments[2],
        ip,
        p.errors.moments[2],
    );
    // overlapping dumbbell against the quadrature reference
    let d = 0.6;
    let p = mass_properties(&dumbbell(r, d, rho), Integration::default());
    let (v, _, ia, ip) = axisymmetric_reference(r, r, d);
    within("overlapping dumbbell volume", p.volume, v, p.errors.volume);
    within(
        "overlapping dumbbell I_axis",
        p.moments[0],
        rho * ia,
        p.errors.moments[0],
    );
    within(
        "overlapping dumbbell I_perp",
        p.moments[1],
        rho * ip,
        p.errors.moments[1],
    );
    within(
        "overlapping dumbbell I_perp",
        p.moments[2],
        rho * ip,
        p.errors.moments[2],
    );
    assert!(p.centre.length() <= 4.0 * p.errors.centre * 1.8 + 1e-15);
    // the bounding radius is exact about the estimated centre
    within(
        "bounding radius",
        p.bounding_radius,
        r + 0.5 * d,
        1.8 * p.errors.centre,
    );
}

/// The error estimate shrinks faster than Monte Carlo's N^−½ as the
/// number of directions grows, and the actual error follows it.
#[test]
fn error_estimate_shrinks() {
    let spec = two_spheres(1.0, 0.8, 0.9, 1.0);
    let (r1, r2, d) = (1.0f64, 0.8f64, 0.9f64);
    let lens = PI * (r1 + r2 - d).powi(2) * (d * d + 2.0 * d * (r1 + r2) - 3.0 * (r1 - r2).powi(2))
        / (12.0 * d);
    let v = 4.0 / 3.0 * PI * (r1.powi(3) + r2.powi(3)) - lens;
    let mut sig = Vec::new();
    for bits in [10, 14, 18] {
        let p = mass_properties(
            &spec,
            Integration {
                points: 1 << bits,
                ..Integration::default()
            },
        );
        eprintln!(
            "2^{bits} directions × 16 shifts: V error {:.2e}, stated σ {:.2e}",
            (p.volume - v).abs(),
            p.errors.volume
        );
        within("volume", p.volume, v, p.errors.volume);
        sig.push(p.errors.volume);
    }
    let rate = (sig[0] / sig[2]).log2() / 8.0;
    eprintln!("σ_V ∝ N^−{rate:.2} (Monte Carlo: N^−0.5)");
    assert!(rate > 0.6);
}

#[test]
fn principal_axes_positively_oriented() {
    let a = [[4.0, 1.0, 0.5], [1.0, 3.0, -0.2], [0.5, -0.2, 2.0]];
    let (vals, axes) = principal(&a);
    assert!(vals[0] <= vals[1] && vals[1] <= vals[2]);
    assert!((axes[0].cross(axes[1]) - axes[2]).length() < 1e-14);
    for k in 0..3 {
        let v = axes[k];
        let av = DVec3::new(
            a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z,
            a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
            a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z,
        );
        assert!((av - vals[k] * v).length() < 1e-13, "eigenpair {k}");
    }
}

#[test]
fn irregular_clumps_are_reproducible_and_sane() {
    let gen = IrregularClump::default();
    let (a, b) = (gen.generate(7), gen.generate(7));
    assert_eq!(a, b);
    assert_ne!(a, gen.generate(8));
    let t = BodyTemplate::new(&a, Integration::default()).unwrap();
    let p = t.props;
    eprintln!(
        "clump: V = {:.5} ± {:.1e}, θ = {:?} ± {:?}, A = {:.4} ± {:.1e}, R = {:.3}",
        p.volume,
        p.errors.volume,
        p.moments,
        p.errors.moments,
        p.area,
        p.errors.area,
        p.bounding_radius
    );
    // the union is inside its bounding sphere and contains the core
    assert!(p.volume > 4.0 / 3.0 * PI && p.volume < 4.0 / 3.0 * PI * p.bounding_radius.powi(3));
    assert!(p.errors.volume / p.volume < 1e-3);
    // centres recentred: Σ over the template of nothing — the CoM is the origin
    let moved: DVec3 = t
        .centres
        .iter()
        .zip(&a.centres)
        .map(|(c, o)| *o - *c)
        .sum::<DVec3>()
        / 10.0;
    assert!((moved - p.centre).length() < 1e-12);
}

#[test]
fn bad_specs_are_refused() {
    let mut s = two_spheres(1.0, 1.0, 1.0, 1.0);
    s.radii.pop();
    assert_eq!(
        BodyTemplate::new(&s, Integration::default()).unwrap_err(),
        TemplateError::Mismatch {
            centres: 2,
            radii: 1
        }
    );
    let mut s = two_spheres(1.0, -1.0, 1.0, 1.0);
    assert!(matches!(
        BodyTemplate::new(&s, Integration::default()),
        Err(TemplateError::Radius { index: 1, .. })
    ));
    s.radii[1] = 1.0;
    s.density = 0.0;
    let e = BodyTemplate::new(&s, Integration::default()).unwrap_err();
    assert_eq!(e.to_string(), "density 0 must be positive and finite");
}
