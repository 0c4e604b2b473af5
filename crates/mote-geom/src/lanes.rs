//! `Lanes`: eight f64 lanes whose every operation is one straight loop
//! over the lanes, so that the compiler turns it into the vector
//! instructions of the build's target (two AVX2 instructions per
//! operation on x86-64-v3, one with AVX-512, four NEON on aarch64). A
//! kernel written on `Lanes` is written once for every CPU; masks are
//! selects ([`Lanes::select_below`]), never branches, so the loops stay
//! straight. Sums over the lanes go in a fixed order ([`Lanes::sum`]), so
//! a kernel's bits do not depend on the CPU's vector width.
//!
//! [`Four`] is the same for four lanes — one AVX2 register, where a kernel
//! holding 3 × 3 matrices of eight lanes would spill out of AVX2's sixteen
//! — and [`Lane`] is what a kernel generic over its width asks of either.

use std::ops::{Add, Div, Mul, Sub};

/// The number of lanes.
pub const LANES: usize = 8;

/// Eight f64 values operated on together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lanes(pub [f64; LANES]);

impl Lanes {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Lanes([x; LANES])
    }

    /// `f` of every lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Lanes(self.0.map(f))
    }

    /// `f` of every pair of lanes.
    #[inline(always)]
    pub fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut out = [0.0; LANES];
        // An indexed loop over the fixed lanes is what the vectoriser
        // takes best (`from_fn` and zipped iterators were left scalar).
        #[allow(clippy::needless_range_loop)]
        for l in 0..LANES {
            out[l] = f(self.0[l], other.0[l]);
        }
        Lanes(out)
    }

    /// `yes` where `self < bound`, else `no`, lane by lane.
    #[inline(always)]
    pub fn select_below(self, bound: f64, yes: f64, no: f64) -> Self {
        self.map(|x| if x < bound { yes } else { no })
    }

    /// `yes` where 0 < `self` < `bound`, else `no`, lane by lane (an
    /// empty lane, at no distance, is outside every cut-off).
    #[inline(always)]
    pub fn select_within(self, bound: f64, yes: f64, no: f64) -> Self {
        // `&`, not `&&`: both compares in every lane, no branch.
        self.map(|x| if (x > 0.0) & (x < bound) { yes } else { no })
    }

    /// 1/x where x > 0, else 0 (a lane of a pair at no distance, or an
    /// empty lane, then adds nothing), lane by lane.
    #[inline(always)]
    pub fn recip_or_zero(self) -> Self {
        self.map(|x| if x > 0.0 { 1.0 / x } else { 0.0 })
    }

    /// √x, lane by lane.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }

    /// The lanes added in order 0, 1, …, 7.
    #[inline(always)]
    pub fn sum(self) -> f64 {
        self.0.iter().fold(0.0, |acc, x| acc + x)
    }

    /// `out[start + l] += lane l` for l < `live` (≤ 8): with all eight
    /// live, one vector load, add and store, where a loop over the live
    /// lanes would check each index.
    #[inline(always)]
    pub fn add_to(self, out: &mut [f64], start: usize, live: usize) {
        self.update(out, start, live, |o, x| o + x);
    }

    /// `out[start + l] -= lane l` for l < `live` (≤ 8), as [`Lanes::add_to`].
    #[inline(always)]
    pub fn subtract_from(self, out: &mut [f64], start: usize, live: usize) {
        self.update(out, start, live, |o, x| o - x);
    }

    #[inline(always)]
    fn update(self, out: &mut [f64], start: usize, live: usize, f: impl Fn(f64, f64) -> f64) {
        if live == LANES {
            let o: &mut [f64; LANES] = (&mut out[start..start + LANES]).try_into().unwrap();
            *o = Lanes(*o).zip(self, f).0;
        } else {
            for (o, &x) in out[start..start + live].iter_mut().zip(&self.0) {
                *o = f(*o, x);
            }
        }
    }

    /// Lanes `start..start + live` of `v` (`live` ≤ 8), zeros after.
    #[inline(always)]
    pub fn load(v: &[f64], start: usize, live: usize) -> Self {
        if live == LANES {
            // The common case: eight in a row, no zeroing.
            let full: &[f64; LANES] = v[start..start + LANES].try_into().unwrap();
            return Lanes(*full);
        }
        let mut x = [0.0; LANES];
        x[..live].copy_from_slice(&v[start..start + live]);
        Lanes(x)
    }
}

