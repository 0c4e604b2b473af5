//! Particles that enter and leave a run: inserters bring spheres into
//! regions at a number or mass rate ([`insert`]), outlets take out those
//! that reach a region or cross a face ([`outlet`]), every `every` steps,
//! after the step's kick (LAMMPS and LIGGGHTS do it between steps too).
//!
//! What the run keeps exact:
//!
//! - **Mass balance**: every particle has an id; inserted ones take the
//!   next unused id, so ids increase along the particles and a contact's
//!   history follows its two ids through a removal. in − out = held, in
//!   number and in mass, at every event.
//! - **Rates**: by time t an inserter has made ⌊ṅ (t − t₀)⌋ particles (or
//!   the fewest whose mass reaches ṁ (t − t₀)); a region too full to take
//!   them leaves the rest owed to the next event, and the summary says so.
//! - **Resumes**: an event's random numbers come from a generator seeded
//!   by the run's seed, the step and the inserter (no state to carry),
//!   and the checkpoint holds which particles exist, by id, with the
//!   inserter and size of each inserted one: a resumed run is the
//!   uninterrupted one bit for bit.
//!
//! A new particle is placed clear of every particle and wall, so its
//! contacts start without history; its first half kick, before any force
//! has been evaluated for it, uses a zero acceleration (as a LAMMPS
//! `fix deposit` atom's does).

pub mod insert;
pub mod outlet;

use glam::DVec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::boundary::Boundary;
use crate::force::granular::Wall;
use crate::force::ForceField;
use crate::particles::System;

pub use insert::{clear_of, Inserter, Rate, Stream};
pub use outlet::{Departure, Exit, Outlet};

/// An axis-aligned box [lo, hi]; flat on one axis, a face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub lo: DVec3,
    pub hi: DVec3,
}

impl Region {
    /// Whether x lies in the box (lower faces in, upper out).
    pub fn contains(&self, x: DVec3) -> bool {
        x.cmpge(self.lo).all() && x.cmplt(self.hi).all()
    }

    pub fn volume(&self) -> f64 {
        (self.hi - self.lo).element_product()
    }

    /// The distance from x to the box (0 inside), through the periodic
    /// axes' nearest image.
    pub fn distance(&self, x: DVec3, boundary: &Boundary) -> f64 {
        let centre = 0.5 * (self.lo + self.hi);
        let half = 0.5 * (self.hi - self.lo);
        let d = boundary.minimum_image(x - centre).abs() - half;
        d.max(DVec3::ZERO).length()
    }
}

/// Marks the particles the scene made (not an inserter).
const SCENE: u32 = u32::MAX;

/// The inserters and outlets of a run.
#[derive(Debug, Clone)]
pub struct Flow {
    pub inserters: Vec<Inserter>,
    pub outlets: Vec<Outlet>,
    /// Steps between events (≥ 1).
    pub every: u64,
    /// The walls new particles keep clear of.
    pub walls: Vec<Wall>,
    ledger: Ledger,
    /// The particles that left at the last event.
    pub departed: Vec<Departure>,
    /// Mass in and out at each event.
    pub balance: Balance,
}

/// Who made each particle, and the next id: what a flow's checkpoint
/// rows say of the particles (shared by spheres and rigid clumps).
#[derive(Debug, Clone)]
pub struct Ledger {
    /// The next unused id.
    next_id: u64,
    /// The inserter that made each particle, or [`SCENE`].
    made_by: Vec<u32>,
}

/// What a checkpoint's particle rows say: which of the scene's particles
/// are still there, and each inserted one as (id, inserter, two numbers
/// its inserter wrote: a sphere's radius and mass, a clump's template
/// and mass).
pub struct Restored {
    pub keep: Vec<bool>,
    pub inserted: Vec<(u64, usize, f64, f64)>,
}

impl Ledger {
    /// The scene's `n` particles, ids 0 … n − 1.
    pub fn new(n: usize) -> Self {
        Self {
            next_id: n as u64,
            made_by: vec![SCENE; n],
        }
    }

