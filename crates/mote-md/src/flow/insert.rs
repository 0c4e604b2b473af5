//! Insertion of spheres into a region at a rate (LIGGGHTS
//! `fix insert/rate/region`, LAMMPS `fix deposit`): at each insertion
//! event the inserter brings its count up to what its rate has owed since
//! it started, each new sphere placed at random in the region where it
//! overlaps no particle and no wall.

use glam::DVec3;
use mote_rcp::SizeSpec;
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::Region;
use crate::boundary::{Boundary, MinimumImage};
use crate::force::granular::Wall;
use crate::particles::{ParticleInit, System};

/// How fast an inserter brings particles in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rate {
    /// Particles per unit time: by time t it has inserted ⌊ṅ (t − t₀)⌋.
    Number(f64),
    /// Mass per unit time: by time t it has inserted the fewest particles
    /// whose mass reaches ṁ (t − t₀) (one particle's mass at most over).
    Mass(f64),
    /// As many as the region takes up to its volume fraction, at every
    /// event.
    Fill,
}

/// The schedule and tally of one stream into a region, shared by the
/// spheres' inserter ([`Inserter`]) and the rigid clumps'
/// (`rigid::flow`): when it owes particles, where and how fast they start,
/// and how many came.
#[derive(Debug, Clone)]
pub struct Stream {
    /// The name the summary and the outflow table use.
    pub name: String,
    pub region: Region,
    pub rate: Rate,
    /// Time t₀ the stream starts.
    pub start: f64,
    /// At most this many in all (`None`: no limit).
    pub count: Option<u64>,
    /// Nothing is added while the particles whose centres lie in the
    /// region fill this fraction of its volume (LIGGGHTS
    /// `volumefraction_region`).
    pub fill: Option<f64>,
    /// The mean velocity, and the standard deviation of each component
    /// about it.
    pub velocity: DVec3,
    pub velocity_spread: f64,
    /// Random positions tried for one particle before the event gives up
    /// (the rest wait for the next event).
    pub attempts: u32,
    /// Particles and mass inserted so far.
    pub inserted: u64,
    pub mass: f64,
    /// The most particles owed and not placed after an event (the region
    /// was too full): the rate was not held while this is above zero.
    pub most_behind: u64,
}

impl Stream {
    /// Whether the stream still owes particles at time t.
    pub fn owes(&self, t: f64) -> bool {
        if t < self.start || self.count.is_some_and(|c| self.inserted >= c) {
            return false;
        }
        let elapsed = t - self.start;
        match self.rate {
            Rate::Number(rate) => (self.inserted as f64) < (rate * elapsed).floor(),
            Rate::Mass(rate) => self.mass < rate * elapsed,
            Rate::Fill => true,
        }
    }

    /// How many particles the stream owes at time t (a number rate), or
    /// an upper bound for a mass rate (the mass owed over the smallest
    /// particle is not known before the sizes are drawn: the loop stops
    /// when the mass is reached).
    pub fn owed(&self, t: f64) -> u64 {
        let elapsed = (t - self.start).max(0.0);
        let due = match self.rate {
            Rate::Number(rate) => (rate * elapsed).floor() as u64,
            Rate::Mass(_) | Rate::Fill => u64::MAX,
        };
        let due = self.count.map_or(due, |c| due.min(c));
        due.saturating_sub(self.inserted)
    }

    /// Counts one particle of mass m made.
    pub fn record(&mut self, m: f64) {
        self.inserted += 1;
        self.mass += m;
    }

    /// After an event at time t: what the stream still owes, if its rate
    /// was not held.
    pub fn note_lag(&mut self, t: f64) {
        match self.rate {
            Rate::Number(_) if self.owes(t) => {
                self.most_behind = self.most_behind.max(self.owed(t));
            }
            Rate::Mass(_) if self.owes(t) => self.most_behind = self.most_behind.max(1),
            _ => {}
        }
    }

    /// A point drawn uniformly in the region, wrapped into the box.
    pub fn draw_point(&self, boundary: &Boundary, rng: &mut Xoshiro256PlusPlus) -> DVec3 {
        let u = DVec3::new(rng.gen(), rng.gen(), rng.gen());
        let (lo, hi) = (self.region.lo, self.region.hi);
        boundary.wrap(lo + (hi - lo) * u)
    }

    /// A velocity: the mean with a normal spread on each component.
    pub fn draw_velocity(&self, rng: &mut Xoshiro256PlusPlus) -> DVec3 {
        self.velocity
            + self.velocity_spread
                * DVec3::new(
                    rng.sample(StandardNormal),
                    rng.sample(StandardNormal),
                    rng.sample(StandardNormal),
                )
    }

    /// The (wrapped position, radius) of the spheres in `spheres` that a
    /// sphere of radius up to `reach` centred in the region could touch.
    pub fn near(
        &self,
        spheres: impl Iterator<Item = (DVec3, f64)>,
        boundary: &Boundary,
        reach: f64,
    ) -> Vec<(DVec3, f64)> {
        spheres
            .map(|(x, r)| (boundary.wrap(x), r))
            .filter(|(x, r)| self.region.distance(*x, boundary) < r + reach)
            .collect()
    }
}

/// Whether a sphere of radius r at x overlaps none of `others` (each
/// through its nearest image).
pub fn clear_of(x: DVec3, r: f64, others: &[(DVec3, f64)], image: &MinimumImage) -> bool {
    others.iter().all(|(y, s)| {
        let reach = r + s;
        image.apply(x - *y).length_squared() >= reach * reach
    })
}

