//! A full neighbour list over a cell-sorted copy of the particles, with their
//! periodic images appended as ghosts: the list that SIMD pair kernels read.
//!
//! Building wraps every particle into the box and sorts the particles by
//! cell, so particles that are neighbours in space are neighbours in memory.
//! Each periodic axis then adds an image x ± L of every copy within
//! r_c + skin of a face; the axes are swept one after the other, so the
//! images of images cover the edges and corners. A pair is then a plain
//! difference x_i − x_j: the pair loop does no minimum image. Each
//! particle's row lists every copy within r_c + skin (both members of a
//! pair see each other), so a kernel sums the force on i alone and writes
//! nothing else: rows run in parallel with no reductions.
//!
//! Between builds, [`GhostList::update`] moves every copy by the
//! displacement of its particle since the build, taken as a minimum image,
//! so the integrator may wrap positions freely. The list is rebuilt when a
//! particle has moved more than half the skin (no pair can then have come
//! within r_c unseen) or after a fixed number of updates if one is set.

use glam::DVec3;
use mote_geom::lanes::{self, Lanes, LANES};
use rayon::prelude::*;

use crate::boundary::Boundary;
use crate::domain::Halo;

/// Particles per parallel block of a build or refresh.
const BLOCK: usize = 512;

/// Rows per block of [`GhostList::sum_rows`] (fixed, so sums do not depend
/// on the number of threads).
pub const ROWS: usize = 256;

/// A copy's coordinates (x, y, z, 0), aligned to 32 bytes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Copy4(pub [f64; 4]);

impl Copy4 {
    /// The copies as plain four-number records, as
    /// [`mote_geom::lanes::gather_xyz`] reads them.
    pub fn records(copies: &[Copy4]) -> &[[f64; 4]] {
        // SAFETY: `Copy4` is `repr(C)` around one `[f64; 4]` with no
        // padding (32 bytes, aligned to 32), so the slices have the same
        // layout and length.
        unsafe { std::slice::from_raw_parts(copies.as_ptr().cast::<[f64; 4]>(), copies.len()) }
    }
}

/// A full Verlet list over sorted copies and periodic ghosts.
#[derive(Debug, Clone, Default)]
pub struct GhostList {
    /// Interaction cut-off r_c.
    pub cutoff: f64,
    /// Skin: the list holds pairs within r_c + skin.
    pub skin: f64,
    /// Rebuild at least every this many updates (0: only on displacement).
    pub every: u64,
    /// The particle of each copy (particles and ghosts, in cell order).
    pub particle: Vec<u32>,
    /// The copies that are particles themselves, one per row, in cell order.
    pub owner: Vec<u32>,
    /// The row of each particle.
    pub slot: Vec<u32>,
    /// Current coordinates of the copies, (x, y, z, 0): one aligned
    /// 32-byte record each, so a kernel loads a neighbour in one go.
    pub position: Vec<Copy4>,
    /// `neighbors[start[r]..start[r + 1]]` are the copies near row r.
    pub start: Vec<u32>,
    pub neighbors: Vec<u32>,
    /// Coordinates of the copies at the build (ghost shifts included).
    base: [Vec<f64>; 3],
    /// Wrapped positions of the particles at the build.
    reference: Vec<DVec3>,
    displacement: Vec<DVec3>,
    since_build: u64,
    /// Number of builds so far.
    pub builds: u64,
    /// A restored build (updates since it, wrapped positions), made at the
    /// next update, when the box is at hand.
    pending: Option<(u64, Vec<DVec3>)>,
    /// The halo generation the list was built for (decomposed runs).
    generation: u64,
}

impl GhostList {
    pub fn new(cutoff: f64, skin: f64) -> Self {
        Self {
            cutoff,
            skin,
            ..Self::default()
        }
    }

    /// Number of particles (rows).
    pub fn len(&self) -> usize {
        self.slot.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slot.is_empty()
    }

    /// Number of ghost copies.
    pub fn ghosts(&self) -> usize {
        self.particle.len() - self.slot.len()
    }

    /// Current position of copy k.
    #[inline]
    pub fn at(&self, k: usize) -> DVec3 {
        let [x, y, z, _] = self.position[k].0;
        DVec3::new(x, y, z)
    }

