//! The built-in examples of every engine: scene files compiled in from
//! examples/ (point particles at the top, rigid/, edmd/ and packing/ below).

use crate::engine::Engine;

/// A built-in example: its name, engine, one-line description and scene text.
pub struct Example {
    pub name: String,
    pub engine: Engine,
    pub description: String,
    pub text: String,
}

macro_rules! scene {
    ($name:literal, $path:literal) => {
        ($name, include_str!(concat!("../../../examples/", $path)))
    };
}

const CHOREOGRAPHY: &str = include_str!("../../../examples/choreography.toml");

const PARTICLES: &[(&str, &str)] = &[
    scene!("sun-earth", "sun-earth.toml"),
    scene!("circumbinary", "circumbinary.toml"),
    scene!("planetary-ring", "planetary-ring.toml"),
    scene!("double-pendulum", "double-pendulum.toml"),
    scene!("membrane", "membrane.toml"),
    scene!("cantilever", "cantilever.toml"),
    scene!("settling", "settling.toml"),
    scene!("column-collapse", "column-collapse.toml"),
    scene!("rotating-drum", "rotating-drum.toml"),
    scene!("chute-flow", "chute-flow.toml"),
    scene!("plummer", "plummer.toml"),
    scene!("ferrofluid", "ferrofluid.toml"),
];

const RIGID: &[(&str, &str)] = &[
    scene!("magnet-in-field", "rigid/magnet-in-field.toml"),
    scene!("clumps-settling", "rigid/clumps-settling.toml"),
    scene!("chains-rotating-field", "rigid/chains-rotating-field.toml"),
    scene!("toning-nip", "rigid/toning-nip.toml"),
    scene!("toning-nip-flow", "rigid/toning-nip-flow.toml"),
    scene!("toning-nip-compress", "rigid/toning-nip-compress.toml"),
];

const PACKING: &[(&str, &str)] = &[scene!("rcp", "packing/rcp.toml")];

/// All examples, grouped by engine, in the order `mote examples` lists them.
pub fn all() -> Vec<Example> {
    let make = |engine: Engine, (name, text): (&str, &str)| Example {
        name: name.to_string(),
        engine,
        description: description(text),
        text: text.to_string(),
    };
    let mut list: Vec<Example> = PARTICLES
        .iter()
        .map(|s| make(Engine::Particles, *s))
        .collect();
    for n in 2..=9 {
        let text = CHOREOGRAPHY.replace("@N@", &n.to_string());
        list.insert(
            n,
            Example {
                name: format!("choreography-{n}"),
                engine: Engine::Particles,
                description: description(&text),
                text,
            },
        );
    }
    list.extend(RIGID.iter().map(|s| make(Engine::Rigid, *s)));
    list.extend(
        mote_edmd::scene::EXAMPLES
            .iter()
            .map(|s| make(Engine::EventDriven, *s)),
    );
    list.extend(PACKING.iter().map(|s| make(Engine::Packing, *s)));
    list
}

/// The example called `name`.
pub fn find(name: &str) -> Option<Example> {
    all().into_iter().find(|e| e.name == name)
}

/// The scene's `title = "..."`, else its first comment line.
pub fn description(text: &str) -> String {
    text.lines()
        .find_map(|l| l.strip_prefix("title = "))
        .map(|t| t.trim().trim_matches('"').to_string())
        .or_else(|| {
            text.lines()
                .find_map(|l| l.strip_prefix('#'))
                .map(|t| t.trim().trim_end_matches('.').to_string())
        })
        .unwrap_or_default()
}
