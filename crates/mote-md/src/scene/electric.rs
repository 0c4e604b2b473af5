//! `[coulomb]`: forces between the particles' charges, by direct summation
//! or a Barnes–Hut tree in open space, by Ewald summation in a cubic
//! periodic box, or by P3M (particle–particle particle–mesh) in any
//! orthorhombic periodic box; `[electric_field]`: a uniform field
//! E(t) = E₀ cos(ωt + φ).

use std::ops::Range;

use glam::DVec3;
use serde::Deserialize;

use mote_io::{ParseError, Source};

use super::gravity::direct;
use super::{Build, Scene, Section};
use crate::boundary::Boundary;
use crate::force::ewald::EwaldCoulomb;
use crate::force::p3m::{self, P3mCoulomb};
use crate::force::{DirectCoulomb, ElectricField};
use crate::tree::TreeCoulomb;

/// `[coulomb]`: Coulomb's law between every pair of charged particles.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoulombSettings {
    /// Coulomb's constant 1/(4πε₀); default: the unit system's (1 in LJ units).
    pub k: Option<f64>,
    /// `direct` (default: every pair, open space), `tree` (Barnes–Hut with
    /// multipoles to quadrupole, open space), `ewald` (cubic periodic box,
    /// tin-foil boundaries) or `p3m` (the Ewald sum's k-space part on a
    /// mesh: any orthorhombic periodic box, O(N log N)).
    #[serde(default = "direct")]
    pub method: String,
    /// Softening length ε of `direct` and `tree` (default 0).
    pub softening: Option<f64>,
    /// Opening angle θ of the tree (default 0.5).
    pub theta: Option<f64>,
    /// The real-space cut-off (Ewald: default half the box side; P3M:
    /// tuned when not given).
    pub cutoff: Option<f64>,
    /// Ewald and P3M: the RMS force error aimed at, in force units (Kolafa
    /// & Perram 1992 choose α and the k-vectors from it; for P3M, Deserno
    /// & Holm 1998 the mesh).
    pub accuracy: Option<f64>,
    /// P3M: the Verlet skin of the real-space list (default a tenth of the
    /// cut-off given, else 0.3 mean particle spacings, at most a tenth of the shortest side).
    pub skin: Option<f64>,
    /// P3M: mesh points along each axis (default: tuned).
    pub mesh: Option<[usize; 3]>,
    /// P3M: charge-assignment order 1–7 (default: tuned, 3–7).
    pub order: Option<usize>,
}

/// The Coulomb law a `[coulomb]` table chooses.
#[derive(Debug)]
pub enum CoulombLaw {
    Direct(DirectCoulomb),
    Tree(TreeCoulomb),
    Ewald(EwaldCoulomb),
    P3m(Box<P3mCoulomb>),
}

impl Section for CoulombSettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let law = self.law(
            span,
            b.src,
            scene.units.coulomb_constant(),
            &b.particles.charge,
            b.boundary,
        )?;
        match law {
            CoulombLaw::Direct(c) => b.forces.push(c),
            CoulombLaw::Tree(c) => b.forces.push(c),
            CoulombLaw::Ewald(c) => b.forces.push(c),
            CoulombLaw::P3m(c) => b.forces.push(*c),
        }
        Ok(())
    }
}

