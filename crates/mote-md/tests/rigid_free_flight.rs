//! The centre of mass of a free, spinning, moving body must move on a
//! straight line. `FreeFlight::Straight` does so to rounding; the seed's
//! literal update `g = E(r, 0) ∘ exp(h_c·Δt) ∘ E(0, x)` (`FreeFlight::Screw`)
//! moves it on screw arcs whose chords are turned by ≈ |ω|Δt/2, so its path
//! error grows ∝ Δt·t — measured here.

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::{dumbbell, BodyTemplate, Frbi, FreeFlight, Integration, RigidBodies};

fn path_error(flight: FreeFlight, dt: f64) -> f64 {
    let t = BodyTemplate::new(&dumbbell(0.5, 1.5, 1.0), Integration::default()).unwrap();
    let mut b = RigidBodies::new();
    let k = b.add_template(t);
    let (x0, v) = (DVec3::new(1.0, -2.0, 0.5), DVec3::new(1.0, 0.3, 0.0));
    b.push(
        k,
        E::new(DVec3::new(0.1, 0.2, 0.3), x0),
        DE::new(DVec3::new(0.2, -0.4, 2.0), v),
    );
    let mut f = Frbi::new();
    f.flight = flight;
    let steps = (10.0 / dt).round() as usize;
    for _ in 0..steps {
        f.step(&mut b, dt);
    }
    let exact = x0 + v * b.time;
    (b.position[0] - exact).length()
}

#[test]
fn centre_of_mass_moves_straight() {
    let e = path_error(FreeFlight::Straight, 1e-2);
    eprintln!("Straight, dt = 1e-2, t = 10: |x − (x₀ + v t)| = {e:.2e}");
    assert!(e < 1e-12);
    let e1 = path_error(FreeFlight::Screw, 1e-2);
    let e2 = path_error(FreeFlight::Screw, 5e-3);
    let order = (e1 / e2).log2();
    eprintln!("Screw (seed literal), t = 10: error {e1:.3e} at dt = 1e-2, {e2:.3e} at 5e-3: order {order:.2}");
    assert!(
        (0.8..1.2).contains(&order),
        "the seed's screw flight errs ∝ dt"
    );
}
