//! Sphere size distributions as sums of populations, their number weights, and the
//! rod-length distribution P1 with its cumulative F in closed form.
//!
//! Notation of seed 003 (Farr 2013) and shared/seeds/README.md: P3(D) is the
//! number-weighted diameter distribution, ⟨Dᵏ⟩ its moments, and the rod lengths of
//! the 1-D model have the number-weighted density (003, Eq. 18)
//!
//! P1(L) = 2L ∫_L^∞ P3(D) dD / ⟨D²⟩,
//!
//! whose cumulative is, after exchanging the integrals (003, Eq. 25),
//!
//! F(x) = ∫_0^∞ P3(D) min(D, x)² dD / ⟨D²⟩.

use crate::erfc::ErfcFlavour;
use crate::error::RcpError;

/// One population of spheres: monodisperse (a delta function in P3) or lognormal.
///
/// `volume` is the occluded volume of the population (or its mass when all
/// populations have the same density); only ratios of volumes matter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Population {
    /// All spheres of one diameter.
    Monodisperse {
        /// Sphere diameter, > 0.
        diameter: f64,
        /// Occluded volume, ≥ 0.
        volume: f64,
    },
    /// Lognormal number distribution of log-width σ (003, Eq. 10), given by its
    /// volume-weighted mean diameter d43; then d32 = d43·e^(−σ²) (003, Eq. 13) and the
    /// number median is D0 = d43·e^(−7σ²/2) (003, Eqs. 11–12).
    Lognormal {
        /// Volume-weighted mean diameter d43, > 0.
        d43: f64,
        /// Log-width σ, ≥ 0 (σ = 0 is monodisperse).
        sigma: f64,
        /// Occluded volume, ≥ 0.
        volume: f64,
    },
}

impl Population {
    /// A monodisperse population.
    pub fn monodisperse(diameter: f64, volume: f64) -> Self {
        Population::Monodisperse { diameter, volume }
    }

    /// A lognormal population from d43 and its width σ.
    pub fn lognormal(d43: f64, sigma: f64, volume: f64) -> Self {
        Population::Lognormal { d43, sigma, volume }
    }

    /// A lognormal population from d43 and d32, with σ² = ln(d43/d32) (003, Eq. 31).
    ///
    /// Errors unless 0 < d32 ≤ d43 (both finite).
    pub fn lognormal_d32(d43: f64, d32: f64, volume: f64) -> Result<Self, RcpError> {
        check_positive(1, "d43", d43)?;
        check_positive(1, "d32", d32)?;
        if d32 > d43 {
            return Err(RcpError::D32AboveD43 { index: 1, d43, d32 });
        }
        let sigma = (d43 / d32).ln().max(0.0).sqrt();
        Ok(Population::Lognormal { d43, sigma, volume })
    }

    /// Occluded volume.
    pub fn volume(&self) -> f64 {
        match *self {
            Population::Monodisperse { volume, .. } | Population::Lognormal { volume, .. } => {
                volume
            }
        }
    }

    /// The same population with another occluded volume.
    pub fn with_volume(self, volume: f64) -> Self {
        match self {
            Population::Monodisperse { diameter, .. } => {
                Population::Monodisperse { diameter, volume }
            }
            Population::Lognormal { d43, sigma, .. } => {
                Population::Lognormal { d43, sigma, volume }
            }
        }
    }

    /// Volume-weighted mean diameter d43 (the diameter of a monodisperse population).
    pub fn d43(&self) -> f64 {
        match *self {
            Population::Monodisperse { diameter, .. } => diameter,
            Population::Lognormal { d43, .. } => d43,
        }
    }

    /// Log-width σ (0 for a monodisperse population).
    pub fn sigma(&self) -> f64 {
        match *self {
            Population::Monodisperse { .. } => 0.0,
            Population::Lognormal { sigma, .. } => sigma,
        }
    }

    /// Surface-weighted mean diameter d32 = d43·e^(−σ²) (003, Eq. 13).
    pub fn d32(&self) -> f64 {
        self.d43() * (-self.sigma() * self.sigma()).exp()
    }

    /// The same population with all diameters multiplied by `factor`.
    pub fn scaled(self, factor: f64) -> Self {
        match self {
            Population::Monodisperse { diameter, volume } => Population::Monodisperse {
                diameter: diameter * factor,
                volume,
            },
            Population::Lognormal { d43, sigma, volume } => Population::Lognormal {
                d43: d43 * factor,
                sigma,
                volume,
            },
        }
    }

