//! All pairs of an open system of dipoles, each pair evaluated once
//! (Newton's third law), in tiles, as [`crate::force::gravity`] does.
//!
//! Particles are cut into tiles of `tile` consecutive indices. The rayon
//! task of tile I sums, for every i in I, the force F_i, the torque τ_i and
//! the virial r·F_i of all pairs (i, j > i) — the "own" part of i — and
//! writes the reactions on each j into six arrays of its own:
//!
//! F_j = −F_i,   τ_j = m_j × B_i,   B_i = k [3 (m_i·r) r / r⁵ − m_i / r³]
//!
//! (004 Eq. 8; r = r_i − r_j and B_i even in r). Every force and torque is
//! then its own part plus the reactions of tiles 0, 1, …, I in that order,
//! so the result is bit-identical for every thread count. Within a task the
//! columns go in blocks of [`COLUMNS`] for all rows of the tile before the
//! next block, so the reactions in use stay in L1.
//!
//! Memory: tile I keeps reactions for particles from its own start to the
//! end, 48 bytes each; with at most 64 tiles that is ≤ 1.6 kB per particle,
//! so above [`TILED_MAX`] particles each row sums over all others instead
//! (every pair twice).

use glam::DVec3;
use mote_geom::simd::Isa;
use rayon::prelude::*;

use mote_geom::lanes::{Lanes, LANES};

use super::portable::pair_lanes;
use super::{DipoleDipole, Kernel, Soa};

/// Above this many particles the reaction arrays would pass ~100 MB.
pub(super) const TILED_MAX: usize = 1 << 16;
/// Columns per block of a tile's sweep: 6 reaction arrays × 8 bytes × 512
/// = 24 kB, within L1.
const COLUMNS: usize = 512;

/// Reactions on particles from a tile's start onwards: forces and torques
/// as six arrays of components.
#[derive(Debug, Clone, Default)]
pub(super) struct Reactions {
    pub fx: Vec<f64>,
    pub fy: Vec<f64>,
    pub fz: Vec<f64>,
    pub tx: Vec<f64>,
    pub ty: Vec<f64>,
    pub tz: Vec<f64>,
}

impl Reactions {
    fn reset(&mut self, len: usize) {
        for v in self.arrays() {
            v.clear();
            v.resize(len, 0.0);
        }
    }

    fn arrays(&mut self) -> [&mut Vec<f64>; 6] {
        [
            &mut self.fx,
            &mut self.fy,
            &mut self.fz,
            &mut self.tx,
            &mut self.ty,
            &mut self.tz,
        ]
    }

    fn at(&self, k: usize) -> (DVec3, DVec3) {
        (
            DVec3::new(self.fx[k], self.fy[k], self.fz[k]),
            DVec3::new(self.tx[k], self.ty[k], self.tz[k]),
        )
    }
}

/// The scratch of one tile's task.
#[derive(Debug, Clone, Default)]
pub(super) struct TileRow {
    /// Own force and torque of the tile's particles.
    own: Vec<(DVec3, DVec3)>,
    /// Σ r·F over the tile's pairs.
    virial: f64,
    reactions: Reactions,
}

/// Force, torque and virial shares of rows i, i + 1, …, i + Q − 1, row
/// i + q over partners `starts[q]..j_end` (those below `n`; `starts`
/// ascending), each pair's reaction (−F, τ_j) added to `r` at `j − base`:
/// the portable twin of the AVX-512 rows, eight partners at a time on
/// [`Lanes`]. The Q rows share each block's loads and reaction updates,
/// row by row in order (every reaction the bits of Q single rows).
#[allow(clippy::too_many_arguments)]
pub(super) fn reacting_rows_portable<const Q: usize>(
    kern: &Kernel,
    s: &Soa,
    i: usize,
    starts: [usize; Q],
    j_end: usize,
    n: usize,
    base: usize,
    r: &mut Reactions,
) -> [(DVec3, DVec3, f64); Q] {
    let a: [[f64; 3]; Q] = std::array::from_fn(|q| [s.mx[i + q], s.my[i + q], s.mz[i + q]]);
    let centre: [[f64; 3]; Q] = std::array::from_fn(|q| [s.x[i + q], s.y[i + q], s.z[i + q]]);
    let j_max = j_end.min(n);
    let zero = Lanes::splat(0.0);
    let (mut f, mut t, mut w) = ([[zero; 3]; Q], [[zero; 3]; Q], [zero; Q]);
    let mut j0 = starts[0];
    while j0 < j_max {
        let live = (j_max - j0).min(LANES);
        let rj = [&s.x, &s.y, &s.z].map(|v| Lanes::load(v, j0, live));
        let b = [&s.mx, &s.my, &s.mz].map(|v| Lanes::load(v, j0, live));
        let k = j0 - base;
        for q in 0..Q {
            let mut d: [Lanes; 3] = std::array::from_fn(|c| rj[c].map(|x| centre[q][c] - x));
            // Lanes past the row's end, or before the row's start, hold no
            // separation and no moment.
            if live < LANES || j0 < starts[q] {
                let keep = Lanes(std::array::from_fn(|l| {
                    if l < live && j0 + l >= starts[q] {
                        1.0
                    } else {
                        0.0
                    }
                }));
                d = d.map(|d| d * keep);
            }
            let p = pair_lanes(kern, d, a[q], b);
            for c in 0..3 {
                f[q][c] = f[q][c] + p.force[c];
                t[q][c] = t[q][c] + p.torque_i[c];
            }
            w[q] = w[q] + p.virial;
            p.force[0].subtract_from(&mut r.fx, k, live);
            p.force[1].subtract_from(&mut r.fy, k, live);
            p.force[2].subtract_from(&mut r.fz, k, live);
            p.torque_j[0].add_to(&mut r.tx, k, live);
            p.torque_j[1].add_to(&mut r.ty, k, live);
            p.torque_j[2].add_to(&mut r.tz, k, live);
        }
        j0 += live;
    }
    std::array::from_fn(|q| {
        (
            DVec3::new(f[q][0].sum(), f[q][1].sum(), f[q][2].sum()),
            DVec3::new(t[q][0].sum(), t[q][1].sum(), t[q][2].sum()),
            w[q].sum(),
        )
    })
}

