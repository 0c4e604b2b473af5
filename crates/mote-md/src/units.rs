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

    /// The label of the charge unit: C in SI; in reduced units the charge
    /// q* = q/√(4πε₀σε); in astronomical units the charge whose Coulomb
    /// energy k q²/r is in Msun AU²/d² for the scene's k.
    pub fn charge_label(self) -> &'static str {
        match self {
            UnitSystem::Si => "C",
            UnitSystem::Lj => "(4*pi*eps0*sigma*epsilon)^(1/2)",
            UnitSystem::Astro => "(Msun*AU^3/d^2/k)^(1/2)",
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

/// The units a file from another program is written in (LAMMPS's `units`
/// names), for `[[from_file]] units`: what one of its length, time, mass
/// and charge units is in SI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileUnits {
    Si,
    /// cm, s, g, statcoulomb.
    Cgs,
    /// Å, fs, g/mol, e.
    Real,
    /// Å, ps, g/mol, e.
    Metal,
    /// µm, µs, pg, pC.
    Micro,
    /// nm, ns, ag, e.
    Nano,
    /// Reduced units: taken as they are, into a scene in LJ units only.
    Lj,
}

/// What one unit of length, time, mass, charge and energy of a file is in
/// the scene's units. Energy is its own unit: LAMMPS's real (kcal/mol) and
/// metal (eV) units do not derive it from mass, length and time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    pub length: f64,
    pub time: f64,
    pub mass: f64,
    pub charge: f64,
    pub energy: f64,
}

impl Scales {
    /// A file in the scene's own units.
    pub const SAME: Scales = Scales {
        length: 1.0,
        time: 1.0,
        mass: 1.0,
        charge: 1.0,
        energy: 1.0,
    };
}

impl FileUnits {
    /// LAMMPS's name of a unit system.
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "si" => FileUnits::Si,
            "cgs" => FileUnits::Cgs,
            "real" => FileUnits::Real,
            "metal" => FileUnits::Metal,
            "micro" => FileUnits::Micro,
            "nano" => FileUnits::Nano,
            "lj" => FileUnits::Lj,
            _ => return None,
        })
    }

    /// The SI value of one unit of length, time, mass, charge and energy
    /// (CODATA 2018: e = 1.602176634e-19 C exactly, 1 g/mol per particle =
    /// 1.66053906660e-27 kg, 1 statC = 3.335640952e-10 C, 1 kcal/mol =
    /// 4184 J / N_A, 1 eV = e·1 V); `None` for LJ.
    pub fn si(self) -> Option<Scales> {
        const E: f64 = 1.602_176_634e-19;
        const DALTON: f64 = 1.660_539_066_60e-27;
        const KCAL_PER_MOL: f64 = 4184.0 / 6.022_140_76e23;
        let (length, time, mass, charge, energy) = match self {
            FileUnits::Si => (1.0, 1.0, 1.0, 1.0, 1.0),
            FileUnits::Cgs => (1e-2, 1.0, 1e-3, 3.335_640_952e-10, 1e-7),
            FileUnits::Real => (1e-10, 1e-15, DALTON, E, KCAL_PER_MOL),
            FileUnits::Metal => (1e-10, 1e-12, DALTON, E, E),
            FileUnits::Micro => (1e-6, 1e-6, 1e-15, 1e-12, 1e-15),
            FileUnits::Nano => (1e-9, 1e-9, 1e-21, E, 1e-21),
            FileUnits::Lj => return None,
        };
        Some(Scales {
            length,
            time,
            mass,
            charge,
            energy,
        })
    }

    /// What one unit of the file is in a scene's units: into an SI scene
    /// from any physical system, into an LJ scene from LJ only; the
    /// astronomical scene takes no files in other units (its charges have
    /// none).
    pub fn into(self, scene: UnitSystem) -> Result<Scales, String> {
        match (scene, self) {
            (UnitSystem::Lj, FileUnits::Lj) => Ok(Scales::SAME),
            (UnitSystem::Lj, _) | (UnitSystem::Si, FileUnits::Lj) => Err(
                "reduced (lj) units and physical units do not convert into each other: \
                 a scene in lj units takes files in lj units, an si scene files in physical units"
                    .into(),
            ),
            (UnitSystem::Si, physical) => Ok(physical.si().expect("physical units")),
            (UnitSystem::Astro, _) => Err(
                "a scene in astro units takes files in its own units: convert the file, or write the scene in si".into(),
            ),
        }
    }
}

#[cfg(test)]
mod file_units_tests {
    use super::*;

    /// An argon atom at 300 K in LAMMPS's real and metal units comes out
    /// the same in SI: 39.948 g/mol, a thermal speed of 0.002741 Å/fs =
    /// 2.741 Å/ps = 274.1 m/s.
    #[test]
    fn real_and_metal_agree_in_si() {
        let real = FileUnits::Real.into(UnitSystem::Si).unwrap();
        let metal = FileUnits::Metal.into(UnitSystem::Si).unwrap();
        let v_real = 0.002741 * real.length / real.time;
        let v_metal = 2.741 * metal.length / metal.time;
        assert!((v_real - 274.1).abs() < 1e-9 && (v_metal - 274.1).abs() < 1e-9);
        assert!((39.948 * real.mass - 6.6335e-26).abs() < 1e-29);
        assert_eq!(real.charge, metal.charge);
        // kcal/mol and eV: 1 eV = 23.0605 kcal/mol.
        assert!((metal.energy / real.energy - 23.060_548).abs() < 1e-5);
        // Where energy is derived (si, cgs, micro, nano) it is m l²/t².
        for units in [
            FileUnits::Si,
            FileUnits::Cgs,
            FileUnits::Micro,
            FileUnits::Nano,
        ] {
            let k = units.si().unwrap();
            let derived = k.mass * k.length * k.length / (k.time * k.time);
            assert!((k.energy / derived - 1.0).abs() < 1e-12, "{units:?}");
        }
        assert!(FileUnits::Real.into(UnitSystem::Lj).is_err());
        assert!(FileUnits::Lj.into(UnitSystem::Si).is_err());
        assert_eq!(FileUnits::Lj.into(UnitSystem::Lj).unwrap().length, 1.0);
        assert_eq!(FileUnits::named("metal"), Some(FileUnits::Metal));
        assert_eq!(FileUnits::named("imperial"), None);
    }
}
