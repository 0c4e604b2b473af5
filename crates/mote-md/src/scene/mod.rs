//! Scene files (TOML) and MPPphys particle files, turned into a [`Simulation`].
//!
//! Every key is documented in docs/scene-format.md. Each table of a scene is
//! a settings type in its own file here that checks itself and builds its
//! own part (lumol's `FromToml` per settings type is the model):
//!
//! - [`particles`]: the particle tables and generators, `[[spring]]`;
//! - one file per force law: [`gravity`] (`[gravity]`, `[field]`),
//!   [`lennard_jones`], [`granular`] (`[granular]`, `[[wall]]`), [`dipolar`]
//!   (`[dipolar]`, `[magnetic_field]`), [`electric`] (`[coulomb]`,
//!   `[electric_field]`), [`bath`] (`[damping]`, `[thermostat]`, `[brownian]`);
//! - [`run`]: `[run]`, `[output]`, `[box]`; [`plist`]: MPPphys particle files.
//!
//! A new force law is a settings type implementing [`Section`] in a file of
//! its own, a field of [`SceneFile`], and one line in [`Scene::build`] where
//! the interactions are listed in the order their forces are summed; a law
//! between rigid bodies' centres (masses, charges, dipoles) is one more
//! entry in [`SceneFile::centre_laws`], and rigid scenes take it as it is.
//!
//! Particles are numbered in this order: `[[particle]]` tables, then
//! `[[lattice]]`, `[[ring]]`, `[[annulus]]`, `[[random_box]]`, `[[fcc]]`,
//! `[[cloud]]` and `[[plummer]]` generators, then `[[lammps_data]]` and
//! `[[from_file]]` files,
//! each in file order.

pub mod bath;
pub mod dipolar;
pub mod electric;
pub mod flow;
pub mod granular;
pub mod gravity;
pub mod lennard_jones;
pub mod parallel;
pub mod particles;
pub mod plist;
pub mod run;

use std::ops::Range;

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;
use toml::Spanned;

use mote_io::{ParseError, Source};

use crate::boundary::Boundary;
use crate::force::{ForceField, SpringNetwork};
use crate::integrate::Stepper;
use crate::observe::Probe;
use crate::particles::{Particles, System};
use crate::simulation::Simulation;
use crate::units::UnitSystem;

pub use bath::{BrownianSettings, DampingSettings, ThermostatSettings};
pub use dipolar::{DipolarSettings, MagneticFieldSettings, WcaSettings};
pub use electric::{CoulombLaw, CoulombSettings, ElectricFieldSettings};
pub use granular::{GranularSettings, WallSpec};
pub use gravity::{FieldSettings, GravitySettings};
pub use lennard_jones::LennardJonesSettings;
pub use mote_run::scene::{BoxTable, Origin, OutputTable, RunLength, RunTable, Setting};
pub use particles::{
    AnnulusSpec, CloudSpec, DataSpec, FccSpec, LatticeSpec, LatticeSprings, ModeSpec, ParticleSpec,
    PlummerSpec, Properties, RandomBoxSpec, RingSpec, SpeedSpec, SpringSpec,
};
pub use plist::PlistSystem;

