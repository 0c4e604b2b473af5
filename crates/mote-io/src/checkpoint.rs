//! Exact checkpoints: the input a run was built from, its seed and options,
//! and the state (time, step, positions, velocities) with every f64 written
//! as the hexadecimal of its bits, so a resumed run continues bit for bit.
//!
//! Written atomically: to `FILE.tmp`, synced, then renamed over `FILE`, so a
//! run killed at any moment leaves the previous checkpoint intact. The last
//! line is a checksum (64-bit FNV-1a) of everything before it, so a file
//! truncated or changed afterwards is refused rather than resumed from
//! (version 1 files, which have none, are still read).

use std::fs::File;
use std::io::Write;
use std::path::Path;

use crate::{IoError, ParseError};

/// Everything needed to rebuild and continue a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Checkpoint {
    pub program: String,
    pub seed: u64,
    /// Options of the original command line, as (key, value).
    pub options: Vec<(String, String)>,
    /// What the input was called (`example:NAME`, a path).
    pub input_label: String,
    /// The whole input text (scene or particle file).
    pub input_text: String,
    pub time: f64,
    pub step: u64,
    pub positions: Vec<[f64; 3]>,
    pub velocities: Vec<[f64; 3]>,
    /// Integrator state carried from step to step (leap-frog's last
    /// accelerations); empty when there is none.
    pub accelerations: Vec<[f64; 3]>,
    /// Angular velocities and carried angular accelerations (ω, α) of
    /// rotating particles; empty when nothing rotates.
    pub angular: Vec<[f64; 6]>,
    /// What the engine carries from step to step besides the particles, by
    /// name: each interaction's contact histories and lists under its key
    /// ([`carried_keys`]), an engine's own tables (`radii`, `run`, ...);
    /// empty lists are omitted. Checkpoints before names numbered them by
    /// position: such a key is the number's digits.
    pub carried: Vec<(String, Vec<f64>)>,
}

impl Checkpoint {
    /// The carried list `name`, or (a checkpoint from before names) the one
    /// numbered `old_index`.
    pub fn carried_list(&self, name: &str, old_index: usize) -> Option<&[f64]> {
        let old = old_index.to_string();
        self.carried
            .iter()
            .find(|(k, _)| k == name)
            .or_else(|| self.carried.iter().find(|(k, _)| *k == old))
            .map(|(_, v)| v.as_slice())
    }

