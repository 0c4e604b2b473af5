//! The pressure tensor P_αβ V = Σ m v_α v_β + W_αβ (`[output]
//! pressure_tensor`) against closed forms: the ideal gas, a strained
//! spring lattice, a static ionic crystal, two pressed grains; its trace
//! against the scalar pressure every run writes; the scenes that cannot
//! have it refused at their line.

use glam::DVec3;
use mote_md::scene::Scene;
use mote_md::Observables;

use crate::common;
use crate::electric_scenes::rock_salt;

const PERIODIC_BOX: &str =
    "[box]\nlo = [0.0, 0.0, 0.0]\nhi = [{L}, {L}, {L}]\nperiodic = [true, true, true]\n";

fn measure(text: &str) -> Observables {
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    assert!(sim.forces.pressure_tensor, "the scene asks for the tensor");
    Observables::measure(&sim.system, &mut sim.forces)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

/// No forces: P_αβ V = Σ m v_α v_β, off-diagonal entries included.
#[test]
fn ideal_gas_tensor_is_the_kinetic_one() {
    let mut text = "units = \"lj\"\n[run]\ndt = 0.01\n[output]\npressure_tensor = true\n"
        .to_string()
        + &PERIODIC_BOX.replace("{L}", "3.0");
    let particles = [
        (1.0, DVec3::new(0.3, -1.2, 0.7)),
        (2.0, DVec3::new(-0.5, 0.4, 1.1)),
        (0.5, DVec3::new(1.5, 0.2, -0.9)),
    ];
    let mut expected = [0.0; 6];
    for (k, (m, v)) in particles.iter().enumerate() {
        text += &format!(
            "[[particle]]\nposition = [{k}.0, 1.0, 1.0]\nmass = {m:?}\nvelocity = [{:?}, {:?}, {:?}]\n",
            v.x, v.y, v.z
        );
        for (e, x) in expected.iter_mut().zip([
            v.x * v.x,
            v.y * v.y,
            v.z * v.z,
            v.x * v.y,
            v.x * v.z,
            v.y * v.z,
        ]) {
            *e += m * x / 27.0;
        }
    }
    let o = measure(&text);
    for (a, (p, e)) in o.pressure_tensor.iter().zip(expected).enumerate() {
        assert!(close(*p, e, 1e-14), "entry {a}: {p} against {e}");
    }
    let trace = o.pressure_tensor[..3].iter().sum::<f64>();
    assert!(close(trace / 3.0, o.pressure, 1e-14));
}

/// A simple cubic lattice of springs (rest length 1, stiffness D) in a
/// periodic box, stretched to spacing a along x: every x bond pulls with
/// D (a − 1), so P_xx = −N D (a − 1) a / V, and P_yy = P_zz = 0 (bonds at
/// rest) with no shear. The bonds that cross the box's faces count as the
/// others do (minimum image), and no particle feels a net force.
#[test]
fn strained_spring_lattice_has_the_closed_form_stress() {
    let (n, a, d) = (4usize, 1.2, 3.0);
    let lengths = [n as f64 * a, n as f64, n as f64];
    let mut text = format!(
        "units = \"lj\"\n[run]\ndt = 0.001\n[output]\npressure_tensor = true\n\
         [box]\nlo = [0.0, 0.0, 0.0]\nhi = [{:?}, {:?}, {:?}]\nperiodic = [true, true, true]\n",
        lengths[0], lengths[1], lengths[2]
    );
    let index = |i: usize, j: usize, k: usize| (i % n * n + j % n) * n + k % n;
    let mut pairs = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                text += &format!(
                    "[[particle]]\nposition = [{:?}, {:?}, {:?}]\n",
                    (i as f64 + 0.5) * a,
                    j as f64 + 0.5,
                    k as f64 + 0.5
                );
                let me = index(i, j, k);
                pairs.push([me, index(i + 1, j, k)]);
                pairs.push([me, index(i, j + 1, k)]);
                pairs.push([me, index(i, j, k + 1)]);
            }
        }
    }
    text += &format!("[[spring]]\npairs = {pairs:?}\nstiffness = {d:?}\nrest_length = 1.0\n");
    let mut built = common::build(&text);
    let sim = &mut built.simulation;
    common::steps(sim, 1, |_| {});
    let moved = sim
        .system
        .particles
        .velocity
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max);
    assert!(moved < 1e-12, "a particle moved: |v| = {moved}");
    let o = Observables::measure(&sim.system, &mut sim.forces);
    let volume = lengths.iter().product::<f64>();
    let pxx = -((n * n * n) as f64) * d * (a - 1.0) * a / volume;
    let p = o.pressure_tensor;
    assert!(close(p[0], pxx, 1e-12), "P_xx = {}, expected {pxx}", p[0]);
    for (k, entry) in p.iter().enumerate().skip(1) {
        assert!(entry.abs() < 1e-12 * pxx.abs(), "entry {k} = {entry}");
    }
    assert!(close(p[0] / 3.0, o.pressure, 1e-12));
}

