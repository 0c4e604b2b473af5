//! The earliest contact among a particle's listed neighbours, eight
//! neighbours at a time with AVX-512 (picked at run time; the scalar loop in
//! `system.rs` is the reference and the fallback).
//!
//! Each particle record is one 64-byte line of eight doubles: x (D), v (D),
//! t, r (and padding for D = 2). Eight records are loaded as rows and
//! transposed, so lane k of column c is field c of neighbour k. The
//! arithmetic is the scalar loop's, operation for operation (no fused
//! multiply–adds, the same order of sums, the same selects), so both paths
//! give bit-identical times and pick the same partner: the earliest time,
//! ties to the first in the list.

use std::arch::x86_64::*;

pub(crate) use crate::system::{Probe, TwoEarliest};

/// Whether this CPU can run [`earliest`].
pub(crate) fn available() -> bool {
    mote_geom::simd::has_avx512()
}

/// Transposes eight rows of eight doubles.
#[inline]
#[target_feature(enable = "avx512f")]
fn transpose(r: [__m512d; 8]) -> [__m512d; 8] {
    let t0 = _mm512_unpacklo_pd(r[0], r[1]);
    let t1 = _mm512_unpackhi_pd(r[0], r[1]);
    let t2 = _mm512_unpacklo_pd(r[2], r[3]);
    let t3 = _mm512_unpackhi_pd(r[2], r[3]);
    let t4 = _mm512_unpacklo_pd(r[4], r[5]);
    let t5 = _mm512_unpackhi_pd(r[4], r[5]);
    let t6 = _mm512_unpacklo_pd(r[6], r[7]);
    let t7 = _mm512_unpackhi_pd(r[6], r[7]);
    let lo = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
    let hi = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
    let u0 = _mm512_permutex2var_pd(t0, lo, t2); // columns 0, 4 of rows 0–3
    let u1 = _mm512_permutex2var_pd(t0, hi, t2); // columns 2, 6
    let u2 = _mm512_permutex2var_pd(t1, lo, t3); // columns 1, 5
    let u3 = _mm512_permutex2var_pd(t1, hi, t3); // columns 3, 7
    let u4 = _mm512_permutex2var_pd(t4, lo, t6); // the same for rows 4–7
    let u5 = _mm512_permutex2var_pd(t4, hi, t6);
    let u6 = _mm512_permutex2var_pd(t5, lo, t7);
    let u7 = _mm512_permutex2var_pd(t5, hi, t7);
    [
        _mm512_shuffle_f64x2::<0x44>(u0, u4),
        _mm512_shuffle_f64x2::<0x44>(u2, u6),
        _mm512_shuffle_f64x2::<0x44>(u1, u5),
        _mm512_shuffle_f64x2::<0x44>(u3, u7),
        _mm512_shuffle_f64x2::<0xEE>(u0, u4),
        _mm512_shuffle_f64x2::<0xEE>(u2, u6),
        _mm512_shuffle_f64x2::<0xEE>(u1, u5),
        _mm512_shuffle_f64x2::<0xEE>(u3, u7),
    ]
}

/// a·b summed as the scalar `dot` does: ((0 + a₀b₀) + a₁b₁) + …
#[inline]
#[target_feature(enable = "avx512f")]
fn dot<const D: usize>(a: &[__m512d; D], b: &[__m512d; D]) -> __m512d {
    let mut s = _mm512_setzero_pd();
    for d in 0..D {
        s = _mm512_add_pd(s, _mm512_mul_pd(a[d], b[d]));
    }
    s
}

