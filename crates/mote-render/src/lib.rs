//! Pictures of particles: a ray tracer for spheres, rigid sphere clumps and
//! bodies given by metrical indicator (signed-distance) functions, after the
//! "detour on graphical representation" of seed 000 (U. Mutze); line plots of
//! observables (MPPphys's particle inspector, seed 002 §3.2); and a POV-Ray scene
//! writer for side-by-side comparisons.
//!
//! - [`bvh`]: exact ray–sphere hits through a bounding-volume hierarchy.
//! - [`sdf`]: indicator functions, union = min, intersection = max, sphere tracing.
//! - [`scene`], [`camera`], [`render`]: what is drawn, from where, and how.
//! - [`colormap`], [`overlay`]: colouring by a per-particle quantity, colour bar.
//! - [`frame`]: a trajectory frame of `mote-io` as a scene.
//! - [`pov`]: the same scene for POV-Ray.
//! - [`plot`]: line plots to PNG or SVG with a bundled font.

pub mod bvh;
pub mod camera;
pub mod colormap;
pub mod frame;
pub mod image;
pub mod overlay;
pub mod plot;
pub mod pov;
pub mod render;
pub mod scene;
pub mod sdf;

pub use bvh::{Bvh, Ray, Sphere};
pub use camera::Camera;
pub use colormap::ColorMap;
/// The vector type of scenes and cameras (glam's, re-exported so users need not depend on glam).
pub use glam::Vec3;
pub use image::Image;
pub use render::{render, RenderOptions, Renderer};
pub use scene::{Cell, Rgb, Scene, SdfBody};
pub use sdf::Sdf;

use std::path::{Path, PathBuf};

/// Errors of the renderer and the plotter.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{0}: PNG: {1}")]
    Png(String, String),
    #[error("{0}")]
    Plot(String),
    /// A request that cannot be drawn (unknown quantity, empty data, ...).
    #[error("{0}")]
    Invalid(String),
}

impl RenderError {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        RenderError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// The bundled font (DejaVu Sans; licence in assets/DejaVuSans-LICENSE.txt).
pub(crate) const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the bundled font with plotters under the family name `sans-serif` (once).
pub(crate) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ =
            plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT);
    });
}
