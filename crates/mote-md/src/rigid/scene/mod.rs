//! The `[rigid]` scene format: templates of overlapping spheres, bodies
//! placed one by one or by generators, fields, contacts and walls, built
//! into bodies and an FRBI (run by [`super::run`]).
//!
//! ```toml
//! seed = 7
//! [rigid]
//! free_flight = "straight"     # or "screw" (the seed's literal free step)
//! spin_update = "keep_momentum" # or "seed"
//! order = "space"              # bodies stored along a Morton curve; or "file"
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
//! drag = { viscosity = 1.8e-5, air_density = 1.2, drag_coefficient = 0.47 }
//!
//! [coulomb]                    # the point particles' table, between the centres:
//! method = "ewald"             # direct or tree (open space), ewald (cubic, periodic)
//! accuracy = 1e-3              # Ewald's RMS force error aimed at
//!
//! [dipolar]                    # the point particles' table, between the centres'
//! method = "ewald"             # dipoles (each body's its template's, turned with it):
//! accuracy = 1e-3              # all pairs, cutoff (minimum image) or ewald
//!
//! [gravity]                    # the point particles' table: mutual gravitation
//! G = 6.674e-11                # of the bodies' masses (open space)
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
//! method = "ewald"             # or "p3m" (with optional mesh, order): O(N log N)
//!
//! [rigid.latent_image]         # surface charge on a belt over the lower plane
//! height = 2e-5                # electrical thickness d/ε_r of the photoconductor
//! speed = 0.3                  # belt speed along x
//! background = 0.0             # charge density outside the patches
//! patches = [[1e-4, 3e-4, -5e-4]]  # [start, end, density]: x-intervals at t = 0
//! period = 4e-4                # the image repeats every period (default: the box's length, which it divides)
//!
//! [rigid.roller]               # magnetic roller inside the upper plane (the shell)
//! field = 0.08                 # B₀ (T) at the shell's surface
//! poles = 8
//! radius = 0.01                # shell radius: the axis is this far above the upper plane
//! frequency = 5.0              # roller turns per second (negative: the other way)
//! x = 2e-4                     # x of the axis (default: the box's centre)
//! dipole_dipole = 1e-7         # μ0/4π: forces between the induced moments (off if absent)
//! iterations = 2               # passes of mutual induction
//! cutoff = 1e-4                # moments farther apart do not see each other (default: all pairs)
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
//!
//! Each table is a [`Section`] of the [`Clumps`] kind, as point-particle
//! scenes' tables are of theirs: templates (templates.rs), placements —
//! bodies one by one, `[[from_file]]`, lattices, random placement —
//! (placement.rs), fields (fields.rs), contacts and walls (contacts.rs),
//! conducting planes, the latent image and the magnetic roller
//! (planes.rs); [`RigidScene::build`] adds them in that order.

use std::ops::Range;
use std::sync::LazyLock;

use glam::DVec3;
use mote_io::{ParseError, Source};
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;
use toml::Spanned;

use super::bodies::RigidBodies;
use super::contacts::RigidContacts;
use super::flow::BodyFlow;
use super::frbi::{Frbi, FreeFlight, SpinUpdate};
use crate::boundary::Boundary;
use crate::force::granular::Material;
use crate::force::slab::ConductingPlanes;
use crate::scene::{add, Kind, SceneFile, Section};

mod centres;
mod contacts;
mod fields;
mod flow;
mod placement;
mod planes;
mod point_tables;
mod sites;
mod templates;

pub use contacts::ContactSettings;
pub use fields::{DragSpec, FieldSettings, FieldSpec};
pub use placement::{BodySpec, Lattice, PlacementSpec, Random};
pub use planes::{LatentSettings, MagneticSpec, PlaneSettings, RollerSettings};
pub use templates::TemplateSpec;