/// The two earliest contact times with the particles of `list` (records in
/// `records`, 8 doubles each) and their positions in `list`.
///
/// # Safety
/// The CPU must have AVX-512F; every index in `list` and `own` must be a
/// record of `records`.
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn earliest<const D: usize, const GROW: bool>(
    records: *const f64,
    own: usize,
    list: &[u32],
    probe: &Probe<D>,
) -> TwoEarliest {
    let inf = _mm512_set1_pd(f64::INFINITY);
    let zero = _mm512_setzero_pd();
    let now = _mm512_set1_pd(probe.now);
    let ri = _mm512_set1_pd(probe.r);
    let xi = probe.x.map(|x| _mm512_set1_pd(x));
    let vi = probe.v.map(|v| _mm512_set1_pd(v));
    let size = probe.size.map(|l| _mm512_set1_pd(l));
    let half = probe.half.map(|h| _mm512_set1_pd(h));
    let minus_half = probe.half.map(|h| _mm512_set1_pd(-h));
    let g = _mm512_set1_pd(probe.g);
    let delta = _mm512_set1_pd(probe.delta);
    let mut two = TwoEarliest::NONE;
    for (block, chunk) in list.chunks(8).enumerate() {
        let m = chunk.len();
        let mut rows = [zero; 8];
        for (k, row) in rows.iter_mut().enumerate() {
            // lanes past the list's end read the particle's own record;
            // their times are discarded below
            let j = if k < m { chunk[k] as usize } else { own };
            // SAFETY: `j` is a record index (caller's contract); records
            // are 64-byte aligned lines of 8 doubles.
            *row = unsafe { _mm512_load_pd(records.add(8 * j)) };
        }
        let col = transpose(rows);
        let dtj = _mm512_sub_pd(now, col[2 * D]);
        let rj = col[2 * D + 1];
        let mut r = [zero; D];
        let mut v = [zero; D];
        for d in 0..D {
            let xj = _mm512_add_pd(col[d], _mm512_mul_pd(col[D + d], dtj));
            r[d] = _mm512_sub_pd(xi[d], xj);
            v[d] = _mm512_sub_pd(vi[d], col[D + d]);
            if probe.periodic[d] {
                let up =
                    _mm512_maskz_mov_pd(_mm512_cmp_pd_mask::<_CMP_GT_OQ>(r[d], half[d]), size[d]);
                let down = _mm512_maskz_mov_pd(
                    _mm512_cmp_pd_mask::<_CMP_LT_OQ>(r[d], minus_half[d]),
                    size[d],
                );
                r[d] = _mm512_add_pd(_mm512_sub_pd(r[d], up), down);
            }
        }
        let t = if GROW {
            let sigma0 = _mm512_add_pd(ri, rj);
            let sigma = _mm512_mul_pd(sigma0, g);
            let sdot = _mm512_mul_pd(sigma0, delta);
            let b = _mm512_sub_pd(dot(&r, &v), _mm512_mul_pd(sigma, sdot));
            let a = _mm512_sub_pd(dot(&v, &v), _mm512_mul_pd(sdot, sdot));
            let c = _mm512_sub_pd(dot(&r, &r), _mm512_mul_pd(sigma, sigma));
            growing_root(a, b, c)
        } else {
            let sigma = _mm512_add_pd(ri, rj);
            let c = _mm512_sub_pd(dot(&r, &r), _mm512_mul_pd(sigma, sigma));
            approach_root(dot(&v, &v), dot(&r, &v), c)
        };
        let t = _mm512_mask_mov_pd(inf, ((1u32 << m) - 1) as u8, t);
        let mut times = [0.0; 8];
        // SAFETY: `times` holds eight doubles.
        unsafe { _mm512_storeu_pd(times.as_mut_ptr(), t) };
        two.offer_block(&times, 8 * block);
    }
    two
}

/// The scalar `approach_root`, lane by lane.
#[inline]
#[target_feature(enable = "avx512f")]
fn approach_root(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
    let zero = _mm512_setzero_pd();
    let disc = _mm512_sub_pd(_mm512_mul_pd(b, b), _mm512_mul_pd(a, c));
    let root = _mm512_div_pd(
        c,
        _mm512_add_pd(neg(b), _mm512_sqrt_pd(_mm512_max_pd(disc, zero))),
    );
    let inside = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(c, zero);
    let t = _mm512_mask_mov_pd(root, inside, zero);
    let hit =
        _mm512_cmp_pd_mask::<_CMP_LT_OQ>(b, zero) & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(disc, zero);
    _mm512_mask_mov_pd(_mm512_set1_pd(f64::INFINITY), hit, t)
}

/// The scalar `growing_root`, lane by lane.
#[inline]
#[target_feature(enable = "avx512f")]
fn growing_root(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
    let zero = _mm512_setzero_pd();
    let inf = _mm512_set1_pd(f64::INFINITY);
    let b_neg = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(b, zero);
    let a_neg = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(a, zero);
    // inside contact: 0 if approaching, −b/a if growth takes over, else +∞
    let later = _mm512_mask_mov_pd(inf, a_neg, _mm512_div_pd(neg(b), a));
    let inside_t = _mm512_mask_mov_pd(later, b_neg, zero);
    // outside: the cancellation-free root
    let disc = _mm512_sub_pd(_mm512_mul_pd(b, b), _mm512_mul_pd(a, c));
    let root = _mm512_div_pd(
        c,
        _mm512_add_pd(neg(b), _mm512_sqrt_pd(_mm512_max_pd(disc, zero))),
    );
    let hit = (b_neg | a_neg) & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(disc, zero);
    let outside_t = _mm512_mask_mov_pd(inf, hit, root);
    let inside = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(c, zero);
    _mm512_mask_mov_pd(outside_t, inside, inside_t)
}

/// −x (a sign flip, exact).
#[inline]
#[target_feature(enable = "avx512f")]
fn neg(x: __m512d) -> __m512d {
    _mm512_castsi512_pd(_mm512_xor_si512(
        _mm512_castpd_si512(x),
        _mm512_set1_epi64(i64::MIN),
    ))
}
