//! Errors of readers and writers.

use std::fmt;
use std::path::PathBuf;

/// A problem at a known place in an input file: displayed as `file:line: message`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct ParseError {
    /// The file (or a pseudo-name such as `<stdin>` or `example:sun-earth`).
    pub file: String,
    /// One-based line number; 0 when the problem concerns the whole file.
    pub line: usize,
    /// What is wrong, and what would be right.
    pub message: String,
}

impl ParseError {
    pub fn new(file: impl Into<String>, line: usize, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            line,
            message: message.into(),
        }
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: {}", self.file, self.line, self.message)
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

/// An input text and its name: turns byte spans (as TOML and other parsers
/// report them) into `file:line` errors. The one place a byte offset becomes
/// a line number.
#[derive(Debug, Clone, Copy)]
pub struct Source<'a> {
    /// The file (or pseudo-name) in messages.
    pub file: &'a str,
    /// The whole text.
    pub text: &'a str,
}

impl<'a> Source<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self { file, text }
    }

    /// Refuses a TOML text that spells a number `nan` or `inf` anywhere
    /// (`cutoff = nan` switched an interaction off without a word): no key
    /// of any scene takes a number that is not finite. The error names the
    /// line and the key. Text that is not TOML passes, for the scene's own
    /// parser to report.
    pub fn finite_numbers(&self) -> Result<(), ParseError> {
        use toml_edit::{Item, Value};
        fn value(src: &Source, key: &str, v: &Value) -> Result<(), ParseError> {
            match v {
                Value::Float(f) if !f.value().is_finite() => Err(ParseError::new(
                    src.file,
                    f.span().map_or(1, |s| src.line_of(s.start)),
                    format!("{key} = {}: a number here must be finite", f.value()),
                )),
                Value::Array(a) => a
                    .iter()
                    .enumerate()
                    .try_for_each(|(k, v)| value(src, &format!("{key}[{k}]"), v)),
                Value::InlineTable(t) => t
                    .iter()
                    .try_for_each(|(k, v)| value(src, &format!("{key}.{k}"), v)),
                _ => Ok(()),
            }
        }
        fn item(src: &Source, key: &str, i: &Item) -> Result<(), ParseError> {
            let join = |k: &str| {
                if key.is_empty() {
                    k.to_string()
                } else {
                    format!("{key}.{k}")
                }
            };
            match i {
                Item::Value(v) => value(src, key, v),
                Item::Table(t) => t.iter().try_for_each(|(k, i)| item(src, &join(k), i)),
                Item::ArrayOfTables(a) => a
                    .iter()
                    .try_for_each(|t| t.iter().try_for_each(|(k, i)| item(src, &join(k), i))),
                Item::None => Ok(()),
            }
        }
        match toml_edit::ImDocument::parse(self.text) {
            Ok(doc) => item(self, "", doc.as_item()),
            Err(_) => Ok(()),
        }
    }

    /// One-based line of a byte offset (offsets past the end give the last line).
    pub fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|b| **b == b'\n')
            .count()
            + 1
    }

    /// One-based line of the header of table `key` (`[key]`, `[key.sub]`,
    /// `[[key]]`), else where `key = ` is set ([`Source::key_line`]).
    pub fn table_line(&self, key: &str) -> usize {
        for (k, l) in self.text.lines().enumerate() {
            let t = l.trim_start().trim_start_matches('[').trim_start();
            if l.trim_start().starts_with('[')
                && t.strip_prefix(key)
                    .is_some_and(|rest| rest.starts_with(']') || rest.starts_with('.'))
            {
                return k + 1;
            }
        }
        self.key_line(key)
    }

    /// One-based line where `key = ` is first set (or an array of tables
    /// `[[...key...]]` starts); 1 if nowhere. For messages about a value
    /// found only after parsing.
    pub fn key_line(&self, key: &str) -> usize {
        for (k, l) in self.text.lines().enumerate() {
            let t = l.trim_start();
            if let Some(rest) = t.strip_prefix(key) {
                if rest.trim_start().starts_with('=') {
                    return k + 1;
                }
            }
            if t.starts_with("[[") && t.contains(key) {
                return k + 1;
            }
        }
        1
    }

    /// `file:line: message` at the start of `span`; an empty span at offset 0
    /// (a default value, not written in the file) gives the whole file
    /// (`file: message`).
    pub fn error(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> ParseError {
        let line = if span.start == 0 && span.end == 0 {
            0
        } else {
            self.line_of(span.start)
        };
        ParseError::new(self.file, line, message)
    }

    /// `file: message`, about the file as a whole.
    pub fn whole(&self, message: impl Into<String>) -> ParseError {
        ParseError::new(self.file, 0, message)
    }

    /// The error of a parser that reports an optional span (a TOML syntax or
    /// type error) with its message trimmed.
    pub fn parser_error(&self, span: Option<std::ops::Range<usize>>, message: &str) -> ParseError {
        let line = span.map_or(0, |s| self.line_of(s.start));
        ParseError::new(self.file, line, message.trim())
    }
}

/// Errors of mote-io: a parse error or an operating-system error on a named file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// The cause is part of the message (and not chained as a source, so
    /// that `{:#}` does not print it twice).
    #[error("{path}: {cause}")]
    Os {
        path: PathBuf,
        cause: std::io::Error,
    },
}

impl IoError {
    pub fn os(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Os {
            path: path.into(),
            cause: source,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_become_lines() {
        let src = Source::new("scene.toml", "a = 1\n\n[b]\nc = 2\n");
        assert_eq!(src.line_of(0), 1);
        assert_eq!(src.line_of(6), 2);
        assert_eq!(src.line_of(7), 3);
        assert_eq!(src.line_of(1000), 5);
        assert_eq!(src.error(7..10, "bad").to_string(), "scene.toml:3: bad");
        assert_eq!(
            src.error(0..0, "missing").to_string(),
            "scene.toml: missing"
        );
        assert_eq!(src.error(0..1, "first").to_string(), "scene.toml:1: first");
        assert_eq!(
            src.parser_error(Some(11..12), " wrong\n").to_string(),
            "scene.toml:4: wrong"
        );
    }
}
