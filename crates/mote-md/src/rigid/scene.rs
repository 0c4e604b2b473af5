//! The `[rigid]` scene format: templates of overlapping spheres, bodies
//! placed one by one or by generators, fields, contacts and walls, built
//! into bodies and an FRBI (run by [`super::run`]).
//!
//! ```toml
//! seed = 7
//! [rigid]
//! free_flight = "straight"     # or "screw" (the seed's literal free step)
//! spin_update = "keep_momentum" # or "seed"
//!
//! [[rigid.template]]
//! name = "bead"
//! generator = "irregular"      # or "sphere", "dumbbell", "trimer"; or spheres = [[x, y, z, r], ...]
//! radius = 1.0
//! lobes = 8
//! density = 1.0                # or mass = ... (density is then set to give it)
//! dipole = [0.0, 0.0, 1.0]
//! charge = 0.0
//!
//! [[rigid.body]]
//! template = "bead"
//! position = [0.0, 0.0, 1.0]
//! rotation = [0.0, 0.0, 0.0]   # rotation vector n·tan(φ/2); or axis + angle
//! velocity = [0.0, 0.0, 0.0]
//! omega = [0.0, 0.0, 0.0]
//!
//! [[rigid.lattice]]            # n bodies on a simple cubic lattice in [lo, hi]
//! template = "bead"
//! n = 100
//! lo = [0.0, 0.0, 0.0]
//! hi = [10.0, 10.0, 10.0]
//! spacing = 2.5
//! arrangement = "cubic"        # or "fcc" (spacing: nearest-neighbour distance)
//! random_orientation = true
//!
//! [[rigid.random]]             # n bodies at random, bounding spheres not overlapping
//! template = "bead"
//! n = 50
//! lo = [0.0, 0.0, 0.0]
//! hi = [10.0, 10.0, 10.0]
//!
//! [rigid.fields]
//! gravity = [0.0, 0.0, -9.81]
//! electric = [0.0, 0.0, 0.0]
//! magnetic = { amplitude = 1.0, axis = [0, 0, 1], start = [1, 0, 0], frequency = 0.5 }
//! coulomb = 8.99e9             # k of Coulomb forces between charges (off if absent)
//! dipole_dipole = 1e-7         # k = μ0/4π of dipole–dipole forces (off if absent)
//! drag = { viscosity = 1.8e-5, air_density = 1.2, drag_coefficient = 0.47 }
//!
//! [rigid.contacts]
//! young = 1e7
//! poisson = 0.3
//! restitution = 0.5
//! friction = 0.5
//! rolling_friction = 0.0
//! skin = 0.2                   # Verlet skin (default 0.2 × the largest sphere diameter)
//!
//! [box]                        # as every engine spells it; contacts search across
//! lo = [0.0, 0.0, 0.0]         # its periodic faces, planes and roller take its faces
//! hi = [1e-3, 1e-3, 2.5e-4]
//! periodic = [true, true, false]  # default: all axes
//!
//! [rigid.planes]               # conducting planes z = lo.z and z = hi.z of [box]
//! coulomb = 8.99e9             # k: Coulomb forces between charges with all their images
//! potential = [0.0, -300.0]    # volts on the lower and the upper plane
//! accuracy = 1e-12             # RMS force error of the Ewald sum (newtons)
//! r_cut = 1e-4                 # real-space cut-off (default from the charges' spacing)
//! every = 1                    # sum the charges' forces every n steps, hold them between
//!
//! [rigid.latent_image]         # surface charge on a belt over the lower plane
//! height = 2e-5                # electrical thickness d/ε_r of the photoconductor
//! speed = 0.3                  # belt speed along x
//! background = 0.0             # charge density outside the patches
//! patches = [[1e-4, 3e-4, -5e-4]]  # [start, end, density]: x-intervals at t = 0
//!
//! [rigid.roller]               # magnetic roller inside the upper plane (the shell)
//! field = 0.08                 # B₀ (T) at the shell's surface
//! poles = 8
//! radius = 0.01                # shell radius: the axis is this far above the upper plane
//! frequency = 5.0              # roller turns per second (negative: the other way)
//! x = 2e-4                     # x of the axis (default: the box's centre)
//! dipole_dipole = 1e-7         # μ0/4π: forces between the induced moments (off if absent)
//! iterations = 2               # passes of mutual induction
//! magnetic = [{ template = "carrier", permeability = 6.0, saturation = 3.3e5 }]
//!
//! [rigid.nip]                  # toning-nip observables in nip.csv (the crate mote-nip)
//! toner = "toner"
//! carrier = "carrier"
//! every = 500                  # default: [output] observables_every
//!
//! [[rigid.wall]]               # as the granular [[wall]]
//! kind = "box"
//! lo = [0.0, 0.0, 0.0]
//! hi = [10.0, 10.0, 10.0]
//!
//! [run]
//! dt = 1e-4
//! steps = 10000                # or until = 1.0
//!
//! [output]
//! dir = "out/my-scene"          # default out/<scene name>
//! observables_every = 100
//! trajectory_every = 1000
//! ```

use glam::DVec3;
use mote_geom::{from_axis_angle, DE, E};
use mote_io::{ParseError, Source};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;
use toml::Spanned;

use super::bodies::RigidBodies;
use super::contacts::RigidContacts;
use super::frbi::{Frbi, FreeFlight, SpinUpdate};
use super::magnet::{InducedDipoles, MagneticRoller};
use super::shapes::{dumbbell, linear_trimer, IrregularClump};
use super::sources::{
    AirDrag, Coulomb, DipoleDipole, ExternalFields, Field, Gravity, LatentField, PlaneCoulomb,
};
use super::template::{BodyTemplate, ClumpSpec, Integration};
use crate::boundary::Boundary;
use crate::force::granular::{ContactLaw, Damping, Material};
use crate::force::latent::{LatentImage, Patch};
use crate::force::slab::ConductingPlanes;

