//! `mote edmd`: event-driven hard spheres and disks (crate `mote-edmd`).
//!
//! Parses its own words (`mote edmd SCENE [options]`), reads the scene or a
//! built-in example, runs it through `mote_edmd::scene::run_scene` and prints
//! a one-paragraph summary.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use mote_edmd::scene::{example, run_scene, Outputs, EXAMPLES};
use mote_edmd::Scene;

/// Event-driven molecular dynamics of hard spheres (3-D) and disks (2-D).
///
/// SCENE is a TOML scene file (keys in docs/edmd.md) or `example:NAME`, one of
/// cube, cradle, cradle-two, cradle-symmetric, cradle-heavy, maxwell2d, eos.
/// Outputs (extended XYZ, CSV) go next to the scene file, or to the current
/// folder for examples, unless --out-dir is given.
#[derive(Parser, Debug)]
#[command(name = "mote edmd", version)]
struct Args {
    /// Scene file or `example:NAME`.
    #[arg(value_name = "SCENE")]
    scene: Option<String>,
    /// List the built-in examples and exit.
    #[arg(long)]
    list: bool,
    /// Simulated time to run (overrides the scene's `time`).
    #[arg(long, value_name = "T")]
    time: Option<f64>,
    /// Folder for the output files.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// Write no trajectory, observables or histogram files.
    #[arg(long)]
    no_output: bool,
    /// Seed of the random number generator (default: the scene's, else chosen and printed).
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Print nothing but errors.
    #[arg(long, short = 'q')]
    quiet: bool,
    /// Accepted for symmetry with other commands; the event loop is serial.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
}

pub fn run(global: &super::GlobalOpts, args: &[String]) -> anyhow::Result<ExitCode> {
    let args = match Args::try_parse_from(
        std::iter::once("mote edmd".to_string()).chain(args.iter().cloned()),
    ) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return Ok(if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            });
        }
    };
    let quiet = global.quiet || args.quiet;
    if args.list {
        for (name, text) in EXAMPLES {
            let first = text
                .lines()
                .next()
                .unwrap_or("")
                .trim_start_matches('#')
                .trim();
            println!("example:{name:<18} {first}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(scene_arg) = args.scene.as_deref() else {
        anyhow::bail!("no scene given: `mote edmd SCENE` (a .toml file or example:NAME; `mote edmd --list` lists the examples)");
    };
    let (mut scene, label, base) = if let Some(name) = scene_arg.strip_prefix("example:") {
        let text = example(name).with_context(|| {
            let names: Vec<&str> = EXAMPLES.iter().map(|(n, _)| *n).collect();
            format!("unknown example `{name}`; known: {}", names.join(", "))
        })?;
        let scene = Scene::parse(text, &format!("example:{name}"))?;
        (scene, scene_arg.to_string(), PathBuf::from("."))
    } else {
        let path = Path::new(scene_arg);
        let scene = Scene::read(path)?;
        let base = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        (scene, scene_arg.to_string(), base)
    };
    if let Some(t) = args.time {
        anyhow::ensure!(
            t >= 0.0 && t.is_finite(),
            "--time {t}: must be a non-negative number"
        );
        scene.time = t;
    }
    if args.no_output {
        scene.trajectory = None;
        scene.observables = None;
        scene.histogram = None;
    }
    let out_base = match &args.out_dir {
        Some(d) => {
            std::fs::create_dir_all(d)
                .with_context(|| format!("{}: cannot create folder", d.display()))?;
            d.clone()
        }
        None => base,
    };
    let seed = args.seed.or(global.seed).or(scene.seed).unwrap_or_else(|| {
        let t = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(0);
        t ^ (std::process::id() as u64).rotate_left(32)
    });
    if !quiet {
        eprintln!("mote edmd: {label}, seed {seed}");
    }
    let out = Outputs {
        base: out_base,
        provenance: mote_io::Provenance {
            program: format!("mote {}", env!("CARGO_PKG_VERSION")),
            scene: label.clone(),
            seed,
        },
    };
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(1000);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {percent:>3}% {elapsed_precise} (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    };
    let cpu0 = cpu_seconds();
    let result = match scene.dimension {
        2 => run_scene::<2>(&scene, seed, &out, |f| {
            bar.set_position((f * 1000.0) as u64)
        }),
        _ => run_scene::<3>(&scene, seed, &out, |f| {
            bar.set_position((f * 1000.0) as u64)
        }),
    };
    bar.finish_and_clear();
    let r = result.with_context(|| format!("{label}: run stopped"))?;
    let cpu = cpu_seconds() - cpu0;
    if !quiet {
        let rate = if cpu > 0.05 {
            format!("{:.3e}", r.collisions as f64 / cpu)
        } else {
            "(too short to time)".to_string()
        };
        let mut s = format!(
            "{} {} (packing fraction {:.4}, seed {}): simulated t = {} after {} of equilibration with {} pair collisions and {} wall collisions \
             ({} events in all) in {:.3} s CPU / {:.3} s wall, {} collisions per CPU-second. ",
            r.n,
            if r.dimension == 2 { "disks" } else { "spheres" },
            r.packing_fraction,
            r.seed,
            r.simulated_time,
            scene.equilibrate,
            r.collisions,
            r.wall_hits,
            r.events,
            cpu,
            r.wall_seconds,
            rate
        );
        if r.z.is_finite() {
            s += &format!(
                "Compressibility factor Z = {:.4} ({} {:.4}, {:+.2} %). ",
                r.z,
                if r.dimension == 2 {
                    "Henderson"
                } else {
                    "Carnahan-Starling"
                },
                r.z_reference,
                100.0 * (r.z - r.z_reference) / r.z_reference
            );
        }
        if r.wall_pressure.is_finite() {
            s += &format!("Wall pressure {:.4e}. ", r.wall_pressure);
        }
        if r.collisions > 0 {
            s += &format!(
                "Collision rate {:.4} per particle per unit time (mean free time {:.4e}). ",
                r.collision_rate, r.mean_free_time
            );
        }
        s += &format!(
            "kT = {:.6}; energy drift {:.1e}",
            r.temperature, r.energy_drift
        );
        if r.momentum_drift.is_finite() {
            s += &format!(", momentum drift {:.1e}", r.momentum_drift);
        }
        s += &format!(
            "; speeds vs Maxwell-Boltzmann: KS D = {:.4}, p = {:.3}.",
            r.ks.0, r.ks.1
        );
        println!("{s}");
        if r.n <= 10 {
            let v: Vec<String> = r.speeds.iter().map(|x| format!("{x:.12}")).collect();
            println!("final speeds: {}", v.join(" "));
            if let Some(vx) = final_vx(&r) {
                println!("{vx}");
            }
        }
        for p in &r.outputs {
            println!("wrote {}", p.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn final_vx(r: &mote_edmd::Run) -> Option<String> {
    if r.final_velocities.is_empty() {
        return None;
    }
    let v: Vec<String> = r
        .final_velocities
        .iter()
        .map(|v| format!("{:+.12}", v[0]))
        .collect();
    Some(format!("final x-velocities: {}", v.join(" ")))
}

/// CPU seconds (user + system) of this process, from /proc (NaN elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // fields after the `(comm)`: state is field 3; utime 14, stime 15
    let Some(rest) = s.rfind(')').map(|k| &s[k + 2..]) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| {
        f.get(k)
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    // the kernel reports in USER_HZ, 100 on Linux
    (ticks(11) + ticks(12)) / 100.0
}