    /// Drops the rows of the particles not kept.
    pub fn retain(&mut self, keep: &[bool]) {
        crate::domain::retain(&mut self.made_by, keep);
    }

    /// A particle inserter `by` made: its id.
    pub fn arrive(&mut self, by: usize) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        self.made_by.push(by as u32);
        id
    }

    /// The next unused id.
    pub fn next_id(&self) -> u64 {
        self.next_id
    }

    /// Appends a row (id, inserter or −1 for the scene's, a, b) per
    /// particle, `row(i)` giving its id, a and b.
    pub fn write(&self, out: &mut Vec<f64>, row: impl Fn(usize) -> [f64; 3]) {
        for (i, by) in self.made_by.iter().enumerate() {
            let by = if *by == SCENE { -1.0 } else { *by as f64 };
            let [id, a, b] = row(i);
            out.extend([id, by, a, b]);
        }
    }

    /// Reads [`Ledger::write`]'s rows, with the next id, for a scene that
    /// makes `scene` particles and has `inserters` inserters; the ledger
    /// then holds the particles the rows name, the scene's first, then the
    /// inserted ones in order (the caller adds those).
    pub fn read(
        &mut self,
        next_id: f64,
        rows: &[f64],
        scene: usize,
        inserters: usize,
    ) -> Result<Restored, String> {
        let bad = |what: &str| format!("flow: {what}");
        if !whole(next_id) {
            return Err(bad("the next id is not a whole number"));
        }
        if !rows.len().is_multiple_of(4) {
            return Err(bad("particle rows of 4 numbers expected"));
        }
        let mut keep = vec![false; scene];
        let mut last = None;
        let mut inserted = Vec::new();
        for r in rows.chunks(4) {
            let (id, by) = (r[0], r[1]);
            if !whole(id) || last.is_some_and(|l| id <= l) || id >= next_id {
                return Err(bad(&format!("particle id {id} out of order")));
            }
            last = Some(id);
            if by == -1.0 {
                if id >= scene as f64 {
                    return Err(bad(&format!("particle {id} is not one the scene makes")));
                }
                keep[id as usize] = true;
            } else if whole(by) && (by as usize) < inserters {
                inserted.push((id as u64, by as usize, r[2], r[3]));
            } else {
                return Err(bad(&format!("particle {id} names inserter {by}")));
            }
        }
        self.made_by = vec![SCENE; keep.iter().filter(|k| **k).count()];
        self.made_by.extend(inserted.iter().map(|r| r.1 as u32));
        self.next_id = next_id as u64;
        Ok(Restored { keep, inserted })
    }
}

/// The mass in and out at each event of a run (of this process: a
/// resumed run counts from its resume), from which its summary says
/// whether the flow was steady.
#[derive(Debug, Clone, Default)]
pub struct Balance {
    /// (t, mass in, mass out, number in, number out) since the run
    /// began, at each event.
    samples: Vec<[f64; 5]>,
}

/// In and out within this fraction of each other: a steady flow (the
/// toning nip's issue asks 2 %).
pub const STEADY: f64 = 0.02;

