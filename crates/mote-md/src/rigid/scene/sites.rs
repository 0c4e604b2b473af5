//! Random sites for `[[rigid.random]]`: random sequential addition of
//! bounding spheres, each trial tested against the spheres of its
//! neighbouring cells only.

use std::collections::HashMap;

use glam::DVec3;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::boundary::Boundary;
use crate::rigid::bodies::RigidBodies;

/// Random sequential addition of bounding spheres (radius `bound`) with
/// centres in [lo, hi], not overlapping each other or bodies already
/// placed — through the nearest image along the box's periodic axes (a
/// region spanning a periodic axis meets itself at the box's faces).
///
/// A trial site x is kept where |x − y| ≥ r + `bound` for every sphere
/// (y, r) taken; only the spheres of the 27 cells around x are looked at
/// ([`Cells`]), which are all that can overlap it, so the sites are those
/// of testing every sphere — in O(N) rather than O(N²) (the printer-size
/// nip's 10⁵ bodies took half a minute).
pub(super) fn random_sites(
    n: usize,
    lo: DVec3,
    hi: DVec3,
    bound: f64,
    placed: &RigidBodies,
    boundary: &Boundary,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<DVec3>, String> {
    let image = boundary.image();
    let mut taken: Vec<(DVec3, f64)> = (0..placed.len())
        .map(|i| (placed.position[i], placed.template(i).props.bounding_radius))
        .collect();
    let largest = taken.iter().fold(bound, |a, (_, r)| a.max(*r));
    let (low, high) = taken
        .iter()
        .fold((lo, hi), |(a, b), (y, _)| (a.min(*y), b.max(*y)));
    let mut cells = Cells::new(largest + bound, boundary, low, high);
    for (k, (y, _)) in taken.iter().enumerate() {
        cells.insert(*y, k);
    }
    let first = taken.len();
    let mut tries = 0usize;
    let mut near = Vec::new();
    while taken.len() - first < n {
        tries += 1;
        if tries > 1000 * (n + 10) {
            return Err(format!(
                "could place only {} of {n} bodies without overlap: enlarge [lo, hi]",
                taken.len() - first
            ));
        }
        let x = DVec3::new(
            rng.gen_range(lo.x..=hi.x),
            rng.gen_range(lo.y..=hi.y),
            rng.gen_range(lo.z..=hi.z),
        );
        cells.around(x, &mut near);
        let clear = near.iter().all(|&k| {
            let (y, r) = taken[k];
            image.apply(x - y).length_squared() >= (r + bound) * (r + bound)
        });
        if clear {
            cells.insert(x, taken.len());
            taken.push((x, bound));
        }
    }
    Ok(taken[first..].iter().map(|(x, _)| *x).collect())
}

/// Points binned in cells wider than `reach`: two points less than
/// `reach` apart (through the box's periodic faces) lie in the same or
/// neighbouring cells. Along a periodic axis the box is cut into whole
/// cells and their indices wrap; along an open axis cells are counted
/// from the lowest point.
struct Cells {
    boundary: Boundary,
    /// The corner cells are counted from: the box's on periodic axes.
    origin: DVec3,
    /// Cell width per axis.
    width: DVec3,
    /// Cells along each periodic axis (0 along open ones).
    count: [i64; 3],
    points: HashMap<[i64; 3], Vec<usize>>,
}

impl Cells {
    /// Cells for points in [low, high] (unwrapped).
    fn new(reach: f64, boundary: &Boundary, low: DVec3, high: DVec3) -> Self {
        // 1 % wider than the reach, so that round-off in a point's cell
        // never puts two points within reach two cells apart; and at most
        // 2⁴⁰ cells an axis, so that cell numbers are exact.
        let least = 1.01 * reach;
        let mut origin = low;
        let mut width = DVec3::ZERO;
        let mut count = [0; 3];
        let length = boundary.lengths();
        for d in 0..3 {
            if boundary.periodic[d] {
                origin[d] = boundary.lo[d];
                count[d] = ((length[d] / least).floor() as i64).max(1);
                width[d] = length[d] / count[d] as f64;
            } else {
                width[d] = least.max((high[d] - low[d]) / (1u64 << 40) as f64);
            }
        }
        Self {
            boundary: *boundary,
            origin,
            width,
            count,
            points: HashMap::new(),
        }
    }

    /// The cell of x.
    fn cell(&self, x: DVec3) -> [i64; 3] {
        let wrapped = self.boundary.wrap(x);
        std::array::from_fn(|d| {
            if self.count[d] > 0 {
                let c = ((wrapped[d] - self.origin[d]) / self.width[d]).floor() as i64;
                c.clamp(0, self.count[d] - 1)
            } else {
                ((x[d] - self.origin[d]) / self.width[d]).floor() as i64
            }
        })
    }

    fn insert(&mut self, x: DVec3, k: usize) {
        self.points.entry(self.cell(x)).or_default().push(k);
    }

    /// The points of the cells around x, into `near`.
    fn around(&self, x: DVec3, near: &mut Vec<usize>) {
        near.clear();
        let c = self.cell(x);
        let axis = |d: usize| -> Vec<i64> {
            match self.count[d] {
                0 => vec![c[d] - 1, c[d], c[d] + 1],
                n if n < 3 => (0..n).collect(),
                n => vec![(c[d] - 1).rem_euclid(n), c[d], (c[d] + 1) % n],
            }
        };
        let (xs, ys, zs) = (axis(0), axis(1), axis(2));
        for &k in &zs {
            for &j in &ys {
                for &i in &xs {
                    if let Some(p) = self.points.get(&[i, j, k]) {
                        near.extend_from_slice(p);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use mote_geom::{DE, E};
    use rand::SeedableRng;

    use super::*;
    use crate::rigid::template::BodyTemplate;

    /// Every sphere tested, as the sites were drawn before the cells.
    fn sites_testing_all(
        n: usize,
        lo: DVec3,
        hi: DVec3,
        bound: f64,
        placed: &RigidBodies,
        boundary: &Boundary,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Vec<DVec3> {
        let image = boundary.image();
        let mut taken: Vec<(DVec3, f64)> = (0..placed.len())
            .map(|i| (placed.position[i], placed.template(i).props.bounding_radius))
            .collect();
        let first = taken.len();
        while taken.len() - first < n {
            let x = DVec3::new(
                rng.gen_range(lo.x..=hi.x),
                rng.gen_range(lo.y..=hi.y),
                rng.gen_range(lo.z..=hi.z),
            );
            let far = |(y, r): &(DVec3, f64)| {
                image.apply(x - *y).length_squared() >= (r + bound) * (r + bound)
            };
            if taken.iter().all(far) {
                taken.push((x, bound));
            }
        }
        taken[first..].iter().map(|(x, _)| *x).collect()
    }

    /// Small spheres added among big ones already placed, in an open box,
    /// in a box periodic along x and y (the region over the whole of
    /// both, so sites meet through the faces), and in one whose periodic
    /// x is narrower than three cells: the cells give the sites of
    /// testing every sphere, bit for bit, from the same draws.
    #[test]
    fn the_cells_give_the_sites_of_testing_every_sphere() {
        let big = BodyTemplate::sphere(1.0, 1.0).unwrap();
        let mut placed = RigidBodies::new();
        let k = placed.add_template(big);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        for _ in 0..40 {
            let x = DVec3::new(
                rng.gen_range(0.0..20.0),
                rng.gen_range(0.0..20.0),
                rng.gen_range(0.0..6.0),
            );
            placed.push(k, E::new(DVec3::ZERO, x), DE::ZERO);
        }
        let (lo, hi) = (DVec3::ZERO, DVec3::new(20.0, 20.0, 6.0));
        let periodic = Boundary {
            lo,
            hi,
            periodic: [true, true, false],
        };
        let narrow_hi = DVec3::new(2.5, 20.0, 6.0);
        let narrow = Boundary {
            lo,
            hi: narrow_hi,
            periodic: [true, false, true],
        };
        for (boundary, hi, n) in [
            (Boundary::open(), hi, 600),
            (periodic, hi, 600),
            (narrow, narrow_hi, 60),
        ] {
            let mut a = Xoshiro256PlusPlus::seed_from_u64(7);
            let mut b = a.clone();
            let cells = random_sites(n, lo, hi, 0.3, &placed, &boundary, &mut a).unwrap();
            let all = sites_testing_all(n, lo, hi, 0.3, &placed, &boundary, &mut b);
            let differs = cells.iter().zip(&all).position(|(x, y)| x != y);
            assert!(
                cells.len() == all.len() && differs.is_none(),
                "{boundary:?}: site {differs:?} differs"
            );
            assert_eq!(a.gen::<u64>(), b.gen::<u64>(), "the same draws");
            // And they do not overlap, through the faces too.
            let image = boundary.image();
            let closest = (cells.iter().enumerate())
                .flat_map(|(i, x)| cells[..i].iter().map(move |y| (*x, *y)))
                .map(|(x, y)| image.apply(x - y).length())
                .fold(f64::INFINITY, f64::min);
            assert!(closest >= 0.6, "{closest}");
        }
    }
}