    /// The copies near the particle of row r.
    #[inline]
    pub fn row(&self, r: usize) -> &[u32] {
        &self.neighbors[self.start[r] as usize..self.start[r + 1] as usize]
    }

    /// Runs `row` on every row in fixed blocks of [`ROWS`], in parallel:
    /// its first part goes to `out[r]` (one entry per row), its K numbers
    /// are summed row after row within a block and block after block, so
    /// every thread count gives the same bits.
    pub fn sum_rows<T: Send, const K: usize>(
        &self,
        out: &mut [T],
        row: impl Fn(usize) -> (T, [f64; K]) + Sync,
    ) -> [f64; K] {
        assert_eq!(out.len(), self.len(), "one output per row");
        let sums: Vec<[f64; K]> = out
            .par_chunks_mut(ROWS)
            .enumerate()
            .map(|(b, out)| {
                let mut sum = [0.0; K];
                for (m, o) in out.iter_mut().enumerate() {
                    let (value, numbers) = row(b * ROWS + m);
                    *o = value;
                    for (s, x) in sum.iter_mut().zip(numbers) {
                        *s += x;
                    }
                }
                sum
            })
            .collect();
        sums.iter().fold([0.0; K], |mut total, s| {
            for (t, x) in total.iter_mut().zip(s) {
                *t += x;
            }
            total
        })
    }

    /// A per-particle vector for every copy (ghosts take their particle's),
    /// as aligned records in copy order: what row kernels read beside the
    /// positions (dipole moments, velocities).
    pub fn gather(&self, values: &[DVec3], out: &mut Vec<Copy4>) {
        out.clear();
        out.par_extend(self.particle.par_iter().with_min_len(BLOCK).map(|&i| {
            let v = values[i as usize];
            Copy4([v.x, v.y, v.z, 0.0])
        }));
    }

    /// [`GhostList::gather`] over a halo: the copies of this rank's
    /// particles take `own`, the ghosts `ghosts` (in the halo's order).
    pub fn gather_halo(&self, own: &[DVec3], ghosts: &[DVec3], out: &mut Vec<Copy4>) {
        let n = own.len();
        out.clear();
        out.par_extend(self.particle.par_iter().with_min_len(BLOCK).map(|&i| {
            let i = i as usize;
            let v = if i < n { own[i] } else { ghosts[i - n] };
            Copy4([v.x, v.y, v.z, 0.0])
        }));
    }

    /// Adds the value of each particle's row (`sorted`, in row order) to
    /// the particle's entry of `to`.
    pub fn scatter_add(&self, sorted: &[DVec3], to: &mut [DVec3]) {
        let slot = &self.slot;
        to.par_iter_mut()
            .with_min_len(4096)
            .enumerate()
            .for_each(|(i, f)| *f += sorted[slot[i] as usize]);
    }

    /// Counts one step: rebuilds the list if it is due or stale, else moves
    /// the copies to `pos`. Returns whether it rebuilt.
    pub fn update(&mut self, pos: &[DVec3], boundary: &Boundary) -> bool {
        self.build_restored(boundary);
        self.since_build += 1;
        let due = self.every > 0 && self.since_build >= self.every;
        self.follow(pos, boundary, due)
    }

    /// Moves the copies to `pos` (rebuilding if a particle has gone too far)
    /// without counting a step: for energies between steps.
    pub fn refresh(&mut self, pos: &[DVec3], boundary: &Boundary) -> bool {
        self.build_restored(boundary);
        self.follow(pos, boundary, false)
    }

    /// Makes the build a checkpoint described ([`GhostList::restore`]).
    fn build_restored(&mut self, boundary: &Boundary) {
        if let Some((since, reference)) = self.pending.take() {
            self.build(&reference, boundary);
            self.since_build = since;
        }
    }