impl Balance {
    /// Records the running totals of the streams and outlets at time t.
    pub fn record<'a>(
        &mut self,
        t: f64,
        streams: impl Iterator<Item = &'a Stream> + Clone,
        outlets: &[Outlet],
    ) {
        let mass_in = streams.clone().map(|i| i.mass).sum();
        let mass_out = outlets.iter().map(|o| o.mass).sum();
        let n_in = streams.map(|i| i.inserted as f64).sum();
        let n_out = outlets.iter().map(|o| o.removed as f64).sum();
        self.samples.push([t, mass_in, mass_out, n_in, n_out]);
        // A long run keeps every other sample once it holds 2¹⁴ (the
        // samples stay evenly spread in time, the memory bounded).
        let n = self.samples.len();
        if n >= 1 << 14 {
            let mut k = 0;
            self.samples.retain(|_| {
                k += 1;
                (n - k).is_multiple_of(2)
            });
        }
    }

    /// The mean rates in and out over the later half of the events seen
    /// (t₀, t₁, ṁ_in, ṁ_out, ṅ_in, ṅ_out), `None` before two events.
    pub fn later_half(&self) -> Option<(f64, f64, f64, f64, f64, f64)> {
        let last = *self.samples.last()?;
        let first = self.samples[self.samples.len() / 2];
        let span = last[0] - first[0];
        (span > 0.0).then(|| {
            let rate = |k: usize| (last[k] - first[k]) / span;
            (first[0], last[0], rate(1), rate(2), rate(3), rate(4))
        })
    }

    /// The summary's sentence: the rates over the later half of the run
    /// and whether they agree within [`STEADY`].
    pub fn sentence(&self) -> Option<String> {
        let (t0, t1, m_in, m_out, n_in, n_out) = self.later_half()?;
        if m_in == 0.0 && m_out == 0.0 {
            return None;
        }
        let apart = (m_in - m_out).abs() / m_in.abs().max(m_out.abs());
        let verdict = if apart <= STEADY {
            format!("steady (in and out within {:.0} %)", 100.0 * STEADY)
        } else if m_in > m_out {
            "not steady: the held mass grows".to_string()
        } else {
            "not steady: the held mass falls".to_string()
        };
        Some(format!(
            "Over t = {t0:.6e} … {t1:.6e} (the later half of this run's events): mass in \
             {m_in:.6e} per unit time, out {m_out:.6e}, {:.1} % apart (in number {:.6e} in, \
             {:.6e} out): {verdict}.",
            100.0 * apart,
            n_in,
            n_out
        ))
    }
}

/// Whether x is a whole number a checkpoint can count with.
fn whole(x: f64) -> bool {
    x >= 0.0 && x.fract() == 0.0 && x < 2f64.powi(53)
}

/// The streams' and outlets' counts as observables columns: for each
/// stream (inserted, mass), for each outlet (removed, mass, charge).
pub fn tally_columns<'a>(
    streams: impl Iterator<Item = &'a Stream>,
    outlets: &[Outlet],
) -> Vec<f64> {
    let ins = streams.flat_map(|i| [i.inserted as f64, i.mass]);
    let outs = outlets
        .iter()
        .flat_map(|o| [o.removed as f64, o.mass, o.charge]);
    ins.chain(outs).collect()
}

/// The names of [`tally_columns`]: `in_NAME`, `mass_in_NAME`,
/// `out_NAME`, `mass_out_NAME`, `charge_out_NAME`.
pub fn tally_names<'a>(
    streams: impl Iterator<Item = &'a Stream>,
    outlets: &[Outlet],
) -> Vec<String> {
    let ins = streams.flat_map(|i| [format!("in_{}", i.name), format!("mass_in_{}", i.name)]);
    let outs = outlets.iter().flat_map(|o| {
        [
            format!("out_{}", o.name),
            format!("mass_out_{}", o.name),
            format!("charge_out_{}", o.name),
        ]
    });
    ins.chain(outs).collect()
}

/// What came and went, for a run's summary; `[one, things]` names what
/// flows (`["particle", "particles"]`, `["body", "bodies"]`).
pub fn tally_summary<'a>(
    streams: impl Iterator<Item = &'a Stream> + Clone,
    outlets: &[Outlet],
    held: usize,
    [one, things]: [&str; 2],
) -> String {
    let n_in: u64 = streams.clone().map(|i| i.inserted).sum();
    let n_out: u64 = outlets.iter().map(|o| o.removed).sum();
    let m_in: f64 = streams.clone().map(|i| i.mass).sum();
    let m_out: f64 = outlets.iter().map(|o| o.mass).sum();
    let mut text = format!(
        "Flow: {n_in} {things} inserted (mass {m_in:.6e}), {n_out} removed (mass {m_out:.6e}), \
         {held} held."
    );
    for i in streams.filter(|i| i.most_behind > 0) {
        text.push_str(&format!(
            " Inserter {} fell behind its rate by up to {} {}: its region was too full.",
            i.name,
            i.most_behind,
            if i.most_behind == 1 { one } else { things }
        ));
    }
    text
}

