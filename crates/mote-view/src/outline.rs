//! Walls as line segments for the page: a plane is drawn where it cuts the
//! scene's extent (a box around the particles and the cell), a cylinder as
//! its two end circles and four lines along it that turn with it.

use glam::DVec3;
use mote_run::WallGeometry;

type V = [f64; 3];

/// Two unit vectors u, v with (u, v, n) right-handed and orthonormal.
fn basis(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = helper.cross(n).normalize();
    (u, n.cross(u))
}

fn corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|k| {
        DVec3::select(glam::BVec3::new(k & 1 == 1, k & 2 == 2, k & 4 == 4), hi, lo)
    })
}

/// The box around the particles (each grown by its radius), the cell and
/// the walls' reference points (a plane's point; a cylinder's point grown
/// by its radius), cut by the planes across an axis.
pub fn extent(frame: &mote_io::xyz::Frame, walls: &[WallGeometry]) -> (V, V) {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    let mut take = |p: DVec3, r: f64| {
        lo = lo.min(p - r);
        hi = hi.max(p + r);
    };
    for w in walls {
        match *w {
            WallGeometry::Plane { point, .. } => take(point.into(), 0.0),
            WallGeometry::Cylinder { point, radius, .. } => take(point.into(), radius),
        }
    }
    for (i, p) in frame.positions.iter().enumerate() {
        take((*p).into(), frame.radii.get(i).copied().unwrap_or(0.0));
    }
    let c = frame.cell.map(DVec3::from);
    if c[0].x * c[1].y * c[2].z != 0.0 {
        for k in corners(DVec3::ZERO, DVec3::ONE) {
            take(
                DVec3::from(frame.origin) + k.x * c[0] + k.y * c[1] + k.z * c[2],
                0.0,
            );
        }
    }
    if lo.x > hi.x || lo.x.is_nan() {
        return ([0.0; 3], [1.0; 3]);
    }
    // A plane across an axis bounds the scene on its side: the extent ends
    // there (a closed box of walls is then drawn as exactly its faces,
    // whatever margin the cell has).
    for w in walls {
        if let WallGeometry::Plane { point, normal } = *w {
            let n = DVec3::from(normal).normalize();
            for a in 0..3 {
                if n[a] > 1.0 - 1e-12 {
                    lo[a] = point[a];
                } else if n[a] < -1.0 + 1e-12 {
                    hi[a] = point[a];
                }
            }
        }
    }
    (lo.to_array(), hi.to_array())
}

