//! The particles of a scene: `[[particle]]` tables, the generators
//! (`[[lattice]]`, `[[ring]]`, `[[annulus]]`, `[[random_box]]`, `[[fcc]]`,
//! `[[cloud]]`, `[[plummer]]`), `[[lammps_data]]` files and `[[spring]]`s
//! between them (002 Eq. 4).

use glam::DVec3;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;

use mote_io::{ParseError, Source};

use super::{all_free, one, white, z_axis, Scene};
use crate::boundary::Boundary;
use crate::force::Spring;
use crate::init::{self, Anchor};
use crate::particles::{ParticleInit, Particles};

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
    /// The name written in trajectories (a chemical symbol reads in ASE;
    /// default `X`, ASE's dummy element).
    pub species: Option<String>,
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
            species: None,
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

/// `[[from_file]]` (and its older name `[[lammps_data]]`): particles from a
/// file, path relative to the scene file: a LAMMPS data file (`.data`,
/// `.lmp`: the styles of [`mote_io::lammps_data`]) or a frame of a
/// trajectory (`.xyz`, `.dump`, `.gsd`, `.vtu`/`.vtp`/`.pvd`; the last
/// frame unless `frame` says which, negative counting from the end).
/// Positions, velocities, radii, masses and spins come from the file where
/// it has them; `radius`, `mass` or `density` fill in what it lacks. A
/// scene without `[box]` takes the box of a trajectory frame with periodic
/// axes; a data file does not say which axes are periodic, so its box is
/// taken only with `periodic = [..]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSpec {
    pub file: String,
    pub frame: Option<i64>,
    /// Take a data file's box, periodic on these axes.
    pub periodic: Option<[bool; 3]>,
    /// Copies of the file's periodic box along x, y, z (LAMMPS'
    /// `replicate`): a settled bed or an equilibrated liquid made large.
    pub replicate: Option<[usize; 3]>,
    /// The atom style of a data file whose `Atoms` line names none
    /// (MDAnalysis writes none): atomic, charge, molecular, full, sphere.
    pub atom_style: Option<String>,
    /// The file's unit system, as LAMMPS names them (`si`, `cgs`, `real`,
    /// `metal`, `micro`, `nano`, `lj`): positions, velocities, spins,
    /// masses, radii, charges and the box are converted into the scene's
    /// units (default: the file is in the scene's units). `radius`,
    /// `mass` and `density` here are in the scene's units.
    pub units: Option<String>,
    pub radius: Option<f64>,
    pub mass: Option<f64>,
    /// Masses from the radii, m = ρ 4π r³/3 (for files without masses).
    pub density: Option<f64>,
    /// The species of every particle (default: the file's names, a data
    /// file's `Atom Type Labels`, else `X`).
    pub species: Option<String>,
    /// The particles' colour (default white).
    pub color: Option<[f64; 3]>,
    /// Rigid bodies only: the templates a frame's spheres are matched to
    /// (default: all the scene's, in order).
    pub templates: Option<Vec<String>>,
    /// Rigid bodies only: the largest misfit of a sphere centre, as a
    /// fraction of the template's bounding radius (default 1e-6; files of
    /// few digits need more).
    pub tolerance: Option<f64>,
}

impl DataSpec {
    /// The particles' colour.
    fn color(&self) -> [f64; 3] {
        self.color.unwrap_or_else(white)
    }

    /// The keys this table gives, of `keys`.
    pub fn given<'k>(&self, keys: &[&'k str]) -> Vec<&'k str> {
        let given = |k: &str| match k {
            "frame" => self.frame.is_some(),
            "periodic" => self.periodic.is_some(),
            "replicate" => self.replicate.is_some(),
            "atom_style" => self.atom_style.is_some(),
            "units" => self.units.is_some(),
            "radius" => self.radius.is_some(),
            "mass" => self.mass.is_some(),
            "density" => self.density.is_some(),
            "species" => self.species.is_some(),
            "color" => self.color.is_some(),
            "templates" => self.templates.is_some(),
            "tolerance" => self.tolerance.is_some(),
            _ => false,
        };
        keys.iter().copied().filter(|k| given(k)).collect()
    }
}

/// The particles of a file, their species, the file's box if it has one,
/// and its bonds as springs (indices within the file).
type FromFile = (
    Vec<ParticleInit>,
    Vec<String>,
    Option<crate::boundary::Boundary>,
    Vec<Spring>,
);

