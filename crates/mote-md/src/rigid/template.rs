//! Body templates: a rigid union of spheres filled with matter (seed 000,
//! "Our particle model"), and its mass properties by stochastic integration.
//!
//! A template is computed once per shape and shared (`Arc`) by every body of
//! that shape; it holds the seed's internal state σ: sphere centres and the
//! dipole in the body's initial frame (origin at the centre of mass, axes of
//! the master frame), the principal axes and moments, the mass, density,
//! Young's modulus, Poisson ratio, charge, surface area and bounding radius.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use mote_geom::Inertia;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

/// What a user says about a body: spheres and material (seed 000: "a list
/// c₁ … cₙ of points and a list r₁ … rₙ of radii … matter of given density
/// ρ and Young's modulus E … an electric point charge q and a magnetic
/// dipole j at the centre of mass").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClumpSpec {
    /// Sphere centres in any frame (the template recentres them).
    pub centres: Vec<DVec3>,
    pub radii: Vec<f64>,
    /// Mass density ρ.
    pub density: f64,
    /// Young's modulus (for Hertz contacts).
    #[serde(default)]
    pub youngs_modulus: f64,
    #[serde(default)]
    pub poisson_ratio: f64,
    /// Point charge q at the centre of mass.
    #[serde(default)]
    pub charge: f64,
    /// Magnetic dipole moment j at the centre of mass, in the spec's frame.
    #[serde(default)]
    pub dipole: DVec3,
}

/// How to integrate: the R₂ low-discrepancy sequence of Roberts
/// (α = 1/φ₂, 1/φ₂²) over directions, with `shifts` independent random
/// shifts of `points` directions each per sphere; the spread over shifts
/// gives the error estimate (randomised quasi-Monte Carlo).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integration {
    pub points: usize,
    pub shifts: usize,
    pub seed: u64,
}

impl Default for Integration {
    fn default() -> Self {
        Integration {
            points: 1 << 14,
            shifts: 16,
            seed: 0x5eed_0000,
        }
    }
}

/// Standard errors (1σ over the random shifts) of the mass properties.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MassErrors {
    pub volume: f64,
    /// Of each coordinate of the centre of mass (the largest).
    pub centre: f64,
    pub moments: [f64; 3],
    pub area: f64,
}

/// Mass properties of a union of spheres (seed 000: "volume V, the mass
/// m = ρV, the centre of mass x, the positively oriented triplet of inertial
/// axes e₁, e₂, e₃ := e₁ × e₂ and the corresponding moments of inertia θ₁,
/// θ₂, θ₃ … the surface A and the radius r of a minimal bounding sphere
/// around x").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    pub volume: f64,
    pub mass: f64,
    /// Centre of mass in the spec's frame.
    pub centre: DVec3,
    /// Principal moments θ₁ ≤ θ₂ ≤ θ₃ about the centre of mass.
    pub moments: [f64; 3],
    /// Principal axes, e₃ = e₁ × e₂.
    pub axes: [DVec3; 3],
    pub area: f64,
    /// max |cᵢ − x| + rᵢ.
    pub bounding_radius: f64,
    pub errors: MassErrors,
}

/// Why a spec cannot become a template.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TemplateError {
    #[error("a body needs at least one sphere")]
    Empty,
    #[error("{centres} centres but {radii} radii: give one radius per centre")]
    Mismatch { centres: usize, radii: usize },
    #[error("sphere {index}: radius {radius} must be positive and finite")]
    Radius { index: usize, radius: f64 },
    #[error("density {0} must be positive and finite")]
    Density(f64),
    #[error("{what} must be finite")]
    NotFinite { what: &'static str },
    #[error("{spheres} spheres: a template holds at most {max}")]
    TooManySpheres { spheres: usize, max: usize },
    #[error(
        "{spheres} spheres overlapping in {pairs} pairs or more: integrating its mass properties \
         ({points} directions × {shifts} shifts a pair) would take about {minutes:.0} minutes; \
         build it of fewer or less overlapping spheres (at most about {max_pairs} overlapping pairs)"
    )]
    TooCostly {
        spheres: usize,
        pairs: usize,
        points: usize,
        shifts: usize,
        minutes: f64,
        max_pairs: usize,
    },
}

