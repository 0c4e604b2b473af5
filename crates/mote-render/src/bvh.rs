//! A bounding-volume hierarchy over spheres, for exact ray–sphere hits in
//! O(log N) per ray.
//!
//! Built top-down with the surface-area heuristic evaluated on a few bins of
//! sphere centres (Wald, "On fast construction of SAH-based bounding volume
//! hierarchies", 2007). The build is sequential and depends only on the input
//! order, so the tree — and every picture — is the same for every thread count.

use glam::{Vec3, Vec3A};

/// A sphere: centre and radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

/// A ray `origin + t·dir`, `dir` of unit length.
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir: dir.normalize(),
        }
    }
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// The first crossing of a ray into a sphere with `t` in `(t_min, t_max)`, exact up to
/// rounding: `|o + t d − c| = r` solved in the form that avoids cancellation
/// (the squared distance of the centre from the ray is computed from the
/// perpendicular vector, not as a difference of squares).
#[inline]
pub fn ray_sphere(ray: &Ray, s: &Sphere, t_min: f32, t_max: f32) -> Option<f32> {
    let l = s.center - ray.origin;
    let tca = l.dot(ray.dir);
    let perp = l - ray.dir * tca;
    let d2 = perp.length_squared();
    let r2 = s.radius * s.radius;
    if d2 > r2 {
        return None;
    }
    let thc = (r2 - d2).sqrt();
    let t0 = tca - thc;
    if t0 > t_min && t0 < t_max {
        return Some(t0);
    }
    let t1 = tca + thc;
    if t1 > t_min && t1 < t_max {
        return Some(t1);
    }
    None
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3A,
    hi: Vec3A,
    /// Leaf: index of the first primitive; inner node: index of the left child
    /// (the right child follows it).
    first: u32,
    /// Number of primitives in a leaf; 0 for an inner node.
    count: u32,
}

/// A BVH over a list of spheres (it keeps its own reordered copy).
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Spheres in leaf order.
    spheres: Vec<Sphere>,
    /// For each leaf-order sphere, its index in the caller's list.
    index: Vec<u32>,
}

const LEAF_SIZE: usize = 4;
const BINS: usize = 12;
/// Subtrees with more spheres than this are built in parallel.
const PARALLEL_FROM: usize = 20_000;
/// Deepest tree the traversal stack holds; the build halves lists below this.
const MAX_DEPTH: usize = 96;

#[derive(Clone, Copy)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    fn empty() -> Self {
        Self {
            lo: Vec3::splat(f32::INFINITY),
            hi: Vec3::splat(f32::NEG_INFINITY),
        }
    }
    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }
    fn area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// A hit: the index of the sphere (in the caller's list) and the ray parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub index: usize,
    pub t: f32,
}

impl Bvh {
    /// Builds the hierarchy. Spheres with non-finite data or non-positive radius are
    /// skipped. Large subtrees are built in parallel (`rayon::join`); each subtree
    /// is built from its own slice and the pieces are joined in a fixed order, so
    /// the tree does not depend on the thread count.
    pub fn build(spheres: &[Sphere]) -> Self {
        let mut prims: Vec<(Sphere, u32)> = spheres
            .iter()
            .enumerate()
            .filter(|(_, s)| s.center.is_finite() && s.radius.is_finite() && s.radius > 0.0)
            .map(|(i, s)| (*s, i as u32))
            .collect();
        let nodes = if prims.is_empty() {
            Vec::new()
        } else {
            Self::subtree(&mut prims, 0, 0)
        };
        Self {
            nodes,
            spheres: prims.iter().map(|p| p.0).collect(),
            index: prims.iter().map(|p| p.1).collect(),
        }
    }

