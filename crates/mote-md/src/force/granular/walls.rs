//! Walls for granular contacts: planes (fixed or moving), boxes (six
//! planes) and cylinders (inside, optionally turning about their axis: a
//! rotating drum). A sphere touches a wall as it would touch a sphere of
//! infinite radius and mass: R* = R, m* = m in the contact law.

use glam::DVec3;
use rayon::prelude::*;

use super::batch::FormedContacts;
use super::law::{ContactLaw, History};
use crate::force::{CarriedRows, HaloReach, Interaction, Spin, State, ViewerHooks, Virial};

/// The shape of a wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallShape {
    /// The plane through `point` with unit `normal` pointing to the side
    /// where the particles are.
    Plane { point: DVec3, normal: DVec3 },
    /// The inside of the cylinder of `radius` about the line through
    /// `point` along unit `axis`.
    Cylinder {
        point: DVec3,
        axis: DVec3,
        radius: f64,
    },
}

/// One wall: its shape at t = 0, translation velocity and angular speed
/// about its axis (cylinders) or normal (planes).
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    pub name: String,
    pub shape: WallShape,
    /// The wall moves rigidly with this velocity until time `stop`: its
    /// position at time t is the t = 0 position plus velocity · min(t,
    /// stop) (a lid that compresses to a set height, then stays).
    pub velocity: DVec3,
    pub stop: f64,
    /// Angular speed Ω about the axis (cylinder) or the normal through
    /// `point` (plane); the wall's surface moves at Ω × (x − point).
    pub angular_speed: f64,
}

impl Wall {
    /// A fixed plane.
    pub fn plane(name: &str, point: DVec3, normal: DVec3) -> Self {
        Self {
            name: name.into(),
            shape: WallShape::Plane {
                point,
                normal: normal.normalize(),
            },
            velocity: DVec3::ZERO,
            stop: f64::INFINITY,
            angular_speed: 0.0,
        }
    }

    /// The six inward faces of the box [lo, hi].
    pub fn closed_box(name: &str, lo: DVec3, hi: DVec3) -> Vec<Self> {
        let mut walls = Vec::new();
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            let e = DVec3::AXES[k];
            walls.push(Self::plane(&format!("{name}.{axis}lo"), lo, e));
            walls.push(Self::plane(&format!("{name}.{axis}hi"), hi, -e));
        }
        walls
    }

    /// The inside of a fixed cylinder.
    pub fn cylinder(name: &str, point: DVec3, axis: DVec3, radius: f64) -> Self {
        Self {
            name: name.into(),
            shape: WallShape::Cylinder {
                point,
                axis: axis.normalize(),
                radius,
            },
            velocity: DVec3::ZERO,
            stop: f64::INFINITY,
            angular_speed: 0.0,
        }
    }

    /// How far the wall has moved by time t.
    #[inline(always)]
    pub fn shift(&self, t: f64) -> DVec3 {
        self.velocity * t.min(self.stop)
    }

    /// The wall's translation velocity at time t (zero once stopped).
    #[inline(always)]
    pub fn translation(&self, t: f64) -> DVec3 {
        if t < self.stop {
            self.velocity
        } else {
            DVec3::ZERO
        }
    }

    /// A plane as (n, c), its gap x·n − c at time t; `None` for a
    /// cylinder.
    pub fn plane_at(&self, t: f64) -> Option<(DVec3, f64)> {
        match self.shape {
            WallShape::Plane { point, normal } => {
                Some((normal, (point + self.shift(t)).dot(normal)))
            }
            WallShape::Cylinder { .. } => None,
        }
    }

    /// Where the wall is at time t, for the live viewer.
    pub fn geometry(&self, t: f64) -> mote_run::WallGeometry {
        let shift = self.shift(t);
        match self.shape {
            WallShape::Plane { point, normal } => mote_run::WallGeometry::Plane {
                point: (point + shift).to_array(),
                normal: normal.to_array(),
            },
            WallShape::Cylinder {
                point,
                axis,
                radius,
            } => mote_run::WallGeometry::Cylinder {
                point: (point + shift).to_array(),
                axis: axis.to_array(),
                radius,
                angle: self.angular_speed * t,
            },
        }
    }

    /// For a sphere at x at time t: the gap along the normal from the wall
    /// surface to the centre, and the unit normal into the particle side.
    #[inline(always)]
    pub fn gap(&self, x: DVec3, t: f64) -> (f64, DVec3) {
        match self.shape {
            WallShape::Plane { point, normal } => ((x - point - self.shift(t)).dot(normal), normal),
            WallShape::Cylinder {
                point,
                axis,
                radius,
            } => {
                let rel = x - point - self.shift(t);
                let radial = rel - axis * rel.dot(axis);
                let rho = radial.length();
                let outward = if rho > 0.0 { radial / rho } else { DVec3::X };
                (radius - rho, -outward)
            }
        }
    }

    /// The velocity of the wall's surface at the contact point
    /// x − gap·n of a sphere at x.
    #[inline]
    pub fn surface_velocity(&self, x: DVec3, gap: f64, n: DVec3, t: f64) -> DVec3 {
        if self.angular_speed == 0.0 {
            return self.translation(t);
        }
        let (point, axis) = match self.shape {
            WallShape::Plane { point, normal } => (point, normal),
            WallShape::Cylinder { point, axis, .. } => (point, axis),
        };
        let contact = x - n * gap;
        self.translation(t) + (axis * self.angular_speed).cross(contact - point - self.shift(t))
    }
}

