//! `mote pack`: random close packings by growing spheres (Lubachevsky–Stillinger).
//!
//! `mote pack [options]` grows a packing with `mote_edmd::pack::Packer` and
//! writes it (extended XYZ with radii), φ(t) and the pressure (CSV), a POV-Ray
//! scene and optionally a PNG picture; `mote pack analyse FILE` reports the
//! structure of a packing (`mote_edmd::analyse`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use mote_edmd::analyse::{
    bond_order, contacts, deepest_overlap, pair_correlation, stable_contacts,
};
use mote_edmd::{Boundary, SimBox};
use mote_front::packing::{Naming, PackRequest, PackingSpec};
use mote_front::Ending;

use super::GlobalOpts;
use mote_front::Terminal;

/// The words of `mote pack` (its help text is the `Pack` variant's in main.rs).
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, allow_negative_numbers = true)]
pub struct PackArgs {
    #[command(subcommand)]
    command: Option<PackCommand>,
    /// Number of particles (ignored with --dist file:PATH or --start).
    #[arg(long, short = 'n', default_value_t = 1000)]
    n: usize,
    /// Grow from the last frame of this trajectory (xyz, dump, gsd, vtp/pvd):
    /// its positions, radii and box, instead of a random start.
    #[arg(long, value_name = "FILE")]
    start: Option<String>,
    /// Dimension: 3 (spheres) or 2 (disks).
    #[arg(long, default_value_t = 3)]
    dim: usize,
    /// Size distribution: mono, bi:RATIO:FRACTION (diameter ratio, number
    /// fraction of the large), lognormal:SIGMA, or file:PATH (one radius per line).
    #[arg(long, default_value = "mono")]
    dist: String,
    /// How to pack (`soft`: the barostat is stepped down to
    /// --min-pressure and φ extrapolated to zero pressure; 3-D, periodic).
    #[arg(long, default_value = "hard", value_parser = super::choices::pack_method())]
    method: String,
    /// Soft method: the lowest pressure P/K (K = 4E*/3): the barostat
    /// holds 1e-2 … 1e-4, then the jamming finish (energy minimisation)
    /// decompresses a decade at a time to this.
    #[arg(long, default_value_t = 1e-8, value_name = "P")]
    min_pressure: f64,
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
    /// Folder for the packing, as `mote run -o` names a run's:
    /// DIR/packing.xyz (numbers exact; another format with --format),
    /// DIR/packing.csv (φ and pressure per window or stage), DIR/packing.pov
    /// (POV-Ray scene) and DIR/checkpoint.mote. Without it, nothing is written.
    #[arg(long, short = 'o', value_name = "DIR")]
    output: Option<PathBuf>,
    /// Format of DIR/packing.* (read back by --start, [[from_file]] and
    /// other programs).
    #[arg(long, value_name = "FORMAT", default_value = "xyz", value_parser = super::choices::trajectory_format())]
    format: String,
    /// Render the packing to this PNG.
    #[arg(long, value_name = "FILE.png")]
    picture: Option<PathBuf>,
    /// Write DIR/checkpoint.mote every N pressure windows (soft method:
    /// chunks of 100 steps) and when a signal stops the run (needs -o);
    /// continue with
    /// `mote run --resume DIR/checkpoint.mote`.
    #[arg(long, value_name = "N")]
    checkpoint_every: Option<u64>,
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
    /// Ray-trace the packing into this PNG (800×800, as `mote pack --picture`).
    #[arg(long, value_name = "FILE.png")]
    picture: Option<PathBuf>,
}

pub fn run(global: &GlobalOpts, args: PackArgs) -> anyhow::Result<ExitCode> {
    match &args.command {
        Some(PackCommand::Analyse(a)) => analyse_cmd(global, a),
        None => pack_cmd(global, &args),
    }
}

impl PackArgs {
    /// The packing these options ask for, in the keys a `[packing]` scene uses.
    fn spec(&self) -> PackingSpec {
        PackingSpec {
            n: self.n,
            dimension: self.dim,
            dist: self.dist.clone(),
            rate: self.rate,
            max_pressure: self.max_pressure,
            phi: self.phi,
            max_collisions: self.max_collisions,
            time_limit: self.time_limit,
            walls: self.walls.clone(),
            rescale_every: self.rescale_every,
            jam: !self.no_jam,
            jam_start: self.jam_start,
            jam_step: self.jam_step,
            jam_relax: self.jam_relax,
            phi_start: self.phi_start,
            tol: self.tol,
            start: self.start.clone(),
            method: self.method.clone(),
            min_pressure: self.min_pressure,
        }
    }
}

