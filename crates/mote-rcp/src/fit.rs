//! The analytic fit to rod-packing results for one lognormal population (003, Eq. 27).

/// φ(σ) ≈ 1 − 0.57e^(−σ) + 0.2135e^(−0.57σ/0.2135)
///        + 0.0019·(cos(2π(1 − e^(−0.75σ^0.7 − 0.025σ⁴))) − 1)   (003, Eq. 27).
///
/// It gives 0.6435 at σ = 0. `compat` uses π ≈ 3.14159265 as spherepack1d's `-s`
/// option does (the difference is below 10⁻¹¹).
pub fn lognormal_fit(sigma: f64, compat: bool) -> f64 {
    // spherepack1d's literal for π (8 decimals), kept for digit parity.
    #[allow(clippy::approx_constant)]
    const PI_SPHEREPACK1D: f64 = 3.14159265;
    let pi = if compat {
        PI_SPHEREPACK1D
    } else {
        std::f64::consts::PI
    };
    let s4 = sigma * sigma * sigma * sigma;
    1.0 - 0.57 * (-sigma).exp()
        + 0.2135 * (-0.57 * sigma / 0.2135).exp()
        + 0.0019 * ((2.0 * pi * (1.0 - (-0.75 * sigma.powf(0.7) - 0.025 * s4).exp())).cos() - 1.0)
}

/// The value spherepack1d prints for `-s` with monodisperse spheres (`-d`).
pub const MONODISPERSE_FIT: f64 = 0.6435;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_at_zero_width_is_monodisperse() {
        assert!((lognormal_fit(0.0, false) - MONODISPERSE_FIT).abs() < 1e-15);
    }
}
