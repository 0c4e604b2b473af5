//! The tables of the scene envelope every engine reads the same way:
//! `[run]` (what the run's length and step are), `[output]` (the folder and
//! when files are written) and `[box]` (the box), with
//! each value's origin, so that an error names the line that gave it, or
//! the command-line option that replaced it.
//!
//! One grammar for every engine: a key an engine cannot take is refused at
//! its line with the reason ([`RunTable::refuse`]); the run's length is
//! read by one rule ([`RunTable::length`], [`RunLength::steps_from`]).

use serde::Deserialize;
use toml::Spanned;

use mote_io::trajectory::Format;
use mote_io::{ParseError, Source};

/// A setting and where it was given.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting<T> {
    pub value: T,
    pub origin: Origin,
}

/// Where a [`Setting`] was given.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// In the scene text, at this byte span.
    Scene(std::ops::Range<usize>),
    /// By a command-line option or argument (`--dt`) replacing the scene's.
    Option(&'static str),
    /// Nowhere: the default, or an MPPphys particle file's own.
    Default,
}

impl<T: std::fmt::Display> Setting<T> {
    /// The value as `option` gave it.
    pub fn from_option(option: &'static str, value: T) -> Self {
        Setting {
            value,
            origin: Origin::Option(option),
        }
    }

    /// A value given nowhere in particular (a default, a particle file's).
    pub fn plain(value: T) -> Self {
        Setting {
            value,
            origin: Origin::Default,
        }
    }

    /// An error about this setting: `file:line: message` where the scene
    /// gave it, `file: --option value: message` where an option did.
    pub fn error(&self, src: Source, message: impl Into<String>) -> ParseError {
        match &self.origin {
            Origin::Scene(span) => src.error(span.clone(), message),
            Origin::Option(option) => ParseError::new(
                src.file,
                0,
                format!("{option} {}: {}", self.value, message.into()),
            ),
            Origin::Default => src.whole(message),
        }
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Setting<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let spanned = Spanned::<T>::deserialize(d)?;
        Ok(Setting {
            origin: Origin::Scene(spanned.span()),
            value: spanned.into_inner(),
        })
    }
}

/// How long to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunLength {
    /// A number of steps.
    Steps(u64),
    /// Until the first step at or past the simulated time T
    /// ([`crate::steps_until`], the rule of every engine).
    Until(f64),
}

impl RunLength {
    /// Number of steps from time `t` with step `dt`; the reason where
    /// `Until` gives no count a run can take (a non-finite end, `dt = 1e-300`).
    pub fn steps_from(self, t: f64, dt: f64) -> Result<u64, String> {
        match self {
            RunLength::Steps(n) => Ok(n),
            RunLength::Until(end) => crate::steps_until(t, end, dt).ok_or_else(|| {
                let n = mote_io::system::human_number;
                format!(
                    "until {} from t = {} with dt = {}: not a number of steps a run can take",
                    n(end),
                    n(t),
                    n(dt)
                )
            }),
        }
    }
}

/// `[run]`, as every engine spells it. Each engine takes the keys that
/// mean something to it and refuses the others at their line
/// ([`RunTable::refuse`]): event-driven runs have no `dt`, rigid bodies no
/// `integrator`, only event-driven runs `equilibrate`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunTable {
    /// The integrator of point particles (`leapfrog`, `euler`, `rk4`, …).
    pub integrator: Option<Setting<String>>,
    /// The time step of the time-stepped engines.
    pub dt: Option<Setting<f64>>,
    /// The run's length as a number of steps …
    pub steps: Option<Setting<u64>>,
    /// … or as the time it ends at (the first step at or past it).
    pub until: Option<Setting<f64>>,
    /// Simulated time run first, without measuring (event-driven runs).
    pub equilibrate: Option<Setting<f64>>,
    /// Move to the centre-of-mass frame before the run (point particles).
    pub centre_of_mass: Option<Setting<bool>>,
}

