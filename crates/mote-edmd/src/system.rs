//! The event-driven system: particles in free flight between instantaneous
//! elastic collisions, one source for disks (D = 2) and spheres (D = 3).
//!
//! Collision rule: 002 §2.4, Eq. (9a,b) (elastic, per-particle masses).
//! Collision prediction: the robust quadratic of Bannerman, Strobl, Lue &
//! Ziegler, arXiv:1211.6718 (overlapping *and* approaching pairs collide now;
//! the root is taken in the cancellation-free form `c / (−b + √(b² − ac))`).
//! Scheduling: one event per particle in an indexed binary heap, invalidated
//! by per-particle collision counters (Smallenburg, arXiv:2201.01099);
//! neighbours from symmetric neighbour lists with a skin: particle i lists
//! every j with |x_i − x_j| < r_i + k_i + r_j + k_j at the moment it builds
//! its list, and rebuilds it (a "neighbour-list event", the analogue of a
//! cell crossing) when it has moved its skin k_i from where it built it, so
//! two unlisted particles cannot touch. k_i = (s − 1)·min(r_i, 2 r_median)
//! (s from [`shell_factor`]): Smallenburg's shell s(r_i + r_j) for all but
//! the largest spheres, which keep a typical sphere's skin. Lists are built
//! from a hierarchy of cell grids, one per size class ([`crate::cells`]).
//! Free flight is lazy (each
//! particle keeps its own time `t_i` and is advanced only when it takes part
//! in an event).
//!
//! Growth (Lubachevsky–Stillinger; 003 §III.1, KTS Eq. 17): with a growth
//! rate δ ≠ 0 ([`System::with_growth`]) every radius is r_i(t) = r_i(0)(1 + δt),
//! the contact distance σ_ij(t) = σ_ij(0)(1 + δt) grows at s = σ_ij(0)δ, the
//! prediction solves |r + vt|² = (σ + st)² ([`growing_pair_time`]) and a
//! collision reflects the normal relative velocity in the frame of the growing
//! surfaces, u_n → 2s − u_n. Neighbour lists and cells are built for the
//! radii at a *horizon* time t_h (R_i = r_i(t_h)), so they stay valid up to
//! t_h; the caller (the packer, [`crate::pack`]) starts a fresh system there.
//! The event loop itself does not change; δ = 0 runs the original code.

use crate::cells::{Cells, ListPos};
use crate::queue::EventQueue;
use crate::vecd::{add_scaled, dot, sub};
use crate::EdmdError;
use mote_geom::lanes::{Lanes, LANES};
use serde::{Deserialize, Serialize};

/// What one axis of the box does at its faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Boundary {
    /// The axis wraps around.
    Periodic,
    /// Hard reflecting walls at 0 and L.
    Wall,
}

/// The box `[0, L_0] × … × [0, L_{D-1}]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimBox<const D: usize> {
    pub size: [f64; D],
    pub boundary: [Boundary; D],
}

impl<const D: usize> SimBox<D> {
    pub fn volume(&self) -> f64 {
        self.size.iter().product()
    }
}

/// The kind of a scheduled event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    None,
    Collision,
    /// Has moved (s − 1) r_i from where it built its neighbour list.
    Rebuild,
    /// Hits the wall of `axis` (`up`: the wall at L).
    Wall,
}

/// A particle's scheduled event, and for a collision what comes next if
/// it turns out stale: a light form of DynamO's per-particle event lists
/// (Bannerman, Sargant & Lue, J. Comput. Chem. 32, 3329 (2011), Sec. 3.2).
///
/// When the partner collides first, the prediction of every other listed
/// pair still holds (their trajectories did not change, or they changed and
/// were predicted again with this particle among their neighbours, so their
/// own events come no later than their contact with it). The next event is
/// then the earlier of the list's second-earliest contact — if that
/// partner's counter has not moved either — and the skin or wall event: no
/// scan of the list is needed.
#[derive(Debug, Clone, Copy)]
struct Event {
    kind: Kind,
    /// The wall of a `Wall` event (also of a wall fallback).
    axis: u8,
    up: bool,
    /// What follows a stale collision: `Collision` (with `later`),
    /// `Rebuild` or `Wall` at `later_time`; `None`: scan the list again.
    fallback: Kind,
    partner: u32,
    /// The partner's collision counter when the event was predicted.
    partner_count: u32,
    later: u32,
    later_count: u32,
    later_time: f64,
}

const NO_EVENT: Event = Event {
    kind: Kind::None,
    axis: 0,
    up: false,
    fallback: Kind::None,
    partner: u32::MAX,
    partner_count: 0,
    later: u32::MAX,
    later_count: 0,
    later_time: f64::INFINITY,
};

/// The two earliest contact times of a list scan and their positions in
/// the list (`u32::MAX`: none), ties to the first in the list: what every
/// scan (scalar, `Lanes`, AVX-512) keeps, offered each time in list order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TwoEarliest {
    pub t: [f64; 2],
    pub at: [u32; 2],
}

impl TwoEarliest {
    pub const NONE: Self = TwoEarliest {
        t: [f64::INFINITY; 2],
        at: [u32::MAX; 2],
    };

    /// Takes the time `t` of list position `at`, by selects (a NaN is never
    /// earlier).
    #[inline(always)]
    pub fn offer(&mut self, t: f64, at: u32) {
        let first = t < self.t[0];
        let second = !first & (t < self.t[1]);
        self.t[1] = if first {
            self.t[0]
        } else if second {
            t
        } else {
            self.t[1]
        };
        self.at[1] = if first {
            self.at[0]
        } else if second {
            at
        } else {
            self.at[1]
        };
        self.t[0] = if first { t } else { self.t[0] };
        self.at[0] = if first { at } else { self.at[0] };
    }

    /// Offers a block of eight times from list position `base` on (lanes
    /// past the list's end hold +∞); skipped whole when none is earlier
    /// than the second.
    #[inline(always)]
    pub fn offer_block(&mut self, t: &[f64; 8], base: usize) {
        let min = t
            .iter()
            .fold(f64::INFINITY, |m, &x| if x < m { x } else { m });
        if min < self.t[1] {
            for (l, &x) in t.iter().enumerate() {
                self.offer(x, (base + l) as u32);
            }
        }
    }
}

const NONE: u32 = u32::MAX;

/// Hints the CPU to load `x` into cache (no effect on results).
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching is a hint; the pointer comes from a valid reference.
    unsafe {
        std::arch::x86_64::_mm_prefetch(x as *const T as *const i8, std::arch::x86_64::_MM_HINT_T0);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// `vec![value; n]` in memory the kernel may back with 2 MiB pages (Linux
/// transparent huge pages, `madvise`): the event loop touches its arrays at
/// random, and with 4 KiB pages a system of 10⁵–10⁶ particles spends much
/// of its time on TLB misses. Elsewhere (or if refused) a plain vector.
pub(crate) fn huge_vec<T: Clone>(n: usize, value: T) -> Vec<T> {
    let mut v: Vec<T> = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let bytes = n * std::mem::size_of::<T>();
        if bytes >= 2 * HUGE {
            let start = v.as_mut_ptr() as usize;
            let lo = start.next_multiple_of(HUGE);
            let hi = (start + bytes) / HUGE * HUGE;
            if hi > lo {
                // SAFETY: [lo, hi) lies inside the vector's fresh, untouched
                // allocation; MADV_HUGEPAGE only changes how it is backed.
                unsafe {
                    libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
                }
            }
        }
    }
    v.resize(n, value);
    v
}

