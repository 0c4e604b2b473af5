//! Holding one target pressure: damped dynamics of the spheres with the
//! box following the Berendsen-type barostat of the module's equations,
//! a chunk of steps at a time, until the pressure holds and the motion has
//! died out (or the step budget is spent).

use super::finish::Jam;
use super::{Phase, SoftPacker, Stage, CHUNK};

/// One target pressure being held.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Hold {
    /// Index of the target in the settings' pressures.
    pub stage: usize,
    /// Steps taken at this target.
    pub steps: u64,
    /// Consecutive checks (every [`CHUNK`] steps) at which it held.
    pub held: u32,
    /// The time step, renewed at every check.
    pub dt: f64,
}

/// The time scales of target pressure `target` (module docs): the
/// vibration frequency ω at its typical overlap, the friction ζ/m = ω and
/// the largest strain rate of the box.
fn scales(target: f64) -> (f64, f64, f64) {
    let overlap = target.powf(2.0 / 3.0);
    let omega = (1.5 * overlap.sqrt()).sqrt();
    let friction = omega; // ζ/m = 1/τ
    let rate_max = 0.1 * overlap * omega;
    (omega, friction, rate_max)
}

impl Hold {
    /// The start of target `stage`: forces of now, and a step 0.1/ω of the
    /// stiffest contact.
    pub fn begin(p: &mut SoftPacker, stage: usize) -> Hold {
        let (omega, _, _) = scales(p.settings.pressures[stage]);
        p.refresh_list();
        let sums = p.pair_forces();
        Hold {
            stage,
            steps: 0,
            held: 0,
            dt: 0.1 / sums.stiffest.max(omega * omega).sqrt(),
        }
    }
}

/// [`CHUNK`] steps at the target of `hold`, then the check: the next
/// phase (this target again, the next, the finish, or the end).
pub(super) fn advance(p: &mut SoftPacker, mut hold: Hold) -> Phase {
    let target = p.settings.pressures[hold.stage];
    let (omega, friction, rate_max) = scales(target);
    let n = p.position.len();
    let (mut pressure, mut kinetic2) = (0.0, 0.0);
    for _ in 0..CHUNK {
        // Velocity Verlet (the dissipative forces use the velocities of
        // the previous half step), then the box follows the pressure.
        let dt = hold.dt;
        for i in 0..n {
            let a = p.force[i] / p.mass[i] - friction * p.velocity[i];
            p.velocity[i] += 0.5 * dt * a;
            p.position[i] += dt * p.velocity[i];
        }
        p.refresh_list();
        let sums = p.pair_forces();
        kinetic2 = 0.0;
        for i in 0..n {
            let a = p.force[i] / p.mass[i] - friction * p.velocity[i];
            p.velocity[i] += 0.5 * dt * a;
            kinetic2 += p.mass[i] * p.velocity[i].length_squared();
        }
        pressure = (kinetic2 + sums.virial) / (3.0 * p.boundary.volume());
        let strain_rate = rate_max * ((pressure - target) / target).clamp(-1.0, 1.0);
        p.dilate((strain_rate * dt).exp());
        p.time += dt;
        p.steps += 1;
        hold.steps += 1;
    }
    let sums = p.sums;
    hold.dt = 0.1 / sums.stiffest.max(omega * omega).sqrt();
    let still = 0.5 * kinetic2 < 1e-4 * sums.elastic;
    if (pressure / target - 1.0).abs() < p.settings.tolerance && still {
        hold.held += 1;
    } else {
        hold.held = 0;
    }
    let converged = hold.held >= 3;
    if !converged && hold.steps < p.settings.max_steps {
        return Phase::Hold(hold);
    }
    p.stages.push(Stage {
        target,
        pressure: (p.kinetic2() + sums.virial) / (3.0 * p.boundary.volume()),
        phi: p.phi(),
        z: 2.0 * sums.contacts as f64 / n as f64,
        steps: hold.steps,
        total: p.steps,
        time: p.time,
        converged,
    });
    let next = hold.stage + 1;
    if next < p.settings.pressures.len() {
        return Phase::Hold(Hold::begin(p, next));
    }
    match p.settings.finish {
        Some(_) => {
            p.barostat_end = Some((p.position.clone(), p.boundary));
            Phase::Jam(Box::new(Jam::after(p.stages())))
        }
        None => Phase::Over,
    }
}
