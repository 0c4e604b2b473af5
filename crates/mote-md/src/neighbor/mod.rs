//! Neighbour search: cell lists feeding a Verlet list with a skin.
//!
//! The list holds, for every particle, the others within r_c + skin: all of
//! them (a full list, each pair twice) or only those of higher index (a half
//! list, each pair once, for loops that apply Newton's third law). It is rebuilt when any particle has moved more than half the skin
//! since the last build (then no pair can have crossed r_c unseen), or after
//! a fixed number of steps if one is set. Building bins the particles into
//! cells of edge ≥ r_c + skin and scans the 27 surrounding cells, O(N).

use glam::DVec3;
use rayon::prelude::*;

use crate::boundary::Boundary;

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;
mod ghosts;
mod sized;
pub use ghosts::{Copy4, GhostList};
pub use sized::SizedList;

/// A Verlet neighbour list in compressed rows.
#[derive(Debug, Clone, Default)]
pub struct VerletList {
    /// Interaction cut-off r_c.
    pub cutoff: f64,
    /// Skin: the list holds pairs within r_c + skin.
    pub skin: f64,
    /// Rebuild at least every this many updates (0: only on displacement).
    pub every: u64,
    /// Keep only neighbours j > i (each pair once).
    pub half: bool,
    /// `neighbors[start[i]..start[i + 1]]` are the neighbours of i.
    pub start: Vec<u32>,
    pub neighbors: Vec<u32>,
    reference: Vec<DVec3>,
    since_build: u64,
    /// Number of builds so far.
    pub builds: u64,
    /// The group of each particle, or empty: pairs within one group (the
    /// spheres of one rigid body) are not listed ([`VerletList::set_groups`]).
    groups: Vec<u32>,
}

impl VerletList {
    pub fn new(cutoff: f64, skin: f64) -> Self {
        Self {
            cutoff,
            skin,
            ..Self::default()
        }
    }

    /// A half list: each pair once, j > i.
    pub fn half(cutoff: f64, skin: f64) -> Self {
        Self {
            half: true,
            ..Self::new(cutoff, skin)
        }
    }

    /// Neighbours of particle i.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.neighbors[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Lists no pair of particles of one group from the next build on
    /// (`groups[i]`, the group of particle i; empty: every pair); a change
    /// of groups makes the next update rebuild.
    pub fn set_groups(&mut self, groups: &[u32]) {
        if self.groups != groups {
            self.groups.clear();
            self.groups.extend_from_slice(groups);
            self.reference.clear();
        }
    }

    /// Makes the next update rebuild (the particles changed).
    pub fn invalidate(&mut self) {
        self.reference.clear();
    }

    /// Rebuilds the list if needed; returns whether it did.
    pub fn update(&mut self, pos: &[DVec3], boundary: &Boundary) -> bool {
        self.since_build += 1;
        let stale = self.reference.len() != pos.len()
            || (self.every > 0 && self.since_build >= self.every)
            || {
                // Wrapped positions: a displacement is less than a box
                // length, so the compare-and-shift image serves.
                let limit = 0.25 * self.skin * self.skin;
                let image = boundary.image();
                pos.par_iter()
                    .with_min_len(4096)
                    .zip(&self.reference)
                    .any(|(r, r0)| image.apply(*r - *r0).length_squared() > limit)
            };
        if stale {
            self.build(pos, boundary);
        }
        stale
    }

    /// Rebuilds if needed, for positions never wrapped into the box (the
    /// spheres of rigid bodies, carried with their bodies): `search` gets
    /// each position wrapped into the box ([`Boundary::wrap`], a function
    /// of the position alone, so a resumed run searches where the
    /// uninterrupted one did), in parallel, and the list is kept there by
    /// [`VerletList::update`]. Returns whether it rebuilt.
    pub fn update_wrapping(
        &mut self,
        pos: &[DVec3],
        boundary: &Boundary,
        search: &mut Vec<DVec3>,
    ) -> bool {
        pos.par_iter()
            .with_min_len(4096)
            .map(|r| boundary.wrap(*r))
            .collect_into_vec(search);
        self.update(search, boundary)
    }