/// A `file:line: [table] key: why` error for the first of `keys` that
/// `given` finds (its origin and value as written), `file: --option value:
/// why` where an option gave it.
fn refuse_given(
    table: &str,
    src: Source,
    keys: &[(&str, &str)],
    given: impl Fn(&str) -> Option<(Origin, String)>,
) -> Result<(), ParseError> {
    for (key, why) in keys {
        if let Some((origin, value)) = given(key) {
            let message = format!("[{table}] {key}: {why}");
            return Err(match origin {
                Origin::Scene(span) => src.error(span, message),
                Origin::Option(option) => {
                    ParseError::new(src.file, 0, format!("{option} {value}: {why}"))
                }
                Origin::Default => src.whole(message),
            });
        }
    }
    Ok(())
}

/// The origin and the value as written of a setting, if it was given.
fn shown<T: std::fmt::Display>(s: &Option<Setting<T>>) -> Option<(Origin, String)> {
    s.as_ref().map(|s| (s.origin.clone(), s.value.to_string()))
}

impl RunTable {
    /// Where `key` was given and its value as written, if it was.
    fn given(&self, key: &str) -> Option<(Origin, String)> {
        match key {
            "integrator" => shown(&self.integrator),
            "dt" => shown(&self.dt),
            "steps" => shown(&self.steps),
            "until" => shown(&self.until),
            "equilibrate" => shown(&self.equilibrate),
            "centre_of_mass" => shown(&self.centre_of_mass),
            _ => None,
        }
    }

    /// Refuses the first of `keys` the scene (or an option) gave, with its
    /// reason: `file:line: [run] key: why`.
    pub fn refuse(&self, src: Source, keys: &[(&str, &str)]) -> Result<(), ParseError> {
        refuse_given("run", src, keys, |k| self.given(k))
    }

    /// The time step, where one is given: positive and finite, else an
    /// error at its line (or option).
    pub fn time_step(&self, src: Source) -> Result<Option<f64>, ParseError> {
        match &self.dt {
            Some(dt) if dt.value > 0.0 && dt.value.is_finite() => Ok(Some(dt.value)),
            Some(dt) => Err(dt.error(src, format!("dt must be positive, found {}", dt.value))),
            None => Ok(None),
        }
    }

    /// The run's length, where one is given: `steps`, or `until` a time
    /// after the start (t = 0); both together are refused.
    pub fn length(&self, src: Source) -> Result<Option<RunLength>, ParseError> {
        match (&self.steps, &self.until) {
            (Some(_), Some(until)) => Err(until.error(src, "[run] takes steps or until, not both")),
            (Some(s), None) => Ok(Some(RunLength::Steps(s.value))),
            (None, Some(t)) if t.value > 0.0 && t.value.is_finite() => {
                Ok(Some(RunLength::Until(t.value)))
            }
            (None, Some(t)) => {
                let why = "must be a time after the start (t = 0); steps = 0 runs none";
                Err(match t.origin {
                    Origin::Scene(_) => t.error(src, format!("until = {}: {why}", t.value)),
                    _ => t.error(src, why),
                })
            }
            (None, None) => Ok(None),
        }
    }

    /// Replaces the scene's step and length by the options that give
    /// them: `--dt`, and `--steps` or `--until` (either replaces both
    /// `steps` and `until` of the scene).
    pub fn with_options(&mut self, dt: Option<f64>, steps: Option<u64>, until: Option<f64>) {
        if let Some(dt) = dt {
            self.dt = Some(Setting::from_option("--dt", dt));
        }
        if let Some(n) = steps {
            self.steps = Some(Setting::from_option("--steps", n));
            self.until = None;
        } else if let Some(t) = until {
            self.until = Some(Setting::from_option("--until", t));
            self.steps = None;
        }
    }
}

