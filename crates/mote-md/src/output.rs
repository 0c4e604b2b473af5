//! Observers that write files through mote-io: observables as CSV (with the
//! particle inspector's columns); trajectories go through `mote_run::Trajectory`.

use std::path::Path;

use glam::DVec3;
use mote_io::csv::CsvWriter;
use mote_io::xyz::Frame;
use mote_io::Provenance;

use crate::error::MdError;
use crate::observe::{Observables, Probe};
use crate::particles::System;
use crate::simulation::Simulation;
use crate::units::UnitSystem;
use mote_run::Observer;

/// observables.csv: time, energies, momentum, angular momentum, step, k_B T,
/// the pressure (only for a box periodic on every axis) and its tensor
/// (`pxx pyy pzz pxy pxz pyz`, when the force field measures it), probes, the total
/// magnetic moment (when there are dipoles), the force on each wall.
pub struct ObservablesCsv {
    writer: CsvWriter,
    every: u64,
    probes: Vec<Probe>,
    pressure: bool,
    tensor: bool,
    walls: usize,
    magnetic: bool,
    /// Whether particles come and go: the count and the flow's columns.
    flow: bool,
}

impl ObservablesCsv {
    #[allow(clippy::too_many_arguments)]
    pub fn create(
        path: &Path,
        provenance: &Provenance,
        units: UnitSystem,
        every: u64,
        probes: Vec<Probe>,
        pressure: bool,
        tensor: bool,
        walls: &[String],
        magnetic: bool,
        flow: Option<&crate::flow::Flow>,
        append: bool,
    ) -> Result<Self, MdError> {
        let [l, t, m, e] = units.labels();
        let p = format!("{m}*{l}/{t}");
        let ang = format!("{m}*{l}^2/{t}");
        let mut columns: Vec<String> = Observables::COLUMNS.iter().map(|s| s.to_string()).collect();
        let mut unit_row: Vec<String> = vec![
            t.into(),
            e.into(),
            e.into(),
            e.into(),
            e.into(),
            e.into(),
            p.clone(),
            p.clone(),
            p,
            ang.clone(),
            ang.clone(),
            ang,
            "1".into(),
            e.into(),
            format!("{e}/{l}^3"),
        ];
        if !pressure {
            columns.pop();
            unit_row.pop();
        }
        if tensor {
            for axes in crate::force::Virial::AXES {
                columns.push(format!("p{axes}"));
                unit_row.push(format!("{e}/{l}^3"));
            }
        }
        for probe in &probes {
            columns.push(probe.label());
            let label = probe.label();
            let unit = match label.split('[').next().unwrap_or("") {
                "x" | "y" | "z" | "r" => l.to_string(),
                "kinetic" => e.to_string(),
                _ => format!("{l}/{t}"),
            };
            unit_row.push(unit);
        }
        // The total magnetic moment of the dipoles.
        if magnetic {
            for axis in ["x", "y", "z"] {
                columns.push(format!("M{axis}"));
                unit_row.push("moment".into());
            }
        }
        // The force on each wall, F = −Σ (contact forces on the particles).
        for wall in walls {
            for axis in ["x", "y", "z"] {
                columns.push(format!("F_{wall}_{axis}"));
                unit_row.push(format!("{m}*{l}/{t}^2"));
            }
        }
        // Particles held, and in and out by each inserter and outlet.
        if let Some(flow) = flow {
            columns.push("N".into());
            unit_row.push("1".into());
            for name in flow.column_names() {
                let unit = match name.split('_').next() {
                    Some("mass") => m,
                    Some("charge") => units.charge_label(),
                    _ => "1",
                };
                unit_row.push(unit.into());
                columns.push(name);
            }
        }
        Ok(Self {
            writer: if append {
                CsvWriter::append(path, columns.len())?
            } else {
                CsvWriter::create(path, provenance, &columns, &unit_row)?
            },
            every,
            probes,
            pressure,
            tensor,
            walls: walls.len(),
            magnetic,
            flow: flow.is_some(),
        })
    }
}

impl Observer<Simulation> for ObservablesCsv {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, sim: &Simulation, obs: &Observables) -> Result<(), MdError> {
        let sys = &sim.system;
        let mut row: Vec<f64> = obs.values(sys.step).to_vec();
        if !self.pressure {
            row.pop();
        }
        if self.tensor {
            row.extend(obs.pressure_tensor);
        }
        row.extend(self.probes.iter().map(|p| p.read(sys)));
        if self.magnetic {
            let m = obs.magnetisation;
            row.extend([m.x, m.y, m.z]);
        }
        for k in 0..self.walls {
            let f = obs.wall_forces.get(k).map_or(DVec3::NAN, |w| w.1);
            row.extend([f.x, f.y, f.z]);
        }
        if self.flow {
            row.push(sys.particles.len() as f64);
            row.extend(sim.flow.as_ref().map(|f| f.columns()).unwrap_or_default());
        }
        Ok(self.writer.row(&row)?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }

    fn event(&mut self, sim: &Simulation, text: &str) -> Result<(), MdError> {
        Ok(self
            .writer
            .comment(&event_line(sim.system.step, sim.system.time, text))?)
    }
}

impl ObservablesCsv {
    /// Names the column a viewer plots first (`# plot: NAME`, before the
    /// rows). Without it the viewer plots the total energy, which a
    /// Newtonian run conserves; an overdamped or thermostatted run
    /// conserves none, and names what it watches instead.
    pub fn suggest_plot(&mut self, column: &str) -> Result<(), MdError> {
        Ok(self.writer.comment(&format!("plot: {column}"))?)
    }
}

/// outflow.csv: a row per particle taken out (step, time, id, outlet,
/// mass, charge, radius, position, velocity), written at each flow
/// event.
pub struct OutflowCsv {
    writer: CsvWriter,
    every: u64,
}