/// Four f64 values operated on together: one AVX2 register.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Four(pub [f64; 4]);

impl Four {
    /// `f` of every pair of lanes.
    #[inline(always)]
    pub fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut out = [0.0; 4];
        // An indexed loop, as `Lanes::zip` (`from_fn` was left in halves).
        #[allow(clippy::needless_range_loop)]
        for l in 0..4 {
            out[l] = f(self.0[l], other.0[l]);
        }
        Four(out)
    }
}

macro_rules! lane_op {
    ($lanes:ident, $trait:ident, $method:ident, $op:tt) => {
        impl $trait for $lanes {
            type Output = $lanes;
            #[inline(always)]
            fn $method(self, o: $lanes) -> $lanes {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $trait<f64> for $lanes {
            type Output = $lanes;
            #[inline(always)]
            fn $method(self, o: f64) -> $lanes {
                $lanes(self.0.map(|a| a $op o))
            }
        }
    };
}
lane_op!(Lanes, Add, add, +);
lane_op!(Lanes, Sub, sub, -);
lane_op!(Lanes, Mul, mul, *);
lane_op!(Lanes, Div, div, /);
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
mod four_ops {
    use super::*;
    lane_op!(Four, Add, add, +);
    lane_op!(Four, Sub, sub, -);
    lane_op!(Four, Mul, mul, *);
    lane_op!(Four, Div, div, /);
}

/// `Four`'s arithmetic as one AVX instruction each: left to the
/// vectoriser, the lanes of the rigid free step went two at a time (SSE
/// halves and shuffles between them). The same IEEE operations lane by
/// lane, so the same bits.
#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
#[allow(unsafe_code)]
mod four_ops {
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_div_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_sqrt_pd,
        _mm256_sub_pd,
    };

    use super::*;

    #[inline(always)]
    fn wide(a: Four) -> __m256d {
        // SAFETY: [f64; 4] and __m256d are 32 bytes of four f64.
        unsafe { std::mem::transmute::<[f64; 4], __m256d>(a.0) }
    }

    #[inline(always)]
    fn four(a: __m256d) -> Four {
        // SAFETY: as `wide`.
        Four(unsafe { std::mem::transmute::<__m256d, [f64; 4]>(a) })
    }

    macro_rules! four_op {
        ($trait:ident, $method:ident, $intrinsic:ident) => {
            impl $trait for Four {
                type Output = Four;
                #[inline(always)]
                fn $method(self, o: Four) -> Four {
                    // SAFETY: the build's target has AVX (cfg above).
                    four(unsafe { $intrinsic(wide(self), wide(o)) })
                }
            }
            impl $trait<f64> for Four {
                type Output = Four;
                #[inline(always)]
                fn $method(self, o: f64) -> Four {
                    // SAFETY: as above.
                    four(unsafe { $intrinsic(wide(self), _mm256_set1_pd(o)) })
                }
            }
        };
    }
    four_op!(Add, add, _mm256_add_pd);
    four_op!(Sub, sub, _mm256_sub_pd);
    four_op!(Mul, mul, _mm256_mul_pd);
    four_op!(Div, div, _mm256_div_pd);

    impl Four {
        /// √x, lane by lane.
        #[inline(always)]
        pub(super) fn sqrt_lanes(self) -> Four {
            // SAFETY: as above.
            four(unsafe { _mm256_sqrt_pd(wide(self)) })
        }
    }
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
impl Four {
    /// √x, lane by lane.
    #[inline(always)]
    fn sqrt_lanes(self) -> Four {
        self.map(f64::sqrt)
    }
}

/// What a kernel generic over its width asks of its lanes ([`Lanes`] or
/// [`Four`]): the arithmetic, lane by lane, and these.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// The number of lanes.
    const N: usize;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// Lane l `f(l)`.
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    /// Lane l.
    fn lane(self, l: usize) -> f64;
    /// `f` of every lane.
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// √x, lane by lane.
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
    /// Lane l where lane l of `gate` is > 0, else 0 (a lane of a pair at
    /// no distance, or an empty lane, then adds nothing).
    fn where_positive(self, gate: Self) -> Self;
    /// Lane l of `yes` where lane l of `self` is greater than lane l of
    /// `bound`, else lane l of `no` (a NaN lane takes `no`): the lane form
    /// of `if a > b { yes } else { no }`, a blend, never a branch.
    fn select_above(self, bound: Self, yes: Self, no: Self) -> Self;
    /// The larger of each lane and `x` (`f64::max` lane by lane).
    #[inline(always)]
    fn max(self, x: f64) -> Self {
        self.map(|a| a.max(x))
    }
    /// 1/√x, lane by lane, by multiplications alone ([`rsqrt`] of each
    /// lane, all in one straight loop where every lane is a positive
    /// normal number; exactly 1/√x of each lane otherwise).
    fn rsqrt(self) -> Self;
    /// Bit l set where lane l is below `bound` (a NaN lane is not).
    #[inline(always)]
    fn bits_below(self, bound: f64) -> u8 {
        let mut bits = 0u8;
        for l in 0..Self::N {
            bits |= u8::from(self.lane(l) < bound) << l;
        }
        bits
    }
}

macro_rules! lane_width {
    ($lanes:ident, $n:expr, $sqrt:path) => {
        impl Lane for $lanes {
            const N: usize = $n;
            #[inline(always)]
            fn splat(x: f64) -> Self {
                $lanes([x; $n])
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
                $lanes(std::array::from_fn(f))
            }
            #[inline(always)]
            fn lane(self, l: usize) -> f64 {
                self.0[l]
            }
            #[inline(always)]
            fn map(self, f: impl Fn(f64) -> f64) -> Self {
                $lanes(self.0.map(f))
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline(always)]
            fn where_positive(self, gate: Self) -> Self {
                self.zip(gate, |x, g| if g > 0.0 { x } else { 0.0 })
            }
            #[inline(always)]
            fn select_above(self, bound: Self, yes: Self, no: Self) -> Self {
                let mut out = no.0;
                // An indexed loop over the fixed lanes, as `zip`: a blend.
                #[allow(clippy::needless_range_loop)]
                for l in 0..$n {
                    if self.0[l] > bound.0[l] {
                        out[l] = yes.0[l];
                    }
                }
                $lanes(out)
            }
            #[inline(always)]
            fn rsqrt(self) -> Self {
                #[cfg(all(
                    target_arch = "x86_64",
                    target_feature = "avx2",
                    target_feature = "fma"
                ))]
                {
                    let mut y = self.0;
                    if rsqrt_avx2::<{ $n / 4 }>(&mut y) {
                        return $lanes(y);
                    }
                }
                #[cfg(not(all(
                    target_arch = "x86_64",
                    target_feature = "avx2",
                    target_feature = "fma"
                )))]
                if let Some(y) = rsqrt_portable(self) {
                    return y;
                }
                self.map(|x| 1.0 / x.sqrt())
            }
        }
    };
}

