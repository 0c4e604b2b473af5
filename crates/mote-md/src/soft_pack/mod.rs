//! Random close packing by soft spheres under a barostat: the SP method of
//! seed 003 (Farr & Groot, J. Chem. Phys. 131, 244104 (2009); its §III.2
//! lost its text in extraction, so the model below is stated in full).
//!
//! Smooth spheres of diameters dᵢ in a periodic cube repel on overlap
//! δ = aᵢ + aⱼ − r with Hertz's law and dissipate along the line of
//! centres only ("radial" dissipation, as in dissipative particle dynamics):
//!
//!   F_ij = [K √R* δ^{3/2} − γ_ij (v_ij · n̂)] n̂,   R* = aᵢaⱼ/(aᵢ + aⱼ),
//!   γ_ij = √(m* k_ij),   k_ij = dF/dδ = (3/2) K √R* δ^{1/2}
//!
//! (K = 4E*/3 = 1 sets the unit of pressure, so a reduced pressure p is
//! P/K). Each sphere also feels Stokes friction −ζᵢ vᵢ from the fluid that
//! moves with the box (FG 2009's "elastic spheres with hydrodynamic
//! friction"), ζᵢ ∝ aᵢ; with the mass ∝ aᵢ too (m = d in units of the mean
//! diameter) every sphere relaxes in the same time τ = m/ζ, the relation
//! between mass and size that FG found removes the dependence of φ on
//! viscosity and size. The box follows a Berendsen-type barostat on the
//! virial pressure
//!
//!   P = (Σᵢ mᵢvᵢ² + Σ_{i<j} F_ij · r_ij) / 3V,
//!   d ln L/dt = ε̇ = ε̇_max · clamp((P − P_t)/P_t, −1, 1),
//!
//! all positions scaled affinely with L. The target pressure steps down a
//! decade at a time; at each target the run goes on until the pressure
//! holds within the tolerance and the kinetic energy has decayed
//! (E_kin < 10⁻⁴ U_elastic), and φ, p and the contact number are recorded.
//! For Hertzian spheres p ∝ (φ − φ_J)^{3/2} near jamming (O'Hern et al.,
//! Phys. Rev. E 68, 011306 (2003), α = 5/2), so φ = φ_J + c p^{2/3}: the
//! least-squares line through the lowest pressures gives φ_J, the packing
//! fraction of hard spheres at vanishing confining pressure.
//!
//! The time scale follows the target: at overlap δ_t ≈ p_t^{2/3} a unit
//! sphere pair vibrates at ω_t = √(3/2 δ_t^{1/2}); τ = 1/ω_t (near critical
//! damping), ε̇_max = 0.1 δ_t ω_t (the box closes a tenth of a typical
//! overlap per vibration), and the step is 0.1/ω of the stiffest contact.
//!
//! The packing is stepped: [`SoftPacker::advance`] takes [`CHUNK`] steps of
//! the dynamics or of the jamming finish's minimiser (fewer where a stage
//! ends), so a packing runs through the one run every engine shares
//! (`mote_run::Driver`: checkpoints, progress, the live viewer). Every
//! loop variable is state the packer saves ([`SoftPacker::save`]), and a
//! packing resumed from any chunk ends in the bits of the uninterrupted one.

use std::time::{Duration, Instant};

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::boundary::Boundary;
use crate::neighbor::SizedList;

mod barostat;
mod finish;
mod propagator;
mod saved;

use barostat::Hold;
use finish::Jam;
pub use propagator::SoftSample;

/// Steps of the dynamics or the minimiser per [`SoftPacker::advance`].
pub const CHUNK: u64 = 100;

/// What a soft-sphere packing is asked for.
#[derive(Debug, Clone)]
pub struct SoftPackSettings {
    /// Sphere diameters in units of the mean diameter (any scale works;
    /// pressures are reduced by K and lengths by the mean diameter).
    pub diameters: Vec<f64>,
    /// Packing fraction of the random start (overlaps are allowed).
    pub phi_start: f64,
    /// Target pressures p = P/K, in the order they are held (decreasing).
    pub pressures: Vec<f64>,
    /// A target is held when |P/P_t − 1| is below this.
    pub tolerance: f64,
    /// Steps allowed per target pressure (and per minimisation).
    pub max_steps: u64,
    pub seed: u64,
    /// The jamming finish after the barostat ([`SoftPacker`]'s FIRE
    /// minimisation and decompression); `None` ends with the barostat.
    pub finish: Option<FinishSettings>,
    /// Wall-clock time after which the packing stops where it is.
    pub wall_clock: Option<Duration>,
}

