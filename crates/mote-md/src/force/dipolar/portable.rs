//! The dipole pair law (004 Eq. 8) with its fused LJ repulsion on eight
//! pairs at a time ([`Lanes`]): the portable kernel of the all-pairs tiles,
//! which the build's target vectorises, 1/r by [`Lane::rsqrt`]. Masks are selects: a pair beyond
//! the dipolar cut-off adds no dipolar term, one beyond the repulsion's
//! none of it, and an empty lane (zero separation, zero moment) nothing at
//! all. The cut-off rows use it too (`listed::row_lanes`), their
//! neighbours gathered by `lanes::gather_xyz`.

use mote_geom::lanes::{Lane, Lanes};

use super::Kernel;

/// What eight pairs (i, j) give, lane by lane: the force on i, the torques
/// on i and on j, and the virial r·F.
pub(super) struct PairLanes {
    pub force: [Lanes; 3],
    pub torque_i: [Lanes; 3],
    pub torque_j: [Lanes; 3],
    pub virial: Lanes,
}

/// The pairs of moment `a` (particle i) with moments `b` at separations
/// `d` = r_i − r_j.
#[inline(always)]
pub(super) fn pair_lanes(kern: &Kernel, d: [Lanes; 3], a: [f64; 3], b: [Lanes; 3]) -> PairLanes {
    let [dx, dy, dz] = d;
    let [ax, ay, az] = a;
    let [bx, by, bz] = b;
    let r2 = dx * dx + dy * dy + dz * dz;
    // 1/r by multiplications alone (`Lane::rsqrt`: no square root or
    // division, the slowest instructions of AVX2), 0 for an empty lane.
    let inv_r = r2.rsqrt().where_positive(r2);
    let inv_r2 = inv_r * inv_r;
    // k where the dipolar part reaches (r² < r_c²), else 0.
    let k = r2.select_within(kern.rc2, kern.k, 0.0);
    let inv_r3 = k * inv_r2 * inv_r;
    let inv_r5 = inv_r3 * inv_r2;
    let a_r = dx * ax + dy * ay + dz * az;
    let b_r = bx * dx + by * dy + bz * dz;
    let ab = bx * ax + by * ay + bz * az;
    let c = inv_r5 * 3.0;
    let radial = c * ab - c * a_r * b_r * inv_r2 * 5.0;
    // The repulsion where r² < r_c,LJ² (0 when there is none).
    let lj_on = r2.select_within(kern.lj_rc2, 1.0, 0.0);
    let s2 = inv_r2 * kern.lj_s2;
    let s6 = s2 * s2 * s2;
    let lj = lj_on * s6 * (s6 * 2.0 - Lanes::splat(1.0)) * inv_r2 * (6.0 * kern.lj4e);
    let along = radial + lj;
    let gx = dx * along + c * (b_r * ax + bx * a_r);
    let gy = dy * along + c * (b_r * ay + by * a_r);
    let gz = dz * along + c * (b_r * az + bz * a_r);
    // τ_i = m_i × d (3 (m_j·d)/r⁵) − m_i × m_j (1/r³ − rf),
    // τ_j = m_j × d (3 (m_i·d)/r⁵) + m_i × m_j (1/r³ − rf), rf the reaction
    // field's coefficient where the dipolar part reaches.
    let (cx, cy, cz) = (bz * ay - by * az, bx * az - bz * ax, by * ax - bx * ay);
    let rf = r2.select_within(kern.rc2, kern.rf, 0.0);
    let twist = inv_r3 - rf;
    let (ci, cj) = (c * b_r, c * a_r);
    PairLanes {
        force: [gx, gy, gz],
        torque_i: [
            (dz * ay - dy * az) * ci - cx * twist,
            (dx * az - dz * ax) * ci - cy * twist,
            (dy * ax - dx * ay) * ci - cz * twist,
        ],
        torque_j: [
            (by * dz - bz * dy) * cj + cx * twist,
            (bz * dx - bx * dz) * cj + cy * twist,
            (bx * dy - by * dx) * cj + cz * twist,
        ],
        virial: gx * dx + gy * dy + gz * dz,
    }
}
