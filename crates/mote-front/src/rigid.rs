//! Rigid clumps of spheres moved by the FRBI (`mote_md::rigid::scene`).

use mote_io::checkpoint::Checkpoint;
use mote_md::rigid::scene::{run_rigid_scene, RigidRun, RigidScene};
use mote_md::MdError;

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
    let dir = options
        .output
        .clone()
        .or_else(|| scene.output.dir.as_ref().map(std::path::PathBuf::from))
        .unwrap_or_else(|| std::path::Path::new("out").join(&input.name));
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
    let run = RigidRun {
        seed: Some(seed),
        out_dir: Some(dir.clone()),
        dt: options.dt,
        steps: options.steps,
        until: options.until,
        force: options.force,
        checkpoints,
        resume: resumed.cloned(),
        trajectory_format: Some(format),
        live: options.live.clone(),
    };
    monitor.start(&format!(
        "mote run {}: rigid clumps (FRBI) with dt = {}, {}, {}",
        input.label,
        mote_io::system::human_number(options.dt.unwrap_or(scene.run.get_ref().dt)),
        crate::seed_phrase(seed, chosen),
        crate::threads_phrase(),
    ));
    let result = run_rigid_scene(&input.text, &input.label, &run, |step, steps, time| {
        if step % 16 == 0 || step == steps {
            monitor.progress(step, steps, &format!("t = {time:.6e}"));
        }
    });
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
    let files: Vec<String> = report
        .files
        .iter()
        .map(|f| f.display().to_string())
        .collect();
    outcome
        .summary
        .push(format!("Output: {}", files.join(", ")));
    if let Some(png) = &options.picture {
        mote_render::frame::picture(&report.final_frame, png, 1920, 1080)?;
        outcome
            .summary
            .push(format!("Picture of the final state: {}.", png.display()));
    }
    Ok(outcome)
}
