//! AVX-512 row kernels of the dipole–dipole interaction (with the LJ/WCA
//! repulsion of the same loop), 8 partners per instruction: over all
//! particles ([`all_pairs_row`]) and over a ghost list's row
//! ([`list_row`]). Both go through one lane function, [`pair8`]: 1/r from
//! `vrsqrt14pd` refined by two Newton–Raphson steps (full double
//! precision), dead lanes (self pair, past the end, beyond the cut-offs)
//! masked out. The arithmetic is that of [`super::all_pairs_row`] and
//! [`super::Kernel::pair`] (tested against them to 1e-12).
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use glam::DVec3;
use mote_geom::simd::avx512::rsqrt;

use super::listed::RowSum;
use super::tiled::Reactions;
use super::{Kernel, Soa};
use crate::neighbor::avx512::{in_eights, load_copies};
use crate::neighbor::Copy4;

/// A kernel's constants, broadcast.
struct Lanes {
    k: __m512d,
    rf: __m512d,
    rc2: __m512d,
    lj_s2: __m512d,
    lj_rc2: __m512d,
    lj4e: __m512d,
    lj6: __m512d,
    lj_shift: __m512d,
}

impl Lanes {
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn of(kern: &Kernel) -> Self {
        let set = _mm512_set1_pd;
        Self {
            k: set(kern.k),
            rf: set(kern.rf),
            rc2: set(kern.rc2),
            lj_s2: set(kern.lj_s2),
            lj_rc2: set(kern.lj_rc2),
            lj4e: set(kern.lj4e),
            lj6: set(6.0 * kern.lj4e),
            lj_shift: set(kern.lj_shift),
        }
    }
}

type V3 = [__m512d; 3];

/// What [`pair8`] gives: [F_x, F_y, F_z, τ_x, τ_y, τ_z, r·F, U] on i, and
/// the two factors of the field of i at j, B_i = c (a·r) r − (k/r³ − rf) a.
struct Pair8 {
    on_i: [__m512d; 8],
    c_a_r: __m512d,
    field: __m512d,
}

