//! Small math on `[f64; D]` vectors (the role nalgebra's fixed vectors play
//! in rapier's dimension-generic sources).

#[inline]
pub fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for d in 0..D {
        s += a[d] * b[d];
    }
    s
}

#[inline]
pub fn sub<const D: usize>(a: &[f64; D], b: &[f64; D]) -> [f64; D] {
    let mut r = [0.0; D];
    for d in 0..D {
        r[d] = a[d] - b[d];
    }
    r
}

/// a + s·b
#[inline]
pub fn add_scaled<const D: usize>(a: &[f64; D], b: &[f64; D], s: f64) -> [f64; D] {
    let mut r = [0.0; D];
    for d in 0..D {
        r[d] = a[d] + s * b[d];
    }
    r
}

/// Embeds a D-vector in 3-D (z = 0 for disks).
#[inline]
pub fn to3<const D: usize>(a: &[f64; D]) -> [f64; 3] {
    let mut r = [0.0; 3];
    r[..D.min(3)].copy_from_slice(&a[..D.min(3)]);
    r
}
