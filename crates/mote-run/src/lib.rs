//! mote's one run loop.
//!
//! Every engine moves its state through a [`Propagator`]: the fixed-step
//! integrators and Brownian dynamics of point particles, the FRBI of rigid
//! clumps, and the event-driven engine (whose step is one output interval:
//! it jumps from collision to collision in between). A [`Driver`] steps a
//! propagator to its last step and owns what every run needs the same way:
//! the observers that sample it on their schedules, checkpoints, the
//! detection of a non-finite state, progress, a clean stop on a signal, and
//! the report the summary is made from.
//!
//! The order within a step is fixed, so that a run resumed from a
//! checkpoint writes exactly what the uninterrupted run would:
//! advance → check the state → sample the observers due → write the
//! checkpoint due → progress → the live tap (frames out, changes in) →
//! stop if a signal asked for it (after writing a checkpoint of this step
//! when checkpoints are on).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use mote_io::checkpoint::{self, Checkpoint};
use mote_io::xyz::Frame;

pub mod comm;
pub mod parallel;
pub mod scene;
mod steer;
mod trajectory;
pub use steer::{Change, FieldKind, Live, LiveSlot, Shown, WallGeometry};
pub use trajectory::Trajectory;

/// The most steps a run takes without being told `--force`: a run longer
/// than this is far more likely a time step or an end time mistyped
/// (`dt = 1e-300`) than a plan.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// The number of steps of size `dt` from time `t` to the first step at or
/// past `end`, the one rule of every time-stepped engine:
///
/// n = ⌈(end − t)/Δt − 10⁻⁹·max(1, (end − t)/Δt)⌉,
///
/// the small relative slack keeping an end that is a whole number of steps
/// as written (`until = 0.3` with `dt = 0.1`, where 0.3/0.1 = 3.0000000000000004)
/// from a step past it by round-off. Zero when `end ≤ t`; `None` when the
/// count is not a finite number a u64 holds (an end or a step that is not
/// finite, or `dt = 1e-300`).
pub fn steps_until(t: f64, end: f64, dt: f64) -> Option<u64> {
    let n = (end - t) / dt;
    if dt.is_nan() || dt <= 0.0 || n.is_nan() {
        return None;
    }
    if n <= 0.0 {
        return Some(0);
    }
    let n = (n - 1e-9 * n.max(1.0)).ceil();
    // 2^64 is the first f64 a u64 cannot hold.
    (n < 18_446_744_073_709_551_616.0).then_some(n as u64)
}

/// Refuses a run of more than [`MAX_STEPS`] steps unless `force`d; the
/// message says how many steps of what.
pub fn check_run_length(steps: u64, dt: f64, force: bool) -> Result<(), String> {
    if steps > MAX_STEPS && !force {
        return Err(format!(
            "{steps} steps of dt = {}: more than {MAX_STEPS}, which is most likely a time step \
             or an end time mistyped; give --force to run them",
            mote_io::system::human_number(dt)
        ));
    }
    Ok(())
}

/// Something that moves a state forward step by step.
pub trait Propagator {
    /// Whole-system observables of one instant, handed to the observers.
    type Sample: Clone;
    /// The engine's error; the driver's own ends come in as [`Stopped`],
    /// file errors as [`mote_io::IoError`].
    type Error: From<Stopped> + From<mote_io::IoError>;

