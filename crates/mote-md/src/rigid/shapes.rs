//! Generators of body shapes: dumbbells, linear trimers, and random
//! irregular clumps like the carrier beads of seed 000's SEM image.

use std::f64::consts::PI;

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::template::ClumpSpec;

fn spec(centres: Vec<DVec3>, radii: Vec<f64>, density: f64) -> ClumpSpec {
    ClumpSpec {
        centres,
        radii,
        density,
        youngs_modulus: 0.0,
        poisson_ratio: 0.0,
        charge: 0.0,
        dipole: DVec3::ZERO,
    }
}

/// Two spheres of radius `radius` with centres `distance` apart on the x axis.
pub fn dumbbell(radius: f64, distance: f64, density: f64) -> ClumpSpec {
    let h = 0.5 * distance;
    spec(
        vec![DVec3::new(-h, 0.0, 0.0), DVec3::new(h, 0.0, 0.0)],
        vec![radius; 2],
        density,
    )
}

/// Three equal spheres in a line along x, neighbours `distance` apart (the
/// linear trimer of LAMMPS's clump benchmark).
pub fn linear_trimer(radius: f64, distance: f64, density: f64) -> ClumpSpec {
    spec(
        vec![
            DVec3::new(-distance, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::new(distance, 0.0, 0.0),
        ],
        vec![radius; 3],
        density,
    )
}

/// Settings of a random irregular clump: a core sphere of radius `radius`
/// and `lobes` spheres with radii in `lobe_radius` (fractions of `radius`)
/// whose centres lie at `offset` (fraction of `radius`, a range) from the
/// core centre in random directions — the knobbly shape of a ferrite carrier
/// bead (seed 000, "SEM image of typical carrier particles").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IrregularClump {
    pub radius: f64,
    pub lobes: usize,
    pub lobe_radius: (f64, f64),
    pub offset: (f64, f64),
    pub density: f64,
}

impl Default for IrregularClump {
    fn default() -> Self {
        IrregularClump {
            radius: 1.0,
            lobes: 9,
            lobe_radius: (0.45, 0.7),
            offset: (0.35, 0.6),
            density: 1.0,
        }
    }
}

impl IrregularClump {
    /// The clump for `seed` (the same seed gives the same shape).
    pub fn generate(&self, seed: u64) -> ClumpSpec {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut centres = vec![DVec3::ZERO];
        let mut radii = vec![self.radius];
        for _ in 0..self.lobes {
            let z: f64 = rng.gen_range(-1.0..1.0);
            let p: f64 = rng.gen_range(0.0..2.0 * PI);
            let s = (1.0 - z * z).sqrt();
            let dir = DVec3::new(s * p.cos(), s * p.sin(), z);
            let d = self.radius * rng.gen_range(self.offset.0..=self.offset.1);
            centres.push(dir * d);
            radii.push(self.radius * rng.gen_range(self.lobe_radius.0..=self.lobe_radius.1));
        }
        spec(centres, radii, self.density)
    }
}
