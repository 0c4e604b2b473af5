//! `[rigid.contacts]` and `[[rigid.wall]]`: Hertz–Mindlin contacts
//! between the spheres of different bodies and with the walls, searched
//! across the periodic faces of `[box]`.

use std::ops::Range;

use mote_io::ParseError;
use serde::Deserialize;
use toml::Spanned;

use super::{positive, Clumps, RigidBuild, RigidScene};
use crate::force::granular::{ContactLaw, Damping, Material};
use crate::rigid::contacts::RigidContacts;
use crate::scene::Section;

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
    pub(super) periodic: Option<Spanned<toml::Value>>,
    #[serde(default)]
    pub(super) box_lo: Option<Spanned<toml::Value>>,
    #[serde(default)]
    pub(super) box_hi: Option<Spanned<toml::Value>>,
}

fn default_poisson() -> f64 {
    0.3
}

impl Section<Clumps> for ContactSettings {
    /// The contact model with the scene's walls (`[[rigid.wall]]`).
    fn add_to(
        &self,
        span: Range<usize>,
        scene: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let cs = self;
        let mut walls = Vec::new();
        for (k, w) in scene.settings().wall.iter().enumerate() {
            walls.extend(w.get_ref().walls(k).map_err(|m| b.error(w.span(), m))?);
        }
        if !positive(cs.young) || !(0.0..0.5).contains(&cs.poisson) {
            return Err(b.error(
                span,
                "contacts need young > 0 and 0 <= poisson < 0.5".into(),
            ));
        }
        if !(0.0..=1.0).contains(&cs.restitution) || cs.friction < 0.0 {
            return Err(b.error(
                span,
                "contacts need 0 <= restitution <= 1 and friction >= 0".into(),
            ));
        }
        let m = Material {
            young: cs.young,
            poisson: cs.poisson,
        };
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
        let r_max = b
            .bodies
            .templates
            .iter()
            .flat_map(|t| t.radii.iter().cloned())
            .fold(0.0, f64::max);
        let skin = cs.skin.unwrap_or(0.4 * r_max);
        let mut model = RigidContacts::new(law, law, walls, skin);
        if let Some((bx, box_span)) = b.scene_box.as_ref().filter(|(bx, _)| bx.is_periodic()) {
            for d in 0..3 {
                if bx.periodic[d] && (bx.hi[d] - bx.lo[d]) < 3.0 * (2.0 * r_max + skin) {
                    return Err(b.error(box_span.clone(), "a periodic axis of [box] must be at least three sphere diameters plus skins long".into()));
                }
            }
            model = model.with_boundary(*bx);
        }
        b.frbi.push(Box::new(model));
        Ok(())
    }
}
