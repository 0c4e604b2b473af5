//! Packing by growth (Lubachevsky–Stillinger): the growing-contact
//! prediction, the collision rule in the growing frame, the stop criteria and
//! jammed packings.
//!
//! The default tests are small and fast. The validation against
//! spheropack's published φ_J curve, the 2-D bidisperse packing, the
//! lognormal family against `mote rcp` and the isostatic N = 10⁴ packing are
//! `#[ignore]`d (minutes each): run them with
//! `cargo test --release -p mote-edmd --test edmd pack:: -- --ignored --nocapture`.

use mote_edmd::analyse::{bond_order, contacts, deepest_overlap};
use mote_edmd::pack::{Finish, PackSettings, Packer, SizeSpec, Stop};
use mote_edmd::{growing_pair_time, Boundary, SimBox, System};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The root is a contact of the growing spheres and no earlier time is.
#[test]
fn growing_contact_time_is_the_first_touch() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut found = 0;
    for _ in 0..20_000 {
        let r: [f64; 3] = [0.0; 3].map(|_| rng.gen_range(-3.0..3.0));
        let v: [f64; 3] = [0.0; 3].map(|_| rng.gen_range(-1.0..1.0));
        let sigma = 1.0;
        let s = rng.gen_range(0.0..1.5);
        let gap = |t: f64| {
            let x: Vec<f64> = (0..3).map(|d| r[d] + v[d] * t).collect();
            (x.iter().map(|a| a * a).sum::<f64>()).sqrt() - (sigma + s * t)
        };
        if gap(0.0) <= 0.0 {
            continue;
        }
        let t = growing_pair_time(&r, &v, sigma, s);
        if t.is_finite() {
            found += 1;
            assert!(gap(t).abs() < 1e-9 * (1.0 + t), "gap {} at t {t}", gap(t));
            for k in 1..50 {
                assert!(gap(t * k as f64 / 50.0) > -1e-9, "touches before {t}");
            }
        } else {
            // no contact within a long time
            for k in 0..200 {
                assert!(gap(k as f64 * 0.1) > 0.0);
            }
        }
    }
    assert!(found > 1000);
}

/// Head-on pair of equal masses: after the collision the normal relative
/// velocity is 2s − u_n (KTS rule), momentum is kept, radii grow as r(0)(1 + δt).
#[test]
fn growing_collision_reflects_in_the_growing_frame() {
    let simbox = SimBox {
        size: [20.0; 3],
        boundary: [Boundary::Periodic; 3],
    };
    let delta = 0.1;
    let mut sys = System::with_growth(
        simbox,
        vec![[8.0, 10.0, 10.0], [12.0, 10.0, 10.0]],
        vec![[0.5, 0.0, 0.0], [-0.3, 0.0, 0.0]],
        vec![0.5, 1.0],
        vec![1.0, 1.0],
        delta,
        5.0,
    )
    .unwrap();
    // contact: 4 − 0.8 t = 1.5 (1 + 0.1 t)  →  t = 2.5 / 0.95
    let tc = 2.5 / 0.95;
    sys.run_until(tc * 0.999);
    assert_eq!(sys.counters().collisions, 0);
    sys.run_until(tc * 1.001);
    assert_eq!(sys.counters().collisions, 1);
    let (v1, v2) = (sys.velocity(0)[0], sys.velocity(1)[0]);
    let s = 1.5 * delta;
    // u_n = (v2 − v1)·n with n from 1 to 2 (+x): −0.8 → 2s + 0.8
    assert!(((v2 - v1) - (2.0 * s + 0.8)).abs() < 1e-12);
    assert!((v1 + v2 - 0.2).abs() < 1e-12);
    let g = 1.0 + delta * sys.time();
    assert!((sys.radius(1) - g).abs() < 1e-12);
}

fn settings(n: usize, rate: f64, seed: u64) -> PackSettings {
    PackSettings {
        n,
        rate,
        seed,
        ..PackSettings::default()
    }
}

/// Exact overlap check of the final state: every pair that can touch.
fn assert_no_overlap<const D: usize>(p: &Packer<D>) {
    let sys = p.system();
    assert_eq!(sys.find_overlap(1e-12), None);
    let gap = deepest_overlap(sys.simbox(), &sys.positions(), &sys.radii());
    assert!(gap.is_none_or(|g| g.2 > -1e-12), "{gap:?}");
}