/// How far the jamming finish goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FinishSettings {
    /// The lowest pressure P/K, below the barostat's last target.
    pub lowest: f64,
    /// A minimisation ends when the root-mean-square net force is below
    /// this fraction of the mean contact force.
    pub force_tolerance: f64,
}

impl SoftPackSettings {
    /// Targets a decade apart from 10⁻² down to `lowest` (inclusive when a
    /// power of ten; the last target is `lowest` itself).
    pub fn decades(lowest: f64) -> Vec<f64> {
        let mut p = 1e-2;
        let mut out = Vec::new();
        while p > lowest * 1.000_001 {
            out.push(p);
            p *= 0.1;
        }
        out.push(lowest);
        out
    }
}

/// One held target pressure, or one minimised state of the finish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stage {
    /// The pressure aimed at (NaN for the finish's first minimisation).
    pub target: f64,
    /// Reduced pressure P/K at the end of the stage.
    pub pressure: f64,
    /// Nominal packing fraction Σ (π/6) dᵢ³ / V.
    pub phi: f64,
    /// Mean number of overlapping neighbours per sphere (all spheres).
    pub z: f64,
    /// Steps taken in this stage (the minimisation's, in the finish).
    pub steps: u64,
    /// Steps of the whole packing when the stage ended.
    pub total: u64,
    /// Simulated time at the end of the stage.
    pub time: f64,
    /// Whether the pressure held and the motion died out within the step
    /// budget (in the finish: whether the residual force came below the
    /// tolerance).
    pub converged: bool,
}

/// Why a packing stopped stepping.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoftStop {
    /// Every stage held and the finish, if asked, went as far as it could.
    Done,
    /// The wall-clock limit passed.
    WallClock,
    /// A signal asked the run to stop.
    Interrupted,
}

impl SoftStop {
    const ALL: [SoftStop; 3] = [SoftStop::Done, SoftStop::WallClock, SoftStop::Interrupted];

    pub fn name(&self) -> &'static str {
        match self {
            SoftStop::Done => "done",
            SoftStop::WallClock => "wall-clock",
            SoftStop::Interrupted => "interrupted",
        }
    }
}

/// Where the packing is.
#[derive(Debug, Clone)]
enum Phase {
    /// Holding the barostat's target `settings.pressures[stage]`.
    Hold(Hold),
    /// The jamming finish.
    Jam(Box<Jam>),
    /// Nothing left to do.
    Over,
}

/// The soft-sphere packing in progress.
pub struct SoftPacker {
    pub position: Vec<DVec3>,
    pub velocity: Vec<DVec3>,
    pub radius: Vec<f64>,
    mass: Vec<f64>,
    /// Forces of the last pass over the pairs.
    force: Vec<DVec3>,
    /// What that pass summed to.
    sums: PairSums,
    pub boundary: Boundary,
    list: SizedList,
    /// The largest diameter.
    d_max: f64,
    /// Positions and box at the last list build (empty: build at the next
    /// refresh).
    reference: Vec<DVec3>,
    reference_box: Boundary,
    pub time: f64,
    /// Steps of the dynamics and the minimiser so far.
    pub steps: u64,
    /// Calls of [`SoftPacker::advance`] so far.
    chunks: u64,
    settings: SoftPackSettings,
    /// The residual force the last minimisation could reach at best
    /// (rounding of the positions), relative to the mean contact force.
    pub last_floor: f64,
    phase: Phase,
    /// The barostat's stages held so far.
    stages: Vec<Stage>,
    /// The finish's minimised states so far (the first is its start).
    finish: Vec<Stage>,
    /// Positions and box when the barostat ended (for what the packing
    /// was before the finish).
    barostat_end: Option<(Vec<DVec3>, Boundary)>,
    stopped: Option<SoftStop>,
    deadline: Option<Instant>,
}

/// Forces and what they sum to, from one pass over the pairs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PairSums {
    /// Σ F_ij · r_ij over overlapping pairs.
    virial: f64,
    /// Σ (2/5) K √R* δ^{5/2}.
    elastic: f64,
    /// Largest k_ij / m* over overlapping pairs.
    stiffest: f64,
    /// Σ δ over overlapping pairs.
    overlap: f64,
    contacts: usize,
}