    fn follow(&mut self, pos: &[DVec3], boundary: &Boundary, due: bool) -> bool {
        if due || self.reference.len() != pos.len() {
            self.build(pos, boundary);
            return true;
        }
        let limit = 0.25 * self.skin * self.skin;
        let reference = &self.reference;
        let farthest = self
            .displacement
            .par_iter_mut()
            .with_min_len(BLOCK)
            .enumerate()
            .map(|(i, d)| {
                *d = boundary.minimum_image(pos[i] - reference[i]);
                d.length_squared()
            })
            .reduce(|| 0.0, f64::max);
        if farthest > limit {
            self.build(pos, boundary);
            return true;
        }
        let displacement = std::mem::take(&mut self.displacement);
        self.move_copies(&displacement);
        self.displacement = displacement;
        false
    }

    /// What a checkpoint must hold for a resumed run to sum forces in the
    /// same order as the uninterrupted one: [updates since the build, then
    /// the wrapped positions of the build, x y z per particle]. Empty before
    /// the first build.
    pub fn carried_state(&self) -> Vec<f64> {
        if self.reference.is_empty() {
            return Vec::new();
        }
        let mut out = Vec::with_capacity(1 + 3 * self.reference.len());
        out.push(self.since_build as f64);
        out.extend(self.reference.iter().flat_map(|r| r.to_array()));
        out
    }

    /// Forgets the build (the particles changed): the next update builds
    /// afresh, and a checkpoint until then carries no list.
    pub fn invalidate(&mut self) {
        self.reference.clear();
        self.pending = None;
    }

    /// Takes the list [`GhostList::carried_state`] describes; it is built
    /// at the next update or refresh, in the box given there. Wrapping is
    /// idempotent, so the build at the stored positions is the one the
    /// uninterrupted run made, row order and all.
    pub fn restore(&mut self, state: &[f64]) -> Result<(), String> {
        let Some((&since, xyz)) = state.split_first() else {
            return Ok(());
        };
        if !(xyz.len().is_multiple_of(3) && since >= 0.0 && since.fract() == 0.0) {
            return Err("neighbour list: a step count and x y z triples expected".into());
        }
        let reference: Vec<DVec3> = xyz.chunks(3).map(DVec3::from_slice).collect();
        self.pending = Some((since as u64, reference));
        Ok(())
    }

    /// Hands over a build a checkpoint described and the list has not
    /// made yet ([`GhostList::restore`]): evaluations since it and the
    /// wrapped positions there (a decomposed run remakes it over its
    /// halo).
    pub fn take_restored(&mut self) -> Option<(u64, Vec<DVec3>)> {
        self.pending.take()
    }

    /// Builds the list from scratch at positions `pos`.
    pub fn build(&mut self, pos: &[DVec3], boundary: &Boundary) {
        let n = pos.len();
        assert!(
            n < u32::MAX as usize / 2,
            "too many particles for u32 lists"
        );
        let reach = self.cutoff + self.skin;
        let wrapped: Vec<DVec3> = pos.par_iter().map(|r| boundary.wrap(*r)).collect();
        let grid = Grid::new(&wrapped, boundary, reach);

        // The particles, then their images within reach of the box.
        let mut copies: Vec<(u32, DVec3)> = (0..n as u32).map(|i| (i, DVec3::ZERO)).collect();
        for k in 0..3 {
            if !boundary.periodic[k] {
                continue;
            }
            let l = boundary.hi[k] - boundary.lo[k];
            let images = (reach / l).ceil() as i32;
            let (lo, hi) = (boundary.lo[k] - reach, boundary.hi[k] + reach);
            for c in 0..copies.len() {
                let (i, shift) = copies[c];
                let r = wrapped[i as usize][k] + shift[k];
                for m in (-images..=images).filter(|&m| m != 0) {
                    let image = r + m as f64 * l;
                    if image >= lo && image < hi {
                        let mut s = shift;
                        s[k] += m as f64 * l;
                        copies.push((i, s));
                    }
                }
            }
        }
        // All copies in cell order: a cell, and a run of cells along x, is
        // a contiguous range of the coordinate arrays.
        let at = |&(i, s): &(u32, DVec3)| wrapped[i as usize] + s;
        let unsorted_cells: Vec<u32> = copies.par_iter().map(|c| grid.cell(at(c))).collect();
        let order = grid.counting_sort(&unsorted_cells);
        let sorted: Vec<Copy> = order
            .iter()
            .map(|&c| {
                let copy = copies[c as usize];
                Copy {
                    particle: copy.0,
                    at: at(&copy),
                    row: copy.1 == DVec3::ZERO,
                    cell: unsorted_cells[c as usize],
                }
            })
            .collect();
        self.fill(&grid, &sorted, n);
        self.reference = wrapped;
        self.displacement = vec![DVec3::ZERO; n];
        self.since_build = 0;
    }

