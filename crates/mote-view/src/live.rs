//! Live runs: the tap the run's driver shows every step to, and the
//! WebSocket through which a page watches and steers the run.
//!
//! The run thread publishes into one [`tokio::sync::watch`] slot: the
//! latest step, time, pause state, log, and (only when a page asked for
//! one, at most 30 times a second) the latest frame. Each page's socket
//! sends a frame only after the page said it drew the previous one, so a
//! slow page gets fewer frames, never a queue: the server holds one frame
//! whatever the number or speed of the pages.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use axum::extract::ws::{Message, WebSocket};
use mote_io::xyz::Frame;
use mote_run::{Change, FieldKind, Live, Shown};
use serde::Deserialize;
use tokio::sync::watch;

use crate::table::Follow;

/// Frames are made at most this often,
const FRAME_INTERVAL: Duration = Duration::from_millis(33);
/// and at most this share of the run's time goes into making them (a
/// frame of 10⁶ spheres takes tens of milliseconds to copy).
const FRAME_SHARE: f64 = 0.05;
/// The log keeps this many entries.
const LOG_KEPT: usize = 200;

/// What the run is at, as the pages see it.
#[derive(Clone, Default)]
pub struct Snapshot {
    pub step: u64,
    pub time: f64,
    pub paused: bool,
    /// The latest frame (made when a page wanted one) and its number.
    pub frame: Option<Arc<Frame>>,
    pub serial: u64,
    /// The frame's species, sorted: colour index = position here.
    pub species: Arc<Vec<String>>,
    /// The walls as segments (x0, y0, z0, x1, y1, z1) around the frame.
    pub walls: Arc<Vec<[f64; 6]>>,
    /// The force on each particle of the frame (empty: not kept).
    pub forces: Arc<Vec<[f64; 3]>>,
    /// How the run ended, and whether it failed.
    pub ended: Option<(String, bool)>,
    /// The last [`LOG_KEPT`] answers and notes, and how many there were.
    pub log: Arc<Vec<String>>,
    pub logged: u64,
}

/// One live run and the pages watching it.
pub struct Session {
    pub label: String,
    /// The run's output folder (its observables.csv is followed).
    pub dir: PathBuf,
    /// What the page must show to open the socket (`doors::new_token`).
    pub token: String,
    latest: watch::Sender<Snapshot>,
    wanted: AtomicBool,
    paused: AtomicBool,
    changes: Mutex<Vec<Change>>,
    /// The share of the run's time frames may take (f64 bits).
    frame_share: AtomicU64,
}

impl Session {
    /// A session whose run starts `paused` or not.
    pub fn new(label: String, dir: PathBuf, paused: bool) -> Arc<Session> {
        Arc::new(Session {
            label,
            dir,
            token: crate::doors::new_token(),
            latest: watch::Sender::new(Snapshot::default()),
            wanted: AtomicBool::new(true),
            paused: AtomicBool::new(paused),
            changes: Mutex::new(Vec::new()),
            frame_share: AtomicU64::new(FRAME_SHARE.to_bits()),
        })
    }

    /// The tap to hand the run (`RunOptions::live`).
    pub fn tap(self: &Arc<Self>) -> Box<dyn Live> {
        Box::new(Tap {
            session: Arc::clone(self),
            last: None,
            interval: FRAME_INTERVAL,
            shown_paused: false,
        })
    }

    /// The latest snapshot.
    pub fn snapshot(&self) -> Snapshot {
        self.latest.borrow().clone()
    }

    /// Adds a line to the log the pages show.
    pub fn note(&self, text: String) {
        self.latest.send_modify(|s| {
            let mut log: Vec<String> = s.log.as_ref().clone();
            log.push(text);
            if log.len() > LOG_KEPT {
                log.drain(..log.len() - LOG_KEPT);
            }
            s.log = Arc::new(log);
            s.logged += 1;
        });
    }

    /// The run has ended: `text` says how (its summary or its error).
    pub fn end(&self, text: String, failed: bool) {
        self.latest.send_modify(|s| {
            s.ended = Some((text, failed));
            s.paused = false;
        });
    }