impl SoftPacker {
    /// A random start at `phi_start` in a periodic cube, ready to hold the
    /// first target.
    pub fn new(settings: SoftPackSettings) -> Result<Self, String> {
        let mut packer = Self::unstarted(settings)?;
        let side = packer.side();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(packer.settings.seed);
        for r in &mut packer.position {
            *r = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * side;
        }
        packer.phase = Phase::Hold(Hold::begin(&mut packer, 0));
        Ok(packer)
    }

    /// The spheres of `settings` at the origin of their box (checked),
    /// before any stage.
    fn unstarted(settings: SoftPackSettings) -> Result<Self, String> {
        let n = settings.diameters.len();
        if n < 2 {
            return Err(format!("need at least 2 spheres, got {n}"));
        }
        if settings
            .diameters
            .iter()
            .any(|d| !(*d > 0.0 && d.is_finite()))
        {
            return Err("every diameter must be positive and finite".into());
        }
        if !(settings.phi_start > 0.0 && settings.phi_start < 0.6) {
            return Err(format!(
                "starting packing fraction {} must lie in (0, 0.6)",
                settings.phi_start
            ));
        }
        if settings.pressures.is_empty()
            || settings.pressures.iter().any(|p| !(*p > 0.0 && *p < 1.0))
        {
            return Err(format!(
                "target pressures {:?} must lie in (0, 1) (units of the Hertz modulus K = 4E*/3)",
                settings.pressures
            ));
        }
        if !(settings.tolerance > 0.0 && settings.tolerance < 1.0) {
            return Err(format!(
                "pressure tolerance {} must lie in (0, 1)",
                settings.tolerance
            ));
        }
        if let Some(f) = settings.finish {
            let last = settings.pressures[settings.pressures.len() - 1];
            if !(f.lowest > 0.0 && f.lowest < last) {
                return Err(format!(
                    "the finish's lowest pressure {} must lie in (0, {last}), below the barostat's last target",
                    f.lowest
                ));
            }
            if !(f.force_tolerance > 0.0 && f.force_tolerance < 1.0) {
                return Err(format!(
                    "the finish's force tolerance {} must lie in (0, 1)",
                    f.force_tolerance
                ));
            }
        }
        let mean = settings.diameters.iter().sum::<f64>() / n as f64;
        let radius: Vec<f64> = settings.diameters.iter().map(|d| 0.5 * d / mean).collect();
        let volume: f64 = radius.iter().map(|a| sphere_volume(*a)).sum();
        let side = (volume / settings.phi_start).cbrt();
        let d_max = 2.0 * radius.iter().cloned().fold(0.0, f64::max);
        let skin = 0.3;
        if side < 2.0 * (d_max + skin) * 1.2 {
            return Err(format!(
                "{n} spheres make a box of side {side:.3} mean diameters at jamming, too small for the largest (diameter {d_max:.3}): use more spheres"
            ));
        }
        let boundary = Boundary::periodic(DVec3::ZERO, DVec3::splat(side));
        let mass = radius.iter().map(|a| 2.0 * a).collect();
        Ok(Self {
            position: vec![DVec3::ZERO; n],
            velocity: vec![DVec3::ZERO; n],
            force: vec![DVec3::ZERO; n],
            sums: PairSums::default(),
            reference: Vec::new(),
            reference_box: boundary,
            list: SizedList::new(skin),
            d_max,
            radius,
            mass,
            boundary,
            time: 0.0,
            steps: 0,
            chunks: 0,
            deadline: settings.wall_clock.map(|d| Instant::now() + d),
            settings,
            last_floor: 0.0,
            phase: Phase::Over,
            stages: Vec::new(),
            finish: Vec::new(),
            barostat_end: None,
            stopped: None,
        })
    }

    /// Side of the cubic box.
    pub fn side(&self) -> f64 {
        self.boundary.lengths().x
    }

    /// Nominal packing fraction Σ volumes / V.
    pub fn phi(&self) -> f64 {
        self.radius.iter().map(|a| sphere_volume(*a)).sum::<f64>() / self.boundary.volume()
    }

    /// The settings the packer was made with.
    pub fn settings(&self) -> &SoftPackSettings {
        &self.settings
    }

    /// The barostat's stages held so far.
    pub fn stages(&self) -> &[Stage] {
        &self.stages
    }

    /// The jamming finish's minimised states so far (the first is the
    /// barostat's end, minimised).
    pub fn finish(&self) -> &[Stage] {
        &self.finish
    }