/// Contacts of every sphere with a set of walls (radii from the step's [`State`]).
#[derive(Debug, Clone)]
pub struct GranularWalls {
    pub law: ContactLaw,
    pub walls: Vec<Wall>,
    /// history[i · walls + w]: the contact of particle i with wall w.
    history: Vec<History>,
    /// Whether particle i touched wall w at the last evaluation (same layout).
    touching: Vec<bool>,
    /// The force the particles exert on each wall at the last evaluation.
    wall_force: Vec<DVec3>,
    /// Each chunk's contacts at the last evaluation (kept for their memory).
    found: Vec<FormedContacts>,
}

impl GranularWalls {
    /// Contacts of `n` spheres with `walls`.
    pub fn new(law: ContactLaw, walls: Vec<Wall>, n: usize) -> Self {
        Self {
            law,
            history: vec![History::default(); n * walls.len()],
            touching: vec![false; n * walls.len()],
            wall_force: vec![DVec3::ZERO; walls.len()],
            found: Vec::new(),
            walls,
        }
    }

    /// One pass over the particles, each tested against every wall; chunks
    /// of particles run in parallel and their wall forces are summed in
    /// chunk order (the same bits for every thread count).
    fn evaluate(
        &mut self,
        state: &State,
        omega: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        const CHUNK: usize = 1024;
        let dt = state.step.dt;
        let t = state.step.time;
        let law = self.law;
        let walls = &self.walls;
        let n_walls = walls.len();
        if n_walls == 0 {
            return;
        }
        let radius = state.radius;
        // Planes as (n, c) with gap = x·n − c at this time.
        let planes: Vec<Option<(DVec3, f64)>> = walls.iter().map(|w| w.plane_at(t)).collect();
        let planes = &planes;
        self.found
            .resize_with(force.len().div_ceil(CHUNK), Default::default);
        let sums: Vec<Vec<DVec3>> = force
            .par_chunks_mut(CHUNK)
            .zip(torque.par_chunks_mut(CHUNK))
            .zip(self.history.par_chunks_mut(CHUNK * n_walls))
            .zip(self.touching.par_chunks_mut(CHUNK * n_walls))
            .zip(self.found.par_iter_mut())
            .enumerate()
            .map(|(c, ((((f, tq), hist), touching), found))| {
                // The chunk's contacts, in order of particle then wall.
                found.clear();
                for k in 0..f.len() {
                    let i = c * CHUNK + k;
                    let x = state.position[i];
                    let r = radius[i];
                    for (w, wall) in walls.iter().enumerate() {
                        let slot = k * n_walls + w;
                        let (gap, n) = match planes[w] {
                            Some((normal, offset)) => (x.dot(normal) - offset, normal),
                            None => wall.gap(x, t),
                        };
                        if gap >= r || gap <= -r {
                            if touching[slot] {
                                touching[slot] = false;
                                hist[slot] = History::default();
                            }
                            continue;
                        }
                        touching[slot] = true;
                        let v_wall = wall.surface_velocity(x, gap, n, t);
                        let delta = r - gap;
                        let arm = r - 0.5 * delta;
                        let v_rel = state.velocity[i] - v_wall - (omega[i] * arm).cross(n);
                        found.push(
                            slot,
                            delta,
                            n,
                            v_rel,
                            omega[i],
                            [arm, 0.0],
                            r,
                            state.mass[i],
                        );
                    }
                }
                found.evaluate(&law, dt, hist);
                let mut sum = vec![DVec3::ZERO; n_walls];
                for (&slot, cf) in found.slot.iter().zip(&found.force) {
                    let (k, w) = (slot as usize / n_walls, slot as usize % n_walls);
                    f[k] += cf.force;
                    tq[k] += cf.torque_i;
                    sum[w] -= cf.force;
                }
                sum
            })
            .collect();
        self.wall_force.iter_mut().for_each(|f| *f = DVec3::ZERO);
        for sum in sums {
            for (total, s) in self.wall_force.iter_mut().zip(sum) {
                *total += s;
            }
        }
    }
}

