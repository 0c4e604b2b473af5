//! The one place a run's seed is chosen when none is given.

/// A seed from the clock and the process id, below 10⁹ + 7 so that it is
/// short enough to read off a summary and type back in.
pub fn fresh_seed() -> u64 {
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    (t.as_nanos() as u64 ^ (std::process::id() as u64) << 32) % 1_000_000_007
}

/// The seed of a run: the command line's, else the scene's, else a fresh
/// one; the flag says whether it was chosen here (summaries say so).
pub fn resolve(command_line: Option<u64>, scene: Option<u64>) -> (u64, bool) {
    match command_line.or(scene) {
        Some(s) => (s, false),
        None => (fresh_seed(), true),
    }
}
