//! Which engine a scene describes, and the scene envelope's check.

use std::collections::BTreeMap;

use toml::Spanned;

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

/// Top-level keys of the first event-driven scene format, and the
/// spelling every engine now uses for each (the hard-sphere keys
/// themselves go in `[event_driven]`).
const OLD_SPELLINGS: &[(&str, &str)] = &[
    (
        "time",
        "write [run] until = (the end time, the equilibration included)",
    ),
    ("equilibrate", "write [run] equilibrate = (time)"),
    ("output_interval", "write [output] interval = (simulated time)"),
    (
        "trajectory",
        "write [output] trajectory = true/false (trajectory.xyz; trajectory_format picks dump, gsd or vtk)",
    ),
    (
        "observables",
        "write [output] observables = true/false (observables.csv)",
    ),
    (
        "histogram",
        "write [output] histogram = true/false (speeds.csv)",
    ),
];

impl Engine {
    /// Every engine, in the order `mote examples` lists them.
    pub const ALL: [Engine; 4] = [
        Engine::Particles,
        Engine::Rigid,
        Engine::EventDriven,
        Engine::Packing,
    ];

    /// The engine of a TOML scene, from its one engine table: `[rigid]`
    /// rigid bodies, `[packing]` a packing by growth, `[event_driven]` hard
    /// spheres; none, point particles. A text that is not TOML is left to
    /// the point-particle parser, whose error names the line.
    pub fn of_scene(text: &str) -> Engine {
        let Ok(table) = text.parse::<toml::Table>() else {
            return Engine::Particles;
        };
        Engine::TABLES
            .iter()
            .find(|(key, _)| table.contains_key(*key))
            .map_or(Engine::Particles, |(_, engine)| *engine)
    }

    /// The tables that name an engine: a scene holds at most one (none is
    /// a point-particle scene).
    const TABLES: [(&'static str, Engine); 3] = [
        ("rigid", Engine::Rigid),
        ("event_driven", Engine::EventDriven),
        ("packing", Engine::Packing),
    ];

    /// The scene envelope's check, then the engine ([`Engine::of_scene`]):
    /// a scene names at most one engine table (a second is refused at its
    /// line, with the engine the first chose), and the top-level keys of
    /// the first event-driven format are refused at their line with the
    /// spelling that replaced them. Text that is not TOML is left to the
    /// parser that names its line.
    pub fn read(label: &str, text: &str) -> Result<Engine, crate::FrontError> {
        type TopLevel = BTreeMap<Spanned<String>, toml::Value>;
        let Ok(top) = toml::from_str::<TopLevel>(text) else {
            return Ok(Engine::of_scene(text));
        };
        let source = mote_io::Source::new(label, text);
        let mut keys: Vec<_> = top.iter().collect();
        keys.sort_by_key(|(k, _)| k.span().start);
        for (key, value) in keys {
            let k = key.get_ref().as_str();
            let why = if let Some((_, spelling)) = OLD_SPELLINGS.iter().find(|(old, _)| *old == k) {
                format!(
                    "`{k}` is a key of the first event-driven format, no longer read: {spelling}"
                )
            } else if k == "box" && value.is_array() || k == "boundary" {
                format!("`{k}`: {}", mote_edmd::scene::BOX_SPELLING)
            } else if k == "file" {
                format!("`{k}`: {}", mote_edmd::scene::FILE_SPELLING)
            } else if mote_edmd::scene::EVENT_DRIVEN_KEYS.contains(&k) {
                format!("`{k}` says what the hard spheres are: it goes in [event_driven]")
            } else {
                continue;
            };
            return Err(crate::FrontError::Parse(source.error(key.span(), why)));
        }
        let mut named = Engine::TABLES
            .iter()
            .filter(|(key, _)| top.keys().any(|k| k.get_ref() == key))
            .map(|&(key, engine)| (source.table_line(key), key, engine))
            .collect::<Vec<_>>();
        named.sort_by_key(|n| n.0);
        if let [(first_line, first, engine), (line, second, _), ..] = named[..] {
            return Err(crate::FrontError::request(format!(
                "{label}:{line}: [{second}] beside [{first}] (line {first_line}): a scene runs one engine, and [{first}] chose {}; give each its own scene",
                engine.title()
            )));
        }
        Ok(named.first().map_or(Engine::Particles, |n| n.2))
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
    fn the_engine_is_the_one_engine_table() {
        let table_box = "[box]\nlo = [0.0, 0.0, 0.0]\nhi = [1.0, 1.0, 1.0]\n";
        assert_eq!(Engine::of_scene(table_box), Engine::Particles);
        assert_eq!(Engine::of_scene("[rigid]\n"), Engine::Rigid);
        assert_eq!(
            Engine::of_scene("[event_driven]\nn = 10\n"),
            Engine::EventDriven
        );
        assert_eq!(Engine::of_scene("[packing]\n"), Engine::Packing);
    }

    #[test]
    fn a_scene_with_two_engine_tables_is_refused_at_the_second() {
        let text = "seed = 1\n[packing]\nn = 100\n\n[event_driven]\nn = 10\n";
        let e = Engine::read("two.toml", text).unwrap_err().to_string();
        assert!(
            e.contains(
                "two.toml:5: [event_driven] beside [packing] (line 2): a scene runs one engine"
            ),
            "{e}"
        );
        assert_eq!(
            Engine::read("one.toml", "[rigid]\n[run]\ndt = 1.0\n").unwrap(),
            Engine::Rigid
        );
        for e in crate::examples::all() {
            assert_eq!(
                Engine::read(&e.name, &e.text).unwrap(),
                e.engine,
                "{}",
                e.name
            );
        }
    }

    /// The first event-driven format's top-level keys are refused at
    /// their line, each with the spelling that replaced it.
    #[test]
    fn old_spellings_are_refused_with_the_new_one() {
        let e = |text: &str| Engine::read("old.toml", text).unwrap_err().to_string();
        assert_eq!(
            e("title = 'x'\nn = 500\npacking_fraction = 0.2\n"),
            "old.toml:2: `n` says what the hard spheres are: it goes in [event_driven]"
        );
        assert_eq!(
            Engine::read(
                "new.toml",
                "[event_driven]\nn = 500\n[box]\nhi = [9.0, 9.0, 9.0]\n"
            )
            .unwrap(),
            Engine::EventDriven,
            "a key after [event_driven] is the table's, not the top level's"
        );
        assert_eq!(
            e("time = 4.0\n[event_driven]\nn = 500\n"),
            "old.toml:1: `time` is a key of the first event-driven format, no longer read: write [run] until = (the end time, the equilibration included)"
        );
        assert!(e("box = [1.0, 1.0, 1.0]\n")
            .starts_with("old.toml:1: `box`: the box is a table of its own"));
        assert!(e("seed = 2\nfile = \"a.xyz\"\n").starts_with(
            "old.toml:2: `file`: a scene starts from a file as every engine spells it: [[from_file]]"
        ));
        assert!(e("output_interval = 0.5\n").contains("write [output] interval"));
    }
}
