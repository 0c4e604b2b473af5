//! Contacts between spheres, through a half Verlet list whose every entry
//! carries the history of that pair's contact. The list is the force
//! field's shared one when the step's [`State`] brings it (every run built
//! from a scene), else the interaction's own.

use glam::DVec3;
use rayon::prelude::*;

use super::history::{block_firsts, split_blocks, PairHistories};
use super::law::{ContactLaw, History};
use crate::force::{add_block_buffers, BlockBuffers, Interaction, Spin, State, Virial};
use crate::neighbor::VerletList;

/// Hertz–Mindlin contacts between all spheres (see [`super::law`]).
///
/// The history (tangential and rolling elongations) sits beside the
/// neighbour list, one entry per listed pair ([`PairHistories`]). Radii and
/// the box come with the step's [`State`].
#[derive(Debug, Clone)]
pub struct GranularContacts {
    pub law: ContactLaw,
    /// The list used when the state brings none (direct callers).
    pub list: VerletList,
    pairs: PairHistories,
    /// The build of the list the histories were last carried to.
    carried_to_build: u64,
    /// One (force, torque) buffer per extra block of particles.
    buffers: BlockBuffers,
    contacts: usize,
    virial: Virial,
}

impl GranularContacts {
    /// Contacts among spheres with radii up to `r_max` (the list's reach is
    /// 2 r_max + `skin`).
    pub fn new(law: ContactLaw, r_max: f64, skin: f64) -> Self {
        Self {
            law,
            list: VerletList::half(2.0 * r_max, skin),
            pairs: PairHistories::default(),
            carried_to_build: 0,
            buffers: Vec::new(),
            contacts: 0,
            virial: Virial::default(),
        }
    }

    /// Number of touching pairs at the last force evaluation.
    pub fn contacts(&self) -> usize {
        self.contacts
    }

    /// The contact history of pair (i, j), if they are listed.
    pub fn history(&self, i: usize, j: usize) -> Option<History> {
        self.pairs.get(i, j)
    }

    /// Brings the own list up to date when the state brings no shared one.
    fn refresh_own(&mut self, state: &State) {
        if state.neighbours.is_none() {
            self.list.update(state.position, state.boundary);
        }
    }

    /// After a rebuild of `list` the histories move with it.
    fn follow(pairs: &mut PairHistories, carried_to_build: &mut u64, list: &VerletList) {
        if list.builds != *carried_to_build || pairs.len() != list.neighbors.len() {
            pairs.carry_to(&list.start, &list.neighbors);
            *carried_to_build = list.builds;
        }
    }

    fn evaluate(
        &mut self,
        state: &State,
        omega: &[DVec3],
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let n = state.position.len();
        self.refresh_own(state);
        let list = state.neighbours.unwrap_or(&self.list);
        Self::follow(&mut self.pairs, &mut self.carried_to_build, list);
        let dt = state.step.dt;

        let blocks = Self::blocks(n);
        let firsts = block_firsts(&list.start, blocks);
        self.buffers
            .resize_with(blocks.saturating_sub(1), Default::default);
        let mut buffers = std::mem::take(&mut self.buffers);
        let mut history = std::mem::take(&mut self.pairs.history);
        let mut touching = std::mem::take(&mut self.pairs.touching);

        let history_blocks = split_blocks(&mut history, &mut touching, &list.start, &firsts);
        // Block 0 adds into the output, block b > 0 into a buffer over the
        // particles from its first one to the end (pairs have j > i).
        let mut targets: Vec<(&mut [DVec3], &mut [DVec3])> = Vec::with_capacity(blocks);
        targets.push((&mut *force, &mut *torque));
        for (b, (f, t)) in buffers.iter_mut().enumerate() {
            let len = n - firsts[b + 1];
            f.clear();
            f.resize(len, DVec3::ZERO);
            t.clear();
            t.resize(len, DVec3::ZERO);
            targets.push((f.as_mut_slice(), t.as_mut_slice()));
        }

        let this = &*self;
        let results: Vec<(usize, Virial)> = targets
            .into_par_iter()
            .zip(history_blocks)
            .enumerate()
            .map(|(b, ((f, t), (hist, touch)))| {
                let (first, last) = (firsts[b], firsts[b + 1]);
                let base = n - f.len();
                this.block(
                    state,
                    list,
                    omega,
                    first..last,
                    dt,
                    (base, f, t),
                    hist,
                    touch,
                )
            })
            .collect();

        add_block_buffers(force, torque, &buffers);
        self.pairs.history = history;
        self.pairs.touching = touching;
        self.buffers = buffers;
        self.contacts = results.iter().map(|r| r.0).sum();
        self.virial = results.iter().map(|r| r.1).sum();
    }

