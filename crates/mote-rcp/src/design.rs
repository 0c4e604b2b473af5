//! Inverse design (003, §V, Figs. 5–6): maximise the rod-packing estimate φ, or hit a
//! target φ, over the volume fractions and lognormal widths of given populations, and
//! scan φ over two parameters.
//!
//! Volume fractions are parametrised by stick breaking with squared sines,
//! w_k = sin²t_k·Π_{j<k} cos²t_j and w_p = Π_{j<p} cos²t_j, so that every point of the
//! simplex, its faces included, is reached by unconstrained parameters; widths by
//! σ = |t|. The search is Nelder–Mead (restarted once from its optimum), a
//! derivative-free method suited to φ, which is continuous but only piecewise smooth in
//! the parameters.

use std::fmt;
use std::str::FromStr;

use crate::distribution::{Population, SizeDistribution};
use crate::error::RcpError;
use crate::RodPacking;

/// A parameter of a list of populations (indices from 0; written from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// Occluded volume of population k (`vol1`, `vol2`, ...).
    Volume(usize),
    /// Diameter or d43 of population k (`d1`, ...).
    Diameter(usize),
    /// Log-width σ of lognormal population k (`sigma1`, ...).
    Sigma(usize),
}

impl FromStr for Param {
    type Err = RcpError;
    fn from_str(s: &str) -> Result<Self, RcpError> {
        let bad = || {
            RcpError::Design(format!(
                "unknown parameter '{s}': expected volK, dK or sigmaK with K the population number from 1"
            ))
        };
        let (name, num) = s
            .find(|c: char| c.is_ascii_digit())
            .map(|i| s.split_at(i))
            .ok_or_else(bad)?;
        let k: usize = num.parse().map_err(|_| bad())?;
        if k == 0 {
            return Err(bad());
        }
        match name {
            "vol" | "v" => Ok(Param::Volume(k - 1)),
            "d" | "d43" => Ok(Param::Diameter(k - 1)),
            "sigma" | "s" => Ok(Param::Sigma(k - 1)),
            _ => Err(bad()),
        }
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Param::Volume(k) => write!(f, "vol{}", k + 1),
            Param::Diameter(k) => write!(f, "d{}", k + 1),
            Param::Sigma(k) => write!(f, "sigma{}", k + 1),
        }
    }
}

impl Param {
    fn index(self) -> usize {
        match self {
            Param::Volume(k) | Param::Diameter(k) | Param::Sigma(k) => k,
        }
    }

    /// `pops` with this parameter set to `value`.
    pub fn apply(self, pops: &[Population], value: f64) -> Result<Vec<Population>, RcpError> {
        let k = self.index();
        if k >= pops.len() {
            return Err(RcpError::Design(format!(
                "parameter {self} names population {} but there are {}",
                k + 1,
                pops.len()
            )));
        }
        let mut out = pops.to_vec();
        out[k] = match (self, pops[k]) {
            (Param::Volume(_), p) => p.with_volume(value),
            (Param::Diameter(_), Population::Monodisperse { volume, .. }) => {
                Population::monodisperse(value, volume)
            }
            (Param::Diameter(_), Population::Lognormal { sigma, volume, .. }) => {
                Population::lognormal(value, sigma, volume)
            }
            (Param::Sigma(_), p) => Population::lognormal(p.d43(), value, p.volume()),
        };
        Ok(out)
    }
}

/// One axis of a scan: `count` values from `start` to `stop` inclusive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// What varies.
    pub param: Param,
    /// First value.
    pub start: f64,
    /// Last value.
    pub stop: f64,
    /// Number of values (≥ 1).
    pub count: usize,
}

impl Axis {
    /// The i-th value.
    pub fn value(&self, i: usize) -> f64 {
        if self.count <= 1 {
            self.start
        } else {
            self.start + (self.stop - self.start) * i as f64 / (self.count - 1) as f64
        }
    }
}