/// A whole scene file: the envelope every time-stepped engine shares
/// (`title`, `seed`, `units`, `[run]`, `[output]`, `[box]`,
/// `[[from_file]]`), the point particles' tables, and `[rigid]`, the rigid
/// clumps' engine table, of type `R`: a point-particle scene ([`Scene`])
/// reads it only to refuse it, a rigid scene (`rigid::scene::RigidScene`,
/// `SceneFile<RigidSettings>`) is built from it, with the laws between
/// point particles its bodies feel between their centres
/// ([`SceneFile::centre_laws`]).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile<R> {
    /// One line saying what the scene is.
    #[serde(default)]
    pub title: String,
    /// `si` (default), `lj` or `astro`.
    #[serde(default)]
    pub units: UnitSystem,
    /// Seed of the random generators; chosen and printed when absent.
    pub seed: Option<u64>,
    #[serde(default)]
    pub run: RunTable,
    pub gravity: Option<Spanned<GravitySettings>>,
    pub field: Option<Spanned<FieldSettings>>,
    pub damping: Option<Spanned<DampingSettings>>,
    pub lennard_jones: Option<Spanned<LennardJonesSettings>>,
    pub thermostat: Option<Spanned<ThermostatSettings>>,
    pub granular: Option<Spanned<GranularSettings>>,
    pub dipolar: Option<Spanned<DipolarSettings>>,
    pub magnetic_field: Option<Spanned<MagneticFieldSettings>>,
    pub coulomb: Option<Spanned<CoulombSettings>>,
    pub electric_field: Option<Spanned<ElectricFieldSettings>>,
    pub brownian: Option<Spanned<BrownianSettings>>,
    #[serde(default)]
    pub plummer: Vec<Spanned<PlummerSpec>>,
    #[serde(default)]
    pub wall: Vec<Spanned<WallSpec>>,
    #[serde(rename = "box")]
    pub bounds: Option<Spanned<BoxTable>>,
    /// `[parallel]`: the bricks of a run on several ranks.
    pub parallel: Option<Spanned<parallel::ParallelTable>>,
    #[serde(default)]
    pub particle: Vec<Spanned<ParticleSpec>>,
    #[serde(default)]
    pub lattice: Vec<Spanned<LatticeSpec>>,
    #[serde(default)]
    pub ring: Vec<Spanned<RingSpec>>,
    #[serde(default)]
    pub annulus: Vec<Spanned<AnnulusSpec>>,
    #[serde(default)]
    pub random_box: Vec<Spanned<RandomBoxSpec>>,
    #[serde(default)]
    pub fcc: Vec<Spanned<FccSpec>>,
    #[serde(default)]
    pub cloud: Vec<Spanned<CloudSpec>>,
    #[serde(default)]
    pub lammps_data: Vec<Spanned<DataSpec>>,
    #[serde(default)]
    pub from_file: Vec<Spanned<DataSpec>>,
    #[serde(default)]
    pub spring: Vec<Spanned<SpringSpec>>,
    /// `[[insert]]`: streams of spheres into regions.
    #[serde(default)]
    pub insert: Vec<Spanned<flow::InsertSpec>>,
    /// `[[outlet]]`: where particles leave.
    #[serde(default)]
    pub outlet: Vec<Spanned<flow::OutletSpec>>,
    #[serde(default)]
    pub output: OutputTable,
    /// `[rigid]`: the rigid clumps' engine table.
    pub rigid: Option<Spanned<R>>,
}

/// A point-particle scene.
pub type Scene = SceneFile<serde::de::IgnoredAny>;

/// A scene turned into its parts, ready to run.
pub struct Built {
    pub simulation: Simulation,
    pub length: Option<RunLength>,
    pub probes: Vec<Probe>,
    pub seed: u64,
}

/// What the sections build together: the particles, the box, the
/// interactions in the order their forces are summed, and the run's random
/// generator (drawn from in table order, so a seed gives one run).
pub struct Build<'a> {
    /// Locates errors: `file:line: message`.
    pub src: Source<'a>,
    pub units: UnitSystem,
    pub rng: Xoshiro256PlusPlus,
    pub particles: Particles,
    pub boundary: Boundary,
    pub forces: ForceField,
    /// The particles are rigid bodies' centres (`SceneFile::centre_laws`):
    /// their masses, charges and dipoles are the templates', and a table
    /// that would change them refuses.
    pub centres_of_bodies: bool,
}

/// The kind of scene a table belongs to: the scene as parsed and what its
/// tables build together. Point particles ([`Points`]: [`Scene`] and
/// [`Build`]) and rigid clumps (`rigid::scene::Clumps`) have their tables
/// as [`Section`]s of their kind.
pub trait Kind {
    type Scene;
    type Build<'a>;
}

/// Point-particle scenes.
pub struct Points;

impl Kind for Points {
    type Scene = Scene;
    type Build<'a> = Build<'a>;
}