impl Interaction for GranularWalls {
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        Some(self)
    }

    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    /// Not part of the pressure (see [`Interaction::virial`]).
    fn virial(&self) -> Option<f64> {
        Some(0.0)
    }

    fn virial_tensor(&mut self, _: &State) -> Option<Virial> {
        Some(Virial::default())
    }

    fn name(&self) -> &'static str {
        "walls"
    }

    fn exerts_torques(&self) -> bool {
        true
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let omega = vec![DVec3::ZERO; force.len()];
        let mut torque = vec![DVec3::ZERO; force.len()];
        self.evaluate(state, &omega, force, &mut torque);
    }

    fn add_forces_and_torques(
        &mut self,
        state: &State,
        spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        self.evaluate(state, spin.angular_velocity, force, torque);
    }

    /// [NaN (the time of the last evaluation before dt came with the
    /// state; kept so earlier checkpoints load), then per touching
    /// (particle, wall) slot: slot, ξ (3), ψ (3)].
    fn carried_state(&self) -> Vec<f64> {
        let mut out = vec![f64::NAN];
        for (k, h) in self.history.iter().enumerate() {
            if self.touching[k] {
                out.push(k as f64);
                out.extend(h.shear.to_array());
                out.extend(h.roll.to_array());
            }
        }
        out
    }

    /// Rows (id · walls + wall, ξ, ψ) of this rank's touching slots.
    fn carried_rows(&self, id: &[u64]) -> Option<CarriedRows> {
        let walls = self.walls.len();
        let mut rows = Vec::new();
        for (k, h) in self.history.iter().enumerate() {
            if self.touching[k] {
                rows.push((id[k / walls] * walls as u64 + (k % walls) as u64) as f64);
                rows.extend(h.shear.to_array());
                rows.extend(h.roll.to_array());
            }
        }
        Some(CarriedRows {
            head: vec![f64::NAN],
            width: 7,
            rows,
        })
    }

    /// A force on each particle alone.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach::NONE)
    }

    /// (wall, ξ, ψ) of each wall particle i touches.
    fn pack_particle(&self, i: usize, _: u64, out: &mut Vec<f64>) {
        let walls = self.walls.len();
        for w in 0..walls {
            let k = i * walls + w;
            if self.touching[k] {
                out.push(w as f64);
                out.extend(self.history[k].shear.to_array());
                out.extend(self.history[k].roll.to_array());
            }
        }
    }

    fn retain_particles(&mut self, keep: &[bool]) {
        let walls = self.walls.len().max(1);
        let slots: Vec<bool> = (0..self.history.len()).map(|k| keep[k / walls]).collect();
        crate::domain::retain(&mut self.history, &slots);
        crate::domain::retain(&mut self.touching, &slots);
    }

    fn unpack_particle(&mut self, _: u64, data: &[f64]) {
        let first = self.history.len();
        let walls = self.walls.len();
        self.history.resize(first + walls, History::default());
        self.touching.resize(first + walls, false);
        for r in data.chunks_exact(7) {
            let k = first + r[0] as usize;
            self.touching[k] = true;
            self.history[k] = History {
                shear: DVec3::new(r[1], r[2], r[3]),
                roll: DVec3::new(r[4], r[5], r[6]),
            };
        }
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        let Some((_, rows)) = state.split_first() else {
            return Ok(());
        };
        if rows.len() % 7 != 0 {
            return Err("wall contact history: rows of 7 numbers expected".into());
        }
        self.touching.iter_mut().for_each(|x| *x = false);
        for r in rows.chunks(7) {
            let k = r[0] as usize;
            if k >= self.history.len() {
                return Err(format!("wall contact history names slot {k}"));
            }
            self.touching[k] = true;
            self.history[k] = History {
                shear: DVec3::new(r[1], r[2], r[3]),
                roll: DVec3::new(r[4], r[5], r[6]),
            };
        }
        Ok(())
    }

    /// The Hertz elastic energy of the wall contacts, Σ (8/15) E* √R δ^{5/2}.
    fn potential_energy(&mut self, state: &State) -> f64 {
        let mut u = 0.0;
        for wall in &self.walls {
            for (i, &x) in state.position.iter().enumerate() {
                let r = state.radius[i];
                let (gap, _) = wall.gap(x, state.step.time);
                if gap < r && gap > -r {
                    u += self.law.elastic_energy(r - gap, r);
                }
            }
        }
        u
    }
}

impl ViewerHooks for GranularWalls {
    fn walls(&self, t: f64) -> Vec<mote_run::WallGeometry> {
        self.walls.iter().map(|w| w.geometry(t)).collect()
    }

    /// The force on each wall at the last evaluation: minus the sum of its
    /// contact forces on the particles.
    fn wall_forces(&self) -> Vec<(String, DVec3)> {
        self.walls
            .iter()
            .zip(&self.wall_force)
            .map(|(w, f)| (w.name.clone(), *f))
            .collect()
    }
}
