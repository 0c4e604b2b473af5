//! Direct-summation softened Newtonian gravity (002 Eq. 2):
//!
//! a_i = G Σ_{j≠i} m_j (r_j − r_i) / (|r_j − r_i|² + ε²)^{3/2},
//!
//! with G = k² in astronomical units (masses as fractions of a standard mass)
//! and softening length ε. The potential energy is
//! U = −G Σ_{i<j} m_i m_j / (|r_j − r_i|² + ε²)^{1/2}.
//!
//! Each pair is evaluated once (Newton's third law): particles are cut into
//! tiles of `tile` consecutive indices; the rayon task of tile I sums, for
//! every i in I, the pull of all j > i (the "own" part of a_i) and subtracts
//! the reaction on each j into a buffer of its own. Every acceleration is
//! then the own part plus the reactions of tiles 0, 1, …, I in that order,
//! so results are bit-identical for every thread count. Positions are copied
//! into separate x, y, z, m arrays so the inner loop vectorises. On CPUs with
//! AVX-512 the inner loop takes 8 pairs per instruction and replaces the
//! square root and division by the hardware estimate of 1/√r² (14 bits)
//! refined by two Newton–Raphson steps y ← y (3/2 − (r²/2) y²), which gives
//! full double precision (agreement with the exact kernel to 1e-14 is tested).

mod avx512;
mod portable;

use glam::DVec3;
use mote_geom::simd::{isa, Isa};
use rayon::prelude::*;

use super::whole::Whole;
use super::{HaloReach, Interaction, State};

/// Lanes of the inner loop: one AVX-512 register of f64.
const LANES: usize = 8;
/// Above this (padded) N the reaction buffers would grow past ~100 MB: each
/// particle's sum then runs over all others (every pair evaluated twice).
const SYMMETRIC_MAX: usize = 1 << 17;

/// Softened direct-summation gravity.
#[derive(Debug, Clone, Default)]
pub struct DirectGravity {
    /// Newton's constant G (k² in astronomical units).
    pub g: f64,
    /// Softening length ε.
    pub softening: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    m: Vec<f64>,
    rows: Vec<TileRow>,
}

/// Scratch of one tile's task: the own parts of its particles, and the
/// reactions it exerts on particles from the tile's start to the end, as
/// three arrays of x, y, z components.
#[derive(Debug, Clone, Default)]
struct TileRow {
    own: Vec<DVec3>,
    rx: Vec<f64>,
    ry: Vec<f64>,
    rz: Vec<f64>,
}

/// The particles as structure-of-arrays slices (length a multiple of 8).
#[derive(Clone, Copy)]
pub(crate) struct Soa<'a> {
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub z: &'a [f64],
    pub m: &'a [f64],
}

impl DirectGravity {
    pub fn new(g: f64, softening: f64) -> Self {
        Self {
            g,
            softening,
            ..Self::default()
        }
    }

    /// Copies the state into the structure-of-arrays scratch, padded to a
    /// multiple of the lane count with massless particles far away.
    fn load(&mut self, state: &State) {
        self.load_strengths(state.position, state.mass);
    }

    /// Copies positions and source strengths (masses, or charges for
    /// Coulomb's law) into the structure-of-arrays scratch.
    fn load_strengths(&mut self, position: &[DVec3], strength: &[f64]) {
        let n = position.len();
        let padded = n.div_ceil(LANES) * LANES;
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.m.clear();
        for (r, m) in position.iter().zip(strength) {
            self.x.push(r.x);
            self.y.push(r.y);
            self.z.push(r.z);
            self.m.push(*m);
        }
        // Padding: massless and far away, yet with a finite r² (1e200) so the
        // Newton–Raphson refinement never sees infinities.
        for _ in n..padded {
            self.x.push(1e100);
            self.y.push(1e100);
            self.z.push(1e100);
            self.m.push(0.0);
        }
    }

