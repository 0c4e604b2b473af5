//! `mote view`: a local web page that shows a trajectory.
//!
//! The server holds the frames of a trajectory file (any format
//! [`mote_io::trajectory::read_frames`] reads) and answers four requests:
//!
//! - `GET /` and `GET /viewer.js`: the page, compiled into the binary
//!   (plain WebGL2, no libraries: sphere impostors need one
//!   shader pair and a few hundred lines, and nothing is fetched at run
//!   time);
//! - `GET /api/meta`: JSON with the file's name, the frame count, each
//!   frame's time and particle count, the box, the species and the
//!   quantities one can colour by;
//! - `GET /api/frame/K?color=Q`: frame K as little-endian binary: u32 N,
//!   then N × (x, y, z, r) as f32, then N values of Q as f32 (species: the
//!   index in the meta's list);
//! - `GET /api/particle/K/I`: particle I of frame K as JSON, every column
//!   the file has for it (the inspector).
//!
//! Nothing is read from disk after the start, so no request can reach a
//! file: every other path is 404. The server listens on 127.0.0.1 unless
//! told otherwise ([`bind`] says whether an address is loopback).

use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;

use axum::body::Body;
use axum::extract::ws::WebSocketUpgrade;
use axum::extract::{Path, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use mote_io::xyz::Frame;
use serde::Deserialize;

pub mod doors;
pub mod live;
pub mod outline;
pub mod table;

const INDEX: &str = include_str!("../assets/index.html");
const SCRIPT: &str = include_str!("../assets/viewer.js");

/// The quantities a frame can be coloured by, besides `species`.
pub use mote_render::frame::QUANTITIES;

/// A trajectory as the page sees it.
pub struct Trajectory {
    /// The name shown on the page (the file's).
    pub label: String,
    pub frames: Vec<Frame>,
    /// The species of all frames, sorted: colour index = position here.
    pub species: Vec<String>,
}

impl Trajectory {
    pub fn new(label: String, frames: Vec<Frame>) -> Self {
        let mut species: Vec<String> = frames
            .iter()
            .flat_map(|f| f.species.iter().cloned())
            .collect();
        species.sort();
        species.dedup();
        Trajectory {
            label,
            frames,
            species,
        }
    }

    /// The JSON of `/api/meta`.
    pub fn meta(&self) -> serde_json::Value {
        let first = self.frames.first();
        serde_json::json!({
            "label": self.label,
            "frames": self.frames.len(),
            "time": self.frames.iter().map(|f| f.time).collect::<Vec<_>>(),
            "count": self.frames.iter().map(|f| f.positions.len()).collect::<Vec<_>>(),
            "cell": first.map(|f| f.cell),
            "origin": first.map(|f| f.origin),
            "species": self.species,
            "quantities": std::iter::once("species")
                .chain(first.map(mote_render::frame::quantities_of).unwrap_or_default())
                .collect::<Vec<_>>(),
        })
    }

    /// Particle `i` of frame `k` as the JSON of `/api/particle/K/I`.
    pub fn particle(&self, k: usize, i: usize) -> Result<serde_json::Value, String> {
        let f = self
            .frames
            .get(k)
            .ok_or_else(|| format!("no frame {k}: the file has {}", self.frames.len()))?;
        particle_json(f, i).map_err(|m| format!("{m} in frame {k}"))
    }

    /// Particle `i` through all frames, as the JSON of `/api/track/I`:
    /// time, x, y, z and speed (NaN where a frame lacks it); an error if
    /// no frame has particle `i`.
    pub fn track(&self, i: usize) -> Result<serde_json::Value, String> {
        let most = self
            .frames
            .iter()
            .map(|f| f.positions.len())
            .max()
            .unwrap_or(0);
        if i >= most {
            return Err(format!("no particle {i}: the largest frame has {most}"));
        }
        let column = |a: usize| -> Vec<f64> {
            self.frames
                .iter()
                .map(|f| f.positions.get(i).map_or(f64::NAN, |p| p[a]))
                .collect()
        };
        let speed: Vec<f64> = self
            .frames
            .iter()
            .map(|f| {
                f.velocities.get(i).map_or(f64::NAN, |v| {
                    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
                })
            })
            .collect();
        // JSON has no NaN: missing values go as null.
        let json = |v: Vec<f64>| -> Vec<Option<f64>> {
            v.into_iter().map(|x| x.is_finite().then_some(x)).collect()
        };
        Ok(serde_json::json!({
            "time": self.frames.iter().map(|f| f.time).collect::<Vec<_>>(),
            "x": json(column(0)),
            "y": json(column(1)),
            "z": json(column(2)),
            "speed": json(speed),
        }))
    }

    /// Frame `k` as the binary of `/api/frame/K`, coloured by `color`.
    pub fn frame_bytes(&self, k: usize, color: &str) -> Result<Vec<u8>, String> {
        let f = self
            .frames
            .get(k)
            .ok_or_else(|| format!("no frame {k}: the file has {}", self.frames.len()))?;
        encode_frame(f, &self.species, color)
    }
}

/// Particle `i` of a frame as JSON: every column the frame has for it.
pub fn particle_json(f: &Frame, i: usize) -> Result<serde_json::Value, String> {
    if i >= f.positions.len() {
        return Err(format!("no particle {i}: there are {}", f.positions.len()));
    }
    let mut out = serde_json::Map::new();
    out.insert("index".into(), i.into());
    out.insert("time".into(), f.time.into());
    out.insert("position".into(), serde_json::json!(f.positions[i]));
    let v3 =
        |name: &str, c: &Vec<[f64; 3]>, out: &mut serde_json::Map<String, serde_json::Value>| {
            if let Some(v) = c.get(i) {
                out.insert(name.into(), serde_json::json!(v));
            }
        };
    v3("velocity", &f.velocities, &mut out);
    v3("omega", &f.angular_velocities, &mut out);
    v3("dipole", &f.dipoles, &mut out);
    if let Some(s) = f.species.get(i) {
        out.insert("species".into(), s.clone().into());
    }
    if let Some(r) = f.radii.get(i) {
        out.insert("radius".into(), (*r).into());
    }
    if let Some(m) = f.masses.get(i) {
        out.insert("mass".into(), (*m).into());
    }
    if let Some(id) = f.ids.get(i) {
        out.insert("id".into(), (*id).into());
    }
    if let Some(b) = f.bodies.get(i) {
        out.insert("body".into(), (*b).into());
    }
    Ok(serde_json::Value::Object(out))
}

/// A frame as the page's binary: little-endian u32 N, N × (x, y, z, r) as
/// f32, N values of `color` as f32 (species: the index in `species`).
pub fn encode_frame(f: &Frame, species: &[String], color: &str) -> Result<Vec<u8>, String> {
    let n = f.positions.len();
    let fallback = mote_render::frame::default_radius(f);
    let values: Vec<f64> = if color == "species" {
        f.species
            .iter()
            .map(|s| species.binary_search(s).map_or(0.0, |i| i as f64))
            .chain(std::iter::repeat(0.0))
            .take(n)
            .collect()
    } else if mote_render::frame::quantities_of(f).contains(&color) {
        mote_render::frame::quantity(f, color).map_err(|e| e.to_string())?
    } else {
        return Err(format!(
            "cannot colour by '{color}': the frame has species, {}",
            mote_render::frame::quantities_of(f).join(", ")
        ));
    };
    let mut out = Vec::with_capacity(4 + 20 * n);
    out.extend((n as u32).to_le_bytes());
    for (i, p) in f.positions.iter().enumerate() {
        let r = f
            .radii
            .get(i)
            .copied()
            .filter(|r| *r > 0.0)
            .unwrap_or(fallback);
        for x in [p[0], p[1], p[2], r] {
            out.extend((x as f32).to_le_bytes());
        }
    }
    for v in values {
        out.extend((v as f32).to_le_bytes());
    }
    Ok(out)
}

#[derive(Deserialize)]
struct FrameQuery {
    color: Option<String>,
}

pub(crate) fn text(status: StatusCode, body: String) -> Response {
    (
        status,
        [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
        body,
    )
        .into_response()
}

/// What the server shows.
pub enum App {
    /// A trajectory file, with the observables table beside it if any.
    File {
        trajectory: Trajectory,
        observables: Option<table::Table>,
    },
    /// A run in progress.
    Live(Arc<live::Session>),
    /// An input that could not be read: the page shows why.
    Failed { label: String, message: String },
}

impl App {
    /// A trajectory file's frames, and the observables.csv of its folder.
    pub fn file(trajectory: Trajectory, observables: Option<table::Table>) -> Arc<App> {
        Arc::new(App::File {
            trajectory,
            observables,
        })
    }

    /// The JSON of `/api/meta`.
    pub fn meta(&self) -> serde_json::Value {
        let quantities: Vec<&str> = std::iter::once("species")
            .chain(QUANTITIES.iter().copied())
            .collect();
        match self {
            App::File {
                trajectory,
                observables,
            } => {
                let mut m = trajectory.meta();
                m["observables"] = observables.is_some().into();
                m
            }
            App::Live(s) => serde_json::json!({
                "label": s.label,
                "live": true,
                "frames": 0,
                "species": [],
                "quantities": quantities,
            }),
            App::Failed { label, message } => serde_json::json!({
                "label": label,
                "error": message,
                "frames": 0,
                "quantities": quantities,
            }),
        }
    }
}

fn file_only(app: &App) -> Option<&Trajectory> {
    match app {
        App::File { trajectory, .. } => Some(trajectory),
        _ => None,
    }
}

fn no_file() -> Response {
    text(
        StatusCode::NOT_FOUND,
        "no trajectory file: this is a live run".into(),
    )
}

async fn frame(
    State(app): State<Arc<App>>,
    Path(k): Path<String>,
    Query(q): Query<FrameQuery>,
) -> Response {
    let Some(t) = file_only(&app) else {
        return no_file();
    };
    let Ok(k) = k.parse::<usize>() else {
        return text(StatusCode::NOT_FOUND, format!("not a frame number: {k}"));
    };
    let color = q.color.unwrap_or_else(|| "species".into());
    match t.frame_bytes(k, &color) {
        Ok(bytes) => (
            [(header::CONTENT_TYPE, "application/octet-stream")],
            Body::from(bytes),
        )
            .into_response(),
        Err(m) => text(StatusCode::NOT_FOUND, m),
    }
}

async fn particle(State(app): State<Arc<App>>, Path((k, i)): Path<(String, String)>) -> Response {
    let Some(t) = file_only(&app) else {
        return no_file();
    };
    match (k.parse::<usize>(), i.parse::<usize>()) {
        (Ok(k), Ok(i)) => match t.particle(k, i) {
            Ok(v) => axum::Json(v).into_response(),
            Err(m) => text(StatusCode::NOT_FOUND, m),
        },
        _ => text(
            StatusCode::NOT_FOUND,
            format!("not a frame and particle: {k}/{i}"),
        ),
    }
}

async fn track(State(app): State<Arc<App>>, Path(i): Path<String>) -> Response {
    let Some(t) = file_only(&app) else {
        return no_file();
    };
    match i.parse::<usize>() {
        Ok(i) => match t.track(i) {
            Ok(v) => axum::Json(v).into_response(),
            Err(m) => text(StatusCode::NOT_FOUND, m),
        },
        Err(_) => text(StatusCode::NOT_FOUND, format!("not a particle: {i}")),
    }
}

/// The file's observables table (columns, rows, events) for the plots.
async fn observables(State(app): State<Arc<App>>) -> Response {
    match &*app {
        App::File {
            observables: Some(t),
            ..
        } => axum::Json(t).into_response(),
        _ => text(StatusCode::NOT_FOUND, "no observables table".into()),
    }
}

/// The live socket's query: the run's token.
#[derive(Deserialize)]
struct LiveQuery {
    token: Option<String>,
}

/// The live run's socket; it needs the run's token.
async fn socket(
    State(app): State<Arc<App>>,
    Query(q): Query<LiveQuery>,
    ws: WebSocketUpgrade,
) -> Response {
    match &*app {
        App::Live(session) => {
            if !q
                .token
                .as_deref()
                .is_some_and(|t| doors::token_matches(t, &session.token))
            {
                return text(
                    StatusCode::FORBIDDEN,
                    "this live run needs its token: open the URL mote view printed".into(),
                );
            }
            let session = Arc::clone(session);
            ws.on_upgrade(move |socket| live::client(socket, session))
        }
        _ => text(StatusCode::NOT_FOUND, "not a live run".into()),
    }
}

/// The page's routes behind the doors ([`doors`]); anything else is 404.
pub fn router(app: Arc<App>, doors: doors::Doors) -> Router {
    Router::new()
        .route(
            "/",
            get(|| async { ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], INDEX) }),
        )
        .route(
            "/viewer.js",
            get(|| async {
                (
                    [(header::CONTENT_TYPE, "text/javascript; charset=utf-8")],
                    SCRIPT,
                )
            }),
        )
        .route(
            "/api/meta",
            get(|State(app): State<Arc<App>>| async move { axum::Json(app.meta()) }),
        )
        .route("/api/frame/{k}", get(frame))
        .route("/api/particle/{k}/{i}", get(particle))
        .route("/api/track/{i}", get(track))
        .route("/api/observables", get(observables))
        .route("/api/live", get(socket))
        .fallback(|| async { text(StatusCode::NOT_FOUND, "not found".into()) })
        .with_state(app)
        .layer(axum::middleware::from_fn_with_state(doors, doors::guard))
}

/// A listener on `host` (an IP address) and `port` (0: any free one), and
/// whether the address is loopback (the only kind `mote view` binds to
/// without a warning).
pub fn bind(host: &str, port: u16) -> Result<(std::net::TcpListener, bool), String> {
    let ip: IpAddr = host
        .parse()
        .map_err(|_| format!("--bind {host}: not an IP address (127.0.0.1, ::1, 0.0.0.0, ...)"))?;
    let listener = std::net::TcpListener::bind(SocketAddr::new(ip, port))
        .map_err(|e| format!("cannot listen on {host}:{port}: {e}"))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot listen on {host}:{port}: {e}"))?;
    Ok((listener, ip.is_loopback()))
}

/// Serves `app` on `listener` until `shutdown` completes.
pub async fn serve(
    listener: std::net::TcpListener,
    app: Arc<App>,
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let doors = doors::Doors::new(listener.local_addr()?);
    let listener = tokio::net::TcpListener::from_std(listener)?;
    axum::serve(listener, router(app, doors))
        .with_graceful_shutdown(shutdown)
        .await
}