    /// Brings the list to the halo of a decomposed run: rebuilt when the
    /// halo was built anew since the list was, else each copy moved by its
    /// particle's displacement. Returns whether it rebuilt.
    pub fn follow_halo(&mut self, halo: &Halo, boundary: &Boundary) -> bool {
        let rebuilt = self.generation != halo.generation;
        if rebuilt {
            self.build_halo(halo, boundary);
        }
        // Zero after a build, but not after one a checkpoint restored.
        self.move_copies(&halo.displacement);
        rebuilt
    }

    /// Builds the list over a rank's particles and ghosts. The copies are
    /// sorted by the cell of one process's grid over the whole box, then
    /// within a cell in the order one process makes them (particles by
    /// id, then the images along x, then along y, along z, each by the
    /// copy it was made from and its image), so every row lists the
    /// neighbours one process's row lists, in its order.
    fn build_halo(&mut self, halo: &Halo, boundary: &Boundary) {
        let n = halo.reference.len();
        assert!(
            n + halo.ghosts.len() < u32::MAX as usize / 2,
            "too many particles for u32 lists"
        );
        let reach = self.cutoff + self.skin;
        let grid = Grid::spanning(boundary, reach, halo.extent, halo.total);
        let own = halo
            .reference
            .iter()
            .zip(&halo.id)
            .map(|(r, id)| (*id, [0; 3], *r));
        let ghosts = halo.ghosts.iter().map(|g| (g.id, g.image, g.base));
        let copies: Vec<(u64, [i32; 3], DVec3)> = own.chain(ghosts).collect();
        let cells: Vec<u32> = copies.par_iter().map(|c| grid.cell(c.2)).collect();
        // By cell (a counting sort), then each cell's few copies by key.
        let mut order = grid.counting_sort(&cells);
        let first = grid.first(&cells);
        let key = |c: &u32| {
            let (id, [mx, my, mz], _) = copies[*c as usize];
            (mz != 0, my != 0, mx != 0, id, mx, my, mz)
        };
        for cell in first.windows(2) {
            order[cell[0] as usize..cell[1] as usize].sort_unstable_by_key(key);
        }
        let sorted: Vec<Copy> = order
            .iter()
            .map(|&c| Copy {
                particle: c,
                at: copies[c as usize].2,
                row: (c as usize) < n,
                cell: cells[c as usize],
            })
            .collect();
        self.fill(&grid, &sorted, n);
        self.generation = halo.generation;
    }

    /// Moves copy k to its place at the build plus `displacement` of its
    /// particle.
    fn move_copies(&mut self, displacement: &[DVec3]) {
        let particle = &self.particle;
        let [bx, by, bz] = &self.base;
        self.position
            .par_chunks_mut(BLOCK)
            .enumerate()
            .for_each(|(b, chunk)| {
                for (c, p) in chunk.iter_mut().enumerate() {
                    let k = b * BLOCK + c;
                    let d = displacement[particle[k] as usize];
                    *p = Copy4([bx[k] + d.x, by[k] + d.y, bz[k] + d.z, 0.0]);
                }
            });
    }

