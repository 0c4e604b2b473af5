//! The listed pairs of granular contacts, in one order on one process and
//! on any number of ranks.
//!
//! The particles a list reads are its rows, in order of their ids (on one
//! process the particles themselves; on a rank its own particles and one
//! copy of each other rank's particle near its brick). Pair (a, b) is
//! listed in row a, the lower id, its partners b in increasing order: the
//! pairs stand in order of their two ids. A contact is evaluated from its
//! lower id's side (the same operations wherever it is evaluated: once on
//! one process, on each rank that holds one of its particles in a
//! decomposed run). Particle a sums the contacts of its row in order; the
//! contacts of the rows before it where it is the partner wait in its
//! inbox, in order of those rows, and it sums them too. So each particle's
//! force is the same sum in the same order whatever the decomposition and
//! whenever the lists were built: the same bits on one process and on any
//! number of ranks.
//!
//! A pair's history is carried from one list to the next by its ids (a
//! merge of two sorted lists); histories restored from a checkpoint, and
//! those a particle brings from another rank, wait until their pairs are
//! listed. Pairs that do not touch hold the zero history, so the touching
//! pairs' entries are the whole state a checkpoint needs.

use std::sync::OnceLock;

use super::history::{history_of, PAIR_ROW};
use super::law::History;

/// Marks a row that is a copy of another rank's particle.
pub const GHOST: u32 = u32::MAX;

/// The rows and pairs of a contact list, with the pairs' histories.
#[derive(Debug, Clone, Default)]
pub struct ContactPairs {
    /// The id of each row, increasing.
    row_id: Vec<u32>,
    /// This rank's particle each row is, or [`GHOST`].
    pub particle: Vec<u32>,
    /// The row of each of this rank's particles.
    pub row: Vec<u32>,
    /// `partner[start[a]..start[a + 1]]`: the rows b > a paired with a.
    pub start: Vec<u32>,
    pub partner: Vec<u32>,
    /// History of each pair.
    pub history: Vec<History>,
    /// Whether each pair touched at the last evaluation; only those
    /// entries' histories are read or cleared.
    pub touching: Vec<bool>,
    /// `inbox_pair[inbox_start[p]..inbox_start[p + 1]]`: the pairs where
    /// this rank's particle p is the partner, in order of their rows.
    pub inbox_start: Vec<u32>,
    pub inbox_pair: Vec<u32>,
    /// Each pair's place in its partner's inbox ([`GHOST`] where the
    /// partner is a copy).
    pub inbox_slot: Vec<u32>,
    /// Histories waiting for their pairs to be listed.
    pending: Vec<([u64; 2], History)>,
    /// (id, pair) for each of this rank's particles in each pair, by id:
    /// made when a particle first leaves after a build.
    by_id: OnceLock<Vec<(u64, u32)>>,
}

impl ContactPairs {
    /// Number of listed pairs.
    pub fn len(&self) -> usize {
        self.partner.len()
    }

    pub fn is_empty(&self) -> bool {
        self.partner.is_empty()
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.row_id.len()
    }

    /// The number of this rank's particles.
    pub fn own(&self) -> usize {
        self.row.len()
    }

    /// Whether row a is one of this rank's particles: its pairs count
    /// here, for energies and the virial (each pair on one rank).
    pub fn counts(&self, a: usize) -> bool {
        self.particle[a] != GHOST
    }

    /// The ids of pair s of row a.
    fn key(&self, a: usize, s: usize) -> [u64; 2] {
        [
            self.row_id[a] as u64,
            self.row_id[self.partner[s] as usize] as u64,
        ]
    }

