//! `mote pack`: random close packings by growing spheres (Lubachevsky–Stillinger).
//!
//! `mote pack [options]` grows a packing with `mote_edmd::pack::Packer` and
//! writes it (extended XYZ with radii), φ(t) and the pressure (CSV), a POV-Ray
//! scene and optionally a PNG picture; `mote pack analyse FILE` reports the
//! structure of a packing (`mote_edmd::analyse`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use mote_edmd::analyse::{bond_order, contacts, deepest_overlap, pair_correlation};
use mote_edmd::pack::{Finish, PackSettings, Packer, SizeSpec, Stop};
use mote_edmd::{Boundary, SimBox};

use super::GlobalOpts;

/// The words of `mote pack` (its help text is the `Pack` variant's in main.rs).
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, allow_negative_numbers = true)]
pub struct PackArgs {
    #[command(subcommand)]
    command: Option<PackCommand>,
    /// Number of particles (ignored with --dist file:PATH).
    #[arg(long, short = 'n', default_value_t = 1000)]
    n: usize,
    /// Dimension: 3 (spheres) or 2 (disks).
    #[arg(long, default_value_t = 3)]
    dim: usize,
    /// Size distribution: mono, bi:RATIO:FRACTION (diameter ratio, number
    /// fraction of the large), lognormal:SIGMA, or file:PATH (one radius per line).
    #[arg(long, default_value = "mono")]
    dist: String,
    /// Growth rate Γ = (1/v_th) d⟨d⟩/dt (smaller: denser, slower).
    #[arg(long, default_value_t = 0.01)]
    rate: f64,
    /// Stop when the reduced pressure PV/(NkT) exceeds this.
    #[arg(long, default_value_t = 1e12)]
    max_pressure: f64,
    /// Stop at this packing fraction.
    #[arg(long, value_name = "PHI")]
    phi: Option<f64>,
    /// Stop after this many pair collisions.
    #[arg(long, value_name = "N")]
    max_collisions: Option<u64>,
    /// Stop after this many seconds of wall-clock time.
    #[arg(long, value_name = "SECONDS")]
    time_limit: Option<f64>,
    /// Hard walls on these axes (e.g. `z` or `xyz`); periodic elsewhere.
    #[arg(long, value_name = "AXES", default_value = "")]
    walls: String,
    /// Collisions per particle between kinetic-energy rescalings (and pressure windows).
    #[arg(long, default_value_t = 10.0)]
    rescale_every: f64,
    /// Grow at Γ to the pressure threshold without the quasi-static finish
    /// (spheropack's `Pressure` criterion; faster, not isostatic).
    #[arg(long)]
    no_jam: bool,
    /// Quasi-static finish: starts when the pressure passes this.
    #[arg(long, default_value_t = 1e3, value_name = "Z")]
    jam_start: f64,
    /// Quasi-static finish: fraction of the estimated gap to jamming closed per step.
    #[arg(long, default_value_t = 0.2, value_name = "F")]
    jam_step: f64,
    /// Quasi-static finish: relaxation windows at fixed size between growth steps.
    #[arg(long, default_value_t = 4, value_name = "K")]
    jam_relax: usize,
    /// Packing fraction of the random start.
    #[arg(long, default_value_t = 0.1)]
    phi_start: f64,
    /// Relative gap tolerance for contacts in the summary (default
    /// 1000/max-pressure: force-bearing gaps are ~1/Z).
    #[arg(long)]
    tol: Option<f64>,
    /// The packing, as extended XYZ with radii; also writes STEM.csv (φ and
    /// pressure per window) and STEM.pov (POV-Ray scene) beside it.
    #[arg(long, short = 'o', value_name = "FILE")]
    output: Option<PathBuf>,
    /// Render the packing to this PNG.
    #[arg(long, value_name = "FILE.png")]
    picture: Option<PathBuf>,
}

