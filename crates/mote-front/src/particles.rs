//! Point-particle runs: fixed-step integrators and Brownian dynamics
//! (`mote_md::Simulation`), from a scene, a particle file or a checkpoint.

use std::path::Path;

use mote_io::checkpoint::{self, Checkpoint};
use mote_md::output::{ObservablesCsv, Trajectory};
use mote_md::scene::{PlistSystem, Scene};
use mote_md::{MdError, RunLength, RunReport, Simulation};
use mote_run::{Checkpoints, Driver};

use crate::checkpoints::{hex, restore, trim_outputs};
use crate::error::{refuse, FrontError};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

/// Puts the checkpoint's state into the freshly built simulation.
pub fn resume_state(
    cp: &Checkpoint,
    sim: &mut mote_md::Simulation,
    label: &str,
) -> Result<(), FrontError> {
    let sys = &mut sim.system;
    if cp.positions.len() != sys.particles.len() {
        refuse!(
            "{label}: the checkpoint has {} particles, its scene makes {}",
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
            refuse!("{label}: the checkpoint's angular table has the wrong length");
        }
        sys.carried_angular_acceleration.clear();
        for (i, a) in cp.angular.iter().enumerate() {
            sys.particles.angular_velocity[i] = mote_md::DVec3::new(a[0], a[1], a[2]);
            sys.carried_angular_acceleration
                .push(mote_md::DVec3::new(a[3], a[4], a[5]));
        }
    }
    let forces = &mut sim.forces;
    let count = forces.interactions.len();
    for (k, values) in &cp.carried {
        let Some(interaction) = forces.interactions.get_mut(*k) else {
            refuse!(
                "{label}: the checkpoint carries state for interaction {k}, the scene has {count}"
            );
        };
        interaction
            .restore_carried_state(values)
            .map_err(|m| FrontError::request(format!("{label}: {m}")))?;
    }
    Ok(())
}