    /// Whether the barostat's stages are over (the finish, if any, begun).
    pub fn barostat_over(&self) -> bool {
        !matches!(self.phase, Phase::Hold(_))
    }

    /// Positions and box when the barostat ended, once it has.
    pub fn barostat_end(&self) -> Option<(&[DVec3], &Boundary)> {
        self.barostat_end.as_ref().map(|(r, b)| (r.as_slice(), b))
    }

    /// Why the packing stopped, once it has.
    pub fn stopped(&self) -> Option<SoftStop> {
        self.stopped
    }

    /// Ends the packing where it is.
    pub fn stop(&mut self, why: SoftStop) {
        self.stopped.get_or_insert(why);
    }

    /// Takes up to [`CHUNK`] steps of the barostat or the finish (fewer
    /// where a stage or minimisation ends there); nothing once stopped.
    pub fn advance(&mut self) {
        if self.stopped.is_some() {
            return;
        }
        if self.deadline.is_some_and(|d| Instant::now() > d) {
            self.stop(SoftStop::WallClock);
            return;
        }
        self.chunks += 1;
        self.phase = match std::mem::replace(&mut self.phase, Phase::Over) {
            Phase::Hold(hold) => barostat::advance(self, hold),
            Phase::Jam(jam) => finish::advance(self, *jam),
            Phase::Over => Phase::Over,
        };
        if matches!(self.phase, Phase::Over) {
            self.stop(SoftStop::Done);
        }
    }

    /// Steps until the packing stops (or `stop` says so between chunks);
    /// the barostat's stages and the finish's states are then
    /// [`SoftPacker::stages`] and [`SoftPacker::finish`].
    pub fn run(&mut self, stop: &dyn Fn() -> bool) {
        while self.stopped.is_none() {
            if stop() {
                self.stop(SoftStop::Interrupted);
                break;
            }
            self.advance();
        }
    }

    /// Rebuilds the neighbour list when a pair may have come within reach
    /// unseen: twice the largest non-affine displacement plus the affine
    /// shrink of the reach since the last build exceeds the skin.
    fn refresh_list(&mut self) {
        let side = self.side();
        let scale = side / self.reference_box.lengths().x;
        let stale = self.reference.len() != self.position.len() || {
            let lo = self.boundary.lo;
            let mut worst = 0.0f64;
            for (r, r0) in self.position.iter().zip(&self.reference) {
                let d = self.boundary.minimum_image(*r - (lo + (*r0 - lo) * scale));
                worst = worst.max(d.length_squared());
            }
            let reach = self.d_max + self.list.skin;
            2.0 * worst.sqrt() + reach * (1.0 - scale).max(0.0) > self.list.skin
        };
        if stale {
            for r in &mut self.position {
                *r = self.boundary.wrap(*r);
            }
            self.list
                .build(&self.position, &self.radius, &self.boundary);
            self.reference.clone_from(&self.position);
            self.reference_box = self.boundary;
        }
    }

    /// Hertz forces with radial dissipation into `self.force`.
    fn pair_forces(&mut self) -> PairSums {
        self.pair_forces_with(true)
    }

    /// Hertz forces, with the radial dissipation when `dissipate`.
    fn pair_forces_with(&mut self, dissipate: bool) -> PairSums {
        let mut sums = PairSums::default();
        self.force.iter_mut().for_each(|f| *f = DVec3::ZERO);
        let image = self.boundary.image();
        for i in 0..self.position.len() {
            let (ri, ai, vi, mi) = (
                self.position[i],
                self.radius[i],
                self.velocity[i],
                self.mass[i],
            );
            let mut fi = DVec3::ZERO;
            for &j in self.list.of(i) {
                let j = j as usize;
                let r = image.apply(ri - self.position[j]);
                let contact = ai + self.radius[j];
                let d2 = r.length_squared();
                if d2 >= contact * contact {
                    continue;
                }
                let dist = d2.sqrt();
                let n = r / dist;
                let overlap = contact - dist;
                let reduced_radius = ai * self.radius[j] / contact;
                let root = (reduced_radius * overlap).sqrt();
                let elastic = root * overlap;
                let stiffness = 1.5 * root;
                let reduced_mass = mi * self.mass[j] / (mi + self.mass[j]);
                let gamma = (reduced_mass * stiffness).sqrt();
                let normal_speed = if dissipate {
                    (vi - self.velocity[j]).dot(n)
                } else {
                    0.0
                };
                let f = n * (elastic - gamma * normal_speed);
                fi += f;
                self.force[j] -= f;
                sums.virial += f.dot(r);
                sums.elastic += 0.4 * elastic * overlap;
                sums.stiffest = sums.stiffest.max(stiffness / reduced_mass);
                sums.overlap += overlap;
                sums.contacts += 1;
            }
            self.force[i] += fi;
        }
        self.sums = sums;
        sums
    }