impl DipoleDipole {
    /// Tile length: at least 64, at most 64 tiles, a multiple of 8.
    fn tile(npad: usize) -> usize {
        (npad.div_ceil(64).div_ceil(8) * 8).max(64)
    }

    /// Adds the forces and torques of all pairs among the first `n`
    /// particles of the (padded) structure of arrays; returns the virial.
    pub(super) fn tiled_forces(
        &mut self,
        n: usize,
        force: &mut [DVec3],
        torque: &mut [DVec3],
        isa: Isa,
    ) -> f64 {
        let kern = self.kernel();
        let soa = &self.soa;
        let npad = soa.x.len();
        let tile = Self::tile(npad);
        let tiles = npad.div_ceil(tile);
        self.tiles.resize_with(tiles, TileRow::default);
        let sweep = |t: usize, row: &mut TileRow| {
            let base = t * tile;
            let end_i = (base + tile).min(n);
            row.own.clear();
            row.own
                .resize(end_i.saturating_sub(base), (DVec3::ZERO, DVec3::ZERO));
            row.reactions.reset(npad - base);
            row.virial = 0.0;
            let mut block = base / COLUMNS * COLUMNS;
            while block < npad {
                let block_end = (block + COLUMNS).min(npad);
                let mut i = base;
                while i < end_i {
                    let j_start = block.max(i + 1);
                    if j_start >= block_end {
                        i += 1;
                        continue;
                    }
                    let r = &mut row.reactions;
                    // Two rows share each block's loads and reaction
                    // updates (the arithmetic of two single rows).
                    if i + 1 < end_i {
                        let starts = [j_start, block.max(i + 2)];
                        let sums = match isa {
                            // SAFETY: the CPU supports AVX-512F (`isa`); the
                            // arrays have the padded length npad ≥ block_end, a
                            // multiple of 8, and the reactions cover base..npad.
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx512 => unsafe {
                                super::avx512::reacting_rows::<2>(
                                    &kern, soa, i, starts, block_end, n, base, r,
                                )
                            },
                            Isa::Portable => reacting_rows_portable::<2>(
                                &kern, soa, i, starts, block_end, n, base, r,
                            ),
                        };
                        for (q, (f, tq, w)) in sums.into_iter().enumerate() {
                            let own = &mut row.own[i + q - base];
                            own.0 += f;
                            own.1 += tq;
                            row.virial += w;
                        }
                        i += 2;
                        continue;
                    }
                    let (f, tq, w) = match isa {
                        // SAFETY: as above, for one row.
                        #[cfg(target_arch = "x86_64")]
                        Isa::Avx512 => unsafe {
                            super::avx512::reacting_rows::<1>(
                                &kern,
                                soa,
                                i,
                                [j_start],
                                block_end,
                                n,
                                base,
                                r,
                            )[0]
                        },
                        Isa::Portable => reacting_rows_portable::<1>(
                            &kern,
                            soa,
                            i,
                            [j_start],
                            block_end,
                            n,
                            base,
                            r,
                        )[0],
                    };
                    let own = &mut row.own[i - base];
                    own.0 += f;
                    own.1 += tq;
                    row.virial += w;
                    i += 1;
                }
                block = block_end;
            }
        };
        // Tile t has about (N − t·tile) rows of work: tasks take tiles t and
        // T − 1 − t together, so that each has the same share.
        self.tiles.truncate(tiles);
        let (first, last) = self.tiles.split_at_mut(tiles.div_ceil(2));
        let mut partners: Vec<Option<&mut TileRow>> = last.iter_mut().rev().map(Some).collect();
        partners.resize_with(first.len(), || None);
        first
            .par_iter_mut()
            .zip(partners)
            .enumerate()
            .for_each(|(t, (row, partner))| {
                sweep(t, row);
                if let Some(row) = partner {
                    sweep(tiles - 1 - t, row);
                }
            });
        let rows = &self.tiles;
        force[..n]
            .par_chunks_mut(tile)
            .zip(torque[..n].par_chunks_mut(tile))
            .enumerate()
            .for_each(|(t, (fc, tc))| {
                for (k, (f, tq)) in fc.iter_mut().zip(tc.iter_mut()).enumerate() {
                    let i = t * tile + k;
                    let (mut sf, mut st) = rows[t].own[k];
                    for (s, row) in rows[..=t].iter().enumerate() {
                        let (rf, rt) = row.reactions.at(i - s * tile);
                        sf += rf;
                        st += rt;
                    }
                    *f += sf;
                    *tq += st;
                }
            });
        self.tiles.iter().map(|r| r.virial).sum()
    }
}
