//! The simulation box: open, or an orthorhombic box periodic per axis.

use glam::DVec3;

/// An orthorhombic box [lo, hi) with periodic boundaries on the flagged
/// axes; an axis that is not periodic is open (particles may leave the box).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Boundary {
    pub lo: DVec3,
    pub hi: DVec3,
    pub periodic: [bool; 3],
}

impl Default for Boundary {
    fn default() -> Self {
        Self::open()
    }
}

impl Boundary {
    /// No box: open in every direction.
    pub fn open() -> Self {
        Self {
            lo: DVec3::splat(f64::NEG_INFINITY),
            hi: DVec3::splat(f64::INFINITY),
            periodic: [false; 3],
        }
    }

    /// A box periodic on every axis.
    pub fn periodic(lo: DVec3, hi: DVec3) -> Self {
        Self {
            lo,
            hi,
            periodic: [true; 3],
        }
    }

    pub fn is_periodic(&self) -> bool {
        self.periodic.iter().any(|p| *p)
    }

    /// Edge lengths (infinite on open axes of an open box).
    pub fn lengths(&self) -> DVec3 {
        self.hi - self.lo
    }

    pub fn volume(&self) -> f64 {
        let l = self.lengths();
        l.x * l.y * l.z
    }

    /// The minimum image of a separation vector d (periodic axes only).
    #[inline(always)]
    pub fn minimum_image(&self, mut d: DVec3) -> DVec3 {
        let l = self.lengths();
        for k in 0..3 {
            if self.periodic[k] {
                d[k] -= l[k] * (d[k] / l[k]).round();
            }
        }
        d
    }

    /// Maps a position back into [lo, hi) on periodic axes.
    #[inline]
    pub fn wrap(&self, mut r: DVec3) -> DVec3 {
        let l = self.lengths();
        for k in 0..3 {
            if self.periodic[k] {
                r[k] -= l[k] * ((r[k] - self.lo[k]) / l[k]).floor();
                if r[k] >= self.hi[k] {
                    r[k] = self.lo[k];
                }
            }
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_image_and_wrap() {
        let b = Boundary::periodic(DVec3::ZERO, DVec3::new(10.0, 5.0, 2.0));
        let d = b.minimum_image(DVec3::new(9.0, -3.0, 0.5));
        assert_eq!(d, DVec3::new(-1.0, 2.0, 0.5));
        let r = b.wrap(DVec3::new(-0.5, 12.0, 2.0));
        assert!((r - DVec3::new(9.5, 2.0, 0.0)).length() < 1e-12);
        let open = Boundary::open();
        assert_eq!(open.minimum_image(DVec3::new(1e9, 0.0, 0.0)).x, 1e9);
    }
}
