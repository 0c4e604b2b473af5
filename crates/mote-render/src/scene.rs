//! What is drawn: spheres (each with a colour and a body id, so that a rigid
//! clump — a union of overlapping spheres, seed 000 — is just its spheres sharing
//! a body id and colour), bodies given by metrical indicator functions, and the
//! simulation box.

use glam::Vec3;

use crate::bvh::Sphere;
use crate::sdf::Sdf;

/// Linear RGB colour with components in 0..=1.
pub type Rgb = [f32; 3];

/// A body drawn by sphere tracing its metrical indicator function.
#[derive(Debug, Clone, PartialEq)]
pub struct SdfBody {
    pub shape: Sdf,
    pub color: Rgb,
}

/// A parallelepiped box: origin corner and the three edge vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    pub origin: Vec3,
    pub edges: [Vec3; 3],
}

impl Cell {
    /// The 12 edges as pairs of end points.
    pub fn segments(&self) -> Vec<(Vec3, Vec3)> {
        let [a, b, c] = self.edges;
        let o = self.origin;
        let corner =
            |i: u32| o + a * (i & 1) as f32 + b * ((i >> 1) & 1) as f32 + c * ((i >> 2) & 1) as f32;
        let mut out = Vec::with_capacity(12);
        for i in 0..8u32 {
            for bit in [1u32, 2, 4] {
                if i & bit == 0 {
                    out.push((corner(i), corner(i | bit)));
                }
            }
        }
        out
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let [a, b, c] = self.edges;
        std::array::from_fn(|i| {
            self.origin + a * (i & 1) as f32 + b * ((i >> 1) & 1) as f32 + c * ((i >> 2) & 1) as f32
        })
    }
}

/// Everything to draw.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    pub spheres: Vec<Sphere>,
    /// One colour per sphere.
    pub colors: Vec<Rgb>,
    /// One body id per sphere: spheres of a clump share it (informational; the
    /// union needs no special treatment because the nearest hit over all its
    /// spheres is the hit on the union, with its sharp creases exact).
    pub body: Vec<u32>,
    pub sdf_bodies: Vec<SdfBody>,
    pub cell: Option<Cell>,
}

impl Scene {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sphere as a body of its own; returns its body id.
    pub fn add_sphere(&mut self, center: Vec3, radius: f32, color: Rgb) -> u32 {
        let id = self.next_body();
        self.spheres.push(Sphere { center, radius });
        self.colors.push(color);
        self.body.push(id);
        id
    }

    /// Adds a rigid clump (a union of spheres, seed 000) of one colour; returns its body id.
    pub fn add_clump(&mut self, spheres: &[(Vec3, f32)], color: Rgb) -> u32 {
        let id = self.next_body();
        for &(center, radius) in spheres {
            self.spheres.push(Sphere { center, radius });
            self.colors.push(color);
            self.body.push(id);
        }
        id
    }

    fn next_body(&self) -> u32 {
        self.body.last().map_or(0, |b| b + 1)
    }

    /// Adds, for an orthorhombic periodic cell, the images of spheres that stick out
    /// of the box through a periodic face, so that the box looks filled as the
    /// simulation sees it. `pbc` says which axes are periodic.
    pub fn add_periodic_images(&mut self, pbc: [bool; 3]) {
        let Some(cell) = self.cell else { return };
        let len = Vec3::new(cell.edges[0].x, cell.edges[1].y, cell.edges[2].z);
        let lo = cell.origin;
        let hi = lo + len;
        let n = self.spheres.len();
        for i in 0..n {
            let s = self.spheres[i];
            let mut shifts = vec![Vec3::ZERO];
            for d in 0..3 {
                if !pbc[d] || len[d] <= 0.0 {
                    continue;
                }
                let mut e = Vec3::ZERO;
                if s.center[d] - s.radius < lo[d] {
                    e[d] = len[d];
                } else if s.center[d] + s.radius > hi[d] {
                    e[d] = -len[d];
                } else {
                    continue;
                }
                let add: Vec<Vec3> = shifts.iter().map(|&v| v + e).collect();
                shifts.extend(add);
            }
            for &v in &shifts[1..] {
                self.spheres.push(Sphere {
                    center: s.center + v,
                    radius: s.radius,
                });
                self.colors.push(self.colors[i]);
                self.body.push(self.body[i]);
            }
        }
    }

    /// Bounds of spheres, bodies and box, or `None` if the scene is empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for s in &self.spheres {
            if s.center.is_finite() && s.radius.is_finite() {
                lo = lo.min(s.center - Vec3::splat(s.radius));
                hi = hi.max(s.center + Vec3::splat(s.radius));
            }
        }
        for b in &self.sdf_bodies {
            if let Some((a, c)) = b.shape.bounds() {
                lo = lo.min(a);
                hi = hi.max(c);
            }
        }
        if let Some(cell) = &self.cell {
            for c in cell.corners() {
                lo = lo.min(c);
                hi = hi.max(c);
            }
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }
}
