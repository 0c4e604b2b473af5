//! Charges, electric fields and Ewald sums reached from scene files, against
//! closed forms: the Madelung constant of rock salt, the tin-foil energy of
//! a cubic lattice of parallel dipoles, Coulomb's circular orbit, and a
//! charge accelerated by a constant and an oscillating field.

use crate::common;

use mote_md::{DVec3, Observables};

/// Madelung constant of rock salt for the nearest-neighbour distance
/// (Kittel, *Introduction to Solid State Physics*, ch. 3).
const MADELUNG_NACL: f64 = 1.747_564_594_633;

/// The 8 ions of rock salt's cubic cell (nearest-neighbour distance 1) in a
/// periodic box of side 2.
pub fn rock_salt(method_keys: &str) -> String {
    rock_salt_scaled(method_keys, 1.0)
}

/// The same crystal with every length times `a`.
fn rock_salt_scaled(method_keys: &str, a: f64) -> String {
    let side = 2.0 * a;
    let mut s = format!(
        "units = \"lj\"\n[run]\ndt = 0.001\n[box]\nlo = [0.0, 0.0, 0.0]\nhi = [{side:?}, {side:?}, {side:?}]\nperiodic = [true, true, true]\n[coulomb]\n{method_keys}\n"
    );
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                let q = if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 };
                let at = |n: i32| (n as f64 + 0.25) * a;
                s += &format!(
                    "[[particle]]\nposition = [{:?}, {:?}, {:?}]\ncharge = {q:.1}\n",
                    at(i),
                    at(j),
                    at(k)
                );
            }
        }
    }
    s
}

/// The pressure of a static ionic crystal under Ewald is U/(3V) (the
/// Coulomb virial is U), and it is −dU/dV of the crystal strained evenly,
/// measured by central differences of the Ewald energy.
#[test]
fn ewald_pressure_of_static_rock_salt_is_u_over_3v_and_minus_du_dv() {
    let keys = "method = \"ewald\"\naccuracy = 1e-12";
    let mut built = common::build(&rock_salt(keys));
    let sim = &mut built.simulation;
    // One step: the forces vanish by symmetry, so nothing moves (K = 0).
    common::steps(sim, 1, |_| {});
    let o = Observables::measure(&sim.system, &mut sim.forces);
    assert!(o.kinetic < 1e-30, "K = {}", o.kinetic);
    let volume = 8.0;
    let expected = o.potential / (3.0 * volume);
    assert!(
        ((o.pressure - expected) / expected).abs() < 1e-6,
        "P = {}, U/(3V) = {expected}",
        o.pressure
    );
    // −dU/dV from the energies of the crystal scaled by 1 ± h.
    let h = 1e-4;
    let energy = |a: f64| {
        let mut b = common::build(&rock_salt_scaled(keys, a));
        let s = &mut b.simulation;
        Observables::measure(&s.system, &mut s.forces).potential
    };
    let (up, down) = (energy(1.0 + h), energy(1.0 - h));
    let dv = 8.0 * ((1.0 + h).powi(3) - (1.0 - h).powi(3));
    let minus_du_dv = -(up - down) / dv;
    assert!(
        ((o.pressure - minus_du_dv) / minus_du_dv).abs() < 1e-6,
        "P = {}, −dU/dV = {minus_du_dv}",
        o.pressure
    );
}

#[test]
fn ewald_scene_gives_the_madelung_energy_of_rock_salt() {
    let mut built = common::build(&rock_salt("method = \"ewald\"\naccuracy = 1e-10"));
    let sim = &mut built.simulation;
    let u = Observables::measure(&sim.system, &mut sim.forces).potential;
    // U = −(N/2) M k q² / r₀ with N = 8, k = q = r₀ = 1.
    let expected = -4.0 * MADELUNG_NACL;
    assert!(
        ((u - expected) / expected).abs() < 1e-8,
        "U = {u}, expected {expected}"
    );
}

#[test]
fn ewald_dipoles_scene_gives_the_tin_foil_energy_of_a_cubic_lattice() {
    // 4×4×4 simple cubic lattice (a = 1) of dipoles μ = 1.5 ẑ. In spherical
    // order the lattice sum vanishes for cubic symmetry (Lorentz), so with
    // tin-foil boundaries U/N = −(2π/3) n μ² (de Leeuw, Perram & Smith 1980).
    let text = "units = \"lj\"\n[run]\ndt = 0.001\n\
        [box]\nlo = [0.0, 0.0, 0.0]\nhi = [4.0, 4.0, 4.0]\nperiodic = [true, true, true]\n\
        [dipolar]\nmethod = \"ewald\"\naccuracy = 1e-9\n\
        [[lattice]]\nn = [4, 4, 4]\nspacing = [1.0, 1.0, 1.0]\norigin = [0.5, 0.5, 0.5]\ndipole = [0.0, 0.0, 1.5]\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    let u = Observables::measure(&sim.system, &mut sim.forces).potential;
    let expected = -64.0 * 2.0 * std::f64::consts::PI / 3.0 * 1.5 * 1.5;
    assert!(
        ((u - expected) / expected).abs() < 1e-7,
        "U = {u}, expected {expected}"
    );
}