    fn validate(&self, index: usize) -> Result<(), RcpError> {
        let volume = self.volume();
        match *self {
            Population::Monodisperse { diameter, .. } => {
                check_positive(index, "diameter", diameter)?;
            }
            Population::Lognormal { d43, sigma, .. } => {
                check_positive(index, "d43", d43)?;
                if !sigma.is_finite() {
                    return Err(RcpError::NotFinite {
                        index,
                        what: "sigma",
                        value: sigma,
                    });
                }
                if sigma < 0.0 {
                    return Err(RcpError::NegativeSigma { index, sigma });
                }
            }
        }
        if !volume.is_finite() {
            return Err(RcpError::NotFinite {
                index,
                what: "volume",
                value: volume,
            });
        }
        if volume < 0.0 {
            return Err(RcpError::NegativeVolume { index, volume });
        }
        Ok(())
    }
}

fn check_positive(index: usize, what: &'static str, value: f64) -> Result<(), RcpError> {
    if !value.is_finite() {
        return Err(RcpError::NotFinite { index, what, value });
    }
    if value <= 0.0 {
        return Err(RcpError::NonPositiveDiameter { index, what, value });
    }
    Ok(())
}

/// A population as it enters F: number fraction and shape.
#[derive(Debug, Clone, Copy)]
struct Component {
    /// Number fraction a_i (003, Eq. 15), Σ a_i = 1.
    weight: f64,
    kind: Kind,
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Delta {
        d: f64,
    },
    Lognormal {
        /// ln D0, D0 = d43·e^(−7σ²/2) the number median.
        ln_d0: f64,
        /// 1/(σ√2).
        inv_s_sqrt2: f64,
        /// σ√2.
        s_sqrt2: f64,
        /// ⟨D²⟩ = d43²·e^(−5σ²).
        mean_d2: f64,
    },
}

/// F and P1 at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CdfPoint {
    /// Rod length x.
    pub x: f64,
    /// F(x), the cumulative of the rod-length distribution.
    pub cdf: f64,
    /// P1(x) = F′(x), the rod-length density.
    pub density: f64,
}

/// A sphere size distribution: a sum of monodisperse and lognormal populations
/// (003, Eq. 14), with number weights from the occluded volumes (003, Eqs. 15–16).
///
/// Monodisperse populations of equal diameter are merged (their volumes added), as
/// spherepack1d does. Populations with zero volume are kept in [`populations`] but do
/// not enter F.
///
/// [`populations`]: SizeDistribution::populations
#[derive(Debug, Clone)]
pub struct SizeDistribution {
    populations: Vec<Population>,
    weights: Vec<f64>,
    comps: Vec<Component>,
    /// Σ a_i ⟨D²⟩_i.
    norm: f64,
    /// Pure sums of delta functions: sorted diameters for the closed-form inverse.
    deltas: Option<DeltaTable>,
}

#[derive(Debug, Clone)]
struct DeltaTable {
    /// Diameters, increasing.
    d: Vec<f64>,
    /// c[k] = Σ_{j<k} a_j d_j² / norm.
    c: Vec<f64>,
    /// s[k] = Σ_{j≥k} a_j / norm.
    s: Vec<f64>,
}

impl SizeDistribution {
    /// Builds and checks a distribution: diameters > 0, σ ≥ 0, volumes ≥ 0 and not all
    /// zero, every number finite.
    pub fn new(populations: impl IntoIterator<Item = Population>) -> Result<Self, RcpError> {
        let mut merged: Vec<Population> = Vec::new();
        for (i, p) in populations.into_iter().enumerate() {
            p.validate(i + 1)?;
            if let Population::Monodisperse { diameter, volume } = p {
                if let Some(Population::Monodisperse { volume: v, .. }) = merged.iter_mut().find(
                    |q| matches!(q, Population::Monodisperse { diameter: d, .. } if *d == diameter),
                ) {
                    *v += volume;
                    continue;
                }
            }
            merged.push(p);
        }
        if merged.is_empty() {
            return Err(RcpError::NoPopulations);
        }
        if !merged.iter().any(|p| p.volume() > 0.0) {
            return Err(RcpError::NoPositiveVolume);
        }
        // Number weights a_i ∝ v_i/⟨D³⟩_i with ⟨D³⟩ = d43³·e^(−6σ²) (003, Eqs. 15–16,
        // 32–33), in logarithms so that wide populations do not overflow.
        let log_w: Vec<f64> = merged
            .iter()
            .map(|p| {
                if p.volume() > 0.0 {
                    let s = p.sigma();
                    p.volume().ln() - 3.0 * p.d43().ln() + 6.0 * s * s
                } else {
                    f64::NEG_INFINITY
                }
            })
            .collect();
        let top = log_w.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let raw: Vec<f64> = log_w.iter().map(|l| (l - top).exp()).collect();
        let total: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / total).collect();

