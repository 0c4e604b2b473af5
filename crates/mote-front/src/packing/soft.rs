//! `mote pack --method soft`: the SP packing of [`mote_md::soft_pack`] run
//! with the common packing files and summary.

use mote_edmd::analyse::{contacts, stable_contacts};
use mote_edmd::pack::{PackSettings, SizeSpec};

use super::{PackFiles, Packed};
use crate::error::FrontError;
use crate::{Ending, Monitor};

/// The SP method ([`mote_md::soft_pack`]): soft spheres compressed by a
/// barostat, the target pressure stepped down a decade at a time to
/// `min_pressure`; φ at each pressure goes to the CSV and the summary with
/// the extrapolation to P = 0; the spheres at the lowest pressure are the
/// packing (overlapping by ~p^{2/3} of a diameter), with their contacts,
/// rattlers and backbone.
pub(super) fn pack_soft(
    settings: PackSettings,
    min_pressure: f64,
    files: &PackFiles,
    provenance: &mote_io::Provenance,
    monitor: &mut dyn Monitor,
) -> Result<Packed, FrontError> {
    use mote_md::soft_pack::{extrapolate, SoftPackSettings, SoftPacker};
    use rand::SeedableRng;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(settings.seed);
    let n = match &settings.sizes {
        SizeSpec::Radii(r) => r.len(),
        _ => settings.n,
    };
    let diameters = settings.sizes.diameters(n, &mut rng);
    // The barostat holds 1e-2 … 1e-4 (the SP method proper); the jamming
    // finish minimises its way on down to `min_pressure`.
    let pressures = SoftPackSettings::decades(min_pressure.max(1e-4));
    let mut packer = SoftPacker::new(SoftPackSettings {
        diameters,
        phi_start: settings.phi_start,
        pressures: pressures.clone(),
        tolerance: 0.02,
        max_steps: 2_000_000,
        seed: settings.seed,
    })
    .map_err(FrontError::request)?;
    let stem = files.stem()?;
    let mut csv = match &stem {
        Some(s) => Some(mote_io::csv::CsvWriter::create(
            &s.with("csv"),
            provenance,
            &["steps", "phi", "pressure", "minimised"].map(String::from),
            &["", "", "K", ""].map(String::from),
        )?),
        None => None,
    };
    let cpu0 = crate::cpu::cpu_seconds();
    let began = std::time::Instant::now();
    let wall_clock = settings.wall_clock;
    let stop = || {
        mote_io::system::stop_requested().is_some()
            || wall_clock.is_some_and(|limit| began.elapsed() > limit)
    };
    let mut csv_err = None;
    let finish_decades = (1e-4 / min_pressure).log10().ceil().max(0.0) as u64;
    let total = pressures.len() as u64 + finish_decades;
    let mut done = 0;
    let stages = packer.run(
        |s, p| {
            done += 1;
            if let Some(w) = csv.as_mut() {
                if let Err(e) = w.row(&[p.steps as f64, s.phi, s.pressure, 0.0]) {
                    csv_err.get_or_insert(e);
                }
            }
            monitor.progress(
                done,
                total,
                &format!("barostat: phi {:.5}  P/K {:.2e}", s.phi, s.pressure),
            );
        },
        &stop,
    );
    let held = stages.len() == pressures.len();
    let barostat_phi_j = extrapolate(&stages[stages.len().saturating_sub(3)..]);
    let analyse = |p: &SoftPacker| {
        let side = p.side();
        let simbox = mote_edmd::system::SimBox::<3> {
            size: [side; 3],
            boundary: [mote_edmd::system::Boundary::Periodic; 3],
        };
        let lo = p.boundary.lo;
        let pos: Vec<[f64; 3]> = p
            .position
            .iter()
            .map(|r| (p.boundary.wrap(*r) - lo).to_array())
            .collect();
        let counted = contacts(&simbox, &pos, &p.radius, 0.0);
        (simbox, pos, counted)
    };
    let before = analyse(&packer).2;
    let barostat_steps = packer.steps;
    let finish = if held && min_pressure < 1e-4 && !stop() {
        let slope = barostat_phi_j.map_or(3.0, |(_, c)| c);
        monitor.progress(done, total, "jamming finish: minimising");
        packer.jam(min_pressure, slope, 1e-10, &stop)
    } else {
        Vec::new()
    };
    // the steps column counts every step so far, FIRE's included
    let mut steps = barostat_steps;
    for s in &finish {
        steps += s.steps;
        if let Some(w) = csv.as_mut() {
            if let Err(e) = w.row(&[steps as f64, s.phi, s.pressure, 1.0]) {
                csv_err.get_or_insert(e);
            }
        }
    }
    monitor.finish();
    if let Some(e) = csv_err {
        return Err(e.into());
    }
    let cpu = crate::cpu::cpu_seconds() - cpu0;
    let (simbox, pos, counted) = analyse(&packer);
    let side = packer.side();
    let radii = packer.radius.clone();
    let frame = mote_io::xyz::Frame {
        time: packer.time,
        cell: [[side, 0.0, 0.0], [0.0, side, 0.0], [0.0, 0.0, side]],
        origin: [0.0; 3],
        pbc: [true; 3],
        species: vec!["H".to_string(); radii.len()],
        positions: pos.clone(),
        radii: radii.clone(),
        ..mote_io::xyz::Frame::default()
    };
    files.write(&frame, provenance)?;
    let mut summary = vec![format!(
        "{} spheres by the soft (SP) method: {} steps in {cpu:.2} s CPU. Barostat (Hertz, radial dissipation, Stokes friction): pressure P/K, packing fraction, overlapping neighbours per sphere:",
        radii.len(),
        packer.steps
    )];
    for s in &stages {
        summary.push(format!(
            "  P/K = {:.3e}  phi = {:.6}  z = {:.4}  ({} steps{})",
            s.pressure,
            s.phi,
            s.z,
            s.steps,
            if s.converged {
                ""
            } else {
                ", NOT held: step budget spent"
            }
        ));
    }
    if let Some((phi_j, _)) = barostat_phi_j {
        summary.push(format!(
            "Barostat extrapolated to zero pressure (phi = phi_J + c p^(2/3)): phi_J = {phi_j:.6}; backbone z = {:.4} with {} rattlers (< 4 contacts, recursively).",
            before.backbone_z,
            before.rattlers()
        ));
    }
    let finish_phi_j = extrapolate(&finish[finish.len().saturating_sub(3)..]);
    if !finish.is_empty() {
        summary.push("Jamming finish (FIRE energy minimisation at fixed box, decompressed a decade of pressure at a time):".into());
        for s in &finish {
            summary.push(format!(
                "  P/K = {:.3e}  phi = {:.6}  z = {:.4}  ({} FIRE steps{})",
                s.pressure,
                s.phi,
                s.z,
                s.steps,
                if s.converged {
                    ""
                } else {
                    ", residual force above 1e-10"
                }
            ));
        }
        if let Some((phi_j, _)) = finish_phi_j {
            summary.push(format!(
                "Finish extrapolated to zero pressure: phi_J = {phi_j:.6}."
            ));
        }
    }
    let strict = stable_contacts(&simbox, &pos, &radii, 0.0);
    summary.push(format!(
        "Contacts (overlaps) at the end: {} rattlers ({:.2} %) by count (< 4 contacts, recursively), backbone z = {:.4}; with force balance (contacts not all in one hemisphere): {} rattlers, backbone z = {:.4} (isostatic 6).",
        counted.rattlers(),
        100.0 * counted.rattlers() as f64 / radii.len() as f64,
        counted.backbone_z,
        strict.rattlers(),
        strict.backbone_z
    ));
    if let Some(o) = &files.xyz {
        summary.push(format!("Wrote {} (+ .csv, .pov).", o.display()));
    }
    let phi_j = finish_phi_j.or(barostat_phi_j).map(|(phi_j, _)| phi_j);
    let last = finish.last().or(stages.last()).copied();
    let interrupted = !held || (min_pressure < 1e-4 && finish.len() < 2);
    let ending = match (interrupted, mote_io::system::stop_requested()) {
        (true, Some(signal)) => Ending::Interrupted {
            signal,
            message: format!("interrupted by signal {signal}; the packing so far is written"),
        },
        _ => Ending::Finished,
    };
    Ok(Packed {
        summary,
        ending,
        frame,
        phi: phi_j.unwrap_or(packer.phi()),
        pressure: last.map_or(f64::NAN, |s| s.pressure),
    })
}