impl CoulombSettings {
    /// The law of this table between point charges `charge` in `boundary`
    /// (point particles, or the centres of rigid bodies), `k` the unit
    /// system's where the table gives none; errors at the table's line.
    pub fn law(
        &self,
        span: Range<usize>,
        src: Source,
        units_k: Option<f64>,
        charge: &[f64],
        boundary: Boundary,
    ) -> Result<CoulombLaw, ParseError> {
        let err = |msg: String| src.error(span.clone(), msg);
        let k = match self.k.or(units_k) {
            Some(k) => positive(src, span.clone(), "[coulomb] k", k)?,
            None => return Err(err("[coulomb] needs k = 1/(4πε₀) in these units".into())),
        };
        if charge.iter().all(|q| *q == 0.0) {
            return Err(err(
                "[coulomb] no particle has a charge: give the particles `charge = ...`".into(),
            ));
        }
        if let Some(q) = charge.iter().find(|q| !q.is_finite()) {
            return Err(err(format!(
                "[coulomb] every charge must be finite, found {q}"
            )));
        }
        let open = |method: &str| {
            if boundary.periodic.iter().any(|p| *p) {
                Err(err(format!(
                    "[coulomb] method = \"{method}\" sums over open space: a periodic box needs method = \"ewald\""
                )))
            } else {
                Ok(())
            }
        };
        let refuse = |key: &str, given: bool, method: &str| {
            if given {
                Err(err(format!(
                    "[coulomb] {key} does not apply to method = \"{method}\""
                )))
            } else {
                Ok(())
            }
        };
        if matches!(self.method.as_str(), "direct" | "tree" | "ewald") {
            for (key, given) in [
                ("skin", self.skin.is_some()),
                ("mesh", self.mesh.is_some()),
                ("order", self.order.is_some()),
            ] {
                refuse(key, given, &self.method)?;
            }
        }
        let softening = self.softening.unwrap_or(0.0);
        if softening.is_nan() || softening < 0.0 {
            return Err(err(format!(
                "[coulomb] softening must not be negative, found {softening}"
            )));
        }
        Ok(match self.method.as_str() {
            "direct" => {
                open("direct")?;
                refuse("theta", self.theta.is_some(), "direct")?;
                refuse("cutoff", self.cutoff.is_some(), "direct")?;
                refuse("accuracy", self.accuracy.is_some(), "direct")?;
                CoulombLaw::Direct(DirectCoulomb::new(k, softening))
            }
            "tree" => {
                open("tree")?;
                refuse("cutoff", self.cutoff.is_some(), "tree")?;
                refuse("accuracy", self.accuracy.is_some(), "tree")?;
                let theta = self.theta.unwrap_or(0.5);
                if !(0.0..1.2).contains(&theta) {
                    return Err(err(format!(
                        "[coulomb] theta must be in [0, 1.2), found {theta}"
                    )));
                }
                CoulombLaw::Tree(TreeCoulomb::new(k, softening, theta))
            }
            "ewald" => {
                refuse("softening", self.softening.is_some(), "ewald")?;
                refuse("theta", self.theta.is_some(), "ewald")?;
                let l = ewald_box(src, span.clone(), boundary, "coulomb")?;
                let rc = positive(
                    src,
                    span.clone(),
                    "[coulomb] cutoff",
                    self.cutoff.unwrap_or(0.5 * l),
                )?;
                if rc > 0.5 * l {
                    return Err(err(format!(
                        "[coulomb] the Ewald cut-off {rc} must be at most half the box side {l}"
                    )));
                }
                let accuracy = self.accuracy.ok_or_else(|| {
                    err("[coulomb] method = \"ewald\" needs accuracy = the RMS force error aimed at (force units)".into())
                })?;
                positive(src, span.clone(), "[coulomb] accuracy", accuracy)?;
                CoulombLaw::Ewald(EwaldCoulomb::new(k, charge, l, rc, accuracy))
            }
            "p3m" => {
                refuse("softening", self.softening.is_some(), "p3m")?;
                refuse("theta", self.theta.is_some(), "p3m")?;
                CoulombLaw::P3m(Box::new(self.p3m(span, src, k, charge, boundary)?))
            }
            other => {
                return Err(err(format!(
                    "[coulomb] unknown method '{other}': expected direct, tree, ewald or p3m"
                )))
            }
        })
    }
}

impl CoulombSettings {
    /// P3M tuned for this table's accuracy, with its fixed choices.
    fn p3m(
        &self,
        span: Range<usize>,
        src: Source,
        k: f64,
        charge: &[f64],
        boundary: Boundary,
    ) -> Result<P3mCoulomb, ParseError> {
        let keys = P3mKeys {
            accuracy: self.accuracy,
            cutoff: self.cutoff,
            skin: self.skin,
            mesh: self.mesh,
            order: self.order,
        };
        let request = keys.request("coulomb", span.clone(), src, charge.len(), boundary)?;
        P3mCoulomb::tuned(k, &request, charge, &boundary)
            .map_err(|e| src.error(span, format!("[coulomb] {e}")))
    }
}

/// The keys of a P3M table (`[coulomb]` or `[dipolar]` with
/// method = "p3m").
pub(crate) struct P3mKeys {
    pub accuracy: Option<f64>,
    pub cutoff: Option<f64>,
    pub skin: Option<f64>,
    pub mesh: Option<[usize; 3]>,
    pub order: Option<usize>,
}

impl P3mKeys {
    /// What tuning is asked for `n` sources in `boundary`, or why the
    /// table cannot be run, at the table.
    pub(crate) fn request(
        &self,
        table: &str,
        span: Range<usize>,
        src: Source,
        n: usize,
        boundary: Boundary,
    ) -> Result<p3m::Request, ParseError> {
        self.check(table, "cutoff", n, boundary)
            .map_err(|m| src.error(span, m))
    }