    /// Takes `copies`, sorted by cell, as the list's copies, with a row for
    /// each of the `rows` copies marked as one, filled from the 3 × 3 runs
    /// of three cells around it without branches on the distance.
    fn fill(&mut self, grid: &Grid, copies: &[Copy], rows: usize) {
        let cell: Vec<u32> = copies.iter().map(|c| c.cell).collect();
        let first = grid.first(&cell);
        self.particle = copies.iter().map(|c| c.particle).collect();
        self.owner.clear();
        self.slot = vec![0; rows];
        for (k, c) in copies.iter().enumerate() {
            if c.row {
                self.slot[c.particle as usize] = self.owner.len() as u32;
                self.owner.push(k as u32);
            }
        }
        for axis in 0..3 {
            self.base[axis] = copies.par_iter().map(|c| c.at[axis]).collect();
        }
        let [bx, by, bz] = &self.base;
        self.position = (0..copies.len())
            .map(|k| Copy4([bx[k], by[k], bz[k], 0.0]))
            .collect();

        let (x, y, z, owner) = (bx, by, bz, &self.owner);
        let reach = self.cutoff + self.skin;
        let reach2 = reach * reach;
        let n = rows;
        let rows: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut near: Vec<u32> = Vec::new();
                let mut len = Vec::with_capacity(BLOCK);
                for r in b * BLOCK..((b + 1) * BLOCK).min(n) {
                    let k = owner[r] as usize;
                    let before = near.len();
                    let (xk, yk, zk) = (x[k], y[k], z[k]);
                    grid.for_each_run_around(cell[k], |lo, hi| {
                        let (lo, hi) = (first[lo] as usize, first[hi + 1] as usize);
                        let count = near.len();
                        near.resize(count + hi - lo + 8, 0);
                        let kept = within(
                            (xk, yk, zk),
                            reach2,
                            (&x[lo..hi], &y[lo..hi], &z[lo..hi]),
                            lo,
                            k,
                            &mut near[count..],
                        );
                        near.truncate(count + kept);
                    });
                    len.push((near.len() - before) as u32);
                }
                (near, len)
            })
            .collect();
        self.start.clear();
        self.neighbors.clear();
        self.start.push(0);
        for (near, len) in &rows {
            self.neighbors.extend_from_slice(near);
            for &l in len {
                let last = *self.start.last().unwrap();
                self.start.push(last + l);
            }
        }
        self.builds += 1;
    }
}

/// A copy at a build: its particle (index into the positions the list was
/// built from, a rank's particles then its ghosts), its place, whether it
/// has a row (a particle itself, not an image or a ghost) and its cell.
struct Copy {
    particle: u32,
    at: DVec3,
    row: bool,
    cell: u32,
}

/// Writes to the front of `out` the indices `first + m` of the points
/// (x[m], y[m], z[m]) closer than √reach2 to `at`, except `exclude`, and
/// returns how many. `out` must have eight entries to spare beyond
/// `x.len()`. Branch-free: AVX-512 compresses eight indices at a time where
/// the CPU has it; else an index is written, then kept or not.
#[inline]
pub(crate) fn within(
    at: (f64, f64, f64),
    reach2: f64,
    (x, y, z): (&[f64], &[f64], &[f64]),
    first: usize,
    exclude: usize,
    out: &mut [u32],
) -> usize {
    assert!(out.len() >= x.len() + 8 && y.len() == x.len() && z.len() == x.len());
    #[cfg(target_arch = "x86_64")]
    if compress_available() {
        // SAFETY: AVX-512F and VL are present; the slices were checked above.
        return unsafe { within_avx512(at, reach2, (x, y, z), first, exclude, out) };
    }
    within_lanes(at, reach2, (x, y, z), first, exclude, out)
}

/// [`within`] eight points at a time on [`Lanes`]: the distances of eight
/// in lanes, r² fused as the AVX-512 kernel takes it (so both levels keep
/// the same points), the kept ones left-packed into `out`
/// ([`lanes::pack_indices`]); the last few points one at a time (a short
/// group loaded into lanes cost a copy per coordinate, a third of the
/// time of a build on an AVX2 CPU); then `exclude` taken out where it was
/// kept.
#[inline]
fn within_lanes(
    at: (f64, f64, f64),
    reach2: f64,
    (x, y, z): (&[f64], &[f64], &[f64]),
    first: usize,
    exclude: usize,
    out: &mut [u32],
) -> usize {
    let (ax, ay, az) = (Lanes::splat(at.0), Lanes::splat(at.1), Lanes::splat(at.2));
    // r² = dz² + (dy² + dx²), fused as the other kernels take it.
    let r2 = |dx: f64, dy: f64, dz: f64| dz.mul_add(dz, dy.mul_add(dy, dx * dx));
    let mut kept = 0;
    let groups = x.len() / LANES * LANES;
    for m in (0..groups).step_by(LANES) {
        let eight = |v: &[f64]| Lanes(v[m..m + LANES].try_into().expect("eight"));
        let (dx, dy, dz) = (ax - eight(x), ay - eight(y), az - eight(z));
        let mut d2 = Lanes::splat(0.0);
        #[allow(clippy::needless_range_loop)]
        for l in 0..LANES {
            d2.0[l] = r2(dx.0[l], dy.0[l], dz.0[l]);
        }
        kept += lanes::pack_indices(d2.bits_below(reach2), (first + m) as u32, &mut out[kept..]);
    }
    for m in groups..x.len() {
        out[kept] = (first + m) as u32;
        kept += usize::from(r2(at.0 - x[m], at.1 - y[m], at.2 - z[m]) < reach2);
    }
    if (first..first + x.len()).contains(&exclude) {
        if let Some(p) = out[..kept].iter().position(|&j| j as usize == exclude) {
            out.copy_within(p + 1..kept, p);
            kept -= 1;
        }
    }
    kept
}