    fn soa(&self) -> Soa<'_> {
        Soa {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            m: &self.m,
        }
    }

    /// Tile length: at least 256, and at most 64 tiles (a multiple of 8).
    fn tile(npad: usize) -> usize {
        (npad.div_ceil(64).div_ceil(LANES) * LANES).max(256)
    }

    /// Accelerations divided by G of the first `out.len()` particles.
    fn field(&mut self, out: &mut [DVec3]) {
        self.field_with(out, isa());
    }

    /// The inverse-square field Σ_{j≠i} s_j (r_j − r_i) / (|r_j − r_i|² + ε²)^{3/2}
    /// of sources of strength s (any sign) at every particle, by the same
    /// tiled pair kernel as gravity.
    pub(crate) fn inverse_square_field(
        &mut self,
        position: &[DVec3],
        strength: &[f64],
        out: &mut [DVec3],
    ) {
        self.load_strengths(position, strength);
        self.field(out);
    }

    /// Σ_i s_i Σ_{j≠i} s_j / (|r_j − r_i|² + ε²)^{1/2} (each pair twice), in a fixed order.
    pub(crate) fn pair_potential_sum(&mut self, position: &[DVec3], strength: &[f64]) -> f64 {
        self.load_strengths(position, strength);
        self.potential_sum(position.len())
    }

    /// Σ_i m_i Σ_{j≠i} m_j / r_ij over the first `n` (unpadded) particles.
    fn potential_sum(&self, n: usize) -> f64 {
        let eps2 = self.softening * self.softening;
        let soa = self.soa();
        let isa = isa();
        let per_i: Vec<f64> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|i| {
                soa.m[i]
                    * match isa {
                        // SAFETY: the CPU supports AVX-512F (`isa`); slices are padded to 8.
                        #[cfg(target_arch = "x86_64")]
                        Isa::Avx512 => unsafe { avx512::potential_at(i, soa, eps2) },
                        Isa::Portable => portable::potential_at(i, soa, eps2),
                    }
            })
            .collect();
        per_i.iter().sum::<f64>()
    }

    fn field_with(&mut self, out: &mut [DVec3], isa: Isa) {
        let eps2 = self.softening * self.softening;
        let npad = self.x.len();
        let n = out.len();
        if npad > SYMMETRIC_MAX {
            let rows: Vec<usize> = (0..n).collect();
            field_rows(self.soa(), eps2, &rows, out, isa);
            return;
        }
        let tile = Self::tile(npad);
        let tiles = npad.div_ceil(tile);
        self.rows.resize_with(tiles, TileRow::default);
        let soa = Soa {
            x: &self.x,
            y: &self.y,
            z: &self.z,
            m: &self.m,
        };
        self.rows.par_iter_mut().enumerate().for_each(|(t, row)| {
            let base = t * tile;
            let len = npad - base;
            row.own.clear();
            row.own.resize(tile.min(len), DVec3::ZERO);
            for r in [&mut row.rx, &mut row.ry, &mut row.rz] {
                r.clear();
                r.resize(len, 0.0);
            }
            let end_i = (base + tile).min(n);
            // Tile by tile along j, so the reactions in use stay in L1.
            for jt in t..tiles {
                let j_end = ((jt + 1) * tile).min(npad);
                let mut i = base;
                while i < end_i {
                    let (rx, ry, rz) = (&mut row.rx[..], &mut row.ry[..], &mut row.rz[..]);
                    // Off the diagonal two rows share every j block: they go
                    // through the loop together, which halves the loads and
                    // stores of the reactions (the arithmetic, and so every
                    // bit, is that of two single rows on the same lanes).
                    if jt > t && i + 1 < end_i {
                        let (a0, a1) = match isa {
                            // SAFETY: as for `avx512::pairs` below, for both rows.
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx512 => unsafe {
                                avx512::pairs2(i, jt * tile, j_end, soa, eps2, base, rx, ry, rz)
                            },
                            Isa::Portable => {
                                portable::pairs2(i, jt * tile, j_end, soa, eps2, base, rx, ry, rz)
                            }
                        };
                        row.own[i - base] += a0;
                        row.own[i + 1 - base] += a1;
                        i += 2;
                        continue;
                    }
                    let j_start = if jt == t { i + 1 } else { jt * tile };
                    if j_start < j_end {
                        row.own[i - base] += match isa {
                            // SAFETY: the CPU supports AVX-512F (`isa`); j_end ≤ npad is a
                            // multiple of 8 and the reaction slices cover base..npad.
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx512 => unsafe {
                                avx512::pairs(i, j_start, j_end, soa, eps2, base, rx, ry, rz)
                            },
                            Isa::Portable => {
                                portable::pairs(i, j_start, j_end, soa, eps2, base, rx, ry, rz)
                            }
                        };
                    }
                    i += 1;
                }
            }
        });
        let rows = &self.rows;
        out.par_chunks_mut(tile).enumerate().for_each(|(t, chunk)| {
            let base = t * tile;
            for (k, a) in chunk.iter_mut().enumerate() {
                let i = base + k;
                let mut sum = rows[t].own[k];
                for (s, row) in rows[..=t].iter().enumerate() {
                    let r = i - s * tile;
                    sum += DVec3::new(row.rx[r], row.ry[r], row.rz[r]);
                }
                *a = sum;
            }
        });
    }
}

