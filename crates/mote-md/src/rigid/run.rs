//! Rigid runs: the FRBI as a [`Propagator`] of mote's one loop, the
//! observers that write a rigid run's files (observables.csv with
//! translational and rotational energy apart and the force on each wall;
//! the spheres as extended XYZ), checkpoints of bodies and contact
//! histories, and [`run_rigid_scene`], which puts them together.

use std::path::PathBuf;
use std::sync::Arc;

use glam::DVec3;
use mote_io::checkpoint::Checkpoint;
use mote_io::csv::CsvWriter;
use mote_io::trajectory::TrajectoryWriter;
use mote_io::xyz::Frame;
use mote_io::{ParseError, Provenance};
use mote_run::{Checkpoints, Driver, Observer, Propagator};

use super::bodies::RigidBodies;
use super::contacts::RigidContacts;
use super::frbi::Frbi;
use super::scene::RigidScene;
use crate::error::MdError;

/// What a caller changes about a rigid scene's run; `None` keeps the scene's.
#[derive(Debug, Clone, Default)]
pub struct RigidRun {
    /// Replaces the scene's seed (the scene's, else 1, when absent).
    pub seed: Option<u64>,
    /// Replaces `[output] dir`.
    pub out_dir: Option<PathBuf>,
    /// Replaces `[run] dt`.
    pub dt: Option<f64>,
    /// Replaces the run length by a number of steps.
    pub steps: Option<u64>,
    /// Replaces the run length by an end time (to the first step at or
    /// past it, [`mote_run::steps_until`]).
    pub until: Option<f64>,
    /// Run even where that is more than [`mote_run::MAX_STEPS`] steps.
    pub force: bool,
    /// Write checkpoints on this schedule (the template holds the run's
    /// input and options; the time step and the run's length are added).
    pub checkpoints: Option<Checkpoints>,
    /// Continue this checkpoint's run (its scene, seed, dt and length must
    /// be those given), appending to the files an earlier run wrote.
    pub resume: Option<Checkpoint>,
    /// Replaces `[output] trajectory_format`.
    pub trajectory_format: Option<mote_io::trajectory::Format>,
    /// The live viewer's tap, if the run is watched.
    pub live: mote_run::LiveSlot,
}

/// Steps from t = 0 to the first step at or past `t` (the rule of every
/// engine, [`mote_run::steps_until`]).
pub(crate) fn steps_until(t: f64, dt: f64) -> Result<u64, MdError> {
    mote_run::steps_until(0.0, t, dt).ok_or_else(|| {
        MdError::Length(format!(
            "until {t} with dt = {dt:e}: not a number of steps a run can take"
        ))
    })
}

/// Rigid bodies moved by the FRBI with a fixed step.
pub struct RigidDynamics {
    pub bodies: RigidBodies,
    pub frbi: Frbi,
    /// The contact model (shared with the integrator), for the wall forces.
    pub contacts: Option<Arc<RigidContacts>>,
    pub dt: f64,
    /// Steps taken since the bodies were placed.
    pub step: u64,
    /// The last step of the run (recorded in checkpoints).
    pub last_step: u64,
}

impl RigidDynamics {
    /// The bodies and integrator a scene built, before their first step.
    pub fn new(built: super::scene::BuiltRigid) -> Self {
        RigidDynamics {
            bodies: built.bodies,
            frbi: built.frbi,
            contacts: built.contacts,
            dt: built.dt,
            step: 0,
            last_step: built.steps,
        }
    }
}

/// The observables of the bodies at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidSample {
    pub time: f64,
    pub translational_energy: f64,
    pub rotational_energy: f64,
    pub potential_energy: f64,
    pub linear_momentum: DVec3,
    pub angular_momentum: DVec3,
    /// The force on each wall, F = −Σ (contact forces of the spheres on it).
    pub wall_forces: Vec<(String, DVec3)>,
}

