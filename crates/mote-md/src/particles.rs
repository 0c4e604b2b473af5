//! Particles as a structure of arrays, and the system that owns them.

use glam::DVec3;
use rayon::prelude::*;

use crate::boundary::Boundary;

/// Per-particle data, one array per quantity (structure of arrays).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Particles {
    pub position: Vec<DVec3>,
    pub velocity: Vec<DVec3>,
    pub mass: Vec<f64>,
    pub charge: Vec<f64>,
    pub radius: Vec<f64>,
    pub color: Vec<[f64; 3]>,
    /// Per axis 1.0 where the particle may move, 0.0 where it is fixed
    /// (MPPphys `vfix`); multiplies accelerations and velocities.
    pub mobility: Vec<DVec3>,
    /// Angular velocity ω of spheres that rotate (zero for point masses).
    pub angular_velocity: Vec<DVec3>,
    /// Moment of inertia I about the centre (2/5 m r² for a solid sphere);
    /// torques turn into angular accelerations τ/I where I > 0.
    pub inertia: Vec<f64>,
    /// Magnetic dipole moment m (a vector: magnitude and orientation; zero
    /// for non-magnetic particles). It turns with the particle's ω.
    pub dipole: Vec<DVec3>,
}

/// Everything needed to add one particle.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleInit {
    pub position: DVec3,
    pub velocity: DVec3,
    pub mass: f64,
    pub charge: f64,
    pub radius: f64,
    pub color: [f64; 3],
    pub free: [bool; 3],
    pub angular_velocity: DVec3,
    /// Moment of inertia; `None` takes the solid sphere's 2/5 m r².
    pub inertia: Option<f64>,
    pub dipole: DVec3,
}

impl Default for ParticleInit {
    fn default() -> Self {
        Self {
            position: DVec3::ZERO,
            velocity: DVec3::ZERO,
            mass: 1.0,
            charge: 0.0,
            radius: 0.0,
            color: [1.0, 1.0, 1.0],
            free: [true; 3],
            angular_velocity: DVec3::ZERO,
            inertia: None,
            dipole: DVec3::ZERO,
        }
    }
}

impl Particles {
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Appends a particle; fixed axes get zero velocity.
    pub fn push(&mut self, p: ParticleInit) {
        let mobility = DVec3::new(
            p.free[0] as u8 as f64,
            p.free[1] as u8 as f64,
            p.free[2] as u8 as f64,
        );
        self.position.push(p.position);
        self.velocity.push(p.velocity * mobility);
        self.mass.push(p.mass);
        self.charge.push(p.charge);
        self.radius.push(p.radius);
        self.color.push(p.color);
        self.mobility.push(mobility);
        self.angular_velocity.push(p.angular_velocity);
        self.inertia
            .push(p.inertia.unwrap_or(0.4 * p.mass * p.radius * p.radius));
        self.dipole.push(p.dipole);
    }

    /// Whether particle i may rotate: it has a moment of inertia and is not
    /// fixed on every axis.
    #[inline]
    pub fn rotates(&self, i: usize) -> bool {
        self.inertia[i] > 0.0 && self.mobility[i] != DVec3::ZERO
    }

    /// Puts the particles in another order: row k becomes the particle
    /// that was at row `order[k]` (`order` a permutation of the rows).
    pub fn reorder(&mut self, order: &[usize]) {
        use crate::order::gathered;
        self.position = gathered(&self.position, order);
        self.velocity = gathered(&self.velocity, order);
        self.mass = gathered(&self.mass, order);
        self.charge = gathered(&self.charge, order);
        self.radius = gathered(&self.radius, order);
        self.color = gathered(&self.color, order);
        self.mobility = gathered(&self.mobility, order);
        self.angular_velocity = gathered(&self.angular_velocity, order);
        self.inertia = gathered(&self.inertia, order);
        self.dipole = gathered(&self.dipole, order);
    }
}

/// The state of a run: particles, simulated time and step count.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct System {
    pub particles: Particles,
    pub boundary: Boundary,
    pub time: f64,
    pub step: u64,
    /// Accelerations leap-frog evaluated at the end of the last step and
    /// uses to start the next (empty when none are carried). Part of the
    /// state so that checkpoints resume bit for bit.
    pub carried_acceleration: Vec<DVec3>,
    /// The angular accelerations τ/I carried the same way (empty when no
    /// interaction exerts torques).
    pub carried_angular_acceleration: Vec<DVec3>,
    /// The species name of each particle, written in trajectories (empty:
    /// all `X`). Names only: no interaction reads them.
    pub species: Vec<String>,
    /// Each particle's id, increasing along the particles (empty: particle
    /// i has id i). Ids stay with particles where particles come and go
    /// ([`crate::flow`]): the next inserted takes the next unused one.
    pub id: Vec<u64>,
    /// The scene's number of the particle with id k, where the particles
    /// are stored in another order than the scene gave them (space order,
    /// [`crate::order`]): files, probes and messages name particles by it.
    /// Empty: every particle's number is its id; ids past its end
    /// (particles inserted during the run) are their own numbers too.
    pub number: std::sync::Arc<[u64]>,
}

