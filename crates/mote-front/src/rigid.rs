//! Rigid clumps of spheres moved by the FRBI (`mote_md::rigid::scene`):
//! the run put together here, as every engine's is — the scene built, its
//! length resolved, the folder claimed, the engine's observers and the
//! applications' (the toning nip's nip.csv, mote-nip) added to the one
//! loop, the summary written.

use std::path::Path;

use mote_io::checkpoint::Checkpoint;
use mote_io::trajectory::TrajectoryWriter;
use mote_io::xyz::Frame;
use mote_md::rigid::run::{RigidCsv, RigidDynamics, SphereTrajectory};
use mote_md::rigid::scene::RigidScene;
use mote_md::MdError;
use mote_run::Driver;

use crate::checkpoints::{restore, trim_outputs};
use crate::error::FrontError;
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    run_with(input, options, None, monitor)
}

/// Continues the rigid run a checkpoint came from, appending to its files.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let (input, options) = restore(cp, given)?;
    run_with(&input, &options, Some(cp), monitor)
}

fn run_with(
    input: &Input,
    options: &RunOptions,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    options.refuse(
        "rigid bodies",
        &[
            (
                options.solver.is_some(),
                "--solver",
                "rigid bodies are moved by the FRBI only",
            ),
            (options.system.is_some(), "--system", crate::WHY_NO_SYSTEM),
        ],
    )?;
    let scene = RigidScene::parse(&input.text, &input.label)?;
    let (seed, chosen) = crate::seed::resolve(options.seed, scene.seed);
    let dir = input.output_dir(options.output.as_ref(), scene.output.dir.as_ref());
    let folder = crate::lock::RunFolder::claim(
        &dir,
        &input.label,
        &input.text,
        resumed.zip(options.resume.as_deref()),
    )?;
    let provenance = crate::provenance(&input.label, seed);
    let format = options.trajectory_format(
        scene
            .output
            .trajectory_format(mote_io::Source::new(&input.label, &input.text))?,
    )?;
    let checkpoints = options.checkpoint_every.map(|every| mote_run::Checkpoints {
        every: every.max(1),
        path: dir.join("checkpoint.mote"),
        template: Checkpoint {
            program: provenance.program.clone(),
            seed,
            options: vec![
                ("engine".into(), "rigid".into()),
                ("name".into(), input.name.clone()),
                ("plist".into(), "false".into()),
                ("checkpoint-every".into(), every.to_string()),
                ("output".into(), dir.display().to_string()),
                ("trajectory-format".into(), format.extension().to_string()),
            ]
            .into_iter()
            .chain(folder.checkpoint_options())
            .collect(),
            input_label: input.label.clone(),
            input_text: input.text.clone(),
            ..Checkpoint::default()
        },
    });
    if let Some(cp) = resumed {
        trim_outputs(&dir, cp.step, cp.time)?;
    }
    monitor.start(&format!(
        "mote run {}: rigid clumps (FRBI) with dt = {}, {}, {}",
        input.label,
        mote_io::system::human_number(options.dt.unwrap_or(scene.run.get_ref().dt)),
        crate::seed_phrase(seed, chosen),
        crate::threads_phrase(),
    ));
    let result = drive(
        input,
        &scene,
        options,
        seed,
        &dir,
        &provenance,
        format,
        checkpoints,
        resumed,
        monitor,
    );
    let mut outcome = Outcome {
        engine: Engine::Rigid,
        seed,
        dir,
        summary: Vec::new(),
        ending: Ending::Finished,
    };
    let report = match result {
        Ok(r) => r,
        Err(e @ MdError::Unstable { .. }) => {
            outcome.ending = Ending::Unstable(e.to_string());
            return Ok(outcome);
        }
        Err(e @ MdError::Interrupted { signal, .. }) => {
            outcome.ending = Ending::Interrupted {
                signal,
                message: e.to_string(),
            };
            return Ok(outcome);
        }
        Err(e) => return Err(e.into()),
    };
    outcome.summary.push(format!(
        "mote run {}: {} rigid bodies ({} spheres), FRBI with dt = {}, {} steps to t = {:.6e} in {:.3} s of wall time, {}. \
         Final kinetic energy {:.6e}, potential {:.6e}; momentum {}, angular momentum {}.",
        input.label,
        report.bodies,
        report.spheres,
        mote_io::system::human_number(report.dt),
        report.steps,
        report.time,
        report.wall_seconds,
        crate::seed_phrase(seed, chosen),
        report.kinetic_energy,
        report.potential_energy,
        report.linear_momentum,
        report.angular_momentum,
    ));
    for (name, f) in &report.wall_forces {
        outcome.summary.push(format!("  force on wall {name}: {f}"));
    }
    outcome
        .summary
        .push(format!("Output: {}", report.files.join(", ")));
    if let Some(png) = &options.picture {
        mote_render::frame::picture(&report.final_frame, png, 1920, 1080)?;
        outcome
            .summary
            .push(format!("Picture of the final state: {}.", png.display()));
    }
    Ok(outcome)
}

