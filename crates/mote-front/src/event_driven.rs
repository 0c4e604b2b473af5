//! Event-driven hard spheres and disks (`mote_edmd::scene::run_scene`).

use std::path::PathBuf;

use mote_edmd::scene::{run_scene, Outputs};
use mote_edmd::Scene;

use mote_io::checkpoint::Checkpoint;

use crate::checkpoints::{hex, trim_outputs, unhex};
use crate::error::{refuse, FrontError};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

/// The words of the old `mote edmd` command, kept as an alias for one
/// release: `--time` is the measured time after `equilibrate` (where
/// `--until` is the end time), and `--no-output` writes no files.
#[derive(Debug, Clone, Default)]
pub struct EdmdWords {
    pub time: Option<f64>,
    pub no_output: bool,
}

pub(crate) fn run(
    input: &Input,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    run_with(input, options, &EdmdWords::default(), monitor)
}

/// Continues the event-driven run a checkpoint came from, appending to its
/// files: the same scene, seed, end time, output folder and checkpoint
/// schedule.
pub(crate) fn resume(
    cp: &Checkpoint,
    given: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let get = |k: &str| cp.option(k).map(str::to_string);
    let input = Input {
        name: get("name").unwrap_or_else(|| "run".into()),
        label: cp.input_label.clone(),
        text: cp.input_text.clone(),
        plist: false,
    };
    let options = RunOptions {
        resume: given.resume.clone(),
        checkpoint_every: get("checkpoint-every").and_then(|v| v.parse().ok()),
        output: given
            .output
            .clone()
            .or_else(|| get("output").map(PathBuf::from)),
        picture: given.picture.clone(),
        trajectory_format: get("trajectory-format"),
        seed: Some(cp.seed),
        threads: given.threads,
        ..RunOptions::default()
    };
    // The measured time, bit for bit (not recomputed from an end time).
    let words = EdmdWords {
        time: get("time").map(|v| unhex(&v)).transpose()?,
        no_output: false,
    };
    run_events(&input, &options, &words, Some(cp), monitor)
}

/// Runs an event-driven scene; `words` are the old command's options.
pub fn run_with(
    input: &Input,
    options: &RunOptions,
    words: &EdmdWords,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    run_events(input, options, words, None, monitor)
}

fn run_events(
    input: &Input,
    options: &RunOptions,
    words: &EdmdWords,
    resumed: Option<&Checkpoint>,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    const WHY_NO_STEP: &str =
        "event-driven dynamics jumps from collision to collision, with no time step";
    options.refuse(
        "event-driven hard spheres",
        &[
            (options.dt.is_some(), "--dt", WHY_NO_STEP),
            (options.steps.is_some(), "--steps", WHY_NO_STEP),
            (options.solver.is_some(), "--solver", crate::WHY_NO_SOLVER),
            (options.system.is_some(), "--system", crate::WHY_NO_SYSTEM),
        ],
    )?;
    let mut scene = Scene::parse(&input.text, &input.label)?;
    if let Some(t) = options.until {
        if !(t.is_finite() && t > scene.equilibrate) {
            refuse!(
                "--until {t}: must be a time after the scene's equilibration ({})",
                scene.equilibrate
            );
        }
        scene.time = t - scene.equilibrate;
    }
    if let Some(t) = words.time {
        if !(t >= 0.0 && t.is_finite()) {
            refuse!("--time {t}: must be a non-negative number");
        }
        scene.time = t;
    }
    if let (Some(t), Some(_)) = (&scene.trajectory, &options.trajectory_format) {
        // The file keeps its name; the extension says the format.
        let format = options.trajectory_format(mote_io::trajectory::Format::Xyz)?;
        let renamed = std::path::Path::new(t).with_extension(format.extension());
        scene.trajectory = Some(renamed.to_string_lossy().into_owned());
    }
    if words.no_output {
        scene.trajectory = None;
        scene.observables = None;
        scene.histogram = None;
    }
    let dir = input.output_dir(options.output.as_ref(), scene.output.dir.as_ref());
    // A run that writes no files (`--no-output`) takes no folder: it
    // neither makes one nor marks the current one as its own.
    let writes = !words.no_output || options.checkpoint_every.is_some() || resumed.is_some();
    let folder = if writes {
        Some(crate::lock::RunFolder::claim(
            &dir,
            &input.label,
            &input.text,
            resumed.zip(options.resume.as_deref()),
        )?)
    } else {
        None
    };
    let scene_dir = input.folder();
    let (seed, chosen) = crate::seed::resolve(options.seed, scene.seed);
    monitor.start(&format!(
        "mote run {}: event-driven hard {}, simulated time {} after {} of equilibration, {}",
        input.label,
        if scene.dimension == 2 {
            "disks"
        } else {
            "spheres"
        },
        scene.time,
        scene.equilibrate,
        crate::seed_phrase(seed, chosen),
    ));
    let provenance = crate::provenance(&input.label, seed);
    if let Some(cp) = resumed {
        trim_outputs(&dir, cp.step, cp.time)?;
    }
    // Checkpoints every N output intervals; the measured time is recorded
    // so a resumed run ends where this one would have.
    let checkpoints = options.checkpoint_every.map(|every| {
        let template = Checkpoint {
            program: provenance.program.clone(),
            seed,
            options: vec![
                ("engine".into(), "event-driven".into()),
                ("name".into(), input.name.clone()),
                ("checkpoint-every".into(), every.to_string()),
                ("time".into(), hex(scene.time)),
                ("output".into(), dir.display().to_string()),
                (
                    "trajectory-format".into(),
                    scene
                        .trajectory
                        .as_deref()
                        .and_then(|t| std::path::Path::new(t).extension())
                        .map_or("xyz".into(), |e| e.to_string_lossy().into_owned()),
                ),
            ]
            .into_iter()
            .chain(
                folder
                    .iter()
                    .flat_map(crate::lock::RunFolder::checkpoint_options),
            )
            .collect(),
            input_label: input.label.clone(),
            input_text: input.text.clone(),
            ..Checkpoint::default()
        };
        mote_run::Checkpoints {
            every: every.max(1),
            path: dir.join("checkpoint.mote"),
            template,
        }
    });
    let out = Outputs {
        base: dir.clone(),
        scene_dir,
        provenance,
        checkpoints,
        resume: resumed.cloned(),
        live: options.live.clone(),
        force: options.force,
    };
    let cpu0 = crate::cpu::cpu_seconds();
    let progress = |f: f64| monitor.progress((f * 1000.0) as u64, 1000, "");
    let r = match scene.dimension {
        2 => run_scene::<2>(&scene, seed, &out, progress),
        _ => run_scene::<3>(&scene, seed, &out, progress),
    };
    let r = match r {
        Ok(r) => r,
        Err(e @ mote_edmd::EdmdError::Interrupted { signal, .. }) => {
            return Ok(Outcome {
                engine: Engine::EventDriven,
                seed,
                dir,
                summary: Vec::new(),
                ending: Ending::Interrupted {
                    signal,
                    message: e.to_string(),
                },
            })
        }
        // refused before it started, at a line of the scene
        Err(e @ mote_edmd::EdmdError::Scene { .. }) => return Err(e.into()),
        Err(e) => {
            return Err(FrontError::request(format!(
                "{}: run stopped: {e}",
                input.label
            )))
        }
    };
    let cpu = crate::cpu::cpu_seconds() - cpu0;
    let mut outcome = Outcome {
        engine: Engine::EventDriven,
        seed,
        dir,
        summary: summary(&r, &scene, cpu),
        ending: Ending::Finished,
    };
    if let (Some(png), Some(frame)) = (&options.picture, &r.final_frame) {
        mote_render::frame::picture(frame, png, 1920, 1080)?;
        outcome
            .summary
            .push(format!("Picture of the final state: {}.", png.display()));
    }
    Ok(outcome)
}