/// A whole rigid scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidScene {
    #[serde(default)]
    pub seed: Option<u64>,
    /// Free text, ignored.
    #[serde(default)]
    pub title: Option<String>,
    pub rigid: Spanned<RigidSettings>,
    pub run: Spanned<RunSettings>,
    /// `[[from_file]]`: bodies from a frame of their spheres (the key every
    /// engine starts from a file with; `templates` and `tolerance` are
    /// this engine's own).
    #[serde(default)]
    pub from_file: Vec<Spanned<FileSpec>>,
    /// `[box]`, spelled as every engine spells it: `lo`, `hi` and the
    /// periodic axes (default all). The contacts search across its
    /// periodic faces; the planes, the roller and the nip take its faces.
    #[serde(rename = "box", default)]
    pub bounds: Option<Spanned<crate::scene::BoxSettings>>,
    /// The `[output]` of every time-stepped engine (`inspect`, which names
    /// point particles, is refused).
    #[serde(default)]
    pub output: crate::scene::OutputSettings,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidSettings {
    #[serde(default)]
    pub free_flight: Option<Spanned<String>>,
    #[serde(default)]
    pub spin_update: Option<Spanned<String>>,
    #[serde(default)]
    pub template: Vec<Spanned<TemplateSpec>>,
    #[serde(default)]
    pub body: Vec<Spanned<BodySpec>>,
    #[serde(default)]
    pub lattice: Vec<Spanned<PlacementSpec>>,
    #[serde(default)]
    pub random: Vec<Spanned<PlacementSpec>>,
    /// `[[rigid.from_file]]`, the first spelling of `[[from_file]]`, read
    /// only to be refused with the one every engine uses.
    #[serde(default)]
    from_file: Vec<Spanned<toml::Value>>,
    #[serde(default)]
    pub fields: Option<Spanned<FieldSettings>>,
    #[serde(default)]
    pub contacts: Option<Spanned<ContactSettings>>,
    #[serde(default)]
    /// `[[rigid.wall]]`: the keys of the granular `[[wall]]`.
    pub wall: Vec<Spanned<crate::scene::WallSpec>>,
    /// `[rigid.planes]`: conducting planes bounding the box along z.
    #[serde(default)]
    pub planes: Option<Spanned<PlaneSettings>>,
    /// `[rigid.latent_image]`: charge on the belt over the lower plane.
    #[serde(default)]
    pub latent_image: Option<Spanned<LatentSettings>>,
    /// `[rigid.roller]`: the magnetic roller above the upper plane.
    #[serde(default)]
    pub roller: Option<Spanned<RollerSettings>>,
    /// `[rigid.nip]`: the toning nip's observables, an application's
    /// table: the crate mote-nip reads it from the scene text; the engine
    /// only lets it through.
    #[serde(default)]
    pub nip: Option<serde::de::IgnoredAny>,
}

/// `[rigid.roller]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollerSettings {
    pub field: f64,
    pub poles: u32,
    pub radius: f64,
    #[serde(default)]
    pub frequency: f64,
    #[serde(default)]
    pub x: Option<f64>,
    #[serde(default)]
    pub dipole_dipole: f64,
    #[serde(default)]
    pub iterations: u32,
    pub magnetic: Vec<MagneticSpec>,
}

/// A magnetic template of `[rigid.roller]`: relative permeability μ_r and
/// saturation magnetisation M_s (A/m; absent: none).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagneticSpec {
    pub template: String,
    pub permeability: f64,
    #[serde(default)]
    pub saturation: Option<f64>,
}

/// `[rigid.latent_image]`: patches across the track, moving along x.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatentSettings {
    pub height: f64,
    #[serde(default)]
    pub speed: f64,
    #[serde(default)]
    pub background: f64,
    #[serde(default)]
    pub patches: Vec<[f64; 3]>,
}

/// `[rigid.planes]`: the box's faces z = box_lo.z and z = box_hi.z are
/// conductors at the given potentials (the box periodic along x and y).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSettings {
    /// k = 1/(4πε₀).
    pub coulomb: f64,
    /// Potentials of the lower and the upper plane.
    #[serde(default)]
    pub potential: [f64; 2],
    /// Requested RMS force error.
    pub accuracy: f64,
    #[serde(default)]
    pub r_cut: Option<f64>,
    /// Sum the charges' forces at every n-th step, hold them in between.
    #[serde(default)]
    pub every: Option<u64>,
}

/// `[[rigid.template]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemplateSpec {
    pub name: String,
    /// Explicit spheres `[x, y, z, r]`.
    #[serde(default)]
    pub spheres: Option<Vec<[f64; 4]>>,
    /// "sphere", "dumbbell", "trimer", "irregular".
    #[serde(default)]
    pub generator: Option<String>,
    #[serde(default)]
    pub radius: Option<f64>,
    /// Centre distance of neighbouring spheres (dumbbell, trimer).
    #[serde(default)]
    pub distance: Option<f64>,
    #[serde(default)]
    pub lobes: Option<usize>,
    #[serde(default)]
    pub lobe_radius: Option<[f64; 2]>,
    #[serde(default)]
    pub offset: Option<[f64; 2]>,
    /// Shape seed of the irregular generator (default: the scene seed).
    #[serde(default)]
    pub seed: Option<u64>,
    #[serde(default)]
    pub density: Option<f64>,
    #[serde(default)]
    pub mass: Option<f64>,
    #[serde(default)]
    pub young: Option<f64>,
    #[serde(default)]
    pub poisson: Option<f64>,
    #[serde(default)]
    pub charge: f64,
    #[serde(default)]
    pub dipole: [f64; 3],
}

