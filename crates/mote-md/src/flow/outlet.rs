//! Removal of particles that reach an outlet (LAMMPS `fix evaporate`,
//! LIGGGHTS' outlets): a region, or a face crossed.

use glam::DVec3;

use super::Region;

/// Where particles leave.
#[derive(Debug, Clone, PartialEq)]
pub enum Exit {
    /// Particles whose centres lie in the region.
    Region(Region),
    /// Particles whose centres have crossed the plane through `point`
    /// along its unit `normal`: (x − point)·n > 0.
    Face { point: DVec3, normal: DVec3 },
}

/// An outlet and what has left through it.
#[derive(Debug, Clone)]
pub struct Outlet {
    pub name: String,
    pub exit: Exit,
    /// Particles, mass and charge taken out so far.
    pub removed: u64,
    pub mass: f64,
    pub charge: f64,
}

impl Outlet {
    /// An outlet with nothing taken out yet.
    pub fn new(name: &str, exit: Exit) -> Self {
        Self {
            name: name.to_string(),
            exit,
            removed: 0,
            mass: 0.0,
            charge: 0.0,
        }
    }

    /// Whether a particle at `x` (wrapped into the box) leaves here.
    pub fn takes(&self, x: DVec3) -> bool {
        match &self.exit {
            Exit::Region(region) => region.contains(x),
            Exit::Face { point, normal } => (x - *point).dot(*normal) > 0.0,
        }
    }
}

/// The first outlet that takes a particle at `x` (wrapped into the box),
/// which counts it with its mass and charge.
pub fn take(outlets: &mut [Outlet], x: DVec3, mass: f64, charge: f64) -> Option<usize> {
    let k = outlets.iter().position(|o| o.takes(x))?;
    let o = &mut outlets[k];
    o.removed += 1;
    o.mass += mass;
    o.charge += charge;
    Some(k)
}

/// A particle that left: what the outflow table writes of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Departure {
    pub step: u64,
    pub time: f64,
    /// Its number: its id, or the scene's number where the particles are
    /// stored in space order ([`crate::particles::System::number_of`]).
    pub id: u64,
    /// The outlet it left through.
    pub outlet: usize,
    pub species: String,
    pub mass: f64,
    pub charge: f64,
    pub radius: f64,
    pub position: DVec3,
    pub velocity: DVec3,
}
