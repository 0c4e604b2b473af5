//! Steering a run from outside: the changes a live viewer may ask for and
//! the tap through which it sees the run.

use mote_io::xyz::Frame;

/// A wall as a viewer draws it, where it is now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallGeometry {
    /// The plane through `point` with unit `normal`.
    Plane { point: [f64; 3], normal: [f64; 3] },
    /// The cylinder of `radius` about the line through `point` along unit
    /// `axis`, turned by `angle` (radians) about it since t = 0.
    Cylinder {
        point: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        angle: f64,
    },
}

/// What a viewer is shown of a state: its particles, the force on each
/// (empty where the engine keeps none) and its walls.
#[derive(Debug, Clone, Default)]
pub struct Shown {
    pub frame: Frame,
    pub forces: Vec<[f64; 3]>,
    pub walls: Vec<WallGeometry>,
}

/// Which uniform external field a [`Change::Field`] sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldKind {
    /// The applied magnetic field (H or B, in the scene's units).
    Magnetic,
    /// The applied electric field E.
    Electric,
    /// Gravity: the uniform acceleration g.
    Gravity,
}

impl FieldKind {
    pub const NAMES: &'static str = "magnetic, electric or gravity";

    pub fn named(name: &str) -> Option<FieldKind> {
        match name {
            "magnetic" => Some(FieldKind::Magnetic),
            "electric" => Some(FieldKind::Electric),
            "gravity" => Some(FieldKind::Gravity),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            FieldKind::Magnetic => "magnetic field",
            FieldKind::Electric => "electric field",
            FieldKind::Gravity => "gravity",
        }
    }
}

/// A change to a running simulation, applied before its next step.
#[derive(Debug, Clone, PartialEq)]
pub enum Change {
    /// The time step Δt.
    Dt(f64),
    /// The value of a constant, uniform external field.
    Field { kind: FieldKind, value: [f64; 3] },
    /// The damping coefficient: γ of global damping F = −γ m v (point
    /// particles), the air's viscosity η of Stokes drag (rigid bodies).
    Damping(f64),
    /// The thermostat's (or Brownian dynamics') temperature k_BT.
    Temperature(f64),
}

impl Change {
    /// What the change sets, in words.
    pub fn what(&self) -> String {
        match self {
            Change::Dt(_) => "the time step".into(),
            Change::Field { kind, .. } => format!("the {}", kind.name()),
            Change::Damping(_) => "the damping".into(),
            Change::Temperature(_) => "the temperature".into(),
        }
    }

    /// Refuses a value that no engine can use: Δt must be positive and
    /// finite, damping and temperature non-negative and finite, a field
    /// finite.
    pub fn check(&self) -> Result<(), String> {
        let ok = match self {
            Change::Dt(v) => *v > 0.0 && v.is_finite(),
            Change::Damping(v) | Change::Temperature(v) => *v >= 0.0 && v.is_finite(),
            Change::Field { value, .. } => value.iter().all(|v| v.is_finite()),
        };
        if ok {
            Ok(())
        } else {
            Err(format!("{}: {self:?} is not a usable value", self.what()))
        }
    }
}

/// The live viewer's tap on a run ([`crate::Driver::live`]).
pub trait Live: Send {
    /// Called after priming and after every step. `frame` makes the
    /// particles and walls of now (call it only when a frame is wanted: it
    /// copies the state). Returns the changes to apply before the next step, and is
    /// called again once they are applied, until it returns none: a paused
    /// viewer holds the run inside this call and returns the changes made
    /// meanwhile without letting it step.
    fn between(
        &mut self,
        step: u64,
        time: f64,
        frame: &mut dyn FnMut() -> Option<Shown>,
    ) -> Vec<Change>;
    /// The run reached its last step: show it (called once, not after an
    /// unstable step or a signal).
    fn last(&mut self, step: u64, time: f64, frame: &mut dyn FnMut() -> Option<Shown>) {
        let _ = (step, time, frame);
    }
    /// The answer to a change: what changed, or why it could not.
    fn answer(&mut self, step: u64, time: f64, change: &Change, answer: &Result<String, String>);
}

/// A place for a [`Live`] tap that travels with a run's options (which
/// are cloned on the way) until the run's driver takes it, once.
#[derive(Clone, Default)]
pub struct LiveSlot(std::sync::Arc<std::sync::Mutex<Option<Box<dyn Live>>>>);

impl LiveSlot {
    pub fn new(live: Box<dyn Live>) -> Self {
        LiveSlot(std::sync::Arc::new(std::sync::Mutex::new(Some(live))))
    }

    /// The tap, for the driver (None when there is none or it was taken).
    pub fn take(&self) -> Option<Box<dyn Live>> {
        self.0.lock().ok()?.take()
    }

    /// Whether a tap waits here.
    pub fn is_set(&self) -> bool {
        self.0.lock().map(|s| s.is_some()).unwrap_or(false)
    }
}

impl std::fmt::Debug for LiveSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.is_set() {
            "LiveSlot(set)"
        } else {
            "LiveSlot(empty)"
        })
    }
}
