//! The cut-off dipole–dipole loop (with its fused LJ/WCA repulsion) over a
//! [`GhostList`]: a full list over cell-sorted copies with periodic images
//! as ghosts, so each row sums the force and the torque on its own particle
//! from plain coordinate differences (no minimum image, no writes to
//! neighbours, no reductions between threads) and every thread count gives
//! the same bits. Rows go eight neighbours at a time in AVX-512 where the
//! CPU has it (`avx512::list_row`); [`row_portable`], one neighbour at a
//! time through [`Kernel::pair`], is the reference they are tested against.
//!
//! Each pair is evaluated from both ends, where a half list with Newton's
//! third law would evaluate it once: the price of independent rows. The
//! row kernel needs only the force and the torque on i (τ_i = m_i × B_j),
//! not τ_j.

use glam::DVec3;
use mote_geom::lanes::{self, Lanes};
use mote_geom::simd::Isa;
use rayon::prelude::*;

use super::portable::pair_lanes;
use super::{DipoleDipole, Kernel};
use crate::boundary::Boundary;
use crate::domain::Halo;
use crate::neighbor::{Copy4, GhostList};

/// What a row adds up: force and torque on its particle, Σ r·F and Σ U
/// over its neighbours (each pair is in two rows, so these count twice).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct RowSum {
    pub force: DVec3,
    pub torque: DVec3,
    pub virial: f64,
    pub energy: f64,
}

/// One row, one neighbour at a time: the pairs within reach of copy `k`
/// through [`Kernel::pair`].
pub(super) fn row_portable(
    kern: &Kernel,
    k: usize,
    row: &[u32],
    position: &[Copy4],
    moment: &[Copy4],
) -> RowSum {
    let xyz = |c: &Copy4| DVec3::new(c.0[0], c.0[1], c.0[2]);
    let (ri, mi) = (xyz(&position[k]), xyz(&moment[k]));
    let reach2 = kern.reach2();
    let mut s = RowSum::default();
    for &j in row {
        let j = j as usize;
        let d = ri - xyz(&position[j]);
        let r2 = d.length_squared();
        if r2 < reach2 {
            let (u, f, ti, _, w) = kern.pair(d, r2, mi, xyz(&moment[j]));
            s.force += f;
            s.torque += ti;
            s.virial += w;
            s.energy += u;
        }
    }
    s
}

/// One row's force and torque, eight neighbours at a time on [`Lanes`]
/// ([`pair_lanes`]; no energy, and the virial only with `VIRIAL`: the
/// stepping pass leaves it out). Lanes past the row's end hold the row's
/// own copy, at no distance, which the pair law leaves out; a neighbour at
/// no distance gives a force that is not a number, as on the reference, so
/// that two particles on one spot stop the run.
pub(super) fn row_lanes<const VIRIAL: bool>(
    kern: &Kernel,
    k: usize,
    row: &[u32],
    position: &[Copy4],
    moment: &[Copy4],
) -> RowSum {
    let (positions, moments) = (Copy4::records(position), Copy4::records(moment));
    let [xi, yi, zi, _] = position[k].0;
    let [ax, ay, az, _] = moment[k].0;
    let zero = Lanes::splat(0.0);
    let (mut force, mut torque, mut virial) = ([zero; 3], [zero; 3], zero);
    let mut coincident = 0u8;
    lanes::in_eights(row, k as u32, |index, pad| {
        let [xj, yj, zj] = lanes::gather_xyz(positions, index);
        let d = [
            Lanes::splat(xi) - xj,
            Lanes::splat(yi) - yj,
            Lanes::splat(zi) - zj,
        ];
        let p = pair_lanes(kern, d, [ax, ay, az], lanes::gather_xyz(moments, index));
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + pad;
        coincident |= r2.bits_below(f64::MIN_POSITIVE);
        for c in 0..3 {
            force[c] = force[c] + p.force[c];
            torque[c] = torque[c] + p.torque_i[c];
        }
        if VIRIAL {
            virial = virial + p.virial;
        }
    });
    let sum = |v: [Lanes; 3]| DVec3::new(v[0].sum(), v[1].sum(), v[2].sum());
    RowSum {
        force: if coincident == 0 {
            sum(force)
        } else {
            DVec3::NAN
        },
        torque: sum(torque),
        virial: virial.sum(),
        energy: 0.0,
    }
}

/// Row r of `list` by the kernel `isa` names (`reference`: one neighbour
/// at a time).
#[inline]
fn row(
    kern: &Kernel,
    list: &GhostList,
    moment: &[Copy4],
    r: usize,
    (isa, reference): (Isa, bool),
    energy: bool,
) -> RowSum {
    let k = list.owner[r] as usize;
    match isa {
        _ if reference => row_portable(kern, k, list.row(r), &list.position, moment),
        // SAFETY: `isa` is AVX-512 only where the CPU has it; the row's
        // entries and k index the copies, which `moment` has one of each.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe {
            super::avx512::list_row(kern, k, list.row(r), &list.position, moment, energy)
        },
        Isa::Portable if energy => row_portable(kern, k, list.row(r), &list.position, moment),
        Isa::Portable => row_lanes::<false>(kern, k, list.row(r), &list.position, moment),
    }
}

impl DipoleDipole {
    /// Brings the ghost list to `pos` in `boundary` (a step when `step`,
    /// else a refresh), takes the moments onto the copies and runs every
    /// row: force and torque per row in row order into the sorted
    /// buffers; returns the halved sums (virial, energy).
    pub(super) fn cut_off_rows(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        boundary: &Boundary,
        halo: Option<&Halo>,
        step: bool,
        energy: bool,
    ) -> (f64, f64) {
        self.follow(pos, dipoles, boundary, halo, step);
        let list = &self.list;
        let (kern, moment) = (self.kernel(), &self.moment);
        let isa = (self.isa, self.reference_rows);
        self.sorted.resize(pos.len(), (DVec3::ZERO, DVec3::ZERO));
        let [w, u] = list.sum_rows(&mut self.sorted, |r| {
            let s = row(&kern, list, moment, r, isa, energy);
            ((s.force, s.torque), [s.virial, s.energy])
        });
        (0.5 * w, 0.5 * u)
    }

    /// Brings the ghost list to `pos` (a step when `step`, else a
    /// refresh; over the halo in a decomposed run) and takes the moments
    /// onto its copies.
    pub(super) fn follow(
        &mut self,
        pos: &[DVec3],
        dipoles: &[DVec3],
        boundary: &Boundary,
        halo: Option<&Halo>,
        step: bool,
    ) {
        match halo {
            Some(h) => {
                self.list.follow_halo(h, boundary);
                self.list.gather_halo(dipoles, &h.moment, &mut self.moment);
            }
            None => {
                if step {
                    self.list.update(pos, boundary);
                } else {
                    self.list.refresh(pos, boundary);
                }
                self.list.gather(dipoles, &mut self.moment);
            }
        }
    }

    /// Adds the rows' forces and torques to the particles'.
    pub(super) fn add_sorted(&self, force: &mut [DVec3], torque: &mut [DVec3]) {
        let (sorted, slot) = (&self.sorted, &self.list.slot);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .with_min_len(4096)
            .enumerate()
            .for_each(|(i, (f, t))| {
                let (fi, ti) = sorted[slot[i] as usize];
                *f += fi;
                *t += ti;
            });
    }
}
