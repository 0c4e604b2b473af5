//! Reference results the simulations are tested against.

use std::f64::consts::PI;

/// Carnahan–Starling equation of state for hard spheres,
/// Z = (1 + η + η² − η³)/(1 − η)³ (J. Chem. Phys. 51, 635 (1969)).
pub fn carnahan_starling(eta: f64) -> f64 {
    (1.0 + eta + eta * eta - eta * eta * eta) / (1.0 - eta).powi(3)
}

/// Henderson's equation of state for hard disks,
/// Z = (1 + η²/8)/(1 − η)² (Mol. Phys. 30, 971 (1975)).
pub fn henderson(eta: f64) -> f64 {
    (1.0 + eta * eta / 8.0) / (1.0 - eta).powi(2)
}

/// Contact value of the pair distribution g(σ) from the equation of state:
/// Z − 1 = (2π/3) n σ³ g(σ) = 4 η g(σ) in 3-D, Z − 1 = 2 η g(σ) in 2-D.
pub fn contact_value(dim: usize, eta: f64) -> f64 {
    match dim {
        2 => (henderson(eta) - 1.0) / (2.0 * eta),
        _ => (carnahan_starling(eta) - 1.0) / (4.0 * eta),
    }
}

/// Enskog collision rate per particle for monodisperse spheres (3-D) or
/// disks (2-D) of diameter σ, mass m, at number density n and temperature kT:
/// Γ = 4 n σ² √(π kT/m) g(σ) (3-D), Γ = 2 n σ √(π kT/m) g(σ) (2-D)
/// (Chapman & Cowling, ch. 16; g(σ) from [`contact_value`]).
pub fn enskog_rate(dim: usize, n_density: f64, sigma: f64, kt: f64, m: f64, eta: f64) -> f64 {
    let g = contact_value(dim, eta);
    let vbar = (PI * kt / m).sqrt();
    match dim {
        2 => 2.0 * n_density * sigma * vbar * g,
        _ => 4.0 * n_density * sigma * sigma * vbar * g,
    }
}

/// The Kolmogorov–Smirnov statistic D_n = sup |F_n − F| of a sample against
/// a continuous CDF, and its asymptotic p-value
/// P(K > √n D_n) = 2 Σ_k (−1)^{k−1} exp(−2k² n D_n²) (with Stephens'
/// small-sample correction √n + 0.12 + 0.11/√n).
pub fn ks_test(sample: &[f64], cdf: impl Fn(f64) -> f64) -> (f64, f64) {
    let mut x = sample.to_vec();
    x.sort_by(f64::total_cmp);
    let n = x.len() as f64;
    let mut dmax: f64 = 0.0;
    for (k, &v) in x.iter().enumerate() {
        let f = cdf(v);
        dmax = dmax
            .max((f - k as f64 / n).abs())
            .max(((k + 1) as f64 / n - f).abs());
    }
    let sn = n.sqrt();
    let lambda = (sn + 0.12 + 0.11 / sn) * dmax;
    (dmax, kolmogorov_q(lambda))
}

/// Q_KS(λ) = 2 Σ_{k≥1} (−1)^{k−1} exp(−2k²λ²).
pub fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda < 1e-3 {
        return 1.0;
    }
    let mut s = 0.0;
    let mut sign = 1.0;
    for k in 1..200 {
        let kf = k as f64;
        let term = sign * (-2.0 * kf * kf * lambda * lambda).exp();
        s += term;
        if term.abs() < 1e-16 {
            break;
        }
        sign = -sign;
    }
    (2.0 * s).clamp(0.0, 1.0)
}

/// CDF of the 2-D Maxwell–Boltzmann speed distribution
/// f(v) = (2v/b²) exp(−v²/b²), 002 Eq. (21): F(v) = 1 − exp(−v²/b²).
pub fn maxwell2d_cdf(v: f64, b2: f64) -> f64 {
    1.0 - (-v * v / b2).exp()
}

/// CDF of the 3-D Maxwell speed distribution with b² = 2kT/m.
pub fn maxwell3d_cdf(v: f64, b2: f64) -> f64 {
    let x = v / b2.sqrt();
    erf(x) - 2.0 / PI.sqrt() * x * (-x * x).exp()
}

/// erf of musl/fdlibm (below 1 ulp), the one erf of the workspace.
pub use libm::erf;

/// Histogram of `values` on `[0, max)` with `bins` bins, normalised as a
/// probability density (counts / (n · width)).
pub fn histogram(values: &[f64], max: f64, bins: usize) -> Vec<f64> {
    let mut h = vec![0.0; bins];
    let w = max / bins as f64;
    for &v in values {
        let k = (v / w) as usize;
        if v >= 0.0 && k < bins {
            h[k] += 1.0;
        }
    }
    let n = values.len().max(1) as f64;
    h.iter_mut().for_each(|x| *x /= n * w);
    h
}