        let mut comps = Vec::new();
        let mut norm = 0.0;
        for (p, &a) in merged.iter().zip(&weights) {
            if a <= 0.0 {
                continue;
            }
            let kind = match *p {
                Population::Lognormal { d43, sigma, .. } if sigma > 0.0 => {
                    let s2 = sigma * sigma;
                    Kind::Lognormal {
                        ln_d0: d43.ln() - 3.5 * s2,
                        inv_s_sqrt2: 1.0 / (sigma * std::f64::consts::SQRT_2),
                        s_sqrt2: sigma * std::f64::consts::SQRT_2,
                        mean_d2: d43 * d43 * (-5.0 * s2).exp(),
                    }
                }
                _ => Kind::Delta { d: p.d43() },
            };
            norm += a * match kind {
                Kind::Delta { d } => d * d,
                Kind::Lognormal { mean_d2, .. } => mean_d2,
            };
            comps.push(Component { weight: a, kind });
        }
        let deltas = if comps.iter().all(|c| matches!(c.kind, Kind::Delta { .. })) {
            let mut ds: Vec<(f64, f64)> = comps
                .iter()
                .map(|c| match c.kind {
                    Kind::Delta { d } => (d, c.weight),
                    Kind::Lognormal { .. } => unreachable!(),
                })
                .collect();
            ds.sort_by(|a, b| a.0.total_cmp(&b.0));
            let m = ds.len();
            let mut c = vec![0.0; m];
            let mut s = vec![0.0; m];
            let mut acc = 0.0;
            for k in 0..m {
                c[k] = acc / norm;
                acc += ds[k].1 * ds[k].0 * ds[k].0;
            }
            let mut acc = 0.0;
            for k in (0..m).rev() {
                acc += ds[k].1;
                s[k] = acc / norm;
            }
            Some(DeltaTable {
                d: ds.iter().map(|x| x.0).collect(),
                c,
                s,
            })
        } else {
            None
        };
        Ok(SizeDistribution {
            populations: merged,
            weights,
            comps,
            norm,
            deltas,
        })
    }

    /// One monodisperse population of diameter 1.
    pub fn monodisperse() -> Self {
        Self::new([Population::monodisperse(1.0, 1.0)]).expect("valid")
    }

    /// One lognormal population of width σ (d43 = 1).
    pub fn lognormal(sigma: f64) -> Result<Self, RcpError> {
        Self::new([Population::lognormal(1.0, sigma, 1.0)])
    }

    /// The populations, after merging equal monodisperse diameters.
    pub fn populations(&self) -> &[Population] {
        &self.populations
    }

    /// Number fractions a_i of the populations (003, Eq. 15), summing to 1.
    pub fn number_fractions(&self) -> &[f64] {
        &self.weights
    }

    /// True when every population with volume is monodisperse (F is piecewise quadratic
    /// and inverted in closed form).
    pub fn is_discrete(&self) -> bool {
        self.deltas.is_some()
    }

    /// ⟨D²⟩ of the number distribution (the normalisation of Eq. 18).
    pub fn mean_square_diameter(&self) -> f64 {
        self.norm
    }

    /// The cumulative rod-length distribution F(x) (003, Eqs. 25, 26, 34–37).
    pub fn cdf(&self, x: f64) -> f64 {
        self.cdf_point(x, ErfcFlavour::Accurate).cdf
    }

    /// The rod-length density P1(x) = 2x ∫_x^∞ P3 / ⟨D²⟩ (003, Eq. 18).
    pub fn density(&self, x: f64) -> f64 {
        self.cdf_point(x, ErfcFlavour::Accurate).density
    }

    /// F(x) and P1(x) together, with the erfc of the given flavour.
    ///
    /// For a lognormal component with u = ln(x/D0)/(σ√2) (003, Eqs. 20, 26):
    /// a·[⟨D²⟩·½erfc(√2σ − u) + x²·½erfc(u)] enters F·⟨D²⟩ and 2x·a·½erfc(u) enters
    /// P1·⟨D²⟩. The compat flavour writes the first term as ⟨D²⟩·½(2 − erfc(u − √2σ))
    /// like spherepack1d.
    pub fn cdf_point(&self, x: f64, flavour: ErfcFlavour) -> CdfPoint {
        if x.is_nan() {
            return CdfPoint {
                x,
                cdf: f64::NAN,
                density: f64::NAN,
            };
        }
        if x <= 0.0 {
            return CdfPoint {
                x,
                cdf: 0.0,
                density: 0.0,
            };
        }
        if x == f64::INFINITY {
            return CdfPoint {
                x,
                cdf: 1.0,
                density: 0.0,
            };
        }
        let x2 = x * x;
        let ln_x = x.ln();
        let mut f = 0.0;
        let mut p = 0.0;
        for c in &self.comps {
            match c.kind {
                Kind::Delta { d } => {
                    if d <= x {
                        f += c.weight * d * d;
                    } else {
                        f += c.weight * x2;
                        p += c.weight * 2.0 * x;
                    }
                }
                Kind::Lognormal {
                    ln_d0,
                    inv_s_sqrt2,
                    s_sqrt2,
                    mean_d2,
                } => {
                    let u = (ln_x - ln_d0) * inv_s_sqrt2;
                    let (lower, upper) = match flavour {
                        ErfcFlavour::Accurate => {
                            (0.5 * libm::erfc(s_sqrt2 - u), 0.5 * libm::erfc(u))
                        }
                        ErfcFlavour::AbramowitzStegun => (
                            0.5 * (2.0 - flavour.erfc(u - s_sqrt2)),
                            0.5 * flavour.erfc(u),
                        ),
                    };
                    f += c.weight * (mean_d2 * lower + x2 * upper);
                    p += c.weight * 2.0 * x * upper;
                }
            }
        }
        CdfPoint {
            x,
            cdf: f / self.norm,
            density: p / self.norm,
        }
    }

    /// F⁻¹(y) for one y in (0, 1), by bracketed Newton iteration.
    pub fn inverse_cdf(&self, y: f64, flavour: ErfcFlavour) -> f64 {
        if y.is_nan() || y <= 0.0 {
            return 0.0;
        }
        if y >= 1.0 {
            return self.upper_bracket(1.0 - f64::EPSILON, flavour);
        }
        let hi = self.upper_bracket(y, flavour);
        let mut last = self.cdf_point(hi, flavour);
        let guess = 0.5 * hi;
        self.solve(y, 0.0, hi, guess, flavour, &mut last)
    }

    /// F⁻¹(y) by 100 bisection steps on [0, 10·1.5^k], the smallest such interval with
    /// F(10·1.5^k) > y, as spherepack1d's `inverseF` does.
    pub fn inverse_cdf_bisection(&self, y: f64, flavour: ErfcFlavour) -> f64 {
        let mut lo = 0.0;
        let mut hi = 10.0;
        for _ in 0..4096 {
            if self.cdf_point(hi, flavour).cdf > y || hi >= f64::MAX {
                break;
            }
            hi *= 1.5;
        }
        let mut mid = 0.5 * (lo + hi);
        for _ in 0..100 {
            mid = 0.5 * (lo + hi);
            if self.cdf_point(mid, flavour).cdf > y {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        mid
    }

    /// Largest diameter scale of the components: a start for brackets.
    fn scale(&self) -> f64 {
        self.comps
            .iter()
            .map(|c| match c.kind {
                Kind::Delta { d } => d,
                Kind::Lognormal { ln_d0, .. } => ln_d0.exp(),
            })
            .fold(0.0, f64::max)
    }

    /// Some x with F(x) > y (for y < 1).
    fn upper_bracket(&self, y: f64, flavour: ErfcFlavour) -> f64 {
        let mut hi = self.scale().max(f64::MIN_POSITIVE);
        for _ in 0..4096 {
            if self.cdf_point(hi, flavour).cdf > y || hi == f64::MAX {
                break;
            }
            hi = (hi * 2.0).min(f64::MAX);
        }
        hi
    }

    /// Solves F(x) = y on [lo, hi] (F(lo) ≤ y ≤ F(hi)) by Newton steps with the known
    /// density, falling back to bisection when a step leaves the bracket. `last` holds the
    /// most recent evaluation on return (used to predict the next rod).
    fn solve(
        &self,
        y: f64,
        mut lo: f64,
        mut hi: f64,
        guess: f64,
        flavour: ErfcFlavour,
        last: &mut CdfPoint,
    ) -> f64 {
        let tol = match flavour {
            ErfcFlavour::Accurate => NEWTON_TOL,
            ErfcFlavour::AbramowitzStegun => NEWTON_TOL_COMPAT,
        };
        let mut x = if guess > lo && guess < hi {
            guess
        } else {
            midpoint(lo, hi)
        };
        for _ in 0..MAX_ITER {
            let pt = self.cdf_point(x, flavour);
            *last = pt;
            let r = pt.cdf - y;
            if r > 0.0 {
                hi = x;
            } else if r < 0.0 {
                lo = x;
            } else {
                return x;
            }
            let step = r / pt.density;
            let next = x - step;
            let next = if pt.density > 0.0 && next > lo && next < hi {
                if step.abs() <= tol * x {
                    return next;
                }
                next
            } else {
                midpoint(lo, hi)
            };
            if hi - lo <= 4.0 * f64::EPSILON * hi {
                return 0.5 * (lo + hi);
            }
            x = next;
        }
        x
    }

    /// The N rod lengths L_i = F⁻¹((2N − 2i + 1)/(2N)), i = 1..N, non-increasing
    /// (003, Eq. 24).
    ///
    /// Monodisperse mixtures are inverted in closed form on each quadratic piece of F;
    /// otherwise the targets are swept downwards, each solved by Newton's method with
    /// the density P1, started from a step off the previous rod and bracketed by it.
    /// With [`ErfcFlavour::AbramowitzStegun`] lognormal input is inverted by bisection
    /// exactly as spherepack1d does (slower, but the same digits).
    pub fn rod_lengths(&self, n: usize, flavour: ErfcFlavour) -> Result<Vec<f64>, RcpError> {
        if n < 2 {
            return Err(RcpError::TooFewRods { n });
        }
        let mut rods = Vec::with_capacity(n.min(1 << 24));
        self.for_each_rod(n, flavour, |l| rods.push(l));
        Ok(rods)
    }

    /// Calls `sink` with each rod length in turn, longest first, without storing them.
    pub fn for_each_rod(&self, n: usize, flavour: ErfcFlavour, mut sink: impl FnMut(f64)) {
        let nf = n as f64;
        let target = |i: usize| (2.0 * nf - 2.0 * i as f64 + 1.0) / (2.0 * nf);
        if let Some(t) = &self.deltas {
            // Piece k of F: x in [d_{k−1}, d_k], F = c_k + s_k x².
            let m = t.d.len();
            let mut k = m - 1;
            for i in 1..=n {
                let y = target(i);
                while k > 0 && y <= t.c[k] + t.s[k] * t.d[k - 1] * t.d[k - 1] {
                    k -= 1;
                }
                let lo = if k == 0 { 0.0 } else { t.d[k - 1] };
                let x = ((y - t.c[k]) / t.s[k]).max(0.0).sqrt();
                sink(x.clamp(lo, t.d[k]));
            }
            return;
        }
        if flavour == ErfcFlavour::AbramowitzStegun {
            // The A&S erfc makes F slightly non-monotone in its far tails (errors of
            // 1.5e-7 against values that are smaller), so F(x) = y can have several
            // roots there; spherepack1d's bisection picks one of them. To reproduce its
            // digits, compat mode inverts F the same way (100 halvings per rod).
            let mut replay = BisectionReplay::default();
            for i in 1..=n {
                sink(replay.solve(self, target(i), flavour));
            }
            return;
        }
        if self
            .comps
            .iter()
            .all(|c| matches!(c.kind, Kind::Lognormal { .. }))
        {
            self.for_each_rod_hermite(n, sink);
            return;
        }
        let mut hi = self.upper_bracket(target(1), flavour);
        let mut last = self.cdf_point(hi, flavour);
        for i in 1..=n {
            let y = target(i);
            let guess = if last.density > 0.0 {
                last.x - (last.cdf - y) / last.density
            } else {
                0.5 * hi
            };
            let x = self.solve(y, 0.0, hi, guess, flavour, &mut last);
            sink(x);
            hi = x;
        }
    }
}

impl SizeDistribution {
    /// P1(x) and P1′(x) for lognormal mixtures (accurate erfc):
    /// P1′ = P1/x − (2/⟨D²⟩)·Σ a_i e^(−u_i²)/(√π σ_i √2), from dS/dx of the survival
    /// S = ½erfc(u) in Eq. 18.
    fn density_and_slope(&self, x: f64) -> (f64, f64) {
        let ln_x = x.ln();
        let mut s = 0.0;
        let mut g = 0.0;
        for c in &self.comps {
            if let Kind::Lognormal {
                ln_d0, inv_s_sqrt2, ..
            } = c.kind
            {
                let u = (ln_x - ln_d0) * inv_s_sqrt2;
                s += c.weight * 0.5 * libm::erfc(u);
                g += c.weight * (-u * u).exp() * inv_s_sqrt2;
            }
        }
        let p = 2.0 * x * s / self.norm;
        (
            p,
            p / x - 2.0 * g / (std::f64::consts::PI.sqrt() * self.norm),
        )
    }

    /// Rods of a pure lognormal mixture (F analytic): the rods are solved exactly at
    /// the ends and the middle of blocks of consecutive rods; inside a block L(y) is the
    /// quintic Hermite interpolant of L, dL/dy = 1/P1 and d²L/dy² = −P1′/P1³ at the two
    /// ends. A block is accepted when the interpolant agrees with the solved middle rod
    /// to `HERMITE_TOL` (relative; the interpolation error, ∝ (t(1 − t))³, is largest
    /// there); blocks double while the error stays 64 times below it and halve
    /// otherwise; below 8 rods (the singular ends y → 0, 1) every rod is solved.
    fn for_each_rod_hermite(&self, n: usize, mut sink: impl FnMut(f64)) {
        let flavour = ErfcFlavour::Accurate;
        let nf = n as f64;
        let target = |i: usize| (2.0 * nf - 2.0 * i as f64 + 1.0) / (2.0 * nf);
        let hi = self.upper_bracket(target(1), flavour);
        let mut last = self.cdf_point(hi, flavour);
        let guess = last.x - (last.cdf - target(1)) / last.density;
        let mut l0 = self.solve(target(1), 0.0, hi, guess, flavour, &mut last);
        sink(l0);
        let mut k0 = self.density_and_slope(l0);
        let mut i0 = 1usize;
        let mut m = 16usize;
        while i0 < n {
            let y0 = target(i0);
            if m < 8 {
                // Solve the next few rods one by one.
                let i1 = (i0 + 8).min(n);
                for i in i0 + 1..=i1 {
                    let y = target(i);
                    let guess = last.x - (last.cdf - y) / last.density;
                    l0 = self.solve(y, 0.0, l0, guess, flavour, &mut last);
                    sink(l0);
                }
                i0 = i1;
                k0 = self.density_and_slope(l0);
                m = 16;
                continue;
            }
            let i1 = (i0 + m).min(n);
            let y1 = target(i1);
            let dy = y1 - y0;
            let (d0, s0) = (1.0 / k0.0, -k0.1 / (k0.0 * k0.0 * k0.0));
            let guess = l0 + d0 * dy + 0.5 * s0 * dy * dy;
            let l1 = self.solve(y1, 0.0, l0, guess, flavour, &mut last);
            let k1 = self.density_and_slope(l1);
            let (d1, s1) = (1.0 / k1.0, -k1.1 / (k1.0 * k1.0 * k1.0));
            let c = hermite5(l0, d0 * dy, s0 * dy * dy, l1, d1 * dy, s1 * dy * dy);
            let span = (i1 - i0) as f64;
            let im = i0 + (i1 - i0) / 2;
            let mut err = 0.0;
            let mut lm = l1;
            if im > i0 {
                let pm = horner(&c, (im - i0) as f64 / span);
                lm = self.solve(target(im), l1, l0, pm, flavour, &mut last);
                err = (pm - lm).abs() / lm;
            }
            if err.is_nan() || err > HERMITE_TOL || !c.iter().all(|v| v.is_finite()) {
                m /= 2;
                continue;
            }
            let mut prev = l0;
            for i in i0 + 1..=i1 {
                let v = if i == i1 {
                    l1
                } else if i == im {
                    lm
                } else {
                    horner(&c, (i - i0) as f64 / span)
                };
                let v = v.min(prev).max(l1);
                sink(v);
                prev = v;
            }
            i0 = i1;
            l0 = l1;
            k0 = k1;
            if err < HERMITE_TOL / 64.0 && m < (1 << 15) {
                m *= 2;
            }
        }
    }
}

/// spherepack1d's bisection (see [`SizeDistribution::inverse_cdf_bisection`]) with
/// the same result, computed with fewer evaluations of F: the bracket [0, 10·1.5^k] is
/// found from cached values F(10·1.5^j); the halvings of the previous target are
/// replayed from their cached F(mid) as long as they take the same decisions (nearby
/// targets share a long prefix); and the loop stops once mid equals an end of the
/// interval, after which the remaining halvings would not change it.
#[derive(Debug, Default)]
struct BisectionReplay {
    /// F(10·1.5^j), j = 0, 1, ...
    brackets: Vec<f64>,
    /// Upper end of the bracket of the cached path.
    top: f64,
    /// The cached path: (lo, hi, F(mid)) before each halving.
    path: Vec<(f64, f64, f64)>,
    /// The target of the cached path.
    y: f64,
}

impl BisectionReplay {
    fn solve(&mut self, dist: &SizeDistribution, y: f64, flavour: ErfcFlavour) -> f64 {
        let mut hi = 10.0;
        let mut j = 0;
        loop {
            if j == self.brackets.len() {
                self.brackets.push(dist.cdf_point(hi, flavour).cdf);
            }
            if self.brackets[j] > y || hi >= f64::MAX || j > 4096 {
                break;
            }
            hi *= 1.5;
            j += 1;
        }
        let mut lo = 0.0;
        let mut k = 0;
        if hi == self.top {
            // Replay the shared prefix.
            while k < self.path.len() {
                let (l, h, fm) = self.path[k];
                if (fm > y) != (fm > self.y) {
                    break;
                }
                let mid = 0.5 * (l + h);
                if fm > y {
                    hi = mid;
                } else {
                    lo = mid;
                }
                k += 1;
            }
            if k < self.path.len() {
                (lo, hi) = (self.path[k].0, self.path[k].1);
            }
        }
        self.path.truncate(k);
        let mut mid = 0.5 * (lo + hi);
        while k < 100 {
            mid = 0.5 * (lo + hi);
            if self.path.len() == k && k > 0 && (mid == lo || mid == hi) {
                // Fixed point: the remaining halvings keep lo, hi and mid.
                break;
            }
            let fm = dist.cdf_point(mid, flavour).cdf;
            self.path.push((lo, hi, fm));
            if fm > y {
                hi = mid;
            } else {
                lo = mid;
            }
            k += 1;
        }
        self.y = y;
        self.top = if self.path.is_empty() {
            f64::NAN
        } else {
            self.path[0].1
        };
        mid
    }
}

/// Coefficients (in t ∈ [0, 1]) of the quintic with values v0, v1, first derivatives
/// d0, d1 and second derivatives s0, s1 at t = 0, 1.
fn hermite5(v0: f64, d0: f64, s0: f64, v1: f64, d1: f64, s1: f64) -> [f64; 6] {
    [
        v0,
        d0,
        0.5 * s0,
        -10.0 * v0 - 6.0 * d0 - 1.5 * s0 + 0.5 * s1 - 4.0 * d1 + 10.0 * v1,
        15.0 * v0 + 8.0 * d0 + 1.5 * s0 - s1 + 7.0 * d1 - 15.0 * v1,
        -6.0 * v0 - 3.0 * d0 - 0.5 * s0 + 0.5 * s1 - 3.0 * d1 + 6.0 * v1,
    ]
}

#[inline]
fn horner(c: &[f64; 6], t: f64) -> f64 {
    ((((c[5] * t + c[4]) * t + c[3]) * t + c[2]) * t + c[1]) * t + c[0]
}

/// Relative accuracy of interpolated rods (see `for_each_rod_hermite`).
const HERMITE_TOL: f64 = 1e-13;
const NEWTON_TOL: f64 = 1e-8;
const NEWTON_TOL_COMPAT: f64 = 1e-12;
const MAX_ITER: usize = 400;

fn midpoint(lo: f64, hi: f64) -> f64 {
    if lo > 0.0 && hi > 4.0 * lo {
        (lo * hi).sqrt()
    } else if lo == 0.0 {
        0.5 * hi
    } else {
        0.5 * (lo + hi)
    }
}
