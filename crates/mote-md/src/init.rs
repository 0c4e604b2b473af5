//! Generators of initial states: lattices (with spring networks), rings of
//! bodies on a circle (choreographies, 002 §4.3), annuli of ring particles
//! on Kepler orbits (002 §4.4), random placement in a box.

use glam::DVec3;
use rand::Rng;

use crate::force::Spring;
use crate::particles::ParticleInit;

/// Circular-orbit speed of N equal masses M on a circle of radius R about
/// their centre (002 Eq. 16): v² = G M / (2^{3/2} R) Σ_{j=1}^{N−1} 1/√(1 − cos(2πj/N)).
pub fn choreography_speed(n: usize, g_mass: f64, radius: f64) -> f64 {
    (g_mass * choreography_sum(n) / (2f64.powf(1.5) * radius)).sqrt()
}

/// Σ_{j=1}^{N−1} 1/√(1 − cos(2πj/N)), the number of 002 Table 1 (v²·R·2^{3/2}/k²).
pub fn choreography_sum(n: usize) -> f64 {
    (1..n)
        .map(|j| 1.0 / (1.0 - (2.0 * std::f64::consts::PI * j as f64 / n as f64).cos()).sqrt())
        .sum()
}

/// Two unit vectors spanning the plane normal to `normal` (right-handed).
pub fn plane_basis(normal: DVec3) -> (DVec3, DVec3) {
    let n = normal.normalize();
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let e1 = (helper - n * helper.dot(n)).normalize();
    let e2 = n.cross(e1);
    (e1, e2)
}

/// N bodies evenly spaced on a circle, moving counter-clockwise about `normal` at `speed`.
pub fn ring(
    n: usize,
    centre: DVec3,
    radius: f64,
    normal: DVec3,
    speed: f64,
    template: &ParticleInit,
) -> Vec<ParticleInit> {
    let (e1, e2) = plane_basis(normal);
    (0..n)
        .map(|k| {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            let (s, c) = phi.sin_cos();
            ParticleInit {
                position: centre + (e1 * c + e2 * s) * radius,
                velocity: template.velocity + (e2 * c - e1 * s) * speed,
                ..template.clone()
            }
        })
        .collect()
}

/// N particles spread uniformly over the annulus R1 ≤ r ≤ R2 (area-uniform
/// radii, random phases), each on a circular Kepler orbit v² = G M / r about
/// a central mass M at `centre` (002 §4.4; the ring's own potential, of
/// relative size M_ring/M, is neglected).
#[allow(clippy::too_many_arguments)]
pub fn annulus(
    n: usize,
    centre: DVec3,
    inner: f64,
    outer: f64,
    normal: DVec3,
    g_central_mass: f64,
    template: &ParticleInit,
    rng: &mut impl Rng,
) -> Vec<ParticleInit> {
    let (e1, e2) = plane_basis(normal);
    (0..n)
        .map(|_| {
            let u: f64 = rng.gen();
            let r = (inner * inner + u * (outer * outer - inner * inner)).sqrt();
            let phi = rng.gen::<f64>() * 2.0 * std::f64::consts::PI;
            let (s, c) = phi.sin_cos();
            let v = (g_central_mass / r).sqrt();
            ParticleInit {
                position: centre + (e1 * c + e2 * s) * r,
                velocity: template.velocity + (e2 * c - e1 * s) * v,
                ..template.clone()
            }
        })
        .collect()
}

/// Uniformly random positions in the box [lo, hi] and velocities with
/// components drawn from N(0, σ²) (σ = 0 for particles at rest).
pub fn random_box(
    n: usize,
    lo: DVec3,
    hi: DVec3,
    sigma_v: f64,
    template: &ParticleInit,
    rng: &mut impl Rng,
) -> Vec<ParticleInit> {
    (0..n)
        .map(|_| {
            let u = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            let g = DVec3::new(gaussian(rng), gaussian(rng), gaussian(rng));
            ParticleInit {
                position: lo + (hi - lo) * u,
                velocity: template.velocity + g * sigma_v,
                ..template.clone()
            }
        })
        .collect()
}

/// A standard normal deviate (Box–Muller).
pub fn gaussian(rng: &mut impl Rng) -> f64 {
    let u1: f64 = 1.0 - rng.gen::<f64>();
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Which lattice sites are held fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    None,
    /// Every site on the outer boundary of the lattice (a membrane's frame).
    Boundary,
    /// The sites with lattice index i = 0 (a cantilever's wall).
    FirstColumn,
}

