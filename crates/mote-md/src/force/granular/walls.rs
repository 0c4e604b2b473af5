//! Walls for granular contacts: planes (fixed or moving), boxes (six
//! planes) and cylinders (inside, optionally turning about their axis: a
//! rotating drum). A sphere touches a wall as it would touch a sphere of
//! infinite radius and mass: R* = R, m* = m in the contact law.

use glam::DVec3;
use rayon::prelude::*;

use super::law::{ContactLaw, History};
use crate::force::{Interaction, Spin, State};

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
    /// The wall moves rigidly with this velocity: its position at time t is
    /// the t = 0 position plus velocity · t.
    pub velocity: DVec3,
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
            angular_speed: 0.0,
        }
    }

    /// For a sphere at x: (gap along the normal from the wall surface to the
    /// centre, unit normal into the particle side, the wall surface's
    /// velocity at the contact point), at time t.
    #[inline]
    fn probe(&self, x: DVec3, t: f64) -> (f64, DVec3, DVec3) {
        let shift = self.velocity * t;
        match self.shape {
            WallShape::Plane { point, normal } => {
                let p = point + shift;
                let gap = (x - p).dot(normal);
                let contact = x - normal * gap;
                let v = self.velocity + (normal * self.angular_speed).cross(contact - p);
                (gap, normal, v)
            }
            WallShape::Cylinder {
                point,
                axis,
                radius,
            } => {
                let p = point + shift;
                let rel = x - p;
                let radial = rel - axis * rel.dot(axis);
                let rho = radial.length();
                let outward = if rho > 0.0 { radial / rho } else { DVec3::X };
                let contact = p + axis * rel.dot(axis) + outward * radius;
                let v = self.velocity + (axis * self.angular_speed).cross(contact - p);
                (radius - rho, -outward, v)
            }
        }
    }
}

/// Contacts of every sphere with a set of walls.
#[derive(Debug, Clone)]
pub struct GranularWalls {
    pub law: ContactLaw,
    pub walls: Vec<Wall>,
    radius: Vec<f64>,
    /// history[w][i]: the contact of particle i with wall w.
    history: Vec<Vec<History>>,
    /// The force the particles exert on each wall at the last evaluation.
    wall_force: Vec<DVec3>,
    last_time: Option<f64>,
}

impl GranularWalls {
    pub fn new(law: ContactLaw, walls: Vec<Wall>, radius: &[f64]) -> Self {
        let n = radius.len();
        Self {
            law,
            history: vec![vec![History::default(); n]; walls.len()],
            wall_force: vec![DVec3::ZERO; walls.len()],
            walls,
            radius: radius.to_vec(),
            last_time: None,
        }
    }

    fn evaluate(
        &mut self,
        state: &State,
        omega: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let dt = self.last_time.map_or(0.0, |t0| state.time - t0);
        self.last_time = Some(state.time);
        let t = state.time;
        let law = self.law;
        let radius = &self.radius;
        for (w, wall) in self.walls.iter().enumerate() {
            let hist = &mut self.history[w];
            let f_wall: DVec3 = force
                .par_iter_mut()
                .zip(torque.par_iter_mut())
                .zip(hist.par_iter_mut())
                .enumerate()
                .with_min_len(1024)
                .map(|(i, ((f, tq), h))| {
                    let x = state.position[i];
                    let r = radius[i];
                    let (gap, n, v_wall) = wall.probe(x, t);
                    if gap >= r || gap <= -r {
                        *h = History::default();
                        return DVec3::ZERO;
                    }
                    let delta = r - gap;
                    let arm = r - 0.5 * delta;
                    let v_rel = state.velocity[i] - v_wall - (omega[i] * arm).cross(n);
                    let c = law.force(delta, n, v_rel, omega[i], arm, 0.0, r, state.mass[i], dt, h);
                    *f += c.force;
                    *tq += c.torque_i;
                    -c.force
                })
                .reduce(|| DVec3::ZERO, |a, b| a + b);
            self.wall_force[w] = f_wall;
        }
    }
}

impl Interaction for GranularWalls {
    fn name(&self) -> &'static str {
        "walls"
    }

    fn exerts_torques(&self) -> bool {
        true
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

    /// The Hertz elastic energy of the wall contacts, Σ (8/15) E* √R δ^{5/2}.
    fn potential_energy(&mut self, state: &State) -> f64 {
        let mut u = 0.0;
        for wall in &self.walls {
            for (i, &x) in state.position.iter().enumerate() {
                let r = self.radius[i];
                let (gap, _, _) = wall.probe(x, state.time);
                if gap < r && gap > -r {
                    u += 8.0 / 15.0 * self.law.e_star * r.sqrt() * (r - gap).powf(2.5);
                }
            }
        }
        u
    }
}
