//! `[rigid.fields]`: gravity, external electric and magnetic fields
//! (constant or rotating) and air drag. (Coulomb and dipole–dipole forces
//! between the bodies are the point particles' `[coulomb]` and `[dipolar]`,
//! between the centres: centres.rs.)

use std::ops::Range;

use glam::DVec3;
use mote_io::ParseError;
use serde::Deserialize;

use super::{Clumps, RigidBuild, RigidScene};
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
    /// The first spelling of `[coulomb]` between the bodies, refused with
    /// it.
    #[serde(default)]
    pub coulomb: Option<f64>,
    /// The first spelling of `[dipolar]` between the bodies, refused with
    /// it.
    #[serde(default)]
    pub dipole_dipole: Option<f64>,
    #[serde(default)]
    pub drag: Option<DragSpec>,
}

impl Section<Clumps> for FieldSettings {
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let fs = self;
        // The laws between the bodies' centres are the point particles'
        // tables (their first spelling was here).
        if fs.coulomb.is_some() {
            return Err(b.error(
                span,
                "[rigid.fields] coulomb: Coulomb's law between the bodies is the point particles' table, [coulomb] k = ... (method direct, tree or ewald)".into(),
            ));
        }
        if fs.dipole_dipole.is_some() {
            return Err(b.error(
                span,
                "[rigid.fields] dipole_dipole: the dipoles' law between the bodies is the point particles' table, [dipolar] mu0 = 4π k (all pairs, cutoff or method = \"ewald\")".into(),
            ));
        }
        if let Some(g) = fs.gravity {
            b.frbi.push(Box::new(Gravity { g: DVec3::from(g) }));
        }
        if fs.electric.is_some() || fs.magnetic.is_some() {
            let electric = field(&fs.electric).map_err(|m| b.error(span.clone(), m))?;
            let magnetic = field(&fs.magnetic).map_err(|m| b.error(span.clone(), m))?;
            b.frbi.push(Box::new(ExternalFields { electric, magnetic }));
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
