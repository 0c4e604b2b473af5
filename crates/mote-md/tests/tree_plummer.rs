//! The Plummer sampler (Aarseth, Hénon & Wielen 1974) reproduces the
//! model's mass profile and is in virial equilibrium.

use mote_md::force::{DirectGravity, Interaction, State};
use mote_md::tree::PlummerSphere;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

#[test]
fn plummer_sample_has_the_model_profile_and_energies() {
    let sphere = PlummerSphere {
        n: 20_000,
        mass: 2.0,
        radius: 0.5,
        g: 1.5,
        max_radius: None,
    };
    let (pos, vel) = sphere.sample(&mut Xoshiro256PlusPlus::seed_from_u64(17));
    let n = pos.len() as f64;
    let m = sphere.mass / n;
    // Fractions of the sample inside a r_k against M(r)/M = r³/(r² + a²)^{3/2}.
    let mut radii: Vec<f64> = pos.iter().map(|r| r.length()).collect();
    radii.sort_by(f64::total_cmp);
    for frac in [0.1, 0.25, 0.5, 0.75, 0.9] {
        let r = radii[(frac * n) as usize] / sphere.radius;
        let model = r.powi(3) / (r * r + 1.0).powf(1.5);
        // Binomial standard error √(f(1 − f)/N) ≤ 0.0035.
        assert!(
            (model - frac).abs() < 0.012,
            "fraction {frac}: model {model}"
        );
    }
    let mass = vec![m; pos.len()];
    let state = State::new(&pos, &vel, &mass, 0.0);
    let u = DirectGravity::new(sphere.g, 0.0).potential_energy(&state);
    let k: f64 = vel.iter().map(|v| 0.5 * m * v.length_squared()).sum();
    let model = sphere.potential_energy();
    println!(
        "U = {u:.5} (model {model:.5}), 2K/|U| = {:.4}",
        2.0 * k / u.abs()
    );
    assert!(((u - model) / model).abs() < 0.03);
    assert!((2.0 * k / u.abs() - 1.0).abs() < 0.03);
}
