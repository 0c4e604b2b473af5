//! Where a run's wall time goes, part by part — LAMMPS's timing breakdown
//! at the end of a run (Pair, Neigh, Modify, Output, Other): each
//! interaction's force passes, the neighbour list's checks and builds, and
//! what the step does besides (integration, thermostat), so that a run
//! that does not speed up with threads says which part stops it.

use std::time::{Duration, Instant};

/// Wall time spent in each interaction's force passes and in the shared
/// neighbour list, summed over a run.
#[derive(Debug, Clone, Default)]
pub struct Timing {
    /// One per interaction, in the force field's order.
    pub interactions: Vec<Duration>,
    /// Checks of the shared list and its builds.
    pub neighbours: Duration,
    /// Builds of the shared list (LAMMPS's "Neighbor list builds").
    pub builds: u64,
}

impl Timing {
    /// Adds the time since `since` to interaction `k`.
    pub(crate) fn interaction(&mut self, k: usize, since: Instant) {
        if self.interactions.len() <= k {
            self.interactions.resize(k + 1, Duration::ZERO);
        }
        self.interactions[k] += since.elapsed();
    }
}

/// A run's wall time in parts, as the summary gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct Breakdown {
    /// (part, seconds), in the order the summary lists them.
    pub parts: Vec<(String, f64)>,
    /// The whole run's wall seconds.
    pub wall: f64,
}

/// "1 build", "N builds": a list's builds as the summary names them.
pub fn builds(n: u64) -> String {
    if n == 1 {
        "1 build".into()
    } else {
        format!("{n} builds")
    }
}

impl Breakdown {
    /// The parts of a run of `wall` seconds whose steps took `stepping`:
    /// the interactions by name (those of one name together), the shared
    /// neighbour list (where there is one), the rest of the steps, and what the run did between
    /// steps (measuring, writing, checkpoints).
    pub fn new(names: &[&str], timing: &Timing, stepping: Duration, wall: Duration) -> Breakdown {
        let mut parts: Vec<(String, f64)> = Vec::new();
        for (name, t) in names.iter().zip(&timing.interactions) {
            match parts.iter_mut().find(|(n, _)| n == name) {
                Some(p) => p.1 += t.as_secs_f64(),
                None => parts.push((name.to_string(), t.as_secs_f64())),
            }
        }
        let forces: f64 = parts.iter().map(|p| p.1).sum();
        // A run without the shared list (all pairs; rigid contacts, whose
        // list is theirs) has no part for it.
        let neighbours = timing.neighbours.as_secs_f64();
        if neighbours > 0.0 {
            parts.push((
                format!("neighbour list ({})", builds(timing.builds)),
                neighbours,
            ));
        }
        let steps = stepping.as_secs_f64();
        parts.push((
            "integration and the rest of the steps".into(),
            (steps - forces - neighbours).max(0.0),
        ));
        let wall = wall.as_secs_f64();
        parts.push(("measuring and writing".into(), (wall - steps).max(0.0)));
        Breakdown { parts, wall }
    }

    /// One sentence: each part's share of the wall time.
    pub fn sentence(&self) -> String {
        let shares: Vec<String> = self
            .parts
            .iter()
            .map(|(name, s)| format!("{name} {:.1} %", 100.0 * s / self.wall.max(1e-12)))
            .collect();
        format!("Wall time: {}.", shares.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parts add up to the wall time: interactions of one name
    /// together, the rest of the steps what their parts leave, the time
    /// between steps what the steps leave.
    #[test]
    fn the_parts_add_up_to_the_wall_time() {
        let ms = Duration::from_millis;
        let timing = Timing {
            interactions: vec![ms(300), ms(100), ms(200)],
            neighbours: ms(50),
            builds: 7,
        };
        let b = Breakdown::new(
            &["granular", "walls", "granular"],
            &timing,
            ms(900),
            ms(1000),
        );
        let names: Vec<&str> = b.parts.iter().map(|p| p.0.as_str()).collect();
        assert_eq!(
            names,
            [
                "granular",
                "walls",
                "neighbour list (7 builds)",
                "integration and the rest of the steps",
                "measuring and writing"
            ]
        );
        let secs: Vec<f64> = b.parts.iter().map(|p| p.1).collect();
        for (got, want) in secs.iter().zip([0.5, 0.1, 0.05, 0.25, 0.1]) {
            assert!((got - want).abs() < 1e-12, "{secs:?}");
        }
        assert!((secs.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let without_list = Timing {
            neighbours: Duration::ZERO,
            ..timing.clone()
        };
        let names: Vec<String> = Breakdown::new(&["gravity"], &without_list, ms(900), ms(1000))
            .parts
            .into_iter()
            .map(|p| p.0)
            .collect();
        assert_eq!(
            names,
            [
                "gravity",
                "integration and the rest of the steps",
                "measuring and writing"
            ]
        );
        assert_eq!(
            b.sentence(),
            "Wall time: granular 50.0 %, walls 10.0 %, neighbour list (7 builds) 5.0 %, integration and the rest of the steps 25.0 %, measuring and writing 10.0 %."
        );
        assert_eq!(
            (builds(1), builds(0)),
            ("1 build".into(), "0 builds".into())
        );
    }
}