/// Rock salt under Ewald: by cubic symmetry P_xx = P_yy = P_zz = U/(3V)
/// and no shear, to the Ewald sum's accuracy.
#[test]
fn static_rock_salt_stress_is_u_over_3v_on_each_axis() {
    let text = rock_salt("method = \"ewald\"\naccuracy = 1e-12").replacen(
        "[run]",
        "[output]\npressure_tensor = true\n[run]",
        1,
    );
    let o = measure(&text);
    let expected = o.potential / (3.0 * 8.0);
    for a in 0..3 {
        let p = o.pressure_tensor[a];
        assert!(
            close(p, expected, 1e-6),
            "P_{a}{a} = {p}, U/(3V) = {expected}"
        );
        let shear = o.pressure_tensor[3 + a];
        assert!(shear.abs() < 1e-6 * expected.abs(), "shear {a} = {shear}");
    }
}

/// Two grains pressed together along x (Hertz, at rest): W_xx = r·F > 0,
/// the only entry; its trace is the virial of the scalar pressure.
#[test]
fn pressed_grains_push_along_their_line() {
    let text = "units = \"lj\"\n[run]\ndt = 1e-6\n[output]\npressure_tensor = true\n\
        [box]\nlo = [0.0, 0.0, 0.0]\nhi = [4.0, 4.0, 4.0]\nperiodic = [true, true, true]\n\
        [granular]\nyoung = 1e4\npoisson = 0.3\nrestitution = 0.9\nfriction = 0.5\n\
        [[particle]]\nposition = [1.5, 2.0, 2.0]\nradius = 0.5\n\
        [[particle]]\nposition = [2.45, 2.0, 2.0]\nradius = 0.5\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    common::steps(sim, 1, |_| {});
    let o = Observables::measure(&sim.system, &mut sim.forces);
    let p = o.pressure_tensor;
    assert!(p[0] > 0.0, "P_xx = {}", p[0]);
    for (k, entry) in p.iter().enumerate().skip(1) {
        assert!(entry.abs() < 1e-6 * p[0], "entry {k} = {entry}");
    }
    assert!(close(p.iter().take(3).sum::<f64>() / 3.0, o.pressure, 1e-9));
}

/// The Lennard-Jones tensor (a portable pass at measurement) and the
/// scalar virial of the step's kernel agree on a liquid, whatever kernel
/// the CPU runs.
#[test]
fn lennard_jones_tensor_trace_is_the_kernels_virial() {
    let text = "units = \"lj\"\nseed = 3\n[run]\ndt = 0.005\n[output]\npressure_tensor = true\n\
        [lennard_jones]\nepsilon = 1.0\nsigma = 1.0\ncutoff = 2.5\n\
        [[fcc]]\ncells = [5, 5, 5]\ndensity = 0.8\nkt = 1.2\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    common::steps(sim, 50, |_| {});
    let o = Observables::measure(&sim.system, &mut sim.forces);
    let trace = o.pressure_tensor.iter().take(3).sum::<f64>();
    assert!(
        close(trace / 3.0, o.pressure, 1e-10),
        "tr/3 {} against P {}",
        trace / 3.0,
        o.pressure
    );
    let shear = o.pressure_tensor[3..]
        .iter()
        .map(|s| s.abs())
        .fold(0.0, f64::max);
    assert!(
        shear < o.pressure.abs(),
        "a liquid bears no large shear: {shear}"
    );
}

/// A dipolar fluid with a cut-off and WCA cores: the tensor (a portable
/// pass) and the scalar virial of the step's kernel agree.
#[test]
fn dipolar_tensor_trace_is_the_kernels_virial() {
    let text = "units = \"lj\"\nseed = 5\n[run]\ndt = 0.002\n[output]\npressure_tensor = true\n\
        [dipolar]\nmu0 = 12.566370614359172\ncutoff = 2.5\nwca = { epsilon = 1.0, sigma = 1.0 }\n\
        [[fcc]]\ncells = [4, 4, 4]\ndensity = 0.7\nkt = 1.0\ndipole = [0.0, 0.0, 1.5]\nradius = 0.5\n";
    let mut built = common::build(text);
    let sim = &mut built.simulation;
    common::steps(sim, 20, |_| {});
    let o = Observables::measure(&sim.system, &mut sim.forces);
    let trace = o.pressure_tensor.iter().take(3).sum::<f64>();
    assert!(o.pressure.is_finite() && o.pressure != 0.0);
    assert!(
        close(trace / 3.0, o.pressure, 1e-10),
        "tr/3 {} against P {}",
        trace / 3.0,
        o.pressure
    );
}

/// Where the tensor cannot be given, the scene is refused at the key.
#[test]
fn scenes_that_cannot_have_the_tensor_are_refused() {
    let open = "units = \"lj\"\n[run]\ndt = 0.01\n[output]\npressure_tensor = true\n\
        [[particle]]\nposition = [0.0, 0.0, 0.0]\n";
    let dipolar = format!(
        "units = \"lj\"\n[run]\ndt = 0.01\n[output]\npressure_tensor = true\n{}\
         [dipolar]\nmethod = \"ewald\"\naccuracy = 1e-4\n\
         [[particle]]\nposition = [1.0, 1.0, 1.0]\ndipole = [0.0, 0.0, 1.0]\n",
        PERIODIC_BOX.replace("{L}", "4.0")
    );
    for (text, words) in [
        (open.to_string(), "periodic on every axis"),
        (dipolar, "dipolar"),
    ] {
        let scene = Scene::parse(&text, "s.toml").unwrap();
        let e = match scene.build(&text, "s.toml", 1) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("must be refused:\n{text}"),
        };
        assert!(e.starts_with("s.toml:5:") && e.contains(words), "{e}");
    }
}
