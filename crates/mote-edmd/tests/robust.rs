//! The collision prediction near contact (Bannerman et al. arXiv:1211.6718):
//! no pass-through and no spurious overlap from round-off.

use mote_edmd::{pair_time, Boundary, SimBox, System};

#[test]
fn touching_and_overlapping_pairs() {
    // at contact and approaching: collide now
    assert_eq!(pair_time(&[1.0, 0.0, 0.0], &[-1.0, 0.0, 0.0], 1.0), 0.0);
    // overlapping by round-off and approaching: collide now
    assert_eq!(
        pair_time(&[1.0 - 1e-15, 0.0, 0.0], &[-1.0, 0.0, 0.0], 1.0),
        0.0
    );
    // overlapping but separating: no event (it is leaving)
    assert_eq!(
        pair_time(&[1.0 - 1e-15, 0.0, 0.0], &[1.0, 0.0, 0.0], 1.0),
        f64::INFINITY
    );
    // grazing miss
    assert_eq!(
        pair_time(&[-5.0, 1.0 + 1e-12], &[1.0, 0.0], 1.0),
        f64::INFINITY
    );
    // head-on from far: exact
    assert_eq!(pair_time(&[-4.0, 0.0], &[1.0, 0.0], 1.0), 3.0);
}

/// Random pairs: the predicted time puts the pair at contact to round-off,
/// and the stable root formula agrees with the textbook one where that is
/// well conditioned.
#[test]
fn predicted_time_reaches_contact() {
    let mut x: u64 = 88172645463325252;
    let mut rnd = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut hits = 0;
    for _ in 0..100_000 {
        let r = [3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd()];
        let v = [rnd(), rnd(), rnd()];
        let sigma = 1.0;
        let r2: f64 = r.iter().map(|a| a * a).sum();
        if r2 < 1.0 {
            continue;
        }
        let t = pair_time(&r, &v, sigma);
        if t.is_finite() {
            hits += 1;
            let rc: Vec<f64> = (0..3).map(|d| r[d] + v[d] * t).collect();
            let dist = rc.iter().map(|a| a * a).sum::<f64>().sqrt();
            assert!(
                (dist - 1.0).abs() < 1e-9 * (1.0 + t),
                "dist {dist} at t {t}"
            );
        }
    }
    assert!(hits > 1000);
}

/// A fast pair that starts a hair apart (1e-15 σ) must bounce, not pass.
#[test]
fn near_contact_pair_does_not_pass_through() {
    let simbox = SimBox {
        size: [10.0, 10.0],
        boundary: [Boundary::Periodic; 2],
    };
    let mut sys = System::<2>::new(
        simbox,
        vec![[4.0, 5.0], [5.0 + 1e-15, 5.0]],
        vec![[1e3, 0.0], [-1e3, 0.0]],
        vec![0.5, 0.5],
        vec![1.0, 1.0],
    )
    .unwrap();
    sys.run_until(1e-3);
    assert_eq!(sys.counters().collisions, 1);
    assert!(sys.velocity(0)[0] < 0.0 && sys.velocity(1)[0] > 0.0);
    assert!(sys.find_overlap_all_pairs(1e-12).is_none());
}

#[test]
fn overlapping_initial_state_is_rejected() {
    let simbox = SimBox {
        size: [10.0, 10.0, 10.0],
        boundary: [Boundary::Wall; 3],
    };
    let e = System::<3>::new(
        simbox,
        vec![[4.0, 5.0, 5.0], [4.9, 5.0, 5.0]],
        vec![[0.0; 3]; 2],
        vec![0.5, 0.5],
        vec![1.0, 1.0],
    )
    .unwrap_err();
    assert!(e.to_string().contains("overlap"), "{e}");
}

