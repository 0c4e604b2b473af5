//! Octree range queries return exactly the brute-force set.

use mote_md::tree::{Octree, PlummerSphere};
use mote_md::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn brute(pos: &[DVec3], c: DVec3, r: f64) -> Vec<usize> {
    (0..pos.len())
        .filter(|&i| (pos[i] - c).length_squared() <= r * r)
        .collect()
}

#[test]
fn range_queries_match_brute_force() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    // A clustered set (Plummer), a uniform box, and duplicates on a lattice.
    let (plummer, _) = PlummerSphere::henon(20_000).sample(&mut rng);
    let uniform: Vec<DVec3> = (0..20_000)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
        .collect();
    let lattice: Vec<DVec3> = (0..6000)
        .map(|k| DVec3::new((k % 10) as f64, (k / 10 % 10) as f64, (k / 100 % 10) as f64) * 0.1)
        .collect();
    for (name, pos) in [
        ("plummer", plummer),
        ("uniform", uniform),
        ("lattice", lattice),
    ] {
        for leaf in [1, 8, 32] {
            let mut tree = Octree::new(leaf);
            tree.build(&pos);
            let mut total = 0;
            for q in 0..200 {
                let c = if q % 2 == 0 {
                    pos[rng.gen_range(0..pos.len())]
                } else {
                    DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - DVec3::ONE
                };
                // Radii from empty to everything; exact lattice spacings hit boundaries.
                let r = [0.0, 0.01, 0.1, 0.2, 0.35, 1.0, 100.0][q % 7];
                let mut got = Vec::new();
                tree.within(c, r, &mut got);
                got.sort_unstable();
                let want = brute(&pos, c, r);
                assert_eq!(got, want, "{name}, leaf {leaf}, centre {c}, radius {r}");
                total += got.len();
            }
            assert!(total > 0);
        }
    }
}
