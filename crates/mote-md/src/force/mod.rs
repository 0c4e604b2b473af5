//! Forces: an [`Interaction`] adds forces to every particle it acts on; a
//! [`ForceField`] is the list of interactions of a run. One virtual call per
//! interaction per evaluation, never per pair: each interaction's pair loop
//! is a plain generic loop over `#[inline]` kernels.

mod damping;
pub mod dipolar;
mod electric;
pub mod ewald;
pub mod granular;
mod gravity;
pub mod latent;
pub mod lennard_jones;
pub mod p3m;
pub mod slab;
mod springs;
pub mod timing;
mod uniform;
mod virial;
mod whole;

pub use damping::GlobalDamping;
pub use electric::{DirectCoulomb, ElectricField};
pub use gravity::DirectGravity;
pub use lennard_jones::LennardJones;
pub use springs::{Spring, SpringNetwork};
pub use uniform::UniformField;
pub use virial::Virial;

/// "(1, 0, 0)": a vector as a change's answer writes it.
pub(crate) fn vector_text(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

use glam::DVec3;
use rayon::prelude::*;

use crate::boundary::Boundary;
use crate::domain::{Domain, Halo};
use crate::neighbor::VerletList;
use crate::particles::System;
pub use crate::viewer::ViewerHooks;
use mote_run::comm::Comm;

/// The parameters of one force evaluation that every interaction reads,
/// for point particles ([`State::step`]) and rigid bodies
/// ([`BodyView::step`](crate::rigid::BodyView)) alike — one struct for both
/// contexts, as rapier's `IntegrationParameters` is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepParameters {
    /// The time t of the evaluation.
    pub time: f64,
    /// The time since the previous force evaluation of the run, by which
    /// history-dependent forces advance (the tangential springs of
    /// granular contacts, ξ += v_t dt): the step h after a step, 0 where an
    /// evaluation repeats or only measures a state (the first evaluation
    /// of a leap-frog run, observables). Set by the integrator.
    pub dt: f64,
}

/// The per-step context of every interaction: a read-only view of the
/// state at which forces are evaluated (the integrator's stage, which need
/// not be the system's current state) and the particles' properties and box
/// as the system holds them. Interactions read radii, charges and the box
/// from here and keep no copies.
#[derive(Clone, Copy)]
pub struct State<'a> {
    pub position: &'a [DVec3],
    pub velocity: &'a [DVec3],
    pub mass: &'a [f64],
    /// The time of the evaluation and the time since the previous one.
    pub step: StepParameters,
    /// Radius of each particle (empty when the caller gives none).
    pub radius: &'a [f64],
    /// Charge of each particle (empty when the caller gives none).
    pub charge: &'a [f64],
    /// Magnetic dipole moment m of each particle (empty when the caller
    /// gives none; zero for particles without one).
    pub dipole: &'a [DVec3],
    /// The simulation box.
    pub boundary: &'a Boundary,
    /// The force field's shared half neighbour list, up to date for
    /// `position` ([`ForceField`] sets it; `None` from the constructors:
    /// an interaction then uses a list of its own).
    pub neighbours: Option<&'a VerletList>,
    /// In a decomposed run, this rank's particles and the ghosts near its
    /// brick, up to date for `position` ([`ForceField`] sets it): an
    /// interaction that decomposes lists its pairs over them.
    pub halo: Option<&'a Halo>,
    /// The ranks of a decomposed run ([`ForceField`] sets it beside
    /// `halo`): what an interaction that sums over every particle (a mesh)
    /// gathers through.
    pub comm: Option<&'a dyn Comm>,
    /// Each particle's id (empty: particle i has id i); ids differ from
    /// indices where particles come and go ([`crate::flow`]).
    pub id: &'a [u64],
}

/// The pairs an interaction lists over a decomposed run's halo: those
/// within `cutoff` + `skin`, its list rebuilt when a particle has moved
/// half the skin or, if `every` > 0, after that many evaluations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HaloReach {
    pub cutoff: f64,
    pub skin: f64,
    pub every: u64,
    /// Whether it reads the ghosts' magnetic moments (forwarded with
    /// their displacements at every evaluation: they turn).
    pub moments: bool,
    /// Whether it reads the ghosts' [`Motion`](crate::domain::Motion):
    /// position, velocity, angular velocity, radius and mass as their
    /// particles hold them (forwarded at every evaluation; contacts).
    pub motion: bool,
}