/// [`Lane::rsqrt`] of `Q` groups of four lanes in place, in AVX2 + FMA
/// registers, where every lane is a positive normal number (true); else
/// `x` is left as it was (false). The Newton–Raphson step is
/// y ← y + y (1/2 − (h y) y), h = x/2: three fused operations, the small
/// correction last, so the step's own rounding stays in the last place.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
))]
#[inline(always)]
#[allow(unsafe_code)]
fn rsqrt_avx2<const Q: usize>(x: &mut [f64]) -> bool {
    use std::arch::x86_64::*;
    assert!(x.len() >= 4 * Q);
    // SAFETY: every load and store is of four f64 within x (checked above).
    unsafe {
        let v: [__m256d; Q] = std::array::from_fn(|q| _mm256_loadu_pd(x.as_ptr().add(4 * q)));
        let (lo, hi) = (_mm256_set1_pd(f64::MIN_POSITIVE), _mm256_set1_pd(f64::MAX));
        let mut normal = 0xf;
        for x in v {
            let inside = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(x, lo),
                _mm256_cmp_pd::<_CMP_LE_OQ>(x, hi),
            );
            normal &= _mm256_movemask_pd(inside);
        }
        if normal != 0xf {
            return false;
        }
        let (half, magic) = (_mm256_set1_pd(0.5), _mm256_set1_epi64x(RSQRT_MAGIC as i64));
        for (q, x4) in v.into_iter().enumerate() {
            let h = _mm256_mul_pd(half, x4);
            let mut y = _mm256_castsi256_pd(_mm256_sub_epi64(
                magic,
                _mm256_srli_epi64::<1>(_mm256_castpd_si256(x4)),
            ));
            for _ in 0..RSQRT_STEPS {
                let half_error = _mm256_fnmadd_pd(_mm256_mul_pd(h, y), y, half);
                y = _mm256_fmadd_pd(y, half_error, y);
            }
            _mm256_storeu_pd(x.as_mut_ptr().add(4 * q), y);
        }
        true
    }
}

