//! `[[insert]]` and `[[outlet]]`: spheres brought into a region at a rate,
//! and taken out where they reach an outlet ([`crate::flow`]).

use std::ops::Range;

use glam::DVec3;
use mote_io::{ParseError, Source};
use mote_rcp::SizeSpec;
use serde::Deserialize;

use super::{Scene, SceneFile};
use crate::flow::{Exit, Flow, Inserter, Outlet, Rate, Region, Stream};
use crate::force::ForceField;
use crate::particles::{ParticleInit, System};

/// `[[insert]]`: a stream of spheres into the box [lo, hi], or through a
/// face (lo = hi on one axis: LIGGGHTS `insert/stream`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InsertSpec {
    /// Name in observables.csv and the summary (default insert0, …).
    pub name: Option<String>,
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Particles per unit time.
    pub rate: Option<f64>,
    /// Mass per unit time (instead of `rate`).
    pub mass_rate: Option<f64>,
    /// At most this many in all.
    pub count: Option<u64>,
    /// Stop adding while the spheres centred in the region fill this
    /// fraction of it; alone, without a rate, each event fills it up to
    /// this fraction.
    pub volume_fraction: Option<f64>,
    /// Time the stream starts.
    #[serde(default)]
    pub start: f64,
    /// The radius (the scale of `sizes`: the small ones' of `bi`, the
    /// number median's of `lognormal`).
    pub radius: Option<f64>,
    /// `mono`, `bi:RATIO:FRACTION` or `lognormal:SIGMA`, as `mote pack`
    /// takes them (default `mono`).
    pub sizes: Option<String>,
    pub density: Option<f64>,
    pub charge: Option<f64>,
    pub color: Option<[f64; 3]>,
    pub species: Option<String>,
    /// The rigid template the stream makes (rigid scenes; the template
    /// gives size, mass and charge).
    pub clump: Option<String>,
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Standard deviation of each velocity component about `velocity`.
    #[serde(default)]
    pub velocity_spread: f64,
    /// Random positions tried for a sphere before an event gives up.
    #[serde(default = "hundred")]
    pub attempts: u32,
    /// Steps between insertion and removal events (one value for the
    /// scene; default 100).
    pub every: Option<u64>,
}

/// `[[outlet]]`: particles whose centres lie in [lo, hi] (an axis not
/// bounded where `lo` or `hi` is not given), or have crossed the plane
/// through `point` along `normal`, are taken out.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutletSpec {
    /// Name in observables.csv, outflow.csv and the summary (default
    /// outlet0, …).
    pub name: Option<String>,
    pub lo: Option<[f64; 3]>,
    pub hi: Option<[f64; 3]>,
    pub point: Option<[f64; 3]>,
    pub normal: Option<[f64; 3]>,
    /// Steps between events (one value for the scene; default 100).
    pub every: Option<u64>,
}

fn hundred() -> u32 {
    100
}

/// Steps between flow events when no table gives them.
const EVERY: u64 = 100;

/// The interactions that keep up with particles coming and going.
const FOLLOW: [&str; 6] = [
    "granular",
    "walls",
    "lennard_jones",
    "uniform_field",
    "electric_field",
    "damping",
];

