//! Structure of a packing: packing fraction, contacts and rattlers, the pair
//! correlation g(r) and the bond-orientational order Q6 (Steinhardt, Nelson
//! & Ronchetti, PRB 28, 784 (1983)) that flags crystallisation.
//!
//! Functions take plain data (positions, radii, box) so they serve a packing
//! just made and one read from a file alike.

use crate::init::ball_volume;
use crate::system::{Boundary, SimBox};
use crate::vecd::dot;

/// Calls `f(i, j, r_ij, |r_ij|)` (r_ij = x_i − x_j, minimum image) for every
/// pair i < j closer than `cutoff`, through a cell list.
pub fn for_pairs<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    cutoff: f64,
    mut f: impl FnMut(usize, usize, [f64; D], f64),
) {
    let n = pos.len();
    let mut ncell = [1usize; D];
    for d in 0..D {
        let m = (simbox.size[d] / cutoff).floor();
        ncell[d] = if m.is_finite() { m as usize } else { 1 << 10 }.clamp(1, 1 << 10);
    }
    // At most about four cells a particle: cells larger than the cut-off
    // are still right, and a box far larger than its spheres (or spheres
    // of no size) must not make a grid of 2³⁰ empty cells.
    let most = 4.0 * n.max(1) as f64;
    let total = ncell.iter().map(|&m| m as f64).product::<f64>();
    if total > most {
        let shrink = (most / total).powf(1.0 / D as f64);
        for m in ncell.iter_mut() {
            *m = ((*m as f64 * shrink).floor() as usize).max(1);
        }
    }
    // fewer than 3 cells on a periodic axis: neighbour cells would repeat
    let small = (0..D).any(|d| simbox.boundary[d] == Boundary::Periodic && ncell[d] < 3);
    let sep = |i: usize, j: usize| -> [f64; D] {
        let mut r = [0.0; D];
        for d in 0..D {
            r[d] = pos[i][d] - pos[j][d];
            if simbox.boundary[d] == Boundary::Periodic {
                let l = simbox.size[d];
                r[d] -= l * (r[d] / l).round();
            }
        }
        r
    };
    if small || n < 64 {
        for i in 0..n {
            for j in (i + 1)..n {
                let r = sep(i, j);
                let dist = dot(&r, &r).sqrt();
                if dist < cutoff {
                    f(i, j, r, dist);
                }
            }
        }
        return;
    }
    let total: usize = ncell.iter().product();
    let cell_of = |x: &[f64; D]| -> [usize; D] {
        let mut c = [0usize; D];
        for d in 0..D {
            let l = simbox.size[d];
            let xd = x[d].rem_euclid(l);
            c[d] = ((xd / l * ncell[d] as f64) as usize).min(ncell[d] - 1);
        }
        c
    };
    let flat = |c: &[usize; D]| -> usize {
        let mut k = 0;
        for d in (0..D).rev() {
            k = k * ncell[d] + c[d];
        }
        k
    };
    let mut head = vec![usize::MAX; total];
    let mut next = vec![usize::MAX; n];
    let cells: Vec<[usize; D]> = pos.iter().map(cell_of).collect();
    for i in 0..n {
        let k = flat(&cells[i]);
        next[i] = head[k];
        head[k] = i;
    }
    let n3 = 3usize.pow(D as u32);
    for i in 0..n {
        for o in 0..n3 {
            let mut cc = [0usize; D];
            let mut oo = o;
            let mut ok = true;
            for d in 0..D {
                let off = (oo % 3) as i64 - 1;
                oo /= 3;
                let k = cells[i][d] as i64 + off;
                let m = ncell[d] as i64;
                if (0..m).contains(&k) {
                    cc[d] = k as usize;
                } else if simbox.boundary[d] == Boundary::Periodic {
                    cc[d] = k.rem_euclid(m) as usize;
                } else {
                    ok = false;
                }
            }
            if !ok {
                continue;
            }
            let mut j = head[flat(&cc)];
            while j != usize::MAX {
                if j > i {
                    let r = sep(i, j);
                    let dist = dot(&r, &r).sqrt();
                    if dist < cutoff {
                        f(i, j, r, dist);
                    }
                }
                j = next[j];
            }
        }
    }
}

