//! AVX-512 versions of the list kernels of [`super::barnes_hut`]: one block
//! of 8 sources per instruction, 1/√r² from `vrsqrt14pd` refined by two
//! Newton–Raphson steps y ← y (3/2 − (r²/2) y²) (14 → 28 → 56 bits), as in
//! the direct-summation kernel. Same sums, same order, as the portable
//! kernels; they differ from them only by the rounding of 1/√r².
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use glam::DVec3;
use mote_geom::simd::avx512::rsqrt;

use super::barnes_hut::{CellBlock, Lanes, ParticleBlock, LANES};

#[inline]
#[target_feature(enable = "avx512f")]
fn load(a: &[f64; LANES]) -> __m512d {
    // SAFETY: `a` holds exactly 8 f64; unaligned load.
    unsafe { _mm512_loadu_pd(a.as_ptr()) }
}

#[inline]
#[target_feature(enable = "avx512f")]
fn store(v: __m512d) -> [f64; LANES] {
    let mut a = [0.0; LANES];
    // SAFETY: `a` has room for exactly 8 f64; unaligned store.
    unsafe { _mm512_storeu_pd(a.as_mut_ptr(), v) };
    a
}

/// See `barnes_hut::particles`.
#[target_feature(enable = "avx512f")]
pub(super) fn particles<const POT: bool>(
    x: DVec3,
    id: f64,
    list: &[ParticleBlock],
    eps2: f64,
) -> Lanes {
    let (xi, yi, zi) = (
        _mm512_set1_pd(x.x),
        _mm512_set1_pd(x.y),
        _mm512_set1_pd(x.z),
    );
    let vid = _mm512_set1_pd(id);
    let veps2 = _mm512_set1_pd(eps2);
    let zero = _mm512_setzero_pd();
    let one = _mm512_set1_pd(1.0);
    let (mut ax, mut ay, mut az, mut ap) = (zero, zero, zero, zero);
    for b in list {
        let dx = _mm512_sub_pd(load(&b.x), xi);
        let dy = _mm512_sub_pd(load(&b.y), yi);
        let dz = _mm512_sub_pd(load(&b.z), zi);
        let r2 = _mm512_fmadd_pd(
            dx,
            dx,
            _mm512_fmadd_pd(dy, dy, _mm512_fmadd_pd(dz, dz, veps2)),
        );
        // Keep lanes that are another particle at r² > 0.
        let keep = _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(load(&b.id), vid)
            & _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, zero);
        let w = _mm512_maskz_mov_pd(keep, load(&b.s));
        let r2 = _mm512_mask_mov_pd(one, keep, r2);
        let inv = rsqrt(r2);
        let winv = _mm512_mul_pd(w, inv);
        let winv3 = _mm512_mul_pd(winv, _mm512_mul_pd(inv, inv));
        ax = _mm512_fmadd_pd(winv3, dx, ax);
        ay = _mm512_fmadd_pd(winv3, dy, ay);
        az = _mm512_fmadd_pd(winv3, dz, az);
        if POT {
            ap = _mm512_add_pd(ap, winv);
        }
    }
    (store(ap), store(ax), store(ay), store(az))
}

/// See `barnes_hut::cells`.
#[target_feature(enable = "avx512f")]
pub(super) fn cells<const POT: bool, const DIP: bool>(
    x: DVec3,
    list: &[CellBlock],
    eps2: f64,
) -> Lanes {
    let (xi, yi, zi) = (
        _mm512_set1_pd(x.x),
        _mm512_set1_pd(x.y),
        _mm512_set1_pd(x.z),
    );
    let veps2 = _mm512_set1_pd(eps2);
    let zero = _mm512_setzero_pd();
    let (three, two_half, half) = (
        _mm512_set1_pd(3.0),
        _mm512_set1_pd(2.5),
        _mm512_set1_pd(0.5),
    );
    let (mut ax, mut ay, mut az, mut ap) = (zero, zero, zero, zero);
    for b in list {
        let c = &b.c;
        let rx = _mm512_sub_pd(xi, load(&c[0]));
        let ry = _mm512_sub_pd(yi, load(&c[1]));
        let rz = _mm512_sub_pd(zi, load(&c[2]));
        let m = load(&c[3]);
        let r2 = _mm512_fmadd_pd(
            rx,
            rx,
            _mm512_fmadd_pd(ry, ry, _mm512_fmadd_pd(rz, rz, veps2)),
        );
        let inv = rsqrt(r2);
        let inv2 = _mm512_mul_pd(inv, inv);
        let inv3 = _mm512_mul_pd(inv, inv2);
        let inv5 = _mm512_mul_pd(inv3, inv2);
        let (qxx, qyy, qzz) = (load(&c[7]), load(&c[8]), load(&c[9]));
        let (qxy, qxz, qyz) = (load(&c[10]), load(&c[11]), load(&c[12]));
        let qx = _mm512_fmadd_pd(qxx, rx, _mm512_fmadd_pd(qxy, ry, _mm512_mul_pd(qxz, rz)));
        let qy = _mm512_fmadd_pd(qxy, rx, _mm512_fmadd_pd(qyy, ry, _mm512_mul_pd(qyz, rz)));
        let qz = _mm512_fmadd_pd(qxz, rx, _mm512_fmadd_pd(qyz, ry, _mm512_mul_pd(qzz, rz)));
        let rqr = _mm512_fmadd_pd(rx, qx, _mm512_fmadd_pd(ry, qy, _mm512_mul_pd(rz, qz)));
        // radial = M/r³ [+ 3 p·R/r⁵] + (5/2) RᵀQR/r⁷
        let mut radial = _mm512_fmadd_pd(
            m,
            inv3,
            _mm512_mul_pd(_mm512_mul_pd(two_half, rqr), _mm512_mul_pd(inv5, inv2)),
        );
        let (mut gx, mut gy, mut gz) = (
            _mm512_mul_pd(qx, inv5),
            _mm512_mul_pd(qy, inv5),
            _mm512_mul_pd(qz, inv5),
        );
        let mut pr = zero;
        if DIP {
            let (px, py, pz) = (load(&c[4]), load(&c[5]), load(&c[6]));
            pr = _mm512_fmadd_pd(px, rx, _mm512_fmadd_pd(py, ry, _mm512_mul_pd(pz, rz)));
            radial = _mm512_fmadd_pd(_mm512_mul_pd(three, pr), inv5, radial);
            gx = _mm512_fmadd_pd(px, inv3, gx);
            gy = _mm512_fmadd_pd(py, inv3, gy);
            gz = _mm512_fmadd_pd(pz, inv3, gz);
        }
        ax = _mm512_add_pd(ax, _mm512_fnmadd_pd(rx, radial, gx));
        ay = _mm512_add_pd(ay, _mm512_fnmadd_pd(ry, radial, gy));
        az = _mm512_add_pd(az, _mm512_fnmadd_pd(rz, radial, gz));
        if POT {
            // M/r [+ p·R/r³] + ½ RᵀQR/r⁵
            let mut p = _mm512_fmadd_pd(m, inv, _mm512_mul_pd(_mm512_mul_pd(half, rqr), inv5));
            if DIP {
                p = _mm512_fmadd_pd(pr, inv3, p);
            }
            ap = _mm512_add_pd(ap, p);
        }
    }
    (store(ap), store(ax), store(ay), store(az))
}
