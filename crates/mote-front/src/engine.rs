//! Which engine a scene describes.

/// The engines `mote run` drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// Point particles with fixed-step integrators or Brownian dynamics
    /// (gravity, springs, Lennard-Jones, granular contacts, dipoles).
    Particles,
    /// Rigid clumps of overlapping spheres moved by the FRBI (`[rigid]`).
    Rigid,
    /// Event-driven hard spheres and disks (mote-edmd).
    EventDriven,
    /// Packings by growing hard spheres (`[packing]`, Lubachevsky–Stillinger).
    Packing,
}

/// Top-level keys of the first event-driven scene format, beside the
/// hard-sphere keys `[event_driven]` now holds
/// ([`mote_edmd::scene::EVENT_DRIVEN_KEYS`]).
const EVENT_DRIVEN_LEGACY_KEYS: &[&str] = &[
    "output_interval",
    "time",
    "equilibrate",
    "histogram",
    "trajectory",
    "observables",
];

impl Engine {
    /// Every engine, in the order `mote examples` lists them.
    pub const ALL: [Engine; 4] = [
        Engine::Particles,
        Engine::Rigid,
        Engine::EventDriven,
        Engine::Packing,
    ];

    /// The engine of a TOML scene: `[rigid]` means rigid bodies,
    /// `[packing]` a packing by growth; the keys
    /// of an event-driven scene (or a `box` given as a list of lengths)
    /// mean hard spheres; anything else is a point-particle scene. A text
    /// that is not TOML is left to the point-particle parser, whose error
    /// names the line.
    pub fn of_scene(text: &str) -> Engine {
        let Ok(table) = text.parse::<toml::Table>() else {
            return Engine::Particles;
        };
        if table.contains_key("rigid") {
            Engine::Rigid
        } else if table.contains_key("packing") {
            Engine::Packing
        } else if table.contains_key("event_driven")
            || mote_edmd::scene::EVENT_DRIVEN_KEYS
                .iter()
                .chain(EVENT_DRIVEN_LEGACY_KEYS)
                .any(|k| *k != "box" && table.contains_key(*k))
            || table.get("box").is_some_and(|b| b.is_array())
        {
            Engine::EventDriven
        } else {
            Engine::Particles
        }
    }

    /// The tables that name an engine: a scene holds at most one (none is
    /// a point-particle scene).
    const TABLES: [(&'static str, Engine); 3] = [
        ("rigid", Engine::Rigid),
        ("event_driven", Engine::EventDriven),
        ("packing", Engine::Packing),
    ];

    /// Refuses a scene with two engine tables (`[rigid]` and `[packing]`,
    /// say), naming the second's line and the engine the first chose: a
    /// scene runs one engine. Text that is not TOML is left to the parser
    /// that names its line.
    pub fn check_one(label: &str, text: &str) -> Result<(), crate::FrontError> {
        let Ok(table) = text.parse::<toml::Table>() else {
            return Ok(());
        };
        let source = mote_io::Source::new(label, text);
        let mut named = Engine::TABLES
            .iter()
            .filter(|(key, _)| table.contains_key(*key))
            .map(|&(key, engine)| (source.table_line(key), key, engine))
            .collect::<Vec<_>>();
        named.sort_by_key(|n| n.0);
        if let [(first_line, first, engine), (line, second, _), ..] = named[..] {
            return Err(crate::FrontError::request(format!(
                "{label}:{line}: [{second}] beside [{first}] (line {first_line}): a scene runs one engine, and [{first}] chose {}; give each its own scene",
                engine.title()
            )));
        }
        Ok(())
    }

    /// The heading `mote examples` groups this engine's examples under.
    pub fn title(self) -> &'static str {
        match self {
            Engine::Particles => "point particles (fixed-step integrators, Brownian dynamics)",
            Engine::Rigid => "rigid clumps of spheres (Fast Rigid Bodies Integrator)",
            Engine::EventDriven => "hard spheres and disks (event-driven)",
            Engine::Packing => "packings by growing spheres (Lubachevsky–Stillinger)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn engines_of_the_built_in_examples() {
        for e in crate::examples::all() {
            assert_eq!(Engine::of_scene(&e.text), e.engine, "example {}", e.name);
        }
    }

    #[test]
    fn a_list_box_is_event_driven_a_table_box_is_not() {
        assert_eq!(
            Engine::of_scene("box = [1.0, 1.0, 1.0]\n"),
            Engine::EventDriven
        );
        assert_eq!(
            Engine::of_scene("[box]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\n"),
            Engine::Particles
        );
        assert_eq!(Engine::of_scene("[rigid]\n"), Engine::Rigid);
    }

    #[test]
    fn a_scene_with_two_engine_tables_is_refused_at_the_second() {
        let text = "seed = 1\n[packing]\nn = 100\n\n[event_driven]\nn = 10\n";
        let e = Engine::check_one("two.toml", text).unwrap_err().to_string();
        assert!(
            e.contains(
                "two.toml:5: [event_driven] beside [packing] (line 2): a scene runs one engine"
            ),
            "{e}"
        );
        assert!(Engine::check_one("one.toml", "[rigid]\n[run]\ndt = 1.0\n").is_ok());
        for e in crate::examples::all() {
            assert!(Engine::check_one(&e.name, &e.text).is_ok(), "{}", e.name);
        }
    }
}
