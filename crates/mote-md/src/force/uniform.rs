//! A uniform gravitational field (MPPphys `grav`): F_i = m_i g.

use glam::DVec3;

use super::{Interaction, State, ViewerHooks, Virial};

/// Uniform acceleration g acting on every particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformField {
    pub g: DVec3,
}

impl Interaction for UniformField {
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
        "uniform_field"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        for (f, m) in force.iter_mut().zip(state.mass) {
            *f += self.g * *m;
        }
    }

    /// U = −Σ m_i g·x_i.
    fn potential_energy(&mut self, state: &State) -> f64 {
        -state
            .position
            .iter()
            .zip(state.mass)
            .map(|(x, m)| m * self.g.dot(*x))
            .sum::<f64>()
    }
}

impl ViewerHooks for UniformField {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        match change {
            mote_run::Change::Field {
                kind: mote_run::FieldKind::Gravity,
                value,
            } => {
                let g = DVec3::from(*value);
                let text = format!(
                    "gravity g {} → {}",
                    super::vector_text(self.g),
                    super::vector_text(g)
                );
                self.g = g;
                Some(Ok(text))
            }
            _ => None,
        }
    }
}