#[derive(clap::Subcommand, Debug)]
enum PackCommand {
    /// Structure of a packing: φ, contacts, rattlers, g(r), Q6.
    #[command(alias = "analyze")]
    Analyse(AnalyseArgs),
}

/// Structure of a packing: φ, contacts at a relative gap tolerance, rattlers,
/// g(r) and the bond-orientational order (Q6 in 3-D, |ψ6| in 2-D).
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
struct AnalyseArgs {
    /// Extended XYZ file with radii (the last frame is analysed).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Relative gap tolerance: i and j touch if |r_ij| < (1 + TOL)(r_i + r_j).
    /// `mote pack` writes every number exactly, so any tolerance works on
    /// its files; other writers' rounding (e.g. 7 digits) sets a floor.
    #[arg(long, default_value_t = 1e-5)]
    tol: f64,
    /// Bonds for Q6: |r_ij| < BOND·(r_i + r_j).
    #[arg(long, default_value_t = 1.2)]
    bond: f64,
    /// Write g(r) (r in mean diameters) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    gr: Option<PathBuf>,
    /// Largest r of g(r), in mean diameters.
    #[arg(long, default_value_t = 3.0)]
    rmax: f64,
}

pub fn run(global: &GlobalOpts, args: PackArgs) -> anyhow::Result<ExitCode> {
    match &args.command {
        Some(PackCommand::Analyse(a)) => analyse_cmd(global, a),
        None => pack_cmd(global, &args),
    }
}

/// Reads one radius per line (`#` starts a comment); errors as `file:line: ...`.
fn read_radii(path: &Path) -> anyhow::Result<Vec<f64>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the radii file", path.display()))?;
    let mut radii = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let r: f64 = body.parse().map_err(|_| {
            anyhow::anyhow!(
                "{}:{}: `{body}` is not a number (one radius per line)",
                path.display(),
                k + 1
            )
        })?;
        anyhow::ensure!(
            r > 0.0 && r.is_finite(),
            "{}:{}: radius {r} must be positive and finite",
            path.display(),
            k + 1
        );
        radii.push(r);
    }
    anyhow::ensure!(
        radii.len() >= 2,
        "{}: needs at least 2 radii, found {}",
        path.display(),
        radii.len()
    );
    Ok(radii)
}

fn pack_cmd(global: &GlobalOpts, a: &PackArgs) -> anyhow::Result<ExitCode> {
    let quiet = global.quiet;
    anyhow::ensure!(a.dim == 2 || a.dim == 3, "--dim {}: must be 2 or 3", a.dim);
    // Positions, velocities, radii, times, event, cell and neighbour entries:
    // at least 300 bytes a sphere.
    mote_io::system::check_fits(&format!("--n {}: the packing", a.n), a.n as f64 * 300.0)
        .map_err(anyhow::Error::msg)?;
    let sizes = match a.dist.strip_prefix("file:") {
        Some(p) => SizeSpec::Radii(read_radii(Path::new(p))?),
        None => SizeSpec::parse(&a.dist).map_err(|e| anyhow::anyhow!("--dist: {e}"))?,
    };
    let axes = &"xyz"[..a.dim];
    let mut walls = vec![false; a.dim];
    for c in a.walls.chars() {
        let k = axes
            .find(c)
            .with_context(|| format!("--walls {}: `{c}` is not an axis of {axes}", a.walls))?;
        walls[k] = true;
    }
    if let Some(t) = a.time_limit {
        anyhow::ensure!(
            t > 0.0 && t.is_finite(),
            "--time-limit {t}: must be a positive number of seconds"
        );
    }
    if let Some(t) = a.tol {
        anyhow::ensure!(
            t >= 0.0 && t.is_finite(),
            "--tol {t}: must be a non-negative number"
        );
    }
    let (seed, chosen) = mote_front::seed::resolve(global.seed, None);
    let settings = PackSettings {
        n: a.n,
        sizes,
        rate: a.rate,
        phi_start: a.phi_start,
        walls,
        max_pressure: a.max_pressure,
        target_phi: a.phi,
        max_collisions: a.max_collisions,
        wall_clock: a.time_limit.map(Duration::from_secs_f64),
        rescale_every: a.rescale_every,
        finish: (!a.no_jam).then_some(Finish {
            start_pressure: a.jam_start,
            relax_windows: a.jam_relax,
            step: a.jam_step,
        }),
        seed,
    };
    let label = format!(
        "mote pack --dim {} --n {} --dist {} --rate {} --max-pressure {:e}{}",
        a.dim,
        a.n,
        a.dist,
        a.rate,
        a.max_pressure,
        if a.no_jam { " --no-jam" } else { "" }
    );
    if !quiet {
        eprintln!(
            "mote pack: {label}, seed {seed}{}",
            if chosen { " (chosen)" } else { "" }
        );
    }
    let provenance = mote_io::Provenance {
        program: format!("mote {}", env!("CARGO_PKG_VERSION")),
        scene: label,
        seed,
    };
    match a.dim {
        2 => pack_dim::<2>(settings, a, &provenance, quiet),
        _ => pack_dim::<3>(settings, a, &provenance, quiet),
    }
}