    /// Σ mᵢvᵢ², twice the kinetic energy.
    fn kinetic2(&self) -> f64 {
        self.velocity
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| m * v.length_squared())
            .sum()
    }

    /// Scales positions and box about the box's lower corner by `scale`.
    fn dilate(&mut self, scale: f64) {
        let lo = self.boundary.lo;
        for r in &mut self.position {
            *r = lo + (*r - lo) * scale;
        }
        self.boundary.hi = lo + (self.boundary.hi - lo) * scale;
    }

    /// The reduced pressure P/K of the spheres at rest (virial only).
    pub fn static_pressure(&mut self) -> f64 {
        self.at_rest().0
    }

    /// The pressure at rest and the overlapping neighbours per sphere.
    fn at_rest(&mut self) -> (f64, f64) {
        self.refresh_list();
        let sums = self.pair_forces_with(false);
        (
            sums.virial / (3.0 * self.boundary.volume()),
            2.0 * sums.contacts as f64 / self.position.len() as f64,
        )
    }
}

/// φ_J and c of φ = φ_J + c p^{2/3} fitted by least squares to the stages
/// (O'Hern et al. 2003: p ∝ (φ − φ_J)^{3/2} for Hertzian spheres); `None`
/// with fewer than two stages.
pub fn extrapolate(stages: &[Stage]) -> Option<(f64, f64)> {
    if stages.len() < 2 {
        return None;
    }
    let xs: Vec<f64> = stages
        .iter()
        .map(|s| s.pressure.max(0.0).powf(2.0 / 3.0))
        .collect();
    let ys: Vec<f64> = stages.iter().map(|s| s.phi).collect();
    let m = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / m, ys.iter().sum::<f64>() / m);
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let c = sxy / sxx;
    Some((my - c * mx, c))
}

fn sphere_volume(a: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * a * a * a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two spheres pressed together: the force is Hertz's K √R* δ^{3/2}
    /// along the line of centres, equal and opposite, and the virial is
    /// F·r.
    #[test]
    fn a_pair_feels_hertz() {
        let mut p = SoftPacker::new(SoftPackSettings {
            diameters: vec![1.0; 64],
            phi_start: 0.05,
            pressures: vec![1e-3],
            tolerance: 0.01,
            max_steps: 10,
            seed: 1,
            finish: None,
            wall_clock: None,
        })
        .unwrap();
        let side = p.side();
        assert!(side > 8.0);
        for (k, r) in p.position.iter_mut().enumerate() {
            // A 4 × 4 × 4 grid of spacing 2 (gaps of a diameter, also
            // across the periodic faces), but 0 and 1 overlapping by 0.01.
            let (a, b, c) = (k % 4, (k / 4) % 4, k / 16);
            *r = DVec3::new(a as f64, b as f64, c as f64) * 2.0 + 0.1;
        }
        p.position[1] = p.position[0] + DVec3::new(0.99, 0.0, 0.0);
        p.refresh_list();
        let sums = p.pair_forces();
        let expected = (0.25f64 * 0.01).sqrt() * 0.01;
        assert!((p.force[1].x - expected).abs() < 1e-15 * expected.max(1.0));
        assert_eq!(p.force[0], -p.force[1]);
        assert_eq!(sums.contacts, 1);
        assert!((sums.virial - expected * 0.99).abs() < 1e-15);
        assert!(p.force[2..].iter().all(|f| *f == DVec3::ZERO));
    }

    /// The fit recovers φ_J and c from exact points of φ_J + c p^{2/3}.
    #[test]
    fn extrapolation_is_exact_on_its_law() {
        let stages: Vec<Stage> = [1e-3, 1e-4, 1e-5]
            .iter()
            .map(|&p: &f64| Stage {
                target: p,
                pressure: p,
                phi: 0.64 + 0.3 * p.powf(2.0 / 3.0),
                z: 6.0,
                steps: 0,
                total: 0,
                time: 0.0,
                converged: true,
            })
            .collect();
        let (phi_j, c) = extrapolate(&stages).unwrap();
        assert!((phi_j - 0.64).abs() < 1e-12 && (c - 0.3).abs() < 1e-9);
    }
}
