//! Surface charge fields (force/latent.rs): the rectangle's closed form
//! against quadrature, its limits and its potential's gradient; the latent
//! image between two conducting planes against the Fourier series of the
//! same periodic charge.

use std::f64::consts::PI;

use mote_md::force::latent::{rectangle, LatentImage, Patch};
use mote_md::DVec3;

/// Gauss–Legendre nodes and weights on [−1, 1], 10 points.
const GL: [(f64, f64); 5] = [
    (0.148_874_338_981_631_2, 0.295_524_224_714_752_9),
    (0.433_395_394_129_247_2, 0.269_266_719_309_996_4),
    (0.679_409_568_299_024_4, 0.219_086_362_515_982),
    (0.865_063_366_688_984_5, 0.149_451_349_150_580_6),
    (0.973_906_528_517_171_7, 0.066_671_344_308_688_1),
];

/// ∫∫ over the rectangle of f(x′, y′), on a 40 × 40 grid of panels with
/// ten Gauss points each way.
fn quadrature(x: [f64; 2], y: [f64; 2], f: impl Fn(f64, f64) -> f64) -> f64 {
    let panels = 40;
    let (hx, hy) = ((x[1] - x[0]) / panels as f64, (y[1] - y[0]) / panels as f64);
    let mut total = 0.0;
    for i in 0..panels {
        for j in 0..panels {
            let (cx, cy) = (x[0] + (i as f64 + 0.5) * hx, y[0] + (j as f64 + 0.5) * hy);
            for &(a, wa) in &GL {
                for sa in [-1.0, 1.0] {
                    for &(b, wb) in &GL {
                        for sb in [-1.0, 1.0] {
                            let (xp, yp) = (cx + sa * a * 0.5 * hx, cy + sb * b * 0.5 * hy);
                            total += wa * wb * f(xp, yp);
                        }
                    }
                }
            }
        }
    }
    total * 0.25 * hx * hy
}

#[test]
fn rectangle_matches_quadrature() {
    let (x, y) = ([-1.0, 2.0], [0.5, 1.5]);
    for p in [
        DVec3::new(0.3, 1.0, 0.7),
        DVec3::new(3.0, -1.0, 0.4),
        DVec3::new(-1.2, 2.0, -0.9),
        DVec3::new(0.5, 0.6, 2.5),
    ] {
        let (phi, e) = rectangle(p, x, y);
        let r = |xp: f64, yp: f64| DVec3::new(p.x - xp, p.y - yp, p.z);
        let q_phi = quadrature(x, y, |a, b| 1.0 / r(a, b).length());
        let q_e = DVec3::new(
            quadrature(x, y, |a, b| r(a, b).x / r(a, b).length().powi(3)),
            quadrature(x, y, |a, b| r(a, b).y / r(a, b).length().powi(3)),
            quadrature(x, y, |a, b| r(a, b).z / r(a, b).length().powi(3)),
        );
        assert!(
            (phi - q_phi).abs() < 1e-10 * q_phi.abs(),
            "{p}: φ {phi} against {q_phi}"
        );
        assert!(
            (e - q_e).length() < 1e-9 * q_e.length(),
            "{p}: E {e} against {q_e}"
        );
    }
}

#[test]
fn rectangle_limits() {
    let (x, y) = ([0.0, 2.0], [0.0, 1.0]);
    // Just above the interior: E_z → 2π (σ/2ε₀ per unit kσ), E_x, E_y → 0 at the centre.
    let (_, e) = rectangle(DVec3::new(1.0, 0.5, 1e-9), x, y);
    assert!((e.z - 2.0 * PI).abs() < 1e-8, "{e}");
    assert!(e.x.abs() < 1e-12 && e.y.abs() < 1e-12);
    // Just below it the normal field reverses.
    let (_, below) = rectangle(DVec3::new(1.0, 0.5, -1e-9), x, y);
    assert!((below.z + 2.0 * PI).abs() < 1e-8);
    // Far away: the point charge of area 2.
    let far = DVec3::new(1.0, 0.5, 0.0) + DVec3::new(300.0, -200.0, 400.0);
    let (phi, e) = rectangle(far, x, y);
    let d = far - DVec3::new(1.0, 0.5, 0.0);
    assert!((phi - 2.0 / d.length()).abs() < 1e-5 * phi);
    assert!((e - 2.0 * d / d.length().powi(3)).length() < 1e-5 * e.length());
    // E = −∇φ (the seed's rectangle potential once had a wrong corner sign:
    // any sign slip breaks this).
    let p = DVec3::new(0.4, 1.3, 0.35);
    let (_, e) = rectangle(p, x, y);
    let h = 1e-5;
    for a in 0..3 {
        let mut dp = DVec3::ZERO;
        dp[a] = h;
        let g = (rectangle(p + dp, x, y).0 - rectangle(p - dp, x, y).0) / (2.0 * h);
        assert!(
            (e[a] + g).abs() < 1e-7,
            "axis {a}: E {} against −∂φ {}",
            e[a],
            -g
        );
    }
}

