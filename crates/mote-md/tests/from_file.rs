//! `[[from_file]]`: a scene starts from a file another program (or mote)
//! wrote: a LAMMPS data file in a point style with `Masses`, or a frame of
//! a GSD or XYZ trajectory; the box comes with it where the file says it
//! is periodic. Before, `[[lammps_data]]` read only atom_style sphere and
//! dropped the box.

use mote_io::trajectory::{Format, TrajectoryWriter};
use mote_io::xyz::Frame;
use mote_io::Provenance;
use mote_md::scene::Scene;
use mote_md::DVec3;

fn build(dir: &std::path::Path, text: &str) -> Result<mote_md::System, String> {
    let label = dir.join("scene.toml");
    let label = label.to_str().unwrap();
    let scene = Scene::parse(text, label).map_err(|e| e.to_string())?;
    let built = scene.build(text, label, 1).map_err(|e| e.to_string())?;
    Ok(built.simulation.system)
}

const RUN: &str = "[run]\ndt = 0.001\nsteps = 1\n";

#[test]
fn a_lammps_data_file_in_atomic_style_with_its_box() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("argon.data"),
        "LAMMPS data file\n\n2 atoms\n1 atom types\n\n0 10 xlo xhi\n0 10 ylo yhi\n-5 5 zlo zhi\n\n\
         Masses\n\n1 39.948\n\nAtoms # atomic\n\n1 1 1 2 3\n2 1 4 5 -1 0 0 0\n\nVelocities\n\n1 0.5 0 0\n2 0 0 -0.5\n",
    )
    .unwrap();
    let sys = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"argon.data\"\nradius = 0.5\nperiodic = [true, true, false]\n"),
    )
    .unwrap();
    let p = &sys.particles;
    assert_eq!(
        p.position,
        [DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, -1.0)]
    );
    assert_eq!(p.velocity[1], DVec3::new(0.0, 0.0, -0.5));
    assert_eq!(p.mass, [39.948, 39.948]);
    assert_eq!(p.radius, [0.5, 0.5]);
    assert_eq!(sys.boundary.lo, DVec3::new(0.0, 0.0, -5.0));
    assert_eq!(sys.boundary.hi, DVec3::new(10.0, 10.0, 5.0));
    assert_eq!(sys.boundary.periodic, [true, true, false]);
    // Without `periodic` the data file's box is not taken (it does not say
    // which axes are periodic); without masses and `mass`, a message.
    let sys = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"argon.data\"\n"),
    )
    .unwrap();
    assert!(!sys.boundary.is_periodic());
    std::fs::write(
        dir.path().join("bare.data"),
        "t\n\n1 atoms\n\nAtoms # atomic\n\n1 1 0 0 0\n",
    )
    .unwrap();
    let e = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"bare.data\"\n"),
    )
    .unwrap_err();
    assert!(e.contains("scene.toml:4:") && e.contains("no mass"), "{e}");
    // An error inside the file names the file's line.
    std::fs::write(
        dir.path().join("bad.data"),
        "t\n\n1 atoms\n\nAtoms # atomic\n\n1 1 0 zero 0\n",
    )
    .unwrap();
    let e = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"bad.data\"\nmass = 1\n"),
    )
    .unwrap_err();
    assert!(e.contains("bad.data:7:") && e.contains("'zero'"), "{e}");
}

