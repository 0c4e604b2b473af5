//! Point-particle runs: fixed-step integrators and Brownian dynamics
//! (`mote_md::Simulation`), from a scene, a particle file or a checkpoint.

use std::path::Path;

use mote_io::checkpoint::{self, Checkpoint};
use mote_io::trajectory::Format;
use mote_md::output::ObservablesCsv;
use mote_md::scene::{Origin, PlistSystem, Scene, Setting};
use mote_md::{MdError, RunLength, RunReport, Simulation};
use mote_run::Observer;

use crate::checkpoints::{hex, restore};
use crate::error::{refuse, FrontError};
use crate::runner::{run_engine, Done, EngineRun, RunFiles};
use crate::{Ending, Engine, Input, Monitor, Outcome, RunOptions};

/// Puts the checkpoint's state into the freshly built simulation.
pub fn resume_state(
    cp: &Checkpoint,
    sim: &mut mote_md::Simulation,
    label: &str,
) -> Result<(), FrontError> {
    sim.check_order(cp)
        .map_err(|m| FrontError::request(format!("{label}: {m}")))?;
    // Particles that came and went: the checkpoint's set first.
    sim.restore_flow(cp)
        .map_err(|m| FrontError::request(format!("{label}: {m}")))?;
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
    let keys = forces.carried_keys();
    let interactions_only = Checkpoint {
        carried: (cp.carried.iter())
            .filter(|(k, _)| {
                k != mote_md::simulation::FLOW_KEY && k != mote_md::simulation::ORDER_KEY
            })
            .cloned()
            .collect(),
        ..Checkpoint::default()
    };
    let matched = mote_io::checkpoint::match_carried(&interactions_only, &keys)
        .map_err(|m| FrontError::request(format!("{label}: {m}")))?;
    for (k, values) in matched {
        forces.interactions[k]
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
            scene.run.integrator = Some(Setting::from_option("--solver", s.clone()));
        }
        scene
    };
    let mut scene = scene;
    scene.run.with_options(args.dt, args.steps, args.until);
    if scene.run.dt.is_none() {
        refuse!(
            "{}: no time step: give one with --dt (a particle file sets it with a 'dt' line)",
            input.label
        );
    }
    let format = args.trajectory_format(
        scene
            .output
            .trajectory_format(mote_io::Source::new(&input.label, &input.text))?,
    )?;
    let engine = PointsRun {
        scene,
        input: input.clone(),
        args: args.clone(),
        format,
        probes: Vec::new(),
        total_steps: 0,
        last_step: 0,
    };
    run_engine(engine, &input, &args, resumed.as_ref(), monitor)
}

/// A time-stepped scene's part of the one run.
struct PointsRun {
    scene: Scene,
    input: Input,
    /// The options, or those of the run a checkpoint continues.
    args: RunOptions,
    format: mote_io::trajectory::Format,
    probes: Vec<mote_md::observe::Probe>,
    /// Steps of the whole run, from its start (before any resume).
    total_steps: u64,
    last_step: u64,
}

impl EngineRun for PointsRun {
    type State = Simulation;
    const ENGINE: Engine = Engine::Particles;
    const NAME: &'static str = "particles";

    fn scene_seed(&self) -> Option<u64> {
        self.scene.seed
    }

    fn scene_dir(&self) -> Option<&String> {
        self.scene.output.dir.as_ref()
    }