    /// Moves onto a fresh list: rows of ids `row_id` (increasing), each
    /// this rank's particle `particle[r]` or [`GHOST`], for `own`
    /// particles; row a's partners `partner[start[a]..start[a + 1]]`, each
    /// above a, increasing. Carries the histories of pairs still listed,
    /// then places waiting ones.
    pub fn rebuild(
        &mut self,
        row_id: Vec<u32>,
        particle: Vec<u32>,
        own: usize,
        start: Vec<u32>,
        partner: Vec<u32>,
    ) {
        debug_assert!(row_id.windows(2).all(|w| w[0] < w[1]));
        let m = partner.len();
        let mut history = vec![History::default(); m];
        let mut touching = vec![false; m];
        // The old pairs and the new, both in order of their ids.
        let old = &*self;
        let old_keys = (0..old.rows()).flat_map(|a| {
            (old.start[a] as usize..old.start[a + 1] as usize).map(move |s| (old.key(a, s), s))
        });
        let new_keys = (0..row_id.len()).flat_map(|a| {
            let (row_id, partner) = (&row_id, &partner);
            (start[a] as usize..start[a + 1] as usize)
                .map(move |s| ([row_id[a] as u64, row_id[partner[s] as usize] as u64], s))
        });
        let mut old_keys = old_keys.peekable();
        for (k, s) in new_keys {
            while old_keys.next_if(|(o, _)| *o < k).is_some() {}
            if let Some((_, o)) = old_keys.next_if(|(o, _)| *o == k) {
                history[s] = old.history[o];
                touching[s] = old.touching[o];
            }
        }
        drop(old_keys);
        let mut row = vec![0u32; own];
        for (r, p) in particle.iter().enumerate() {
            if *p != GHOST {
                row[*p as usize] = r as u32;
            }
        }
        // Each particle's inbox: the pairs of the rows before its own,
        // in row order.
        let mut inbox_start = vec![0u32; own + 1];
        for &b in &partner {
            if particle[b as usize] != GHOST {
                inbox_start[particle[b as usize] as usize + 1] += 1;
            }
        }
        for p in 0..own {
            inbox_start[p + 1] += inbox_start[p];
        }
        let mut fill = inbox_start.clone();
        let mut inbox_pair = vec![0u32; inbox_start[own] as usize];
        let mut inbox_slot = vec![GHOST; m];
        for (s, &b) in partner.iter().enumerate() {
            let p = particle[b as usize];
            if p != GHOST {
                let e = &mut fill[p as usize];
                inbox_pair[*e as usize] = s as u32;
                inbox_slot[s] = *e;
                *e += 1;
            }
        }
        (self.row_id, self.particle, self.row) = (row_id, particle, row);
        (self.start, self.partner) = (start, partner);
        (self.history, self.touching) = (history, touching);
        (self.inbox_start, self.inbox_pair, self.inbox_slot) =
            (inbox_start, inbox_pair, inbox_slot);
        for (k, h) in std::mem::take(&mut self.pending) {
            if let Some(s) = self.find(k) {
                self.history[s] = h;
                self.touching[s] = true;
            }
        }
        self.by_id = OnceLock::new();
    }

    /// The pair of ids `k` (lower first), if listed.
    fn find(&self, k: [u64; 2]) -> Option<usize> {
        let id = |i: u64| u32::try_from(i).ok();
        let a = self.row_id.binary_search(&id(k[0])?).ok()?;
        let b = self.row_id.binary_search(&id(k[1])?).ok()? as u32;
        let row = self.start[a] as usize..self.start[a + 1] as usize;
        let at = self.partner[row.clone()].binary_search(&b).ok()?;
        Some(row.start + at)
    }

    /// The history of the pair of particles with ids i and j, if listed.
    pub fn get(&self, i: u64, j: u64) -> Option<History> {
        let k = if i < j { [i, j] } else { [j, i] };
        self.find(k).map(|s| self.history[s])
    }

