//! The dipole–dipole interaction (004 Eq. 8), WCA (Eq. 9) and the Zeeman
//! energy (Eq. 10): textbook pair energies, forces = −∇U, torques = the
//! derivative of U under rotation, Newton's third law for forces and for
//! angular momentum, and the equivalence of the summation modes.

use std::f64::consts::PI;

use mote_md::boundary::Boundary;
use mote_md::force::dipolar::{
    vacuum_permeability, AppliedField, DipoleDipole, PairRepulsion, Zeeman,
};
use mote_md::integrate::rotate;
use mote_md::units::UnitSystem;
use mote_md::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn mu0() -> f64 {
    vacuum_permeability(UnitSystem::Si).unwrap()
}

/// (energy, forces, torques) of a configuration.
fn evaluate(dd: &mut DipoleDipole, pos: &[DVec3], m: &[DVec3]) -> (f64, Vec<DVec3>, Vec<DVec3>) {
    let mut f = vec![DVec3::ZERO; pos.len()];
    let mut t = vec![DVec3::ZERO; pos.len()];
    dd.forces_and_torques(pos, m, &mut f, &mut t);
    (dd.energy(pos, m), f, t)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(f64::MIN_POSITIVE)
}

/// Two magnetite-like nanoparticles: m = 2.5e-19 A m² (a 10 nm core), 12 nm apart.
#[test]
fn two_dipoles_textbook_energies_and_force_signs() {
    let m = 2.5e-19;
    let r: f64 = 12e-9;
    let unit = mu0() * m * m / (4.0 * PI * r.powi(3));
    let x = DVec3::X;
    let z = DVec3::Z;
    // (name, m_0, m_1, expected energy / unit, expected sign of F_0·x̂ (particle 1 at +x))
    let cases = [
        ("head-to-tail", x * m, x * m, -2.0, 1.0),
        ("side-by-side antiparallel", z * m, -z * m, -1.0, 1.0),
        ("side-by-side parallel", z * m, z * m, 1.0, -1.0),
        ("head-to-head", x * m, -x * m, 2.0, -1.0),
    ];
    let pos = [DVec3::ZERO, x * r];
    for mut dd in [
        DipoleDipole::all_pairs(mu0()),
        DipoleDipole::cut_off(mu0(), 5.0 * r, r, Boundary::open()).unwrap(),
    ] {
        for (name, m0, m1, u, sign) in cases {
            let (e, f, t) = evaluate(&mut dd, &pos, &[m0, m1]);
            assert!(
                close(e, u * unit, 1e-14),
                "{name}: U = {e}, expected {}",
                u * unit
            );
            // |F| = 3 |U| / r along the axis, attracting when U < 0.
            assert!(
                close(f[0].x, sign * 3.0 * u.abs() * unit / r, 1e-14),
                "{name}: F = {}",
                f[0]
            );
            assert!(f[0].y.abs() + f[0].z.abs() < 1e-12 * f[0].x.abs(), "{name}");
            assert_eq!(f[0], -f[1], "{name}: Newton's third law");
            // Aligned or antialigned along or across the axis: no torque.
            assert!(
                t[0].length() < 1e-12 * unit && t[1].length() < 1e-12 * unit,
                "{name}: {t:?}"
            );
        }
        // Perpendicular: m_0 along x, m_1 along z at +x: the field of 1 at 0
        // is −k m ẑ/r³, so τ_0 = m x̂ × (−k m/r³) ẑ = +k m²/r³ ŷ.
        let (_, _, t) = evaluate(&mut dd, &pos, &[x * m, z * m]);
        assert!(close(t[0].y, unit, 1e-14), "τ_0 = {}", t[0]);
    }
}

/// A random open cluster: exact all pairs, or a cut-off larger than the cluster.
fn cluster(n: usize, seed: u64) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut pos: Vec<DVec3> = Vec::new();
    // Volume fraction about 0.12 of spheres of diameter 0.9.
    let side = 4.0 * (n as f64 / 40.0).cbrt();
    while pos.len() < n {
        let r = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * side;
        // Keep centres at least 0.9 apart (WCA range 1.12).
        if pos.iter().all(|q| (*q - r).length() > 0.9) {
            pos.push(r);
        }
    }
    let m = (0..n)
        .map(|_| {
            let v = DVec3::new(
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
            );
            v.normalize() * rng.gen_range(0.5..2.0)
        })
        .collect();
    (pos, m)
}