impl OutflowCsv {
    /// The table for `flow`'s outlets (named in a comment by their
    /// numbers in the `outlet` column).
    pub fn create(
        path: &Path,
        provenance: &Provenance,
        units: UnitSystem,
        outlets: &[crate::flow::Outlet],
        every: u64,
        append: bool,
    ) -> Result<Self, MdError> {
        let [l, t, m, _] = units.labels();
        let v = format!("{l}/{t}");
        let columns = [
            "step", "time", "id", "outlet", "mass", "charge", "radius", "x", "y", "z", "vx", "vy",
            "vz",
        ];
        let units = [
            "1",
            t,
            "1",
            "1",
            m,
            units.charge_label(),
            l,
            l,
            l,
            l,
            &v,
            &v,
            &v,
        ];
        let writer = if append {
            CsvWriter::append(path, columns.len())?
        } else {
            let columns: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
            let units: Vec<String> = units.iter().map(|c| c.to_string()).collect();
            let mut w = CsvWriter::create(path, provenance, &columns, &units)?;
            let names: Vec<String> = (outlets.iter().enumerate())
                .map(|(k, o)| format!("{k} = {}", o.name))
                .collect();
            w.comment(&format!("outlets: {}", names.join(", ")))?;
            w
        };
        Ok(Self { writer, every })
    }
}

/// A run whose particles or bodies leave at outlets: those that left at
/// its last flow event.
pub trait Departures {
    /// The step the run stands at.
    fn at_step(&self) -> u64;
    /// What left at the last event (empty without outlets).
    fn departed(&self) -> &[crate::flow::Departure];
}

impl Departures for Simulation {
    fn at_step(&self) -> u64 {
        self.system.step
    }
    fn departed(&self) -> &[crate::flow::Departure] {
        self.flow.as_ref().map_or(&[], |f| &f.departed)
    }
}

impl Departures for crate::rigid::run::RigidDynamics {
    fn at_step(&self) -> u64 {
        self.step
    }
    fn departed(&self) -> &[crate::flow::Departure] {
        self.flow.as_ref().map_or(&[], |f| &f.departed)
    }
}

impl<P> Observer<P> for OutflowCsv
where
    P: mote_run::Propagator<Error = MdError> + Departures,
{
    /// Every flow event: the departures of each are there until the next.
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, run: &P, _: &P::Sample) -> Result<(), MdError> {
        let step = run.at_step();
        for d in run.departed().iter().filter(|d| d.step == step) {
            let row = [
                d.step as f64,
                d.time,
                (d.id + 1) as f64,
                d.outlet as f64,
                d.mass,
                d.charge,
                d.radius,
                d.position.x,
                d.position.y,
                d.position.z,
                d.velocity.x,
                d.velocity.y,
                d.velocity.z,
            ];
            self.writer.row(&row)?;
        }
        Ok(())
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }
}

/// The comment an observables table records an event of the run with:
/// `event: step S, t = T: what changed`.
pub fn event_line(step: u64, time: f64, text: &str) -> String {
    format!("event: step {step}, t = {time}: {text}")
}

/// The system as a plain frame: the cell is the simulation box when it is
/// finite, else a box enclosing the particles.
pub fn frame_of(sys: &System) -> Frame {
    let p = &sys.particles;
    let positions: Vec<[f64; 3]> = p.position.iter().map(|r| r.to_array()).collect();
    let b = &sys.boundary;
    let (cell, origin) = if b.volume().is_finite() {
        let l = b.lengths();
        (
            [[l.x, 0.0, 0.0], [0.0, l.y, 0.0], [0.0, 0.0, l.z]],
            b.lo.to_array(),
        )
    } else {
        Frame::bounding_cell(&positions, &p.radius, 0.0)
    };
    let frame = Frame {
        time: sys.time,
        cell,
        origin,
        pbc: b.periodic,
        species: if sys.species.len() == p.len() {
            sys.species.clone()
        } else {
            vec!["X".to_string(); p.len()]
        },
        positions,
        velocities: p.velocity.iter().map(|v| v.to_array()).collect(),
        radii: p.radius.clone(),
        masses: p.mass.clone(),
        // Ids where particles come and go (written from 1).
        ids: (0..sys.id.len()).map(|i| sys.number_of(i) + 1).collect(),
        angular_velocities: nonzero(&p.angular_velocity),
        dipoles: nonzero(&p.dipole),
        ..Frame::default()
    };
    match sys.rows_by_number() {
        Some(rows) => in_rows(frame, &rows),
        None => frame,
    }
}

/// The frame's particles in the order of `rows` (the particles stored in
/// space order, written in the scene's).
pub(crate) fn in_rows(frame: Frame, rows: &[usize]) -> Frame {
    use crate::order::gathered;
    Frame {
        species: gathered(&frame.species, rows),
        positions: gathered(&frame.positions, rows),
        velocities: gathered(&frame.velocities, rows),
        radii: gathered(&frame.radii, rows),
        masses: gathered(&frame.masses, rows),
        ids: gathered(&frame.ids, rows),
        angular_velocities: gathered(&frame.angular_velocities, rows),
        dipoles: gathered(&frame.dipoles, rows),
        bodies: gathered(&frame.bodies, rows),
        orientations: gathered(&frame.orientations, rows),
        ..frame
    }
}

/// The vectors as arrays, or none if all are zero (a column not worth writing).
fn nonzero(v: &[DVec3]) -> Vec<[f64; 3]> {
    if v.iter().any(|x| *x != DVec3::ZERO) {
        v.iter().map(|x| x.to_array()).collect()
    } else {
        Vec::new()
    }
}
