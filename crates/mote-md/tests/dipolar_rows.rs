//! The cut-off dipole–dipole rows (over a ghost list: AVX-512 where the CPU
//! has it, eight lanes on every CPU) against two references: the row loop
//! one neighbour at a time (1e-12 of the largest force, torque, virial and
//! energy) and a brute-force sum over
//! every pair's minimum image (which checks that the list holds every pair
//! within reach). Random configurations: periodic on all axes and on two
//! (open along z), polydisperse moments (some zero), pairs placed just
//! inside and just outside both cut-offs, with and without a reaction
//! field and the LJ repulsion. One and two threads give the same bits.

use std::f64::consts::PI;

use mote_md::force::dipolar::{dipole_pair, DipoleDipole, PairRepulsion};
use mote_md::force::Interaction;
use mote_md::{Boundary, DVec3};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const RC: f64 = 2.5;
const LJ_RC: f64 = 1.5;

/// A jittered cubic lattice (spacing 1.05, no overlaps) in a box of edge
/// `l`, moments of random direction and length in [0, 1.5) (every tenth
/// zero), and four pairs at r_c (1 ± 10⁻⁷) and r_c^LJ (1 ± 10⁻⁷).
fn configuration(l: f64, seed: u64) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let per_side = (l / 1.05).floor() as usize;
    let mut pos = Vec::new();
    for i in 0..per_side {
        for j in 0..per_side {
            for k in 0..per_side {
                let jitter = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.04;
                pos.push(DVec3::new(i as f64, j as f64, k as f64) * 1.05 + jitter);
            }
        }
    }
    // Pairs straddling the cut-offs, along random directions, in place of
    // lattice sites far apart.
    let m = pos.len();
    for (q, r) in [
        RC * (1.0 - 1e-7),
        RC * (1.0 + 1e-7),
        LJ_RC * (1.0 - 1e-7),
        LJ_RC * (1.0 + 1e-7),
    ]
    .into_iter()
    .enumerate()
    {
        let z: f64 = rng.gen_range(-1.0..1.0);
        let phi: f64 = rng.gen_range(0.0..2.0 * PI);
        let s = (1.0 - z * z).sqrt();
        let e = DVec3::new(s * phi.cos(), s * phi.sin(), z);
        let a = pos[q * m / 5];
        pos[q * m / 5 + m / 10] = a + e * r;
    }
    let dip = (0..pos.len())
        .map(|i| {
            if i % 10 == 0 {
                return DVec3::ZERO;
            }
            let v = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - DVec3::ONE;
            v.normalize() * rng.gen_range(0.0..1.5)
        })
        .collect();
    (pos, dip)
}

struct Sums {
    force: Vec<DVec3>,
    torque: Vec<DVec3>,
    virial: f64,
    energy: f64,
}

/// The row kernels: the fastest the CPU has, eight lanes, one neighbour at
/// a time.
#[derive(Debug, Clone, Copy)]
enum Rows {
    Fastest,
    Lanes,
    Reference,
}

fn rows(dd: &DipoleDipole, pos: &[DVec3], dip: &[DVec3], kernel: Rows) -> Sums {
    let mut dd = dd.clone();
    dd.set_simd(matches!(kernel, Rows::Fastest));
    dd.set_reference_rows(matches!(kernel, Rows::Reference));
    let n = pos.len();
    let (mut force, mut torque) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    let stepped = dd.forces_and_torques(pos, dip, &mut force, &mut torque);
    // The stepping pass leaves the virial out; the energy's pass measures it.
    assert!(stepped.is_nan(), "a virial from the stepping pass");
    assert!(Interaction::virial(&dd).unwrap().is_nan());
    let energy = dd.energy(pos, dip);
    let virial = Interaction::virial(&dd).unwrap();
    Sums {
        force,
        torque,
        virial,
        energy,
    }
}

/// Every pair's minimum image, i < j, with the pair formulas of 004 Eq. 8
/// (`dipole_pair`), the reaction field and the LJ repulsion written out.
fn brute_force(
    boundary: &Boundary,
    pos: &[DVec3],
    dip: &[DVec3],
    rf: f64,
    lj: Option<PairRepulsion>,
) -> Sums {
    let n = pos.len();
    let mut s = Sums {
        force: vec![DVec3::ZERO; n],
        torque: vec![DVec3::ZERO; n],
        virial: 0.0,
        energy: 0.0,
    };
    for i in 0..n {
        for j in i + 1..n {
            let d = boundary.minimum_image(pos[i] - pos[j]);
            let r2 = d.length_squared();
            if r2 < RC * RC {
                let (u, f, ti, tj) = dipole_pair(1.0, d, 1.0 / r2, dip[i], dip[j]);
                let x = dip[i].cross(dip[j]) * rf;
                s.force[i] += f;
                s.force[j] -= f;
                s.torque[i] += ti + x;
                s.torque[j] += tj - x;
                s.virial += f.dot(d);
                s.energy += u - rf * dip[i].dot(dip[j]);
            }
            if let Some(p) = lj.filter(|p| r2 < p.cutoff * p.cutoff) {
                let s6 = (p.sigma * p.sigma / r2).powi(3);
                let f = d * (24.0 * p.epsilon * s6 * (2.0 * s6 - 1.0) / r2);
                s.force[i] += f;
                s.force[j] -= f;
                s.virial += f.dot(d);
                s.energy += 4.0 * p.epsilon * (s6 * s6 - s6);
            }
        }
    }
    s
}