impl FromStr for Axis {
    type Err = RcpError;
    /// `PARAM=START:STOP:COUNT`, e.g. `d2=1:5:21`.
    fn from_str(s: &str) -> Result<Self, RcpError> {
        let bad = || {
            RcpError::Design(format!(
                "bad axis '{s}': expected PARAM=START:STOP:COUNT, e.g. d2=1:5:21"
            ))
        };
        let (p, range) = s.split_once('=').ok_or_else(bad)?;
        let param: Param = p.trim().parse()?;
        let parts: Vec<&str> = range.split(':').collect();
        if parts.len() != 3 {
            return Err(bad());
        }
        let start: f64 = parts[0].trim().parse().map_err(|_| bad())?;
        let stop: f64 = parts[1].trim().parse().map_err(|_| bad())?;
        let count: usize = parts[2].trim().parse().map_err(|_| bad())?;
        if count == 0 || !start.is_finite() || !stop.is_finite() {
            return Err(bad());
        }
        Ok(Axis {
            param,
            start,
            stop,
            count,
        })
    }
}

/// What to optimise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Objective {
    /// The largest φ.
    Maximise,
    /// φ as close as possible to the target.
    Target(f64),
}

/// Which parameters an optimisation varies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Search {
    /// Vary the volume fractions of all populations.
    pub volumes: bool,
    /// Vary the widths σ of all lognormal populations.
    pub widths: bool,
    /// Stop after this many evaluations of φ.
    pub max_evaluations: usize,
    /// Stop when the objective values of the simplex agree to this (absolute).
    pub tolerance: f64,
}

impl Default for Search {
    fn default() -> Self {
        Search {
            volumes: true,
            widths: false,
            max_evaluations: 600,
            tolerance: 1e-7,
        }
    }
}

/// The outcome of an optimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimum {
    /// The populations at the optimum (volumes normalised to fractions summing to 1
    /// when volumes were varied).
    pub populations: Vec<Population>,
    /// φ there.
    pub phi: f64,
    /// Number of evaluations of φ.
    pub evaluations: usize,
}

/// Maximises φ (or approaches a target) over the chosen parameters of `base`.
pub fn optimise(
    base: &[Population],
    estimator: &RodPacking,
    objective: Objective,
    search: &Search,
) -> Result<Optimum, RcpError> {
    SizeDistribution::new(base.iter().copied())?;
    let p = base.len();
    let lognormal: Vec<usize> = (0..p)
        .filter(|&k| matches!(base[k], Population::Lognormal { .. }))
        .collect();
    let nv = if search.volumes && p > 1 { p - 1 } else { 0 };
    let nw = if search.widths { lognormal.len() } else { 0 };
    if nv + nw == 0 {
        return Err(RcpError::Design(
            "nothing to vary: volumes need at least two populations, widths a lognormal one".into(),
        ));
    }
    // Start: the base volume fractions and widths.
    let total: f64 = base.iter().map(|q| q.volume()).sum();
    let fractions: Vec<f64> = base.iter().map(|q| q.volume() / total).collect();
    let mut x0 = if nv > 0 {
        stick_from_fractions(&fractions)
    } else {
        vec![]
    };
    x0.extend(lognormal.iter().take(nw).map(|&k| base[k].sigma()));
    let decode = |x: &[f64]| -> Vec<Population> {
        let mut pops = base.to_vec();
        if nv > 0 {
            for (q, w) in pops.iter_mut().zip(fractions_from_stick(&x[..nv])) {
                *q = q.with_volume(w);
            }
        }
        for (j, &k) in lognormal.iter().take(nw).enumerate() {
            let q = pops[k];
            pops[k] = Population::lognormal(q.d43(), x[nv + j].abs(), q.volume());
        }
        pops
    };
    let mut evaluations = 0usize;
    let mut phi_of = |x: &[f64]| -> f64 {
        evaluations += 1;
        SizeDistribution::new(decode(x))
            .and_then(|d| estimator.estimate(&d))
            .map(|pk| pk.phi)
            .unwrap_or(f64::NAN)
    };
    let cost = |phi: f64| -> f64 {
        if phi.is_nan() {
            return f64::INFINITY;
        }
        match objective {
            Objective::Maximise => -phi,
            Objective::Target(t) => (phi - t) * (phi - t),
        }
    };
    // Two rounds: a wide simplex, then a restart with a small one from its optimum.
    let mut best = x0;
    let mut best_cost = f64::INFINITY;
    let mut used = 0;
    for (round, step) in [0.35f64, 0.1].into_iter().enumerate() {
        let budget = if round == 0 {
            search.max_evaluations * 2 / 3
        } else {
            search.max_evaluations.saturating_sub(used)
        };
        let (x, c, n) = nelder_mead(&best, step, |x| cost(phi_of(x)), search.tolerance, budget);
        used += n;
        if c <= best_cost {
            best = x;
            best_cost = c;
        }
    }
    let pops = decode(&best);
    let phi = estimator
        .estimate(&SizeDistribution::new(pops.iter().copied())?)?
        .phi;
    evaluations += 1;
    Ok(Optimum {
        populations: pops,
        phi,
        evaluations,
    })
}

