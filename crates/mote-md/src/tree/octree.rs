//! The octree: particles sorted along the Morton curve, cells as contiguous
//! ranges of that order.
//!
//! Build: the bounding cube is cut into 2²¹ cells per axis, each particle
//! gets the Morton key of its cell ([`super::morton`]), and the (key, index)
//! pairs are sorted (O(N log N), parallel, deterministic because the pairs
//! are distinct). A node is a range of the sorted order; its children are
//! the sub-ranges sharing the next three key bits, found by binary search,
//! so every node costs O(log N) and the whole build is O(N log N) with a
//! small constant. Children of a node are stored next to each other, in
//! octant order, and after their parent. Allocations are kept between
//! builds.

use glam::DVec3;
use rayon::prelude::*;

use super::morton;

/// One cell of the octree (48 bytes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Centre of the cubic cell.
    pub centre: DVec3,
    /// Half the side of the cell.
    pub half: f64,
    /// First particle of the cell in the sorted order.
    pub first: u32,
    /// Number of particles in the cell.
    pub count: u32,
    /// Index of the first child; children are contiguous.
    pub child: u32,
    /// Number of children (0 for a leaf).
    pub children: u32,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.children == 0
    }

    /// Sorted-order particle range.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.first as usize..(self.first + self.count) as usize
    }

    /// Squared distance from `p` to the cell (0 inside).
    #[inline]
    pub fn distance2(&self, p: DVec3) -> f64 {
        let d = ((p - self.centre).abs() - DVec3::splat(self.half)).max(DVec3::ZERO);
        d.length_squared()
    }

    /// Index range of the children in [`Octree::nodes`].
    pub fn child_range(&self) -> std::ops::Range<usize> {
        self.child as usize..(self.child + self.children) as usize
    }
}

/// An octree over a set of points (the root is node 0).
#[derive(Debug, Clone, Default)]
pub struct Octree {
    /// Maximum number of particles in a leaf (unless all share one key).
    pub leaf_size: usize,
    /// `order[k]` is the caller's index of the k-th particle in Morton order.
    pub order: Vec<u32>,
    /// Positions in Morton order.
    pub position: Vec<DVec3>,
    /// The cells, root first; children after their parent.
    pub nodes: Vec<Node>,
    keys: Vec<(u64, u32)>,
    sorted_keys: Vec<u64>,
}

impl Octree {
    /// An empty tree whose leaves hold at most `leaf_size` particles.
    pub fn new(leaf_size: usize) -> Self {
        Self {
            leaf_size: leaf_size.max(1),
            ..Self::default()
        }
    }