/// Eight pairs at separations d = r_i − r_j (r² = |d|²) between moment
/// `a` (of i) and moments `b`: [F_x, F_y, F_z, τ_x, τ_y, τ_z, r·F, U] on
/// i, the dipolar terms (with the reaction field) in the lanes of `dip`,
/// the repulsion in those of `lj`, zero elsewhere. U only if `energy`.
///
/// F_i = c (a·b − 5 (a·r)(b·r)/r²) r + c ((b·r) a + (a·r) b) with
/// c = 3k/r⁵; τ_i = a × B', B' = c (b·r) r − (k/r³ − rf) b;
/// U = (k/r³ − rf) a·b − c (a·r)(b·r) (004 Eq. 8, Barker–Watts).
#[inline]
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
fn pair8(
    c: &Lanes,
    d: V3,
    r2: __m512d,
    a: V3,
    b: V3,
    dip: __mmask8,
    lj: __mmask8,
    energy: bool,
) -> Pair8 {
    let set = _mm512_set1_pd;
    let (one, two, three, five) = (set(1.0), set(2.0), set(3.0), set(5.0));
    let [dx, dy, dz] = d;
    let [ax, ay, az] = a;
    let [bx, by, bz] = b;
    // Lanes in neither range compute with r² = 1 and add nothing.
    let r2 = _mm512_mask_blend_pd(dip | lj, one, r2);
    let y = rsqrt(r2);
    let inv_r2 = _mm512_mul_pd(y, y);
    let inv_r3 = _mm512_maskz_mul_pd(dip, c.k, _mm512_mul_pd(inv_r2, y));
    let cc = _mm512_mul_pd(three, _mm512_mul_pd(inv_r3, inv_r2));
    let field = _mm512_maskz_sub_pd(dip, inv_r3, c.rf);
    let a_r = _mm512_fmadd_pd(ax, dx, _mm512_fmadd_pd(ay, dy, _mm512_mul_pd(az, dz)));
    let b_r = _mm512_fmadd_pd(bx, dx, _mm512_fmadd_pd(by, dy, _mm512_mul_pd(bz, dz)));
    let ab = _mm512_fmadd_pd(ax, bx, _mm512_fmadd_pd(ay, by, _mm512_mul_pd(az, bz)));
    let a_r_b_r = _mm512_mul_pd(a_r, b_r);
    let (ca, cb) = (_mm512_mul_pd(cc, a_r), _mm512_mul_pd(cc, b_r));
    // radial = c (a·b − 5 (a·r)(b·r)/r²)
    let radial = _mm512_mul_pd(
        cc,
        _mm512_fnmadd_pd(five, _mm512_mul_pd(a_r_b_r, inv_r2), ab),
    );
    // LJ: 6·4ε s⁶ (2 s⁶ − 1)/r², s² = σ²/r²; skipped where no lane is
    // within its reach (adding its zeros would change no bit).
    let s6 = || {
        let s2 = _mm512_mul_pd(c.lj_s2, inv_r2);
        _mm512_mul_pd(_mm512_mul_pd(s2, s2), s2)
    };
    let along = if lj != 0 {
        let s6 = s6();
        let lj_f = _mm512_maskz_mul_pd(
            lj,
            _mm512_mul_pd(c.lj6, _mm512_mul_pd(s6, _mm512_fmsub_pd(two, s6, one))),
            inv_r2,
        );
        _mm512_add_pd(radial, lj_f)
    } else {
        radial
    };
    // F_i = along r + c ((b·r) a + (a·r) b)
    let g = |d: __m512d, a: __m512d, b: __m512d| {
        _mm512_fmadd_pd(d, along, _mm512_fmadd_pd(a, cb, _mm512_mul_pd(b, ca)))
    };
    let (gx, gy, gz) = (g(dx, ax, bx), g(dy, ay, by), g(dz, az, bz));
    let bfx = _mm512_fmsub_pd(cb, dx, _mm512_mul_pd(field, bx));
    let bfy = _mm512_fmsub_pd(cb, dy, _mm512_mul_pd(field, by));
    let bfz = _mm512_fmsub_pd(cb, dz, _mm512_mul_pd(field, bz));
    let tx = _mm512_fmsub_pd(ay, bfz, _mm512_mul_pd(az, bfy));
    let ty = _mm512_fmsub_pd(az, bfx, _mm512_mul_pd(ax, bfz));
    let tz = _mm512_fmsub_pd(ax, bfy, _mm512_mul_pd(ay, bfx));
    let w = _mm512_fmadd_pd(gx, dx, _mm512_fmadd_pd(gy, dy, _mm512_mul_pd(gz, dz)));
    let u = if energy {
        let dip_u = _mm512_fmsub_pd(field, ab, _mm512_mul_pd(cc, a_r_b_r));
        if lj != 0 {
            let s6 = s6();
            let lj_u = _mm512_fmsub_pd(_mm512_fmsub_pd(c.lj4e, s6, c.lj4e), s6, c.lj_shift);
            _mm512_mask_add_pd(dip_u, lj, dip_u, lj_u)
        } else {
            dip_u
        }
    } else {
        _mm512_setzero_pd()
    };
    Pair8 {
        on_i: [gx, gy, gz, tx, ty, tz, w, u],
        c_a_r: ca,
        field,
    }
}

/// The eight sums as a row's totals.
#[inline]
#[target_feature(enable = "avx512f")]
fn totals(acc: &[__m512d; 8]) -> RowSum {
    let sum = |q: usize| _mm512_reduce_add_pd(acc[q]);
    RowSum {
        force: DVec3::new(sum(0), sum(1), sum(2)),
        torque: DVec3::new(sum(3), sum(4), sum(5)),
        virial: sum(6),
        energy: sum(7),
    }
}

