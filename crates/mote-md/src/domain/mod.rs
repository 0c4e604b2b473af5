//! Spatial domain decomposition (Plimpton 1995, J. Comput. Phys. 117, 1;
//! LAMMPS's `comm`): the box cut into bricks, one per rank; each rank owns
//! the particles in its brick and holds copies ("ghosts") of every particle
//! within the cut-off and skin of its brick.
//!
//! At a list build the particles that left their brick migrate to the
//! rank that now holds them, with all their state, and the ghosts are sent
//! in three stages, x then y then z, each to the two face neighbours, a
//! stage forwarding what the earlier ones brought (so the edges and
//! corners arrive without diagonal messages); a copy that crosses a
//! periodic face takes the image ±L there. Between builds, every force
//! evaluation forwards along the same paths how far each particle has
//! moved since the build, and a copy stands at its place at the build
//! plus that displacement.
//!
//! The ghosts are exactly the periodic images one process makes
//! ([`GhostList`](crate::neighbor::GhostList)) and the neighbours a brick
//! needs; the list over them orders each row as one process would (by
//! cell, then by particle id and image), and the rebuild rule is the one
//! process's, reduced over the ranks: a decomposed run's forces, hence its
//! trajectory, are the same bits on any number of ranks.

pub mod bricks;

use std::sync::Arc;

use glam::DVec3;
use mote_run::comm::Comm;

use crate::boundary::Boundary;
use crate::force::{HaloReach, Interaction};
use crate::particles::System;
pub use bricks::Bricks;

/// A copy of a particle near this rank's brick: another rank's particle,
/// or this rank's own across a periodic face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ghost {
    /// The particle's id (its index in the undivided system).
    pub id: u64,
    /// The periodic image: the copy stands `image · L` from the particle.
    pub image: [i32; 3],
    /// The copy's place at the build: the particle's wrapped position
    /// there plus the image.
    pub base: DVec3,
}

/// What a rank's pair lists read: its particles and the ghosts near its
/// brick as of the last build, and how far each has moved since.
#[derive(Debug, Clone, Default)]
pub struct Halo {
    /// Counts the builds: a list built for another generation is rebuilt.
    pub generation: u64,
    /// The id of each of this rank's particles.
    pub id: Vec<u64>,
    /// The wrapped positions of this rank's particles at the build.
    pub reference: Vec<DVec3>,
    pub ghosts: Vec<Ghost>,
    /// The minimum-image displacement since the build of this rank's
    /// particles, then of the ghosts (each its particle's).
    pub displacement: Vec<DVec3>,
    /// The ghosts' magnetic moments now (where an interaction reads them).
    pub moment: Vec<DVec3>,
    /// The ghosts' motion now (where an interaction reads it).
    pub motion: Vec<Motion>,
    /// The number of particles on all ranks.
    pub total: usize,
    /// The smallest and largest wrapped coordinates of all particles at the
    /// build: the cell grid of an open axis spans them.
    pub extent: (DVec3, DVec3),
}

/// What contacts read of a ghost's particle (granular contacts: the
/// relative velocity at the contact point), as its rank holds it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Motion {
    /// The position as the particle's rank holds it (not wrapped, not
    /// shifted by the image: a contact takes the minimum image, as one
    /// process does).
    pub position: DVec3,
    pub velocity: DVec3,
    /// The angular velocity ω.
    pub spin: DVec3,
    pub radius: f64,
    pub mass: f64,
}

impl Motion {
    /// Numbers per motion in a message.
    const WIDTH: usize = 11;

    fn write(&self, out: &mut Vec<f64>) {
        out.extend(self.position.to_array());
        out.extend(self.velocity.to_array());
        out.extend(self.spin.to_array());
        out.extend([self.radius, self.mass]);
    }

    fn read(g: &[f64]) -> Self {
        Self {
            position: DVec3::from_slice(&g[0..3]),
            velocity: DVec3::from_slice(&g[3..6]),
            spin: DVec3::from_slice(&g[6..9]),
            radius: g[9],
            mass: g[10],
        }
    }
}