/// A rectangular lattice of n = (nx, ny, nz) sites with spacing `a`,
/// index k = i + nx (j + ny l), with springs between nearest neighbours
/// (and the in-plane diagonals when `diagonals`) at their initial lengths.
#[derive(Debug, Clone)]
pub struct Lattice {
    pub sites: Vec<ParticleInit>,
    pub springs: Vec<Spring>,
}

#[allow(clippy::too_many_arguments)]
pub fn lattice(
    n: [usize; 3],
    origin: DVec3,
    spacing: DVec3,
    template: &ParticleInit,
    anchor: Anchor,
    springs: Option<(f64, f64, bool)>,
) -> Lattice {
    let [nx, ny, nz] = n;
    let index = |i: usize, j: usize, l: usize| i + nx * (j + ny * l);
    let mut sites = Vec::with_capacity(nx * ny * nz);
    for l in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let on_boundary = |k: usize, m: usize| m > 1 && (k == 0 || k == m - 1);
                let fixed = match anchor {
                    Anchor::None => false,
                    Anchor::Boundary => {
                        on_boundary(i, nx) || on_boundary(j, ny) || on_boundary(l, nz)
                    }
                    Anchor::FirstColumn => i == 0,
                };
                let mut p = template.clone();
                p.position = origin + DVec3::new(i as f64, j as f64, l as f64) * spacing;
                if fixed {
                    p.free = [false; 3];
                    p.velocity = DVec3::ZERO;
                }
                sites.push(p);
            }
        }
    }
    let mut list = Vec::new();
    if let Some((stiffness, damping, diagonals)) = springs {
        let mut link = |a: usize, b: usize| {
            let rest_length = (sites[a].position - sites[b].position).length();
            list.push(Spring {
                i: a,
                j: b,
                stiffness,
                damping,
                rest_length,
            });
        };
        for l in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let k = index(i, j, l);
                    if i + 1 < nx {
                        link(k, index(i + 1, j, l));
                    }
                    if j + 1 < ny {
                        link(k, index(i, j + 1, l));
                    }
                    if l + 1 < nz {
                        link(k, index(i, j, l + 1));
                    }
                    if diagonals {
                        if i + 1 < nx && j + 1 < ny {
                            link(k, index(i + 1, j + 1, l));
                            link(index(i + 1, j, l), index(i, j + 1, l));
                        }
                        if i + 1 < nx && l + 1 < nz {
                            link(k, index(i + 1, j, l + 1));
                            link(index(i + 1, j, l), index(i, j, l + 1));
                        }
                        if j + 1 < ny && l + 1 < nz {
                            link(k, index(i, j + 1, l + 1));
                            link(index(i, j + 1, l), index(i, j, l + 1));
                        }
                    }
                }
            }
        }
    }
    Lattice {
        sites,
        springs: list,
    }
}

/// A face-centred cubic crystal of cells = (nx, ny, nz) cubic cells at
/// number density ρ (lattice constant a = (4/ρ)^{1/3}), shifted by a/4 off
/// the box faces, and the periodic box it fills. Velocities are drawn from
/// the Maxwell–Boltzmann distribution at k_B T = `kt`, the total momentum
/// removed and the kinetic energy rescaled to exactly (3N − 3) kT / 2.
pub fn fcc(
    cells: [usize; 3],
    density: f64,
    origin: DVec3,
    kt: f64,
    template: &ParticleInit,
    rng: &mut impl Rng,
) -> (Vec<ParticleInit>, crate::boundary::Boundary) {
    let a = (4.0 / density).cbrt();
    let basis = [
        DVec3::ZERO,
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(0.5, 0.0, 0.5),
        DVec3::new(0.0, 0.5, 0.5),
    ];
    let mut out = Vec::with_capacity(4 * cells[0] * cells[1] * cells[2]);
    for k in 0..cells[2] {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                for b in basis {
                    let cell = DVec3::new(i as f64, j as f64, k as f64);
                    let sigma = (kt / template.mass).sqrt();
                    out.push(ParticleInit {
                        position: origin + (cell + b + DVec3::splat(0.25)) * a,
                        velocity: DVec3::new(gaussian(rng), gaussian(rng), gaussian(rng)) * sigma,
                        ..template.clone()
                    });
                }
            }
        }
    }
    let n = out.len() as f64;
    let p: DVec3 = out.iter().map(|q| q.velocity * q.mass).sum();
    let m: f64 = out.iter().map(|q| q.mass).sum();
    out.iter_mut().for_each(|q| q.velocity -= p / m);
    let k: f64 = out
        .iter()
        .map(|q| 0.5 * q.mass * q.velocity.length_squared())
        .sum();
    if k > 0.0 && n > 1.0 {
        let scale = (0.5 * (3.0 * n - 3.0) * kt / k).sqrt();
        out.iter_mut().for_each(|q| q.velocity *= scale);
    }
    let size = DVec3::new(cells[0] as f64, cells[1] as f64, cells[2] as f64) * a;
    (
        out,
        crate::boundary::Boundary::periodic(origin, origin + size),
    )
}

