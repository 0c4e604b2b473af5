//! `mote run`: a scene file, an MPPphys particle file or a built-in example.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use mote_io::checkpoint::{self, Checkpoint};
use mote_io::Provenance;
use mote_md::output::{ObservablesCsv, TrajectoryXyz};
use mote_md::scene::{PlistSystem, Scene};
use mote_md::{MdError, Observables, Observer, RunLength, RunReport, System};

use crate::examples;

#[derive(clap::Args, Debug, Clone)]
pub struct RunArgs {
    /// Scene file (.toml), MPPphys particle file (.plist or any other name), or `example:NAME`.
    #[arg(required_unless_present = "resume")]
    pub input: Option<String>,
    /// Continue a run from its checkpoint, bit for bit as if it had not stopped.
    #[arg(long, value_name = "CHECKPOINT", conflicts_with_all = ["input", "until", "steps", "dt", "solver", "output"])]
    pub resume: Option<PathBuf>,
    /// Write DIR/checkpoint.mote every N steps and at the end (atomically).
    #[arg(long, value_name = "N")]
    pub checkpoint_every: Option<u64>,
    /// Run until this simulated time (overrides the scene).
    #[arg(long, value_name = "T", conflicts_with = "steps")]
    pub until: Option<f64>,
    /// Run this many steps (overrides the scene).
    #[arg(long, value_name = "N")]
    pub steps: Option<u64>,
    /// Time step (overrides the scene or the particle file's `dt`).
    #[arg(long, value_name = "DT")]
    pub dt: Option<f64>,
    /// Model of an MPPphys particle file: nbody (DirectNbody) or springs (MassSpring).
    #[arg(long, value_name = "MODEL", default_value = "nbody")]
    pub system: String,
    /// Integrator: euler, symplectic-euler, rk4 (RK4), leapfrog (LF).
    #[arg(long, value_name = "NAME")]
    pub solver: Option<String>,
    /// Folder for the output files (default: the scene's, or out/NAME).
    #[arg(long, short = 'o', value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Ray-trace the final state into this PNG (1920×1080, shadows, box drawn).
    #[arg(long, value_name = "FILE.png")]
    pub picture: Option<PathBuf>,
}

/// The input text and the name it goes by in messages and headers.
struct Input {
    name: String,
    label: String,
    text: String,
    plist: bool,
}

fn read_input(spec: &str) -> anyhow::Result<Input> {
    if let Some(name) = spec.strip_prefix("example:") {
        let Some(e) = examples::find(name) else {
            let names: Vec<String> = examples::all().into_iter().map(|e| e.name).collect();
            bail!(
                "no example called '{name}'; the examples are: {}",
                names.join(", ")
            );
        };
        return Ok(Input {
            name: name.to_string(),
            label: spec.to_string(),
            text: e.text,
            plist: false,
        });
    }
    let path = Path::new(spec);
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {spec}"))?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "run".into());
    let plist = path.extension().and_then(|e| e.to_str()) != Some("toml");
    Ok(Input {
        name,
        label: spec.to_string(),
        text,
        plist,
    })
}

/// A seed from the clock when none is given.
fn fresh_seed() -> u64 {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    (t.as_nanos() as u64 ^ (std::process::id() as u64) << 32) % 1_000_000_007
}

/// Writes DIR/checkpoint.mote on its schedule: the run's input and options
/// (`template`) with the current state.
struct CheckpointWriter {
    path: PathBuf,
    every: u64,
    template: Checkpoint,
    /// The interactions' carried state, taken just before `observe`.
    carried: Vec<(usize, Vec<f64>)>,
}

impl Observer for CheckpointWriter {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe_forces(&mut self, forces: &mote_md::ForceField) {
        self.carried = forces
            .interactions
            .iter()
            .enumerate()
            .map(|(k, i)| (k, i.carried_state()))
            .filter(|(_, v)| !v.is_empty())
            .collect();
    }

    fn observe(&mut self, sys: &System, _obs: &Observables) -> Result<(), MdError> {
        let p = &sys.particles;
        let rotating = !sys.carried_angular_acceleration.is_empty();
        let cp = Checkpoint {
            angular: if rotating {
                p.angular_velocity
                    .iter()
                    .zip(&sys.carried_angular_acceleration)
                    .map(|(w, a)| [w.x, w.y, w.z, a.x, a.y, a.z])
                    .collect()
            } else {
                Vec::new()
            },
            carried: self.carried.clone(),
            time: sys.time,
            step: sys.step,
            positions: p.position.iter().map(|r| r.to_array()).collect(),
            velocities: p.velocity.iter().map(|v| v.to_array()).collect(),
            accelerations: sys
                .carried_acceleration
                .iter()
                .map(|a| a.to_array())
                .collect(),
            ..self.template.clone()
        };
        Ok(checkpoint::write(&self.path, &cp)?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.path.display().to_string()]
    }
}

