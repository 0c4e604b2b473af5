//! `[[rigid.template]]`: the shapes bodies are made of — spheres listed,
//! or made by a generator (a sphere, a dumbbell, a linear trimer, an
//! irregular clump) — with their density or mass, charge and dipole.

use std::ops::Range;

use glam::DVec3;
use mote_io::ParseError;
use serde::Deserialize;

use super::{Clumps, RigidBuild, RigidScene};
use crate::force::granular::Material;
use crate::rigid::shapes::{dumbbell, linear_trimer, IrregularClump};
use crate::rigid::template::{BodyTemplate, ClumpSpec, Integration};
use crate::scene::Section;

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

impl Section<Clumps> for TemplateSpec {
    /// Adds the template under its name (the body kind is its place in
    /// the list); an irregular shape without a seed of its own takes the
    /// scene's seed plus its place.
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let ts = self;
        if b.names.iter().any(|(n, _)| *n == ts.name) {
            return Err(b.error(span, format!("template '{}' is defined twice", ts.name)));
        }
        let k = b.names.len();
        let spec = template_spec(ts, b.seed.wrapping_add(k as u64), b.material)
            .map_err(|m| b.error(span.clone(), m))?;
        let tpl = BodyTemplate::new(&spec, Integration::default())
            .map_err(|e| b.error(span.clone(), format!("template '{}': {e}", ts.name)))?;
        let tpl = match ts.mass {
            Some(m) => {
                // Scale the density to give the asked mass.
                let mut spec = spec;
                spec.density *= m / tpl.mass();
                BodyTemplate::new(&spec, Integration::default())
                    .map_err(|e| b.error(span.clone(), format!("template '{}': {e}", ts.name)))?
            }
            None => tpl,
        };
        let kind = b.bodies.add_template(tpl);
        b.names.push((ts.name.clone(), kind));
        Ok(())
    }
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
            if g.lobes >= crate::rigid::template::MAX_TEMPLATE_SPHERES {
                return Err(format!(
                    "lobes = {}: a template holds at most {} spheres",
                    g.lobes,
                    crate::rigid::template::MAX_TEMPLATE_SPHERES
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