#[cfg(target_arch = "x86_64")]
fn compress_available() -> bool {
    mote_geom::simd::has_avx512()
}

/// [`within`] eight points at a time: contiguous loads, one compare, the
/// kept indices compressed into a register and stored whole (the eight
/// spare entries of `out` take the overhang).
///
/// # Safety
/// AVX-512F and AVX-512VL; `y`, `z` as long as `x`; `out` at least
/// `x.len() + 8` long.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl")]
unsafe fn within_avx512(
    at: (f64, f64, f64),
    reach2: f64,
    (x, y, z): (&[f64], &[f64], &[f64]),
    first: usize,
    exclude: usize,
    out: &mut [u32],
) -> usize {
    use std::arch::x86_64::*;
    let (ax, ay, az) = (
        _mm512_set1_pd(at.0),
        _mm512_set1_pd(at.1),
        _mm512_set1_pd(at.2),
    );
    let limit = _mm512_set1_pd(reach2);
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let n = x.len();
    let mut kept = 0;
    let mut m = 0;
    while m < n {
        let valid: __mmask8 = if n - m >= 8 {
            0xff
        } else {
            ((1u32 << (n - m)) - 1) as u8
        };
        // SAFETY: lanes outside `valid` are not read.
        let (xj, yj, zj) = unsafe {
            (
                _mm512_maskz_loadu_pd(valid, x.as_ptr().add(m)),
                _mm512_maskz_loadu_pd(valid, y.as_ptr().add(m)),
                _mm512_maskz_loadu_pd(valid, z.as_ptr().add(m)),
            )
        };
        let (dx, dy, dz) = (
            _mm512_sub_pd(ax, xj),
            _mm512_sub_pd(ay, yj),
            _mm512_sub_pd(az, zj),
        );
        let r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
        let mut near = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(valid, r2, limit);
        let j0 = first + m;
        if exclude >= j0 && exclude < j0 + 8 {
            near &= !(1u8 << (exclude - j0));
        }
        let index = _mm256_add_epi32(lanes, _mm256_set1_epi32(j0 as i32));
        let packed = _mm256_maskz_compress_epi32(near, index);
        // SAFETY: kept ≤ m and out.len() ≥ n + 8 ≥ kept + 8.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().add(kept) as *mut __m256i, packed) };
        kept += near.count_ones() as usize;
        m += 8;
    }
    kept
}

/// Cells of edge ≥ r_c + skin over the box and its ghost shell (periodic
/// axes) or over the particles' extent (open axes).
struct Grid {
    lo: DVec3,
    inverse_edge: DVec3,
    dims: [u32; 3],
}

impl Grid {
    fn new(wrapped: &[DVec3], boundary: &Boundary, reach: f64) -> Self {
        let lo = wrapped.iter().fold(DVec3::INFINITY, |a, r| a.min(*r));
        let hi = wrapped.iter().fold(DVec3::NEG_INFINITY, |a, r| a.max(*r));
        Self::spanning(boundary, reach, (lo, hi), wrapped.len())
    }