/// Two unlike charges: a light one on the circular orbit about a heavy one
/// (k q² / r² = m v² / r with k = q = r = m = 1 gives v = 1) comes back
/// after one period 2π; direct and tree sums give the same orbit.
#[test]
fn coulomb_attraction_keeps_a_circular_orbit() {
    for method in ["direct", "tree"] {
        let text = format!(
            "units = \"lj\"\n[run]\ndt = 0.001\n[coulomb]\nmethod = \"{method}\"\n\
             [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1e12\ncharge = 1.0\n\
             [[particle]]\nposition = [1.0, 0.0, 0.0]\nvelocity = [0.0, 1.0, 0.0]\ncharge = -1.0\n"
        );
        let mut built = common::build(&text);
        let sim = &mut built.simulation;
        let e0 = Observables::measure(&sim.system, &mut sim.forces).total_energy();
        let steps = (2.0 * std::f64::consts::PI / 0.001).round() as u64;
        common::steps(sim, steps, |_| {});
        let r = sim.system.particles.position[1];
        assert!(
            (r - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-3,
            "{method}: after one period at {r}"
        );
        assert!(common::energy_error(sim, e0) < 1e-6, "{method}");
    }
}

/// The tree's energy of a cloud of like and unlike charges agrees with the
/// direct sum to the accuracy of θ = 0.3.
#[test]
fn tree_and_direct_coulomb_agree_on_a_cloud() {
    let cloud = |method: &str| {
        format!(
            "units = \"lj\"\nseed = 5\n[run]\ndt = 0.001\n[coulomb]\nmethod = \"{method}\"\n{}\n\
             [[random_box]]\nn = 300\nmin = [0.0, 0.0, 0.0]\nmax = [10.0, 10.0, 10.0]\ncharge = 1.0\n\
             [[random_box]]\nn = 200\nmin = [0.0, 0.0, 0.0]\nmax = [10.0, 10.0, 10.0]\ncharge = -1.5\n",
            if method == "tree" { "theta = 0.3" } else { "" }
        )
    };
    let energy = |text: String| {
        let mut built = common::build(&text);
        let sim = &mut built.simulation;
        Observables::measure(&sim.system, &mut sim.forces).potential
    };
    let (direct, tree) = (energy(cloud("direct")), energy(cloud("tree")));
    assert!(
        ((tree - direct) / direct).abs() < 1e-3,
        "tree {tree} vs direct {direct}"
    );
}

/// A charge q of mass m in E(t) = E₀ cos(ωt + φ):
/// v(t) = (q E₀ / m ω) [sin(ωt + φ) − sin φ]; and in a constant field
/// v = q E t / m exactly (leap-frog integrates constant forces exactly).
#[test]
fn a_charge_is_accelerated_by_the_electric_field() {
    let text = "units = \"lj\"\n[run]\ndt = 0.001\n[electric_field]\ne = [1.0, 0.0, -2.0]\n\
                [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 0.5\ncharge = 2.0\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    common::steps(sim, 1000, |_| {});
    let v = sim.system.particles.velocity[0];
    assert!((v - DVec3::new(4.0, 0.0, -8.0)).length() < 1e-12, "v = {v}");

    let (omega, phase): (f64, f64) = (3.0, 0.4);
    let text = format!(
        "units = \"lj\"\n[run]\ndt = 0.0005\n[electric_field]\ne = [0.0, 1.5, 0.0]\nangular_frequency = {omega}\nphase = {phase}\n\
         [[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 0.5\ncharge = 2.0\n"
    );
    let mut built = common::build(&text);
    let sim = &mut built.simulation;
    common::steps(sim, 2000, |_| {});
    let t = 1.0;
    let exact = 2.0 * 1.5 / (0.5 * omega) * ((omega * t + phase).sin() - phase.sin());
    let vy = sim.system.particles.velocity[0].y;
    assert!((vy - exact).abs() < 1e-5, "v_y = {vy}, exact {exact}");
}

/// One stretched spring in a periodic box: W = r_ij · F_ij = −D (r − l) r,
/// so P = W/(3V) at rest; an interaction without a virial (direct
/// gravity, put in by hand: a scene refuses it in a periodic box) takes the
/// pressure away, never leaving a number without its part.
#[test]
fn spring_pressure_and_a_pressure_not_given() {
    let text = "units = \"lj\"\n[run]\ndt = 1e-12\n\
        [box]\nlo = [0.0, 0.0, 0.0]\nhi = [10.0, 10.0, 10.0]\nperiodic = [true, true, true]\n\
        [[particle]]\nposition = [4.0, 5.0, 5.0]\n\
        [[particle]]\nposition = [5.5, 5.0, 5.0]\n\
        [[spring]]\npairs = [[0, 1]]\nstiffness = 3.0\nrest_length = 1.0\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    common::steps(sim, 1, |_| {});
    let o = Observables::measure(&sim.system, &mut sim.forces);
    let expected = -3.0 * 0.5 * 1.5 / (3.0 * 1000.0);
    assert!(
        ((o.pressure - expected) / expected).abs() < 1e-9,
        "P = {}, expected {expected}",
        o.pressure
    );
    assert!(sim.forces.without_virial().is_empty());
    // A scene cannot put open-space gravity into a periodic box (it is
    // refused at its table); put in by hand, it takes the pressure away.
    let charged = text.replace("[[spring]]", "[gravity]\nG = 1.0\n[[spring]]");
    let e = mote_md::scene::Scene::parse(&charged, "g.toml")
        .unwrap()
        .build(&charged, "g.toml", 1)
        .err()
        .unwrap();
    assert!(
        e.to_string()
            .contains("[gravity] sums over open space, and the [box] is periodic"),
        "{e}"
    );
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    sim.forces
        .push(mote_md::force::DirectGravity::new(1.0, 0.0));
    common::steps(sim, 1, |_| {});
    assert_eq!(sim.forces.without_virial(), ["gravity"]);
    assert!(Observables::measure(&sim.system, &mut sim.forces)
        .pressure
        .is_nan());
}
