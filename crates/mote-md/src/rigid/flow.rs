//! Rigid clumps that enter and leave a run: the spheres' streams and
//! outlets ([`crate::flow`]) for bodies. An inserter makes clumps of one
//! template, each at a random place in its region with a random
//! orientation (uniform on the rotations), none of its spheres touching a
//! sphere of another body or a wall; an outlet takes out the bodies whose
//! centres of mass reach it.
//!
//! What the run keeps exact is what the spheres' flow keeps: bodies have
//! ids (inserted ones the next unused), the contact histories of the
//! spheres that stay follow them through a removal
//! ([`BodyInteraction::bodies_changed`](super::BodyInteraction::bodies_changed)),
//! in − out = held in number and mass at every event, and a checkpoint
//! holds which bodies exist and who made them, so that a resumed run is
//! the uninterrupted one bit for bit.

use std::sync::Arc;

use glam::DVec3;
use mote_geom::{rotation_matrix, DE, E};
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::bodies::RigidBodies;
use super::frbi::Frbi;
use super::interaction::WorldFrame;
use super::template::BodyTemplate;
use crate::boundary::Boundary;
use crate::flow::{self, clear_of, Departure, Ledger, Outlet, Stream};
use crate::force::granular::Wall;

/// A stream of clumps of one template into a region.
#[derive(Debug, Clone)]
pub struct ClumpInserter {
    pub stream: Stream,
    /// The template it makes, and its index among the bodies' templates.
    pub template: Arc<BodyTemplate>,
    pub kind: u32,
    /// The template's name (the outflow table's species).
    pub species: String,
}

impl ClumpInserter {
    /// The farthest any of the template's spheres reaches from its centre
    /// of mass.
    fn reach(&self) -> f64 {
        let t = &self.template;
        (t.centres.iter().zip(&t.radii))
            .map(|(c, r)| c.length() + r)
            .fold(0.0, f64::max)
    }

    /// The solid fraction of the region this stream keeps: the volume of
    /// the bodies of its template whose centres lie in it over its volume
    /// (so that streams of carriers and of toner into one region keep a
    /// developer's mixture, each to its own fraction).
    fn filled(&self, bodies: &RigidBodies, boundary: &Boundary) -> f64 {
        let region = &self.stream.region;
        let solid: f64 = (0..bodies.len())
            .filter(|&i| bodies.kind[i] == self.kind)
            .filter(|&i| region.contains(boundary.wrap(bodies.position[i])))
            .map(|i| bodies.template(i).props.volume)
            .sum();
        solid / region.volume()
    }

