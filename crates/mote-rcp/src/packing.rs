//! The 1-D rod packing of Farr & Groot (J. Chem. Phys. 131, 244104 (2009); 003, §IV.1).
//!
//! Rods are placed longest first, each into the currently largest gap, at the leftmost
//! admissible position; every gap must be at least f times the shorter of its two
//! neighbouring rods (f = 0.7654 for spheres). Inserting rod L into the largest gap G
//! replaces G by a left gap fL and a right gap max(fL, G − (f + 1)L) (the gap is widened,
//! and the periodic line lengthened, when G < (2f + 1)L). The estimate is
//! φ = ΣL / (ΣL + Σgaps).
//!
//! Only the multiset of gap lengths matters, so no positions are kept. Because the rods
//! come in non-increasing order, every gap present after rod i is at least f·L_i: a new
//! left gap fL_{i+1} is never larger than any gap present. The snug gaps fL therefore
//! enter a FIFO queue in sorted order, and only the slack gaps G − (f + 1)L need a binary
//! heap: O(N log N) time at worst, O(N) memory.

use std::collections::{BinaryHeap, VecDeque};

use crate::error::RcpError;

/// Default gap fraction f for spheres (Farr & Groot 2009; 003).
pub const SPHERE_GAP_FRACTION: f64 = 0.7654;

/// The outcome of a rod packing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Packing {
    /// The estimate of the random close packing fraction, ΣL / (ΣL + Σgaps).
    pub phi: f64,
    /// Number of rods.
    pub rods: usize,
    /// ΣL.
    pub rod_length: f64,
    /// Σgaps (the length of the periodic line is ΣL + Σgaps).
    pub gap_length: f64,
}

/// Packs rods streamed longest first; see the module documentation.
///
/// ```
/// use mote_rcp::RodPacker;
/// let mut packer = RodPacker::new(0.7654);
/// for l in [1.0, 0.8, 0.5, 0.1] {
///     packer.push(l);
/// }
/// let p = packer.finish();
/// assert!(p.phi > 0.0 && p.phi < 1.0);
/// ```
#[derive(Debug, Clone)]
pub struct RodPacker {
    f: f64,
    /// Snug gaps (= f·L of the rod that made them), largest at the front.
    snug: VecDeque<f64>,
    /// Slack gaps, as the bits of positive f64 (ordered like the values).
    slack: BinaryHeap<u64>,
    rods: usize,
    rod_length: f64,
    last: f64,
}

impl RodPacker {
    /// A packer with gap fraction `f` (≥ 0; not checked here, see [`pack_rods`]).
    pub fn new(f: f64) -> Self {
        Self::with_capacity(f, 0)
    }

    /// A packer with room for `n` rods.
    pub fn with_capacity(f: f64, n: usize) -> Self {
        RodPacker {
            f,
            snug: VecDeque::with_capacity(n),
            slack: BinaryHeap::with_capacity(n / 2),
            rods: 0,
            rod_length: 0.0,
            last: f64::INFINITY,
        }
    }

    /// Inserts the next rod, which must not be longer than the previous one.
    #[inline]
    pub fn push(&mut self, l: f64) {
        debug_assert!(l <= self.last);
        self.last = l;
        self.rods += 1;
        self.rod_length += l;
        let f = self.f;
        let g1 = f * l;
        if self.rods == 1 {
            // One rod on a periodic line: a single gap of f·L.
            self.snug.push_back(g1);
            return;
        }
        // Take the largest gap.
        let front = self.snug.front().copied().unwrap_or(0.0);
        let top = self.slack.peek().map(|&b| f64::from_bits(b)).unwrap_or(0.0);
        let from_heap = top > front;
        let g = if from_heap { top } else { front };
        let g2 = if (2.0 * f + 1.0) * l >= g {
            g1
        } else {
            g - (f + 1.0) * l
        };
        let g2_slack = g2 > g1;
        match (from_heap, g2_slack) {
            (true, true) => {
                if let Some(mut t) = self.slack.peek_mut() {
                    *t = g2.to_bits();
                }
            }
            (true, false) => {
                self.slack.pop();
                self.snug.push_back(g2);
            }
            (false, true) => {
                self.snug.pop_front();
                self.slack.push(g2.to_bits());
            }
            (false, false) => {
                self.snug.pop_front();
                self.snug.push_back(g2);
            }
        }
        self.snug.push_back(g1);
    }

    /// Number of rods so far.
    pub fn len(&self) -> usize {
        self.rods
    }

    /// True before the first rod.
    pub fn is_empty(&self) -> bool {
        self.rods == 0
    }

    /// The packing fraction of the rods so far.
    pub fn finish(&self) -> Packing {
        let gaps =
            sum(self.snug.iter().copied()) + sum(self.slack.iter().map(|&b| f64::from_bits(b)));
        Packing {
            phi: self.rod_length / (self.rod_length + gaps),
            rods: self.rods,
            rod_length: self.rod_length,
            gap_length: gaps,
        }
    }
}

/// Compensated (Neumaier) sum, so that Σgaps does not depend on storage order.
fn sum(values: impl Iterator<Item = f64>) -> f64 {
    let mut s = 0.0f64;
    let mut c = 0.0f64;
    for v in values {
        let t = s + v;
        if s.abs() >= v.abs() {
            c += (s - t) + v;
        } else {
            c += (v - t) + s;
        }
        s = t;
    }
    s + c
}

/// Packs a given list of rods (longest first) with gap fraction f.
///
/// Errors if there are fewer than 2 rods, if f is negative or not finite, or if the
/// rods are not finite, non-negative and non-increasing.
pub fn pack_rods(rods: &[f64], f: f64) -> Result<Packing, RcpError> {
    check_gap_fraction(f)?;
    if rods.len() < 2 {
        return Err(RcpError::TooFewRods { n: rods.len() });
    }
    let mut prev = f64::INFINITY;
    for (i, &l) in rods.iter().enumerate() {
        if !(l.is_finite() && l >= 0.0 && l <= prev) {
            return Err(RcpError::BadRod {
                index: i + 1,
                length: l,
            });
        }
        prev = l;
    }
    let mut packer = RodPacker::with_capacity(f, rods.len());
    for &l in rods {
        packer.push(l);
    }
    Ok(packer.finish())
}

pub(crate) fn check_gap_fraction(f: f64) -> Result<(), RcpError> {
    if f.is_finite() && f >= 0.0 {
        Ok(())
    } else {
        Err(RcpError::BadGapFraction { f })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_rods_are_all_snug() {
        // Equal rods: every gap is f·L, so φ = 1/(1 + f).
        let p = pack_rods(&[1.0; 10], 0.5).unwrap();
        assert!((p.phi - 1.0 / 1.5).abs() < 1e-15);
    }

    #[test]
    fn two_rods_by_hand() {
        // Rod 1 (L=1) leaves a gap 0.5. Rod 2 (L=0.1): G = 0.5 ≥ 2·0.1·... (2f+1)L = 0.2 < 0.5,
        // so gaps 0.05 and 0.5 − 0.15 = 0.35. φ = 1.1/(1.1 + 0.4).
        let p = pack_rods(&[1.0, 0.1], 0.5).unwrap();
        assert!((p.phi - 1.1 / 1.5).abs() < 1e-15);
    }
}
