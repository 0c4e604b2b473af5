//! The seed's figure (seed 000, "Behavior of linear momentum, energy, and
//! angular momentum of a magnetized particle in a homogeneous magnetic
//! field"): linear momentum, energy and L_y are conserved quantities; in the
//! FRBI the energy fluctuates with an amplitude ∝ dt² and no trend, L_y has
//! a trend ∝ dt, and linear momentum is kept exactly.
//!
//! Set `MOTE_RIGID_CSV=path.csv` to write the run at the middle step for
//! plotting (`mote plot path.csv --x time --y energy_error ...`).

use std::path::Path;

use glam::DVec3;
use mote_geom::{DE, E};
use mote_md::rigid::{
    BodyTemplate, ClumpSpec, ExternalFields, Field, Frbi, Integration, RigidBodies, SpinUpdate,
};

const B: DVec3 = DVec3::new(0.0, 1.0, 0.0);

/// An asymmetric three-sphere body with a dipole off its principal axes
/// (dimensionless units: density 1, |j| ≈ 1, |B| = 1).
fn magnet(spin_scale: f64) -> (RigidBodies, Frbi) {
    let spec = ClumpSpec {
        centres: vec![
            DVec3::ZERO,
            DVec3::new(0.8, 0.3, 0.0),
            DVec3::new(-0.2, 0.7, 0.5),
        ],
        radii: vec![1.0, 0.6, 0.5],
        density: 1.0,
        youngs_modulus: 0.0,
        poisson_ratio: 0.0,
        charge: 0.0,
        dipole: DVec3::new(0.3, 1.0, 0.2),
    };
    let t = BodyTemplate::new(&spec, Integration::default()).unwrap();
    let mut b = RigidBodies::new();
    let k = b.add_template(t);
    b.push(
        k,
        E::new(DVec3::new(0.2, -0.1, 0.4), DVec3::new(1.0, 2.0, 3.0)),
        DE::new(
            spin_scale * DVec3::new(0.5, -0.3, 0.8),
            DVec3::new(0.1, 0.2, -0.05),
        ),
    );
    let frbi = Frbi::new().with(ExternalFields {
        electric: Field::zero(),
        magnetic: Field::Constant(B),
    });
    (b, frbi)
}

struct Run {
    /// max − min of E(t) − E(0)
    energy_amplitude: f64,
    /// slope of a least-squares line through E(t), times the run length
    energy_trend: f64,
    /// slope of a least-squares line through L_y(t)
    ly_slope: f64,
    /// max − min of L_y(t) about that line
    ly_amplitude: f64,
    /// max |L_y(t) − L_y(0)|
    ly_deviation: f64,
}

