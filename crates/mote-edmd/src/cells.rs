//! Cell lists for neighbour-list builds: the hierarchy of grids of
//! [`mote_geom::grids`] (one grid per size class), with each cell's
//! particles stored in place, so that wide size distributions cost what
//! narrow ones do.

use crate::system::{huge_vec, prefetch, Boundary, SimBox};
use mote_geom::grids::GridHierarchy;

/// A list-building position and the reach ρ: what a neighbour-list scan
/// reads.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct ListPos<const D: usize> {
    pub x: [f64; D],
    pub r: f64,
}

impl<const D: usize> ListPos<D> {
    pub const ZERO: Self = ListPos {
        x: [0.0; D],
        r: 0.0,
    };
}

const NONE: u32 = u32::MAX;

/// The grids and their contents: cell f holds `len[f]` particles in slots
/// `f·cap ..`, their list positions (copies, so that a scan reads one
/// contiguous run per cell) and internal indices.
#[derive(Debug, Clone)]
pub(crate) struct Cells<const D: usize> {
    grids: GridHierarchy<D>,
    /// Level, cell and slot within the cell of each particle.
    level: Vec<u8>,
    cell: Vec<u32>,
    at: Vec<u32>,
    pos: Vec<ListPos<D>>,
    id: Vec<u32>,
    len: Vec<u32>,
    cap: usize,
}

impl<const D: usize> Cells<D> {
    /// Empty grids for particles of reach `reaches` (ρ_i > 0: pairs closer
    /// than ρ_i + ρ_j are listed).
    pub fn new(simbox: &SimBox<D>, reaches: &[f64]) -> Self {
        let periodic = simbox.boundary.map(|b| b == Boundary::Periodic);
        let (grids, level) = GridHierarchy::new(simbox.size, periodic, reaches);
        let cells = grids.cell_count();
        let cap = 8;
        Cells {
            grids,
            level,
            cell: vec![NONE; reaches.len()],
            at: vec![0; reaches.len()],
            pos: huge_vec(cells * cap, ListPos::ZERO),
            id: huge_vec(cells * cap, NONE),
            len: vec![0; cells],
            cap,
        }
    }

    /// The shape of each level's grid, finest first.
    pub fn shapes(&self) -> Vec<[usize; D]> {
        self.grids.shapes()
    }

    /// The cell of the finest grid that holds `x` (for a spatial ordering).
    pub fn finest_cell(&self, x: &[f64; D]) -> [usize; D] {
        self.grids.finest_cell(x)
    }

    /// Files particle `i` under its list position `p`.
    pub fn insert(&mut self, i: usize, p: ListPos<D>) {
        let f = self.grids.cell(self.level[i], &p.x);
        if self.len[f] as usize == self.cap {
            self.grow();
        }
        let k = self.len[f] as usize;
        self.pos[f * self.cap + k] = p;
        self.id[f * self.cap + k] = i as u32;
        self.cell[i] = f as u32;
        self.at[i] = k as u32;
        self.len[f] += 1;
    }

    /// Takes particle `i` out of its cell (the cell's last entry fills the
    /// hole).
    pub fn remove(&mut self, i: usize) {
        let f = self.cell[i] as usize;
        let base = f * self.cap;
        let k = self.at[i] as usize;
        let last = self.len[f] as usize - 1;
        let moved = self.id[base + last];
        self.pos[base + k] = self.pos[base + last];
        self.id[base + k] = moved;
        self.at[moved as usize] = k as u32;
        self.len[f] -= 1;
        self.cell[i] = NONE;
    }

    /// Doubles the slots per cell.
    fn grow(&mut self) {
        let cap = 2 * self.cap;
        let cells = self.len.len();
        let mut pos = huge_vec(cells * cap, ListPos::ZERO);
        let mut id = huge_vec(cells * cap, NONE);
        for f in 0..cells {
            let k = self.len[f] as usize;
            let old = f * self.cap;
            pos[f * cap..f * cap + k].copy_from_slice(&self.pos[old..old + k]);
            id[f * cap..f * cap + k].copy_from_slice(&self.id[old..old + k]);
        }
        self.pos = pos;
        self.id = id;
        self.cap = cap;
    }

    /// Appends to `out` the slot ranges of the occupied cells that can hold
    /// a j with |x − x_j| < ρ + ρ_j.
    pub fn near(&self, x: &[f64; D], rho: f64, out: &mut Vec<(u32, u32)>) {
        self.grids.for_each_cell_near(x, rho, |f| {
            let n = self.len[f];
            if n > 0 {
                let base = f * self.cap;
                prefetch(&self.pos[base]);
                out.push((base as u32, base as u32 + n));
            }
        });
    }

    /// Asks the CPU for the cells [`Cells::near`] would visit (their list
    /// positions and indices), ahead of a list build: a hint, no effect on
    /// results.
    pub fn prefetch_near(&self, x: &[f64; D], rho: f64) {
        self.grids.for_each_cell_near(x, rho, |f| {
            let base = f * self.cap;
            prefetch(&self.len[f]);
            prefetch(&self.pos[base]);
            prefetch(&self.pos[base + 2]);
            prefetch(&self.id[base]);
        });
    }

    /// Particle index and list position in slot `s`.
    #[inline]
    pub fn entry(&self, s: usize) -> (u32, ListPos<D>) {
        (self.id[s], self.pos[s])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Filed, moved and searched: every pair within reach is found once.
    #[test]
    fn near_finds_every_pair_within_reach_once() {
        let b = SimBox {
            size: [10.0; 3],
            boundary: [Boundary::Periodic, Boundary::Periodic, Boundary::Wall],
        };
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let n = 400;
        let radii: Vec<f64> = (0..n)
            .map(|_| 0.05 * (4.0 * rng.gen::<f64>()).exp())
            .collect();
        let x: Vec<[f64; 3]> = (0..n)
            .map(|_| [0.0; 3].map(|_: f64| 10.0 * rng.gen::<f64>()))
            .collect();
        let mut cells = Cells::new(&b, &radii);
        assert!(cells.shapes().len() > 2);
        for i in 0..n {
            cells.insert(
                i,
                ListPos {
                    x: x[i],
                    r: radii[i],
                },
            );
        }
        // move a few, as a rebuild does
        for i in (0..n).step_by(7) {
            cells.remove(i);
            cells.insert(
                i,
                ListPos {
                    x: x[i],
                    r: radii[i],
                },
            );
        }
        let mut ranges = Vec::new();
        for i in 0..n {
            ranges.clear();
            cells.near(&x[i], radii[i], &mut ranges);
            let mut found: Vec<u32> = ranges
                .iter()
                .flat_map(|&(a, b)| (a..b).map(|s| cells.entry(s as usize).0))
                .collect();
            found.sort_unstable();
            let len = found.len();
            found.dedup();
            assert_eq!(found.len(), len, "a particle found twice");
            for j in 0..n {
                let mut r2 = 0.0;
                for d in 0..3 {
                    let mut dx = x[i][d] - x[j][d];
                    if d < 2 {
                        dx -= 10.0 * (dx / 10.0).round();
                    }
                    r2 += dx * dx;
                }
                let s = radii[i] + radii[j];
                if r2 < s * s {
                    assert!(found.binary_search(&(j as u32)).is_ok(), "{i} misses {j}");
                }
            }
        }
    }
}