/// This rank's particles as the ghosts copy them: positions, velocities
/// and angular velocities at the evaluation (spins empty: at rest, as a
/// measurement, which reads none, takes them), radii, masses and moments.
#[derive(Clone, Copy)]
pub struct Sources<'a> {
    pub position: &'a [DVec3],
    pub velocity: &'a [DVec3],
    pub spin: &'a [DVec3],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub dipole: &'a [DVec3],
}

impl<'a> Sources<'a> {
    /// The particles of `sys` as they stand.
    pub fn of(sys: &'a System) -> Self {
        let p = &sys.particles;
        Self {
            position: &p.position,
            velocity: &p.velocity,
            spin: &p.angular_velocity,
            radius: &p.radius,
            mass: &p.mass,
            dipole: &p.dipole,
        }
    }

    fn motion(&self, i: usize) -> Motion {
        Motion {
            position: self.position[i],
            velocity: self.velocity[i],
            spin: self.spin.get(i).copied().unwrap_or_default(),
            radius: self.radius.get(i).copied().unwrap_or_default(),
            mass: self.mass[i],
        }
    }
}

/// One of the six messages of a ghost exchange: what goes to one face
/// neighbour and comes from the opposite one.
#[derive(Debug, Clone, Default)]
struct Stage {
    to: Option<usize>,
    from: Option<usize>,
    /// The copies sent, as indices into this rank's particles then ghosts.
    send: Vec<u32>,
}

/// This rank's part of a decomposed run.
pub struct Domain {
    comm: Arc<dyn Comm>,
    pub bricks: Bricks,
    /// Pairs within cutoff + skin are listed.
    pub cutoff: f64,
    pub skin: f64,
    /// Rebuild at least every this many evaluations (0: on displacement).
    pub every: u64,
    /// Forward the ghosts' magnetic moments with their displacements.
    moments: bool,
    /// Forward the ghosts' [`Motion`] with their displacements.
    motion: bool,
    halo: Halo,
    stages: Vec<Stage>,
    since_build: u64,
    /// The builds so far (the run summary's count).
    pub builds: u64,
    /// The particles this rank has sent to another so far.
    pub migrated: u64,
    /// Shift the bricks' cuts at a build where the most particles a rank
    /// holds exceed the mean by this factor (0: never).
    pub balance: f64,
    /// The builds at which the cuts shifted so far.
    pub shifts: u64,
    /// A checkpoint's build to remake at the first evaluation: its
    /// evaluations since (the positions are the halo's reference).
    restored: Option<u64>,
    /// The species names of the undivided system; a particle carries its
    /// species as an index into them.
    species: Vec<String>,
}

/// The imbalance (most particles a rank over the mean) above which the
/// cuts shift, unless the scene says otherwise: LAMMPS's usual threshold.
pub const DEFAULT_BALANCE: f64 = 1.1;

/// Bins of the particles' histogram along an axis from which the cuts are
/// placed.
const BINS: usize = 1024;

/// The numbers a migrating particle carries, [`pack`]'s layout.
const CARRIED: usize = 31;

impl Domain {
    /// This rank's part of a run over `boundary` on `comm`'s ranks, for
    /// pair lists of `reach` ([`ForceField::halo_reach`]); `grid` forces
    /// the bricks. A run without pairs rebuilds (migrates) every step.
    /// Along an axis without periodicity or box (walls, or nothing, keep
    /// the particles) the slabs are cut over the particles' `extent` (the
    /// smallest and largest coordinates), the outer two reaching beyond.
    ///
    /// [`ForceField::halo_reach`]: crate::ForceField::halo_reach
    pub fn new(
        comm: Arc<dyn Comm>,
        boundary: &Boundary,
        extent: (DVec3, DVec3),
        reach: HaloReach,
        grid: Option<[usize; 3]>,
    ) -> Result<Self, String> {
        let (cutoff, skin) = if reach == HaloReach::NONE {
            (0.0, 0.0)
        } else {
            (reach.cutoff, reach.skin)
        };
        let cut = cut_box(boundary, extent);
        let dims = Bricks::choose(comm.size(), &cut, cutoff + skin, grid)?;
        let bricks = Bricks::new(dims, comm.rank(), &cut);
        Ok(Self {
            comm,
            bricks,
            cutoff,
            skin,
            every: reach.every,
            moments: reach.moments,
            motion: reach.motion,
            halo: Halo::default(),
            stages: Vec::new(),
            since_build: 0,
            builds: 0,
            migrated: 0,
            balance: DEFAULT_BALANCE,
            shifts: 0,
            restored: None,
            species: Vec::new(),
        })
    }