/// Lomont's constant for doubles (C. Lomont 2003, "Fast inverse square
/// root"): with it, [`rsqrt_estimate`] is within 3.4 % of 1/√x for every
/// normal x.
const RSQRT_MAGIC: u64 = 0x5fe6_eb50_c7b5_37a9;

/// Newton–Raphson steps after [`rsqrt_estimate`]: a relative error e
/// becomes 3e²/2 (+ e³/2), so 3.4·10⁻² → 1.8·10⁻³ → 4.6·10⁻⁶ → 3.2·10⁻¹¹
/// → 1.5·10⁻²¹, below the last place of an f64.
const RSQRT_STEPS: usize = 4;

/// [`Lane::rsqrt`] in plain lane arithmetic (the fallback where the
/// build lacks AVX2 + FMA; separate multiply and add), or None where a
/// lane is not a positive normal number.
#[cfg_attr(
    all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ),
    allow(dead_code)
)]
#[inline(always)]
fn rsqrt_portable<L: Lane>(x: L) -> Option<L> {
    let mut normal = true;
    for l in 0..L::N {
        let x = x.lane(l);
        normal &= (f64::MIN_POSITIVE..=f64::MAX).contains(&x);
    }
    if !normal {
        return None;
    }
    let h = x * 0.5;
    let mut y = x.map(rsqrt_estimate);
    for _ in 0..RSQRT_STEPS {
        let half_error = L::splat(0.5) - h * y * y;
        y = y + y * half_error;
    }
    Some(y)
}

/// 1/√x to 3.4 % for a positive normal x: halving the exponent (and
/// mantissa) by one shift of the bits, subtracted from [`RSQRT_MAGIC`].
#[cfg_attr(
    all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma"
    ),
    allow(dead_code)
)]
#[inline(always)]
fn rsqrt_estimate(x: f64) -> f64 {
    f64::from_bits(RSQRT_MAGIC - (x.to_bits() >> 1))
}

/// 1/√x of one number as [`Lane::rsqrt`] computes each lane: a 3.4 %
/// estimate from the bits refined by four Newton–Raphson steps, within two
/// units in the last place of `1.0 / x.sqrt()` for every
/// positive normal x, without a square root or a division (the AVX-512
/// kernels' `vrsqrt14pd` and two steps do the same; AVX2 has no double
/// estimate). Other x: exactly 1/√x.
pub fn rsqrt(x: f64) -> f64 {
    Four::splat(x).rsqrt().0[0]
}
lane_width!(Lanes, LANES, Lanes::sqrt);
lane_width!(Four, 4, Four::sqrt_lanes);

impl Lanes {
    /// Bit l set where lane l is below `bound` (a NaN lane is not).
    #[inline(always)]
    pub fn bits_below(self, bound: f64) -> u8 {
        let mut bits = 0u8;
        #[allow(clippy::needless_range_loop)]
        for l in 0..LANES {
            bits |= u8::from(self.0[l] < bound) << l;
        }
        bits
    }
}

