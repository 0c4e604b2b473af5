//! `[run]` (integrator, time step, length: the envelope's
//! [`RunTable`], read here for point particles), `[output]` (the
//! envelope's [`OutputTable`]: the inspected particles, the event-driven
//! keys refused) and `[box]` (the simulation box).

use glam::DVec3;
use toml::Spanned;

use mote_io::{ParseError, Source};

use crate::boundary::Boundary;
use crate::integrate::Integrator;
use crate::observe::Probe;
use mote_run::scene::{BoxTable, OutputTable, RunLength, RunTable, Setting};

/// The box of a time-stepped scene's `[box]` (the envelope's
/// [`BoxTable`]): `hi` and `lo` (default the origin) on three axes, the
/// periodic axes (default all).
pub fn scene_box(table: &Spanned<BoxTable>, src: Source) -> Result<Boundary, ParseError> {
    let b = table.get_ref();
    b.axes(src, 3)?;
    let Some(hi) = &b.hi else {
        return Err(src.error(
            table.span(),
            "[box] needs hi, its upper corner: hi = [10, 10, 10] (lo, the lower one, defaults to the origin)",
        ));
    };
    let periodic = b.periodic(3);
    Ok(Boundary {
        lo: DVec3::from_slice(&b.lo(3)),
        hi: DVec3::from_slice(hi.get_ref()),
        periodic: [periodic[0], periodic[1], periodic[2]],
    })
}

/// The box of `[box]`, else the one an `[[fcc]]` crystal set, else none.
pub fn boundary(
    bounds: &Option<Spanned<BoxTable>>,
    fcc_box: Option<Boundary>,
    src: Source,
) -> Result<Boundary, ParseError> {
    Ok(match bounds {
        Some(b) => scene_box(b, src)?,
        None => fcc_box.unwrap_or_default(),
    })
}

/// The integrator `[run]` names (default leapfrog), with where it was named.
pub fn integrator_setting(run: &RunTable) -> Setting<String> {
    run.integrator
        .clone()
        .unwrap_or_else(|| Setting::plain("leapfrog".into()))
}

/// The integrator, the time step and the length of the run (if the scene
/// gives one) of a point-particle scene's `[run]`.
pub fn schedule(
    run: &RunTable,
    src: Source,
) -> Result<(Integrator, f64, Option<RunLength>), ParseError> {
    run.refuse(
        src,
        &[(
            "equilibrate",
            "point particles are measured from the first step; equilibrate is the event-driven engine's (run an equilibration as a scene of its own and start from its last frame with [[from_file]])",
        )],
    )?;
    let integrator = integrator_setting(run);
    let known = Integrator::from_name(&integrator.value).ok_or_else(|| {
        integrator.error(
            src,
            format!(
                "unknown integrator '{}': expected {}",
                integrator.value,
                Integrator::NAMES
            ),
        )
    })?;
    let dt = run
        .time_step(src)?
        .ok_or_else(|| src.whole("[run] needs a time step: dt = ..."))?;
    Ok((known, dt, run.length(src)?))
}

/// Refuses the `[output]` keys of the event-driven engine in a
/// time-stepped scene (points or rigid bodies), with the spelling that
/// counts steps.
pub fn refuse_event_driven_output(output: &OutputTable, src: Source) -> Result<(), ParseError> {
    const STEPS: &str = "a time-stepped run counts steps: observables_every = N, trajectory_every = N (0 turns a file off)";
    output.refuse(
        src,
        &[
            ("interval", STEPS),
            ("observables", STEPS),
            ("trajectory", STEPS),
            (
                "histogram",
                "speeds.csv is the event-driven engine's; the speeds are in the trajectory",
            ),
        ],
    )
}

/// The per-particle columns of `[output] inspect`, checked against the
/// `n` particles.
pub fn probes(output: &OutputTable, src: Source, n: usize) -> Result<Vec<Probe>, ParseError> {
    let mut probes = Vec::new();
    for p in &output.inspect {
        let probe = Probe::parse(p.get_ref()).map_err(|m| src.error(p.span(), m))?;
        if probe.particle >= n {
            return Err(src.error(
                p.span(),
                format!("inspect '{}': there are only {n} particles", p.get_ref()),
            ));
        }
        probes.push(probe);
    }
    Ok(probes)
}
