//! The magnetic roller (rigid/magnet.rs): its field against the polar
//! multipole form, Maxwell's equations and finite differences; induced
//! moments against the closed forms of one bead and of two beads that
//! induce each other; the forces between moments keep Newton's third law.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::force::StepParameters;
use mote_md::rigid::magnet::{InducedDipoles, MagneticRoller, MU0};
use mote_md::rigid::{BodyInteraction, BodyTemplate, BodyView, RigidBodies, WorldFrame};

fn roller() -> MagneticRoller {
    MagneticRoller {
        field: 0.08,
        poles: 8,
        radius: 0.01,
        angular_velocity: 2.0 * PI * 3.0,
        axis: [0.002, 0.0105],
    }
}

#[test]
fn field_is_the_polar_multipole() {
    let r = roller();
    let n = 4.0;
    for (p, t) in [
        (DVec3::new(0.0025, 0.1, 0.0), 0.0),
        (DVec3::new(0.001, 0.0, 0.0003), 0.013),
        (DVec3::new(-0.003, 0.0, -0.002), 0.2),
    ] {
        let b = r.at(p, t);
        let (wx, wz) = (p.x - r.axis[0], p.z - r.axis[1]);
        let (rr, theta) = (wx.hypot(wz), wz.atan2(wx));
        let mag = r.field * (r.radius / rr).powf(n + 1.0);
        let alpha = n * (theta - r.angular_velocity * t);
        let (br, bt) = (mag * alpha.cos(), mag * alpha.sin());
        let polar = DVec3::new(
            br * theta.cos() - bt * theta.sin(),
            0.0,
            br * theta.sin() + bt * theta.cos(),
        );
        assert!((b - polar).length() < 1e-12 * mag, "{b} against {polar}");
        assert!((b.length() - mag).abs() < 1e-12 * mag);
    }
    // B₀ at the shell's radius, straight below the axis.
    let below = DVec3::new(r.axis[0], 0.0, r.axis[1] - r.radius);
    assert!((r.at(below, 0.37).length() - r.field).abs() < 1e-15);
}

#[test]
fn field_is_curl_and_divergence_free_and_turns() {
    let r = roller();
    let p = DVec3::new(0.0013, 0.0, 0.0002);
    let t = 0.021;
    let h = 1e-7;
    let d = |a: usize| {
        let mut e = DVec3::ZERO;
        e[a] = h;
        (r.at(p + e, t) - r.at(p - e, t)) / (2.0 * h)
    };
    let (dx, dz) = (d(0), d(2));
    let scale = r.at(p, t).length() / 0.001;
    assert!(
        (dx.x + dz.z).abs() < 1e-6 * scale,
        "div B = {}",
        dx.x + dz.z
    );
    assert!(
        (dz.x - dx.z).abs() < 1e-6 * scale,
        "curl B = {}",
        dz.x - dx.z
    );
    // (m·∇)B against the differences.
    let m = DVec3::new(0.3, 0.0, -0.8);
    let (_, grad) = r.with_gradient(p, m, t);
    let fd = m.x * dx + m.z * dz;
    assert!(
        (grad - fd).length() < 1e-6 * fd.length(),
        "{grad} against {fd}"
    );
    // At a fixed point the field turns at nΩ: a quarter turn in
    // (π/2)/(nΩ), and at constant magnitude.
    let quarter = 0.5 * PI / (4.0 * r.angular_velocity);
    let (a, b) = (r.at(p, t), r.at(p, t + quarter));
    assert!(a.dot(b).abs() < 1e-12 * a.length_squared());
    assert!((a.length() - b.length()).abs() < 1e-12 * a.length());
}

/// A bead template: one sphere of radius `a` (40 µm carriers).
fn bead(a: f64) -> Arc<BodyTemplate> {
    BodyTemplate::sphere(a, 5000.0).unwrap()
}

fn bodies_at(points: &[DVec3]) -> RigidBodies {
    let mut b = RigidBodies::new();
    let k = b.add_template(bead(20e-6));
    for p in points {
        b.push(k, E::new(DVec3::ZERO, *p), DE::ZERO);
    }
    b
}

fn forces(model: &mut InducedDipoles, b: &RigidBodies, t: f64) -> Vec<DVec3> {
    let mut world = WorldFrame::default();
    world.update(b);
    let view = BodyView {
        bodies: b,
        world: &world,
        step: StepParameters { time: t, dt: 0.0 },
    };
    let mut w = vec![DE::ZERO; b.len()];
    model.add_wrenches(&view, &mut w);
    w.iter().map(|x| x.v).collect()
}

fn volume(a: f64) -> f64 {
    4.0 / 3.0 * PI * a * a * a
}