/// `[[rigid.body]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub template: String,
    pub position: [f64; 3],
    #[serde(default)]
    pub rotation: Option<[f64; 3]>,
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    /// Degrees.
    #[serde(default)]
    pub angle: Option<f64>,
    #[serde(default)]
    pub velocity: [f64; 3],
    #[serde(default)]
    pub omega: [f64; 3],
}

/// `[[from_file]]` of a rigid scene: the bodies of a trajectory frame (`.xyz`,
/// `.dump`, `.gsd`, `.vtp`/`.vtu`/`.pvd`; path relative to the scene file;
/// the last frame unless `frame` says which, negative counting from the
/// end), as a rigid run writes them: one row per sphere with its radius and
/// body id (a LAMMPS dump's `mol`), and where present the orientation
/// quaternion and angular velocity. Each body is matched to a template by
/// its spheres (see [`super::from_file`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileSpec {
    pub file: String,
    #[serde(default)]
    pub frame: Option<i64>,
    /// Only these templates (default: all the scene's, in order).
    #[serde(default)]
    pub templates: Option<Vec<String>>,
    /// The largest misfit of a sphere centre, as a fraction of the
    /// template's bounding radius (default 1e-6; files of few digits need
    /// more).
    #[serde(default)]
    pub tolerance: Option<f64>,
}

/// `[[rigid.lattice]]` / `[[rigid.random]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacementSpec {
    pub template: String,
    pub n: usize,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Lattice spacing (default: the template's bounding diameter); for
    /// fcc the nearest-neighbour distance.
    #[serde(default)]
    pub spacing: Option<f64>,
    /// "cubic" (default) or "fcc" (face-centred cubic, cube edge
    /// √2·spacing: 74 % of space in touching spheres against 52 %).
    #[serde(default)]
    pub arrangement: Option<String>,
    #[serde(default = "yes")]
    pub random_orientation: bool,
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Random velocities of this magnitude in random directions, added.
    #[serde(default)]
    pub speed: f64,
}

fn yes() -> bool {
    true
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum FieldSpec {
    Constant([f64; 3]),
    Rotating {
        amplitude: f64,
        axis: [f64; 3],
        start: [f64; 3],
        frequency: f64,
        #[serde(default)]
        phase: f64,
        #[serde(default)]
        offset: [f64; 3],
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DragSpec {
    #[serde(default)]
    pub viscosity: f64,
    #[serde(default)]
    pub air_density: f64,
    #[serde(default)]
    pub drag_coefficient: f64,
    #[serde(default)]
    pub wind: [f64; 3],
}

/// `[rigid.fields]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    #[serde(default)]
    pub gravity: Option<[f64; 3]>,
    #[serde(default)]
    pub electric: Option<FieldSpec>,
    #[serde(default)]
    pub magnetic: Option<FieldSpec>,
    #[serde(default)]
    pub coulomb: Option<f64>,
    #[serde(default)]
    pub dipole_dipole: Option<f64>,
    #[serde(default)]
    pub drag: Option<DragSpec>,
}

/// `[rigid.contacts]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSettings {
    pub young: f64,
    #[serde(default = "default_poisson")]
    pub poisson: f64,
    pub restitution: f64,
    #[serde(default)]
    pub friction: f64,
    #[serde(default)]
    pub rolling_friction: f64,
    #[serde(default)]
    pub adhesion: f64,
    #[serde(default)]
    pub limit_damping: bool,
    #[serde(default)]
    pub skin: Option<f64>,
    /// The box's old spellings, read only to be refused with the new one.
    #[serde(default)]
    periodic: Option<Spanned<toml::Value>>,
    #[serde(default)]
    box_lo: Option<Spanned<toml::Value>>,
    #[serde(default)]
    box_hi: Option<Spanned<toml::Value>>,
}

fn default_poisson() -> f64 {
    0.3
}

/// `[run]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSettings {
    pub dt: f64,
    #[serde(default)]
    pub steps: Option<u64>,
    #[serde(default)]
    pub until: Option<f64>,
}

/// The built scene: bodies, the integrator and what to run.
pub struct BuiltRigid {
    pub bodies: RigidBodies,
    pub frbi: Frbi,
    pub dt: f64,
    pub steps: u64,
    pub seed: u64,
}

impl BuiltRigid {
    /// The contact model, if the scene has `[rigid.contacts]`.
    pub fn contacts(&self) -> Option<&RigidContacts> {
        self.frbi.find()
    }
}

/// Whether a scene text is a rigid-body scene (has a `[rigid]` table).
pub fn is_rigid_scene(text: &str) -> bool {
    text.parse::<toml::Table>()
        .map(|t| t.contains_key("rigid"))
        .unwrap_or(false)
}

impl RigidScene {
    /// Parses a scene; errors are `file:line: message`.
    pub fn parse(text: &str, file: &str) -> Result<Self, ParseError> {
        Source::new(file, text).finite_numbers()?;
        toml::from_str::<RigidScene>(text)
            .map_err(|e| Source::new(file, text).parser_error(e.span(), e.message()))
    }