    /// Appends a checkpoint row (id i, id j, ξ, ψ) per touching pair that
    /// counts here, in order.
    pub fn write_rows(&self, out: &mut Vec<f64>) {
        for a in (0..self.rows()).filter(|&a| self.counts(a)) {
            for s in self.start[a] as usize..self.start[a + 1] as usize {
                if self.touching[s] {
                    let ([i, j], h) = (self.key(a, s), self.history[s]);
                    out.extend([i as f64, j as f64]);
                    out.extend(h.shear.to_array());
                    out.extend(h.roll.to_array());
                }
            }
        }
    }

    /// Reads rows written by [`ContactPairs::write_rows`]; they are placed
    /// when their pairs are next listed.
    pub fn restore_rows(&mut self, rows: &[f64]) -> Result<(), String> {
        if !rows.len().is_multiple_of(PAIR_ROW) {
            return Err(format!(
                "contact history: rows of {PAIR_ROW} numbers expected"
            ));
        }
        self.pending.clear();
        for r in rows.chunks(PAIR_ROW) {
            let (i, j) = (r[0], r[1]);
            let whole = |x: f64| x >= 0.0 && x.fract() == 0.0 && x < u32::MAX as f64;
            if !whole(i) || !whole(j) || i >= j {
                return Err(format!("contact history names pair ({i}, {j})"));
            }
            self.pending
                .push(([i as u64, j as u64], history_of(&r[2..])));
        }
        Ok(())
    }

    /// Appends, for particle `id` leaving this rank, (partner id, ξ, ψ)
    /// for each of its touching pairs.
    pub fn pack(&self, id: u64, out: &mut Vec<f64>) {
        let by_id = self.by_id.get_or_init(|| {
            let mut v: Vec<(u64, u32)> = Vec::new();
            for a in 0..self.rows() {
                for s in self.start[a] as usize..self.start[a + 1] as usize {
                    let k = self.key(a, s);
                    let rows = [a, self.partner[s] as usize];
                    for side in 0..2 {
                        if self.counts(rows[side]) {
                            v.push((k[side], s as u32));
                        }
                    }
                }
            }
            v.sort_unstable();
            v
        });
        let first = by_id.partition_point(|e| e.0 < id);
        let mut write = |k: [u64; 2], h: &History| {
            out.push(if k[0] == id { k[1] } else { k[0] } as f64);
            out.extend(h.shear.to_array());
            out.extend(h.roll.to_array());
        };
        for &(_, s) in by_id[first..].iter().take_while(|e| e.0 == id) {
            let s = s as usize;
            if self.touching[s] {
                let a = self.start.partition_point(|&x| x as usize <= s) - 1;
                write(self.key(a, s), &self.history[s]);
            }
        }
        // A particle passing on at the same build took its histories in
        // from the rank before.
        for (k, h) in self.pending.iter().filter(|(k, _)| k.contains(&id)) {
            write(*k, h);
        }
    }

