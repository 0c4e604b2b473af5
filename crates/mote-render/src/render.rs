//! The ray tracer: one primary ray per sample, exact ray–sphere hits through the
//! BVH, sphere tracing for indicator-function bodies, Lambert + Blinn–Phong
//! shading, shadow rays, ambient occlusion and the seed's cubic reflectance
//! lattice (seed 000, "A detour on graphical representation": patterns defined
//! in space, not on the surface, so that both eyes of a stereo pair see the same
//! texture on every body — what the anaglyph method needs).
//!
//! Rows are shaded in parallel (rayon); each pixel depends only on its own
//! coordinates, so the picture is bit-identical for every thread count.

use glam::Vec3;
use rayon::prelude::*;

use crate::bvh::{Bvh, Ray};
use crate::camera::Camera;
use crate::image::{anaglyph, Image};
use crate::scene::{Rgb, Scene};

/// How to shade.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Cast shadow rays towards the light.
    pub shadows: bool,
    /// Ambient-occlusion rays per sample (0: off).
    pub ao_samples: u32,
    /// Reach of ambient-occlusion rays; `None`: three times the median sphere radius.
    pub ao_radius: Option<f32>,
    /// Period of the cubic reflectance lattice (`None`: plain colours).
    pub lattice: Option<f32>,
    /// Direction towards the light in camera coordinates (right, up, backwards).
    pub light: Vec3,
    pub background: Rgb,
    /// Draw the box edges (if the scene has a box).
    pub draw_box: bool,
    pub box_color: Rgb,
    /// Samples per pixel along each axis (1: one ray through the pixel centre).
    pub samples: u32,
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            shadows: false,
            ao_samples: 0,
            ao_radius: None,
            lattice: None,
            light: Vec3::new(-0.5, 1.0, 0.8),
            background: [1.0, 1.0, 1.0],
            draw_box: true,
            box_color: [0.15, 0.15, 0.15],
            samples: 1,
            ambient: 0.25,
            diffuse: 0.75,
            specular: 0.35,
            shininess: 40.0,
        }
    }
}

/// A scene prepared for rendering (its BVH built once, for several views).
pub struct Renderer<'a> {
    scene: &'a Scene,
    bvh: Bvh,
    /// Length scale for ray offsets.
    eps: f32,
    median_radius: f32,
}

/// A surface point found by a primary or secondary ray.
struct SurfaceHit {
    t: f32,
    point: Vec3,
    normal: Vec3,
    color: Rgb,
}