#[test]
fn a_frame_of_a_gsd_trajectory_with_its_periodic_box() {
    let dir = tempfile::tempdir().unwrap();
    let frame = |t: f64| Frame {
        time: t,
        cell: [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]],
        origin: [-2.0, 0.0, 1.0],
        pbc: [true; 3],
        species: vec!["X".into(); 2],
        positions: vec![[0.0, 1.0, 2.0], [1.0 + t, 3.0, 4.0]],
        velocities: vec![[0.1, 0.0, 0.0], [0.0, 0.2, 0.0]],
        radii: vec![0.5, 0.25],
        masses: vec![2.0, 3.0],
        ..Frame::default()
    };
    let path = dir.path().join("start.gsd");
    let mut w = TrajectoryWriter::create(&path, Format::Gsd, Provenance::default(), true).unwrap();
    w.write(0, &frame(0.0)).unwrap();
    w.write(1, &frame(0.5)).unwrap();
    drop(w);
    for (frame_key, x) in [("", 1.5), ("frame = 0\n", 1.0), ("frame = -2\n", 1.0)] {
        let sys = build(
            dir.path(),
            &format!("{RUN}[[from_file]]\nfile = \"start.gsd\"\n{frame_key}"),
        )
        .unwrap();
        let p = &sys.particles;
        assert_eq!(p.position[1], DVec3::new(x, 3.0, 4.0), "{frame_key}");
        assert_eq!(
            (p.mass.clone(), p.radius.clone()),
            (vec![2.0, 3.0], vec![0.5, 0.25])
        );
        assert_eq!(sys.boundary.lo, DVec3::new(-2.0, 0.0, 1.0));
        assert_eq!(sys.boundary.hi, DVec3::new(2.0, 5.0, 7.0));
        assert_eq!(sys.boundary.periodic, [true; 3]);
    }
    let e = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"start.gsd\"\nframe = 5\n"),
    )
    .unwrap_err();
    assert!(e.contains("no frame 5 among its 2 frames"), "{e}");
}

/// Species names: given on any generator (`species = "Ar"`), taken from a
/// trajectory file, written in every frame (ASE reads chemical symbols);
/// a name with a space is refused at its line.
#[test]
fn species_names_travel_from_scene_and_file_to_trajectories() {
    let dir = tempfile::tempdir().unwrap();
    let frame = Frame {
        cell: [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
        species: vec!["Fe".into(), "O".into()],
        positions: vec![[0.0, 1.0, 2.0], [1.0, 3.0, 2.0]],
        radii: vec![0.5, 0.25],
        masses: vec![55.845, 15.999],
        ..Frame::default()
    };
    let path = dir.path().join("oxide.xyz");
    let mut w = TrajectoryWriter::create(&path, Format::Xyz, Provenance::default(), true).unwrap();
    w.write(0, &frame).unwrap();
    drop(w);
    let sys = build(
        dir.path(),
        &format!(
            "{RUN}[[particle]]\nposition = [3, 3, 3]\nspecies = \"Ar\"\n\n[[from_file]]\nfile = \"oxide.xyz\"\n"
        ),
    )
    .unwrap();
    let written = mote_md::output::frame_of(&sys);
    assert_eq!(written.species, ["Ar", "Fe", "O"]);
    let e = build(
        dir.path(),
        &format!("{RUN}[[particle]]\nposition = [3, 3, 3]\nspecies = \"Ar gon\"\n"),
    )
    .unwrap_err();
    assert!(e.contains("scene.toml:4:") && e.contains("one word"), "{e}");
}

/// Files MDAnalysis 2.11 writes (fixtures in mote-io/tests/data): a data
/// file whose `Atoms` line names no style (id mol type x y z: refused
/// without `atom_style`, read with it) and a plain XYZ.
#[test]
fn mdanalysis_files_start_a_scene() {
    let dir = tempfile::tempdir().unwrap();
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mote-io/tests/data");
    for f in ["mdanalysis.data", "mdanalysis.xyz"] {
        std::fs::copy(fixtures.join(f), dir.path().join(f)).unwrap();
    }
    let e = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"mdanalysis.data\"\n"),
    )
    .unwrap_err();
    assert!(
        e.contains("mdanalysis.data:") && e.contains("name it"),
        "{e}"
    );
    let sys = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"mdanalysis.data\"\natom_style = \"molecular\"\nradius = 0.5\nperiodic = [true, true, true]\n"),
    )
    .unwrap();
    let want = [
        DVec3::new(0.5, 1.0, 1.5),
        DVec3::new(2.25, 0.125, 3.0),
        DVec3::new(3.5, 4.75, 5.5),
    ];
    assert_eq!(sys.particles.position, want);
    assert_eq!(sys.particles.mass, [39.948, 55.845, 39.948]);
    assert_eq!(sys.boundary.hi, DVec3::new(4.0, 5.0, 6.0));
    let sys = build(
        dir.path(),
        &format!("{RUN}[[from_file]]\nfile = \"mdanalysis.xyz\"\nmass = 1\n"),
    )
    .unwrap();
    assert_eq!(sys.particles.position, want);
    assert_eq!(sys.species, ["Ar", "Fe", "Ar"]);
}

