//! The integration tests of mote-geom, one binary (`cargo test -p mote-geom --test geom MODULE::`).

mod algebra;
mod shape_preservation;
