//! Global damping (MPPphys `damp`): F_i = −γ v_i on every particle.

use glam::DVec3;

use super::{Interaction, State, ViewerHooks, Virial};

/// Viscous drag with coefficient γ (force per velocity), the same for all particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalDamping {
    pub gamma: f64,
}

impl Interaction for GlobalDamping {
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        Some(self)
    }

    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    /// Not part of the pressure (see [`Interaction::virial`]).
    fn virial(&self) -> Option<f64> {
        Some(0.0)
    }

    fn virial_tensor(&mut self, _: &State) -> Option<Virial> {
        Some(Virial::default())
    }

    /// A force on each particle alone.
    fn halo_reach(&self) -> Option<super::HaloReach> {
        Some(super::HaloReach::NONE)
    }

    fn name(&self) -> &'static str {
        "damping"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        for (f, v) in force.iter_mut().zip(state.velocity) {
            *f -= *v * self.gamma;
        }
    }

    fn potential_energy(&mut self, _state: &State) -> f64 {
        0.0
    }
}

impl ViewerHooks for GlobalDamping {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        match change {
            mote_run::Change::Damping(gamma) => {
                let text = format!("damping γ {} → {gamma}", self.gamma);
                self.gamma = *gamma;
                Some(Ok(text))
            }
            _ => None,
        }
    }
}