#[test]
fn one_bead_is_pulled_up_the_field_gradient() {
    let a = 20e-6;
    let alpha = InducedDipoles::polarisability(volume(a), 6.0);
    assert!((alpha - 3.0 * volume(a) * (5.0 / 8.0) / MU0).abs() < 1e-12 * alpha);
    let mut model = InducedDipoles {
        roller: roller(),
        polarisability: vec![alpha],
        saturation: vec![f64::INFINITY],
        dipole_dipole: 1e-7,
        iterations: 3,
        period: [0.0, 0.0],
        cutoff: f64::INFINITY,
    };
    let p = DVec3::new(0.0021, 0.0, 0.0003);
    let b = bodies_at(&[p]);
    let f = forces(&mut model, &b, 0.0)[0];
    // F = (α/2)∇|B|² = −α(n + 1)|B|²/r r̂ (towards the axis).
    let w = DVec3::new(p.x - model.roller.axis[0], 0.0, p.z - model.roller.axis[1]);
    let b2 = model.roller.at(p, 0.0).length_squared();
    let expected = -alpha * 5.0 * b2 / w.length_squared() * w;
    assert!(
        (f - expected).length() < 1e-10 * expected.length(),
        "{f} against {expected}"
    );
    // Saturated: the moment is M_s V along B, the force (m·∇)B with it.
    let cap = 0.1 * alpha * b2.sqrt();
    model.saturation = vec![cap];
    let f = forces(&mut model, &b, 0.0)[0];
    let bhat = model.roller.at(p, 0.0).normalize();
    let (_, grad) = model.roller.with_gradient(p, cap * bhat, 0.0);
    assert!((f - grad).length() < 1e-12 * grad.length());
    assert!((f.length() - 0.1 * expected.length()).abs() < 1e-9 * expected.length());
}

#[test]
fn two_beads_along_the_field_induce_each_other() {
    // Far below a roller of huge radius the field is uniform over the
    // pair: B₀ along x. Two beads on the x axis at distance d: by symmetry
    // m = α(B + 2k m/d³), so m = αB/(1 − 2kα/d³); they attract with
    // F = 6k m²/d⁴.
    let big = MagneticRoller {
        field: 0.05,
        poles: 2,
        radius: 1e9,
        angular_velocity: 0.0,
        axis: [0.0, 1e9],
    };
    let a = 20e-6;
    let alpha = InducedDipoles::polarisability(volume(a), 8.0);
    let k = 1e-7;
    let d = 45e-6;
    let mut model = InducedDipoles {
        roller: big,
        polarisability: vec![alpha],
        saturation: vec![f64::INFINITY],
        dipole_dipole: k,
        iterations: 60,
        period: [0.0, 0.0],
        cutoff: f64::INFINITY,
    };
    let b = bodies_at(&[
        DVec3::new(-0.5 * d, 0.0, 0.0),
        DVec3::new(0.5 * d, 0.0, 0.0),
    ]);
    let field = big.at(DVec3::ZERO, 0.0);
    assert!(field.z.abs() < 1e-12 * field.length());
    let m = alpha * field.x / (1.0 - 2.0 * k * alpha / d.powi(3));
    let f = forces(&mut model, &b, 0.0);
    let expected = 6.0 * k * m * m / d.powi(4);
    assert!(
        (f[0].x - expected).abs() < 1e-6 * expected,
        "{} against {expected}",
        f[0].x
    );
    assert!((f[0] + f[1]).length() < 1e-9 * expected);
    // Without mutual induction the moments are αB: a weaker attraction.
    let mut first = InducedDipoles {
        iterations: 0,
        ..model.clone()
    };
    let f0 = forces(&mut first, &b, 0.0);
    let m0 = alpha * field.x;
    assert!((f0[0].x - 6.0 * k * m0 * m0 / d.powi(4)).abs() < 1e-6 * expected);
}

#[test]
fn pair_forces_cancel_and_periodic_images_are_nearest() {
    let mut model = InducedDipoles {
        roller: roller(),
        polarisability: vec![InducedDipoles::polarisability(volume(20e-6), 5.0)],
        saturation: vec![f64::INFINITY],
        dipole_dipole: 1e-7,
        iterations: 2,
        period: [4e-4, 2e-4],
        cutoff: f64::INFINITY,
    };
    let points = [
        DVec3::new(0.0, 0.0, 0.0002),
        DVec3::new(3.7e-4, 1e-5, 0.00025),
        DVec3::new(1.5e-4, 1.8e-4, 0.00018),
        DVec3::new(2.0e-4, 0.5e-4, 0.0003),
    ];
    let b = bodies_at(&points);
    let t = 0.004;
    let f = forces(&mut model, &b, t);
    let (_, _, m) = model.moments(
        &BodyView {
            bodies: &b,
            world: &{
                let mut w = WorldFrame::default();
                w.update(&b);
                w
            },
            step: StepParameters { time: t, dt: 0.0 },
        },
        t,
    );
    // Σ F = Σ (m·∇)B of the roller: the pair forces cancel.
    let external: DVec3 = points
        .iter()
        .zip(&m)
        .map(|(p, mi)| model.roller.with_gradient(*p, *mi, t).1)
        .sum();
    let total: DVec3 = f.iter().copied().sum();
    let scale: f64 = f.iter().map(|v| v.length()).sum();
    assert!((total - external).length() < 1e-10 * scale);
    // Beads 0 and 1 are 3e-5 apart along x through the boundary: with the
    // periods they act as bead 1 moved by −L_x would without (in a field
    // uniform over the box: the roller's is not periodic along x).
    let mut model = InducedDipoles {
        roller: MagneticRoller {
            field: 0.05,
            poles: 2,
            radius: 1e9,
            angular_velocity: 0.0,
            axis: [0.0, 1e9],
        },
        ..model
    };
    let pair = bodies_at(&points[..2]);
    let moved = bodies_at(&[points[0], points[1] - DVec3::new(4e-4, 0.0, 0.0)]);
    let mut open = InducedDipoles {
        period: [0.0, 0.0],
        cutoff: f64::INFINITY,
        ..model.clone()
    };
    let (a, b) = (forces(&mut model, &pair, t), forces(&mut open, &moved, t));
    for i in 0..2 {
        assert!(
            (a[i] - b[i]).length() < 1e-6 * b[i].length(),
            "{} against {}",
            a[i],
            b[i]
        );
    }
}