/// The most overlapping sphere pairs a template's mass properties are
/// integrated for with the default integration: about a minute on a 2-core
/// AMD EPYC, where 100 lobes (5 016 pairs) took 22 s and 30 lobes (457)
/// 1.8 s — the work goes as the pairs times the directions and shifts.
/// 1 000 lobes (≈ 5·10⁵ pairs) would have taken an hour and more.
pub const MAX_OVERLAPPING_PAIRS: usize = 12_000;

/// The most spheres a template holds: its mass properties look at every
/// pair once (10⁴ spheres: 5·10⁷ distance tests).
pub const MAX_TEMPLATE_SPHERES: usize = 10_000;

/// Seconds a pair costs with the default integration (the figure above).
const SECONDS_PER_PAIR: f64 = 22.5 / 5016.0;

/// The pairs (j < i) of overlapping spheres of a clump, what the mass
/// properties' cost goes as, counted up to `limit` (then `limit + 1`).
pub fn overlapping_pairs(spec: &ClumpSpec, limit: usize) -> usize {
    let n = spec.centres.len();
    let mut pairs = 0;
    for i in 0..n {
        pairs += (0..i)
            .filter(|&j| {
                (spec.centres[i] - spec.centres[j]).length() < spec.radii[i] + spec.radii[j]
            })
            .count();
        if pairs > limit {
            return limit + 1;
        }
    }
    pairs
}

/// A body shape with its mass properties: the seed's internal state σ,
/// constant in time and invariant under placement.
#[derive(Clone, Debug)]
pub struct BodyTemplate {
    /// Sphere centres relative to the centre of mass, initial frame.
    pub centres: Vec<DVec3>,
    pub radii: Vec<f64>,
    pub density: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub charge: f64,
    /// Dipole j in the initial frame.
    pub dipole: DVec3,
    pub props: MassProperties,
    /// `I₀ = I(θ₁, θ₂, θ₃, e₁, e₂, e₃, m)`.
    pub inertia: Inertia,
    /// Radius of the sphere of the same volume (for drag).
    pub equivalent_radius: f64,
}

impl BodyTemplate {
    /// Validates the spec and integrates its mass properties.
    pub fn new(spec: &ClumpSpec, integration: Integration) -> Result<Arc<Self>, TemplateError> {
        validate(spec)?;
        if spec.centres.len() > MAX_TEMPLATE_SPHERES {
            return Err(TemplateError::TooManySpheres {
                spheres: spec.centres.len(),
                max: MAX_TEMPLATE_SPHERES,
            });
        }
        let work = (integration.points.max(16) * integration.shifts.max(2)) as f64;
        let default = Integration::default();
        let default_work = (default.points * default.shifts) as f64;
        let max_pairs = (MAX_OVERLAPPING_PAIRS as f64 * default_work / work) as usize;
        // counted only as far as the limit and a good deal past it, for the message
        let pairs = overlapping_pairs(spec, 100 * max_pairs);
        if pairs > max_pairs {
            return Err(TemplateError::TooCostly {
                spheres: spec.centres.len(),
                pairs,
                points: integration.points,
                shifts: integration.shifts,
                minutes: pairs as f64 * SECONDS_PER_PAIR * work / default_work / 60.0,
                max_pairs,
            });
        }
        let props = mass_properties(spec, integration);
        Ok(Arc::new(Self::assemble(spec, props)))
    }

    /// A template whose mass properties are given, not integrated (analytic
    /// bodies, tests); `centre` is taken from `props` and sphere centres are
    /// recentred on it.
    pub fn with_properties(
        spec: &ClumpSpec,
        props: MassProperties,
    ) -> Result<Arc<Self>, TemplateError> {
        validate(spec)?;
        Ok(Arc::new(Self::assemble(spec, props)))
    }

    /// A single sphere of radius `radius` (exact mass properties).
    pub fn sphere(radius: f64, density: f64) -> Result<Arc<Self>, TemplateError> {
        let spec = ClumpSpec {
            centres: vec![DVec3::ZERO],
            radii: vec![radius],
            density,
            youngs_modulus: 0.0,
            poisson_ratio: 0.0,
            charge: 0.0,
            dipole: DVec3::ZERO,
        };
        Self::new(&spec, Integration::default())
    }

