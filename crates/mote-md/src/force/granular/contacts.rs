//! Contacts between spheres, over pairs listed in one order on one process
//! and on any number of ranks ([`ContactPairs`]), each carrying the history
//! of its contact. On one process the pairs are those of the force field's
//! shared half list when the step's [`State`] brings it (every run built
//! from a scene), else of the interaction's own; in a decomposed run, those
//! within reach among the rank's particles and ghosts ([`State::halo`]).
//!
//! A step evaluates the rows in parallel blocks: each pair once, its force
//! and torque summed into its row's particle, those on the partner put in
//! the partner's inbox; then each particle adds its inbox and its row, in
//! parallel. Within a block, each run of rows (at most `BATCH` pairs)
//! first keeps its touching pairs, then applies the law to them four at a
//! time ([`super::batch`], the scalar law's bits), then sums them in list
//! order. No two threads write one place, and the bits depend neither
//! on the threads nor on the ranks.

use glam::DVec3;
use rayon::prelude::*;

use super::batch::{ContactBatch, Spheres};
use super::history::{block_firsts, split_blocks};
use super::law::{ContactLaw, History};
use super::pairs::{ContactPairs, GHOST};
use crate::boundary::Boundary;
use crate::domain::Halo;
use crate::force::{CarriedRows, HaloReach, Interaction, Spin, State, Virial};
use crate::neighbor::VerletList;

/// The most pairs a batch of the contact loop holds (its rows' pairs).
const BATCH: usize = 256;

/// Hertz–Mindlin contacts between all spheres (see [`super::law`]).
///
/// The history (tangential and rolling elongations) sits beside the listed
/// pairs, one entry each. Radii and the box come with the step's [`State`].
#[derive(Debug, Clone)]
pub struct GranularContacts {
    pub law: ContactLaw,
    /// The list used when the state brings none (direct callers).
    pub list: VerletList,
    pairs: ContactPairs,
    /// What the pairs were listed from.
    listed_from: Option<Listed>,
    /// The list the inbox was laid out for (zero where no contact is).
    inbox_for: Option<Listed>,
    /// Each row's sum of its contacts' forces and torques.
    row_sum: Vec<(DVec3, DVec3)>,
    /// The force and torque of each contact on its partner, in the
    /// partners' inboxes.
    inbox: Vec<(DVec3, DVec3)>,
    /// A decomposed run's particles and ghosts as the pairs read them.
    bodies: Bodies,
    /// The list over a rank's particles and ghosts (decomposed runs).
    halo_list: VerletList,
    /// Each block's touching pairs, kept between steps for their memory.
    batches: Vec<ContactBatch>,
    contacts: usize,
    virial: Virial,
}

/// The list the pairs were taken from: a half list's build and length, or
/// a halo's generation.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Listed {
    List(u64, usize),
    Halo(u64),
}

/// A rank's particles and one copy of each other rank's particle near its
/// brick, in order of their ids: the rows its pairs read (decomposed runs).
#[derive(Debug, Clone, Default)]
struct Bodies {
    /// The halo's ghost copy each row that is not the rank's reads.
    copy: Vec<u32>,
    position: Vec<DVec3>,
    velocity: Vec<DVec3>,
    spin: Vec<DVec3>,
    radius: Vec<f64>,
    mass: Vec<f64>,
}

/// The particles a step's pairs read, by row.
#[derive(Clone, Copy)]
struct View<'a> {
    position: &'a [DVec3],
    velocity: &'a [DVec3],
    spin: &'a [DVec3],
    radius: &'a [f64],
    mass: &'a [f64],
}

impl<'a> View<'a> {
    /// The state's particles (spins `omega`), or on a rank the rows
    /// `bodies` gathered.
    fn of(bodies: &'a Bodies, state: &State<'a>, omega: &'a [DVec3]) -> Self {
        match state.halo {
            Some(_) => bodies.view(),
            None => View {
                position: state.position,
                velocity: state.velocity,
                spin: omega,
                radius: state.radius,
                mass: state.mass,
            },
        }
    }
}