    /// The grid of `particles` particles whose wrapped coordinates lie
    /// within `extent` (the grid of an open axis spans them).
    fn spanning(boundary: &Boundary, reach: f64, extent: (DVec3, DVec3), particles: usize) -> Self {
        let mut lo = DVec3::ZERO;
        let mut inverse_edge = DVec3::ZERO;
        let mut dims = [1usize; 3];
        let mut len = [0.0; 3];
        for k in 0..3 {
            let (a, b) = if boundary.periodic[k] {
                (boundary.lo[k] - reach, boundary.hi[k] + reach)
            } else if extent.0[k].is_finite() {
                (extent.0[k], extent.1[k])
            } else {
                (0.0, 1.0)
            };
            len[k] = (b - a).max(reach);
            dims[k] = ((len[k] / reach).floor() as usize).clamp(1, 1 << 10);
            lo[k] = a;
        }
        mote_geom::grids::cap_cells(&mut dims, 8 * particles.max(8));
        for k in 0..3 {
            inverse_edge[k] = dims[k] as f64 / len[k];
        }
        Self {
            lo,
            inverse_edge,
            dims: dims.map(|d| d as u32),
        }
    }

    fn count(&self) -> usize {
        (self.dims[0] * self.dims[1] * self.dims[2]) as usize
    }