    /// Builds the list from scratch: blocks of particles in parallel, each
    /// filling its rows into one buffer (no allocation per particle),
    /// every row's partners sorted, the blocks joined in order. The
    /// distances are tested eight at a time over the runs of cells around
    /// each particle (`within` of the ghost lists: AVX-512 compression, or
    /// [`Lanes`](mote_geom::lanes::Lanes)), each run shifted by its
    /// periodic image; a periodic axis of fewer than three cells, where
    /// one cell holds several images of a particle, takes the minimum
    /// image pair by pair.
    pub fn build(&mut self, pos: &[DVec3], boundary: &Boundary) {
        const BLOCK: usize = 512;
        let reach = self.cutoff + self.skin;
        let reach2 = reach * reach;
        let cells = CellGrid::new(pos, boundary, reach);
        let image = boundary.image();
        let half = self.half;
        let groups = &self.groups;
        let grouped = !groups.is_empty();
        let wanted = |i: usize, j: usize| {
            (if half { j > i } else { j != i }) && !(grouped && groups[i] == groups[j])
        };
        let shifted = cells.runs_are_images();
        let blocks: Vec<(Vec<u32>, Vec<u32>)> = (0..pos.len().div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let rows = b * BLOCK..((b + 1) * BLOCK).min(pos.len());
                let mut lengths = Vec::with_capacity(rows.len());
                let mut near: Vec<u32> = Vec::new();
                // The places a run keeps, in cell order (kept between runs:
                // no zeroing per run).
                let mut kept_at: Vec<u32> = Vec::new();
                for i in rows {
                    let row = near.len();
                    let ri = pos[i];
                    if shifted {
                        let ri = boundary.wrap(ri);
                        cells.for_each_image_run(ri, |from, to, shift| {
                            if kept_at.len() < to - from + 8 {
                                kept_at.resize(to - from + 8, 0);
                            }
                            let at = ri - shift;
                            let kept = ghosts::within(
                                (at.x, at.y, at.z),
                                reach2,
                                (&cells.x[from..to], &cells.y[from..to], &cells.z[from..to]),
                                from,
                                usize::MAX,
                                &mut kept_at,
                            );
                            // The kept places → particles, those the list
                            // wants.
                            near.extend(
                                kept_at[..kept]
                                    .iter()
                                    .map(|&m| cells.order[m as usize])
                                    .filter(|&j| wanted(i, j))
                                    .map(|j| j as u32),
                            );
                        });
                    } else {
                        cells.for_each_run(ri, |js, rs| {
                            for (&j, &rj) in js.iter().zip(rs) {
                                if wanted(i, j) && image.apply(rj - ri).length_squared() < reach2 {
                                    near.push(j as u32);
                                }
                            }
                        });
                    }
                    near[row..].sort_unstable();
                    lengths.push((near.len() - row) as u32);
                }
                (lengths, near)
            })
            .collect();
        self.start.clear();
        self.neighbors.clear();
        self.start.push(0);
        for (lengths, near) in &blocks {
            let mut end = self.neighbors.len() as u32;
            self.start.extend(lengths.iter().map(|l| {
                end += l;
                end
            }));
            self.neighbors.extend_from_slice(near);
        }
        self.reference.clear();
        self.reference.extend_from_slice(pos);
        self.since_build = 0;
        self.builds += 1;
    }
}

/// Particles binned into cells of edge ≥ `reach`.
pub struct CellGrid {
    lo: DVec3,
    edge: DVec3,
    dims: [usize; 3],
    periodic: [bool; 3],
    /// Particle indices sorted by cell; `first[c]..first[c + 1]` is cell c.
    order: Vec<usize>,
    first: Vec<usize>,
    /// The positions in that order, so that a scan reads them in a row.
    sorted: Vec<DVec3>,
    /// Their coordinates wrapped into the box, one array each (for tests
    /// eight at a time).
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    /// The box's edges (periodic axes; zero on open ones).
    length: DVec3,
}

