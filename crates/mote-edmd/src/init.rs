//! Initial states: lattices, random placement, velocities.

use crate::vecd::dot;
use rand::Rng;

/// Volume of a D-ball of radius r (disk area for D = 2).
pub fn ball_volume(dim: usize, r: f64) -> f64 {
    match dim {
        2 => std::f64::consts::PI * r * r,
        3 => 4.0 / 3.0 * std::f64::consts::PI * r * r * r,
        _ => f64::NAN,
    }
}

/// `n` sites of a lattice filling the box `size` (units along each axis
/// chosen so that the cells are as cubic as the box allows): simple cubic /
/// square (`basis` = 1 site per cell) or fcc (3-D, 4 sites per cell). The
/// first `n` sites in order are returned; the rest of the lattice is empty.
pub fn lattice<const D: usize>(n: usize, size: [f64; D], fcc: bool) -> Vec<[f64; D]> {
    let basis: Vec<[f64; D]> = if fcc && D == 3 {
        let mut b = vec![[0.0; D]; 4];
        let half = [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.5, 0.0, 0.5],
            [0.0, 0.5, 0.5],
        ];
        for (k, h) in half.iter().enumerate() {
            b[k][..3].copy_from_slice(h);
        }
        b
    } else {
        vec![[0.0; D]]
    };
    let cells_needed = n.div_ceil(basis.len()).max(1);
    // cells per axis proportional to box length, product >= cells_needed
    let vol: f64 = size.iter().product();
    let a = (vol / cells_needed as f64).powf(1.0 / D as f64);
    let mut m = [1usize; D];
    for d in 0..D {
        m[d] = ((size[d] / a).round() as usize).max(1);
    }
    while m.iter().product::<usize>() < cells_needed {
        // grow the axis with the largest cell length
        let d = (0..D)
            .max_by(|&x, &y| (size[x] / m[x] as f64).total_cmp(&(size[y] / m[y] as f64)))
            .unwrap_or(0);
        m[d] += 1;
    }
    let mut out = Vec::with_capacity(n);
    let total: usize = m.iter().product();
    'outer: for c in 0..total {
        let mut idx = [0usize; D];
        let mut cc = c;
        for d in 0..D {
            idx[d] = cc % m[d];
            cc /= m[d];
        }
        for b in &basis {
            if out.len() == n {
                break 'outer;
            }
            let mut p = [0.0; D];
            for d in 0..D {
                let w = size[d] / m[d] as f64;
                p[d] = (idx[d] as f64 + b[d] + 0.25) * w;
            }
            out.push(p);
        }
    }
    out
}

/// Smallest distance between lattice sites produced by [`lattice`] (for
/// checking that the radii fit).
pub fn min_pair_distance<const D: usize>(
    p: &[[f64; D]],
    size: [f64; D],
    periodic: [bool; D],
) -> f64 {
    let mut best = f64::INFINITY;
    let n = p.len().min(600);
    for i in 0..n {
        for j in (i + 1)..n {
            let mut r = [0.0; D];
            for d in 0..D {
                r[d] = p[i][d] - p[j][d];
                if periodic[d] {
                    r[d] -= size[d] * (r[d] / size[d]).round();
                }
            }
            best = best.min(dot(&r, &r).sqrt());
        }
    }
    best
}

/// Random sequential placement of spheres of the given radii without overlap
/// (and inside walls); returns `None` after `max_tries` failures for one
/// particle. Uses a simple grid for the overlap test. The largest spheres
/// are placed first (equal radii keep their order): in a wide distribution
/// a large sphere placed last finds no hole left among the small ones.
pub fn random_placement<const D: usize, R: Rng>(
    radii: &[f64],
    size: [f64; D],
    periodic: [bool; D],
    rng: &mut R,
    max_tries: usize,
) -> Option<Vec<[f64; D]>> {
    let rmax = radii.iter().cloned().fold(0.0, f64::max);
    let mut m = [1usize; D];
    for d in 0..D {
        m[d] = ((size[d] / (2.0 * rmax)).floor() as usize).clamp(1, 1 << 10);
    }
    mote_geom::grids::cap_cells(&mut m, (8 * radii.len()).max(64));
    let total: usize = m.iter().product();
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); total];
    let mut out: Vec<[f64; D]> = vec![[0.0; D]; radii.len()];
    let mut order: Vec<usize> = (0..radii.len()).collect();
    order.sort_by(|&a, &b| radii[b].total_cmp(&radii[a]));
    let cell = |p: &[f64; D]| -> [usize; D] {
        let mut c = [0; D];
        for d in 0..D {
            c[d] = ((p[d] / size[d] * m[d] as f64) as usize).min(m[d] - 1);
        }
        c
    };
    for i in order {
        let r = radii[i];
        let mut placed = false;
        for _ in 0..max_tries {
            let mut p = [0.0; D];
            for d in 0..D {
                p[d] = if periodic[d] {
                    rng.gen::<f64>() * size[d]
                } else {
                    r + rng.gen::<f64>() * (size[d] - 2.0 * r)
                };
            }
            let c = cell(&p);
            let mut ok = true;
            'nb: for k in 0..3usize.pow(D as u32) {
                let mut kk = k;
                let mut flat = 0;
                let mut stride = 1;
                for d in 0..D {
                    let o = (kk % 3) as i64 - 1;
                    kk /= 3;
                    let mut x = c[d] as i64 + o;
                    if x < 0 || x >= m[d] as i64 {
                        if !periodic[d] {
                            continue 'nb;
                        }
                        x = x.rem_euclid(m[d] as i64);
                    }
                    flat += x as usize * stride;
                    stride *= m[d];
                }
                for &j in &grid[flat] {
                    let q = &out[j as usize];
                    let mut d2 = 0.0;
                    for d in 0..D {
                        let mut x = p[d] - q[d];
                        if periodic[d] {
                            x -= size[d] * (x / size[d]).round();
                        }
                        d2 += x * x;
                    }
                    let s = r + radii[j as usize];
                    if d2 < s * s * (1.0 + 1e-9) {
                        ok = false;
                        break 'nb;
                    }
                }
            }
            if ok {
                let mut flat = 0;
                let mut stride = 1;
                for d in 0..D {
                    flat += c[d] * stride;
                    stride *= m[d];
                }
                grid[flat].push(i as u32);
                out[i] = p;
                placed = true;
                break;
            }
        }
        if !placed {
            return None;
        }
    }
    Some(out)
}

