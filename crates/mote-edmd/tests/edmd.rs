//! The integration tests of mote-edmd, one binary (`cargo test -p mote-edmd --test edmd MODULE::`).

mod conservation;
mod cradle;
mod pack;
mod polydisperse;
mod robust;
mod scene;
mod scene_values;
mod statistics;