impl RigidSample {
    pub fn kinetic_energy(&self) -> f64 {
        self.translational_energy + self.rotational_energy
    }
}

impl Propagator for RigidDynamics {
    type Sample = RigidSample;
    type Error = MdError;

    fn step(&self) -> u64 {
        self.step
    }

    fn time(&self) -> f64 {
        self.bodies.time
    }

    fn advance(&mut self) -> Result<(), MdError> {
        self.frbi.step(&mut self.bodies, self.dt);
        self.step += 1;
        Ok(())
    }

    fn unstable(&self) -> Option<(usize, String)> {
        let b = &self.bodies;
        let (column, i) =
            crate::simulation::first_non_finite(&[&b.position, &b.velocity, &b.omega])?;
        let what = [
            "a non-finite position",
            "a non-finite velocity",
            "a non-finite spin",
        ][column];
        Some((
            i,
            format!(
                "{what} (x {}, v {}, ω {})",
                b.position[i], b.velocity[i], b.omega[i]
            ),
        ))
    }

    fn measure(&mut self) -> RigidSample {
        let e = self.frbi.energies(&self.bodies);
        let o = self.bodies.observables();
        RigidSample {
            time: self.bodies.time,
            translational_energy: o.translational_energy,
            rotational_energy: o.rotational_energy,
            potential_energy: e.potential,
            linear_momentum: o.linear_momentum,
            angular_momentum: o.angular_momentum,
            wall_forces: self
                .contacts
                .as_ref()
                .map(|c| c.wall_forces())
                .unwrap_or_default(),
        }
    }

    fn frame(&self) -> Option<Frame> {
        Some(self.sphere_frame())
    }

    /// The force on each sphere's body at the last step's midpoint (each
    /// sphere of a body shows its body's).
    fn forces(&self) -> Vec<[f64; 3]> {
        let w = self.frbi.last_wrenches();
        if w.len() != self.bodies.len() {
            return Vec::new();
        }
        let mut world = super::interaction::WorldFrame::default();
        world.update(&self.bodies);
        world
            .sphere_body
            .iter()
            .map(|&k| w[k as usize].v.to_array())
            .collect()
    }

    fn walls(&self) -> Vec<mote_run::WallGeometry> {
        let t = self.bodies.time;
        self.contacts
            .iter()
            .flat_map(|c| c.walls.iter().map(move |w| w.geometry(t)))
            .collect()
    }

    /// Δt is the integrator's; fields and drag go to the interaction that
    /// owns them. Rigid runs have no thermostat.
    fn change(&mut self, change: &mote_run::Change) -> Result<String, String> {
        if let mote_run::Change::Dt(dt) = change {
            let text = format!("dt {} → {dt}", self.dt);
            self.dt = *dt;
            return Ok(text);
        }
        self.frbi
            .interactions_mut()
            .iter_mut()
            .find_map(|i| i.steer(change))
            .unwrap_or_else(|| Err(format!("{}: the scene has none", change.what())))
    }

    /// The bodies (the angular table holds the rotation vector r and ω),
    /// the contact histories, and the resolved `dt` and `total-steps`.
    fn save(&mut self, cp: &mut Checkpoint) -> Result<(), MdError> {
        let b = &self.bodies;
        cp.options.retain(|(k, _)| k != "dt" && k != "total-steps");
        cp.options
            .push(("dt".into(), mote_io::checkpoint::hex(self.dt)));
        cp.options
            .push(("total-steps".into(), self.last_step.to_string()));
        cp.time = b.time;
        cp.step = self.step;
        cp.positions = b.position.iter().map(|x| x.to_array()).collect();
        cp.velocities = b.velocity.iter().map(|v| v.to_array()).collect();
        cp.angular = b
            .rotation
            .iter()
            .zip(&b.omega)
            .map(|(r, w)| [r.x, r.y, r.z, w.x, w.y, w.z])
            .collect();
        cp.carried = self.frbi.carried_state();
        Ok(())
    }
}