/// A standard normal deviate (Box–Muller).
pub fn normal<R: Rng>(rng: &mut R) -> f64 {
    loop {
        let u: f64 = rng.gen();
        if u > 0.0 {
            let v: f64 = rng.gen();
            return (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos();
        }
    }
}

/// Maxwell–Boltzmann velocities at temperature `kt` (k_B T), with the
/// centre-of-mass momentum removed and the kinetic energy set exactly to
/// D N kT / 2.
pub fn thermal_velocities<const D: usize, R: Rng>(
    masses: &[f64],
    kt: f64,
    rng: &mut R,
) -> Vec<[f64; D]> {
    let n = masses.len();
    let mut v: Vec<[f64; D]> = masses
        .iter()
        .map(|m| {
            let s = (kt / m).sqrt();
            let mut x = [0.0; D];
            for xd in x.iter_mut() {
                *xd = s * normal(rng);
            }
            x
        })
        .collect();
    if n > 1 {
        let mtot: f64 = masses.iter().sum();
        let mut p = [0.0; D];
        for (vi, m) in v.iter().zip(masses) {
            for d in 0..D {
                p[d] += m * vi[d];
            }
        }
        for vi in v.iter_mut() {
            for d in 0..D {
                vi[d] -= p[d] / mtot;
            }
        }
    }
    let ke: f64 = v.iter().zip(masses).map(|(x, m)| 0.5 * m * dot(x, x)).sum();
    let target = 0.5 * D as f64 * n as f64 * kt;
    if ke > 0.0 {
        let s = (target / ke).sqrt();
        for vi in v.iter_mut() {
            for x in vi.iter_mut() {
                *x *= s;
            }
        }
    }
    v
}

/// Velocities of equal magnitude `speed` in uniformly random directions
/// (002 §4.9).
pub fn fixed_speed_velocities<const D: usize, R: Rng>(
    n: usize,
    speed: f64,
    rng: &mut R,
) -> Vec<[f64; D]> {
    (0..n)
        .map(|_| loop {
            let mut x = [0.0; D];
            for xd in x.iter_mut() {
                *xd = normal(rng);
            }
            let l = dot(&x, &x).sqrt();
            if l > 1e-12 {
                for xd in x.iter_mut() {
                    *xd *= speed / l;
                }
                break x;
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// One big sphere listed after 2000 small ones (φ ≈ 0.15): placed last
    /// it would need a hole of radius 3.5 among the small centres, which
    /// random tries do not find (probability ~e⁻⁴⁵ each); placed first it
    /// always fits. No overlaps, positions in the caller's order.
    #[test]
    fn wide_distributions_place_the_largest_first() {
        let mut radii = vec![0.5; 2000];
        radii.push(3.0);
        let size = [20.0; 3];
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let pos = random_placement(&radii, size, [true; 3], &mut rng, 10_000).expect("placed");
        assert_eq!(pos.len(), radii.len());
        for i in 0..pos.len() {
            for j in i + 1..pos.len() {
                let mut d2 = 0.0;
                for d in 0..3 {
                    let mut x = pos[i][d] - pos[j][d];
                    x -= size[d] * (x / size[d]).round();
                    d2 += x * x;
                }
                let s = radii[i] + radii[j];
                assert!(d2 >= s * s, "{i} and {j} overlap");
            }
        }
    }
}