    /// The number of particles on all ranks.
    pub fn total(&self) -> usize {
        self.halo.total
    }

    pub fn comm(&self) -> &dyn Comm {
        &*self.comm
    }

    /// The particles and ghosts as of the last build and evaluation.
    pub fn halo(&self) -> &Halo {
        &self.halo
    }

    /// This rank's particles of the undivided system `whole` (which every
    /// rank holds at the start): those its brick holds, in id order, with
    /// what they carry. With `restored` (a checkpoint's list: evaluations
    /// since its build and the particles' wrapped positions there, by id),
    /// the bricks hold the particles where they stood at that build, which
    /// is remade at the first evaluation, as one process remakes it. The
    /// `interactions` keep what they hold of this rank's particles.
    pub fn scatter(
        &mut self,
        whole: &System,
        restored: Option<(u64, Vec<DVec3>)>,
        interactions: &mut [Box<dyn Interaction>],
    ) -> System {
        self.species = distinct(&whole.species);
        let b = &whole.boundary;
        let n = whole.particles.len();
        // A build for another number of particles is not this run's: the
        // list is then built afresh, as one process builds it.
        let restored = restored.filter(|(_, reference)| reference.len() == n);
        let at = |i: usize| match &restored {
            Some((_, reference)) => reference[i],
            None => b.wrap(whole.particles.position[i]),
        };
        let mine: Vec<usize> = (0..n)
            .filter(|&i| self.bricks.owner(at(i)) == self.comm.rank())
            .collect();
        let mut keep = vec![false; n];
        mine.iter().for_each(|&i| keep[i] = true);
        for interaction in interactions {
            interaction.retain_particles(&keep);
        }
        let mut part = whole.without_particles();
        self.halo = Halo {
            total: n,
            ..Halo::default()
        };
        for &i in &mine {
            let row = pack(whole, i, i as u64, &self.species);
            self.halo.id.push(unpack(&mut part, &row, &self.species));
        }
        if let Some((since, _)) = restored {
            self.halo.reference = mine.iter().map(|&i| at(i)).collect();
            self.restored = Some(since);
        }
        part
    }

    /// Each rank's particles, ghosts (at the last build) and particles
    /// sent away so far, at rank 0 in rank order (`None` elsewhere): the
    /// summary's census of the decomposition.
    pub fn census(&self) -> Option<Vec<[u64; 3]>> {
        let mine = [
            self.halo.id.len() as f64,
            self.halo.ghosts.len() as f64,
            self.migrated as f64,
        ];
        let all = self.comm.gather(&mine);
        (self.comm.rank() == 0).then(|| {
            all.iter()
                .map(|v| [v[0] as u64, v[1] as u64, v[2] as u64])
                .collect()
        })
    }

    /// What a checkpoint holds of the lists over the halo, in one
    /// process's form ([`GhostList::carried_state`]): evaluations since the
    /// build, then the wrapped positions there in id order. At rank 0
    /// (`None` elsewhere, and before the first build).
    ///
    /// [`GhostList::carried_state`]: crate::neighbor::GhostList::carried_state
    pub fn carried_state(&self) -> Option<Vec<f64>> {
        let h = &self.halo;
        let rows: Vec<f64> =
            h.id.iter()
                .zip(&h.reference)
                .flat_map(|(id, r)| [*id as f64, r.x, r.y, r.z])
                .collect();
        let all = self.comm.gather(&rows);
        if self.comm.rank() != 0 || self.builds == 0 {
            return None;
        }
        let mut rows: Vec<&[f64]> = all.iter().flat_map(|v| v.chunks(4)).collect();
        rows.sort_by_key(|r| r[0] as u64);
        let mut out = vec![self.since_build as f64];
        out.extend(rows.iter().flat_map(|r| r[1..4].iter().copied()));
        Some(out)
    }