impl HaloReach {
    /// A force on each particle alone: no pairs.
    pub const NONE: HaloReach = HaloReach {
        cutoff: 0.0,
        skin: f64::INFINITY,
        every: 0,
        moments: false,
        motion: false,
    };

    /// One halo for both: the widest cut-off and skin together, rebuilt
    /// when either list must be (the smaller skin, the more frequent
    /// forced rebuild).
    pub fn and(self, other: HaloReach) -> HaloReach {
        if self == Self::NONE {
            return other;
        }
        if other == Self::NONE {
            return self;
        }
        let reach = (self.cutoff + self.skin).max(other.cutoff + other.skin);
        let skin = self.skin.min(other.skin);
        let every = match (self.every, other.every) {
            (0, e) | (e, 0) => e,
            (a, b) => a.min(b),
        };
        HaloReach {
            cutoff: reach - skin,
            skin,
            every,
            moments: self.moments || other.moments,
            motion: self.motion || other.motion,
        }
    }
}

/// A rank's part of what an interaction carries, in one process's form
/// ([`Interaction::carried_rows`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CarriedRows {
    /// What comes before the rows (the same on every rank).
    pub head: Vec<f64>,
    /// Numbers per row.
    pub width: usize,
    pub rows: Vec<f64>,
}

/// The box of a state given without one.
static OPEN_SPACE: Boundary = Boundary {
    lo: DVec3::NEG_INFINITY,
    hi: DVec3::INFINITY,
    periodic: [false; 3],
};

impl<'a> State<'a> {
    /// Positions, velocities and masses alone, in open space, with no radii
    /// or charges (kernels and their tests).
    pub fn new(position: &'a [DVec3], velocity: &'a [DVec3], mass: &'a [f64], time: f64) -> Self {
        Self {
            position,
            velocity,
            mass,
            step: StepParameters { time, dt: 0.0 },
            radius: &[],
            charge: &[],
            dipole: &[],
            boundary: &OPEN_SPACE,
            neighbours: None,
            halo: None,
            comm: None,
            id: &[],
        }
    }

    /// The system's particles at an integrator stage (`position`,
    /// `velocity`, `time`), `dt` after the previous evaluation, with their
    /// radii, charges, dipoles and box.
    pub fn of(
        sys: &'a System,
        position: &'a [DVec3],
        velocity: &'a [DVec3],
        time: f64,
        dt: f64,
    ) -> Self {
        let p = &sys.particles;
        Self {
            position,
            velocity,
            mass: &p.mass,
            step: StepParameters { time, dt },
            radius: &p.radius,
            charge: &p.charge,
            dipole: &p.dipole,
            boundary: &sys.boundary,
            neighbours: None,
            halo: None,
            comm: None,
            id: &sys.id,
        }
    }

    /// The charges, one per particle (an interaction that needs them
    /// panics with this message when the caller gave none).
    pub fn charges(&self) -> &'a [f64] {
        assert_eq!(
            self.charge.len(),
            self.position.len(),
            "charges must come with the state, one per particle"
        );
        self.charge
    }

    /// The same state with these charges.
    pub fn with_charges(self, charge: &'a [f64]) -> Self {
        Self { charge, ..self }
    }

    /// The same state with these dipoles.
    pub fn with_dipoles(self, dipole: &'a [DVec3]) -> Self {
        Self { dipole, ..self }
    }

    /// The same state with these radii.
    pub fn with_radii(self, radius: &'a [f64]) -> Self {
        Self { radius, ..self }
    }

    /// The same state, `dt` after the previous evaluation.
    pub fn after(self, dt: f64) -> Self {
        Self {
            step: StepParameters { dt, ..self.step },
            ..self
        }
    }

    /// The same state in this box.
    pub fn in_box(self, boundary: &'a Boundary) -> Self {
        Self { boundary, ..self }
    }
}

/// The rotational state at which torques are evaluated, beside [`State`].
#[derive(Clone, Copy)]
pub struct Spin<'a> {
    /// Angular velocity ω of each particle.
    pub angular_velocity: &'a [DVec3],
}