/// Packing fraction Σ v_i / V.
pub fn packing_fraction<const D: usize>(simbox: &SimBox<D>, radii: &[f64]) -> f64 {
    radii.iter().map(|r| ball_volume(D, *r)).sum::<f64>() / simbox.volume()
}

/// The deepest overlap, as (i, j, |r|/σ − 1 < 0), or `None` if no pair is
/// closer than its contact distance. Exact over all pairs that can touch.
pub fn deepest_overlap<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
) -> Option<(usize, usize, f64)> {
    let rmax = radii.iter().cloned().fold(0.0, f64::max);
    let mut worst: Option<(usize, usize, f64)> = None;
    for_pairs(simbox, pos, 2.0 * rmax, |i, j, _, dist| {
        let gap = dist / (radii[i] + radii[j]) - 1.0;
        if gap < 0.0 && worst.is_none_or(|w| gap < w.2) {
            worst = Some((i, j, gap));
        }
    });
    worst
}

/// Contacts of a packing at a relative gap tolerance, and its rattlers.
#[derive(Debug, Clone)]
pub struct Contacts {
    /// The relative gap tolerance: i and j touch if |r_ij| < (1 + tol)(r_i + r_j).
    pub tol: f64,
    /// Contacts per particle (all contacts).
    pub z: Vec<usize>,
    /// Particles with fewer than D + 1 contacts in the backbone (removed
    /// repeatedly, since removing one may leave a neighbour short).
    pub rattler: Vec<bool>,
    /// Mean contact number of the backbone (non-rattlers, contacts with
    /// non-rattlers only).
    pub backbone_z: f64,
    /// Wall contacts count as contacts when walls are present.
    pub pairs: Vec<(usize, usize)>,
}

impl Contacts {
    pub fn rattlers(&self) -> usize {
        self.rattler.iter().filter(|&&r| r).count()
    }
}

/// Finds contacts at relative gap `tol` and rattlers (fewer than D + 1
/// contacts with non-rattlers, removed recursively; a particle touching a
/// wall counts the wall as a contact).
pub fn contacts<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
    tol: f64,
) -> Contacts {
    contacts_with(simbox, pos, radii, tol, false)
}

/// As [`contacts`], with the strict test of mechanical stability: a
/// particle is also a rattler when its contacts with non-rattlers all lie
/// in one open hemisphere, so that no repulsive contact forces can balance
/// it (the origin outside the convex hull of the contact directions:
/// [`balanced`]). Removing a particle can unbalance its neighbours, so the
/// test cascades: what is left is a backbone in which every particle can
/// be in force balance.
pub fn stable_contacts<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
    tol: f64,
) -> Contacts {
    contacts_with(simbox, pos, radii, tol, true)
}

fn contacts_with<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
    tol: f64,
    strict: bool,
) -> Contacts {
    let n = pos.len();
    let rmax = radii.iter().cloned().fold(0.0, f64::max);
    let mut pairs = Vec::new();
    // Unit directions from each particle to each of its contacts.
    let mut adj: Vec<Vec<(usize, [f64; D])>> = vec![Vec::new(); n];
    for_pairs(simbox, pos, 2.0 * rmax * (1.0 + tol), |i, j, r, dist| {
        if dist < (1.0 + tol) * (radii[i] + radii[j]) && dist > 0.0 {
            pairs.push((i, j));
            // r = x_i − x_j: j lies along −r from i.
            let u = r.map(|x| x / dist);
            adj[i].push((j, u.map(|x| -x)));
            adj[j].push((i, u));
        }
    });
    let mut walls: Vec<Vec<[f64; D]>> = vec![Vec::new(); n];
    for i in 0..n {
        for d in 0..D {
            if simbox.boundary[d] == Boundary::Wall {
                let r = radii[i] * (1.0 + tol);
                let mut u = [0.0; D];
                if pos[i][d] < r {
                    u[d] = -1.0;
                    walls[i].push(u);
                } else if pos[i][d] > simbox.size[d] - r {
                    u[d] = 1.0;
                    walls[i].push(u);
                }
            }
        }
    }
    let z: Vec<usize> = (0..n).map(|i| adj[i].len() + walls[i].len()).collect();
    let mut rattler = vec![false; n];
    let loose = |i: usize, rattler: &[bool]| -> bool {
        let dirs: Vec<[f64; D]> = adj[i]
            .iter()
            .filter(|(j, _)| !rattler[*j])
            .map(|(_, u)| *u)
            .chain(walls[i].iter().copied())
            .collect();
        dirs.len() < D + 1 || (strict && !balanced(&dirs))
    };
    let mut stack: Vec<usize> = (0..n).filter(|&i| loose(i, &rattler)).collect();
    while let Some(i) = stack.pop() {
        if rattler[i] {
            continue;
        }
        rattler[i] = true;
        for &(j, _) in &adj[i] {
            if !rattler[j] && loose(j, &rattler) {
                stack.push(j);
            }
        }
    }
    let back: Vec<usize> = (0..n).filter(|&i| !rattler[i]).collect();
    let backbone_z = if back.is_empty() {
        0.0
    } else {
        back.iter()
            .map(|&i| adj[i].iter().filter(|(j, _)| !rattler[*j]).count())
            .sum::<usize>() as f64
            / back.len() as f64
    };
    Contacts {
        tol,
        z,
        rattler,
        backbone_z,
        pairs,
    }
}