    /// Steps done since the state was made (absolute: a resumed run goes
    /// on counting where its checkpoint stopped, so schedules line up).
    fn step(&self) -> u64;
    /// The simulated time.
    fn time(&self) -> f64;
    /// Makes ready to step: leap-frog's first forces, the event-driven
    /// engine's equilibration. `progress` may be called meanwhile.
    fn prime(&mut self, progress: &mut dyn FnMut(&Self)) -> Result<(), Self::Error> {
        let _ = progress;
        Ok(())
    }
    /// Advances one step.
    fn advance(&mut self) -> Result<(), Self::Error>;
    /// Whether the propagator has reached an end of its own (a packing
    /// that jammed): the run ends there, as at its last step.
    fn finished(&self) -> bool {
        false
    }
    /// The first particle (index, what is wrong) whose state is not a
    /// finite number, if any (on any rank of a decomposed run: every rank
    /// answers alike).
    fn unstable(&self) -> Option<(usize, String)>;
    /// The largest `x` over the ranks of a decomposed run, at every rank;
    /// `x` itself in one process. The ranks agree through it to stop
    /// together on a signal only some of them have seen.
    fn most(&self, x: f64) -> f64 {
        x
    }
    /// Measures the observables of now.
    fn measure(&mut self) -> Self::Sample;
    /// Puts the state (time, step, tables, what interactions carry) into a
    /// checkpoint that already holds the run's input and options.
    fn save(&mut self, cp: &mut Checkpoint) -> Result<(), Self::Error>;
    /// The particles (spheres) of now as a trajectory frame, for the live
    /// viewer; `None` if the engine cannot show itself.
    fn frame(&self) -> Option<Frame> {
        None
    }
    /// The walls where they are now, for the live viewer.
    fn walls(&self) -> Vec<WallGeometry> {
        Vec::new()
    }
    /// The force on each particle of [`Propagator::frame`] as of the last
    /// force evaluation, for the live viewer's inspector (empty if the
    /// engine keeps none).
    fn forces(&self) -> Vec<[f64; 3]> {
        Vec::new()
    }
    /// Applies a change asked for from outside (the live viewer) before
    /// the next step: what changed, in words ("dt 0.001 → 0.0005"), or why
    /// it cannot.
    fn change(&mut self, change: &Change) -> Result<String, String> {
        Err(format!(
            "{} cannot be changed in this engine",
            change.what()
        ))
    }
}

/// A sample whose values are named columns: an observables table's header
/// and rows, and what a caller reads without knowing the engine.
pub trait Columns {
    /// The name and unit of each column.
    const COLUMNS: &'static [(&'static str, &'static str)];
    /// The values, in the order of [`Columns::COLUMNS`].
    fn values(&self) -> Vec<f64>;
}

/// Something that samples a run on a schedule (tables, trajectories).
/// Observers are `Send`, so that a state and its driver can be stepped
/// from another thread (Python's, with its lock released).
pub trait Observer<P: Propagator>: Send {
    /// Sample when the step number is a multiple of this (≥ 1); the first
    /// and the last step of a run are always sampled.
    fn every(&self) -> u64;
    /// Samples the state; `sample` holds the observables of this instant.
    fn observe(&mut self, state: &P, sample: &P::Sample) -> Result<(), P::Error>;
    /// Files this observer writes, for the report.
    fn files(&self) -> Vec<String> {
        Vec::new()
    }
    /// Records an event of the run (a change made from the live viewer)
    /// where the samples of its time are: observables tables write it as a
    /// `# event:` comment line.
    fn event(&mut self, state: &P, text: &str) -> Result<(), P::Error> {
        let _ = (state, text);
        Ok(())
    }
}

/// What the other ranks of a decomposed run do where rank 0's observer
/// samples and writes: they take part in the measurement (the Driver's)
/// and, for a trajectory, in gathering the frame, and write nothing.
#[derive(Debug, Clone, Copy)]
pub struct Follower {
    /// The steps between the samples of the observer followed.
    pub every: u64,
    /// Whether that observer takes a frame ([`Propagator::frame`]).
    pub frames: bool,
}

impl<P: Propagator> Observer<P> for Follower {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, state: &P, _: &P::Sample) -> Result<(), P::Error> {
        if self.frames {
            state.frame();
        }
        Ok(())
    }
}

/// Where and how often a run writes its checkpoint.
#[derive(Debug, Clone)]
pub struct Checkpoints {
    /// Steps between checkpoints (≥ 1); one is also written at the last
    /// step and, when a signal stops the run, at the step it stopped.
    pub every: u64,
    pub path: PathBuf,
    /// The run's input, seed and options; the propagator adds its state.
    pub template: Checkpoint,
    /// Whether this process writes the file: false on the ranks of a
    /// decomposed run but rank 0, which take part in gathering the state
    /// at the same steps and write nothing.
    pub writes: bool,
}