/// `replicate = [nx, ny, nz]`: copies of a periodic frame shifted by
/// whole box lengths. The copies join without a seam, so a Lennard-Jones
/// liquid replicated 2 × 3 × 2 has the same potential energy per particle
/// as the original to rounding (every pair distance of the copy is one of
/// the original's images); an axis that is not periodic, no box, or zero
/// copies are refused at the scene's line.
#[test]
fn replicate_copies_a_periodic_frame_without_a_seam() {
    use rand::{Rng, SeedableRng};
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
    // 64 atoms at density 0.3 in a 5.97³ box (≥ 2 (cutoff + skin)), kept
    // apart by rejection so no pair is closer than 0.9 σ.
    let l = (64.0f64 / 0.3).cbrt();
    let mut positions: Vec<[f64; 3]> = Vec::new();
    while positions.len() < 64 {
        let x = [
            rng.gen::<f64>() * l,
            rng.gen::<f64>() * l,
            rng.gen::<f64>() * l,
        ];
        let close = positions.iter().any(|y| {
            let d2: f64 = (0..3)
                .map(|k| {
                    let d = x[k] - y[k];
                    let d = d - l * (d / l).round();
                    d * d
                })
                .sum();
            d2 < 0.81
        });
        if !close {
            positions.push(x);
        }
    }
    let n = positions.len();
    let frame = Frame {
        cell: [[l, 0.0, 0.0], [0.0, l, 0.0], [0.0, 0.0, l]],
        pbc: [true, true, false],
        species: vec!["Ar".into(); n],
        velocities: vec![[0.0; 3]; n],
        masses: vec![1.0; n],
        positions,
        ..Frame::default()
    };
    let path = dir.path().join("liquid.xyz");
    let mut w = TrajectoryWriter::create(&path, Format::Xyz, Provenance::default(), true).unwrap();
    w.write(0, &frame).unwrap();
    drop(w);
    let energy = |replicate: &str| {
        let label = dir.path().join("scene.toml");
        let label = label.to_str().unwrap();
        let text = format!(
            "{RUN}[lennard_jones]\ncutoff = 2.5\n[[from_file]]\nfile = \"liquid.xyz\"\n{replicate}"
        );
        let scene = Scene::parse(&text, label).map_err(|e| e.to_string())?;
        let mut sim = scene
            .build(&text, label, 1)
            .map_err(|e| e.to_string())?
            .simulation;
        let sys = &sim.system;
        let state = mote_md::force::State::of(
            sys,
            &sys.particles.position,
            &sys.particles.velocity,
            0.0,
            0.0,
        );
        let (u, _) = sim.forces.potential_energy(&state);
        Ok::<_, String>((u / sys.particles.len() as f64, sys.clone()))
    };
    let (u1, one) = energy("").unwrap();
    let (u6, six) = energy("replicate = [2, 3, 1]\n").unwrap();
    assert_eq!(six.particles.len(), 6 * n);
    assert_eq!(six.boundary.lo, one.boundary.lo);
    assert_eq!(six.boundary.hi, DVec3::new(2.0 * l, 3.0 * l, l));
    assert_eq!(six.boundary.periodic, [true, true, false]);
    // Copy (i, j) = (1, 2) is the fifth block of n: shifted by (L, 2L, 0).
    assert_eq!(
        six.particles.position[5 * n + 7],
        one.particles.position[7] + DVec3::new(l, 2.0 * l, 0.0)
    );
    assert_eq!(six.species[5 * n], "Ar");
    assert!(u1 < 0.0 && ((u6 - u1) / u1).abs() < 1e-12, "{u1} {u6}");
    let e = energy("replicate = [1, 1, 2]\n").unwrap_err();
    assert!(
        e.contains("scene.toml:6:") && e.contains("not periodic along z"),
        "{e}"
    );
    let e = energy("replicate = [0, 1, 1]\n").unwrap_err();
    assert!(e.contains("at least one copy"), "{e}");
}