/// `text`, and `more` after it where there is more to say.
pub fn join(text: String, more: Option<String>) -> String {
    match more {
        Some(m) => format!("{text} {m}"),
        None => text,
    }
}

/// Appends each stream's count, mass and lag, then each outlet's count,
/// mass and charge (with the numbers of each).
pub fn write_tally<'a>(
    out: &mut Vec<f64>,
    streams: impl ExactSizeIterator<Item = &'a Stream>,
    outlets: &[Outlet],
) {
    out.push(streams.len() as f64);
    for i in streams {
        out.extend([i.inserted as f64, i.mass, i.most_behind as f64]);
    }
    out.push(outlets.len() as f64);
    for o in outlets {
        out.extend([o.removed as f64, o.mass, o.charge]);
    }
}

/// Reads [`write_tally`]'s numbers into the scene's streams and outlets;
/// returns how many numbers it read.
pub fn read_tally<'a>(
    state: &[f64],
    streams: impl ExactSizeIterator<Item = &'a mut Stream>,
    outlets: &mut [Outlet],
) -> Result<usize, String> {
    let bad = |what: &str| format!("flow: {what}");
    let mut at = 0;
    let mut take = |k: usize| -> Result<&[f64], String> {
        let slice = state
            .get(at..at + k)
            .ok_or_else(|| bad("the carried state is cut short"))?;
        at += k;
        Ok(slice)
    };
    if take(1)?[0] != streams.len() as f64 {
        return Err(bad("the checkpoint's inserters are not the scene's"));
    }
    for i in streams {
        let r = take(3)?;
        if !whole(r[0]) || !whole(r[2]) {
            return Err(bad("an inserter's count is not a whole number"));
        }
        (i.inserted, i.mass, i.most_behind) = (r[0] as u64, r[1], r[2] as u64);
    }
    if take(1)?[0] != outlets.len() as f64 {
        return Err(bad("the checkpoint's outlets are not the scene's"));
    }
    for o in outlets {
        let r = take(3)?;
        if !whole(r[0]) {
            return Err(bad("an outlet's count is not a whole number"));
        }
        (o.removed, o.mass, o.charge) = (r[0] as u64, r[1], r[2]);
    }
    Ok(at)
}

/// The random numbers of inserter `c` at `step`: a generator seeded
/// through SplitMix64 from the seed, the step and the inserter.
pub fn stream_rng(seed: u64, step: u64, c: usize) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(
        seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(17)
            ^ (c as u64 + 1)
                .wrapping_mul(0x94D0_49BB_1331_11EB)
                .rotate_left(41),
    )
}

impl Flow {
    /// The flow of a run whose scene made the particles of `sys`, which
    /// get their ids 0, 1, … here.
    pub fn new(
        sys: &mut System,
        inserters: Vec<Inserter>,
        outlets: Vec<Outlet>,
        every: u64,
        walls: Vec<Wall>,
    ) -> Self {
        let n = sys.particles.len();
        sys.id = (0..n as u64).collect();
        Self {
            inserters,
            outlets,
            every: every.max(1),
            walls,
            ledger: Ledger::new(n),
            departed: Vec::new(),
            balance: Balance::default(),
        }
    }

