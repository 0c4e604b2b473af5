//! `[parallel]`: how a run on several MPI ranks cuts its box into bricks
//! (docs/parallel.md). One process reads the table and ignores it.

use serde::Deserialize;

/// `[parallel]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParallelTable {
    /// Bricks along x, y and z, their product the number of ranks
    /// (default: the grid of least brick surface for the box's shape).
    pub grid: Option<[usize; 3]>,
}