/// `units` on `[[from_file]]`: the same argon data file written by LAMMPS
/// in `real` units (Å, Å/fs, g/mol) comes into an SI scene in metres,
/// metres a second and kilograms; a radius filled in by the scene stays in
/// the scene's units; lj files go into lj scenes only, and an unknown name
/// is refused at the table's line.
#[test]
fn a_file_in_real_units_comes_into_an_si_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("argon.data"),
        "LAMMPS data file\n\n2 atoms\n1 atom types\n\n0 10 xlo xhi\n0 10 ylo yhi\n-5 5 zlo zhi\n\n\
         Masses\n\n1 39.948\n\nAtoms # atomic\n\n1 1 1 2 3\n2 1 4 5 -1 0 0 0\n\nVelocities\n\n1 0.002741 0 0\n2 0 0 -0.5\n",
    )
    .unwrap();
    let table =
        "[[from_file]]\nfile = \"argon.data\"\nradius = 1.7e-10\nperiodic = [true, true, true]\n";
    let sys = build(
        dir.path(),
        &format!("units = \"si\"\n{RUN}{table}units = \"real\"\n"),
    )
    .unwrap();
    let p = &sys.particles;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(p.position[0].y, 2e-10) && close(p.position[1].z, -1e-10));
    assert!(close(p.velocity[0].x, 274.1), "{}", p.velocity[0].x); // 0.002741 Å/fs
    assert!(close(p.mass[0], 39.948 * 1.660_539_066_60e-27));
    assert_eq!(p.radius[0], 1.7e-10); // the scene's own number
    assert!(close(sys.boundary.hi.x, 1e-9) && close(sys.boundary.lo.z, -5e-10));
    let e = build(
        dir.path(),
        &format!("units = \"lj\"\n{RUN}{table}units = \"real\"\n"),
    )
    .unwrap_err();
    assert!(e.contains("scene.toml:5:") && e.contains("lj"), "{e}");
    let e = build(
        dir.path(),
        &format!("units = \"si\"\n{RUN}{table}units = \"imperial\"\n"),
    )
    .unwrap_err();
    assert!(
        e.contains("scene.toml:5:") && e.contains("not one of"),
        "{e}"
    );
}

