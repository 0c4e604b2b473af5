//! Size distributions as users name them (`mote pack`'s `--dist`, a
//! scene's `sizes`): one diameter, two, or a lognormal, up to a common
//! scale; packings draw a whole set, inserters one particle at a time.

use crate::{Population, SizeDistribution};

/// A size distribution of spheres (diameters up to a common scale).
#[derive(Debug, Clone, PartialEq)]
pub enum SizeSpec {
    /// All diameters equal.
    Monodisperse,
    /// Two sizes: diameter ratio large/small ≥ 1 and the number fraction of
    /// the large ones.
    Bidisperse { ratio: f64, large_fraction: f64 },
    /// Lognormal number distribution of log-width σ (003 Eq. 10; the same
    /// [`Population::Lognormal`] that `mote rcp` estimates).
    Lognormal { sigma: f64 },
    /// Given radii (their number fixes N).
    Radii(Vec<f64>),
}

impl SizeSpec {
    /// The names [`SizeSpec::parse`] takes, for messages.
    pub const NAMES: &'static str = "mono, bi:RATIO:FRACTION or lognormal:SIGMA";

    /// Parses `mono`, `bi:RATIO:FRACTION` (number fraction of the large),
    /// `lognormal:SIGMA`; radii files are read by the caller.
    pub fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let num = |s: &str, what: &str| -> Result<f64, String> {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{what} `{s}` is not a number"))
        };
        match parts.as_slice() {
            ["mono"] | ["monodisperse"] => Ok(SizeSpec::Monodisperse),
            ["bi", ratio, frac] | ["bidisperse", ratio, frac] => {
                let ratio = num(ratio, "diameter ratio")?;
                let large_fraction = num(frac, "number fraction")?;
                if ratio < 1.0 {
                    return Err(format!("diameter ratio {ratio} must be ≥ 1 (large/small)"));
                }
                if !(0.0..=1.0).contains(&large_fraction) {
                    return Err(format!(
                        "number fraction {large_fraction} of the large particles must lie in [0, 1]"
                    ));
                }
                Ok(SizeSpec::Bidisperse {
                    ratio,
                    large_fraction,
                })
            }
            ["lognormal", sigma] | ["logn", sigma] => {
                let sigma = num(sigma, "lognormal width σ")?;
                if !(0.0..=2.0).contains(&sigma) {
                    return Err(format!("lognormal width σ = {sigma} must lie in [0, 2]"));
                }
                Ok(SizeSpec::Lognormal { sigma })
            }
            _ => Err(format!(
                "unknown size distribution `{text}`: use mono, bi:RATIO:FRACTION, lognormal:SIGMA or file:PATH"
            )),
        }
    }

    /// One diameter drawn from the distribution, from a uniform number
    /// `u` in [0, 1) and a standard normal one `z` (each used where the
    /// distribution needs it): 1 or the ratio with the large fraction's
    /// probability; the lognormal's D₀ e^{σz} with the number median
    /// D₀ = d₄₃ e^{−7σ²/2}, d₄₃ = 1 (003 Eqs. 11–12); given radii in turn by
    /// u. Independent draws of a stream, where a packing draws its set
    /// with exact counts.
    pub fn draw(&self, u: f64, z: f64) -> f64 {
        match self {
            SizeSpec::Monodisperse => 1.0,
            SizeSpec::Bidisperse {
                ratio,
                large_fraction,
            } => {
                if u < *large_fraction {
                    *ratio
                } else {
                    1.0
                }
            }
            SizeSpec::Lognormal { sigma } => (-3.5 * sigma * sigma).exp() * (sigma * z).exp(),
            SizeSpec::Radii(r) => 2.0 * r[((u * r.len() as f64) as usize).min(r.len() - 1)],
        }
    }

    /// The same distribution as `mote rcp` describes it (occluded volumes
    /// from number fractions, 003 Eqs. 15–16), for its RCP estimate; `None`
    /// for a file of radii.
    pub fn rcp_distribution(&self) -> Option<SizeDistribution> {
        let pops = match self {
            SizeSpec::Monodisperse => vec![Population::monodisperse(1.0, 1.0)],
            SizeSpec::Bidisperse {
                ratio,
                large_fraction,
            } => vec![
                Population::monodisperse(1.0, 1.0 - large_fraction),
                Population::monodisperse(*ratio, large_fraction * ratio.powi(3)),
            ],
            SizeSpec::Lognormal { sigma } => vec![Population::lognormal(1.0, *sigma, 1.0)],
            SizeSpec::Radii(_) => return None,
        };
        SizeDistribution::new(pops).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_follow_the_named_distribution() {
        let bi = SizeSpec::parse("bi:1.4:0.25").unwrap();
        assert_eq!(bi.draw(0.2, 0.0), 1.4);
        assert_eq!(bi.draw(0.3, 0.0), 1.0);
        let logn = SizeSpec::parse("lognormal:0.2").unwrap();
        // The number median at z = 0; one σ up multiplies by e^σ.
        let median = (-3.5f64 * 0.04).exp();
        assert_eq!(logn.draw(0.5, 0.0), median);
        assert!((logn.draw(0.5, 1.0) / median - 0.2f64.exp()).abs() < 1e-15);
        assert!(SizeSpec::parse("bi:0.5:0.5").is_err());
        assert!(SizeSpec::parse("lognormal:x").is_err());
    }
}
