//! The whole system as a sum over all pairs reads it: every particle's
//! position and one property in id order — the state's own in one process,
//! gathered to every rank ([`crate::domain::gathered`]) in a decomposed run,
//! with the indices of this rank's particles in it. The Ewald sums and the
//! open-space sums (gravity, Coulomb's law) decompose this way: each rank
//! evaluates the rows of its own particles against all.

use glam::DVec3;

use super::State;

/// Every particle's position and `value`, in id order.
pub(crate) struct Whole<T> {
    pub position: Vec<DVec3>,
    pub value: Vec<T>,
    /// On ranks: this rank's particles' indices in the whole (in its own
    /// order), and whether it is rank 0 (which counts the whole system's
    /// terms once).
    pub rows: Option<(Vec<usize>, bool)>,
}

impl<T: Copy> Whole<T> {
    fn of<const K: usize>(
        state: &State,
        own: &[T],
        pack: impl Fn(DVec3, T) -> [f64; K],
        unpack: impl Fn(&[f64; K]) -> T,
    ) -> Self {
        match (state.halo, state.comm) {
            (Some(halo), Some(comm)) => {
                let all = crate::domain::gathered(
                    state.position.iter().zip(own).map(|(r, v)| pack(*r, *v)),
                    halo,
                    comm,
                    halo.total,
                );
                Whole {
                    position: all.iter().map(|a| DVec3::new(a[0], a[1], a[2])).collect(),
                    value: all.iter().map(unpack).collect(),
                    rows: Some((
                        halo.id.iter().map(|&id| id as usize).collect(),
                        comm.rank() == 0,
                    )),
                }
            }
            _ => Whole {
                position: state.position.to_vec(),
                value: own.to_vec(),
                rows: None,
            },
        }
    }
}

impl Whole<f64> {
    /// Positions and charges.
    pub fn charges(state: &State) -> Self {
        Self::of(state, state.charges(), |r, q| [r.x, r.y, r.z, q], |a| a[3])
    }

    /// Positions and masses.
    pub fn masses(state: &State) -> Self {
        Self::of(state, state.mass, |r, m| [r.x, r.y, r.z, m], |a| a[3])
    }
}

impl Whole<DVec3> {
    /// Positions and magnetic moments.
    pub fn dipoles(state: &State) -> Self {
        Self::of(
            state,
            state.dipole,
            |r, m| [r.x, r.y, r.z, m.x, m.y, m.z],
            |a| DVec3::new(a[3], a[4], a[5]),
        )
    }
}