/// Force and torque on particle i from the first n others, and its share
/// of the virial; see [`super::all_pairs_row`].
///
/// # Safety
/// The CPU must support AVX-512F; the arrays of `s` must hold at least n values.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn all_pairs_row(
    kern: &Kernel,
    s: &Soa,
    i: usize,
    n: usize,
) -> (DVec3, DVec3, f64) {
    debug_assert!([&s.x, &s.y, &s.z, &s.mx, &s.my, &s.mz]
        .iter()
        .all(|v| v.len() >= n));
    let c = Lanes::of(kern);
    let set = _mm512_set1_pd;
    let (xi, yi, zi) = (set(s.x[i]), set(s.y[i]), set(s.z[i]));
    let a = [set(s.mx[i]), set(s.my[i]), set(s.mz[i])];
    let zero = _mm512_setzero_pd();
    let mut acc = [zero; 8];
    let mut j = 0;
    while j < n {
        let lanes: __mmask8 = if j + 8 <= n {
            0xFF
        } else {
            ((1u16 << (n - j)) - 1) as u8
        };
        // SAFETY: lanes past n are masked, so no load reads beyond the slices.
        let load = |v: &[f64]| unsafe { _mm512_maskz_loadu_pd(lanes, v.as_ptr().add(j)) };
        let dx = _mm512_sub_pd(xi, load(&s.x));
        let dy = _mm512_sub_pd(yi, load(&s.y));
        let dz = _mm512_sub_pd(zi, load(&s.z));
        let b = [load(&s.mx), load(&s.my), load(&s.mz)];
        let r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
        let live = _mm512_mask_cmp_pd_mask::<_CMP_GT_OQ>(lanes, r2, zero);
        let lj = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(live, r2, c.lj_rc2);
        let v = pair8(&c, [dx, dy, dz], r2, a, b, live, lj, false).on_i;
        for (a, v) in acc.iter_mut().zip(v) {
            *a = _mm512_add_pd(*a, v);
        }
        j += 8;
    }
    let t = totals(&acc);
    (t.force, t.torque, t.virial)
}

/// The sums of a ghost list's row of copy `k` (see
/// [`super::listed::row_portable`]): neighbours' positions and moments
/// loaded as records and transposed, dipolar lanes within r_c, repulsive
/// ones within the repulsion's cut-off.
///
/// # Safety
/// The CPU must have AVX-512F; `k` and every entry of `row` must index
/// `position` and `moment`.
#[target_feature(enable = "avx512f")]
pub(super) unsafe fn list_row(
    kern: &Kernel,
    k: usize,
    row: &[u32],
    position: &[Copy4],
    moment: &[Copy4],
    energy: bool,
) -> RowSum {
    debug_assert_eq!(position.len(), moment.len());
    let c = Lanes::of(kern);
    let set = _mm512_set1_pd;
    let [xi, yi, zi, _] = position[k].0;
    let (xi, yi, zi) = (set(xi), set(yi), set(zi));
    let [ax, ay, az, _] = moment[k].0;
    let a = [set(ax), set(ay), set(az)];
    let mut acc = [_mm512_setzero_pd(); 8];
    let lanes = |index: &[u32; 8], valid: __mmask8| {
        // SAFETY: the caller guarantees every index is in bounds of both.
        let ((xj, yj, zj), (bx, by, bz)) =
            unsafe { (load_copies(position, index), load_copies(moment, index)) };
        let (dx, dy, dz) = (
            _mm512_sub_pd(xi, xj),
            _mm512_sub_pd(yi, yj),
            _mm512_sub_pd(zi, zj),
        );
        let r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
        let dip = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(valid, r2, c.rc2);
        let lj = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(valid, r2, c.lj_rc2);
        let v = pair8(&c, [dx, dy, dz], r2, a, [bx, by, bz], dip, lj, energy).on_i;
        for (a, v) in acc.iter_mut().zip(v) {
            *a = _mm512_add_pd(*a, v);
        }
    };
    in_eights(row, k as u32, lanes);
    totals(&acc)
}