/// A whole rigid scene file: the one scene of every time-stepped engine
/// with its `[rigid]` table. Of the point particles' tables, the laws
/// between point particles the bodies feel between their centres
/// ([`SceneFile::centre_laws`]: `[gravity]`, `[dipolar]`, `[coulomb]`) are taken; the
/// others are refused at their line with what a rigid scene says instead.
pub type RigidScene = SceneFile<RigidSettings>;

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidSettings {
    #[serde(default)]
    pub free_flight: Option<Spanned<String>>,
    #[serde(default)]
    pub spin_update: Option<Spanned<String>>,
    /// How the bodies are stored: `space` (default) sorts them along a
    /// Morton curve once the scene has placed them, so that contact and
    /// pair-sum partners are near in memory ([`crate::order`]); `file`
    /// keeps the order the scene gives. Files, messages and Python's
    /// `numbers` use the scene's numbering either way.
    #[serde(default)]
    pub order: crate::order::ParticleOrder,
    #[serde(default)]
    pub template: Vec<Spanned<TemplateSpec>>,
    #[serde(default)]
    pub body: Vec<Spanned<BodySpec>>,
    #[serde(default)]
    pub lattice: Vec<Spanned<Lattice>>,
    #[serde(default)]
    pub random: Vec<Spanned<Random>>,
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

/// The built scene: bodies, the integrator and what to run.
pub struct BuiltRigid {
    pub bodies: RigidBodies,
    pub frbi: Frbi,
    /// Bodies inserted and taken out, where the scene has `[[insert]]`
    /// or `[[outlet]]`.
    pub flow: Option<BodyFlow>,
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

/// Rigid-clump scenes: their tables are [`Section`]s of this kind.
pub struct Clumps;

impl Kind for Clumps {
    type Scene = RigidScene;
    type Build<'a> = RigidBuild<'a>;
}

/// What the tables of a rigid scene build together, in table order: the
/// templates (by name), the bodies, the integrator with its interactions
/// in the order their wrenches are summed, and the placements' random
/// generator (drawn from in table order, so a seed gives one scene).
pub struct RigidBuild<'a> {
    /// Locates errors: `file:line: message`.
    pub src: Source<'a>,
    pub seed: u64,
    /// The contacts' material, where the scene has contacts (the
    /// templates take it).
    pub material: Option<Material>,
    /// The templates' names and body kinds, in the order they are listed.
    pub names: Vec<(String, u32)>,
    pub bodies: RigidBodies,
    pub frbi: Frbi,
    pub rng: Xoshiro256PlusPlus,
    /// `[box]` checked, with its span.
    pub scene_box: Option<(Boundary, Range<usize>)>,
    /// The conducting planes and the height of the lower one, once
    /// `[rigid.planes]` is built (the latent image lies on them).
    pub planes: Option<(ConductingPlanes, f64)>,
}

impl RigidBuild<'_> {
    /// `file:line: message` at `span`.
    fn error(&self, span: Range<usize>, message: String) -> ParseError {
        self.src.error(span, message)
    }

    /// The body kind of the template named `name`, or an error at `span`.
    fn kind_of(&self, name: &str, span: Range<usize>) -> Result<u32, ParseError> {
        self.names
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, k)| *k)
            .ok_or_else(|| self.error(span, format!("unknown template '{name}'")))
    }
}

/// Adds the tables of a list (`[[rigid.template]]`, ...), in order.
fn add_each<T: Section<Clumps>>(
    tables: &[Spanned<T>],
    scene: &RigidScene,
    b: &mut RigidBuild,
) -> Result<(), ParseError> {
    tables
        .iter()
        .try_for_each(|t| t.get_ref().add_to(t.span(), scene, b))
}

impl RigidScene {
    /// Parses a rigid scene; errors are `file:line: message`.
    pub fn parse(text: &str, file: &str) -> Result<RigidScene, ParseError> {
        crate::scene::parse(text, file)
    }

    /// The `[rigid]` table (an empty one where the scene has none, which
    /// [`RigidScene::build`] refuses first).
    pub fn settings(&self) -> &RigidSettings {
        static NONE: LazyLock<RigidSettings> = LazyLock::new(RigidSettings::default);
        self.rigid.as_ref().map_or(&NONE, |r| r.get_ref())
    }