impl Bodies {
    /// The rows at `state` (spins `omega`): this rank's particles as
    /// `pairs` places them, the ghosts' motion now.
    fn gather(&mut self, state: &State, omega: &[DVec3], halo: &Halo, pairs: &ContactPairs) {
        let motion = |t: u32| {
            halo.motion
                .get(t as usize)
                .copied()
                .expect("the halo forwards the ghosts' motion to granular contacts")
        };
        for v in [&mut self.position, &mut self.velocity, &mut self.spin] {
            v.clear();
        }
        self.radius.clear();
        self.mass.clear();
        for (&p, &t) in pairs.particle.iter().zip(&self.copy) {
            let (x, v, w, radius, mass) = if p == GHOST {
                let m = motion(t);
                (m.position, m.velocity, m.spin, m.radius, m.mass)
            } else {
                let p = p as usize;
                let at = |a: &[f64]| a[p];
                (
                    state.position[p],
                    state.velocity[p],
                    omega[p],
                    at(state.radius),
                    at(state.mass),
                )
            };
            self.position.push(x);
            self.velocity.push(v);
            self.spin.push(w);
            self.radius.push(radius);
            self.mass.push(mass);
        }
    }

    fn view(&self) -> View<'_> {
        View {
            position: &self.position,
            velocity: &self.velocity,
            spin: &self.spin,
            radius: &self.radius,
            mass: &self.mass,
        }
    }
}

impl GranularContacts {
    /// Contacts among spheres with radii up to `r_max` (the list's reach is
    /// 2 r_max + `skin`).
    pub fn new(law: ContactLaw, r_max: f64, skin: f64) -> Self {
        Self {
            law,
            list: VerletList::half(2.0 * r_max, skin),
            pairs: ContactPairs::default(),
            listed_from: None,
            inbox_for: None,
            row_sum: Vec::new(),
            inbox: Vec::new(),
            bodies: Bodies::default(),
            halo_list: VerletList::half(2.0 * r_max, skin),
            batches: Vec::new(),
            contacts: 0,
            virial: Virial::default(),
        }
    }

    /// Number of touching pairs at the last force evaluation (on this
    /// rank, those whose lower id is its own).
    pub fn contacts(&self) -> usize {
        self.contacts
    }

    /// The contact history of the particles with ids i and j, if they are
    /// listed.
    pub fn history(&self, i: usize, j: usize) -> Option<History> {
        self.pairs.get(i as u64, j as u64)
    }

    /// Lists the pairs anew where the list they come from was rebuilt, and
    /// gathers a decomposed run's particles and ghosts (spins `omega`).
    fn bring_up_to_date(&mut self, state: &State, omega: &[DVec3]) {
        match state.halo {
            Some(halo) => {
                if self.listed_from != Some(Listed::Halo(halo.generation)) {
                    self.list_halo(halo);
                    self.listed_from = Some(Listed::Halo(halo.generation));
                }
                self.bodies.gather(state, omega, halo, &self.pairs);
            }
            None => {
                if state.neighbours.is_none() {
                    self.list.update(state.position, state.boundary);
                }
                let list = state.neighbours.unwrap_or(&self.list);
                let from = Listed::List(list.builds, list.neighbors.len());
                if self.listed_from != Some(from) {
                    // The rows are the particles, named by their ids
                    // (increasing along them).
                    let n = state.position.len();
                    let particle: Vec<u32> = (0..n as u32).collect();
                    let ids = (0..n).map(|i| state.id.get(i).map_or(i as u32, |id| *id as u32));
                    let (start, partner) = (list.start.clone(), list.neighbors.clone());
                    self.pairs
                        .rebuild(ids.collect(), particle, n, start, partner);
                    self.listed_from = Some(from);
                }
            }
        }
    }