/// Runs a point-particle input, or resumes `options.resume` when `input` is None.
pub(crate) fn run(
    input: Option<Input>,
    options: &RunOptions,
    monitor: &mut dyn Monitor,
) -> Result<Outcome, FrontError> {
    let resumed = match &options.resume {
        Some(path) => Some(checkpoint::read(path)?),
        None => None,
    };
    let (input, args) = match (&resumed, input) {
        (Some(cp), _) => restore(cp, options)?,
        (None, Some(input)) => (input, options.clone()),
        (None, None) => refuse!("no input to run"),
    };
    let scene = if input.plist {
        let system = match args.system.as_deref().unwrap_or("nbody") {
            "nbody" => PlistSystem::Nbody,
            "springs" => PlistSystem::Springs,
            other => refuse!("unknown --system '{other}': expected nbody or springs"),
        };
        let pf = mote_io::plist::parse(&input.text, &input.label)?;
        let solver = args.solver.clone().unwrap_or_else(|| "leapfrog".into());
        Scene::from_plist(&pf, system, &solver, &input.label)?
    } else {
        if args.system.is_some() {
            refuse!(
                "{}: --system chooses the model of an MPPphys particle file; a scene names its forces itself",
                input.label
            );
        }
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
        refuse!(
            "{}: no time step: give one with --dt (a particle file sets it with a 'dt' line)",
            input.label
        );
    }
    let (seed, chosen) = crate::seed::resolve(args.seed, scene.seed);
    let mut built = scene.build(&input.text, &input.label, seed)?;
    let length = match (args.steps, args.until, built.length) {
        (Some(n), _, _) => RunLength::Steps(n),
        (None, Some(t), _) => RunLength::Until(t),
        (None, None, Some(l)) => l,
        (None, None, None) => refuse!(
            "{}: no run length: give --until T or --steps N",
            input.label
        ),
    };
    if let (RunLength::Until(t), None) = (length, &resumed) {
        let t0 = built.simulation.system.time;
        if t <= t0 {
            refuse!(
                "{}: until {t}: the run starts at t = {t0}: nothing to run",
                input.label
            );
        }
    }
    let total_steps = length
        .steps_from(built.simulation.system.time, built.simulation.dt)
        .map_err(|e| FrontError::request(format!("{}: {e}", input.label)))?;
    if resumed.is_none() {
        mote_run::check_run_length(total_steps, built.simulation.dt, options.force)
            .map_err(|m| FrontError::request(format!("{}: {m}", input.label)))?;
    }

    let dir = input.output_dir(args.output.as_ref(), scene.output.dir.as_ref());
    if resumed.is_none() && !options.force {
        check_disk(
            &dir,
            &scene.output,
            total_steps,
            built.simulation.system.particles.len(),
        )
        .map_err(|m| FrontError::request(format!("{}: {m}", input.label)))?;
    }
    let folder = crate::lock::RunFolder::claim(
        &dir,
        &input.label,
        &input.text,
        resumed.as_ref().zip(options.resume.as_deref()),
    )?;
    let append = resumed.is_some();
    if let Some(cp) = &resumed {
        resume_state(cp, &mut built.simulation, &input.label)?;
    }
    let length =
        RunLength::Steps(total_steps - resumed.as_ref().map_or(0, |cp| cp.step.min(total_steps)));
    let provenance = crate::provenance(&input.label, seed);
    if let Some(cp) = &resumed {
        trim_outputs(&dir, cp.step, cp.time)?;
    }
    let out = &scene.output;
    let format = args.trajectory_format(
        out.trajectory_format(mote_io::Source::new(&input.label, &input.text))?,
    )?;
    let sim = &mut built.simulation;
    let mut driver = Driver::<Simulation>::new();
    driver.sample_at_start = !append;
    driver.live = args.live.take();
    driver.observers = file_observers(
        &scene,
        sim,
        &built.probes,
        &dir,
        &provenance,
        format,
        append,
    )?;
    if let Some(every) = args.checkpoint_every {
        let mut options = vec![
            ("name".to_string(), input.name.clone()),
            ("plist".to_string(), input.plist.to_string()),
            (
                "system".to_string(),
                args.system.clone().unwrap_or_else(|| "nbody".into()),
            ),
            ("total-steps".to_string(), total_steps.to_string()),
            ("checkpoint-every".to_string(), every.to_string()),
            ("dt".to_string(), hex(sim.dt)),
            ("output".to_string(), dir.display().to_string()),
            (
                "trajectory-format".to_string(),
                format.extension().to_string(),
            ),
        ];
        options.extend(folder.checkpoint_options());
        if let Some(s) = &args.solver {
            options.push(("solver".to_string(), s.clone()));
        }
        driver.checkpoints = Some(Checkpoints {
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
        });
    }

    let steps = length.steps_from(sim.system.time, sim.dt)?;
    let last_step = sim.system.step + steps;
    let propagator = if sim.brownian.is_some() {
        "Brownian dynamics".to_string()
    } else {
        sim.stepper.scheme.name().to_string()
    };
    monitor.start(&format!(
        "mote run {}: {} particles, {} with dt = {}, {} steps, {}, {}",
        input.label,
        sim.system.particles.len(),
        propagator,
        mote_io::system::human_number(sim.dt),
        steps,
        crate::seed_phrase(seed, chosen),
        crate::threads_phrase(),
    ));
    let result = driver.run(
        sim,
        |_| last_step,
        |sim| {
            let sys = &sim.system;
            if sys.step % 16 == 0 {
                monitor.progress(sys.step, last_step, &format!("t = {:.6e}", sys.time));
            }
        },
    );
    let mut outcome = Outcome {
        engine: Engine::Particles,
        seed,
        dir: dir.clone(),
        summary: Vec::new(),
        ending: Ending::Finished,
    };
    match result {
        Ok(report) => {
            outcome.summary.push(summary(&report, sim, &scene, &dir));
            if let Some(png) = &args.picture {
                let frame = mote_md::output::frame_of(&sim.system);
                mote_render::frame::picture(&frame, png, 1920, 1080)?;
                outcome
                    .summary
                    .push(format!("Picture of the final state: {}.", png.display()));
            }
        }
        Err(e @ MdError::Unstable { .. }) => outcome.ending = Ending::Unstable(e.to_string()),
        Err(e @ MdError::Interrupted { signal, .. }) => {
            outcome.ending = Ending::Interrupted {
                signal,
                message: e.to_string(),
            }
        }
        Err(e) => return Err(e.into()),
    }
    Ok(outcome)
}

