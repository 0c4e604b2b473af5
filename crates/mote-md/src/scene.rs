//! Scene files (TOML) and MPPphys particle files, turned into a [`Simulation`].
//!
//! Every key is documented in docs/scene-format.md. Particles are numbered in
//! this order: `[[particle]]` tables, then `[[lattice]]`, `[[ring]]`,
//! `[[annulus]]`, `[[random_box]]`, `[[fcc]]` and `[[cloud]]` generators,
//! then `[[lammps_data]]` files, each in file order.

use glam::DVec3;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;
use toml::Spanned;

use mote_io::plist::ParticleFile;
use mote_io::ParseError;

use crate::force::granular::{
    ContactLaw, Damping, GranularContacts, GranularWalls, Material, Wall,
};
use crate::force::{
    DirectGravity, ForceField, GlobalDamping, LennardJones, Spring, SpringNetwork, UniformField,
};
use crate::init::{self, Anchor};
use crate::integrate::{Integrator, Stepper};
use crate::observe::Probe;
use crate::particles::{ParticleInit, Particles, System};
use crate::simulation::{RunLength, Simulation};
use crate::thermostat::Thermostat;
use crate::units::UnitSystem;

/// A whole scene file.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// One line saying what the scene is.
    #[serde(default)]
    pub title: String,
    /// `si` (default), `lj` or `astro`.
    #[serde(default)]
    pub units: UnitSystem,
    /// Seed of the random generators; chosen and printed when absent.
    pub seed: Option<u64>,
    #[serde(default)]
    pub run: RunSettings,
    pub gravity: Option<GravitySettings>,
    pub field: Option<FieldSettings>,
    pub damping: Option<DampingSettings>,
    pub lennard_jones: Option<Spanned<LennardJonesSettings>>,
    pub thermostat: Option<Spanned<ThermostatSettings>>,
    pub granular: Option<Spanned<GranularSettings>>,
    pub dipolar: Option<Spanned<DipolarSettings>>,
    pub magnetic_field: Option<Spanned<MagneticFieldSettings>>,
    pub brownian: Option<Spanned<BrownianSettings>>,
    #[serde(default)]
    pub plummer: Vec<Spanned<PlummerSpec>>,
    #[serde(default)]
    pub wall: Vec<Spanned<WallSpec>>,
    #[serde(rename = "box")]
    pub bounds: Option<Spanned<BoxSettings>>,
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
    pub spring: Vec<Spanned<SpringSpec>>,
    #[serde(default)]
    pub output: OutputSettings,
}

/// `[granular]`: Hertz–Mindlin contacts between all particles of radius > 0
/// (see `force::granular::law`), and the material of the `[[wall]]`s.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GranularSettings {
    /// Young's modulus E of the particles.
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Coefficient of restitution e of a head-on impact.
    pub restitution: f64,
    /// Sliding friction coefficient μ.
    pub friction: f64,
    /// Rolling friction coefficient μ_r (default 0).
    #[serde(default)]
    pub rolling_friction: f64,
    /// Work of adhesion w (DMT pull 2πwR*; default 0).
    #[serde(default)]
    pub adhesion: f64,
    /// `exact` (α solved so that e is met, default) or `tsuji` (LAMMPS'
    /// polynomial fit, for comparisons).
    #[serde(default = "exact")]
    pub damping: String,
    /// Never let the normal force pull (LAMMPS `limit_damping`).
    #[serde(default)]
    pub limit_damping: bool,
    /// Verlet-list skin (default a quarter of the smallest diameter).
    pub skin: Option<f64>,
    /// Walls' Young's modulus and Poisson's ratio (default: the particles').
    pub wall_young: Option<f64>,
    pub wall_poisson: Option<f64>,
    /// Friction with the walls (default: `friction`).
    pub wall_friction: Option<f64>,
}

fn exact() -> String {
    "exact".into()
}

/// `[[wall]]`: a wall for granular contacts. `kind = "plane"` (point,
/// normal towards the particles), `"box"` (lo, hi: six inward planes) or
/// `"cylinder"` (point, axis, radius: the particles are inside).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    pub kind: String,
    /// Name in observables.csv (default wall0, wall1, ...).
    pub name: Option<String>,
    pub point: Option<[f64; 3]>,
    pub normal: Option<[f64; 3]>,
    pub lo: Option<[f64; 3]>,
    pub hi: Option<[f64; 3]>,
    pub axis: Option<[f64; 3]>,
    pub radius: Option<f64>,
    /// The wall translates at this velocity.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Angular speed about the cylinder's axis or the plane's normal (rad/s).
    #[serde(default)]
    pub angular_speed: f64,
}

/// `[[cloud]]`: n non-overlapping spheres placed at random in [min, max]
/// (random sequential addition), radii uniform in radius·(1 ± spread).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudSpec {
    pub n: usize,
    pub min: [f64; 3],
    pub max: [f64; 3],
    #[serde(default)]
    pub spread: f64,
    #[serde(flatten)]
    pub props: Properties,
}

/// `[[lammps_data]]`: spheres from a LAMMPS data file (`atom_style sphere`:
/// id type diameter density x y z), path relative to the scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSpec {
    pub file: String,
    #[serde(default = "white")]
    pub color: [f64; 3],
}

/// `[run]`: integrator, time step and length.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSettings {
    /// Default: leapfrog.
    #[serde(default = "default_integrator")]
    pub integrator: Spanned<String>,
    pub dt: Option<Spanned<f64>>,
    pub steps: Option<u64>,
    pub until: Option<f64>,
    /// Move to the centre-of-mass frame before the run (only if nothing is fixed).
    #[serde(default)]
    pub centre_of_mass: bool,
}