/// Something that exerts forces.
pub trait Interaction: Send + Sync {
    /// A short name for reports (`gravity`, `springs`, ...).
    fn name(&self) -> &'static str;
    /// Adds this interaction's force on each particle to `force`.
    fn add_forces(&mut self, state: &State, force: &mut [DVec3]);
    /// What it needs to run decomposed, where it can: its forces on a
    /// rank's particles come from those particles and the ghosts of
    /// [`State::halo`] within the reach it names (none for a force on
    /// each particle alone). `None`: it cannot run decomposed.
    fn halo_reach(&self) -> Option<HaloReach> {
        None
    }
    /// The build of its pair list a checkpoint restored and the list has
    /// not made yet (evaluations since it, wrapped positions there): a
    /// decomposed run remakes it over its halo.
    fn take_restored_list(&mut self) -> Option<(u64, Vec<DVec3>)> {
        None
    }
    /// Whether this interaction exerts torques (frictional contacts,
    /// dipoles); then the integrator rotates the particles and calls
    /// [`Interaction::add_forces_and_torques`].
    fn exerts_torques(&self) -> bool {
        false
    }
    /// Adds forces and torques about each particle's centre. Interactions
    /// without torques keep the default, which adds the forces only.
    fn add_forces_and_torques(
        &mut self,
        state: &State,
        spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        let _ = (spin, torque);
        self.add_forces(state, force);
    }
    /// The potential energy of the interaction; 0 for dissipative forces.
    fn potential_energy(&mut self, state: &State) -> f64;
    /// What this interaction carries from one evaluation to the next (contact
    /// histories), as plain numbers for checkpoints; empty if nothing.
    fn carried_state(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Restores what [`Interaction::carried_state`] gave, before the first
    /// evaluation of a resumed run.
    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        if state.is_empty() {
            Ok(())
        } else {
            Err(format!("{} carries no state", self.name()))
        }
    }
    /// In a decomposed run, this rank's part of
    /// [`Interaction::carried_state`] in one process's form, its particles
    /// named by their ids (row i of the rank is particle `id[i]`): a head,
    /// then rows of `width` numbers, each row held by one rank, which rank
    /// 0 puts in the order of their first two numbers. `None`: it carries
    /// nothing per particle (or its list, which the domain gathers).
    fn carried_rows(&self, id: &[u64]) -> Option<CarriedRows> {
        let _ = id;
        None
    }
    /// Appends to `out` what it keeps of particle i (id `id`) that goes
    /// with the particle when it moves to another rank (contact
    /// histories); nothing by default.
    fn pack_particle(&self, i: usize, id: u64, out: &mut Vec<f64>) {
        let _ = (i, id, out);
    }
    /// Keeps the particles where `keep` is true, in order, as a
    /// decomposed run's system does (those leaving already packed).
    fn retain_particles(&mut self, keep: &[bool]) {
        let _ = keep;
    }
    /// Takes in particle `id`, arriving from another rank after this
    /// rank's particles, with what [`Interaction::pack_particle`] wrote.
    fn unpack_particle(&mut self, id: u64, data: &[f64]) {
        let _ = (id, data);
    }
    /// The live viewer's hooks (walls, their loads, steering), where this
    /// interaction has any.
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        None
    }
    /// [`Interaction::viewer`], to steer.
    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        None
    }
    /// The virial W = Σ_pairs r_ij · F_ij of the last force evaluation
    /// (Lennard-Jones: of the last [`Interaction::potential_energy`], which
    /// a measurement asks for first; NaN after a later force pass), for
    /// the pressure P V = N k T + W/3 of periodic systems; `None` where the
    /// interaction does not compute it (the pressure is then not given,
    /// rather than given without its part). External fields, damping and
    /// walls give `Some(0)`: as in LAMMPS, where fixes add no virial unless
    /// told to (`fix_modify virial yes`), they are not part of the pressure.
    fn virial(&self) -> Option<f64> {
        None
    }
    /// The virial tensor W_αβ = Σ_pairs r_ij,α F_ij,β at `state` (see
    /// [`Virial`]), computed when a run asks for the pressure tensor
    /// (`[output] pressure_tensor`), not at every step; `None` where the
    /// interaction does not compute it (the run is then refused, never
    /// given a tensor without its part). Fields, damping and walls give
    /// zero, as [`Interaction::virial`] says.
    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        let _ = state;
        None
    }
    /// The (cut-off, skin) of the pairs this interaction reads from the
    /// shared neighbour list ([`State::neighbours`]); `None` if it reads none.
    fn neighbour_reach(&self) -> Option<(f64, f64)> {
        None
    }
    /// A sentence for the run's summary on the parameters it chose (a
    /// tuned long-range solver's mesh and error estimate); `None` if
    /// there is nothing to say.
    fn describe(&self) -> Option<String> {
        None
    }
}

