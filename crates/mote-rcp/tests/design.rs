//! Inverse design (003, §V): the optimiser finds the best composition of a tridisperse
//! mixture (003, Fig. 6) at least as well as a grid search, hits target values, and
//! scans produce a complete grid.

use mote_rcp::design::{optimise, scan, Axis, Objective, Param, Search};
use mote_rcp::{Population, RodPacking, SizeDistribution};

fn tri(w: [f64; 3]) -> Vec<Population> {
    vec![
        Population::monodisperse(1.0, w[0]),
        Population::monodisperse(3.0, w[1]),
        Population::monodisperse(9.0, w[2]),
    ]
}

#[test]
fn optimum_beats_a_composition_grid() {
    let est = RodPacking::default().rods(2000);
    let mut grid_best: f64 = 0.0;
    for i in 0..=10 {
        for j in 0..=(10 - i) {
            let w = [i as f64 / 10.0, j as f64 / 10.0, (10 - i - j) as f64 / 10.0];
            if let Ok(d) = SizeDistribution::new(tri(w)) {
                grid_best = grid_best.max(est.estimate(&d).unwrap().phi);
            }
        }
    }
    let opt = optimise(
        &tri([1.0, 1.0, 1.0]),
        &est,
        Objective::Maximise,
        &Search::default(),
    )
    .unwrap();
    assert!(opt.phi >= grid_best - 1e-9, "{} < {grid_best}", opt.phi);
    assert!(opt.phi > 0.8 && opt.phi < 0.9);
    assert!(opt.evaluations > 10 && opt.evaluations <= Search::default().max_evaluations + 20);
    // the largest spheres carry most of the volume at the optimum
    let total: f64 = opt.populations.iter().map(|p| p.volume()).sum();
    assert!(opt.populations[2].volume() / total > 0.5);
}

#[test]
fn target_is_reached_over_widths() {
    let est = RodPacking::default().rods(2000);
    let base = [Population::lognormal(1.0, 0.2, 1.0)];
    let search = Search {
        volumes: false,
        widths: true,
        ..Search::default()
    };
    let opt = optimise(&base, &est, Objective::Target(0.75), &search).unwrap();
    assert!((opt.phi - 0.75).abs() < 1e-4, "{}", opt.phi);
    // and the analytic fit (003, Eq. 27) agrees at the width found (σ ≈ 0.72)
    let sigma = opt.populations[0].sigma();
    assert!(
        (mote_rcp::lognormal_fit(sigma, false) - 0.75).abs() < 2e-3,
        "{sigma}"
    );
}

#[test]
fn nothing_to_vary_is_an_error() {
    let est = RodPacking::default().rods(100);
    let e = optimise(
        &[Population::monodisperse(1.0, 1.0)],
        &est,
        Objective::Maximise,
        &Search::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("nothing to vary"));
}

#[test]
fn scan_fills_the_grid() {
    let est = RodPacking::default().rods(500);
    let x: Axis = "vol2=0:1:5".parse().unwrap();
    let y = Axis {
        param: Param::Sigma(0),
        start: 0.0,
        stop: 1.0,
        count: 3,
    };
    let base = [
        Population::lognormal(1.0, 0.1, 1.0),
        Population::lognormal(5.0, 0.1, 1.0),
    ];
    let s = scan(&base, &est, x, y, None, |_| {}).unwrap();
    assert_eq!(s.phi.len(), 15);
    assert!(s.phi.iter().all(|p| p.is_finite() && *p > 0.6 && *p < 1.0));
    // wider small population packs denser (003, Fig. 2)
    assert!(s.phi[2 * 5 + 2] > s.phi[2]);
    let csv = s.to_csv();
    assert_eq!(csv.lines().count(), 16);
    let img = mote_rcp::heatmap::render(&s, "PHI");
    let mut png = Vec::new();
    img.write_png(&mut png).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // a parameter naming a missing population is an error
    let bad: Axis = "d3=1:2:2".parse().unwrap();
    assert!(scan(&base, &est, bad, y, None, |_| {}).is_err());
}
