//! Reference equations of state used to validate simulations.
//!
//! The Lennard-Jones fluid: the modified Benedict–Webb–Rubin equation of
//! Johnson, Zollweg & Gubbins, Mol. Phys. 78, 591 (1993), "JZG", in reduced
//! units (ε = σ = k_B = 1), for the full (untruncated) potential:
//!
//! P = ρT + Σ_{i=1}^{8} a_i(T) ρ^{i+1} + F Σ_{i=1}^{6} b_i(T) ρ^{2i+1},  F = e^{−γρ²},
//! U/N = Σ_{i=1}^{8} c_i(T) ρ^i / i + Σ_{i=1}^{6} d_i(T) G_i(ρ)          (residual energy),
//! A/N = Σ_{i=1}^{8} a_i(T) ρ^i / i + Σ_{i=1}^{6} b_i(T) G_i(ρ)          (residual Helmholtz),
//!
//! G_1 = (1 − F)/(2γ), G_i = −(F ρ^{2(i−1)} − 2(i−1) G_{i−1})/(2γ), γ = 3,
//! with a_i, b_i (JZG Table 5), c_i, d_i (Table 7) built from the 32
//! coefficients x_1…x_32 of Table 10.

/// x_1 … x_32 of JZG Table 10 (x[0] unused).
#[allow(clippy::excessive_precision)]
const X: [f64; 33] = [
    0.0,
    0.8623085097507421,
    2.976218765822098,
    -8.402230115796038,
    0.1054136629203555,
    -0.8564583828174598,
    1.582759470107601,
    0.7639421948305453,
    1.753173414312048,
    2.798291772190376e3,
    -4.8394220260857657e-2,
    0.9963265197721935,
    -3.698000291272493e1,
    2.084012299434647e1,
    8.305402124717285e1,
    -9.574799715203068e2,
    -1.477746229234994e2,
    6.398607852471505e1,
    1.603993673294834e1,
    6.805916615864377e1,
    -2.791293578795945e3,
    -6.245128304568454,
    -8.116836104958410e3,
    1.488735559561229e1,
    -1.059346754655084e4,
    -1.131607632802822e2,
    -8.867771540418822e3,
    -3.986982844450543e1,
    -4.689270299917261e3,
    2.593535277438717e2,
    -2.694523589434903e3,
    -7.218487631550215e2,
    1.721802063863269e2,
];

const GAMMA: f64 = 3.0;

/// a_1 … a_8 (JZG Table 5).
fn a(t: f64) -> [f64; 8] {
    let x = &X;
    [
        x[1] * t + x[2] * t.sqrt() + x[3] + x[4] / t + x[5] / (t * t),
        x[6] * t + x[7] + x[8] / t + x[9] / (t * t),
        x[10] * t + x[11] + x[12] / t,
        x[13],
        x[14] / t + x[15] / (t * t),
        x[16] / t,
        x[17] / t + x[18] / (t * t),
        x[19] / (t * t),
    ]
}

/// b_1 … b_6 (JZG Table 5).
fn b(t: f64) -> [f64; 6] {
    let x = &X;
    let (t2, t3, t4) = (t * t, t * t * t, t * t * t * t);
    [
        x[20] / t2 + x[21] / t3,
        x[22] / t2 + x[23] / t4,
        x[24] / t2 + x[25] / t3,
        x[26] / t2 + x[27] / t4,
        x[28] / t2 + x[29] / t3,
        x[30] / t2 + x[31] / t3 + x[32] / t4,
    ]
}

/// c_1 … c_8 (JZG Table 7).
fn c(t: f64) -> [f64; 8] {
    let x = &X;
    let t2 = t * t;
    [
        x[2] * t.sqrt() / 2.0 + x[3] + 2.0 * x[4] / t + 3.0 * x[5] / t2,
        x[7] + 2.0 * x[8] / t + 3.0 * x[9] / t2,
        x[11] + 2.0 * x[12] / t,
        x[13],
        2.0 * x[14] / t + 3.0 * x[15] / t2,
        2.0 * x[16] / t,
        2.0 * x[17] / t + 3.0 * x[18] / t2,
        3.0 * x[19] / t2,
    ]
}

