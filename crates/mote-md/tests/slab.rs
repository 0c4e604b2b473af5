//! Charges between two conducting planes (force/slab.rs): the image force
//! on one charge against the closed form with the trigamma function, the
//! force between two charges against the image series summed directly, the
//! forces on the planes against the forces on the charges, the bias field,
//! and forces against finite differences of the energy.

use mote_md::force::ewald::Ewald;
use mote_md::force::p3m::Request;
use mote_md::force::slab::ConductingPlanes;
use mote_md::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Coulomb's constant in units where it is 1.
const K: f64 = 1.0;

/// Trigamma ψ₁(x) = Σ_{m≥0} 1/(x + m)², by recurrence to x + 20 and the
/// asymptotic series 1/y + 1/2y² + 1/6y³ − 1/30y⁵ + 1/42y⁷ − 1/30y⁹
/// (Abramowitz & Stegun 6.4.12; error below 1e-16 at y ≥ 20).
fn trigamma(x: f64) -> f64 {
    let mut sum = 0.0;
    let mut y = x;
    while y < 20.0 {
        sum += 1.0 / (y * y);
        y += 1.0;
    }
    let r = 1.0 / y;
    let r2 = r * r;
    sum + r + 0.5 * r2 + r * r2 * (1.0 / 6.0 - r2 * (1.0 / 30.0 - r2 * (1.0 / 42.0 - r2 / 30.0)))
}

#[test]
fn trigamma_matches_known_values() {
    // ψ₁(1) = π²/6, ψ₁(1/2) = π²/2, ψ₁(1/4) = π² + 8G (G: Catalan's constant).
    let pi2 = std::f64::consts::PI.powi(2);
    assert!((trigamma(1.0) - pi2 / 6.0).abs() < 1e-14);
    assert!((trigamma(0.5) - pi2 / 2.0).abs() < 1e-14);
    let catalan = 0.915_965_594_177_219;
    assert!((trigamma(0.25) - (pi2 + 8.0 * catalan)).abs() < 1e-13);
}

/// Planes with gap h = 1 and lateral periods 10h: a charge's image column
/// acts on the lateral copies of another as e^{−πρ/h} (the slowest mode of
/// the slab), so the copies add e^{−10π} ≈ 2e-14 to the forces that the
/// closed forms below give for one column.
fn wide_planes(charge: &[f64], potential: [f64; 2]) -> ConductingPlanes {
    ConductingPlanes::new(K, 1.0, [10.0, 10.0], potential, charge, 1.0, 1e-11)
}

#[test]
fn one_charge_feels_its_images_as_the_trigamma_closed_form() {
    // F_z = −k q²/(4h²) [ψ₁(a) − ψ₁(1 − a)], a = z/h (Jackson problem 3.20).
    let q = [1.5];
    let mut planes = wide_planes(&q, [0.0, 0.0]);
    for a in [0.05, 0.2, 0.37, 0.5, 0.81, 0.96] {
        let pos = [DVec3::new(2.0, 3.0, a)];
        let mut f = [DVec3::ZERO];
        planes.evaluate(&pos, &q, Some(&mut f));
        let exact = -K * q[0] * q[0] / 4.0 * (trigamma(a) - trigamma(1.0 - a));
        let scale = exact.abs().max(K * q[0] * q[0]);
        assert!(
            (f[0].z - exact).abs() < 2e-8 * scale,
            "a = {a}: F_z = {}, closed form {exact}",
            f[0].z
        );
        assert!(f[0].x.abs() < 1e-8 * scale && f[0].y.abs() < 1e-8 * scale);
    }
}

/// The force on a charge q₂ at r₂ from a unit charge at r₁ and all the
/// images of r₁ (not those of q₂): +q at 2nh + z₁ (n ≠ 0), −q at 2nh − z₁,
/// |n| ≤ m, with the tail's leading term added: for |n| > m the pairs
/// are dipoles 2z₁ ẑ at distance 2|n|h, whose field on the axis is
/// 2p/(2nh)³ per side.
fn image_series_force(r1: DVec3, r2: DVec3, h: f64, m: i64) -> DVec3 {
    let field = |src: DVec3, q: f64| {
        let d = r2 - src;
        q * d / d.length_squared().powf(1.5)
    };
    let mut e = field(r1, 1.0);
    for n in -m..=m {
        let s = 2.0 * n as f64 * h;
        if n != 0 {
            e += field(DVec3::new(r1.x, r1.y, s + r1.z), 1.0);
        }
        e += field(DVec3::new(r1.x, r1.y, s - r1.z), -1.0);
    }
    // Σ_{|n|>m} 2p/(2|n|h)³ with p = 2z₁ (the dipoles point along +z).
    let zeta_tail: f64 = (m + 1..m + 200_000).map(|n| 1.0 / (n as f64).powi(3)).sum();
    e.z += 2.0 * (2.0 * 2.0 * r1.z) / (8.0 * h.powi(3)) * zeta_tail;
    K * e
}

