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

    /// The fast minimum image for separations of wrapped positions.
    pub fn image(&self) -> MinimumImage {
        MinimumImage::new(self)
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

/// Minimum image for separations of wrapped positions (|d| < L on periodic
/// axes): one compare-and-shift per axis instead of a rounding; open axes get
/// an infinite half-length and are left alone.
pub struct MinimumImage {
    length: DVec3,
    half: DVec3,
}

impl MinimumImage {
    pub fn new(b: &Boundary) -> Self {
        let l = b.lengths();
        let mut length = DVec3::ZERO;
        let mut half = DVec3::INFINITY;
        for k in 0..3 {
            if b.periodic[k] {
                length[k] = l[k];
                half[k] = 0.5 * l[k];
            }
        }
        Self { length, half }
    }

    #[inline(always)]
    pub fn apply(&self, d: DVec3) -> DVec3 {
        let up = DVec3::select(d.cmplt(-self.half), self.length, DVec3::ZERO);
        let down = DVec3::select(d.cmpgt(self.half), self.length, DVec3::ZERO);
        d + up - down
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
        let fast = b.image();
        for d in [
            DVec3::new(9.0, -3.0, 0.5),
            DVec3::new(-9.9, 4.9, -1.5),
            DVec3::new(0.1, 2.6, 1.01),
        ] {
            assert_eq!(fast.apply(d), b.minimum_image(d), "{d}");
        }
        let open = Boundary::open();
        assert_eq!(open.minimum_image(DVec3::new(1e9, 0.0, 0.0)).x, 1e9);
    }
}
