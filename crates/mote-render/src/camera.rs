//! A pinhole camera, framed automatically on a scene by default.

use glam::Vec3;

use crate::bvh::Ray;

/// A perspective pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    /// Approximate up direction (made orthogonal to the view).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    pub width: u32,
    pub height: u32,
}

/// Default viewing direction (from the eye towards the scene): from the
/// +x, −y, +z octant, as in a textbook perspective drawing with z up.
pub const DEFAULT_VIEW: Vec3 = Vec3::new(-0.55, 1.0, -0.45);

impl Camera {
    /// Frames the box `lo..hi` so that its bounding sphere fits into the picture,
    /// looking along `view` with vertical field of view `fov_deg`.
    pub fn frame(lo: Vec3, hi: Vec3, view: Vec3, fov_deg: f32, width: u32, height: u32) -> Self {
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let view = if view.length_squared() > 0.0 {
            view.normalize()
        } else {
            DEFAULT_VIEW.normalize()
        };
        let aspect = width as f32 / height.max(1) as f32;
        let half_v = (fov_deg.to_radians() * 0.5).clamp(1e-3, 1.5);
        let half_h = (half_v.tan() * aspect).atan();
        let half = half_v.min(half_h);
        let dist = radius / half.sin() * 1.02;
        let up = if view.cross(Vec3::Z).length() < 1e-3 {
            Vec3::Y
        } else {
            Vec3::Z
        };
        Self {
            eye: center - view * dist,
            target: center,
            up,
            fov_deg,
            width,
            height,
        }
    }

    /// Orthonormal basis: right, true up, forward.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let f = (self.target - self.eye).normalize();
        let mut r = f.cross(self.up);
        if r.length_squared() < 1e-12 {
            r = f.any_orthonormal_vector();
        }
        let r = r.normalize();
        let u = r.cross(f);
        (r, u, f)
    }

    /// Half height of the image plane at unit distance.
    fn tan_half(&self) -> f32 {
        (self.fov_deg.to_radians() * 0.5).tan()
    }

    /// The ray through image point (x, y) in pixels (x right, y down; pixel
    /// centres at half-integers).
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let (r, u, f) = self.basis();
        self.ray_in_basis(x, y, r, u, f)
    }

    #[inline]
    pub(crate) fn ray_in_basis(&self, x: f32, y: f32, r: Vec3, u: Vec3, f: Vec3) -> Ray {
        let th = self.tan_half();
        let h = self.height as f32;
        let w = self.width as f32;
        let sx = (2.0 * x - w) / h * th;
        let sy = (h - 2.0 * y) / h * th;
        Ray::new(self.eye, f + r * sx + u * sy)
    }

    /// Projects a point to pixel coordinates; `None` if it is behind the eye.
    pub fn project(&self, p: Vec3) -> Option<(f32, f32, f32)> {
        let (r, u, f) = self.basis();
        let d = p - self.eye;
        let z = d.dot(f);
        if z <= 1e-6 {
            return None;
        }
        let th = self.tan_half();
        let h = self.height as f32;
        let w = self.width as f32;
        let sx = d.dot(r) / z / th;
        let sy = d.dot(u) / z / th;
        Some(((sx * h + w) * 0.5, (h - sy * h) * 0.5, z))
    }

    /// The same camera moved sideways by `offset` (along its right vector), still
    /// looking at the same target: one eye of a stereo pair.
    pub fn eye_shifted(&self, offset: f32) -> Self {
        let (r, _, _) = self.basis();
        Self {
            eye: self.eye + r * offset,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_inverts_the_ray() {
        let cam = Camera::frame(Vec3::ZERO, Vec3::ONE, DEFAULT_VIEW, 35.0, 320, 200);
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 10.25)] {
            let ray = cam.ray(x, y);
            let (px, py, _) = cam.project(ray.at(7.0)).unwrap();
            assert!(
                (px - x).abs() < 1e-3 && (py - y).abs() < 1e-3,
                "{x},{y} -> {px},{py}"
            );
        }
        // The centre of the picture looks at the target.
        let c = cam.ray(160.0, 100.0);
        assert!(c.dir.dot((cam.target - cam.eye).normalize()) > 0.99999);
    }
}
