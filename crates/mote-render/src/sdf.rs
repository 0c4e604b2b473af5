//! Metrical indicator functions (signed-distance functions) of bodies, and
//! sphere tracing to find where a ray first meets them.
//!
//! Seed 000, "A detour on graphical representation": a body is described by a
//! function that is negative inside, positive outside and approximately the
//! distance to the surface near it; a sphere is `f(p) = |p − c| − r`. Bodies are
//! combined with **union = min** and **intersection = max** (the seed's text has
//! the two swapped; see shared/seeds/README.md), and a complement is `−f`.
//!
//! Sharp edges (where two pieces of a union or intersection meet) are handled by
//! taking the normal from the gradient of the piece that is active at the hit
//! point — the one that attains the min or max — instead of by finite differences
//! across the edge, which would round the edge off.

use glam::Vec3;

use crate::bvh::Ray;

/// A body given by its metrical indicator function.
#[derive(Debug, Clone, PartialEq)]
pub enum Sdf {
    /// `|p − c| − r`.
    Sphere { center: Vec3, radius: f32 },
    /// An axis-aligned box of half sizes `half` about `center` (exact distance).
    Cuboid { center: Vec3, half: Vec3 },
    /// The half space `n·p ≤ d` (`n` of unit length): `n·p − d`.
    HalfSpace { normal: Vec3, offset: f32 },
    /// A finite cylinder along the segment a–b with radius r (exact distance).
    Cylinder { a: Vec3, b: Vec3, radius: f32 },
    /// Union of bodies: the minimum of their functions.
    Union(Vec<Sdf>),
    /// Intersection of bodies: the maximum of their functions.
    Intersection(Vec<Sdf>),
    /// Complement: `−f` (so a difference A∖B is `Intersection[A, Complement(B)]`).
    Complement(Box<Sdf>),
}

impl Sdf {
    /// The value of the indicator function at `p`.
    pub fn eval(&self, p: Vec3) -> f32 {
        self.eval_grad(p).0
    }

    /// The value and the gradient (outward normal direction) at `p`; at an edge
    /// the gradient is that of the active piece.
    pub fn eval_grad(&self, p: Vec3) -> (f32, Vec3) {
        match self {
            Sdf::Sphere { center, radius } => {
                let d = p - *center;
                let len = d.length();
                let g = if len > 0.0 { d / len } else { Vec3::Z };
                (len - radius, g)
            }
            Sdf::Cuboid { center, half } => {
                let d = p - *center;
                let q = d.abs() - *half;
                let outside = q.max(Vec3::ZERO);
                let out_len = outside.length();
                if out_len > 0.0 {
                    (out_len, (outside * d.signum()) / out_len)
                } else {
                    // Inside: the nearest face.
                    let m = q.max_element();
                    let axis = if q.x == m {
                        Vec3::X
                    } else if q.y == m {
                        Vec3::Y
                    } else {
                        Vec3::Z
                    };
                    (m, axis * d.signum())
                }
            }
            Sdf::HalfSpace { normal, offset } => (normal.dot(p) - offset, *normal),
            Sdf::Cylinder { a, b, radius } => {
                let ba = *b - *a;
                let h = ba.length();
                let axis = ba / h;
                let pa = p - *a;
                let s = pa.dot(axis);
                let radial = pa - axis * s;
                let rl = radial.length();
                let rdir = if rl > 0.0 {
                    radial / rl
                } else {
                    axis.any_orthonormal_vector()
                };
                let dr = rl - radius; // distance outside the infinite cylinder
                let (ds, sdir) = if s < h * 0.5 {
                    (-s, -axis)
                } else {
                    (s - h, axis)
                };
                if dr > 0.0 && ds > 0.0 {
                    let v = rdir * dr + sdir * ds;
                    let l = v.length();
                    (l, v / l)
                } else if dr > ds {
                    (dr, rdir)
                } else {
                    (ds, sdir)
                }
            }
            Sdf::Union(parts) => {
                parts
                    .iter()
                    .map(|s| s.eval_grad(p))
                    .fold(
                        (f32::INFINITY, Vec3::Z),
                        |a, b| if b.0 < a.0 { b } else { a },
                    )
            }
            Sdf::Intersection(parts) => {
                parts
                    .iter()
                    .map(|s| s.eval_grad(p))
                    .fold(
                        (f32::NEG_INFINITY, Vec3::Z),
                        |a, b| if b.0 > a.0 { b } else { a },
                    )
            }
            Sdf::Complement(inner) => {
                let (f, g) = inner.eval_grad(p);
                (-f, -g)
            }
        }
    }