/// How a run ended before its last step.
#[derive(Debug, Clone, PartialEq)]
pub enum Stopped {
    /// A position or velocity became a non-finite number; what the
    /// observers wrote until then stays on disk.
    Unstable {
        step: u64,
        time: f64,
        particle: usize,
        what: String,
    },
    /// A signal asked the run to stop; it stopped after a whole step.
    Interrupted { signal: i32, step: u64, time: f64 },
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct Report<S> {
    /// Steps taken in this run (not counting those before a resume).
    pub steps: u64,
    pub wall: Duration,
    /// The observables after priming and at the last step.
    pub initial: S,
    pub last: S,
    /// The files the observers and checkpoints wrote.
    pub files: Vec<String>,
}

/// The one run loop: observers, checkpoints, interruption, progress.
pub struct Driver<P: Propagator> {
    pub observers: Vec<Box<dyn Observer<P>>>,
    pub checkpoints: Option<Checkpoints>,
    /// Hand the starting state to the observers (false when resuming: the
    /// interrupted run already wrote it).
    pub sample_at_start: bool,
    /// The live viewer's tap: sees the state after priming and after every
    /// step, hands back changes (and holds the run while paused).
    pub live: Option<Box<dyn Live>>,
}

impl<P: Propagator> Default for Driver<P> {
    fn default() -> Self {
        Driver {
            observers: Vec::new(),
            checkpoints: None,
            sample_at_start: true,
            live: None,
        }
    }
}

impl<P: Propagator> Driver<P> {
    /// A run without observers or checkpoints.
    pub fn new() -> Self {
        Self::default()
    }

    /// Primes `state`, then steps it until step `last_step(state)` (asked
    /// after priming), calling `progress` after every step: [`Driver::start`]
    /// then [`Driver::advance_to`] the last step, as one run.
    pub fn run(
        &mut self,
        state: &mut P,
        last_step: impl FnOnce(&P) -> u64,
        mut progress: impl FnMut(&P),
    ) -> Result<Report<P::Sample>, P::Error> {
        let start = Instant::now();
        state.prime(&mut progress)?;
        let first = state.step();
        let last_step = last_step(state);
        let initial = self.begin(state)?;
        let last = self.advance_to(state, last_step, true, &mut progress)?;
        if let Some(live) = self.live.as_mut() {
            live.last(state.step(), state.time(), &mut || Self::shown(state));
        }
        // The last step's sample, measured here where no observer took it
        // (observables switched off): the summary's end time and energy
        // are the run's end, not its start.
        let last = match last {
            Some(s) => s,
            None if state.step() > first => state.measure(),
            None => initial.clone(),
        };
        let mut files: Vec<String> = self.observers.iter().flat_map(|o| o.files()).collect();
        if let Some(c) = &self.checkpoints {
            files.push(c.path.display().to_string());
        }
        Ok(Report {
            steps: state.step() - first,
            wall: start.elapsed(),
            initial,
            last,
            files,
        })
    }

    /// Primes `state`, measures it and hands that sample to the observers
    /// (when [`Driver::sample_at_start`]) and the state to the live tap:
    /// the start of a run. Returns the sample.
    pub fn start(
        &mut self,
        state: &mut P,
        progress: &mut dyn FnMut(&P),
    ) -> Result<P::Sample, P::Error> {
        state.prime(progress)?;
        self.begin(state)
    }

    /// Measures a primed state, hands the sample to the observers and the
    /// state to the live tap.
    fn begin(&mut self, state: &mut P) -> Result<P::Sample, P::Error> {
        let initial = state.measure();
        if self.sample_at_start {
            for o in &mut self.observers {
                o.observe(state, &initial)?;
            }
        }
        self.tap(state)?;
        Ok(initial)
    }

    /// Steps `state` to step `last_step` (a run after [`Driver::start`], or
    /// one stretch of it): observers sample at their multiples, checkpoints
    /// are written at theirs, a non-finite state or a signal stops it. With
    /// `ends_run`, `last_step` is the run's last: every observer samples it
    /// and a checkpoint is written there; a stretch that does not end the
    /// run samples only on the schedules, so stepping a run in stretches
    /// writes what stepping it whole does. Returns the last sample taken.
    pub fn advance_to(
        &mut self,
        state: &mut P,
        last_step: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(&P),
    ) -> Result<Option<P::Sample>, P::Error> {
        let mut last = None;
        while state.step() < last_step && !state.finished() {
            parallel::keep_warm();
            state.advance()?;
            let step = state.step();
            if let Some((particle, what)) = state.unstable() {
                return Err(Stopped::Unstable {
                    step,
                    time: state.time(),
                    particle,
                    what,
                }
                .into());
            }
            let end = ends_run && (step >= last_step || state.finished());
            let due = |o: &dyn Observer<P>| end || step.is_multiple_of(o.every().max(1));
            if self.observers.iter().any(|o| due(o.as_ref())) {
                let sample = state.measure();
                for o in &mut self.observers {
                    if due(o.as_ref()) {
                        o.observe(state, &sample)?;
                    }
                }
                last = Some(sample);
            }
            let saved = match &self.checkpoints {
                Some(c) if end || step.is_multiple_of(c.every.max(1)) => {
                    Self::save(c, state)?;
                    true
                }
                _ => false,
            };
            progress(state);
            self.tap(state)?;
            let asked = mote_io::system::stop_requested().unwrap_or(0);
            let signal = state.most(asked as f64) as i32;
            if signal != 0 && !end {
                if let Some(c) = self.checkpoints.as_ref().filter(|_| !saved) {
                    Self::save(c, state)?;
                }
                return Err(Stopped::Interrupted {
                    signal,
                    step,
                    time: state.time(),
                }
                .into());
            }
        }
        Ok(last)
    }