/// The Fourier series of the periodic strip pattern σ on [x₁, x₂] (period
/// L) at height d between grounded planes 0 and h, at z > d:
/// E_z = 4πk [σ̄ d/h + Σ_{m≠0} σ_m sinh(kd) cosh(k(h−z))/sinh(kh) e^{ikx}],
/// E_x = −4πk Σ ik σ_m sinh(kd) sinh(k(h−z))/(k sinh(kh)) e^{ikx},
/// σ_m = σ (e^{−ikx₁} − e^{−ikx₂})/(ikL).
fn fourier_field(img: &LatentImage, x: f64, z: f64) -> (f64, f64) {
    let (h, d, l) = (img.gap, img.height, img.period);
    let p = img.patches[0];
    let sigma = p.density - img.background;
    let mut ez = img.background * d / h + sigma * (p.end - p.start) / l * d / h;
    let mut ex = 0.0;
    let e = |a: f64| (-a).exp();
    for m in 1..200_000 {
        let k = 2.0 * PI * m as f64 / l;
        if k * (z - d) > 45.0 {
            break;
        }
        // sinh(kd)/sinh(kh) · cosh or sinh of k(h − z), without overflow.
        let base = e(k * (z - d)) * (1.0 - e(2.0 * k * d)) / (1.0 - e(2.0 * k * h)) * 0.5;
        let (ch, sh) = (
            base * (1.0 + e(2.0 * k * (h - z))),
            base * (1.0 - e(2.0 * k * (h - z))),
        );
        // σ_m e^{ikx} + σ_{−m} e^{−ikx} = 2 Re(σ_m e^{ikx}).
        let (c1, s1) = ((k * (x - p.start)).cos(), (k * (x - p.start)).sin());
        let (c2, s2) = ((k * (x - p.end)).cos(), (k * (x - p.end)).sin());
        // σ_m e^{ikx} = σ/(ikL) (e^{ik(x−x₁)} − e^{ik(x−x₂)}).
        let (re, im) = ((s1 - s2) / (k * l) * sigma, -(c1 - c2) / (k * l) * sigma);
        ez += 2.0 * re * ch;
        // −ik · (re + i im) = k im − i k re: real part k·im.
        ex += 2.0 * im * sh;
    }
    (4.0 * PI * img.k * ex, 4.0 * PI * img.k * ez)
}

#[test]
fn latent_image_matches_the_fourier_series() {
    for (period, start, end) in [(1.2, 0.2, 0.7), (0.5, -0.1, 0.3), (3.0, 1.0, 2.9)] {
        let img = LatentImage {
            k: 0.7,
            gap: 1.0,
            height: 0.08,
            period,
            speed: 0.0,
            background: -0.3,
            patches: vec![Patch {
                start,
                end,
                density: 1.1,
            }],
        };
        img.check().unwrap();
        for (x, z) in [
            (0.25, 0.12),
            (0.7, 0.1),
            (-0.4, 0.5),
            (2.95, 0.93),
            (0.2, 0.2),
        ] {
            let (ex, ez) = img.field(x, z, 0.0);
            let (fx, fz) = fourier_field(&img, x, z);
            let scale = fx.hypot(fz);
            assert!(
                (ex - fx).abs() < 1e-9 * scale && (ez - fz).abs() < 1e-9 * scale,
                "L {period} x {x} z {z}: ({ex}, {ez}) against the series ({fx}, {fz})"
            );
        }
    }
}

