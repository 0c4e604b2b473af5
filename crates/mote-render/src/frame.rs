//! A trajectory frame (`mote_io::xyz::Frame`) as a scene: one sphere per
//! particle, coloured by species or by a per-particle quantity, with its box.

use glam::Vec3;
use mote_io::xyz::Frame;

use crate::colormap::{category_color, finite_range, ColorMap};
use crate::scene::{Cell, Scene};
use crate::RenderError;

/// What colours the particles.
#[derive(Debug, Clone, PartialEq)]
pub enum ColorBy {
    /// One colour per species name (categorical palette).
    Species,
    /// A per-particle quantity through a colour map: `speed`, `radius`, `vx`,
    /// `vy`, `vz`, `x`, `y`, `z`.
    Quantity(String),
}

/// The quantities [`ColorBy::Quantity`] knows.
pub const QUANTITIES: &[&str] = &[
    "speed", "radius", "vx", "vy", "vz", "x", "y", "z", "mass", "spin", "wx", "wy", "wz", "moment",
    "mx", "my", "mz", "id", "body",
];

/// The quantities of [`QUANTITIES`] a frame has columns for (positions
/// always; velocities, radii, masses, spins, dipoles, ids, bodies where
/// the frame carries them).
pub fn quantities_of(frame: &Frame) -> Vec<&'static str> {
    let n = frame.positions.len();
    let has = |len: usize| len == n && n > 0;
    QUANTITIES
        .iter()
        .copied()
        .filter(|q| match *q {
            "x" | "y" | "z" => true,
            "speed" | "vx" | "vy" | "vz" => has(frame.velocities.len()),
            "radius" => has(frame.radii.len()),
            "mass" => has(frame.masses.len()),
            "spin" | "wx" | "wy" | "wz" => has(frame.angular_velocities.len()),
            "moment" | "mx" | "my" | "mz" => has(frame.dipoles.len()),
            "id" => has(frame.ids.len()),
            "body" => has(frame.bodies.len()),
            _ => false,
        })
        .collect()
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// `f` of each entry of a per-particle column, NaN where it is missing.
fn column<T>(values: &[T], n: usize, f: impl Fn(&T) -> f64) -> Vec<f64> {
    (0..n).map(|i| values.get(i).map_or(f64::NAN, &f)).collect()
}

/// The values of a named per-particle quantity (NaN for a particle whose
/// frame lacks the column): speed, radius, velocity and position
/// components, mass, spin |ω| and its components, dipole moment |m| and its
/// components, id, body.
pub fn quantity(frame: &Frame, name: &str) -> Result<Vec<f64>, RenderError> {
    let n = frame.positions.len();
    let vel = |i: usize| frame.velocities.get(i).copied().unwrap_or([0.0; 3]);
    let v: Vec<f64> = match name {
        "speed" => (0..n)
            .map(|i| {
                let v = vel(i);
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            })
            .collect(),
        "radius" => (0..n)
            .map(|i| frame.radii.get(i).copied().unwrap_or(f64::NAN))
            .collect(),
        "vx" | "vy" | "vz" => {
            let d = (name.as_bytes()[1] - b'x') as usize;
            (0..n).map(|i| vel(i)[d]).collect()
        }
        "x" | "y" | "z" => {
            let d = (name.as_bytes()[0] - b'x') as usize;
            frame.positions.iter().map(|p| p[d]).collect()
        }
        "mass" => column(&frame.masses, n, |m| *m),
        "spin" => column(&frame.angular_velocities, n, norm),
        "wx" | "wy" | "wz" => {
            let d = (name.as_bytes()[1] - b'x') as usize;
            column(&frame.angular_velocities, n, |w| w[d])
        }
        "moment" => column(&frame.dipoles, n, norm),
        "mx" | "my" | "mz" => {
            let d = (name.as_bytes()[1] - b'x') as usize;
            column(&frame.dipoles, n, |m| m[d])
        }
        "id" => column(&frame.ids, n, |k| *k as f64),
        "body" => column(&frame.bodies, n, |k| *k as f64),
        other => {
            return Err(RenderError::Invalid(format!(
                "unknown quantity '{other}' to colour by; known: species, {}",
                QUANTITIES.join(", ")
            )))
        }
    };
    Ok(v)
}

/// What [`scene_from_frame`] made of the colours: the quantity's range for a colour bar.
#[derive(Debug, Clone, PartialEq)]
pub struct Coloring {
    pub map: ColorMap,
    pub range: Option<(f64, f64)>,
}