impl RigidDynamics {
    /// Puts a checkpoint's state into freshly built bodies and integrator.
    pub fn resume(&mut self, cp: &Checkpoint, label: &str) -> Result<(), MdError> {
        let b = &mut self.bodies;
        let n = b.len();
        if cp.positions.len() != n || cp.velocities.len() != n || cp.angular.len() != n {
            return Err(ParseError::new(
                label,
                0,
                format!(
                    "the checkpoint holds {} bodies, the scene makes {n}",
                    cp.positions.len()
                ),
            )
            .into());
        }
        for i in 0..n {
            b.position[i] = DVec3::from(cp.positions[i]);
            b.velocity[i] = DVec3::from(cp.velocities[i]);
            let a = cp.angular[i];
            b.rotation[i] = DVec3::new(a[0], a[1], a[2]);
            b.omega[i] = DVec3::new(a[3], a[4], a[5]);
        }
        b.time = cp.time;
        self.step = cp.step;
        self.frbi
            .restore_carried_state(&cp.carried)
            .map_err(|m| ParseError::new(label, 0, format!("checkpoint: {m}")))?;
        Ok(())
    }
}

/// observables.csv of a rigid run: time, kinetic (translational +
/// rotational), translational, rotational, potential and total energy,
/// momentum, angular momentum (the first twelve of the point-particle
/// engine's columns, by the same names), the force on each wall.
pub struct RigidCsv {
    writer: CsvWriter,
    every: u64,
}

impl RigidCsv {
    pub fn create(
        path: &std::path::Path,
        provenance: &Provenance,
        walls: &[String],
        every: u64,
        append: bool,
    ) -> Result<Self, MdError> {
        // The point-particle engine's words for the same quantities.
        let mut columns: Vec<String> = crate::Observables::COLUMNS[..12]
            .iter()
            .map(|s| s.to_string())
            .collect();
        for w in walls {
            for a in ["x", "y", "z"] {
                columns.push(format!("{w}.f{a}"));
            }
        }
        let writer = if append {
            CsvWriter::append(path, columns.len())?
        } else {
            CsvWriter::create(path, provenance, &columns, &[])?
        };
        Ok(RigidCsv { writer, every })
    }
}

impl Observer<RigidDynamics> for RigidCsv {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, _: &RigidDynamics, s: &RigidSample) -> Result<(), MdError> {
        let mut row = vec![
            s.time,
            s.kinetic_energy(),
            s.translational_energy,
            s.rotational_energy,
            s.potential_energy,
            s.kinetic_energy() + s.potential_energy,
        ];
        row.extend(s.linear_momentum.to_array());
        row.extend(s.angular_momentum.to_array());
        for (_, f) in &s.wall_forces {
            row.extend(f.to_array());
        }
        Ok(self.writer.row(&row)?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }

    fn event(&mut self, d: &RigidDynamics, text: &str) -> Result<(), MdError> {
        Ok(self
            .writer
            .comment(&crate::output::event_line(d.step, d.bodies.time, text))?)
    }
}

/// trajectory.xyz of a rigid run: the spheres of every body.
pub struct SphereTrajectory {
    writer: TrajectoryWriter,
    every: u64,
}

impl Observer<RigidDynamics> for SphereTrajectory {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, d: &RigidDynamics, _: &RigidSample) -> Result<(), MdError> {
        Ok(self.writer.write(d.step, &d.sphere_frame())?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }
}

/// The spheres of every body as an extended-XYZ frame: world positions,
/// velocities v + ω × (c − x), radii; species `B<kind>`.
/// Each sphere's share of its body's mass, in proportion to its volume
/// (so a body's spheres add up to its mass; overlaps are shared).
fn sphere_masses(b: &RigidBodies, world: &super::interaction::WorldFrame) -> Vec<f64> {
    let cube = |r: f64| r * r * r;
    world
        .sphere_body
        .iter()
        .zip(&world.sphere_radius)
        .map(|(&k, &r)| {
            let t = &b.templates[b.kind[k as usize] as usize];
            let total: f64 = t.radii.iter().map(|&s| cube(s)).sum();
            t.props.mass * cube(r) / total
        })
        .collect()
}