/// Neighbour shell factor s at packing fraction η: pairs closer than
/// s(r_i + r_j) are listed (Smallenburg's `shellsize`, 1.5 in his code).
/// Chosen so that a particle has about 16 (3-D) or 10 (2-D) listed
/// neighbours — 8ηs³ = 16, 4ηs² = 10 — which gives s ≈ 1.65 at η = 0.45
/// (measured slightly faster than 1.5 here) and a wide shell in dilute gases,
/// where a narrow one would be renewed many times per free path. Clamped to
/// [1.3, 4].
pub fn shell_factor(dim: usize, eta: f64) -> f64 {
    let s = if dim == 2 {
        (2.5 / eta).sqrt()
    } else {
        (2.0 / eta).cbrt()
    };
    if s.is_finite() {
        s.clamp(1.3, 4.0)
    } else {
        4.0
    }
}

/// The skin k_i of a particle of list radius `r`: it renews its list when
/// it has moved k_i from where it built it, so pairs farther apart than
/// R_i + k_i + R_j + k_j then cannot touch before one of them renews.
/// k = (s − 1)·min(R, cap): for sizes up to `cap` the list reach is
/// s·R (Smallenburg's shell); larger spheres, which move as fast in a
/// packing (equal masses), keep a skin of a typical sphere's.
#[inline]
fn skin(r: f64, shell: f64, cap: f64) -> f64 {
    (shell - 1.0) * r.min(cap)
}

/// The reach ρ_i = R_i + k_i: pairs with |x_i − x_j| < ρ_i + ρ_j are listed.
#[inline]
fn list_reach(r: f64, shell: f64, cap: f64) -> f64 {
    r + skin(r, shell, cap)
}

/// Position `x` at the particle's own time `t`, velocity `v`, radius `r`.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Particle<const D: usize> {
    x: [f64; D],
    v: [f64; D],
    t: f64,
    r: f64,
}

// The AVX-512 scan loads a record as one line of eight doubles:
// x (D), v (D), t, r.
const _: () = assert!(std::mem::size_of::<Particle<2>>() == 64);
const _: () = assert!(std::mem::size_of::<Particle<3>>() == 64);

/// Running totals since the last [`System::reset_counters`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counters {
    /// Pair collisions.
    pub collisions: u64,
    /// Wall collisions.
    pub wall_hits: u64,
    /// Neighbour-list rebuilds.
    pub rebuilds: u64,
    /// Events found invalid when they came up.
    pub invalid: u64,
    /// Σ r_ij·Δp_i over pair collisions (the collision virial).
    pub virial: f64,
    /// Σ |Δp| over wall collisions, per axis.
    pub wall_impulse_sum: f64,
    /// Simulated time at the start of the counting window.
    pub since: f64,
}

/// The state of a hard-sphere (D = 3) or hard-disk (D = 2) system.
///
/// Positions are stored at each particle's own time `t_i`; use
/// [`System::position`] for the position at the current time or
/// [`System::synchronize`] to advance everyone.
#[derive(Debug, Clone)]
pub struct System<const D: usize> {
    pub(crate) simbox: SimBox<D>,
    /// Hot per-particle data, one cache line per sphere (internal order).
    p: Vec<Particle<D>>,
    mass: Vec<f64>,
    /// Caller's index of internal particle k, and internal index of caller's i.
    id: Vec<u32>,
    slot: Vec<u32>,
    /// Collisions (and other velocity changes) of each particle, wrapping:
    /// an event is stale when its partner's count moved on.
    count: Vec<u32>,
    /// Cell lists for the list builds, one grid per size class.
    cells: Cells<D>,
    /// Slot ranges of the cells a list build visits (reused).
    ranges: Vec<(u32, u32)>,
    // neighbour lists: row i of `nbr` (capacity `cap`) holds nn[i] entries
    /// Where each particle built its neighbour list, with its radius.
    xn: Vec<ListPos<D>>,
    nbr: Vec<u32>,
    nn: Vec<u32>,
    cap: usize,
    shell: f64,
    // events
    events: Vec<Event>,
    queue: EventQueue,
    now: f64,
    counters: Counters,
    max_radius: f64,
    /// Relative growth rate δ: r_i(t) = r_i(0)(1 + δt); 0 for plain EDMD.
    growth: f64,
    /// Lists and cells are valid up to this time (+∞ without growth).
    horizon: f64,
    /// r_i(horizon)/r_i(0): lists are built for radii R_i = r_i(0)·factor.
    list_factor: f64,
    /// Skins are capped at (s − 1)·`skin_cap` (twice the median list
    /// radius), so a large sphere lists a thin shell of small ones.
    skin_cap: f64,
    /// Scan neighbour lists with AVX-512 (same results as the scalar loop).
    simd: bool,
    /// The neighbour scan on [`Lanes`] where AVX-512 is not used.
    lanes: bool,
}

/// Time until two particles at relative position `r` with relative velocity
/// `v` reach the contact distance `sigma`, or +∞.
///
/// Bannerman et al., arXiv:1211.6718, Sec. 3: a pair that is (by round-off)
/// already inside contact and approaching collides now; otherwise the earlier
/// root of `a t² + 2 b t + c = 0`, `a = v·v`, `b = r·v`, `c = r·r − σ²`, is
/// computed as `c / (−b + √(b² − ac))`, which has no cancellation for b < 0.
#[inline]
pub fn pair_time<const D: usize>(r: &[f64; D], v: &[f64; D], sigma: f64) -> f64 {
    approach_root(dot(v, v), dot(r, v), dot(r, r) - sigma * sigma)
}

/// Time until a pair at relative position `r`, relative velocity `v` and
/// contact distance `sigma` growing at rate `s` touches, or +∞: the earlier
/// positive root of A t² + 2B t + C = 0 with A = v·v − s², B = r·v − σs,
/// C = r·r − σ² (|r + vt| = σ + st). As in [`pair_time`] (Bannerman et al.),
/// a pair inside contact that approaches in the growing frame (B < 0)
/// collides now; the root C/(−B + √(B² − AC)) is free of cancellation and
/// also holds for A < 0 (growth faster than the relative speed), where a
/// receding pair is still caught.
#[inline]
pub fn growing_pair_time<const D: usize>(r: &[f64; D], v: &[f64; D], sigma: f64, s: f64) -> f64 {
    let b = dot(r, v) - sigma * s;
    let a = dot(v, v) - s * s;
    let c = dot(r, r) - sigma * sigma;
    growing_root(a, b, c)
}

/// The root of [`growing_pair_time`] from its coefficients A, B, C.
#[inline(always)]
fn growing_root(a: f64, b: f64, c: f64) -> f64 {
    if c <= 0.0 {
        return if b < 0.0 {
            0.0
        } else if a < 0.0 {
            // momentarily receding, overlapping by round-off: meet when the
            // growth takes over
            -b / a
        } else {
            f64::INFINITY
        };
    }
    let disc = b * b - a * c;
    let root = c / (-b + disc.max(0.0).sqrt());
    if (b < 0.0 || a < 0.0) && disc >= 0.0 {
        root
    } else {
        f64::INFINITY
    }
}

