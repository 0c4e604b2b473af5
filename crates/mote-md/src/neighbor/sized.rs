//! A half neighbour list for spheres of many sizes: each pair with
//! |r_i − r_j| < a_i + a_j + skin once (j > i), found through the grid
//! hierarchy of [`mote_geom::grids`] (reach ρ_i = a_i + skin/2).
//!
//! [`VerletList`](super::VerletList) lists every pair within one reach, the
//! largest diameter plus the skin: at lognormal σ = 0.5 that is hundreds of
//! spheres for each sphere in contact with a dozen, and its single grid is
//! 4 × 4 × 4 cells at N = 10⁴.

use glam::DVec3;
use mote_geom::grids::GridHierarchy;

use crate::boundary::Boundary;

/// Compressed rows: `neighbors[start[i]..start[i + 1]]` are i's j > i.
#[derive(Debug, Clone, Default)]
pub struct SizedList {
    /// Pairs within a_i + a_j + skin are listed.
    pub skin: f64,
    start: Vec<u32>,
    neighbors: Vec<u32>,
    /// Number of builds so far.
    pub builds: u64,
}

impl SizedList {
    pub fn new(skin: f64) -> Self {
        SizedList {
            skin,
            ..Self::default()
        }
    }

    /// Neighbours j > i of particle i.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.neighbors[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Pairs listed.
    pub fn len(&self) -> usize {
        self.neighbors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.neighbors.is_empty()
    }

    /// Builds the list for positions `pos` (inside the box on periodic
    /// axes) and radii `radius`.
    pub fn build(&mut self, pos: &[DVec3], radius: &[f64], boundary: &Boundary) {
        let n = pos.len();
        let size = boundary.lengths().to_array();
        let reach: Vec<f64> = radius.iter().map(|a| a + 0.5 * self.skin).collect();
        let local = |r: DVec3| (r - boundary.lo).to_array();
        let (grids, level) = GridHierarchy::new(size, boundary.periodic, &reach);
        // particles sorted by cell (counting sort)
        let cell: Vec<usize> = (0..n)
            .map(|i| grids.cell(level[i], &local(pos[i])))
            .collect();
        let mut first = vec![0u32; grids.cell_count() + 1];
        for &c in &cell {
            first[c + 1] += 1;
        }
        for c in 0..grids.cell_count() {
            first[c + 1] += first[c];
        }
        let mut fill = first.clone();
        let mut members = vec![0u32; n];
        for (i, &c) in cell.iter().enumerate() {
            members[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        let image = boundary.image();
        self.start.clear();
        self.neighbors.clear();
        self.start.push(0);
        for i in 0..n {
            let (ri, rho) = (pos[i], reach[i]);
            grids.for_each_cell_near(&local(ri), rho, |c| {
                for &j in &members[first[c] as usize..first[c + 1] as usize] {
                    if j as usize > i {
                        let s = rho + reach[j as usize];
                        if image.apply(ri - pos[j as usize]).length_squared() < s * s {
                            self.neighbors.push(j);
                        }
                    }
                }
            });
            self.start.push(self.neighbors.len() as u32);
        }
        self.builds += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Against all pairs: the list holds exactly the pairs within reach.
    #[test]
    fn lists_exactly_the_pairs_within_reach() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(9);
        let b = Boundary::periodic(DVec3::splat(-5.0), DVec3::splat(5.0));
        let n = 500;
        let radius: Vec<f64> = (0..n)
            .map(|_| 0.05 * (3.5 * rng.gen::<f64>()).exp())
            .collect();
        let pos: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 10.0 - 5.0)
            .collect();
        let mut list = SizedList::new(0.1);
        list.build(&pos, &radius, &b);
        let mut count = 0;
        for i in 0..n {
            for j in i + 1..n {
                let s = radius[i] + radius[j] + 0.1;
                let within = b.minimum_image(pos[i] - pos[j]).length_squared() < s * s;
                assert_eq!(list.of(i).contains(&(j as u32)), within, "{i} {j}");
                count += within as usize;
            }
        }
        assert_eq!(list.len(), count);
    }
}