fn pack_dim<const D: usize>(
    settings: PackSettings,
    a: &PackArgs,
    provenance: &mote_io::Provenance,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let max_pressure = settings.max_pressure;
    let mut packer = Packer::<D>::new(settings).context("mote pack")?;
    let stem = a.output.as_ref().map(|p| p.with_extension(""));
    if let Some(dir) = a.output.as_ref().and_then(|p| p.parent()) {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the folder {}", dir.display()))?;
        }
    }
    let mut csv = match &stem {
        Some(s) => {
            let path = s.with_extension("csv");
            Some(mote_io::csv::CsvWriter::create(
                &path,
                provenance,
                &["collisions", "time", "phi", "pressure"].map(String::from),
                &["", "", "", ""].map(String::from),
            )?)
        }
        None => None,
    };
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(1000);
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {elapsed_precise} {bar:30} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        // drawn only after a second, so short runs stay silent
        b.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        b
    };
    let t0 = std::time::Instant::now();
    let cpu0 = mote_front::cpu::cpu_seconds();
    let mut csv_err = None;
    let result = packer.run(|s| {
        if let Some(w) = csv.as_mut() {
            if let Err(e) = w.row(&[s.collisions as f64, s.time, s.phi, s.pressure]) {
                csv_err.get_or_insert(e);
            }
        }
        if !quiet {
            if t0.elapsed().as_secs_f64() > 1.0 && bar.is_hidden() {
                bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            }
            // progress: log10 of the pressure towards the threshold
            let f = (s.pressure.max(1.0).log10() / max_pressure.log10()).clamp(0.0, 1.0);
            bar.set_position((f * 1000.0) as u64);
            bar.set_message(format!(
                "phi {:.5}  Z {:.3e}  {} collisions",
                s.phi, s.pressure, s.collisions
            ));
        }
    });
    bar.finish_and_clear();
    let out = result.context("mote pack: run stopped")?;
    if let Some(e) = csv_err {
        return Err(e.into());
    }
    let cpu = mote_front::cpu::cpu_seconds() - cpu0;
    let sys = packer.system();
    let simbox = *sys.simbox();
    let pos = sys.positions();
    let radii = sys.radii();
    let overlap = deepest_overlap(&simbox, &pos, &radii);
    let frame = mote_edmd::scene::frame(sys);
    if let Some(s) = &stem {
        let path = a.output.clone().unwrap_or_else(|| s.with_extension("xyz"));
        let mut w = mote_io::xyz::XyzWriter::create(&path, provenance.clone())?.exact();
        w.write(&frame)?;
        write_pov(&frame, &s.with_extension("pov"))?;
    }
    if let Some(p) = &a.picture {
        mote_render::frame::picture(&frame, p, 800, 800)
            .with_context(|| format!("{}: cannot render the picture", p.display()))?;
    }
    if !quiet {
        let tol = a.tol.unwrap_or(1e3 / max_pressure);
        let c = contacts(&simbox, &pos, &radii, tol);
        let (q, _) = bond_order(&simbox, &pos, &radii, 1.2);
        let stop = match out.stop {
            Stop::Pressure => format!("reduced pressure passed {max_pressure:e} (jammed)"),
            Stop::TargetPhi => "target packing fraction reached".to_string(),
            Stop::Collisions => "collision budget spent".to_string(),
            Stop::WallClock => "wall-clock limit reached".to_string(),
            Stop::Interrupted => "run was interrupted by a signal (not jammed)".to_string(),
        };
        println!(
            "{} {}: phi = {:.6}, reduced pressure Z = {:.3e}, stopped because the {stop}.",
            sys.len(),
            if D == 2 { "disks" } else { "spheres" },
            out.phi,
            out.pressure
        );
        println!(
            "{} collisions in {:.2} s CPU ({:.3e} per CPU-second), {} growth epochs.",
            out.collisions,
            cpu,
            out.collisions as f64 / cpu.max(1e-9),
            out.epochs
        );
        println!(
            "Contacts at relative gap {:e}: {} rattlers (< {} contacts), backbone mean contact number {:.4} (isostatic {}); {} = {:.4}.",
            tol,
            c.rattlers(),
            D + 1,
            c.backbone_z,
            2 * D,
            if D == 2 { "|psi6|" } else { "Q6" },
            q
        );
        match overlap {
            None => println!("No overlaps (exact check over all pairs that can touch)."),
            Some((_, _, g)) if g > -1e-12 => println!(
                "No overlaps beyond round-off (exact check over all pairs that can touch; deepest |r|/sigma - 1 = {g:.1e})."
            ),
            Some((i, j, g)) => println!(
                "OVERLAP: particles {i} and {j}, |r|/sigma - 1 = {g:.3e}."
            ),
        }
        if let Some(o) = &a.output {
            println!("Wrote {} (+ .csv, .pov).", o.display());
        }
    }
    if let Some((i, j, g)) = overlap {
        anyhow::ensure!(
            g > -1e-9,
            "particles {i} and {j} overlap by {:.3e} of their contact distance",
            -g
        );
    }
    // A signal stopped it: the packing so far is written; exit 128 + signal.
    if let (Stop::Interrupted, Some(signal)) = (out.stop, mote_io::system::stop_requested()) {
        eprintln!("mote pack: interrupted by signal {signal}; the packing so far is written");
        return Ok(ExitCode::from((128 + signal).clamp(0, 255) as u8));
    }
    Ok(ExitCode::SUCCESS)
}

