//! Observables as CSV: a `#` header line with provenance and units, then a
//! row of column names, then one row per sample.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{IoError, Provenance};

/// Writes a table of numbers, one row per sample, flushed on every row so a
/// run that stops early keeps what it wrote.
pub struct CsvWriter {
    path: PathBuf,
    out: BufWriter<File>,
    columns: usize,
}

impl CsvWriter {
    /// Creates `path` and writes the header: `# provenance`, `# units: ...`
    /// (one unit per column, may be empty) and the column names.
    pub fn create(
        path: &Path,
        provenance: &Provenance,
        columns: &[String],
        units: &[String],
    ) -> Result<Self, IoError> {
        let file = File::create(path).map_err(|e| IoError::os(path, e))?;
        let mut out = BufWriter::new(file);
        let mut write = || -> std::io::Result<()> {
            writeln!(out, "# {}", provenance.line())?;
            if !units.is_empty() {
                writeln!(out, "# units: {}", units.join(","))?;
            }
            writeln!(out, "{}", columns.join(","))?;
            Ok(())
        };
        write().map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out,
            columns: columns.len(),
        })
    }

    /// Opens an existing table to append rows (a resumed run); the header is
    /// already there.
    pub fn append(path: &Path, columns: usize) -> Result<Self, IoError> {
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| IoError::os(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            columns,
        })
    }

    /// Appends one row (must have as many values as there are columns).
    pub fn row(&mut self, values: &[f64]) -> Result<(), IoError> {
        debug_assert_eq!(values.len(), self.columns);
        let mut line = String::with_capacity(values.len() * 24);
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            line.push_str(&format!("{v:.16e}"));
        }
        line.push('\n');
        self.out
            .write_all(line.as_bytes())
            .and_then(|_| self.out.flush())
            .map_err(|e| IoError::os(&self.path, e))
    }

    /// Writes `# text` between the rows (an event of the run, such as a
    /// change made from the live viewer); CSV readers skip it as a comment.
    pub fn comment(&mut self, text: &str) -> Result<(), IoError> {
        let line = format!("# {}\n", text.replace('\n', " "));
        self.out
            .write_all(line.as_bytes())
            .and_then(|_| self.out.flush())
            .map_err(|e| IoError::os(&self.path, e))
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// A table read back from a CSV written by [`CsvWriter`] (or any CSV of numbers
/// with one header row; `#` lines are skipped).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// The values of the named column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// Reads a CSV of numbers; errors name `file:line`.
pub fn read_table(path: &Path) -> Result<Table, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    let name = path.display().to_string();
    let mut columns: Option<Vec<String>> = None;
    let mut rows = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match &columns {
            None => columns = Some(line.split(',').map(|s| s.trim().to_string()).collect()),
            Some(cols) => {
                let row: Result<Vec<f64>, _> = line.split(',').map(|s| s.trim().parse()).collect();
                let row = row.map_err(|_| {
                    crate::ParseError::new(&name, k + 1, "expected comma-separated numbers")
                })?;
                if row.len() != cols.len() {
                    return Err(crate::ParseError::new(
                        &name,
                        k + 1,
                        format!("{} values, but the header names {}", row.len(), cols.len()),
                    )
                    .into());
                }
                rows.push(row);
            }
        }
    }
    let columns =
        columns.ok_or_else(|| crate::ParseError::new(&name, 0, "no header row of column names"))?;
    Ok(Table { columns, rows })
}