impl<'a> Renderer<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        let bvh = Bvh::build(&scene.spheres);
        // Ray offsets must exceed the rounding of f32 coordinates, which grows
        // with their magnitude as well as with the scene's size.
        let size = scene
            .bounds()
            .map(|(lo, hi)| (hi - lo).length().max(lo.abs().max(hi.abs()).max_element()))
            .filter(|s| s.is_finite() && *s > 0.0)
            .unwrap_or(1.0);
        let mut radii: Vec<f32> = scene
            .spheres
            .iter()
            .map(|s| s.radius)
            .filter(|r| r.is_finite() && *r > 0.0)
            .collect();
        let median_radius = if radii.is_empty() {
            size * 0.02
        } else {
            let k = radii.len() / 2;
            *radii.select_nth_unstable_by(k, |a, b| a.total_cmp(b)).1
        };
        Self {
            scene,
            bvh,
            eps: size * 4e-6,
            median_radius,
        }
    }

    fn hit(&self, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut t_best = t_max;
        if let Some(h) = self.bvh.closest(ray, self.eps, t_best) {
            let s = self.scene.spheres[h.index];
            let point = ray.at(h.t);
            t_best = h.t;
            best = Some(SurfaceHit {
                t: h.t,
                point,
                normal: (point - s.center) / s.radius,
                color: self.scene.colors[h.index],
            });
        }
        for body in &self.scene.sdf_bodies {
            if let Some(t) = body.shape.trace(ray, self.eps, t_best, self.eps) {
                let point = ray.at(t);
                let (_, g) = body.shape.eval_grad(point);
                t_best = t;
                best = Some(SurfaceHit {
                    t,
                    point,
                    normal: g.normalize_or_zero(),
                    color: body.color,
                });
            }
        }
        best
    }

    fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.bvh.occluded(ray, self.eps, t_max)
            || self
                .scene
                .sdf_bodies
                .iter()
                .any(|b| b.shape.trace(ray, self.eps, t_max, self.eps).is_some())
    }

    /// The colour seen along a primary ray, and the distance to the surface.
    fn shade(&self, ray: &Ray, light: Vec3, opts: &RenderOptions, seed: u32) -> (Rgb, f32) {
        let Some(h) = self.hit(ray, f32::INFINITY) else {
            return (opts.background, f32::INFINITY);
        };
        let mut n = h.normal;
        if n.dot(ray.dir) > 0.0 {
            n = -n;
        }
        let p = h.point + n * (self.eps * 4.0);
        let mut albedo = h.color;
        if let Some(a) = opts.lattice {
            // Cubic reflectance lattice: cells of side a alternate between full
            // and 60 % reflectance, a 3-D checkerboard fixed in space.
            let c = (h.point / a).floor();
            if (c.x as i64 + c.y as i64 + c.z as i64).rem_euclid(2) == 1 {
                albedo = albedo.map(|v| v * 0.6);
            }
        }
        let ndl = n.dot(light);
        let lit = if ndl > 0.0 && opts.shadows {
            !self.occluded(
                &Ray {
                    origin: p,
                    dir: light,
                },
                f32::INFINITY,
            )
        } else {
            ndl > 0.0
        };
        let mut ambient = opts.ambient;
        if opts.ao_samples > 0 {
            let reach = opts.ao_radius.unwrap_or(3.0 * self.median_radius);
            let mut open = 0u32;
            let (tx, ty) = orthonormal(n);
            for k in 0..opts.ao_samples {
                let u1 = hash01(seed, 2 * k);
                let u2 = hash01(seed, 2 * k + 1);
                // Cosine-weighted direction in the hemisphere around n.
                let r = u1.sqrt();
                let phi = std::f32::consts::TAU * u2;
                let d = tx * (r * phi.cos()) + ty * (r * phi.sin()) + n * (1.0 - u1).sqrt();
                if !self.occluded(&Ray { origin: p, dir: d }, reach) {
                    open += 1;
                }
            }
            ambient *= open as f32 / opts.ao_samples as f32;
        }
        let mut c = albedo.map(|a| a * ambient);
        if lit {
            let half = (light - ray.dir).normalize_or_zero();
            let spec = opts.specular * n.dot(half).max(0.0).powf(opts.shininess);
            for k in 0..3 {
                c[k] += albedo[k] * opts.diffuse * ndl + spec;
            }
        }
        (c, h.t)
    }

    /// Renders one view.
    pub fn render(&self, camera: &Camera, opts: &RenderOptions) -> Image {
        let (w, h) = (camera.width, camera.height);
        let mut img = Image::new(w, h);
        let (r, u, f) = camera.basis();
        let light = (r * opts.light.x + u * opts.light.y - f * opts.light.z).normalize();
        let ns = opts.samples.max(1);
        let rows: Vec<(Vec<u8>, Vec<f32>)> = (0..h)
            .into_par_iter()
            .map(|y| {
                let mut rgb = Vec::with_capacity(3 * w as usize);
                let mut depth = Vec::with_capacity(w as usize);
                for x in 0..w {
                    let mut acc = [0.0f32; 3];
                    let mut d = f32::INFINITY;
                    for sy in 0..ns {
                        for sx in 0..ns {
                            let px = x as f32 + (sx as f32 + 0.5) / ns as f32;
                            let py = y as f32 + (sy as f32 + 0.5) / ns as f32;
                            let ray = camera.ray_in_basis(px, py, r, u, f);
                            let seed = (y.wrapping_mul(w).wrapping_add(x))
                                .wrapping_mul(ns * ns)
                                .wrapping_add(sy * ns + sx);
                            let (c, t) = self.shade(&ray, light, opts, seed);
                            for k in 0..3 {
                                acc[k] += c[k];
                            }
                            // Depth along the central ray direction's distance.
                            d = d.min(t);
                        }
                    }
                    let inv = 1.0 / (ns * ns) as f32;
                    for a in acc {
                        rgb.push(to_u8(a * inv));
                    }
                    depth.push(d);
                }
                (rgb, depth)
            })
            .collect();
        for (y, (rgb, depth)) in rows.into_iter().enumerate() {
            let k = y * w as usize;
            img.rgb[3 * k..3 * (k + w as usize)].copy_from_slice(&rgb);
            img.depth[k..k + w as usize].copy_from_slice(&depth);
        }
        if opts.draw_box {
            if let Some(cell) = &self.scene.cell {
                let width = (h as f32 / 540.0).max(1.0);
                for (a, b) in cell.segments() {
                    draw_segment(&mut img, camera, a, b, opts.box_color, width);
                }
            }
        }
        img
    }

    /// A red–cyan anaglyph: two views from eyes `separation` apart (default: 1/30
    /// of the distance to the target), combined by [`anaglyph`].
    pub fn render_anaglyph(
        &self,
        camera: &Camera,
        opts: &RenderOptions,
        separation: Option<f32>,
    ) -> Image {
        let sep = separation.unwrap_or((camera.target - camera.eye).length() / 30.0);
        let left = self.render(&camera.eye_shifted(-0.5 * sep), opts);
        let right = self.render(&camera.eye_shifted(0.5 * sep), opts);
        anaglyph(&left, &right)
    }
}

