//! AVX-512 kernels: 8 pairs per instruction, 1/√r² from `vrsqrt14pd` refined
//! by two Newton–Raphson steps y ← y (3/2 − (r²/2) y²) (14 → 28 → 56 bits).
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use glam::DVec3;
use mote_geom::simd::avx512::rsqrt;

use super::Soa;

/// Separations d = r_j − r_i of the 8 particles from j, their masses, and
/// r² = |d|² + ε².
#[inline]
#[target_feature(enable = "avx512f")]
unsafe fn separations(
    p: Soa,
    j: usize,
    ri: [__m512d; 3],
    eps2: __m512d,
) -> ([__m512d; 3], __m512d, __m512d) {
    // SAFETY: the caller guarantees j + 8 ≤ the slices' length.
    let (rj, m) = unsafe { load(p, j) };
    let (d, r2) = separated(rj, ri, eps2);
    (d, m, r2)
}

/// The 8 particles from j: positions and masses.
///
/// # Safety
/// j + 8 ≤ the slices' length.
#[inline]
#[target_feature(enable = "avx512f")]
unsafe fn load(p: Soa, j: usize) -> ([__m512d; 3], __m512d) {
    // SAFETY: the caller guarantees j + 8 ≤ the slices' length.
    unsafe {
        (
            [
                _mm512_loadu_pd(p.x.as_ptr().add(j)),
                _mm512_loadu_pd(p.y.as_ptr().add(j)),
                _mm512_loadu_pd(p.z.as_ptr().add(j)),
            ],
            _mm512_loadu_pd(p.m.as_ptr().add(j)),
        )
    }
}

/// d = r_j − r_i and r² = |d|² + ε².
#[inline]
#[target_feature(enable = "avx512f")]
fn separated(rj: [__m512d; 3], ri: [__m512d; 3], eps2: __m512d) -> ([__m512d; 3], __m512d) {
    let dx = _mm512_sub_pd(rj[0], ri[0]);
    let dy = _mm512_sub_pd(rj[1], ri[1]);
    let dz = _mm512_sub_pd(rj[2], ri[2]);
    let r2 = _mm512_fmadd_pd(
        dx,
        dx,
        _mm512_fmadd_pd(dy, dy, _mm512_fmadd_pd(dz, dz, eps2)),
    );
    ([dx, dy, dz], r2)
}

/// The pull m_j d/r³ of 8 partners added to `a` (lanes at no distance add nothing).
#[inline]
#[target_feature(enable = "avx512f")]
fn pull(a: &mut [__m512d; 3], d: [__m512d; 3], m: __m512d, r2: __m512d) {
    let live = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, _mm512_setzero_pd());
    let y = rsqrt(r2);
    let s = _mm512_maskz_mul_pd(live, _mm512_mul_pd(_mm512_mul_pd(y, y), y), m);
    for (a, d) in a.iter_mut().zip(d) {
        *a = _mm512_fmadd_pd(s, d, *a);
    }
}

/// The lanes of a row's sums added up.
#[inline]
#[target_feature(enable = "avx512f")]
fn reduced(a: [__m512d; 3]) -> DVec3 {
    DVec3::new(
        _mm512_reduce_add_pd(a[0]),
        _mm512_reduce_add_pd(a[1]),
        _mm512_reduce_add_pd(a[2]),
    )
}

/// r_i broadcast to all lanes.
#[inline]
#[target_feature(enable = "avx512f")]
fn broadcast(p: Soa, i: usize) -> [__m512d; 3] {
    [
        _mm512_set1_pd(p.x[i]),
        _mm512_set1_pd(p.y[i]),
        _mm512_set1_pd(p.z[i]),
    ]
}

