//! `mote render`: pictures of a trajectory by ray tracing (crate `mote-render`;
//! seed 000, "A detour on graphical representation").

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use mote_render::Vec3;

use mote_io::xyz::Frame;
use mote_render::frame::{default_radius, scene_from_frame, ColorBy, QUANTITIES};
use mote_render::{Camera, ColorMap, RenderOptions, Renderer};

/// Ray-traced pictures of a trajectory (extended XYZ, LAMMPS dump, VTU or PVD).
#[derive(clap::Args, Debug)]
#[command(
    allow_negative_numbers = true,
    after_help = "Examples:\n  mote render traj.xyz -o last.png\n  mote render traj.xyz --all -o movie/frame.png --color-by speed --shadows\n  mote render traj.xyz --frame 0 -o first.png --anaglyph --lattice 0.2\n  mote render traj.xyz -o scene.png --pov scene.pov   (POV-Ray twin of the picture)"
)]
pub struct RenderArgs {
    /// Trajectory: .xyz (extended XYZ), .dump/.lammpstrj (LAMMPS), .vtu or .pvd.
    traj: PathBuf,
    /// Output picture (.png). With --all, frames become NAME_00000.png, NAME_00001.png, ...
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
    /// Frame to draw, counted from 0; negative counts from the end (default: the last).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "all")]
    frame: Option<i64>,
    /// Draw every frame, numbered for a movie.
    #[arg(long)]
    all: bool,
    /// Colour by `species` or a per-particle quantity.
    #[arg(long, value_name = "Q", default_value = "species", value_parser = super::choices::color_by())]
    color_by: String,
    /// Colour map for quantities.
    #[arg(long, value_name = "NAME", default_value = "viridis", value_parser = super::choices::colormap())]
    colormap: String,
    /// Fixed colour range LO,HI (default: the frame's range).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
    range: Option<String>,
    /// Leave out the colour bar.
    #[arg(long)]
    no_colorbar: bool,
    /// Picture size WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1920x1080")]
    size: String,
    /// Viewing direction DX,DY,DZ (from the eye towards the scene).
    #[arg(long, value_name = "DX,DY,DZ", allow_hyphen_values = true)]
    view: Option<String>,
    /// Vertical field of view in degrees.
    #[arg(long, value_name = "DEG", default_value_t = 30.0)]
    fov: f32,
    /// Cast shadows.
    #[arg(long)]
    shadows: bool,
    /// Ambient occlusion with N rays per pixel (e.g. 16).
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "16")]
    ao: Option<u32>,
    /// Samples per pixel along each axis (antialiasing; 2 means 4 rays per pixel).
    #[arg(long, value_name = "N", default_value_t = 1)]
    samples: u32,
    /// Red–cyan anaglyph stereo picture.
    #[arg(long)]
    anaglyph: bool,
    /// The seed's cubic reflectance lattice with this period (gives the anaglyph texture).
    #[arg(long, value_name = "A")]
    lattice: Option<f32>,
    /// Do not draw the box.
    #[arg(long)]
    no_box: bool,
    /// Add periodic images of particles that stick out of a periodic box.
    #[arg(long)]
    images: bool,
    /// Radius of particles that have none (default: a third of the mean spacing).
    #[arg(long, value_name = "R")]
    radius: Option<f64>,
    /// Also write the scene, camera and light as a POV-Ray file.
    #[arg(long, value_name = "FILE")]
    pov: Option<PathBuf>,
}