/// Central finite differences of U: dU/dx for every coordinate and
/// dU/dφ for rotations of each moment about each axis; F = −∇U and
/// τ = −∂U/∂φ.
fn check_derivatives(dd: &mut DipoleDipole, pos: &[DVec3], m: &[DVec3], tol: f64) {
    let (_, f, t) = evaluate(dd, pos, m);
    let h = 1e-6;
    let scale_f = f.iter().map(|v| v.length()).fold(0.0, f64::max);
    let scale_t = t.iter().map(|v| v.length()).fold(0.0, f64::max);
    let mut worst_f: f64 = 0.0;
    let mut worst_t: f64 = 0.0;
    for i in 0..pos.len() {
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = h;
            let mut p = pos.to_vec();
            p[i] = pos[i] + e;
            let up = dd.energy(&p, m);
            p[i] = pos[i] - e;
            let down = dd.energy(&p, m);
            worst_f = worst_f.max((-(up - down) / (2.0 * h) - f[i][k]).abs() / scale_f);
            let mut q = m.to_vec();
            q[i] = rotate(m[i], e);
            let up = dd.energy(pos, &q);
            q[i] = rotate(m[i], -e);
            let down = dd.energy(pos, &q);
            worst_t = worst_t.max((-(up - down) / (2.0 * h) - t[i][k]).abs() / scale_t);
        }
    }
    assert!(
        worst_f < tol,
        "force vs −∇U: worst relative error {worst_f:e}"
    );
    assert!(
        worst_t < tol,
        "torque vs −∂U/∂φ: worst relative error {worst_t:e}"
    );
}

#[test]
fn forces_and_torques_are_derivatives_of_the_energy() {
    let (pos, m) = cluster(40, 7);
    // Reduced units, μ₀/4π = 1.
    let mut all = DipoleDipole::all_pairs(4.0 * PI);
    check_derivatives(&mut all, &pos, &m, 1e-7);
    let mut wca = DipoleDipole::all_pairs(4.0 * PI)
        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
        .unwrap();
    check_derivatives(&mut wca, &pos, &m, 1e-7);
}

#[test]
fn isolated_system_conserves_momentum_and_angular_momentum() {
    let (pos, m) = cluster(60, 11);
    for (name, mut dd) in [
        ("all pairs", DipoleDipole::all_pairs(4.0 * PI)),
        (
            "cut-off 2.5 + LJ",
            DipoleDipole::cut_off(4.0 * PI, 2.5, 0.3, Boundary::open())
                .unwrap()
                .with_repulsion(PairRepulsion::lennard_jones(1.0, 1.0, 2.5))
                .unwrap(),
        ),
        (
            "cut-off 2 + reaction field",
            DipoleDipole::cut_off(4.0 * PI, 2.0, 0.3, Boundary::open())
                .unwrap()
                .with_reaction_field(f64::INFINITY),
        ),
    ] {
        let (_, f, t) = evaluate(&mut dd, &pos, &m);
        let fsum: DVec3 = f.iter().copied().sum();
        let lsum: DVec3 = (0..pos.len()).map(|i| t[i] + pos[i].cross(f[i])).sum();
        let fscale: f64 = f.iter().map(|v| v.length()).sum();
        let lscale: f64 = (0..pos.len())
            .map(|i| t[i].length() + pos[i].cross(f[i]).length())
            .sum();
        assert!(
            fsum.length() < 1e-14 * fscale,
            "{name}: ΣF = {fsum} (scale {fscale})"
        );
        assert!(
            lsum.length() < 1e-14 * lscale,
            "{name}: Σ(τ + r×F) = {lsum} (scale {lscale})"
        );
    }
}

#[test]
fn cut_off_sum_with_long_cut_off_equals_all_pairs() {
    let (pos, m) = cluster(50, 3);
    let mut all = DipoleDipole::all_pairs(4.0 * PI)
        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
        .unwrap();
    let mut cut = DipoleDipole::cut_off(4.0 * PI, 100.0, 0.5, Boundary::open())
        .unwrap()
        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
        .unwrap();
    let (ea, fa, ta) = evaluate(&mut all, &pos, &m);
    let (ec, fc, tc) = evaluate(&mut cut, &pos, &m);
    assert!(close(ec, ea, 1e-13), "{ec} vs {ea}");
    for i in 0..pos.len() {
        assert!(
            (fa[i] - fc[i]).length() < 1e-12 * fa[i].length().max(1.0),
            "{i}"
        );
        assert!(
            (ta[i] - tc[i]).length() < 1e-12 * ta[i].length().max(1.0),
            "{i}"
        );
    }
}