/// The particles of one `[[from_file]]`, their species and the file's box
/// if it has one. `data`: read it as a LAMMPS data file whatever its name
/// (`[[lammps_data]]`). `scales`: one unit of the file's length, time,
/// mass and charge in the scene's units (`units`), applied to what the
/// file gives before `radius`, `mass` or `density` (scene units) fill in
/// what it lacks. Errors in the file name its own lines; the others come
/// back as messages for the scene's line (`at`).
fn from_file(
    s: &DataSpec,
    path: &std::path::Path,
    data: bool,
    scales: Option<crate::units::Scales>,
    at: &dyn Fn(String) -> ParseError,
) -> Result<FromFile, ParseError> {
    let k = scales.unwrap_or(crate::units::Scales::SAME);
    let speed = k.length / k.time;
    let io = |e: mote_io::IoError| match e {
        mote_io::IoError::Parse(p) if p.line > 0 => p,
        other => at(other.to_string()),
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    // LAMMPS names data files data.NAME or NAME.data.
    let data = data
        || matches!(ext.as_str(), "data" | "lmp" | "lammps")
        || path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with("data."));
    let fill = |radius: f64, mass: f64| -> Result<(f64, f64), ParseError> {
        let r = if radius > 0.0 {
            radius
        } else {
            s.radius.unwrap_or(0.0)
        };
        let m = if mass > 0.0 {
            mass
        } else if let Some(m) = s.mass {
            m
        } else if let Some(rho) = s.density {
            sphere_mass(rho, r)
        } else {
            return Err(at(format!(
                "{}: the file gives no mass: set mass or density",
                path.display()
            )));
        };
        Ok((r, m))
    };
    if data {
        let style = match &s.atom_style {
            None => None,
            Some(name) => Some(mote_io::lammps_data::AtomStyle::named(name).ok_or_else(|| {
                at(format!(
                    "atom_style '{name}' is not one of atomic, charge, molecular, full, sphere"
                ))
            })?),
        };
        let data = mote_io::lammps_data::read_as(path, style).map_err(|e| io(e.into()))?;
        let mut out = Vec::with_capacity(data.atoms.len());
        for a in &data.atoms {
            let radius = 0.5 * a.diameter;
            let mass = if a.density > 0.0 {
                sphere_mass(a.density, radius)
            } else {
                a.mass
            };
            let (radius, mass) = fill(radius * k.length, mass * k.mass)?;
            out.push(ParticleInit {
                position: DVec3::from(a.position) * k.length,
                velocity: DVec3::from(a.velocity) * speed,
                angular_velocity: DVec3::from(a.angular_velocity) / k.time,
                mass,
                radius,
                charge: a.charge * k.charge,
                color: s.color(),
                ..ParticleInit::default()
            });
        }
        let boundary = match s.periodic {
            Some(periodic) if data.bounded.iter().all(|b| *b) => Some(crate::boundary::Boundary {
                lo: DVec3::from(data.lo) * k.length,
                hi: DVec3::from(data.hi) * k.length,
                periodic,
            }),
            Some(_) => {
                return Err(at(format!(
                    "{}: periodic is set but the file gives no box (xlo xhi, ylo yhi, zlo zhi)",
                    path.display()
                )))
            }
            None => None,
        };
        let names = data
            .atoms
            .iter()
            .map(|a| match (&s.species, data.type_labels.get(&a.kind)) {
                (Some(name), _) => name.clone(),
                (None, Some(label)) => label.clone(),
                (None, None) => "X".to_string(),
            })
            .collect();
        // E = K (r − r₀)² of bond_style harmonic is a spring of stiffness
        // D = 2K (002 Eq. 4: F = D (r − l)); K is energy per length².
        let stiffness = k.energy / (k.length * k.length);
        let springs = data
            .bonds
            .iter()
            .map(|b| Spring {
                i: b.atoms[0],
                j: b.atoms[1],
                stiffness: 2.0 * b.k * stiffness,
                damping: 0.0,
                rest_length: b.r0 * k.length,
            })
            .collect();
        return Ok((out, names, boundary, springs));
    }
    let frames = mote_io::trajectory::read_frames(path).map_err(io)?;
    let f = mote_io::trajectory::pick(&frames, s.frame, path).map_err(at)?;
    let n = f.positions.len();
    let get = |v: &Vec<[f64; 3]>, i: usize| {
        if v.len() == n {
            DVec3::from(v[i])
        } else {
            DVec3::ZERO
        }
    };
    if scales.is_some() && f.dipoles.iter().any(|m| *m != [0.0; 3]) {
        return Err(at(format!(
            "{}: the file's magnetic dipoles have no unit conversion: leave out units",
            path.display()
        )));
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (radius, mass) = fill(
            f.radii.get(i).copied().unwrap_or(0.0) * k.length,
            f.masses.get(i).copied().unwrap_or(0.0) * k.mass,
        )?;
        out.push(ParticleInit {
            position: DVec3::from(f.positions[i]) * k.length,
            velocity: get(&f.velocities, i) * speed,
            angular_velocity: get(&f.angular_velocities, i) / k.time,
            dipole: get(&f.dipoles, i),
            mass,
            radius,
            color: s.color(),
            ..ParticleInit::default()
        });
    }
    let c = f.cell;
    let orthogonal = c[0][1] == 0.0
        && c[0][2] == 0.0
        && c[1][0] == 0.0
        && c[1][2] == 0.0
        && c[2][0] == 0.0
        && c[2][1] == 0.0;
    let boundary = (f.pbc.iter().any(|p| *p) && orthogonal).then(|| {
        let lo = DVec3::from(f.origin) * k.length;
        crate::boundary::Boundary {
            lo,
            hi: lo + DVec3::new(c[0][0], c[1][1], c[2][2]) * k.length,
            periodic: f.pbc,
        }
    });
    let names = (0..n)
        .map(|i| match (&s.species, f.species.get(i)) {
            (Some(name), _) => name.clone(),
            (None, Some(name)) if !name.is_empty() => name.clone(),
            _ => "X".to_string(),
        })
        .collect();
    Ok((out, names, boundary, Vec::new()))
}

