//! AVX-512 row kernel of the all-pairs dipole–dipole interaction (with the
//! LJ/WCA repulsion of the same loop): 8 partners per instruction, 1/r from
//! `vrsqrt14pd` refined by two Newton–Raphson steps (full double precision),
//! the self pair and the lanes past the end masked out. The arithmetic is
//! that of [`super::all_pairs_row`] (tested against it to 1e-12).
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use glam::DVec3;
use mote_geom::simd::avx512::rsqrt;

use super::{Kernel, Soa};

/// Force and torque on particle i from all others, and its share of the
/// virial; see [`super::all_pairs_row`].
///
/// # Safety
/// The CPU must support AVX-512F; the arrays of `s` must have equal lengths.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn all_pairs_row(kern: &Kernel, s: &Soa, i: usize) -> (DVec3, DVec3, f64) {
    let n = s.x.len();
    debug_assert!([&s.y, &s.z, &s.mx, &s.my, &s.mz]
        .iter()
        .all(|v| v.len() == n));
    let set = _mm512_set1_pd;
    let (xi, yi, zi) = (set(s.x[i]), set(s.y[i]), set(s.z[i]));
    let (ax, ay, az) = (set(s.mx[i]), set(s.my[i]), set(s.mz[i]));
    let k = set(kern.k);
    let lj_s2 = set(kern.lj_s2);
    let lj_rc2 = set(kern.lj_rc2);
    let lj6 = set(6.0 * kern.lj4e);
    let (one, two, three, five) = (set(1.0), set(2.0), set(3.0), set(5.0));
    let zero = _mm512_setzero_pd();
    let mut acc = [zero; 7];
    let mut j = 0;
    while j < n {
        let lanes: __mmask8 = if j + 8 <= n {
            0xFF
        } else {
            ((1u16 << (n - j)) - 1) as u8
        };
        // SAFETY: lanes past n are masked, so no load reads beyond the slices.
        let load = |v: &[f64]| _mm512_maskz_loadu_pd(lanes, v.as_ptr().add(j));
        let dx = _mm512_sub_pd(xi, load(&s.x));
        let dy = _mm512_sub_pd(yi, load(&s.y));
        let dz = _mm512_sub_pd(zi, load(&s.z));
        let (bx, by, bz) = (load(&s.mx), load(&s.my), load(&s.mz));
        let r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
        let live = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero) & lanes;
        // Dead lanes (self, past the end) compute with r² = 1 and are not added.
        let r2 = _mm512_mask_blend_pd(live, one, r2);
        let y = rsqrt(r2);
        let inv_r2 = _mm512_mul_pd(y, y);
        let inv_r3 = _mm512_mul_pd(k, _mm512_mul_pd(inv_r2, y));
        let c = _mm512_mul_pd(three, _mm512_mul_pd(inv_r3, inv_r2));
        let a_r = _mm512_fmadd_pd(ax, dx, _mm512_fmadd_pd(ay, dy, _mm512_mul_pd(az, dz)));
        let b_r = _mm512_fmadd_pd(bx, dx, _mm512_fmadd_pd(by, dy, _mm512_mul_pd(bz, dz)));
        let ab = _mm512_fmadd_pd(ax, bx, _mm512_fmadd_pd(ay, by, _mm512_mul_pd(az, bz)));
        // radial = c (a·b) − 5 c (a·r)(b·r)/r²
        let radial = _mm512_fmsub_pd(
            c,
            ab,
            _mm512_mul_pd(
                _mm512_mul_pd(five, c),
                _mm512_mul_pd(_mm512_mul_pd(a_r, b_r), inv_r2),
            ),
        );
        // LJ: 6·4ε s⁶ (2 s⁶ − 1)/r², s² = σ²/r², where r² < r_c².
        let s2 = _mm512_mul_pd(lj_s2, inv_r2);
        let s6 = _mm512_mul_pd(_mm512_mul_pd(s2, s2), s2);
        let lj_on = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(r2, lj_rc2);
        let lj = _mm512_maskz_mul_pd(
            lj_on,
            _mm512_mul_pd(lj6, _mm512_mul_pd(s6, _mm512_fmsub_pd(two, s6, one))),
            inv_r2,
        );
        let along = _mm512_add_pd(radial, lj);
        let gx = _mm512_fmadd_pd(
            dx,
            along,
            _mm512_mul_pd(c, _mm512_fmadd_pd(ax, b_r, _mm512_mul_pd(bx, a_r))),
        );
        let gy = _mm512_fmadd_pd(
            dy,
            along,
            _mm512_mul_pd(c, _mm512_fmadd_pd(ay, b_r, _mm512_mul_pd(by, a_r))),
        );
        let gz = _mm512_fmadd_pd(
            dz,
            along,
            _mm512_mul_pd(c, _mm512_fmadd_pd(az, b_r, _mm512_mul_pd(bz, a_r))),
        );
        // B_j = k (3 (m_j·r) r/r⁵ − m_j/r³); τ_i = m_i × B_j.
        let cb = _mm512_mul_pd(c, b_r);
        let bfx = _mm512_fmsub_pd(cb, dx, _mm512_mul_pd(inv_r3, bx));
        let bfy = _mm512_fmsub_pd(cb, dy, _mm512_mul_pd(inv_r3, by));
        let bfz = _mm512_fmsub_pd(cb, dz, _mm512_mul_pd(inv_r3, bz));
        let tx = _mm512_fmsub_pd(ay, bfz, _mm512_mul_pd(az, bfy));
        let ty = _mm512_fmsub_pd(az, bfx, _mm512_mul_pd(ax, bfz));
        let tz = _mm512_fmsub_pd(ax, bfy, _mm512_mul_pd(ay, bfx));
        let w = _mm512_fmadd_pd(gx, dx, _mm512_fmadd_pd(gy, dy, _mm512_mul_pd(gz, dz)));
        for (a, v) in acc.iter_mut().zip([gx, gy, gz, tx, ty, tz, w]) {
            *a = _mm512_mask_add_pd(*a, live, *a, v);
        }
        j += 8;
    }
    let sum = |q: usize| _mm512_reduce_add_pd(acc[q]);
    (
        DVec3::new(sum(0), sum(1), sum(2)),
        DVec3::new(sum(3), sum(4), sum(5)),
        sum(6),
    )
}