/// The contact time of [`pair_time`] from a = v·v, b = r·v, c = r·r − σ²,
/// written without branches (selects only), so that a loop over
/// neighbours runs without mispredictions: +∞ unless approaching (b < 0)
/// with a real root; 0 when approaching inside contact (Bannerman et al.).
#[inline(always)]
fn approach_root(a: f64, b: f64, c: f64) -> f64 {
    let disc = b * b - a * c;
    let root = c / (-b + disc.max(0.0).sqrt());
    let t = if c <= 0.0 { 0.0 } else { root };
    if b < 0.0 && disc >= 0.0 {
        t
    } else {
        f64::INFINITY
    }
}

/// What the vector neighbour scans need to know about the particle `i`
/// itself (advanced to `now`) and the box.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Probe<const D: usize> {
    pub x: [f64; D],
    pub v: [f64; D],
    /// Radius at time 0 (the records hold radii at time 0 too).
    pub r: f64,
    pub now: f64,
    pub size: [f64; D],
    pub half: [f64; D],
    pub periodic: [bool; D],
    /// Growth factor 1 + δ·now and rate δ (1 and 0 without growth).
    pub g: f64,
    pub delta: f64,
}

/// The two earliest contact times with the particles of `list` and their
/// positions in `list`: the scalar scan of `System::predict` eight
/// neighbours at a time on [`Lanes`] (every CPU; AVX2 on the x86-64-v3
/// build), each lane the scalar loop's operations in its order (no fused
/// multiply–adds, the same selects), so every time is the scalar's to the
/// bit and the earliest are the same partners, ties to the first in the
/// list.
fn earliest_lanes<const D: usize, const GROW: bool>(
    p: &[Particle<D>],
    list: &[u32],
    own: usize,
    probe: &Probe<D>,
) -> TwoEarliest {
    let mut two = TwoEarliest::NONE;
    for (block, chunk) in list.chunks(LANES).enumerate() {
        let m = chunk.len();
        // Lanes past the list's end read the particle's own record; their
        // times are discarded below.
        let rec: [&Particle<D>; LANES] =
            std::array::from_fn(|k| &p[if k < m { chunk[k] as usize } else { own }]);
        let field = |f: &dyn Fn(&Particle<D>) -> f64| Lanes(rec.map(f));
        let dtj = Lanes::splat(probe.now) - field(&|q| q.t);
        let rj = field(&|q| q.r);
        let mut r = [Lanes::splat(0.0); D];
        let mut v = [Lanes::splat(0.0); D];
        for d in 0..D {
            let (xj, vj) = (field(&|q| q.x[d]), field(&|q| q.v[d]));
            r[d] = Lanes::splat(probe.x[d]) - (xj + vj * dtj);
            v[d] = Lanes::splat(probe.v[d]) - vj;
            if probe.periodic[d] {
                let (half, size) = (probe.half[d], probe.size[d]);
                let up = r[d].map(|x| if x > half { size } else { 0.0 });
                let down = r[d].map(|x| if x < -half { size } else { 0.0 });
                r[d] = r[d] - up + down;
            }
        }
        let dot =
            |a: &[Lanes; D], b: &[Lanes; D]| (0..D).fold(Lanes::splat(0.0), |s, d| s + a[d] * b[d]);
        let t = if GROW {
            let sigma0 = rj + probe.r;
            let (sigma, sdot) = (sigma0 * probe.g, sigma0 * probe.delta);
            let b = dot(&r, &v) - sigma * sdot;
            let a = dot(&v, &v) - sdot * sdot;
            let c = dot(&r, &r) - sigma * sigma;
            Lanes(std::array::from_fn(|k| {
                growing_root(a.0[k], b.0[k], c.0[k])
            }))
        } else {
            let sigma = rj + probe.r;
            let c = dot(&r, &r) - sigma * sigma;
            approach_root_lanes(dot(&v, &v), dot(&r, &v), c)
        };
        let mut t = t.0;
        t[m..].fill(f64::INFINITY);
        two.offer_block(&t, LANES * block);
    }
    two
}

/// [`approach_root`] lane by lane, with selects.
#[inline(always)]
fn approach_root_lanes(a: Lanes, b: Lanes, c: Lanes) -> Lanes {
    let disc = b * b - a * c;
    let root = c / (b.map(|x| -x) + disc.map(|x| x.max(0.0)).sqrt());
    let t = Lanes(std::array::from_fn(|k| {
        if c.0[k] <= 0.0 {
            0.0
        } else {
            root.0[k]
        }
    }));
    Lanes(std::array::from_fn(|k| {
        if (b.0[k] < 0.0) & (disc.0[k] >= 0.0) {
            t.0[k]
        } else {
            f64::INFINITY
        }
    }))
}

