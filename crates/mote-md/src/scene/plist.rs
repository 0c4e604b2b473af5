//! MPPphys particle files (002 §2) as scenes: the same particles, forces
//! and step, so both inputs run identical physics.

use toml::Spanned;

use mote_io::plist::ParticleFile;
use mote_io::ParseError;

use super::gravity::direct;
use super::{
    DampingSettings, FieldSettings, GravitySettings, ParticleSpec, Properties, Scene, SpringSpec,
};
use crate::units::UnitSystem;

/// Which MPPphys model a particle file is run with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlistSystem {
    /// DirectNbody: softened gravity with k² (002 §2.2).
    Nbody,
    /// MassSpring: the file's springs (002 §2.3).
    Springs,
}

impl Scene {
    /// The scene twin of an MPPphys particle file: the same particles, forces
    /// and step, so both inputs run identical physics.
    /// `file` names the particle file in errors.
    pub fn from_plist(
        pf: &ParticleFile,
        system: PlistSystem,
        solver: &str,
        file: &str,
    ) -> Result<Scene, ParseError> {
        let mut scene = Scene {
            title: "MPPphys particle file".into(),
            units: UnitSystem::Astro,
            ..Scene::default()
        };
        scene.run.integrator = Some(super::Setting::plain(solver.to_string()));
        scene.run.dt = pf.dt.map(super::Setting::plain);
        for p in &pf.particles {
            scene.particle.push(Spanned::new(
                0..0,
                ParticleSpec {
                    position: p.position,
                    velocity: p.velocity,
                    displacement: p.displacement,
                    props: Properties {
                        mass: p.mass,
                        charge: p.charge,
                        radius: p.radius,
                        density: None,
                        dipole: [0.0; 3],
                        color: p.color,
                        free: p.free,
                        species: None,
                    },
                },
            ));
        }
        match system {
            PlistSystem::Nbody => {
                scene.gravity = Some(Spanned::new(
                    0..0,
                    GravitySettings {
                        g: Some(pf.k2.unwrap_or(UnitSystem::Astro.gravitational_constant())),
                        softening: pf.softening.unwrap_or(0.0),
                        method: direct(),
                        theta: None,
                    },
                ));
            }
            PlistSystem::Springs => {
                for link in &pf.springs {
                    let kind = pf
                        .spring_types
                        .iter()
                        .find(|s| s.id == link.kind)
                        .ok_or_else(|| {
                            ParseError::new(
                                file,
                                0,
                                format!("spring type {} is not defined", link.kind),
                            )
                        })?;
                    scene.spring.push(Spanned::new(
                        0..0,
                        SpringSpec {
                            pairs: vec![[link.i, link.j]],
                            stiffness: kind.stiffness,
                            damping: kind.damping,
                            rest_length: link.rest_length,
                        },
                    ));
                }
            }
        }
        scene.field = pf.gravity.map(|g| Spanned::new(0..0, FieldSettings { g }));
        scene.damping = pf
            .damping
            .map(|gamma| Spanned::new(0..0, DampingSettings { gamma }));
        Ok(scene)
    }
}