#[test]
fn small_jammed_packing_3d() {
    let mut s = settings(300, 0.1, 3);
    s.max_pressure = 1e9;
    s.finish = Some(Finish::default());
    let mut p = Packer::<3>::new(s).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_eq!(out.stop, Stop::Pressure);
    assert_no_overlap(&p);
    assert!(out.phi > 0.62 && out.phi < 0.65, "phi_J = {}", out.phi);
    let sys = p.system();
    // gaps of force-bearing contacts are ~1/Z = 1e-9: tolerance 1e-6
    let c = contacts(sys.simbox(), &sys.positions(), &sys.radii(), 1e-6);
    // jammed: few rattlers, backbone near isostatic (N = 300: 6(1 − 1/N) ≈ 6)
    assert!(c.rattlers() < 30, "{} rattlers", c.rattlers());
    assert!((c.backbone_z - 6.0).abs() < 0.4, "z = {}", c.backbone_z);
    // and still jammed at fixed size: the pressure stays high
    let mut relax = System::new(
        *sys.simbox(),
        sys.positions(),
        sys.velocities(),
        sys.radii(),
        sys.masses(),
    )
    .unwrap();
    relax.run_collisions(3000);
    assert!(
        relax.compressibility() > 1e7,
        "Z = {}",
        relax.compressibility()
    );
}

#[test]
fn faster_growth_jams_looser() {
    // Γ = 1 vs Γ = 0.1 without the quasi-static finish, N = 300, 3 seeds
    let mean = |rate: f64| {
        (1..=3)
            .map(|seed| {
                let mut s = settings(300, rate, seed);
                s.max_pressure = 1e6;
                let mut p = Packer::<3>::new(s).unwrap();
                let out = p.run(|_| {}).unwrap();
                assert_no_overlap(&p);
                out.phi
            })
            .sum::<f64>()
            / 3.0
    };
    let (fast, slow) = (mean(1.0), mean(0.1));
    assert!(slow > fast + 0.005, "Γ = 0.1: {slow}, Γ = 1: {fast}");
}

#[test]
fn bidisperse_disks_and_hexatic_order() {
    let mut s = settings(400, 0.1, 5);
    s.sizes = SizeSpec::Bidisperse {
        ratio: 1.4,
        large_fraction: 0.5,
    };
    s.max_pressure = 1e8;
    let mut p = Packer::<2>::new(s).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_no_overlap(&p);
    assert!(out.phi > 0.80 && out.phi < 0.86, "phi_J = {}", out.phi);
    let sys = p.system();
    let (psi6, _) = bond_order(sys.simbox(), &sys.positions(), &sys.radii(), 1.2);
    assert!(psi6 < 0.2, "|psi6| = {psi6}");
}

#[test]
fn stops_at_target_phi_budget_and_keeps_walls() {
    let mut s = settings(300, 0.1, 9);
    s.target_phi = Some(0.5);
    s.walls = vec![false, false, true];
    let mut p = Packer::<3>::new(s).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_eq!(out.stop, Stop::TargetPhi);
    assert!((out.phi - 0.5).abs() < 1e-9, "{}", out.phi);
    assert_no_overlap(&p);
    let sys = p.system();
    let lz = sys.simbox().size[2];
    for (x, r) in sys.positions().iter().zip(sys.radii()) {
        assert!(x[2] - r > -1e-12 && x[2] + r < lz + 1e-12);
    }
    let mut s = settings(300, 0.1, 9);
    s.max_collisions = Some(12_345);
    let out = Packer::<3>::new(s).unwrap().run(|_| {}).unwrap();
    assert_eq!(out.stop, Stop::Collisions);
    assert_eq!(out.collisions, 12_345);
}

#[test]
fn same_seed_same_packing() {
    let run = || {
        let mut s = settings(200, 0.3, 4);
        s.max_pressure = 1e5;
        let mut p = Packer::<3>::new(s).unwrap();
        p.run(|_| {}).unwrap();
        p.system().positions()
    };
    assert_eq!(run(), run());
}

