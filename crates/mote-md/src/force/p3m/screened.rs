//! The screened Coulomb pair of the real-space sum as short polynomials.
//!
//! With x = αr, the pair of unit charges has the energy erfc(x)/r and the
//! force F = ψ(x) r/r³, ψ(x) = erfc x + (2/√π) x e^{−x²}. Both erfc and ψ
//! are smooth on [0, X], so each is a Chebyshev series of degree 7 on the
//! intervals of width 1/16 in x, interpolated at construction from libm's
//! erfc (relative error below 1e-15); the series' own error is below
//! 1e-14 of the pair at contact (erfc 0 = ψ 0 = 1) and below 1e-13
//! relative for x < 3 (tested). A pair then costs a square root, one division and
//! one short polynomial: no exponential, no erfc (LAMMPS's `coul/long`
//! reaches its speed by linear tables in r², accurate to about 1e-6).

use libm::erfc;
use mote_geom::lanes::Lanes;

/// Points (and coefficients) per interval.
const NODES: usize = 8;
/// Intervals per unit of x.
const PER_UNIT: f64 = 16.0;

use std::f64::consts::FRAC_2_SQRT_PI as TWO_OVER_SQRT_PI;

/// ψ(x) = erfc x + (2/√π) x e^{−x²}: r³ F/(q_i q_j) at x = αr.
pub fn psi(x: f64) -> f64 {
    erfc(x) + TWO_OVER_SQRT_PI * x * (-x * x).exp()
}

/// A function on [0, X] as a piecewise Chebyshev series.
#[derive(Debug, Clone)]
struct Series {
    /// Chebyshev coefficients c_0 … c_7 of each interval, in t ∈ [−1, 1].
    coefficients: Vec<[f64; NODES]>,
}

impl Series {
    fn new(intervals: usize, f: impl Fn(f64) -> f64) -> Self {
        let pi = std::f64::consts::PI;
        let coefficients = (0..intervals)
            .map(|k| {
                let (a, b) = (k as f64 / PER_UNIT, (k + 1) as f64 / PER_UNIT);
                // Values at the Chebyshev nodes t_j = cos(π(j + ½)/n).
                let nodes: Vec<(f64, f64)> = (0..NODES)
                    .map(|j| {
                        let theta = pi * (j as f64 + 0.5) / NODES as f64;
                        (theta, f(0.5 * (a + b) + 0.5 * (b - a) * theta.cos()))
                    })
                    .collect();
                let mut c = [0.0; NODES];
                for (m, cm) in c.iter_mut().enumerate() {
                    let sum: f64 = nodes.iter().map(|(th, v)| v * (m as f64 * th).cos()).sum();
                    *cm = 2.0 / NODES as f64 * sum;
                }
                c[0] *= 0.5;
                c
            })
            .collect();
        Self { coefficients }
    }

    /// The series of interval `k` at t ∈ [−1, 1] (Clenshaw's recurrence).
    #[inline]
    fn at(&self, k: usize, t: f64) -> f64 {
        let c = &self.coefficients[k];
        let (mut b1, mut b2) = (0.0, 0.0);
        for &cm in c[1..].iter().rev() {
            let b0 = 2.0 * t * b1 - b2 + cm;
            b2 = b1;
            b1 = b0;
        }
        t * b1 - b2 + c[0]
    }

    /// The series at eight points x (each within the table).
    #[inline(always)]
    fn at_lanes(&self, x: Lanes) -> Lanes {
        let scaled = x * PER_UNIT;
        let k = scaled
            .0
            .map(|s| (s as usize).min(self.coefficients.len() - 1));
        let t = Lanes(std::array::from_fn(|l| {
            2.0 * (scaled.0[l] - k[l] as f64) - 1.0
        }));
        let two_t = t * 2.0;
        let (mut b1, mut b2) = (Lanes::splat(0.0), Lanes::splat(0.0));
        for m in (1..NODES).rev() {
            let c = Lanes(k.map(|k| self.coefficients[k][m]));
            let b0 = two_t * b1 - b2 + c;
            b2 = b1;
            b1 = b0;
        }
        t * b1 - b2 + Lanes(k.map(|k| self.coefficients[k][0]))
    }
}

/// erfc and ψ on [0, X].
#[derive(Debug, Clone)]
pub struct Screened {
    /// The last x covered; beyond it, libm.
    limit: f64,
    erfc: Series,
    psi: Series,
}

impl Screened {
    /// Covering x ∈ [0, `limit`].
    pub fn new(limit: f64) -> Self {
        // One interval past X, so that x = X itself is inside.
        let intervals = (limit * PER_UNIT).floor() as usize + 1;
        Self {
            limit: intervals as f64 / PER_UNIT,
            erfc: Series::new(intervals, erfc),
            psi: Series::new(intervals, psi),
        }
    }

    /// The interval of x and x's place in it.
    #[inline]
    fn locate(x: f64) -> (usize, f64) {
        let scaled = x * PER_UNIT;
        let k = scaled as usize;
        (k, 2.0 * (scaled - k as f64) - 1.0)
    }

    /// ψ(x) for x ≥ 0.
    #[inline]
    pub fn psi(&self, x: f64) -> f64 {
        if x >= self.limit {
            return psi(x);
        }
        let (k, t) = Self::locate(x);
        self.psi.at(k, t)
    }