    /// Blocks of particles of the parallel pair loop: a function of N
    /// alone (never of the thread count), one per 4096 particles, at most
    /// 16, so that the sums, and so the bits, are the same on any number of
    /// threads; each block past the first costs a buffer of forces and
    /// torques.
    fn blocks(n: usize) -> usize {
        (n / 4096).clamp(1, 16)
    }

    /// The pairs of particles `range` (and their partners j > i), adding
    /// forces and torques into `out` = (base, f, t), f[k] and t[k] those of
    /// particle base + k; returns (contacts, virial tensor).
    #[allow(clippy::too_many_arguments)]
    fn block(
        &self,
        state: &State,
        list: &VerletList,
        omega: &[DVec3],
        range: std::ops::Range<usize>,
        dt: f64,
        out: (usize, &mut [DVec3], &mut [DVec3]),
        hist: &mut [History],
        touch: &mut [bool],
    ) -> (usize, Virial) {
        let (base, f, t) = out;
        debug_assert!(base <= range.start);
        let pos = state.position;
        let vel = state.velocity;
        let mass = state.mass;
        let radius = state.radius;
        let image = state.boundary.image();
        let offset = list.start[range.start] as usize;
        let mut contacts = 0usize;
        let mut virial = Virial::default();
        for i in range {
            let (ri, vi, wi, radi, mi) = (pos[i], vel[i], omega[i], radius[i], mass[i]);
            let (mut fi, mut ti) = (DVec3::ZERO, DVec3::ZERO);
            let lo = list.start[i] as usize;
            for (k, &j) in list.of(i).iter().enumerate() {
                let j = j as usize;
                let slot = lo + k - offset;
                let d = image.apply(ri - pos[j]);
                let reach = radi + radius[j];
                let r2 = d.length_squared();
                if r2 >= reach * reach {
                    if touch[slot] {
                        touch[slot] = false;
                        hist[slot] = History::default();
                    }
                    continue;
                }
                touch[slot] = true;
                let h = &mut hist[slot];
                let r = r2.sqrt();
                let nrm = d / r;
                let delta = reach - r;
                let (arm_i, arm_j) = (radi - 0.5 * delta, radius[j] - 0.5 * delta);
                let wj = omega[j];
                let v_rel = vi - vel[j] - (wi * arm_i + wj * arm_j).cross(nrm);
                let r_eff = radi * radius[j] / reach;
                let m_eff = mi * mass[j] / (mi + mass[j]);
                let c = self.law.force(
                    delta,
                    nrm,
                    v_rel,
                    wi - wj,
                    arm_i,
                    arm_j,
                    r_eff,
                    m_eff,
                    dt,
                    h,
                );
                fi += c.force;
                f[j - base] -= c.force;
                ti += c.torque_i;
                t[j - base] += c.torque_j;
                contacts += 1;
                virial += Virial::pair(d, c.force);
            }
            f[i - base] += fi;
            t[i - base] += ti;
        }
        (contacts, virial)
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

    /// [NaN (the time of the last evaluation before dt came with the
    /// state; kept so earlier checkpoints load), then per touching pair
    /// i, j, ξ (3), ψ (3)].
    fn carried_state(&self) -> Vec<f64> {
        let mut out = vec![f64::NAN];
        self.pairs.write_rows(&mut out);
        out
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        let Some((_, rows)) = state.split_first() else {
            return Ok(());
        };
        self.pairs
            .restore_rows(rows, usize::MAX)
            .map_err(|m| format!("granular {m}"))
    }

    /// The elastic energy of the Hertz springs, Σ (8/15) E* √R* δ^{5/2}.
    fn potential_energy(&mut self, state: &State) -> f64 {
        let pos = state.position;
        self.refresh_own(state);
        let list = state.neighbours.unwrap_or(&self.list);
        let image = state.boundary.image();
        let radius = state.radius;
        let mut u = 0.0;
        for i in 0..pos.len() {
            for &j in list.of(i) {
                let j = j as usize;
                let reach = radius[i] + radius[j];
                let r = image.apply(pos[i] - pos[j]).length();
                if r < reach {
                    let delta = reach - r;
                    let r_eff = radius[i] * radius[j] / reach;
                    u += self.law.elastic_energy(delta, r_eff);
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
