//! Three-dimensional complex FFTs of a mesh of M_x × M_y × M_z points,
//! stored x-major (z fastest), by one-dimensional transforms of rustfft.
//!
//! Each pass transforms the contiguous lines of the fastest axis, then
//! rotates the axes (x, y, z) → (z, x, y) so that the next axis is the
//! fastest; three passes bring the mesh back to its order. Lines go to the
//! threads in fixed chunks and every line is transformed alone, so the
//! result does not depend on the thread count. Unnormalised, as rustfft:
//! forward Σ_j a_j e^{−2πi jn/M}, inverse with e^{+2πi jn/M}.

use std::sync::Arc;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftDirection, FftPlanner};

/// Lines per parallel task of a pass.
const LINES: usize = 64;

/// The plans of a mesh, both directions.
#[derive(Clone)]
pub struct Fft3 {
    /// Points along x, y, z.
    pub dims: [usize; 3],
    forward: [Arc<dyn Fft<f64>>; 3],
    inverse: [Arc<dyn Fft<f64>>; 3],
    /// Where a pass rotates into.
    spare: Vec<Complex64>,
}

impl std::fmt::Debug for Fft3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fft3").field("dims", &self.dims).finish()
    }
}

impl Fft3 {
    pub fn new(dims: [usize; 3]) -> Self {
        let mut planner = FftPlanner::new();
        Self {
            dims,
            forward: dims.map(|m| planner.plan_fft_forward(m)),
            inverse: dims.map(|m| planner.plan_fft_inverse(m)),
            spare: Vec::new(),
        }
    }

    /// Number of mesh points.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Transforms `data` (x-major) in place.
    pub fn transform(&mut self, data: &mut Vec<Complex64>, direction: FftDirection) {
        assert_eq!(data.len(), self.len(), "a mesh of {:?}", self.dims);
        let plans = match direction {
            FftDirection::Forward => &self.forward,
            FftDirection::Inverse => &self.inverse,
        };
        self.spare.resize(data.len(), Complex64::default());
        // (x, y, z): z fastest; then (z, x, y); then (y, z, x).
        let [mx, my, mz] = self.dims;
        for (plan, shape) in [(2, [mx, my, mz]), (1, [mz, mx, my]), (0, [my, mz, mx])] {
            lines(plans[plan].as_ref(), data);
            rotate(data, &mut self.spare, shape);
            std::mem::swap(data, &mut self.spare);
        }
    }
}

/// Transforms every contiguous line of `plan`'s length in `data`.
fn lines(plan: &dyn Fft<f64>, data: &mut [Complex64]) {
    let len = plan.len();
    let scratch = plan.get_inplace_scratch_len();
    data.par_chunks_mut(len * LINES).for_each(|chunk| {
        let mut work = vec![Complex64::default(); scratch];
        plan.process_with_scratch(chunk, &mut work);
    });
}

/// Output planes per task of a rotation: each task reads runs of this
/// many contiguous points and writes them to as many planes.
const PLANES: usize = 8;

/// `out` (c, a, b) from `data` (a, b, c), c fastest in `data` and b in
/// `out`: out[(c A + a) B + b] = data[(a B + b) C + c]. Blocked over c,
/// so that reads run along contiguous lines rather than striding by C
/// (a power-of-two stride would fall into one cache set).
fn rotate(data: &[Complex64], out: &mut [Complex64], [na, nb, nc]: [usize; 3]) {
    let plane = na * nb;
    out.par_chunks_mut(plane * PLANES)
        .enumerate()
        .for_each(|(block, planes)| {
            let c0 = block * PLANES;
            let width = planes.len() / plane;
            for a in 0..na {
                for b in 0..nb {
                    let line = &data[(a * nb + b) * nc + c0..][..width];
                    for (dc, v) in line.iter().enumerate() {
                        planes[dc * plane + a * nb + b] = *v;
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the defining sum, on a mesh of three different sides.
    #[test]
    fn matches_the_discrete_fourier_sum() {
        let dims = [4, 6, 5];
        let n: usize = dims.iter().product();
        let data: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new((i as f64 * 0.37).sin(), (i as f64 * 0.11).cos()))
            .collect();
        let mut fft = Fft3::new(dims);
        let mut out = data.clone();
        fft.transform(&mut out, FftDirection::Forward);
        let tau = 2.0 * std::f64::consts::PI;
        for (idx, got) in out.iter().enumerate() {
            let k = [idx / 30, (idx / 5) % 6, idx % 5];
            let mut sum = Complex64::default();
            for (jdx, a) in data.iter().enumerate() {
                let j = [jdx / 30, (jdx / 5) % 6, jdx % 5];
                let phase: f64 = (0..3).map(|d| (k[d] * j[d]) as f64 / dims[d] as f64).sum();
                sum += a * Complex64::from_polar(1.0, -tau * phase);
            }
            assert!((got - sum).norm() < 1e-10, "{idx}: {got} vs {sum}");
        }
        // The inverse brings it back, times the number of points.
        fft.transform(&mut out, FftDirection::Inverse);
        for (a, b) in out.iter().zip(&data) {
            assert!((a / n as f64 - b).norm() < 1e-12);
        }
    }
}