/// `mote pack [options]`: the same packing run as a `[packing]` scene under
/// `mote run` (`mote_front::packing`), spelled as options.
fn pack_cmd(global: &GlobalOpts, a: &PackArgs) -> anyhow::Result<ExitCode> {
    let quiet = global.quiet;
    let format = mote_io::trajectory::Format::named(&a.format).with_context(|| {
        format!(
            "--format {}: expected one of {}",
            a.format,
            mote_io::trajectory::Format::NAMES
        )
    })?;
    // -o named the packing file before it named the folder, as in `mote run`.
    if let Some(o) = &a.output {
        if let Some(named) = mote_front::packing::named_like_a_file(o) {
            let folder = o.with_extension("");
            anyhow::bail!(
                "-o {}: -o names the packing's folder, as `mote run -o` names a run's; \
                 the packing goes to DIR/packing.{}: give -o {}{}",
                o.display(),
                named.extension(),
                folder.display(),
                if named == mote_io::trajectory::Format::Xyz {
                    String::new()
                } else {
                    format!(" --format {}", format_name(named))
                }
            );
        }
    }
    if let Some(p) = &a.picture {
        mote_front::check_picture_path(p)?;
    }
    let spec = a.spec();
    let (seed, seed_chosen) = mote_front::seed::resolve(global.seed, None);
    let method = spec.method(Naming::Options)?;
    let start = match &a.start {
        Some(file) => format!("--start {file}"),
        None => format!("--n {} --dist {}", a.n, a.dist),
    };
    let label = match method {
        mote_front::packing::Method::Hard => format!(
            "mote pack --dim {} {start} --rate {} --max-pressure {:e}{}",
            a.dim,
            a.rate,
            a.max_pressure,
            if a.no_jam { " --no-jam" } else { "" }
        ),
        mote_front::packing::Method::Soft { min_pressure } => {
            format!("mote pack {start} --method soft --min-pressure {min_pressure:e}")
        }
    };
    match (a.checkpoint_every, &a.output) {
        (Some(0), _) => anyhow::bail!("--checkpoint-every 0: give a number of steps ≥ 1"),
        (Some(_), None) => {
            anyhow::bail!("--checkpoint-every needs -o DIR: the packing is resumed into it")
        }
        _ => {}
    }
    let request = PackRequest {
        output: a.output.clone(),
        format,
        picture: a.picture.clone(),
        checkpoint_every: a.checkpoint_every,
        seed,
        seed_chosen,
    };
    let mut terminal = Terminal::new(quiet);
    let packed = mote_front::packing::pack(&spec, &label, &request, &mut terminal)?;
    if !quiet {
        for line in &packed.summary {
            say!("{line}");
        }
    }
    // A signal stopped it: the packing so far is written; exit 128 + signal.
    if let Ending::Interrupted { signal, message } = &packed.ending {
        tell!("mote pack: {message}");
        return Ok(ExitCode::from((128 + signal).clamp(0, 255) as u8));
    }
    Ok(ExitCode::SUCCESS)
}

/// The name --format gives `format` by.
fn format_name(format: mote_io::trajectory::Format) -> &'static str {
    use mote_io::trajectory::Format;
    match format {
        Format::Xyz => "xyz",
        Format::Dump => "dump",
        Format::Gsd => "gsd",
        Format::Vtk => "vtk",
    }
}

fn analyse_cmd(global: &GlobalOpts, a: &AnalyseArgs) -> anyhow::Result<ExitCode> {
    let quiet = global.quiet;
    let frames = mote_io::trajectory::read_frames(&a.file)?;
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
    // A packing is of spheres with a size, in a box of finite size.
    if let Some((i, r)) = frame
        .radii
        .iter()
        .enumerate()
        .find(|(_, r)| !(r.is_finite() && **r > 0.0))
    {
        anyhow::bail!(
            "{}: sphere {i} has radius {r}: a packing's spheres have positive radii",
            a.file.display()
        );
    }
    if let Some(d) = (0..3).find(|&d| !frame.cell[d][d].is_finite()) {
        anyhow::bail!(
            "{}: the cell has no finite length on axis {d}",
            a.file.display()
        );
    }
    if let Some(png) = &a.picture {
        mote_front::check_picture_path(png)?;
        mote_render::frame::picture(frame, png, 800, 800)?;
    }
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
        say!(
            "{}: {n} {}",
            a.file.display(),
            if D == 2 { "disks" } else { "spheres" }
        );
        say!("packing fraction      {phi:.6}");
        say!(
            "contacts (gap < {:e}) mean {:.4} over all; {} rattlers (< {} contacts, {:.2} %); backbone mean {:.4} (isostatic {})",
            a.tol,
            mean_all,
            c.rattlers(),
            D + 1,
            100.0 * c.rattlers() as f64 / n as f64,
            c.backbone_z,
            2 * D
        );
        let s = stable_contacts(&simbox, &pos, radii, a.tol);
        say!(
            "force balance         {} rattlers ({:.2} %) when contacts all in one hemisphere also rattle, recursively; backbone mean {:.4}",
            s.rattlers(),
            100.0 * s.rattlers() as f64 / n as f64,
            s.backbone_z
        );
        say!(
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
        say!(
            "g(r) peak             {:.3} at r = {:.3} mean diameters",
            peak.1,
            peak.0
        );
        match overlap {
            None => say!("overlaps              none"),
            Some((i, j, g)) => say!("deepest overlap       {i}, {j}: |r|/sigma - 1 = {g:.3e}"),
        }
    }
    Ok(ExitCode::SUCCESS)
}
