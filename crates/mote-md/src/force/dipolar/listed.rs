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
use mote_geom::simd::Isa;
use rayon::prelude::*;

use super::{DipoleDipole, Kernel};
use crate::boundary::Boundary;
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

/// Row r of `list` by the kernel `isa` names.
#[inline]
fn row(
    kern: &Kernel,
    list: &GhostList,
    moment: &[Copy4],
    r: usize,
    isa: Isa,
    energy: bool,
) -> RowSum {
    let k = list.owner[r] as usize;
    match isa {
        // SAFETY: `isa` is AVX-512 only where the CPU has it; the row's
        // entries and k index the copies, which `moment` has one of each.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe {
            super::avx512::list_row(kern, k, list.row(r), &list.position, moment, energy)
        },
        Isa::Portable => row_portable(kern, k, list.row(r), &list.position, moment),
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
        step: bool,
        energy: bool,
    ) -> (f64, f64) {
        if step {
            self.list.update(pos, boundary);
        } else {
            self.list.refresh(pos, boundary);
        }
        let list = &self.list;
        list.gather(dipoles, &mut self.moment);
        let (kern, isa, moment) = (self.kernel(), self.isa, &self.moment);
        self.sorted.resize(pos.len(), (DVec3::ZERO, DVec3::ZERO));
        let [w, u] = list.sum_rows(&mut self.sorted, |r| {
            let s = row(&kern, list, moment, r, isa, energy);
            ((s.force, s.torque), [s.virial, s.energy])
        });
        (0.5 * w, 0.5 * u)
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
