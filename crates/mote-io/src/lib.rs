//! File formats as plain data.
//!
//! Readers and writers here know nothing of engines: they take and give plain
//! numbers and strings. Every reader reports bad input as
//! `file:line: what is wrong` ([`ParseError`]).

pub mod checkpoint;
pub mod csv;
pub mod elements;
pub mod error;
pub mod gsd;
pub mod header;
pub mod lammps_data;
pub mod lammps_dump;
pub mod plist;
pub mod png;
pub mod system;
pub mod trajectory;
pub mod vtu;
pub mod xyz;

pub use error::{IoError, ParseError, Source};
pub use header::Provenance;
