//! Provenance: the header line every output file carries.

/// Who wrote a file and from what: mote's version, the scene, the seed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Provenance {
    /// Program and version, e.g. `mote 0.1.0`.
    pub program: String,
    /// The scene file or example the run came from.
    pub scene: String,
    /// The seed of the run's random number generator.
    pub seed: u64,
}

impl Provenance {
    /// `program=mote 0.1.0 scene=... seed=N` as one line, without comment marker.
    pub fn line(&self) -> String {
        format!(
            "program=\"{}\" scene=\"{}\" seed={}",
            self.program,
            self.scene.replace('"', "'"),
            self.seed
        )
    }
}