/// The largest and smallest radius an `[[insert]]` table makes (a
/// lognormal's draws are kept within 4σ of its median), for the contact
/// list's reach and skin.
pub fn radius_range(scene: &Scene) -> Option<(f64, f64)> {
    let mut range: Option<(f64, f64)> = None;
    for spec in &scene.insert {
        let s = spec.get_ref();
        let Some(radius) = s.radius else { continue };
        let (lo, hi) = match SizeSpec::parse(s.sizes.as_deref().unwrap_or("mono")) {
            Ok(SizeSpec::Bidisperse { ratio, .. }) => (radius, radius * ratio),
            Ok(SizeSpec::Lognormal { sigma }) => {
                let median = radius * (-3.5 * sigma * sigma).exp();
                (median * (-4.0 * sigma).exp(), median * (4.0 * sigma).exp())
            }
            _ => (radius, radius),
        };
        range = Some(range.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
    }
    range
}

/// The run's flow from its `[[insert]]` and `[[outlet]]` tables, or
/// `None` without them; refuses what cannot follow particles coming and
/// going. `sys` gets its ids.
pub fn flow(
    scene: &Scene,
    src: Source,
    sys: &mut System,
    forces: &ForceField,
) -> Result<Option<Flow>, ParseError> {
    let first = match (scene.insert.first(), scene.outlet.first()) {
        (Some(i), _) => i.span(),
        (None, Some(o)) => o.span(),
        (None, None) => return Ok(None),
    };
    let what = if scene.insert.is_empty() {
        "[[outlet]]"
    } else {
        "[[insert]]"
    };
    let refuse = |why: String| Err(src.error(first.clone(), format!("{what}: {why}")));
    let cannot: Vec<&str> = forces
        .interactions
        .iter()
        .map(|i| i.name())
        .filter(|n| !FOLLOW.contains(n))
        .collect();
    if !cannot.is_empty() {
        return refuse(format!(
            "particles cannot come and go under {} yet (granular contacts and walls, \
             Lennard-Jones, uniform and electric fields and damping can)",
            cannot.join(", ")
        ));
    }
    if scene.brownian.is_some() {
        return refuse("particles cannot come and go in Brownian dynamics yet".into());
    }
    let integrator = super::run::integrator_setting(&scene.run);
    if crate::Integrator::from_name(&integrator.value) != Some(crate::Integrator::LeapFrog) {
        return refuse("particles come and go under integrator = \"leapfrog\"".into());
    }
    if !scene.output.inspect.is_empty() {
        return refuse(
            "the particle inspector ([output] inspect) follows particles by their place in the \
             scene, which removal changes"
                .into(),
        );
    }
    if !scene.insert.is_empty() && sys.particles.radius.iter().any(|r| *r <= 0.0) {
        return refuse(
            "new spheres are kept clear of the others by their radii, and the scene's \
             particles have none: give them a radius (σ/2 for Lennard-Jones)"
                .into(),
        );
    }
    let every = interval(scene, src)?;
    let inserters = scene
        .insert
        .iter()
        .enumerate()
        .map(|(k, s)| inserter(s.get_ref(), k, s.span(), src))
        .collect::<Result<Vec<_>, _>>()?;
    let outlets = outlets(scene, src)?;
    let mut walls = Vec::new();
    for (k, w) in scene.wall.iter().enumerate() {
        walls.extend(w.get_ref().walls(k).map_err(|m| src.error(w.span(), m))?);
    }
    Ok(Some(Flow::new(sys, inserters, outlets, every, walls)))
}

/// The steps between flow events: the one `every` the `[[insert]]` and
/// `[[outlet]]` tables give (100 where none does).
pub fn interval<T>(scene: &SceneFile<T>, src: Source) -> Result<u64, ParseError> {
    let mut every: Option<(u64, Range<usize>)> = None;
    let givens = (scene.insert.iter().map(|s| (s.get_ref().every, s.span())))
        .chain(scene.outlet.iter().map(|s| (s.get_ref().every, s.span())));
    for (given, span) in givens {
        let Some(e) = given else { continue };
        if e == 0 {
            return Err(src.error(span, "every: at least 1 step between events"));
        }
        match &every {
            Some((other, _)) if *other != e => {
                return Err(src.error(
                    span,
                    format!(
                        "every = {e}, and another table says {other}: insertion and removal \
                         share one interval"
                    ),
                ))
            }
            _ => every = Some((e, span)),
        }
    }
    Ok(every.map_or(EVERY, |e| e.0))
}

/// The scene's `[[outlet]]` tables.
pub fn outlets<T>(scene: &SceneFile<T>, src: Source) -> Result<Vec<Outlet>, ParseError> {
    (scene.outlet.iter().enumerate())
        .map(|(k, s)| outlet(s.get_ref(), k, s.span(), src))
        .collect()
}

/// The sphere stream of an `[[insert]]` table of a point-particle scene.
fn inserter(
    s: &InsertSpec,
    k: usize,
    span: Range<usize>,
    src: Source,
) -> Result<Inserter, ParseError> {
    let stream = stream(s, k, span.clone(), src)?;
    let bad =
        |why: String| Err(src.error(span.clone(), format!("[[insert]] {}: {why}", stream.name)));
    if s.clump.is_some() {
        return bad("clump names a rigid template, and this scene has no [rigid] table".into());
    }
    let (Some(radius), Some(density)) = (s.radius, s.density) else {
        return bad("give the spheres' radius and density".into());
    };
    if radius <= 0.0 || density <= 0.0 {
        return bad("radius and density must be positive".into());
    }
    let sizes = match SizeSpec::parse(s.sizes.as_deref().unwrap_or("mono")) {
        Ok(sizes) => sizes,
        Err(m) => return bad(format!("sizes: {m}")),
    };
    Ok(Inserter {
        radius,
        sizes,
        density,
        template: ParticleInit {
            charge: s.charge.unwrap_or(0.0),
            color: s.color.unwrap_or_else(super::white),
            ..ParticleInit::default()
        },
        species: s.species.clone().unwrap_or_else(|| "X".into()),
        stream,
    })
}

/// What an `[[insert]]` table says of its stream, whatever it makes:
/// name, region, rate, count, start, velocity, attempts.
pub fn stream(
    s: &InsertSpec,
    k: usize,
    span: Range<usize>,
    src: Source,
) -> Result<Stream, ParseError> {
    let name = s.name.clone().unwrap_or_else(|| format!("insert{k}"));
    let bad = |why: String| Err(src.error(span.clone(), format!("[[insert]] {name}: {why}")));
    let (lo, hi) = (DVec3::from(s.lo), DVec3::from(s.hi));
    let flat = (0..3).filter(|&a| hi[a] == lo[a]).count();
    if (0..3).any(|a| hi[a] < lo[a]) || flat > 1 {
        return bad(
            "the region needs lo < hi on every axis, or on all but one for a face \
             (lo = hi on that axis)"
                .into(),
        );
    }
    if flat == 1 && s.volume_fraction.is_some() {
        return bad("a face (lo = hi on one axis) has no volume to fill".into());
    }
    if !name
        .chars()
        .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
    {
        return bad("a name is letters, digits, _ and - (it names columns)".into());
    }
    let rate = match (s.rate, s.mass_rate, s.volume_fraction) {
        (Some(_), Some(_), _) => return bad("give rate or mass_rate, not both".into()),
        (Some(r), None, _) if r > 0.0 => Rate::Number(r),
        (None, Some(r), _) if r > 0.0 => Rate::Mass(r),
        (Some(_), None, _) | (None, Some(_), _) => return bad("the rate must be positive".into()),
        (None, None, Some(_)) => Rate::Fill,
        (None, None, None) => {
            return bad(
                "give rate (particles per unit time), mass_rate, or volume_fraction to fill \
                 the region up to"
                    .into(),
            )
        }
    };
    if s.volume_fraction.is_some_and(|f| !(f > 0.0 && f < 1.0)) {
        return bad("volume_fraction must lie in (0, 1)".into());
    }
    if s.count == Some(0) || s.attempts == 0 {
        return bad("count and attempts must be at least 1".into());
    }
    if s.start < 0.0 || s.velocity_spread < 0.0 {
        return bad("start and velocity_spread must not be negative".into());
    }
    Ok(Stream {
        name,
        region: Region { lo, hi },
        rate,
        start: s.start,
        count: s.count,
        fill: s.volume_fraction,
        velocity: DVec3::from(s.velocity),
        velocity_spread: s.velocity_spread,
        attempts: s.attempts,
        inserted: 0,
        mass: 0.0,
        most_behind: 0,
    })
}

fn outlet(s: &OutletSpec, k: usize, span: Range<usize>, src: Source) -> Result<Outlet, ParseError> {
    let name = s.name.clone().unwrap_or_else(|| format!("outlet{k}"));
    let bad = |why: &str| Err(src.error(span.clone(), format!("[[outlet]] {name}: {why}")));
    if !name
        .chars()
        .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
    {
        return bad("a name is letters, digits, _ and - (it names columns)");
    }
    let exit =
        match (s.lo, s.hi, s.point, s.normal) {
            (None, None, Some(point), Some(normal)) => {
                let n = DVec3::from(normal);
                if n.length() == 0.0 {
                    return bad("the face's normal must not be zero");
                }
                Exit::Face {
                    point: DVec3::from(point),
                    normal: n.normalize(),
                }
            }
            (lo, hi, None, None) if lo.is_some() || hi.is_some() => {
                let lo = lo.map_or(DVec3::NEG_INFINITY, DVec3::from);
                let hi = hi.map_or(DVec3::INFINITY, DVec3::from);
                if (0..3).any(|a| hi[a] <= lo[a]) {
                    return bad("the region needs lo < hi on every axis");
                }
                Exit::Region(Region { lo, hi })
            }
            _ => return bad(
                "give a region (lo and/or hi) or a face (point and normal) particles leave through",
            ),
        };
    Ok(Outlet::new(&name, exit))
}
