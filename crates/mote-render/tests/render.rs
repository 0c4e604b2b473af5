//! The integration tests of mote-render, one binary (`cargo test -p mote-render --test render MODULE::`).

mod files;
mod golden;