    fn assemble(spec: &ClumpSpec, props: MassProperties) -> Self {
        BodyTemplate {
            centres: spec.centres.iter().map(|c| *c - props.centre).collect(),
            radii: spec.radii.clone(),
            density: spec.density,
            youngs_modulus: spec.youngs_modulus,
            poisson_ratio: spec.poisson_ratio,
            charge: spec.charge,
            dipole: spec.dipole,
            inertia: Inertia::new(props.moments, props.axes, props.mass),
            equivalent_radius: (3.0 * props.volume / (4.0 * PI)).cbrt(),
            props,
        }
    }

    pub fn mass(&self) -> f64 {
        self.props.mass
    }

    pub fn sphere_count(&self) -> usize {
        self.centres.len()
    }
}

fn validate(spec: &ClumpSpec) -> Result<(), TemplateError> {
    if spec.centres.is_empty() {
        return Err(TemplateError::Empty);
    }
    if spec.centres.len() != spec.radii.len() {
        return Err(TemplateError::Mismatch {
            centres: spec.centres.len(),
            radii: spec.radii.len(),
        });
    }
    for (index, &radius) in spec.radii.iter().enumerate() {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(TemplateError::Radius { index, radius });
        }
    }
    if !(spec.density > 0.0 && spec.density.is_finite()) {
        return Err(TemplateError::Density(spec.density));
    }
    if !spec.centres.iter().all(|c| c.is_finite()) {
        return Err(TemplateError::NotFinite {
            what: "sphere centres",
        });
    }
    if !(spec.charge.is_finite() && spec.dipole.is_finite() && spec.youngs_modulus.is_finite()) {
        return Err(TemplateError::NotFinite {
            what: "charge, dipole and Young's modulus",
        });
    }
    Ok(())
}

/// The R₂ sequence of Roberts (2018): αₖ = φ₂^−k with φ₂ the positive
/// root of x³ = x + 1 (the plastic number).
const PHI2: f64 = 1.324_717_957_244_746;

/// Volume, centre, principal moments and area from one random shift.
type ShiftEstimate = (f64, DVec3, [f64; 3], f64);

/// Sums of one random shift: volume, first and second moments, area.
#[derive(Clone, Copy, Default)]
struct Sums {
    volume: f64,
    first: DVec3,
    second: [[f64; 3]; 3],
    area: f64,
}

