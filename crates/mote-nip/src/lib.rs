//! The toning nip of an electrophotographic printer (seed 000): toner and
//! carrier beads between a magnetic roller's shell and a photoconductor
//! belt carrying a latent image. An application above mote's engines: the
//! physics (rigid clumps, Hertz contacts, charges between conducting planes,
//! the roller's field, the latent image) is the rigid-body engine's
//! (`mote_md::rigid`); this crate adds what a printer engineer reads off
//! the nip — developed toner on image and background, the brush, the free
//! volume ([`probe`]) — from its own table of a rigid scene:
//!
//! ```toml
//! [rigid.nip]
//! toner = "toner"        # the templates that are toner and carrier
//! carrier = "carrier"
//! every = 50             # steps between rows of nip.csv (default: [output] observables_every)
//! window = [5e-4, 6e-4]  # measure toner and free volume only there (default: the whole box)
//! ```
//!
//! The front (`mote run`) asks [`probe`] for the probe of a rigid scene and
//! adds its observer, [`NipCsv`], to the run.

#![allow(clippy::needless_range_loop)] // index loops over parallel arrays, as in mote-md

pub mod probe;

pub use probe::{NipCsv, NipProbe, NipSample};

use mote_io::{ParseError, Source};
use mote_md::rigid::scene::RigidScene;
use serde::Deserialize;
use toml::Spanned;

/// `[rigid.nip]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NipSettings {
    /// The template of the toner particles.
    pub toner: String,
    /// The template of the carrier beads.
    pub carrier: String,
    /// Steps between rows of nip.csv (default: `[output] observables_every`).
    #[serde(default)]
    pub every: Option<u64>,
    /// Measure the developed toner and the free volume only where
    /// x₀ ≤ x < x₁ (a flowing nip's exit); default the whole box.
    #[serde(default)]
    pub window: Option<[f64; 2]>,
}

/// The one table of a scene this crate reads; every other key is the
/// engine's, which checks it.
#[derive(Deserialize)]
struct Tables {
    rigid: Option<RigidTables>,
}

#[derive(Deserialize)]
struct RigidTables {
    nip: Option<Spanned<NipSettings>>,
}

/// The probe `[rigid.nip]` of a rigid scene asks for, with its interval in
/// steps; `None` when the scene has no such table. `text` is the scene
/// (parsed as `scene`), `file` names it in errors (`file:line: message`).
pub fn probe(
    scene: &RigidScene,
    text: &str,
    file: &str,
) -> Result<Option<(NipProbe, u64)>, ParseError> {
    let src = Source::new(file, text);
    let tables: Tables =
        toml::from_str(text).map_err(|e| src.parser_error(e.span(), e.message()))?;
    let Some(table) = tables.rigid.and_then(|r| r.nip) else {
        return Ok(None);
    };
    let (span, nip) = (table.span(), table.get_ref());
    let kind = |name: &str| {
        scene.template_kind(name).ok_or_else(|| {
            src.error(
                span.clone(),
                format!("[rigid.nip] names unknown template '{name}'"),
            )
        })
    };
    let Some((lo, hi, _)) = scene.box_faces() else {
        return Err(src.error(
            span.clone(),
            "[rigid.nip] needs the scene's [box] (the shell and the belt are its faces)",
        ));
    };
    let latent = scene.settings().latent_image.as_ref().map(|l| l.get_ref());
    let contrast = latent
        .map(|l| l.patches.first().map_or(0.0, |p| p[2] - l.background))
        .unwrap_or(0.0);
    let probe = NipProbe {
        toner: kind(&nip.toner)?,
        carrier: kind(&nip.carrier)?,
        belt: lo.z + latent.map_or(0.0, |l| l.height),
        shell: hi.z,
        lo,
        hi,
        patches: latent
            .map(|l| l.patches.iter().map(|p| [p[0], p[1]]).collect())
            .unwrap_or_default(),
        speed: latent.map_or(0.0, |l| l.speed),
        contrast,
        window: nip.window,
    };
    if let Some([x0, x1]) = nip.window {
        if !(lo.x <= x0 && x0 < x1 && x1 <= hi.x) {
            return Err(src.error(
                span,
                format!("[rigid.nip] window = [{x0}, {x1}]: give lo.x ≤ x₀ < x₁ ≤ hi.x of the box"),
            ));
        }
    }
    let every = match nip.every {
        Some(0) => {
            return Err(src.error(
                span,
                "[rigid.nip] every = 0: give at least 1 step (without [rigid.nip] no nip.csv is written)",
            ))
        }
        Some(n) => n,
        None => scene.output.observables_every().max(1),
    };
    Ok(Some((probe, every)))
}
