//! The box cut into a grid of bricks, one per rank (MPI's Cartesian
//! communicator): the grid chosen from the box's shape so that a brick's
//! surface, hence its ghost layer, is least (LAMMPS's `processors *`).
//! The cuts along each axis start even and may shift so that every slab
//! between two cuts holds as many particles (LAMMPS's `balance shift`).

use glam::DVec3;

use crate::boundary::Boundary;

/// This rank's brick in a grid of `dims` bricks over the box.
#[derive(Debug, Clone, PartialEq)]
pub struct Bricks {
    /// Bricks along x, y, z; their product is the number of ranks.
    pub dims: [usize; 3],
    /// This rank's brick, (x, y, z) in the grid.
    pub at: [usize; 3],
    /// The planes between the slabs along each axis: `cuts[k]` holds
    /// dims[k] + 1 coordinates, the box's faces first and last, increasing.
    cuts: [Vec<f64>; 3],
    periodic: [bool; 3],
}

impl Bricks {
    /// The grid for `ranks` ranks over `boundary`: among the ways to write
    /// `ranks` as px·py·pz, the one whose bricks have the least surface
    /// Lx Ly/(px py) + Ly Lz/(py pz) + Lz Lx/(pz px), every cut brick at
    /// least `reach` wide (so ghosts come from face neighbours alone), and
    /// no cut along an axis of infinite length (`Domain` hands it a box
    /// whose open axes span the particles). `grid` (from
    /// `[parallel] grid`) chooses it instead.
    pub fn choose(
        ranks: usize,
        boundary: &Boundary,
        reach: f64,
        grid: Option<[usize; 3]>,
    ) -> Result<[usize; 3], String> {
        let l = boundary.lengths();
        let fits_axis = |k: usize, p: usize| {
            let width = l[k] / p as f64;
            let needed = p > 1 || boundary.periodic[k];
            !needed || (width.is_finite() && width >= reach)
        };
        let fits = |d: [usize; 3]| (0..3).all(|k| fits_axis(k, d[k]));
        // The most bricks along axis k, each at least `reach` wide.
        let most = |k: usize| {
            if l[k].is_finite() {
                ((l[k] / reach).floor() as usize).max(1)
            } else {
                1
            }
        };
        if let Some(d) = grid {
            if d.iter().product::<usize>() != ranks {
                return Err(format!(
                    "a grid of {}×{}×{} bricks for {ranks} ranks",
                    d[0], d[1], d[2]
                ));
            }
            if !fits(d) {
                let k = (0..3).find(|&k| !fits_axis(k, d[k])).unwrap_or(0);
                return Err(format!(
                    "a grid of {}×{}×{} bricks leaves bricks {} wide along {}, narrower \
                     than the cut-off and skin ({reach}): at most {} along {} (a brick at \
                     least {reach} wide)",
                    d[0],
                    d[1],
                    d[2],
                    l[k] / d[k] as f64,
                    ["x", "y", "z"][k],
                    most(k),
                    ["x", "y", "z"][k],
                ));
            }
            return Ok(d);
        }
        let mut best: Option<([usize; 3], f64)> = None;
        // Ties go to the grid cut most along x, then y.
        for px in (1..=ranks).rev().filter(|p| ranks.is_multiple_of(*p)) {
            let rest = ranks / px;
            for py in (1..=rest).rev().filter(|p| rest.is_multiple_of(*p)) {
                let d = [px, py, rest / py];
                if !fits(d) {
                    continue;
                }
                let b = l / DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64);
                let surface = b.x * b.y + b.y * b.z + b.z * b.x;
                if best.is_none_or(|(_, s)| surface < s) {
                    best = Some((d, surface));
                }
            }
        }
        best.map(|(d, _)| d).ok_or_else(|| {
            format!(
                "the box ({} × {} × {}) cannot be cut into {ranks} bricks each at \
                 least the cut-off and skin ({reach}) wide: it holds at most {}×{}×{} \
                 such bricks; run on fewer ranks",
                l.x,
                l.y,
                l.z,
                most(0),
                most(1),
                most(2)
            )
        })
    }

    /// The brick of `rank` in a grid of `dims` over `boundary` (x fastest).
    pub fn new(dims: [usize; 3], rank: usize, boundary: &Boundary) -> Self {
        assert!(rank < dims.iter().product(), "rank {rank} outside the grid");
        Self {
            dims,
            at: [
                rank % dims[0],
                (rank / dims[0]) % dims[1],
                rank / (dims[0] * dims[1]),
            ],
            cuts: std::array::from_fn(|k| {
                let (lo, hi, p) = (boundary.lo[k], boundary.hi[k], dims[k]);
                let inner = (1..p).map(|c| lo + (hi - lo) * c as f64 / p as f64);
                std::iter::once(lo).chain(inner).chain([hi]).collect()
            }),
            periodic: boundary.periodic,
        }
    }

    /// The planes between the slabs along axis k (see `cuts`).
    pub fn cuts(&self, k: usize) -> &[f64] {
        &self.cuts[k]
    }

    /// Moves the planes between the slabs along axis k to `inner` (`dims[k]
    /// − 1` increasing coordinates inside the box).
    pub fn shift(&mut self, k: usize, inner: &[f64]) {
        let p = self.dims[k];
        assert_eq!(
            inner.len() + 1,
            p,
            "{} planes between {p} slabs",
            inner.len()
        );
        self.cuts[k][1..p].copy_from_slice(inner);
    }

    /// The rank of brick `c`.
    pub fn rank_of(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The brick index along axis k of coordinate x (clamped to the grid:
    /// open axes are never cut).
    pub fn index(&self, k: usize, x: f64) -> usize {
        let p = self.dims[k];
        if p == 1 {
            return 0;
        }
        self.cuts[k][1..p].partition_point(|&c| c <= x)
    }

    /// The rank whose brick holds the (wrapped) point `r`.
    pub fn owner(&self, r: DVec3) -> usize {
        self.rank_of([self.index(0, r.x), self.index(1, r.y), self.index(2, r.z)])
    }

    /// This brick's faces along axis k, (lower, upper); the box's own faces
    /// where the axis is not cut (infinite on an open axis).
    pub fn faces(&self, k: usize) -> (f64, f64) {
        let c = self.at[k];
        (self.cuts[k][c], self.cuts[k][c + 1])
    }

    /// The neighbour along axis k below (`up` false) or above, with the
    /// periodic image a copy sent to it takes (−1, 0 or +1 box edges: +1
    /// where the lowest brick sends across the box's lower face); `None`
    /// beyond a face without periodicity.
    pub fn neighbour(&self, k: usize, up: bool) -> Option<(usize, i32)> {
        let (p, c) = (self.dims[k], self.at[k]);
        let (next, image) = match (up, c) {
            (false, 0) => (p - 1, 1),
            (false, c) => (c - 1, 0),
            (true, c) if c + 1 == p => (0, -1),
            (true, c) => (c + 1, 0),
        };
        if image != 0 && !self.periodic[k] {
            return None;
        }
        let mut at = self.at;
        at[k] = next;
        Some((self.rank_of(at), image))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(l: DVec3) -> Boundary {
        Boundary::periodic(DVec3::ZERO, l)
    }

    #[test]
    fn grids_cut_the_longest_edges() {
        let b = cube(DVec3::new(40.0, 10.0, 10.0));
        assert_eq!(Bricks::choose(4, &b, 2.8, None), Ok([4, 1, 1]));
        let b = cube(DVec3::splat(20.0));
        assert_eq!(Bricks::choose(8, &b, 2.8, None), Ok([2, 2, 2]));
        assert_eq!(Bricks::choose(3, &b, 2.8, None), Ok([3, 1, 1]));
        // Bricks narrower than the reach are refused.
        assert_eq!(Bricks::choose(4, &b, 6.0, None), Ok([2, 2, 1]));
        // Refused with the most the box holds.
        let e = Bricks::choose(8, &b, 11.0, None).unwrap_err();
        assert!(e.contains("at most 1×1×1 such bricks"), "{e}");
        let e = Bricks::choose(4, &b, 6.0, Some([4, 1, 1])).unwrap_err();
        assert!(
            e.contains("bricks 5 wide along x") && e.contains("at most 3 along x"),
            "{e}"
        );
        assert!(Bricks::choose(4, &b, 2.0, Some([3, 1, 1])).is_err());
        // An axis without periodicity and without walls is never cut.
        let open = Boundary {
            lo: DVec3::new(0.0, f64::NEG_INFINITY, 0.0),
            hi: DVec3::new(10.0, f64::INFINITY, 10.0),
            periodic: [true, false, true],
        };
        assert_eq!(Bricks::choose(2, &open, 1.0, None), Ok([2, 1, 1]));
    }

    /// Every point has one owner, the brick whose faces hold it; the
    /// neighbours of a 3 × 1 × 2 grid wrap with the right image.
    #[test]
    fn bricks_own_their_points_and_know_their_neighbours() {
        let b = cube(DVec3::new(9.0, 4.0, 6.0));
        let dims = [3, 1, 2];
        for rank in 0..6 {
            let brick = Bricks::new(dims, rank, &b);
            assert_eq!(brick.rank_of(brick.at), rank);
            let centre = DVec3::new(
                0.5 * (brick.faces(0).0 + brick.faces(0).1),
                0.5 * (brick.faces(1).0 + brick.faces(1).1),
                0.5 * (brick.faces(2).0 + brick.faces(2).1),
            );
            assert_eq!(brick.owner(centre), rank);
        }
        let corner = Bricks::new(dims, 0, &b);
        assert_eq!(corner.neighbour(0, false), Some((2, 1)));
        assert_eq!(corner.neighbour(0, true), Some((1, 0)));
        assert_eq!(corner.neighbour(1, true), Some((0, -1)));
        assert_eq!(corner.neighbour(2, false), Some((3, 1)));
        let mut slab = b;
        slab.periodic[0] = false;
        assert_eq!(Bricks::new(dims, 0, &slab).neighbour(0, false), None);
        assert_eq!(Bricks::new(dims, 2, &slab).neighbour(0, true), None);
    }
}
