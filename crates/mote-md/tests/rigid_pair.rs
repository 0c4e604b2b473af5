//! Two magnetised, charged irregular bodies interacting through Coulomb and
//! dipole–dipole forces and torques: total linear momentum is kept to
//! rounding; total angular momentum (spins plus orbital, about the origin)
//! is kept by the forces and torques themselves (checked per evaluation),
//! and through the run to the integrator's accuracy.

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::{
    BodyTemplate, Coulomb, DipoleDipole, Frbi, Integration, IrregularClump, RigidBodies, SpinUpdate,
};

fn pair() -> RigidBodies {
    let gen = IrregularClump::default();
    let mut b = RigidBodies::new();
    for (seed, q, j, x, w, v) in [
        (
            1,
            0.5,
            DVec3::new(0.3, 1.0, 0.2),
            DVec3::new(-1.6, 0.1, 0.0),
            DVec3::new(0.2, 0.1, -0.3),
            DVec3::new(0.05, 0.0, 0.02),
        ),
        (
            2,
            0.8,
            DVec3::new(-0.5, 0.2, 0.9),
            DVec3::new(1.7, -0.2, 0.3),
            DVec3::new(-0.1, 0.4, 0.2),
            DVec3::new(-0.03, 0.01, 0.0),
        ),
    ] {
        let mut spec = gen.generate(seed);
        spec.charge = q;
        spec.dipole = j;
        let t = BodyTemplate::new(&spec, Integration::default()).unwrap();
        let k = b.add_template(t);
        b.push(
            k,
            E::new(DVec3::new(0.1 * seed as f64, 0.2, -0.3), x),
            DE::new(w, v),
        );
    }
    b
}

fn frbi(spin: SpinUpdate) -> Frbi {
    let mut f = Frbi::new()
        .with(Coulomb::coulomb(1.0))
        .with(DipoleDipole::dipoles(1.0));
    f.spin = spin;
    f
}

/// Forces cancel and torques plus moments of forces cancel (Newton's third
/// law in its strong form for dipoles), at one evaluation.
#[test]
fn wrenches_balance() {
    let b = pair();
    let mut f = frbi(SpinUpdate::Seed);
    let w = f.wrenches(&b, 0.0, 0.0).to_vec();
    let force = w[0].v + w[1].v;
    let torque =
        w[0].omega + w[1].omega + b.position[0].cross(w[0].v) + b.position[1].cross(w[1].v);
    let scale = w[0].v.length() + w[0].omega.length();
    eprintln!("ΣF = {force}, Σ(T + x × F) = {torque}, scale {scale:.3e}");
    assert!(force.length() < 1e-15 * scale);
    assert!(torque.length() < 1e-14 * scale);
}

/// The force is minus the gradient of the potential energy, by central
/// differences (checks the dipole–dipole formula against its energy).
#[test]
fn force_is_gradient_of_energy() {
    let mut b = pair();
    let mut f = frbi(SpinUpdate::Seed);
    let w = f.wrenches(&b, 0.0, 0.0)[0];
    let h = 1e-5;
    for k in 0..3 {
        let x0 = b.position[0];
        b.position[0][k] = x0[k] + h;
        let up = f.energies(&b).potential;
        b.position[0][k] = x0[k] - h;
        let dn = f.energies(&b).potential;
        b.position[0] = x0;
        let fd = -(up - dn) / (2.0 * h);
        assert!(
            (fd - w.v[k]).abs() < 1e-7 * w.v.length(),
            "F_{k}: {} vs −∂U = {fd}",
            w.v[k]
        );
    }
}

fn run(dt: f64, steps: usize, spin: SpinUpdate) -> (f64, f64, f64) {
    let mut b = pair();
    let mut f = frbi(spin);
    let o0 = b.observables();
    let e0 = f.energies(&b).total();
    let (mut dp, mut dl, mut de) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..steps {
        f.step(&mut b, dt);
        let o = b.observables();
        dp = dp.max((o.linear_momentum - o0.linear_momentum).length());
        dl = dl.max((o.angular_momentum - o0.angular_momentum).length());
        de = de.max((f.energies(&b).total() - e0).abs());
    }
    let (p, l) = (o0.linear_momentum.length(), o0.angular_momentum.length());
    eprintln!(
        "{spin:?} dt = {dt}: max |ΔP| = {dp:.2e} (|P| = {p:.3}), max |ΔL| = {dl:.2e} (|L| = {l:.3}), max |ΔE| = {de:.2e} (E = {e0:.4})"
    );
    (dp, dl / l, de)
}

#[test]
fn pair_conserves_momenta() {
    let b = pair();
    let p = b.observables().linear_momentum.length();
    // KeepMomentum: react adds Σ(T + x × F)Δt = 0 and the free step carries
    // each spin exactly, so L is kept to rounding: at most 1e-15 relative
    // per step
    let steps = 20_000;
    let (dp, dl, _) = run(1e-3, steps, SpinUpdate::KeepMomentum);
    assert!(dp < 1e-13 * p.max(1.0));
    assert!(dl < 1e-15 * steps as f64, "relative |ΔL| {dl:.2e}");
    // Seed: the free step keeps each spin to O(Δt²) per step: L drifts ∝ Δt
    let (dp1, dl1, _) = run(2e-3, 10_000, SpinUpdate::Seed);
    let (dp2, dl2, _) = run(1e-3, 20_000, SpinUpdate::Seed);
    assert!(dp1 < 1e-13 * p.max(1.0) && dp2 < 1e-13 * p.max(1.0));
    let order = (dl1 / dl2).log2();
    eprintln!("Seed spin update: |ΔL| order {order:.2}");
    assert!(dl2 < 1e-3);
}
