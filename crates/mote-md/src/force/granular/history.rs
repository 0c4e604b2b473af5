//! Contact histories beside a half neighbour list, shared by the contacts
//! of spheres ([`super::GranularContacts`]) and of rigid clumps
//! (`rigid::contacts`).
//!
//! Pair (i, j), j > i, has its entry k in `start[i]..start[i + 1]` with
//! `partner[k] = j`, partners sorted: the force loop reads the history
//! beside the list without a search. When the list is rebuilt the entries
//! of pairs still listed are carried over, a merge of the two sorted
//! partner lists; a pair leaves the list only when it is farther apart than
//! the skin, long after its contact has ended. Pairs that do not touch hold
//! the zero history, so the touching pairs' entries are the whole state a
//! checkpoint needs.

use std::ops::Range;

use glam::DVec3;

use super::law::History;

/// Numbers per pair in a checkpoint row: i, j, ξ (3), ψ (3).
pub const PAIR_ROW: usize = 8;

/// The histories of the listed pairs.
#[derive(Debug, Clone)]
pub struct PairHistories {
    start: Vec<u32>,
    partner: Vec<u32>,
    /// History of each listed pair.
    pub history: Vec<History>,
    /// Whether each listed pair touched at the last evaluation; only those
    /// entries' histories are read or cleared.
    pub touching: Vec<bool>,
    /// Histories restored from a checkpoint, placed once their pairs are listed.
    pending: Vec<(u32, u32, History)>,
}

impl Default for PairHistories {
    fn default() -> Self {
        Self {
            start: vec![0],
            partner: Vec::new(),
            history: Vec::new(),
            touching: Vec::new(),
            pending: Vec::new(),
        }
    }
}

impl PairHistories {
    /// Number of listed pairs.
    pub fn len(&self) -> usize {
        self.partner.len()
    }

    pub fn is_empty(&self) -> bool {
        self.partner.is_empty()
    }

    /// Number of rows (particles) of the list.
    pub fn rows(&self) -> usize {
        self.start.len() - 1
    }

    /// The entries of row i.
    pub fn range(&self, i: usize) -> Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// The partner of entry k.
    pub fn partner(&self, k: usize) -> u32 {
        self.partner[k]
    }

    /// The row starts (`rows() + 1` of them).
    pub fn starts(&self) -> &[u32] {
        &self.start
    }

    /// Moves onto a freshly built list, carrying the histories of the pairs
    /// still listed, then placing restored ones. Rows are independent:
    /// blocks of rows merge in parallel.
    pub fn carry_to(&mut self, start: &[u32], partner: &[u32]) {
        use rayon::prelude::*;
        const ROWS: usize = 2048;
        let mut history = vec![History::default(); partner.len()];
        let mut touching = vec![false; partner.len()];
        let rows = start.len().saturating_sub(1);
        let firsts: Vec<usize> = (0..=rows.div_ceil(ROWS))
            .map(|b| (b * ROWS).min(rows))
            .collect();
        let blocks = split_blocks(&mut history, &mut touching, start, &firsts);
        let old = &*self;
        blocks
            .into_par_iter()
            .enumerate()
            .for_each(|(block, (history, touching))| {
                let base = start[firsts[block]] as usize;
                for i in firsts[block]..firsts[block + 1].min(old.rows()) {
                    let (mut a, a_end) = (old.start[i] as usize, old.start[i + 1] as usize);
                    let (mut b, b_end) = (start[i] as usize, start[i + 1] as usize);
                    while a < a_end && b < b_end {
                        match old.partner[a].cmp(&partner[b]) {
                            std::cmp::Ordering::Less => a += 1,
                            std::cmp::Ordering::Greater => b += 1,
                            std::cmp::Ordering::Equal => {
                                history[b - base] = old.history[a];
                                touching[b - base] = old.touching[a];
                                a += 1;
                                b += 1;
                            }
                        }
                    }
                }
            });
        self.start.clear();
        self.start.extend_from_slice(start);
        self.partner.clear();
        self.partner.extend_from_slice(partner);
        self.history = history;
        self.touching = touching;
        self.place_pending();
    }