#[test]
fn two_charges_match_the_image_series() {
    let h = 1.0;
    let q = [1.0, -0.7];
    let mut planes = wide_planes(&q, [0.0, 0.0]);
    for (r1, r2) in [
        (DVec3::new(3.0, 3.0, 0.3), DVec3::new(3.4, 2.9, 0.55)),
        (DVec3::new(1.0, 2.0, 0.1), DVec3::new(1.05, 2.02, 0.15)),
        (DVec3::new(2.0, 2.0, 0.8), DVec3::new(2.9, 2.5, 0.2)),
    ] {
        let pos = [r1, r2];
        let mut f = [DVec3::ZERO; 2];
        planes.evaluate(&pos, &q, Some(&mut f));
        // q₂'s own images, from the closed form.
        let a = r2.z / h;
        let own = -K * q[1] * q[1] / (4.0 * h * h) * (trigamma(a) - trigamma(1.0 - a));
        let expected = q[1] * q[0] * image_series_force(r1, r2, h, 20_000) + DVec3::Z * own;
        let err = (f[1] - expected).length();
        assert!(
            err < 1e-7 * expected.length(),
            "{r1} {r2}: {} against the series {expected}",
            f[1]
        );
    }
}

fn random_charges(n: usize, lateral: [f64; 2], h: f64, seed: u64) -> (Vec<DVec3>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let pos = (0..n)
        .map(|_| {
            DVec3::new(
                rng.gen::<f64>() * lateral[0],
                rng.gen::<f64>() * lateral[1],
                (0.1 + 0.8 * rng.gen::<f64>()) * h,
            )
        })
        .collect();
    let q = (0..n).map(|_| rng.gen_range(-1.0..1.0)).collect();
    (pos, q)
}

#[test]
fn forces_are_minus_the_energy_gradient() {
    let (lateral, h) = ([2.0, 1.5], 1.0);
    let (pos, q) = random_charges(12, lateral, h, 3);
    let mut planes = ConductingPlanes::new(K, h, lateral, [0.3, -1.2], &q, 0.75, 1e-11);
    let mut f = vec![DVec3::ZERO; pos.len()];
    planes.evaluate(&pos, &q, Some(&mut f));
    let dx = 1e-6;
    for i in [0, 5, 11] {
        for axis in 0..3 {
            let mut p = pos.clone();
            p[i][axis] += dx;
            let up = planes.evaluate(&p, &q, None).total();
            p[i][axis] -= 2.0 * dx;
            let down = planes.evaluate(&p, &q, None).total();
            let numeric = -(up - down) / (2.0 * dx);
            assert!(
                (numeric - f[i][axis]).abs() < 1e-6 * (1.0 + f[i].length()),
                "particle {i} axis {axis}: {} against −dU/dx {numeric}",
                f[i][axis]
            );
        }
    }
}

#[test]
fn the_planes_take_the_reaction_of_every_force_on_the_charges() {
    // F₀ + F_h (Maxwell stress on the planes' surface charges, summed in
    // lateral Fourier modes) = −Σ F_i (Ewald on the doubled cell): two
    // independent computations, with and without a bias.
    let (lateral, h) = ([1.6, 1.2], 1.0);
    let (pos, q) = random_charges(10, lateral, h, 11);
    for potential in [[0.0, 0.0], [0.0, 2.5], [-1.0, 0.4]] {
        let mut planes = ConductingPlanes::new(K, h, lateral, potential, &q, 0.6, 1e-12);
        let mut f = vec![DVec3::ZERO; pos.len()];
        planes.evaluate(&pos, &q, Some(&mut f));
        let total: DVec3 = f.iter().copied().sum();
        // z ≥ 0.1 h: modes to k = 200 leave e^{−40} of the sum.
        let [f0, fh] = planes.plane_forces(&pos, &q, 200.0);
        let scale = f.iter().map(|v| v.length()).sum::<f64>();
        assert!(
            (f0 + fh + total.z).abs() < 1e-8 * scale,
            "V = {potential:?}: planes {f0} + {fh}, charges {}",
            total.z
        );
        assert!(total.x.abs() < 1e-8 * scale && total.y.abs() < 1e-8 * scale);
        // The bias alone pushes Σq E_bias; the planes attract each other
        // by the capacitor's ε₀E²A/2, which cancels in the sum.
        assert!(f0 > 0.0 && fh < 0.0, "each plane is pulled into the gap");
    }
}