    fn coords(&self, r: DVec3) -> [u32; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            let x = ((r[k] - self.lo[k]) * self.inverse_edge[k]).floor();
            c[k] = x.clamp(0.0, (self.dims[k] - 1) as f64) as u32;
        }
        c
    }

    fn cell(&self, r: DVec3) -> u32 {
        let [x, y, z] = self.coords(r);
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Start of each cell's members in [`Grid::counting_sort`]'s order.
    fn first(&self, cells: &[u32]) -> Vec<u32> {
        let mut first = vec![0u32; self.count() + 1];
        for &c in cells {
            first[c as usize + 1] += 1;
        }
        for c in 0..self.count() {
            first[c + 1] += first[c];
        }
        first
    }

    /// Indices sorted by cell, stable within a cell.
    fn counting_sort(&self, cells: &[u32]) -> Vec<u32> {
        let mut fill = self.first(cells);
        let mut order = vec![0u32; cells.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        order
    }

    /// Calls `f(first, last)` for the nine runs of cells along x around
    /// cell `c` (itself included), clipped to the grid: the ghost shell
    /// stands in for periodic neighbours. (Halved cells, runs of five in a
    /// 5 × 5 stencil, test 42 % fewer candidates but ran the LJ melt 8 %
    /// slower: more and shorter runs.)
    fn for_each_run_around(&self, c: u32, mut f: impl FnMut(usize, usize)) {
        let [dx, dy] = [self.dims[0], self.dims[1]];
        let (x, y, z) = (c % dx, (c / dx) % dy, c / (dx * dy));
        let span = |v: u32, d: u32| v.saturating_sub(1)..=(v + 1).min(d - 1);
        let (x0, x1) = (x.saturating_sub(1), (x + 1).min(dx - 1));
        for cz in span(z, self.dims[2]) {
            for cy in span(y, dy) {
                let row = dx * (cy + dy * cz);
                f((row + x0) as usize, (row + x1) as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scatter(n: usize, l: DVec3, seed: u64) -> Vec<DVec3> {
        let mut s = seed;
        let mut u = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| DVec3::new(u() * l.x, u() * l.y, u() * l.z))
            .collect()
    }

    /// Each kernel of [`within`] keeps exactly the points a plain loop
    /// keeps (r² = dz² + (dy² + dx²) by fused multiply-adds, as the
    /// kernels take it), in order, for every length of a run (the tails)
    /// and with the excluded point anywhere or nowhere in it.
    #[test]
    fn within_keeps_the_points_in_reach_at_every_level() {
        let l = DVec3::splat(3.0);
        let pos = scatter(37, l, 11);
        let (x, y, z): (Vec<f64>, Vec<f64>, Vec<f64>) = (
            pos.iter().map(|p| p.x).collect(),
            pos.iter().map(|p| p.y).collect(),
            pos.iter().map(|p| p.z).collect(),
        );
        let at = (1.4, 1.6, 1.5);
        let reach2 = 1.2f64 * 1.2;
        let first = 100;
        type Kernel =
            fn((f64, f64, f64), f64, (&[f64], &[f64], &[f64]), usize, usize, &mut [u32]) -> usize;
        let kernels: Vec<(&str, Kernel)> = vec![("lanes", within_lanes), ("dispatched", within)];
        for len in 0..=x.len() {
            for exclude in [
                first + len / 2,
                first + len.saturating_sub(1),
                first + 9,
                7,
                first + 1000,
            ] {
                let expected: Vec<u32> = (0..len)
                    .filter(|&m| {
                        let (dx, dy, dz) = (at.0 - x[m], at.1 - y[m], at.2 - z[m]);
                        dz.mul_add(dz, dy.mul_add(dy, dx * dx)) < reach2 && first + m != exclude
                    })
                    .map(|m| (first + m) as u32)
                    .collect();
                for (name, kernel) in &kernels {
                    let mut out = vec![0u32; len + 8];
                    let kept = kernel(
                        at,
                        reach2,
                        (&x[..len], &y[..len], &z[..len]),
                        first,
                        exclude,
                        &mut out,
                    );
                    assert_eq!(
                        out[..kept],
                        expected[..],
                        "{name}: {len} points, {exclude} excluded"
                    );
                }
            }
        }
        #[cfg(target_arch = "x86_64")]
        if compress_available() {
            let mut out = vec![0u32; x.len() + 8];
            // SAFETY: AVX-512F and VL are present; out has eight to spare.
            let kept = unsafe { within_avx512(at, reach2, (&x, &y, &z), first, 7, &mut out) };
            let mut plain = vec![0u32; x.len() + 8];
            let n = within(at, reach2, (&x, &y, &z), first, 7, &mut plain);
            assert_eq!(out[..kept], plain[..n]);
        }
    }

    /// Every pair within r_c + skin (minimum image) is in both rows, once,
    /// and nothing else; periodic, mixed and open boundaries.
    #[test]
    fn rows_hold_exactly_the_pairs_in_reach() {
        let l = DVec3::new(7.0, 8.0, 9.0);
        for periodic in [[true; 3], [true, false, true], [false; 3]] {
            let b = Boundary {
                lo: DVec3::ZERO,
                hi: l,
                periodic,
            };
            let pos = scatter(600, l, 7);
            let mut list = GhostList::new(1.1, 0.4);
            list.build(&pos, &b);
            let reach2 = 1.5f64 * 1.5;
            for i in 0..pos.len() {
                let r = list.slot[i] as usize;
                let k = list.owner[r] as usize;
                let mut seen: Vec<usize> = list
                    .row(r)
                    .iter()
                    .map(|&j| list.particle[j as usize] as usize)
                    .collect();
                seen.sort_unstable();
                let expect: Vec<usize> = (0..pos.len())
                    .filter(|&j| {
                        j != i && b.minimum_image(pos[j] - pos[i]).length_squared() < reach2
                    })
                    .collect();
                assert_eq!(seen, expect, "particle {i}, periodic {periodic:?}");
                for &j in list.row(r) {
                    let j = j as usize;
                    let d = list.at(k) - list.at(j);
                    let i2 = list.particle[j] as usize;
                    let m = b.minimum_image(pos[i] - pos[i2]);
                    assert!((d - m).length() < 1e-12);
                }
            }
        }
    }

    /// Copies follow wrapped particles between builds.
    #[test]
    fn copies_follow_wrapped_particles() {
        let l = DVec3::splat(6.0);
        let b = Boundary {
            lo: DVec3::ZERO,
            hi: l,
            periodic: [true; 3],
        };
        let mut pos = scatter(300, l, 3);
        let mut list = GhostList::new(1.0, 0.6);
        list.update(&pos, &b);
        for r in pos.iter_mut() {
            *r = b.wrap(*r + DVec3::new(0.2, -0.1, 0.15));
        }
        assert!(!list.update(&pos, &b));
        for i in 0..pos.len() {
            let r = list.slot[i] as usize;
            let k = list.owner[r] as usize;
            for &j in list.row(r) {
                let j = j as usize;
                let d = list.at(k) - list.at(j);
                let m = b.minimum_image(pos[i] - pos[list.particle[j] as usize]);
                assert!((d - m).length() < 1e-12);
            }
        }
    }
}