/// d_1 … d_6 (JZG Table 7).
fn d(t: f64) -> [f64; 6] {
    let x = &X;
    let (t2, t3, t4) = (t * t, t * t * t, t * t * t * t);
    [
        3.0 * x[20] / t2 + 4.0 * x[21] / t3,
        3.0 * x[22] / t2 + 5.0 * x[23] / t4,
        3.0 * x[24] / t2 + 4.0 * x[25] / t3,
        3.0 * x[26] / t2 + 5.0 * x[27] / t4,
        3.0 * x[28] / t2 + 4.0 * x[29] / t3,
        3.0 * x[30] / t2 + 4.0 * x[31] / t3 + 5.0 * x[32] / t4,
    ]
}

fn g(rho: f64) -> [f64; 6] {
    let f = (-GAMMA * rho * rho).exp();
    let mut out = [0.0; 6];
    out[0] = (1.0 - f) / (2.0 * GAMMA);
    for i in 1..6 {
        let k = i as f64; // i − 1 in the paper's 1-based numbering
        out[i] = -(f * rho.powi(2 * i as i32) - 2.0 * k * out[i - 1]) / (2.0 * GAMMA);
    }
    out
}

/// Pressure P* of the full LJ fluid at density ρ* and temperature T* (JZG).
pub fn lj_pressure(rho: f64, t: f64) -> f64 {
    let f = (-GAMMA * rho * rho).exp();
    let mut p = rho * t;
    for (i, ai) in a(t).iter().enumerate() {
        p += ai * rho.powi(i as i32 + 2);
    }
    for (i, bi) in b(t).iter().enumerate() {
        p += f * bi * rho.powi(2 * i as i32 + 3);
    }
    p
}

/// Residual (configurational) energy per particle U*/N of the full LJ fluid (JZG).
pub fn lj_energy(rho: f64, t: f64) -> f64 {
    let mut u = 0.0;
    for (i, ci) in c(t).iter().enumerate() {
        u += ci * rho.powi(i as i32 + 1) / (i as f64 + 1.0);
    }
    for (di, gi) in d(t).iter().zip(g(rho)) {
        u += di * gi;
    }
    u
}

/// Residual Helmholtz energy per particle A*/N of the full LJ fluid (JZG).
pub fn lj_helmholtz(rho: f64, t: f64) -> f64 {
    let mut f = 0.0;
    for (i, ai) in a(t).iter().enumerate() {
        f += ai * rho.powi(i as i32 + 1) / (i as f64 + 1.0);
    }
    for (bi, gi) in b(t).iter().zip(g(rho)) {
        f += bi * gi;
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The residual Helmholtz energy against teqp's value at T* = 2, ρ* = 0.4
    /// (α^r = A/(N T) = −0.33527709335199357), and the thermodynamic
    /// consistency of the three forms: P = ρT + ρ² ∂(A/N)/∂ρ and
    /// U/N = ∂(A/(N T))/∂(1/T).
    #[test]
    fn jzg_forms_are_consistent_and_match_a_reference_value() {
        assert!((lj_helmholtz(0.4, 2.0) / 2.0 + 0.335_277_093_351_993_57).abs() < 1e-12);
        for (rho, t) in [(0.8442, 0.72), (0.4, 2.0), (0.1, 1.5), (0.9, 3.0)] {
            let h = 1e-6;
            let dadrho = (lj_helmholtz(rho + h, t) - lj_helmholtz(rho - h, t)) / (2.0 * h);
            let p = rho * t + rho * rho * dadrho;
            assert!((p - lj_pressure(rho, t)).abs() < 1e-6, "P at ({rho}, {t})");
            let beta = |t: f64| 1.0 / t;
            let u = (lj_helmholtz(rho, 1.0 / (beta(t) + h)) * (beta(t) + h)
                - lj_helmholtz(rho, 1.0 / (beta(t) - h)) * (beta(t) - h))
                / (2.0 * h);
            assert!(
                (u - lj_energy(rho, t)).abs() < 1e-5,
                "U at ({rho}, {t}): {u} vs {}",
                lj_energy(rho, t)
            );
        }
    }
}