/// LAMMPS' `replicate`: the particles copied `copies` times along the
/// axes of their periodic box, each copy shifted by whole box lengths,
/// x' = x + (i Lx, j Ly, k Lz); the box grows to hold them. An axis copied
/// more than once must be periodic, so the copies join without a seam.
fn replicate(
    made: &mut Vec<ParticleInit>,
    names: &mut Vec<String>,
    file_box: Option<crate::boundary::Boundary>,
    copies: [usize; 3],
) -> Result<crate::boundary::Boundary, String> {
    const AXES: [&str; 3] = ["x", "y", "z"];
    if copies.contains(&0) {
        return Err(format!(
            "replicate = {copies:?} needs at least one copy along every axis"
        ));
    }
    let Some(b) = file_box else {
        return Err("replicate needs the file's box: a trajectory frame with periodic axes, or a data file with periodic = [..]".into());
    };
    for k in 0..3 {
        if copies[k] > 1 && !b.periodic[k] {
            return Err(format!(
                "replicate copies along {0} but the file's box is not periodic along {0}",
                AXES[k]
            ));
        }
    }
    let total = made.len() as f64 * copies.iter().map(|&c| c as f64).product::<f64>();
    mote_io::system::check_fits(
        &format!("replicate = {copies:?} makes {total:.0} particles, which"),
        total * BYTES_PER_PARTICLE,
    )?;
    let l = b.lengths();
    let (one, one_names) = (std::mem::take(made), std::mem::take(names));
    for i in 0..copies[0] {
        for j in 0..copies[1] {
            for k in 0..copies[2] {
                let shift = DVec3::new(i as f64 * l.x, j as f64 * l.y, k as f64 * l.z);
                made.extend(one.iter().map(|p| ParticleInit {
                    position: p.position + shift,
                    ..p.clone()
                }));
                names.extend(one_names.iter().cloned());
            }
        }
    }
    let n = DVec3::new(copies[0] as f64, copies[1] as f64, copies[2] as f64);
    Ok(crate::boundary::Boundary {
        lo: b.lo,
        hi: b.lo + l * n,
        periodic: b.periodic,
    })
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

/// The particles of a scene, the springs between them, and the periodic box
/// an `[[fcc]]` crystal sets.
pub struct Made {
    pub particles: Particles,
    /// The species of each particle.
    pub species: Vec<String>,
    pub springs: Vec<Spring>,
    pub fcc_box: Option<Boundary>,
}

impl Made {
    /// Stores the particles in space order ([`crate::order`]), with their
    /// species and springs; returns the order (row k was row `order[k]`).
    pub fn to_space_order(&mut self) -> Vec<usize> {
        let p = &mut self.particles;
        let order = crate::order::space_order(&p.position, &p.radius);
        p.reorder(&order);
        self.species = crate::order::gathered(&self.species, &order);
        let rows = crate::order::new_rows(&order);
        for s in &mut self.springs {
            (s.i, s.j) = (rows[s.i], rows[s.j]);
        }
        order
    }
}

/// Bytes per particle, a lower bound while a scene is built: the particle
/// arrays (six vectors, four scalars, a colour: 200 B), the generators'
/// staging copy (about as much) and the integrator's carried accelerations.
const BYTES_PER_PARTICLE: f64 = 450.0;

/// The number of particles the generators will make (files not counted),
/// and the table that makes the most, refused before anything is allocated
/// when their arrays alone would not fit in the available memory.
fn refuse_too_large(scene: &Scene, src: Source) -> Result<(), ParseError> {
    fn each<'a, T>(
        tables: &'a [toml::Spanned<T>],
        name: &'static str,
        n: impl Fn(&T) -> f64 + 'a,
    ) -> impl Iterator<Item = (std::ops::Range<usize>, &'static str, f64)> + 'a {
        tables.iter().map(move |t| (t.span(), name, n(t.get_ref())))
    }
    let product = |n: &[usize; 3]| n.iter().map(|&k| k as f64).product::<f64>();
    let counts: Vec<_> = each(&scene.lattice, "[[lattice]]", |s| product(&s.n))
        .chain(each(&scene.fcc, "[[fcc]]", |s| 4.0 * product(&s.cells)))
        .chain(each(&scene.ring, "[[ring]]", |s| s.n as f64))
        .chain(each(&scene.annulus, "[[annulus]]", |s| s.n as f64))
        .chain(each(&scene.random_box, "[[random_box]]", |s| s.n as f64))
        .chain(each(&scene.cloud, "[[cloud]]", |s| s.n as f64))
        .chain(each(&scene.plummer, "[[plummer]]", |s| s.n as f64))
        .collect();
    let total = scene.particle.len() as f64 + counts.iter().map(|c| c.2).sum::<f64>();
    let Some((span, table, n)) = counts.into_iter().max_by(|a, b| a.2.total_cmp(&b.2)) else {
        return Ok(());
    };
    mote_io::system::check_fits(
        &format!("the scene makes {total:.0} particles ({n:.0} from this {table}), which"),
        total * BYTES_PER_PARTICLE,
    )
    .map_err(|m| src.error(span, m))
}

/// Makes every particle of the scene, in the order of the module's doc,
/// drawing from `rng` in that order.
pub fn make(scene: &Scene, src: Source, rng: &mut Xoshiro256PlusPlus) -> Result<Made, ParseError> {
    refuse_too_large(scene, src)?;
    let file = src.file;
    let err = |span: std::ops::Range<usize>, msg: String| src.error(span, msg);
    let g_const = scene
        .gravity
        .as_ref()
        .and_then(|g| g.get_ref().g)
        .unwrap_or(scene.units.gravitational_constant());
    let mut inits: Vec<ParticleInit> = Vec::new();
    let mut species: Vec<String> = Vec::new();
    let name = |p: &Properties| p.species.clone().unwrap_or_else(|| "X".to_string());
    let mut displacements: Vec<DVec3> = Vec::new();
    let mut springs: Vec<Spring> = Vec::new();

    let check_props = |p: &Properties, span: std::ops::Range<usize>| -> Result<(), ParseError> {
        if let Some(name) = &p.species {
            if name.is_empty() || name.contains(char::is_whitespace) {
                return Err(err(
                    span,
                    format!("species '{name}' must be one word (no spaces)"),
                ));
            }
        }
        // Bounded so that products such as m v² and G m₁ m₂ stay finite.
        if !(p.mass > 0.0 && p.mass <= 1e100) {
            return Err(err(
                span,
                format!(
                    "mass must be positive and at most 1e100, found {}",
                    mote_io::system::human_number(p.mass)
                ),
            ));
        }
        if !(0.0..=1e100).contains(&p.radius) {
            return Err(err(
                span,
                format!(
                    "radius must be in [0, 1e100], found {}",
                    mote_io::system::human_number(p.radius)
                ),
            ));
        }
        if p.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
            return Err(err(
                span,
                format!(
                    "color = {:?}: each of red, green, blue is in [0, 1]",
                    p.color
                ),
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

    for spec in &scene.particle {
        let s = spec.get_ref();
        check_props(&s.props, spec.span())?;
        let mut p = s.props.template();
        p.position = DVec3::from(s.position);
        p.velocity = DVec3::from(s.velocity);
        inits.push(p);
        displacements.push(DVec3::from(s.displacement));
        species.push(name(&s.props));
    }
    for spec in &scene.lattice {
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
                    format!("unknown anchor '{other}': expected none, boundary or first-column"),
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
            species.push(name(&s.props));
        }
        springs.extend(lat.springs.into_iter().map(|sp| Spring {
            i: sp.i + offset,
            j: sp.j + offset,
            ..sp
        }));
    }
    for spec in &scene.ring {
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
            species.push(name(&s.props));
        }
    }
    for spec in &scene.annulus {
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
            rng,
        ) {
            inits.push(p);
            displacements.push(DVec3::ZERO);
            species.push(name(&s.props));
        }
    }
    for spec in &scene.random_box {
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
            rng,
        ) {
            inits.push(p);
            displacements.push(DVec3::ZERO);
            species.push(name(&s.props));
        }
    }
    let mut fcc_box: Option<crate::boundary::Boundary> = None;
    for spec in &scene.fcc {
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
            rng,
        );
        // Every `[[fcc]]` sets the periodic box: two (a rock-salt pair,
        // half a cell apart) must agree on its sides, else one would be
        // dropped silently.
        if let Some(first) = fcc_box {
            let (a, b) = (first.lengths(), lat.1.lengths());
            if (a - b).abs().max_element() > 1e-9 * a.max_element() {
                return Err(err(
                    spec.span(),
                    format!(
                        "this [[fcc]] makes a box of {} × {} × {}, an earlier one {} × {} × {}: every [[fcc]] sets the periodic box, so they must agree (same cells and density)",
                        b.x, b.y, b.z, a.x, a.y, a.z
                    ),
                ));
            }
        }
        fcc_box = Some(lat.1);
        for p in lat.0 {
            inits.push(p);
            displacements.push(DVec3::ZERO);
            species.push(name(&s.props));
        }
    }
    for spec in &scene.cloud {
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
            rng,
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
            species.push(name(&s.props));
        }
    }
    for spec in &scene.plummer {
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
        for p in sphere.particles(&template, rng) {
            inits.push(p);
            displacements.push(DVec3::ZERO);
            species.push("X".to_string());
        }
    }
    let data_files = scene.lammps_data.iter().map(|s| (s, true));
    for (spec, data) in data_files.chain(scene.from_file.iter().map(|s| (s, false))) {
        let s = spec.get_ref();
        let path = std::path::Path::new(file)
            .parent()
            .unwrap_or(std::path::Path::new("."))
            .join(&s.file);
        let at = |m: String| err(spec.span(), m);
        let scales = match &s.units {
            None => None,
            Some(name) => Some(
                crate::units::FileUnits::named(name)
                    .ok_or_else(|| {
                        at(format!(
                            "units = \"{name}\": not one of si, cgs, real, metal, micro, nano, lj"
                        ))
                    })?
                    .into(scene.units)
                    .map_err(|m| at(format!("units = \"{name}\": {m}")))?,
            ),
        };
        let (mut made, mut names, mut file_box, bonds) = from_file(s, &path, data, scales, &at)?;
        if s.replicate.is_some() && !bonds.is_empty() {
            return Err(at(format!(
                "{}: replicate copies atoms, not their {} bonds (a bond across the box would join the wrong copies): replicate in LAMMPS and read its data file",
                path.display(),
                bonds.len()
            )));
        }
        let first = inits.len();
        springs.extend(bonds.into_iter().map(|b| Spring {
            i: first + b.i,
            j: first + b.j,
            ..b
        }));
        if let Some(copies) = s.replicate {
            let b = replicate(&mut made, &mut names, file_box, copies)
                .map_err(|m| at(format!("{}: {m}", path.display())))?;
            file_box = Some(b);
        }
        if fcc_box.is_none() {
            fcc_box = file_box;
        }
        for (p, n) in made.into_iter().zip(names) {
            inits.push(p);
            displacements.push(DVec3::ZERO);
            species.push(n);
        }
    }
    let n = inits.len();
    if n == 0 && scene.insert.is_empty() {
        return Err(src.whole("the scene makes no particles: add [[particle]] or a generator ([[lattice]], [[ring]], [[annulus]], [[random_box]], [[fcc]], [[cloud]], [[plummer]]), [[from_file]] or [[insert]]"));
    }
    for spec in &scene.spring {
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

    Ok(Made {
        particles,
        species,
        springs,
        fcc_box,
    })
}
