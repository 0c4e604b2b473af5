//! An MPPphys particle file and its TOML twin run identical physics.

use crate::common;

use mote_md::scene::{PlistSystem, Scene};

fn run_plist(text: &str, system: PlistSystem, solver: &str, n: u64) -> Vec<mote_md::DVec3> {
    let pf = mote_io::plist::parse(text, "twin.plist").unwrap();
    let scene = Scene::from_plist(&pf, system, solver, "twin.plist").unwrap();
    let mut sim = scene.build("", "twin.plist", 1).unwrap().simulation;
    common::steps(&mut sim, n, |_| {});
    sim.system.particles.position
}

fn run_toml(text: &str, n: u64) -> Vec<mote_md::DVec3> {
    let mut sim = common::build(text).simulation;
    common::steps(&mut sim, n, |_| {});
    sim.system.particles.position
}

#[test]
fn nbody_plist_equals_scene() {
    let plist = "\
pos 0 0.0 0.0 0.0 1.0 0.0 0.1 1.0 1.0 0.0
pos 1 1.0 0.0 0.0 3e-6 0.0 0.03 0.3 0.3 1.0
pos 2 0.0 1.5 0.2 1e-3 0.0 0.03 0.3 0.3 1.0
vel 1 0.0 0.0172 0.0
vel 2 -0.014 0.0 0.0
vfix 0 1 1 0
k2 2.9584e-4
eps 0.001
dt 0.03
";
    let toml = r#"
units = "astro"
[run]
integrator = "LF"
dt = 0.03
[gravity]
G = 2.9584e-4
softening = 0.001
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
free = [true, true, false]
[[particle]]
position = [1.0, 0.0, 0.0]
velocity = [0.0, 0.0172, 0.0]
mass = 3e-6
[[particle]]
position = [0.0, 1.5, 0.2]
velocity = [-0.014, 0.0, 0.0]
mass = 1e-3
"#;
    for solver in ["LF", "RK4", "euler"] {
        let t = toml.replace("\"LF\"", &format!("\"{solver}\""));
        let a = run_plist(plist, PlistSystem::Nbody, solver, 5000);
        let b = run_toml(&t, 5000);
        assert_eq!(a, b, "{solver}");
        assert!(a[1] != mote_md::DVec3::new(1.0, 0.0, 0.0));
    }
}

#[test]
fn springs_plist_equals_scene() {
    let plist = "\
# a triangle of springs hanging from a fixed point, damped
pos 0 0 0 0 1 0 0.01
pos 1 1 0 0 2 0 0.01
pos 2 0.5 0 -0.8 1 0 0.01
vfix 0 0 0 0
s 0 50.0 0.1
s 1 20.0 0.0
sl 0 1 0
sl 1 2 1
sl 2 0 1 0.9
dis 2 0.1 0.0 0.05
grav 0 0 -9.81
damp 0.02
dt 0.001
";
    let toml = r#"
[run]
integrator = "rk4"
dt = 0.001
[field]
g = [0.0, 0.0, -9.81]
[damping]
gamma = 0.02
[[particle]]
position = [0.0, 0.0, 0.0]
radius = 0.01
free = [false, false, false]
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 2.0
radius = 0.01
[[particle]]
position = [0.5, 0.0, -0.8]
displacement = [0.1, 0.0, 0.05]
radius = 0.01
[[spring]]
pairs = [[0, 1]]
stiffness = 50.0
damping = 0.1
[[spring]]
pairs = [[1, 2]]
stiffness = 20.0
[[spring]]
pairs = [[2, 0]]
stiffness = 20.0
rest_length = 0.9
"#;
    let a = run_plist(plist, PlistSystem::Springs, "RK4", 3000);
    let b = run_toml(toml, 3000);
    assert_eq!(a, b);
    assert_eq!(a[0], mote_md::DVec3::ZERO);
}
