//! A hierarchy of uniform cell grids, one per size class, for neighbour
//! searches among spheres of many sizes (Ogarko & Luding, Comput. Phys.
//! Commun. 183, 931 (2012)). Shared by the event-driven engine's list
//! builds and the soft-sphere packer's.
//!
//! Each sphere has a reach ρ (its radius and its share of the skin: pairs
//! with |x_i − x_j| < ρ_i + ρ_j are neighbours). A sphere is filed on level
//! k = ⌊log₂(ρ/ρ_min)⌋, which holds ρ ∈ [2^k ρ_min, 2^{k+1} ρ_min); the
//! level's cells are at least 2ρ_k wide (ρ_k its largest reach), so a cell
//! holds a bounded number of spheres however wide the distribution. A
//! search around sphere i visits, on each level, the cells that the ball of
//! radius ρ_i + ρ_k around it touches: every j with |x_i − x_j| < ρ_i + ρ_j
//! lies in one of them. With ρ_max < 2ρ_min there is one level, the plain
//! cell list. A single grid sized by the largest sphere has, at lognormal
//! σ = 0.5 and N = 10⁴, 3 × 3 × 3 cells: every search reads every sphere.
//!
//! Only the geometry lives here (which cell, which cells are near); the
//! users keep the cells' contents in whatever layout their loops want.

/// Shrinks a cell grid's cells per axis (`dims`) until it has at most
/// `limit` cells, halving the axis with the most each time: every cell only
/// grows, so a cell at least a reach wide stays so. Cells past a few per
/// particle cost memory and time and find nothing (a cut-off of 1e-300
/// asked a neighbour list for 10⁹ cells, and 24 GB went to empty placement
/// cells of a sparse start). Used by every uniform cell grid of mote.
pub fn cap_cells<const D: usize>(dims: &mut [usize; D], limit: usize) {
    let count = |d: &[usize; D]| d.iter().fold(1usize, |a, &x| a.saturating_mul(x));
    while count(dims) > limit.max(1) {
        let widest = (0..D).max_by_key(|&k| dims[k]).expect("an axis");
        dims[widest] = (dims[widest] / 2).max(1);
    }
}

/// One grid of the hierarchy.
#[derive(Debug, Clone)]
struct Level<const D: usize> {
    ncell: [usize; D],
    width: [f64; D],
    stride: [usize; D],
    /// Index of its first cell among all levels' cells.
    first: usize,
    /// Largest reach filed here.
    reach: f64,
}

/// The grids of a box `[0, L_0) × …` for a given set of reaches.
#[derive(Debug, Clone)]
pub struct GridHierarchy<const D: usize> {
    levels: Vec<Level<D>>,
    periodic: [bool; D],
    cells: usize,
}

impl<const D: usize> GridHierarchy<D> {
    /// The grids for spheres of reach `reaches` (ρ_i > 0) in a box of
    /// `size`, periodic where `periodic`; with each sphere's level.
    pub fn new(size: [f64; D], periodic: [bool; D], reaches: &[f64]) -> (Self, Vec<u8>) {
        let r_min = reaches.iter().cloned().fold(f64::INFINITY, f64::min);
        let r_max = reaches.iter().cloned().fold(0.0, f64::max);
        let classes = if reaches.is_empty() {
            1
        } else {
            class(r_max, r_min) + 1
        };
        let mut count = vec![0usize; classes];
        let mut largest = vec![0.0f64; classes];
        for &r in reaches {
            let k = class(r, r_min).min(classes - 1);
            count[k] += 1;
            largest[k] = largest[k].max(r);
        }
        // occupied classes become levels (one empty level for no spheres)
        let mut level_of_class = vec![0u8; classes];
        let mut levels = Vec::new();
        let mut first = 0;
        for k in 0..classes {
            if count[k] == 0 && !reaches.is_empty() {
                continue;
            }
            level_of_class[k] = levels.len() as u8;
            let level = Level::sized(size, 2.0 * largest[k], largest[k], count[k], first);
            first += level.ncell.iter().product::<usize>();
            levels.push(level);
        }
        let level = reaches
            .iter()
            .map(|&r| level_of_class[class(r, r_min).min(classes - 1)])
            .collect();
        let grids = GridHierarchy {
            levels,
            periodic,
            cells: first,
        };
        (grids, level)
    }

