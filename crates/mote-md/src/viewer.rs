//! What the live viewer asks of an interaction, as a capability of its
//! own: most interactions (pair forces, fields without a dial) have none,
//! so the force traits carry one query ([`crate::force::Interaction::viewer`],
//! [`crate::rigid::BodyInteraction::viewer_mut`]) instead of three hooks
//! every interaction must know of.

use glam::DVec3;

/// The walls an interaction draws, the loads on them, and the changes it
/// owns (a field's strength, a damping rate).
pub trait ViewerHooks {
    /// The walls where they are at time `t`.
    fn walls(&self, t: f64) -> Vec<mote_run::WallGeometry> {
        let _ = t;
        Vec::new()
    }
    /// The force the particles exert on each wall (name, force) at the
    /// last evaluation.
    fn wall_forces(&self) -> Vec<(String, DVec3)> {
        Vec::new()
    }
    /// Applies a change asked for from the live viewer when this
    /// interaction owns what it sets: `Some(what changed)`, or
    /// `Some(Err(why not))`; `None` when the change is not its business.
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        let _ = change;
        None
    }
}