    /// Shows the state to the live tap and applies the changes it hands
    /// back, each recorded by the observers as an event and answered.
    fn tap(&mut self, state: &mut P) -> Result<(), P::Error> {
        let Some(live) = self.live.as_mut() else {
            return Ok(());
        };
        loop {
            let changes = live.between(state.step(), state.time(), &mut || Self::shown(state));
            if changes.is_empty() {
                return Ok(());
            }
            for change in changes {
                let answer = change.check().and_then(|_| state.change(&change));
                if let Ok(text) = &answer {
                    for o in &mut self.observers {
                        o.event(state, text)?;
                    }
                }
                live.answer(state.step(), state.time(), &change, &answer);
            }
        }
    }

    fn shown(state: &P) -> Option<Shown> {
        state.frame().map(|frame| Shown {
            frame,
            forces: state.forces(),
            walls: state.walls(),
        })
    }

    fn save(c: &Checkpoints, state: &mut P) -> Result<(), P::Error> {
        let mut cp = c.template.clone();
        state.save(&mut cp)?;
        if c.writes {
            checkpoint::write(&c.path, &cp)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod length_tests {
    use super::*;

    #[test]
    fn steps_until_reach_the_first_step_at_or_past_the_end() {
        assert_eq!(steps_until(0.0, 0.3, 0.1), Some(3));
        assert_eq!(steps_until(0.0, 0.35, 0.1), Some(4));
        assert_eq!(steps_until(0.0, 0.32, 0.1), Some(4));
        assert_eq!(steps_until(0.0, 365.25, 0.5), Some(731));
        assert_eq!(steps_until(1.0, 1.0, 0.1), Some(0));
        assert_eq!(steps_until(2.0, 1.0, 0.1), Some(0));
        // Every count from 1 to 10⁴ steps of an awkward dt comes back.
        let dt = 0.1 + 0.2;
        for n in 1..10_000u64 {
            assert_eq!(steps_until(0.0, n as f64 * dt, dt), Some(n), "{n}");
            let past = steps_until(0.0, (n as f64 + 0.5) * dt, dt).unwrap();
            assert_eq!(past, n + 1);
            assert!(past as f64 * dt >= (n as f64 + 0.5) * dt);
        }
        for bad in [
            (0.0, f64::NAN, 0.1),
            (0.0, 1.0, 0.0),
            (0.0, 1.0, -1.0),
            (0.0, 10.0, 1e-300),
        ] {
            assert_eq!(steps_until(bad.0, bad.1, bad.2), None, "{bad:?}");
        }
        assert_eq!(steps_until(0.0, f64::INFINITY, 0.1), None);
    }

    #[test]
    fn runs_longer_than_a_billion_steps_need_force() {
        assert!(check_run_length(MAX_STEPS, 0.1, false).is_ok());
        let e = check_run_length(MAX_STEPS + 1, 1e-9, false).unwrap_err();
        assert!(e.contains("--force"), "{e}");
        assert!(check_run_length(MAX_STEPS + 1, 1e-9, true).is_ok());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x' = −x by explicit Euler: x_{k+1} = (1 − h) x_k.
    struct Decay {
        x: f64,
        h: f64,
        step: u64,
    }

    #[derive(Debug)]
    #[allow(dead_code)] // read through Debug when a test fails
    enum DecayError {
        Stopped(Stopped),
        Io(mote_io::IoError),
    }
    impl From<Stopped> for DecayError {
        fn from(s: Stopped) -> Self {
            DecayError::Stopped(s)
        }
    }
    impl From<mote_io::IoError> for DecayError {
        fn from(e: mote_io::IoError) -> Self {
            DecayError::Io(e)
        }
    }

    impl Propagator for Decay {
        type Sample = f64;
        type Error = DecayError;
        fn step(&self) -> u64 {
            self.step
        }
        fn time(&self) -> f64 {
            self.step as f64 * self.h
        }
        fn advance(&mut self) -> Result<(), DecayError> {
            self.x *= 1.0 - self.h;
            self.step += 1;
            Ok(())
        }
        fn unstable(&self) -> Option<(usize, String)> {
            (!self.x.is_finite()).then(|| (0, format!("x = {}", self.x)))
        }
        fn measure(&mut self) -> f64 {
            self.x
        }
        fn save(&mut self, cp: &mut Checkpoint) -> Result<(), DecayError> {
            cp.step = self.step;
            cp.time = self.time();
            cp.positions = vec![[self.x, 0.0, 0.0]];
            cp.velocities = vec![[-self.x, 0.0, 0.0]];
            Ok(())
        }
        fn change(&mut self, change: &Change) -> Result<String, String> {
            match change {
                Change::Dt(h) => {
                    let text = format!("dt {} → {h}", self.h);
                    self.h = *h;
                    Ok(text)
                }
                other => Err(format!("{} cannot be changed", other.what())),
            }
        }
    }

    /// Asks for dt = 0.5 and a field at step 2; records the answers and
    /// the steps it saw.
    struct Steer(std::sync::Arc<std::sync::Mutex<Vec<String>>>, bool);
    impl Live for Steer {
        fn between(
            &mut self,
            step: u64,
            _time: f64,
            _frame: &mut dyn FnMut() -> Option<Shown>,
        ) -> Vec<Change> {
            self.0.lock().unwrap().push(format!("step {step}"));
            if step == 2 && !self.1 {
                self.1 = true;
                vec![
                    Change::Dt(0.5),
                    Change::Field {
                        kind: FieldKind::Gravity,
                        value: [0.0, 0.0, -1.0],
                    },
                    Change::Dt(-1.0),
                ]
            } else {
                Vec::new()
            }
        }
        fn answer(&mut self, _: u64, _: f64, _: &Change, answer: &Result<String, String>) {
            self.0.lock().unwrap().push(match answer {
                Ok(t) => format!("ok {t}"),
                Err(m) => format!("no {m}"),
            });
        }
    }

    /// Records the events the driver hands the observers.
    struct Events(std::sync::Arc<std::sync::Mutex<Vec<(u64, String)>>>);
    impl Observer<Decay> for Events {
        fn every(&self) -> u64 {
            1
        }
        fn observe(&mut self, _: &Decay, _: &f64) -> Result<(), DecayError> {
            Ok(())
        }
        fn event(&mut self, s: &Decay, text: &str) -> Result<(), DecayError> {
            self.0.lock().unwrap().push((s.step, text.to_string()));
            Ok(())
        }
    }

    /// Without observers the report still ends at the last step: its
    /// sample is measured there (it was the first step's, so a summary
    /// said a run of 10 steps ended at t = 0 with no energy drift).
    #[test]
    fn a_run_without_observers_reports_its_last_step() {
        let mut p = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        let report = Driver::new().run(&mut p, |_| 10, |_| {}).unwrap();
        assert_eq!(report.steps, 10);
        assert_eq!(report.initial, 1.0);
        let x10 = (0..10).fold(1.0, |x: f64, _| x * (1.0 - 0.1));
        assert_eq!(report.last, x10);
        let mut q = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        let none = Driver::new().run(&mut q, |_| 0, |_| {}).unwrap();
        assert_eq!((none.steps, none.last), (0, 1.0));
    }

    #[test]
    fn the_live_tap_changes_the_next_step_and_the_observers_record_it() {
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let events = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let mut d = Driver::new();
        d.live = Some(Box::new(Steer(log.clone(), false)));
        d.observers.push(Box::new(Events(events.clone())));
        let mut p = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        d.run(&mut p, |_| 4, |_| {}).unwrap();
        // Steps 1, 2 at h = 0.1, steps 3, 4 at h = 0.5.
        assert_eq!(p.x, 0.9 * 0.9 * 0.5 * 0.5);
        let log = log.lock().unwrap();
        assert_eq!(log[0], "step 0");
        assert_eq!(log[3], "ok dt 0.1 → 0.5");
        assert!(log[4].starts_with("no the gravity cannot"), "{}", log[4]);
        assert!(
            log[5].starts_with("no the time step: Dt(-1.0)"),
            "{}",
            log[5]
        );
        // Step 2 is shown again after its changes, before stepping on.
        assert_eq!(log[6], "step 2");
        assert_eq!(log.len(), 9);
        assert_eq!(
            *events.lock().unwrap(),
            vec![(2, "dt 0.1 → 0.5".to_string())]
        );
    }

    /// Records the steps it saw.
    struct Steps(u64, std::sync::Arc<std::sync::Mutex<Vec<u64>>>);
    impl Observer<Decay> for Steps {
        fn every(&self) -> u64 {
            self.0
        }
        fn observe(&mut self, s: &Decay, _: &f64) -> Result<(), DecayError> {
            self.1.lock().unwrap().push(s.step);
            Ok(())
        }
    }

    #[test]
    fn observers_see_the_start_their_schedule_and_the_last_step() {
        let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let mut d = Driver::new();
        d.observers.push(Box::new(Steps(4, seen.clone())));
        let mut p = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        let r = d.run(&mut p, |_| 10, |_| {}).unwrap();
        assert_eq!(*seen.lock().unwrap(), vec![0, 4, 8, 10]);
        assert_eq!(r.steps, 10);
        assert_eq!(r.initial, 1.0);
        assert_eq!(r.last, (0..10).fold(1.0, |x, _| x * 0.9));
    }

    /// A run stepped in stretches (Python's chunks and callbacks) samples
    /// what the run stepped whole samples, and ends in its state.
    #[test]
    fn stretches_sample_and_end_as_one_run() {
        let whole = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let mut d = Driver::new();
        d.observers.push(Box::new(Steps(4, whole.clone())));
        let mut p = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        d.run(&mut p, |_| 10, |_| {}).unwrap();

        let parts = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let mut d = Driver::new();
        d.observers.push(Box::new(Steps(4, parts.clone())));
        let mut q = Decay {
            x: 1.0,
            h: 0.1,
            step: 0,
        };
        assert_eq!(d.start(&mut q, &mut |_| {}).unwrap(), 1.0);
        for (to, ends) in [(3, false), (5, false), (9, false), (10, true)] {
            d.advance_to(&mut q, to, ends, &mut |_| {}).unwrap();
            assert_eq!(q.step, to);
        }
        assert_eq!(*parts.lock().unwrap(), *whole.lock().unwrap());
        assert_eq!(q.x.to_bits(), p.x.to_bits());
    }

    #[test]
    fn a_non_finite_state_stops_the_run_at_its_step() {
        let mut p = Decay {
            x: 1.0,
            h: f64::INFINITY,
            step: 0,
        };
        let e = Driver::new().run(&mut p, |_| 10, |_| {}).unwrap_err();
        match e {
            DecayError::Stopped(Stopped::Unstable { step, particle, .. }) => {
                assert_eq!((step, particle), (1, 0))
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn checkpoints_follow_their_schedule_and_the_last_step() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.mote");
        let mut d = Driver::<Decay>::new();
        d.checkpoints = Some(Checkpoints {
            writes: true,
            every: 3,
            path: path.clone(),
            template: Checkpoint {
                seed: 9,
                ..Checkpoint::default()
            },
        });
        let mut p = Decay {
            x: 1.0,
            h: 0.5,
            step: 0,
        };
        let mut written = Vec::new();
        d.run(
            &mut p,
            |_| 7,
            |s| {
                if path.exists() {
                    let cp = checkpoint::read(&path).unwrap();
                    written.push((s.step, cp.step));
                }
            },
        )
        .unwrap();
        assert_eq!(written, vec![(3, 3), (4, 3), (5, 3), (6, 6), (7, 7)]);
        let cp = checkpoint::read(&path).unwrap();
        assert_eq!(
            (cp.step, cp.seed, cp.positions[0][0]),
            (7, 9, 0.5f64.powi(7))
        );
    }
}
