//! `mote plot`: the particle inspector of MPPphys (seed 002 §3.2) — columns of an
//! observables CSV against one another, as PNG or SVG.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};

use mote_render::plot::{axis_label, Plot, Series};

/// Plots columns of a CSV written by mote (or any CSV of numbers with a header row).
#[derive(clap::Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  mote plot energy.csv --x time --y total_energy -o energy.png\n  mote plot energy.csv --x time --y kinetic_energy --y potential_energy --logy -o e.svg"
)]
pub struct PlotArgs {
    /// The CSV file (lines starting with # are comments; `# units: u1,u2,...` gives units).
    file: PathBuf,
    /// Column for the horizontal axis.
    #[arg(long, value_name = "COLUMN", default_value = "time")]
    x: String,
    /// Column(s) to plot; repeat for several series (default: every other column).
    #[arg(long, value_name = "COLUMN")]
    y: Vec<String>,
    /// Output picture: .png or .svg.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
    /// Logarithmic horizontal axis.
    #[arg(long)]
    logx: bool,
    /// Logarithmic vertical axis.
    #[arg(long)]
    logy: bool,
    /// Title above the plot (default: the file name).
    #[arg(long)]
    title: Option<String>,
    /// Picture size WIDTHxHEIGHT in pixels.
    #[arg(long, value_name = "WxH", default_value = "1000x600")]
    size: String,
}

pub fn run(global: &super::GlobalOpts, a: PlotArgs) -> anyhow::Result<ExitCode> {
    let (width, height) = parse_size(&a.size)?;
    // (The error's own text already names the file; no second copy of its cause.)
    let table = mote_io::csv::read_table(&a.file).map_err(|e| anyhow::anyhow!("{e}"))?;
    let units = read_units(&a.file)?;
    let unit_of = |name: &str| -> Option<String> {
        let k = table.columns.iter().position(|c| c == name)?;
        units.as_ref()?.get(k).cloned()
    };
    let known = || table.columns.join(", ");
    let x = table.column(&a.x).with_context(|| {
        format!(
            "{}: no column '{}' for --x; columns: {}",
            a.file.display(),
            a.x,
            known()
        )
    })?;
    let ys: Vec<String> = if a.y.is_empty() {
        table
            .columns
            .iter()
            .filter(|c| **c != a.x)
            .cloned()
            .collect()
    } else {
        a.y.clone()
    };
    if ys.is_empty() {
        bail!("{}: no column to plot besides '{}'", a.file.display(), a.x);
    }
    let mut series = Vec::new();
    for name in &ys {
        let y = table.column(name).with_context(|| {
            format!(
                "{}: no column '{name}' for --y; columns: {}",
                a.file.display(),
                known()
            )
        })?;
        series.push(Series {
            name: axis_label(name, unit_of(name).as_deref()),
            x: x.clone(),
            y,
        });
    }
    // The vertical axis is labelled by the series when there is one, or by their
    // common unit when there are several.
    let y_label = if ys.len() == 1 {
        axis_label(&ys[0], unit_of(&ys[0]).as_deref())
    } else {
        let us: Vec<Option<String>> = ys.iter().map(|n| unit_of(n)).collect();
        match us.first().cloned().flatten() {
            Some(u) if us.iter().all(|v| v.as_deref() == Some(u.as_str())) => {
                format!("value [{u}]")
            }
            _ => "value".to_string(),
        }
    };
    let plot = Plot {
        title: Some(
            a.title
                .clone()
                .unwrap_or_else(|| a.file.display().to_string()),
        ),
        x_label: axis_label(&a.x, unit_of(&a.x).as_deref()),
        y_label,
        series,
        log_x: a.logx,
        log_y: a.logy,
        width,
        height,
    };
    plot.write(&a.output)?;
    if !global.quiet {
        tell!(
            "{} series, {} points -> {}",
            ys.len(),
            x.len(),
            a.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// The units from a `# units: u1,u2,...` header line, one per column, if present.
fn read_units(path: &Path) -> anyhow::Result<Option<Vec<String>>> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    for line in text.lines() {
        let l = line.trim();
        if !l.starts_with('#') {
            break;
        }
        if let Some(u) = l.trim_start_matches('#').trim().strip_prefix("units:") {
            return Ok(Some(u.split(',').map(|s| s.trim().to_string()).collect()));
        }
    }
    Ok(None)
}

fn parse_size(s: &str) -> anyhow::Result<(u32, u32)> {
    let bad = || anyhow::anyhow!("--size: '{s}' is not WIDTHxHEIGHT such as 1000x600");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(100..=8192).contains(&w) || !(100..=8192).contains(&h) {
        bail!("--size: {w}x{h} is outside 100x100 .. 8192x8192");
    }
    Ok((w, h))
}