impl RigidDynamics {
    /// The spheres as a frame: in the periodic box of the contacts, if
    /// any, each body moved whole into it ([`sphere_frame_in`]).
    pub fn sphere_frame(&self) -> Frame {
        match &self.contacts {
            Some(c) if c.boundary.is_periodic() => sphere_frame_in(&self.bodies, &c.boundary),
            _ => sphere_frame(&self.bodies),
        }
    }
}

/// [`sphere_frame`] in a periodic box: each body is shifted by whole
/// periods so that its centre of mass lies in the box (its spheres may
/// stick out), and the frame's cell and `pbc` are the box's.
pub fn sphere_frame_in(b: &RigidBodies, boundary: &crate::boundary::Boundary) -> Frame {
    let mut frame = sphere_frame(b);
    let shift: Vec<DVec3> = b.position.iter().map(|x| boundary.wrap(*x) - *x).collect();
    for (p, &k) in frame.positions.iter_mut().zip(&frame.bodies) {
        let s = shift[k as usize];
        for d in 0..3 {
            p[d] += s[d];
        }
    }
    // Along open axes nothing moved: the bounding cell stays.
    let l = boundary.lengths();
    for d in 0..3 {
        if l[d].is_finite() {
            frame.cell[d][d] = l[d];
            frame.origin[d] = boundary.lo[d];
        }
    }
    frame.pbc = boundary.periodic;
    frame
}

pub fn sphere_frame(b: &RigidBodies) -> Frame {
    let mut world = super::interaction::WorldFrame::default();
    world.update(b);
    let positions: Vec<[f64; 3]> = world.sphere_centre.iter().map(|c| c.to_array()).collect();
    let velocities: Vec<[f64; 3]> = world
        .sphere_centre
        .iter()
        .zip(&world.sphere_body)
        .map(|(c, &k)| {
            let k = k as usize;
            (b.velocity[k] + b.omega[k].cross(*c - b.position[k])).to_array()
        })
        .collect();
    // A margin of the largest sphere's radius: the scene's own scale (a
    // fixed 1 made a box of metres around micrometre beads).
    let pad = world.sphere_radius.iter().copied().fold(0.0, f64::max);
    let (cell, origin) = Frame::bounding_cell(&positions, &world.sphere_radius, pad);
    Frame {
        time: b.time,
        cell,
        origin,
        pbc: [false; 3],
        // "X" is ASE's dummy element; the body column says which clump.
        species: vec!["X".to_string(); positions.len()],
        masses: sphere_masses(b, &world),
        bodies: world.sphere_body.iter().map(|&k| u64::from(k)).collect(),
        angular_velocities: world
            .sphere_body
            .iter()
            .map(|&k| b.omega[k as usize].to_array())
            .collect(),
        // The body's orientation: rotation vector r = n tan(φ/2) as the
        // unit quaternion (cos φ/2, n sin φ/2) = (1, r)/√(1 + r²).
        orientations: world
            .sphere_body
            .iter()
            .map(|&k| {
                let r = b.rotation[k as usize];
                let c = 1.0 / (1.0 + r.length_squared()).sqrt();
                [c, r.x * c, r.y * c, r.z * c]
            })
            .collect(),
        positions,
        velocities,
        radii: world.sphere_radius.clone(),
        ..Frame::default()
    }
}

/// What a rigid run did.
#[derive(Debug, Clone)]
pub struct Report {
    pub bodies: usize,
    pub spheres: usize,
    pub steps: u64,
    pub time: f64,
    pub wall_seconds: f64,
    pub kinetic_energy: f64,
    pub potential_energy: f64,
    pub linear_momentum: DVec3,
    pub angular_momentum: DVec3,
    /// The force on each wall at the last step.
    pub wall_forces: Vec<(String, DVec3)>,
    pub files: Vec<PathBuf>,
    pub seed: u64,
    pub dt: f64,
    /// The spheres at the end (for a picture).
    pub final_frame: Frame,
}