    /// Builds the tree over `position` (finite coordinates), reusing the
    /// allocations of the previous build.
    pub fn build(&mut self, position: &[DVec3]) {
        let n = position.len();
        assert!(n < u32::MAX as usize, "octree: too many particles");
        self.nodes.clear();
        self.order.clear();
        self.position.clear();
        self.keys.clear();
        self.sorted_keys.clear();
        if n == 0 {
            return;
        }
        let (lo, hi) = position
            .par_iter()
            .fold(
                || (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |(lo, hi), r| (lo.min(*r), hi.max(*r)),
            )
            .reduce(
                || (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                |a, b| (a.0.min(b.0), a.1.max(b.1)),
            );
        assert!(
            lo.is_finite() && hi.is_finite(),
            "octree: non-finite position"
        );
        let centre = 0.5 * (lo + hi);
        // A little larger than the extent, so the top cell index stays below 2²¹.
        let half = (0.5 * (hi - lo).max_element()).max(f64::MIN_POSITIVE) * (1.0 + 1e-9) + 1e-300;
        let origin = centre - DVec3::splat(half);
        let cells = (1u64 << morton::BITS) as f64;
        let scale = cells / (2.0 * half);
        let top = (1u64 << morton::BITS) - 1;
        position
            .par_iter()
            .enumerate()
            .map(|(i, r)| {
                let c = ((*r - origin) * scale).max(DVec3::ZERO);
                let cell = |v: f64| (v as u64).min(top);
                (morton::key(cell(c.x), cell(c.y), cell(c.z)), i as u32)
            })
            .collect_into_vec(&mut self.keys);
        self.keys.par_sort_unstable();
        self.order.extend(self.keys.iter().map(|k| k.1));
        self.sorted_keys.extend(self.keys.iter().map(|k| k.0));
        self.position
            .extend(self.order.iter().map(|&i| position[i as usize]));
        self.nodes.push(Node {
            centre,
            half,
            first: 0,
            count: n as u32,
            child: 0,
            children: 0,
        });
        self.split(0, 0);
    }

    /// Splits node `index` at depth `level` into its non-empty octants, recursively.
    fn split(&mut self, index: usize, level: u32) {
        let node = self.nodes[index];
        if node.count as usize <= self.leaf_size || level >= morton::BITS {
            return;
        }
        let shift = 3 * (morton::BITS - 1 - level);
        let keys = &self.sorted_keys[node.range()];
        let first_child = self.nodes.len();
        let mut start = 0;
        for octant in 0..8u64 {
            let end = start + keys[start..].partition_point(|k| (k >> shift) & 7 <= octant);
            if end > start {
                let sign = |bit: u64| if octant & bit != 0 { 1.0 } else { -1.0 };
                let offset = DVec3::new(sign(4), sign(2), sign(1)) * (0.5 * node.half);
                self.nodes.push(Node {
                    centre: node.centre + offset,
                    half: 0.5 * node.half,
                    first: node.first + start as u32,
                    count: (end - start) as u32,
                    child: 0,
                    children: 0,
                });
            }
            start = end;
        }
        let children = self.nodes.len() - first_child;
        self.nodes[index].child = first_child as u32;
        self.nodes[index].children = children as u32;
        for c in first_child..first_child + children {
            self.split(c, level + 1);
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Appends to `out` the caller's indices of all particles with
    /// |r − centre|² ≤ radius² (computed as `(r - centre).length_squared()`),
    /// in Morton order.
    pub fn within(&self, centre: DVec3, radius: f64, out: &mut Vec<usize>) {
        if self.nodes.is_empty() {
            return;
        }
        let r2 = radius * radius;
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k];
            if node.distance2(centre) > r2 {
                continue;
            }
            if node.is_leaf() {
                for s in node.range() {
                    if (self.position[s] - centre).length_squared() <= r2 {
                        out.push(self.order[s] as usize);
                    }
                }
            } else {
                stack.extend(node.child_range().rev());
            }
        }
    }

    /// Groups for a Barnes–Hut walk: the highest nodes holding at most
    /// `size` particles (or leaves), in Morton order; their particle ranges
    /// tile 0..N.
    pub fn groups(&self, size: usize, out: &mut Vec<usize>) {
        out.clear();
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k];
            if node.is_leaf() || node.count as usize <= size {
                out.push(k);
            } else {
                stack.extend(node.child_range().rev());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let t = k as f64;
                DVec3::new((2.1 * t).sin(), (1.7 * t).cos(), (0.37 * t).sin().powi(3))
            })
            .collect()
    }

    #[test]
    fn nodes_partition_their_parents() {
        let pos = points(3000);
        let mut tree = Octree::new(8);
        tree.build(&pos);
        let mut seen = vec![false; pos.len()];
        for &i in &tree.order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        for node in &tree.nodes {
            for s in node.range() {
                assert!(
                    node.distance2(tree.position[s]) == 0.0,
                    "particle outside its cell"
                );
            }
            if node.is_leaf() {
                assert!(node.count as usize <= tree.leaf_size);
            } else {
                let kids = &tree.nodes[node.child_range()];
                assert_eq!(kids[0].first, node.first);
                assert_eq!(kids.iter().map(|c| c.count).sum::<u32>(), node.count);
                for w in kids.windows(2) {
                    assert_eq!(w[0].first + w[0].count, w[1].first);
                }
            }
        }
        let mut groups = Vec::new();
        tree.groups(64, &mut groups);
        let mut next = 0;
        for &g in &groups {
            assert_eq!(tree.nodes[g].first as usize, next);
            next += tree.nodes[g].count as usize;
        }
        assert_eq!(next, pos.len());
    }

    #[test]
    fn coincident_points_stop_at_the_deepest_level() {
        let pos = vec![DVec3::ONE; 40];
        let mut tree = Octree::new(4);
        tree.build(&pos);
        // One chain of single children down to the 21st level, then a leaf.
        assert_eq!(tree.nodes.len(), 1 + morton::BITS as usize);
        let mut out = Vec::new();
        tree.within(DVec3::ONE, 0.0, &mut out);
        assert_eq!(out.len(), 40);
    }
}