#[test]
fn bad_settings_are_errors() {
    let mut s = settings(300, -1.0, 1);
    assert!(Packer::<3>::new(s.clone()).is_err());
    s.rate = 0.1;
    s.n = 1;
    assert!(Packer::<3>::new(s.clone()).is_err());
    s.n = 20; // box too small for the cells
    assert!(Packer::<3>::new(s).is_err());
    assert!(SizeSpec::parse("bi:0.5:0.5").is_err());
    assert!(SizeSpec::parse("lognormal:x").is_err());
    assert!(SizeSpec::parse("gauss:1").is_err());
}

// ----- validation (ignored: minutes) --------------------------------------

fn jammed_phi<const D: usize>(n: usize, sizes: SizeSpec, rate: f64, seed: u64) -> f64 {
    let mut s = settings(n, rate, seed);
    s.sizes = sizes;
    s.finish = Some(Finish::default());
    s.max_pressure = 1e9;
    let mut p = Packer::<D>::new(s).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_no_overlap(&p);
    assert_eq!(out.stop, Stop::Pressure);
    out.phi
}

fn spheropack_curve(rate: f64, published: f64) {
    let phis: Vec<f64> = (1..=5)
        .map(|seed| jammed_phi::<3>(1000, SizeSpec::Monodisperse, rate, seed))
        .collect();
    let mean = phis.iter().sum::<f64>() / 5.0;
    println!("Γ = {rate}: φ_J = {phis:?}, mean {mean:.4} (spheropack {published})");
    assert!(
        (mean - published).abs() < 0.003,
        "mean {mean} vs {published}"
    );
}

#[test]
#[ignore]
fn spheropack_curve_rate_0_1() {
    spheropack_curve(0.1, 0.6344);
}

#[test]
#[ignore]
fn spheropack_curve_rate_0_01() {
    spheropack_curve(0.01, 0.6439);
}

#[test]
#[ignore]
fn spheropack_curve_rate_0_001() {
    spheropack_curve(0.001, 0.6496);
}

#[test]
#[ignore]
fn bidisperse_disks_rate_0_01() {
    let sizes = SizeSpec::Bidisperse {
        ratio: 1.4,
        large_fraction: 0.5,
    };
    let phis: Vec<f64> = (1..=3)
        .map(|seed| jammed_phi::<2>(1000, sizes.clone(), 0.01, seed))
        .collect();
    let mean = phis.iter().sum::<f64>() / phis.len() as f64;
    println!("2-D 1:1.4 50/50, Γ = 0.01: {phis:?}, mean {mean:.4} (0.842)");
    assert!((mean - 0.842).abs() < 0.005);
}

#[test]
#[ignore]
fn lognormal_agrees_with_rod_packing_estimate() {
    for sigma in [0.1, 0.2, 0.3, 0.4, 0.5] {
        let sizes = SizeSpec::Lognormal { sigma };
        let rcp = mote_rcp::RodPacking::default()
            .estimate(&sizes.rcp_distribution().unwrap())
            .unwrap()
            .phi;
        // N = 2000 is too few at σ = 0.5 (the largest sphere outgrows a
        // third of the box); 10⁴ takes about a minute each here
        let phi = jammed_phi::<3>(10_000, sizes, 0.01, 1);
        println!("σ = {sigma}: φ_J = {phi:.4}, mote rcp {rcp:.4}");
        assert!((phi - rcp).abs() < 0.01, "σ = {sigma}: {phi} vs {rcp}");
    }
}

#[test]
#[ignore]
fn isostatic_at_ten_thousand() {
    let mut s = settings(10_000, 0.01, 1);
    s.finish = Some(Finish::default());
    s.max_pressure = 1e12;
    let mut p = Packer::<3>::new(s).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_no_overlap(&p);
    let sys = p.system();
    let (b, x, r) = (sys.simbox(), sys.positions(), sys.radii());
    let c = contacts(b, &x, &r, 1e-9);
    let (q6, _) = bond_order(b, &x, &r, 1.2);
    println!(
        "N = 10⁴, Γ = 0.01: φ_J = {:.5}, rattlers {}, backbone z = {:.4} at gap 1e-9, Q6 = {q6:.4}",
        out.phi,
        c.rattlers(),
        c.backbone_z
    );
    assert!((c.backbone_z / 6.0 - 1.0).abs() < 0.03);
    assert!(q6 < 0.05);
}

