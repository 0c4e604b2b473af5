//! Observables of the whole system and the "particle inspector" (002 §3.2).

use glam::DVec3;

use crate::force::{ForceField, State, Virial};
use crate::particles::System;

/// Whole-system observables at one instant.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Observables {
    pub time: f64,
    /// K = Σ ½ m v² + Σ ½ I ω² (translation and rotation).
    pub kinetic: f64,
    /// The rotational part Σ ½ I ω².
    pub rotational: f64,
    /// U from every interaction with a potential.
    pub potential: f64,
    /// Total linear momentum P = Σ m v.
    pub momentum: DVec3,
    /// Total angular momentum about the origin L = Σ (m r × v + I ω).
    pub angular_momentum: DVec3,
    /// k_B T = 2K / N_f in energy units (N_f: free translational degrees of freedom).
    pub kt: f64,
    /// P = (2K + W)/(3V) from the virial W of the last force evaluation; NaN without a periodic box.
    pub pressure: f64,
    /// P_αβ = (Σ m v_α v_β + W_αβ)/V as [xx, yy, zz, xy, xz, yz], when the
    /// force field measures it ([`ForceField::pressure_tensor`]) in a box
    /// periodic on every axis; NaN otherwise.
    pub pressure_tensor: [f64; 6],
    /// The force the particles exert on each wall (name, force), from the
    /// last force evaluation.
    pub wall_forces: Vec<(String, DVec3)>,
    /// Total magnetic moment Σ m_i of the dipoles.
    pub magnetisation: DVec3,
}

/// The sums over the particles (and the ranks) observables are made of.
struct Sums {
    /// Σ ½ m v² (translation only) and Σ ½ I ω².
    kinetic: f64,
    rotational: f64,
    potential: f64,
    momentum: DVec3,
    angular_momentum: DVec3,
    magnetisation: DVec3,
    /// The virial W, where the box is periodic on every axis and every
    /// interaction gives its part.
    virial: Option<f64>,
    /// Σ m v ⊗ v + W_αβ, when measured.
    tensor: Option<Virial>,
    /// Free translational axes and particles.
    free: f64,
    count: f64,
    wall_forces: Vec<(String, DVec3)>,
}

impl Sums {
    /// The sums of a decomposed run's ranks, added in rank order (the same
    /// bits on every rank).
    fn over_ranks(self, comm: &dyn mote_run::comm::Comm) -> Self {
        let mut local = vec![
            self.kinetic,
            self.rotational,
            self.potential,
            self.free,
            self.count,
        ];
        local.extend(self.momentum.to_array());
        local.extend(self.angular_momentum.to_array());
        local.extend(self.magnetisation.to_array());
        local.push(self.virial.unwrap_or(f64::NAN));
        local.extend(self.tensor.map_or([f64::NAN; 6], |t| t.0));
        local.extend(self.wall_forces.iter().flat_map(|w| w.1.to_array()));
        let total = comm.sum(&local);
        let walls = total[21..].chunks(3).map(DVec3::from_slice);
        Self {
            kinetic: total[0],
            rotational: total[1],
            potential: total[2],
            free: total[3],
            count: total[4],
            momentum: DVec3::from_slice(&total[5..8]),
            angular_momentum: DVec3::from_slice(&total[8..11]),
            magnetisation: DVec3::from_slice(&total[11..14]),
            virial: self.virial.map(|_| total[14]),
            tensor: self
                .tensor
                .map(|_| Virial(total[15..21].try_into().expect("six"))),
            wall_forces: self
                .wall_forces
                .into_iter()
                .zip(walls)
                .map(|(w, f)| (w.0, f))
                .collect(),
        }
    }
}

impl Observables {
    pub fn total_energy(&self) -> f64 {
        self.kinetic + self.potential
    }

    /// Measures the system (the potential energy needs the force field).
    pub fn measure(sys: &System, ff: &mut ForceField) -> Self {
        let p = &sys.particles;
        let mut kinetic = 0.0;
        let mut momentum = DVec3::ZERO;
        let mut angular_momentum = DVec3::ZERO;
        for i in 0..p.len() {
            let mv = p.velocity[i] * p.mass[i];
            kinetic += 0.5 * mv.dot(p.velocity[i]);
            momentum += mv;
            angular_momentum += p.position[i].cross(mv);
        }
        let mut rotational = 0.0;
        for i in 0..p.len() {
            let iw = p.angular_velocity[i] * p.inertia[i];
            rotational += 0.5 * iw.dot(p.angular_velocity[i]);
            angular_momentum += iw;
        }
        let state = State::of(sys, &p.position, &p.velocity, sys.time, 0.0);
        let (potential, _) = ff.potential_energy(&state);
        let periodic =
            sys.boundary.periodic.iter().all(|p| *p) && sys.boundary.volume().is_finite();
        let virial = ff.virial().filter(|_| periodic);
        let mut tensor = None;
        if ff.pressure_tensor && virial.is_some_and(f64::is_finite) {
            if let Some(w) = ff.virial_tensor(&state) {
                let mut kinetic = Virial::default();
                for (m, v) in p.mass.iter().zip(&p.velocity) {
                    kinetic += Virial::pair(*v, *v * *m);
                }
                tensor = Some(kinetic + w);
            }
        }
        let sums = Sums {
            kinetic,
            rotational,
            potential,
            momentum,
            angular_momentum,
            magnetisation: p.dipole.iter().sum(),
            virial,
            tensor,
            free: p.mobility.iter().map(|m| m.x + m.y + m.z).sum(),
            count: p.len() as f64,
            wall_forces: ff
                .interactions
                .iter()
                .filter_map(|i| i.viewer())
                .flat_map(|v| v.wall_forces())
                .collect(),
        };
        let sums = match &ff.domain {
            Some(domain) => sums.over_ranks(domain.comm()),
            None => sums,
        };
        Self::from_sums(sys, sums)
    }

