//! Bodies from a frame of spheres (`[[from_file]]` of a rigid scene): the spheres of
//! each body (grouped by the frame's body column) are matched to one of the
//! scene's templates, and the body's placement g = E(r, x) and velocity
//! h = dE(ω, v) are recovered from them.
//!
//! * Rotation: from the frame's orientation quaternion q = (1, r)/√(1 + r²)
//!   when it has one (r = q_v/q₀, exact), else by the least-squares fit of
//!   the template's sphere centres cₖ onto the file's yₖ (Horn 1987,
//!   J. Opt. Soc. Am. A 4, 629: the unit quaternion maximising Σ yₖ·(R cₖ)
//!   is the eigenvector of the largest eigenvalue of a symmetric 4×4 matrix
//!   built from M = Σ cₖ yₖᵀ).
//! * Centre of mass: x = ȳ − R c̄ (bars: means over the body's spheres).
//! * Velocity: with the frame's angular velocities, ω is their mean and
//!   v = mean(vₖ − ω × (yₖ − x)); without them ω is the least-squares
//!   solution of vₖ − v̄ = ω × (yₖ − ȳ), i.e. G ω = Σ dₖ × uₖ with
//!   G = Σ (|dₖ|² 1 − dₖ dₖᵀ) (pseudo-inverse: the spin of a sphere or
//!   about a line of spheres is not seen in their velocities, taken as 0).
//!
//! A body fits a template when it has as many spheres, with the same radii
//! in the same order (relative 1e-6), and the fitted centres lie within
//! 1e-6 of the template's bounding radius of the file's (files written with
//! fewer digits need `tolerance`).

use std::sync::Arc;

use glam::DVec3;
use mote_geom::{rotate, DE, E};
use mote_io::xyz::Frame;

use super::template::{principal, BodyTemplate};

/// One body's spheres as read: world centres, radii, velocities.
struct Spheres {
    centres: Vec<DVec3>,
    radii: Vec<f64>,
    velocities: Vec<DVec3>,
    omegas: Vec<DVec3>,
    orientation: Option<[f64; 4]>,
}

/// A body matched to a template: index into the candidates, placement and
/// velocity.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    pub template: usize,
    pub placement: E,
    pub velocity: DE,
}

/// The bodies of `frame`, each placed as one of `templates` (tried in
/// order; the first that fits is taken). Spheres without a body column are
/// bodies of one sphere each. On periodic axes a body's spheres are
/// unwrapped to the minimum image of its first sphere. `tolerance`: the
/// largest misfit of a sphere centre as a fraction of the template's
/// bounding radius.
pub fn place_bodies(
    frame: &Frame,
    templates: &[(String, Arc<BodyTemplate>)],
    tolerance: f64,
) -> Result<Vec<Placed>, String> {
    let n = frame.positions.len();
    if n == 0 {
        return Err("the frame has no spheres".into());
    }
    if frame.radii.len() != n {
        return Err(
            "the frame gives no radii: rigid bodies are matched to templates by their sphere radii"
                .into(),
        );
    }
    // Group spheres by body id, bodies in order of first appearance.
    let mut order: Vec<u64> = Vec::new();
    let mut members: std::collections::HashMap<u64, Vec<usize>> = Default::default();
    for i in 0..n {
        let id = if frame.bodies.len() == n {
            frame.bodies[i]
        } else {
            i as u64
        };
        members
            .entry(id)
            .or_insert_with(|| {
                order.push(id);
                Vec::new()
            })
            .push(i);
    }
    let period = |d: usize| frame.cell[d][d];
    let vec_of = |v: &Vec<[f64; 3]>, i: usize| {
        if v.len() == n {
            DVec3::from(v[i])
        } else {
            DVec3::ZERO
        }
    };
    let mut placed = Vec::with_capacity(order.len());
    for id in order {
        let idx = &members[&id];
        let first = DVec3::from(frame.positions[idx[0]]);
        let centres = idx
            .iter()
            .map(|&i| {
                let mut y = DVec3::from(frame.positions[i]);
                for d in 0..3 {
                    let l = period(d);
                    if frame.pbc[d] && l > 0.0 {
                        y[d] -= l * ((y[d] - first[d]) / l).round();
                    }
                }
                y
            })
            .collect();
        let spheres = Spheres {
            centres,
            radii: idx.iter().map(|&i| frame.radii[i]).collect(),
            velocities: idx.iter().map(|&i| vec_of(&frame.velocities, i)).collect(),
            omegas: if frame.angular_velocities.len() == n {
                idx.iter()
                    .map(|&i| DVec3::from(frame.angular_velocities[i]))
                    .collect()
            } else {
                Vec::new()
            },
            orientation: (frame.orientations.len() == n).then(|| frame.orientations[idx[0]]),
        };
        let mut nearest: Option<(f64, usize)> = None;
        let mut found = None;
        for (k, (_, t)) in templates.iter().enumerate() {
            let Some(misfit) = fit(t, &spheres) else {
                continue;
            };
            let rel = misfit.1 / t.props.bounding_radius;
            if rel <= tolerance {
                found = Some((k, misfit.0));
                break;
            }
            if nearest.is_none_or(|(m, _)| rel < m) {
                nearest = Some((rel, k));
            }
        }
        let (k, placement) = found.ok_or_else(|| {
            let what = format!(
                "body {id} ({} sphere{}, radii {:?}) fits no template",
                spheres.radii.len(),
                if spheres.radii.len() == 1 { "" } else { "s" },
                spheres.radii
            );
            match nearest {
                Some((rel, k)) => format!(
                    "{what}: the nearest, template '{}', misses by {rel:.2e} of its bounding radius (tolerance {tolerance:.0e})",
                    templates[k].0
                ),
                None => format!("{what}: none has these sphere radii in this order"),
            }
        })?;
        placed.push(Placed {
            template: k,
            placement,
            velocity: body_velocity(&spheres, placement.a),
        });
    }
    Ok(placed)
}