/// Volume fractions from stick-breaking angles (see the module documentation).
pub fn fractions_from_stick(t: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(t.len() + 1);
    let mut rest = 1.0;
    for &a in t {
        let s = a.sin() * a.sin();
        out.push(rest * s);
        rest *= 1.0 - s;
    }
    out.push(rest);
    out
}

/// Stick-breaking angles reproducing the given fractions (summing to 1).
pub fn stick_from_fractions(w: &[f64]) -> Vec<f64> {
    let mut t = Vec::with_capacity(w.len().saturating_sub(1));
    let mut rest = 1.0;
    for &wk in &w[..w.len() - 1] {
        let s = if rest > 0.0 {
            (wk / rest).clamp(0.0, 1.0)
        } else {
            0.0
        };
        t.push(s.sqrt().asin());
        rest -= wk;
    }
    t
}

/// Minimises `f` by Nelder–Mead from `x0` with initial step `step`; returns the best
/// point, its value and the number of evaluations (at most about `max_evals`).
pub fn nelder_mead(
    x0: &[f64],
    step: f64,
    mut f: impl FnMut(&[f64]) -> f64,
    tol: f64,
    max_evals: usize,
) -> (Vec<f64>, f64, usize) {
    let n = x0.len();
    let mut simplex: Vec<Vec<f64>> = vec![x0.to_vec()];
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step;
        simplex.push(x);
    }
    let mut vals: Vec<f64> = simplex.iter().map(|x| f(x)).collect();
    let mut evals = n + 1;
    let point = |c: &[f64], x: &[f64], t: f64| -> Vec<f64> {
        c.iter().zip(x).map(|(ci, xi)| ci + t * (xi - ci)).collect()
    };
    while evals < max_evals {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&a, &b| vals[a].total_cmp(&vals[b]));
        simplex = order.iter().map(|&i| simplex[i].clone()).collect();
        vals = order.iter().map(|&i| vals[i]).collect();
        let spread = (vals[n] - vals[0]).abs();
        let size = simplex[1..]
            .iter()
            .map(|x| {
                x.iter()
                    .zip(&simplex[0])
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        if spread <= tol && size <= 1e-4 {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|x| x[j]).sum::<f64>() / n as f64)
            .collect();
        let xr = point(&centroid, &simplex[n], -1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < vals[0] {
            let xe = point(&centroid, &simplex[n], -2.0);
            let fe = f(&xe);
            evals += 1;
            if fe < fr {
                simplex[n] = xe;
                vals[n] = fe;
            } else {
                simplex[n] = xr;
                vals[n] = fr;
            }
        } else if fr < vals[n - 1] {
            simplex[n] = xr;
            vals[n] = fr;
        } else {
            let (xc, fc) = if fr < vals[n] {
                let xc = point(&centroid, &xr, 0.5);
                let fc = f(&xc);
                (xc, fc)
            } else {
                let xc = point(&centroid, &simplex[n], 0.5);
                let fc = f(&xc);
                (xc, fc)
            };
            evals += 1;
            if fc < vals[n].min(fr) {
                simplex[n] = xc;
                vals[n] = fc;
            } else {
                for i in 1..=n {
                    simplex[i] = point(&simplex[0], &simplex[i], 0.5);
                    vals[i] = f(&simplex[i]);
                    evals += 1;
                }
            }
        }
    }
    let best = (0..=n)
        .min_by(|&a, &b| vals[a].total_cmp(&vals[b]))
        .unwrap_or(0);
    (simplex[best].clone(), vals[best], evals)
}

/// Largest number of grid points of a scan.
pub const MAX_SCAN_POINTS: usize = 10_000_000;

/// A two-parameter scan: φ on a grid, row by row (y outer, x inner).
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// The x axis.
    pub x: Axis,
    /// The y axis.
    pub y: Axis,
    /// φ at (x_i, y_j), index j·x.count + i (NaN where the point is invalid).
    pub phi: Vec<f64>,
    /// With an inner optimisation: the optimal volume fractions at each point.
    pub fractions: Vec<Vec<f64>>,
    /// Evaluations of φ in all.
    pub evaluations: usize,
}