/// Segments (x0, y0, z0, x1, y1, z1) drawing `walls` within [lo, hi].
pub fn outlines(walls: &[WallGeometry], lo: V, hi: V) -> Vec<[f64; 6]> {
    let (lo, hi) = (DVec3::from(lo), DVec3::from(hi));
    let segment = |a: DVec3, b: DVec3| [a.x, a.y, a.z, b.x, b.y, b.z];
    let mut out = Vec::new();
    let box_corners = corners(lo, hi);
    let size = (hi - lo).length().max(f64::MIN_POSITIVE);
    for w in walls {
        match *w {
            WallGeometry::Plane { point, normal } => {
                let (point, n) = (DVec3::from(point), DVec3::from(normal).normalize());
                // Where the box's twelve edges cross the plane.
                let tol = 1e-12 * size;
                let mut hits: Vec<DVec3> = Vec::new();
                for (i, &a) in box_corners.iter().enumerate() {
                    for bit in 0..3 {
                        if i >> bit & 1 == 1 {
                            continue;
                        }
                        let b = box_corners[i | 1 << bit];
                        let (da, db) = ((a - point).dot(n), (b - point).dot(n));
                        if da.abs() <= tol {
                            hits.push(a);
                        }
                        if db.abs() <= tol {
                            hits.push(b);
                        }
                        if (da < -tol && db > tol) || (da > tol && db < -tol) {
                            hits.push(a + (b - a) * (da / (da - db)));
                        }
                    }
                }
                let mut unique: Vec<DVec3> = Vec::new();
                for h in hits {
                    if unique.iter().all(|u| u.distance(h) > 1e-9 * size) {
                        unique.push(h);
                    }
                }
                if unique.len() < 3 {
                    continue;
                }
                // Round the polygon in order of angle about its centre.
                let centre = unique.iter().sum::<DVec3>() / unique.len() as f64;
                let (u, v) = basis(n);
                let angle = |x: &DVec3| (*x - centre).dot(v).atan2((*x - centre).dot(u));
                unique.sort_by(|p, q| angle(p).total_cmp(&angle(q)));
                for k in 0..unique.len() {
                    out.push(segment(unique[k], unique[(k + 1) % unique.len()]));
                }
            }
            WallGeometry::Cylinder {
                point,
                axis,
                radius,
                angle,
            } => {
                let (point, n) = (DVec3::from(point), DVec3::from(axis).normalize());
                let (u, v) = basis(n);
                let (s0, s1) = box_corners
                    .iter()
                    .map(|c| (*c - point).dot(n))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                        (a.min(s), b.max(s))
                    });
                let at =
                    |s: f64, phi: f64| point + s * n + radius * (phi.cos() * u + phi.sin() * v);
                let steps = 48;
                let turn = |k: usize| std::f64::consts::TAU * k as f64 / steps as f64;
                for s in [s0, s1] {
                    for k in 0..steps {
                        out.push(segment(at(s, turn(k)), at(s, turn(k + 1))));
                    }
                }
                for k in 0..4 {
                    let phi = angle + std::f64::consts::FRAC_PI_2 * k as f64;
                    out.push(segment(at(s0, phi), at(s1, phi)));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_across_a_box_is_its_cross_section() {
        // z = 0.5 across the unit cube: a square of four edges, at z = 0.5.
        let plane = WallGeometry::Plane {
            point: [0.0, 0.0, 0.5],
            normal: [0.0, 0.0, 1.0],
        };
        let lines = outlines(&[plane], [0.0; 3], [1.0; 3]);
        assert_eq!(lines.len(), 4);
        let length: f64 = lines
            .iter()
            .map(|l| DVec3::new(l[0], l[1], l[2]).distance(DVec3::new(l[3], l[4], l[5])))
            .sum();
        assert!((length - 4.0).abs() < 1e-12);
        assert!(lines.iter().all(|l| l[2] == 0.5 && l[5] == 0.5));
        // A face of the box is the face; a plane outside draws nothing.
        let face = WallGeometry::Plane {
            point: [0.0; 3],
            normal: [1.0, 0.0, 0.0],
        };
        assert_eq!(outlines(&[face], [0.0; 3], [1.0; 3]).len(), 4);
        let outside = WallGeometry::Plane {
            point: [2.0, 0.0, 0.0],
            normal: [1.0, 0.0, 0.0],
        };
        assert!(outlines(&[outside], [0.0; 3], [1.0; 3]).is_empty());
        // A diagonal plane through the cube's centre cuts a hexagon.
        let diagonal = WallGeometry::Plane {
            point: [0.5; 3],
            normal: [1.0, 1.0, 1.0],
        };
        assert_eq!(outlines(&[diagonal], [0.0; 3], [1.0; 3]).len(), 6);
    }

    #[test]
    fn a_closed_box_of_walls_is_the_extent() {
        let frame = mote_io::xyz::Frame {
            positions: vec![[0.5, 0.5, 0.2]],
            radii: vec![0.1],
            cell: [[1.2, 0.0, 0.0], [0.0, 1.2, 0.0], [0.0, 0.0, 1.2]],
            origin: [-0.1; 3],
            ..Default::default()
        };
        let mut walls = Vec::new();
        for a in 0..3 {
            let mut n = [0.0; 3];
            n[a] = 1.0;
            walls.push(WallGeometry::Plane {
                point: [0.0; 3],
                normal: n,
            });
            n[a] = -1.0;
            walls.push(WallGeometry::Plane {
                point: [1.0; 3],
                normal: n,
            });
        }
        assert_eq!(extent(&frame, &walls), ([0.0; 3], [1.0; 3]));
        let (lo, hi) = extent(&frame, &[]);
        assert!(lo
            .iter()
            .chain(&hi)
            .zip([-0.1, -0.1, -0.1, 1.1, 1.1, 1.1])
            .all(|(a, b)| (a - b).abs() < 1e-12));
    }

    #[test]
    fn a_cylinder_is_two_circles_and_four_turning_lines() {
        let drum = WallGeometry::Cylinder {
            point: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            radius: 2.0,
            angle: 0.3,
        };
        let lines = outlines(&[drum], [-1.0; 3], [1.0; 3]);
        assert_eq!(lines.len(), 2 * 48 + 4);
        // Every end point lies on the cylinder, the ends at z = ±1.
        for l in &lines {
            for p in [[l[0], l[1], l[2]], [l[3], l[4], l[5]]] {
                assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 2.0).abs() < 1e-12);
                assert!((p[2].abs() - 1.0).abs() < 1e-12);
            }
        }
        // The first turning line sits at its angle from the first circle's start.
        let first = lines[2 * 48];
        let start = lines[0];
        let turned = first[1].atan2(first[0]) - start[1].atan2(start[0]);
        assert!((turned - 0.3).abs() < 1e-12, "{turned}");
    }
}