/// The placement of `t` that best fits the spheres and the largest distance
/// of a fitted centre from the file's; `None` when counts or radii differ.
fn fit(t: &BodyTemplate, s: &Spheres) -> Option<(E, f64)> {
    if t.radii.len() != s.radii.len()
        || t.radii
            .iter()
            .zip(&s.radii)
            .any(|(a, b)| (a - b).abs() > 1e-6 * a.abs().max(b.abs()))
    {
        return None;
    }
    let m = s.centres.len() as f64;
    let ybar = s.centres.iter().sum::<DVec3>() / m;
    let cbar = t.centres.iter().sum::<DVec3>() / m;
    let r = match s.orientation {
        Some(q) if q[0] != 0.0 => {
            let s = q[0].signum();
            DVec3::new(q[1], q[2], q[3]) * s / (q[0] * s)
        }
        _ => {
            let c: Vec<DVec3> = t.centres.iter().map(|c| *c - cbar).collect();
            let y: Vec<DVec3> = s.centres.iter().map(|y| *y - ybar).collect();
            horn_rotation(&c, &y)
        }
    };
    let x = ybar - rotate(cbar, r);
    let misfit = t
        .centres
        .iter()
        .zip(&s.centres)
        .map(|(c, y)| (x + rotate(*c, r) - *y).length())
        .fold(0.0, f64::max);
    Some((E::new(r, x), misfit))
}

/// The rotation vector of the rotation R minimising Σ |R aₖ − bₖ|² (both
/// sets centred), by Horn's quaternion method.
pub(crate) fn horn_rotation(a: &[DVec3], b: &[DVec3]) -> DVec3 {
    let mut s = [[0.0; 3]; 3];
    for (a, b) in a.iter().zip(b) {
        for p in 0..3 {
            for q in 0..3 {
                s[p][q] += a[p] * b[q];
            }
        }
    }
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = s;
    let n = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let q = largest_eigenvector4(n);
    let q = if q[0] < 0.0 { q.map(|x| -x) } else { q };
    // A half turn (q₀ = 0) has |r| = ∞; 1e-150 keeps it finite and exact to
    // far below f64 resolution (`rotate` handles |r| > 1e50).
    DVec3::new(q[1], q[2], q[3]) / q[0].max(1e-150)
}

