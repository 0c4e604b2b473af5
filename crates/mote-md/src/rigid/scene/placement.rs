//! Where bodies start: `[[rigid.body]]` one by one, `[[from_file]]` from a
//! frame of their spheres, `[[rigid.lattice]]` on a simple cubic or fcc
//! lattice and `[[rigid.random]]` at random without overlaps — each with
//! its velocities and orientations, drawn in table order.

use std::ops::Range;

use glam::DVec3;
use mote_geom::{from_axis_angle, DE, E};
use mote_io::ParseError;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;

use super::sites::random_sites;
use super::{positive, Clumps, RigidBuild, RigidScene};
use crate::boundary::Boundary;
use crate::scene::{DataSpec, Section};

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

impl Section<Clumps> for BodySpec {
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let bs = self;
        let k = b.kind_of(&bs.template, span.clone())?;
        let r = match (bs.rotation, bs.axis, bs.angle) {
            (Some(r), None, None) => DVec3::from(r),
            (None, Some(a), Some(deg)) => {
                let a = DVec3::from(a);
                if a.length() == 0.0 {
                    return Err(b.error(span, "the rotation axis must not be zero".into()));
                }
                from_axis_angle(a.normalize(), deg.to_radians())
            }
            (None, None, None) => DVec3::ZERO,
            _ => {
                return Err(b.error(
                    span,
                    "give either `rotation` or both `axis` and `angle`".into(),
                ))
            }
        };
        b.bodies.push(
            k,
            E::new(r, DVec3::from(bs.position)),
            DE::new(DVec3::from(bs.omega), DVec3::from(bs.velocity)),
        );
        Ok(())
    }
}

/// `[[from_file]]` of a rigid scene, the table every time-stepped engine
/// starts from a file with: the bodies of a trajectory frame (`.xyz`,
/// `.dump`, `.gsd`, `.vtp`/`.vtu`/`.pvd`; path relative to the scene file;
/// the last frame unless `frame` says which, negative counting from the
/// end), as a rigid run writes them: one row per sphere with its radius and
/// body id (a LAMMPS dump's `mol`), and where present the orientation
/// quaternion and angular velocity. Each body is matched to a template by
/// its spheres (see [`crate::rigid::from_file`]); `templates` and `tolerance` are
/// this engine's keys, the point particles' (masses, radii, units, box)
/// are refused: a body's are its template's.
impl Section<Clumps> for DataSpec {
    /// The bodies of the frame, each matched to one of the templates
    /// named (all, by default) by its spheres.
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let fs = self;
        let at = |m: String| b.error(span.clone(), m);
        let points = [
            "periodic",
            "replicate",
            "atom_style",
            "units",
            "radius",
            "mass",
            "density",
            "species",
            "color",
        ];
        if let [key, ..] = fs.given(&points)[..] {
            return Err(at(format!(
                "[[from_file]] {key}: a key of point particles; a body's spheres, mass and charge are its template's (this table takes file, frame, templates, tolerance)"
            )));
        }
        let candidates: Vec<(String, u32)> = match &fs.templates {
            None => b.names.clone(),
            Some(list) => list
                .iter()
                .map(|n| Ok((n.clone(), b.kind_of(n, span.clone())?)))
                .collect::<Result<_, ParseError>>()?,
        };
        let tolerance = fs.tolerance.unwrap_or(1e-6);
        if !positive(tolerance) {
            return Err(at("tolerance must be positive".into()));
        }
        let path = std::path::Path::new(b.src.file)
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
            .map(|(n, k)| (n.clone(), b.bodies.templates[*k as usize].clone()))
            .collect();
        let placed = crate::rigid::from_file::place_bodies(frame, &templates, tolerance)
            .map_err(|m| at(format!("{}: {m}", path.display())))?;
        for p in placed {
            b.bodies
                .push(candidates[p.template].1, p.placement, p.velocity);
        }
        Ok(())
    }
}

/// The keys of `[[rigid.lattice]]` and `[[rigid.random]]`.
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

/// `[[rigid.lattice]]`: n bodies on lattice sites in [lo, hi].
#[derive(Debug, Deserialize)]
#[serde(transparent)]
pub struct Lattice(pub PlacementSpec);

/// `[[rigid.random]]`: n bodies at random in [lo, hi], their bounding
/// spheres not overlapping (each other, or the bodies placed before).
#[derive(Debug, Deserialize)]
#[serde(transparent)]
pub struct Random(pub PlacementSpec);

impl Section<Clumps> for Lattice {
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        self.0.place(false, span, b)
    }
}

impl Section<Clumps> for Random {
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        self.0.place(true, span, b)
    }
}

impl PlacementSpec {
    /// Places the n bodies, at random sites or on the lattice, with their
    /// orientations and velocities (random draws in that order).
    fn place(
        &self,
        random: bool,
        span: Range<usize>,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let ps = self;
        let k = b.kind_of(&ps.template, span.clone())?;
        let bound = b.bodies.templates[k as usize].props.bounding_radius;
        // Placement, velocities and kind of each body (100 B) and the
        // world-frame centre, radius and owner of each sphere (40 B):
        // refused before anything is allocated when it cannot fit.
        let spheres = b.bodies.templates[k as usize].sphere_count() as f64;
        mote_io::system::check_fits(
            &format!("{} bodies of {} spheres", ps.n, spheres),
            ps.n as f64 * (100.0 + 40.0 * spheres),
        )
        .map_err(|m| b.error(span.clone(), m))?;
        let (lo, hi) = (DVec3::from(ps.lo), DVec3::from(ps.hi));
        if (0..3).any(|d| hi[d] < lo[d]) {
            return Err(b.error(span, "lo must not exceed hi".into()));
        }
        // (a region of 1.8e308 made the uniform draw overflow and panic)
        if (0..3).any(|d| !(2.0 * (hi[d] - lo[d])).is_finite()) {
            return Err(b.error(
                span,
                format!(
                    "the region [lo, hi] = [{lo}, {hi}] is wider than a placement can draw from"
                ),
            ));
        }
        let sites = if random {
            let boundary = b.scene_box.as_ref().map(|(bx, _)| *bx);
            let boundary = boundary.unwrap_or_else(Boundary::open);
            random_sites(ps.n, lo, hi, bound, &b.bodies, &boundary, &mut b.rng)
        } else {
            let spacing = ps.spacing.unwrap_or(2.0 * bound);
            match ps.arrangement.as_deref() {
                None | Some("cubic") => lattice_sites(ps.n, lo, hi, spacing),
                Some("fcc") => fcc_sites(ps.n, lo, hi, spacing),
                Some(o) => Err(format!("unknown arrangement '{o}': expected cubic or fcc")),
            }
        }
        .map_err(|m| b.error(span.clone(), m))?;
        for x in sites {
            let r = if ps.random_orientation {
                random_rotation(&mut b.rng)
            } else {
                DVec3::ZERO
            };
            let v = DVec3::from(ps.velocity) + ps.speed * random_unit(&mut b.rng);
            b.bodies.push(k, E::new(r, x), DE::new(DVec3::ZERO, v));
        }
        Ok(())
    }
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