    /// Builds bodies and integrator; `seed` overrides the scene's.
    pub fn build(
        &self,
        text: &str,
        file: &str,
        seed: Option<u64>,
    ) -> Result<BuiltRigid, ParseError> {
        let src = Source::new(file, text);
        let err = |span: std::ops::Range<usize>, msg: String| src.error(span, msg);
        let seed = seed.or(self.seed).unwrap_or(1);
        let rigid = self.rigid.get_ref();
        if let Some(p) = self.output.inspect.first() {
            return Err(err(
                p.span(),
                "[output] inspect names point particles; a rigid scene has bodies (their observables are in observables.csv)".into(),
            ));
        }
        if let Some(p) = &self.output.pressure_tensor {
            return Err(err(
                p.span(),
                "[output] pressure_tensor: the rigid engine measures the scalar pressure only (observables.csv's pressure column, in a periodic box)".into(),
            ));
        }
        let mut frbi = Frbi::new();
        if let Some(f) = &rigid.free_flight {
            frbi.flight = match f.get_ref().as_str() {
                "straight" => FreeFlight::Straight,
                "screw" => FreeFlight::Screw,
                o => {
                    return Err(err(
                        f.span(),
                        format!("unknown free_flight '{o}': expected straight or screw"),
                    ))
                }
            };
        }
        if let Some(s) = &rigid.spin_update {
            frbi.spin = match s.get_ref().as_str() {
                "keep_momentum" => SpinUpdate::KeepMomentum,
                "seed" => SpinUpdate::Seed,
                o => {
                    return Err(err(
                        s.span(),
                        format!("unknown spin_update '{o}': expected keep_momentum or seed"),
                    ))
                }
            };
        }
        let contact = rigid.contacts.as_ref();
        if let Some(c) = contact {
            let c = c.get_ref();
            for (key, value) in [
                ("box_lo", &c.box_lo),
                ("box_hi", &c.box_hi),
                ("periodic", &c.periodic),
            ] {
                if let Some(v) = value {
                    return Err(err(
                        v.span(),
                        format!("[rigid.contacts] {key}: the box is a table of its own, spelled as every engine spells it: [box] lo = [...], hi = [...], periodic = [...]"),
                    ));
                }
            }
        }
        let scene_box = self.scene_box(src)?;
        let material = contact.map(|c| Material {
            young: c.get_ref().young,
            poisson: c.get_ref().poisson,
        });

        // Templates.
        let mut bodies = RigidBodies::new();
        let mut names: Vec<(String, u32)> = Vec::new();
        for (k, t) in rigid.template.iter().enumerate() {
            let (span, ts) = (t.span(), t.get_ref());
            if names.iter().any(|(n, _)| *n == ts.name) {
                return Err(err(
                    span,
                    format!("template '{}' is defined twice", ts.name),
                ));
            }
            let spec = template_spec(ts, seed.wrapping_add(k as u64), material)
                .map_err(|m| err(span.clone(), m))?;
            let tpl = BodyTemplate::new(&spec, Integration::default())
                .map_err(|e| err(span.clone(), format!("template '{}': {e}", ts.name)))?;
            let tpl = match ts.mass {
                Some(m) => {
                    // Scale the density to give the asked mass.
                    let mut spec = spec;
                    spec.density *= m / tpl.mass();
                    BodyTemplate::new(&spec, Integration::default())
                        .map_err(|e| err(span.clone(), format!("template '{}': {e}", ts.name)))?
                }
                None => tpl,
            };
            names.push((ts.name.clone(), bodies.add_template(tpl)));
        }
        let kind_of = |name: &str, span: std::ops::Range<usize>| -> Result<u32, ParseError> {
            names
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, k)| *k)
                .ok_or_else(|| err(span, format!("unknown template '{name}'")))
        };

        // Bodies.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        for b in &rigid.body {
            let (span, bs) = (b.span(), b.get_ref());
            let k = kind_of(&bs.template, span.clone())?;
            let r = match (bs.rotation, bs.axis, bs.angle) {
                (Some(r), None, None) => DVec3::from(r),
                (None, Some(a), Some(deg)) => {
                    let a = DVec3::from(a);
                    if a.length() == 0.0 {
                        return Err(err(span, "the rotation axis must not be zero".into()));
                    }
                    from_axis_angle(a.normalize(), deg.to_radians())
                }
                (None, None, None) => DVec3::ZERO,
                _ => {
                    return Err(err(
                        span,
                        "give either `rotation` or both `axis` and `angle`".into(),
                    ))
                }
            };
            bodies.push(
                k,
                E::new(r, DVec3::from(bs.position)),
                DE::new(DVec3::from(bs.omega), DVec3::from(bs.velocity)),
            );
        }
        if let Some(f) = rigid.from_file.first() {
            return Err(err(
                f.span(),
                "[[rigid.from_file]]: a scene starts from a file as every engine spells it: [[from_file]] file = \"...\" (with frame, templates, tolerance)".into(),
            ));
        }
        for f in &self.from_file {
            let (span, fs) = (f.span(), f.get_ref());
            let at = |m: String| err(span.clone(), m);
            let candidates: Vec<(String, u32)> = match &fs.templates {
                None => names.clone(),
                Some(list) => list
                    .iter()
                    .map(|n| Ok((n.clone(), kind_of(n, span.clone())?)))
                    .collect::<Result<_, ParseError>>()?,
            };
            let tolerance = fs.tolerance.unwrap_or(1e-6);
            if !positive(tolerance) {
                return Err(at("tolerance must be positive".into()));
            }
            let path = std::path::Path::new(file)
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(&fs.file);
            let frames = mote_io::trajectory::read_frames(&path).map_err(|e| match e {
                mote_io::IoError::Parse(p) if p.line > 0 => p,
                other => at(other.to_string()),
            })?;
            let frame = mote_io::trajectory::pick(&frames, fs.frame, &path).map_err(at)?;
            let templates: Vec<_> = candidates
                .iter()
                .map(|(n, k)| (n.clone(), bodies.templates[*k as usize].clone()))
                .collect();
            let placed = super::from_file::place_bodies(frame, &templates, tolerance)
                .map_err(|m| at(format!("{}: {m}", path.display())))?;
            for p in placed {
                bodies.push(candidates[p.template].1, p.placement, p.velocity);
            }
        }
        for (random, list) in [(false, &rigid.lattice), (true, &rigid.random)] {
            for p in list {
                let (span, ps) = (p.span(), p.get_ref());
                let k = kind_of(&ps.template, span.clone())?;
                let bound = bodies.templates[k as usize].props.bounding_radius;
                // Placement, velocities and kind of each body (100 B) and the
                // world-frame centre, radius and owner of each sphere (40 B):
                // refused before anything is allocated when it cannot fit.
                let spheres = bodies.templates[k as usize].sphere_count() as f64;
                mote_io::system::check_fits(
                    &format!("{} bodies of {} spheres", ps.n, spheres),
                    ps.n as f64 * (100.0 + 40.0 * spheres),
                )
                .map_err(|m| err(span.clone(), m))?;
                let (lo, hi) = (DVec3::from(ps.lo), DVec3::from(ps.hi));
                if (0..3).any(|d| hi[d] < lo[d]) {
                    return Err(err(span, "lo must not exceed hi".into()));
                }
                // (a region of 1.8e308 made the uniform draw overflow and panic)
                if (0..3).any(|d| !(2.0 * (hi[d] - lo[d])).is_finite()) {
                    return Err(err(
                        span,
                        format!(
                            "the region [lo, hi] = [{lo}, {hi}] is wider than a placement can draw from"
                        ),
                    ));
                }
                let sites = if random {
                    random_sites(ps.n, lo, hi, bound, &bodies, &mut rng)
                } else {
                    let spacing = ps.spacing.unwrap_or(2.0 * bound);
                    match ps.arrangement.as_deref() {
                        None | Some("cubic") => lattice_sites(ps.n, lo, hi, spacing),
                        Some("fcc") => fcc_sites(ps.n, lo, hi, spacing),
                        Some(o) => Err(format!("unknown arrangement '{o}': expected cubic or fcc")),
                    }
                }
                .map_err(|m| err(span.clone(), m))?;
                for x in sites {
                    let r = if ps.random_orientation {
                        random_rotation(&mut rng)
                    } else {
                        DVec3::ZERO
                    };
                    let v = DVec3::from(ps.velocity) + ps.speed * random_unit(&mut rng);
                    bodies.push(k, E::new(r, x), DE::new(DVec3::ZERO, v));
                }
            }
        }
        if bodies.is_empty() {
            return Err(src.error(
                self.rigid.span(),
                "the scene makes no bodies: add [[rigid.body]], [[rigid.lattice]], [[rigid.random]] or [[from_file]]",
            ));
        }

        // Fields.
        if let Some(f) = &rigid.fields {
            let fs = f.get_ref();
            if let Some(g) = fs.gravity {
                frbi.push(Box::new(Gravity { g: DVec3::from(g) }));
            }
            if fs.electric.is_some() || fs.magnetic.is_some() {
                let conv = |s: &Option<FieldSpec>| -> Result<Field, String> {
                    Ok(match s {
                        None => Field::zero(),
                        Some(FieldSpec::Constant(v)) => Field::Constant(DVec3::from(*v)),
                        Some(FieldSpec::Rotating {
                            amplitude,
                            axis,
                            start,
                            frequency,
                            phase,
                            offset,
                        }) => {
                            let (axis, start) = (DVec3::from(*axis), DVec3::from(*start));
                            if axis.length() == 0.0 || start.cross(axis).length() == 0.0 {
                                return Err("a rotating field needs a non-zero axis and a start direction not along it".into());
                            }
                            let axis = axis.normalize();
                            let start = (start - axis * start.dot(axis)).normalize();
                            Field::Rotating {
                                offset: DVec3::from(*offset),
                                amplitude: *amplitude,
                                axis,
                                start,
                                frequency: *frequency,
                                phase: *phase,
                            }
                        }
                    })
                };
                let electric = conv(&fs.electric).map_err(|m| err(f.span(), m))?;
                let magnetic = conv(&fs.magnetic).map_err(|m| err(f.span(), m))?;
                frbi.push(Box::new(ExternalFields { electric, magnetic }));
            }
            if let Some(k) = fs.coulomb {
                frbi.push(Box::new(Coulomb::new(k)));
            }
            if let Some(k) = fs.dipole_dipole {
                frbi.push(Box::new(DipoleDipole { k }));
            }
            if let Some(d) = &fs.drag {
                frbi.push(Box::new(AirDrag {
                    viscosity: d.viscosity,
                    air_density: d.air_density,
                    drag_coefficient: d.drag_coefficient,
                    wind: DVec3::from(d.wind),
                }));
            }
        }

        // Contacts and walls.
        let mut walls = Vec::new();
        for (k, w) in rigid.wall.iter().enumerate() {
            walls.extend(w.get_ref().walls(k).map_err(|m| err(w.span(), m))?);
        }
        match contact {
            Some(c) => {
                let (span, cs) = (c.span(), c.get_ref());
                if !positive(cs.young) || !(0.0..0.5).contains(&cs.poisson) {
                    return Err(err(
                        span,
                        "contacts need young > 0 and 0 <= poisson < 0.5".into(),
                    ));
                }
                if !(0.0..=1.0).contains(&cs.restitution) || cs.friction < 0.0 {
                    return Err(err(
                        span,
                        "contacts need 0 <= restitution <= 1 and friction >= 0".into(),
                    ));
                }
                let m = material.unwrap();
                let mut law = ContactLaw::new(
                    m,
                    m,
                    cs.restitution,
                    cs.friction,
                    Damping::Exact,
                    cs.limit_damping,
                );
                law.rolling_friction = cs.rolling_friction;
                law.adhesion = cs.adhesion;
                let r_max = bodies
                    .templates
                    .iter()
                    .flat_map(|t| t.radii.iter().cloned())
                    .fold(0.0, f64::max);
                let skin = cs.skin.unwrap_or(0.4 * r_max);
                let mut model = RigidContacts::new(law, law, walls, skin);
                if let Some((b, span)) = scene_box.as_ref().filter(|(b, _)| b.is_periodic()) {
                    for d in 0..3 {
                        if b.periodic[d] && (b.hi[d] - b.lo[d]) < 3.0 * (2.0 * r_max + skin) {
                            return Err(err(span.clone(), "a periodic axis of [box] must be at least three sphere diameters plus skins long".into()));
                        }
                    }
                    model = model.with_boundary(*b);
                }
                frbi.push(Box::new(model));
            }
            None if !walls.is_empty() => {
                return Err(err(
                    rigid.wall[0].span(),
                    "walls need [rigid.contacts] (young, restitution, ...)".into(),
                ));
            }
            None => {}
        }

        let mut planes = None;
        if let Some(p) = &rigid.planes {
            let built = plane_coulomb(p, self.box_faces(), &rigid.fields, &bodies)
                .map_err(|m| err(p.span(), m))?;
            planes = Some((built.planes.clone(), built.z0));
            frbi.push(Box::new(built));
        }
        if let Some(l) = &rigid.latent_image {
            let Some((planes, z0)) = &planes else {
                return Err(err(
                    l.span(),
                    "[rigid.latent_image] needs [rigid.planes] (the belt is the lower plane)"
                        .into(),
                ));
            };
            let ls = l.get_ref();
            let image = LatentImage {
                k: planes.k,
                gap: planes.gap,
                height: ls.height,
                period: planes.lateral[0],
                speed: ls.speed,
                background: ls.background,
                patches: ls
                    .patches
                    .iter()
                    .map(|p| Patch {
                        start: p[0],
                        end: p[1],
                        density: p[2],
                    })
                    .collect(),
            };
            image.check().map_err(|m| err(l.span(), m))?;
            frbi.push(Box::new(LatentField { image, z0: *z0 }));
        }
        if let Some(r) = &rigid.roller {
            let model = induced_dipoles(r.get_ref(), self.box_faces(), &names, &bodies)
                .map_err(|m| err(r.span(), m))?;
            frbi.push(Box::new(model));
        }

        // Run length.
        let (rspan, run) = (self.run.span(), self.run.get_ref());
        if !positive(run.dt) {
            return Err(err(rspan, "[run] dt must be > 0".into()));
        }
        let steps = match (run.steps, run.until) {
            (Some(s), None) => s,
            (None, Some(t)) if t <= 0.0 => {
                return Err(err(
                    rspan,
                    format!("[run] until = {t}: must be a time after the start (t = 0)"),
                ))
            }
            (None, Some(t)) => match mote_run::steps_until(0.0, t, run.dt) {
                Some(n) => n,
                None => {
                    return Err(err(
                        rspan,
                        format!(
                            "[run] until = {} with dt = {}: not a number of steps a run can take",
                            mote_io::system::human_number(t),
                            mote_io::system::human_number(run.dt)
                        ),
                    ))
                }
            },
            _ => {
                return Err(err(
                    rspan,
                    "[run] needs exactly one of `steps` and `until`".into(),
                ))
            }
        };
        Ok(BuiltRigid {
            bodies,
            frbi,
            dt: run.dt,
            steps,
            seed,
        })
    }
}