    /// A box that contains the body, or `None` if it is unbounded (a half space,
    /// a complement, or a union containing one).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        match self {
            Sdf::Sphere { center, radius } => Some((
                *center - Vec3::splat(*radius),
                *center + Vec3::splat(*radius),
            )),
            Sdf::Cuboid { center, half } => Some((*center - *half, *center + *half)),
            Sdf::Cylinder { a, b, radius } => {
                let r = Vec3::splat(*radius);
                Some((a.min(*b) - r, a.max(*b) + r))
            }
            Sdf::HalfSpace { .. } | Sdf::Complement(_) => None,
            Sdf::Union(parts) => {
                let mut lo = Vec3::splat(f32::INFINITY);
                let mut hi = Vec3::splat(f32::NEG_INFINITY);
                for p in parts {
                    let (a, b) = p.bounds()?;
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                Some((lo, hi))
            }
            Sdf::Intersection(parts) => {
                let mut lo = Vec3::splat(f32::NEG_INFINITY);
                let mut hi = Vec3::splat(f32::INFINITY);
                let mut any = false;
                for p in parts {
                    if let Some((a, b)) = p.bounds() {
                        lo = lo.max(a);
                        hi = hi.min(b);
                        any = true;
                    }
                }
                any.then_some((lo, hi))
            }
        }
    }

    /// The first `t` in `(t_min, t_max)` where the ray meets the surface, by sphere
    /// tracing: step along the ray by the value of the function, which never
    /// exceeds the distance to the surface for min/max/complement combinations of
    /// exact distance functions. Stops when the value is below `eps·(1 + t)`.
    pub fn trace(&self, ray: &Ray, t_min: f32, t_max: f32, eps: f32) -> Option<f32> {
        let (mut t0, mut t1) = (t_min, t_max);
        if let Some((lo, hi)) = self.bounds() {
            // Clip to the bounding box.
            let inv = ray.dir.recip();
            let a = (lo - ray.origin) * inv;
            let b = (hi - ray.origin) * inv;
            let tn = a.min(b).max_element();
            let tf = a.max(b).min_element();
            if tn.is_nan() || tf.is_nan() || tn > tf || tf < t_min || tn > t_max {
                return None;
            }
            t0 = t0.max(tn - eps);
            t1 = t1.min(tf + eps);
        }
        let mut t = t0;
        let inside = self.eval(ray.at(t)) < 0.0;
        for _ in 0..512 {
            if t > t1 {
                return None;
            }
            let f = self.eval(ray.at(t));
            let d = if inside { -f } else { f };
            if d < eps * (1.0 + t.abs()) {
                if t > t_min {
                    return Some(t);
                }
                t += 2.0 * eps * (1.0 + t.abs());
                continue;
            }
            t += d;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(x: f32, r: f32) -> Sdf {
        Sdf::Sphere {
            center: Vec3::new(x, 0.0, 0.0),
            radius: r,
        }
    }

    #[test]
    fn union_is_min_and_intersection_is_max() {
        // Two unit balls at x = ±0.5: the lens between them is in both, the
        // points at x = ±1.4 are in one only.
        let a = ball(-0.5, 1.0);
        let b = ball(0.5, 1.0);
        let u = Sdf::Union(vec![a.clone(), b.clone()]);
        let i = Sdf::Intersection(vec![a, b]);
        for x in [-1.4f32, 1.4] {
            let p = Vec3::new(x, 0.0, 0.0);
            assert!(u.eval(p) < 0.0, "{x} must be inside the union");
            assert!(i.eval(p) > 0.0, "{x} must be outside the intersection");
        }
        let p = Vec3::ZERO;
        assert!(u.eval(p) < 0.0 && i.eval(p) < 0.0);
        // Exact values: the union's function at x = 2 is the distance to the
        // nearer ball (0.5), the intersection's that to the farther (1.5).
        let p = Vec3::new(2.0, 0.0, 0.0);
        assert!((u.eval(p) - 0.5).abs() < 1e-6);
        assert!((i.eval(p) - 1.5).abs() < 1e-6);
    }

    #[test]
    fn tracing_finds_the_exact_surface_and_the_sharp_edge_normal() {
        // Lens: intersection of two unit balls at x = ±0.5 has its rim on the
        // circle x = 0, y² + z² = 0.75 — a sharp edge.
        let lens = Sdf::Intersection(vec![ball(-0.5, 1.0), ball(0.5, 1.0)]);
        let ray = Ray::new(Vec3::new(3.0, 0.0, 0.0), -Vec3::X);
        let t = lens.trace(&ray, 0.0, 100.0, 1e-5).unwrap();
        // Surface at x = 0.5 (ball centred at -0.5 with radius 1).
        assert!((t - 2.5).abs() < 1e-4, "t = {t}");
        let (_, n) = lens.eval_grad(ray.at(t));
        assert!((n - Vec3::X).length() < 1e-3, "normal {n}");
        // Just above and below the rim the normals belong to different balls and
        // differ by the full edge angle (60°), not a smoothed average.
        let r = 0.75f32.sqrt();
        let (_, n1) = lens.eval_grad(Vec3::new(0.01, r - 0.01, 0.0));
        let (_, n2) = lens.eval_grad(Vec3::new(-0.01, r - 0.01, 0.0));
        let angle = n1.dot(n2).clamp(-1.0, 1.0).acos().to_degrees();
        assert!((angle - 60.0).abs() < 2.0, "edge angle {angle}");
        // Union: a ray along y at x = 1.4 hits the right ball only.
        let u = Sdf::Union(vec![ball(-0.5, 1.0), ball(0.5, 1.0)]);
        let ray = Ray::new(Vec3::new(1.4, -5.0, 0.0), Vec3::Y);
        let t = u.trace(&ray, 0.0, 100.0, 1e-5).unwrap();
        let expect = 5.0 - (1.0f32 - 0.81).sqrt();
        assert!((t - expect).abs() < 1e-4, "t = {t}, expected {expect}");
        // The same ray misses the lens.
        assert!(lens.trace(&ray, 0.0, 100.0, 1e-5).is_none());
    }

    #[test]
    fn difference_by_complement() {
        // A cube with a ball cut out of its centre: a ray through the middle
        // enters the cube at x = 1, and the hole makes it leave the material at
        // the ball's surface (tracing from inside the material).
        let body = Sdf::Intersection(vec![
            Sdf::Cuboid {
                center: Vec3::ZERO,
                half: Vec3::ONE,
            },
            Sdf::Complement(Box::new(ball(0.0, 0.5))),
        ]);
        assert!(body.eval(Vec3::ZERO) > 0.0);
        assert!(body.eval(Vec3::new(0.75, 0.0, 0.0)) < 0.0);
        let ray = Ray::new(Vec3::new(4.0, 0.0, 0.0), -Vec3::X);
        let t = body.trace(&ray, 0.0, 100.0, 1e-5).unwrap();
        assert!((t - 3.0).abs() < 1e-4);
        let t2 = body.trace(&ray, t + 1e-3, 100.0, 1e-5).unwrap();
        assert!((t2 - 3.5).abs() < 1e-4, "t2 = {t2}");
    }
}
