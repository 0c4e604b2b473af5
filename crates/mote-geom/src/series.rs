//! The scalar functions behind exp and log, each accurate to a few ulps for
//! every argument: a Taylor series near zero, the closed form elsewhere.

/// `sin φ / φ`.
#[inline]
pub(crate) fn sinc(phi: f64) -> f64 {
    if phi.abs() < 1e-4 {
        let p2 = phi * phi;
        1.0 - p2 / 6.0 * (1.0 - p2 / 20.0)
    } else {
        phi.sin() / phi
    }
}

/// `(1 − cos φ) / φ²`, written as `2 sin²(φ/2) / φ²` so it never cancels.
#[inline]
pub(crate) fn one_minus_cos_over_sq(phi: f64) -> f64 {
    if phi.abs() < 1e-4 {
        let p2 = phi * phi;
        0.5 - p2 / 24.0 * (1.0 - p2 / 30.0)
    } else {
        let s = (0.5 * phi).sin();
        2.0 * s * s / (phi * phi)
    }
}

/// `(1 − sin φ / φ) / φ²`.
#[inline]
pub(crate) fn one_minus_sinc_over_sq(phi: f64) -> f64 {
    if phi.abs() < 0.3 {
        // Σ (−1)^k φ^(2k) / (2k+3)!, k = 0..=5
        const C: [f64; 6] = [
            1.0 / 6.0,
            -1.0 / 120.0,
            1.0 / 5040.0,
            -1.0 / 362_880.0,
            1.0 / 39_916_800.0,
            -1.0 / 6_227_020_800.0,
        ];
        let p2 = phi * phi;
        C.iter().rev().fold(0.0, |acc, c| acc * p2 + c)
    } else {
        (1.0 - phi.sin() / phi) / (phi * phi)
    }
}

/// `tan(φ/2) / φ` (the factor that turns ω·τ into a rotation vector).
#[inline]
pub(crate) fn half_tan_over(phi: f64) -> f64 {
    if phi.abs() < 1e-3 {
        let p2 = phi * phi;
        // tan x / x = 1 + x²/3 + 2x⁴/15 with x = φ/2
        0.5 * (1.0 + p2 / 12.0 + p2 * p2 / 120.0)
    } else {
        (0.5 * phi).tan() / phi
    }
}

/// `atan ρ / ρ`.
#[inline]
pub(crate) fn atan_over(rho: f64) -> f64 {
    if rho < 1e-4 {
        let r2 = rho * rho;
        1.0 - r2 / 3.0 + r2 * r2 / 5.0
    } else {
        rho.atan() / rho
    }
}

/// `(1 − atan ρ / ρ) / ρ²`.
#[inline]
pub(crate) fn one_minus_atan_over_sq(rho: f64) -> f64 {
    if rho < 0.2 {
        // Σ (−1)^k ρ^(2k) / (2k+3), k = 0..=11
        let r2 = rho * rho;
        (0..12).rev().fold(0.0, |acc, k| {
            let c = 1.0 / (2 * k + 3) as f64;
            acc * r2 + if k % 2 == 0 { c } else { -c }
        })
    } else {
        (1.0 - rho.atan() / rho) / (rho * rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each branch meets the other at its switch point (continuity to ~1e-15).
    #[test]
    fn branches_agree_at_switch() {
        for &x in &[1e-4, 1e-3, 0.2, 0.3] {
            let (lo, hi) = (x * (1.0 - 1e-15), x * (1.0 + 1e-15));
            for f in [
                sinc,
                one_minus_cos_over_sq,
                one_minus_sinc_over_sq,
                half_tan_over,
                atan_over,
                one_minus_atan_over_sq,
            ] {
                let (a, b) = (f(lo), f(hi));
                assert!((a - b).abs() <= 1e-13 * a.abs(), "x={x}: {a} vs {b}");
            }
        }
    }
}