    /// Brings the stream up to time `t`: each clump's orientation, place
    /// and velocity drawn from `rng`, kept where no sphere of it overlaps
    /// one of `spheres` (every body's, wrapped, with radii; those placed
    /// before it are appended) or a wall at time t. Returns the placements
    /// and velocities of the clumps to add, in order.
    pub fn insert(
        &mut self,
        bodies: &RigidBodies,
        spheres: &mut Vec<(DVec3, f64)>,
        walls: &[Wall],
        t: f64,
        boundary: &Boundary,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Vec<(E, DE)> {
        let mut made = Vec::new();
        let stream = &self.stream;
        if !stream.owes(t)
            || stream
                .fill
                .is_some_and(|f| self.filled(bodies, boundary) >= f)
        {
            return made;
        }
        let reach = self.reach();
        let near = stream.near(spheres.iter().copied(), boundary, reach);
        let mut placed: Vec<(DVec3, f64)> = Vec::new();
        let volume = self.template.props.volume;
        let fill_volume =
            (stream.fill).map(|f| (f - self.filled(bodies, boundary)) * stream.region.volume());
        let mut added_volume = 0.0;
        let mut owed = stream.owed(t);
        while owed > 0 && self.stream.owes(t) {
            if fill_volume.is_some_and(|room| added_volume + volume > room) {
                break;
            }
            let Some((g, world)) = self.place(&near, &placed, walls, t, boundary, rng) else {
                break;
            };
            let v = self.stream.draw_velocity(rng);
            placed.extend(world);
            added_volume += volume;
            self.stream.record(self.template.mass());
            owed -= 1;
            made.push((g, DE::new(DVec3::ZERO, v)));
        }
        spheres.extend(placed);
        self.stream.note_lag(t);
        made
    }

    /// A placement in the region whose spheres (returned, wrapped, with
    /// their radii) are clear of `near`, `placed` and the walls; `None`
    /// after the stream's attempts.
    fn place(
        &self,
        near: &[(DVec3, f64)],
        placed: &[(DVec3, f64)],
        walls: &[Wall],
        t: f64,
        boundary: &Boundary,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Option<(E, Vec<(DVec3, f64)>)> {
        let image = boundary.image();
        let tpl = &self.template;
        for _ in 0..self.stream.attempts {
            let x = self.stream.draw_point(boundary, rng);
            let r = random_rotation(rng);
            let m = rotation_matrix(r);
            let world: Vec<(DVec3, f64)> = (tpl.centres.iter().zip(&tpl.radii))
                .map(|(c, &radius)| (boundary.wrap(x + m * *c), radius))
                .collect();
            let clear = world.iter().all(|&(c, radius)| {
                walls.iter().all(|w| w.gap(c, t).0 >= radius)
                    && clear_of(c, radius, near, &image)
                    && clear_of(c, radius, placed, &image)
            });
            if clear {
                return Some((E::new(r, x), world));
            }
        }
        None
    }
}

/// A rotation drawn uniformly (Shoemake: a unit quaternion q = (w, u)
/// from four normal numbers, w ≥ 0), as the placement's rotation vector
/// r = u / w = n tan(φ/2).
pub fn random_rotation(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    loop {
        let q: [f64; 4] = std::array::from_fn(|_| rng.sample(StandardNormal));
        let w = q[0].abs();
        if w > 1e-9 {
            return DVec3::new(q[1], q[2], q[3]) * (q[0].signum() / w);
        }
    }
}

/// The inserters and outlets of a rigid run.
#[derive(Debug, Clone)]
pub struct BodyFlow {
    pub inserters: Vec<ClumpInserter>,
    pub outlets: Vec<Outlet>,
    /// Steps between events (≥ 1).
    pub every: u64,
    /// The walls new clumps keep clear of.
    pub walls: Vec<Wall>,
    /// The box: periodic axes are wrapped, outlets and regions read the
    /// centres wrapped into it.
    pub boundary: Boundary,
    ledger: Ledger,
    /// The bodies that left at the last event.
    pub departed: Vec<Departure>,
    /// Mass in and out at each event.
    pub balance: flow::Balance,
}

impl BodyFlow {
    /// The flow of a run whose scene placed `bodies` (which get their ids
    /// 0, 1, … here); each inserter's template is registered with them.
    pub fn new(
        bodies: &mut RigidBodies,
        mut inserters: Vec<ClumpInserter>,
        outlets: Vec<Outlet>,
        every: u64,
        walls: Vec<Wall>,
        boundary: Boundary,
    ) -> Self {
        let n = bodies.len();
        bodies.id = (0..n as u64).collect();
        for ins in &mut inserters {
            ins.kind = bodies.add_template(ins.template.clone());
        }
        Self {
            inserters,
            outlets,
            every: every.max(1),
            walls,
            boundary,
            ledger: Ledger::new(n),
            departed: Vec::new(),
            balance: flow::Balance::default(),
        }
    }

    fn streams(&self) -> impl ExactSizeIterator<Item = &Stream> + Clone {
        self.inserters.iter().map(|i| &i.stream)
    }

    /// Every sphere of `bodies`, wrapped into the box, with its radius.
    fn spheres(&self, bodies: &RigidBodies) -> Vec<(DVec3, f64)> {
        let mut world = WorldFrame::default();
        world.update(bodies);
        (world.sphere_centre.iter().zip(&world.sphere_radius))
            .map(|(c, r)| (self.boundary.wrap(*c), *r))
            .collect()
    }

    /// The event at `step`: the outlets take out the bodies whose centres
    /// reached them (in body order, each through the first outlet that
    /// takes it; `departed` lists them by scene number), then each inserter in turn brings its stream up to the
    /// bodies' time; the integrator's interactions hear of both.
    pub fn apply(&mut self, bodies: &mut RigidBodies, frbi: &mut Frbi, seed: u64, step: u64) {
        let time = bodies.time;
        self.departed.clear();
        let n = bodies.len();
        let mut keep = vec![true; n];
        for (i, kept) in keep.iter_mut().enumerate() {
            let x = self.boundary.wrap(bodies.position[i]);
            let t = bodies.template(i);
            let Some(k) = flow::outlet::take(&mut self.outlets, x, t.mass(), t.charge) else {
                continue;
            };
            *kept = false;
            self.departed.push(Departure {
                step,
                time,
                id: bodies.number_of(i),
                outlet: k,
                species: self.species(bodies.kind[i]),
                mass: t.mass(),
                charge: t.charge,
                radius: t.equivalent_radius,
                position: bodies.position[i],
                velocity: bodies.velocity[i],
            });
        }
        // Written in the scene's numbering, whatever the storage order.
        self.departed.sort_by_key(|d| d.id);
        let removed = !self.departed.is_empty();
        let kept_spheres: Vec<bool> = (0..n)
            .flat_map(|i| std::iter::repeat_n(keep[i], bodies.template(i).sphere_count()))
            .collect();
        if removed {
            bodies.retain(&keep);
            self.ledger.retain(&keep);
        }
        let mut arrived = false;
        let mut spheres = if self.inserters.is_empty() {
            Vec::new()
        } else {
            self.spheres(bodies)
        };
        for c in 0..self.inserters.len() {
            let mut rng = flow::stream_rng(seed, step, c);
            let (walls, boundary) = (&self.walls, &self.boundary);
            let made =
                self.inserters[c].insert(bodies, &mut spheres, walls, time, boundary, &mut rng);
            for (g, h) in made {
                let id = self.ledger.arrive(c);
                bodies.push(self.inserters[c].kind, g, h);
                bodies.id.push(id);
                arrived = true;
            }
        }
        if removed || arrived {
            frbi.bodies_changed(removed.then_some(&kept_spheres));
        }
        let streams = self.inserters.iter().map(|i| &i.stream);
        self.balance.record(time, streams, &self.outlets);
    }

    /// The name of template `kind`: the inserter's that makes it, else
    /// `B<kind>` (the trajectories' species of bodies).
    fn species(&self, kind: u32) -> String {
        (self.inserters.iter().find(|i| i.kind == kind))
            .map_or_else(|| format!("B{kind}"), |i| i.species.clone())
    }

    /// Bodies in and out, and their masses ([`flow::tally_columns`]).
    pub fn columns(&self) -> Vec<f64> {
        flow::tally_columns(self.streams(), &self.outlets)
    }

    /// The names of [`BodyFlow::columns`].
    pub fn column_names(&self) -> Vec<String> {
        flow::tally_names(self.streams(), &self.outlets)
    }

    /// What came and went, for the run's summary.
    pub fn summary(&self, held: usize) -> String {
        let text = flow::tally_summary(self.streams(), &self.outlets, held, ["body", "bodies"]);
        flow::join(text, self.balance.sentence())
    }

    /// What a checkpoint needs: the next id, the counts, then a row per
    /// body (id, inserter or −1 for the scene's, template, mass).
    pub fn carried_state(&self, bodies: &RigidBodies) -> Vec<f64> {
        let mut out = vec![self.ledger.next_id() as f64];
        flow::write_tally(&mut out, self.streams(), &self.outlets);
        self.ledger.write(&mut out, |i| {
            let kind = bodies.kind[i];
            [
                bodies.id_of(i) as f64,
                kind as f64,
                bodies.template(i).mass(),
            ]
        });
        out
    }

    /// Makes `bodies`, freshly placed by the scene, hold the bodies of
    /// [`BodyFlow::carried_state`]: the scene's still there, then those
    /// inserted, each of its inserter's template (placements and
    /// velocities are the checkpoint's, put in after).
    pub fn restore(
        &mut self,
        state: &[f64],
        bodies: &mut RigidBodies,
        frbi: &mut Frbi,
    ) -> Result<(), String> {
        let bad = |what: &str| format!("flow: {what}");
        let Some((&next_id, state)) = state.split_first() else {
            return Err(bad("the carried state is empty"));
        };
        let at = flow::read_tally(
            state,
            self.inserters.iter_mut().map(|i| &mut i.stream),
            &mut self.outlets,
        )?;
        let scene = bodies.len();
        let restored = (self.ledger).read(next_id, &state[at..], scene, self.inserters.len())?;
        let kept_spheres: Vec<bool> = (0..scene)
            .flat_map(|i| std::iter::repeat_n(restored.keep[i], bodies.template(i).sphere_count()))
            .collect();
        bodies.retain(&restored.keep);
        bodies.id = (0..scene as u64)
            .zip(&restored.keep)
            .filter(|k| *k.1)
            .map(|k| k.0)
            .collect();
        for &(id, by, kind, mass) in &restored.inserted {
            let ins = &self.inserters[by];
            if kind != ins.kind as f64 || mass != ins.template.mass() {
                return Err(bad(&format!(
                    "body {id}: template {kind} of mass {mass} is not inserter {}'s",
                    ins.stream.name
                )));
            }
            bodies.push(ins.kind, E::IDENTITY, DE::ZERO);
            bodies.id.push(id);
        }
        frbi.bodies_changed(Some(&kept_spheres));
        Ok(())
    }
}