/// The moments and forces of 29 beads (three blocks of eight and a tail),
/// some saturated, in a box periodic along x and y: the lanes give every
/// body the bits of the loops over pairs with the scalar dipole laws —
/// over all pairs, and with a cut-off over the pairs within it (the
/// loops then skip the others), found through the cells.
#[test]
fn lanes_give_the_bits_of_the_loops_over_pairs() {
    // All pairs; a cut-off beyond every pair (the same bits); cut-offs
    // that keep some pairs and not others (the list's cells fewer than
    // three along x and y, then four along x and three along y).
    for cutoff in [f64::INFINITY, 1e-3, 1.49e-4, 0.9e-4] {
        loops_over_pairs(cutoff);
    }
}

fn loops_over_pairs(cutoff: f64) {
    use mote_md::force::dipolar::{dipole_field, dipole_pair};
    let period = [4e-4, 3e-4];
    let alpha = InducedDipoles::polarisability(volume(20e-6), 6.0);
    let cap = alpha * 0.068;
    let mut model = InducedDipoles {
        roller: roller(),
        polarisability: vec![alpha],
        saturation: vec![cap],
        dipole_dipole: 1e-7,
        iterations: 2,
        period,
        cutoff,
    };
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut points: Vec<DVec3> = (0..29)
        .map(|_| {
            DVec3::new(
                period[0] * uniform(),
                period[1] * uniform(),
                1e-4 + 1.5e-4 * uniform(),
            )
        })
        .collect();
    // Two bodies outside the box, a period along x and y away.
    points[3].x += period[0];
    points[17].y -= period[1];
    let b = bodies_at(&points);
    let t = 0.0031;
    let f = forces(&mut model, &b, t);

    // The reference: the loops over pairs, one pair at a time.
    let image = |mut d: DVec3| {
        for a in 0..2 {
            d[a] -= (d[a] / period[a]).round() * period[a];
        }
        d
    };
    // The pairs the sums take: within the cut-off, minimum image.
    let (mut kept, mut left) = (0, 0);
    let near = |i: usize, j: usize| {
        let d = image(points[i] - points[j]);
        j != i && d.length_squared() < cutoff * cutoff
    };
    for i in 0..points.len() {
        for j in 0..points.len() {
            if j != i {
                if near(i, j) {
                    kept += 1;
                } else {
                    left += 1;
                }
            }
        }
    }
    if cutoff < 1e-3 {
        assert!(kept > 0 && left > 0, "{kept} pairs kept, {left} left out");
    } else {
        assert_eq!(left, 0, "the cut-off {cutoff} leaves out pairs");
    }
    let induce = |b: DVec3| {
        let m = alpha * b;
        if m.length() > cap {
            m * (cap / m.length())
        } else {
            m
        }
    };
    let external: Vec<DVec3> = points.iter().map(|p| model.roller.at(*p, t)).collect();
    let mut m: Vec<DVec3> = external.iter().map(|b| induce(*b)).collect();
    for _ in 0..2 {
        m = (0..points.len())
            .map(|i| {
                let mut local = external[i];
                for j in (0..points.len()).filter(|&j| near(i, j)) {
                    let d = image(points[i] - points[j]);
                    local += dipole_field(1e-7, m[j], d, 1.0 / d.length_squared());
                }
                induce(local)
            })
            .collect();
    }
    let saturated = m
        .iter()
        .filter(|v| v.length() >= cap * (1.0 - 1e-12))
        .count();
    assert!(
        saturated > 0 && saturated < m.len(),
        "{saturated} saturated"
    );
    for i in 0..points.len() {
        let (_, mut expected) = model.roller.with_gradient(points[i], m[i], t);
        for j in (0..points.len()).filter(|&j| near(i, j)) {
            let d = image(points[i] - points[j]);
            expected += dipole_pair(1e-7, d, 1.0 / d.length_squared(), m[i], m[j]).1;
        }
        assert_eq!(
            f[i].to_array().map(f64::to_bits),
            expected.to_array().map(f64::to_bits),
            "body {i}, cut-off {cutoff}: {} against {expected}",
            f[i]
        );
    }
}