    /// The event at the system's step: the outlets take out what reached
    /// them (in particle order, each particle through the first outlet
    /// that takes it; `departed` lists them by scene number), then each inserter in turn brings its stream up to
    /// the system's time. The interactions hear of both.
    pub fn apply(&mut self, sys: &mut System, forces: &mut ForceField, seed: u64) {
        let (step, time) = (sys.step, sys.time);
        self.departed.clear();
        let n = sys.particles.len();
        let mut keep = vec![true; n];
        for (i, kept) in keep.iter_mut().enumerate() {
            let p = &sys.particles;
            let x = sys.boundary.wrap(p.position[i]);
            let Some(k) = outlet::take(&mut self.outlets, x, p.mass[i], p.charge[i]) else {
                continue;
            };
            *kept = false;
            self.departed.push(Departure {
                step,
                time,
                id: sys.number_of(i),
                outlet: k,
                species: sys.species.get(i).cloned().unwrap_or_else(|| "X".into()),
                mass: p.mass[i],
                charge: p.charge[i],
                radius: p.radius[i],
                position: p.position[i],
                velocity: p.velocity[i],
            });
        }
        // Written in the scene's numbering, whatever the storage order.
        self.departed.sort_by_key(|d| d.id);
        let removed = !self.departed.is_empty();
        if removed {
            sys.retain_particles(&keep);
            self.ledger.retain(&keep);
        }
        let mut arrived = Vec::new();
        let (t, rotating) = (sys.time, forces.exerts_torques());
        for c in 0..self.inserters.len() {
            let mut rng = stream_rng(seed, step, c);
            let made = self.inserters[c].insert(sys, &self.walls, t, &mut rng);
            for m in made {
                let id = self.ledger.arrive(c);
                add(sys, m.init, &m.species, id, rotating);
                arrived.push(id);
            }
        }
        if removed || !arrived.is_empty() {
            forces.particles_changed(removed.then_some(&keep), &arrived);
        }
        let streams = self.inserters.iter().map(|i| &i.stream);
        self.balance.record(time, streams, &self.outlets);
    }

    fn streams(&self) -> impl ExactSizeIterator<Item = &Stream> + Clone {
        self.inserters.iter().map(|i| &i.stream)
    }

    /// Particles in and out, and their masses, since the run began
    /// ([`tally_columns`]).
    pub fn columns(&self) -> Vec<f64> {
        tally_columns(self.streams(), &self.outlets)
    }

    /// The names of [`Flow::columns`].
    pub fn column_names(&self) -> Vec<String> {
        tally_names(self.streams(), &self.outlets)
    }

    /// What came and went, for the run's summary.
    pub fn summary(&self, held: usize) -> String {
        let text = tally_summary(
            self.streams(),
            &self.outlets,
            held,
            ["particle", "particles"],
        );
        join(text, self.balance.sentence())
    }

    /// What a checkpoint needs: the next id, the streams' and outlets'
    /// counts ([`write_tally`]), then a row per particle (id, inserter or
    /// −1 for the scene's, radius, mass).
    pub fn carried_state(&self, sys: &System) -> Vec<f64> {
        let mut out = vec![self.ledger.next_id() as f64];
        write_tally(&mut out, self.streams(), &self.outlets);
        let p = &sys.particles;
        (self.ledger).write(&mut out, |i| [sys.id_of(i) as f64, p.radius[i], p.mass[i]]);
        out
    }

    /// Makes `sys`, freshly built from the scene, hold the particles of
    /// [`Flow::carried_state`]: the scene's particles still there, then
    /// those inserted, each from its inserter with its size (positions and
    /// velocities are the checkpoint's, put in after).
    pub fn restore(
        &mut self,
        state: &[f64],
        sys: &mut System,
        forces: &mut ForceField,
    ) -> Result<(), String> {
        let bad = |what: &str| format!("flow: {what}");
        let Some((&next_id, state)) = state.split_first() else {
            return Err(bad("the carried state is empty"));
        };
        let at = read_tally(
            state,
            self.inserters.iter_mut().map(|i| &mut i.stream),
            &mut self.outlets,
        )?;
        let scene = sys.particles.len();
        let restored = (self.ledger).read(next_id, &state[at..], scene, self.inserters.len())?;
        let keep = &restored.keep;
        sys.retain_particles(keep);
        sys.id = (0..scene as u64)
            .zip(keep)
            .filter(|k| *k.1)
            .map(|k| k.0)
            .collect();
        forces.particles_changed(Some(keep), &[]);
        let mut arrived = Vec::new();
        for &(id, by, radius, mass) in &restored.inserted {
            let ins = &self.inserters[by];
            let mut init = ins.particle(radius);
            if init.mass != mass {
                return Err(bad(&format!(
                    "particle {id}: mass {mass} is not inserter {}'s for radius {radius}",
                    ins.stream.name
                )));
            }
            init.position = DVec3::ZERO;
            add(sys, init, &ins.species.clone(), id, forces.exerts_torques());
            arrived.push(id);
        }
        forces.particles_changed(None, &arrived);
        Ok(())
    }
}

