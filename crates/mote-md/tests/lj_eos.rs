//! The Lennard-Jones liquid at ρ* = 0.8442, T* ≈ 0.72 against the equation
//! of state of Johnson, Zollweg & Gubbins (1993), with the standard
//! long-range tail corrections for the cut-off at 2.5σ (truncated, not shifted).

use crate::common;

use common::*;
use mote_md::force::LennardJones;
use mote_md::thermostat::Thermostat;
use mote_md::{eos, Observables};

/// Mean (T, U/N, P) of an N = 4·cells³ liquid: melted at T* = 2, brought to
/// T* = 0.72 by a Bussi thermostat, then sampled in NVE every 10 steps.
fn sample(cells: usize, equilibrate: u64, production: u64) -> (f64, f64, f64, f64) {
    let text = format!(
        r#"
units = "lj"
seed = 5
[run]
integrator = "leapfrog"
dt = 0.005
[lennard_jones]
cutoff = 2.5
shifted = false
[[fcc]]
cells = [{cells}, {cells}, {cells}]
density = 0.8442
kt = 2.0
[thermostat]
kind = "bussi"
kt = 2.0
tau = 0.1
"#
    );
    let mut sim = build(&text).simulation;
    let n = sim.system.particles.len() as f64;
    let rho = n / sim.system.boundary.volume();
    let (u_tail, p_tail) = LennardJones::new(1.0, 1.0, 2.5, false, 0.3).tail_corrections(rho);
    let run = |sim: &mut mote_md::Simulation, steps: u64| {
        for _ in 0..steps {
            mote_run::Propagator::advance(sim).unwrap();
        }
    };
    run(&mut sim, 1000); // melt
    sim.thermostat = Some(Thermostat::Bussi { kt: 0.72, tau: 0.1 });
    run(&mut sim, equilibrate);
    sim.thermostat = None;
    let (mut t, mut u, mut p, mut k) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..production / 10 {
        run(&mut sim, 10);
        let o = Observables::measure(&sim.system, &mut sim.forces);
        t += o.kt;
        u += o.potential / n + u_tail;
        p += o.pressure + p_tail;
        k += 1.0;
    }
    (rho, t / k, u / k, p / k)
}

fn check(cells: usize, equilibrate: u64, production: u64, tol_u: f64, tol_p: f64) {
    let (rho, t, u, p) = sample(cells, equilibrate, production);
    let (u_ref, p_ref) = (eos::lj_energy(rho, t), eos::lj_pressure(rho, t));
    eprintln!(
        "N = {}: T* = {t:.4}, U/N = {u:.4} (JZG {u_ref:.4}), P* = {p:.4} (JZG {p_ref:.4})",
        4 * cells.pow(3)
    );
    assert!((t - 0.72).abs() < 0.03, "NVE temperature {t}");
    assert!(
        (u - u_ref).abs() < tol_u * u_ref.abs(),
        "U/N = {u}, JZG {u_ref}"
    );
    assert!((p - p_ref).abs() < tol_p, "P* = {p}, JZG {p_ref}");
}

/// A short run in the normal suite: 500 atoms, U/N within 1 %, P* within 0.1.
/// (At this state P* ≈ 0.08 is a small difference of large terms, so it is
/// checked in absolute terms; we measured 0.057 here.)
#[test]
fn lj_liquid_matches_jzg_quick() {
    check(5, 1500, 2000, 0.01, 0.1);
}

/// The full check (`cargo test --release -- --ignored`): 864 atoms, 2·10⁴
/// NVE steps, U/N within 1 % and P* within 0.02 of JZG.
#[test]
#[ignore]
fn lj_liquid_matches_jzg() {
    check(6, 4000, 20_000, 0.01, 0.02);
}