/// Whether repulsive forces along unit directions `dirs` can balance:
/// whether the origin lies in their convex hull. By Carathéodory it then
/// lies in the hull of some D + 1 of them, so every such subset is tried:
/// Σ λₖ uₖ = 0, Σ λₖ = 1 solved for λ, accepted when λ ≥ 0 (to 1e-12).
/// Directions all in one open hemisphere never balance.
pub fn balanced<const D: usize>(dirs: &[[f64; D]]) -> bool {
    let m = dirs.len();
    if m < D + 1 {
        // Fewer: the hull is too small unless two are opposite (a particle
        // squeezed along a line, which is still no mechanical backbone).
        return false;
    }
    let mut pick: Vec<usize> = (0..=D).collect();
    loop {
        if simplex_holds_origin::<D>(&pick.iter().map(|&k| dirs[k]).collect::<Vec<_>>()) {
            return true;
        }
        // The next (D + 1)-subset in lexicographic order.
        let mut k = D;
        loop {
            if pick[k] < m - (D + 1 - k) {
                pick[k] += 1;
                for l in k + 1..=D {
                    pick[l] = pick[l - 1] + 1;
                }
                break;
            }
            if k == 0 {
                return false;
            }
            k -= 1;
        }
    }
}

/// Whether the origin lies in the simplex of D + 1 points (barycentric
/// weights by Gaussian elimination with partial pivoting).
fn simplex_holds_origin<const D: usize>(v: &[[f64; D]]) -> bool {
    let size = D + 1;
    // Rows: D coordinates and the sum of weights; columns: the points.
    let mut a = vec![vec![0.0; size + 1]; size];
    for (k, p) in v.iter().enumerate() {
        for d in 0..D {
            a[d][k] = p[d];
        }
        a[D][k] = 1.0;
    }
    a[D][size] = 1.0;
    for col in 0..size {
        let pivot = (col..size)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap();
        if a[pivot][col].abs() < 1e-12 {
            // Degenerate (coplanar points): some other subset decides.
            return false;
        }
        a.swap(col, pivot);
        for row in 0..size {
            if row != col {
                let f = a[row][col] / a[col][col];
                for c in col..=size {
                    a[row][c] -= f * a[col][c];
                }
            }
        }
    }
    (0..size).all(|k| a[k][size] / a[k][k] >= -1e-12)
}

/// The pair correlation g(r) with r in units of the mean diameter, over
/// `bins` bins up to `rmax`; rows (r at the bin centre, g). Periodic boxes
/// only give the bulk value (walls lower it near the faces).
pub fn pair_correlation<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
    rmax: f64,
    bins: usize,
) -> Vec<(f64, f64)> {
    let n = pos.len();
    let mean_d = 2.0 * radii.iter().sum::<f64>() / n as f64;
    let cutoff = rmax * mean_d;
    let mut hist = vec![0u64; bins];
    for_pairs(simbox, pos, cutoff, |_, _, _, dist| {
        let k = (dist / cutoff * bins as f64) as usize;
        if k < bins {
            hist[k] += 2;
        }
    });
    let rho = n as f64 / simbox.volume();
    let dr = rmax / bins as f64;
    (0..bins)
        .map(|k| {
            let (r0, r1) = (k as f64 * dr * mean_d, (k + 1) as f64 * dr * mean_d);
            let shell = ball_volume(D, r1) - ball_volume(D, r0);
            (
                (k as f64 + 0.5) * dr,
                hist[k] as f64 / (n as f64 * rho * shell),
            )
        })
        .collect()
}