/// A boxed interaction is one: a scene's tables make them so, and a law
/// between rigid bodies' centres wraps what its table made.
impl Interaction for Box<dyn Interaction> {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        (**self).add_forces(state, force)
    }
    fn halo_reach(&self) -> Option<HaloReach> {
        (**self).halo_reach()
    }
    fn take_restored_list(&mut self) -> Option<(u64, Vec<DVec3>)> {
        (**self).take_restored_list()
    }
    fn exerts_torques(&self) -> bool {
        (**self).exerts_torques()
    }
    fn add_forces_and_torques(
        &mut self,
        state: &State,
        spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        (**self).add_forces_and_torques(state, spin, force, torque)
    }
    fn potential_energy(&mut self, state: &State) -> f64 {
        (**self).potential_energy(state)
    }
    fn carried_state(&self) -> Vec<f64> {
        (**self).carried_state()
    }
    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        (**self).restore_carried_state(state)
    }
    fn carried_rows(&self, id: &[u64]) -> Option<CarriedRows> {
        (**self).carried_rows(id)
    }
    fn pack_particle(&self, i: usize, id: u64, out: &mut Vec<f64>) {
        (**self).pack_particle(i, id, out)
    }
    fn retain_particles(&mut self, keep: &[bool]) {
        (**self).retain_particles(keep)
    }
    fn unpack_particle(&mut self, id: u64, data: &[f64]) {
        (**self).unpack_particle(id, data)
    }
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        (**self).viewer()
    }
    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        (**self).viewer_mut()
    }
    fn virial(&self) -> Option<f64> {
        (**self).virial()
    }
    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        (**self).virial_tensor(state)
    }
    fn neighbour_reach(&self) -> Option<(f64, f64)> {
        (**self).neighbour_reach()
    }
    fn describe(&self) -> Option<String> {
        (**self).describe()
    }
}

/// `state` with the shared list.
fn sharing<'a>(
    state: &State<'a>,
    neighbours: &'a Option<(VerletList, usize)>,
    domain: &'a Option<Domain>,
) -> State<'a> {
    State {
        neighbours: neighbours.as_ref().map(|n| &n.0),
        halo: domain.as_ref().map(|d| d.halo()),
        comm: domain.as_ref().map(|d| d.comm()),
        ..*state
    }
}

/// All interactions of a run, and the one neighbour list the short-range
/// ones share.
#[derive(Default)]
pub struct ForceField {
    pub interactions: Vec<Box<dyn Interaction>>,
    /// Measure the pressure tensor with the observables (a pass of its
    /// own over the pairs: only when a run writes it).
    pub pressure_tensor: bool,
    force: Vec<DVec3>,
    torque: Vec<DVec3>,
    /// The shared half list and the number of interactions it was made for.
    neighbours: Option<(VerletList, usize)>,
    /// Wall time of the force passes, by interaction, and of the list.
    pub timing: timing::Timing,
    /// This rank's part of a decomposed run (`None`: one process).
    pub domain: Option<Domain>,
}

impl ForceField {
    pub fn new() -> Self {
        Self::default()
    }

    /// The keys under which checkpoints carry each interaction's state:
    /// its name, a repeated one numbered (`granular#2`).
    pub fn carried_keys(&self) -> Vec<String> {
        mote_io::checkpoint::carried_keys(self.interactions.iter().map(|i| i.name()))
    }

    pub fn with(mut self, interaction: impl Interaction + 'static) -> Self {
        self.push(interaction);
        self
    }

    pub fn push(&mut self, interaction: impl Interaction + 'static) {
        self.interactions.push(Box::new(interaction));
    }

    pub fn is_empty(&self) -> bool {
        self.interactions.is_empty()
    }

