//! The point particles' tables a rigid scene does not take, refused at
//! their line with what a rigid scene says instead (the laws between
//! centres, [`SceneFile::centre_laws`](crate::scene::SceneFile::centre_laws), are
//! taken; see centres.rs).

use std::ops::Range;

use mote_io::{ParseError, Source};
use toml::Spanned;

use super::RigidScene;
use crate::units::UnitSystem;

/// Where bodies come from, for the tables that make point particles.
const PLACED: &str =
    "bodies are placed by [[rigid.body]], [[rigid.lattice]], [[rigid.random]] or [[from_file]]";

/// The span of an optional table.
fn table<T>(t: &Option<Spanned<T>>) -> Option<Range<usize>> {
    t.as_ref().map(Spanned::span)
}

/// The span of the first of a list of tables.
fn first<T>(list: &[Spanned<T>]) -> Option<Range<usize>> {
    list.first().map(Spanned::span)
}

/// Refuses the first point-particle table of `scene` that a rigid scene
/// does not take, and units other than SI (the rigid engine's).
pub(super) fn refuse(scene: &RigidScene, src: Source) -> Result<(), ParseError> {
    if scene.units != UnitSystem::Si {
        return Err(ParseError::new(
            src.file,
            src.key_line("units"),
            "units: rigid bodies are in SI units (leave out units)",
        ));
    }
    let refused = [
        (
            table(&scene.field),
            "[field]",
            "a uniform field on rigid bodies is [rigid.fields] gravity = [gx, gy, gz]",
        ),
        (
            table(&scene.damping),
            "[damping]",
            "air drag on rigid bodies is [rigid.fields] drag",
        ),
        (
            table(&scene.lennard_jones),
            "[lennard_jones]",
            "rigid bodies touch through [rigid.contacts]",
        ),
        (
            table(&scene.thermostat),
            "[thermostat]",
            "rigid bodies have no thermostat",
        ),
        (
            table(&scene.parallel),
            "[parallel]",
            "rigid bodies do not run on several ranks yet (docs/parallel.md)",
        ),
        (
            table(&scene.brownian),
            "[brownian]",
            "rigid bodies have no Brownian dynamics",
        ),
        (
            table(&scene.granular),
            "[granular]",
            "contacts between rigid bodies are [rigid.contacts]",
        ),
        (
            table(&scene.magnetic_field),
            "[magnetic_field]",
            "a field on rigid bodies is [rigid.fields] magnetic",
        ),
        (
            table(&scene.electric_field),
            "[electric_field]",
            "a field on rigid bodies is [rigid.fields] electric",
        ),
        (
            first(&scene.wall),
            "[[wall]]",
            "walls of rigid bodies are [[rigid.wall]]",
        ),
        (
            first(&scene.spring),
            "[[spring]]",
            "springs join point particles",
        ),
        (first(&scene.particle), "[[particle]]", PLACED),
        (first(&scene.lattice), "[[lattice]]", PLACED),
        (first(&scene.ring), "[[ring]]", PLACED),
        (first(&scene.annulus), "[[annulus]]", PLACED),
        (first(&scene.random_box), "[[random_box]]", PLACED),
        (first(&scene.fcc), "[[fcc]]", PLACED),
        (first(&scene.cloud), "[[cloud]]", PLACED),
        (first(&scene.plummer), "[[plummer]]", PLACED),
        (first(&scene.lammps_data), "[[lammps_data]]", PLACED),
    ];
    let mut given: Vec<_> = refused
        .into_iter()
        .filter_map(|(span, name, why)| span.map(|s| (s, name, why)))
        .collect();
    given.sort_by_key(|(span, _, _)| span.start);
    match given.first() {
        Some((span, name, why)) => Err(src.error(
            span.clone(),
            format!("{name} is a point particles' table, and this is a rigid scene: {why}"),
        )),
        None => Ok(()),
    }
}