    /// The undivided system at rank 0, particles in id order (`None` on
    /// the other ranks): what output and checkpoints write.
    pub fn gather(&self, part: &System) -> Option<System> {
        let rows: Vec<f64> = (0..part.particles.len())
            .flat_map(|i| pack(part, i, self.halo.id[i], &self.species))
            .collect();
        let all = self.comm.gather(&rows);
        if self.comm.rank() != 0 {
            return None;
        }
        let mut rows: Vec<&[f64]> = all.iter().flat_map(|v| v.chunks(CARRIED)).collect();
        rows.sort_by_key(|r| r[0] as u64);
        let mut whole = part.without_particles();
        for r in rows {
            unpack(&mut whole, r, &self.species);
        }
        Some(whole)
    }

    /// Readies the halo for a force evaluation at the system's positions,
    /// counting one evaluation: the rank's particles' displacements since
    /// the build, and a rebuild when the largest over all ranks exceeds
    /// half the skin, a rebuild is due, or none was made (the one-process
    /// rule of [`GhostList`](crate::neighbor::GhostList)); else the
    /// displacements forwarded to the ghosts. Returns whether it rebuilt.
    /// Particles that migrate take with them what the `interactions` keep
    /// of them ([`Interaction::pack_particle`]).
    pub fn prepare(&mut self, sys: &mut System, interactions: &mut [Box<dyn Interaction>]) -> bool {
        self.remake_restored(&sys.boundary, &Sources::of(sys));
        self.since_build += 1;
        let due = self.every > 0 && self.since_build >= self.every;
        let farthest = self.displace(&sys.particles.position, &sys.boundary);
        let farthest = self.comm.max(farthest);
        if self.builds == 0 || due || farthest > 0.25 * self.skin * self.skin {
            self.build(sys, interactions);
            return true;
        }
        self.forward(&Sources::of(sys));
        false
    }

    /// Brings the ghosts to this rank's particles `own` without counting
    /// an evaluation or rebuilding (measurements between steps, at the
    /// positions of the last evaluation; the first build where none was
    /// made).
    pub fn refresh(&mut self, own: &Sources, boundary: &Boundary) {
        self.remake_restored(boundary, own);
        let position = own.position;
        if self.builds == 0 {
            // Measured before any evaluation (Brownian dynamics primes
            // none): the particles are in their bricks since the scatter,
            // so the first build needs no migration, as one process's
            // list is built at its first refresh.
            self.halo.reference = position.iter().map(|r| boundary.wrap(*r)).collect();
            self.share(boundary, own);
            return;
        }
        self.displace(position, boundary);
        self.forward(own);
    }

    /// Makes the build a checkpoint restored ([`Domain::scatter`]), once.
    fn remake_restored(&mut self, boundary: &Boundary, own: &Sources) {
        if let Some(since) = self.restored.take() {
            self.share(boundary, own);
            self.since_build = since;
        }
    }

    /// Sets this rank's displacements; returns the largest |d|².
    fn displace(&mut self, position: &[DVec3], boundary: &Boundary) -> f64 {
        let h = &mut self.halo;
        if h.reference.len() != position.len() {
            return f64::INFINITY;
        }
        h.displacement.truncate(position.len());
        let mut farthest = 0.0f64;
        for (i, d) in h.displacement.iter_mut().enumerate() {
            *d = boundary.minimum_image(position[i] - h.reference[i]);
            farthest = farthest.max(d.length_squared());
        }
        farthest
    }

    /// Forwards the displacements (and moments and motion, where read,
    /// `own` this rank's) along the build's six messages.
    fn forward(&mut self, own: &Sources) {
        let h = &mut self.halo;
        let n = h.reference.len();
        h.moment.clear();
        h.motion.clear();
        let extra = Extra::new(self.moments, self.motion);
        let width = 3 + extra.width();
        for stage in &self.stages {
            let mut out = Vec::with_capacity(width * stage.send.len());
            for &s in &stage.send {
                let s = s as usize;
                out.extend(h.displacement[s].to_array());
                extra.write(s, n, own, h, &mut out);
            }
            let got = self.comm.exchange(stage.to, &out, stage.from);
            for g in got.chunks(width) {
                h.displacement.push(DVec3::from_slice(&g[..3]));
                extra.read(&g[3..], h);
            }
        }
    }

