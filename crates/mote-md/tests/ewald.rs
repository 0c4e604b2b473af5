//! Ewald sums against direct sums over periodic images, and forces,
//! fields and torques against finite differences of the energy.
//!
//! The image-sum references use configurations invariant under the 48
//! symmetries of the cube (about the box centre): such a cell has no net
//! charge, dipole, quadrupole or octupole moment, so the sum over images
//! in spherical order has no surface term (it equals the tin-foil result)
//! and converges like K⁻⁶ in the image radius K.

use mote_md::force::ewald::Ewald;
use mote_md::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const L: f64 = 1.0;

/// The 48 signed permutation matrices, as maps of vectors.
fn cube_group() -> Vec<Box<dyn Fn(DVec3) -> DVec3>> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out: Vec<Box<dyn Fn(DVec3) -> DVec3>> = Vec::new();
    for p in perms {
        for signs in 0..8 {
            let s = [
                if signs & 1 != 0 { -1.0 } else { 1.0 },
                if signs & 2 != 0 { -1.0 } else { 1.0 },
                if signs & 4 != 0 { -1.0 } else { 1.0 },
            ];
            out.push(Box::new(move |v: DVec3| {
                DVec3::new(s[0] * v[p[0]], s[1] * v[p[1]], s[2] * v[p[2]])
            }));
        }
    }
    out
}

/// The orbit of base offsets (from the box centre) under the cube group,
/// each carrying a vector attribute transformed alongside.
fn orbit(base: &[(DVec3, DVec3)]) -> (Vec<DVec3>, Vec<DVec3>, Vec<usize>) {
    let centre = DVec3::splat(0.5 * L);
    let (mut pos, mut vec, mut which) = (Vec::new(), Vec::new(), Vec::new());
    for g in cube_group() {
        for (k, (d, v)) in base.iter().enumerate() {
            pos.push(centre + g(*d));
            vec.push(g(*v));
            which.push(k);
        }
    }
    (pos, vec, which)
}

/// Σ over image cells n with |n| ≤ K of ½ Σ_{i,j}' u(r_i − r_j + nL).
fn image_sum(pos: &[DVec3], k: i32, pair: impl Fn(usize, usize, DVec3) -> f64) -> f64 {
    let mut total = 0.0;
    for a in -k..=k {
        for b in -k..=k {
            for c in -k..=k {
                if a * a + b * b + c * c > k * k {
                    continue;
                }
                let shift = DVec3::new(a as f64, b as f64, c as f64) * L;
                let mut cell = 0.0;
                for i in 0..pos.len() {
                    for j in 0..pos.len() {
                        if i == j && (a, b, c) == (0, 0, 0) {
                            continue;
                        }
                        cell += pair(i, j, pos[i] - pos[j] + shift);
                    }
                }
                total += 0.5 * cell;
            }
        }
    }
    total
}

#[test]
fn charges_agree_with_the_image_sum() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let qs = [1.0, -1.0, 0.6, -0.6];
    let base: Vec<(DVec3, DVec3)> = qs
        .iter()
        .map(|_| {
            let d = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.9 - DVec3::splat(0.45);
            (d, DVec3::ZERO)
        })
        .collect();
    let (pos, _, which) = orbit(&base);
    let q: Vec<f64> = which.iter().map(|&k| qs[k]).collect();
    let ewald = Ewald::for_charges(L, 0.5 * L, 1e-10, &q);
    let u = ewald.charges(&pos, &q, None);
    println!(
        "N = {}, α = {:.4}, n_max = {}, estimated force error {:.1e}: U = {u:.12}",
        pos.len(),
        ewald.alpha,
        ewald.n_max,
        ewald.estimated_error()
    );
    let mut last = 0.0;
    for k in [4, 6, 8] {
        let direct = image_sum(&pos, k, |i, j, r| q[i] * q[j] / r.length());
        println!(
            "image sum |n| ≤ {k}: {direct:.12}, relative difference {:.2e}",
            ((direct - u) / u).abs()
        );
        last = direct;
    }
    assert!(
        ((last - u) / u).abs() < 1e-6,
        "Ewald {u} vs image sum {last}"
    );
}

#[test]
fn dipoles_agree_with_the_image_sum() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
    let base: Vec<(DVec3, DVec3)> = (0..3)
        .map(|_| {
            let d = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.9 - DVec3::splat(0.45);
            let m = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - DVec3::splat(0.5);
            (d, m)
        })
        .collect();
    let (pos, mu, _) = orbit(&base);
    let total: DVec3 = mu.iter().copied().sum();
    assert!(total.length() < 1e-12);
    let ewald = Ewald::for_dipoles(L, 0.5 * L, 1e-10, &mu);
    let n = pos.len();
    let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    let u = ewald.dipoles(&pos, &mu, &mut f, &mut h);
    println!(
        "N = {n}, α = {:.4}, n_max = {}, estimated force error {:.1e}: U = {u:.12}",
        ewald.alpha,
        ewald.n_max,
        ewald.estimated_error()
    );
    let mut last = 0.0;
    for k in [4, 6, 8] {
        let direct = image_sum(&pos, k, |i, j, r| {
            let r2 = r.length_squared();
            let r3 = r2 * r2.sqrt();
            (mu[i].dot(mu[j]) - 3.0 * mu[i].dot(r) * mu[j].dot(r) / r2) / r3
        });
        println!(
            "image sum |n| ≤ {k}: {direct:.12}, relative difference {:.2e}",
            ((direct - u) / u).abs()
        );
        last = direct;
    }
    assert!(
        ((last - u) / u).abs() < 1e-6,
        "Ewald {u} vs image sum {last}"
    );
}

