//! The integration tests of mote, one binary (`cargo test -p mote --test cli MODULE::`).

mod checkpoint_cli;
mod edmd_cli;
mod faults_cli;
mod fuzz_readers;
mod pack_cli;
mod rcp_cli;
mod render_cli;
mod run_cli;
mod soak;
mod view_cli;