/// Appends a particle of id `id` and species `species` to `sys`, with
/// zero carried accelerations where the integrator carries them (angular
/// ones where the forces turn the particles).
fn add(
    sys: &mut System,
    init: crate::particles::ParticleInit,
    species: &str,
    id: u64,
    rotating: bool,
) {
    let n = sys.particles.len();
    if sys.species.len() != n {
        sys.species = vec!["X".to_string(); n];
    }
    if sys.carried_acceleration.len() == n {
        sys.carried_acceleration.push(DVec3::ZERO);
    }
    if rotating && sys.carried_angular_acceleration.len() == n {
        sys.carried_angular_acceleration.push(DVec3::ZERO);
    }
    sys.particles.push(init);
    sys.species.push(species.to_string());
    sys.id.push(id);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream() -> Stream {
        Stream {
            name: "s".into(),
            region: Region {
                lo: DVec3::ZERO,
                hi: DVec3::ONE,
            },
            rate: Rate::Number(1.0),
            start: 0.0,
            count: None,
            fill: None,
            velocity: DVec3::ZERO,
            velocity_spread: 0.0,
            attempts: 1,
            inserted: 0,
            mass: 0.0,
            most_behind: 0,
        }
    }

    /// Equal rates over the later half are steady, whatever came before;
    /// a rate 5 % short is not.
    #[test]
    fn the_summary_says_how_far_a_stream_fell_behind_in_its_own_words() {
        let mut s = stream();
        (s.inserted, s.mass, s.most_behind) = (5, 15.0, 1);
        let one = tally_summary([s.clone()].iter(), &[], 5, ["body", "bodies"]);
        assert!(
            one.starts_with("Flow: 5 bodies inserted (mass 1.500000e1), 0 removed")
                && one.ends_with(
                    "Inserter s fell behind its rate by up to 1 body: its region was too full."
                ),
            "{one}"
        );
        s.most_behind = 3;
        let three = tally_summary([s].iter(), &[], 5, ["particle", "particles"]);
        assert!(
            three.ends_with("by up to 3 particles: its region was too full."),
            "{three}"
        );
    }

    #[test]
    fn a_flow_is_steady_when_in_and_out_agree_over_the_later_half() {
        // One particle of mass 3 in per unit time; from t = 50 one out.
        let record = |b: &mut Balance, t: f64, n_in: u64, n_out: u64, m_out: f64| {
            let mut s = stream();
            (s.inserted, s.mass) = (n_in, 3.0 * n_in as f64);
            let mut o = Outlet::new("o", Exit::Region(s.region));
            (o.removed, o.mass) = (n_out, m_out);
            b.record(t, [s].iter(), &[o]);
        };
        let mut b = Balance::default();
        assert_eq!(b.sentence(), None);
        for k in 0..=100u64 {
            let out = k.saturating_sub(50);
            record(&mut b, k as f64, k, out, 3.0 * out as f64);
        }
        assert_eq!(b.later_half().unwrap(), (50.0, 100.0, 3.0, 3.0, 1.0, 1.0));
        let steady = b.sentence().unwrap();
        assert!(
            steady.ends_with(
                "0.0 % apart (in number 1.000000e0 in, 1.000000e0 out): steady (in and out within 2 %)."
            ),
            "{steady}"
        );
        // Thinned when long, the last sample kept.
        let mut long = Balance::default();
        for k in 0..=(1u64 << 15) {
            record(&mut long, k as f64, k, k, 3.0 * k as f64);
        }
        assert!(long.samples.len() < 1 << 14);
        assert_eq!(long.samples.last().unwrap()[0], (1u64 << 15) as f64);
        // The same count out, each 5 % lighter.
        let mut short = Balance::default();
        for k in 0..=100u64 {
            record(&mut short, k as f64, k, k, 2.85 * k as f64);
        }
        let growing = short.sentence().unwrap();
        assert!(growing.contains("5.0 % apart"), "{growing}");
        assert!(
            growing.ends_with("not steady: the held mass grows."),
            "{growing}"
        );
    }
}
