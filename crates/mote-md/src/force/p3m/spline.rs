//! Charge assignment: the cardinal B-spline of order p (Hockney & Eastwood,
//! *Computer Simulation Using Particles*, §5-3; Deserno & Holm 1998, J.
//! Chem. Phys. 109, 7678, Eq. 5 and Appendix E), which spreads a charge
//! over the p mesh points nearest it along each axis.
//!
//! With u the position in mesh spacings, a particle gives mesh point j the
//! weight W_p(j − u) = N_p(j − u + p/2), N_p the cardinal B-spline of
//! support [0, p] (N_1 the unit box, N_p = N_{p−1} ∗ N_1), by
//! N_p(t) = [t N_{p−1}(t) + (p − t) N_{p−1}(t − 1)]/(p − 1) (de Boor's
//! recursion). Its Fourier transform is sinc^p(k h/2), sinc x = sin x / x.
//! Order 1 is nearest grid point, 2 cloud in cell, 3 triangular-shaped
//! cloud. The weights of a particle sum to 1.

/// The highest assignment order (LAMMPS and ESPResSo go to 7 too).
pub const MAX_ORDER: usize = 7;

/// The mesh points and weights of one coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stencil {
    /// The first of the p mesh points (unwrapped: may lie outside the mesh).
    pub first: i64,
    /// The weight of mesh point `first + i`, i < p.
    pub weight: [f64; MAX_ORDER],
}

/// The stencil of order `order` at `u` mesh spacings from mesh point 0.
#[inline]
pub fn stencil(order: usize, u: f64) -> Stencil {
    debug_assert!((1..=MAX_ORDER).contains(&order));
    // The points j with |j − u| < p/2: j = first + i, first = ⌈u − p/2⌉,
    // and point first + i has N_p(f + i), f = first − (u − p/2) ∈ [0, 1).
    let s = u - 0.5 * order as f64;
    let first = s.ceil();
    let f = first - s;
    let mut w = [0.0; MAX_ORDER];
    w[0] = 1.0;
    for n in 2..=order {
        let inv = 1.0 / (n - 1) as f64;
        // Down, so that w[i − 1] is still of order n − 1 when read.
        for i in (0..n).rev() {
            let t = f + i as f64;
            let right = if i + 1 < n { w[i] } else { 0.0 };
            let left = if i >= 1 { w[i - 1] } else { 0.0 };
            w[i] = (t * right + (n as f64 - t) * left) * inv;
        }
    }
    Stencil {
        first: first as i64,
        weight: w,
    }
}

/// sinc x = sin x / x (1 at 0).
#[inline]
pub fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-8 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_match_the_low_orders() {
        for order in 1..=MAX_ORDER {
            for k in 0..97 {
                let u = -3.0 + 0.173 * k as f64;
                let s = stencil(order, u);
                let sum: f64 = s.weight[..order].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "order {order} at {u}: {sum}");
                assert!(s.weight[..order].iter().all(|w| *w >= 0.0));
                // The charge's centre is where it was: Σ w j = u.
                let centre: f64 = (0..order)
                    .map(|i| s.weight[i] * (s.first + i as i64) as f64)
                    .sum();
                if order >= 2 {
                    assert!((centre - u).abs() < 1e-12, "order {order}: {centre} vs {u}");
                }
            }
        }
        // Nearest grid point, cloud in cell, triangular-shaped cloud.
        assert_eq!(stencil(1, 2.4).first, 2);
        assert_eq!(stencil(1, 2.6).first, 3);
        let cic = stencil(2, 2.25);
        assert_eq!((cic.first, cic.weight[0], cic.weight[1]), (2, 0.75, 0.25));
        let tsc = stencil(3, 5.1);
        let d: f64 = 0.1;
        assert_eq!(tsc.first, 4);
        let expect = [
            0.5 * (0.5 - d).powi(2),
            0.75 - d * d,
            0.5 * (0.5 + d).powi(2),
        ];
        for (w, e) in tsc.weight.iter().zip(expect) {
            assert!((w - e).abs() < 1e-15, "{w} vs {e}");
        }
    }

    /// The discrete transform of the weights of a charge at mesh point 0
    /// sampled on a fine grid approaches sinc^p: the Fourier transform of
    /// N_p is that of p unit boxes convolved.
    #[test]
    fn fourier_transform_is_sinc_to_the_p() {
        let order = 4;
        // W_p(x) as a function of x = j − u, sampled finely.
        let n = 4000;
        let dx = order as f64 / n as f64;
        let k = 1.3;
        let mut ft = 0.0;
        for m in 0..n {
            let x = -0.5 * order as f64 + (m as f64 + 0.5) * dx;
            // The weight at distance x: the stencil of u = −x, point 0.
            let s = stencil(order, -x);
            let w = s.weight[(-s.first) as usize];
            ft += w * (k * x).cos() * dx;
        }
        assert!((ft - sinc(0.5 * k).powi(order as i32)).abs() < 1e-6);
    }
}