/// Rows i₀, i₀ + 1, …, i₀ + R − 1 of a tile of the all-pairs sum (see
/// `tiled.rs`): row i₀ + q takes the pairs (i, j) for j in
/// `j_start[q]..j_end` and j < n, eight at a time, and the R rows share
/// each block's loads and its reaction updates (row 0's, then row 1's, …:
/// the order of R single rows). Returns the force, torque and virial on
/// each i and adds the reactions −F and τ_j = m_j × B_i to `r` at j − base.
/// Dead lanes (below a row's start, past n) add exact zeros.
///
/// # Safety
/// The CPU must have AVX-512F; the arrays of `s` must hold at least
/// `j_end` values, `j_end` a multiple of 8; i₀ ≥ base, j_start[q] > i₀ + q
/// and j_start[q] ≥ j_start[0]; the reaction arrays must cover
/// `base..j_end`.
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn reacting_rows<const R: usize>(
    kern: &Kernel,
    s: &Soa,
    i0: usize,
    j_start: [usize; R],
    j_end: usize,
    n: usize,
    base: usize,
    r: &mut Reactions,
) -> [(DVec3, DVec3, f64); R] {
    debug_assert!(j_end.is_multiple_of(8) && i0 >= base);
    debug_assert!((0..R).all(|q| j_start[q] > i0 + q && j_start[q] >= j_start[0]));
    debug_assert!([&s.x, &s.y, &s.z, &s.mx, &s.my, &s.mz]
        .iter()
        .all(|v| v.len() >= j_end));
    debug_assert!(r.tz.len() >= j_end - base);
    let c = Lanes::of(kern);
    let set = _mm512_set1_pd;
    let zero = _mm512_setzero_pd();
    let ri: [V3; R] =
        std::array::from_fn(|q| [set(s.x[i0 + q]), set(s.y[i0 + q]), set(s.z[i0 + q])]);
    let a: [V3; R] =
        std::array::from_fn(|q| [set(s.mx[i0 + q]), set(s.my[i0 + q]), set(s.mz[i0 + q])]);
    let mut acc = [[zero; 7]; R];
    let mut j = j_start[0] & !7;
    let reactions = [
        r.fx.as_mut_ptr(),
        r.fy.as_mut_ptr(),
        r.fz.as_mut_ptr(),
        r.tx.as_mut_ptr(),
        r.ty.as_mut_ptr(),
        r.tz.as_mut_ptr(),
    ];
    while j < j_end {
        let tail: __mmask8 = if j + 8 > n {
            ((1u16 << (n - j).min(8)) - 1) as u8
        } else {
            0xFF
        };
        // SAFETY: j + 8 ≤ j_end ≤ every array's length.
        let load = |v: &[f64]| unsafe { _mm512_loadu_pd(v.as_ptr().add(j)) };
        let rj = [load(&s.x), load(&s.y), load(&s.z)];
        let b = [load(&s.mx), load(&s.my), load(&s.mz)];
        let [bx, by, bz] = b;
        let k = j - base;
        for q in 0..R {
            let lanes = if j_start[q] > j {
                tail & (0xFFu8.checked_shl((j_start[q] - j) as u32).unwrap_or(0))
            } else {
                tail
            };
            let dx = _mm512_sub_pd(ri[q][0], rj[0]);
            let dy = _mm512_sub_pd(ri[q][1], rj[1]);
            let dz = _mm512_sub_pd(ri[q][2], rj[2]);
            let r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
            let live = _mm512_mask_cmp_pd_mask::<_CMP_GT_OQ>(lanes, r2, zero);
            let lj = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(live, r2, c.lj_rc2);
            let p = pair8(&c, [dx, dy, dz], r2, a[q], b, live, lj, false);
            for (a, v) in acc[q].iter_mut().zip(p.on_i) {
                *a = _mm512_add_pd(*a, v);
            }
            // B_i = c (a·r) r − field a; τ_j = b × B_i.
            let field_i =
                |d: __m512d, a: __m512d| _mm512_fmsub_pd(p.c_a_r, d, _mm512_mul_pd(p.field, a));
            let (fx, fy, fz) = (
                field_i(dx, a[q][0]),
                field_i(dy, a[q][1]),
                field_i(dz, a[q][2]),
            );
            let tj = [
                _mm512_fmsub_pd(by, fz, _mm512_mul_pd(bz, fy)),
                _mm512_fmsub_pd(bz, fx, _mm512_mul_pd(bx, fz)),
                _mm512_fmsub_pd(bx, fy, _mm512_mul_pd(by, fx)),
            ];
            for c in 0..3 {
                // SAFETY: k + 8 ≤ j_end − base ≤ the reaction arrays' length.
                unsafe {
                    let pf = reactions[c].add(k);
                    _mm512_storeu_pd(pf, _mm512_sub_pd(_mm512_loadu_pd(pf), p.on_i[c]));
                    let pt = reactions[3 + c].add(k);
                    _mm512_storeu_pd(pt, _mm512_add_pd(_mm512_loadu_pd(pt), tj[c]));
                }
            }
        }
        j += 8;
    }
    std::array::from_fn(|q| {
        let sum = |c: usize| _mm512_reduce_add_pd(acc[q][c]);
        (
            DVec3::new(sum(0), sum(1), sum(2)),
            DVec3::new(sum(3), sum(4), sum(5)),
            sum(6),
        )
    })
}