/// The files a time-stepped run writes as it goes, by the scene's
/// `[output]`: observables.csv every `observables_every` steps (with the
/// pressure where the box is periodic and every interaction gives its
/// virial) and the trajectory every `trajectory_every` in `format`; with
/// `append`, onto the files of the run being resumed.
pub(crate) fn file_observers(
    scene: &Scene,
    sim: &Simulation,
    probes: &[mote_md::observe::Probe],
    dir: &Path,
    provenance: &mote_io::Provenance,
    format: mote_io::trajectory::Format,
    append: bool,
) -> Result<Vec<Box<dyn mote_run::Observer<Simulation>>>, FrontError> {
    let out = &scene.output;
    let mut observers: Vec<Box<dyn mote_run::Observer<Simulation>>> = Vec::new();
    if out.observables_every > 0 {
        let mut csv = ObservablesCsv::create(
            &dir.join("observables.csv"),
            provenance,
            scene.units,
            out.observables_every,
            probes.to_vec(),
            sim.system.boundary.periodic.iter().all(|p| *p)
                && sim.forces.without_virial().is_empty(),
            sim.forces.pressure_tensor,
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
        )?;
        // The viewer's first plot: what the dynamics leave to watch.
        let watched = if sim.brownian.is_some() {
            Some("potential_energy")
        } else if sim.thermostat.is_some() {
            Some("kT")
        } else {
            None
        };
        if let (Some(column), false) = (watched, append) {
            csv.suggest_plot(column)?;
        }
        observers.push(Box::new(csv));
    }
    if out.trajectory_every > 0 {
        observers.push(Box::new(Trajectory::create(
            &dir.join(format!("trajectory.{}", format.extension())),
            format,
            provenance.clone(),
            out.trajectory_every,
            append,
        )?));
    }
    Ok(observers)
}

/// The paragraph that ends a run. Overdamped (Brownian) runs have no
/// conserved energy, so they report the energies, not a drift.
fn summary(report: &RunReport, sim: &Simulation, scene: &Scene, dir: &Path) -> String {
    let secs = report.wall.as_secs_f64();
    let [_, t_unit, _, e_unit] = scene.units.labels();
    let files = if report.files.is_empty() {
        "no files (output switched off)".to_string()
    } else {
        report.files.join(", ")
    };
    let energy = if sim.brownian.is_some() {
        format!(
            "Overdamped dynamics conserve no energy: potential energy went from {:.9e} to {:.9e} {}.",
            report.initial.potential, report.last.potential, e_unit
        )
    } else if sim.thermostat.is_some() {
        // A bath exchanges energy with the system: a "drift" would mean
        // nothing; the temperature is what the thermostat holds.
        format!(
            "A thermostat exchanges energy with a bath (no drift to report): total energy went from {:.9e} to {:.9e} {}, k_B T from {:.6e} to {:.6e}.",
            report.initial.total_energy(),
            report.last.total_energy(),
            e_unit,
            report.initial.kt,
            report.last.kt,
        )
    } else {
        format!(
            "Total energy went from {:.9e} to {:.9e} {}: relative drift {:.3e} at the end, {:.3e} at most over the sampled instants.",
            report.initial.total_energy(),
            report.last.total_energy(),
            e_unit,
            rel(report.last.total_energy(), report.initial.total_energy()),
            sim.max_energy_error(),
        )
    };
    let without = sim.forces.without_virial();
    let pressure = if sim.system.boundary.periodic.iter().all(|p| *p) && !without.is_empty() {
        format!(
            " No pressure column: {} do{} not compute {} virial.",
            without.join(", "),
            if without.len() == 1 { "es" } else { "" },
            if without.len() == 1 { "its" } else { "their" }
        )
    } else {
        String::new()
    };
    format!(
        "Ran {} steps to t = {:.6e} {} in {:.3} s of wall time ({:.0} steps/s). {energy}{pressure} Output in {}: {}.",
        report.steps,
        report.last.time,
        t_unit,
        secs,
        report.steps as f64 / secs.max(1e-9),
        dir.display(),
        files
    )
}

/// Refuses a run whose files would not fit on the disk of `dir`: a lower
/// bound of what it writes (12 bytes a particle a trajectory frame, a
/// position in f32, the least any format writes; 100 bytes an observables
/// row) against the free space of the nearest folder that exists.
fn check_disk(
    dir: &Path,
    out: &mote_md::scene::OutputSettings,
    steps: u64,
    particles: usize,
) -> Result<(), String> {
    // Every `every` steps and at the start; never where `every` is 0.
    let frames = |every: u64| steps.checked_div(every).map_or(0.0, |n| (n + 1) as f64);
    let bytes = frames(out.trajectory_every) * particles as f64 * 12.0
        + frames(out.observables_every) * 100.0;
    let existing = dir
        .ancestors()
        .find(|p| p.exists())
        .unwrap_or(Path::new("."));
    match mote_io::system::free_disk(existing) {
        Some(free) if bytes > free as f64 => Err(format!(
            "the run writes at least {} into {} ({} steps, {particles} particles) and its disk has {} free; \
             write less often ([output] trajectory_every), or give --force",
            mote_io::system::human_bytes(bytes),
            dir.display(),
            steps,
            mote_io::system::human_bytes(free as f64)
        )),
        _ => Ok(()),
    }
}

fn rel(e: f64, e0: f64) -> f64 {
    if e0 != 0.0 {
        (e - e0).abs() / e0.abs()
    } else {
        (e - e0).abs()
    }
}