fn random_box(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * L)
        .collect()
}

#[test]
fn charge_forces_are_minus_the_energy_gradient() {
    let pos = random_box(16, 3);
    let q: Vec<f64> = (0..16)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let ewald = Ewald::for_charges(L, 0.5 * L, 1e-10, &q);
    let mut f = vec![DVec3::ZERO; 16];
    ewald.charges(&pos, &q, Some(&mut f));
    let scale = f.iter().map(|v| v.length()).fold(0.0, f64::max);
    let h = 1e-5;
    let mut worst = 0.0f64;
    for i in [0, 5, 11] {
        for a in 0..3 {
            let mut p = pos.clone();
            p[i][a] += h;
            let up = ewald.charges(&p, &q, None);
            p[i][a] -= 2.0 * h;
            let down = ewald.charges(&p, &q, None);
            worst = worst.max((-(up - down) / (2.0 * h) - f[i][a]).abs() / scale);
        }
    }
    println!("largest |F + ∂U/∂r| / max |F| = {worst:.1e}");
    assert!(worst < 1e-7);
}

/// Rotates v about the unit `axis` by `angle` (Rodrigues).
fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * axis.dot(v) * (1.0 - c)
}

#[test]
fn dipole_forces_and_torques_are_energy_derivatives() {
    let n = 12;
    let pos = random_box(n, 4);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let mu: Vec<DVec3> = (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) - DVec3::splat(0.5))
        .collect();
    let ewald = Ewald::for_dipoles(L, 0.5 * L, 1e-10, &mu);
    let energy = |p: &[DVec3], m: &[DVec3]| {
        let (mut f, mut h) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        ewald.dipoles(p, m, &mut f, &mut h)
    };
    let (mut f, mut field) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    ewald.dipoles(&pos, &mu, &mut f, &mut field);
    let f_scale = f.iter().map(|v| v.length()).fold(0.0, f64::max);
    let torque: Vec<DVec3> = (0..n).map(|i| mu[i].cross(field[i])).collect();
    let t_scale = torque.iter().map(|v| v.length()).fold(0.0, f64::max);
    let h = 1e-5;
    let (mut worst_f, mut worst_t) = (0.0f64, 0.0f64);
    for i in [0, 4, 9] {
        for a in 0..3 {
            let mut p = pos.clone();
            p[i][a] += h;
            let up = energy(&p, &mu);
            p[i][a] -= 2.0 * h;
            let down = energy(&p, &mu);
            worst_f = worst_f.max((-(up - down) / (2.0 * h) - f[i][a]).abs() / f_scale);
            let axis = [DVec3::X, DVec3::Y, DVec3::Z][a];
            let mut m = mu.clone();
            m[i] = rotate(mu[i], axis, h);
            let up = energy(&pos, &m);
            m[i] = rotate(mu[i], axis, -h);
            let down = energy(&pos, &m);
            worst_t = worst_t.max((-(up - down) / (2.0 * h) - torque[i][a]).abs() / t_scale);
        }
    }
    println!(
        "largest force error {worst_f:.1e}, torque error {worst_t:.1e} (relative to the largest)"
    );
    assert!(worst_f < 1e-7 && worst_t < 1e-7);
}

/// The RMS force error at a requested accuracy, measured against a much
/// tighter Ewald sum, is of the Kolafa–Perram estimate's size.
#[test]
fn requested_accuracy_is_met() {
    let n = 100;
    let pos = random_box(n, 6);
    let q: Vec<f64> = (0..n)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let reference = Ewald::for_charges(L, 0.5 * L, 1e-12, &q);
    let mut f_ref = vec![DVec3::ZERO; n];
    reference.charges(&pos, &q, Some(&mut f_ref));
    for accuracy in [1e-2, 1e-4] {
        let ewald = Ewald::for_charges(L, 0.5 * L, accuracy, &q);
        let mut f = vec![DVec3::ZERO; n];
        ewald.charges(&pos, &q, Some(&mut f));
        let rms = (f
            .iter()
            .zip(&f_ref)
            .map(|(a, b)| (*a - *b).length_squared())
            .sum::<f64>()
            / n as f64)
            .sqrt();
        println!(
            "requested {accuracy:.0e}: α = {:.3}, n_max = {}, estimate {:.2e}, measured RMS {rms:.2e}",
            ewald.alpha,
            ewald.n_max,
            ewald.estimated_error()
        );
        assert!(
            rms < 2.0 * accuracy,
            "measured {rms:e} for requested {accuracy:e}"
        );
    }
}
