//! Observables tables (mote's CSV: `#` comment lines, a row of column
//! names, rows of numbers; `# event: …` lines where a run was changed),
//! read whole or followed as a run appends to them.

use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// What the page plots: the column names, the rows so far and the events.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    /// `event: …` comment lines, without the `# `.
    pub events: Vec<String>,
    /// The column to plot first, where the table names one (`# plot:
    /// NAME`: a run that conserves no energy); else the page plots the
    /// total energy.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plot: Option<String>,
}

impl Table {
    /// Parses whole lines (a trailing partial line is the caller's to keep);
    /// the first line that is not a comment names the columns unless
    /// `header_seen`.
    fn take_lines(&mut self, text: &str, mut header_seen: bool) {
        for line in text.lines() {
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            if let Some(comment) = line.strip_prefix('#') {
                let comment = comment.trim();
                if comment.starts_with("event:") {
                    self.events.push(comment.to_string());
                } else if let Some(column) = comment.strip_prefix("plot:") {
                    self.plot.get_or_insert_with(|| column.trim().to_string());
                }
            } else if !header_seen {
                self.columns = line.split(',').map(|c| c.trim().to_string()).collect();
                header_seen = true;
            } else {
                self.rows.push(
                    line.split(',')
                        .map(|v| v.trim().parse().unwrap_or(f64::NAN))
                        .collect(),
                );
            }
        }
    }

    /// Reads a whole table.
    pub fn read(path: &Path) -> std::io::Result<Table> {
        let mut t = Table::default();
        t.take_lines(&std::fs::read_to_string(path)?, false);
        Ok(t)
    }
}

/// Follows a table that a run appends to: each [`Follow::poll`] gives what
/// was added since the last, in whole lines. Holds only the partial last
/// line, whatever the file's length.
pub struct Follow {
    path: PathBuf,
    offset: u64,
    partial: String,
    columns_sent: bool,
}

impl Follow {
    pub fn new(path: PathBuf) -> Self {
        Follow {
            path,
            offset: 0,
            partial: String::new(),
            columns_sent: false,
        }
    }

    /// What was appended since the last call (at most `limit` bytes read
    /// per call); `None` when nothing new. The columns come with the first
    /// part that has them.
    pub fn poll(&mut self, limit: u64) -> Option<Table> {
        let mut file = std::fs::File::open(&self.path).ok()?;
        let len = file.metadata().ok()?.len();
        if len < self.offset {
            // Rewritten from the start (a new run in the same folder).
            self.offset = 0;
            self.partial.clear();
            self.columns_sent = false;
        }
        if len == self.offset {
            return None;
        }
        file.seek(SeekFrom::Start(self.offset)).ok()?;
        let mut bytes = Vec::new();
        file.take(limit).read_to_end(&mut bytes).ok()?;
        self.offset += bytes.len() as u64;
        self.partial.push_str(&String::from_utf8_lossy(&bytes));
        let whole = self.partial.rfind('\n').map(|k| k + 1).unwrap_or(0);
        let text: String = self.partial.drain(..whole).collect();
        let mut t = Table::default();
        t.take_lines(&text, self.columns_sent);
        self.columns_sent |= !t.columns.is_empty();
        (!t.rows.is_empty() || !t.events.is_empty() || !t.columns.is_empty() || t.plot.is_some())
            .then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn a_followed_table_gives_whole_lines_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("observables.csv");
        let mut f = std::fs::File::create(&path).unwrap();
        write!(f, "# mote 0.1\ntime,energy\n0,1\n1,2").unwrap();
        f.flush().unwrap();
        let mut follow = Follow::new(path.clone());
        let first = follow.poll(1 << 20).unwrap();
        assert_eq!(first.columns, ["time", "energy"]);
        assert_eq!(first.rows, vec![vec![0.0, 1.0]]);
        assert_eq!(follow.poll(1 << 20), None);
        write!(f, ".5\n# event: step 2, t = 1: dt 1 → 2\n2,3\n").unwrap();
        f.flush().unwrap();
        let next = follow.poll(1 << 20).unwrap();
        assert!(next.columns.is_empty());
        assert_eq!(next.rows, vec![vec![1.0, 2.5], vec![2.0, 3.0]]);
        assert_eq!(next.events, ["event: step 2, t = 1: dt 1 → 2"]);
        assert_eq!(Table::read(&path).unwrap().rows.len(), 3);
    }
}

#[cfg(test)]
mod plot_tests {
    use super::*;

    /// A table that names its first plot (`# plot: NAME`, as a Brownian
    /// run's does) hands the name to the page; one that does not, none.
    #[test]
    fn a_table_names_the_column_to_plot_first() {
        let mut t = Table::default();
        t.take_lines(
            "# mote\ntime,kinetic_energy,potential_energy,total_energy\n# plot: potential_energy\n0,1,2,3\n",
            false,
        );
        assert_eq!(t.plot.as_deref(), Some("potential_energy"));
        assert_eq!(t.rows.len(), 1);
        let mut plain = Table::default();
        plain.take_lines("time,total_energy\n0,1\n", false);
        assert_eq!(plain.plot, None);
        assert!(!serde_json::to_string(&plain).unwrap().contains("plot"));
    }
}
