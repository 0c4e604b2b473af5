//! Which vector instructions this CPU has, asked once per process, and the
//! small vector helpers every AVX-512 kernel of mote shares.
//!
//! mote is built for x86-64-v3 (AVX2 + FMA, .cargo/config.toml); kernels
//! with an AVX-512 path pick it at run time through [`isa`] and keep a
//! portable path that they are tested against.

use std::sync::OnceLock;

/// The instruction sets a kernel can be dispatched to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Isa {
    /// Plain Rust (auto-vectorised for the build's target).
    Portable,
    /// AVX-512 F + VL (Skylake-X, Ice Lake, Zen 4 and later).
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

/// The widest instruction set this CPU runs, detected once.
pub fn isa() -> Isa {
    static ISA: OnceLock<Isa> = OnceLock::new();
    *ISA.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
            {
                return Isa::Avx512;
            }
        }
        Isa::Portable
    })
}

/// Whether the AVX-512 kernels can run here.
pub fn has_avx512() -> bool {
    isa() != Isa::Portable
}

/// AVX-512 helpers.
#[cfg(target_arch = "x86_64")]
pub mod avx512 {
    use std::arch::x86_64::*;

    /// 1/√r² to full double precision (r² > 0 and finite): the 14-bit
    /// estimate of `vrsqrt14pd` refined by two Newton–Raphson steps
    /// y ← y (3/2 − (r²/2) y²) (14 → 28 → 56 bits).
    ///
    /// # Safety
    /// The CPU must have AVX-512F ([`super::has_avx512`]).
    #[inline]
    #[target_feature(enable = "avx512f")]
    pub fn rsqrt(r2: __m512d) -> __m512d {
        let three_halves = _mm512_set1_pd(1.5);
        let h = _mm512_mul_pd(_mm512_set1_pd(0.5), r2);
        let mut y = _mm512_rsqrt14_pd(r2);
        y = _mm512_mul_pd(y, _mm512_fnmadd_pd(_mm512_mul_pd(h, y), y, three_halves));
        _mm512_mul_pd(y, _mm512_fnmadd_pd(_mm512_mul_pd(h, y), y, three_halves))
    }
}