    /// The particles the pairs read: the state's, or on a rank its
    /// particles and ghosts as gathered.
    fn view<'a>(&'a self, state: &State<'a>, omega: &'a [DVec3]) -> View<'a> {
        View::of(&self.bodies, state, omega)
    }

    /// Lists the pairs within reach among a rank's particles and ghosts
    /// at the halo's build: the rows are its particles and one copy of
    /// each other particle near its brick (a particle's copies across
    /// periodic faces are one row), in order of their ids; each pair has
    /// at least one particle of this rank.
    fn list_halo(&mut self, halo: &Halo) {
        let n = halo.id.len();
        assert!(
            halo.total < GHOST as usize,
            "too many particles for u32 lists"
        );
        // (id, particle or GHOST, copy) of every copy; rows are the ids.
        let own = halo.id.iter().enumerate().map(|(i, id)| (*id, i as u32, i));
        let ghosts = halo
            .ghosts
            .iter()
            .enumerate()
            .map(|(g, ghost)| (ghost.id, GHOST, n + g));
        let mut copies: Vec<(u64, u32, usize)> = own.chain(ghosts).collect();
        // A particle of this rank sorts before its copies.
        copies.sort_unstable_by_key(|c| (c.0, c.1 == GHOST, c.2));
        let mut row_of_copy = vec![0u32; copies.len()];
        let (mut row_id, mut particle) = (Vec::new(), Vec::new());
        self.bodies.copy.clear();
        for (k, &(id, p, c)) in copies.iter().enumerate() {
            if k == 0 || copies[k - 1].0 != id {
                row_id.push(id as u32);
                particle.push(p);
                self.bodies.copy.push(c.saturating_sub(n) as u32);
            }
            row_of_copy[c] = (row_id.len() - 1) as u32;
        }
        let at: Vec<DVec3> = halo
            .reference
            .iter()
            .copied()
            .chain(halo.ghosts.iter().map(|g| g.base))
            .collect();
        self.halo_list.build(&at, &Boundary::open());
        let mut listed: Vec<(u32, u32)> = Vec::new();
        for (c, &a) in row_of_copy.iter().enumerate() {
            for &d in self.halo_list.of(c) {
                let b = row_of_copy[d as usize];
                let ghosts = particle[a as usize] == GHOST && particle[b as usize] == GHOST;
                if a != b && !ghosts {
                    listed.push((a.min(b), a.max(b)));
                }
            }
        }
        listed.sort_unstable();
        listed.dedup();
        let mut start = vec![0u32; row_id.len() + 1];
        for &(a, _) in &listed {
            start[a as usize + 1] += 1;
        }
        for r in 0..row_id.len() {
            start[r + 1] += start[r];
        }
        let partner = listed.iter().map(|l| l.1).collect();
        self.pairs.rebuild(row_id, particle, n, start, partner);
    }

    /// The rows' contacts in parallel blocks of rows, then each of this
    /// rank's particles' sum of its inbox and its row, in parallel over the
    /// particles.
    fn evaluate(
        &mut self,
        state: &State,
        omega: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        self.bring_up_to_date(state, omega);
        let pairs = &self.pairs;
        let rows = pairs.rows();
        // Blocks of equal numbers of pairs: how the work is cut changes no
        // sum.
        let firsts = block_firsts(&pairs.start, (pairs.len() / 4096).clamp(1, 256));
        let mut history = std::mem::take(&mut self.pairs.history);
        let mut touching = std::mem::take(&mut self.pairs.touching);
        let pairs = &self.pairs;
        self.row_sum.resize(rows, (DVec3::ZERO, DVec3::ZERO));
        if self.inbox.len() != pairs.inbox_pair.len() || self.listed_from != self.inbox_for {
            self.inbox.clear();
            self.inbox
                .resize(pairs.inbox_pair.len(), (DVec3::ZERO, DVec3::ZERO));
            self.inbox_for = self.listed_from;
        }
        let inbox = Inbox(self.inbox.as_mut_ptr());
        let mut row_sums = Vec::with_capacity(firsts.len());
        let mut rest = self.row_sum.as_mut_slice();
        for w in firsts.windows(2) {
            let (head, tail) = rest.split_at_mut(w[1] - w[0]);
            row_sums.push(head);
            rest = tail;
        }
        let at = View::of(&self.bodies, state, omega);
        let image = state.boundary.image();
        let (law, dt) = (&self.law, state.step.dt);
        let blocks = split_blocks(&mut history, &mut touching, &pairs.start, &firsts);
        self.batches
            .resize_with(blocks.len(), ContactBatch::default);
        let sums: Vec<(usize, Virial)> = blocks
            .into_par_iter()
            .zip(row_sums)
            .zip(self.batches.par_iter_mut())
            .enumerate()
            .map(|(block, (((history, touching), row_sum), batch))| {
                let (first, base) = (firsts[block], pairs.start[firsts[block]] as usize);
                let spheres = Spheres {
                    velocity: at.velocity,
                    spin: at.spin,
                    radius: at.radius,
                    mass: at.mass,
                };
                let (mut count, mut virial) = (0usize, Virial::default());
                let end = first + row_sum.len();
                // Runs of rows with at most BATCH pairs (or one row), so
                // that a batch stays in the first-level cache from the
                // filter through the law to the sums.
                let mut rows = first..first;
                while rows.end < end {
                    rows.start = rows.end;
                    rows.end += 1;
                    let from = pairs.start[rows.start] as usize;
                    while rows.end < end && pairs.start[rows.end + 1] as usize - from <= BATCH {
                        rows.end += 1;
                    }
                    // The touching pairs, in list order; the others'
                    // histories cleared where they had touched.
                    batch.clear(pairs.start[rows.end] as usize - from);
                    for a in rows.clone() {
                        let (xa, ra) = (at.position[a], at.radius[a]);
                        for s in pairs.start[a] as usize..pairs.start[a + 1] as usize {
                            let (k, b) = (s - base, pairs.partner[s] as usize);
                            let d = image.apply(xa - at.position[b]);
                            let reach = ra + at.radius[b];
                            let r2 = d.length_squared();
                            let now = r2 < reach * reach;
                            batch.push_if(now, a, b, s, d, r2);
                            if touching[k] & !now {
                                history[k] = History::default();
                                let slot = pairs.inbox_slot[s];
                                if slot != GHOST {
                                    // SAFETY: as below.
                                    unsafe { inbox.put(slot as usize, (DVec3::ZERO, DVec3::ZERO)) };
                                }
                            }
                            touching[k] = now;
                        }
                    }
                    batch.evaluate(law, spheres, dt, history, base);
                    // Each row's contacts summed in list order.
                    let mut c = 0;
                    for a in rows.clone() {
                        let (mut f, mut t) = (DVec3::ZERO, DVec3::ZERO);
                        let counts = pairs.counts(a);
                        while c < batch.len() && batch.ends[c][0] as usize == a {
                            let (contact, s) = (batch.force[c], batch.entry[c] as usize);
                            f += contact.force;
                            t += contact.torque_i;
                            let slot = pairs.inbox_slot[s];
                            if slot != GHOST {
                                // SAFETY: each pair has its own slot (a
                                // pair's place in its partner's inbox), so
                                // no two writes meet, and the slot is
                                // within the inbox, sized for every slot.
                                unsafe {
                                    inbox.put(slot as usize, (-contact.force, contact.torque_j))
                                };
                            }
                            if counts {
                                count += 1;
                                virial += Virial::pair(batch.separation[c], contact.force);
                            }
                            c += 1;
                        }
                        row_sum[a - first] = (f, t);
                    }
                }
                (count, virial)
            })
            .collect();
        let (row_sum, inbox) = (&self.row_sum, &self.inbox);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
            .for_each(|(p, (f, t))| {
                let (mut in_f, mut in_t) = (DVec3::ZERO, DVec3::ZERO);
                for e in pairs.inbox_start[p] as usize..pairs.inbox_start[p + 1] as usize {
                    in_f += inbox[e].0;
                    in_t += inbox[e].1;
                }
                let (row_f, row_t) = row_sum[pairs.row[p] as usize];
                *f += in_f + row_f;
                *t += in_t + row_t;
            });
        self.pairs.history = history;
        self.pairs.touching = touching;
        self.contacts = sums.iter().map(|s| s.0).sum();
        self.virial = sums.iter().map(|s| s.1).sum();
    }
}

