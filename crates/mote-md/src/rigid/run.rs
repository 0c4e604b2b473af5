//! Rigid runs: the FRBI as a [`Propagator`] of mote's one loop, the
//! observers that write a rigid run's files (observables.csv with
//! translational and rotational energy apart and the force on each wall;
//! the spheres as extended XYZ) and checkpoints of bodies and contact
//! histories. The run is put together by the front (mote-front's rigid.rs),
//! as every engine's is.

use glam::DVec3;
use mote_io::checkpoint::Checkpoint;
use mote_io::csv::CsvWriter;
use mote_io::xyz::Frame;
use mote_io::{ParseError, Provenance};
use mote_run::{Observer, Propagator};

use super::bodies::RigidBodies;
use super::contacts::RigidContacts;
use super::flow::BodyFlow;
use super::frbi::Frbi;
use crate::error::MdError;
use crate::simulation::{FLOW_KEY, ORDER_KEY};

/// Rigid bodies moved by the FRBI with a fixed step.
pub struct RigidDynamics {
    pub bodies: RigidBodies,
    pub frbi: Frbi,
    pub dt: f64,
    /// Steps taken since the bodies were placed.
    pub step: u64,
    /// The last step of the run (recorded in checkpoints).
    pub last_step: u64,
    /// Wall time spent stepping (the FRBI's timing says how much of it
    /// went to each interaction).
    pub stepping: std::time::Duration,
    /// Bodies inserted and taken out every `flow.every` steps, after the
    /// step ([`crate::rigid::flow`]).
    pub flow: Option<BodyFlow>,
    /// The run's seed (the flow's random numbers).
    pub seed: u64,
}

impl RigidDynamics {
    /// The contact model the integrator owns, if any (wall forces, the
    /// periodic box).
    pub fn contacts(&self) -> Option<&RigidContacts> {
        self.frbi.find()
    }

    /// The volume of the box a pressure is measured in: the contacts' box,
    /// when it is periodic on every axis.
    pub fn pressure_volume(&self) -> Option<f64> {
        let b = &self.contacts()?.boundary;
        (b.periodic.iter().all(|p| *p) && b.volume().is_finite()).then(|| b.volume())
    }

    /// The interactions that cannot give a virial (none: the pressure is
    /// measured wherever the box is periodic).
    pub fn without_virial(&mut self) -> Vec<String> {
        self.frbi.virial(&self.bodies).err().unwrap_or_default()
    }

    /// The pressure P = (Σ_I M_I V_I² + W)/3V of the bodies in a periodic
    /// box, W the molecular (body-centre) virial; NaN where it is not
    /// measured (no periodic box, or an interaction without a virial).
    fn pressure(&mut self, translational_energy: f64) -> f64 {
        let Some(volume) = self.pressure_volume() else {
            return f64::NAN;
        };
        match self.frbi.virial(&self.bodies) {
            Ok(w) => (2.0 * translational_energy + w) / (3.0 * volume),
            Err(_) => f64::NAN,
        }
    }

    /// The bodies and integrator a scene built, before their first step.
    pub fn new(built: super::scene::BuiltRigid) -> Self {
        RigidDynamics {
            bodies: built.bodies,
            frbi: built.frbi,
            dt: built.dt,
            step: 0,
            last_step: built.steps,
            stepping: std::time::Duration::ZERO,
            flow: built.flow,
            seed: built.seed,
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
    /// The pressure in a periodic box ([`RigidDynamics::pressure_volume`]);
    /// NaN where it is not measured.
    pub pressure: f64,
    /// The bodies held, and where bodies come and go, what came and went
    /// ([`BodyFlow::columns`]).
    pub held: usize,
    pub flow: Vec<f64>,
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
        let since = std::time::Instant::now();
        self.frbi.step(&mut self.bodies, self.dt);
        self.step += 1;
        if let Some(flow) = self
            .flow
            .as_mut()
            .filter(|f| self.step.is_multiple_of(f.every))
        {
            flow.apply(&mut self.bodies, &mut self.frbi, self.seed, self.step);
        }
        self.stepping += since.elapsed();
        Ok(())
    }

    /// The first body with a non-finite placement, velocity or spin, by
    /// its scene number ([`RigidBodies::number_of`]).
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
            b.number_of(i) as usize,
            format!(
                "{what} (x {}, v {}, ω {})",
                b.position[i], b.velocity[i], b.omega[i]
            ),
        ))
    }

    fn measure(&mut self) -> RigidSample {
        let e = self.frbi.energies(&self.bodies);
        let o = self.bodies.observables();
        let pressure = self.pressure(o.translational_energy);
        RigidSample {
            pressure,
            time: self.bodies.time,
            translational_energy: o.translational_energy,
            rotational_energy: o.rotational_energy,
            potential_energy: e.potential,
            linear_momentum: o.linear_momentum,
            angular_momentum: o.angular_momentum,
            wall_forces: self.contacts().map(|c| c.wall_forces()).unwrap_or_default(),
            held: self.bodies.len(),
            flow: self.flow.as_ref().map(|f| f.columns()).unwrap_or_default(),
        }
    }

    fn frame(&self) -> Option<Frame> {
        Some(self.sphere_frame())
    }

    /// The force on each sphere's body at the last step's midpoint (each
    /// sphere of a body shows its body's), in the frame's order.
    fn forces(&self) -> Vec<[f64; 3]> {
        let b = &self.bodies;
        let w = self.frbi.last_wrenches();
        if w.len() != b.len() {
            return Vec::new();
        }
        scene_rows(b)
            .flat_map(|k| std::iter::repeat_n(w[k].v.to_array(), b.template(k).sphere_count()))
            .collect()
    }

    fn walls(&self) -> Vec<mote_run::WallGeometry> {
        let t = self.bodies.time;
        self.contacts()
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
            .find_map(|i| i.viewer_mut().and_then(|v| v.steer(change)))
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
        if let Some(flow) = &self.flow {
            cp.carried
                .push((FLOW_KEY.to_string(), flow.carried_state(&self.bodies)));
        }
        if !b.number.is_empty() {
            let number = b.number.iter().map(|&k| k as f64).collect();
            cp.carried.push((ORDER_KEY.to_string(), number));
        }
        Ok(())
    }
}