    /// The value of option `key`.
    pub fn option(&self, key: &str) -> Option<&str> {
        self.options
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// An f64 as the 16 hexadecimal digits of its bits: how checkpoints keep
/// every number exactly (options included).
pub fn hex(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

/// The f64 whose bits [`hex`] wrote; `None` if `s` is not 1–16 hex digits.
pub fn unhex(s: &str) -> Option<f64> {
    u64::from_str_radix(s, 16).ok().map(f64::from_bits)
}

/// Writes `cp` to `path` atomically.
pub fn write(path: &Path, cp: &Checkpoint) -> Result<(), IoError> {
    let mut text = String::new();
    text.push_str("mote-checkpoint 2\n");
    text.push_str(&format!("program {}\n", cp.program));
    text.push_str(&format!("seed {}\n", cp.seed));
    for (k, v) in &cp.options {
        text.push_str(&format!("option {k} {v}\n"));
    }
    text.push_str(&format!("time {}\n", hex(cp.time)));
    text.push_str(&format!("step {}\n", cp.step));
    text.push_str(&format!("input-label {}\n", cp.input_label));
    let lines: Vec<&str> = cp.input_text.split('\n').collect();
    text.push_str(&format!("input {}\n", lines.len()));
    for l in &lines {
        text.push_str(l);
        text.push('\n');
    }
    text.push_str(&format!("particles {}\n", cp.positions.len()));
    for (r, v) in cp.positions.iter().zip(&cp.velocities) {
        let w: Vec<String> = r.iter().chain(v.iter()).map(|x| hex(*x)).collect();
        text.push_str(&w.join(" "));
        text.push('\n');
    }
    text.push_str(&format!("accelerations {}\n", cp.accelerations.len()));
    for a in &cp.accelerations {
        let w: Vec<String> = a.iter().map(|x| hex(*x)).collect();
        text.push_str(&w.join(" "));
        text.push('\n');
    }
    text.push_str(&format!("angular {}\n", cp.angular.len()));
    for a in &cp.angular {
        let w: Vec<String> = a.iter().map(|x| hex(*x)).collect();
        text.push_str(&w.join(" "));
        text.push('\n');
    }
    for (name, values) in &cp.carried {
        let lines = values.len().div_ceil(8);
        // a name is one word of the record
        let name = one_word(name);
        text.push_str(&format!("carried {name} {} {lines}\n", values.len()));
        for chunk in values.chunks(8) {
            let w: Vec<String> = chunk.iter().map(|x| hex(*x)).collect();
            text.push_str(&w.join(" "));
            text.push('\n');
        }
    }
    text.push_str(&format!("checksum {:016x}\n", fnv1a(text.as_bytes())));
    let tmp = path.with_extension("tmp");
    let write = || -> std::io::Result<()> {
        let mut f = File::create(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|e| IoError::os(path, e))
}

/// Reads a checkpoint; errors name `file:line`.
pub fn read(path: &Path) -> Result<Checkpoint, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    let mut lines: Vec<&str> = text.split('\n').collect();
    let err = |k: usize, m: &str| ParseError::new(&name, k + 1, m.to_string());
    match lines.first() {
        Some(&"mote-checkpoint 1") => {}
        Some(&"mote-checkpoint 2") => {
            // The checksum line is the last non-empty one and covers all before it.
            let last = lines.iter().rposition(|l| !l.is_empty()).unwrap_or(0);
            let Some(sum) = lines[last].strip_prefix("checksum ") else {
                return Err(ParseError::new(
                    &name,
                    0,
                    "the checkpoint ends without its checksum line: it is truncated",
                )
                .into());
            };
            let covered: usize = lines[..last].iter().map(|l| l.len() + 1).sum();
            if u64::from_str_radix(sum, 16).ok() != Some(fnv1a(&text.as_bytes()[..covered])) {
                return Err(err(
                    last,
                    "the checksum does not match the contents: the checkpoint is corrupted",
                )
                .into());
            }
            lines.truncate(last);
        }
        _ => {
            return Err(err(0, "not a mote checkpoint (expected 'mote-checkpoint 2')").into());
        }
    }
    let mut cp = Checkpoint::default();
    let mut k = 1;
    let bits = |s: &str, k: usize| -> Result<f64, ParseError> {
        unhex(s).ok_or_else(|| err(k, &format!("'{s}' is not a hexadecimal f64")))
    };
    while k < lines.len() {
        let line = lines[k];
        let (key, rest) = line.split_once(' ').unwrap_or((line, ""));
        match key {
            "program" => cp.program = rest.to_string(),
            "seed" => {
                cp.seed = rest
                    .parse()
                    .map_err(|_| err(k, "seed must be an integer"))?
            }
            "option" => {
                let (a, b) = rest.split_once(' ').unwrap_or((rest, ""));
                cp.options.push((a.to_string(), b.to_string()));
            }
            "time" => cp.time = bits(rest, k)?,
            "step" => {
                cp.step = rest
                    .parse()
                    .map_err(|_| err(k, "step must be an integer"))?
            }
            "input-label" => cp.input_label = rest.to_string(),
            "input" => {
                let n: usize = rest
                    .parse()
                    .map_err(|_| err(k, "input needs its line count"))?;
                if k + n >= lines.len() {
                    return Err(err(k, "the input ends before its announced lines").into());
                }
                cp.input_text = lines[k + 1..=k + n].join("\n");
                k += n;
            }
            "particles" => {
                let rows = table(&lines, k, rest, 6, "x y z vx vy vz", &bits, &err)?;
                for v in &rows {
                    cp.positions.push([v[0], v[1], v[2]]);
                    cp.velocities.push([v[3], v[4], v[5]]);
                }
                k += rows.len();
            }
            "accelerations" => {
                let rows = table(&lines, k, rest, 3, "ax ay az", &bits, &err)?;
                cp.accelerations
                    .extend(rows.iter().map(|v| [v[0], v[1], v[2]]));
                k += rows.len();
            }
            "angular" => {
                let rows = table(
                    &lines,
                    k,
                    rest,
                    6,
                    "wx wy wz alpha_x alpha_y alpha_z",
                    &bits,
                    &err,
                )?;
                cp.angular
                    .extend(rows.iter().map(|v| [v[0], v[1], v[2], v[3], v[4], v[5]]));
                k += rows.len();
            }
            "carried" => {
                let w: Vec<&str> = rest.split_whitespace().collect();
                let [name, count, nlines] = w[..] else {
                    return Err(err(k, "carried needs: name count lines").into());
                };
                let number = |x: &str| -> Result<usize, IoError> {
                    x.parse()
                        .map_err(|_| err(k, "carried needs: name count lines").into())
                };
                let (name, count, nlines) = (name.to_string(), number(count)?, number(nlines)?);
                // Eight values a line: the lines there bound what is reserved.
                let mut values = Vec::with_capacity(count.min(nlines.saturating_mul(8)));
                for ln in k + 1..=k + nlines {
                    let line = lines
                        .get(ln)
                        .ok_or_else(|| err(ln, "the carried state ends early"))?;
                    for x in line.split_whitespace() {
                        values.push(bits(x, ln)?);
                    }
                }
                if values.len() != count {
                    return Err(err(
                        k,
                        &format!("carried announces {count} numbers, found {}", values.len()),
                    )
                    .into());
                }
                cp.carried.push((name, values));
                k += nlines;
            }
            "" => {}
            other => return Err(err(k, &format!("unknown record '{other}'")).into()),
        }
        k += 1;
    }
    Ok(cp)
}

/// The 64-bit FNV-1a hash of `bytes` (Fowler–Noll–Vo): the checksum line.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The `count` rows of `width` hexadecimal f64 after the record at line k.
fn table(
    lines: &[&str],
    k: usize,
    count: &str,
    width: usize,
    names: &str,
    bits: &dyn Fn(&str, usize) -> Result<f64, ParseError>,
    err: &dyn Fn(usize, &str) -> ParseError,
) -> Result<Vec<Vec<f64>>, ParseError> {
    let n: usize = count
        .parse()
        .map_err(|_| err(k, "the record needs a row count"))?;
    (k + 1..k + 1 + n)
        .map(|ln| {
            let w: Vec<&str> = lines
                .get(ln)
                .map(|l| l.split_whitespace().collect())
                .unwrap_or_default();
            if w.len() != width {
                return Err(err(
                    ln,
                    &format!("expected {width} hexadecimal f64: {names}"),
                ));
            }
            w.iter().map(|s| bits(s, ln)).collect()
        })
        .collect()
}

/// The keys under which a checkpoint carries the state of interactions
/// named `names` (in order): the name with `_` for blanks (a key is one
/// word of the file), and `name#2`, `name#3`, … for the second and later
/// of one name.
pub fn carried_keys<'a>(names: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let mut keys: Vec<String> = Vec::new();
    let mut seen: Vec<String> = Vec::new();
    for name in names {
        let word = one_word(name);
        let count = seen.iter().filter(|n| **n == word).count();
        keys.push(if count == 0 {
            word.clone()
        } else {
            format!("{word}#{}", count + 1)
        });
        seen.push(word);
    }
    keys
}

/// `name` with `_` for each blank.
fn one_word(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect()
}

/// Which interaction (index into `keys`, see [`carried_keys`]) each
/// carried list of `cp` belongs to; a key that names none is an error (a
/// checkpoint of another scene), and a number is an index (checkpoints
/// from before names).
pub fn match_carried<'c>(
    cp: &'c Checkpoint,
    keys: &[String],
) -> Result<Vec<(usize, &'c [f64])>, String> {
    cp.carried
        .iter()
        .map(|(key, values)| {
            let k = keys
                .iter()
                .position(|k| k == key)
                .or_else(|| key.parse::<usize>().ok().filter(|k| *k < keys.len()))
                .ok_or_else(|| {
                    format!(
                        "the checkpoint carries the state of '{key}', which this scene has no interaction for (it has: {})",
                        if keys.is_empty() { "none".to_string() } else { keys.join(", ") }
                    )
                })?;
            Ok((k, values.as_slice()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.mote");
        let cp = Checkpoint {
            program: "mote 0.1.0".into(),
            seed: 42,
            options: vec![
                ("dt".into(), "0.1".into()),
                ("total-steps".into(), "100".into()),
            ],
            input_label: "example:x".into(),
            input_text: "[run]\ndt = 0.1\n\n# a comment\n".into(),
            time: 0.1 + 0.2,
            step: 3,
            positions: vec![[1.0 / 3.0, -0.0, 1e-300], [f64::MAX, 2.5, -7.25]],
            velocities: vec![[0.1, 0.2, 0.3], [std::f64::consts::PI, 0.0, -1.0]],
            accelerations: vec![[1e-9, -2.0, 3.5], [0.0, 0.0, 1.0]],
            angular: vec![[1.0, 2.0, 3.0, 4.0, 5.0, f64::MIN_POSITIVE]; 2],
            carried: vec![
                ("granular".into(), (0..11).map(|k| k as f64 / 7.0).collect()),
                ("granular#2".into(), vec![-0.0, f64::INFINITY]),
            ],
        };
        write(&path, &cp).unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back, cp);
        assert_eq!(back.positions[0][1].to_bits(), (-0.0f64).to_bits());
        assert!(!path.with_extension("tmp").exists());
        std::fs::write(&path, "mote-checkpoint 1\nparticles 1\n00 11\n").unwrap();
        assert!(read(&path).unwrap_err().to_string().contains("c.mote:3:"));
    }

    /// A checkpoint changed or cut after it was written is refused with
    /// the reason, never resumed from: one digit of a velocity flipped to
    /// another valid digit, the last rows cut off, the checksum gone.
    #[test]
    fn corrupted_or_truncated_checkpoints_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.mote");
        let cp = Checkpoint {
            program: "mote".into(),
            input_text: "[run]\n".into(),
            positions: vec![[1.0, 2.0, 3.0]; 4],
            velocities: vec![[0.5, -0.5, 0.25]; 4],
            ..Checkpoint::default()
        };
        write(&path, &cp).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines = text.lines().count();

        let flipped = text.replacen("3fd0000000000000", "3fd0000000000001", 1);
        assert_ne!(flipped, text);
        std::fs::write(&path, &flipped).unwrap();
        assert_eq!(
            read(&path).unwrap_err().to_string(),
            format!(
                "{}:{lines}: the checksum does not match the contents: the checkpoint is corrupted",
                path.display()
            )
        );

        let cut: String = text
            .lines()
            .take(lines - 3)
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(&path, cut).unwrap();
        assert_eq!(
            read(&path).unwrap_err().to_string(),
            format!(
                "{}: the checkpoint ends without its checksum line: it is truncated",
                path.display()
            )
        );
    }

    /// Interactions are found by name wherever they stand; a repeated name
    /// is numbered; an old numbered list is its index; a foreign one is an
    /// error that says what the scene has.
    #[test]
    fn carried_lists_find_their_interaction_by_name() {
        let keys = carried_keys(["springs", "granular", "granular", "walls"]);
        assert_eq!(keys, ["springs", "granular", "granular#2", "walls"]);
        assert_eq!(
            carried_keys(["air drag", "air drag"]),
            ["air_drag", "air_drag#2"]
        );
        let cp = Checkpoint {
            carried: vec![
                ("granular#2".into(), vec![1.0]),
                ("springs".into(), vec![2.0]),
                ("3".into(), vec![3.0]),
            ],
            ..Checkpoint::default()
        };
        let matched = match_carried(&cp, &keys).unwrap();
        assert_eq!(
            matched,
            vec![(2, &[1.0][..]), (0, &[2.0][..]), (3, &[3.0][..])]
        );
        let other = Checkpoint {
            carried: vec![("lennard-jones".into(), vec![1.0])],
            ..Checkpoint::default()
        };
        let e = match_carried(&other, &keys).unwrap_err();
        assert!(
            e.contains("'lennard-jones'") && e.contains("springs, granular"),
            "{e}"
        );
        assert_eq!(other.carried_list("lennard-jones", 0), Some(&[1.0][..]));
        assert_eq!(cp.carried_list("walls", 3), Some(&[3.0][..]));
    }
}