fn assert_close(a: &Sums, b: &Sums, tol: f64, what: &str) {
    let close = |x: &[DVec3], y: &[DVec3], name: &str| {
        let scale = x.iter().map(|v| v.length()).fold(0.0, f64::max);
        let worst = x
            .iter()
            .zip(y)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f64::max);
        assert!(
            worst <= tol * scale,
            "{what}: {name} differ by {worst:e} of {scale:e}"
        );
    };
    close(&a.force, &b.force, "forces");
    close(&a.torque, &b.torque, "torques");
    for (name, x, y) in [
        ("virial", a.virial, b.virial),
        ("energy", a.energy, b.energy),
    ] {
        assert!(
            (x - y).abs() <= tol * x.abs().max(1.0),
            "{what}: {name} {x} vs {y}"
        );
    }
}

fn boxes(l: f64) -> [(&'static str, Boundary); 2] {
    let periodic = Boundary::periodic(DVec3::ZERO, DVec3::splat(l));
    let slab = Boundary {
        periodic: [true, true, false],
        ..periodic
    };
    [("periodic", periodic), ("periodic in x, y", slab)]
}

#[test]
fn rows_agree_with_the_portable_rows_and_with_every_minimum_image_pair() {
    let l = 9.0;
    for (name, boundary) in boxes(l) {
        let (pos, dip) = configuration(l, 7);
        for (rf, lj) in [
            (1.0, None),
            (
                f64::INFINITY,
                Some(PairRepulsion::lennard_jones(1.0, 1.0, LJ_RC)),
            ),
            (80.0, Some(PairRepulsion::wca(0.7, 1.2))),
        ] {
            let mut dd = DipoleDipole::cut_off(4.0 * PI, RC, 0.3, boundary)
                .unwrap()
                .with_reaction_field(rf);
            if let Some(p) = lj {
                dd = dd.with_repulsion(p).unwrap();
            }
            let what = format!("{name}, ε_RF {rf}, repulsion {lj:?}");
            let portable = rows(&dd, &pos, &dip, Rows::Reference);
            for kernel in [Rows::Fastest, Rows::Lanes] {
                let vector = rows(&dd, &pos, &dip, kernel);
                assert_close(&vector, &portable, 1e-12, &format!("{kernel:?}, {what}"));
            }
            let c = if rf.is_infinite() {
                1.0
            } else {
                2.0 * (rf - 1.0) / (2.0 * rf + 1.0)
            };
            let reference = brute_force(&boundary, &pos, &dip, c / RC.powi(3), lj);
            // The WCA shift is a constant per pair within its cut-off.
            let mut reference = reference;
            if let Some(p) = lj.filter(|p| p.shifted) {
                let s6 = (p.sigma / p.cutoff).powi(6);
                let shift = 4.0 * p.epsilon * (s6 * s6 - s6);
                let inside = (0..pos.len())
                    .flat_map(|i| (i + 1..pos.len()).map(move |j| (i, j)))
                    .filter(|&(i, j)| {
                        boundary.minimum_image(pos[i] - pos[j]).length_squared()
                            < p.cutoff * p.cutoff
                    })
                    .count();
                reference.energy -= shift * inside as f64;
            }
            assert_close(&portable, &reference, 1e-12, &what);
        }
    }
}

#[test]
fn one_and_two_threads_give_the_same_bits() {
    let l = 14.0;
    let (_, boundary) = boxes(l)[0];
    let (pos, dip) = configuration(l, 11);
    let dd = DipoleDipole::cut_off(4.0 * PI, RC, 0.3, boundary)
        .unwrap()
        .with_repulsion(PairRepulsion::lennard_jones(1.0, 1.0, LJ_RC))
        .unwrap();
    for kernel in [Rows::Fastest, Rows::Lanes] {
        let run =
            |threads: usize| mote_testkit::on_threads(threads, || rows(&dd, &pos, &dip, kernel));
        let (one, two) = (run(1), run(2));
        assert!(pos.len() > 2000, "more rows than one block");
        assert_eq!(one.force, two.force, "{kernel:?}");
        assert_eq!(one.torque, two.torque, "{kernel:?}");
        assert_eq!(one.virial.to_bits(), two.virial.to_bits(), "{kernel:?}");
        assert_eq!(one.energy.to_bits(), two.energy.to_bits(), "{kernel:?}");
    }
}

/// Two particles on one spot give a force that is not a number on the
/// eight-lane rows, as on the reference: the run stops as unstable rather
/// than leave the pair out.
#[test]
fn coincident_dipoles_are_not_left_out_by_the_lane_rows() {
    let l = 9.0;
    let (_, boundary) = boxes(l)[0];
    let (mut pos, dip) = configuration(l, 3);
    pos[5] = pos[40];
    let dd = DipoleDipole::cut_off(4.0 * PI, RC, 0.3, boundary)
        .unwrap()
        .with_repulsion(PairRepulsion::wca(1.0, 1.0))
        .unwrap();
    for kernel in [Rows::Reference, Rows::Lanes] {
        let s = rows(&dd, &pos, &dip, kernel);
        assert!(
            !s.force[5].is_finite() && !s.force[40].is_finite(),
            "{kernel:?}: {:?}",
            s.force[5]
        );
    }
}