impl RigidDynamics {
    /// Puts a checkpoint's state into freshly built bodies and integrator.
    pub fn resume(&mut self, cp: &Checkpoint, label: &str) -> Result<(), MdError> {
        let malformed = |m: String| ParseError::new(label, 0, format!("checkpoint: {m}"));
        self.check_order(cp).map_err(malformed)?;
        let carried = cp.carried.iter().find(|(k, _)| k == FLOW_KEY);
        match (&mut self.flow, carried) {
            (Some(flow), Some((_, state))) => flow
                .restore(state, &mut self.bodies, &mut self.frbi)
                .map_err(malformed)?,
            (None, None) => {}
            (Some(_), None) => {
                return Err(malformed(
                    "the checkpoint has no flow state, and the scene inserts or removes bodies"
                        .into(),
                )
                .into())
            }
            (None, Some(_)) => return Err(malformed(
                "the checkpoint has a flow state, and the scene neither inserts nor removes bodies"
                    .into(),
            )
            .into()),
        }
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
        let interactions = Checkpoint {
            carried: (cp.carried.iter())
                .filter(|(k, _)| k != FLOW_KEY && k != ORDER_KEY)
                .cloned()
                .collect(),
            ..Checkpoint::default()
        };
        self.frbi
            .restore_carried_state(&interactions)
            .map_err(malformed)?;
        Ok(())
    }

    /// Checks that the checkpoint stores the bodies in the order this
    /// build does: both in the scene's, or both in the same space order.
    pub fn check_order(&self, cp: &Checkpoint) -> Result<(), String> {
        crate::order::check_saved_order(cp, &self.bodies.number, "bodies", "[rigid] order")
    }
}

/// observables.csv of a rigid run: time, kinetic (translational +
/// rotational), translational, rotational, potential and total energy,
/// momentum, angular momentum (the first twelve of the point-particle
/// engine's columns, by the same names), the pressure where it is measured
/// (a periodic box), the force on each wall; where bodies come and go,
/// the bodies held (N) and what came and went ([`BodyFlow::columns`]).
pub struct RigidCsv {
    writer: CsvWriter,
    every: u64,
    pressure: bool,
    /// Whether bodies come and go (the N and flow columns).
    flow: bool,
}

impl RigidCsv {
    pub fn create(
        path: &std::path::Path,
        provenance: &Provenance,
        walls: &[String],
        every: u64,
        pressure: bool,
        flow: Option<&BodyFlow>,
        append: bool,
    ) -> Result<Self, MdError> {
        // The point-particle engine's words for the same quantities.
        let mut columns: Vec<String> = crate::Observables::COLUMNS[..12]
            .iter()
            .map(|s| s.to_string())
            .collect();
        if pressure {
            columns.push("pressure".into());
        }
        for w in walls {
            for a in ["x", "y", "z"] {
                columns.push(format!("{w}.f{a}"));
            }
        }
        if let Some(f) = flow {
            columns.push("N".into());
            columns.extend(f.column_names());
        }
        let writer = if append {
            CsvWriter::append(path, columns.len())?
        } else {
            CsvWriter::create(path, provenance, &columns, &[])?
        };
        Ok(RigidCsv {
            writer,
            every,
            pressure,
            flow: flow.is_some(),
        })
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
        if self.pressure {
            row.push(s.pressure);
        }
        for (_, f) in &s.wall_forces {
            row.extend(f.to_array());
        }
        if self.flow {
            row.push(s.held as f64);
            row.extend(&s.flow);
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
        match self.contacts() {
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
    // Each body's shift for each of its spheres, in the frame's order.
    let shift = scene_rows(b).flat_map(|i| {
        let s = boundary.wrap(b.position[i]) - b.position[i];
        std::iter::repeat_n(s, b.template(i).sphere_count())
    });
    for (p, s) in frame.positions.iter_mut().zip(shift) {
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

/// The bodies' rows in the order of their scene numbers (bodies stored in
/// space order are written in the scene's).
fn scene_rows(b: &RigidBodies) -> impl Iterator<Item = usize> {
    b.rows_by_number()
        .unwrap_or_else(|| (0..b.len()).collect())
        .into_iter()
}

/// The spheres of the bodies as a frame, body after body in the order of
/// the scene's numbers; the `bodies` column holds each sphere's body's.
pub fn sphere_frame(b: &RigidBodies) -> Frame {
    let frame = stored_sphere_frame(b);
    match b.rows_by_number() {
        Some(rows) => {
            // Each body's spheres are one run of rows: its first sphere's
            // row and count, taken in the bodies' scene order.
            let mut first = Vec::with_capacity(b.len());
            let mut at = 0;
            for i in 0..b.len() {
                first.push(at);
                at += b.template(i).sphere_count();
            }
            let spheres: Vec<usize> = (rows.iter())
                .flat_map(|&i| first[i]..first[i] + b.template(i).sphere_count())
                .collect();
            crate::output::in_rows(frame, &spheres)
        }
        None => frame,
    }
}

/// The spheres as a frame in the bodies' stored order.
fn stored_sphere_frame(b: &RigidBodies) -> Frame {
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
        bodies: world
            .sphere_body
            .iter()
            .map(|&k| b.number_of(k as usize))
            .collect(),
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