/// Builds the scene of a frame. Particles without a radius (0) are drawn with
/// `default_radius`. The box is the frame's cell if it has a non-zero volume.
pub fn scene_from_frame(
    frame: &Frame,
    color_by: &ColorBy,
    map: ColorMap,
    default_radius: f64,
) -> Result<(Scene, Coloring), RenderError> {
    let mut scene = Scene::new();
    let n = frame.positions.len();
    let mut range = None;
    let colors: Vec<[f32; 3]> = match color_by {
        ColorBy::Species => {
            let mut names: Vec<&str> = Vec::new();
            (0..n)
                .map(|i| {
                    let s = frame.species.get(i).map(String::as_str).unwrap_or("X");
                    let k = names.iter().position(|&x| x == s).unwrap_or_else(|| {
                        names.push(s);
                        names.len() - 1
                    });
                    category_color(k)
                })
                .collect()
        }
        ColorBy::Quantity(name) => {
            let q = quantity(frame, name)?;
            let (lo, hi) = finite_range(&q);
            range = Some((lo, hi));
            q.iter()
                .map(|&v| map.at(((v - lo) / (hi - lo)) as f32))
                .collect()
        }
    };
    for (i, (p, color)) in frame.positions.iter().zip(&colors).enumerate() {
        let r = frame
            .radii
            .get(i)
            .copied()
            .filter(|r| *r > 0.0)
            .unwrap_or(default_radius);
        scene.add_sphere(
            Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
            r as f32,
            *color,
        );
    }
    let c = frame.cell;
    let edges = c.map(|e| Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32));
    if edges[0].cross(edges[1]).dot(edges[2]).abs() > 0.0 {
        scene.cell = Some(Cell {
            origin: Vec3::new(
                frame.origin[0] as f32,
                frame.origin[1] as f32,
                frame.origin[2] as f32,
            ),
            edges,
        });
    }
    Ok((scene, Coloring { map, range }))
}

/// A radius for point particles: a third of the mean spacing `(V/N)^(1/d)` in the
/// frame's bounding box, d the number of axes along which the particles spread.
pub fn default_radius(frame: &Frame) -> f64 {
    // The extent of the positions themselves (a bounding cell gives flat
    // axes a thickness, which is not a spread).
    let mut ext = [0.0f64; 3];
    for d in 0..3 {
        let (lo, hi) = frame
            .positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[d]), hi.max(p[d]))
            });
        ext[d] = (hi - lo).max(0.0);
    }
    let n = frame.positions.len().max(1) as f64;
    // Mean spacing in the dimensions the particles spread in (a flat or linear
    // arrangement has zero extent along some axes).
    let big = ext.iter().cloned().fold(0.0, f64::max);
    let spread: Vec<f64> = ext.iter().cloned().filter(|e| *e > 1e-9 * big).collect();
    let measure: f64 = spread.iter().product();
    let r = (measure / n).powf(1.0 / spread.len().max(1) as f64) / 3.0;
    if r.is_finite() && r > 0.0 {
        r
    } else {
        0.5
    }
}

/// One call for "a picture at the end of a run" (`mote run --picture`,
/// `mote pack --picture`): the frame coloured by species, auto-framed from the
/// default direction, shadows on, box drawn, written as PNG of `width`×`height`.
pub fn picture(
    frame: &Frame,
    path: &std::path::Path,
    width: u32,
    height: u32,
) -> Result<(), RenderError> {
    picture_image(frame, width, height)?.write_png(path)
}

/// The image [`picture`] writes.
pub fn picture_image(frame: &Frame, width: u32, height: u32) -> Result<crate::Image, RenderError> {
    let (scene, _) = scene_from_frame(
        frame,
        &ColorBy::Species,
        ColorMap::Viridis,
        default_radius(frame),
    )?;
    let (lo, hi) = scene
        .bounds()
        .ok_or_else(|| RenderError::Invalid("the frame has nothing to draw".into()))?;
    let cam = crate::Camera::frame(lo, hi, crate::camera::DEFAULT_VIEW, 30.0, width, height);
    let opts = crate::RenderOptions {
        shadows: true,
        ..crate::RenderOptions::default()
    };
    Ok(crate::Renderer::new(&scene).render(&cam, &opts))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_follow_the_columns_a_frame_has() {
        let mut f = Frame {
            positions: vec![[1.0, 2.0, 3.0], [0.0; 3]],
            angular_velocities: vec![[3.0, 4.0, 0.0], [0.0, 0.0, 1.0]],
            bodies: vec![7, 7],
            ..Frame::default()
        };
        assert_eq!(
            quantities_of(&f),
            ["x", "y", "z", "spin", "wx", "wy", "wz", "body"]
        );
        assert_eq!(quantity(&f, "spin").unwrap(), [5.0, 1.0]);
        assert_eq!(quantity(&f, "wy").unwrap(), [4.0, 0.0]);
        assert_eq!(quantity(&f, "body").unwrap(), [7.0, 7.0]);
        // A column a frame lacks gives NaN, not a panic.
        f.masses = vec![2.0];
        let m = quantity(&f, "mass").unwrap();
        assert_eq!(m[0], 2.0);
        assert!(m[1].is_nan());
        assert!(!quantities_of(&f).contains(&"mass"));
        assert!(quantity(&f, "charge").is_err());
    }
}
