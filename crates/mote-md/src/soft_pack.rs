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

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::boundary::Boundary;
use crate::neighbor::SizedList;

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
    /// Steps allowed per target pressure.
    pub max_steps: u64,
    pub seed: u64,
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

/// One held target pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stage {
    pub target: f64,
    /// Reduced pressure P/K at the end of the stage.
    pub pressure: f64,
    /// Nominal packing fraction Σ (π/6) dᵢ³ / V.
    pub phi: f64,
    /// Mean number of overlapping neighbours per sphere (all spheres).
    pub z: f64,
    /// Steps taken in this stage.
    pub steps: u64,
    /// Simulated time at the end of the stage.
    pub time: f64,
    /// Whether the pressure held and the motion died out within the
    /// step budget.
    pub converged: bool,
}

/// The soft-sphere packing in progress.
pub struct SoftPacker {
    pub position: Vec<DVec3>,
    pub velocity: Vec<DVec3>,
    pub radius: Vec<f64>,
    mass: Vec<f64>,
    force: Vec<DVec3>,
    pub boundary: Boundary,
    list: SizedList,
    /// The largest diameter.
    d_max: f64,
    /// Positions and box side at the last list build.
    reference: Vec<DVec3>,
    reference_side: f64,
    pub time: f64,
    pub steps: u64,
    settings: SoftPackSettings,
    /// The residual force the last minimisation could reach at best
    /// (rounding of the positions), relative to the mean contact force.
    pub last_floor: f64,
}

/// Forces and what they sum to, from one pass over the pairs.
#[derive(Debug, Clone, Copy, Default)]
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
    /// A random start at `phi_start` in a periodic cube.
    pub fn new(settings: SoftPackSettings) -> Result<Self, String> {
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
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(settings.seed);
        let position: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * side)
            .collect();
        let mass = radius.iter().map(|a| 2.0 * a).collect();
        Ok(Self {
            velocity: vec![DVec3::ZERO; n],
            force: vec![DVec3::ZERO; n],
            reference: Vec::new(),
            reference_side: side,
            list: SizedList::new(skin),
            d_max,
            position,
            radius,
            mass,
            boundary,
            time: 0.0,
            steps: 0,
            settings,
            last_floor: 0.0,
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

    /// Rebuilds the neighbour list when a pair may have come within reach
    /// unseen: twice the largest non-affine displacement plus the affine
    /// shrink of the reach since the last build exceeds the skin.
    fn refresh_list(&mut self) {
        let side = self.side();
        let scale = side / self.reference_side;
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
            self.reference_side = side;
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
        sums
    }

    /// Holds each target pressure in turn; `on_stage` sees each stage as
    /// it ends. `stop` is asked between chunks of steps; when it says so
    /// the run ends with the stages so far.
    pub fn run(
        &mut self,
        mut on_stage: impl FnMut(&Stage, &Self),
        stop: &dyn Fn() -> bool,
    ) -> Vec<Stage> {
        let mut stages = Vec::new();
        let targets = self.settings.pressures.clone();
        for target in targets {
            match self.hold(target, stop) {
                Some(stage) => {
                    on_stage(&stage, self);
                    stages.push(stage);
                }
                None => break,
            }
        }
        stages
    }

    /// Runs at target pressure `target` until it holds (or the step budget
    /// is spent); `None` when `stop` ended it.
    fn hold(&mut self, target: f64, stop: &dyn Fn() -> bool) -> Option<Stage> {
        let n = self.position.len() as f64;
        let overlap = target.powf(2.0 / 3.0);
        let omega = (1.5 * overlap.sqrt()).sqrt();
        let friction = omega; // ζ/m = 1/τ
        let rate_max = 0.1 * overlap * omega;
        let tol = self.settings.tolerance;
        let mut steps = 0u64;
        let mut held = 0u32;
        self.refresh_list();
        let mut sums = self.pair_forces();
        let mut dt = 0.1 / sums.stiffest.max(omega * omega).sqrt();
        let converged = loop {
            // Velocity Verlet (the dissipative forces use the velocities
            // of the previous half step), then the box follows the
            // pressure.
            for i in 0..self.position.len() {
                let a = self.force[i] / self.mass[i] - friction * self.velocity[i];
                self.velocity[i] += 0.5 * dt * a;
                self.position[i] += dt * self.velocity[i];
            }
            self.refresh_list();
            sums = self.pair_forces();
            let mut kinetic2 = 0.0;
            for i in 0..self.position.len() {
                let a = self.force[i] / self.mass[i] - friction * self.velocity[i];
                self.velocity[i] += 0.5 * dt * a;
                kinetic2 += self.mass[i] * self.velocity[i].length_squared();
            }
            let volume = self.boundary.volume();
            let pressure = (kinetic2 + sums.virial) / (3.0 * volume);
            let strain_rate = rate_max * ((pressure - target) / target).clamp(-1.0, 1.0);
            let scale = (strain_rate * dt).exp();
            let lo = self.boundary.lo;
            for r in &mut self.position {
                *r = lo + (*r - lo) * scale;
            }
            self.boundary.hi = lo + (self.boundary.hi - lo) * scale;
            self.time += dt;
            self.steps += 1;
            steps += 1;
            if steps.is_multiple_of(100) {
                dt = 0.1 / sums.stiffest.max(omega * omega).sqrt();
                let still = 0.5 * kinetic2 < 1e-4 * sums.elastic;
                if (pressure / target - 1.0).abs() < tol && still {
                    held += 1;
                    if held >= 3 {
                        break true;
                    }
                } else {
                    held = 0;
                }
                if steps >= self.settings.max_steps {
                    break false;
                }
                if steps.is_multiple_of(1000) && stop() {
                    return None;
                }
            }
        };
        let volume = self.boundary.volume();
        let kinetic2: f64 = self
            .velocity
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| m * v.length_squared())
            .sum();
        Some(Stage {
            target,
            pressure: (kinetic2 + sums.virial) / (3.0 * volume),
            phi: self.phi(),
            z: 2.0 * sums.contacts as f64 / n,
            steps,
            time: self.time,
            converged,
        })
    }
}

