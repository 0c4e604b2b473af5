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
    /// At a list build where the most particles a rank holds exceed the
    /// mean by this factor, the cuts between bricks shift so that each
    /// slab holds as many (default 1.1; 0: never).
    pub balance: Option<f64>,
}