/// Whether the AVX-512 neighbour scan runs here (x86-64 with AVX-512F, and
/// a record of at most eight doubles).
fn simd_available<const D: usize>() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        2 * D + 2 <= 8 && crate::avx512::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl<const D: usize> System<D> {
    /// Builds a system; checks that particles lie inside the box and do not
    /// overlap (relative tolerance 1e-9 of the contact distance), and
    /// schedules the first events.
    pub fn new(
        simbox: SimBox<D>,
        positions: Vec<[f64; D]>,
        velocities: Vec<[f64; D]>,
        radii: Vec<f64>,
        masses: Vec<f64>,
    ) -> Result<Self, EdmdError> {
        Self::with_growth(
            simbox,
            positions,
            velocities,
            radii,
            masses,
            0.0,
            f64::INFINITY,
        )
    }

    /// A system of growing particles: `radii` are the radii at time 0 and
    /// grow as r_i(t) = r_i(0)(1 + `growth`·t) (KTS, 003 Eq. 17). Neighbour
    /// lists and cells hold for the radii at `horizon` (finite when growth ≠
    /// 0); events after it must not be processed ([`System::horizon`]).
    pub fn with_growth(
        simbox: SimBox<D>,
        positions: Vec<[f64; D]>,
        velocities: Vec<[f64; D]>,
        radii: Vec<f64>,
        masses: Vec<f64>,
        growth: f64,
        horizon: f64,
    ) -> Result<Self, EdmdError> {
        let (growth, horizon) = if growth == 0.0 {
            (0.0, f64::INFINITY)
        } else {
            (growth, horizon)
        };
        let g_end = if growth == 0.0 {
            1.0
        } else {
            1.0 + growth * horizon
        };
        if !(growth >= 0.0 && growth.is_finite() && g_end.is_finite() && g_end >= 1.0) {
            return Err(EdmdError::Invalid(format!(
                "growth rate {growth} and horizon {horizon} must be finite and non-negative"
            )));
        }
        let n = positions.len();
        if velocities.len() != n || radii.len() != n || masses.len() != n {
            return Err(EdmdError::Invalid(
                "positions, velocities, radii and masses differ in length".into(),
            ));
        }
        if n >= NONE as usize {
            return Err(EdmdError::Invalid("too many particles".into()));
        }
        for (i, (&r, &m)) in radii.iter().zip(&masses).enumerate() {
            if !(r > 0.0 && r.is_finite() && m > 0.0 && m.is_finite()) {
                return Err(EdmdError::Invalid(format!(
                    "particle {i}: radius {r} and mass {m} must be positive and finite"
                )));
            }
            if velocities[i].iter().any(|x| !x.is_finite()) {
                return Err(EdmdError::Invalid(format!(
                    "particle {i}: velocity is not finite"
                )));
            }
        }
        let max_radius = radii.iter().cloned().fold(0.0, f64::max);
        // cells and shells are sized for the radii at the horizon
        let max_list_radius = max_radius * g_end;
        let unit = if D == 2 {
            std::f64::consts::PI
        } else {
            4.0 / 3.0 * std::f64::consts::PI
        };
        let eta = radii.iter().map(|r| unit * r.powi(D as i32)).sum::<f64>() / simbox.volume();
        let mut shell = shell_factor(D, eta);
        // periodic axes need three cells of width s·(largest diameter)
        for d in 0..D {
            if simbox.boundary[d] == Boundary::Periodic && max_radius > 0.0 {
                let smax = simbox.size[d] / (3.0 * 2.0 * max_list_radius * (1.0 + 4e-9));
                shell = shell.min(smax);
            }
        }
        if shell < 1.05 {
            return Err(EdmdError::Invalid(format!(
                "periodic box {:?} too small for diameter {}: each periodic length must exceed 3.15 largest diameters",
                simbox.size,
                2.0 * max_list_radius
            )));
        }
        for d in 0..D {
            let l = simbox.size[d];
            if !(l > 0.0 && l.is_finite()) {
                return Err(EdmdError::Invalid(format!(
                    "box length {l} on axis {d} must be positive"
                )));
            }
        }
        let skin_cap = {
            let mut r: Vec<f64> = radii.iter().map(|r| r * g_end).collect();
            if r.is_empty() {
                f64::INFINITY
            } else {
                2.0 * *r.select_nth_unstable_by(n / 2, f64::total_cmp).1
            }
        };
        let reach = |r: f64| list_reach(r * g_end, shell, skin_cap);
        let reaches: Vec<f64> = radii.iter().map(|&r| reach(r)).collect();
        let cells = Cells::new(&simbox, &reaches);
        // Store particles in Morton (Z) order of their cells on the finest
        // grid, so that neighbours in space are mostly neighbours in memory;
        // the public API keeps the caller's numbering (`id`, `slot`).
        let key = |x: &[f64; D]| -> u64 {
            let mut y = *x;
            for d in 0..D {
                let l = simbox.size[d];
                y[d] = if y[d].is_finite() {
                    y[d].rem_euclid(l)
                } else {
                    0.0
                };
            }
            let c = cells.finest_cell(&y);
            let mut k = 0u64;
            let bits = 64 / D;
            for d in 0..D {
                for b in 0..bits {
                    k |= ((c[d] as u64 >> b) & 1) << (b * D + d);
                }
            }
            k
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&i| key(&positions[i]));
        let mut slot = vec![0u32; n];
        for (k, &i) in order.iter().enumerate() {
            slot[i] = k as u32;
        }
        let mut p = huge_vec(
            n,
            Particle {
                x: [0.0; D],
                v: [0.0; D],
                t: 0.0,
                r: 0.0,
            },
        );
        for (k, &i) in order.iter().enumerate() {
            p[k] = Particle {
                x: positions[i],
                v: velocities[i],
                t: 0.0,
                r: radii[i],
            };
        }
        let mut mass = huge_vec(n, 0.0);
        for (k, &i) in order.iter().enumerate() {
            mass[k] = masses[i];
        }
        let id = order.iter().map(|&i| i as u32).collect();
        // the same grids, with each particle's level in internal order
        let internal: Vec<f64> = order.iter().map(|&i| reaches[i]).collect();
        let cells = Cells::new(&simbox, &internal);
        let mut sys = System {
            simbox,
            p,
            mass,
            id,
            slot,
            count: huge_vec(n, 0),
            cells,
            ranges: Vec::new(),
            xn: huge_vec(n, ListPos::ZERO),
            nbr: huge_vec(n * 16, 0),
            nn: vec![0; n],
            cap: 16,
            shell,
            events: huge_vec(n, NO_EVENT),
            queue: EventQueue::new(n, 0.0, 1.0),
            now: 0.0,
            counters: Counters::default(),
            max_radius,
            growth,
            horizon,
            list_factor: g_end,
            skin_cap,
            simd: simd_available::<D>(),
            lanes: !simd_available::<D>(),
        };
        for i in 0..n {
            for d in 0..D {
                let x = sys.p[i].x[d];
                let r = sys.p[i].r;
                let l = simbox.size[d];
                let ok = match simbox.boundary[d] {
                    Boundary::Periodic => x.is_finite(),
                    Boundary::Wall => x - r >= -1e-12 * l && x + r <= l * (1.0 + 1e-12),
                };
                if !ok {
                    return Err(EdmdError::Invalid(format!(
                        "particle {} at {:?} (radius {r}) is outside the box {:?}",
                        sys.id[i], sys.p[i].x, simbox.size
                    )));
                }
                if simbox.boundary[d] == Boundary::Periodic {
                    sys.p[i].x[d] = x.rem_euclid(l);
                    if sys.p[i].x[d] >= l {
                        sys.p[i].x[d] = 0.0;
                    }
                }
            }
            sys.xn[i] = ListPos {
                x: sys.p[i].x,
                r: reach(sys.p[i].r),
            };
            sys.cells.insert(i, sys.xn[i]);
        }
        for i in 0..n {
            sys.scan_neighbours(i, true);
        }
        if let Some((i, j, gap)) = sys.find_overlap(1e-9) {
            return Err(EdmdError::Invalid(format!(
                "particles {i} and {j} overlap (distance/contact − 1 = {gap:.3e})"
            )));
        }
        for i in 0..n {
            sys.predict(i);
        }
        sys.tune_queue();
        Ok(sys)
    }

    /// Chooses the calendar's block length so that a block holds about 32
    /// events: with τ̄ the mean time to each particle's next event, events
    /// come at a rate ≈ N/τ̄.
    fn tune_queue(&mut self) {
        let n = self.len();
        let (mut sum, mut k) = (0.0, 0usize);
        for i in 0..n {
            let t = self.queue.time(i) - self.now;
            if t.is_finite() {
                sum += t;
                k += 1;
            }
        }
        let tau = if k > 0 && sum > 0.0 {
            sum / k as f64
        } else {
            1.0
        };
        let dt = 32.0 * tau / n.max(1) as f64;
        self.queue.retune(self.now, dt);
    }

    // ----- accessors -----------------------------------------------------

    pub fn len(&self) -> usize {
        self.p.len()
    }
    pub fn is_empty(&self) -> bool {
        self.p.is_empty()
    }
    /// Current simulated time.
    pub fn time(&self) -> f64 {
        self.now
    }
    pub fn simbox(&self) -> &SimBox<D> {
        &self.simbox
    }
    /// Radii in the caller's numbering (as are all per-particle accessors).
    pub fn radii(&self) -> Vec<f64> {
        self.slot.iter().map(|&k| self.rad(k as usize)).collect()
    }
    pub fn radius(&self, i: usize) -> f64 {
        self.rad(self.slot[i] as usize)
    }
    /// Radius of internal particle k now.
    #[inline]
    fn rad(&self, k: usize) -> f64 {
        self.p[k].r * self.growth_factor()
    }
    /// r_i(now)/r_i(0) = 1 + δ·now (1 without growth).
    #[inline]
    pub fn growth_factor(&self) -> f64 {
        1.0 + self.growth * self.now
    }
    /// The relative growth rate δ.
    pub fn growth_rate(&self) -> f64 {
        self.growth
    }
    /// The time up to which neighbour lists and cells hold.
    pub fn horizon(&self) -> f64 {
        self.horizon
    }
    pub fn velocity(&self, i: usize) -> [f64; D] {
        self.p[self.slot[i] as usize].v
    }
    pub fn masses(&self) -> Vec<f64> {
        self.slot.iter().map(|&k| self.mass[k as usize]).collect()
    }
    pub fn velocities(&self) -> Vec<[f64; D]> {
        self.slot.iter().map(|&k| self.p[k as usize].v).collect()
    }
    pub fn counters(&self) -> &Counters {
        &self.counters
    }
    /// Cells per axis of each grid of the cell hierarchy, finest first
    /// (one grid unless the list radii span a factor of 2 or more).
    pub fn cell_grids(&self) -> Vec<[usize; D]> {
        self.cells.shapes()
    }
    /// The neighbour shell factor s in use.
    pub fn shell(&self) -> f64 {
        self.shell
    }
    /// Largest radius (now).
    pub fn max_radius(&self) -> f64 {
        self.max_radius * self.growth_factor()
    }

    /// Position of particle `i` at the current time (inside the box, up to
    /// a quarter diameter beyond a periodic face).
    pub fn position(&self, i: usize) -> [f64; D] {
        self.pos_int(self.slot[i] as usize)
    }

    #[inline]
    fn pos_int(&self, k: usize) -> [f64; D] {
        add_scaled(&self.p[k].x, &self.p[k].v, self.now - self.p[k].t)
    }

    /// Positions of all particles at the current time.
    pub fn positions(&self) -> Vec<[f64; D]> {
        (0..self.len()).map(|i| self.position(i)).collect()
    }

    /// Advances every particle to the current time (does not change any
    /// trajectory or scheduled event).
    pub fn synchronize(&mut self) {
        for i in 0..self.len() {
            self.advance(i);
        }
    }

    #[inline]
    fn advance(&mut self, i: usize) {
        let dt = self.now - self.p[i].t;
        if dt != 0.0 {
            self.p[i].x = add_scaled(&self.p[i].x, &self.p[i].v, dt);
            self.p[i].t = self.now;
        }
    }

    /// Kinetic energy Σ m v²/2.
    pub fn kinetic_energy(&self) -> f64 {
        self.p
            .iter()
            .zip(&self.mass)
            .map(|(p, m)| 0.5 * m * dot(&p.v, &p.v))
            .sum()
    }

    /// Total momentum Σ m v.
    pub fn momentum(&self) -> [f64; D] {
        let mut p = [0.0; D];
        for (q, m) in self.p.iter().zip(&self.mass) {
            for d in 0..D {
                p[d] += m * q.v[d];
            }
        }
        p
    }

    /// Temperature k_B T = 2 K / (D N) (no degrees of freedom removed).
    pub fn temperature(&self) -> f64 {
        2.0 * self.kinetic_energy() / (D as f64 * self.len() as f64)
    }

    /// Packing fraction: Σ particle volumes / box volume.
    pub fn packing_fraction(&self) -> f64 {
        let unit = if D == 2 {
            std::f64::consts::PI
        } else {
            4.0 / 3.0 * std::f64::consts::PI
        };
        self.p
            .iter()
            .map(|p| unit * p.r.powi(D as i32))
            .sum::<f64>()
            * self.growth_factor().powi(D as i32)
            / self.simbox.volume()
    }

    /// Speeds |v_i|.
    pub fn speeds(&self) -> Vec<f64> {
        self.slot
            .iter()
            .map(|&k| dot(&self.p[k as usize].v, &self.p[k as usize].v).sqrt())
            .collect()
    }

    /// An estimate of the events the next `duration` of simulated time
    /// takes, from the velocities as they are: each particle renews its
    /// neighbour list once per skin k_i it travels, |v_i|·t/k_i renewals,
    /// and meets others at the Enskog rate with its own speed for the mean
    /// relative speed, Γ_i = √2 |v_i| n π σ̄² g(σ̄) in 3-D and
    /// √2 |v_i| n 2σ̄ g(σ̄) in 2-D (σ̄ the mean diameter; Chapman & Cowling,
    /// ch. 16), each collision ending two flights. Within a factor of a few
    /// of what a run takes: enough to tell a mistyped mass or temperature
    /// (10¹⁵⁰ events) from a long run.
    pub fn expected_events(&self, duration: f64) -> f64 {
        let n = self.len();
        if n == 0 || duration.is_nan() || duration <= 0.0 {
            return 0.0;
        }
        let density = n as f64 / self.simbox.volume();
        let sigma = 2.0 * self.p.iter().map(|p| p.r).sum::<f64>() / n as f64 * self.growth_factor();
        let g = crate::theory::contact_value(D, self.packing_fraction().clamp(1e-6, 0.7));
        let cross_section = if D == 2 {
            2.0 * sigma
        } else {
            std::f64::consts::PI * sigma * sigma
        };
        let per_speed = std::f64::consts::SQRT_2 * density * cross_section * g / 2.0;
        self.p
            .iter()
            .map(|p| {
                let speed = dot(&p.v, &p.v).sqrt();
                let k = skin(p.r * self.list_factor, self.shell, self.skin_cap);
                speed * duration * (1.0 / k + per_speed)
            })
            .sum()
    }

    /// Starts a new window for the collision counters and virial.
    pub fn reset_counters(&mut self) {
        self.counters = Counters {
            since: self.now,
            ..Counters::default()
        };
    }

    /// Compressibility factor Z = PV/(N k_B T) over the current counting
    /// window, from the collision virial: PV = N k_B T + Σ r_ij·Δp_i /(D t)
    /// (Alder & Wainwright, J. Chem. Phys. 33, 1439 (1960)); with
    /// N k_B T = 2K/D this is Z = 1 + Σ r_ij·Δp_i / (2 K t). Walls are not
    /// counted: for a bulk pressure use periodic axes.
    pub fn compressibility(&self) -> f64 {
        let t = self.now - self.counters.since;
        if t <= 0.0 {
            return f64::NAN;
        }
        1.0 + self.counters.virial / (2.0 * self.kinetic_energy() * t)
    }

    /// Pressure P = Z N k_B T / V over the current window.
    pub fn pressure(&self) -> f64 {
        self.compressibility() * self.len() as f64 * self.temperature() / self.simbox.volume()
    }

    /// Pressure on the walls: Σ|Δp| / (t · wall area), over the current window
    /// (NaN if there are no walls).
    pub fn wall_pressure(&self) -> f64 {
        let t = self.now - self.counters.since;
        let mut area = 0.0;
        for d in 0..D {
            if self.simbox.boundary[d] == Boundary::Wall {
                area += 2.0 * self.simbox.volume() / self.simbox.size[d];
            }
        }
        if area == 0.0 || t <= 0.0 {
            return f64::NAN;
        }
        self.counters.wall_impulse_sum / (t * area)
    }

    /// Pair collisions per particle per unit time over the current window
    /// (each collision counts for two particles).
    pub fn collision_rate(&self) -> f64 {
        let t = self.now - self.counters.since;
        2.0 * self.counters.collisions as f64 / (self.len() as f64 * t)
    }

    /// Mean free time: 1 / collision rate per particle.
    pub fn mean_free_time(&self) -> f64 {
        1.0 / self.collision_rate()
    }

    // ----- overlap check -------------------------------------------------

    /// Minimum-image separation r_i − r_j at the current time.
    pub fn separation(&self, i: usize, j: usize) -> [f64; D] {
        self.sep_int(self.slot[i] as usize, self.slot[j] as usize)
    }

    fn sep_int(&self, k: usize, l: usize) -> [f64; D] {
        let mut r = sub(&self.pos_int(k), &self.pos_int(l));
        for (d, rd) in r.iter_mut().enumerate() {
            if self.simbox.boundary[d] == Boundary::Periodic {
                let l = self.simbox.size[d];
                *rd -= l * (*rd / l).round();
            }
        }
        r
    }

    /// The first pair whose distance is below its contact distance by more
    /// than `rel_tol` (relative), as `(i, j, |r|/σ − 1)`; also reports a
    /// particle outside a wall as `(i, i, depth)`. Exact: it checks every
    /// pair in neighbouring cells, which holds all pairs that could touch.
    pub fn find_overlap(&self, rel_tol: f64) -> Option<(usize, usize, f64)> {
        let n = self.len();
        let pos: Vec<[f64; D]> = (0..n).map(|k| self.pos_int(k)).collect();
        for i in 0..n {
            for d in 0..D {
                if self.simbox.boundary[d] == Boundary::Wall {
                    let r = self.rad(i);
                    let l = self.simbox.size[d];
                    let depth = (r - pos[i][d]).max(pos[i][d] + r - l);
                    if depth > rel_tol * r {
                        let e = self.id[i] as usize;
                        return Some((e, e, depth / r));
                    }
                }
            }
        }
        // every pair in contact is on the neighbour lists
        for i in 0..n {
            for &j in &self.nbr[i * self.cap..i * self.cap + self.nn[i] as usize] {
                let ju = j as usize;
                if ju > i {
                    let r = self.sep_int(i, ju);
                    let s = self.rad(i) + self.rad(ju);
                    let dist = dot(&r, &r).sqrt();
                    if dist < s * (1.0 - rel_tol) {
                        let (a, b) = (self.id[i] as usize, self.id[ju] as usize);
                        return Some((a.min(b), a.max(b), dist / s - 1.0));
                    }
                }
            }
        }
        None
    }

    /// Like [`System::find_overlap`] but over all N² pairs, without the cell
    /// list (for tests of the cell list itself).
    pub fn find_overlap_all_pairs(&self, rel_tol: f64) -> Option<(usize, usize, f64)> {
        let n = self.len();
        for i in 0..n {
            for j in (i + 1)..n {
                let r = self.separation(i, j);
                let s = self.radius(i) + self.radius(j);
                let dist = dot(&r, &r).sqrt();
                if dist < s * (1.0 - rel_tol) {
                    return Some((i, j, dist / s - 1.0));
                }
            }
        }
        None
    }

    // ----- prediction ----------------------------------------------------

    /// Schedules the next event of particle `i` (advanced to now): the
    /// earliest of its neighbour-list expiry, wall hits and collisions with
    /// listed neighbours.
    fn predict(&mut self, i: usize) {
        if self.growth == 0.0 {
            self.predict_with::<false>(i)
        } else {
            self.predict_with::<true>(i)
        }
    }

    /// [`System::predict`] for fixed (`GROW = false`, the original code) or
    /// growing radii.
    #[inline(always)]
    fn predict_with<const GROW: bool>(&mut self, i: usize) {
        // advance i to now, keeping its data in registers (reading the
        // record back right after storing it would stall on the store)
        let now = self.now;
        let (vi, ti, ri) = (self.p[i].v, self.p[i].t, self.p[i].r);
        let xi = if now != ti {
            add_scaled(&self.p[i].x, &vi, now - ti)
        } else {
            self.p[i].x
        };
        self.p[i].x = xi;
        self.p[i].t = now;
        let (g, delta) = if GROW {
            (1.0 + self.growth * now, self.growth)
        } else {
            (1.0, 0.0)
        };
        let a = dot(&vi, &vi);
        let mut best = f64::INFINITY;
        let mut ev = NO_EVENT;
        if a > 0.0 {
            // |x + v t − x_n| = k_i (the skin), the outer root
            let dr = sub(&xi, &self.xn[i].x);
            let m = skin(self.p[i].r * self.list_factor, self.shell, self.skin_cap);
            let c = dot(&dr, &dr) - m * m;
            best = if c >= 0.0 {
                0.0
            } else {
                let b = dot(&dr, &vi);
                let q = (b * b - a * c).sqrt();
                if b > 0.0 {
                    -c / (b + q)
                } else {
                    (q - b) / a
                }
            };
            ev.kind = Kind::Rebuild;
        }
        for d in 0..D {
            if self.simbox.boundary[d] != Boundary::Wall {
                continue;
            }
            let v = vi[d];
            // the surfaces move at v ± ṙ (ṙ = r_i(0)δ): a growing particle
            // at rest still reaches a wall
            let (rn, rdot) = if GROW {
                (ri * g, ri * delta)
            } else {
                (ri, 0.0)
            };
            for up in [true, false] {
                let u = if up { v + rdot } else { v - rdot };
                let dt = if up && u > 0.0 {
                    (self.simbox.size[d] - rn - xi[d]) / u
                } else if !up && u < 0.0 {
                    (rn - xi[d]) / u
                } else {
                    continue;
                }
                .max(0.0);
                if dt < best {
                    best = dt;
                    ev = Event {
                        kind: Kind::Wall,
                        axis: d as u8,
                        up,
                        ..NO_EVENT
                    };
                }
            }
        }
        let base = i * self.cap;
        let size = self.simbox.size;
        let periodic = self.simbox.boundary.map(|b| b == Boundary::Periodic);
        let half = size.map(|l| 0.5 * l);
        let nn = self.nn[i] as usize;
        // The neighbours' data are scattered in memory: ask for all of them
        // first so the cache misses overlap instead of queueing.
        for k in 0..nn {
            prefetch(&self.p[self.nbr[base + k] as usize]);
        }
        let probe = Probe {
            x: xi,
            v: vi,
            r: ri,
            now,
            size,
            half,
            periodic,
            g,
            delta,
        };
        let list = &self.nbr[base..base + nn];
        // The vector scans, where they run: AVX-512, else eight at a time
        // on `Lanes`; the same bits as the scalar loop below.
        let mut scanned: Option<TwoEarliest> = None;
        #[cfg(target_arch = "x86_64")]
        if self.simd {
            // SAFETY: `simd` is set only where AVX-512F exists; list entries
            // and `i` index `p`, whose records are 64-byte lines of 8 doubles.
            scanned = Some(unsafe {
                crate::avx512::earliest::<D, GROW>(self.p.as_ptr() as *const f64, i, list, &probe)
            });
        }
        if scanned.is_none() && self.lanes {
            scanned = Some(earliest_lanes::<D, GROW>(&self.p, list, i, &probe));
        }
        if let Some(two) = scanned {
            return self.schedule(i, best, ev, two);
        }
        let mut two = TwoEarliest::NONE;
        // Branch-free: every listed pair's time is computed (no early outs,
        // whose outcome is a coin toss for the branch predictor and which
        // chain each pair's test to the previous pair's division) and the
        // earliest kept by selects; ties go to the first in the list.
        for k in 0..nn {
            let j = self.nbr[base + k];
            let pj = &self.p[j as usize];
            let dtj = now - pj.t;
            let mut r = [0.0; D];
            let mut v = [0.0; D];
            for d in 0..D {
                r[d] = xi[d] - (pj.x[d] + pj.v[d] * dtj);
                v[d] = vi[d] - pj.v[d];
            }
            for d in 0..D {
                if periodic[d] {
                    let up = if r[d] > half[d] { size[d] } else { 0.0 };
                    let down = if r[d] < -half[d] { size[d] } else { 0.0 };
                    r[d] = r[d] - up + down;
                }
            }
            let dt = if GROW {
                let sigma0 = ri + pj.r;
                let (sigma, sdot) = (sigma0 * g, sigma0 * delta);
                let b = dot(&r, &v) - sigma * sdot;
                let av = dot(&v, &v) - sdot * sdot;
                let c = dot(&r, &r) - sigma * sigma;
                growing_root(av, b, c)
            } else {
                approach_root(
                    dot(&v, &v),
                    dot(&r, &v),
                    dot(&r, &r) - (ri + pj.r) * (ri + pj.r),
                )
            };
            two.offer(dt, k as u32);
        }
        self.schedule(i, best, ev, two)
    }

    /// Files the next event of `i`: the earliest listed contact of `two`
    /// if it comes before `dt` (the skin or wall event `ev`), else `ev`, at
    /// `now` plus its time; a collision keeps the earlier of the second
    /// contact and `ev` as its fallback.
    #[inline(always)]
    fn schedule(&mut self, i: usize, dt: f64, mut ev: Event, two: TwoEarliest) {
        let now = self.now;
        let mut t = now + dt;
        if two.t[0] < dt {
            let base = i * self.cap;
            let j = self.nbr[base + two.at[0] as usize];
            let (fallback, later, later_count, later_time) = if two.t[1] < dt {
                let k = self.nbr[base + two.at[1] as usize];
                (Kind::Collision, k, self.count[k as usize], now + two.t[1])
            } else {
                (ev.kind, NONE, 0, t)
            };
            ev = Event {
                kind: Kind::Collision,
                fallback,
                partner: j,
                partner_count: self.count[j as usize],
                later,
                later_count,
                later_time,
                ..ev
            };
            t = now + two.t[0];
        }
        self.events[i] = ev;
        self.queue.update(i, t);
    }

    /// The next event of `i` after its collision turned out stale (the
    /// partner collided first): its fallback where that still holds (see
    /// [`Event`]), else a new scan of its list.
    fn fall_back(&mut self, i: usize, ev: Event) {
        let holds = match ev.fallback {
            Kind::Collision => self.count[ev.later as usize] == ev.later_count,
            Kind::Rebuild | Kind::Wall => true,
            Kind::None => false,
        };
        if holds {
            self.events[i] = Event {
                kind: ev.fallback,
                fallback: Kind::None,
                partner: ev.later,
                partner_count: ev.later_count,
                ..ev
            };
            self.queue.update(i, ev.later_time);
        } else {
            self.predict(i);
        }
    }

    /// Turns the vector neighbour scans (AVX-512 where the CPU has it, else
    /// eight neighbours at a time on [`Lanes`]) off or back on: results do
    /// not change, only speed. For tests and timings.
    #[doc(hidden)]
    pub fn set_simd(&mut self, on: bool) {
        self.simd = on && simd_available::<D>();
        self.lanes = on && !self.simd;
    }

    /// Adds to the lists of `i` (and symmetrically to theirs) every particle
    /// within the shell of its list position; with `only_greater`, only
    /// j > i (for the first build of all lists).
    fn scan_neighbours(&mut self, i: usize, only_greater: bool) {
        let xi = self.xn[i].x;
        let ri = self.xn[i].r;
        let mut ranges = std::mem::take(&mut self.ranges);
        ranges.clear();
        self.cells.near(&xi, ri, &mut ranges);
        let periodic = self.simbox.boundary.map(|b| b == Boundary::Periodic);
        for &(start, end) in &ranges {
            for slot in start as usize..end as usize {
                let (j, ListPos { x: xj, r: rj }) = self.cells.entry(slot);
                let ju = j as usize;
                if ju != i && (!only_greater || ju > i) {
                    let mut r = sub(&xi, &xj);
                    for (d, rd) in r.iter_mut().enumerate() {
                        if periodic[d] {
                            let l = self.simbox.size[d];
                            if *rd > 0.5 * l {
                                *rd -= l;
                            } else if *rd < -0.5 * l {
                                *rd += l;
                            }
                        }
                    }
                    let s = ri + rj;
                    if dot(&r, &r) < s * s {
                        if self.nn[i] as usize == self.cap || self.nn[ju] as usize == self.cap {
                            self.grow_lists();
                        }
                        let cap = self.cap;
                        self.nbr[i * cap + self.nn[i] as usize] = j;
                        self.nn[i] += 1;
                        self.nbr[ju * cap + self.nn[ju] as usize] = i as u32;
                        self.nn[ju] += 1;
                    }
                }
            }
        }
        self.ranges = ranges;
    }

    fn grow_lists(&mut self) {
        let n = self.len();
        let cap = self.cap * 2;
        let mut nbr = huge_vec(n * cap, 0u32);
        for i in 0..n {
            let k = self.nn[i] as usize;
            nbr[i * cap..i * cap + k].copy_from_slice(&self.nbr[i * self.cap..i * self.cap + k]);
        }
        self.nbr = nbr;
        self.cap = cap;
    }

    /// Rebuilds the neighbour list of `i` at the current time.
    fn rebuild(&mut self, i: usize) {
        self.advance(i);
        for d in 0..D {
            if self.simbox.boundary[d] == Boundary::Periodic {
                let l = self.simbox.size[d];
                let x = &mut self.p[i].x[d];
                if *x >= l {
                    *x -= l;
                } else if *x < 0.0 {
                    *x += l;
                }
            }
        }
        self.xn[i] = ListPos {
            x: self.p[i].x,
            r: list_reach(self.p[i].r * self.list_factor, self.shell, self.skin_cap),
        };
        self.cells.remove(i);
        self.cells.insert(i, self.xn[i]);
        let cap = self.cap;
        for k in 0..self.nn[i] as usize {
            prefetch(&self.nbr[self.nbr[i * cap + k] as usize * cap]);
        }
        for k in 0..self.nn[i] as usize {
            let j = self.nbr[i * cap + k] as usize;
            let row = &mut self.nbr[j * cap..j * cap + self.nn[j] as usize];
            if let Some(pos) = row.iter().position(|&x| x as usize == i) {
                let last = row.len() - 1;
                row[pos] = row[last];
                self.nn[j] -= 1;
            }
        }
        self.nn[i] = 0;
        self.scan_neighbours(i, false);
    }

    // ----- the event loop ------------------------------------------------

    /// Processes the next event if it happens no later than `t_end`;
    /// returns false (and leaves the time unchanged) otherwise.
    pub fn step(&mut self, t_end: f64) -> bool {
        let Some((t, i)) = self.queue.min() else {
            return false;
        };
        if t > t_end || t == f64::INFINITY {
            return false;
        }
        self.now = t;
        // Every branch below files a new event for i; take the old one out
        // now and look up the event after it, so that its particle's data
        // are fetched while this event is worked on.
        self.queue.pop();
        let next_event = self.queue.min();
        let next = next_event.map(|(_, k)| k);
        if let Some(k) = next {
            prefetch(&self.events[k]);
            prefetch(&self.p[k]);
            prefetch(&self.xn[k]);
            prefetch(&self.nbr[k * self.cap]);
        }
        let ev = self.events[i];
        match ev.kind {
            Kind::None => {
                // no event at all (particle at rest, no partner): park it
                self.queue.update(i, f64::INFINITY);
            }
            Kind::Collision => {
                let j = ev.partner as usize;
                if self.count[j] != ev.partner_count {
                    self.counters.invalid += 1;
                    self.fall_back(i, ev);
                } else {
                    self.collide(i, j);
                    self.predict(i);
                    self.predict(j);
                }
            }
            Kind::Rebuild => {
                self.counters.rebuilds += 1;
                self.rebuild(i);
                self.predict(i);
            }
            Kind::Wall => {
                self.advance(i);
                let d = ev.axis as usize;
                let v = self.p[i].v[d];
                // in the frame of the growing surface (ṙ = 0 without growth)
                let rdot = self.p[i].r * self.growth;
                let u = if ev.up { v + rdot } else { v - rdot };
                if (u > 0.0) == ev.up && u != 0.0 {
                    self.p[i].v[d] = v - 2.0 * u;
                    self.counters.wall_hits += 1;
                    self.counters.wall_impulse_sum += 2.0 * self.mass[i] * u.abs();
                    self.count[i] = self.count[i].wrapping_add(1);
                }
                self.predict(i);
            }
        }
        // by now the next event itself is in cache: fetch its partner
        if let Some(k) = next {
            let e = self.events[k];
            if e.kind == Kind::Collision {
                let j = e.partner as usize;
                prefetch(&self.p[j]);
                prefetch(&self.count[j]);
                prefetch(&self.mass[j]);
                prefetch(&self.xn[j]);
                prefetch(&self.nbr[j * self.cap]);
            } else if e.kind == Kind::Rebuild {
                // the cells its list build will scan, around where it
                // will be then
                let (t, _) = next_event.unwrap_or((self.now, k));
                let q = &self.p[k];
                let x = add_scaled(&q.x, &q.v, t - q.t);
                self.cells.prefetch_near(&x, self.xn[k].r);
            }
        }
        true
    }

    /// Elastic collision of i and j at the current time, 002 Eq. (9a,b);
    /// with growth, elastic in the frame of the growing surfaces (KTS rule,
    /// seeds/README.md): u_n → 2s − u_n with s = σ_ij(0)δ, momentum kept.
    fn collide(&mut self, i: usize, j: usize) {
        self.advance(i);
        self.advance(j);
        let mut r = sub(&self.p[i].x, &self.p[j].x);
        // periodic image: pick the nearest (neighbour cells are at most one
        // box length apart, and periodic axes have at least three cells)
        for (d, rd) in r.iter_mut().enumerate() {
            if self.simbox.boundary[d] == Boundary::Periodic {
                let l = self.simbox.size[d];
                if *rd > 0.5 * l {
                    *rd -= l;
                } else if *rd < -0.5 * l {
                    *rd += l;
                }
            }
        }
        let v = sub(&self.p[i].v, &self.p[j].v);
        let b = dot(&r, &v);
        let r2 = dot(&r, &r);
        let (mi, mj) = (self.mass[i], self.mass[j]);
        // Δp_i = −2 μ (b / r²) r; growing: −2 μ ((b − s|r|) / r²) r
        let b = if self.growth == 0.0 {
            b
        } else {
            b - (self.p[i].r + self.p[j].r) * self.growth * r2.sqrt()
        };
        let mu = mi * mj / (mi + mj);
        if mu.is_normal() {
            let f = -2.0 * mu * b / r2;
            for d in 0..D {
                self.p[i].v[d] += f / mi * r[d];
                self.p[j].v[d] -= f / mj * r[d];
            }
            self.counters.virial += -2.0 * mu * b;
        } else {
            // Masses so small (below ~10⁻¹⁵⁴) that m_i m_j underflows: μ = 0
            // would leave the pair approaching and colliding again at the
            // same instant for ever. The velocity changes take the mass
            // fractions m_j/(m_i + m_j), m_i/(m_i + m_j) instead.
            let (wi, wj) = (mj / (mi + mj), mi / (mi + mj));
            let f = -2.0 * b / r2;
            for d in 0..D {
                self.p[i].v[d] += f * wi * r[d];
                self.p[j].v[d] -= f * wj * r[d];
            }
            self.counters.virial += -2.0 * (mi * wi) * b;
        }
        self.counters.collisions += 1;
        self.count[i] = self.count[i].wrapping_add(1);
        self.count[j] = self.count[j].wrapping_add(1);
    }

    /// Runs until time `t_end` (all events up to and including `t_end`),
    /// then sets the clock to `t_end`. Returns the number of events.
    pub fn run_until(&mut self, t_end: f64) -> u64 {
        let mut k = 0;
        while self.step(t_end) {
            k += 1;
        }
        if t_end > self.now {
            self.now = t_end;
        }
        k
    }

    /// Runs until `count` more pair collisions have happened or the next
    /// event comes after `t_end`; true if the collisions were reached.
    pub fn run_collisions_until(&mut self, count: u64, t_end: f64) -> bool {
        let target = self.counters.collisions + count;
        while self.counters.collisions < target {
            if !self.step(t_end) {
                return false;
            }
        }
        true
    }

    /// Runs until `count` more pair collisions have happened.
    pub fn run_collisions(&mut self, count: u64) {
        let target = self.counters.collisions + count;
        while self.counters.collisions < target {
            if !self.step(f64::INFINITY) {
                break;
            }
        }
    }

    /// Scales all velocities by `s` (a thermostat step); trajectories
    /// change, so every event is predicted again.
    pub fn scale_velocities(&mut self, s: f64) {
        self.synchronize();
        for i in 0..self.len() {
            for d in 0..D {
                self.p[i].v[d] *= s;
            }
            self.count[i] = self.count[i].wrapping_add(1);
        }
        for i in 0..self.len() {
            self.predict(i);
        }
        self.tune_queue();
        self.counters.since = self.now;
        self.counters.virial = 0.0;
        self.counters.collisions = 0;
        self.counters.wall_hits = 0;
        self.counters.wall_impulse_sum = 0.0;
    }

    /// Replaces the counters (a resumed run continues its predecessor's).
    pub fn set_counters(&mut self, counters: Counters) {
        self.counters = counters;
    }

    /// Shifts the clock back to zero (keeps numbers small in long runs):
    /// positions are synchronized and every event predicted again.
    pub fn rebase_time(&mut self) {
        self.synchronize();
        let t0 = self.now;
        self.p.iter_mut().for_each(|p| p.t = 0.0);
        self.now = 0.0;
        self.counters.since -= t0;
        for i in 0..self.len() {
            self.predict(i);
        }
        self.tune_queue();
    }
}
