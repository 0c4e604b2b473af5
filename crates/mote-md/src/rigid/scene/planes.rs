//! The toning nip's electrostatics and magnetics as general tables:
//! `[rigid.planes]` (the box's faces z = lo.z and z = hi.z as conductors
//! at given potentials, the charges' forces summed with all their images),
//! `[rigid.latent_image]` (surface charge on a belt over the lower plane)
//! and `[rigid.roller]` (a multipole magnetic roller inside the upper
//! plane, inducing the carriers' moments).

use std::ops::Range;

use glam::DVec3;
use mote_io::ParseError;
use serde::Deserialize;

use super::{positive, Clumps, RigidBuild, RigidScene};
use crate::boundary::Boundary;
use crate::force::latent::{LatentImage, Patch};
use crate::force::slab::ConductingPlanes;
use crate::rigid::bodies::RigidBodies;
use crate::rigid::magnet::{InducedDipoles, MagneticRoller};
use crate::rigid::sources::{LatentField, PlaneCoulomb};
use crate::scene::electric::P3mKeys;
use crate::scene::Section;

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
    /// Moments farther apart do not see each other (absent: all pairs).
    pub cutoff: Option<f64>,
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
    /// The image repeats along x every this (default: the box's length,
    /// which it must divide).
    pub period: Option<f64>,
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
    /// The real-space cut-off (Ewald: default 3.5 spacings of the doubled
    /// cell's charges; P3M: tuned).
    #[serde(default)]
    pub r_cut: Option<f64>,
    /// How the doubled cell is summed: `"ewald"` (default) or `"p3m"`.
    #[serde(default)]
    pub method: Option<String>,
    /// P3M: mesh points along each axis of the doubled cell (default tuned).
    #[serde(default)]
    pub mesh: Option<[usize; 3]>,
    /// P3M: assignment order 1–7 (default tuned).
    #[serde(default)]
    pub order: Option<usize>,
    /// Sum the charges' forces at every n-th step, hold them in between.
    #[serde(default)]
    pub every: Option<u64>,
}

impl Section<Clumps> for PlaneSettings {
    fn add_to(
        &self,
        span: Range<usize>,
        scene: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let built =
            plane_coulomb(self, scene.box_faces(), &b.bodies).map_err(|m| b.error(span, m))?;
        b.planes = Some((built.planes.clone(), built.z0));
        b.frbi.push(Box::new(built));
        Ok(())
    }
}

impl Section<Clumps> for LatentSettings {
    /// The image's field, on the belt over the lower plane (which
    /// `[rigid.planes]` must have made).
    fn add_to(
        &self,
        span: Range<usize>,
        _: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let Some((planes, z0)) = &b.planes else {
            return Err(b.error(
                span,
                "[rigid.latent_image] needs [rigid.planes] (the belt is the lower plane)".into(),
            ));
        };
        let ls = self;
        let length = planes.lateral[0];
        let period = ls.period.unwrap_or(length);
        let copies = length / period;
        if !(period > 0.0
            && copies.round() >= 1.0
            && (copies - copies.round()).abs() < 1e-9 * copies)
        {
            return Err(b.error(
                span,
                format!("[rigid.latent_image] period {period} must divide the box's length along x ({length}) a whole number of times"),
            ));
        }
        let image = LatentImage {
            k: planes.k,
            gap: planes.gap,
            height: ls.height,
            period,
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
        let z0 = *z0;
        image.check().map_err(|m| b.error(span, m))?;
        b.frbi.push(Box::new(LatentField { image, z0 }));
        Ok(())
    }
}

impl Section<Clumps> for RollerSettings {
    fn add_to(
        &self,
        span: Range<usize>,
        scene: &RigidScene,
        b: &mut RigidBuild<'_>,
    ) -> Result<(), ParseError> {
        let model = induced_dipoles(self, scene.box_faces(), &b.names, &b.bodies)
            .map_err(|m| b.error(span, m))?;
        b.frbi.push(Box::new(model));
        Ok(())
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
    let period = [hi.x - lo.x, hi.y - lo.y];
    let cutoff = rs.cutoff.unwrap_or(f64::INFINITY);
    let half = 0.5 * period[0].min(period[1]);
    if rs.cutoff.is_some_and(|rc| !positive(rc) || rc > half) {
        return Err(format!(
            "[rigid.roller] cutoff must be > 0 and at most half the shorter period ({half}) for the minimum image"
        ));
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
        period,
        cutoff,
    })
}

/// `[rigid.planes]` on the faces of the scene's `[box]`.
fn plane_coulomb(
    ps: &PlaneSettings,
    scene_box: Option<(DVec3, DVec3, [bool; 3])>,
    bodies: &RigidBodies,
) -> Result<PlaneCoulomb, String> {
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
    let planes = match ps.method.as_deref().unwrap_or("ewald") {
        "ewald" => {
            if ps.mesh.is_some() || ps.order.is_some() {
                return Err("[rigid.planes] mesh and order are keys of method = \"p3m\"".into());
            }
            // About 3.5 spacings of the doubled cell's 2N charges: some 180
            // neighbours in reach, on linked cells.
            let spacing = (2.0 * size.element_product() / (2 * charge.len().max(1)) as f64).cbrt();
            let r_cut = ps.r_cut.unwrap_or((3.5 * spacing).min(largest));
            if !positive(r_cut) || r_cut > largest * (1.0 + 1e-12) {
                return Err(format!("[rigid.planes] r_cut must be > 0 and at most {largest} (half the smallest side of the box doubled along z)"));
            }
            ConductingPlanes::new(
                ps.coulomb,
                size.z,
                [size.x, size.y],
                ps.potential,
                &charge,
                r_cut,
                ps.accuracy,
            )
        }
        "p3m" => {
            let keys = P3mKeys {
                accuracy: Some(ps.accuracy),
                cutoff: ps.r_cut,
                skin: None,
                mesh: ps.mesh,
                order: ps.order,
            };
            let doubled = Boundary::periodic(
                DVec3::new(0.0, 0.0, -size.z),
                DVec3::new(size.x, size.y, size.z),
            );
            let request = keys.check("rigid.planes", "r_cut", 2 * charge.len(), doubled)?;
            ConductingPlanes::with_p3m(
                ps.coulomb,
                size.z,
                [size.x, size.y],
                ps.potential,
                &charge,
                &request,
            )
            .map_err(|e| format!("[rigid.planes] {e}"))?
        }
        other => {
            return Err(format!(
                "[rigid.planes] unknown method '{other}': expected ewald or p3m"
            ))
        }
    };
    if ps.every == Some(0) {
        return Err("[rigid.planes] every must be at least 1".into());
    }
    Ok(PlaneCoulomb::new(planes, lo.z, ps.every.unwrap_or(1)))
}