/// Scans φ over two parameters of `base`; with `inner`, each point is an optimisation
/// over the volume fractions (003, Fig. 6). Points are evaluated in parallel on the
/// rayon pool (the result does not depend on the number of threads);
/// `progress(points_done)` is called after each point.
pub fn scan(
    base: &[Population],
    estimator: &RodPacking,
    x: Axis,
    y: Axis,
    inner: Option<&Search>,
    progress: impl Fn(usize) + Sync,
) -> Result<Scan, RcpError> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    SizeDistribution::new(base.iter().copied())?;
    x.param.apply(base, x.start)?;
    y.param.apply(base, y.start)?;
    let points = x
        .count
        .checked_mul(y.count)
        .filter(|&p| p <= MAX_SCAN_POINTS);
    let Some(points) = points else {
        return Err(RcpError::Design(format!(
            "{} × {} points is too many for a scan (at most {MAX_SCAN_POINTS})",
            x.count, y.count
        )));
    };
    let done = AtomicUsize::new(0);
    let points: Vec<(f64, Option<Vec<f64>>, usize)> = (0..points)
        .into_par_iter()
        .map(|idx| {
            let (i, j) = (idx % x.count, idx / x.count);
            let pops = x
                .param
                .apply(base, x.value(i))
                .and_then(|p| y.param.apply(&p, y.value(j)))
                .expect("indices checked above");
            let out = match inner {
                None => (
                    SizeDistribution::new(pops)
                        .and_then(|d| estimator.estimate(&d))
                        .map(|p| p.phi)
                        .unwrap_or(f64::NAN),
                    None,
                    1,
                ),
                Some(search) => match optimise(&pops, estimator, Objective::Maximise, search) {
                    Ok(opt) => {
                        let total: f64 = opt.populations.iter().map(|q| q.volume()).sum();
                        let w = opt.populations.iter().map(|q| q.volume() / total).collect();
                        (opt.phi, Some(w), opt.evaluations)
                    }
                    Err(_) => (f64::NAN, Some(vec![f64::NAN; pops.len()]), 0),
                },
            };
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
            out
        })
        .collect();
    let evaluations = points.iter().map(|p| p.2).sum();
    let phi = points.iter().map(|p| p.0).collect();
    let fractions = points.into_iter().filter_map(|p| p.1).collect();
    Ok(Scan {
        x,
        y,
        phi,
        fractions,
        evaluations,
    })
}

impl Scan {
    /// The scan as CSV: a header line, then `x,y,phi` (and `w1..wp` with an inner
    /// optimisation) for each point.
    pub fn to_csv(&self) -> String {
        let mut s = format!("{},{},phi", self.x.param, self.y.param);
        let p = self.fractions.first().map_or(0, Vec::len);
        for k in 1..=p {
            s.push_str(&format!(",w{k}"));
        }
        s.push('\n');
        for j in 0..self.y.count {
            for i in 0..self.x.count {
                let idx = j * self.x.count + i;
                s.push_str(&format!(
                    "{},{},{:.6}",
                    self.x.value(i),
                    self.y.value(j),
                    self.phi[idx]
                ));
                if let Some(w) = self.fractions.get(idx) {
                    for v in w {
                        s.push_str(&format!(",{v:.6}"));
                    }
                }
                s.push('\n');
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stick_breaking_round_trip() {
        let w = [0.2, 0.5, 0.3];
        let back = fractions_from_stick(&stick_from_fractions(&w));
        for (a, b) in w.iter().zip(&back) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn nelder_mead_finds_a_quadratic_minimum() {
        let (x, v, _) = nelder_mead(
            &[0.0, 0.0],
            0.5,
            |x| (x[0] - 1.0).powi(2) + 3.0 * (x[1] + 0.5).powi(2),
            1e-14,
            2000,
        );
        assert!((x[0] - 1.0).abs() < 1e-4 && (x[1] + 0.5).abs() < 1e-4 && v < 1e-8);
    }

    #[test]
    fn params_parse() {
        assert_eq!("vol2".parse::<Param>().unwrap(), Param::Volume(1));
        assert_eq!("sigma1".parse::<Param>().unwrap(), Param::Sigma(0));
        assert!("x3".parse::<Param>().is_err());
        assert!("d0".parse::<Param>().is_err());
        let a: Axis = "d2=1:5:21".parse().unwrap();
        assert_eq!(a.count, 21);
        assert!((a.value(20) - 5.0).abs() < 1e-15);
    }
}