/// `[output]`, as every engine spells it: the folder, and when and how
/// the files are written. The time-stepped engines count steps
/// (`observables_every`, `trajectory_every`; 0 turns a file off), the
/// event-driven engine counts time (`interval`) and switches files on and
/// off (`observables`, `trajectory`, `histogram`); each engine refuses the
/// keys it cannot take at their line ([`OutputTable::refuse`]).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputTable {
    /// Folder of the output files (default `out/<scene name>`).
    pub dir: Option<String>,
    /// Steps between rows of observables.csv (default 10); 0 turns it off.
    pub observables_every: Option<Setting<u64>>,
    /// Steps between frames of the trajectory (default 100); 0 turns it off.
    pub trajectory_every: Option<Setting<u64>>,
    /// Simulated time between rows and frames (event-driven runs).
    pub interval: Option<Setting<f64>>,
    /// Write observables.csv (event-driven runs; default true).
    pub observables: Option<Setting<bool>>,
    /// Write the trajectory (event-driven runs; default true).
    pub trajectory: Option<Setting<bool>>,
    /// Write speeds.csv, the speed histogram (event-driven runs; default true).
    pub histogram: Option<Setting<bool>>,
    /// Format of the trajectory: `xyz` (default), `dump`, `gsd` or `vtk`.
    pub trajectory_format: Option<Setting<String>>,
    /// Per-particle quantities added to observables.csv (point particles).
    #[serde(default)]
    pub inspect: Vec<Spanned<String>>,
    /// Add the pressure tensor to observables.csv (point particles).
    pub pressure_tensor: Option<Setting<bool>>,
}

impl OutputTable {
    /// Steps between rows of observables.csv (default 10; 0: none).
    pub fn observables_every(&self) -> u64 {
        self.observables_every.as_ref().map_or(10, |s| s.value)
    }

    /// Steps between frames of the trajectory (default 100; 0: none).
    pub fn trajectory_every(&self) -> u64 {
        self.trajectory_every.as_ref().map_or(100, |s| s.value)
    }

    /// Whether a file the event-driven engine switches (`observables`,
    /// `trajectory`, `histogram`) is written: as given, else yes.
    pub fn writes(&self, file: &Option<Setting<bool>>) -> bool {
        file.as_ref().is_none_or(|s| s.value)
    }

    /// The trajectory's format (`trajectory_format`, default extended XYZ),
    /// else an error at its line naming the formats.
    pub fn trajectory_format(&self, src: Source) -> Result<Format, ParseError> {
        match &self.trajectory_format {
            None => Ok(Format::Xyz),
            Some(f) => Format::named(&f.value).ok_or_else(|| {
                f.error(
                    src,
                    format!(
                        "trajectory_format '{}' is not one of {}",
                        f.value,
                        Format::NAMES
                    ),
                )
            }),
        }
    }

    /// Where `key` was given and its value as written, if it was.
    fn given(&self, key: &str) -> Option<(Origin, String)> {
        match key {
            "observables_every" => shown(&self.observables_every),
            "trajectory_every" => shown(&self.trajectory_every),
            "interval" => shown(&self.interval),
            "observables" => shown(&self.observables),
            "trajectory" => shown(&self.trajectory),
            "histogram" => shown(&self.histogram),
            "trajectory_format" => shown(&self.trajectory_format),
            "pressure_tensor" => shown(&self.pressure_tensor),
            "inspect" => self
                .inspect
                .first()
                .map(|p| (Origin::Scene(p.span()), p.get_ref().clone())),
            _ => None,
        }
    }

    /// Refuses the first of `keys` the scene gave, with its reason:
    /// `file:line: [output] key: why`.
    pub fn refuse(&self, src: Source, keys: &[(&str, &str)]) -> Result<(), ParseError> {
        refuse_given("output", src, keys, |k| self.given(k))
    }
}

/// `[box]`, as every engine spells it: the corners `lo` (default the
/// origin) and `hi` and which axes are `periodic` (default all), each with
/// its span. Each engine checks the number
/// of axes and what it requires ([`BoxTable::axes`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxTable {
    pub lo: Option<Spanned<Vec<f64>>>,
    pub hi: Option<Spanned<Vec<f64>>>,
    pub periodic: Option<Spanned<Vec<bool>>>,
}