impl SoftPacker {
    /// The jamming finish: the elastic energy minimised at fixed box by
    /// FIRE (Bitzek et al., Phys. Rev. Lett. 97, 170201 (2006): damped
    /// dynamics that mixes the velocity towards the force, v ← (1 − α) v +
    /// α |v| F̂, speeding up while the power F·v stays positive and
    /// stopping dead when it turns negative), until the root-mean-square
    /// net force is below `ftol` times the mean contact force (or the floor
    /// the rounding of the positions sets, ~50 ε L/δ̄; or when the best
    /// residual has not halved in 20 000 steps). The barostat
    /// leaves a residual imbalance of a few per cent; at a true minimum
    /// the spheres that carry no load lose their contacts, so rattlers and
    /// the backbone's contact number are those of a mechanically stable
    /// packing. Returns the steps taken and the relative residual reached.
    pub fn minimise(&mut self, ftol: f64, max_steps: u64) -> (u64, f64) {
        // Bitzek et al.'s parameters.
        const N_MIN: u64 = 5;
        const F_INC: f64 = 1.1;
        const F_DEC: f64 = 0.5;
        const ALPHA0: f64 = 0.1;
        const F_ALPHA: f64 = 0.99;
        self.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
        self.refresh_list();
        let mut sums = self.pair_forces_with(false);
        let dt0 = 0.1 / sums.stiffest.max(1e-300).sqrt();
        let (mut dt, mut alpha, mut since_negative) = (dt0, ALPHA0, 0u64);
        let residual = |p: &Self, sums: &PairSums| -> f64 {
            let rms = (p.force.iter().map(|f| f.length_squared()).sum::<f64>()
                / p.force.len() as f64)
                .sqrt();
            // Mean contact force from the virial: Σ F·r ≈ F̄ d̄ per contact.
            let mean_contact = sums.virial / sums.contacts.max(1) as f64;
            rms / mean_contact.max(1e-300)
        };
        // Positions carry ~ε L of rounding, so overlaps δ carry a relative
        // error ε L/δ and forces 3/2 of it: no minimiser gets below that.
        let side = self.side();
        let floor = |sums: &PairSums| {
            let mean_overlap = sums.overlap / sums.contacts.max(1) as f64;
            50.0 * f64::EPSILON * side / mean_overlap.max(1e-300)
        };
        let mut steps = 0;
        let mut rel = residual(self, &sums);
        // Stagnation: the best residual must halve every 20 000 steps.
        let (mut best, mut best_at) = (rel, 0u64);
        while rel > ftol.max(floor(&sums)) && steps < max_steps && steps - best_at < 20_000 {
            let power: f64 = self
                .force
                .iter()
                .zip(&self.velocity)
                .map(|(f, v)| f.dot(*v))
                .sum();
            if power > 0.0 {
                let (fnorm, vnorm) = (
                    self.force
                        .iter()
                        .map(|f| f.length_squared())
                        .sum::<f64>()
                        .sqrt(),
                    self.velocity
                        .iter()
                        .map(|v| v.length_squared())
                        .sum::<f64>()
                        .sqrt(),
                );
                for (v, f) in self.velocity.iter_mut().zip(&self.force) {
                    *v = (1.0 - alpha) * *v + alpha * vnorm * *f / fnorm.max(1e-300);
                }
                since_negative += 1;
                if since_negative > N_MIN {
                    dt = (dt * F_INC).min(10.0 * dt0);
                    alpha *= F_ALPHA;
                }
            } else {
                self.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
                since_negative = 0;
                dt *= F_DEC;
                alpha = ALPHA0;
            }
            for i in 0..self.position.len() {
                self.velocity[i] += 0.5 * dt * self.force[i] / self.mass[i];
                self.position[i] += dt * self.velocity[i];
            }
            self.refresh_list();
            sums = self.pair_forces_with(false);
            for i in 0..self.position.len() {
                self.velocity[i] += 0.5 * dt * self.force[i] / self.mass[i];
            }
            steps += 1;
            self.steps += 1;
            rel = residual(self, &sums);
            if rel < 0.5 * best {
                (best, best_at) = (rel, steps);
            }
        }
        self.last_floor = floor(&sums);
        self.velocity.iter_mut().for_each(|v| *v = DVec3::ZERO);
        (steps, rel)
    }