impl DirectGravity {
    /// The field of [`DirectGravity::inverse_square_field`] at `rows` of
    /// the sources only, into `out` (one per row): each row summed over
    /// every source, in the sources' order ([`portable::field_at`] or its
    /// AVX-512 twin), so a row's bits do not depend on which rows are asked
    /// for. A decomposed run's share: the rows of its rank's particles.
    pub(crate) fn inverse_square_rows(
        &mut self,
        position: &[DVec3],
        strength: &[f64],
        rows: &[usize],
        out: &mut [DVec3],
    ) {
        self.load_strengths(position, strength);
        let eps2 = self.softening * self.softening;
        field_rows(self.soa(), eps2, rows, out, isa());
    }

    /// Σ_{i ∈ rows} s_i Σ_{j≠i} s_j / (|r_j − r_i|² + ε²)^{1/2}, the rows
    /// in their order: [`DirectGravity::pair_potential_sum`]'s share of
    /// `rows`.
    pub(crate) fn pair_potential_rows(
        &mut self,
        position: &[DVec3],
        strength: &[f64],
        rows: &[usize],
    ) -> f64 {
        self.load_strengths(position, strength);
        let eps2 = self.softening * self.softening;
        let (soa, isa) = (self.soa(), isa());
        let per_i: Vec<f64> = rows
            .par_iter()
            .with_min_len(16)
            .map(|&i| {
                soa.m[i]
                    * match isa {
                        // SAFETY: as in `inverse_square_rows`.
                        #[cfg(target_arch = "x86_64")]
                        Isa::Avx512 => unsafe { avx512::potential_at(i, soa, eps2) },
                        Isa::Portable => portable::potential_at(i, soa, eps2),
                    }
            })
            .collect();
        per_i.iter().sum()
    }
}

/// The field at each of `rows` into `out`, each row over every particle of
/// `soa` in its order, two rows through each block of partners together
/// (each row the bits of the one-row kernel, whatever its neighbour: so a
/// row's bits do not depend on which rows are asked for).
fn field_rows(soa: Soa, eps2: f64, rows: &[usize], out: &mut [DVec3], isa: Isa) {
    out.par_chunks_mut(2)
        .zip(rows.par_chunks(2))
        .with_min_len(8)
        .for_each(|(a, i)| match (i, isa) {
            // SAFETY: the CPU supports AVX-512F (`isa`); slices are padded to 8.
            #[cfg(target_arch = "x86_64")]
            (&[i0, i1], Isa::Avx512) => {
                (a[0], a[1]) = unsafe { avx512::field_at2(i0, i1, soa, eps2) }
            }
            #[cfg(target_arch = "x86_64")]
            (&[i0], Isa::Avx512) => a[0] = unsafe { avx512::field_at(i0, soa, eps2) },
            (&[i0, i1], _) => (a[0], a[1]) = portable::field_at2(i0, i1, soa, eps2),
            (i, _) => a[0] = portable::field_at(i[0], soa, eps2),
        });
}

