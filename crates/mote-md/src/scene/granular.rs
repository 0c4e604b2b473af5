//! `[granular]`: Hertz–Mindlin contacts with friction, rolling friction and
//! adhesion between spheres; `[[wall]]`: planes, boxes and cylinders the
//! spheres touch with the same law.

use std::ops::Range;

use glam::DVec3;
use serde::Deserialize;

use mote_io::{ParseError, Source};

use super::{Build, Scene, Section};
use crate::force::granular::{
    ContactLaw, Damping, GranularContacts, GranularWalls, Material, Wall,
};
use crate::integrate::Integrator;

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
    /// How the particles are stored: `space` (default) sorts them along a
    /// Morton curve once the scene is built, so that contact partners are
    /// near in memory ([`crate::order`]); `file` keeps the scene's order.
    /// Files, probes and messages use the scene's numbering either way.
    #[serde(default)]
    pub order: ParticleOrder,
}

pub use crate::order::ParticleOrder;

pub(crate) fn exact() -> String {
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
    /// The distance the wall translates before it stops (default: it
    /// never stops).
    pub travel: Option<f64>,
}

impl Section for GranularSettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let src = b.src;
        let err = |span: Range<usize>, msg: String| src.error(span, msg);
        let v = self;
        let radius = &b.particles.radius;
        let bad = |msg: &str| Err(err(span.clone(), msg.to_string()));
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
            return bad("[granular] friction, rolling_friction and adhesion must not be negative");
        }
        if radius.iter().any(|r| *r <= 0.0) {
            return bad("[granular] needs every particle to have a radius > 0");
        }
        let integrator = super::run::integrator_setting(&scene.run);
        if Integrator::from_name(&integrator.value) != Some(Integrator::LeapFrog) {
            return Err(integrator.error(
                src,
                "[granular] contacts turn the spheres: use integrator = \"leapfrog\"",
            ));
        }
        let damping = match v.damping.as_str() {
            "exact" => Damping::Exact,
            "tsuji" => Damping::TsujiFit,
            other => {
                return Err(err(
                    span.clone(),
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
        // The spheres `[[insert]]` brings in count among them.
        let (r_lo, r_hi) = super::flow::radius_range(scene).unwrap_or((f64::INFINITY, 0.0));
        let d_min = radius.iter().cloned().fold(r_lo, f64::min) * 2.0;
        let r_max = radius.iter().cloned().fold(r_hi, f64::max);
        let n = radius.len();
        let skin = v.skin.unwrap_or(0.25 * d_min);
        if skin.is_nan() || skin <= 0.0 {
            return bad("[granular] skin must be positive");
        }
        b.forces.push(GranularContacts::new(law, r_max, skin));
        if !scene.wall.is_empty() {
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
            for (k, w) in scene.wall.iter().enumerate() {
                walls.extend(w.get_ref().walls(k).map_err(|m| err(w.span(), m))?);
            }
            b.forces.push(GranularWalls::new(wall_law, walls, n));
        }
        Ok(())
    }
}

/// `[[wall]]`s act through the contact law of `[granular]`: without it they
/// are refused.
pub fn refuse_walls_without_contacts(scene: &Scene, src: Source) -> Result<(), ParseError> {
    match (&scene.granular, scene.wall.first()) {
        (None, Some(w)) => Err(src.error(
            w.span(),
            "[[wall]] needs a [granular] section for its contact law",
        )),
        _ => Ok(()),
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
        let velocity = DVec3::from(w.velocity);
        let stop = match w.travel {
            None => f64::INFINITY,
            Some(d) if d > 0.0 && velocity != DVec3::ZERO => d / velocity.length(),
            Some(_) => return Err("travel: a positive distance, for a wall with a velocity".into()),
        };
        for wall in &mut walls {
            wall.velocity = velocity;
            wall.stop = stop;
            wall.angular_speed = w.angular_speed;
        }
        Ok(walls)
    }
}