fn default_integrator() -> Spanned<String> {
    Spanned::new(0..0, "leapfrog".into())
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            integrator: default_integrator(),
            dt: None,
            steps: None,
            until: None,
            centre_of_mass: false,
        }
    }
}

/// `[gravity]`: softened direct-summation Newtonian gravity (002 Eq. 2).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySettings {
    /// Newton's constant; default: the unit system's (k² in astro units).
    #[serde(rename = "G")]
    pub g: Option<f64>,
    #[serde(default)]
    pub softening: f64,
    /// `direct` (default: every pair, exact) or `tree` (Barnes–Hut).
    #[serde(default = "direct")]
    pub method: String,
    /// Opening angle θ of the tree (default 0.5).
    pub theta: Option<f64>,
}

fn direct() -> String {
    "direct".into()
}

/// `[dipolar]`: magnetic dipole–dipole forces and torques (004 Eq. 8)
/// between particles with a `dipole`, optionally with WCA repulsion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DipolarSettings {
    /// μ₀ (default: the unit system's; 4π in LJ units).
    pub mu0: Option<f64>,
    /// Cut-off with the minimum image (periodic boxes); absent: all pairs.
    pub cutoff: Option<f64>,
    /// Verlet skin of the cut-off list (default 0.3).
    pub skin: Option<f64>,
    /// Relative permeability of the reaction field beyond the cut-off;
    /// `"conducting"` for ε_RF = ∞ (absent: none).
    pub reaction_field: Option<toml::Value>,
    /// WCA repulsion `{ epsilon, sigma }` in the same pair loop.
    pub wca: Option<WcaSettings>,
    /// Turn every dipole into a random direction (same |m|) at the start.
    #[serde(default)]
    pub random_orientation: bool,
}

/// `{ epsilon, sigma }` of a WCA repulsion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WcaSettings {
    pub epsilon: f64,
    pub sigma: f64,
}

/// `[magnetic_field]`: an applied field H acting on the dipoles (Zeeman,
/// 004 Eq. 10): uniform `h = [..]`, or rotating with `amplitude`,
/// `angular_frequency` (rad per time), `axis`, `phase`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagneticFieldSettings {
    pub h: Option<[f64; 3]>,
    pub amplitude: Option<f64>,
    pub angular_frequency: Option<f64>,
    pub axis: Option<[f64; 3]>,
    #[serde(default)]
    pub phase: f64,
    pub mu0: Option<f64>,
}

/// `[brownian]`: overdamped Brownian dynamics at `kt` with friction
/// coefficients `translational` ξ_t and `rotational` ξ_r, or the Stokes
/// drag of each sphere in a liquid of `viscosity`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrownianSettings {
    pub kt: f64,
    pub translational: Option<f64>,
    pub rotational: Option<f64>,
    pub viscosity: Option<f64>,
    /// Turn the dipoles (rotational diffusion and torques; default true).
    #[serde(default = "yes")]
    pub rotate: bool,
}

/// `[[plummer]]`: a Plummer sphere (Aarseth, Hénon & Wielen 1974) of `n`
/// particles, total mass `total_mass`, scale radius `scale_radius`, in
/// virial equilibrium, truncated at `max_radius` (default 20 scale radii).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlummerSpec {
    pub n: usize,
    #[serde(default = "one")]
    pub total_mass: f64,
    #[serde(default = "one")]
    pub scale_radius: f64,
    pub max_radius: Option<f64>,
    #[serde(default = "white")]
    pub color: [f64; 3],
}

/// `[field]`: uniform gravitational acceleration (MPPphys `grav`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    pub g: [f64; 3],
}

/// `[damping]`: force −γ v on every particle (MPPphys `damp`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSettings {
    pub gamma: f64,
}

/// `[box]`: an orthorhombic simulation box.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSettings {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    #[serde(default = "all_free")]
    pub periodic: [bool; 3],
}

/// `[lennard_jones]`: LJ or WCA between all particles through a Verlet list.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LennardJonesSettings {
    #[serde(default = "one")]
    pub epsilon: f64,
    #[serde(default = "one")]
    pub sigma: f64,
    /// Cut-off r_c in units of length (default 2.5 σ; WCA: 2^{1/6} σ).
    pub cutoff: Option<f64>,
    /// Subtract U(r_c) (default true).
    #[serde(default = "yes")]
    pub shifted: bool,
    /// Purely repulsive WCA: cut at 2^{1/6} σ and shifted.
    #[serde(default)]
    pub wca: bool,
    /// Verlet-list skin (default 0.3 σ).
    pub skin: Option<f64>,
    /// Also rebuild the list every this many steps (0: only on displacement).
    #[serde(default)]
    pub rebuild_every: u64,
}

fn yes() -> bool {
    true
}

/// `[thermostat]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThermostatSettings {
    /// `langevin` or `bussi`.
    pub kind: String,
    /// Temperature as k_B T in energy units (in LJ units: T*).
    pub kt: f64,
    /// Langevin friction γ (per time).
    pub gamma: Option<f64>,
    /// Bussi relaxation time τ.
    pub tau: Option<f64>,
}

/// `[[fcc]]`: a face-centred cubic crystal at a number density, with
/// Maxwell–Boltzmann velocities at temperature kT (zero total momentum,
/// rescaled to exactly kT); sets a periodic `[box]` when the scene has none.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FccSpec {
    pub cells: [usize; 3],
    pub density: f64,
    #[serde(default)]
    pub kt: f64,
    #[serde(default)]
    pub origin: [f64; 3],
    #[serde(flatten)]
    pub props: Properties,
}

fn one() -> f64 {
    1.0
}
fn white() -> [f64; 3] {
    [1.0, 1.0, 1.0]
}
fn all_free() -> [bool; 3] {
    [true; 3]
}