/// Mass properties by randomised quasi-Monte Carlo, with the analytic
/// sphere integrals as control variates: the union is the disjoint union of
/// `Sᵢ \ (S₁ ∪ … ∪ Sᵢ₋₁)`, so for each sphere we take its exact volume and
/// moments and subtract the part shared with earlier spheres. That part is
/// integrated along rays from the centre of `Sᵢ`: on each ray the shared
/// part is a union of intervals (ray–sphere intersections), integrated in
/// closed form (∫t²dt, ∫t³dt, ∫t⁴dt); only the directions are sampled. The
/// integrand over directions is continuous, so the error falls about as
/// N⁻¹ rather than the N^−½…N^−⅔ of points thrown into a volume. A single
/// sphere and disjoint spheres come out exact; the error lives in the
/// overlaps only. The area of sphere i is `4πrᵢ²` times
/// the fraction of its surface outside all other spheres (points by the R₂
/// sequence mapped area-preservingly).
pub fn mass_properties(spec: &ClumpSpec, integration: Integration) -> MassProperties {
    let n = spec.centres.len();
    let k_shifts = integration.shifts.max(2);
    let npts = integration.points.max(16);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(integration.seed);
    let a2 = [1.0 / PHI2, 1.0 / (PHI2 * PHI2)];
    let inside_any = |y: DVec3, pred: &dyn Fn(usize) -> bool| {
        (0..n).any(|j| {
            pred(j) && (y - spec.centres[j]).length_squared() < spec.radii[j] * spec.radii[j]
        })
    };
    let mut per_shift = Vec::with_capacity(k_shifts);
    for _ in 0..k_shifts {
        let s2v = [rng.gen::<f64>(), rng.gen::<f64>()];
        let s2 = [rng.gen::<f64>(), rng.gen::<f64>()];
        let mut sums = Sums::default();
        for i in 0..n {
            let (c, r) = (spec.centres[i], spec.radii[i]);
            let v = 4.0 / 3.0 * PI * r * r * r;
            // exact sphere integrals
            sums.volume += v;
            sums.first += v * c;
            for p in 0..3 {
                for q in 0..3 {
                    sums.second[p][q] += v * (c[p] * c[q] + if p == q { r * r / 5.0 } else { 0.0 });
                }
            }
            // minus the part already counted by earlier spheres, ray by ray
            let earlier: Vec<usize> = (0..i)
                .filter(|&j| (c - spec.centres[j]).length() < r + spec.radii[j])
                .collect();
            if !earlier.is_empty() {
                let w = 4.0 * PI / npts as f64; // solid angle per direction
                let (mut ov, mut of, mut os) = (0.0, DVec3::ZERO, [[0.0; 3]; 3]);
                let mut segs: Vec<(f64, f64)> = Vec::with_capacity(earlier.len());
                for m in 0..npts {
                    let dir = sphere_surface(lattice2(s2v, a2, m));
                    let ns = covered_segments(c, r, dir, &earlier, spec, &mut segs);
                    for &(ta, tb) in &segs[..ns] {
                        // ∫ t² dt, ∫ t³ dt, ∫ t⁴ dt over [ta, tb]
                        let m2 = (tb * tb * tb - ta * ta * ta) / 3.0;
                        let m3 = (tb.powi(4) - ta.powi(4)) / 4.0;
                        let m4 = (tb.powi(5) - ta.powi(5)) / 5.0;
                        ov += m2;
                        of += c * m2 + dir * m3;
                        for p in 0..3 {
                            for q in 0..3 {
                                os[p][q] += c[p] * c[q] * m2
                                    + (c[p] * dir[q] + dir[p] * c[q]) * m3
                                    + dir[p] * dir[q] * m4;
                            }
                        }
                    }
                }
                sums.volume -= w * ov;
                sums.first -= w * of;
                for p in 0..3 {
                    for q in 0..3 {
                        sums.second[p][q] -= w * os[p][q];
                    }
                }
            }
            // area outside all other spheres
            let area = 4.0 * PI * r * r;
            let any_overlap =
                (0..n).any(|j| j != i && (c - spec.centres[j]).length() < r + spec.radii[j]);
            if any_overlap {
                let mut out = 0usize;
                for m in 0..npts {
                    let u = lattice2(s2, a2, m);
                    let y = c + r * sphere_surface(u);
                    if !inside_any(y, &|j| j != i) {
                        out += 1;
                    }
                }
                sums.area += area * out as f64 / npts as f64;
            } else {
                sums.area += area;
            }
        }
        per_shift.push(sums);
    }
    let rho = spec.density;
    // per-shift derived quantities
    let derived: Vec<ShiftEstimate> = per_shift
        .iter()
        .map(|s| {
            let x = s.first / s.volume;
            let (moments, _) = principal(&inertia_tensor(s, x, rho));
            (s.volume, x, moments, s.area)
        })
        .collect();
    let mean = {
        let k = k_shifts as f64;
        let mut m = Sums::default();
        for s in &per_shift {
            m.volume += s.volume / k;
            m.first += s.first / k;
            m.area += s.area / k;
            for p in 0..3 {
                for q in 0..3 {
                    m.second[p][q] += s.second[p][q] / k;
                }
            }
        }
        m
    };
    let centre = mean.first / mean.volume;
    let (moments, axes) = principal(&inertia_tensor(&mean, centre, rho));
    let se = |f: &dyn Fn(&ShiftEstimate) -> f64| {
        let k = derived.len() as f64;
        let mu = derived.iter().map(f).sum::<f64>() / k;
        let var = derived.iter().map(|d| (f(d) - mu).powi(2)).sum::<f64>() / (k - 1.0);
        (var / k).sqrt()
    };
    let errors = MassErrors {
        volume: se(&|d| d.0),
        centre: se(&|d| d.1.x).max(se(&|d| d.1.y)).max(se(&|d| d.1.z)),
        moments: [se(&|d| d.2[0]), se(&|d| d.2[1]), se(&|d| d.2[2])],
        area: se(&|d| d.3),
    };
    let bounding_radius = spec
        .centres
        .iter()
        .zip(&spec.radii)
        .map(|(c, r)| (*c - centre).length() + r)
        .fold(0.0, f64::max);
    MassProperties {
        volume: mean.volume,
        mass: rho * mean.volume,
        centre,
        moments,
        axes,
        area: mean.area,
        bounding_radius,
        errors,
    }
}

