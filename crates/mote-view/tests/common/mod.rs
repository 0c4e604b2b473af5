//! What the viewer's tests share: a server for a trajectory in a thread.
#![allow(dead_code)] // each test uses some of these

use std::sync::Arc;

use mote_io::xyz::Frame;
use mote_view::{bind, serve, App, Trajectory};

/// Serves `frames` (named `label`) on 127.0.0.1 and a free port, in a
/// thread that lives as long as the test; returns the port.
pub fn start(label: &str, frames: Vec<Frame>) -> u16 {
    start_app(App::file(Trajectory::new(label.into(), frames), None))
}

/// Serves `app` likewise.
pub fn start_app(app: Arc<App>) -> u16 {
    let (listener, loopback) = bind("127.0.0.1", 0).unwrap();
    assert!(loopback);
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        tokio::runtime::Runtime::new()
            .unwrap()
            .block_on(serve(listener, app, std::future::pending()))
            .unwrap();
    });
    port
}
