//! `[rigid.fields]`: gravity, external electric and magnetic fields
//! (constant or rotating), Coulomb and dipole–dipole forces between the
//! bodies, and air drag.

use std::ops::Range;

use glam::DVec3;
use mote_io::ParseError;
use serde::Deserialize;

use super::{Clumps, RigidBuild, RigidScene};
use crate::rigid::centres::{Coulomb, DipoleDipole};
use crate::rigid::sources::{AirDrag, ExternalFields, Field, Gravity};
use crate::scene::Section;

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

impl Section<Clumps> for FieldSettings {
    fn add_to(
        &self,
        span: Range<usize>,
        scene: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let fs = self;
        // With conducting planes, [rigid.planes] says what to do with the
        // charges (its table is the one to keep).
        let planes = scene.settings().planes.is_some();
        if let Some(g) = fs.gravity {
            b.frbi.push(Box::new(Gravity { g: DVec3::from(g) }));
        }
        if fs.electric.is_some() || fs.magnetic.is_some() {
            let electric = field(&fs.electric).map_err(|m| b.error(span.clone(), m))?;
            let magnetic = field(&fs.magnetic).map_err(|m| b.error(span.clone(), m))?;
            b.frbi.push(Box::new(ExternalFields { electric, magnetic }));
        }
        let periodic = b
            .scene_box
            .as_ref()
            .is_some_and(|(bx, _)| bx.periodic.iter().any(|p| *p));
        if let Some(k) = fs.coulomb {
            if periodic && !planes {
                return Err(b.error(
                    span,
                    "[rigid.fields] coulomb sums over open space, and the [box] is periodic: give [coulomb] method = \"ewald\" (a box periodic on every axis) or [rigid.planes] coulomb (periodic along the planes)".into(),
                ));
            }
            b.frbi.push(Box::new(Coulomb::coulomb(k)));
        }
        if let Some(k) = fs.dipole_dipole {
            if periodic {
                return Err(b.error(
                    span,
                    "[rigid.fields] dipole_dipole sums over open space, and the [box] is periodic: the images would be missed (the roller's induced moments, [rigid.roller] dipole_dipole, take the minimum image)".into(),
                ));
            }
            b.frbi.push(Box::new(DipoleDipole::dipoles(k)));
        }
        if let Some(d) = &fs.drag {
            b.frbi.push(Box::new(AirDrag {
                viscosity: d.viscosity,
                air_density: d.air_density,
                drag_coefficient: d.drag_coefficient,
                wind: DVec3::from(d.wind),
            }));
        }
        Ok(())
    }
}

/// The field a key gives (zero where it is absent).
fn field(s: &Option<FieldSpec>) -> Result<Field, String> {
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
                return Err(
                    "a rotating field needs a non-zero axis and a start direction not along it"
                        .into(),
                );
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
}