    /// Cells of all levels together.
    pub fn cell_count(&self) -> usize {
        self.cells
    }

    /// The shape of each level's grid, finest first.
    pub fn shapes(&self) -> Vec<[usize; D]> {
        self.levels.iter().map(|l| l.ncell).collect()
    }

    /// The cell of the finest grid that holds `x`, per axis (for a spatial
    /// ordering).
    pub fn finest_cell(&self, x: &[f64; D]) -> [usize; D] {
        self.levels[0].cell_of(x)
    }

    /// The index (among all levels' cells) of the cell of `level` that
    /// holds `x` (clamped into the box).
    #[inline]
    pub fn cell(&self, level: u8, x: &[f64; D]) -> usize {
        let l = &self.levels[level as usize];
        l.first + l.flat(&l.cell_of(x))
    }

    /// Calls `f` with every cell, level by level, that can hold a j with
    /// |x − x_j| < ρ + ρ_j, each once.
    #[inline]
    pub fn for_each_cell_near(&self, x: &[f64; D], rho: f64, mut f: impl FnMut(usize)) {
        for level in &self.levels {
            let reach = rho + level.reach;
            let mut lo = [0i64; D];
            let mut span = [0usize; D];
            let mut empty = false;
            for d in 0..D {
                let n = level.ncell[d] as i64;
                let a = ((x[d] - reach) / level.width[d]).floor() as i64;
                let b = ((x[d] + reach) / level.width[d]).floor() as i64;
                if self.periodic[d] {
                    if b - a + 1 >= n {
                        (lo[d], span[d]) = (0, n as usize);
                    } else {
                        (lo[d], span[d]) = (a, (b - a + 1) as usize);
                    }
                } else {
                    let (a, b) = (a.max(0), b.min(n - 1));
                    empty |= b < a;
                    (lo[d], span[d]) = (a, (b - a + 1).max(0) as usize);
                }
            }
            if empty {
                continue;
            }
            // odometer over the block of cells
            let mut k = [0usize; D];
            'block: loop {
                let mut c = level.first;
                for d in 0..D {
                    let m = level.ncell[d] as i64;
                    c += (lo[d] + k[d] as i64).rem_euclid(m) as usize * level.stride[d];
                }
                f(c);
                for d in 0..D {
                    k[d] += 1;
                    if k[d] < span[d] {
                        continue 'block;
                    }
                    k[d] = 0;
                }
                break;
            }
        }
    }
}

/// Size class of reach `r`: ⌊log₂(r/r_min)⌋.
fn class(r: f64, r_min: f64) -> usize {
    let q = r / r_min;
    if q < 2.0 {
        0
    } else {
        (q.log2().floor() as usize).min(63)
    }
}

impl<const D: usize> Level<D> {
    /// A grid of cells at least `min_width` wide for `n` spheres: at most
    /// about 4n + 64 cells (halving the finest axis), so that a dilute or
    /// sparsely filled level is not mostly empty cells.
    fn sized(size: [f64; D], min_width: f64, reach: f64, n: usize, first: usize) -> Level<D> {
        let mut ncell = [1usize; D];
        let mut width = [0.0; D];
        for d in 0..D {
            let l = size[d];
            let nc = if min_width > 0.0 {
                ((l / (min_width * (1.0 + 1e-9))).floor() as usize).max(1)
            } else {
                1
            };
            ncell[d] = nc.min(1 << 20);
            width[d] = l / ncell[d] as f64;
        }
        while ncell.iter().product::<usize>() > 4 * n + 64 {
            let (d, _) = ncell
                .iter()
                .enumerate()
                .max_by_key(|(_, &c)| c)
                .expect("D > 0");
            if ncell[d] < 2 {
                break;
            }
            ncell[d] /= 2;
            width[d] = size[d] / ncell[d] as f64;
        }
        let mut stride = [1usize; D];
        for d in 1..D {
            stride[d] = stride[d - 1] * ncell[d - 1];
        }
        Level {
            ncell,
            width,
            stride,
            first,
            reach,
        }
    }