fn run(dt: f64, t_end: f64, spin: SpinUpdate, spin_scale: f64, csv: Option<&Path>) -> Run {
    let (mut b, mut frbi) = magnet(spin_scale);
    frbi.spin = spin;
    let p0 = b.observables().linear_momentum;
    let ly0 = b.observables().angular_momentum.y;
    let e0 = frbi.energies(&b).total();
    let steps = (t_end / dt).round() as usize;
    let stride = (steps / 4000).max(1);
    let mut out = csv.map(|p| {
        let w = std::fs::File::create(p).unwrap();
        let mut w = std::io::BufWriter::new(w);
        use std::io::Write;
        writeln!(w, "# program=\"mote rigid_field test\" scene=\"seed 000 magnetised body, dt={dt}\" seed=0").unwrap();
        writeln!(w, "time,energy_error,energy_error_ppm,kinetic_energy,potential_energy,angular_momentum_y,linear_momentum_error").unwrap();
        w
    });
    let (mut ts, mut es, mut ls) = (Vec::new(), Vec::new(), Vec::new());
    for s in 1..=steps {
        frbi.step(&mut b, dt);
        let o = b.observables();
        assert_eq!(o.linear_momentum, p0, "linear momentum is kept exactly");
        if s % stride == 0 {
            let en = frbi.energies(&b);
            ts.push(b.time);
            es.push(en.total() - e0);
            ls.push(o.angular_momentum.y);
            if let Some(w) = out.as_mut() {
                use std::io::Write;
                writeln!(
                    w,
                    "{:.10e},{:.10e},{:.6},{:.10e},{:.10e},{:.10e},{:.3e}",
                    b.time,
                    en.total() - e0,
                    1e6 * (en.total() - e0) / e0.abs(),
                    en.kinetic,
                    en.potential,
                    o.angular_momentum.y,
                    (o.linear_momentum - p0).length()
                )
                .unwrap();
            }
        }
    }
    let (e_slope, _) = fit(&ts, &es);
    let (l_slope, l_icpt) = fit(&ts, &ls);
    let span = |v: &[f64]| {
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let resid: Vec<f64> = ts
        .iter()
        .zip(&ls)
        .map(|(t, l)| l - (l_icpt + l_slope * t))
        .collect();
    let ly_deviation = ls.iter().map(|l| (l - ly0).abs()).fold(0.0, f64::max);
    Run {
        ly_deviation,
        energy_amplitude: span(&es),
        energy_trend: e_slope * t_end,
        ly_slope: l_slope,
        ly_amplitude: span(&resid),
    }
}

/// Least-squares slope and intercept.
fn fit(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let s = sxy / sxx;
    (s, my - s * mx)
}

fn orders(spin: SpinUpdate, spin_scale: f64, t_end: f64, dts: [f64; 3]) -> Vec<Run> {
    let csv = std::env::var_os("MOTE_RIGID_CSV");
    let runs: Vec<Run> = dts
        .iter()
        .enumerate()
        .map(|(k, &dt)| {
            let path = csv.as_ref().filter(|_| k == 1 && spin == SpinUpdate::Seed);
            run(dt, t_end, spin, spin_scale, path.map(Path::new))
        })
        .collect();
    for (r, dt) in runs.iter().zip(dts) {
        eprintln!(
            "{spin:?} dt = {dt:.4}: energy amplitude {:.3e}, energy trend over run {:.2e}, L_y slope {:.3e}, L_y amplitude about the line {:.3e}, max |ΔL_y| {:.3e}",
            r.energy_amplitude, r.energy_trend, r.ly_slope, r.ly_amplitude, r.ly_deviation
        );
    }
    let p = |a: f64, b: f64| (a / b).log2();
    eprintln!(
        "{spin:?} orders (per halving of dt): energy amplitude {:.2} {:.2}; L_y slope {:.2} {:.2}; L_y amplitude {:.2} {:.2}; max |ΔL_y| {:.2} {:.2}",
        p(runs[0].energy_amplitude, runs[1].energy_amplitude),
        p(runs[1].energy_amplitude, runs[2].energy_amplitude),
        p(runs[0].ly_slope.abs(), runs[1].ly_slope.abs()),
        p(runs[1].ly_slope.abs(), runs[2].ly_slope.abs()),
        p(runs[0].ly_amplitude, runs[1].ly_amplitude),
        p(runs[1].ly_amplitude, runs[2].ly_amplitude),
        p(runs[0].ly_deviation, runs[1].ly_deviation),
        p(runs[1].ly_deviation, runs[2].ly_deviation),
    );
    runs
}

fn order(a: f64, b: f64) -> f64 {
    (a / b).log2()
}

/// The seed's figure at three step sizes (200 time units, ~30 turns). What
/// holds cleanly: energy swing ∝ dt², no energy trend, linear momentum
/// bit-exact, and the excursion of L_y ∝ dt. The fitted L_y *slope* alone
/// is not a clean power of dt here — the tumbling is chaotic, runs at
/// different dt part ways, and the drift rate depends on where the orbit
/// goes — so it is printed, not asserted.
#[test]
fn magnetised_body_in_uniform_field() {
    let runs = orders(SpinUpdate::Seed, 1.0, 200.0, [0.02, 0.01, 0.005]);
    for w in runs.windows(2) {
        let oe = order(w[0].energy_amplitude, w[1].energy_amplitude);
        assert!((1.8..2.2).contains(&oe), "energy amplitude order {oe}");
        // no trend: the fitted drift over the run is small against the swing
        assert!(w[1].energy_trend.abs() < 0.2 * w[1].energy_amplitude);
    }
    // L_y is not kept exactly by the seed's spin update, and shrinks with dt
    assert!(runs[2].ly_deviation < 0.5 * runs[0].ly_deviation);
}

/// A fast top (5× the spin) precesses regularly in the field, runs at
/// different dt stay together, and the seed's L_y trend shows its order: the
/// fitted slope ∝ dt.
#[test]
fn fast_top_in_field_ly_trend_is_first_order() {
    let runs = orders(SpinUpdate::Seed, 5.0, 100.0, [0.004, 0.002, 0.001]);
    for w in runs.windows(2) {
        let ol = order(w[0].ly_slope.abs(), w[1].ly_slope.abs());
        assert!((0.7..1.3).contains(&ol), "L_y trend order {ol}");
        let oe = order(w[0].energy_amplitude, w[1].energy_amplitude);
        assert!((1.7..2.3).contains(&oe), "energy amplitude order {oe}");
    }
}

#[test]
fn keep_momentum_variant_in_uniform_field() {
    let runs = orders(SpinUpdate::KeepMomentum, 1.0, 200.0, [0.02, 0.01, 0.005]);
    for w in runs.windows(2) {
        let oe = order(w[0].energy_amplitude, w[1].energy_amplitude);
        assert!((1.8..2.2).contains(&oe), "energy amplitude order {oe}");
        assert!(w[1].energy_trend.abs() < 0.2 * w[1].energy_amplitude);
    }
    // the torque j × B is ⊥ B and the free step carries L exactly: L_y
    // stays to rounding (|L| ≈ 2)
    for r in &runs {
        assert!(r.ly_deviation < 1e-10, "max |ΔL_y| {:.2e}", r.ly_deviation);
    }
}

/// The seed's figure over 10⁶ steps: no trend in the energy.
#[test]
#[ignore = "10⁶ steps, run with --ignored --release"]
fn magnetised_body_million_steps() {
    let r = run(0.01, 1e4, SpinUpdate::Seed, 1.0, None);
    eprintln!(
        "10⁶ steps of 0.01: energy amplitude {:.3e}, trend over run {:.2e}, L_y slope {:.3e}",
        r.energy_amplitude, r.energy_trend, r.ly_slope
    );
    assert!(r.energy_trend.abs() < 0.2 * r.energy_amplitude);
}