/// Writes `first + l` for every bit l set in `bits`, in increasing l, to
/// the front of `out` and returns how many: the left-pack that turns a
/// lane mask into list entries. `out` must have room for eight (it may be
/// written past the count). With AVX2 it is one table-driven permute and
/// one store.
#[inline(always)]
pub fn pack_indices(bits: u8, first: u32, out: &mut [u32]) -> usize {
    let out: &mut [u32; LANES] = (&mut out[..LANES]).try_into().expect("eight");
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        use std::arch::x86_64::*;
        let order = &PACK_ORDER[bits as usize];
        // SAFETY: both pointers are to eight u32; unaligned access is used.
        #[allow(unsafe_code)]
        unsafe {
            let index = _mm256_add_epi32(
                _mm256_set1_epi32(first as i32),
                _mm256_loadu_si256(order.as_ptr().cast()),
            );
            _mm256_storeu_si256(out.as_mut_ptr().cast(), index);
        }
        bits.count_ones() as usize
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    pack_indices_scalar(bits, first, out)
}

/// [`pack_indices`] without vector instructions: the build's fallback,
/// and the reference the AVX2 path is tested against.
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx2"), allow(dead_code))]
#[inline(always)]
fn pack_indices_scalar(bits: u8, first: u32, out: &mut [u32; LANES]) -> usize {
    let mut k = 0;
    for l in 0..LANES as u32 {
        out[k] = first + l;
        k += usize::from(bits >> l & 1 == 1);
    }
    k
}

/// For each mask, the set lanes in increasing order (then zeros).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
static PACK_ORDER: [[u32; LANES]; 256] = pack_order();

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
const fn pack_order() -> [[u32; LANES]; 256] {
    let mut table = [[0u32; LANES]; 256];
    let mut bits = 0;
    while bits < 256 {
        let (mut l, mut k) = (0, 0);
        while l < LANES {
            if bits >> l & 1 == 1 {
                table[bits][k] = l as u32;
                k += 1;
            }
            l += 1;
        }
        bits += 1;
    }
    table
}

/// Calls `lanes(index, pad)` on a list row eight entries at a time: full
/// groups with `pad` zero in every lane, then the rest filled with `fill`
/// (an index the kernel may load, such as the row's own) and `pad` +∞ in
/// the filled lanes, which a kernel adds to their r² to put them beyond
/// every cut-off.
#[inline(always)]
pub fn in_eights(row: &[u32], fill: u32, mut lanes: impl FnMut(&[u32; LANES], Lanes)) {
    let chunks = row.chunks_exact(LANES);
    let tail = chunks.remainder();
    for chunk in chunks {
        lanes(chunk.try_into().expect("eight"), Lanes::splat(0.0));
    }
    if !tail.is_empty() {
        let mut index = [fill; LANES];
        index[..tail.len()].copy_from_slice(tail);
        let mut pad = [f64::INFINITY; LANES];
        pad[..tail.len()].fill(0.0);
        lanes(&index, Lanes(pad));
    }
}