    /// Migrates the particles that left the brick, shifts the cuts where
    /// the ranks' loads are uneven, then sends the ghosts.
    fn build(&mut self, sys: &mut System, interactions: &mut [Box<dyn Interaction>]) {
        for k in 0..3 {
            self.migrate(sys, k, interactions);
        }
        if self.balance > 0.0 && self.imbalance(sys.particles.len()) > self.balance {
            self.shift_cuts(sys);
            // A particle may now lie bricks away: it moves a brick a pass.
            loop {
                let sent: usize = (0..3).map(|k| self.migrate(sys, k, interactions)).sum();
                if self.comm.sum(&[sent as f64])[0] == 0.0 {
                    break;
                }
            }
        }
        let b = sys.boundary;
        self.halo.reference = sys.particles.position.iter().map(|r| b.wrap(*r)).collect();
        self.share(&b, &Sources::of(sys));
    }

    /// Makes the build at the halo's reference positions: the ghosts,
    /// the particle count and extent every rank's grid needs.
    fn share(&mut self, b: &Boundary, own: &Sources) {
        let h = &mut self.halo;
        h.displacement = vec![DVec3::ZERO; h.reference.len()];
        h.ghosts.clear();
        h.moment.clear();
        h.motion.clear();
        h.total = self.comm.sum(&[h.id.len() as f64])[0] as usize;
        let lo = h.reference.iter().fold(DVec3::INFINITY, |a, r| a.min(*r));
        let hi = h
            .reference
            .iter()
            .fold(DVec3::NEG_INFINITY, |a, r| a.max(*r));
        let lo = -DVec3::from_array(self.comm_max3(-lo));
        let hi = DVec3::from_array(self.comm_max3(hi));
        self.halo.extent = (lo, hi);
        self.send_ghosts(b, own);
        self.since_build = 0;
        self.builds += 1;
        self.halo.generation += 1;
    }

    fn comm_max3(&self, v: DVec3) -> [f64; 3] {
        [self.comm.max(v.x), self.comm.max(v.y), self.comm.max(v.z)]
    }

    /// The most particles a rank holds over the mean.
    fn imbalance(&self, mine: usize) -> f64 {
        let most = self.comm.max(mine as f64);
        let mean = self.comm.sum(&[mine as f64])[0] / self.comm.size() as f64;
        if mean > 0.0 {
            most / mean
        } else {
            1.0
        }
    }