#[test]
fn periodic_minimum_image_with_reaction_field_is_consistent() {
    // A dilute periodic fluid: L = 10, r_c = 4 with a conducting reaction field.
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let l = 10.0;
    let boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(l));
    let mut pos: Vec<DVec3> = Vec::new();
    while pos.len() < 80 {
        let r = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * l;
        let ok = pos.iter().all(|q| {
            let d = boundary.minimum_image(*q - r).length();
            // Away from contact and from the cut-off, so that the
            // finite differences see a smooth energy.
            d > 0.95 && (d - 4.0).abs() > 1e-3
        });
        if ok {
            pos.push(r);
        }
    }
    let m: Vec<DVec3> = (0..pos.len())
        .map(|_| {
            DVec3::new(
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
                rng.gen::<f64>() - 0.5,
            )
            .normalize()
                * 1.5
        })
        .collect();
    let mut dd = DipoleDipole::cut_off(4.0 * PI, 4.0, 0.4, boundary)
        .unwrap()
        .with_reaction_field(f64::INFINITY)
        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
        .unwrap();
    check_derivatives(&mut dd, &pos, &m, 1e-7);
    let (_, f, _) = evaluate(&mut dd, &pos, &m);
    let fsum: DVec3 = f.iter().copied().sum();
    assert!(fsum.length() < 1e-13 * f.iter().map(|v| v.length()).sum::<f64>());
    // Too long a cut-off for the box is refused.
    assert!(DipoleDipole::cut_off(4.0 * PI, 5.5, 0.4, boundary).is_err());
}

#[test]
fn zeeman_torque_energy_and_gradient_forces() {
    let mu0 = mu0();
    let m = DVec3::new(1.0, 2.0, -0.5) * 1e-19;
    let pos = [DVec3::new(1e-7, -2e-7, 3e-7)];
    // Uniform: τ = μ₀ m × H, no force, U = −μ₀ m·H.
    let h = DVec3::new(0.0, 0.0, 4e4);
    let z = Zeeman::uniform(mu0, h);
    let (mut f, mut t) = (vec![DVec3::ZERO], vec![DVec3::ZERO]);
    z.forces_and_torques(&pos, &[m], 0.0, &mut f, &mut t);
    assert_eq!(f[0], DVec3::ZERO);
    assert!((t[0] - m.cross(h) * mu0).length() < 1e-15 * t[0].length());
    assert!(close(z.energy(&pos, &[m], 0.0), -mu0 * m.dot(h), 1e-15));

    // Rotating: H(t) turns counter-clockwise about z with |H| fixed.
    let rot = AppliedField::Rotating {
        amplitude: 1e4,
        angular_frequency: 2.0 * PI * 50.0,
        axis: DVec3::Z,
        phase: 0.0,
    };
    assert!((rot.at(DVec3::ZERO, 0.0) - DVec3::X * 1e4).length() < 1e-9);
    assert!((rot.at(DVec3::ZERO, 0.005) - DVec3::Y * 1e4).length() < 1e-9);

    // Non-uniform fields: F = −∇U and τ = −∂U/∂φ by finite differences.
    let g = mote_md::force::dipolar::AppliedField::LinearGradient {
        h0: DVec3::new(1e3, 0.0, 2e4),
        // Symmetric and traceless: curl- and divergence-free (A/m per m).
        gradient: glam::DMat3::from_cols_array(&[1e9, 2e9, 0.0, 2e9, -3e9, 5e8, 0.0, 5e8, 2e9]),
    };
    let source = AppliedField::PointDipole {
        position: DVec3::new(-3e-7, 1e-7, 0.0),
        moment: DVec3::new(0.0, 1e-15, 2e-15),
    };
    for field in [g, source] {
        let z = Zeeman::new(mu0, field.clone());
        let (mut f, mut t) = (vec![DVec3::ZERO], vec![DVec3::ZERO]);
        z.forces_and_torques(&pos, &[m], 0.0, &mut f, &mut t);
        let hx = 1e-12;
        let hphi = 1e-6;
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = 1.0;
            let fd = -(z.energy(&[pos[0] + e * hx], &[m], 0.0)
                - z.energy(&[pos[0] - e * hx], &[m], 0.0))
                / (2.0 * hx);
            assert!(
                (fd - f[0][k]).abs() < 1e-6 * f[0].length(),
                "{field:?} F[{k}] = {} vs {fd}",
                f[0][k]
            );
            let fd = -(z.energy(&pos, &[rotate(m, e * hphi)], 0.0)
                - z.energy(&pos, &[rotate(m, -e * hphi)], 0.0))
                / (2.0 * hphi);
            assert!(
                (fd - t[0][k]).abs() < 1e-7 * t[0].length(),
                "{field:?} τ[{k}] = {} vs {fd}",
                t[0][k]
            );
            assert!((t[0] - m.cross(field.at(pos[0], 0.0)) * mu0).length() < 1e-12 * t[0].length());
        }
    }
}

#[test]
fn all_pairs_is_bit_identical_for_every_thread_count() {
    let (pos, m) = cluster(300, 21);
    let run = |threads: usize| {
        mote_testkit::on_threads(threads, || {
            let mut dd = DipoleDipole::all_pairs(4.0 * PI)
                .with_repulsion(PairRepulsion::wca(1.0, 1.0))
                .unwrap();
            evaluate(&mut dd, &pos, &m)
        })
    };
    let (e1, f1, t1) = run(1);
    for threads in [2, 3] {
        let (e, f, t) = run(threads);
        assert_eq!(e1.to_bits(), e.to_bits());
        assert_eq!(f1, f);
        assert_eq!(t1, t);
    }
}
