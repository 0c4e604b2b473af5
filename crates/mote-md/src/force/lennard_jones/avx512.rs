//! One row of the Lennard-Jones pair loop, eight neighbours at a time:
//! eight 32-byte records loaded and transposed (`load_copies`), 1/r² from `vrcp14pd`
//! refined by two Newton–Raphson steps y ← y (2 − r² y) (14 → 28 → 56 bits), lanes beyond
//! r_c masked to zero. The portable loop in `mod.rs` is the reference.

use std::arch::x86_64::*;

use glam::DVec3;

use super::{Coefficients, RowSum};
use crate::neighbor::avx512::{in_eights, load_copies};
use crate::neighbor::Copy4;

/// The sums of row `row` of particle copy `k` (see [`super::row_portable`]).
///
/// # Safety
/// The CPU must have AVX-512F; `k` and every entry of `row` must index
/// `position`.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn row(
    k: usize,
    row: &[u32],
    position: &[Copy4],
    c: &Coefficients,
    energy: bool,
) -> RowSum {
    let [xi, yi, zi, _] = position[k].0;
    let (xi, yi, zi) = (_mm512_set1_pd(xi), _mm512_set1_pd(yi), _mm512_set1_pd(zi));
    let cutoff2 = _mm512_set1_pd(c.cutoff2);
    let sigma2 = _mm512_set1_pd(c.sigma2);
    let eps48 = _mm512_set1_pd(c.eps48);
    let eps24 = _mm512_set1_pd(c.eps24);
    let eps4 = _mm512_set1_pd(c.eps4);
    let shift = _mm512_set1_pd(c.shift);
    let two = _mm512_set1_pd(2.0);
    let zero = _mm512_setzero_pd();
    let (mut fx, mut fy, mut fz, mut w, mut u) = (zero, zero, zero, zero, zero);

    let lanes = |index: &[u32; 8], valid: __mmask8| {
        // SAFETY: the caller guarantees every index is in bounds.
        let (xj, yj, zj) = unsafe { load_copies(position, index) };
        let dx = _mm512_sub_pd(xi, xj);
        let dy = _mm512_sub_pd(yi, yj);
        let dz = _mm512_sub_pd(zi, zj);
        let r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
        let inside = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(valid, r2, cutoff2);
        // Lanes outside (padding: r² = 0) may compute infinities; the
        // masked product below discards them.
        let mut inv = _mm512_rcp14_pd(r2);
        inv = _mm512_mul_pd(inv, _mm512_fnmadd_pd(r2, inv, two));
        inv = _mm512_mul_pd(inv, _mm512_fnmadd_pd(r2, inv, two));
        let s2 = _mm512_mul_pd(sigma2, inv);
        let s6 = _mm512_mul_pd(_mm512_mul_pd(s2, s2), s2);
        let f = _mm512_maskz_mul_pd(
            inside,
            _mm512_mul_pd(inv, s6),
            _mm512_fmsub_pd(eps48, s6, eps24),
        );
        fx = _mm512_fmadd_pd(f, dx, fx);
        fy = _mm512_fmadd_pd(f, dy, fy);
        fz = _mm512_fmadd_pd(f, dz, fz);
        w = _mm512_fmadd_pd(f, r2, w);
        if energy {
            let e = _mm512_fmsub_pd(_mm512_fmsub_pd(eps4, s6, eps4), s6, shift);
            u = _mm512_mask_add_pd(u, inside, u, e);
        }
    };

    in_eights(row, k as u32, lanes);
    RowSum {
        force: DVec3::new(
            _mm512_reduce_add_pd(fx),
            _mm512_reduce_add_pd(fy),
            _mm512_reduce_add_pd(fz),
        ),
        virial: _mm512_reduce_add_pd(w),
        energy: _mm512_reduce_add_pd(u),
    }
}
