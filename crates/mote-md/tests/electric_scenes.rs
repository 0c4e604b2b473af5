//! Charges, electric fields and Ewald sums reached from scene files, against
//! closed forms: the Madelung constant of rock salt, the tin-foil energy of
//! a cubic lattice of parallel dipoles, Coulomb's circular orbit, and a
//! charge accelerated by a constant and an oscillating field.

mod common;

use mote_md::{DVec3, Observables};

/// Madelung constant of rock salt for the nearest-neighbour distance
/// (Kittel, *Introduction to Solid State Physics*, ch. 3).
const MADELUNG_NACL: f64 = 1.747_564_594_633;

/// The 8 ions of rock salt's cubic cell (nearest-neighbour distance 1) in a
/// periodic box of side 2.
fn rock_salt(method_keys: &str) -> String {
    let mut s = format!(
        "units = \"lj\"\n[run]\ndt = 0.001\n[box]\nlo = [0.0, 0.0, 0.0]\nhi = [2.0, 2.0, 2.0]\nperiodic = [true, true, true]\n[coulomb]\n{method_keys}\n"
    );
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                let q = if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 };
                s += &format!(
                    "[[particle]]\nposition = [{}.25, {}.25, {}.25]\ncharge = {q:.1}\n",
                    i, j, k
                );
            }
        }
    }
    s
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