/// A table of a scene that adds to what the scene builds (interactions,
/// particles or bodies), in the order the scene's build calls it.
pub trait Section<K: Kind = Points> {
    /// Checks the table and adds what it makes to `b`; `span` locates the
    /// table in errors, `scene` gives the other tables.
    fn add_to(
        &self,
        span: Range<usize>,
        scene: &K::Scene,
        b: &mut K::Build<'_>,
    ) -> Result<(), ParseError>;
}

/// Adds an optional table of a scene of kind `K` (point particles, rigid
/// clumps).
pub(crate) fn add<K: Kind, T: Section<K>>(
    table: &Option<Spanned<T>>,
    scene: &K::Scene,
    b: &mut K::Build<'_>,
) -> Result<(), ParseError> {
    match table {
        Some(t) => t.get_ref().add_to(t.span(), scene, b),
        None => Ok(()),
    }
}

/// Parses a scene of either kind; errors are `file:line: message`.
pub(crate) fn parse<S: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<S, ParseError> {
    Source::new(file, text).finite_numbers()?;
    toml::from_str::<S>(text)
        .map_err(|e| Source::new(file, text).parser_error(e.span(), e.message()))
}

impl<R> SceneFile<R> {
    /// The tables of laws between point particles that rigid bodies feel
    /// between their centres of mass, where their masses, charges and
    /// dipoles sit (`rigid::AtCentres`), in the order their forces are
    /// summed: a law listed here is one kernel for points and clumps.
    pub fn centre_laws(&self) -> Vec<(&dyn Section, Range<usize>)> {
        fn listed<T: Section>(t: &Option<Spanned<T>>) -> Option<(&dyn Section, Range<usize>)> {
            t.as_ref().map(|t| (t.get_ref() as &dyn Section, t.span()))
        }
        [
            listed(&self.gravity),
            listed(&self.dipolar),
            listed(&self.coulomb),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

impl Scene {
    /// Parses a point-particle scene; errors are `file:line: message`.
    pub fn parse(text: &str, file: &str) -> Result<Scene, ParseError> {
        parse(text, file)
    }

    /// Readies the scene to resume `cp`: a checkpoint that names no order
    /// of its particles (written before granular scenes were stored in
    /// space order) resumes in the scene's order, the one it was written in.
    pub fn keep_order_of(&mut self, cp: &mote_io::checkpoint::Checkpoint) {
        if let (false, Some(g)) = (crate::order::names_order(cp), &mut self.granular) {
            g.get_mut().order = granular::ParticleOrder::File;
        }
    }

    /// Builds the simulation. `text` and `file` locate errors; `seed` overrides the scene's.
    pub fn build(&self, text: &str, file: &str, seed: u64) -> Result<Built, ParseError> {
        let src = Source::new(file, text);
        if let Some(r) = &self.rigid {
            return Err(src.error(
                r.span(),
                "[rigid] makes rigid bodies: the scene is the rigid engine's (mote run builds it so)",
            ));
        }
        if let Some(p) = &self.parallel {
            if p.get_ref().grid.is_some_and(|g| g.contains(&0)) {
                return Err(src.error(
                    p.span(),
                    "[parallel] grid: every axis needs at least one brick",
                ));
            }
            if let Some(b) = p.get_ref().balance.filter(|b| !(*b == 0.0 || *b >= 1.0)) {
                return Err(src.error(
                    p.span(),
                    format!(
                        "[parallel] balance = {b}: the imbalance (most particles a rank over \
                         the mean) above which the bricks shift is at least 1, or 0 for never"
                    ),
                ));
            }
        }
        let files = (self.lammps_data.iter().map(|s| ("lammps_data", s)))
            .chain(self.from_file.iter().map(|s| ("from_file", s)));
        for (table, spec) in files {
            if let [key, ..] = spec.get_ref().given(&["templates", "tolerance"])[..] {
                return Err(src.error(
                    spec.span(),
                    format!("[[{table}]] {key}: it matches a frame's spheres to the templates of rigid bodies, and the scene has no [rigid]"),
                ));
            }
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut made = particles::make(self, src, &mut rng)?;
        let in_space_order = self
            .granular
            .as_ref()
            .is_some_and(|g| g.get_ref().order == granular::ParticleOrder::Space);
        let number = in_space_order.then(|| made.to_space_order());
        let boundary = run::boundary(&self.bounds, made.fcc_box, src)?;
        let mut b = Build {
            src,
            units: self.units,
            rng,
            particles: made.particles,
            boundary,
            forces: ForceField::new(),
            centres_of_bodies: false,
        };
        // The interactions, in the order their forces are summed.
        add(&self.gravity, self, &mut b)?;
        if !made.springs.is_empty() {
            b.forces.push(SpringNetwork::new(made.springs));
        }
        add(&self.field, self, &mut b)?;
        add(&self.damping, self, &mut b)?;
        add(&self.lennard_jones, self, &mut b)?;
        add(&self.granular, self, &mut b)?;
        granular::refuse_walls_without_contacts(self, src)?;
        add(&self.dipolar, self, &mut b)?;
        add(&self.magnetic_field, self, &mut b)?;
        add::<Points, _>(&self.coulomb, self, &mut b)?;
        add(&self.electric_field, self, &mut b)?;

        let brownian = bath::brownian(&self.brownian, &b)?;
        let thermostat = bath::thermostat(&self.thermostat, src)?;
        let (integrator, dt, length) = run::schedule(&self.run, src)?;
        run::refuse_event_driven_output(&self.output, src)?;
        let mut probes = run::probes(&self.output, src, b.particles.len())?;
        let mut system = System::new(b.particles);
        system.species = made.species;
        if let Some(number) = number {
            // Probes name particles by the scene's numbers; they read rows.
            let rows = crate::order::new_rows(&number);
            probes.iter_mut().for_each(|p| p.row = rows[p.particle]);
            system.number = number.iter().map(|&i| i as u64).collect();
        }
        system.boundary = b.boundary;
        system.wrap_positions();
        if self.run.centre_of_mass.as_ref().is_some_and(|c| c.value) {
            system.to_centre_of_mass_frame();
        }
        let mut forces = b.forces;
        let flow = flow::flow(self, src, &mut system, &forces)?;
        if let Some(asked) = &self.output.pressure_tensor {
            forces.pressure_tensor = asked.value;
            pressure_tensor_measurable(&system, &mut forces, asked, src)?;
        }
        Ok(Built {
            simulation: {
                let mut sim = Simulation::new(system, forces, Stepper::new(integrator), dt, seed);
                sim.thermostat = thermostat;
                sim.brownian = brownian;
                sim.flow = flow;
                sim
            },
            length,
            probes,
            seed,
        })
    }
}

/// Refuses `[output] pressure_tensor = true` where the tensor cannot be
/// given: a box not periodic on every axis, or an interaction that does
/// not compute its virial tensor.
fn pressure_tensor_measurable(
    system: &System,
    forces: &mut ForceField,
    asked: &Setting<bool>,
    src: Source,
) -> Result<(), ParseError> {
    if !forces.pressure_tensor {
        return Ok(());
    }
    if !system.boundary.periodic.iter().all(|p| *p) {
        return Err(asked.error(
            src,
            "pressure_tensor needs a box periodic on every axis ([box] periodic = [true, true, true])",
        ));
    }
    let p = &system.particles;
    let state = crate::force::State::of(system, &p.position, &p.velocity, system.time, 0.0);
    let without = forces.without_virial_tensor(&state);
    if !without.is_empty() {
        return Err(asked.error(
            src,
            format!(
                "pressure_tensor: {} do{} not compute the virial tensor yet",
                without.join(", "),
                if without.len() == 1 { "es" } else { "" }
            ),
        ));
    }
    Ok(())
}

pub(crate) fn one() -> f64 {
    1.0
}
pub(crate) fn yes() -> bool {
    true
}
pub(crate) fn white() -> [f64; 3] {
    [1.0, 1.0, 1.0]
}
pub(crate) fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}
pub(crate) fn all_free() -> [bool; 3] {
    [true; 3]
}
