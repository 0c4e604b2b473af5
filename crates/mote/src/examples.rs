//! The built-in examples: scene files compiled into the binary.

/// A built-in example: its name and scene text.
pub struct Example {
    pub name: String,
    pub text: String,
}

const CHOREOGRAPHY: &str = include_str!("../../../examples/choreography.toml");

const SCENES: [(&str, &str); 11] = [
    (
        "sun-earth",
        include_str!("../../../examples/sun-earth.toml"),
    ),
    (
        "circumbinary",
        include_str!("../../../examples/circumbinary.toml"),
    ),
    (
        "planetary-ring",
        include_str!("../../../examples/planetary-ring.toml"),
    ),
    (
        "double-pendulum",
        include_str!("../../../examples/double-pendulum.toml"),
    ),
    ("membrane", include_str!("../../../examples/membrane.toml")),
    (
        "cantilever",
        include_str!("../../../examples/cantilever.toml"),
    ),
    ("settling", include_str!("../../../examples/settling.toml")),
    (
        "column-collapse",
        include_str!("../../../examples/column-collapse.toml"),
    ),
    (
        "rotating-drum",
        include_str!("../../../examples/rotating-drum.toml"),
    ),
    ("plummer", include_str!("../../../examples/plummer.toml")),
    (
        "ferrofluid",
        include_str!("../../../examples/ferrofluid.toml"),
    ),
];

/// All examples, in the order `mote examples` lists them.
pub fn all() -> Vec<Example> {
    let mut list: Vec<Example> = SCENES
        .iter()
        .map(|(name, text)| Example {
            name: name.to_string(),
            text: text.to_string(),
        })
        .collect();
    for n in 2..=9 {
        list.insert(
            2 + n - 2,
            Example {
                name: format!("choreography-{n}"),
                text: CHOREOGRAPHY.replace("@N@", &n.to_string()),
            },
        );
    }
    list
}

/// The example called `name`.
pub fn find(name: &str) -> Option<Example> {
    all().into_iter().find(|e| e.name == name)
}

/// The scene's `title = "..."` line, for the listing.
pub fn title(text: &str) -> String {
    text.lines()
        .find_map(|l| l.strip_prefix("title = "))
        .map(|t| t.trim().trim_matches('"').to_string())
        .unwrap_or_default()
}