impl CellGrid {
    pub fn new(pos: &[DVec3], boundary: &Boundary, reach: f64) -> Self {
        // Periodic axes use the box; open axes the particles' extent.
        let mut lo = DVec3::ZERO;
        let mut len = DVec3::ZERO;
        let mut dims = [1usize; 3];
        for k in 0..3 {
            if boundary.periodic[k] {
                lo[k] = boundary.lo[k];
                len[k] = boundary.hi[k] - boundary.lo[k];
                dims[k] = ((len[k] / reach).floor() as usize).clamp(1, 1 << 10);
            } else {
                let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
                for r in pos {
                    a = a.min(r[k]);
                    b = b.max(r[k]);
                }
                if pos.is_empty() {
                    (a, b) = (0.0, 1.0);
                }
                lo[k] = a;
                len[k] = (b - a).max(reach);
                dims[k] = ((len[k] / reach).floor() as usize).clamp(1, 1 << 10);
            }
        }
        mote_geom::grids::cap_cells(&mut dims, 8 * pos.len().max(8));
        for k in 0..3 {
            // Fewer than 3 cells along a periodic axis would visit the
            // same cell twice.
            if boundary.periodic[k] && dims[k] < 3 {
                dims[k] = 1;
            }
        }
        let edge = DVec3::new(
            len.x / dims[0] as f64,
            len.y / dims[1] as f64,
            len.z / dims[2] as f64,
        );
        let mut grid = Self {
            lo,
            edge,
            dims,
            periodic: boundary.periodic,
            order: Vec::new(),
            first: Vec::new(),
            sorted: Vec::new(),
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            length: DVec3::select(
                glam::BVec3::from(boundary.periodic),
                boundary.hi - boundary.lo,
                DVec3::ZERO,
            ),
        };
        let ncell = dims[0] * dims[1] * dims[2];
        let cell_of: Vec<usize> = pos
            .iter()
            .map(|r| grid.cell_index(grid.coords(*r)))
            .collect();
        let mut count = vec![0usize; ncell + 1];
        for &c in &cell_of {
            count[c + 1] += 1;
        }
        for c in 0..ncell {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut order = vec![0usize; pos.len()];
        for (i, &c) in cell_of.iter().enumerate() {
            order[fill[c]] = i;
            fill[c] += 1;
        }
        grid.sorted = order.iter().map(|&i| pos[i]).collect();
        // Wrapped into the box, where the cells put them.
        let wrapped: Vec<DVec3> = grid.sorted.iter().map(|r| boundary.wrap(*r)).collect();
        grid.x = wrapped.iter().map(|r| r.x).collect();
        grid.y = wrapped.iter().map(|r| r.y).collect();
        grid.z = wrapped.iter().map(|r| r.z).collect();
        grid.order = order;
        grid.first = count;
        grid
    }

    fn coords(&self, r: DVec3) -> [isize; 3] {
        let mut c = [0isize; 3];
        for k in 0..3 {
            let mut x = ((r[k] - self.lo[k]) / self.edge[k]).floor() as isize;
            let d = self.dims[k] as isize;
            if self.periodic[k] {
                x = x.rem_euclid(d);
            } else {
                x = x.clamp(0, d - 1);
            }
            c[k] = x;
        }
        c
    }

    fn cell_index(&self, c: [isize; 3]) -> usize {
        (c[0] as usize) + self.dims[0] * ((c[1] as usize) + self.dims[1] * (c[2] as usize))
    }

    /// Calls `f(j)` for every particle in the cells around position r.
    pub fn for_each_candidate(&self, r: DVec3, mut f: impl FnMut(usize)) {
        self.for_each_run(r, |js, _| js.iter().for_each(|&j| f(j)));
    }

    /// Whether each cell around a position is one periodic image of it at
    /// most: every periodic axis has three cells or more (with fewer, a
    /// cell holds two images of a particle, and only the minimum image
    /// pair by pair tells them apart).
    pub fn runs_are_images(&self) -> bool {
        (0..3).all(|k| !self.periodic[k] || self.dims[k] >= 3)
    }

    /// Calls `f(from, to, shift)` for runs `from..to` of the cell order
    /// (the particles `order[from..to]`, wrapped at `x`, `y`, `z[from..to]`)
    /// in the cells around position r (wrapped), each with the shift of
    /// its periodic image: the image of a particle at r_j of the run
    /// nearest r is r_j + shift. Needs [`CellGrid::runs_are_images`].
    pub fn for_each_image_run(&self, r: DVec3, mut f: impl FnMut(usize, usize, DVec3)) {
        let c = self.coords(r);
        // Along each axis the (at most three) distinct cells and the
        // image shift of each: −L below the first cell of a periodic
        // axis, +L above its last.
        let range = |k: usize| -> ([isize; 3], [f64; 3], usize) {
            let d = self.dims[k] as isize;
            let l = self.length[k];
            if d == 1 {
                ([0; 3], [0.0; 3], 1)
            } else if self.periodic[k] {
                let below = if c[k] == 0 {
                    (d - 1, -l)
                } else {
                    (c[k] - 1, 0.0)
                };
                let above = if c[k] == d - 1 {
                    (0, l)
                } else {
                    (c[k] + 1, 0.0)
                };
                ([below.0, c[k], above.0], [below.1, 0.0, above.1], 3)
            } else {
                let (a, b) = ((c[k] - 1).max(0), (c[k] + 1).min(d - 1));
                ([a, a + 1, a + 2], [0.0; 3], (b - a + 1) as usize)
            }
        };
        let (xs, ys, zs) = (range(0), range(1), range(2));
        let cells_x = &xs.0[..xs.2];
        // x-cells in increasing order without a wrap: one run of memory.
        let run = cells_x.windows(2).all(|w| w[1] == w[0] + 1);
        for (&z, &shift_z) in zs.0[..zs.2].iter().zip(&zs.1) {
            for (&y, &shift_y) in ys.0[..ys.2].iter().zip(&ys.1) {
                let mut visit = |from: usize, to: usize, shift_x: f64| {
                    if to > from {
                        f(from, to, DVec3::new(shift_x, shift_y, shift_z));
                    }
                };
                if run {
                    let first = self.cell_index([cells_x[0], y, z]);
                    let last = self.cell_index([cells_x[cells_x.len() - 1], y, z]);
                    visit(self.first[first], self.first[last + 1], 0.0);
                } else {
                    for (&x, &shift_x) in cells_x.iter().zip(&xs.1) {
                        let cell = self.cell_index([x, y, z]);
                        visit(self.first[cell], self.first[cell + 1], shift_x);
                    }
                }
            }
        }
    }

    /// Calls `f(js, rs)` for runs of the particles in the cells around
    /// position r: their indices and positions, side by side in memory.
    /// The cells along x of one row (y, z) are neighbours in memory, so
    /// where the row does not wrap around a periodic face its cells are
    /// one run.
    pub fn for_each_run(&self, r: DVec3, mut f: impl FnMut(&[usize], &[DVec3])) {
        let c = self.coords(r);
        // The (at most three) distinct cells along each axis, without
        // allocating: a periodic axis of one cell visits it once.
        let range = |k: usize| -> ([isize; 3], usize) {
            let d = self.dims[k] as isize;
            if d == 1 {
                ([0, 0, 0], 1)
            } else if self.periodic[k] {
                (
                    [(c[k] - 1).rem_euclid(d), c[k], (c[k] + 1).rem_euclid(d)],
                    3,
                )
            } else {
                let (a, b) = ((c[k] - 1).max(0), (c[k] + 1).min(d - 1));
                ([a, a + 1, a + 2], (b - a + 1) as usize)
            }
        };
        let (xs, ys, zs) = (range(0), range(1), range(2));
        let xs = &xs.0[..xs.1];
        // x-cells in increasing order without a wrap: one run of memory.
        let run = xs.windows(2).all(|w| w[1] == w[0] + 1);
        let mut visit = |from: usize, to: usize| {
            if to > from {
                f(&self.order[from..to], &self.sorted[from..to]);
            }
        };
        for &z in &zs.0[..zs.1] {
            for &y in &ys.0[..ys.1] {
                if run {
                    let first = self.cell_index([xs[0], y, z]);
                    let last = self.cell_index([xs[xs.len() - 1], y, z]);
                    visit(self.first[first], self.first[last + 1]);
                } else {
                    for &x in xs {
                        let cell = self.cell_index([x, y, z]);
                        visit(self.first[cell], self.first[cell + 1]);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A list grouped by body lists exactly the pairs of the plain list
    /// whose particles are of different groups (across a periodic side
    /// too), and a change of groups rebuilds it.
    #[test]
    fn grouped_lists_leave_out_pairs_within_a_group() {
        let boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(6.0));
        let pos: Vec<DVec3> = (0..300)
            .map(|i| {
                let t = i as f64;
                DVec3::new((t * 0.37) % 6.0, (t * 0.71) % 6.0, (t * 1.13) % 6.0)
            })
            .collect();
        let groups: Vec<u32> = (0..300).map(|i| i % 7).collect();
        let mut plain = VerletList::half(1.0, 0.2);
        plain.update(&pos, &boundary);
        let mut grouped = VerletList::half(1.0, 0.2);
        grouped.set_groups(&groups);
        grouped.update(&pos, &boundary);
        let mut kept = 0;
        for i in 0..pos.len() {
            let want: Vec<u32> = (plain.of(i).iter())
                .filter(|&&j| groups[j as usize] != groups[i])
                .copied()
                .collect();
            assert_eq!(grouped.of(i), want.as_slice(), "row {i}");
            kept += want.len();
        }
        assert!(kept > 0 && kept < plain.neighbors.len());
        let builds = grouped.builds;
        assert!(!grouped.update(&pos, &boundary));
        grouped.set_groups(&vec![0; 300]);
        assert!(grouped.update(&pos, &boundary));
        assert_eq!((grouped.builds, grouped.neighbors.len()), (builds + 1, 0));
    }

    /// Every list, built eight distances at a time over runs shifted by
    /// their periodic images, holds exactly the pairs within reach by the
    /// minimum image (pair by pair, all pairs), in boxes periodic on every
    /// axis, on some, on none, and with a periodic axis too short for
    /// three cells (the pair-by-pair path); positions slightly outside a
    /// periodic box are found too.
    #[test]
    fn lists_hold_exactly_the_pairs_within_reach() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let (lo, hi) = (DVec3::new(-1.0, 0.0, 2.0), DVec3::new(7.0, 5.0, 8.5));
        for periodic in [
            [true; 3],
            [true, true, false],
            [false; 3],
            [false, true, true],
        ] {
            for short in [false, true] {
                let mut hi = hi;
                if short {
                    // Two cells along y: a cell holds two images.
                    hi.y = lo.y + 2.5;
                }
                let boundary = Boundary {
                    periodic,
                    ..Boundary::periodic(lo, hi)
                };
                let pos: Vec<DVec3> = (0..700)
                    .map(|_| {
                        let u = DVec3::new(rng.gen(), rng.gen(), rng.gen());
                        // A few a hair outside the box.
                        lo + (hi - lo) * (u * 1.0002 - 0.0001)
                    })
                    .collect();
                let image = boundary.image();
                for half in [true, false] {
                    let mut list = if half {
                        VerletList::half(0.9, 0.2)
                    } else {
                        VerletList::new(0.9, 0.2)
                    };
                    list.build(&pos, &boundary);
                    let reach2 = 1.1f64 * 1.1;
                    for i in 0..pos.len() {
                        let want: Vec<u32> = (0..pos.len())
                            .filter(|&j| if half { j > i } else { j != i })
                            .filter(|&j| {
                                let d = boundary.minimum_image(pos[j] - pos[i]);
                                d.length_squared() < reach2
                            })
                            .map(|j| j as u32)
                            .collect();
                        let got = list.of(i);
                        // Only a pair at the reach to round-off may differ.
                        let at_edge = |j: &u32| {
                            let d = image.apply(pos[*j as usize] - pos[i]).length_squared();
                            (d - reach2).abs() < 1e-12
                        };
                        let missing: Vec<_> = want
                            .iter()
                            .filter(|j| !got.contains(j) && !at_edge(j))
                            .collect();
                        let extra: Vec<_> = got
                            .iter()
                            .filter(|j| !want.contains(j) && !at_edge(j))
                            .collect();
                        assert!(
                            missing.is_empty() && extra.is_empty(),
                            "{periodic:?} short {short} half {half} row {i}: missing {missing:?}, extra {extra:?}"
                        );
                        assert!(got.windows(2).all(|w| w[0] < w[1]), "rows sorted");
                    }
                    assert!(list.neighbors.len() > pos.len(), "{}", list.neighbors.len());
                }
            }
        }
    }
}
