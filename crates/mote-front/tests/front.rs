//! The integration tests of mote-front, one binary (`cargo test -p mote-front --test front MODULE::`).

mod live;
mod option_scene_parity;
mod packing_values;
mod rigid_runs;