    /// Builds the subtree of `prims` (which start at position `offset` of the
    /// final order); returns its nodes, root first, child indices relative to it.
    fn subtree(prims: &mut [(Sphere, u32)], offset: usize, depth: usize) -> Vec<Node> {
        let mut bounds = Aabb::empty();
        let mut cb = Aabb::empty();
        for (s, _) in prims.iter() {
            bounds.grow(
                s.center - Vec3::splat(s.radius),
                s.center + Vec3::splat(s.radius),
            );
            cb.grow(s.center, s.center);
        }
        let count = prims.len();
        let leaf = || {
            vec![Node {
                lo: bounds.lo.into(),
                hi: bounds.hi.into(),
                first: offset as u32,
                count: count as u32,
            }]
        };
        if count <= LEAF_SIZE {
            return leaf();
        }
        // Binned SAH over all three axes.
        let ext = cb.hi - cb.lo;
        let mut best = (f32::INFINITY, 0usize, 0usize); // cost, axis, bin split
        for axis in 0..3 {
            if ext[axis] <= 0.0 {
                continue;
            }
            let scale = BINS as f32 / ext[axis];
            let mut bin_box = [Aabb::empty(); BINS];
            let mut bin_n = [0usize; BINS];
            for (s, _) in prims.iter() {
                let b = (((s.center[axis] - cb.lo[axis]) * scale) as usize).min(BINS - 1);
                bin_n[b] += 1;
                bin_box[b].grow(
                    s.center - Vec3::splat(s.radius),
                    s.center + Vec3::splat(s.radius),
                );
            }
            let mut left_area = [0.0f32; BINS];
            let mut left_n = [0usize; BINS];
            let mut acc = Aabb::empty();
            let mut n = 0;
            for b in 0..BINS - 1 {
                acc.grow(bin_box[b].lo, bin_box[b].hi);
                n += bin_n[b];
                left_area[b] = acc.area();
                left_n[b] = n;
            }
            let mut acc = Aabb::empty();
            let mut n = 0;
            for b in (1..BINS).rev() {
                acc.grow(bin_box[b].lo, bin_box[b].hi);
                n += bin_n[b];
                let cost = left_area[b - 1] * left_n[b - 1] as f32 + acc.area() * n as f32;
                if left_n[b - 1] > 0 && n > 0 && cost < best.0 {
                    best = (cost, axis, b);
                }
            }
        }
        let mid = if best.0.is_finite() && depth < MAX_DEPTH / 2 {
            let (axis, b) = (best.1, best.2);
            let scale = BINS as f32 / ext[axis];
            let lo = cb.lo[axis];
            partition(prims, |p| {
                (((p.0.center[axis] - lo) * scale) as usize).min(BINS - 1) < b
            })
        } else {
            // All centres coincide (or the tree grows too deep): halve the list.
            count / 2
        };
        if mid == 0 || mid == count {
            return leaf();
        }
        let (lp, rp) = prims.split_at_mut(mid);
        let (left, right) = if count > PARALLEL_FROM {
            rayon::join(
                || Self::subtree(lp, offset, depth + 1),
                || Self::subtree(rp, offset + mid, depth + 1),
            )
        } else {
            (
                Self::subtree(lp, offset, depth + 1),
                Self::subtree(rp, offset + mid, depth + 1),
            )
        };
        // Layout: root, left child, right child, rest of the left subtree, rest of
        // the right. Left index k maps to 1 (k = 0) or k + 2; right index k to 2
        // (k = 0) or k + 1 + (number of left nodes).
        let nl = left.len() as u32;
        let map_l = |k: u32| if k == 0 { 1 } else { k + 2 };
        let map_r = |k: u32| if k == 0 { 2 } else { k + 1 + nl };
        let fix = |n: &Node, map: &dyn Fn(u32) -> u32| -> Node {
            if n.count > 0 {
                *n
            } else {
                Node {
                    first: map(n.first),
                    ..*n
                }
            }
        };
        let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
        nodes.push(Node {
            lo: bounds.lo.into(),
            hi: bounds.hi.into(),
            first: 1,
            count: 0,
        });
        nodes.push(fix(&left[0], &map_l));
        nodes.push(fix(&right[0], &map_r));
        nodes.extend(left[1..].iter().map(|n| fix(n, &map_l)));
        nodes.extend(right[1..].iter().map(|n| fix(n, &map_r)));
        nodes
    }

    /// Number of spheres in the tree.
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// Bounds of everything in the tree, or `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.nodes.first().map(|n| (n.lo.into(), n.hi.into()))
    }

    #[inline]
    fn slab(n: &Node, o: Vec3A, inv: Vec3A, t_max: f32) -> f32 {
        let t0 = (n.lo - o) * inv;
        let t1 = (n.hi - o) * inv;
        let tn = t0.min(t1).max_element();
        let tf = t0.max(t1).min_element();
        if tn <= tf && tf > 0.0 && tn < t_max {
            tn
        } else {
            f32::INFINITY
        }
    }

    /// The nearest hit with `t` in `(t_min, t_max)`.
    pub fn closest(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        self.traverse(ray, t_min, t_max, false)
    }

    /// Whether anything is hit with `t` in `(t_min, t_max)` (for shadows and occlusion).
    pub fn occluded(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        self.traverse(ray, t_min, t_max, true).is_some()
    }

    fn traverse(&self, ray: &Ray, t_min: f32, t_max: f32, any: bool) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = Vec3A::from(ray.dir).recip();
        let o = Vec3A::from(ray.origin);
        let mut best_t = t_max;
        let mut best: Option<usize> = None;
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0usize;
        let mut node = 0usize;
        if Self::slab(&self.nodes[0], o, inv, best_t) == f32::INFINITY {
            return None;
        }
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first as usize;
                for k in first..first + n.count as usize {
                    if let Some(t) = ray_sphere(ray, &self.spheres[k], t_min, best_t) {
                        best_t = t;
                        best = Some(k);
                        if any {
                            return Some(Hit {
                                index: self.index[k] as usize,
                                t,
                            });
                        }
                    }
                }
            } else {
                let l = n.first as usize;
                let r = l + 1;
                let tl = Self::slab(&self.nodes[l], o, inv, best_t);
                let tr = Self::slab(&self.nodes[r], o, inv, best_t);
                let (near, far, tn, tf) = if tl <= tr {
                    (l, r, tl, tr)
                } else {
                    (r, l, tr, tl)
                };
                if tn.is_finite() {
                    if tf.is_finite() && sp < stack.len() {
                        stack[sp] = far as u32;
                        sp += 1;
                    }
                    node = near;
                    continue;
                }
            }
            // Pop the next node that can still hold a nearer hit.
            loop {
                if sp == 0 {
                    return best.map(|k| Hit {
                        index: self.index[k] as usize,
                        t: best_t,
                    });
                }
                sp -= 1;
                let cand = stack[sp] as usize;
                if Self::slab(&self.nodes[cand], o, inv, best_t).is_finite() {
                    node = cand;
                    break;
                }
            }
        }
    }
}