    /// What tuning is asked for `n` sources in `boundary`, or why the
    /// table cannot be run; the cut-off is the key `cutoff_key`.
    pub(crate) fn check(
        &self,
        table: &str,
        cutoff_key: &str,
        n: usize,
        boundary: Boundary,
    ) -> Result<p3m::Request, String> {
        let err = |msg: String| msg;
        let l = boundary.lengths();
        if boundary.periodic != [true; 3] || !(l.min_element() > 0.0 && l.max_element().is_finite())
        {
            return Err(err(format!(
                "[{table}] method = \"p3m\" needs a [box] periodic on every axis"
            )));
        }
        let accuracy = self.accuracy.ok_or_else(|| {
            err(format!("[{table}] method = \"p3m\" needs accuracy = the RMS force error aimed at (force units)"))
        })?;
        let positive = |what: String, value: f64| {
            if value > 0.0 && value.is_finite() {
                Ok(value)
            } else {
                Err(format!("{what} must be positive, found {value}"))
            }
        };
        positive(format!("[{table}] accuracy"), accuracy)?;
        let cutoff = match self.cutoff {
            Some(rc) => Some(positive(format!("[{table}] {cutoff_key}"), rc)?),
            None => None,
        };
        let skin = match (self.skin, cutoff) {
            (Some(s), _) => {
                if !(s >= 0.0 && s.is_finite()) {
                    return Err(err(format!(
                        "[{table}] skin must not be negative, found {s}"
                    )));
                }
                s
            }
            (None, Some(rc)) => 0.1 * rc,
            // A tenth of the cut-off tuning is likely to choose: three
            // particle spacings; with few sources in the box (a spacing
            // past the box), a tenth of the largest cut-off it allows.
            (None, None) => {
                (0.3 * (l.element_product() / n.max(1) as f64).cbrt()).min(0.1 * l.min_element())
            }
        };
        if let Some(rc) = cutoff {
            if rc + skin > 0.5 * l.min_element() {
                return Err(err(format!(
                    "[{table}] {cutoff_key} + skin = {} must be at most half the shortest box side, {}",
                    rc + skin,
                    0.5 * l.min_element()
                )));
            }
        }
        if let Some(p) = self.order {
            if !(1..=p3m::spline::MAX_ORDER).contains(&p) {
                return Err(err(format!(
                    "[{table}] order must be 1 to {}, found {p}",
                    p3m::spline::MAX_ORDER
                )));
            }
        }
        if let Some(mesh) = self.mesh {
            let least = self.order.unwrap_or(1).max(2);
            if mesh.iter().any(|&m| m < least || m > 4096) {
                return Err(err(format!(
                    "[{table}] mesh {mesh:?}: every side must be {least} to 4096 points (at least the order)"
                )));
            }
        }
        Ok(p3m::Request {
            accuracy,
            cutoff,
            skin,
            mesh: self.mesh,
            order: self.order,
        })
    }
}

/// `[electric_field]`: E(t) = e cos(ωt + φ) on every charge (constant by default).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElectricFieldSettings {
    /// The field E₀ (force per charge).
    pub e: [f64; 3],
    /// Angular frequency ω in rad per time (default 0: constant).
    #[serde(default)]
    pub angular_frequency: f64,
    /// Phase φ (default 0).
    #[serde(default)]
    pub phase: f64,
}

impl Section for ElectricFieldSettings {
    fn add_to(&self, span: Range<usize>, _: &Scene, b: &mut Build) -> Result<(), ParseError> {
        if self
            .e
            .iter()
            .chain([&self.angular_frequency, &self.phase])
            .any(|x| !x.is_finite())
        {
            return Err(b.src.error(
                span,
                "[electric_field] e, angular_frequency and phase must be finite",
            ));
        }
        b.forces.push(ElectricField {
            amplitude: DVec3::from(self.e),
            angular_frequency: self.angular_frequency,
            phase: self.phase,
        });
        Ok(())
    }
}

/// The side L of the cubic periodic box Ewald sums need, or why there is none.
pub(crate) fn ewald_box(
    src: Source,
    span: Range<usize>,
    boundary: Boundary,
    table: &str,
) -> Result<f64, ParseError> {
    let l = boundary.lengths();
    let cubic = (l.x - l.y).abs() <= 1e-12 * l.x && (l.x - l.z).abs() <= 1e-12 * l.x;
    if boundary.periodic != [true; 3] || !cubic || !(l.x > 0.0 && l.x.is_finite()) {
        return Err(src.error(
            span,
            format!("[{table}] method = \"ewald\" needs a cubic [box] periodic on every axis"),
        ));
    }
    Ok(l.x)
}

/// `value` if it is positive and finite, else `file:line: what must be positive`.
pub(crate) fn positive(
    src: Source,
    span: Range<usize>,
    what: &str,
    value: f64,
) -> Result<f64, ParseError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(src.error(span, format!("{what} must be positive, found {value}")))
    }
}