#[test]
fn induced_charge_equals_minus_the_charge_between_the_planes() {
    let (pos, q) = random_charges(25, [1.0, 1.0], 2.0, 5);
    let planes = ConductingPlanes::new(K, 2.0, [1.0, 1.0], [0.0, 0.0], &q, 0.5, 1e-8);
    let [q0, qh] = planes.induced_charges(&pos, &q);
    let total: f64 = q.iter().sum();
    assert!((q0 + qh + total).abs() < 1e-14);
    // A charge at the middle induces half of −q on each plane.
    let [a, b] = planes.induced_charges(&[DVec3::new(0.5, 0.5, 1.0)], &[2.0]);
    assert!((a + 1.0).abs() < 1e-15 && (b + 1.0).abs() < 1e-15);
}

#[test]
fn a_bias_alone_gives_the_uniform_field() {
    // Far apart in a wide slab the charges feel q E_bias plus their images;
    // the difference of two biases is exactly q ΔE.
    let q = [0.4, -0.9];
    let pos = [DVec3::new(1.0, 1.0, 0.3), DVec3::new(4.0, 4.0, 0.6)];
    let (mut f0, mut f1) = ([DVec3::ZERO; 2], [DVec3::ZERO; 2]);
    wide_planes(&q, [0.0, 0.0]).evaluate(&pos, &q, Some(&mut f0));
    wide_planes(&q, [1.0, 4.0]).evaluate(&pos, &q, Some(&mut f1));
    for i in 0..2 {
        let d = f1[i] - f0[i];
        let expected = DVec3::new(0.0, 0.0, -3.0 * q[i]);
        assert!((d - expected).length() < 1e-12, "{d} against {expected}");
    }
}

#[test]
fn linked_cells_give_the_all_pairs_real_space_sum() {
    // 300 charges: at the smaller cut-off the real-space sum runs on
    // linked cells (three or more cells per axis; in the second box two
    // along y, all visited); at the larger one, beyond half a side, over
    // all pairs and images. Both meet the requested accuracy.
    for (cell, small, large) in [
        (DVec3::new(1.0, 1.3, 0.9), 0.9 / 3.5, 0.45),
        (DVec3::new(1.0, 0.45, 0.9), 0.22, 0.46),
    ] {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let pos: Vec<DVec3> = (0..300)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * cell)
            .collect();
        let mut q: Vec<f64> = (0..300).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let mean = q.iter().sum::<f64>() / q.len() as f64;
        q.iter_mut().for_each(|x| *x -= mean);
        let cells = Ewald::for_charges_in(cell, small, 1e-9, &q);
        let pairs = Ewald::for_charges_in(cell, large, 1e-9, &q);
        let (mut fa, mut fb) = (vec![DVec3::ZERO; 300], vec![DVec3::ZERO; 300]);
        let ua = cells.charges(&pos, &q, Some(&mut fa));
        let ub = pairs.charges(&pos, &q, Some(&mut fb));
        assert!((ua - ub).abs() < 1e-7 * ub.abs(), "{ua} against {ub}");
        let rms = (fa
            .iter()
            .zip(&fb)
            .map(|(a, b)| (*a - *b).length_squared())
            .sum::<f64>()
            / 300.0)
            .sqrt();
        assert!(rms < 1e-8, "RMS force difference {rms}");
    }
}

