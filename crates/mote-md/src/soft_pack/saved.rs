//! A soft packing in a checkpoint, and back: the spheres, the forces and
//! sums of the last pass, the neighbour list's reference state (the list
//! is rebuilt from it, so pairs are summed in the same order), the stages
//! so far and every loop variable of the barostat and the finish — so a
//! packing resumed at any chunk ends in the uninterrupted one's bits.

use glam::DVec3;
use mote_io::checkpoint::Checkpoint;

use super::barostat::Hold;
use super::finish::{Attempt, Fire, Jam};
use super::{PairSums, Phase, SoftPackSettings, SoftPacker, SoftStop, Stage};
use crate::boundary::Boundary;

/// The carried lists of a soft packing's checkpoint.
const RADII: &str = "radii";
const FORCES: &str = "forces";
const BOX: &str = "box";
const LIST: &str = "list";
const RUN: &str = "run";
const STAGES: &str = "stages";
const FINISH: &str = "finish";
const ATTEMPT: &str = "attempt";
const BAROSTAT_END: &str = "barostat_end";

/// Numbers of one stage in a list.
const STAGE: usize = 8;

fn stage_numbers(s: &Stage, out: &mut Vec<f64>) {
    out.extend([
        s.target,
        s.pressure,
        s.phi,
        s.z,
        s.steps as f64,
        s.total as f64,
        s.time,
        if s.converged { 1.0 } else { 0.0 },
    ]);
}

fn box_numbers(b: &Boundary, out: &mut Vec<f64>) {
    out.extend(b.lo.to_array());
    out.extend(b.hi.to_array());
}

fn flat(points: &[DVec3], out: &mut Vec<f64>) {
    out.extend(points.iter().flat_map(|r| r.to_array()));
}

/// Reads numbers off a carried list in the order they were written.
struct Numbers<'a> {
    list: &'a [f64],
    name: &'static str,
}

impl<'a> Numbers<'a> {
    fn of(cp: &'a Checkpoint, name: &'static str) -> Self {
        Numbers {
            list: cp.carried_list(name, usize::MAX).unwrap_or(&[]),
            name,
        }
    }

    fn bad(&self, what: &str) -> String {
        format!(
            "checkpoint of a soft packing: its `{}` list {what}",
            self.name
        )
    }

    fn take(&mut self, n: usize) -> Result<&'a [f64], String> {
        if self.list.len() < n {
            return Err(self.bad("is too short"));
        }
        let (head, rest) = self.list.split_at(n);
        self.list = rest;
        Ok(head)
    }

    fn number(&mut self) -> Result<f64, String> {
        Ok(self.take(1)?[0])
    }

    fn count(&mut self) -> Result<u64, String> {
        let x = self.number()?;
        if x >= 0.0 && x.fract() == 0.0 && x < 2f64.powi(53) {
            Ok(x as u64)
        } else {
            Err(self.bad("holds a count that is not a whole number"))
        }
    }

    fn flag(&mut self) -> Result<bool, String> {
        Ok(self.count()? != 0)
    }

    fn boundary(&mut self) -> Result<Boundary, String> {
        let b = self.take(6)?;
        Ok(Boundary::periodic(
            DVec3::new(b[0], b[1], b[2]),
            DVec3::new(b[3], b[4], b[5]),
        ))
    }

    fn points(&mut self, n: usize) -> Result<Vec<DVec3>, String> {
        Ok(self
            .take(3 * n)?
            .chunks_exact(3)
            .map(DVec3::from_slice)
            .collect())
    }

    fn stage(&mut self) -> Result<Stage, String> {
        Ok(Stage {
            target: self.number()?,
            pressure: self.number()?,
            phi: self.number()?,
            z: self.number()?,
            steps: self.count()?,
            total: self.count()?,
            time: self.number()?,
            converged: self.flag()?,
        })
    }

    fn stages(&mut self) -> Result<Vec<Stage>, String> {
        if !self.list.len().is_multiple_of(STAGE) {
            return Err(self.bad("is not whole stages"));
        }
        let mut out = Vec::new();
        while !self.list.is_empty() {
            out.push(self.stage()?);
        }
        Ok(out)
    }

    fn done(&self) -> Result<(), String> {
        if self.list.is_empty() {
            Ok(())
        } else {
            Err(self.bad("is too long"))
        }
    }
}