impl RigidScene {
    /// The body kind (template index) of the template named `name`:
    /// templates are numbered in the order `[[rigid.template]]` lists them.
    pub fn template_kind(&self, name: &str) -> Option<u32> {
        let templates = &self.rigid.get_ref().template;
        templates
            .iter()
            .position(|t| t.get_ref().name == name)
            .map(|k| k as u32)
    }

    /// The scene's `[box]` (lower and upper corner, periodic axes), if it
    /// has one.
    pub fn box_faces(&self) -> Option<(DVec3, DVec3, [bool; 3])> {
        let b = self.bounds.as_ref()?.get_ref();
        Some((DVec3::from(b.lo), DVec3::from(b.hi), b.periodic))
    }

    /// `[box]` checked (lo < hi on every axis), with its span.
    fn scene_box(
        &self,
        src: Source,
    ) -> Result<Option<(Boundary, std::ops::Range<usize>)>, ParseError> {
        match &self.bounds {
            None => Ok(None),
            Some(b) => Ok(Some((
                crate::scene::run::boundary(&self.bounds, None, src)?,
                b.span(),
            ))),
        }
    }
}

/// `[rigid.roller]` above the scene's `[box]`.
fn induced_dipoles(
    rs: &RollerSettings,
    scene_box: Option<(DVec3, DVec3, [bool; 3])>,
    names: &[(String, u32)],
    bodies: &RigidBodies,
) -> Result<InducedDipoles, String> {
    let Some((lo, hi, [true, true, _])) = scene_box else {
        return Err(
            "[rigid.roller] needs a [box] periodic along x and y (the shell is its face z = hi.z)"
                .into(),
        );
    };
    if !positive(rs.field) || !positive(rs.radius) || rs.poles < 2 || !rs.poles.is_multiple_of(2) {
        return Err(
            "[rigid.roller] needs field > 0, radius > 0 and an even number of poles".into(),
        );
    }
    let n = bodies.templates.len();
    let (mut polarisability, mut saturation) = (vec![0.0; n], vec![f64::INFINITY; n]);
    for m in &rs.magnetic {
        let Some((_, k)) = names.iter().find(|(name, _)| *name == m.template) else {
            return Err(format!(
                "[rigid.roller] names unknown template '{}'",
                m.template
            ));
        };
        if m.permeability.is_nan()
            || m.permeability < 1.0
            || m.saturation.is_some_and(|s| !positive(s))
        {
            return Err(
                "[rigid.roller] magnetic templates need permeability >= 1 and saturation > 0"
                    .into(),
            );
        }
        let volume = bodies.templates[*k as usize].props.volume;
        polarisability[*k as usize] = InducedDipoles::polarisability(volume, m.permeability);
        if let Some(ms) = m.saturation {
            saturation[*k as usize] = ms * volume;
        }
    }
    let roller = MagneticRoller {
        field: rs.field,
        poles: rs.poles,
        radius: rs.radius,
        angular_velocity: 2.0 * std::f64::consts::PI * rs.frequency,
        axis: [rs.x.unwrap_or(0.5 * (lo.x + hi.x)), hi.z + rs.radius],
    };
    Ok(InducedDipoles {
        roller,
        polarisability,
        saturation,
        dipole_dipole: rs.dipole_dipole,
        iterations: rs.iterations,
        period: [hi.x - lo.x, hi.y - lo.y],
    })
}

