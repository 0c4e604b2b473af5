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

/// The environment variable that forces a level (`avx512`, `avx2` or
/// `portable`), so that every level a kernel dispatches to can be run,
/// tested and timed on one machine.
pub const LEVEL_VARIABLE: &str = "MOTE_SIMD";

impl Isa {
    /// The level's name in run summaries.
    pub fn name(self) -> &'static str {
        match self {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => "AVX-512",
            #[cfg(target_arch = "x86_64")]
            Isa::Portable => "AVX2 + FMA (portable kernels)",
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Portable => "portable kernels",
        }
    }
}

/// The widest instruction set this CPU runs.
pub fn detected() -> Isa {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
        {
            return Isa::Avx512;
        }
    }
    Isa::Portable
}

/// The level `request` (the value of [`LEVEL_VARIABLE`]) asks for on a CPU
/// whose widest level is `widest`: none asked, the widest; a level the
/// CPU lacks or a name that is none is refused with the names there are.
pub fn level(request: Option<&str>, widest: Isa) -> Result<Isa, String> {
    let Some(name) = request else {
        return Ok(widest);
    };
    let asked = match name.trim().to_ascii_lowercase().as_str() {
        "" => return Ok(widest),
        #[cfg(target_arch = "x86_64")]
        "avx512" | "avx-512" => Isa::Avx512,
        // The portable kernels are compiled for the build's target
        // (x86-64-v3: AVX2 + FMA, .cargo/config.toml).
        "avx2" | "portable" => Isa::Portable,
        "scalar" => {
            return Err(format!(
                "{LEVEL_VARIABLE}=scalar: this build has no scalar level; its portable kernels \
                 are compiled for AVX2 + FMA (x86-64-v3): give {LEVEL_VARIABLE}=avx2"
            ))
        }
        _ => {
            return Err(format!(
                "{LEVEL_VARIABLE}={name}: expected avx512, avx2 or portable"
            ))
        }
    };
    if asked == Isa::Portable || asked == widest {
        Ok(asked)
    } else {
        Err(format!(
            "{LEVEL_VARIABLE}={name}: this CPU lacks it (its widest level: {})",
            widest.name()
        ))
    }
}

/// The level `MOTE_SIMD` asks for on this CPU, or why it cannot be had.
/// Programs check it once at their start ([`isa`] falls back to the
/// widest level where the request is refused).
pub fn requested() -> Result<Isa, String> {
    let value = std::env::var(LEVEL_VARIABLE).ok();
    level(value.as_deref(), detected())
}

/// The instruction set kernels dispatch to, decided once per process: the
/// widest this CPU runs, or the one `MOTE_SIMD` forces.
pub fn isa() -> Isa {
    static ISA: OnceLock<Isa> = OnceLock::new();
    *ISA.get_or_init(|| requested().unwrap_or_else(|_| detected()))
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

#[cfg(test)]
mod level_tests {
    use super::*;

    #[test]
    fn a_forced_level_is_taken_where_the_cpu_has_it_and_refused_where_not() {
        assert_eq!(level(None, Isa::Portable), Ok(Isa::Portable));
        assert_eq!(level(Some("avx2"), Isa::Portable), Ok(Isa::Portable));
        assert_eq!(level(Some(" Portable "), Isa::Portable), Ok(Isa::Portable));
        let bogus = level(Some("sse9"), Isa::Portable).unwrap_err();
        assert!(
            bogus.contains("MOTE_SIMD=sse9: expected avx512, avx2"),
            "{bogus}"
        );
        let scalar = level(Some("scalar"), Isa::Portable).unwrap_err();
        assert!(scalar.contains("no scalar level"), "{scalar}");
        #[cfg(target_arch = "x86_64")]
        {
            assert_eq!(level(None, Isa::Avx512), Ok(Isa::Avx512));
            assert_eq!(level(Some("avx2"), Isa::Avx512), Ok(Isa::Portable));
            assert_eq!(level(Some("AVX512"), Isa::Avx512), Ok(Isa::Avx512));
            let lacking = level(Some("avx512"), Isa::Portable).unwrap_err();
            assert!(lacking.contains("this CPU lacks it"), "{lacking}");
        }
    }
}