    /// Builds bodies and integrator; `seed` overrides the scene's.
    pub fn build(
        &self,
        text: &str,
        file: &str,
        seed: Option<u64>,
    ) -> Result<BuiltRigid, ParseError> {
        let src = Source::new(file, text);
        let err = |span: Range<usize>, msg: String| src.error(span, msg);
        let Some(rigid_table) = &self.rigid else {
            return Err(src.whole("a rigid scene needs its [rigid] table"));
        };
        point_tables::refuse(self, src)?;
        let seed = seed.or(self.seed).unwrap_or(1);
        let rigid = rigid_table.get_ref();
        self.output.refuse(
            src,
            &[
                ("inspect", "it names point particles; a rigid scene has bodies (their observables are in observables.csv)"),
                ("pressure_tensor", "the rigid engine measures the scalar pressure only (observables.csv's pressure column, in a periodic box)"),
            ],
        )?;
        crate::scene::run::refuse_event_driven_output(&self.output, src)?;
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
        let mut b = RigidBuild {
            src,
            seed,
            material: contact.map(|c| Material {
                young: c.get_ref().young,
                poisson: c.get_ref().poisson,
            }),
            names: Vec::new(),
            bodies: RigidBodies::new(),
            frbi,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            scene_box: self.scene_box(src)?,
            planes: None,
        };

        add_each(&rigid.template, self, &mut b)?;
        add_each(&rigid.body, self, &mut b)?;
        if let Some(f) = rigid.from_file.first() {
            return Err(err(
                f.span(),
                "[[rigid.from_file]]: a scene starts from a file as every engine spells it: [[from_file]] file = \"...\" (with frame, templates, tolerance)".into(),
            ));
        }
        add_each(&self.from_file, self, &mut b)?;
        add_each(&rigid.lattice, self, &mut b)?;
        add_each(&rigid.random, self, &mut b)?;
        if b.bodies.is_empty() && self.insert.is_empty() {
            return Err(src.error(
                rigid_table.span(),
                "the scene makes no bodies: add [[rigid.body]], [[rigid.lattice]], [[rigid.random]], [[from_file]] or [[insert]]",
            ));
        }
        // Stored in space order before any interaction sees the bodies.
        if rigid.order == crate::order::ParticleOrder::Space {
            b.bodies.to_space_order();
        }
        add(&rigid.fields, self, &mut b)?;
        centres::refuse_coulomb_between_planes(self, &b)?;
        for (law, span) in self.centre_laws() {
            centres::add_law(law, span, &mut b)?;
        }
        match contact {
            Some(_) => add(&rigid.contacts, self, &mut b)?,
            None => {
                for (k, w) in rigid.wall.iter().enumerate() {
                    w.get_ref().walls(k).map_err(|m| err(w.span(), m))?;
                }
                if let Some(w) = rigid.wall.first() {
                    return Err(err(
                        w.span(),
                        "walls need [rigid.contacts] (young, restitution, ...)".into(),
                    ));
                }
            }
        }
        add(&rigid.planes, self, &mut b)?;
        add(&rigid.latent_image, self, &mut b)?;
        add(&rigid.roller, self, &mut b)?;
        let flow = flow::body_flow(self, &mut b)?;

        // Run length.
        let run = &self.run;
        run.refuse(
            src,
            &[
                ("integrator", "rigid bodies are moved by the FRBI only"),
                (
                    "equilibrate",
                    "rigid bodies are measured from the first step; equilibrate is the event-driven engine's",
                ),
                (
                    "centre_of_mass",
                    "rigid bodies keep the frame they are placed in",
                ),
            ],
        )?;
        let dt = run
            .time_step(src)?
            .ok_or_else(|| src.whole("[run] needs a time step: dt = ..."))?;
        let Some(length) = run.length(src)? else {
            return Err(src.whole("[run] needs exactly one of `steps` and `until`"));
        };
        // Only an end time can fail to give a count.
        let steps = length.steps_from(0.0, dt).map_err(|m| match &run.until {
            Some(until) => until.error(src, m),
            None => src.whole(m),
        })?;
        Ok(BuiltRigid {
            bodies: b.bodies,
            frbi: b.frbi,
            flow,
            dt,
            steps,
            seed,
        })
    }
}

impl RigidScene {
    /// Readies the scene to resume `cp`: a checkpoint that names no order
    /// of its bodies (written before rigid bodies were stored in space
    /// order) resumes in the scene's order, the one it was written in.
    pub fn keep_order_of(&mut self, cp: &mote_io::checkpoint::Checkpoint) {
        if let (false, Some(r)) = (crate::order::names_order(cp), &mut self.rigid) {
            r.get_mut().order = crate::order::ParticleOrder::File;
        }
    }

    /// The body kind (template index) of the template named `name`:
    /// templates are numbered in the order `[[rigid.template]]` lists them.
    pub fn template_kind(&self, name: &str) -> Option<u32> {
        let templates = &self.settings().template;
        templates
            .iter()
            .position(|t| t.get_ref().name == name)
            .map(|k| k as u32)
    }

    /// The scene's `[box]` (lower and upper corner, periodic axes), if it
    /// has one.
    pub fn box_faces(&self) -> Option<(DVec3, DVec3, [bool; 3])> {
        let b = self.bounds.as_ref()?.get_ref();
        let (lo, hi) = (b.lo(3), b.hi.as_ref()?.get_ref());
        let p = b.periodic(3);
        (lo.len() == 3 && hi.len() == 3).then(|| {
            (
                DVec3::from_slice(&lo),
                DVec3::from_slice(hi),
                [p[0], p[1], p[2]],
            )
        })
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

/// x > 0 (false for NaN).
fn positive(x: f64) -> bool {
    x > 0.0
}

pub use super::run::sphere_frame;