    /// Places the cuts along every cut axis so that each slab holds as
    /// many particles, from their histogram along the axis summed over the
    /// ranks (the same cuts on every rank); each slab stays at least the
    /// cut-off and skin wide, so ghosts still come from face neighbours.
    fn shift_cuts(&mut self, sys: &System) {
        let reach = self.cutoff + self.skin;
        for k in 0..3 {
            let p = self.bricks.dims[k];
            if p == 1 {
                continue;
            }
            let (lo, hi) = if sys.boundary.lengths()[k].is_finite() {
                (sys.boundary.lo[k], sys.boundary.hi[k])
            } else {
                // Over the particles now; the outer slabs reach beyond.
                let (lo, hi) = sys
                    .particles
                    .position
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                        (lo.min(r[k]), hi.max(r[k]))
                    });
                (-self.comm.max(-lo), self.comm.max(hi))
            };
            if !(hi - lo).is_finite() {
                continue;
            }
            let width = (hi - lo) / BINS as f64;
            let mut mine = vec![0.0; BINS];
            for r in &sys.particles.position {
                let x = sys.boundary.wrap(*r)[k];
                mine[(((x - lo) / width) as usize).min(BINS - 1)] += 1.0;
            }
            let count = self.comm.sum(&mine);
            let total: f64 = count.iter().sum();
            let mut inner = Vec::with_capacity(p - 1);
            let (mut below, mut bin) = (0.0, 0);
            for j in 1..p {
                let target = total * j as f64 / p as f64;
                while bin < BINS - 1 && below + count[bin] < target {
                    below += count[bin];
                    bin += 1;
                }
                let within = if count[bin] > 0.0 {
                    ((target - below) / count[bin]).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                inner.push(lo + (bin as f64 + within) * width);
            }
            // Every slab at least `reach` wide: from below, then from above.
            let mut last = lo;
            for c in inner.iter_mut() {
                *c = c.max(last + reach);
                last = *c;
            }
            let mut next = hi;
            for c in inner.iter_mut().rev() {
                *c = c.min(next - reach);
                next = *c;
            }
            self.bricks.shift(k, &inner);
        }
        self.shifts += 1;
    }

    /// Sends along axis k the particles whose brick index along k is no
    /// longer this rank's, to the face neighbour on their side (a particle
    /// moves less than a brick between builds), and takes in the others'.
    /// Each particle's row is followed by what every interaction keeps of
    /// it, as (length, numbers).
    /// Returns how many it sent.
    fn migrate(
        &mut self,
        sys: &mut System,
        k: usize,
        interactions: &mut [Box<dyn Interaction>],
    ) -> usize {
        if self.bricks.dims[k] == 1 {
            return 0;
        }
        let mut sent = 0;
        let (b, at, p) = (sys.boundary, self.bricks.at[k], self.bricks.dims[k]);
        let mut going = [Vec::new(), Vec::new()];
        let mut stays = vec![true; sys.particles.len()];
        for (i, stay) in stays.iter_mut().enumerate() {
            let c = self.bricks.index(k, b.wrap(sys.particles.position[i])[k]);
            if c != at {
                // Below or above, the shorter way round a periodic axis.
                let down = (at + p - c) % p;
                let up = (c + p - at) % p;
                let side = if b.periodic[k] {
                    usize::from(up <= down)
                } else {
                    usize::from(c > at)
                };
                let id = self.halo.id[i];
                let out = &mut going[side];
                out.extend(pack(sys, i, id, &self.species));
                for interaction in interactions.iter() {
                    let head = out.len();
                    out.push(0.0);
                    interaction.pack_particle(i, id, out);
                    out[head] = (out.len() - head - 1) as f64;
                }
                self.migrated += 1;
                sent += 1;
                *stay = false;
            }
        }
        if sent > 0 {
            retain(&mut self.halo.id, &stays);
            sys.retain_particles(&stays);
            for interaction in interactions.iter_mut() {
                interaction.retain_particles(&stays);
            }
        }
        for (side, out) in going.iter().enumerate() {
            let to = self.bricks.neighbour(k, side == 1).map(|n| n.0);
            let from = self.bricks.neighbour(k, side == 0).map(|n| n.0);
            let got = self.comm.exchange(to, out, from);
            let mut at = 0;
            while at < got.len() {
                let id = unpack(sys, &got[at..at + CARRIED], &self.species);
                self.halo.id.push(id);
                at += CARRIED;
                for interaction in interactions.iter_mut() {
                    let len = got[at] as usize;
                    interaction.unpack_particle(id, &got[at + 1..at + 1 + len]);
                    at += 1 + len;
                }
            }
        }
        sent
    }

    /// The staged ghost exchange at a build (see the module's text), the
    /// moments and motion with the copies where interactions read them.
    fn send_ghosts(&mut self, boundary: &Boundary, own: &Sources) {
        let extra = Extra::new(self.moments, self.motion);
        let width = 7 + extra.width();
        let reach = self.cutoff + self.skin;
        let l = boundary.lengths();
        self.stages.clear();
        let h = &mut self.halo;
        let n = h.reference.len();
        for k in 0..3 {
            // The copies at the start of the stage: a stage forwards what
            // the earlier axes brought, not its own.
            let count = n + h.ghosts.len();
            let place = |s: usize, h: &Halo| {
                if s < n {
                    (h.id[s], [0; 3], h.reference[s])
                } else {
                    let g = h.ghosts[s - n];
                    (g.id, g.image, g.base)
                }
            };
            let (lower, upper) = self.bricks.faces(k);
            // A little beyond the reach: a copy too many is never in a row,
            // one too few would be a missing pair. (An axis without a
            // length has no neighbours.)
            let slack = 1e-9 * (reach + if l[k].is_finite() { l[k] } else { 0.0 });
            for up in [false, true] {
                let neighbour = self.bricks.neighbour(k, up);
                let from = self.bricks.neighbour(k, !up).map(|n| n.0);
                let mut send = Vec::new();
                let mut out = Vec::new();
                if let Some((_, image)) = neighbour {
                    for s in 0..count {
                        let (id, mut m, mut at) = place(s, h);
                        let near = if up {
                            at[k] >= upper - reach - slack
                        } else {
                            at[k] < lower + reach + slack
                        };
                        if !near {
                            continue;
                        }
                        if image != 0 {
                            // (Only across a periodic face: an open axis
                            // has no length.)
                            m[k] += image;
                            at[k] += image as f64 * l[k];
                        }
                        send.push(s as u32);
                        out.extend([id as f64, m[0] as f64, m[1] as f64, m[2] as f64]);
                        out.extend(at.to_array());
                        extra.write(s, n, own, h, &mut out);
                    }
                }
                let got = self.comm.exchange(neighbour.map(|n| n.0), &out, from);
                for g in got.chunks(width) {
                    h.ghosts.push(Ghost {
                        id: g[0] as u64,
                        image: [g[1] as i32, g[2] as i32, g[3] as i32],
                        base: DVec3::new(g[4], g[5], g[6]),
                    });
                    h.displacement.push(DVec3::ZERO);
                    extra.read(&g[7..], h);
                }
                self.stages.push(Stage {
                    to: neighbour.map(|n| n.0),
                    from,
                    send,
                });
            }
        }
    }
}

