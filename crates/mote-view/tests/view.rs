//! The integration tests of mote-view, one binary (`cargo test -p mote-view --test view MODULE::`).

mod cdp;
mod common;
mod live;
mod live_cost;
mod render_cost;
mod server;