    /// ψ at eight points in [0, X] (clamped to the table).
    #[inline(always)]
    pub fn psi_lanes(&self, x: Lanes) -> Lanes {
        self.psi.at_lanes(x)
    }

    /// erfc at eight points in [0, X] (clamped to the table).
    #[inline(always)]
    pub fn erfc_lanes(&self, x: Lanes) -> Lanes {
        self.erfc.at_lanes(x)
    }

    /// erfc(x) for x ≥ 0.
    #[inline]
    pub fn erfc(&self, x: f64) -> f64 {
        if x >= self.limit {
            return erfc(x);
        }
        let (k, t) = Self::locate(x);
        self.erfc.at(k, t)
    }
}

/// (4/√π) x³ e^{−x²} + 3ψ(x): r⁵ C(r) of the dipolar Ewald sum at x = αr.
pub fn dipolar_c(x: f64) -> f64 {
    3.0 * psi(x) + 2.0 * TWO_OVER_SQRT_PI * x.powi(3) * (-x * x).exp()
}

/// 5 c(x) + (8/√π) x⁵ e^{−x²}: r⁷ D(r) of the dipolar Ewald sum.
pub fn dipolar_d(x: f64) -> f64 {
    5.0 * dipolar_c(x) + 4.0 * TWO_OVER_SQRT_PI * x.powi(5) * (-x * x).exp()
}

/// The screened dipole pair of the real-space sum (Wang & Holm 2001,
/// Eqs. 5–9): with x = αr,
///
///   B = b(x)/r³, C = c(x)/r⁵, D = d(x)/r⁷,
///   b = ψ, c = 3ψ + (4/√π) x³ e^{−x²}, d = 5c + (8/√π) x⁵ e^{−x²},
///
/// b, c and d as the piecewise Chebyshev series of [`Screened`].
#[derive(Debug, Clone)]
pub struct DipolarScreened {
    b: Series,
    c: Series,
    d: Series,
}

impl DipolarScreened {
    /// Covering x ∈ [0, `limit`].
    pub fn new(limit: f64) -> Self {
        let intervals = (limit * PER_UNIT).floor() as usize + 1;
        Self {
            b: Series::new(intervals, psi),
            c: Series::new(intervals, dipolar_c),
            d: Series::new(intervals, dipolar_d),
        }
    }

    /// (b, c, d) at x ≥ 0, libm's beyond the table.
    #[cfg(test)]
    pub fn at(&self, x: f64) -> (f64, f64, f64) {
        let (k, t) = Screened::locate(x);
        if k >= self.b.coefficients.len() {
            return (psi(x), dipolar_c(x), dipolar_d(x));
        }
        (self.b.at(k, t), self.c.at(k, t), self.d.at(k, t))
    }

    /// (b, c) at eight points in [0, X] (clamped to the table).
    #[inline(always)]
    pub fn bc_lanes(&self, x: Lanes) -> (Lanes, Lanes) {
        (self.b.at_lanes(x), self.c.at_lanes(x))
    }

    /// d at eight points in [0, X] (clamped to the table).
    #[inline(always)]
    pub fn d_lanes(&self, x: Lanes) -> Lanes {
        self.d.at_lanes(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against libm: to round-off of the pair at contact (absolute 1e-14
    /// of erfc 0 = ψ 0 = 1, the scale of every pair's force), and to 1e-13
    /// relative wherever the pair is more than 1e-5 of that (x < 3).
    #[test]
    fn matches_libm_to_round_off() {
        let table = Screened::new(6.0);
        let mut worst = [0.0f64; 4];
        for i in 0..=60_000 {
            let x = i as f64 * 1e-4;
            let (e, p) = (table.erfc(x) - erfc(x), table.psi(x) - psi(x));
            worst[0] = worst[0].max(e.abs());
            worst[1] = worst[1].max(p.abs());
            if x < 3.0 {
                worst[2] = worst[2].max((e / erfc(x)).abs());
                worst[3] = worst[3].max((p / psi(x)).abs());
            }
        }
        println!(
            "absolute {:e} {:e}, relative below 3 {:e} {:e}",
            worst[0], worst[1], worst[2], worst[3]
        );
        assert!(worst[0] < 1e-14 && worst[1] < 1e-14, "{worst:?}");
        assert!(worst[2] < 1e-13 && worst[3] < 1e-13, "{worst:?}");
    }

    /// The dipolar b, c, d against libm to 1e-14 of their values at
    /// contact (1, 3, 15) and 1e-12 relative for x < 3.
    #[test]
    fn dipolar_series_match_libm() {
        let table = DipolarScreened::new(6.0);
        let mut worst = [0.0f64; 6];
        for i in 0..=60_000 {
            let x = i as f64 * 1e-4;
            let (b, c, d) = table.at(x);
            let exact = [psi(x), dipolar_c(x), dipolar_d(x)];
            for (s, (got, want)) in [b, c, d].into_iter().zip(exact).enumerate() {
                worst[s] = worst[s].max((got - want).abs() / [1.0, 3.0, 15.0][s]);
                if x < 3.0 {
                    worst[3 + s] = worst[3 + s].max(((got - want) / want).abs());
                }
            }
        }
        println!("dipolar series: {worst:?}");
        assert!(worst[..3].iter().all(|w| *w < 1e-14), "{worst:?}");
        assert!(worst[3..].iter().all(|w| *w < 1e-12), "{worst:?}");
    }
}