/// Renders a scene from one camera (builds the BVH, then shades).
pub fn render(scene: &Scene, camera: &Camera, opts: &RenderOptions) -> Image {
    Renderer::new(scene).render(camera, opts)
}

fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn orthonormal(n: Vec3) -> (Vec3, Vec3) {
    let t = n.any_orthonormal_vector();
    (t, n.cross(t))
}

/// A deterministic pseudo-random number in [0, 1) from a pixel seed and a counter
/// (a 32-bit integer hash; no state shared between pixels).
fn hash01(seed: u32, k: u32) -> f32 {
    let mut x = seed.wrapping_mul(0x9E37_79B9) ^ k.wrapping_mul(0x85EB_CA6B);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Draws a 3-D segment of the given pixel width, hidden where a surface in the
/// depth buffer is nearer than the segment.
fn draw_segment(img: &mut Image, cam: &Camera, a: Vec3, b: Vec3, color: Rgb, width: f32) {
    // Clip against a near plane in front of the eye.
    let (_, _, f) = cam.basis();
    let near = 1e-3 * (cam.target - cam.eye).length();
    let za = (a - cam.eye).dot(f);
    let zb = (b - cam.eye).dot(f);
    if za < near && zb < near {
        return;
    }
    let (a, b) = if za < near {
        (a + (b - a) * ((near - za) / (zb - za)), b)
    } else if zb < near {
        (a, b + (a - b) * ((near - zb) / (za - zb)))
    } else {
        (a, b)
    };
    let (Some(pa), Some(pb)) = (cam.project(a), cam.project(b)) else {
        return;
    };
    let len = ((pb.0 - pa.0).powi(2) + (pb.1 - pa.1).powi(2)).sqrt();
    let steps = (len * 2.0).ceil().max(1.0) as usize;
    let c = color.map(to_u8);
    let half = (width * 0.5).max(0.5);
    let (w, h) = (img.width as i64, img.height as i64);
    for k in 0..=steps {
        let s = k as f32 / steps as f32;
        // Perspective-correct point on the segment for this screen position.
        let inv_z = (1.0 - s) / pa.2 + s / pb.2;
        let s3 = (s / pb.2) / inv_z;
        let p = a + (b - a) * s3;
        let dist = (p - cam.eye).length();
        let x = pa.0 + (pb.0 - pa.0) * s;
        let y = pa.1 + (pb.1 - pa.1) * s;
        let x0 = (x - half).round() as i64;
        let y0 = (y - half).round() as i64;
        let span = (2.0 * half).round().max(1.0) as i64;
        for yy in y0..y0 + span {
            for xx in x0..x0 + span {
                if xx < 0 || yy < 0 || xx >= w || yy >= h {
                    continue;
                }
                let idx = (yy * w + xx) as usize;
                if img.depth[idx] >= dist * (1.0 - 1e-4) {
                    img.set_pixel(xx as u32, yy as u32, c);
                }
            }
        }
    }
}