/// See [`super::portable::pairs`].
///
/// # Safety
/// The CPU must support AVX-512F; `j_end` must be a multiple of 8 no larger
/// than the (equal) lengths of the slices of `p`; `r·` must cover `base..j_end`
/// with `base ≤ j_start & !7`.
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn pairs(
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
    debug_assert!(j_end.is_multiple_of(8) && j_end <= p.x.len() && base <= j_start & !7);
    debug_assert!(rx.len() >= j_end - base && ry.len() >= j_end - base && rz.len() >= j_end - base);
    let ri = broadcast(p, i);
    let mi = _mm512_set1_pd(p.m[i]);
    let veps2 = _mm512_set1_pd(eps2);
    let zero = _mm512_setzero_pd();
    let (mut ax, mut ay, mut az) = (zero, zero, zero);
    let mut j = j_start & !7;
    // Lanes of the first block below j_start take no part.
    let mut lanes: __mmask8 = 0xFFu8 << (j_start - j);
    while j < j_end {
        // SAFETY: j + 8 ≤ j_end ≤ len for the particle arrays, and
        // j − base + 8 ≤ j_end − base ≤ len for the reaction arrays.
        let ([dx, dy, dz], mj, r2) = separations(p, j, ri, veps2);
        let live = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero) & lanes;
        let y = rsqrt(r2);
        let s = _mm512_maskz_mul_pd(live, _mm512_mul_pd(y, y), y);
        let sj = _mm512_mul_pd(s, mj);
        ax = _mm512_fmadd_pd(sj, dx, ax);
        ay = _mm512_fmadd_pd(sj, dy, ay);
        az = _mm512_fmadd_pd(sj, dz, az);
        let si = _mm512_mul_pd(s, mi);
        let k = j - base;
        let px = rx.as_mut_ptr().add(k);
        let py = ry.as_mut_ptr().add(k);
        let pz = rz.as_mut_ptr().add(k);
        _mm512_storeu_pd(px, _mm512_fnmadd_pd(si, dx, _mm512_loadu_pd(px)));
        _mm512_storeu_pd(py, _mm512_fnmadd_pd(si, dy, _mm512_loadu_pd(py)));
        _mm512_storeu_pd(pz, _mm512_fnmadd_pd(si, dz, _mm512_loadu_pd(pz)));
        lanes = 0xFF;
        j += 8;
    }
    DVec3::new(
        _mm512_reduce_add_pd(ax),
        _mm512_reduce_add_pd(ay),
        _mm512_reduce_add_pd(az),
    )
}

/// [`pairs`] for rows i and i + 1 over the same j range `j_start..j_end`
/// (j_start a multiple of 8): both rows' pulls are returned and the
/// reactions of row i, then of row i + 1, are subtracted per j block — the
/// same operations in the same order as two calls of [`pairs`].
///
/// # Safety
/// As for [`pairs`], with j_start a multiple of 8 and i + 1 < the slices' length.
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn pairs2(
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
    debug_assert!(
        j_start.is_multiple_of(8)
            && j_end.is_multiple_of(8)
            && j_end <= p.x.len()
            && base <= j_start
    );
    let (r0, r1) = (broadcast(p, i), broadcast(p, i + 1));
    let (m0, m1) = (_mm512_set1_pd(p.m[i]), _mm512_set1_pd(p.m[i + 1]));
    let veps2 = _mm512_set1_pd(eps2);
    let zero = _mm512_setzero_pd();
    let mut a0 = [zero; 3];
    let mut a1 = [zero; 3];
    let mut j = j_start;
    while j < j_end {
        // SAFETY: j + 8 ≤ j_end ≤ len, and j − base + 8 ≤ the reaction slices' length.
        let (d0, mj, r2_0) = separations(p, j, r0, veps2);
        let (d1, _, r2_1) = separations(p, j, r1, veps2);
        let y0 = rsqrt(r2_0);
        let y1 = rsqrt(r2_1);
        let s0 = _mm512_maskz_mul_pd(
            _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2_0, zero),
            _mm512_mul_pd(y0, y0),
            y0,
        );
        let s1 = _mm512_maskz_mul_pd(
            _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2_1, zero),
            _mm512_mul_pd(y1, y1),
            y1,
        );
        let (sj0, sj1) = (_mm512_mul_pd(s0, mj), _mm512_mul_pd(s1, mj));
        let (si0, si1) = (_mm512_mul_pd(s0, m0), _mm512_mul_pd(s1, m1));
        let k = j - base;
        for (c, r) in [rx.as_mut_ptr(), ry.as_mut_ptr(), rz.as_mut_ptr()]
            .into_iter()
            .enumerate()
        {
            a0[c] = _mm512_fmadd_pd(sj0, d0[c], a0[c]);
            a1[c] = _mm512_fmadd_pd(sj1, d1[c], a1[c]);
            let pr = r.add(k);
            let after0 = _mm512_fnmadd_pd(si0, d0[c], _mm512_loadu_pd(pr));
            _mm512_storeu_pd(pr, _mm512_fnmadd_pd(si1, d1[c], after0));
        }
        j += 8;
    }
    let sum = |a: [__m512d; 3]| {
        DVec3::new(
            _mm512_reduce_add_pd(a[0]),
            _mm512_reduce_add_pd(a[1]),
            _mm512_reduce_add_pd(a[2]),
        )
    };
    (sum(a0), sum(a1))
}

