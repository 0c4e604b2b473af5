//! Portable kernels: exact square root and division, any CPU.

use glam::DVec3;

use super::Soa;

/// Own pull on i of the pairs (i, j), j in j_start..j_end, returned; the
/// reactions −m_i d/r³ are added to r·[j − base].
#[allow(clippy::too_many_arguments)]
pub(super) fn pairs(
    i: usize,
    j_start: usize,
    j_end: usize,
    p: Soa,
    eps2: f64,
    base: usize,
    rx: &mut [f64],
    ry: &mut [f64],
    rz: &mut [f64],
) -> DVec3 {
    let (xi, yi, zi, mi) = (p.x[i], p.y[i], p.z[i], p.m[i]);
    let mut a = DVec3::ZERO;
    for j in j_start..j_end {
        let (dx, dy, dz) = (p.x[j] - xi, p.y[j] - yi, p.z[j] - zi);
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        if r2 > 0.0 {
            let s = 1.0 / (r2 * r2.sqrt());
            let sj = s * p.m[j];
            a += DVec3::new(sj * dx, sj * dy, sj * dz);
            let si = s * mi;
            let k = j - base;
            rx[k] -= si * dx;
            ry[k] -= si * dy;
            rz[k] -= si * dz;
        }
    }
    a
}

/// Σ_{j≠i} m_j d_j / (|d_j|² + ε²)^{3/2}, d_j = r_j − r_i (every j).
pub(super) fn field_at(i: usize, p: Soa, eps2: f64) -> DVec3 {
    let (xi, yi, zi) = (p.x[i], p.y[i], p.z[i]);
    let mut a = DVec3::ZERO;
    for j in 0..p.x.len() {
        let (dx, dy, dz) = (p.x[j] - xi, p.y[j] - yi, p.z[j] - zi);
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        if r2 > 0.0 {
            let s = p.m[j] / (r2 * r2.sqrt());
            a += DVec3::new(s * dx, s * dy, s * dz);
        }
    }
    a
}

/// Σ_{j≠i} m_j / (|r_j − r_i|² + ε²)^{1/2}.
pub(super) fn potential_at(i: usize, p: Soa, eps2: f64) -> f64 {
    let mut u = 0.0;
    for j in 0..p.x.len() {
        let (dx, dy, dz) = (p.x[j] - p.x[i], p.y[j] - p.y[i], p.z[j] - p.z[i]);
        let r2 = dx * dx + dy * dy + dz * dz + eps2;
        if j != i && r2 > 0.0 {
            u += p.m[j] / r2.sqrt();
        }
    }
    u
}