/// What a ghost's record carries beyond its place: its magnetic moment,
/// its motion, where interactions read them.
#[derive(Clone, Copy)]
struct Extra {
    moments: bool,
    motion: bool,
}

impl Extra {
    fn new(moments: bool, motion: bool) -> Self {
        Self { moments, motion }
    }

    fn width(self) -> usize {
        3 * usize::from(self.moments) + Motion::WIDTH * usize::from(self.motion)
    }

    /// Appends copy s's (this rank's particle s < n, else ghost s − n).
    fn write(self, s: usize, n: usize, own: &Sources, h: &Halo, out: &mut Vec<f64>) {
        if self.moments {
            let m = if s < n {
                own.dipole[s]
            } else {
                h.moment[s - n]
            };
            out.extend(m.to_array());
        }
        if self.motion {
            let m = if s < n {
                own.motion(s)
            } else {
                h.motion[s - n]
            };
            m.write(out);
        }
    }

    /// Takes a received copy's from `g`.
    fn read(self, g: &[f64], h: &mut Halo) {
        let mut g = g;
        if self.moments {
            h.moment.push(DVec3::from_slice(&g[..3]));
            g = &g[3..];
        }
        if self.motion {
            h.motion.push(Motion::read(g));
        }
    }
}

/// The box the bricks cut: `boundary`, with the particles' `extent` along
/// its axes of infinite length.
fn cut_box(boundary: &Boundary, extent: (DVec3, DVec3)) -> Boundary {
    let mut cut = *boundary;
    for k in 0..3 {
        if !boundary.lengths()[k].is_finite() {
            cut.lo[k] = extent.0[k];
            cut.hi[k] = extent.1[k];
        }
    }
    cut
}

/// Keeps the entries of `v` where `keep` is true, in order.
pub(crate) fn retain<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut k = keep.iter();
    v.retain(|_| *k.next().expect("one flag per entry"));
}

/// The distinct names in `names`, in order of first appearance.
fn distinct(names: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        if !out.contains(n) {
            out.push(n.clone());
        }
    }
    out
}