impl BoxTable {
    /// Checks that each list given has `d` entries and that `hi` > `lo`
    /// on every axis where both are given; errors at the list's line.
    pub fn axes(&self, src: Source, d: usize) -> Result<(), ParseError> {
        let count = |name: &str, span: std::ops::Range<usize>, n: usize| {
            if n == d {
                Ok(())
            } else {
                Err(src.error(
                    span,
                    format!("[box] {name} must list {d} entries, one per axis (found {n})"),
                ))
            }
        };
        if let Some(lo) = &self.lo {
            count("lo", lo.span(), lo.get_ref().len())?;
        }
        if let Some(hi) = &self.hi {
            count("hi", hi.span(), hi.get_ref().len())?;
        }
        if let Some(p) = &self.periodic {
            count("periodic", p.span(), p.get_ref().len())?;
        }
        if let Some(hi) = &self.hi {
            let (l, h) = (self.lo(d), hi.get_ref());
            if (0..d).any(|k| h[k] <= l[k] || h[k].is_nan() || l[k].is_nan()) {
                return Err(src.error(hi.span(), "[box] needs lo < hi on every axis"));
            }
        }
        Ok(())
    }

    /// The lower corner: as given, else the origin (the default of every
    /// engine).
    pub fn lo(&self, d: usize) -> Vec<f64> {
        self.lo
            .as_ref()
            .map_or_else(|| vec![0.0; d], |lo| lo.get_ref().clone())
    }

    /// Which axes are periodic: as given, else every axis (the default
    /// of every engine).
    pub fn periodic(&self, d: usize) -> Vec<bool> {
        self.periodic
            .as_ref()
            .map_or_else(|| vec![true; d], |p| p.get_ref().clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> RunTable {
        #[derive(Deserialize)]
        struct Scene {
            run: RunTable,
        }
        toml::from_str::<Scene>(text).unwrap().run
    }

    #[test]
    fn a_refused_key_is_named_at_its_line_or_option() {
        let src = Source::new("s.toml", "title = 'x'\n[run]\nsteps = 4\ndt = 0.1\n");
        let mut run = table(src.text);
        let e = run.refuse(src, &[("dt", "no time step here")]).unwrap_err();
        assert_eq!(
            (e.line, e.message.as_str()),
            (4, "[run] dt: no time step here")
        );
        run.dt = None;
        run.with_options(Some(0.5), None, None);
        let e = run.refuse(src, &[("dt", "no time step here")]).unwrap_err();
        assert_eq!(e.message, "--dt 0.5: no time step here");
    }

    #[test]
    fn the_length_is_steps_or_an_end_after_the_start() {
        let src = Source::new("s.toml", "[run]\nsteps = 4\nuntil = 2.0\n");
        let e = table(src.text).length(src).unwrap_err();
        assert_eq!(e.line, 3);
        let src = Source::new("s.toml", "[run]\nuntil = -1.0\n");
        assert_eq!(table(src.text).length(src).unwrap_err().line, 2);
        let mut run = table(src.text);
        run.with_options(None, Some(7), None);
        assert_eq!(run.length(src).unwrap(), Some(RunLength::Steps(7)));
        assert_eq!(RunLength::Until(0.3).steps_from(0.0, 0.1), Ok(3));
        assert!(RunLength::Until(1.0).steps_from(0.0, 1e-300).is_err());
    }

    #[test]
    fn a_box_with_the_wrong_number_of_axes_is_refused_at_its_line() {
        #[derive(Deserialize)]
        struct Scene {
            #[serde(rename = "box")]
            bounds: BoxTable,
        }
        let text = "[box]\nlo = [0, 0]\nhi = [1, 1, 1]\n";
        let b = toml::from_str::<Scene>(text).unwrap().bounds;
        let e = b.axes(Source::new("s.toml", text), 3).unwrap_err();
        assert_eq!(e.line, 2);
        let text = "[box]\nlo = [0, 0]\nhi = [1, -1]\n";
        let b = toml::from_str::<Scene>(text).unwrap().bounds;
        assert_eq!(b.axes(Source::new("s.toml", text), 2).unwrap_err().line, 3);
        assert_eq!(b.periodic(2), vec![true, true]);
        // lo defaults to the origin, and hi must lie beyond it
        let text = "[box]\nhi = [1, -1, 1]\n";
        let b = toml::from_str::<Scene>(text).unwrap().bounds;
        assert_eq!(b.lo(3), vec![0.0; 3]);
        assert_eq!(b.axes(Source::new("s.toml", text), 3).unwrap_err().line, 2);
    }
}