/// Moves the elements for which `pred` holds to the front (stable for neither
/// part, but deterministic); returns how many there are.
fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    let mut j = v.len();
    while i < j {
        if pred(&v[i]) {
            i += 1;
        } else {
            j -= 1;
            v.swap(i, j);
        }
    }
    i
}

/// The nearest hit by testing every sphere: the reference for tests.
pub fn closest_brute_force(spheres: &[Sphere], ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut t_best = t_max;
    for (i, s) in spheres.iter().enumerate() {
        if let Some(t) = ray_sphere(ray, s, t_min, t_best) {
            t_best = t;
            best = Some(Hit { index: i, t });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 40) as f32) / (1u64 << 24) as f32
    }

    #[test]
    fn ray_hits_sphere_at_known_distance() {
        let s = Sphere {
            center: Vec3::new(0.0, 0.0, 10.0),
            radius: 2.0,
        };
        let r = Ray::new(Vec3::ZERO, Vec3::Z);
        assert_eq!(ray_sphere(&r, &s, 0.0, f32::INFINITY), Some(8.0));
        // From inside, the exit point.
        let r = Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::Z);
        assert_eq!(ray_sphere(&r, &s, 0.0, f32::INFINITY), Some(2.0));
        // A ray passing at distance 2.01 misses.
        let r = Ray::new(Vec3::new(2.01, 0.0, 0.0), Vec3::Z);
        assert_eq!(ray_sphere(&r, &s, 0.0, f32::INFINITY), None);
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut st = 12345u64;
        let spheres: Vec<Sphere> = (0..3000)
            .map(|_| Sphere {
                center: Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) * 20.0,
                radius: 0.05 + 0.5 * lcg(&mut st),
            })
            .collect();
        let bvh = Bvh::build(&spheres);
        assert_eq!(bvh.len(), spheres.len());
        let mut hits = 0;
        for _ in 0..4000 {
            let o = Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) * 40.0 - 10.0;
            let d = Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) - 0.5;
            let ray = Ray::new(o, d);
            let a = bvh.closest(&ray, 1e-4, f32::INFINITY);
            let b = closest_brute_force(&spheres, &ray, 1e-4, f32::INFINITY);
            match (a, b) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert_eq!(a.t, b.t);
                    // Equal t on two spheres is possible only in degenerate cases.
                    assert_eq!(a.index, b.index);
                }
                (None, None) => {}
                other => panic!("bvh and brute force disagree: {other:?}"),
            }
            assert_eq!(bvh.occluded(&ray, 1e-4, f32::INFINITY), b.is_some());
        }
        assert!(hits > 500, "too few hits ({hits}) to mean anything");
    }

    #[test]
    fn parallel_build_is_the_same_tree_and_finds_the_same_hits() {
        let mut st = 777u64;
        let spheres: Vec<Sphere> = (0..60_000)
            .map(|_| Sphere {
                center: Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) * 50.0,
                radius: 0.3,
            })
            .collect();
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        };
        let a = pool(1).install(|| Bvh::build(&spheres));
        let b = pool(3).install(|| Bvh::build(&spheres));
        assert_eq!(a.index, b.index);
        assert_eq!(a.nodes.len(), b.nodes.len());
        for _ in 0..500 {
            let o = Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) * 50.0;
            let d = Vec3::new(lcg(&mut st), lcg(&mut st), lcg(&mut st)) - 0.5;
            let ray = Ray::new(o, d);
            let want = closest_brute_force(&spheres, &ray, 1e-4, f32::INFINITY);
            assert_eq!(b.closest(&ray, 1e-4, f32::INFINITY), want);
        }
    }

    #[test]
    fn degenerate_inputs_do_not_break_the_build() {
        let same = vec![
            Sphere {
                center: Vec3::ONE,
                radius: 1.0
            };
            100
        ];
        let bvh = Bvh::build(&same);
        let ray = Ray::new(Vec3::new(1.0, 1.0, -5.0), Vec3::Z);
        assert_eq!(bvh.closest(&ray, 0.0, f32::INFINITY).unwrap().t, 5.0);
        let bad = vec![
            Sphere {
                center: Vec3::NAN,
                radius: 1.0,
            },
            Sphere {
                center: Vec3::ZERO,
                radius: 0.0,
            },
        ];
        assert!(Bvh::build(&bad).is_empty());
        assert!(Bvh::build(&[]).closest(&ray, 0.0, 1.0).is_none());
    }
}