/// A bead-spring file: `Bonds` with `Bond Coeffs # harmonic` become springs
/// of stiffness 2K and rest length r₀ (LAMMPS's E = K (r − r₀)²), joined to
/// the file's own atoms after the scene's other particles. The energy is
/// LAMMPS's, Σ K (r − r₀)², and a stretched dimer swings through its
/// compressed turning point after half a period, T = 2π/√(4K/m) (reduced
/// mass m/2); replicating bonded atoms is refused; a file in real units
/// brings K in kcal/mol/Å².
#[test]
fn bonds_of_a_data_file_become_springs() {
    let dir = tempfile::tempdir().unwrap();
    let chain = "chain\n\n3 atoms\n1 atom types\n2 bonds\n2 bond types\n\n\
         -5 5 xlo xhi\n-5 5 ylo yhi\n-5 5 zlo zhi\n\nMasses\n\n1 1.0\n\n\
         Atoms # bond\n\n1 1 1 0 0 0\n2 1 1 1.3 0 0\n3 1 1 1.3 1.0 0\n\n\
         Bond Coeffs # harmonic\n\n1 50.0 1.0\n2 30.0 1.2\n\n\
         Bonds\n\n1 1 1 2\n2 2 2 3\n";
    std::fs::write(dir.path().join("chain.data"), chain).unwrap();
    let scene = |extra: &str| {
        format!(
            "units = \"lj\"\n[run]\ndt = 0.0001\nsteps = 1\n\
             [[particle]]\nposition = [4.0, 4.0, 4.0]\nmass = 1.0\n\
             [[from_file]]\nfile = \"chain.data\"\nradius = 0.5\n{extra}"
        )
    };
    let label = dir.path().join("scene.toml");
    let label = label.to_str().unwrap();
    let text = scene("");
    let built = Scene::parse(&text, label)
        .unwrap()
        .build(&text, label, 1)
        .unwrap();
    let mut sim = built.simulation;
    let o = mote_md::Observables::measure(&sim.system, &mut sim.forces);
    let want = 50.0 * 0.3f64.powi(2) + 30.0 * 0.2f64.powi(2);
    assert!(
        (o.potential - want).abs() < 1e-12,
        "{} vs {want}",
        o.potential
    );

    // The first bond alone: released stretched by 0.3, it is compressed
    // by 0.3 half a period later.
    let dimer = chain
        .replace("3 atoms", "2 atoms")
        .replace("2 bonds", "1 bonds")
        .replace("3 1 1 1.3 1.0 0\n", "")
        .replace("2 2 2 3\n", "");
    std::fs::write(dir.path().join("chain.data"), dimer).unwrap();
    let built = Scene::parse(&text, label)
        .unwrap()
        .build(&text, label, 1)
        .unwrap();
    let mut sim = built.simulation;
    let half_period = std::f64::consts::PI / (4.0f64 * 50.0).sqrt();
    let steps = (half_period / sim.dt).round() as u64;
    for _ in 0..steps {
        sim.stepper.step(&mut sim.system, &mut sim.forces, sim.dt);
    }
    let p = &sim.system.particles.position;
    let r = (p[2] - p[1]).length();
    assert!((r - 0.7).abs() < 1e-3, "separation {r} after T/2");

    let e = build(
        dir.path(),
        &scene("replicate = [2, 1, 1]\nperiodic = [true, true, true]\n"),
    )
    .unwrap_err();
    assert!(
        e.contains("scene.toml:") && e.contains("replicate copies atoms, not their 1 bonds"),
        "{e}"
    );

    // Real units: K = 1 kcal/mol/Å², r₀ = 1.5 Å into SI.
    let real = "real\n\n2 atoms\n1 atom types\n1 bonds\n1 bond types\n\n\
        Masses\n\n1 12.011\n\nAtoms # full\n\n1 1 1 0 0 0 0\n2 1 1 0 1.5 0 0\n\n\
        Bond Coeffs # harmonic\n\n1 1.0 1.5\n\nBonds\n\n1 1 1 2\n";
    std::fs::write(dir.path().join("real.data"), real).unwrap();
    let text = "units = \"si\"\n[run]\ndt = 1e-16\nsteps = 1\n\
        [[from_file]]\nfile = \"real.data\"\nradius = 1e-10\nunits = \"real\"\n";
    let built = Scene::parse(text, label)
        .unwrap()
        .build(text, label, 1)
        .unwrap();
    let mut sim = built.simulation;
    sim.system.particles.position[1].x = 1.6e-10;
    let o = mote_md::Observables::measure(&sim.system, &mut sim.forces);
    let kcal_per_mol = 4184.0 / 6.022_140_76e23;
    let want = kcal_per_mol * 0.1f64.powi(2); // K (0.1 Å)²
    assert!(
        (o.potential / want - 1.0).abs() < 1e-9,
        "{} J vs {want} J",
        o.potential
    );
}