    /// The scene built with `seed` and its length resolved (the options'
    /// `--steps` or `--until`, else the scene's), the checkpoint's state
    /// put in when resuming.
    fn build(&mut self, seed: u64, resumed: Option<&Checkpoint>) -> Result<Simulation, FrontError> {
        if let Some(cp) = resumed {
            self.scene.keep_order_of(cp);
        }
        let (args, label) = (&self.args, &self.input.label);
        let built = self.scene.build(&self.input.text, label, seed)?;
        let Some(length) = built.length else {
            refuse!("{label}: no run length: give --until T or --steps N")
        };
        // Where the length was given, for its messages: an option, or the
        // line of the scene's [run] key.
        let run = &self.scene.run;
        let origin = run.steps.as_ref().map(|s| &s.origin);
        let given = match origin.or(run.until.as_ref().map(|t| &t.origin)) {
            Some(Origin::Scene(span)) => {
                let source = mote_io::Source::new(label, &self.input.text);
                format!("{label}:{}", source.line_of(span.start))
            }
            _ => label.to_string(),
        };
        let mut sim = built.simulation;
        if let (RunLength::Until(t), None) = (length, resumed) {
            let t0 = sim.system.time;
            if t <= t0 {
                refuse!("{label}: until {t}: the run starts at t = {t0}: nothing to run");
            }
        }
        self.total_steps = length
            .steps_from(sim.system.time, sim.dt)
            .map_err(|e| FrontError::request(format!("{given}: {e}")))?;
        if resumed.is_none() {
            mote_run::check_run_length(self.total_steps, sim.dt, args.force)
                .map_err(|m| FrontError::request(format!("{given}: {m}")))?;
        }
        if let Some(cp) = resumed {
            resume_state(cp, &mut sim, label)?;
        }
        if let Some(ranks) = args.ranks.as_ref().filter(|r| r.0.size() > 1) {
            if !built.probes.is_empty() {
                refuse!(
                    "{label}: the particle inspector ([output] inspect) does not run on {} ranks yet: run it on one",
                    ranks.0.size()
                );
            }
            let parallel = self.scene.parallel.as_ref();
            let grid = parallel.and_then(|p| p.get_ref().grid);
            sim.decompose(ranks.0.clone(), grid).map_err(|m| {
                let at = match parallel.filter(|_| grid.is_some()) {
                    Some(p) => {
                        let source = mote_io::Source::new(label, &self.input.text);
                        format!(
                            "{label}:{}: [parallel] grid",
                            source.line_of(p.span().start)
                        )
                    }
                    None => label.to_string(),
                };
                FrontError::request(format!("{at}: {m}"))
            })?;
            if let (Some(domain), Some(b)) = (
                sim.forces.domain.as_mut(),
                parallel.and_then(|p| p.get_ref().balance),
            ) {
                domain.balance = b;
            }
        }
        let done = resumed.map_or(0, |cp| cp.step.min(self.total_steps));
        self.last_step = sim.system.step + (self.total_steps - done);
        self.probes = built.probes;
        Ok(sim)
    }

    fn check_folder(&self, sim: &Simulation, dir: &Path) -> Result<(), FrontError> {
        check_disk(
            dir,
            &self.scene.output,
            self.total_steps,
            sim.particle_count(),
        )
        .map_err(|m| FrontError::request(format!("{}: {m}", self.input.label)))
    }

    fn observers(
        &self,
        sim: &Simulation,
        files: &RunFiles,
    ) -> Result<Vec<Box<dyn Observer<Simulation>>>, FrontError> {
        table_observers(&self.scene, sim, &self.probes, files)
    }

    fn table_every(&self) -> Vec<u64> {
        let every = self.scene.output.observables_every();
        (every > 0).then_some(every).into_iter().collect()
    }

    fn trajectory(&self) -> Result<Option<(String, Format, u64)>, FrontError> {
        Ok(crate::runner::scene_trajectory(
            self.scene.output.trajectory_every(),
            self.format,
        ))
    }

    fn checkpoint_options(&self, sim: &Simulation) -> Vec<(String, String)> {
        let mut options = vec![
            (
                "system".to_string(),
                self.args.system.clone().unwrap_or_else(|| "nbody".into()),
            ),
            ("total-steps".to_string(), self.total_steps.to_string()),
            ("dt".to_string(), hex(sim.dt)),
        ];
        if let Some(s) = &self.args.solver {
            options.push(("solver".to_string(), s.clone()));
        }
        options
    }

    fn last_step(&self, _: &Simulation) -> u64 {
        self.last_step
    }

    fn opening(&self, sim: &Simulation) -> String {
        let propagator = if sim.brownian.is_some() {
            "Brownian dynamics".to_string()
        } else {
            sim.stepper.scheme.name().to_string()
        };
        let ranks = sim.forces.domain.as_ref().map_or(String::new(), |d| {
            let [x, y, z] = d.bricks.dims;
            format!(", on {} ranks ({x} × {y} × {z} bricks)", d.comm().size())
        });
        format!(
            "{} particles, {} with dt = {}, {} steps{ranks}",
            sim.particle_count(),
            propagator,
            mote_io::system::human_number(sim.dt),
            self.last_step - sim.system.step,
        )
    }

    fn ending(&self, _: &mut Self::State, e: MdError) -> Result<Ending, FrontError> {
        crate::rigid::md_ending(e)
    }

    fn summary(
        &self,
        sim: &Simulation,
        report: &RunReport,
        done: &Done,
    ) -> Result<Vec<String>, FrontError> {
        let mut lines = vec![summary(report, sim, &self.scene, &done.files.dir)];
        if let Some(flow) = &sim.flow {
            lines.push(flow.summary(sim.system.particles.len()));
        }
        // Every rank takes part in the census; rank 0 says it.
        if let Some(domain) = sim.forces.domain.as_ref() {
            if let Some(census) = domain.census() {
                lines.push(ranks_sentence(&census, domain.shifts));
            }
        }
        Ok(lines)
    }
}