fn write_pov(frame: &mote_io::xyz::Frame, path: &Path) -> anyhow::Result<()> {
    use mote_render::frame::{default_radius, scene_from_frame, ColorBy};
    let (scene, _) = scene_from_frame(
        frame,
        &ColorBy::Species,
        mote_render::ColorMap::Viridis,
        default_radius(frame),
    )?;
    let (lo, hi) = scene.bounds().context("nothing to draw")?;
    let cam = mote_render::Camera::frame(lo, hi, mote_render::camera::DEFAULT_VIEW, 30.0, 800, 800);
    let opts = mote_render::RenderOptions {
        shadows: true,
        ..mote_render::RenderOptions::default()
    };
    mote_render::pov::write_pov(path, &scene, &cam, &opts)?;
    Ok(())
}

fn analyse_cmd(global: &GlobalOpts, a: &AnalyseArgs) -> anyhow::Result<ExitCode> {
    let quiet = global.quiet;
    let frames = mote_io::xyz::read_frames(&a.file)?;
    let frame = frames
        .last()
        .with_context(|| format!("{}: no frame in the file", a.file.display()))?;
    anyhow::ensure!(
        frame.radii.len() == frame.positions.len() && !frame.radii.is_empty(),
        "{}: the frame has no radius column (Properties=...:radius:R:1)",
        a.file.display()
    );
    anyhow::ensure!(
        a.tol >= 0.0 && a.bond > 1.0 && a.rmax > 0.0,
        "--tol must be ≥ 0, --bond > 1 and --rmax > 0"
    );
    let flat = frame.positions.iter().all(|p| p[2] == 0.0) && !frame.pbc[2];
    if flat {
        analyse_dim::<2>(frame, a, quiet)
    } else {
        analyse_dim::<3>(frame, a, quiet)
    }
}