    /// Queues a change for the run's next step (or now, when paused).
    pub fn ask(&self, change: Change) {
        if let Ok(mut c) = self.changes.lock() {
            c.push(change);
        }
    }

    /// Lets frames take this share of the run's time (default 5 %; 1: as
    /// many as the pages ask for, up to 30 a second).
    pub fn set_frame_share(&self, share: f64) {
        self.frame_share.store(share.to_bits(), Ordering::Relaxed);
    }

    pub fn set_paused(&self, paused: bool) {
        self.paused.store(paused, Ordering::Relaxed);
    }

    fn publish_frame(&self, step: u64, time: f64, shown: Shown) {
        let Shown {
            frame,
            forces,
            walls,
        } = shown;
        let (lo, hi) = crate::outline::extent(&frame, &walls);
        let walls = crate::outline::outlines(&walls, lo, hi);
        let mut species: Vec<String> = frame.species.clone();
        species.sort_unstable();
        species.dedup();
        self.latest.send_modify(|s| {
            s.step = step;
            s.time = time;
            s.serial += 1;
            s.frame = Some(Arc::new(frame));
            s.walls = Arc::new(walls);
            s.forces = Arc::new(forces);
            if *s.species != species {
                s.species = Arc::new(species);
            }
        });
    }
}

/// Runs `options` through mote's front in a thread of its own (with a
/// pool of as many threads as the caller's), watched through `session`.
/// `report` says how the run ended, as the line the pages show and whether
/// it failed (the binary also prints it there).
pub fn spawn_run(
    mut options: mote_front::RunOptions,
    session: &Arc<Session>,
    report: impl FnOnce(&Result<mote_front::Outcome, mote_front::FrontError>) -> (String, bool)
        + Send
        + 'static,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    options.live = mote_run::LiveSlot::new(session.tap());
    let session = Arc::clone(session);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(rayon::current_num_threads())
        .build()
        .map_err(std::io::Error::other)?;
    std::thread::Builder::new()
        .name("mote run".into())
        .spawn(move || {
            let result = pool.install(|| mote_front::run(&options, &mut mote_front::Silent));
            let (text, failed) = report(&result);
            session.end(text, failed);
        })
}

/// The usual ending line: the summary, the instability, the signal or the
/// error.
pub fn ending(result: &Result<mote_front::Outcome, mote_front::FrontError>) -> (String, bool) {
    use mote_front::Ending;
    match result {
        Ok(o) => match &o.ending {
            Ending::Finished => (o.summary.join(" "), false),
            Ending::Unstable(m) => (m.clone(), true),
            Ending::Interrupted { message, .. } => (message.clone(), false),
        },
        Err(e) => (e.to_string(), true),
    }
}

/// The run thread's side.
struct Tap {
    session: Arc<Session>,
    /// When the last snapshot went out.
    last: Option<Instant>,
    /// The wait between frames: [`FRAME_INTERVAL`], or longer where making
    /// a frame takes more than [`FRAME_SHARE`] of it.
    interval: Duration,
    /// Whether the pages were last told the run is paused.
    shown_paused: bool,
}

impl Tap {
    /// Publishes step and time at most every [`FRAME_INTERVAL`], with a
    /// frame when a page wants one.
    fn show(&mut self, step: u64, time: f64, frame: &mut dyn FnMut() -> Option<Shown>) {
        let s = &self.session;
        let due = self.last.is_none_or(|t| t.elapsed() >= self.interval);
        if !due {
            return;
        }
        let now = Instant::now();
        self.last = Some(now);
        if s.wanted.swap(false, Ordering::Relaxed) {
            if let Some(f) = frame() {
                s.publish_frame(step, time, f);
                let cost = now.elapsed().as_secs_f64();
                let share = f64::from_bits(s.frame_share.load(Ordering::Relaxed));
                self.interval = FRAME_INTERVAL.max(Duration::from_secs_f64(cost / share));
                return;
            }
        }
        s.latest.send_if_modified(|snap| {
            let changed = snap.step != step;
            snap.step = step;
            snap.time = time;
            changed
        });
    }