    fn cell_of(&self, x: &[f64; D]) -> [usize; D] {
        let mut c = [0usize; D];
        for d in 0..D {
            let k = (x[d] / self.width[d]).floor();
            c[d] = (k.max(0.0) as usize).min(self.ncell[d] - 1);
        }
        c
    }

    fn flat(&self, c: &[usize; D]) -> usize {
        (0..D).map(|d| c[d] * self.stride[d]).sum()
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn capped_grids_hold_at_most_the_limit_and_never_shrink_a_cell() {
        let mut dims = [1024usize, 1024, 1024];
        cap_cells(&mut dims, 160);
        assert!(dims.iter().product::<usize>() <= 160, "{dims:?}");
        assert!(dims.iter().all(|&d| (1..=1024).contains(&d)), "{dims:?}");
        let mut small = [4usize, 3, 2];
        cap_cells(&mut small, 64);
        assert_eq!(small, [4, 3, 2]);
        let mut flat = [usize::MAX, 7];
        cap_cells(&mut flat, 1);
        assert_eq!(flat, [1, 1]);
    }

    use super::*;
    use rand::{Rng, SeedableRng};

    const SIZE: [f64; 3] = [10.0; 3];
    const PERIODIC: [bool; 3] = [true, true, false];

    #[test]
    fn one_level_for_a_narrow_distribution_and_one_per_octave_beyond() {
        let (g, _) = GridHierarchy::new(SIZE, PERIODIC, &[0.13, 0.2, 0.25]);
        assert_eq!(g.shapes().len(), 1);
        // 0.1 → class 0, 0.45 → class 2, 1.3 → class 3: three occupied levels
        let (g, level) = GridHierarchy::new(SIZE, PERIODIC, &[0.1, 0.45, 1.3]);
        assert_eq!(level, vec![0, 1, 2]);
        // the coarsest grid is sized by its largest reach: 10/2.6 → 3
        assert_eq!(g.shapes()[2], [3, 3, 3]);
        assert_eq!(
            g.cell_count(),
            g.shapes().iter().map(|s| s.iter().product::<usize>()).sum()
        );
    }

    #[test]
    fn every_pair_within_reach_is_in_a_visited_cell_and_no_cell_twice() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let n = 400;
        let reach: Vec<f64> = (0..n)
            .map(|_| 0.05 * (4.0 * rng.gen::<f64>()).exp())
            .collect();
        let x: Vec<[f64; 3]> = (0..n)
            .map(|_| [0.0; 3].map(|_: f64| 10.0 * rng.gen::<f64>()))
            .collect();
        let (g, level) = GridHierarchy::new(SIZE, PERIODIC, &reach);
        assert!(g.shapes().len() > 2);
        let cell: Vec<usize> = (0..n).map(|i| g.cell(level[i], &x[i])).collect();
        for i in 0..n {
            let mut seen = Vec::new();
            g.for_each_cell_near(&x[i], reach[i], |c| seen.push(c));
            let len = seen.len();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen.len(), len, "a cell visited twice");
            for j in 0..n {
                let mut r2 = 0.0;
                for d in 0..3 {
                    let mut dx = x[i][d] - x[j][d];
                    if PERIODIC[d] {
                        dx -= 10.0 * (dx / 10.0).round();
                    }
                    r2 += dx * dx;
                }
                let s = reach[i] + reach[j];
                if r2 < s * s {
                    assert!(seen.binary_search(&cell[j]).is_ok(), "{i} misses {j}");
                }
            }
        }
    }
}
