//! Checkpoints shared by the time-stepped engines: the options a checkpoint
//! records, and trimming the files of an interrupted run back to it.

use std::path::{Path, PathBuf};

use mote_io::checkpoint::Checkpoint;
use mote_io::IoError;

use crate::error::FrontError;
use crate::{Input, RunOptions};

pub(crate) use mote_io::checkpoint::hex;

/// A checkpoint option written by [`hex`], exactly.
pub(crate) fn unhex(s: &str) -> Result<f64, FrontError> {
    mote_io::checkpoint::unhex(s)
        .ok_or_else(|| FrontError::request("a checkpoint option is not a hexadecimal f64"))
}

fn number<T: std::str::FromStr>(key: &str, v: String) -> Result<T, FrontError> {
    v.parse().map_err(|_| {
        FrontError::request(format!("checkpoint option {key} = '{v}' is not a number"))
    })
}

/// Drops what an interrupted run wrote after its last checkpoint (rows past
/// `step`, or past `time` in tables without a step column, and frames past
/// `time`), so the resumed run continues the files.
pub(crate) fn trim_outputs(dir: &Path, step: u64, time: f64) -> Result<(), FrontError> {
    trim_table(&dir.join("observables.csv"), step, time)?;
    // The particles taken out by outlets (`[[outlet]]`).
    trim_table(&dir.join("outflow.csv"), step, time)?;
    // A toning nip's table (rigid `[rigid.nip]`), where there is one.
    trim_table(&dir.join("nip.csv"), step, time)?;
    // A packing's windows (by time: the table has no step column).
    trim_table(&dir.join("packing.csv"), step, time)?;
    // Frames up to the checkpoint are kept verbatim (byte for byte).
    use mote_io::trajectory::{keep_until, Format};
    for format in [Format::Xyz, Format::Dump, Format::Gsd, Format::Vtk] {
        let path = dir.join(format!("trajectory.{}", format.extension()));
        if path.exists() {
            keep_until(&path, format, step, time)?;
        }
    }
    Ok(())
}

/// Drops the rows of a CSV table past `step` (its `step` column), or past
/// `time` (its `time` column) in a table without one; a missing file is
/// left alone.
pub(crate) fn trim_table(csv: &Path, step: u64, time: f64) -> Result<(), FrontError> {
    if let Ok(text) = std::fs::read_to_string(csv) {
        let mut column = None;
        let mut kept = String::new();
        for line in text.lines() {
            let keep = if line.starts_with('#') {
                true
            } else if let Some((k, limit)) = column {
                line.split(',')
                    .nth(k)
                    .and_then(|v| v.trim().parse::<f64>().ok())
                    .is_some_and(|s| s <= limit)
            } else {
                // The column names: rows are kept up to the checkpoint's
                // step, or its time where there is no step column (rigid
                // runs; times are written with 17 digits, so exactly).
                let names: Vec<&str> = line.split(',').map(str::trim).collect();
                column = match names.iter().position(|c| *c == "step") {
                    Some(k) => Some((k, step as f64)),
                    None => names.iter().position(|c| *c == "time").map(|k| (k, time)),
                };
                true
            };
            if keep {
                kept.push_str(line);
                kept.push('\n');
            }
        }
        std::fs::write(csv, kept).map_err(|e| IoError::os(csv, e))?;
    }
    Ok(())
}

/// The input and the options of the run a checkpoint came from.
pub(crate) fn restore(
    cp: &Checkpoint,
    given: &RunOptions,
) -> Result<(Input, RunOptions), FrontError> {
    let get = |k: &str| cp.option(k).map(str::to_string);
    let plist = get("plist").as_deref() == Some("true");
    let input = Input {
        name: get("name").unwrap_or_else(|| "run".into()),
        label: cp.input_label.clone(),
        text: cp.input_text.clone(),
        plist,
    };
    let options = RunOptions {
        input: None,
        resume: given.resume.clone(),
        checkpoint_every: get("checkpoint-every")
            .map(|v| number("checkpoint-every", v))
            .transpose()?,
        until: None,
        steps: get("total-steps")
            .map(|v| number("total-steps", v))
            .transpose()?,
        dt: get("dt").map(|v| unhex(&v)).transpose()?,
        system: get("system").filter(|_| plist),
        solver: get("solver"),
        // Where the run goes on (`lock::resume_folder`), else where it was.
        output: given
            .output
            .clone()
            .or_else(|| get("output").map(PathBuf::from)),
        picture: given.picture.clone(),
        trajectory_format: get("trajectory-format"),
        seed: Some(cp.seed),
        threads: given.threads,
        force: given.force,
        live: given.live.clone(),
        ranks: given.ranks.clone(),
    };
    Ok((input, options))
}
