//! The SP method (soft spheres under a barostat) and its jamming finish,
//! checked against what is known of frictionless Hertzian spheres at
//! jamming (O'Hern et al., Phys. Rev. E 68, 011306 (2003)): monodisperse
//! spheres jam at φ_J ≈ 0.64; near jamming p ∝ (φ − φ_J)^{3/2}; at a true
//! energy minimum near zero pressure the backbone (rattlers removed) is
//! isostatic, z → 2D = 6.

use mote_md::soft_pack::{extrapolate, FinishSettings, SoftPackSettings, SoftPacker};

/// Mean contact number of the backbone: spheres with fewer than 4
/// overlapping neighbours among the non-rattlers removed recursively;
/// returns (z, rattlers).
fn backbone(p: &SoftPacker) -> (f64, usize) {
    let n = p.position.len();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        for j in i + 1..n {
            let r = p.boundary.minimum_image(p.position[i] - p.position[j]);
            if r.length() < p.radius[i] + p.radius[j] {
                adj[i].push(j);
                adj[j].push(i);
            }
        }
    }
    let mut rattler = vec![false; n];
    loop {
        let loose: Vec<usize> = (0..n)
            .filter(|&i| !rattler[i] && adj[i].iter().filter(|&&j| !rattler[j]).count() < 4)
            .collect();
        if loose.is_empty() {
            break;
        }
        loose.iter().for_each(|&i| rattler[i] = true);
    }
    let back: Vec<usize> = (0..n).filter(|&i| !rattler[i]).collect();
    let links: usize = back
        .iter()
        .map(|&i| adj[i].iter().filter(|&&j| !rattler[j]).count())
        .sum();
    (links as f64 / back.len() as f64, n - back.len())
}

#[test]
fn monodisperse_soft_spheres_jam_isostatic_near_0_64() {
    let mut p = SoftPacker::new(SoftPackSettings {
        diameters: vec![1.0; 1000],
        phi_start: 0.3,
        pressures: SoftPackSettings::decades(1e-4),
        tolerance: 0.02,
        max_steps: 400_000,
        seed: 3,
        finish: Some(FinishSettings {
            lowest: 1e-8,
            force_tolerance: 1e-10,
        }),
        wall_clock: None,
    })
    .unwrap();
    while !p.barostat_over() {
        p.advance();
    }
    let stages = p.stages().to_vec();
    assert_eq!(stages.len(), 3);
    for s in &stages {
        assert!(s.converged, "{s:?}");
        assert!((s.pressure / s.target - 1.0).abs() < 0.02, "{s:?}");
    }
    // Compressed soft spheres: φ rises with pressure, above φ_J.
    assert!(stages[0].phi > stages[1].phi && stages[1].phi > stages[2].phi);
    let (z_before, _) = backbone(&p);
    p.run(&|| false);
    let finish = p.finish().to_vec();
    assert!(finish.len() >= 4, "{finish:?}");
    assert!(finish.iter().all(|s| s.converged && s.pressure > 0.0));
    let lowest = finish.last().unwrap();
    assert!(lowest.pressure < 1.5e-8, "{lowest:?}");
    let (phi_j, _) = extrapolate(&finish[finish.len() - 3..]).unwrap();
    assert!((0.636..0.646).contains(&phi_j), "phi_J = {phi_j}");
    // p ∝ (φ − φ_J)^{3/2}: the log-log slope over the finish's decades.
    let (a, b) = (finish[1], finish[finish.len() - 1]);
    let exponent = (a.pressure / b.pressure).ln() / ((a.phi - phi_j) / (b.phi - phi_j)).ln();
    assert!((exponent - 1.5).abs() < 0.15, "exponent {exponent}");
    // Isostatic backbone after the finish (it was hyperstatic before):
    // within 1 % of 2D (issue 21), z − 6 ∝ (φ − φ_J)^{1/2} at p = 10⁻⁸.
    let (z, rattlers) = backbone(&p);
    assert!(z_before > 6.15, "before the finish z = {z_before}");
    assert!((z - 6.0).abs() < 0.06, "backbone z = {z}");
    assert!(
        z >= 6.0 - 0.01,
        "a stable backbone is not hypostatic: z = {z}"
    );
    assert!(rattlers < 60, "{rattlers} rattlers");
}

/// A packing resumed from a checkpoint of any chunk — holding a target,
/// at the barostat's end, inside a minimisation, inside a decompression
/// step — ends in the bits of the uninterrupted packing: the spheres, the
/// box and every stage.
#[test]
fn a_soft_packing_resumed_from_any_chunk_ends_bit_for_bit() {
    let settings = SoftPackSettings {
        diameters: (0..128).map(|k| 0.8 + 0.4 * (k % 5) as f64 / 4.0).collect(),
        phi_start: 0.3,
        pressures: SoftPackSettings::decades(1e-4),
        tolerance: 0.02,
        max_steps: 400_000,
        seed: 11,
        finish: Some(FinishSettings {
            lowest: 1e-6,
            force_tolerance: 1e-10,
        }),
        wall_clock: None,
    };
    let mut whole = SoftPacker::new(settings.clone()).unwrap();
    let mut saved = Vec::new();
    let mut barostat_end = None;
    while whole.stopped().is_none() {
        let mut cp = mote_io::checkpoint::Checkpoint::default();
        whole.save(&mut cp);
        if barostat_end.is_none() && whole.barostat_over() {
            barostat_end = Some(saved.len());
        }
        saved.push(cp);
        whole.advance();
    }
    assert!(whole.finish().len() >= 3, "{:?}", whole.finish());
    let ended = |p: &SoftPacker| {
        format!(
            "{:?} {:?} {:?} {:?} {} {}",
            p.position,
            p.boundary,
            p.stages(),
            p.finish(),
            p.steps,
            p.time
        )
    };
    let k = saved.len();
    let end = barostat_end.unwrap();
    let dir = tempfile::tempdir().unwrap();
    for at in [k / 10, end / 2, end, (end + k) / 2, k - 2] {
        // through the file, as a resumed run reads it
        let path = dir.path().join("checkpoint.mote");
        mote_io::checkpoint::write(&path, &saved[at]).unwrap();
        let cp = mote_io::checkpoint::read(&path).unwrap();
        let mut p = SoftPacker::resume(settings.clone(), &cp).unwrap();
        p.run(&|| false);
        assert_eq!(ended(&p), ended(&whole), "resumed at chunk {at} of {k}");
    }
}