    /// Brings the shared neighbour list up to date at `state`, making it
    /// first from the interactions' reaches (c_k, s_k): it holds the pairs
    /// within R = max(c_k + s_k) and is rebuilt when a particle has moved
    /// half of R − max c_k, so every interaction sees all its pairs. One
    /// build and one displacement check per evaluation, however many
    /// interactions read it.
    fn refresh_neighbours(&mut self, state: &State) {
        if self.domain.is_some() {
            // A decomposed run's interactions list their pairs over the halo.
            return;
        }
        let count = self.interactions.len();
        if self
            .neighbours
            .as_ref()
            .is_none_or(|(_, made_for)| *made_for != count)
        {
            let reaches: Vec<(f64, f64)> = self
                .interactions
                .iter()
                .filter_map(|i| i.neighbour_reach())
                .collect();
            self.neighbours = if reaches.is_empty() {
                None
            } else {
                let cutoff = reaches.iter().map(|r| r.0).fold(0.0, f64::max);
                let reach = reaches.iter().map(|r| r.0 + r.1).fold(0.0, f64::max);
                Some((VerletList::half(cutoff, reach - cutoff), count))
            };
        }
        if let Some((list, _)) = &mut self.neighbours {
            let since = std::time::Instant::now();
            if list.update(state.position, state.boundary) {
                self.timing.builds += 1;
            }
            self.timing.neighbours += since.elapsed();
        }
    }

    /// Tells every interaction that particles left and came
    /// ([`crate::flow`]): those where `keep` is false are gone (`None`:
    /// none left), then the particles of ids `arrived` were appended in
    /// that order, carrying nothing. The shared list is made afresh at the
    /// next evaluation.
    pub fn particles_changed(&mut self, keep: Option<&[bool]>, arrived: &[u64]) {
        for interaction in &mut self.interactions {
            if let Some(keep) = keep {
                interaction.retain_particles(keep);
            }
            for id in arrived {
                interaction.unpack_particle(*id, &[]);
            }
        }
        self.neighbours = None;
    }

    /// Readies a decomposed run's halo for a force evaluation at the
    /// system's positions (particles migrate at a rebuild, so the system
    /// may change); nothing in one process. Integrators call it before
    /// every evaluation.
    pub fn before_forces(&mut self, sys: &mut System) {
        if let Some(domain) = &mut self.domain {
            let since = std::time::Instant::now();
            if domain.prepare(sys, &mut self.interactions) {
                self.timing.builds += 1;
            }
            self.timing.neighbours += since.elapsed();
        }
    }

    /// Brings a decomposed run's ghosts to `state` for a measurement.
    fn refresh_halo(&mut self, state: &State) {
        if let Some(domain) = &mut self.domain {
            let own = crate::domain::Sources {
                position: state.position,
                velocity: state.velocity,
                spin: &[],
                radius: state.radius,
                mass: state.mass,
                dipole: state.dipole,
            };
            domain.refresh(&own, state.boundary);
        }
    }