fn hex(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

fn unhex(s: &str) -> anyhow::Result<f64> {
    Ok(f64::from_bits(
        u64::from_str_radix(s, 16).context("a checkpoint option is not a hexadecimal f64")?,
    ))
}

/// Drops what an interrupted run wrote after its last checkpoint (rows past
/// `step`, frames past `time`), so the resumed run continues the files.
fn trim_outputs(dir: &Path, step: u64, time: f64, provenance: &Provenance) -> anyhow::Result<()> {
    let csv = dir.join("observables.csv");
    if let Ok(text) = std::fs::read_to_string(&csv) {
        let mut column = None;
        let mut kept = String::new();
        for line in text.lines() {
            let keep = if line.starts_with('#') {
                true
            } else if let Some(k) = column {
                line.split(',')
                    .nth(k)
                    .and_then(|v| v.trim().parse::<f64>().ok())
                    .is_some_and(|s| s <= step as f64)
            } else {
                column = line.split(',').position(|c| c.trim() == "step");
                true
            };
            if keep {
                kept.push_str(line);
                kept.push('\n');
            }
        }
        std::fs::write(&csv, kept).with_context(|| format!("cannot rewrite {}", csv.display()))?;
    }
    let xyz = dir.join("trajectory.xyz");
    if xyz.exists() {
        let frames = mote_io::xyz::read_frames(&xyz)?;
        let mut w = mote_io::xyz::XyzWriter::create(&xyz, provenance.clone())?;
        for f in frames.iter().filter(|f| f.time <= time) {
            w.write(f)?;
        }
    }
    Ok(())
}

/// The input and the options of the run a checkpoint came from.
fn restore(cp: &Checkpoint) -> anyhow::Result<(Input, RunArgs)> {
    let get = |k: &str| cp.option(k).map(str::to_string);
    let input = Input {
        name: get("name").unwrap_or_else(|| "run".into()),
        label: cp.input_label.clone(),
        text: cp.input_text.clone(),
        plist: get("plist").as_deref() == Some("true"),
    };
    let args = RunArgs {
        input: None,
        resume: None,
        checkpoint_every: get("checkpoint-every").map(|v| v.parse()).transpose()?,
        until: None,
        steps: get("total-steps").map(|v| v.parse()).transpose()?,
        dt: get("dt").map(|v| unhex(&v)).transpose()?,
        system: get("system").unwrap_or_else(|| "nbody".into()),
        solver: get("solver"),
        output: get("output").map(PathBuf::from),
        picture: None,
    };
    Ok((input, args))
}

pub fn run(global: &super::GlobalOpts, args: RunArgs) -> anyhow::Result<ExitCode> {
    global.init_threads()?;
    let resumed = match &args.resume {
        Some(path) => Some(checkpoint::read(path)?),
        None => None,
    };
    let picture = args.picture.clone();
    let (input, args) = match &resumed {
        Some(cp) => restore(cp)?,
        None => (read_input(args.input.as_deref().unwrap_or_default())?, args),
    };
    if !input.plist && resumed.is_none() && mote_md::rigid::scene::is_rigid_scene(&input.text) {
        return run_rigid(global, &input.label, &input.text, args.output.as_deref());
    }
    let scene = if input.plist {
        let system = match args.system.as_str() {
            "nbody" => PlistSystem::Nbody,
            "springs" => PlistSystem::Springs,
            other => bail!("unknown --system '{other}': expected nbody or springs"),
        };
        let pf = mote_io::plist::parse(&input.text, &input.label)?;
        let solver = args.solver.clone().unwrap_or_else(|| "leapfrog".into());
        Scene::from_plist(&pf, system, &solver, &input.label)?
    } else {
        let mut scene = Scene::parse(&input.text, &input.label)?;
        if let Some(s) = &args.solver {
            scene.run.integrator = toml::Spanned::new(0..0, s.clone());
        }
        scene
    };
    let mut scene = scene;
    if let Some(dt) = args.dt {
        scene.run.dt = Some(toml::Spanned::new(0..0, dt));
    }
    if scene.run.dt.is_none() {
        bail!(
            "{}: no time step: give one with --dt (a particle file sets it with a 'dt' line)",
            input.label
        );
    }
    let seed_given = resumed
        .as_ref()
        .map(|cp| cp.seed)
        .or(global.seed)
        .or(scene.seed);
    let seed = seed_given.unwrap_or_else(fresh_seed);
    let mut built = scene.build(&input.text, &input.label, seed)?;
    let length = match (args.steps, args.until, built.length) {
        (Some(n), _, _) => RunLength::Steps(n),
        (None, Some(t), _) => RunLength::Until(t),
        (None, None, Some(l)) => l,
        (None, None, None) => bail!(
            "{}: no run length: give --until T or --steps N",
            input.label
        ),
    };

    let dir = args
        .output
        .clone()
        .or_else(|| scene.output.dir.as_ref().map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("out").join(&input.name));
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the output folder {}", dir.display()))?;
    let total_steps = length.steps_from(built.simulation.system.time, built.simulation.dt);
    let append = resumed.is_some();
    if let Some(cp) = &resumed {
        let sys = &mut built.simulation.system;
        if cp.positions.len() != sys.particles.len() {
            bail!(
                "{}: the checkpoint has {} particles, its scene makes {}",
                input.label,
                cp.positions.len(),
                sys.particles.len()
            );
        }
        sys.time = cp.time;
        sys.step = cp.step;
        for (i, (r, v)) in cp.positions.iter().zip(&cp.velocities).enumerate() {
            sys.particles.position[i] = mote_md::DVec3::from(*r);
            sys.particles.velocity[i] = mote_md::DVec3::from(*v);
        }
        sys.carried_acceleration = cp
            .accelerations
            .iter()
            .map(|a| mote_md::DVec3::from(*a))
            .collect();
        if !cp.angular.is_empty() {
            if cp.angular.len() != sys.particles.len() {
                bail!(
                    "{}: the checkpoint's angular table has the wrong length",
                    input.label
                );
            }
            sys.carried_angular_acceleration.clear();
            for (i, a) in cp.angular.iter().enumerate() {
                sys.particles.angular_velocity[i] = mote_md::DVec3::new(a[0], a[1], a[2]);
                sys.carried_angular_acceleration
                    .push(mote_md::DVec3::new(a[3], a[4], a[5]));
            }
        }
        let forces = &mut built.simulation.forces;
        let count = forces.interactions.len();
        for (k, values) in &cp.carried {
            let interaction = forces.interactions.get_mut(*k).ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: the checkpoint carries state for interaction {k}, the scene has {count}",
                    input.label
                )
            })?;
            interaction
                .restore_carried_state(values)
                .map_err(|m| anyhow::anyhow!("{}: {m}", input.label))?;
        }
        built.simulation.sample_at_start = false;
    }
    let length =
        RunLength::Steps(total_steps - resumed.as_ref().map_or(0, |cp| cp.step.min(total_steps)));
    let provenance = Provenance {
        program: format!("mote {}", env!("CARGO_PKG_VERSION")),
        scene: input.label.clone(),
        seed,
    };
    if let Some(cp) = &resumed {
        trim_outputs(&dir, cp.step, cp.time, &provenance)?;
    }
    let out = &scene.output;
    let sim = &mut built.simulation;
    if out.observables_every > 0 {
        sim.observers.push(Box::new(ObservablesCsv::create(
            &dir.join("observables.csv"),
            &provenance,
            scene.units,
            out.observables_every,
            built.probes.clone(),
            sim.system.boundary.periodic.iter().all(|p| *p),
            &sim.forces
                .interactions
                .iter()
                .flat_map(|i| i.wall_forces())
                .map(|w| w.0)
                .collect::<Vec<_>>(),
            sim.system
                .particles
                .dipole
                .iter()
                .any(|m| *m != mote_md::DVec3::ZERO),
            append,
        )?));
    }
    if out.trajectory_every > 0 {
        sim.observers.push(Box::new(TrajectoryXyz::create(
            &dir.join("trajectory.xyz"),
            provenance.clone(),
            out.trajectory_every,
            append,
        )?));
    }
    if let Some(every) = args.checkpoint_every {
        let mut options = vec![
            ("name".to_string(), input.name.clone()),
            ("plist".to_string(), input.plist.to_string()),
            ("system".to_string(), args.system.clone()),
            ("total-steps".to_string(), total_steps.to_string()),
            ("checkpoint-every".to_string(), every.to_string()),
            ("dt".to_string(), hex(sim.dt)),
            ("output".to_string(), dir.display().to_string()),
        ];
        if let Some(s) = &args.solver {
            options.push(("solver".to_string(), s.clone()));
        }
        sim.observers.push(Box::new(CheckpointWriter {
            path: dir.join("checkpoint.mote"),
            every: every.max(1),
            template: Checkpoint {
                program: provenance.program.clone(),
                seed,
                options,
                input_label: input.label.clone(),
                input_text: input.text.clone(),
                ..Checkpoint::default()
            },
            carried: Vec::new(),
        }));
    }

    let steps = length.steps_from(sim.system.time, sim.dt);
    if !global.quiet {
        let threads = rayon::current_num_threads();
        eprintln!(
            "mote run {}: {} particles, {} with dt = {}, {} steps, seed {}{}, {} thread{}",
            input.label,
            sim.system.particles.len(),
            sim.stepper.scheme.name(),
            sim.dt,
            steps,
            seed,
            if seed_given.is_some() {
                ""
            } else {
                " (chosen)"
            },
            threads,
            if threads == 1 { "" } else { "s" }
        );
    }
    let bar = progress_bar(steps, global.quiet);
    let started = Instant::now();
    let mut shown = false;
    let result = sim.run(length, |sys| {
        if !shown && started.elapsed() > Duration::from_secs(1) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            shown = true;
        }
        if sys.step % 16 == 0 {
            bar.set_position(sys.step);
            bar.set_message(format!("t = {:.6e}", sys.time));
        }
    });
    bar.finish_and_clear();
    match result {
        Ok(report) => {
            if let Some(png) = &picture {
                let frame = mote_md::output::frame_of(&sim.system);
                mote_render::frame::picture(&frame, png, 1920, 1080)
                    .with_context(|| format!("cannot draw {}", png.display()))?;
            }
            if !global.quiet {
                summary(&report, &scene, &dir, steps);
                if let Some(png) = &picture {
                    println!("Picture of the final state: {}.", png.display());
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e @ MdError::Unstable { .. }) => {
            eprintln!("error: {e}");
            eprintln!(
                "the files written up to that point are kept in {}",
                dir.display()
            );
            Ok(ExitCode::from(3))
        }
        Err(e) => Err(e.into()),
    }
}

fn progress_bar(steps: u64, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} steps  {msg}  {per_sec}  ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

fn summary(report: &RunReport, scene: &Scene, dir: &Path, _steps: u64) {
    let secs = report.wall.as_secs_f64();
    let [_, t_unit, _, e_unit] = scene.units.labels();
    let files = if report.files.is_empty() {
        "no files (output switched off)".to_string()
    } else {
        report.files.join(", ")
    };
    println!(
        "Ran {} steps to t = {:.6e} {} in {:.3} s of wall time ({:.0} steps/s). Total energy went from {:.9e} to {:.9e} {}: \
         relative drift {:.3e} at the end, {:.3e} at most over the sampled instants. Output in {}: {}.",
        report.steps,
        report.last.time,
        t_unit,
        secs,
        report.steps as f64 / secs.max(1e-9),
        report.initial.total_energy(),
        report.last.total_energy(),
        e_unit,
        rel(report.last.total_energy(), report.initial.total_energy()),
        report.max_energy_error,
        dir.display(),
        files
    );
}

fn rel(e: f64, e0: f64) -> f64 {
    if e0 != 0.0 {
        (e - e0).abs() / e0.abs()
    } else {
        (e - e0).abs()
    }
}

/// A scene with a `[rigid]` table: rigid clumps moved by the FRBI
/// (`mote_md::rigid::scene`), with its own run loop and writers.
fn run_rigid(
    global: &super::GlobalOpts,
    label: &str,
    text: &str,
    out: Option<&Path>,
) -> anyhow::Result<ExitCode> {
    let report =
        mote_md::rigid::scene::run_rigid_scene(text, label, global.seed, out, global.quiet)?;
    if !global.quiet {
        println!(
            "mote run {label}: {} rigid bodies ({} spheres), {} steps to t = {:.6e} in {:.3} s of wall time. Final kinetic energy {:.6e}, potential {:.6e}; momentum {}, angular momentum {}.",
            report.bodies,
            report.spheres,
            report.steps,
            report.time,
            report.wall_seconds,
            report.kinetic_energy,
            report.potential_energy,
            report.linear_momentum,
            report.angular_momentum,
        );
        for (name, f) in &report.wall_forces {
            println!("  force on wall {name}: {f}");
        }
        let files: Vec<String> = report
            .files
            .iter()
            .map(|f| f.display().to_string())
            .collect();
        println!("Output: {}", files.join(", "));
    }
    Ok(ExitCode::SUCCESS)
}