/// Coordinates of eight records gathered into lanes: `[x, y, z]` with
/// record `index[m]` in lane m. Records are four f64 (x, y, z, pad), the
/// layout neighbour lists keep their copies in. With AVX2 (the build's
/// x86-64-v3) each four records are loaded as 128-bit halves and
/// transposed by in-lane unpacks — eight loads and three shuffles, where
/// a per-lane gather costs a load and an insert per coordinate.
#[inline(always)]
pub fn gather_xyz(records: &[[f64; 4]], index: &[u32; LANES]) -> [Lanes; 3] {
    for &i in index {
        assert!(
            (i as usize) < records.len(),
            "record {i} of {}",
            records.len()
        );
    }
    // SAFETY: every index was checked against the records just above.
    #[allow(unsafe_code)]
    unsafe {
        gather_xyz_unchecked(records, index)
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline(always)]
#[allow(unsafe_code)]
unsafe fn gather_xyz_unchecked(records: &[[f64; 4]], index: &[u32; LANES]) -> [Lanes; 3] {
    use std::arch::x86_64::*;
    let base = records.as_ptr() as *const f64;
    let mut out = [[0.0; LANES]; 3];
    for half in 0..2 {
        // SAFETY: the caller checked every index; a record is four f64.
        let at = |m: usize| unsafe { base.add(4 * index[4 * half + m] as usize) };
        // a_m = (x_m, y_m | x_{m+2}, y_{m+2}), b_m the same of (z, pad)
        let pair = |m: usize, offset: usize| unsafe {
            _mm256_insertf128_pd::<1>(
                _mm256_castpd128_pd256(_mm_loadu_pd(at(m).add(offset))),
                _mm_loadu_pd(at(m + 2).add(offset)),
            )
        };
        let (a0, a1) = (pair(0, 0), pair(1, 0));
        let (b0, b1) = (pair(0, 2), pair(1, 2));
        let lanes = 4 * half;
        // SAFETY: each store writes four of the eight f64 of a lane array.
        unsafe {
            _mm256_storeu_pd(out[0][lanes..].as_mut_ptr(), _mm256_unpacklo_pd(a0, a1));
            _mm256_storeu_pd(out[1][lanes..].as_mut_ptr(), _mm256_unpackhi_pd(a0, a1));
            _mm256_storeu_pd(out[2][lanes..].as_mut_ptr(), _mm256_unpacklo_pd(b0, b1));
        }
    }
    out.map(Lanes)
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
#[inline(always)]
#[allow(unsafe_code)]
unsafe fn gather_xyz_unchecked(records: &[[f64; 4]], index: &[u32; LANES]) -> [Lanes; 3] {
    gather_xyz_scalar(records, index)
}

/// [`gather_xyz`] lane by lane: the build's fallback, and the reference
/// the AVX2 path is tested against.
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx2"), allow(dead_code))]
#[inline(always)]
fn gather_xyz_scalar(records: &[[f64; 4]], index: &[u32; LANES]) -> [Lanes; 3] {
    let mut out = [[0.0; LANES]; 3];
    for (m, &i) in index.iter().enumerate() {
        let r = records[i as usize];
        for (c, o) in out.iter_mut().enumerate() {
            o[m] = r[c];
        }
    }
    out.map(Lanes)
}

#[cfg(test)]
mod tests {
    /// Four lanes compute what eight do, lane for lane, bit for bit;
    /// bits_below and sqrt through the trait agree with `Lanes`' own.
    #[test]
    fn four_lanes_agree_with_eight() {
        let x = [1.5, -2.0, f64::NAN, 1e-300, 3.0, 0.25, -0.0, 7.0];
        let y = [0.5, 4.0, 1.0, 3.0, -1.0, 2.0, 5.0, 1e300];
        let (a, b) = (Lanes(x), Lanes(y));
        let eight = [a + b, a - b, a * b, a / b, a * 3.0, a / 7.0, Lane::sqrt(a)];
        for half in 0..2 {
            let q = |v: [f64; 8]| Four(std::array::from_fn(|l| v[4 * half + l]));
            let (c, d) = (q(x), q(y));
            let four = [c + d, c - d, c * d, c / d, c * 3.0, c / 7.0, Lane::sqrt(c)];
            for (e, f) in eight.iter().zip(four) {
                for l in 0..4 {
                    assert_eq!(e.0[4 * half + l].to_bits(), f.0[l].to_bits());
                }
            }
            let below = Lane::bits_below(c, 2.0);
            assert_eq!(below, (a.bits_below(2.0) >> (4 * half)) & 0xf);
        }
    }

    use super::*;

    #[test]
    fn lanes_compute_lane_by_lane_and_sum_in_order() {
        let a = Lanes([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        let b = Lanes::splat(2.0);
        assert_eq!(
            (a * b - a + 1.0).0,
            [2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
        );
        assert_eq!(a.sum(), 36.0);
        let r = Lanes([0.0, 4.0, -1.0, 0.25, 0.0, 1.0, 2.0, 8.0]).recip_or_zero();
        assert_eq!(r.0, [0.0, 0.25, 0.0, 4.0, 0.0, 1.0, 0.5, 0.125]);
        assert_eq!(
            a.select_below(3.5, 1.0, 0.0).0,
            [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
        let r2 = Lanes([0.0, 1.0, 2.0, 3.0, 0.0, 0.5, 9.0, 0.0]);
        assert_eq!(
            r2.select_within(2.5, 1.0, 0.0).0,
            [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0]
        );
        let mut out = [10.0; 12];
        a.add_to(&mut out, 2, 8);
        a.subtract_from(&mut out, 0, 3);
        assert_eq!(
            out,
            [9.0, 8.0, 8.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0, 18.0, 10.0, 10.0]
        );
        assert_eq!(
            Lanes::load(&[9.0, 8.0, 7.0], 1, 2).0,
            [8.0, 7.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
        // The sum is in lane order, not pairwise: 1e16 + 1 − 1e16 … shows it.
        let s = Lanes([1e16, 1.0, -1e16, 1.0, 0.0, 0.0, 0.0, 0.0]).sum();
        assert_eq!(s, ((1e16 + 1.0) - 1e16) + 1.0);
    }

    /// 1/√x by multiplications is within 2 ulp of 1/x.sqrt() (itself
    /// within half an ulp of the truth and within an ulp of the
    /// correctly rounded value) over the whole range of normal numbers,
    /// on eight lanes and on four alike, by the build's path (AVX2 + FMA)
    /// and by the plain fallback; zero, subnormal, negative, infinite and
    /// NaN lanes get exactly 1/x.sqrt().
    #[test]
    fn rsqrt_is_one_over_the_square_root_to_the_last_places() {
        let mut worst: f64 = 0.0;
        // A xorshift walk through the bits of the normal numbers, plus
        // the ends of the range and the powers of two.
        let mut bits = 0x9e37_79b9_7f4a_7c15_u64;
        let mut xs = vec![f64::MIN_POSITIVE, f64::MAX, 1.0, 2.0, 0.5, 4.0, 1.0 - 1e-16];
        for _ in 0..200_000 {
            bits ^= bits << 13;
            bits ^= bits >> 7;
            bits ^= bits << 17;
            let x = f64::from_bits(bits >> 1);
            if x.is_normal() {
                xs.push(x);
            }
        }
        for k in -1022..1024 {
            xs.push(2f64.powi(k));
        }
        for x in xs.chunks_exact(LANES) {
            let lanes = Lanes(x.try_into().unwrap()).rsqrt();
            let four = Four(x[..4].try_into().unwrap()).rsqrt();
            let plain = rsqrt_portable(Lanes(x.try_into().unwrap())).unwrap();
            for (l, &x) in x.iter().enumerate() {
                let exact = 1.0 / x.sqrt();
                let ulp = exact - f64::from_bits(exact.to_bits() - 1);
                worst = worst.max((lanes.0[l] - exact).abs() / ulp);
                worst = worst.max((plain.0[l] - exact).abs() / ulp);
                assert_eq!(lanes.0[l].to_bits(), rsqrt(x).to_bits(), "{x:e}");
                if l < 4 {
                    assert_eq!(four.0[l].to_bits(), lanes.0[l].to_bits(), "{x:e}");
                }
            }
        }
        assert!(worst <= 2.0, "{worst} ulp");
        let odd = [
            0.0,
            -0.0,
            1e-310,
            -1.0,
            f64::INFINITY,
            f64::NAN,
            3.0,
            5e-324,
        ];
        let y = Lanes(odd).rsqrt();
        for (l, x) in odd.into_iter().enumerate() {
            let exact = 1.0 / x.sqrt();
            assert!(
                y.0[l] == exact || (exact.is_nan() && y.0[l].is_nan()),
                "{x:e}"
            );
        }
        let gate = Lanes([1.0, 0.0, -1.0, f64::NAN, 2.0, 1e-300, 0.0, 3.0]);
        assert_eq!(
            Lanes::splat(7.0).where_positive(gate).0,
            [7.0, 0.0, 0.0, 0.0, 7.0, 7.0, 0.0, 7.0]
        );
    }

    #[test]
    fn records_gather_into_coordinate_lanes() {
        let records: Vec<[f64; 4]> = (0..20)
            .map(|i| {
                let i = i as f64;
                [i, 100.0 + i, 200.0 + i, -1.0]
            })
            .collect();
        let index = [7, 0, 19, 3, 3, 12, 5, 18];
        let [x, y, z] = gather_xyz(&records, &index);
        for (m, &i) in index.iter().enumerate() {
            assert_eq!([x.0[m], y.0[m], z.0[m]], records[i as usize][..3]);
        }
        // The build's path (AVX2 on x86-64-v3) against the scalar one.
        assert_eq!(
            gather_xyz(&records, &index),
            gather_xyz_scalar(&records, &index)
        );
    }

    #[test]
    fn masks_pack_into_list_entries_in_lane_order() {
        let r2 = Lanes([0.5, 3.0, 1.0, f64::NAN, 2.0, 0.1, 9.0, 1.5]);
        let bits = r2.bits_below(2.0);
        assert_eq!(bits, 0b1010_0101);
        let mut out = [0u32; 10];
        assert_eq!(pack_indices(bits, 100, &mut out[1..]), 4);
        assert_eq!(out[1..5], [100, 102, 105, 107]);
        for bits in 0..=255u8 {
            let mut out = [0u32; 8];
            let n = pack_indices(bits, 7, &mut out);
            let want: Vec<u32> = (0..8)
                .filter(|l| bits >> l & 1 == 1)
                .map(|l| 7 + l)
                .collect();
            assert_eq!(out[..n], want[..], "mask {bits:08b}");
            let mut scalar = [0u32; 8];
            assert_eq!(pack_indices_scalar(bits, 7, &mut scalar), n);
            assert_eq!(scalar[..n], out[..n], "mask {bits:08b}: scalar path");
        }
    }

    #[test]
    #[should_panic(expected = "record 20 of 20")]
    fn a_record_beyond_the_slice_is_refused() {
        let records = vec![[0.0; 4]; 20];
        gather_xyz(&records, &[0, 1, 2, 3, 20, 5, 6, 7]);
    }
}

/// N three-vectors, one per lane: the lane form of glam's `DVec3`, each
/// operation glam's, term for term and in its order, so a kernel written
/// on it gives every lane the bits of the scalar code on `DVec3`.
#[derive(Debug, Clone, Copy)]
pub struct V3<L> {
    pub x: L,
    pub y: L,
    pub z: L,
}

impl<L: Lane> V3<L> {
    /// Lane l from `f(l)`.
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> glam::DVec3) -> Self {
        V3 {
            x: L::from_fn(|l| f(l).x),
            y: L::from_fn(|l| f(l).y),
            z: L::from_fn(|l| f(l).z),
        }
    }

    /// The first N vectors of `v`, one per lane.
    #[inline(always)]
    pub fn of(v: &[glam::DVec3]) -> Self {
        Self::from_fn(|l| v[l])
    }

    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: glam::DVec3) -> Self {
        V3 {
            x: L::splat(v.x),
            y: L::splat(v.y),
            z: L::splat(v.z),
        }
    }

    /// Lane l.
    #[inline(always)]
    pub fn lane(self, l: usize) -> glam::DVec3 {
        glam::DVec3::new(self.x.lane(l), self.y.lane(l), self.z.lane(l))
    }

    /// Into the first N entries of `out` (fewer where `out` is shorter).
    #[inline(always)]
    pub fn write(self, out: &mut [glam::DVec3]) {
        for (l, o) in out.iter_mut().take(L::N).enumerate() {
            *o = self.lane(l);
        }
    }

    #[inline(always)]
    #[allow(clippy::should_implement_trait)]
    pub fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    #[allow(clippy::should_implement_trait)]
    pub fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    /// −v (glam's `Neg`: the sign of each component flipped).
    #[inline(always)]
    #[allow(clippy::should_implement_trait)]
    pub fn neg(self) -> Self {
        V3 {
            x: self.x.map(|a| -a),
            y: self.y.map(|a| -a),
            z: self.z.map(|a| -a),
        }
    }

    /// Component by component (glam's `DVec3 * DVec3`).
    #[inline(always)]
    #[allow(clippy::should_implement_trait)]
    pub fn mul(self, o: Self) -> Self {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// Each component times `s` (glam's `DVec3 * f64`).
    #[inline(always)]
    pub fn scale(self, s: L) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Each component over `s` (glam's `DVec3 / f64`: three divisions).
    #[inline(always)]
    pub fn over(self, s: L) -> Self {
        V3 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// (x·x' + y·y') + z·z', glam's order.
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// glam's `cross`, term for term.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// Lane l of `yes` where lane l of `a` > lane l of `b`, else of `no`.
    #[inline(always)]
    pub fn select_above(a: L, b: L, yes: Self, no: Self) -> Self {
        V3 {
            x: a.select_above(b, yes.x, no.x),
            y: a.select_above(b, yes.y, no.y),
            z: a.select_above(b, yes.z, no.z),
        }
    }
}