/// Properties shared by the particles a table makes.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Properties {
    #[serde(default = "one")]
    pub mass: f64,
    #[serde(default)]
    pub charge: f64,
    #[serde(default)]
    pub radius: f64,
    /// Mass density ρ: when given, the mass is ρ (4/3)π r³ (solid spheres).
    pub density: Option<f64>,
    /// Magnetic dipole moment m (a vector).
    #[serde(default)]
    pub dipole: [f64; 3],

    #[serde(default = "white")]
    pub color: [f64; 3],
    /// Per axis: may the particle move? (MPPphys `vfix` 1 1 1 = all free.)
    #[serde(default = "all_free")]
    pub free: [bool; 3],
}

impl Default for Properties {
    fn default() -> Self {
        Self {
            mass: 1.0,
            charge: 0.0,
            radius: 0.0,
            density: None,
            dipole: [0.0; 3],
            color: white(),
            free: all_free(),
        }
    }
}

impl Properties {
    fn template(&self) -> ParticleInit {
        ParticleInit {
            mass: self
                .density
                .map_or(self.mass, |rho| sphere_mass(rho, self.radius)),
            charge: self.charge,
            radius: self.radius,
            color: self.color,
            free: self.free,
            dipole: DVec3::from(self.dipole),
            ..ParticleInit::default()
        }
    }
}

/// The mass ρ (4/3)π r³ of a solid sphere.
fn sphere_mass(density: f64, radius: f64) -> f64 {
    density * 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3)
}

/// `[[particle]]`: one particle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    pub position: [f64; 3],
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Displacement applied after spring rest lengths are taken (MPPphys `dis`).
    #[serde(default)]
    pub displacement: [f64; 3],
    #[serde(flatten)]
    pub props: Properties,
}

/// `[[lattice]]`: a rectangular lattice, optionally joined by springs.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSpec {
    pub n: [usize; 3],
    pub spacing: [f64; 3],
    #[serde(default)]
    pub origin: [f64; 3],
    #[serde(default)]
    pub velocity: [f64; 3],
    /// `none` (default), `boundary` or `first-column`.
    #[serde(default)]
    pub anchor: Option<String>,
    pub springs: Option<LatticeSprings>,
    /// Displacement of mode (r, s): u = amplitude · sin(rπx/a) sin(sπy/b) over the lattice (002 Eq. 20).
    pub mode: Option<ModeSpec>,
    #[serde(flatten)]
    pub props: Properties,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSprings {
    pub stiffness: f64,
    #[serde(default)]
    pub damping: f64,
    #[serde(default)]
    pub diagonals: bool,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModeSpec {
    pub r: u32,
    pub s: u32,
    pub amplitude: [f64; 3],
}

/// The speed of ring bodies: a number or a rule.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum SpeedSpec {
    Value(f64),
    Rule(String),
}

/// `[[ring]]`: N equal bodies on a circle.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RingSpec {
    pub n: usize,
    /// Radius R of the circle (the bodies' own size is `radius`).
    pub orbit_radius: f64,
    #[serde(default)]
    pub centre: [f64; 3],
    #[serde(default = "z_axis")]
    pub normal: [f64; 3],
    /// `"choreography"` (002 Eq. 16), `"kepler"` (about `central_mass`) or a number.
    pub speed: SpeedSpec,
    #[serde(default)]
    pub central_mass: f64,
    #[serde(default)]
    pub velocity: [f64; 3],
    #[serde(flatten)]
    pub props: Properties,
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// `[[annulus]]`: ring particles on Kepler orbits about a central mass.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnnulusSpec {
    pub n: usize,
    pub inner: f64,
    pub outer: f64,
    pub central_mass: f64,
    #[serde(default)]
    pub centre: [f64; 3],
    #[serde(default = "z_axis")]
    pub normal: [f64; 3],
    #[serde(default)]
    pub velocity: [f64; 3],
    #[serde(flatten)]
    pub props: Properties,
}

/// `[[random_box]]`: N particles uniformly at random in a box.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomBoxSpec {
    pub n: usize,
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// Standard deviation of each velocity component.
    #[serde(default)]
    pub velocity_sigma: f64,
    #[serde(flatten)]
    pub props: Properties,
}

/// `[[spring]]`: springs between listed particle pairs (002 Eq. 4).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    pub pairs: Vec<[usize; 2]>,
    pub stiffness: f64,
    #[serde(default)]
    pub damping: f64,
    /// Default: the distance of the pair before displacements.
    pub rest_length: Option<f64>,
}

/// `[output]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSettings {
    /// Folder of the output files (default `out/<scene name>`).
    pub dir: Option<String>,
    /// Steps between rows of observables.csv; 0 turns it off.
    #[serde(default = "default_observables_every")]
    pub observables_every: u64,
    /// Steps between frames of trajectory.xyz; 0 turns it off.
    #[serde(default = "default_trajectory_every")]
    pub trajectory_every: u64,
    /// Per-particle quantities added to observables.csv, e.g. `["z[30]", "speed[1]"]`.
    #[serde(default)]
    pub inspect: Vec<Spanned<String>>,
}

fn default_observables_every() -> u64 {
    10
}
fn default_trajectory_every() -> u64 {
    100
}

impl Default for OutputSettings {
    fn default() -> Self {
        Self {
            dir: None,
            observables_every: default_observables_every(),
            trajectory_every: default_trajectory_every(),
            inspect: Vec::new(),
        }
    }
}

/// A scene turned into its parts, ready to run.
pub struct Built {
    pub simulation: Simulation,
    pub length: Option<RunLength>,
    pub probes: Vec<Probe>,
    pub seed: u64,
}

/// Byte offset → one-based line number.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())]
        .bytes()
        .filter(|b| *b == b'\n')
        .count()
        + 1
}

