//! Portable kernels, any CPU: the tiled pairs on mote-geom's [`Lanes`],
//! 1/√r² by [`Lane::rsqrt`] (multiplications only: no square root or
//! division, which take AVX2 four times the cycles of the rest of a pair);
//! the all-pairs sums one element at a time with the exact square root.

use glam::DVec3;
use mote_geom::lanes::{Lane, Lanes, LANES};

use super::Soa;

/// Own pull on i of the pairs (i, j), j in j_start..j_end, returned; the
/// reactions −m_i d/r³ are added to r·[j − base]. Eight partners at a time
/// on [`Lanes`] (the build's target vectorises them), the lanes' sums
/// added in a fixed order; a pair at no distance (r² = 0) adds nothing,
/// and a lane past `j_end` has no mass and writes no reaction.
#[allow(clippy::too_many_arguments)]
pub(super) fn pairs(
    i: usize,
    j_start: usize,
    j_end: usize,
    p: Soa,
    eps2: f64,
    base: usize,
    rx: &mut [f64],
    ry: &mut [f64],
    rz: &mut [f64],
) -> DVec3 {
    let (xi, yi, zi, mi) = (p.x[i], p.y[i], p.z[i], p.m[i]);
    let zero = Lanes::splat(0.0);
    let (mut ax, mut ay, mut az) = (zero, zero, zero);
    let mut j0 = j_start;
    while j0 < j_end {
        let live = (j_end - j0).min(LANES);
        let dx = Lanes::load(p.x, j0, live) - xi;
        let dy = Lanes::load(p.y, j0, live) - yi;
        let dz = Lanes::load(p.z, j0, live) - zi;
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        let y = r2.rsqrt();
        let s = (y * y * y).where_positive(r2);
        let sj = s * Lanes::load(p.m, j0, live);
        ax = ax + sj * dx;
        ay = ay + sj * dy;
        az = az + sj * dz;
        let si = s * mi;
        let k = j0 - base;
        (si * dx).subtract_from(rx, k, live);
        (si * dy).subtract_from(ry, k, live);
        (si * dz).subtract_from(rz, k, live);
        j0 += live;
    }
    DVec3::new(ax.sum(), ay.sum(), az.sum())
}

/// [`pairs`] for rows i and i + 1 over the same j range (its ends
/// multiples of [`LANES`]): both rows' pulls returned, the reactions of row
/// i then of row i + 1 subtracted per j block (every reaction the bits of
/// two single rows). Two rows share each j block's loads and reaction
/// stores, and give the out-of-order core two independent 1/√r² chains
/// (on [`mote_geom::lanes::Four`], one AVX2 register, the same kernel took
/// twice as long).
#[allow(clippy::too_many_arguments)]
pub(super) fn pairs2(
    i: usize,
    j_start: usize,
    j_end: usize,
    p: Soa,
    eps2: f64,
    base: usize,
    rx: &mut [f64],
    ry: &mut [f64],
    rz: &mut [f64],
) -> (DVec3, DVec3) {
    debug_assert!(j_start.is_multiple_of(LANES) && j_end.is_multiple_of(LANES));
    let row = |i: usize| [p.x[i], p.y[i], p.z[i]].map(Lanes::splat);
    let (r0, r1) = (row(i), row(i + 1));
    let (m0, m1) = (p.m[i], p.m[i + 1]);
    let zero = Lanes::splat(0.0);
    let (mut a0, mut a1) = ([zero; 3], [zero; 3]);
    for j in (j_start..j_end).step_by(LANES) {
        let rj = [p.x, p.y, p.z].map(|v| Lanes::load(v, j, LANES));
        let mj = Lanes::load(p.m, j, LANES);
        let d0: [Lanes; 3] = std::array::from_fn(|c| rj[c] - r0[c]);
        let d1: [Lanes; 3] = std::array::from_fn(|c| rj[c] - r1[c]);
        let r2_0 = d0[0] * d0[0] + d0[1] * d0[1] + d0[2] * d0[2] + eps2;
        let r2_1 = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2] + eps2;
        let (y0, y1) = (r2_0.rsqrt(), r2_1.rsqrt());
        let s0 = (y0 * y0 * y0).where_positive(r2_0);
        let s1 = (y1 * y1 * y1).where_positive(r2_1);
        let (sj0, sj1) = (s0 * mj, s1 * mj);
        let (si0, si1) = (s0 * m0, s1 * m1);
        let k = j - base;
        for (c, r) in [&mut *rx, &mut *ry, &mut *rz].into_iter().enumerate() {
            a0[c] = a0[c] + sj0 * d0[c];
            a1[c] = a1[c] + sj1 * d1[c];
            (si0 * d0[c]).subtract_from(r, k, LANES);
            (si1 * d1[c]).subtract_from(r, k, LANES);
        }
    }
    let sum = |a: [Lanes; 3]| DVec3::new(a[0].sum(), a[1].sum(), a[2].sum());
    (sum(a0), sum(a1))
}