/// The inbox as the blocks of rows write it, each pair to its own slot.
#[derive(Clone, Copy)]
struct Inbox(*mut (DVec3, DVec3));

// SAFETY: the blocks write disjoint slots (see the write) and nothing
// reads the inbox until they are done.
unsafe impl Send for Inbox {}
unsafe impl Sync for Inbox {}

impl Inbox {
    /// Writes slot k.
    ///
    /// # Safety
    /// k is within the inbox and no other thread touches slot k meanwhile.
    unsafe fn put(&self, k: usize, value: (DVec3, DVec3)) {
        *self.0.add(k) = value;
    }
}

impl Interaction for GranularContacts {
    fn name(&self) -> &'static str {
        "granular"
    }

    fn exerts_torques(&self) -> bool {
        true
    }

    /// Without rotation the spheres are taken as not spinning.
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

    /// Pairs within 2 r_max + skin of the rank's particles; the ghosts'
    /// positions, velocities, spins, radii and masses forwarded at every
    /// evaluation.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach {
            cutoff: self.list.cutoff,
            skin: self.list.skin,
            every: self.list.every,
            moments: false,
            motion: true,
        })
    }

    /// [NaN (the time of the last evaluation before dt came with the
    /// state; kept so earlier checkpoints load), then per touching pair
    /// i, j, ξ (3), ψ (3)].
    fn carried_state(&self) -> Vec<f64> {
        let mut out = vec![f64::NAN];
        self.pairs.write_rows(&mut out);
        out
    }

    /// The pairs are named by their ids already: each rank writes those
    /// whose lower id is its own.
    fn carried_rows(&self, _: &[u64]) -> Option<CarriedRows> {
        let mut rows = Vec::new();
        self.pairs.write_rows(&mut rows);
        Some(CarriedRows {
            head: vec![f64::NAN],
            width: super::history::PAIR_ROW,
            rows,
        })
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        let Some((_, rows)) = state.split_first() else {
            return Ok(());
        };
        self.pairs
            .restore_rows(rows)
            .map_err(|m| format!("granular {m}"))
    }

    fn pack_particle(&self, _: usize, id: u64, out: &mut Vec<f64>) {
        self.pairs.pack(id, out);
    }

    fn unpack_particle(&mut self, id: u64, data: &[f64]) {
        self.pairs.arrive(id, data);
        (self.listed_from, self.inbox_for) = (None, None);
    }

    /// The pairs are listed afresh at the next evaluation (a list of the
    /// same length is not the same list once particles have gone); their
    /// histories follow by the particles' ids.
    fn retain_particles(&mut self, _: &[bool]) {
        (self.listed_from, self.inbox_for) = (None, None);
    }

    /// The elastic energy of the Hertz springs, Σ (8/15) E* √R* δ^{5/2}
    /// (on a rank, of the pairs it counts).
    fn potential_energy(&mut self, state: &State) -> f64 {
        let omega = vec![DVec3::ZERO; state.position.len()];
        self.bring_up_to_date(state, &omega);
        let at = self.view(state, &omega);
        let image = state.boundary.image();
        let pairs = &self.pairs;
        let mut u = 0.0;
        for a in (0..pairs.rows()).filter(|&a| pairs.counts(a)) {
            for &b in &pairs.partner[pairs.start[a] as usize..pairs.start[a + 1] as usize] {
                let b = b as usize;
                let reach = at.radius[a] + at.radius[b];
                let r = image.apply(at.position[a] - at.position[b]).length();
                if r < reach {
                    let r_eff = at.radius[a] * at.radius[b] / reach;
                    u += self.law.elastic_energy(reach - r, r_eff);
                }
            }
        }
        u
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial.trace())
    }

    /// The tensor of the last force evaluation (contact forces depend on
    /// their histories, which only a step advances).
    fn virial_tensor(&mut self, _: &State) -> Option<Virial> {
        Some(self.virial)
    }

    fn neighbour_reach(&self) -> Option<(f64, f64)> {
        Some((self.list.cutoff, self.list.skin))
    }
}