/// `[rigid.planes]` on the faces of the scene's `[box]`.
fn plane_coulomb(
    p: &Spanned<PlaneSettings>,
    scene_box: Option<(DVec3, DVec3, [bool; 3])>,
    fields: &Option<Spanned<FieldSettings>>,
    bodies: &RigidBodies,
) -> Result<PlaneCoulomb, String> {
    let ps = p.get_ref();
    if fields
        .as_ref()
        .is_some_and(|f| f.get_ref().coulomb.is_some())
    {
        return Err("[rigid.planes] sums the Coulomb forces with their images: remove coulomb from [rigid.fields]".into());
    }
    let Some((lo, hi, [true, true, false])) = scene_box else {
        return Err("[rigid.planes] needs a [box] with periodic = [true, true, false] (the planes are its faces z = lo.z and z = hi.z)".into());
    };
    if !positive(ps.coulomb) || !positive(ps.accuracy) {
        return Err("[rigid.planes] needs coulomb > 0 and accuracy > 0".into());
    }
    let charge: Vec<f64> = (0..bodies.len())
        .map(|i| bodies.template(i).charge)
        .filter(|&q| q != 0.0)
        .collect();
    let size = hi - lo;
    let largest = size.x.min(size.y).min(2.0 * size.z) / 2.0;
    // About 3.5 spacings of the doubled cell's 2N charges: some 180
    // neighbours in reach, on linked cells.
    let spacing = (2.0 * size.element_product() / (2 * charge.len().max(1)) as f64).cbrt();
    let r_cut = ps.r_cut.unwrap_or((3.5 * spacing).min(largest));
    if !positive(r_cut) || r_cut > largest * (1.0 + 1e-12) {
        return Err(format!("[rigid.planes] r_cut must be > 0 and at most {largest} (half the smallest side of the box doubled along z)"));
    }
    let planes = ConductingPlanes::new(
        ps.coulomb,
        size.z,
        [size.x, size.y],
        ps.potential,
        &charge,
        r_cut,
        ps.accuracy,
    );
    if ps.every == Some(0) {
        return Err("[rigid.planes] every must be at least 1".into());
    }
    Ok(PlaneCoulomb::new(planes, lo.z, ps.every.unwrap_or(1)))
}