/// Particles are stored in spatial (Morton) order inside; every accessor
/// keeps the caller's numbering.
#[test]
fn numbering_is_the_callers() {
    let simbox = SimBox {
        size: [20.0, 20.0],
        boundary: [Boundary::Periodic, Boundary::Wall],
    };
    // a reversed, interleaved order so that the internal order differs
    let mut pos = Vec::new();
    for k in (0..50).rev() {
        pos.push([(k % 10) as f64 * 2.0 + 1.0, (k / 10) as f64 * 3.0 + 1.5]);
    }
    let vel: Vec<[f64; 2]> = (0..50)
        .map(|k| [k as f64 * 0.01, -(k as f64) * 0.02])
        .collect();
    let radii: Vec<f64> = (0..50).map(|k| 0.3 + 0.001 * k as f64).collect();
    let masses: Vec<f64> = (0..50).map(|k| 1.0 + k as f64).collect();
    let sys = System::<2>::new(
        simbox,
        pos.clone(),
        vel.clone(),
        radii.clone(),
        masses.clone(),
    )
    .unwrap();
    assert_eq!(sys.positions(), pos);
    assert_eq!(sys.velocities(), vel);
    assert_eq!(sys.radii(), radii);
    assert_eq!(sys.masses(), masses);
    for i in 0..50 {
        assert_eq!(sys.velocity(i), vel[i]);
        assert_eq!(sys.radius(i), radii[i]);
    }
    // an overlap is reported with the caller's indices
    let mut p2 = pos.clone();
    p2[7] = [p2[3][0] + 0.1, p2[3][1]];
    let e = System::<2>::new(simbox, p2, vel, radii, masses).unwrap_err();
    assert!(e.to_string().contains("particles 3 and 7"), "{e}");
}

/// The vector neighbour scan (AVX-512 where the CPU has it, else eight
/// neighbours at a time on `Lanes`) and the scalar loop give bit-identical
/// runs: same collisions, same positions and velocities, with and without
/// growth, D = 2 and 3, polydisperse, walls and periodic axes.
#[test]
fn vector_and_scalar_scans_agree_bit_for_bit() {
    use mote_edmd::init::{random_placement, thermal_velocities};
    use rand::SeedableRng;
    fn run<const D: usize>(growth: f64, simd: bool) -> (u64, Vec<[f64; D]>, Vec<[f64; D]>) {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let n = 400;
        let radii: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 0.7 } else { 0.5 }).collect();
        let size = [if D == 2 { 30.0 } else { 14.0 }; D];
        let mut periodic = [true; D];
        periodic[0] = false;
        let pos = random_placement(&radii, size, periodic, &mut rng, 10_000).unwrap();
        let masses: Vec<f64> = radii.iter().map(|r| r * r * r).collect();
        let vel = thermal_velocities::<D, _>(&masses, 1.0, &mut rng);
        let mut boundary = [Boundary::Periodic; D];
        boundary[0] = Boundary::Wall;
        let simbox = SimBox { size, boundary };
        let horizon = if growth > 0.0 { 2.0 } else { f64::INFINITY };
        let mut sys =
            System::with_growth(simbox, pos, vel, radii, masses, growth, horizon).unwrap();
        sys.set_simd(simd);
        sys.run_until(if growth > 0.0 { 2.0 } else { 20.0 });
        (sys.counters().collisions, sys.positions(), sys.velocities())
    }
    for growth in [0.0, 0.1] {
        let (c0, x0, v0) = run::<3>(growth, false);
        let (c1, x1, v1) = run::<3>(growth, true);
        assert!(c0 > 1000, "only {c0} collisions");
        assert_eq!((c0, &x0, &v0), (c1, &x1, &v1), "3-D, growth {growth}");
        let (c0, x0, v0) = run::<2>(growth, false);
        let (c1, x1, v1) = run::<2>(growth, true);
        assert!(c0 > 1000, "only {c0} collisions");
        assert_eq!((c0, &x0, &v0), (c1, &x1, &v1), "2-D, growth {growth}");
    }
}