/// The copies summed as two progressions of products (one logarithm
/// each, or one for the ratio of the two) give the copy-by-copy sum's
/// field to round-off: the toning nip's geometry (L = 2.3 h) and periods
/// down to 0.23 h (q = e^{−πL/h} = 0.48),
/// from just above the charged surface to just under the shell, over a
/// whole period and with the belt moved.
#[test]
fn image_copies_by_progressions_match_copy_by_copy() {
    for (gap, period, height, patches) in [
        (
            2.58e-4,
            6.0e-4,
            8.0e-6,
            vec![[0.0, 1.5e-4, 6.6e-4], [3.0e-4, 4.5e-4, 6.6e-4]],
        ),
        (1.0, 1.2, 0.08, vec![[0.2, 0.7, 1.1]]),
        (1.0, 0.5, 0.08, vec![[-0.1, 0.3, -1.0], [0.35, 0.45, 2.0]]),
        (1.0, 0.23, 0.05, vec![[0.0, 0.2, 1.0]]),
        // q = 0.323, just inside the bound under which each side's two
        // progressions are summed as one ratio.
        (1.0, 0.36, 0.02, vec![[0.0, 0.2, 1.0]]),
    ] {
        let img = belt_image(gap, height, period, &patches);
        img.check().unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..=40 {
            for z in [
                1.0001,
                1.01,
                1.5,
                4.0,
                0.5 * gap / height,
                0.999 * gap / height,
            ] {
                let (x, z) = (period * (i as f64 / 40.0 - 0.3), z * height);
                for t in [0.0, 1.7e-4] {
                    let (ex, ez) = img.field(x, z, t);
                    let (rx, rz) = img.field_copy_by_copy(x, z, t);
                    let scale = rx.hypot(rz);
                    worst = worst.max((ex - rx).hypot(ez - rz) / scale);
                }
            }
        }
        assert!(worst < 1e-12, "L = {period}, h = {gap}: {worst:.2e}");
    }
}

#[test]
fn latent_image_limits_and_motion() {
    let mut img = LatentImage {
        k: 1.0,
        gap: 2.0,
        height: 0.1,
        period: 4.0,
        speed: 0.5,
        background: 0.2,
        patches: Vec::new(),
    };
    // Uniform charge: E_z = 4πkσ d/h everywhere above it, no E_x.
    let (ex, ez) = img.field(1.3, 1.0, 0.0);
    assert!(ex == 0.0 && (ez - 4.0 * PI * 0.2 * 0.1 / 2.0).abs() < 1e-15);
    // A patch over the whole period is the same as raising the background.
    img.patches.push(Patch {
        start: 0.0,
        end: 4.0,
        density: 1.0,
    });
    let (ex, ez) = img.field(0.7, 0.4, 3.0);
    assert!(
        ex.abs() < 1e-12 && (ez - 4.0 * PI * 0.1 / 2.0).abs() < 1e-12,
        "{ex} {ez}"
    );
    // A patch moves with the belt: its field at x, t is the field at
    // x − vt, 0.
    img.patches[0] = Patch {
        start: 0.5,
        end: 1.5,
        density: -2.0,
    };
    let a = img.field(2.3, 0.3, 1.6);
    let b = img.field(2.3 - 0.5 * 1.6, 0.3, 0.0);
    assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12);
    // Just above the negative patch the field points down (towards the
    // belt), just above the positive background up.
    let (_, near) = img.field(1.0, 0.1001, 0.0);
    let (_, away) = img.field(3.0, 0.1001, 0.0);
    assert!(near < 0.0 && away > 0.0, "{near} {away}");
    assert!(img.check().is_ok());
    img.patches[0].end = 5.0;
    assert!(img.check().is_err());
}