/// Runs a rigid scene: `text` is the TOML, `file_label` locates errors and
/// goes into the provenance headers, `options` replace the scene's seed,
/// output folder, time step or run length. Writes `observables.csv` and,
/// with `trajectory_every` > 0, `trajectory.xyz` (the spheres). Calls
/// `progress(step, last step, time)` after every step.
pub fn run_rigid_scene(
    text: &str,
    file_label: &str,
    options: &RigidRun,
    mut progress: impl FnMut(u64, u64, f64),
) -> Result<Report, MdError> {
    let scene = RigidScene::parse(text, file_label)?;
    let mut built = scene.build(text, file_label, options.seed)?;
    if let Some(dt) = options.dt {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(
                ParseError::new(file_label, 0, format!("time step {dt}: must be > 0")).into(),
            );
        }
        if let Some(t) = scene.run.get_ref().until {
            built.steps = steps_until(t, dt)?;
        }
        built.dt = dt;
    }
    if let Some(n) = options.steps {
        built.steps = n;
    } else if let Some(t) = options.until {
        built.steps = steps_until(t, built.dt)?;
    }
    if options.resume.is_none() {
        mote_run::check_run_length(built.steps, built.dt, options.force)
            .map_err(|m| MdError::Length(format!("{file_label}: {m}")))?;
    }
    let dir = options
        .out_dir
        .clone()
        .or_else(|| scene.output.dir.as_ref().map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("out"));
    std::fs::create_dir_all(&dir).map_err(|e| mote_io::IoError::os(&dir, e))?;
    let provenance = Provenance {
        program: format!("mote {}", env!("CARGO_PKG_VERSION")),
        scene: file_label.to_string(),
        seed: built.seed,
    };
    let walls: Vec<String> = built
        .contacts
        .as_ref()
        .map(|c| c.walls.iter().map(|w| w.name.clone()).collect())
        .unwrap_or_default();
    let append = options.resume.is_some();
    let mut driver = Driver::new();
    driver.live = options.live.take();
    driver.observers.push(Box::new(RigidCsv::create(
        &dir.join("observables.csv"),
        &provenance,
        &walls,
        scene.output.observables_every.max(1),
        append,
    )?));
    if scene.output.trajectory_every > 0 {
        let format = match options.trajectory_format {
            Some(f) => f,
            None => scene
                .output
                .trajectory_format(mote_io::Source::new(file_label, text))?,
        };
        let p = dir.join(format!("trajectory.{}", format.extension()));
        driver.observers.push(Box::new(SphereTrajectory {
            writer: if append {
                TrajectoryWriter::append(&p, format, provenance.clone(), false)?
            } else {
                TrajectoryWriter::create(&p, format, provenance.clone(), false)?
            },
            every: scene.output.trajectory_every,
        }));
    }
    if let Some((probe, every)) = built.nip.take() {
        driver.observers.push(Box::new(super::nip::NipCsv::create(
            &dir.join("nip.csv"),
            &provenance,
            probe,
            every,
            append,
        )?));
    }
    driver.checkpoints = options.checkpoints.clone();
    driver.sample_at_start = !append;
    let (seed, dt, last_step) = (built.seed, built.dt, built.steps);
    let mut dynamics = RigidDynamics::new(built);
    if let Some(cp) = &options.resume {
        dynamics.resume(cp, file_label)?;
    }
    let report = driver.run(
        &mut dynamics,
        |_| last_step,
        |d| progress(d.step, last_step, d.bodies.time),
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
        files: report.files.iter().map(PathBuf::from).collect(),
        seed,
        dt,
        final_frame: dynamics.sphere_frame(),
    })
}