    fn take_changes(&self) -> Vec<Change> {
        self.session
            .changes
            .lock()
            .map(|mut c| std::mem::take(&mut *c))
            .unwrap_or_default()
    }
}

impl Live for Tap {
    fn between(
        &mut self,
        step: u64,
        time: f64,
        frame: &mut dyn FnMut() -> Option<Shown>,
    ) -> Vec<Change> {
        self.show(step, time, frame);
        let changes = self.take_changes();
        if !changes.is_empty() {
            return changes;
        }
        let s = Arc::clone(&self.session);
        // Held here while paused: frames on request, changes applied at
        // once (the driver calls again after them), a signal still ends
        // the run.
        loop {
            let paused =
                s.paused.load(Ordering::Relaxed) && mote_io::system::stop_requested().is_none();
            if paused != self.shown_paused {
                self.shown_paused = paused;
                s.latest.send_modify(|snap| {
                    snap.paused = paused;
                    snap.step = step;
                    snap.time = time;
                });
            }
            if !paused {
                return Vec::new();
            }
            std::thread::sleep(Duration::from_millis(15));
            let changes = self.take_changes();
            if !changes.is_empty() {
                return changes;
            }
            if s.wanted.swap(false, Ordering::Relaxed) {
                if let Some(f) = frame() {
                    s.publish_frame(step, time, f);
                }
            }
        }
    }

    fn last(&mut self, step: u64, time: f64, frame: &mut dyn FnMut() -> Option<Shown>) {
        match frame() {
            Some(f) => self.session.publish_frame(step, time, f),
            None => self.session.latest.send_modify(|s| {
                s.step = step;
                s.time = time;
            }),
        }
    }

    fn answer(&mut self, step: u64, time: f64, change: &Change, answer: &Result<String, String>) {
        self.session.note(match answer {
            Ok(text) => format!("step {step}, t = {time:.6e}: {text}"),
            Err(why) => format!("step {step}: not changed: {why} ({change:?})"),
        });
        // The change shows at once, even while paused.
        self.session.wanted.store(true, Ordering::Relaxed);
        self.last = None;
    }
}

/// What a page sends.
#[derive(Deserialize, Debug)]
#[serde(rename_all = "lowercase", tag = "do")]
enum Command {
    /// The page drew the last frame and can take another.
    Ready,
    /// Colour the frames by this quantity.
    Color {
        quantity: String,
    },
    Pause,
    Resume,
    /// Send this particle's columns with every frame (none: stop).
    Pick {
        index: Option<usize>,
    },
    /// Change dt, damping or temperature (`value`), or a field (`kind`,
    /// `vector`).
    Set {
        what: String,
        value: Option<f64>,
        kind: Option<String>,
        vector: Option<[f64; 3]>,
    },
}

fn change_of(
    what: &str,
    value: Option<f64>,
    kind: Option<&str>,
    vector: Option<[f64; 3]>,
) -> Result<Change, String> {
    let number = || value.ok_or_else(|| format!("set {what}: no value"));
    match what {
        "dt" => Ok(Change::Dt(number()?)),
        "damping" => Ok(Change::Damping(number()?)),
        "temperature" => Ok(Change::Temperature(number()?)),
        "field" => {
            let kind = kind.unwrap_or("magnetic");
            let kind = FieldKind::named(kind)
                .ok_or_else(|| format!("set field: kind {kind}: expected {}", FieldKind::NAMES))?;
            let value = vector.ok_or("set field: no vector")?;
            Ok(Change::Field { kind, value })
        }
        other => Err(format!(
            "set {other}: expected dt, field, damping or temperature"
        )),
    }
}

