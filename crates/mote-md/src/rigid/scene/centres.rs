//! The point particles' laws between the bodies' centres: a table of
//! [`SceneFile::centre_laws`](crate::scene::SceneFile::centre_laws) (`[gravity]`, `[dipolar]`, `[coulomb]`) is built by its own
//! point-particle section, on the bodies as point particles — each body's
//! centre of mass with its mass, charge, dipole and velocity — and each
//! interaction it makes acts between the centres ([`AtCentres`]). A law
//! listed there needs nothing here: one table, one check, one kernel for
//! points and clumps.

use std::ops::Range;

use mote_io::ParseError;

use super::{RigidBuild, RigidScene};
use crate::boundary::Boundary;
use crate::force::ForceField;
use crate::particles::{ParticleInit, Particles};
use crate::rigid::centres::AtCentres;
use crate::scene::{Build, Scene, Section};
use crate::units::UnitSystem;

/// Adds the interactions the point-particle table `law` (at `span`) makes
/// for the bodies built so far, each between their centres.
pub(super) fn add_law(
    law: &dyn Section,
    span: Range<usize>,
    b: &mut RigidBuild<'_>,
) -> Result<(), ParseError> {
    let bodies = &b.bodies;
    let mut particles = Particles::default();
    for i in 0..bodies.len() {
        let template = bodies.template(i);
        particles.push(ParticleInit {
            position: bodies.position[i],
            velocity: bodies.velocity[i],
            mass: template.mass(),
            charge: template.charge,
            radius: template.props.bounding_radius,
            dipole: bodies.dipole(i),
            ..ParticleInit::default()
        });
    }
    let mut centres = Build {
        src: b.src,
        units: UnitSystem::Si,
        rng: b.rng.clone(),
        particles,
        boundary: b.scene_box.as_ref().map_or(Boundary::open(), |(bx, _)| *bx),
        forces: ForceField::new(),
        centres_of_bodies: true,
    };
    // A law between centres reads no other point-particle table.
    law.add_to(span, &Scene::default(), &mut centres)?;
    b.rng = centres.rng;
    for inner in centres.forces.interactions {
        b.frbi.push(Box::new(AtCentres::new(inner)));
    }
    Ok(())
}

/// Refuses `[coulomb]` between conducting planes, whose own sum
/// (`[rigid.planes] coulomb`) takes the charges' images. (`[rigid.fields]
/// coulomb`, the other rigid sum, is refused by its table.)
pub(super) fn refuse_coulomb_between_planes(
    scene: &RigidScene,
    b: &RigidBuild<'_>,
) -> Result<(), ParseError> {
    match &scene.coulomb {
        Some(coulomb) if scene.settings().planes.is_some() => Err(b.error(
            coulomb.span(),
            "[coulomb] between conducting planes is [rigid.planes] coulomb (with the planes' images)".into(),
        )),
        _ => Ok(()),
    }
}
