//! Damped springs between particle pairs (002 Eq. 4):
//!
//! F_i = Σ_j [ D_ij (x_j − x_i)/|x_j − x_i| (|x_j − x_i| − l_ij) + c_ij (v_j − v_i) ],
//!
//! with stiffness D, damping c (along the full relative velocity, as in the
//! seed) and rest length l; F_j = −F_i for each spring. In a periodic box
//! x_j − x_i is the minimum image, so a spring may cross the box's faces.
//!
//! On MPI ranks each rank evaluates, in the network's order, the springs
//! with an end among its particles — the other end a ghost, whose position
//! and velocity come with the halo ([`crate::domain::Motion`]) — each as
//! one process does from end i's side, and adds the force to the ends it
//! holds: every particle's force is one process's sum in one process's
//! order, so the trajectory has its bits on any rank count. A spring
//! counts its energy and virial at end i's rank.

use glam::DVec3;

use super::{HaloReach, Interaction, State, Virial};
use crate::domain::Halo;

/// One spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    pub i: usize,
    pub j: usize,
    /// Stiffness D.
    pub stiffness: f64,
    /// Damping coefficient c.
    pub damping: f64,
    /// Rest length l.
    pub rest_length: f64,
}

/// All springs of a mass–spring network.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpringNetwork {
    pub springs: Vec<Spring>,
    /// W = Σ r_ij · F_ij of the last force evaluation.
    pub virial: f64,
    /// On a rank: where each spring's ends are, as of a halo's build.
    ends: Option<Ends>,
}

/// Where a particle of a spring is on this rank.
#[derive(Debug, Clone, Copy, PartialEq)]
enum At {
    /// This rank's particle p.
    Own(usize),
    /// Ghost g of the halo (its motion).
    Ghost(usize),
    /// Not within the halo.
    Away,
}

/// The springs a rank evaluates, as of the halo's build `generation`:
/// each with an end among its particles, in the network's order, with
/// where its two ends are.
#[derive(Debug, Clone, PartialEq)]
struct Ends {
    generation: u64,
    springs: Vec<(usize, [At; 2])>,
}

impl Ends {
    fn of(springs: &[Spring], halo: &Halo) -> Self {
        let mut at = vec![At::Away; halo.total];
        for (g, ghost) in halo.ghosts.iter().enumerate() {
            at[ghost.id as usize] = At::Ghost(g);
        }
        for (p, &id) in halo.id.iter().enumerate() {
            at[id as usize] = At::Own(p);
        }
        let own = |e: At| matches!(e, At::Own(_));
        Ends {
            generation: halo.generation,
            springs: springs
                .iter()
                .enumerate()
                .map(|(k, s)| (k, [at[s.i], at[s.j]]))
                .filter(|(_, e)| own(e[0]) || own(e[1]))
                .collect(),
        }
    }
}

impl SpringNetwork {
    /// Elastic plus damping force on particle i of one spring whose
    /// separation is d = x_j − x_i.
    #[inline]
    fn force_on_i(s: &Spring, d: DVec3, vi: DVec3, vj: DVec3) -> DVec3 {
        let len = d.length();
        let elastic = if len > 0.0 {
            d * (s.stiffness * (len - s.rest_length) / len)
        } else {
            DVec3::ZERO
        };
        elastic + (vj - vi) * s.damping
    }
}

impl Interaction for SpringNetwork {
    fn name(&self) -> &'static str {
        "springs"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let image = state.boundary.image();
        let mut virial = 0.0;
        self.each(state, |s, [i, j], xi, xj, vi, vj| {
            let d = image.apply(xj - xi);
            let f = Self::force_on_i(s, d, vi, vj);
            if let Some(i) = i {
                force[i] += f;
                // r_ij · F_ij with r_ij = x_i − x_j = −d and F_ij = f on i.
                virial -= d.dot(f);
            }
            if let Some(j) = j {
                force[j] -= f;
            }
        });
        self.virial = virial;
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        let image = state.boundary.image();
        let mut w = Virial::default();
        self.each(state, |s, [i, _], xi, xj, vi, vj| {
            if i.is_some() {
                let d = image.apply(xj - xi);
                w += Virial::pair(-d, Self::force_on_i(s, d, vi, vj));
            }
        });
        Some(w)
    }

    /// U = Σ ½ D (|x_j − x_i| − l)².
    fn potential_energy(&mut self, state: &State) -> f64 {
        let image = state.boundary.image();
        let mut u = 0.0;
        self.each(state, |s, [i, _], xi, xj, _, _| {
            if i.is_some() {
                let stretch = image.apply(xj - xi).length() - s.rest_length;
                u += 0.5 * s.stiffness * stretch * stretch;
            }
        });
        u
    }

    /// Decomposed over ranks: the ghosts reach twice the longest rest
    /// length (with their motion forwarded), so a spring is evaluated
    /// where either end is until it stretches past that; a spring longer
    /// still gives its ends a non-finite force, which ends the run naming
    /// the particle, never a silently missing force.
    fn halo_reach(&self) -> Option<HaloReach> {
        let longest = self
            .springs
            .iter()
            .map(|s| s.rest_length)
            .fold(0.0, f64::max);
        (longest > 0.0 || self.springs.is_empty()).then_some(HaloReach {
            cutoff: SPRING_REACH * longest,
            skin: 0.25 * longest,
            every: 0,
            moments: false,
            motion: true,
        })
    }
}

/// The ghosts of a decomposed run reach this many times the longest rest
/// length.
const SPRING_REACH: f64 = 2.0;

impl SpringNetwork {
    /// The springs of a network, none of them placed on ranks yet.
    pub fn new(springs: Vec<Spring>) -> Self {
        Self {
            springs,
            virial: 0.0,
            ends: None,
        }
    }

    /// Calls `f(spring, [i, j], x_i, x_j, v_i, v_j)` for every spring this
    /// evaluation has, in the network's order, with the indices of its
    /// ends among the state's particles where they are this rank's: all
    /// of them in one process; on a rank, those with an end of its own,
    /// the other end's motion from the halo (NaN where it is beyond it).
    fn each(
        &mut self,
        state: &State,
        mut f: impl FnMut(&Spring, [Option<usize>; 2], DVec3, DVec3, DVec3, DVec3),
    ) {
        let (x, v) = (state.position, state.velocity);
        let Some(halo) = state.halo else {
            for s in &self.springs {
                f(s, [Some(s.i), Some(s.j)], x[s.i], x[s.j], v[s.i], v[s.j]);
            }
            return;
        };
        if self.ends.as_ref().map(|e| e.generation) != Some(halo.generation) {
            self.ends = Some(Ends::of(&self.springs, halo));
        }
        let motion = |at: At| match at {
            At::Own(p) => (Some(p), x[p], v[p]),
            At::Ghost(g) => match halo.motion.get(g) {
                Some(m) => (None, m.position, m.velocity),
                None => (None, DVec3::NAN, DVec3::NAN),
            },
            At::Away => (None, DVec3::NAN, DVec3::NAN),
        };
        for &(k, [a, b]) in &self.ends.as_ref().expect("placed above").springs {
            let ((i, xi, vi), (j, xj, vj)) = (motion(a), motion(b));
            f(&self.springs[k], [i, j], xi, xj, vi, vj);
        }
    }
}