impl System {
    pub fn new(particles: Particles) -> Self {
        Self {
            particles,
            boundary: Boundary::open(),
            time: 0.0,
            step: 0,
            carried_acceleration: Vec::new(),
            carried_angular_acceleration: Vec::new(),
            species: Vec::new(),
            id: Vec::new(),
            number: Default::default(),
        }
    }

    /// The same box, time and step, without particles.
    pub fn without_particles(&self) -> System {
        System {
            particles: Particles::default(),
            boundary: self.boundary,
            time: self.time,
            step: self.step,
            carried_acceleration: Vec::new(),
            carried_angular_acceleration: Vec::new(),
            species: Vec::new(),
            id: Vec::new(),
            number: self.number.clone(),
        }
    }

    /// The id of particle i.
    #[inline]
    pub fn id_of(&self, i: usize) -> u64 {
        self.id.get(i).copied().unwrap_or(i as u64)
    }

    /// The scene's number of particle i (its id where the particles are
    /// stored as the scene gave them).
    #[inline]
    pub fn number_of(&self, i: usize) -> u64 {
        self.number_of_id(self.id_of(i))
    }

    /// The scene's number of the particle with id `id`.
    #[inline]
    pub fn number_of_id(&self, id: u64) -> u64 {
        self.number.get(id as usize).copied().unwrap_or(id)
    }

    /// The rows in the order of the particles' scene numbers, or `None`
    /// where that is the rows' own order: the order files are written in.
    pub fn rows_by_number(&self) -> Option<Vec<usize>> {
        if self.number.is_empty() {
            return None;
        }
        let mut rows: Vec<usize> = (0..self.particles.len()).collect();
        rows.sort_unstable_by_key(|&i| self.number_of(i));
        Some(rows)
    }

    /// Keeps the particles where `keep` is true, in order, with all they
    /// carry (a decomposed run's particles leaving this rank).
    pub fn retain_particles(&mut self, keep: &[bool]) {
        use crate::domain::retain;
        let p = &mut self.particles;
        retain(&mut p.position, keep);
        retain(&mut p.velocity, keep);
        retain(&mut p.mass, keep);
        retain(&mut p.charge, keep);
        retain(&mut p.radius, keep);
        retain(&mut p.color, keep);
        retain(&mut p.mobility, keep);
        retain(&mut p.angular_velocity, keep);
        retain(&mut p.inertia, keep);
        retain(&mut p.dipole, keep);
        for carried in [
            &mut self.carried_acceleration,
            &mut self.carried_angular_acceleration,
        ] {
            if !carried.is_empty() {
                retain(carried, keep);
            }
        }
        if !self.species.is_empty() {
            retain(&mut self.species, keep);
        }
        if !self.id.is_empty() {
            retain(&mut self.id, keep);
        }
    }

    /// Maps positions back into the box on periodic axes.
    pub fn wrap_positions(&mut self) {
        if self.boundary.is_periodic() {
            let b = self.boundary;
            self.particles
                .position
                .par_iter_mut()
                .with_min_len(4096)
                .for_each(|r| *r = b.wrap(*r));
        }
    }

    /// Degrees of freedom of translation: the free axes, less the three of
    /// total momentum when nothing is fixed.
    pub fn degrees_of_freedom(&self) -> f64 {
        let p = &self.particles;
        let free: f64 = p.mobility.iter().map(|m| m.x + m.y + m.z).sum();
        translational_freedom(free, p.len() as f64)
    }

    /// Moves to the centre-of-mass frame: subtracts the mass-weighted mean
    /// position and velocity of the free particles (only if none is fixed).
    pub fn to_centre_of_mass_frame(&mut self) {
        let p = &mut self.particles;
        if p.mobility.iter().any(|m| *m != DVec3::ONE) {
            return;
        }
        let m_tot: f64 = p.mass.iter().sum();
        let r_cm: DVec3 = p
            .position
            .iter()
            .zip(&p.mass)
            .map(|(r, m)| *r * *m)
            .sum::<DVec3>()
            / m_tot;
        let v_cm: DVec3 = p
            .velocity
            .iter()
            .zip(&p.mass)
            .map(|(v, m)| *v * *m)
            .sum::<DVec3>()
            / m_tot;
        p.position.iter_mut().for_each(|r| *r -= r_cm);
        p.velocity.iter_mut().for_each(|v| *v -= v_cm);
    }
}

/// Degrees of freedom of translation of `count` particles with `free`
/// free axes in all: less the three of total momentum when nothing is
/// fixed (the sums may be a decomposed run's, over its ranks).
pub fn translational_freedom(free: f64, count: f64) -> f64 {
    if free == 3.0 * count && count > 1.0 {
        free - 3.0
    } else {
        free
    }
}