/// What a rigid run did, for its summary.
struct Report {
    bodies: usize,
    spheres: usize,
    steps: u64,
    time: f64,
    wall_seconds: f64,
    kinetic_energy: f64,
    potential_energy: f64,
    linear_momentum: glam::DVec3,
    angular_momentum: glam::DVec3,
    wall_forces: Vec<(String, glam::DVec3)>,
    files: Vec<String>,
    dt: f64,
    final_frame: Frame,
}

/// Builds the scene with the options' seed, time step and length, puts
/// the engine's observers (observables.csv, the spheres' trajectory) and
/// the nip's (nip.csv, when the scene has `[rigid.nip]`) into the one
/// loop, and runs it.
#[allow(clippy::too_many_arguments)]
fn drive(
    input: &Input,
    scene: &RigidScene,
    options: &RunOptions,
    seed: u64,
    dir: &Path,
    provenance: &mote_io::Provenance,
    format: mote_io::trajectory::Format,
    checkpoints: Option<mote_run::Checkpoints>,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Report, MdError> {
    let (text, label) = (&input.text, &input.label);
    let mut built = scene.build(text, label, Some(seed))?;
    let nip = mote_nip::probe(scene, text, label)?;
    let until_steps = |t: f64, dt: f64| {
        mote_run::steps_until(0.0, t, dt).ok_or_else(|| {
            MdError::Length(format!(
                "until {t} with dt = {dt:e}: not a number of steps a run can take"
            ))
        })
    };
    if let Some(dt) = options.dt {
        if let Some(t) = scene.run.get_ref().until {
            built.steps = until_steps(t, dt)?;
        }
        built.dt = dt;
    }
    if let Some(n) = options.steps {
        built.steps = n;
    } else if let Some(t) = options.until {
        built.steps = until_steps(t, built.dt)?;
    }
    if resumed.is_none() {
        mote_run::check_run_length(built.steps, built.dt, options.force)
            .map_err(|m| MdError::Length(format!("{label}: {m}")))?;
    }
    let walls: Vec<String> = built
        .contacts()
        .map(|c| c.walls.iter().map(|w| w.name.clone()).collect())
        .unwrap_or_default();
    let append = resumed.is_some();
    let mut driver = Driver::new();
    driver.live = options.live.clone().take();
    driver.observers.push(Box::new(RigidCsv::create(
        &dir.join("observables.csv"),
        provenance,
        &walls,
        scene.output.observables_every.max(1),
        append,
    )?));
    if scene.output.trajectory_every > 0 {
        let p = dir.join(format!("trajectory.{}", format.extension()));
        let writer = if append {
            TrajectoryWriter::append(&p, format, provenance.clone(), false)?
        } else {
            TrajectoryWriter::create(&p, format, provenance.clone(), false)?
        };
        driver.observers.push(Box::new(SphereTrajectory::new(
            writer,
            scene.output.trajectory_every,
        )));
    }
    if let Some((probe, every)) = nip {
        driver.observers.push(Box::new(mote_nip::NipCsv::create(
            &dir.join("nip.csv"),
            provenance,
            probe,
            every,
            append,
        )?));
    }
    driver.checkpoints = checkpoints;
    driver.sample_at_start = !append;
    let (dt, last_step) = (built.dt, built.steps);
    let mut dynamics = RigidDynamics::new(built);
    if let Some(cp) = resumed {
        dynamics.resume(cp, label)?;
    }
    let report = driver.run(
        &mut dynamics,
        |_| last_step,
        |d| {
            let step = d.step;
            if step % 16 == 0 || step == last_step {
                monitor.progress(step, last_step, &format!("t = {:.6e}", d.bodies.time));
            }
        },
    )?;
    let b = &dynamics.bodies;
    let last = report.last;
    Ok(Report {
        bodies: b.len(),
        spheres: (0..b.len()).map(|i| b.template(i).sphere_count()).sum(),
        steps: last_step,
        time: b.time,
        wall_seconds: report.wall.as_secs_f64(),
        kinetic_energy: last.kinetic_energy(),
        potential_energy: last.potential_energy,
        linear_momentum: last.linear_momentum,
        angular_momentum: last.angular_momentum,
        wall_forces: last.wall_forces,
        files: report.files,
        dt,
        final_frame: dynamics.sphere_frame(),
    })
}
