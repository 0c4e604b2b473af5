//! Walls as line segments for the page: a plane is drawn where it cuts the
//! scene's extent (a box around the particles and the cell), a cylinder as
//! its two end circles and four lines along it that turn with it.

use mote_run::WallGeometry;

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn axpy(a: f64, x: V, y: V) -> V {
    [a * x[0] + y[0], a * x[1] + y[1], a * x[2] + y[2]]
}
fn unit(a: V) -> V {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        a.map(|x| x / l)
    } else {
        [1.0, 0.0, 0.0]
    }
}

/// Two unit vectors u, v with (u, v, n) right-handed and orthonormal.
fn basis(n: V) -> (V, V) {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = unit(cross(helper, n));
    (u, cross(n, u))
}

fn corners(lo: V, hi: V) -> [V; 8] {
    let mut c = [[0.0; 3]; 8];
    for (k, p) in c.iter_mut().enumerate() {
        for a in 0..3 {
            p[a] = if k >> a & 1 == 1 { hi[a] } else { lo[a] };
        }
    }
    c
}

/// The box around the particles (each grown by its radius), the cell and
/// the walls' reference points (a plane's point; a cylinder's point grown
/// by its radius), cut by the planes across an axis.
pub fn extent(frame: &mote_io::xyz::Frame, walls: &[WallGeometry]) -> (V, V) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for w in walls {
        let (p, r) = match *w {
            WallGeometry::Plane { point, .. } => (point, 0.0),
            WallGeometry::Cylinder { point, radius, .. } => (point, radius),
        };
        for a in 0..3 {
            lo[a] = lo[a].min(p[a] - r);
            hi[a] = hi[a].max(p[a] + r);
        }
    }
    for (i, p) in frame.positions.iter().enumerate() {
        let r = frame.radii.get(i).copied().unwrap_or(0.0);
        for a in 0..3 {
            lo[a] = lo[a].min(p[a] - r);
            hi[a] = hi[a].max(p[a] + r);
        }
    }
    let c = frame.cell;
    if c[0][0] * c[1][1] * c[2][2] != 0.0 {
        for k in corners([0.0; 3], [1.0; 3]) {
            let p: V = std::array::from_fn(|a| {
                frame.origin[a] + k[0] * c[0][a] + k[1] * c[1][a] + k[2] * c[2][a]
            });
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    if lo[0] > hi[0] || lo[0].is_nan() {
        return ([0.0; 3], [1.0; 3]);
    }
    // A plane across an axis bounds the scene on its side: the extent ends
    // there (a closed box of walls is then drawn as exactly its faces,
    // whatever margin the cell has).
    for w in walls {
        if let WallGeometry::Plane { point, normal } = *w {
            let n = unit(normal);
            for a in 0..3 {
                if n[a] > 1.0 - 1e-12 {
                    lo[a] = point[a];
                } else if n[a] < -1.0 + 1e-12 {
                    hi[a] = point[a];
                }
            }
        }
    }
    (lo, hi)
}

/// Segments (x0, y0, z0, x1, y1, z1) drawing `walls` within [lo, hi].
pub fn outlines(walls: &[WallGeometry], lo: V, hi: V) -> Vec<[f64; 6]> {
    let mut out = Vec::new();
    let box_corners = corners(lo, hi);
    let size = dot(sub(hi, lo), sub(hi, lo)).sqrt().max(f64::MIN_POSITIVE);
    for w in walls {
        match *w {
            WallGeometry::Plane { point, normal } => {
                let n = unit(normal);
                // Where the box's twelve edges cross the plane.
                let mut hits: Vec<V> = Vec::new();
                for (i, a) in box_corners.iter().enumerate() {
                    for bit in 0..3 {
                        if i >> bit & 1 == 1 {
                            continue;
                        }
                        let b = box_corners[i | 1 << bit];
                        let (da, db) = (dot(sub(*a, point), n), dot(sub(b, point), n));
                        let tol = 1e-12 * size;
                        if da.abs() <= tol {
                            hits.push(*a);
                        }
                        if db.abs() <= tol {
                            hits.push(b);
                        }
                        if (da < -tol && db > tol) || (da > tol && db < -tol) {
                            hits.push(axpy(da / (da - db), sub(b, *a), *a));
                        }
                    }
                }
                let mut unique: Vec<V> = Vec::new();
                for h in hits {
                    if unique
                        .iter()
                        .all(|u| dot(sub(*u, h), sub(*u, h)).sqrt() > 1e-9 * size)
                    {
                        unique.push(h);
                    }
                }
                if unique.len() < 3 {
                    continue;
                }
                // Round the polygon in order of angle about its centre.
                let centre = unique
                    .iter()
                    .fold([0.0; 3], |c, p| axpy(1.0 / unique.len() as f64, *p, c));
                let (u, v) = basis(n);
                unique.sort_by(|p, q| {
                    let angle = |x: &V| dot(sub(*x, centre), v).atan2(dot(sub(*x, centre), u));
                    angle(p).total_cmp(&angle(q))
                });
                for k in 0..unique.len() {
                    let (a, b) = (unique[k], unique[(k + 1) % unique.len()]);
                    out.push([a[0], a[1], a[2], b[0], b[1], b[2]]);
                }
            }
            WallGeometry::Cylinder {
                point,
                axis,
                radius,
                angle,
            } => {
                let n = unit(axis);
                let (u, v) = basis(n);
                let along: Vec<f64> = box_corners.iter().map(|c| dot(sub(*c, point), n)).collect();
                let (s0, s1) = along
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                        (a.min(*s), b.max(*s))
                    });
                let at = |s: f64, phi: f64| {
                    let radial = axpy(phi.sin(), v, u.map(|x| x * phi.cos()));
                    axpy(radius, radial, axpy(s, n, point))
                };
                let steps = 48;
                for s in [s0, s1] {
                    for k in 0..steps {
                        let (p0, p1) = (
                            2.0 * std::f64::consts::PI * k as f64 / steps as f64,
                            2.0 * std::f64::consts::PI * (k + 1) as f64 / steps as f64,
                        );
                        let (a, b) = (at(s, p0), at(s, p1));
                        out.push([a[0], a[1], a[2], b[0], b[1], b[2]]);
                    }
                }
                for k in 0..4 {
                    let phi = angle + std::f64::consts::FRAC_PI_2 * k as f64;
                    let (a, b) = (at(s0, phi), at(s1, phi));
                    out.push([a[0], a[1], a[2], b[0], b[1], b[2]]);
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
            .map(|l| {
                dot(
                    sub([l[3], l[4], l[5]], [l[0], l[1], l[2]]),
                    sub([l[3], l[4], l[5]], [l[0], l[1], l[2]]),
                )
                .sqrt()
            })
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
