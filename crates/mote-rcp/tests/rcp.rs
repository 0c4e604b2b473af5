//! The integration tests of mote-rcp, one binary (`cargo test -p mote-rcp --test rcp MODULE::`).

mod design;
mod properties;
mod published;