    /// Keeps the rows of the particles with `keep[i]`, renumbered in
    /// order (particle i becomes the number of kept ones before it), and
    /// the pairs of two kept particles with their histories: the list as
    /// it stands after particles were taken out, until the next build
    /// (which merges with it as with any list). Restored rows not yet
    /// placed are renumbered too.
    pub fn retain(&mut self, keep: &[bool]) {
        let mut new_index = Vec::with_capacity(keep.len());
        let mut kept = 0u32;
        for &k in keep {
            new_index.push(if k { kept } else { u32::MAX });
            kept += u32::from(k);
        }
        let renumber = |i: u32| new_index.get(i as usize).copied().unwrap_or(u32::MAX);
        let (mut start, mut partner) = (vec![0u32], Vec::new());
        let (mut history, mut touching) = (Vec::new(), Vec::new());
        for i in 0..self.rows().min(keep.len()) {
            if !keep[i] {
                continue;
            }
            for k in self.range(i) {
                let j = renumber(self.partner[k]);
                if j != u32::MAX {
                    partner.push(j);
                    history.push(self.history[k]);
                    touching.push(self.touching[k]);
                }
            }
            start.push(partner.len() as u32);
        }
        (self.start, self.partner) = (start, partner);
        (self.history, self.touching) = (history, touching);
        self.pending.retain_mut(|(i, j, _)| {
            (*i, *j) = (renumber(*i), renumber(*j));
            *i != u32::MAX && *j != u32::MAX
        });
    }

    /// The entry of pair (i, j), if listed.
    pub fn find(&self, i: usize, j: usize) -> Option<usize> {
        let (i, j) = if i < j { (i, j) } else { (j, i) };
        if i + 1 >= self.start.len() {
            return None;
        }
        let range = self.range(i);
        let k = self.partner[range.clone()]
            .binary_search(&(j as u32))
            .ok()?;
        Some(range.start + k)
    }

    /// The history of pair (i, j), if listed.
    pub fn get(&self, i: usize, j: usize) -> Option<History> {
        self.find(i, j).map(|k| self.history[k])
    }

    /// Appends a checkpoint row (i, j, ξ, ψ) per touching pair, in list order.
    pub fn write_rows(&self, out: &mut Vec<f64>) {
        for i in 0..self.rows() {
            for k in self.range(i) {
                if self.touching.get(k) == Some(&true) {
                    let h = self.history[k];
                    out.extend([i as f64, self.partner[k] as f64]);
                    out.extend(h.shear.to_array());
                    out.extend(h.roll.to_array());
                }
            }
        }
    }

    /// Reads rows written by [`PairHistories::write_rows`] for `n`
    /// particles; they are placed when their pairs are next listed.
    pub fn restore_rows(&mut self, rows: &[f64], n: usize) -> Result<(), String> {
        if !rows.len().is_multiple_of(PAIR_ROW) {
            return Err(format!(
                "contact history: rows of {PAIR_ROW} numbers expected"
            ));
        }
        self.pending.clear();
        for r in rows.chunks(PAIR_ROW) {
            let (i, j) = (r[0] as usize, r[1] as usize);
            if i >= n || j >= n || i >= j {
                return Err(format!("contact history names pair ({i}, {j})"));
            }
            self.pending.push((i as u32, j as u32, history_of(&r[2..])));
        }
        self.place_pending();
        Ok(())
    }

    /// Puts restored histories into the list (every touching pair is
    /// listed, since touching means closer than the cut-off).
    fn place_pending(&mut self) {
        if self.pending.is_empty() || self.is_empty() {
            return;
        }
        for (i, j, h) in std::mem::take(&mut self.pending) {
            if let Some(k) = self.find(i as usize, j as usize) {
                self.history[k] = h;
                self.touching[k] = true;
            }
        }
    }
}

/// The history of six numbers ξ, ψ.
pub fn history_of(r: &[f64]) -> History {
    History {
        shear: DVec3::new(r[0], r[1], r[2]),
        roll: DVec3::new(r[3], r[4], r[5]),
    }
}

/// The first row of each of `blocks` blocks of a half list's rows, and n:
/// blocks of equal numbers of listed pairs. A half list lists pair (i, j)
/// at the lower index, so rows shrink along the particles: blocks of equal
/// numbers of particles left the first of two blocks three quarters of the
/// pairs (and two threads 1.26 times as fast as one). The split depends on
/// the list alone, never on the thread count.
pub fn block_firsts(start: &[u32], blocks: usize) -> Vec<usize> {
    let n = start.len() - 1;
    let pairs = start[n] as usize;
    let mut firsts: Vec<usize> = (0..blocks)
        .map(|b| {
            start
                .partition_point(|&s| (s as usize) < b * pairs / blocks)
                .min(n)
        })
        .collect();
    firsts.push(n);
    firsts
}