    /// The halo the interactions need to run decomposed: the widest
    /// reach, the smallest skin, the most frequent forced rebuild; `Err`
    /// with the names of those that cannot.
    pub fn halo_reach(&self) -> Result<HaloReach, Vec<&'static str>> {
        let mut refused = Vec::new();
        let mut need = HaloReach::NONE;
        for i in &self.interactions {
            match i.halo_reach() {
                Some(r) => need = need.and(r),
                None => refused.push(i.name()),
            }
        }
        if refused.is_empty() {
            Ok(need)
        } else {
            Err(refused)
        }
    }

    /// The shared neighbour list as of the last evaluation, if any.
    pub fn neighbours(&self) -> Option<&VerletList> {
        self.neighbours.as_ref().map(|n| &n.0)
    }

    /// Accelerations a_i = F_i / m_i, zero along fixed axes (`mobility`).
    pub fn accelerations(&mut self, state: &State, mobility: &[DVec3], acc: &mut [DVec3]) {
        let n = state.position.len();
        if self.nothing_to_do(n) {
            return;
        }
        self.refresh_neighbours(state);
        let state = &sharing(state, &self.neighbours, &self.domain);
        self.force.clear();
        self.force.resize(n, DVec3::ZERO);
        for (k, interaction) in self.interactions.iter_mut().enumerate() {
            let since = std::time::Instant::now();
            interaction.add_forces(state, &mut self.force);
            self.timing.interaction(k, since);
        }
        let (force, mass) = (&self.force, state.mass);
        acc.par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(i, a)| *a = force[i] / mass[i] * mobility[i]);
    }

    /// Whether there are no particles to evaluate (a run whose particles
    /// are all yet to be inserted, or all gone); a decomposed run's rank
    /// without particles still takes part in its ranks' exchanges.
    fn nothing_to_do(&self, n: usize) -> bool {
        n == 0 && self.domain.is_none()
    }

    /// Whether any interaction exerts torques.
    pub fn exerts_torques(&self) -> bool {
        self.interactions.iter().any(|i| i.exerts_torques())
    }

    /// Accelerations a_i = F_i / m_i and angular accelerations α_i = τ_i / I_i
    /// (zero for particles that do not rotate, see [`Particles::rotates`]).
    ///
    /// [`Particles::rotates`]: crate::Particles::rotates
    pub fn accelerations_and_angular(
        &mut self,
        state: &State,
        spin: &Spin,
        particles: &crate::Particles,
        acc: &mut [DVec3],
        alpha: &mut [DVec3],
    ) {
        let n = state.position.len();
        let (mut force, mut torque) = (
            std::mem::take(&mut self.force),
            std::mem::take(&mut self.torque),
        );
        force.clear();
        force.resize(n, DVec3::ZERO);
        torque.clear();
        torque.resize(n, DVec3::ZERO);
        self.add_forces_and_torques(state, spin, &mut force, &mut torque);
        (self.force, self.torque) = (force, torque);
        let (force, torque, mass) = (&self.force, &self.torque, state.mass);
        (acc, alpha)
            .into_par_iter()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(i, (a, al))| {
                *a = force[i] / mass[i] * particles.mobility[i];
                *al = if particles.rotates(i) {
                    torque[i] / particles.inertia[i]
                } else {
                    DVec3::ZERO
                };
            });
    }

    /// Adds every interaction's forces and torques at `state` to `force`
    /// and `torque` (through the shared neighbour list).
    pub fn add_forces_and_torques(
        &mut self,
        state: &State,
        spin: &Spin,
        force: &mut [DVec3],
        torque: &mut [DVec3],
    ) {
        if self.nothing_to_do(state.position.len()) {
            return;
        }
        self.refresh_neighbours(state);
        let state = &sharing(state, &self.neighbours, &self.domain);
        for (k, interaction) in self.interactions.iter_mut().enumerate() {
            let since = std::time::Instant::now();
            interaction.add_forces_and_torques(state, spin, force, torque);
            self.timing.interaction(k, since);
        }
    }

    /// Total virial of the last force evaluation; `None` if an interaction
    /// does not compute its part ([`ForceField::without_virial`]).
    pub fn virial(&self) -> Option<f64> {
        self.interactions.iter().map(|i| i.virial()).sum()
    }

    /// The virial tensor at `state`, summed over the interactions; `None`
    /// if one does not compute its part ([`ForceField::without_virial_tensor`]).
    pub fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        self.refresh_halo(state);
        self.refresh_neighbours(state);
        let state = &sharing(state, &self.neighbours, &self.domain);
        self.interactions
            .iter_mut()
            .map(|i| i.virial_tensor(state))
            .sum()
    }

    /// The interactions that do not compute their virial tensor.
    pub fn without_virial_tensor(&mut self, state: &State) -> Vec<&'static str> {
        self.refresh_halo(state);
        self.refresh_neighbours(state);
        let state = &sharing(state, &self.neighbours, &self.domain);
        self.interactions
            .iter_mut()
            .filter_map(|i| i.virial_tensor(state).is_none().then(|| i.name()))
            .collect()
    }

    /// The interactions that do not compute their virial: with any of them
    /// the pressure is not given.
    pub fn without_virial(&self) -> Vec<&'static str> {
        self.interactions
            .iter()
            .filter(|i| i.virial().is_none())
            .map(|i| i.name())
            .collect()
    }

    /// Total potential energy, and its parts by interaction name.
    pub fn potential_energy(&mut self, state: &State) -> (f64, Vec<(&'static str, f64)>) {
        if self.nothing_to_do(state.position.len()) {
            let parts = self.interactions.iter().map(|i| (i.name(), 0.0)).collect();
            return (0.0, parts);
        }
        self.refresh_halo(state);
        self.refresh_neighbours(state);
        let state = &sharing(state, &self.neighbours, &self.domain);
        let parts: Vec<(&'static str, f64)> = self
            .interactions
            .iter_mut()
            .map(|it| (it.name(), it.potential_energy(state)))
            .collect();
        (parts.iter().map(|p| p.1).sum(), parts)
    }
}