impl Scene {
    /// Parses a scene; errors are `file:line: message`.
    pub fn parse(text: &str, file: &str) -> Result<Scene, ParseError> {
        toml::from_str::<Scene>(text).map_err(|e| {
            let line = e.span().map(|s| line_of(text, s.start)).unwrap_or(0);
            ParseError::new(file, line, e.message().trim().to_string())
        })
    }

    /// Builds the simulation. `text` and `file` locate errors; `seed` overrides the scene's.
    pub fn build(&self, text: &str, file: &str, seed: u64) -> Result<Built, ParseError> {
        let err = |span: std::ops::Range<usize>, msg: String| {
            ParseError::new(
                file,
                if span.is_empty() && span.start == 0 {
                    0
                } else {
                    line_of(text, span.start)
                },
                msg,
            )
        };
        let g_const = self
            .gravity
            .as_ref()
            .and_then(|g| g.g)
            .unwrap_or(self.units.gravitational_constant());
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut inits: Vec<ParticleInit> = Vec::new();
        let mut displacements: Vec<DVec3> = Vec::new();
        let mut springs: Vec<Spring> = Vec::new();

        let check_props = |p: &Properties,
                           span: std::ops::Range<usize>|
         -> Result<(), ParseError> {
            if !p.mass.is_finite() || p.mass <= 0.0 {
                return Err(err(
                    span,
                    format!("mass must be positive, found {}", p.mass),
                ));
            }
            if let Some(rho) = p.density {
                if !rho.is_finite() || rho <= 0.0 || p.radius <= 0.0 {
                    return Err(err(
                        span,
                        format!("density must be positive and needs a radius, found density {rho}"),
                    ));
                }
            }
            if p.radius < 0.0 {
                return Err(err(
                    span,
                    format!("radius must not be negative, found {}", p.radius),
                ));
            }
            Ok(())
        };

        for spec in &self.particle {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            let mut p = s.props.template();
            p.position = DVec3::from(s.position);
            p.velocity = DVec3::from(s.velocity);
            inits.push(p);
            displacements.push(DVec3::from(s.displacement));
        }
        for spec in &self.lattice {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if s.n.contains(&0) {
                return Err(err(
                    spec.span(),
                    "lattice n needs at least one site per axis".into(),
                ));
            }
            let anchor = match s.anchor.as_deref() {
                None | Some("none") => Anchor::None,
                Some("boundary") => Anchor::Boundary,
                Some("first-column") => Anchor::FirstColumn,
                Some(other) => {
                    return Err(err(
                        spec.span(),
                        format!(
                            "unknown anchor '{other}': expected none, boundary or first-column"
                        ),
                    ))
                }
            };
            let mut t = s.props.template();
            t.velocity = DVec3::from(s.velocity);
            let lat = init::lattice(
                s.n,
                DVec3::from(s.origin),
                DVec3::from(s.spacing),
                &t,
                anchor,
                s.springs
                    .as_ref()
                    .map(|sp| (sp.stiffness, sp.damping, sp.diagonals)),
            );
            let offset = inits.len();
            let [nx, ny, _] = s.n;
            for (k, site) in lat.sites.into_iter().enumerate() {
                let mut d = DVec3::ZERO;
                if let Some(m) = &s.mode {
                    let (i, j) = (k % nx, (k / nx) % ny);
                    let fx = if nx > 1 {
                        i as f64 / (nx - 1) as f64
                    } else {
                        0.5
                    };
                    let fy = if ny > 1 {
                        j as f64 / (ny - 1) as f64
                    } else {
                        0.5
                    };
                    let pi = std::f64::consts::PI;
                    d = DVec3::from(m.amplitude)
                        * ((m.r as f64 * pi * fx).sin() * (m.s as f64 * pi * fy).sin());
                }
                inits.push(site);
                displacements.push(d);
            }
            springs.extend(lat.springs.into_iter().map(|sp| Spring {
                i: sp.i + offset,
                j: sp.j + offset,
                ..sp
            }));
        }
        for spec in &self.ring {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if s.n == 0 || !s.orbit_radius.is_finite() || s.orbit_radius <= 0.0 {
                return Err(err(
                    spec.span(),
                    "a ring needs n ≥ 1 and orbit_radius > 0".into(),
                ));
            }
            let speed = match &s.speed {
                SpeedSpec::Value(v) => *v,
                SpeedSpec::Rule(r) if r == "choreography" => {
                    init::choreography_speed(s.n, g_const * s.props.mass, s.orbit_radius)
                }
                SpeedSpec::Rule(r) if r == "kepler" => {
                    (g_const * s.central_mass / s.orbit_radius).sqrt()
                }
                SpeedSpec::Rule(r) => {
                    return Err(err(
                        spec.span(),
                        format!(
                        "unknown speed '{r}': expected \"choreography\", \"kepler\" or a number"
                    ),
                    ))
                }
            };
            let mut t = s.props.template();
            t.velocity = DVec3::from(s.velocity);
            for p in init::ring(
                s.n,
                DVec3::from(s.centre),
                s.orbit_radius,
                DVec3::from(s.normal),
                speed,
                &t,
            ) {
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        for spec in &self.annulus {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if s.inner.is_nan() || s.inner <= 0.0 || s.outer.is_nan() || s.outer < s.inner {
                return Err(err(
                    spec.span(),
                    "an annulus needs 0 < inner ≤ outer".into(),
                ));
            }
            let mut t = s.props.template();
            t.velocity = DVec3::from(s.velocity);
            for p in init::annulus(
                s.n,
                DVec3::from(s.centre),
                s.inner,
                s.outer,
                DVec3::from(s.normal),
                g_const * s.central_mass,
                &t,
                &mut rng,
            ) {
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        for spec in &self.random_box {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if (0..3).any(|d| s.max[d] < s.min[d]) {
                return Err(err(
                    spec.span(),
                    "random_box needs min ≤ max on every axis".into(),
                ));
            }
            let t = s.props.template();
            for p in init::random_box(
                s.n,
                DVec3::from(s.min),
                DVec3::from(s.max),
                s.velocity_sigma,
                &t,
                &mut rng,
            ) {
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        let mut fcc_box: Option<crate::boundary::Boundary> = None;
        for spec in &self.fcc {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if s.cells.contains(&0) || s.density.is_nan() || s.density <= 0.0 || s.kt < 0.0 {
                return Err(err(
                    spec.span(),
                    "fcc needs cells ≥ 1 on every axis, density > 0 and kt ≥ 0".into(),
                ));
            }
            let lat = init::fcc(
                s.cells,
                s.density,
                DVec3::from(s.origin),
                s.kt,
                &s.props.template(),
                &mut rng,
            );
            fcc_box = Some(lat.1);
            for p in lat.0 {
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        for spec in &self.cloud {
            let s = spec.get_ref();
            check_props(&s.props, spec.span())?;
            if s.props.radius <= 0.0 || !(0.0..1.0).contains(&s.spread) {
                return Err(err(
                    spec.span(),
                    "a cloud needs radius > 0 and 0 ≤ spread < 1".into(),
                ));
            }
            let made = init::cloud(
                s.n,
                DVec3::from(s.min),
                DVec3::from(s.max),
                s.props.radius,
                s.spread,
                &s.props.template(),
                &mut rng,
            );
            if made.len() < s.n {
                return Err(err(
                    spec.span(),
                    format!(
                        "only {} of {} spheres fit in the cloud's box without overlap: enlarge it or lower n",
                        made.len(),
                        s.n
                    ),
                ));
            }
            for mut p in made {
                if let Some(rho) = s.props.density {
                    p.mass = sphere_mass(rho, p.radius);
                }
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        for spec in &self.plummer {
            let s = spec.get_ref();
            if s.n == 0
                || s.total_mass.is_nan()
                || s.total_mass <= 0.0
                || s.scale_radius.is_nan()
                || s.scale_radius <= 0.0
            {
                return Err(err(
                    spec.span(),
                    "a plummer sphere needs n ≥ 1, total_mass > 0 and scale_radius > 0".into(),
                ));
            }
            let sphere = crate::tree::PlummerSphere {
                n: s.n,
                mass: s.total_mass,
                radius: s.scale_radius,
                g: g_const,
                max_radius: Some(s.max_radius.unwrap_or(20.0 * s.scale_radius)),
            };
            let template = ParticleInit {
                mass: s.total_mass / s.n as f64,
                color: s.color,
                ..ParticleInit::default()
            };
            for p in sphere.particles(&template, &mut rng) {
                inits.push(p);
                displacements.push(DVec3::ZERO);
            }
        }
        for spec in &self.lammps_data {
            let s = spec.get_ref();
            let path = std::path::Path::new(file)
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(&s.file);
            let data = mote_io::lammps_data::read(&path).map_err(|e| {
                if e.line == 0 && e.message.starts_with("cannot read") {
                    err(spec.span(), format!("{}: {}", path.display(), e.message))
                } else {
                    e
                }
            })?;
            for a in &data.atoms {
                let radius = 0.5 * a.diameter;
                inits.push(ParticleInit {
                    position: DVec3::from(a.position),
                    velocity: DVec3::from(a.velocity),
                    angular_velocity: DVec3::from(a.angular_velocity),
                    mass: sphere_mass(a.density, radius),
                    radius,
                    color: s.color,
                    ..ParticleInit::default()
                });
                displacements.push(DVec3::ZERO);
            }
        }
        let n = inits.len();
        if n == 0 {
            return Err(ParseError::new(file, 0, "the scene makes no particles: add [[particle]] or a generator ([[lattice]], [[ring]], [[annulus]], [[random_box]])"));
        }
        for spec in &self.spring {
            let s = spec.get_ref();
            if s.stiffness < 0.0 || s.damping < 0.0 {
                return Err(err(
                    spec.span(),
                    "spring stiffness and damping must not be negative".into(),
                ));
            }
            for &[i, j] in &s.pairs {
                if i >= n || j >= n || i == j {
                    return Err(err(
                        spec.span(),
                        format!(
                            "spring pair [{i}, {j}] must name two different particles 0..{}",
                            n - 1
                        ),
                    ));
                }
                springs.push(Spring {
                    i,
                    j,
                    stiffness: s.stiffness,
                    damping: s.damping,
                    rest_length: s
                        .rest_length
                        .unwrap_or_else(|| (inits[i].position - inits[j].position).length()),
                });
            }
        }
        // Displacements come after rest lengths were taken (MPPphys `dis`).
        let mut particles = Particles::default();
        for (mut p, d) in inits.into_iter().zip(displacements) {
            p.position += d;
            particles.push(p);
        }

        let boundary = match &self.bounds {
            Some(b) => {
                let v = b.get_ref();
                if (0..3).any(|k| v.hi[k].is_nan() || v.lo[k].is_nan() || v.hi[k] <= v.lo[k]) {
                    return Err(err(b.span(), "[box] needs lo < hi on every axis".into()));
                }
                crate::boundary::Boundary {
                    lo: DVec3::from(v.lo),
                    hi: DVec3::from(v.hi),
                    periodic: v.periodic,
                }
            }
            None => fcc_box.unwrap_or_default(),
        };
        let mut forces = ForceField::new();
        if let Some(g) = &self.gravity {
            if g.softening < 0.0 {
                return Err(ParseError::new(
                    file,
                    0,
                    "[gravity] softening must not be negative",
                ));
            }
            match (g.method.as_str(), g.theta) {
                ("direct", None) => forces.push(DirectGravity::new(g_const, g.softening)),
                ("tree", theta) => {
                    let theta = theta.unwrap_or(0.5);
                    if !(0.0..1.2).contains(&theta) {
                        return Err(ParseError::new(
                            file,
                            0,
                            format!("[gravity] theta must be in [0, 1.2), found {theta}"),
                        ));
                    }
                    forces.push(crate::tree::TreeGravity::new(g_const, g.softening, theta));
                }
                ("direct", Some(_)) => {
                    return Err(ParseError::new(
                        file,
                        0,
                        "[gravity] theta needs method = \"tree\"",
                    ))
                }
                (other, _) => {
                    return Err(ParseError::new(
                        file,
                        0,
                        format!("[gravity] unknown method '{other}': expected direct or tree"),
                    ))
                }
            }
        }
        if !springs.is_empty() {
            forces.push(SpringNetwork { springs });
        }
        if let Some(f) = &self.field {
            forces.push(UniformField {
                g: DVec3::from(f.g),
            });
        }
        if let Some(d) = &self.damping {
            forces.push(GlobalDamping { gamma: d.gamma });
        }
        if let Some(lj) = &self.lennard_jones {
            let v = lj.get_ref();
            if v.epsilon <= 0.0 || v.sigma <= 0.0 {
                return Err(err(
                    lj.span(),
                    "[lennard_jones] needs epsilon > 0 and sigma > 0".into(),
                ));
            }
            let skin = v.skin.unwrap_or(0.3 * v.sigma);
            let mut pair = if v.wca {
                LennardJones::wca(v.epsilon, v.sigma, skin, boundary)
            } else {
                let rc = v.cutoff.unwrap_or(2.5 * v.sigma);
                LennardJones::new(v.epsilon, v.sigma, rc, v.shifted, skin, boundary)
            };
            if pair.cutoff <= 0.0 || skin < 0.0 {
                return Err(err(
                    lj.span(),
                    "[lennard_jones] needs cutoff > 0 and skin ≥ 0".into(),
                ));
            }
            let reach = pair.cutoff + skin;
            let l = boundary.lengths();
            if (0..3).any(|k| boundary.periodic[k] && l[k] < 2.0 * reach) {
                return Err(err(
                    lj.span(),
                    format!("the periodic box ({} × {} × {}) must be at least twice cutoff + skin = {reach} on every periodic axis", l.x, l.y, l.z),
                ));
            }
            pair.list.every = v.rebuild_every;
            forces.push(pair);
        }
        if let Some(g) = &self.granular {
            let v = g.get_ref();
            let radius: Vec<f64> = particles.radius.clone();
            let bad = |msg: &str| Err(err(g.span(), msg.to_string()));
            if v.young.is_nan()
                || v.young <= 0.0
                || v.poisson.is_nan()
                || v.poisson <= -1.0
                || v.poisson >= 0.5
            {
                return bad("[granular] needs young > 0 and −1 < poisson < 0.5");
            }
            if !(v.restitution > 0.0 && v.restitution <= 1.0) {
                return bad("[granular] restitution must be in (0, 1]");
            }
            if v.friction < 0.0 || v.rolling_friction < 0.0 || v.adhesion < 0.0 {
                return bad(
                    "[granular] friction, rolling_friction and adhesion must not be negative",
                );
            }
            if radius.iter().any(|r| *r <= 0.0) {
                return bad("[granular] needs every particle to have a radius > 0");
            }
            if Integrator::from_name(self.run.integrator.get_ref()) != Some(Integrator::LeapFrog) {
                return Err(err(
                    self.run.integrator.span(),
                    "[granular] contacts turn the spheres: use integrator = \"leapfrog\"".into(),
                ));
            }
            let damping = match v.damping.as_str() {
                "exact" => Damping::Exact,
                "tsuji" => Damping::TsujiFit,
                other => {
                    return Err(err(
                        g.span(),
                        format!("unknown damping '{other}': expected exact or tsuji"),
                    ))
                }
            };
            let particle = Material {
                young: v.young,
                poisson: v.poisson,
            };
            let mut law = ContactLaw::new(
                particle,
                particle,
                v.restitution,
                v.friction,
                damping,
                v.limit_damping,
            );
            law.rolling_friction = v.rolling_friction;
            law.adhesion = v.adhesion;
            let d_min = radius.iter().cloned().fold(f64::INFINITY, f64::min) * 2.0;
            let skin = v.skin.unwrap_or(0.25 * d_min);
            if skin.is_nan() || skin <= 0.0 {
                return bad("[granular] skin must be positive");
            }
            forces.push(GranularContacts::new(law, &radius, skin, boundary));
            if !self.wall.is_empty() {
                let wall_material = Material {
                    young: v.wall_young.unwrap_or(v.young),
                    poisson: v.wall_poisson.unwrap_or(v.poisson),
                };
                let mut wall_law = ContactLaw::new(
                    particle,
                    wall_material,
                    v.restitution,
                    v.wall_friction.unwrap_or(v.friction),
                    damping,
                    v.limit_damping,
                );
                wall_law.rolling_friction = v.rolling_friction;
                wall_law.adhesion = v.adhesion;
                let mut walls = Vec::new();
                for (k, w) in self.wall.iter().enumerate() {
                    walls.extend(w.get_ref().walls(k).map_err(|m| err(w.span(), m))?);
                }
                forces.push(GranularWalls::new(wall_law, walls, &radius));
            }
        } else if let Some(w) = self.wall.first() {
            return Err(err(
                w.span(),
                "[[wall]] needs a [granular] section for its contact law".into(),
            ));
        }
        let mu0_default = crate::force::dipolar::vacuum_permeability(self.units);
        if let Some(d) = &self.dipolar {
            let v = d.get_ref();
            let mu0 = v
                .mu0
                .or(mu0_default)
                .ok_or_else(|| err(d.span(), "[dipolar] needs mu0 in these units".into()))?;
            if v.random_orientation {
                use rand::Rng;
                for m in particles.dipole.iter_mut() {
                    let len = m.length();
                    let u: f64 = 2.0 * rng.gen::<f64>() - 1.0;
                    let phi = 2.0 * std::f64::consts::PI * rng.gen::<f64>();
                    let s = (1.0 - u * u).sqrt();
                    *m = DVec3::new(s * phi.cos(), s * phi.sin(), u) * len;
                }
            }
            let mut pair = match v.cutoff {
                None => crate::force::dipolar::DipoleDipole::all_pairs(mu0),
                Some(rc) => crate::force::dipolar::DipoleDipole::cut_off(
                    mu0,
                    rc,
                    v.skin.unwrap_or(0.3),
                    boundary,
                )
                .map_err(|e| err(d.span(), format!("[dipolar] {e}")))?,
            };
            match &v.reaction_field {
                None => {}
                Some(toml::Value::String(s)) if s == "conducting" => {
                    pair = pair.with_reaction_field(f64::INFINITY)
                }
                Some(toml::Value::Float(x)) if *x >= 1.0 => pair = pair.with_reaction_field(*x),
                Some(toml::Value::Integer(x)) if *x >= 1 => {
                    pair = pair.with_reaction_field(*x as f64)
                }
                Some(other) => {
                    return Err(err(
                        d.span(),
                        format!("[dipolar] reaction_field must be \"conducting\" or a permeability ≥ 1, found {other}"),
                    ))
                }
            }
            if let Some(w) = &v.wca {
                pair = pair
                    .with_repulsion(crate::force::dipolar::PairRepulsion::wca(
                        w.epsilon, w.sigma,
                    ))
                    .map_err(|e| err(d.span(), format!("[dipolar] {e}")))?;
            }
            forces.push(pair);
        }
        if let Some(f) = &self.magnetic_field {
            let v = f.get_ref();
            let mu0 = v
                .mu0
                .or(mu0_default)
                .ok_or_else(|| err(f.span(), "[magnetic_field] needs mu0 in these units".into()))?;
            use crate::force::dipolar::{AppliedField, Zeeman};
            let field = match (v.h, v.amplitude, v.angular_frequency) {
                (Some(h), None, None) => AppliedField::Uniform(DVec3::from(h)),
                (None, Some(amplitude), Some(angular_frequency)) => AppliedField::Rotating {
                    amplitude,
                    angular_frequency,
                    axis: DVec3::from(v.axis.unwrap_or([0.0, 0.0, 1.0])).normalize(),
                    phase: v.phase,
                },
                _ => {
                    return Err(err(
                        f.span(),
                        "[magnetic_field] takes h = [..] (uniform) or amplitude and angular_frequency (rotating)".into(),
                    ))
                }
            };
            forces.push(Zeeman::new(mu0, field));
        }
        let brownian = match &self.brownian {
            None => None,
            Some(b) => {
                let v = b.get_ref();
                use crate::brownian::{BrownianStepper, Friction};
                let friction = match (v.translational, v.rotational, v.viscosity) {
                    (Some(t), Some(r), None) if t > 0.0 && r > 0.0 => Friction::Uniform {
                        translational: t,
                        rotational: r,
                    },
                    (None, None, Some(eta)) if eta > 0.0 => {
                        if particles.radius.iter().any(|r| *r <= 0.0) {
                            return Err(err(
                                b.span(),
                                "[brownian] viscosity needs every particle's radius > 0".into(),
                            ));
                        }
                        Friction::Stokes { viscosity: eta }
                    }
                    _ => return Err(err(
                        b.span(),
                        "[brownian] needs translational > 0 and rotational > 0, or viscosity > 0"
                            .into(),
                    )),
                };
                if v.kt.is_nan() || v.kt < 0.0 {
                    return Err(err(b.span(), "[brownian] needs kt ≥ 0".into()));
                }
                let mut bd = BrownianStepper::new(v.kt, friction);
                bd.rotate = v.rotate;
                Some(bd)
            }
        };
        let thermostat = match &self.thermostat {
            None => None,
            Some(t) => {
                let v = t.get_ref();
                if v.kt.is_nan() || v.kt < 0.0 {
                    return Err(err(t.span(), "[thermostat] needs kt ≥ 0".into()));
                }
                Some(match (v.kind.as_str(), v.gamma, v.tau) {
                    ("langevin", Some(gamma), _) if gamma > 0.0 => {
                        Thermostat::Langevin { kt: v.kt, gamma }
                    }
                    ("bussi", _, Some(tau)) if tau > 0.0 => Thermostat::Bussi { kt: v.kt, tau },
                    ("langevin", _, _) => {
                        return Err(err(
                            t.span(),
                            "a langevin thermostat needs gamma > 0".into(),
                        ))
                    }
                    ("bussi", _, _) => {
                        return Err(err(t.span(), "a bussi thermostat needs tau > 0".into()))
                    }
                    (other, _, _) => {
                        return Err(err(
                            t.span(),
                            format!("unknown thermostat '{other}': expected langevin or bussi"),
                        ))
                    }
                })
            }
        };

        let integrator = Integrator::from_name(self.run.integrator.get_ref()).ok_or_else(|| {
            err(
                self.run.integrator.span(),
                format!(
                    "unknown integrator '{}': expected {}",
                    self.run.integrator.get_ref(),
                    Integrator::NAMES
                ),
            )
        })?;
        let dt = match &self.run.dt {
            Some(dt) if *dt.get_ref() > 0.0 && dt.get_ref().is_finite() => *dt.get_ref(),
            Some(dt) => {
                return Err(err(
                    dt.span(),
                    format!("dt must be positive, found {}", dt.get_ref()),
                ))
            }
            None => {
                return Err(ParseError::new(
                    file,
                    0,
                    "[run] needs a time step: dt = ...",
                ))
            }
        };
        let length = match (self.run.steps, self.run.until) {
            (Some(_), Some(_)) => {
                return Err(ParseError::new(
                    file,
                    0,
                    "[run] takes steps or until, not both",
                ))
            }
            (Some(s), None) => Some(RunLength::Steps(s)),
            (None, Some(t)) => Some(RunLength::Until(t)),
            (None, None) => None,
        };
        let mut probes = Vec::new();
        for p in &self.output.inspect {
            let probe = Probe::parse(p.get_ref()).map_err(|m| err(p.span(), m))?;
            if probe.particle >= n {
                return Err(err(
                    p.span(),
                    format!("inspect '{}': there are only {n} particles", p.get_ref()),
                ));
            }
            probes.push(probe);
        }
        let mut system = System::new(particles);
        system.boundary = boundary;
        system.wrap_positions();
        if self.run.centre_of_mass {
            system.to_centre_of_mass_frame();
        }
        Ok(Built {
            simulation: Simulation {
                system,
                forces,
                stepper: Stepper::new(integrator),
                dt,
                observers: Vec::new(),
                thermostat,
                seed,
                sample_at_start: true,
                brownian,
            },
            length,
            probes,
            seed,
        })
    }
}

impl WallSpec {
    /// The walls this table makes (a box makes six); `index` names an
    /// unnamed wall `wall<index>`.
    pub fn walls(&self, index: usize) -> Result<Vec<Wall>, String> {
        let w = self;
        let name = w.name.clone().unwrap_or_else(|| format!("wall{index}"));
        let need = |v: Option<[f64; 3]>, key: &str| -> Result<DVec3, String> {
            v.map(DVec3::from)
                .ok_or_else(|| format!("a {} wall needs `{key}`", w.kind))
        };
        let mut walls = match w.kind.as_str() {
            "plane" => {
                let normal = need(w.normal, "normal")?;
                if normal.length() == 0.0 {
                    return Err("the plane's normal must not be zero".into());
                }
                vec![Wall::plane(&name, need(w.point, "point")?, normal)]
            }
            "box" => {
                let (lo, hi) = (need(w.lo, "lo")?, need(w.hi, "hi")?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err("a box wall needs lo < hi on every axis".into());
                }
                Wall::closed_box(&name, lo, hi)
            }
            "cylinder" => {
                let axis = need(w.axis, "axis")?;
                let radius = w.radius.ok_or("a cylinder wall needs `radius`")?;
                if axis.length() == 0.0 || radius.is_nan() || radius <= 0.0 {
                    return Err("a cylinder needs a non-zero axis and radius > 0".into());
                }
                vec![Wall::cylinder(&name, need(w.point, "point")?, axis, radius)]
            }
            other => {
                return Err(format!(
                    "unknown wall kind '{other}': expected plane, box or cylinder"
                ))
            }
        };
        for wall in &mut walls {
            wall.velocity = DVec3::from(w.velocity);
            wall.angular_speed = w.angular_speed;
        }
        Ok(walls)
    }
}

/// Which MPPphys model a particle file is run with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlistSystem {
    /// DirectNbody: softened gravity with k² (002 §2.2).
    Nbody,
    /// MassSpring: the file's springs (002 §2.3).
    Springs,
}

impl Scene {
    /// The scene twin of an MPPphys particle file: the same particles, forces
    /// and step, so both inputs run identical physics.
    /// `file` names the particle file in errors.
    pub fn from_plist(
        pf: &ParticleFile,
        system: PlistSystem,
        solver: &str,
        file: &str,
    ) -> Result<Scene, ParseError> {
        let mut scene = Scene {
            title: "MPPphys particle file".into(),
            units: UnitSystem::Astro,
            ..Scene::default()
        };
        scene.run.integrator = Spanned::new(0..0, solver.to_string());
        scene.run.dt = pf.dt.map(|dt| Spanned::new(0..0, dt));
        for p in &pf.particles {
            scene.particle.push(Spanned::new(
                0..0,
                ParticleSpec {
                    position: p.position,
                    velocity: p.velocity,
                    displacement: p.displacement,
                    props: Properties {
                        mass: p.mass,
                        charge: p.charge,
                        radius: p.radius,
                        density: None,
                        dipole: [0.0; 3],
                        color: p.color,
                        free: p.free,
                    },
                },
            ));
        }
        match system {
            PlistSystem::Nbody => {
                scene.gravity = Some(GravitySettings {
                    g: Some(pf.k2.unwrap_or(UnitSystem::Astro.gravitational_constant())),
                    softening: pf.softening.unwrap_or(0.0),
                    method: direct(),
                    theta: None,
                });
            }
            PlistSystem::Springs => {
                for link in &pf.springs {
                    let kind = pf
                        .spring_types
                        .iter()
                        .find(|s| s.id == link.kind)
                        .ok_or_else(|| {
                            ParseError::new(
                                file,
                                0,
                                format!("spring type {} is not defined", link.kind),
                            )
                        })?;
                    scene.spring.push(Spanned::new(
                        0..0,
                        SpringSpec {
                            pairs: vec![[link.i, link.j]],
                            stiffness: kind.stiffness,
                            damping: kind.damping,
                            rest_length: link.rest_length,
                        },
                    ));
                }
            }
        }
        scene.field = pf.gravity.map(|g| FieldSettings { g });
        scene.damping = pf.damping.map(|gamma| DampingSettings { gamma });
        Ok(scene)
    }
}