/// One page's socket: snapshots and frames out, commands in, the
/// observables table followed.
pub async fn client(mut socket: WebSocket, session: Arc<Session>) {
    let mut latest = session.latest.subscribe();
    let mut table = Follow::new(session.dir.join("observables.csv"));
    let mut tick = tokio::time::interval(Duration::from_millis(300));
    let mut color = "species".to_string();
    let mut pick: Option<usize> = None;
    let mut ready = true;
    let mut sent_serial = 0;
    let mut logged = 0;
    session.wanted.store(true, Ordering::Relaxed);
    loop {
        let mut message = None;
        tokio::select! {
            incoming = socket.recv() => match incoming {
                Some(Ok(Message::Text(text))) => match serde_json::from_str::<Command>(&text) {
                    Ok(Command::Ready) => ready = true,
                    Ok(Command::Color { quantity }) => {
                        color = quantity;
                        sent_serial = 0;
                    }
                    Ok(Command::Pause) => session.set_paused(true),
                    Ok(Command::Resume) => session.set_paused(false),
                    Ok(Command::Pick { index }) => pick = index,
                    Ok(Command::Set { what, value, kind, vector }) => {
                        match change_of(&what, value, kind.as_deref(), vector) {
                            _ if latest.borrow().ended.is_some() => {
                                message = Some(error_message(&format!("set {what}: the run has ended")))
                            }
                            Ok(c) => session.ask(c),
                            Err(m) => message = Some(error_message(&m)),
                        }
                    }
                    Err(e) => message = Some(error_message(&format!("not a command: {e}"))),
                },
                Some(Ok(Message::Close(_))) | None | Some(Err(_)) => return,
                Some(Ok(_)) => {}
            },
            changed = latest.changed() => if changed.is_err() { return },
            _ = tick.tick() => {
                if let Some(t) = table.poll(1 << 20) {
                    let json = serde_json::json!({ "type": "observables", "table": t });
                    if socket.send(Message::Text(json.to_string().into())).await.is_err() {
                        return;
                    }
                }
                continue;
            }
        }
        if let Some(m) = message {
            if socket.send(m).await.is_err() {
                return;
            }
        }
        let snap = latest.borrow_and_update().clone();
        let fresh: Vec<&String> = {
            let new = (snap.logged - logged.min(snap.logged)) as usize;
            snap.log
                .iter()
                .skip(snap.log.len().saturating_sub(new))
                .collect()
        };
        logged = snap.logged;
        let status = serde_json::json!({
            "type": "status",
            "step": snap.step,
            "time": snap.time,
            "paused": snap.paused,
            "ended": snap.ended.as_ref().map(|e| &e.0),
            "failed": snap.ended.as_ref().is_some_and(|e| e.1),
            "log": fresh,
        });
        if socket
            .send(Message::Text(status.to_string().into()))
            .await
            .is_err()
        {
            return;
        }
        let Some(frame) = snap.frame.as_ref() else {
            continue;
        };
        if !ready {
            continue;
        }
        if snap.serial == sent_serial {
            // The page is ready and has this frame: ask the run for the next.
            session.wanted.store(true, Ordering::Relaxed);
            continue;
        }
        let bytes = match crate::encode_frame(frame, &snap.species, &color) {
            Ok(b) => b,
            Err(m) => {
                color = "species".into();
                if socket.send(error_message(&m)).await.is_err() {
                    return;
                }
                continue;
            }
        };
        let head = serde_json::json!({
            "type": "frame",
            "serial": snap.serial,
            "step": snap.step,
            "time": frame.time,
            "count": frame.positions.len(),
            "cell": frame.cell,
            "origin": frame.origin,
            "species": *snap.species,
            "walls": *snap.walls,
            "quantities": mote_render::frame::quantities_of(frame),
            "color": color,
            "particle": pick.and_then(|i| {
                let mut p = crate::particle_json(frame, i).ok()?;
                if let Some(f) = snap.forces.get(i) {
                    p["force"] = serde_json::json!(f);
                }
                Some(p)
            }),
        });
        if socket
            .send(Message::Text(head.to_string().into()))
            .await
            .is_err()
            || socket.send(Message::Binary(bytes.into())).await.is_err()
        {
            return;
        }
        ready = false;
        sent_serial = snap.serial;
    }
}

fn error_message(m: &str) -> Message {
    Message::Text(
        serde_json::json!({ "type": "error", "message": m })
            .to_string()
            .into(),
    )
}