#[test]
fn rigid_scene_planes_act_on_a_charged_body() {
    // `[rigid.planes]` on the box 10 × 10 × 1 lifted to z ∈ [2, 3]: a
    // charged sphere at height 0.3 above the lower plane feels its images
    // and the bias field (−2 V over the unit gap: E_z = −2).
    use mote_md::rigid::scene::RigidScene;
    let text = r#"
[rigid]
[[rigid.template]]
name = "toner"
generator = "sphere"
radius = 0.05
density = 1.0
charge = 0.8

[[rigid.body]]
template = "toner"
position = [4.0, 5.0, 2.3]

[box]
lo = [0.0, 0.0, 2.0]
hi = [10.0, 10.0, 3.0]
periodic = [true, true, false]

[rigid.contacts]
young = 1e5
restitution = 0.5

[rigid.planes]
coulomb = 1.0
potential = [0.0, 2.0]
accuracy = 1e-11
r_cut = 1.0

[run]
dt = 1e-3
steps = 1
"#;
    let mut built = RigidScene::parse(text, "planes.toml")
        .unwrap()
        .build(text, "planes.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    let w = built.frbi.wrenches(&built.bodies, 0.0, 0.0)[0];
    let (q, a) = (0.8, 0.3);
    let exact = -K * q * q / 4.0 * (trigamma(a) - trigamma(1.0 - a)) - 2.0 * q;
    assert!(
        (w.v.z - exact).abs() < 1e-8 * exact.abs(),
        "F_z = {}, expected {exact}",
        w.v.z
    );
    assert!(w.v.x.abs() < 1e-9 && w.v.y.abs() < 1e-9);
    // With the point particles' Coulomb table too, the scene is refused
    // at that table: the planes sum the charges' forces with their images.
    let twice = text.replace("[rigid.planes]", "[coulomb]\nk = 1.0\n\n[rigid.planes]");
    let e = RigidScene::parse(&twice, "planes.toml")
        .unwrap()
        .build(&twice, "planes.toml", None)
        .err()
        .unwrap();
    assert!(
        e.to_string()
            .contains("[coulomb] between conducting planes is [rigid.planes] coulomb"),
        "{e}"
    );
    let coulomb_line = twice.lines().position(|l| l == "[coulomb]").unwrap() + 1;
    assert_eq!(e.line, coulomb_line, "{e}");
    // The box's first spelling, inside [rigid.contacts], is refused with
    // the one every engine uses.
    let old = text
        .replace("[box]\nlo = [0.0, 0.0, 2.0]\nhi = [10.0, 10.0, 3.0]\nperiodic = [true, true, false]\n\n", "")
        .replace("[rigid.contacts]\n", "[rigid.contacts]\nbox_lo = [0.0, 0.0, 2.0]\n");
    assert_ne!(old, text);
    let e = RigidScene::parse(&old, "old.toml")
        .unwrap()
        .build(&old, "old.toml", None)
        .err()
        .unwrap();
    let line = old.lines().position(|l| l.starts_with("box_lo")).unwrap() + 1;
    assert_eq!(e.line, line, "{e}");
    assert!(
        e.to_string()
            .contains("[box] lo = [...], hi = [...], periodic = [...]"),
        "{e}"
    );
}

/// P3M on the doubled cell against Ewald on it (converged far past it):
/// forces and energies of random charges between planes at a bias, to
/// the accuracy asked for; the forces without the energy are the same.
#[test]
fn p3m_on_the_doubled_cell_matches_ewald() {
    let (h, lateral) = (5.0, [9.0, 8.0]);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(41);
    let n = 300;
    let pos: Vec<DVec3> = (0..n)
        .map(|_| {
            DVec3::new(
                rng.gen::<f64>() * lateral[0],
                rng.gen::<f64>() * lateral[1],
                0.1 + rng.gen::<f64>() * (h - 0.2),
            )
        })
        .collect();
    let q: Vec<f64> = (0..n)
        .map(|i| if i % 3 == 0 { -2.0 } else { 1.0 })
        .collect();
    let potential = [0.5, -1.5];
    let mut exact = ConductingPlanes::new(K, h, lateral, potential, &q, 4.0, 1e-10);
    let mut f_ref = vec![DVec3::ZERO; n];
    let u_ref = exact.evaluate(&pos, &q, Some(&mut f_ref));
    for accuracy in [1e-3, 1e-4] {
        let request = Request {
            accuracy,
            skin: 0.3,
            ..Request::default()
        };
        let mut planes =
            ConductingPlanes::with_p3m(K, h, lateral, potential, &q, &request).unwrap();
        println!("{}", planes.describe());
        let mut f = vec![DVec3::ZERO; n];
        let u = planes.evaluate(&pos, &q, Some(&mut f));
        let rms = (f
            .iter()
            .zip(&f_ref)
            .map(|(a, b)| (*a - *b).length_squared())
            .sum::<f64>()
            / n as f64)
            .sqrt();
        println!(
            "δ = {accuracy:e}: RMS force error {rms:.3e}; U {:.8} vs Ewald {:.8}",
            u.total(),
            u_ref.total()
        );
        assert!(rms < accuracy, "RMS force error {rms:e}");
        assert!((u.bias - u_ref.bias).abs() < 1e-12 * u_ref.bias.abs());
        assert!((u.images - u_ref.images).abs() < accuracy * n as f64);
        let mut g = vec![DVec3::ZERO; n];
        planes.add_forces(&pos, &q, &mut g);
        assert_eq!(f, g);
    }
}