    /// Takes in what [`ContactPairs::pack`] wrote for particle `id`.
    pub fn arrive(&mut self, id: u64, data: &[f64]) {
        for r in data.chunks_exact(PAIR_ROW - 1) {
            let partner = r[0] as u64;
            let k = if id < partner {
                [id, partner]
            } else {
                [partner, id]
            };
            self.pending.push((k, history_of(&r[1..])));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn h(x: f64) -> History {
        History {
            shear: DVec3::splat(x),
            roll: DVec3::ZERO,
        }
    }

    /// One process's list of four particles: rows are the particles.
    fn list(start: &[u32], partner: &[u32]) -> (Vec<u32>, Vec<u32>, usize, Vec<u32>, Vec<u32>) {
        (
            (0..4).collect(),
            (0..4).collect(),
            4,
            start.to_vec(),
            partner.to_vec(),
        )
    }

    fn rebuild(p: &mut ContactPairs, l: (Vec<u32>, Vec<u32>, usize, Vec<u32>, Vec<u32>)) {
        p.rebuild(l.0, l.1, l.2, l.3, l.4);
    }

    /// A rebuild keeps the histories of pairs still listed and drops the
    /// others; checkpoint rows come back into pairs listed later; each
    /// particle's inbox holds its lower partners' pairs in their order.
    #[test]
    fn histories_follow_their_pairs_and_inboxes_are_in_row_order() {
        let mut p = ContactPairs::default();
        // (0, 1), (0, 3), (1, 2).
        rebuild(&mut p, list(&[0, 2, 3, 3, 3], &[1, 3, 2]));
        p.history[1] = h(3.0); // (0, 3)
        p.touching[1] = true;
        p.history[2] = h(2.0); // (1, 2)
        p.touching[2] = true;
        // Rebuilt: (0, 3) kept, (1, 2) dropped, (0, 2) and (2, 3) new.
        rebuild(&mut p, list(&[0, 2, 2, 3, 3], &[2, 3, 3]));
        assert_eq!(p.get(3, 0), Some(h(3.0)));
        assert_eq!(p.get(0, 2), Some(History::default()));
        assert_eq!(p.get(1, 2), None);
        // Particle 3's inbox: pairs (0, 3) then (2, 3); 2's: (0, 2).
        let inbox =
            |q: usize| &p.inbox_pair[p.inbox_start[q] as usize..p.inbox_start[q + 1] as usize];
        assert_eq!(inbox(3), &[1, 2]);
        assert_eq!(inbox(2), &[0]);
        assert!(inbox(0).is_empty() && inbox(1).is_empty());
        assert_eq!(
            p.inbox_slot,
            vec![p.inbox_start[2], p.inbox_start[3], p.inbox_start[3] + 1]
        );

        let mut rows = Vec::new();
        p.write_rows(&mut rows);
        assert_eq!(rows.len(), PAIR_ROW);
        let mut q = ContactPairs::default();
        q.restore_rows(&rows).unwrap();
        assert_eq!(q.get(0, 3), None, "not listed yet");
        q.rebuild(vec![0, 3], vec![0, 1], 2, vec![0, 1, 1], vec![1]);
        assert_eq!(q.get(0, 3), Some(h(3.0)));
        assert!(q.touching[0]);
        assert!(q.restore_rows(&rows[..5]).is_err());
        let mut bad = rows.clone();
        bad[0] = 3.0;
        assert!(q.restore_rows(&bad).is_err(), "(3, 3) is no pair");
    }

    /// A particle leaving a rank takes its touching pairs' histories, and
    /// the rank it reaches places them once the pairs are listed there; a
    /// rank counts the pairs whose lower id is its own.
    #[test]
    fn histories_travel_with_their_particles() {
        let mut a = ContactPairs::default();
        // Rank a holds particles 5 (its particle 0) and 9 (1); 7 is a copy.
        // Rows by id: 5, 7, 9; pairs (5, 7), (5, 9), (7, 9).
        a.rebuild(
            vec![5, 7, 9],
            vec![0, GHOST, 1],
            2,
            vec![0, 2, 3, 3],
            vec![1, 2, 2],
        );
        a.touching.iter_mut().for_each(|t| *t = true);
        a.history = vec![h(1.0), h(2.0), h(3.0)];
        assert!(a.counts(0) && !a.counts(1) && a.counts(2));
        assert_eq!(a.row, vec![0, 2]);
        let mut out = Vec::new();
        a.pack(9, &mut out);
        assert_eq!(out.len(), 2 * (PAIR_ROW - 1));
        let mut b = ContactPairs::default();
        b.arrive(9, &out);
        // On b, 9 is its particle 0, 5 and 7 copies.
        b.rebuild(
            vec![5, 7, 9],
            vec![GHOST, GHOST, 0],
            1,
            vec![0, 1, 2, 2],
            vec![2, 2],
        );
        assert_eq!(b.get(5, 9), Some(h(2.0)));
        assert_eq!(b.get(9, 7), Some(h(3.0)));
        assert_eq!(b.inbox_pair, vec![0, 1]);
    }
}
