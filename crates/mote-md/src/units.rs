//! Unit systems. Constants belong to the unit system, not to the code.

use serde::Deserialize;

/// The units a scene is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UnitSystem {
    /// SI: metre, second, kilogram.
    #[default]
    Si,
    /// Lennard-Jones reduced units: σ = ε = m = 1, and G = 1.
    Lj,
    /// Astronomical: AU, day, solar mass; G = k² with Gauss' constant
    /// k = 0.01720209895 AU^{3/2} day⁻¹ M☉^{-1/2} (002 Eq. 2).
    Astro,
}

/// Gauss' gravitational constant in AU^{3/2} / day (IAU 1976).
pub const GAUSS_K: f64 = 0.017_202_098_95;

impl UnitSystem {
    /// Newton's constant G in this unit system.
    pub fn gravitational_constant(self) -> f64 {
        match self {
            UnitSystem::Si => 6.674_30e-11,
            UnitSystem::Lj => 1.0,
            UnitSystem::Astro => GAUSS_K * GAUSS_K,
        }
    }

    /// Boltzmann's constant k_B in this unit system's energy per kelvin
    /// (reduced units: 1, temperatures are k_B T/ε).
    pub fn boltzmann(self) -> f64 {
        const K_B: f64 = 1.380_649e-23;
        match self {
            UnitSystem::Si => K_B,
            UnitSystem::Lj => 1.0,
            // J → M☉ AU² / day².
            UnitSystem::Astro => {
                K_B / (1.988_409_87e30 * 1.495_978_707e11f64.powi(2) / 86_400f64.powi(2))
            }
        }
    }

    /// Coulomb's constant k = 1/(4πε₀): 8.987 551 7923e9 N m² C⁻² in SI
    /// (CODATA 2018), 1 in reduced units (charges q* = q/√(4πε₀σε)); none
    /// in astronomical units, where a scene must give it.
    pub fn coulomb_constant(self) -> Option<f64> {
        match self {
            UnitSystem::Si => Some(8.987_551_792_3e9),
            UnitSystem::Lj => Some(1.0),
            UnitSystem::Astro => None,
        }
    }

    /// Unit labels for (length, time, mass, energy).
    pub fn labels(self) -> [&'static str; 4] {
        match self {
            UnitSystem::Si => ["m", "s", "kg", "J"],
            UnitSystem::Lj => ["sigma", "tau", "m", "epsilon"],
            UnitSystem::Astro => ["AU", "d", "Msun", "Msun*AU^2/d^2"],
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            UnitSystem::Si => "si",
            UnitSystem::Lj => "lj",
            UnitSystem::Astro => "astro",
        }
    }
}