impl SoftPacker {
    /// Puts the packing's state into `cp` (which holds the run's input and
    /// options).
    pub fn save(&self, cp: &mut Checkpoint) {
        cp.time = self.time;
        cp.step = self.chunks;
        cp.positions = self.position.iter().map(|r| r.to_array()).collect();
        cp.velocities = self.velocity.iter().map(|v| v.to_array()).collect();
        let mut carried: Vec<(&str, Vec<f64>)> = Vec::new();
        carried.push((RADII, self.radius.clone()));
        let mut forces = Vec::new();
        flat(&self.force, &mut forces);
        carried.push((FORCES, forces));
        let mut b = Vec::new();
        box_numbers(&self.boundary, &mut b);
        carried.push((BOX, b));
        if !self.reference.is_empty() {
            let mut list = Vec::new();
            box_numbers(&self.reference_box, &mut list);
            flat(&self.reference, &mut list);
            carried.push((LIST, list));
        }
        let s = &self.sums;
        let mut run = vec![
            self.time,
            self.steps as f64,
            self.chunks as f64,
            self.last_floor,
            s.virial,
            s.elastic,
            s.stiffest,
            s.overlap,
            s.contacts as f64,
            self.stopped
                .and_then(|stop| SoftStop::ALL.iter().position(|s| *s == stop))
                .map_or(0.0, |k| 1.0 + k as f64),
        ];
        match &self.phase {
            Phase::Over => run.push(0.0),
            Phase::Hold(h) => {
                run.extend([1.0, h.stage as f64, h.steps as f64, h.held as f64, h.dt])
            }
            Phase::Jam(j) => {
                run.extend([2.0, j.slope, j.fails as f64]);
                match &j.fire {
                    None => run.push(0.0),
                    Some(f) => run.extend([
                        1.0,
                        f.dt0,
                        f.dt,
                        f.alpha,
                        f.since_negative as f64,
                        f.steps as f64,
                        f.rel,
                        f.best,
                        f.best_at as f64,
                    ]),
                }
                if let Some(a) = &j.attempt {
                    let mut numbers = vec![a.aim, a.dphi];
                    box_numbers(&a.boundary, &mut numbers);
                    stage_numbers(&a.last, &mut numbers);
                    flat(&a.position, &mut numbers);
                    carried.push((ATTEMPT, numbers));
                }
            }
        }
        carried.push((RUN, run));
        for (name, stages) in [(STAGES, &self.stages), (FINISH, &self.finish)] {
            let mut numbers = Vec::new();
            stages.iter().for_each(|s| stage_numbers(s, &mut numbers));
            carried.push((name, numbers));
        }
        if let Some((position, boundary)) = &self.barostat_end {
            let mut numbers = Vec::new();
            box_numbers(boundary, &mut numbers);
            flat(position, &mut numbers);
            carried.push((BAROSTAT_END, numbers));
        }
        cp.carried = carried
            .into_iter()
            .filter(|(_, v)| !v.is_empty())
            .map(|(k, v)| (k.to_string(), v))
            .collect();
    }

    /// The packing of `settings` in the state checkpoint `cp` saved.
    pub fn resume(settings: SoftPackSettings, cp: &Checkpoint) -> Result<Self, String> {
        let mut p = Self::unstarted(settings)?;
        let n = p.position.len();
        let bad = |m: &str| format!("checkpoint of a soft packing: {m}");
        if cp.positions.len() != n || cp.velocities.len() != n {
            return Err(bad(&format!(
                "it holds {} spheres, the scene {n}",
                cp.positions.len()
            )));
        }
        let radii = Numbers::of(cp, RADII).take(n)?;
        if radii
            .iter()
            .zip(&p.radius)
            .any(|(a, b)| a.to_bits() != b.to_bits())
        {
            return Err(bad("its spheres' sizes are not the scene's"));
        }
        p.position = cp.positions.iter().map(|r| DVec3::from_array(*r)).collect();
        p.velocity = cp
            .velocities
            .iter()
            .map(|v| DVec3::from_array(*v))
            .collect();
        let mut forces = Numbers::of(cp, FORCES);
        p.force = forces.points(n)?;
        forces.done()?;
        let mut b = Numbers::of(cp, BOX);
        p.boundary = b.boundary()?;
        b.done()?;
        let mut list = Numbers::of(cp, LIST);
        if !list.list.is_empty() {
            p.reference_box = list.boundary()?;
            p.reference = list.points(n)?;
            list.done()?;
            p.list.build(&p.reference, &p.radius, &p.reference_box);
        }
        let mut run = Numbers::of(cp, RUN);
        p.time = run.number()?;
        p.steps = run.count()?;
        p.chunks = run.count()?;
        p.last_floor = run.number()?;
        p.sums = PairSums {
            virial: run.number()?,
            elastic: run.number()?,
            stiffest: run.number()?,
            overlap: run.number()?,
            contacts: run.count()? as usize,
        };
        p.stopped = match run.count()? {
            0 => None,
            k => Some(
                *SoftStop::ALL
                    .get(k as usize - 1)
                    .ok_or_else(|| run.bad("names no way to stop"))?,
            ),
        };
        p.stages = Numbers::of(cp, STAGES).stages()?;
        p.finish = Numbers::of(cp, FINISH).stages()?;
        let mut end = Numbers::of(cp, BAROSTAT_END);
        if !end.list.is_empty() {
            let boundary = end.boundary()?;
            p.barostat_end = Some((end.points(n)?, boundary));
            end.done()?;
        }
        p.phase = match run.count()? {
            0 => Phase::Over,
            1 => {
                let hold = Hold {
                    stage: run.count()? as usize,
                    steps: run.count()?,
                    held: run.count()? as u32,
                    dt: run.number()?,
                };
                if hold.stage >= p.settings.pressures.len() {
                    return Err(bad("it holds a target pressure the scene lacks"));
                }
                Phase::Hold(hold)
            }
            2 => {
                if p.settings.finish.is_none() {
                    return Err(bad("taken in the jamming finish, for settings without one"));
                }
                let slope = run.number()?;
                let fails = run.count()? as u32;
                let fire = match run.flag()? {
                    false => None,
                    true => Some(Fire {
                        dt0: run.number()?,
                        dt: run.number()?,
                        alpha: run.number()?,
                        since_negative: run.count()?,
                        steps: run.count()?,
                        rel: run.number()?,
                        best: run.number()?,
                        best_at: run.count()?,
                    }),
                };
                let mut a = Numbers::of(cp, ATTEMPT);
                let attempt = match a.list.is_empty() {
                    true => None,
                    false => Some(Attempt {
                        aim: a.number()?,
                        dphi: a.number()?,
                        boundary: a.boundary()?,
                        last: a.stage()?,
                        position: a.points(n)?,
                    }),
                };
                a.done()?;
                Phase::Jam(Box::new(Jam {
                    slope,
                    fails,
                    attempt,
                    fire,
                }))
            }
            _ => return Err(run.bad("names no phase of a packing")),
        };
        run.done()?;
        Ok(p)
    }
}