impl Interaction for DirectGravity {
    fn name(&self) -> &'static str {
        "gravity"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let mut field = vec![DVec3::ZERO; state.position.len()];
        match Whole::masses(state) {
            Whole {
                position,
                value,
                rows: Some((rows, _)),
            } => self.inverse_square_rows(&position, &value, &rows, &mut field),
            _ => {
                self.load(state);
                self.field(&mut field);
            }
        }
        for ((f, a), m) in force.iter_mut().zip(&field).zip(state.mass) {
            *f += *a * (self.g * m);
        }
    }

    /// U = −(G/2) Σ_i m_i Σ_{j≠i} m_j / (|r_j − r_i|² + ε²)^{1/2}, summed in a fixed order
    /// (on ranks, each rank's share: the sum over its own particles).
    fn potential_energy(&mut self, state: &State) -> f64 {
        let sum = match Whole::masses(state) {
            Whole {
                position,
                value,
                rows: Some((rows, _)),
            } => self.pair_potential_rows(&position, &value, &rows),
            _ => {
                self.load(state);
                self.potential_sum(state.position.len())
            }
        };
        -0.5 * self.g * sum
    }

    /// Decomposed over ranks: every rank gathers every particle's position
    /// and mass in id order ([`Whole`]) and sums the pull of all of them
    /// on each of its own particles, row by row; no ghosts.
    fn halo_reach(&self) -> Option<HaloReach> {
        Some(HaloReach::NONE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_bodies_attract_with_inverse_square() {
        let pos = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0)];
        let vel = [DVec3::ZERO; 2];
        let mass = [3.0, 5.0];
        let state = State::new(&pos, &vel, &mass, 0.0);
        let mut g = DirectGravity::new(0.5, 0.0);
        let mut f = [DVec3::ZERO; 2];
        g.add_forces(&state, &mut f);
        let expected = 0.5 * 3.0 * 5.0 / 4.0;
        assert!((f[0].x - expected).abs() < 1e-15 * expected);
        assert_eq!(f[1].x, -f[0].x);
        assert!((g.potential_energy(&state) + 0.5 * 15.0 / 2.0).abs() < 1e-15);
    }

    /// Positions spread over separations of twelve orders of magnitude.
    fn cloud(n: usize) -> (Vec<DVec3>, Vec<DVec3>, Vec<f64>) {
        let pos = (0..n)
            .map(|k| {
                let t = k as f64;
                let scale = 10f64.powf((k % 13) as f64 - 6.0);
                DVec3::new((2.1 * t).sin(), (1.7 * t).cos(), (0.3 * t).sin()) * scale
            })
            .collect();
        let mass = (0..n).map(|k| 1.0 + (k % 7) as f64).collect();
        (pos, vec![DVec3::ZERO; n], mass)
    }

    /// Exact Σ_{j≠i} m_j d / (d² + ε²)^{3/2}, term by term.
    fn exact_field(pos: &[DVec3], mass: &[f64], eps: f64, i: usize) -> DVec3 {
        let mut a = DVec3::ZERO;
        for j in 0..pos.len() {
            if j != i {
                let d = pos[j] - pos[i];
                let r2 = d.length_squared() + eps * eps;
                a += d * (mass[j] / (r2 * r2.sqrt()));
            }
        }
        a
    }

    /// The tiled pair-symmetric field (several tiles, the fast and the
    /// portable kernel) and the all-pairs field agree with the exact sum.
    #[test]
    fn every_kernel_agrees_with_the_exact_sum() {
        for n in [37, 203, 1500] {
            let (pos, vel, mass) = cloud(n);
            let state = State::new(&pos, &vel, &mass, 0.0);
            for eps in [0.0, 1e-3] {
                let mut g = DirectGravity::new(1.0, eps);
                g.load(&state);
                let mut isas = vec![Isa::Portable];
                if isa() != Isa::Portable {
                    isas.push(isa());
                }
                for &which in &isas {
                    let mut tiled = vec![DVec3::ZERO; n];
                    g.field_with(&mut tiled, which);
                    for i in 0..n {
                        let exact = exact_field(&pos, &mass, eps, i);
                        let all_pairs = match which {
                            #[cfg(target_arch = "x86_64")]
                            Isa::Avx512 => unsafe { avx512::field_at(i, g.soa(), eps * eps) },
                            Isa::Portable => portable::field_at(i, g.soa(), eps * eps),
                        };
                        for (name, a) in [("tiled", tiled[i]), ("all-pairs", all_pairs)] {
                            let err = (a - exact).length() / exact.length();
                            assert!(
                                err < 1e-13,
                                "{which:?} {name}, N = {n}, ε = {eps}, particle {i}: {err:.2e}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Two rows through each block of partners give each row the bits of
    /// the one-row kernel, at every level (so a rank's rows do not depend
    /// on which rows it holds).
    #[test]
    fn paired_rows_have_the_bits_of_single_rows() {
        let (pos, vel, mass) = cloud(203);
        let state = State::new(&pos, &vel, &mass, 0.0);
        let mut g = DirectGravity::new(1.0, 1e-3);
        g.load(&state);
        let eps2 = 1e-6;
        let mut isas = vec![Isa::Portable];
        if isa() != Isa::Portable {
            isas.push(isa());
        }
        for which in isas {
            for (i0, i1) in [(0, 1), (5, 150), (202, 7)] {
                let single = |i| match which {
                    #[cfg(target_arch = "x86_64")]
                    Isa::Avx512 => unsafe { avx512::field_at(i, g.soa(), eps2) },
                    Isa::Portable => portable::field_at(i, g.soa(), eps2),
                };
                let paired = match which {
                    #[cfg(target_arch = "x86_64")]
                    Isa::Avx512 => unsafe { avx512::field_at2(i0, i1, g.soa(), eps2) },
                    Isa::Portable => portable::field_at2(i0, i1, g.soa(), eps2),
                };
                assert_eq!(
                    paired,
                    (single(i0), single(i1)),
                    "{which:?} rows {i0}, {i1}"
                );
            }
            // Asked for in any order and number, a row is the same.
            let mut all = vec![DVec3::ZERO; 203];
            field_rows(
                g.soa(),
                eps2,
                &(0..203).collect::<Vec<_>>(),
                &mut all,
                which,
            );
            let some = [150, 3, 77];
            let mut three = vec![DVec3::ZERO; 3];
            field_rows(g.soa(), eps2, &some, &mut three, which);
            for (k, &i) in some.iter().enumerate() {
                assert_eq!(three[k], all[i], "{which:?} row {i}");
            }
        }
    }

    #[test]
    fn potential_agrees_with_the_exact_pair_sum() {
        let (pos, vel, mass) = cloud(203);
        let state = State::new(&pos, &vel, &mass, 0.0);
        for eps in [0.0, 1e-3] {
            let mut exact = 0.0;
            for i in 0..pos.len() {
                for j in i + 1..pos.len() {
                    exact -=
                        mass[i] * mass[j] / ((pos[j] - pos[i]).length_squared() + eps * eps).sqrt();
                }
            }
            let u = DirectGravity::new(1.0, eps).potential_energy(&state);
            // Both sides sum ~2·10⁴ positive terms in different orders.
            assert!(
                (u - exact).abs() < 1e-13 * exact.abs(),
                "ε = {eps}: U = {u}, exact {exact}"
            );
        }
    }

    /// Newton's third law holds exactly pair by pair: Σ m_i a_i = 0 to round-off.
    #[test]
    fn total_force_vanishes() {
        let n = 700;
        let pos: Vec<DVec3> = (0..n)
            .map(|k| {
                DVec3::new(
                    (k as f64 * 0.37).sin(),
                    (k as f64 * 1.3).cos(),
                    (k as f64 * 0.11).sin(),
                )
            })
            .collect();
        let vel = vec![DVec3::ZERO; n];
        let mass: Vec<f64> = (0..n).map(|k| 1.0 + (k % 3) as f64).collect();
        let state = State::new(&pos, &vel, &mass, 0.0);
        let mut f = vec![DVec3::ZERO; n];
        DirectGravity::new(1.0, 0.01).add_forces(&state, &mut f);
        let total: DVec3 = f.iter().copied().sum();
        let scale: f64 = f.iter().map(|v| v.length()).sum();
        assert!(total.length() < 1e-14 * scale, "{total} against {scale}");
    }
}
