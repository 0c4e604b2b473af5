//! Loading listed neighbours into AVX-512 lanes.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use super::Copy4;

/// The eight records `copies[index[m]]`, transposed into (x, y, z) with
/// record m in lane m: two records to a register (a_m = r_m | r_{m+4}),
/// unpacked in pairs per 128-bit lane, then each coordinate picked by a
/// two-source permute. Eight aligned loads and eight shuffles, where
/// gathers would cost three eight-lane gathers.
///
/// # Safety
/// The CPU must have AVX-512F; every `index[m]` must index `copies`.
#[inline]
#[target_feature(enable = "avx512f")]
pub(crate) unsafe fn load_copies(
    copies: &[Copy4],
    index: &[u32; 8],
) -> (__m512d, __m512d, __m512d) {
    let base = copies.as_ptr() as *const f64;
    let low = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
    let high = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
    // SAFETY: the caller guarantees every index is in bounds; a Copy4 is
    // four f64 aligned to 32 bytes.
    let record = |m: usize| unsafe { _mm256_load_pd(base.add(4 * index[m] as usize)) };
    let pair = |m: usize| _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(record(m)), record(m + 4));
    let (a0, a1, a2, a3) = (pair(0), pair(1), pair(2), pair(3));
    let (xz01, yw01) = (_mm512_unpacklo_pd(a0, a1), _mm512_unpackhi_pd(a0, a1));
    let (xz23, yw23) = (_mm512_unpacklo_pd(a2, a3), _mm512_unpackhi_pd(a2, a3));
    (
        _mm512_permutex2var_pd(xz01, low, xz23),
        _mm512_permutex2var_pd(yw01, low, yw23),
        _mm512_permutex2var_pd(xz01, high, xz23),
    )
}

/// Calls `lanes(index, valid)` on a row's neighbours eight at a time: full
/// groups with every lane valid, then the rest padded with `pad` (any index
/// the kernel may load) and only its own lanes valid.
#[inline(always)]
pub(crate) fn in_eights(row: &[u32], pad: u32, mut lanes: impl FnMut(&[u32; 8], __mmask8)) {
    let chunks = row.chunks_exact(8);
    let tail = chunks.remainder();
    for chunk in chunks {
        lanes(chunk.try_into().expect("eight"), 0xff);
    }
    if !tail.is_empty() {
        let mut padded = [pad; 8];
        padded[..tail.len()].copy_from_slice(tail);
        lanes(&padded, ((1u32 << tail.len()) - 1) as __mmask8);
    }
}