#[test]
fn rigid_scene_latent_image_pushes_charged_bodies() {
    // The same scene with and without `[rigid.latent_image]`: the bodies'
    // forces differ by q E of the image at their centres, the belt's
    // conductor being the lower plane z = 1.
    use mote_md::rigid::scene::RigidScene;
    let base = r#"
[rigid]
[[rigid.template]]
name = "toner"
generator = "sphere"
radius = 0.02
density = 1.0
charge = -0.5

[[rigid.body]]
template = "toner"
position = [0.3, 0.2, 1.15]

[[rigid.body]]
template = "toner"
position = [1.1, 0.3, 1.6]

[box]
lo = [0.0, 0.0, 1.0]
hi = [1.5, 0.5, 2.0]
periodic = [true, true, false]

[rigid.contacts]
young = 1e5
restitution = 0.5

[rigid.planes]
coulomb = 1.0
potential = [0.0, 0.5]
accuracy = 1e-10
r_cut = 0.25

[run]
dt = 1e-3
steps = 1
"#;
    let latent = base.replace(
        "[run]",
        "[rigid.latent_image]\nheight = 0.1\nspeed = 2.0\nbackground = 0.1\npatches = [[0.2, 0.6, -1.0]]\n\n[run]",
    );
    let wrenches = |text: &str, t: f64| {
        let mut built = RigidScene::parse(text, "nip.toml")
            .unwrap()
            .build(text, "nip.toml", None)
            .unwrap_or_else(|e| panic!("{e}"));
        built.frbi.wrenches(&built.bodies, t, 0.0).to_vec()
    };
    let image = LatentImage {
        k: 1.0,
        gap: 1.0,
        height: 0.1,
        period: 1.5,
        speed: 2.0,
        background: 0.1,
        patches: vec![Patch {
            start: 0.2,
            end: 0.6,
            density: -1.0,
        }],
    };
    let t = 0.05;
    let (a, b) = (wrenches(&latent, t), wrenches(base, t));
    for (i, (x, z)) in [(0.3, 0.15), (1.1, 0.6)].into_iter().enumerate() {
        let (ex, ez) = image.field(x, z, t);
        let d = a[i].v - b[i].v;
        let expected = -0.5 * DVec3::new(ex, 0.0, ez);
        assert!(
            (d - expected).length() < 1e-12 * expected.length(),
            "{d} against {expected}"
        );
    }
    // Without planes the latent image is refused at its table.
    let alone = latent.replace(
        "[rigid.planes]\ncoulomb = 1.0\npotential = [0.0, 0.5]\naccuracy = 1e-10\nr_cut = 0.25\n",
        "",
    );
    let e = RigidScene::parse(&alone, "nip.toml")
        .unwrap()
        .build(&alone, "nip.toml", None)
        .err()
        .unwrap();
    assert!(e.to_string().contains("needs [rigid.planes]"), "{e}");
}

/// `[rigid.latent_image] period`: a patch repeating every 300 µm is the
/// flowing nip's two patches in its 600 µm box (to round-off), and the
/// scene refuses a period that does not divide the box's length.
#[test]
fn a_period_that_divides_the_box_repeats_the_patches() {
    let image = |period: f64, patches: &[[f64; 3]]| belt_image(2.58e-4, 8.0e-6, period, patches);
    let one = image(3.0e-4, &[[0.0, 1.5e-4, 6.6e-4]]);
    let two = image(6.0e-4, &[[0.0, 1.5e-4, 6.6e-4], [3.0e-4, 4.5e-4, 6.6e-4]]);
    for i in 0..=60 {
        for z in [1.2e-5, 6e-5, 2.5e-4] {
            let x = 6.0e-4 * i as f64 / 60.0;
            let (a, b) = (one.field(x, z, 1.3e-4), two.field(x, z, 1.3e-4));
            let scale = b.0.hypot(b.1);
            assert!(
                (a.0 - b.0).hypot(a.1 - b.1) < 1e-12 * scale,
                "{a:?} against {b:?}"
            );
        }
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/rigid/toning-nip-flow.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let with = |period: &str| {
        text.replace(
            "background = 1.1e-4",
            &format!("background = 1.1e-4\nperiod = {period}"),
        )
    };
    use mote_md::rigid::scene::RigidScene;
    for (period, ok) in [
        ("3.0e-4", true),
        ("6.0e-4", true),
        ("2.5e-4", false),
        ("0.0", false),
        ("7e-4", false),
    ] {
        let text = with(period);
        let built = RigidScene::parse(&text, "nip.toml")
            .unwrap()
            .build(&text, "nip.toml", None);
        match (built, ok) {
            (Ok(_), true) => {}
            (Err(e), false) => {
                let line = text
                    .lines()
                    .position(|l| l == "[rigid.latent_image]")
                    .unwrap()
                    + 1;
                assert_eq!(e.line, line, "{e}");
                assert!(
                    e.to_string().contains("must divide the box's length"),
                    "{e}"
                );
            }
            (Ok(_), false) => panic!("period {period} taken"),
            (Err(e), true) => panic!("period {period} refused: {e}"),
        }
    }
}

/// A latent image of the nip's belt (k of SI, 0.3 m/s, background
/// 1.1·10⁻⁴ C/m²) with `patches` [start, end, density].
fn belt_image(gap: f64, height: f64, period: f64, patches: &[[f64; 3]]) -> LatentImage {
    LatentImage {
        k: 8.9875517923e9,
        gap,
        height,
        period,
        speed: 0.3,
        background: 1.1e-4,
        patches: patches
            .iter()
            .map(|&[start, end, density]| Patch {
                start,
                end,
                density,
            })
            .collect(),
    }
}
