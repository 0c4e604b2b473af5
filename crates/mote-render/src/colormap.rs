//! Colour maps for per-particle quantities, and a palette for categories.

use crate::scene::Rgb;

/// A continuous colour map from 0..=1 to colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColorMap {
    /// Perceptually uniform, colour-blind safe (matplotlib's viridis, sampled at 9 points).
    Viridis,
    /// Blue – white – red, for signed quantities such as a velocity component.
    CoolWarm,
    /// Black – red – yellow – white.
    Heat,
}

const VIRIDIS: [Rgb; 9] = [
    [0.267, 0.005, 0.329],
    [0.283, 0.141, 0.458],
    [0.254, 0.265, 0.530],
    [0.207, 0.372, 0.553],
    [0.164, 0.471, 0.558],
    [0.128, 0.567, 0.551],
    [0.135, 0.659, 0.518],
    [0.478, 0.821, 0.3181],
    [0.993, 0.906, 0.144],
];
const COOLWARM: [Rgb; 5] = [
    [0.230, 0.299, 0.754],
    [0.552, 0.690, 0.996],
    [0.866, 0.866, 0.866],
    [0.958, 0.604, 0.482],
    [0.706, 0.016, 0.150],
];
const HEAT: [Rgb; 4] = [
    [0.05, 0.0, 0.0],
    [0.85, 0.1, 0.0],
    [1.0, 0.85, 0.1],
    [1.0, 1.0, 1.0],
];

impl ColorMap {
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "viridis" => Some(Self::Viridis),
            "coolwarm" => Some(Self::CoolWarm),
            "heat" => Some(Self::Heat),
            _ => None,
        }
    }

    /// The colour at `s` (clamped to 0..=1; NaN gives grey).
    pub fn at(&self, s: f32) -> Rgb {
        if s.is_nan() {
            return [0.5, 0.5, 0.5];
        }
        let table: &[Rgb] = match self {
            Self::Viridis => &VIRIDIS,
            Self::CoolWarm => &COOLWARM,
            Self::Heat => &HEAT,
        };
        let x = s.clamp(0.0, 1.0) * (table.len() - 1) as f32;
        let i = (x as usize).min(table.len() - 2);
        let f = x - i as f32;
        std::array::from_fn(|c| table[i][c] * (1.0 - f) + table[i + 1][c] * f)
    }
}

/// A fixed palette for categories (species, clump ids): distinct, colour-blind
/// friendly (Okabe & Ito, 2008), repeated when there are more categories.
pub fn category_color(k: usize) -> Rgb {
    const OKABE_ITO: [Rgb; 8] = [
        [0.902, 0.624, 0.0],
        [0.337, 0.706, 0.914],
        [0.0, 0.620, 0.451],
        [0.941, 0.894, 0.259],
        [0.0, 0.447, 0.698],
        [0.835, 0.369, 0.0],
        [0.800, 0.475, 0.655],
        [0.6, 0.6, 0.6],
    ];
    OKABE_ITO[k % OKABE_ITO.len()]
}

/// The range of finite values of `q` (min, max); (0, 1) if there are none, and
/// widened symmetrically when all values are equal.
pub fn finite_range(q: &[f64]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in q.iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if lo == hi {
        let w = if lo == 0.0 { 1.0 } else { lo.abs() * 1e-3 };
        return (lo - w, hi + w);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_hit_their_end_points_and_clamp() {
        assert_eq!(ColorMap::Viridis.at(0.0), VIRIDIS[0]);
        assert_eq!(ColorMap::Viridis.at(1.0), VIRIDIS[8]);
        assert_eq!(ColorMap::Viridis.at(7.0), VIRIDIS[8]);
        assert_eq!(ColorMap::CoolWarm.at(0.5), COOLWARM[2]);
        assert_eq!(finite_range(&[2.0, f64::NAN, -1.0]), (-1.0, 2.0));
        assert_eq!(finite_range(&[]), (0.0, 1.0));
    }
}
