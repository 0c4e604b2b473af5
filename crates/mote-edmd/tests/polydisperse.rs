//! Wide size distributions (issue 21 part 2): the hierarchy of cell grids
//! and the capped skins find every pair that can collide, and a packing of
//! a wide mixture runs to jamming or is refused at once.

use mote_edmd::{PackSettings, Packer, Scene, SizeSpec, Stop, System};
use std::path::Path;

/// Spheres of diameter ratio 8 (20 large among 2000 small, masses ∝
/// volume) at η = 0.3: two grids, energy kept to round-off and no overlap
/// over all pairs at any of the checks.
#[test]
fn a_one_to_eight_mixture_keeps_its_energy_and_never_overlaps() {
    let scene = Scene::parse(
        "[event_driven]\ndimension = 3\nn = 2020\npacking_fraction = 0.30\nlarge_fraction = 0.0099\nsize_ratio = 8\nplacement = \"random\"\ntemperature = 1.0\n",
        "test",
    )
    .unwrap();
    let mut sys: System<3> = scene.build(11, Path::new(".")).unwrap();
    assert_eq!(sys.cell_grids().len(), 2, "{:?}", sys.cell_grids());
    let e0 = sys.kinetic_energy();
    for _ in 0..5 {
        sys.run_collisions(40_000);
        let de = ((sys.kinetic_energy() - e0) / e0).abs();
        assert!(de < 1e-12, "energy drift {de:e} at t = {}", sys.time());
        assert!(
            sys.find_overlap_all_pairs(1e-9).is_none(),
            "overlap at t = {}",
            sys.time()
        );
    }
    assert!(sys.counters().collisions >= 200_000);
}

fn settings(n: usize, sizes: SizeSpec) -> PackSettings {
    PackSettings {
        n,
        sizes,
        rate: 0.1,
        seed: 5,
        max_pressure: 1e6,
        ..PackSettings::default()
    }
}

/// Diameter ratio 4 with 7 % large spheres (70 % of the volume) grows to
/// jamming without overlaps; random close packing of such a mixture lies
/// well above the monodisperse 0.64.
#[test]
fn a_one_to_four_mixture_packs() {
    let sizes = SizeSpec::Bidisperse {
        ratio: 4.0,
        large_fraction: 0.07,
    };
    let mut p = Packer::<3>::new(settings(600, sizes)).unwrap();
    let out = p.run(|_| {}).unwrap();
    assert_eq!(out.stop, Stop::Pressure);
    assert!(p.system().cell_grids().len() >= 2);
    assert!(p.system().find_overlap_all_pairs(1e-12).is_none());
    assert!(out.phi > 0.66 && out.phi < 0.80, "φ = {}", out.phi);
}

/// Too few particles for the widest spheres' share of the periodic box at
/// jamming: refused before the run, with what would do.
#[test]
fn a_run_that_cannot_finish_is_refused_at_once() {
    let err = Packer::<3>::new(settings(500, SizeSpec::Lognormal { sigma: 0.5 }))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("too few") && err.contains("try about"),
        "{err}"
    );
}