/// The unit eigenvector of the largest eigenvalue of a symmetric 4×4
/// matrix, by cyclic Jacobi rotations.
fn largest_eigenvector4(mut a: [[f64; 4]; 4]) -> [f64; 4] {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..60 {
        let off: f64 = (0..4)
            .flat_map(|p| (p + 1..4).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q].abs())
            .sum();
        let scale: f64 = (0..4)
            .map(|i| a[i][i].abs())
            .sum::<f64>()
            .max(f64::MIN_POSITIVE);
        if off <= 1e-17 * scale {
            break;
        }
        for p in 0..4 {
            for q in p + 1..4 {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = if theta == 0.0 {
                    1.0
                } else {
                    theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
                };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (kp, kq) = (row[p], row[q]);
                    row[p] = c * kp - s * kq;
                    row[q] = s * kp + c * kq;
                }
                for k in 0..4 {
                    let (pk, qk) = (a[p][k], a[q][k]);
                    a[p][k] = c * pk - s * qk;
                    a[q][k] = s * pk + c * qk;
                }
                for row in v.iter_mut() {
                    let (kp, kq) = (row[p], row[q]);
                    row[p] = c * kp - s * kq;
                    row[q] = s * kp + c * kq;
                }
            }
        }
    }
    let best = (0..4).max_by(|&i, &j| a[i][i].total_cmp(&a[j][j])).unwrap();
    let e = [v[0][best], v[1][best], v[2][best], v[3][best]];
    let norm = e.iter().map(|x| x * x).sum::<f64>().sqrt();
    e.map(|x| x / norm)
}