/// One stream of spheres into a region.
#[derive(Debug, Clone)]
pub struct Inserter {
    pub stream: Stream,
    /// The radius scale: a sphere's radius is this times the diameter
    /// `sizes` draws on its scale (1 for `mono`, 1 or the ratio for `bi`).
    pub radius: f64,
    pub sizes: SizeSpec,
    /// Mass density ρ: a sphere of radius r has mass ρ (4/3)π r³ and
    /// moment of inertia (2/5) m r².
    pub density: f64,
    /// Charge, colour, free axes and dipole of every particle it makes.
    pub template: ParticleInit,
    /// The name written in trajectories.
    pub species: String,
}

/// A particle the inserter made: what [`System`] needs to add it.
pub struct Made {
    pub init: ParticleInit,
    pub species: String,
}

impl Inserter {
    /// The particle of radius r this inserter makes (mass from its
    /// density), at rest at the origin.
    pub fn particle(&self, radius: f64) -> ParticleInit {
        let mass = self.density * ball(radius);
        ParticleInit {
            radius,
            mass,
            inertia: Some(0.4 * mass * radius * radius),
            ..self.template.clone()
        }
    }

    /// The solid fraction of the region: the volume of the spheres whose
    /// centres lie in it over its volume.
    fn filled(&self, sys: &System) -> f64 {
        let p = &sys.particles;
        let solid: f64 = (0..p.len())
            .filter(|&i| (self.stream.region).contains(sys.boundary.wrap(p.position[i])))
            .map(|i| ball(p.radius[i]))
            .sum();
        solid / self.stream.region.volume()
    }

    /// Brings the stream up to time `t`: draws each particle's size,
    /// velocity and position from `rng`, keeping positions that overlap
    /// no particle of `sys` (nor any placed before it) and no wall;
    /// returns the particles to add in order. `walls` are at time t.
    pub fn insert(
        &mut self,
        sys: &System,
        walls: &[Wall],
        t: f64,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Vec<Made> {
        let mut made: Vec<Made> = Vec::new();
        let stream = &self.stream;
        if !stream.owes(t) || stream.fill.is_some_and(|f| self.filled(sys) >= f) {
            return made;
        }
        let p = &sys.particles;
        let spheres = (0..p.len()).map(|i| (p.position[i], p.radius[i]));
        let near = stream.near(spheres, &sys.boundary, self.largest());
        let mut placed: Vec<(DVec3, f64)> = Vec::new();
        let fill_volume = (stream.fill).map(|f| f * stream.region.volume() - self.solid(sys));
        let mut added_volume = 0.0;
        let mut owed = stream.owed(t);
        while owed > 0 && self.stream.owes(t) {
            // A lognormal's draws within 4σ of its median.
            let z = loop {
                let z: f64 = rng.sample(StandardNormal);
                if z.abs() <= 4.0 {
                    break z;
                }
            };
            let radius = self.radius * self.sizes.draw(rng.gen(), z);
            let volume = ball(radius);
            if fill_volume.is_some_and(|room| added_volume + volume > room) {
                break;
            }
            let Some(x) = self.place(radius, &near, &placed, walls, t, &sys.boundary, rng) else {
                break;
            };
            let mut init = self.particle(radius);
            init.position = x;
            init.velocity = self.stream.draw_velocity(rng);
            placed.push((x, radius));
            added_volume += volume;
            self.stream.record(init.mass);
            owed -= 1;
            made.push(Made {
                init,
                species: self.species.clone(),
            });
        }
        self.stream.note_lag(t);
        made
    }

    /// The volume of the spheres whose centres lie in the region.
    fn solid(&self, sys: &System) -> f64 {
        self.filled(sys) * self.stream.region.volume()
    }

    /// The largest radius the sizes give: the ratio's for two sizes,
    /// e^{4σ} above the median for a lognormal (drawn within 4σ).
    fn largest(&self) -> f64 {
        let d = match &self.sizes {
            SizeSpec::Monodisperse => 1.0,
            SizeSpec::Bidisperse { ratio, .. } => *ratio,
            SizeSpec::Lognormal { sigma } => (-3.5 * sigma * sigma + 4.0 * sigma).exp(),
            SizeSpec::Radii(r) => 2.0 * r.iter().copied().fold(0.0, f64::max),
        };
        self.radius * d
    }

    /// A position for a sphere of `radius` inside the region, clear of
    /// every sphere of `near` and `placed` and of every wall; `None`
    /// after [`Stream::attempts`] tries.
    #[allow(clippy::too_many_arguments)]
    fn place(
        &self,
        radius: f64,
        near: &[(DVec3, f64)],
        placed: &[(DVec3, f64)],
        walls: &[Wall],
        t: f64,
        boundary: &Boundary,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Option<DVec3> {
        let image = boundary.image();
        for _ in 0..self.stream.attempts {
            let x = self.stream.draw_point(boundary, rng);
            if walls.iter().all(|w| w.gap(x, t).0 >= radius)
                && clear_of(x, radius, near, &image)
                && clear_of(x, radius, placed, &image)
            {
                return Some(x);
            }
        }
        None
    }
}

/// The volume (4/3)π r³ of a sphere of radius r.
pub fn ball(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r.powi(3)
}
