//! `Lanes`: eight f64 lanes whose every operation is one straight loop
//! over the lanes, so that the compiler turns it into the vector
//! instructions of the build's target (two AVX2 instructions per
//! operation on x86-64-v3, one with AVX-512, four NEON on aarch64). A
//! kernel written on `Lanes` is written once for every CPU; masks are
//! selects ([`Lanes::select`]), never branches, so the loops stay
//! straight. Sums over the lanes go in a fixed order ([`Lanes::sum`]), so
//! a kernel's bits do not depend on the CPU's vector width.

use std::ops::{Add, Mul, Sub};

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

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, o: Lanes) -> Lanes {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $trait<f64> for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, o: f64) -> Lanes {
                self.map(|a| a $op o)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);

#[cfg(test)]
mod tests {
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
        assert_eq!(
            Lanes::load(&[9.0, 8.0, 7.0], 1, 2).0,
            [8.0, 7.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
        // The sum is in lane order, not pairwise: 1e16 + 1 − 1e16 … shows it.
        let s = Lanes([1e16, 1.0, -1e16, 1.0, 0.0, 0.0, 0.0, 0.0]).sum();
        assert_eq!(s, ((1e16 + 1.0) - 1e16) + 1.0);
    }
}