fn analyse_dim<const D: usize>(
    frame: &mote_io::xyz::Frame,
    a: &AnalyseArgs,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let mut size = [0.0; D];
    let mut boundary = [Boundary::Wall; D];
    for d in 0..D {
        size[d] = frame.cell[d][d];
        anyhow::ensure!(
            size[d] > 0.0,
            "{}: the cell has no length on axis {d} (Lattice=\"...\")",
            a.file.display()
        );
        if frame.pbc[d] {
            boundary[d] = Boundary::Periodic;
        }
    }
    let simbox = SimBox { size, boundary };
    let pos: Vec<[f64; D]> = frame
        .positions
        .iter()
        .map(|p| {
            let mut x = [0.0; D];
            for d in 0..D {
                x[d] = p[d] - frame.origin[d];
            }
            x
        })
        .collect();
    let radii = &frame.radii;
    let phi = mote_edmd::analyse::packing_fraction(&simbox, radii);
    let c = contacts(&simbox, &pos, radii, a.tol);
    let (q, bonds) = bond_order(&simbox, &pos, radii, a.bond);
    let overlap = deepest_overlap(&simbox, &pos, radii);
    let g = pair_correlation(&simbox, &pos, radii, a.rmax, (a.rmax * 50.0) as usize);
    if let Some(path) = &a.gr {
        let prov = mote_io::Provenance {
            program: format!("mote {}", env!("CARGO_PKG_VERSION")),
            scene: format!("mote pack analyse {}", a.file.display()),
            seed: 0,
        };
        let mut w = mote_io::csv::CsvWriter::create(
            path,
            &prov,
            &["r".to_string(), "g".to_string()],
            &["mean diameters".to_string(), String::new()],
        )?;
        for (r, v) in &g {
            w.row(&[*r, *v])?;
        }
    }
    if !quiet {
        let n = radii.len();
        let mean_all = c.z.iter().sum::<usize>() as f64 / n as f64;
        let peak = g
            .iter()
            .cloned()
            .fold((0.0, 0.0), |m, x| if x.1 > m.1 { x } else { m });
        println!(
            "{}: {n} {}",
            a.file.display(),
            if D == 2 { "disks" } else { "spheres" }
        );
        println!("packing fraction      {phi:.6}");
        println!(
            "contacts (gap < {:e}) mean {:.4} over all; {} rattlers (< {} contacts, {:.2} %); backbone mean {:.4} (isostatic {})",
            a.tol,
            mean_all,
            c.rattlers(),
            D + 1,
            100.0 * c.rattlers() as f64 / n as f64,
            c.backbone_z,
            2 * D
        );
        println!(
            "{}                   {q:.4} over {bonds} bonds < {}·(r_i + r_j) ({})",
            if D == 2 { "|psi6|" } else { "Q6  " },
            a.bond,
            if D == 3 {
                if q > 0.2 {
                    "crystalline order (fcc 0.575)"
                } else {
                    "no crystalline order (fcc 0.575)"
                }
            } else if q > 0.5 {
                "hexatic order"
            } else {
                "no hexatic order"
            }
        );
        println!(
            "g(r) peak             {:.3} at r = {:.3} mean diameters",
            peak.1, peak.0
        );
        match overlap {
            None => println!("overlaps              none"),
            Some((i, j, g)) => println!("deepest overlap       {i}, {j}: |r|/sigma - 1 = {g:.3e}"),
        }
    }
    Ok(ExitCode::SUCCESS)
}