/// Σ_{j≠i} m_j d_j / (|d_j|² + ε²)^{3/2}, d_j = r_j − r_i (every j), eight
/// partners at a time on [`Lanes`], 1/√r² by [`Lane::rsqrt`].
pub(super) fn field_at(i: usize, p: Soa, eps2: f64) -> DVec3 {
    let ri = [p.x[i], p.y[i], p.z[i]].map(Lanes::splat);
    let mut a = [Lanes::splat(0.0); 3];
    for j in (0..p.x.len()).step_by(LANES) {
        let (rj, mj) = partners(p, j);
        pull(&mut a, rj, mj, ri, eps2);
    }
    a.map(Lanes::sum).into()
}

/// [`field_at`] of rows i0 and i1 through each block of partners together
/// (shared loads, two independent 1/√r² chains); each row the bits of
/// [`field_at`].
pub(super) fn field_at2(i0: usize, i1: usize, p: Soa, eps2: f64) -> (DVec3, DVec3) {
    let row = |i: usize| [p.x[i], p.y[i], p.z[i]].map(Lanes::splat);
    let (r0, r1) = (row(i0), row(i1));
    let (mut a0, mut a1) = ([Lanes::splat(0.0); 3], [Lanes::splat(0.0); 3]);
    for j in (0..p.x.len()).step_by(LANES) {
        let (rj, mj) = partners(p, j);
        pull(&mut a0, rj, mj, r0, eps2);
        pull(&mut a1, rj, mj, r1, eps2);
    }
    (a0.map(Lanes::sum).into(), a1.map(Lanes::sum).into())
}

/// Positions and masses of the eight partners from j (the slices are
/// padded to a multiple of [`LANES`]).
#[inline(always)]
fn partners(p: Soa, j: usize) -> ([Lanes; 3], Lanes) {
    (
        [p.x, p.y, p.z].map(|v| Lanes::load(v, j, LANES)),
        Lanes::load(p.m, j, LANES),
    )
}

/// a += m_j d/(|d|² + ε²)^{3/2}, d = r_j − r_i, lane by lane (a lane at no
/// distance adds nothing).
#[inline(always)]
fn pull(a: &mut [Lanes; 3], rj: [Lanes; 3], mj: Lanes, ri: [Lanes; 3], eps2: f64) {
    let d: [Lanes; 3] = std::array::from_fn(|c| rj[c] - ri[c]);
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + eps2;
    let y = r2.rsqrt();
    let s = (y * y * y).where_positive(r2) * mj;
    for (a, d) in a.iter_mut().zip(d) {
        *a = *a + s * d;
    }
}

/// Σ_{j≠i} m_j / (|r_j − r_i|² + ε²)^{1/2}.
pub(super) fn potential_at(i: usize, p: Soa, eps2: f64) -> f64 {
    let mut u = 0.0;
    for j in 0..p.x.len() {
        let (dx, dy, dz) = (p.x[j] - p.x[i], p.y[j] - p.y[i], p.z[j] - p.z[i]);
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        if j != i && r2 > 0.0 {
            u += p.m[j] / r2.sqrt();
        }
    }
    u
}