/// A packer resumed from any of its checkpoints, in growth or in the
/// quasi-static finish (at a cycle's top or inside one), ends with the bits of the run that wrote them.
#[test]
fn resumed_from_a_checkpoint_ends_bit_for_bit() {
    use mote_edmd::pack::{PackCheckpoints, PackState};
    let mut s = settings(200, 0.1, 5);
    s.max_pressure = 1e7;
    s.finish = Some(Finish::default());
    let mut states: Vec<PackState> = Vec::new();
    let mut p = Packer::<3>::new(s.clone()).unwrap();
    let mut save = |st: &PackState| {
        states.push(st.clone());
        Ok(())
    };
    let mut cps = PackCheckpoints {
        every: 3,
        save: &mut save,
    };
    let whole = p.run_with(|_| {}, Some(&mut cps)).unwrap();
    let (positions, radii) = (p.system().positions(), p.system().radii());
    assert!(
        states.iter().any(|s| s.finishing.is_some())
            && states.iter().any(|s| s.finishing.is_none())
    );
    // Growing, at a finish cycle's top, inside a cycle, and the last.
    let picks = [
        states.iter().position(|s| s.finishing.is_none()).unwrap(),
        states.iter().position(|s| s.finishing == Some(0)).unwrap(),
        states
            .iter()
            .position(|s| s.finishing.is_some_and(|k| k > 0))
            .unwrap(),
        states.len() - 1,
    ];
    let dir = tempfile::tempdir().unwrap();
    for k in picks {
        // Through a checkpoint file, bit for bit.
        let file = dir.path().join("p.mote");
        let cp = states[k].to_checkpoint(&mote_io::checkpoint::Checkpoint::default());
        mote_io::checkpoint::write(&file, &cp).unwrap();
        let read = mote_io::checkpoint::read(&file).unwrap();
        assert_eq!(PackState::from_checkpoint(&read, 3).unwrap(), states[k]);
        let mut again = Packer::<3>::resume(s.clone(), &states[k]).unwrap();
        let mut later = Vec::new();
        let mut save = |st: &PackState| {
            later.push(st.clone());
            Ok(())
        };
        let mut cps = PackCheckpoints {
            every: 3,
            save: &mut save,
        };
        let out = again.run_with(|_| {}, Some(&mut cps)).unwrap();
        assert_eq!(out.collisions, whole.collisions, "from checkpoint {k}");
        assert_eq!(out.phi.to_bits(), whole.phi.to_bits());
        assert_eq!(out.history, whole.history);
        assert_eq!(again.system().positions(), positions);
        assert_eq!(again.system().radii(), radii);
        // And it writes the checkpoints the whole run wrote after k.
        assert_eq!(later, states[k + 1..]);
    }
}

/// A packing stepped one window at a time through the driver every run
/// shares (with its end-of-run checkpoint) ends where [`Packer::run`]
/// does: the same windows and the same spheres, bit for bit; each step
/// closes one window, and the driver stops where the packer jammed.
#[test]
fn stepped_by_the_driver_as_run_whole() {
    use mote_run::{Driver, Propagator};
    let mut s = settings(150, 0.1, 9);
    s.max_pressure = 1e8;
    s.finish = Some(Finish::default());
    let mut whole = Packer::<3>::new(s.clone()).unwrap();
    let out = whole.run(|_| {}).unwrap();
    assert_eq!(out.stop, Stop::Pressure);

    let mut stepped = Packer::<3>::new(s).unwrap();
    let mut steps = Vec::new();
    let mut driver = Driver::new();
    driver
        .run(&mut stepped, |_| u64::MAX, |p| steps.push(p.step()))
        .unwrap();
    assert!(stepped.finished());
    assert_eq!(stepped.stopped(), Some(Stop::Pressure));
    assert_eq!(steps, (1..=out.history.len() as u64).collect::<Vec<_>>());
    assert_eq!(stepped.windows(), &out.history[..]);
    assert_eq!(stepped.system().positions(), whole.system().positions());
    assert_eq!(stepped.system().radii(), whole.system().radii());
}