/// A cloud of non-overlapping spheres in the box [min, max] by random
/// sequential addition (as Yade's `makeCloud`): radii uniform in
/// r (1 ± spread), each sphere tried at up to 20 000 random places and
/// kept where it overlaps nothing. Returns fewer than `n` spheres if the box
/// is too full; the caller reports that.
pub fn cloud(
    n: usize,
    min: DVec3,
    max: DVec3,
    radius: f64,
    spread: f64,
    template: &ParticleInit,
    rng: &mut impl Rng,
) -> Vec<ParticleInit> {
    let r_max = radius * (1.0 + spread);
    let edge = 2.0 * r_max;
    let span = (max - min).max(DVec3::splat(edge));
    let dims = [0, 1, 2].map(|k| ((span[k] / edge).floor() as usize).max(1));
    let mut cells: Vec<Vec<usize>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
    let cell_of = |x: DVec3| -> [usize; 3] {
        [0, 1, 2].map(|k| (((x[k] - min[k]) / span[k] * dims[k] as f64) as usize).min(dims[k] - 1))
    };
    let mut placed: Vec<ParticleInit> = Vec::with_capacity(n);
    const ATTEMPTS: usize = 20_000;
    for _ in 0..n {
        let r = radius * (1.0 + spread * (2.0 * rng.gen::<f64>() - 1.0));
        let lo = min + DVec3::splat(r);
        let hi = max - DVec3::splat(r);
        if (0..3).any(|k| hi[k] < lo[k]) {
            break;
        }
        let mut found = None;
        'attempt: for _ in 0..ATTEMPTS {
            let x = lo + (hi - lo) * DVec3::new(rng.gen(), rng.gen(), rng.gen());
            let c = cell_of(x);
            for cz in c[2].saturating_sub(1)..=(c[2] + 1).min(dims[2] - 1) {
                for cy in c[1].saturating_sub(1)..=(c[1] + 1).min(dims[1] - 1) {
                    for cx in c[0].saturating_sub(1)..=(c[0] + 1).min(dims[0] - 1) {
                        for &j in &cells[cx + dims[0] * (cy + dims[1] * cz)] {
                            let q = &placed[j];
                            let reach = r + q.radius;
                            if (q.position - x).length_squared() < reach * reach {
                                continue 'attempt;
                            }
                        }
                    }
                }
            }
            found = Some(x);
            break;
        }
        let Some(x) = found else { break };
        let c = cell_of(x);
        cells[c[0] + dims[0] * (c[1] + dims[1] * c[2])].push(placed.len());
        placed.push(ParticleInit {
            position: x,
            radius: r,
            ..template.clone()
        });
    }
    placed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 002 Table 1, with the N = 8 entry as corrected in shared/seeds/README.md.
    #[test]
    #[allow(clippy::approx_constant)] // 0.707107 is the table's entry, not 1/√2
    fn choreography_sums_match_table_1() {
        let table = [
            (2, 0.707107),
            (3, 1.632993),
            (4, 2.707107),
            (5, 3.892996),
            (6, 5.168527),
            (7, 6.518859),
            (8, 7.933359),
            (9, 9.404033),
        ];
        for (n, expected) in table {
            let v = choreography_sum(n);
            assert!((v - expected).abs() < 6e-7, "N = {n}: {v:.6} vs {expected}");
            assert_eq!(format!("{v:.6}"), format!("{expected:.6}"), "N = {n}");
        }
    }

    #[test]
    fn lattice_springs_count_and_anchors() {
        let t = ParticleInit::default();
        let lat = lattice(
            [8, 8, 1],
            DVec3::ZERO,
            DVec3::ONE,
            &t,
            Anchor::Boundary,
            Some((1.0, 0.0, false)),
        );
        assert_eq!(lat.sites.len(), 64);
        assert_eq!(lat.springs.len(), 2 * 8 * 7);
        assert_eq!(
            lat.sites.iter().filter(|p| p.free == [false; 3]).count(),
            28
        );
        let lat = lattice(
            [4, 2, 1],
            DVec3::ZERO,
            DVec3::ONE,
            &t,
            Anchor::FirstColumn,
            Some((1.0, 0.0, true)),
        );
        assert_eq!(lat.springs.len(), 3 * 2 + 4 + 2 * 3);
        assert!(lat.springs.iter().all(|s| s.rest_length > 0.99));
    }
}