    /// The observables of the whole system's sums.
    fn from_sums(sys: &System, s: Sums) -> Self {
        let translational = s.kinetic;
        let nf = crate::particles::translational_freedom(s.free, s.count);
        let volume = sys.boundary.volume();
        let pressure = s
            .virial
            .map_or(f64::NAN, |w| (2.0 * translational + w) / (3.0 * volume));
        let pressure_tensor = match s.tensor {
            Some(t) if pressure.is_finite() => t.scaled(1.0 / volume).0,
            _ => [f64::NAN; 6],
        };
        Self {
            time: sys.time,
            pressure_tensor,
            kinetic: s.kinetic + s.rotational,
            rotational: s.rotational,
            potential: s.potential,
            momentum: s.momentum,
            angular_momentum: s.angular_momentum,
            magnetisation: s.magnetisation,
            wall_forces: s.wall_forces,
            kt: if nf > 0.0 {
                2.0 * translational / nf
            } else {
                0.0
            },
            pressure,
        }
    }

    /// Column names of [`Observables::values`].
    /// The columns of observables.csv, the same words as the rigid
    /// engine's: kinetic energy whole, then its translational and
    /// rotational parts (LAMMPS's `ke` is the translational one).
    pub const COLUMNS: [&'static str; 15] = [
        "time",
        "kinetic_energy",
        "translational_energy",
        "rotational_energy",
        "potential_energy",
        "total_energy",
        "px",
        "py",
        "pz",
        "Lx",
        "Ly",
        "Lz",
        "step",
        "kT",
        "pressure",
    ];

    pub fn values(&self, step: u64) -> [f64; 15] {
        [
            self.time,
            self.kinetic,
            self.kinetic - self.rotational,
            self.rotational,
            self.potential,
            self.total_energy(),
            self.momentum.x,
            self.momentum.y,
            self.momentum.z,
            self.angular_momentum.x,
            self.angular_momentum.y,
            self.angular_momentum.z,
            step as f64,
            self.kt,
            self.pressure,
        ]
    }
}

/// A per-particle quantity named in a scene, such as `z[30]` or `speed[1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Probe {
    pub quantity: ProbeQuantity,
    /// The particle's number in the scene.
    pub particle: usize,
    /// Its row in the system (the number, unless the particles are stored
    /// in space order).
    pub row: usize,
}

/// What a [`Probe`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbeQuantity {
    X,
    Y,
    Z,
    Vx,
    Vy,
    Vz,
    /// |r|, distance from the origin.
    R,
    /// |v|.
    Speed,
    /// ½ m v².
    Kinetic,
}

impl Probe {
    pub const QUANTITIES: &'static str = "x, y, z, vx, vy, vz, r, speed, kinetic";

    /// Parses `name[index]`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let err = || {
            format!(
                "'{text}' is not a particle quantity: write NAME[INDEX] with NAME one of {}",
                Self::QUANTITIES
            )
        };
        let (name, rest) = text.trim().split_once('[').ok_or_else(err)?;
        let index = rest.strip_suffix(']').ok_or_else(err)?;
        let particle: usize = index.trim().parse().map_err(|_| err())?;
        let quantity = match name.trim() {
            "x" => ProbeQuantity::X,
            "y" => ProbeQuantity::Y,
            "z" => ProbeQuantity::Z,
            "vx" => ProbeQuantity::Vx,
            "vy" => ProbeQuantity::Vy,
            "vz" => ProbeQuantity::Vz,
            "r" => ProbeQuantity::R,
            "speed" => ProbeQuantity::Speed,
            "kinetic" => ProbeQuantity::Kinetic,
            _ => return Err(err()),
        };
        Ok(Self {
            quantity,
            particle,
            row: particle,
        })
    }

    pub fn label(&self) -> String {
        let name = match self.quantity {
            ProbeQuantity::X => "x",
            ProbeQuantity::Y => "y",
            ProbeQuantity::Z => "z",
            ProbeQuantity::Vx => "vx",
            ProbeQuantity::Vy => "vy",
            ProbeQuantity::Vz => "vz",
            ProbeQuantity::R => "r",
            ProbeQuantity::Speed => "speed",
            ProbeQuantity::Kinetic => "kinetic",
        };
        format!("{name}[{}]", self.particle)
    }

    pub fn read(&self, sys: &System) -> f64 {
        let p = &sys.particles;
        let (r, v) = (p.position[self.row], p.velocity[self.row]);
        match self.quantity {
            ProbeQuantity::X => r.x,
            ProbeQuantity::Y => r.y,
            ProbeQuantity::Z => r.z,
            ProbeQuantity::Vx => v.x,
            ProbeQuantity::Vy => v.y,
            ProbeQuantity::Vz => v.z,
            ProbeQuantity::R => r.length(),
            ProbeQuantity::Speed => v.length(),
            ProbeQuantity::Kinetic => 0.5 * p.mass[self.row] * v.length_squared(),
        }
    }
}