fn template_spec(
    ts: &TemplateSpec,
    seed: u64,
    material: Option<Material>,
) -> Result<ClumpSpec, String> {
    let density = match (ts.density, ts.mass) {
        (Some(d), None) => d,
        (None, Some(_)) => 1.0,
        (None, None) => return Err("a template needs `density` or `mass`".into()),
        (Some(_), Some(_)) => return Err("give `density` or `mass`, not both".into()),
    };
    let radius = || {
        ts.radius
            .ok_or_else(|| "this generator needs `radius`".to_string())
    };
    let mut spec = match (&ts.spheres, ts.generator.as_deref()) {
        (Some(s), None) => {
            if s.is_empty() {
                return Err("`spheres` is empty".into());
            }
            ClumpSpec {
                centres: s.iter().map(|p| DVec3::new(p[0], p[1], p[2])).collect(),
                radii: s.iter().map(|p| p[3]).collect(),
                density,
                youngs_modulus: 0.0,
                poisson_ratio: 0.0,
                charge: 0.0,
                dipole: DVec3::ZERO,
            }
        }
        (None, Some("sphere")) => ClumpSpec {
            centres: vec![DVec3::ZERO],
            radii: vec![radius()?],
            density,
            youngs_modulus: 0.0,
            poisson_ratio: 0.0,
            charge: 0.0,
            dipole: DVec3::ZERO,
        },
        (None, Some("dumbbell")) => dumbbell(
            radius()?,
            ts.distance.ok_or("a dumbbell needs `distance`")?,
            density,
        ),
        (None, Some("trimer")) => linear_trimer(
            radius()?,
            ts.distance.ok_or("a trimer needs `distance`")?,
            density,
        ),
        (None, Some("irregular")) => {
            let d = IrregularClump::default();
            let g = IrregularClump {
                radius: ts.radius.unwrap_or(d.radius),
                lobes: ts.lobes.unwrap_or(d.lobes),
                lobe_radius: ts.lobe_radius.map_or(d.lobe_radius, |r| (r[0], r[1])),
                offset: ts.offset.map_or(d.offset, |r| (r[0], r[1])),
                density,
            };
            if g.lobe_radius.0 > g.lobe_radius.1 || g.offset.0 > g.offset.1 {
                return Err("lobe_radius and offset are [min, max] ranges".into());
            }
            // (lobes = 10¹² asked for 40 TB before anything was checked)
            if g.lobes >= super::template::MAX_TEMPLATE_SPHERES {
                return Err(format!(
                    "lobes = {}: a template holds at most {} spheres",
                    g.lobes,
                    super::template::MAX_TEMPLATE_SPHERES
                ));
            }
            g.generate(ts.seed.unwrap_or(seed))
        }
        (None, Some(o)) => {
            return Err(format!(
                "unknown generator '{o}': expected sphere, dumbbell, trimer or irregular"
            ))
        }
        (Some(_), Some(_)) => return Err("give `spheres` or `generator`, not both".into()),
        (None, None) => return Err("a template needs `spheres` or `generator`".into()),
    };
    if let Some(m) = material {
        let (y, p) = (ts.young.unwrap_or(m.young), ts.poisson.unwrap_or(m.poisson));
        if y != m.young || p != m.poisson {
            return Err("per-template materials are not supported yet: set young and poisson in [rigid.contacts]".into());
        }
        spec.youngs_modulus = y;
        spec.poisson_ratio = p;
    } else {
        spec.youngs_modulus = ts.young.unwrap_or(0.0);
        spec.poisson_ratio = ts.poisson.unwrap_or(0.0);
    }
    spec.charge = ts.charge;
    spec.dipole = DVec3::from(ts.dipole);
    Ok(spec)
}