/// Associated Legendre P_l^m(x) for 0 ≤ m ≤ l (Condon–Shortley phase left
/// out: it cancels in |q_lm|²), by the standard upward recurrence.
fn legendre(l: usize, m: usize, x: f64) -> f64 {
    let s = (1.0 - x * x).max(0.0).sqrt();
    let mut pmm = 1.0;
    for k in 0..m {
        pmm *= (2 * k + 1) as f64 * s;
    }
    if l == m {
        return pmm;
    }
    let mut p1 = x * (2 * m + 1) as f64 * pmm;
    if l == m + 1 {
        return p1;
    }
    let mut p0 = pmm;
    for ll in (m + 2)..=l {
        let p2 = ((2 * ll - 1) as f64 * x * p1 - (ll + m - 1) as f64 * p0) / (ll - m) as f64;
        p0 = p1;
        p1 = p2;
    }
    p1
}

fn factorial(k: usize) -> f64 {
    (1..=k).map(|x| x as f64).product()
}

/// Global bond-orientational order of the bonds shorter than `bond`·(r_i +
/// r_j): in 3-D Steinhardt's Q6 = √(4π/13 Σ_m |⟨Y_6m⟩|²) (0.575 for fcc,
/// → 0 as N^(−1/2) for random packings); in 2-D the hexatic |⟨e^(6iθ)⟩|.
/// Returns (order, bonds).
pub fn bond_order<const D: usize>(
    simbox: &SimBox<D>,
    pos: &[[f64; D]],
    radii: &[f64],
    bond: f64,
) -> (f64, usize) {
    let rmax = radii.iter().cloned().fold(0.0, f64::max);
    const L: usize = 6;
    let mut re = [0.0; L + 1];
    let mut im = [0.0; L + 1];
    let mut count = 0usize;
    for_pairs(simbox, pos, 2.0 * rmax * bond, |i, j, r, dist| {
        if dist >= bond * (radii[i] + radii[j]) || dist == 0.0 {
            return;
        }
        count += 1;
        if D == 2 {
            let th = r[1].atan2(r[0]);
            re[0] += (6.0 * th).cos();
            im[0] += (6.0 * th).sin();
        } else {
            let ct = r[2] / dist;
            let ph = r[1].atan2(r[0]);
            for m in 0..=L {
                let p = legendre(L, m, ct);
                re[m] += p * (m as f64 * ph).cos();
                im[m] += p * (m as f64 * ph).sin();
            }
        }
    });
    if count == 0 {
        return (0.0, 0);
    }
    let nb = count as f64;
    if D == 2 {
        return ((re[0] * re[0] + im[0] * im[0]).sqrt() / nb, count);
    }
    let mut sum = 0.0;
    for m in 0..=L {
        let k2 =
            (2 * L + 1) as f64 / (4.0 * std::f64::consts::PI) * factorial(L - m) / factorial(L + m);
        let q2 = k2 * (re[m] * re[m] + im[m] * im[m]) / (nb * nb);
        sum += if m == 0 { q2 } else { 2.0 * q2 };
    }
    ((4.0 * std::f64::consts::PI / 13.0 * sum).sqrt(), count)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit<const D: usize>(v: [f64; D]) -> [f64; D] {
        let l = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / l)
    }

    /// Contacts balance when they surround the particle, not when they
    /// all lie in one hemisphere (or one plane in 3-D).
    #[test]
    fn contact_directions_balance_only_around_the_particle() {
        let tetra = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ]
        .map(unit);
        assert!(balanced(&tetra));
        let mut octa = Vec::new();
        for d in 0..3 {
            for s in [1.0, -1.0] {
                let mut u = [0.0; 3];
                u[d] = s;
                octa.push(u);
            }
        }
        assert!(balanced(&octa));
        // Six contacts, all above the equator: no force can push down.
        let cap: Vec<[f64; 3]> = (0..6)
            .map(|k| {
                let a = k as f64 * std::f64::consts::PI / 3.0;
                unit([a.cos(), a.sin(), 0.2])
            })
            .collect();
        assert!(!balanced(&cap));
        // The same with one contact below: balanced.
        let mut held = cap.clone();
        held.push([0.0, 0.0, -1.0]);
        assert!(balanced(&held));
        // Four in a plane: nothing out of it.
        assert!(!balanced(&[
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0]
        ]));
        // 2-D: a triangle around the disk balances; three in a half-plane do not.
        let tri = [0.0f64, 2.0, 4.0].map(|a| [a.cos(), a.sin()]);
        assert!(balanced(&tri));
        assert!(!balanced(&[[1.0, 0.1], [0.0, 1.0], [-1.0, 0.1]].map(unit)));
        assert!(balanced(&[[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]]));
    }

    /// A crystal has no rattlers; a disk lifted off its lower neighbours
    /// keeps only its two upper contacts and rattles.
    #[test]
    fn a_particle_lifted_off_its_neighbours_is_a_rattler() {
        // A triangular crystal of touching disks, periodic: every disk has
        // six contacts all round.
        let (nx, ny) = (6, 6);
        let h = 3f64.sqrt() / 2.0;
        let simbox = SimBox {
            size: [nx as f64, ny as f64 * h],
            boundary: [Boundary::Periodic; 2],
        };
        let mut pos = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                pos.push([i as f64 + 0.5 * (j % 2) as f64, j as f64 * h]);
            }
        }
        let radii = vec![0.5; pos.len()];
        for c in [
            contacts(&simbox, &pos, &radii, 1e-9),
            stable_contacts(&simbox, &pos, &radii, 1e-9),
        ] {
            assert_eq!(c.rattlers(), 0);
            assert!((c.backbone_z - 6.0).abs() < 1e-12);
        }
        let k = 3 * nx + 2;
        let mut moved = pos.clone();
        moved[k][1] += 0.01;
        let c = contacts(&simbox, &moved, &radii, 1e-9);
        assert!(c.rattler[k], "contacts {}", c.z[k]);
        assert_eq!(c.z[k], 2, "two upper neighbours still touch it");
    }
    use crate::init::lattice;

    #[test]
    fn fcc_has_steinhardt_q6() {
        // fcc: Q6 = 0.57452 (Steinhardt et al. 1983, Table I)
        let size = [4.0 * 2f64.sqrt(); 3];
        let pos = lattice::<3>(256, size, true);
        let simbox = SimBox {
            size,
            boundary: [Boundary::Periodic; 3],
        };
        let radii = vec![0.5; 256];
        let (q6, bonds) = bond_order(&simbox, &pos, &radii, 1.2);
        assert_eq!(bonds, 256 * 6);
        assert!((q6 - 0.57452).abs() < 1e-4, "Q6 = {q6}");
        let c = contacts(&simbox, &pos, &radii, 1e-9);
        assert_eq!(c.rattlers(), 0);
        assert!((c.backbone_z - 12.0).abs() < 1e-12);
        let g = pair_correlation(&simbox, &pos, &radii, 1.25, 10);
        // all 12 neighbours at r = d: the peak is the bin around 1
        let peak = g
            .iter()
            .cloned()
            .fold((0.0, 0.0), |m, x| if x.1 > m.1 { x } else { m });
        assert!((peak.0 - 1.0).abs() <= 0.0625 + 1e-12, "{g:?}");
    }

    #[test]
    fn triangular_lattice_has_hexatic_order_one() {
        let n = 10;
        let mut pos = Vec::new();
        for a in 0..n {
            for b in 0..n {
                pos.push([a as f64 + 0.5 * (b % 2) as f64, b as f64 * 0.75f64.sqrt()]);
            }
        }
        let simbox = SimBox {
            size: [n as f64, n as f64 * 0.75f64.sqrt()],
            boundary: [Boundary::Periodic; 2],
        };
        let radii = vec![0.5; n * n];
        let (psi6, bonds) = bond_order(&simbox, &pos, &radii, 1.1);
        assert_eq!(bonds, 3 * n * n);
        assert!((psi6 - 1.0).abs() < 1e-9);
    }
}
