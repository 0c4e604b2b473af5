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
use crate::force::HaloReach;
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
    /// The number of particles on all ranks.
    pub total: usize,
    /// The smallest and largest wrapped coordinates of all particles at the
    /// build: the cell grid of an open axis spans them.
    pub extent: (DVec3, DVec3),
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
    halo: Halo,
    stages: Vec<Stage>,
    since_build: u64,
    /// The builds so far (the run summary's count).
    pub builds: u64,
    /// The particles this rank has sent to another so far.
    pub migrated: u64,
    /// A checkpoint's build to remake at the first evaluation: its
    /// evaluations since (the positions are the halo's reference).
    restored: Option<u64>,
    /// The species names of the undivided system; a particle carries its
    /// species as an index into them.
    species: Vec<String>,
}

/// The numbers a migrating particle carries, [`pack`]'s layout.
const CARRIED: usize = 31;

impl Domain {
    /// This rank's part of a run over `boundary` on `comm`'s ranks, for
    /// pair lists of `reach` ([`ForceField::halo_reach`]); `grid` forces
    /// the bricks. A run without pairs rebuilds (migrates) every step.
    ///
    /// [`ForceField::halo_reach`]: crate::ForceField::halo_reach
    pub fn new(
        comm: Arc<dyn Comm>,
        boundary: &Boundary,
        reach: HaloReach,
        grid: Option<[usize; 3]>,
    ) -> Result<Self, String> {
        let (cutoff, skin) = if reach == HaloReach::NONE {
            (0.0, 0.0)
        } else {
            (reach.cutoff, reach.skin)
        };
        let dims = Bricks::choose(comm.size(), boundary, cutoff + skin, grid)?;
        let bricks = Bricks::new(dims, comm.rank(), boundary);
        Ok(Self {
            comm,
            bricks,
            cutoff,
            skin,
            every: reach.every,
            moments: reach.moments,
            halo: Halo::default(),
            stages: Vec::new(),
            since_build: 0,
            builds: 0,
            migrated: 0,
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
    /// is remade at the first evaluation, as one process remakes it.
    pub fn scatter(&mut self, whole: &System, restored: Option<(u64, Vec<DVec3>)>) -> System {
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
    pub fn prepare(&mut self, sys: &mut System) -> bool {
        self.remake_restored(&sys.boundary, &sys.particles.dipole);
        self.since_build += 1;
        let due = self.every > 0 && self.since_build >= self.every;
        let farthest = self.displace(&sys.particles.position, &sys.boundary);
        let farthest = self.comm.max(farthest);
        if self.builds == 0 || due || farthest > 0.25 * self.skin * self.skin {
            self.build(sys);
            return true;
        }
        self.forward(&sys.particles.dipole);
        false
    }

    /// Brings the ghosts to positions `position` (and moments `dipole`)
    /// of this rank's particles without counting an evaluation or
    /// rebuilding (measurements between steps, at the positions of the
    /// last evaluation; the first build where none was made).
    pub fn refresh(&mut self, position: &[DVec3], dipole: &[DVec3], boundary: &Boundary) {
        self.remake_restored(boundary, dipole);
        if self.builds == 0 {
            // Measured before any evaluation (Brownian dynamics primes
            // none): the particles are in their bricks since the scatter,
            // so the first build needs no migration, as one process's
            // list is built at its first refresh.
            self.halo.reference = position.iter().map(|r| boundary.wrap(*r)).collect();
            self.share(boundary, dipole);
            return;
        }
        self.displace(position, boundary);
        self.forward(dipole);
    }

    /// Makes the build a checkpoint restored ([`Domain::scatter`]), once.
    fn remake_restored(&mut self, boundary: &Boundary, dipole: &[DVec3]) {
        if let Some(since) = self.restored.take() {
            self.share(boundary, dipole);
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

    /// Forwards the displacements (and moments, `dipole` this rank's)
    /// along the build's six messages.
    fn forward(&mut self, dipole: &[DVec3]) {
        let h = &mut self.halo;
        let n = h.reference.len();
        h.moment.clear();
        let width = if self.moments { 6 } else { 3 };
        for stage in &self.stages {
            let mut out = Vec::with_capacity(width * stage.send.len());
            for &s in &stage.send {
                let s = s as usize;
                out.extend(h.displacement[s].to_array());
                if self.moments {
                    let m = if s < n { dipole[s] } else { h.moment[s - n] };
                    out.extend(m.to_array());
                }
            }
            let got = self.comm.exchange(stage.to, &out, stage.from);
            for g in got.chunks(width) {
                h.displacement.push(DVec3::from_slice(&g[..3]));
                if self.moments {
                    h.moment.push(DVec3::from_slice(&g[3..6]));
                }
            }
        }
    }

    /// Migrates the particles that left the brick, then sends the ghosts.
    fn build(&mut self, sys: &mut System) {
        for k in 0..3 {
            self.migrate(sys, k);
        }
        let b = sys.boundary;
        self.halo.reference = sys.particles.position.iter().map(|r| b.wrap(*r)).collect();
        self.share(&b, &sys.particles.dipole);
    }

    /// Makes the build at the halo's reference positions: the ghosts,
    /// the particle count and extent every rank's grid needs.
    fn share(&mut self, b: &Boundary, dipole: &[DVec3]) {
        let h = &mut self.halo;
        h.displacement = vec![DVec3::ZERO; h.reference.len()];
        h.ghosts.clear();
        h.moment.clear();
        h.total = self.comm.sum(&[h.id.len() as f64])[0] as usize;
        let lo = h.reference.iter().fold(DVec3::INFINITY, |a, r| a.min(*r));
        let hi = h
            .reference
            .iter()
            .fold(DVec3::NEG_INFINITY, |a, r| a.max(*r));
        let lo = -DVec3::from_array(self.comm_max3(-lo));
        let hi = DVec3::from_array(self.comm_max3(hi));
        self.halo.extent = (lo, hi);
        self.send_ghosts(b, dipole);
        self.since_build = 0;
        self.builds += 1;
        self.halo.generation += 1;
    }

    fn comm_max3(&self, v: DVec3) -> [f64; 3] {
        [self.comm.max(v.x), self.comm.max(v.y), self.comm.max(v.z)]
    }

    /// Sends along axis k the particles whose brick index along k is no
    /// longer this rank's, to the face neighbour on their side (a particle
    /// moves less than a brick between builds), and takes in the others'.
    fn migrate(&mut self, sys: &mut System, k: usize) {
        if self.bricks.dims[k] == 1 {
            return;
        }
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
                going[side].extend(pack(sys, i, self.halo.id[i], &self.species));
                self.migrated += 1;
                *stay = false;
            }
        }
        retain(&mut self.halo.id, &stays);
        sys.retain_particles(&stays);
        for (side, out) in going.iter().enumerate() {
            let to = self.bricks.neighbour(k, side == 1).map(|n| n.0);
            let from = self.bricks.neighbour(k, side == 0).map(|n| n.0);
            let got = self.comm.exchange(to, out, from);
            for row in got.chunks(CARRIED) {
                self.halo.id.push(unpack(sys, row, &self.species));
            }
        }
    }

    /// The staged ghost exchange at a build (see the module's text), the
    /// moments with the copies where interactions read them.
    fn send_ghosts(&mut self, boundary: &Boundary, dipole: &[DVec3]) {
        let moments = self.moments;
        let width = if moments { 10 } else { 7 };
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
                        m[k] += image;
                        at[k] += image as f64 * l[k];
                        send.push(s as u32);
                        out.extend([id as f64, m[0] as f64, m[1] as f64, m[2] as f64]);
                        out.extend(at.to_array());
                        if moments {
                            let mu = if s < n { dipole[s] } else { h.moment[s - n] };
                            out.extend(mu.to_array());
                        }
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
                    if moments {
                        h.moment.push(DVec3::new(g[7], g[8], g[9]));
                    }
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