/// The histories and touching flags of each block of rows (`firsts` from
/// [`block_firsts`], `start` the rows' starts), as disjoint slices that
/// blocks of a parallel loop advance each on its own.
pub fn split_blocks<'h>(
    history: &'h mut [History],
    touching: &'h mut [bool],
    start: &[u32],
    firsts: &[usize],
) -> Vec<(&'h mut [History], &'h mut [bool])> {
    let mut blocks = Vec::with_capacity(firsts.len().saturating_sub(1));
    let (mut rest, mut rest_touching) = (history, touching);
    let mut taken = start[firsts[0]] as usize;
    for &next in &firsts[1..] {
        let end = start[next] as usize;
        let (head, tail) = rest.split_at_mut(end - taken);
        let (head_touching, tail_touching) = rest_touching.split_at_mut(end - taken);
        blocks.push((head, head_touching));
        (rest, rest_touching) = (tail, tail_touching);
        taken = end;
    }
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h(x: f64) -> History {
        History {
            shear: DVec3::splat(x),
            roll: DVec3::ZERO,
        }
    }

    /// A rebuild keeps the histories of pairs still listed and drops the
    /// others; checkpoint rows come back into a list built later.
    #[test]
    fn histories_follow_their_pairs_through_rebuilds_and_checkpoints() {
        let mut p = PairHistories::default();
        // Row 0: partners 1, 3; row 1: partner 2; row 2: none.
        p.carry_to(&[0, 2, 3, 3], &[1, 3, 2]);
        p.history[1] = h(3.0); // (0, 3)
        p.touching[1] = true;
        p.history[2] = h(2.0); // (1, 2)
        p.touching[2] = true;
        // Rebuilt: (0, 3) kept, (1, 2) dropped, (0, 2) and (2, 3) new.
        p.carry_to(&[0, 2, 2, 3], &[2, 3, 3]);
        assert_eq!(p.get(0, 3), Some(h(3.0)));
        assert_eq!(p.get(3, 0), Some(h(3.0)));
        assert_eq!(p.get(0, 2), Some(History::default()));
        assert_eq!(p.get(1, 2), None);
        let mut rows = Vec::new();
        p.write_rows(&mut rows);
        assert_eq!(rows.len(), PAIR_ROW);

        let mut q = PairHistories::default();
        q.restore_rows(&rows, 4).unwrap();
        assert_eq!(q.get(0, 3), None, "not listed yet");
        q.carry_to(&[0, 1, 1, 1], &[3]);
        assert_eq!(q.get(0, 3), Some(h(3.0)));
        assert!(q.touching[0]);
        assert!(q.restore_rows(&rows[..5], 4).is_err());
        assert!(q.restore_rows(&rows, 2).is_err());
    }

    /// Taking particles out keeps the pairs of those that stay, with their
    /// histories, under the kept particles' new numbers.
    #[test]
    fn histories_follow_their_pairs_when_particles_are_taken_out() {
        let mut p = PairHistories::default();
        // Pairs (0, 1), (0, 3), (1, 2), (2, 3).
        p.carry_to(&[0, 2, 3, 4, 4], &[1, 3, 2, 3]);
        for (k, x) in [1.0, 3.0, 2.0, 5.0].into_iter().enumerate() {
            p.history[k] = h(x);
            p.touching[k] = true;
        }
        p.retain(&[true, false, true, true]);
        // 0 → 0, 2 → 1, 3 → 2: (0, 3) is (0, 2), (2, 3) is (1, 2).
        assert_eq!((p.rows(), p.len()), (3, 2));
        assert_eq!(p.get(0, 2), Some(h(3.0)));
        assert_eq!(p.get(1, 2), Some(h(5.0)));
        assert_eq!(p.get(0, 1), None);
        // A list built after, with a new particle 3 beside 2, carries them.
        p.carry_to(&[0, 1, 2, 3, 3], &[2, 2, 3]);
        assert_eq!(p.get(0, 2), Some(h(3.0)));
        assert_eq!(p.get(1, 2), Some(h(5.0)));
        assert_eq!(p.get(2, 3), Some(History::default()));
    }

    /// Blocks of a half list's rows split its pairs evenly, not its
    /// particles: rows shrinking along the particles (row i of n holding
    /// n − 1 − i pairs) give the first of two blocks ~29 % of the
    /// particles; the bounds run from 0 to n in order, and an empty list
    /// puts every block at 0.
    #[test]
    fn blocks_hold_equal_numbers_of_pairs() {
        let n = 1000usize;
        let mut start = vec![0u32];
        for i in 0..n {
            start.push(start[i] + (n - 1 - i) as u32);
        }
        let pairs = start[n] as usize;
        for blocks in 1..6 {
            let firsts = block_firsts(&start, blocks);
            assert_eq!((firsts[0], firsts[blocks]), (0, n));
            assert!(firsts.windows(2).all(|w| w[0] <= w[1]), "{firsts:?}");
            for b in 0..blocks {
                let held = (start[firsts[b + 1]] - start[firsts[b]]) as usize;
                let share = held as f64 * blocks as f64 / pairs as f64;
                assert!((share - 1.0).abs() < 0.01, "block {b} of {blocks}: {share}");
            }
        }
        let two = block_firsts(&start, 2);
        assert!((two[1] as f64 / n as f64 - (1.0 - 0.5f64.sqrt())).abs() < 0.01);
        assert_eq!(block_firsts(&[0; 11], 3), vec![0, 0, 0, 10]);
    }
}