/// x > 0 (false for NaN).
fn positive(x: f64) -> bool {
    x > 0.0
}

fn random_unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    let z: f64 = rng.gen_range(-1.0..1.0);
    let p: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    let s = (1.0 - z * z).sqrt();
    DVec3::new(s * p.cos(), s * p.sin(), z)
}

/// A uniformly random rotation as a rotation vector n·tan(φ/2) = q⃗/q₀ of a
/// uniform unit quaternion (Shoemake), with q₀ ≥ 0.
fn random_rotation(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    let (u1, u2, u3): (f64, f64, f64) = (rng.gen(), rng.gen(), rng.gen());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = [
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    ];
    let w = q[3].abs().max(1e-9) * q[3].signum();
    DVec3::new(q[0], q[1], q[2]) / w
}

fn lattice_sites(n: usize, lo: DVec3, hi: DVec3, spacing: f64) -> Result<Vec<DVec3>, String> {
    if !positive(spacing) {
        return Err("spacing must be > 0".into());
    }
    let count = |k: usize| ((hi[k] - lo[k]) / spacing).floor() as usize + 1;
    let (nx, ny, nz) = (count(0), count(1), count(2));
    if nx * ny * nz < n {
        return Err(format!(
            "only {} lattice sites of spacing {spacing} fit in [lo, hi], {n} asked",
            nx * ny * nz
        ));
    }
    let mut out = Vec::with_capacity(n);
    'fill: for iz in 0..nz {
        for iy in 0..ny {
            for ix in 0..nx {
                if out.len() == n {
                    break 'fill;
                }
                out.push(lo + spacing * DVec3::new(ix as f64, iy as f64, iz as f64));
            }
        }
    }
    Ok(out)
}

/// The first n sites, by height, of the face-centred cubic lattice with
/// nearest-neighbour distance `spacing` and a corner at `lo`, inside [lo, hi].
fn fcc_sites(n: usize, lo: DVec3, hi: DVec3, spacing: f64) -> Result<Vec<DVec3>, String> {
    if !positive(spacing) {
        return Err("spacing must be > 0".into());
    }
    let a = spacing * std::f64::consts::SQRT_2;
    let cells = |k: usize| ((hi[k] - lo[k]) / a).floor() as i64 + 1;
    let basis = [
        DVec3::ZERO,
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(0.5, 0.0, 0.5),
        DVec3::new(0.0, 0.5, 0.5),
    ];
    let mut sites = Vec::new();
    for iz in 0..cells(2) {
        for iy in 0..cells(1) {
            for ix in 0..cells(0) {
                for b in &basis {
                    let x = lo + a * (DVec3::new(ix as f64, iy as f64, iz as f64) + *b);
                    if (0..3).all(|k| x[k] <= hi[k] + 1e-9 * a) {
                        sites.push(x);
                    }
                }
            }
        }
    }
    if sites.len() < n {
        return Err(format!(
            "only {} fcc sites of spacing {spacing} fit in [lo, hi], {n} asked",
            sites.len()
        ));
    }
    sites.sort_by(|p, q| {
        p.z.total_cmp(&q.z)
            .then(p.y.total_cmp(&q.y))
            .then(p.x.total_cmp(&q.x))
    });
    sites.truncate(n);
    Ok(sites)
}

/// Random sequential addition of bounding spheres (radius `bound`) with
/// centres in [lo, hi], not overlapping each other or bodies already placed.
fn random_sites(
    n: usize,
    lo: DVec3,
    hi: DVec3,
    bound: f64,
    placed: &RigidBodies,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<DVec3>, String> {
    let mut taken: Vec<(DVec3, f64)> = (0..placed.len())
        .map(|i| (placed.position[i], placed.template(i).props.bounding_radius))
        .collect();
    let first = taken.len();
    let mut tries = 0usize;
    while taken.len() - first < n {
        tries += 1;
        if tries > 1000 * (n + 10) {
            return Err(format!(
                "could place only {} of {n} bodies without overlap: enlarge [lo, hi]",
                taken.len() - first
            ));
        }
        let x = DVec3::new(
            rng.gen_range(lo.x..=hi.x),
            rng.gen_range(lo.y..=hi.y),
            rng.gen_range(lo.z..=hi.z),
        );
        if taken
            .iter()
            .all(|(y, r)| (x - *y).length_squared() >= (r + bound) * (r + bound))
        {
            taken.push((x, bound));
        }
    }
    Ok(taken[first..].iter().map(|(x, _)| *x).collect())
}

pub use super::run::sphere_frame;
