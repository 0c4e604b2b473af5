//! Particles stored in space order: rows sorted along a Morton (Z-order)
//! curve of cells one particle diameter wide, so that particles near in
//! space are near in memory and a pair sweep's partners come from a few
//! cache lines, not from the whole system (LAMMPS's `atom_modify sort`,
//! done once, when a scene is built).
//!
//! The rigid engine sorts its bodies the same way, on cells one largest
//! bounding diameter wide, and so the spheres its contacts sweep.
//!
//! The rows' order is the particles' ids, which fix the order of every sum
//! (one process, threads and ranks alike); the scene's numbering is kept
//! beside them ([`crate::particles::System::number`]) for files, probes
//! and messages.

use glam::DVec3;
use serde::Deserialize;

use crate::tree::morton;

/// How a scene's particles or bodies are stored (`[granular] order`,
/// `[rigid] order`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParticleOrder {
    /// Along a Morton curve of cells one diameter wide.
    #[default]
    Space,
    /// As the scene gave them.
    File,
}

/// The rows in space order: row k of the sorted particles is row
/// `order[k]` of the given ones. Cells are one largest diameter wide
/// (the mean spacing where the particles are points), counted from the
/// corner of the particles' bounding box; within a cell the given order
/// stays.
pub fn space_order(position: &[DVec3], radius: &[f64]) -> Vec<usize> {
    let n = position.len();
    if n < 2 {
        return (0..n).collect();
    }
    let lo = position.iter().fold(DVec3::INFINITY, |a, r| a.min(*r));
    let hi = position.iter().fold(DVec3::NEG_INFINITY, |a, r| a.max(*r));
    let extent = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let diameter = 2.0 * radius.iter().fold(0.0_f64, |a, r| a.max(*r));
    let spacing = (extent.x * extent.y * extent.z / n as f64).cbrt();
    // At most 2²¹ cells an axis, the keys' width.
    let widest = extent.max_element() / ((1u64 << morton::BITS) - 1) as f64;
    let cell = if diameter > 0.0 { diameter } else { spacing }.max(widest);
    let key = |r: DVec3| {
        let c = ((r - lo) / cell).floor();
        morton::key(c.x as u64, c.y as u64, c.z as u64)
    };
    let mut order: Vec<usize> = (0..n).collect();
    let keys: Vec<u64> = position.iter().map(|r| key(*r)).collect();
    order.sort_by_key(|&i| keys[i]);
    order
}

/// `values` in the rows' new order: element k is `values[order[k]]`.
pub fn gathered<T: Clone>(values: &[T], order: &[usize]) -> Vec<T> {
    if values.is_empty() {
        return Vec::new();
    }
    order.iter().map(|&i| values[i].clone()).collect()
}

/// The inverse permutation: the new row of given row i is `rows[i]`.
pub fn new_rows(order: &[usize]) -> Vec<usize> {
    let mut rows = vec![0; order.len()];
    for (k, &i) in order.iter().enumerate() {
        rows[i] = k;
    }
    rows
}

/// Whether a checkpoint names the order it stores its particles or
/// bodies in (one written before scenes were stored in space order names
/// none, and was written in the scene's order).
pub fn names_order(cp: &mote_io::checkpoint::Checkpoint) -> bool {
    cp.carried
        .iter()
        .any(|(k, _)| k == crate::simulation::ORDER_KEY)
}

/// Checks that a checkpoint stores its `what` ("particles", "bodies") in
/// the order a build does: both in the scene's (`number` empty, no
/// order saved), or both in the same space order. `table` names the key
/// that sets it (`[granular] order`).
pub fn check_saved_order(
    cp: &mote_io::checkpoint::Checkpoint,
    number: &[u64],
    what: &str,
    table: &str,
) -> Result<(), String> {
    let saved = cp
        .carried
        .iter()
        .find(|(k, _)| k == crate::simulation::ORDER_KEY);
    match saved {
        None if number.is_empty() => Ok(()),
        None => Err(format!(
            "the checkpoint stores the {what} in the scene's order, and this build in space order ({table})"
        )),
        Some(_) if number.is_empty() => Err(format!(
            "the checkpoint stores the {what} in space order, and this build in the scene's ({table} = \"file\")"
        )),
        Some((_, saved)) => {
            let same = saved.len() == number.len()
                && saved.iter().zip(number).all(|(a, b)| *a == *b as f64);
            if same {
                Ok(())
            } else {
                Err(format!(
                    "the checkpoint stores the {what} in another space order than this build: it was written from another scene"
                ))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic lattice given in a scrambled order comes back in space
    /// order: each octant of the lattice is one run of rows, and every row
    /// appears once.
    #[test]
    fn a_scrambled_lattice_comes_back_octant_by_octant() {
        let side = 8;
        let mut position = Vec::new();
        for i in 0..side * side * side {
            // A fixed scramble: 101 is prime to 512.
            let k = (i * 101) % (side * side * side);
            let (x, y, z) = (k % side, (k / side) % side, k / (side * side));
            position.push(DVec3::new(x as f64, y as f64, z as f64));
        }
        let radius = vec![0.5; position.len()];
        let order = space_order(&position, &radius);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..position.len()).collect::<Vec<_>>());
        let octant =
            |r: DVec3| (r.x >= 4.0) as u8 * 4 + (r.y >= 4.0) as u8 * 2 + (r.z >= 4.0) as u8;
        let octants: Vec<u8> = order.iter().map(|&i| octant(position[i])).collect();
        for (run, rows) in octants.chunks(64).enumerate() {
            assert!(
                rows.iter().all(|o| *o as usize == run),
                "run {run}: {rows:?}"
            );
        }
        // Consecutive rows lie close: in Z order a step is one lattice
        // spacing half the time, and their mean distance is a fraction of
        // the scrambled order's.
        let mean_step = |rows: &[usize]| {
            let sum: f64 = rows
                .windows(2)
                .map(|w| position[w[0]].distance(position[w[1]]))
                .sum();
            sum / (rows.len() - 1) as f64
        };
        let scrambled: Vec<usize> = (0..position.len()).collect();
        let (sorted, given) = (mean_step(&order), mean_step(&scrambled));
        assert!(
            sorted < 2.0 && sorted < 0.3 * given,
            "{sorted} against {given}"
        );
        // And the inverse puts every row back.
        let rows = new_rows(&order);
        assert!((0..order.len()).all(|i| order[rows[i]] == i));
    }

    /// Points without radii are ordered on cells of their mean spacing,
    /// and one or no particle is its own order.
    #[test]
    fn points_and_tiny_systems() {
        assert_eq!(space_order(&[], &[]), Vec::<usize>::new());
        assert_eq!(space_order(&[DVec3::ONE], &[0.0]), vec![0]);
        let position = [
            DVec3::new(9.0, 9.0, 9.0),
            DVec3::ZERO,
            DVec3::new(0.5, 0.0, 0.0),
        ];
        assert_eq!(space_order(&position, &[0.0; 3]), vec![1, 2, 0]);
    }
}