/// ω and v of the body whose centre of mass is `x` (see the module doc).
fn body_velocity(s: &Spheres, x: DVec3) -> DE {
    let m = s.centres.len() as f64;
    let omega = if !s.omegas.is_empty() {
        s.omegas.iter().sum::<DVec3>() / m
    } else {
        let ybar = s.centres.iter().sum::<DVec3>() / m;
        let vbar = s.velocities.iter().sum::<DVec3>() / m;
        let mut g = [[0.0; 3]; 3];
        let mut rhs = DVec3::ZERO;
        for (y, v) in s.centres.iter().zip(&s.velocities) {
            let d = *y - ybar;
            rhs += d.cross(*v - vbar);
            let dd = d.length_squared();
            for p in 0..3 {
                for q in 0..3 {
                    g[p][q] += if p == q { dd } else { 0.0 } - d[p] * d[q];
                }
            }
        }
        let (vals, axes) = principal(&g);
        let top = vals[2].abs();
        axes.iter()
            .zip(vals)
            .filter(|(_, l)| top > 0.0 && l.abs() > 1e-9 * top)
            .map(|(e, l)| e.dot(rhs) / l * *e)
            .sum()
    };
    let v = s
        .centres
        .iter()
        .zip(&s.velocities)
        .map(|(y, v)| *v - omega.cross(*y - x))
        .sum::<DVec3>()
        / m;
    DE::new(omega, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rigid::template::{ClumpSpec, Integration};

    fn trimer() -> Arc<BodyTemplate> {
        let spec = crate::rigid::shapes::linear_trimer(0.5, 0.8, 1.0);
        BodyTemplate::new(&spec, Integration::default()).unwrap()
    }

    fn bent() -> Arc<BodyTemplate> {
        let spec = ClumpSpec {
            centres: vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.9, 0.2)],
            radii: vec![0.6, 0.5, 0.4],
            density: 2.0,
            youngs_modulus: 0.0,
            poisson_ratio: 0.0,
            charge: 0.0,
            dipole: DVec3::ZERO,
        };
        BodyTemplate::new(&spec, Integration::default()).unwrap()
    }

    fn named(t: &[Arc<BodyTemplate>]) -> Vec<(String, Arc<BodyTemplate>)> {
        t.iter()
            .enumerate()
            .map(|(k, t)| (format!("t{k}"), t.clone()))
            .collect()
    }

    /// The spheres of body (t, g, h) as a frame's rows.
    fn rows(t: &BodyTemplate, g: E, h: DE, frame: &mut Frame, id: u64) {
        for (c, r) in t.centres.iter().zip(&t.radii) {
            let y = g.a + rotate(*c, g.r);
            frame.positions.push(y.to_array());
            frame.radii.push(*r);
            frame
                .velocities
                .push((h.v + h.omega.cross(y - g.a)).to_array());
            frame.bodies.push(id);
        }
    }

    #[test]
    fn placements_and_velocities_come_back_without_orientations() {
        let (a, b) = (trimer(), bent());
        let bodies = [
            (
                1,
                E::new(DVec3::new(0.3, -2.0, 0.7), DVec3::new(1.0, 2.0, 3.0)),
                DE::new(DVec3::new(0.5, -1.0, 2.0), DVec3::new(1.0, 0.0, -1.0)),
            ),
            (
                0,
                E::new(DVec3::new(-0.2, 0.1, 0.4), DVec3::new(-1.0, 0.0, 5.0)),
                DE::new(DVec3::ZERO, DVec3::new(0.0, 3.0, 0.0)),
            ),
            (
                1,
                E::new(DVec3::new(40.0, 10.0, -3.0), DVec3::ZERO),
                DE::new(DVec3::new(0.0, 0.0, -4.0), DVec3::ZERO),
            ),
        ];
        let mut frame = Frame::default();
        for (id, (k, g, h)) in bodies.iter().enumerate() {
            let t = if *k == 0 { &a } else { &b };
            rows(t, *g, *h, &mut frame, 10 + id as u64);
        }
        let placed = place_bodies(&frame, &named(&[a.clone(), b.clone()]), 1e-9).unwrap();
        assert_eq!(placed.len(), 3);
        for (p, (k, g, h)) in placed.iter().zip(&bodies) {
            assert_eq!(p.template, *k);
            let t = if *k == 0 { &a } else { &b };
            // The trimer's spin and orientation about its axis are not seen
            // in its spheres, and its template's centre of mass is off the
            // axis by the integration error (1e-7): compare where the
            // spheres are.
            if *k == 1 {
                assert!(
                    (p.placement.a - g.a).length() < 1e-12,
                    "{:?} {:?}",
                    p.placement,
                    g
                );
            }
            for c in &t.centres {
                let d = rotate(*c, p.placement.r) - rotate(*c, g.r);
                let d = d + p.placement.a - g.a;
                assert!(d.length() < 1e-12, "{d}");
            }
            assert!((p.velocity.v - h.v).length() < 1e-12);
            if *k == 1 {
                assert!((p.velocity.omega - h.omega).length() < 1e-12);
            }
        }
    }

    #[test]
    fn orientations_and_spins_in_the_frame_are_used() {
        let a = trimer();
        let g = E::new(DVec3::new(0.2, 0.5, -0.1), DVec3::new(3.0, 1.0, 0.0));
        let h = DE::new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.0, 1.0));
        let mut frame = Frame::default();
        rows(&a, g, h, &mut frame, 0);
        let c = 1.0 / (1.0 + g.r.length_squared()).sqrt();
        frame.orientations = vec![[c, g.r.x * c, g.r.y * c, g.r.z * c]; 3];
        frame.angular_velocities = vec![h.omega.to_array(); 3];
        let p = place_bodies(&frame, &named(&[a]), 1e-9).unwrap();
        assert!((p[0].placement.r - g.r).length() < 1e-14);
        assert!((p[0].velocity.omega - h.omega).length() < 1e-14);
        assert!((p[0].velocity.v - h.v).length() < 1e-12);
    }

    #[test]
    fn a_body_split_by_the_periodic_box_is_joined() {
        let a = bent();
        let g = E::new(DVec3::new(0.0, 0.0, 0.3), DVec3::new(9.9, 5.0, 5.0));
        let mut frame = Frame::default();
        rows(&a, g, DE::ZERO, &mut frame, 0);
        frame.cell = [[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]];
        frame.pbc = [true; 3];
        for p in &mut frame.positions {
            p[0] = p[0].rem_euclid(10.0);
        }
        let p = place_bodies(&frame, &named(&[a]), 1e-9).unwrap();
        let x = p[0].placement.a;
        assert!((x.x.rem_euclid(10.0) - 9.9).abs() < 1e-12, "{x}");
    }

    #[test]
    fn a_misfit_is_refused_with_the_body_and_the_miss() {
        let a = trimer();
        let mut frame = Frame::default();
        rows(&a, E::IDENTITY, DE::ZERO, &mut frame, 7);
        frame.positions[2][0] += 0.1;
        let e = place_bodies(&frame, &named(std::slice::from_ref(&a)), 1e-6).unwrap_err();
        assert!(e.contains("body 7") && e.contains("misses by"), "{e}");
        frame.radii[1] = 0.3;
        let e = place_bodies(&frame, &named(&[a]), 1e-6).unwrap_err();
        assert!(e.contains("none has these sphere radii"), "{e}");
    }

    #[test]
    fn horn_finds_a_half_turn() {
        let a = [DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, 2.0)];
        let r = DVec3::new(0.0, 0.0, 1e100); // π about z
        let b: Vec<DVec3> = a.iter().map(|x| rotate(*x, r)).collect();
        let got = horn_rotation(&a, &b);
        for (x, y) in a.iter().zip(&b) {
            assert!((rotate(*x, got) - *y).length() < 1e-12);
        }
    }
}