pub fn run(global: &super::GlobalOpts, a: RenderArgs) -> anyhow::Result<ExitCode> {
    let opts_view = parse_vec3(a.view.as_deref(), "--view")?;
    let (w, h) = parse_size(&a.size)?;
    let map = ColorMap::parse(&a.colormap).with_context(|| {
        format!(
            "--colormap: unknown map '{}'; known: viridis, coolwarm, heat",
            a.colormap
        )
    })?;
    let color_by = if a.color_by == "species" {
        ColorBy::Species
    } else if QUANTITIES.contains(&a.color_by.as_str()) {
        ColorBy::Quantity(a.color_by.clone())
    } else {
        bail!(
            "--color-by: unknown quantity '{}'; known: species, {}",
            a.color_by,
            QUANTITIES.join(", ")
        );
    };
    let range = a.range.as_deref().map(parse_range).transpose()?;
    let is_png = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    };
    if !is_png(&a.output) {
        bail!(
            "-o {}: pictures are written as PNG; give a name ending in .png",
            a.output.display()
        );
    }
    if a.samples == 0 || a.samples > 8 {
        bail!("--samples must be 1 to 8, not {}", a.samples);
    }
    if a.fov.is_nan() || a.fov <= 0.0 || a.fov >= 179.0 {
        bail!("--fov must be between 0 and 179 degrees, not {}", a.fov);
    }
    for p in std::iter::once(&a.output).chain(a.pov.as_ref()) {
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the folder {}", dir.display()))?;
        }
    }
    let frames = read_trajectory(&a.traj)?;
    if frames.is_empty() {
        bail!("{}: no frames", a.traj.display());
    }
    let chosen: Vec<usize> = if a.all {
        (0..frames.len()).collect()
    } else {
        let k = a.frame.unwrap_or(-1);
        let n = frames.len() as i64;
        let idx = if k < 0 { n + k } else { k };
        if idx < 0 || idx >= n {
            bail!(
                "--frame {k}: {} has {n} frames (0..{}, or -1 for the last)",
                a.traj.display(),
                n - 1
            );
        }
        vec![idx as usize]
    };
    if let ColorBy::Quantity(q) = &color_by {
        let has = mote_render::frame::quantities_of(&frames[chosen[0]]);
        if !has.contains(&q.as_str()) {
            bail!(
                "--color-by {q}: {} has no column for it; it has species, {}",
                a.traj.display(),
                has.join(", ")
            );
        }
    }
    let opts = RenderOptions {
        shadows: a.shadows,
        ao_samples: a.ao.unwrap_or(0),
        lattice: a.lattice,
        draw_box: !a.no_box,
        samples: a.samples,
        ..RenderOptions::default()
    };
    // A movie keeps one camera and one colour range for all its frames: the
    // union of the frames' bounds and of their quantity ranges.
    let mut range = range;
    let mut movie_bounds: Option<(Vec3, Vec3)> = None;
    if chosen.len() > 1 {
        let mut qlo = f64::INFINITY;
        let mut qhi = f64::NEG_INFINITY;
        for &k in &chosen {
            let frame = &frames[k];
            let radius = a.radius.unwrap_or_else(|| default_radius(frame));
            let (mut scene, coloring) = scene_from_frame(frame, &color_by, map, radius)?;
            if a.images {
                scene.add_periodic_images(frame.pbc);
            }
            if let Some((lo, hi)) = scene.bounds() {
                movie_bounds = Some(match movie_bounds {
                    Some((l, h)) => (l.min(lo), h.max(hi)),
                    None => (lo, hi),
                });
            }
            if let Some((lo, hi)) = coloring.range {
                qlo = qlo.min(lo);
                qhi = qhi.max(hi);
            }
        }
        if range.is_none() && qlo < qhi {
            range = Some((qlo, qhi));
        }
    }
    for (n, &k) in chosen.iter().enumerate() {
        let frame = &frames[k];
        let out = if a.all {
            numbered(&a.output, n)
        } else {
            a.output.clone()
        };
        let radius = a.radius.unwrap_or_else(|| default_radius(frame));
        let (mut scene, coloring) = scene_from_frame(frame, &color_by, map, radius)?;
        if let (Some((lo, hi)), ColorBy::Quantity(q)) = (range, &color_by) {
            // Recolour with the fixed range.
            let values = mote_render::frame::quantity(frame, q)?;
            for (c, v) in scene.colors.iter_mut().zip(values) {
                *c = map.at(((v - lo) / (hi - lo)) as f32);
            }
        }
        if a.images {
            scene.add_periodic_images(frame.pbc);
        }
        let Some((lo, hi)) = movie_bounds.or_else(|| scene.bounds()) else {
            bail!("{}: frame {k} has nothing to draw", a.traj.display());
        };
        let view = opts_view.unwrap_or(mote_render::camera::DEFAULT_VIEW);
        let cam = Camera::frame(lo, hi, view, a.fov, w, h);
        let renderer = Renderer::new(&scene);
        let mut img = if a.anaglyph {
            renderer.render_anaglyph(&cam, &opts, None)
        } else {
            renderer.render(&cam, &opts)
        };
        if let (false, false, ColorBy::Quantity(q)) = (a.no_colorbar, a.anaglyph, &color_by) {
            let (lo, hi) = range.or(coloring.range).unwrap_or((0.0, 1.0));
            mote_render::overlay::color_bar(&mut img, map, lo, hi, q)?;
        }
        // (RenderError's text names the file and its cause already.)
        img.write_png(&out).map_err(|e| anyhow::anyhow!("{e}"))?;
        if let Some(pov) = &a.pov {
            let pov = if a.all { numbered(pov, n) } else { pov.clone() };
            mote_render::pov::write_pov(&pov, &scene, &cam, &opts)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        if !global.quiet {
            tell!(
                "frame {k} (t = {}): {} spheres -> {}",
                frame.time,
                scene.spheres.len(),
                out.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Reads all frames of a trajectory, by file extension.
fn read_trajectory(path: &Path) -> anyhow::Result<Vec<Frame>> {
    read_any(path).map_err(|e| anyhow::anyhow!("{e}"))
}

fn read_any(path: &Path) -> anyhow::Result<Vec<Frame>> {
    Ok(mote_io::trajectory::read_frames(path)?)
}

/// `dir/name.png` → `dir/name_00042.png`.
fn numbered(path: &Path, n: usize) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("frame");
    let ext = path.extension().and_then(|s| s.to_str()).unwrap_or("png");
    path.with_file_name(format!("{stem}_{n:05}.{ext}"))
}

fn parse_size(s: &str) -> anyhow::Result<(u32, u32)> {
    let bad = || anyhow::anyhow!("--size: '{s}' is not WIDTHxHEIGHT such as 1920x1080");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        bail!("--size: {w}x{h} is outside 1x1 .. 16384x16384");
    }
    Ok((w, h))
}

fn parse_vec3(s: Option<&str>, opt: &str) -> anyhow::Result<Option<Vec3>> {
    let Some(s) = s else { return Ok(None) };
    let v: Result<Vec<f32>, _> = s.split(',').map(|x| x.trim().parse::<f32>()).collect();
    match v {
        Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) && v.iter().any(|x| *x != 0.0) => {
            Ok(Some(Vec3::new(v[0], v[1], v[2])))
        }
        _ => bail!("{opt}: '{s}' is not a non-zero direction DX,DY,DZ such as -1,1,-0.5"),
    }
}

fn parse_range(s: &str) -> anyhow::Result<(f64, f64)> {
    let bad = || anyhow::anyhow!("--range: '{s}' is not LO,HI with LO < HI");
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
    let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
    if !lo.is_finite() || !hi.is_finite() || lo >= hi {
        return Err(bad());
    }
    Ok((lo, hi))
}