/// "Ranks: particles 15 998–16 002 a rank (…), ghosts …, … migrated.": how a
/// decomposed run's particles and ghosts were spread over its ranks.
fn ranks_sentence(census: &[[u64; 3]], shifts: u64) -> String {
    let range = |k: usize| {
        let lo = census.iter().map(|c| c[k]).min().unwrap_or(0);
        let hi = census.iter().map(|c| c[k]).max().unwrap_or(0);
        if lo == hi {
            format!("{lo}")
        } else {
            format!("{lo}–{hi}")
        }
    };
    let moved: u64 = census.iter().map(|c| c[2]).sum();
    let shifted = match shifts {
        0 => String::new(),
        1 => " The cuts between bricks shifted once to balance them.".to_string(),
        n => format!(" The cuts between bricks shifted {n} times to balance them."),
    };
    format!(
        "Ranks: {} particles a rank at the end, {} ghosts a rank at the last list build; \
         {moved} particles changed rank.{shifted}",
        range(0),
        range(1)
    )
}

/// The tables a time-stepped run writes as it goes, by the scene's
/// `[output]`: observables.csv every `observables_every` steps (with the
/// pressure where the box is periodic and every interaction gives its
/// virial); with `files.append`, onto the table of the run being resumed.
/// The trajectory is the run's own (`mote_run::Trajectory`).
pub(crate) fn table_observers(
    scene: &Scene,
    sim: &Simulation,
    probes: &[mote_md::observe::Probe],
    files: &RunFiles,
) -> Result<Vec<Box<dyn mote_run::Observer<Simulation>>>, FrontError> {
    let (dir, provenance, append) = (&files.dir, &files.provenance, files.append);
    let out = &scene.output;
    let mut observers: Vec<Box<dyn mote_run::Observer<Simulation>>> = Vec::new();
    if out.observables_every() > 0 {
        let mut csv = ObservablesCsv::create(
            &dir.join("observables.csv"),
            provenance,
            scene.units,
            out.observables_every(),
            probes.to_vec(),
            sim.system.boundary.periodic.iter().all(|p| *p)
                && sim.forces.without_virial().is_empty(),
            sim.forces.pressure_tensor,
            &sim.forces
                .interactions
                .iter()
                .filter_map(|i| i.viewer())
                .flat_map(|v| v.wall_forces())
                .map(|w| w.0)
                .collect::<Vec<_>>(),
            sim.system
                .particles
                .dipole
                .iter()
                .any(|m| *m != mote_md::DVec3::ZERO),
            sim.flow.as_ref(),
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
    // What left through the outlets, particle by particle.
    if let Some(flow) = sim.flow.as_ref().filter(|f| !f.outlets.is_empty()) {
        observers.push(Box::new(mote_md::output::OutflowCsv::create(
            &dir.join("outflow.csv"),
            provenance,
            scene.units,
            &flow.outlets,
            flow.every,
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
    } else if sim.flow.is_some() {
        // Particles carry energy in and out: no drift to report.
        format!(
            "Particles come and go, carrying energy in and out (no drift to report): total energy went from {:.9e} to {:.9e} {}.",
            report.initial.total_energy(),
            report.last.total_energy(),
            e_unit,
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
        format!(" {}", crate::no_pressure_column(&without))
    } else {
        String::new()
    };
    let solvers: String = sim
        .forces
        .interactions
        .iter()
        .filter_map(|i| i.describe())
        .map(|d| format!(" {d}"))
        .collect();
    format!(
        "Ran {} steps to t = {:.6e} {} in {:.3} s of wall time ({:.0} steps/s). {energy}{pressure}{solvers} Output in {}: {}. {}",
        report.steps,
        report.last.time,
        t_unit,
        secs,
        report.steps as f64 / secs.max(1e-9),
        dir.display(),
        files,
        sim.breakdown(report.wall).sentence(),
    )
}

/// Refuses a run whose files would not fit on the disk of `dir`: a lower
/// bound of what it writes (12 bytes a particle a trajectory frame, a
/// position in f32, the least any format writes; 100 bytes an observables
/// row) against the free space of the nearest folder that exists.
fn check_disk(
    dir: &Path,
    out: &mote_md::scene::OutputTable,
    steps: u64,
    particles: usize,
) -> Result<(), String> {
    // Every `every` steps and at the start; never where `every` is 0.
    let frames = |every: u64| steps.checked_div(every).map_or(0.0, |n| (n + 1) as f64);
    let bytes = frames(out.trajectory_every()) * particles as f64 * 12.0
        + frames(out.observables_every()) * 100.0;
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