/// The parts `[ta, tb] ⊂ [0, r]` of the ray `c + t·dir` inside any of the
/// spheres `which`, merged into disjoint sorted segments; returns their
/// count.
fn covered_segments(
    c: DVec3,
    r: f64,
    dir: DVec3,
    which: &[usize],
    spec: &ClumpSpec,
    segs: &mut Vec<(f64, f64)>,
) -> usize {
    segs.clear();
    for &j in which {
        let w = c - spec.centres[j];
        let b = dir.dot(w);
        let disc = b * b - (w.length_squared() - spec.radii[j] * spec.radii[j]);
        if disc <= 0.0 {
            continue;
        }
        let sd = disc.sqrt();
        let (ta, tb) = ((-b - sd).max(0.0), (-b + sd).min(r));
        if tb > ta {
            segs.push((ta, tb));
        }
    }
    let n = segs.len();
    if n <= 1 {
        return n;
    }
    segs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut k = 0;
    for m in 1..n {
        if segs[m].0 <= segs[k].1 {
            segs[k].1 = segs[k].1.max(segs[m].1);
        } else {
            k += 1;
            segs[k] = segs[m];
        }
    }
    k + 1
}

#[inline]
fn lattice2(s: [f64; 2], a: [f64; 2], m: usize) -> [f64; 2] {
    let mf = m as f64;
    [(s[0] + mf * a[0]).fract(), (s[1] + mf * a[1]).fract()]
}

/// Unit square → unit sphere, area-preserving (Archimedes).
#[inline]
fn sphere_surface(u: [f64; 2]) -> DVec3 {
    let z = 2.0 * u[0] - 1.0;
    let s = (1.0 - z * z).max(0.0).sqrt();
    let (sp, cp) = (2.0 * PI * u[1]).sin_cos();
    DVec3::new(s * cp, s * sp, z)
}

/// `J = ρ (tr(M) 𝟙 − M)` with M the second moment about the centre x.
fn inertia_tensor(s: &Sums, x: DVec3, rho: f64) -> [[f64; 3]; 3] {
    let mut m = s.second;
    for p in 0..3 {
        for q in 0..3 {
            m[p][q] -= s.volume * x[p] * x[q];
        }
    }
    let tr = m[0][0] + m[1][1] + m[2][2];
    let mut j = [[0.0; 3]; 3];
    for p in 0..3 {
        for q in 0..3 {
            j[p][q] = rho * (if p == q { tr } else { 0.0 } - m[p][q]);
        }
    }
    j
}

/// Eigenvalues (ascending) and a positively oriented orthonormal eigenbasis
/// (e₃ = e₁ × e₂) of a symmetric 3×3 matrix, by cyclic Jacobi rotations.
pub fn principal(a: &[[f64; 3]; 3]) -> ([f64; 3], [DVec3; 3]) {
    let mut a = *a;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-17 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for k in 0..3 {
                let (vkp, vkq) = (v[k][p], v[k][q]);
                v[k][p] = c * vkp - s * vkq;
                v[k][q] = s * vkp + c * vkq;
            }
        }
    }
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let vals = idx.map(|i| a[i][i]);
    let col = |i: usize| DVec3::new(v[0][i], v[1][i], v[2][i]).normalize();
    let e1 = col(idx[0]);
    let e2 = (col(idx[1]) - e1 * e1.dot(col(idx[1]))).normalize();
    (vals, [e1, e2, e1.cross(e2)])
}