/// See [`super::portable::field_at`].
///
/// # Safety
/// The CPU must support AVX-512F; the slices of `p` have equal lengths, a multiple of 8.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn field_at(i: usize, p: Soa, eps2: f64) -> DVec3 {
    let ri = broadcast(p, i);
    let veps2 = _mm512_set1_pd(eps2);
    let mut a = [_mm512_setzero_pd(); 3];
    for j in (0..p.x.len()).step_by(8) {
        // SAFETY: j + 8 ≤ len.
        let (rj, m) = unsafe { load(p, j) };
        let (d, r2) = separated(rj, ri, veps2);
        pull(&mut a, d, m, r2);
    }
    reduced(a)
}

/// [`field_at`] of rows i0 and i1 through each block of partners together:
/// one load of the block for both, two independent 1/√r² chains; each row
/// the bits of [`field_at`].
///
/// # Safety
/// As for [`field_at`]; i0, i1 < the slices' length.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn field_at2(i0: usize, i1: usize, p: Soa, eps2: f64) -> (DVec3, DVec3) {
    let (r0, r1) = (broadcast(p, i0), broadcast(p, i1));
    let veps2 = _mm512_set1_pd(eps2);
    let (mut a0, mut a1) = ([_mm512_setzero_pd(); 3], [_mm512_setzero_pd(); 3]);
    for j in (0..p.x.len()).step_by(8) {
        // SAFETY: j + 8 ≤ len.
        let (rj, m) = unsafe { load(p, j) };
        let (d0, r2_0) = separated(rj, r0, veps2);
        let (d1, r2_1) = separated(rj, r1, veps2);
        pull(&mut a0, d0, m, r2_0);
        pull(&mut a1, d1, m, r2_1);
    }
    (reduced(a0), reduced(a1))
}

/// See [`super::portable::potential_at`].
///
/// # Safety
/// As for [`field_at`]; i < the slices' length.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn potential_at(i: usize, p: Soa, eps2: f64) -> f64 {
    let ri = broadcast(p, i);
    let veps2 = _mm512_set1_pd(eps2);
    let zero = _mm512_setzero_pd();
    let vi = _mm512_set1_epi64(i as i64);
    let mut lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
    let eight = _mm512_set1_epi64(8);
    let mut u = zero;
    for j in (0..p.x.len()).step_by(8) {
        // SAFETY: j + 8 ≤ len.
        let (_, m, r2) = separations(p, j, ri, veps2);
        let live = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero) & _mm512_cmpneq_epi64_mask(lane, vi);
        u = _mm512_mask3_fmadd_pd(m, rsqrt(r2), u, live);
        lane = _mm512_add_epi64(lane, eight);
    }
    _mm512_reduce_add_pd(u)
}
