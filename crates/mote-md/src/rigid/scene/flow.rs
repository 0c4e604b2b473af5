//! `[[insert]]` and `[[outlet]]` in a rigid scene: clumps of a template
//! brought into a region at a rate, and bodies taken out where their
//! centres reach an outlet ([`crate::rigid::flow`]). The tables are the
//! point particles' (`crate::scene::flow`), with `clump` naming the
//! template in place of the spheres' size, density and charge.

use mote_io::ParseError;

use super::{RigidBuild, RigidScene};
use crate::boundary::Boundary;
use crate::rigid::flow::{BodyFlow, ClumpInserter};
use crate::rigid::RigidContacts;
use crate::scene::flow::{interval, outlets, stream};

/// The run's flow of bodies from its `[[insert]]` and `[[outlet]]`
/// tables, or `None` without them; the bodies get their ids.
pub(super) fn body_flow(
    scene: &RigidScene,
    b: &mut RigidBuild,
) -> Result<Option<BodyFlow>, ParseError> {
    if scene.insert.is_empty() && scene.outlet.is_empty() {
        return Ok(None);
    }
    let src = b.src;
    let every = interval(scene, src)?;
    let mut inserters = Vec::new();
    for (k, spec) in scene.insert.iter().enumerate() {
        let (s, span) = (spec.get_ref(), spec.span());
        let stream = stream(s, k, span.clone(), src)?;
        let bad = |why: &str| src.error(span.clone(), format!("[[insert]] {}: {why}", stream.name));
        let given = [
            ("radius", s.radius.is_some()),
            ("sizes", s.sizes.is_some()),
            ("density", s.density.is_some()),
            ("charge", s.charge.is_some()),
            ("color", s.color.is_some()),
            ("species", s.species.is_some()),
        ];
        if let Some((key, _)) = given.iter().find(|g| g.1) {
            return Err(bad(&format!(
                "{key}: a clump's size, density and charge are its template's (clump = \"...\")"
            )));
        }
        let Some(name) = &s.clump else {
            return Err(bad(
                "give the template the stream makes: clump = \"(a [[rigid.template]] name)\"",
            ));
        };
        let kind = b.kind_of(name, span.clone())?;
        inserters.push(ClumpInserter {
            stream,
            template: b.bodies.templates[kind as usize].clone(),
            kind,
            species: name.clone(),
        });
    }
    let outlets = outlets(scene, src)?;
    let walls = (b.frbi.find::<RigidContacts>())
        .map(|c| c.walls.clone())
        .unwrap_or_default();
    let boundary = (b.scene_box.as_ref()).map_or_else(Boundary::open, |(bx, _)| *bx);
    Ok(Some(BodyFlow::new(
        &mut b.bodies,
        inserters,
        outlets,
        every,
        walls,
        boundary,
    )))
}