/// The paragraph that ends an event-driven run, then the final speeds of
/// small systems (Newton's cradles) and the files written.
fn summary(r: &mote_edmd::Run, scene: &Scene, cpu: f64) -> Vec<String> {
    let rate = if cpu > 0.05 {
        format!("{:.3e}", r.collisions as f64 / cpu)
    } else {
        "(too short to time)".to_string()
    };
    let mut s = format!(
        "{} {} (packing fraction {:.4}, seed {}): simulated t = {} after {} of equilibration with {} pair collisions and {} wall collisions \
         ({} events in all) in {:.3} s CPU / {:.3} s wall, {} collisions per CPU-second. ",
        r.n,
        if r.dimension == 2 { "disks" } else { "spheres" },
        r.packing_fraction,
        r.seed,
        r.simulated_time,
        scene.equilibrate,
        r.collisions,
        r.wall_hits,
        r.events,
        cpu,
        r.wall_seconds,
        rate
    );
    if r.z.is_finite() {
        s += &format!(
            "Compressibility factor Z = {:.4} ({} {:.4}, {:+.2} %). ",
            r.z,
            if r.dimension == 2 {
                "Henderson"
            } else {
                "Carnahan-Starling"
            },
            r.z_reference,
            100.0 * (r.z - r.z_reference) / r.z_reference
        );
    }
    if r.wall_pressure.is_finite() {
        s += &format!("Wall pressure {:.4e}. ", r.wall_pressure);
    }
    if r.collisions > 0 {
        s += &format!(
            "Collision rate {:.4} per particle per unit time (mean free time {:.4e}). ",
            r.collision_rate, r.mean_free_time
        );
    }
    s += &format!(
        "kT = {:.6}; energy drift {:.1e}",
        r.temperature, r.energy_drift
    );
    if r.momentum_drift.is_finite() {
        s += &format!(", momentum drift {:.1e}", r.momentum_drift);
    }
    s += &format!(
        "; speeds vs Maxwell-Boltzmann: KS D = {:.4}, p = {:.3}.",
        r.ks.0, r.ks.1
    );
    let mut lines = vec![s];
    lines.extend(scene.notes.iter().cloned());
    if r.n <= 10 {
        let v: Vec<String> = r.speeds.iter().map(|x| format!("{x:.12}")).collect();
        lines.push(format!("final speeds: {}", v.join(" ")));
        if !r.final_velocities.is_empty() {
            let v: Vec<String> = r
                .final_velocities
                .iter()
                .map(|v| format!("{:+.12}", v[0]))
                .collect();
            lines.push(format!("final x-velocities: {}", v.join(" ")));
        }
    }
    for p in &r.outputs {
        lines.push(format!("wrote {}", p.display()));
    }
    lines
}