    /// The jamming finish towards vanishing pressure: energy minimisation
    /// at fixed box ([`SoftPacker::minimise`]) alternated with affine
    /// decompression, a decade of pressure at a time down to `lowest`
    /// (O'Hern et al. 2003's protocol). Near jamming φ is linear in
    /// x = p^{2/3}, so each next φ comes from the line through the last two
    /// minimised states (the first step takes the slope of the barostat's
    /// stages, `slope`); a step that unjams the packing (pressure below a
    /// thousandth of its aim) is undone and halved. Returns the minimised
    /// states (pressure, φ, minimiser steps), the first being the start.
    pub fn jam(
        &mut self,
        lowest: f64,
        slope: f64,
        ftol: f64,
        stop: &dyn Fn() -> bool,
    ) -> Vec<Stage> {
        let mut out: Vec<Stage> = Vec::new();
        let record = |p: &mut Self, steps: u64, target: f64, converged: bool| {
            let (pressure, z) = p.at_rest();
            Stage {
                target,
                pressure,
                phi: p.phi(),
                z,
                steps,
                time: p.time,
                converged,
            }
        };
        let (steps, rel) = self.minimise(ftol, self.settings.max_steps);
        let first = record(self, steps, f64::NAN, rel <= ftol.max(self.last_floor));
        if first.pressure <= 0.0 {
            return vec![first];
        }
        out.push(first);
        let mut fails = 0;
        while out.last().unwrap().pressure > 1.5 * lowest && fails < 20 && !stop() {
            let last = *out.last().unwrap();
            let aim = (last.pressure / 10.0).max(lowest);
            let x = |p: f64| p.powf(2.0 / 3.0);
            let c = match out.len() {
                1 => slope,
                k => {
                    let prev = out[k - 2];
                    (last.phi - prev.phi) / (x(last.pressure) - x(prev.pressure))
                }
            };
            let c = if c.is_finite() && c > 0.0 { c } else { slope };
            let mut dphi = c * (x(last.pressure) - x(aim)) / 2f64.powi(fails);
            let saved = (self.position.clone(), self.boundary, self.reference_side);
            loop {
                let scale = (last.phi / (last.phi - dphi)).cbrt();
                let lo = self.boundary.lo;
                for r in &mut self.position {
                    *r = lo + (*r - lo) * scale;
                }
                self.boundary.hi = lo + (self.boundary.hi - lo) * scale;
                let (steps, rel) = self.minimise(ftol, self.settings.max_steps);
                let now = record(self, steps, aim, rel <= ftol.max(self.last_floor));
                if now.pressure > 1e-3 * aim {
                    out.push(now);
                    break;
                }
                // Unjammed: back to the saved state, half the step.
                (self.position, self.boundary, self.reference_side) = saved.clone();
                self.reference.clear();
                dphi *= 0.5;
                fails += 1;
                if fails >= 20 || stop() {
                    break;
                }
            }
        }
        out
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
                time: 0.0,
                converged: true,
            })
            .collect();
        let (phi_j, c) = extrapolate(&stages).unwrap();
        assert!((phi_j - 0.64).abs() < 1e-12 && (c - 0.3).abs() < 1e-9);
    }
}
