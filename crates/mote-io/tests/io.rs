//! The integration tests of mote-io, one binary (`cargo test -p mote-io --test io MODULE::`).

mod formats;
mod gsd_others;
mod ovito_others;
mod quaternions;
mod strict_readers;
mod vtu_others;
mod xyz_others;