/// Particle i of `sys` as [`CARRIED`] numbers: id, species, x, v, mass,
/// charge, radius, colour, mobility, ω, inertia, dipole moment, which of
/// the carried accelerations the system holds (1: linear, 2: angular),
/// and those.
fn pack(sys: &System, i: usize, id: u64, species: &[String]) -> [f64; CARRIED] {
    let p = &sys.particles;
    let kind = sys
        .species
        .get(i)
        .and_then(|s| species.iter().position(|n| n == s))
        .map_or(-1.0, |k| k as f64);
    let mut row = [0.0; CARRIED];
    row[0] = id as f64;
    row[1] = kind;
    row[2..5].copy_from_slice(&p.position[i].to_array());
    row[5..8].copy_from_slice(&p.velocity[i].to_array());
    row[8] = p.mass[i];
    row[9] = p.charge[i];
    row[10] = p.radius[i];
    row[11..14].copy_from_slice(&p.color[i]);
    row[14..17].copy_from_slice(&p.mobility[i].to_array());
    row[17..20].copy_from_slice(&p.angular_velocity[i].to_array());
    row[20] = p.inertia[i];
    row[21..24].copy_from_slice(&p.dipole[i].to_array());
    let (acc, alpha) = (&sys.carried_acceleration, &sys.carried_angular_acceleration);
    row[24] = f64::from(u8::from(!acc.is_empty()) + 2 * u8::from(!alpha.is_empty()));
    if let Some(a) = acc.get(i) {
        row[25..28].copy_from_slice(&a.to_array());
    }
    if let Some(a) = alpha.get(i) {
        row[28..31].copy_from_slice(&a.to_array());
    }
    row
}

/// Appends the particle [`pack`] wrote to `sys`; returns its id.
fn unpack(sys: &mut System, row: &[f64], species: &[String]) -> u64 {
    let p = &mut sys.particles;
    p.position.push(DVec3::from_slice(&row[2..5]));
    p.velocity.push(DVec3::from_slice(&row[5..8]));
    p.mass.push(row[8]);
    p.charge.push(row[9]);
    p.radius.push(row[10]);
    p.color.push([row[11], row[12], row[13]]);
    p.mobility.push(DVec3::from_slice(&row[14..17]));
    p.angular_velocity.push(DVec3::from_slice(&row[17..20]));
    p.inertia.push(row[20]);
    p.dipole.push(DVec3::from_slice(&row[21..24]));
    if row[1] >= 0.0 {
        sys.species.push(species[row[1] as usize].clone());
    }
    let carried = row[24] as u8;
    if carried & 1 != 0 {
        sys.carried_acceleration
            .push(DVec3::from_slice(&row[25..28]));
    }
    if carried & 2 != 0 {
        sys.carried_angular_acceleration
            .push(DVec3::from_slice(&row[28..31]));
    }
    row[0] as u64
}

/// Every particle's K numbers in id order, at every rank: this rank's
/// (`own`, in its particles' order) with the halo's ids go to rank 0,
/// which places them and sends the whole back. A sum over every particle
/// (a mesh, a structure factor) made from them is made from the same
/// numbers in the same order as one process makes it, so its bits do not
/// depend on the ranks (positions are the ranks' own, unwrapped, as one
/// process holds them). The long-range solvers' way to the whole system:
/// P3M's meshes, the Ewald sums.
pub fn gathered<const K: usize>(
    own: impl Iterator<Item = [f64; K]>,
    halo: &Halo,
    comm: &dyn Comm,
    total: usize,
) -> Vec<[f64; K]> {
    let mut send = Vec::with_capacity((K + 1) * halo.id.len());
    for (id, values) in halo.id.iter().zip(own) {
        send.push(*id as f64);
        send.extend(values);
    }
    let parts = comm.gather(&send);
    let mut placed = Vec::new();
    if comm.rank() == 0 {
        placed = vec![0.0; K * total];
        for record in parts.iter().flat_map(|p| p.chunks_exact(K + 1)) {
            let id = record[0] as usize;
            placed[K * id..K * (id + 1)].copy_from_slice(&record[1..]);
        }
    }
    comm.broadcast(&placed)
        .chunks_exact(K)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect()
}
