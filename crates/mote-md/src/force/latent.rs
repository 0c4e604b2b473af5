//! The field of surface charge on a plane: a uniformly charged rectangle in
//! open space, and the latent image of a photoconductor belt between two
//! conducting planes.
//!
//! **A rectangle in open space.** A rectangle x′ ∈ [x₁, x₂], y′ ∈ [y₁, y₂]
//! of the plane z = 0 with charge density σ has, with X = x − x′,
//! Y = y − y′, R = (X² + Y² + z²)^{1/2} and the corner sum
//! \[\[F\]\] = F(x−x₁, y−y₁) − F(x−x₁, y−y₂) − F(x−x₂, y−y₁) + F(x−x₂, y−y₂)
//! (Durand, *Électrostatique* I (1964); Hummer, J. Chem. Phys. 105, 2004
//! (1996), Eq. A1):
//!
//! φ = kσ [[X ln(Y + R) + Y ln(X + R) − z atan(XY/(zR))]],
//! E_x = −kσ [[ln(Y + R)]], E_y = −kσ [[ln(X + R)]], E_z = kσ [[atan(XY/(zR))]],
//!
//! k = 1/(4πε₀). Far away it is the point charge σ(x₂−x₁)(y₂−y₁); just
//! above its interior E_z → 2πkσ = σ/2ε₀.
//!
//! **The latent image.** The belt is a grounded conductor z = 0 under a
//! photoconductor whose top surface z = d carries the image charge
//! σ(x − vt): background σ_b, and patches [x₁, x₂] of density σ_p that span
//! the box across the track (in a slice periodic along y, a narrower patch
//! would be a stripe pattern anyway). The shell z = h is grounded too (its
//! bias is [`super::slab::ConductingPlanes`]'s). The photoconductor's
//! dielectric is taken as vacuum of the electrical thickness d = d_pc/ε_r.
//! The field is two-dimensional; the map ζ = e^{πw/h}, w = x + iz, takes the
//! gap to the upper half-plane, where the image of a line charge is its
//! mirror, and integrating the line charges of a strip gives the field of
//! a charged strip with all its images in both planes in closed form
//! (z > d; u = π/h, θ₁ = u(z + d), θ₂ = u(z − d)):
//!
//! E_x − iE_z = 2kσ [Λ(x₂ − x) − Λ(x₁ − x)],
//! Λ(s) = ln(1 − e^{us} e^{−iθ₁}) − ln(1 − e^{us} e^{−iθ₂})          (s ≤ 0),
//! Λ(s) = ln(1 − e^{−us} e^{iθ₁}) − ln(1 − e^{−us} e^{iθ₂}) − 2iud    (s > 0),
//!
//! two forms of ln((ζ − ζ̄′)/(ζ − ζ′)) that agree at s = 0 and never
//! overflow. The whole plane gives the uniform field E_z = 4πkσ d/h. The
//! periodic copies of a strip along x, at distance s, add e^{−π|s|/h}: they
//! are summed until that is below 10⁻¹⁷. The copies on either side of a
//! point are each a geometric progression in e^{∓us} of ratio q = e^{−uL},
//! so each side's logarithms are the logarithm of one product (one ln and
//! one atan2 for all its copies; copy by copy where q ≥ ½), and the two
//! products of a side (θ₁ and θ₂) one ratio where its argument cannot
//! pass ±π (ud + πq/(1 − q) < π/2: one ln and one atan2 for the side).

use glam::DVec3;

/// ln(Y + R) without cancellation where Y < 0 (R ≥ |Y|, R² − Y² = ρ²).
#[inline]
fn log_sum(y: f64, r: f64, rho2: f64) -> f64 {
    if y >= 0.0 {
        (y + r).ln()
    } else {
        (rho2 / (r - y)).ln()
    }
}

/// Potential and field of the rectangle x′ ∈ `x`, y′ ∈ `y` of the plane
/// z = 0 at the point `p`, per unit kσ (multiply both by kσ). Not defined
/// on the rectangle itself (z = 0).
pub fn rectangle(p: DVec3, x: [f64; 2], y: [f64; 2]) -> (f64, DVec3) {
    let z = p.z;
    let mut phi = 0.0;
    let mut e = DVec3::ZERO;
    for (xs, sx) in [(x[0], 1.0), (x[1], -1.0)] {
        for (ys, sy) in [(y[0], 1.0), (y[1], -1.0)] {
            let (a, b) = (p.x - xs, p.y - ys);
            let r = (a * a + b * b + z * z).sqrt();
            let s = sx * sy;
            let ly = log_sum(b, r, a * a + z * z);
            let lx = log_sum(a, r, b * b + z * z);
            let t = if z == 0.0 {
                0.0
            } else {
                (a * b / (z * r)).atan()
            };
            phi += s * (a * ly + b * lx - z * t);
            e += s * DVec3::new(-ly, -lx, t);
        }
    }
    (phi, e)
}

/// A patch of the latent image: x ∈ [start, end) at time 0 (it moves with
/// the belt), charge density `density`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    pub start: f64,
    pub end: f64,
    pub density: f64,
}

/// The latent image on the belt z = d above the grounded plane z = 0, with
/// the grounded shell z = h, periodic along x with period L.
#[derive(Debug, Clone, PartialEq)]
pub struct LatentImage {
    /// k = 1/(4πε₀).
    pub k: f64,
    /// The gap h between the conducting planes.
    pub gap: f64,
    /// The height d of the charged surface above the belt's conductor
    /// (the photoconductor's electrical thickness).
    pub height: f64,
    /// The period L along x.
    pub period: f64,
    /// The belt's speed along x.
    pub speed: f64,
    /// Charge density σ_b outside the patches.
    pub background: f64,
    pub patches: Vec<Patch>,
}

/// ln(1 − A e^{iθ}) as (re, im), 0 ≤ A ≤ 1.
#[inline]
fn log_one_minus(a: f64, theta: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    let (re, im) = (1.0 - a * c, -a * s);
    (0.5 * (re * re + im * im).ln(), im.atan2(re))
}

/// Σ_{k<count} ln(1 − A qᵏ e^{iθ}) as (re, im), 0 ≤ A ≤ 1, 0 ≤ q < ½,
/// given (sin θ, cos θ): the logarithm of the product — one logarithm and
/// one arctangent for the progression instead of one each a term. The
/// first factor turns by less than π/2 (its real part 1 − A cos θ ≥ 0), the
/// others (k ≥ 1) each by at most arcsin qᵏ, together less than 1.02, so the
/// product's argument is the sum of theirs (no turn of 2π lost).
fn log_progression(a: f64, q: f64, (s, c): (f64, f64), count: usize) -> (f64, f64) {
    let (mut re, mut im, mut x) = (1.0, 0.0, a);
    for _ in 0..count {
        let (fr, fi) = (1.0 - x * c, -x * s);
        (re, im) = (re * fr - im * fi, re * fi + im * fr);
        x *= q;
    }
    (0.5 * (re * re + im * im).ln(), im.atan2(re))
}

/// Σ_{k<count} [ln(1 − A qᵏ e^{iθ₁}) − ln(1 − A qᵏ e^{iθ₂})] as (re, im),
/// given (sin θ, cos θ) of both: [`log_progression`] of θ₁ less that of θ₂,
/// as the logarithm of the ratio of the two products — one logarithm and
/// one arctangent for both. The arctangent of P₁P̄₂ gives arg P₁ − arg P₂
/// only within (−π, π]; the caller takes this form where that interval
/// holds the difference ([`LatentImage::ratio_holds`]).
fn log_ratio_progression(
    a: f64,
    q: f64,
    (s1, c1): (f64, f64),
    (s2, c2): (f64, f64),
    count: usize,
) -> (f64, f64) {
    // The two products in one loop, not two calls of one product's loop:
    // the two chains of multiplications then overlap (the same bits; two
    // loops measured 5–8 % slower on the whole nip).
    let (mut re1, mut im1, mut re2, mut im2, mut x) = (1.0, 0.0, 1.0, 0.0, a);
    for _ in 0..count {
        let (fr1, fi1) = (1.0 - x * c1, -x * s1);
        let (fr2, fi2) = (1.0 - x * c2, -x * s2);
        (re1, im1) = (re1 * fr1 - im1 * fi1, re1 * fi1 + im1 * fr1);
        (re2, im2) = (re2 * fr2 - im2 * fi2, re2 * fi2 + im2 * fr2);
        x *= q;
    }
    // P₁P̄₂ and |P₁|²/|P₂|².
    let (re, im) = (re1 * re2 + im1 * im2, im1 * re2 - re1 * im2);
    let ratio = (re1 * re1 + im1 * im1) / (re2 * re2 + im2 * im2);
    (0.5 * ratio.ln(), im.atan2(re))
}

impl LatentImage {
    /// Whether the two progressions of a side of [`LatentImage::field`]
    /// may be summed as one ratio ([`log_ratio_progression`]): their first
    /// factors turn by angles in [−ud, π/2] (or [−π/2, ud]) for d < z < h,
    /// u = π/h, and the later ones each by at most arcsin qᵏ ≤ (π/2) qᵏ,
    /// so the difference of the two arguments stays within
    /// π/2 + ud + π q/(1 − q), which is below π where this holds (the
    /// caller also asks d < z < h, where those angles hold).
    fn ratio_holds(&self, q: f64) -> bool {
        let u = std::f64::consts::PI / self.gap;
        u * self.height + std::f64::consts::PI * q / (1.0 - q) < std::f64::consts::FRAC_PI_2
    }

    /// Checks the geometry: 0 < d < h, L > 0, patches inside one period.
    pub fn check(&self) -> Result<(), String> {
        if !(self.gap > 0.0 && self.height > 0.0 && self.height < self.gap) {
            return Err("the latent image needs 0 < height < gap".into());
        }
        if self.period.is_nan() || self.period <= 0.0 {
            return Err("the latent image needs a period > 0".into());
        }
        for p in &self.patches {
            if !(p.end > p.start && p.end - p.start <= self.period) {
                return Err(format!(
                    "a patch [{}, {}] must have start < end within one period {}",
                    p.start, p.end, self.period
                ));
            }
        }
        Ok(())
    }

    /// Λ(s) as (re, im) at height z.
    #[inline]
    fn lambda(&self, s: f64, z: f64) -> (f64, f64) {
        let u = std::f64::consts::PI / self.gap;
        let (t1, t2) = (u * (z + self.height), u * (z - self.height));
        if s <= 0.0 {
            let b = (u * s).exp();
            let (a1, a2) = (log_one_minus(b, -t1), log_one_minus(b, -t2));
            (a1.0 - a2.0, a1.1 - a2.1)
        } else {
            let a = (-u * s).exp();
            let (a1, a2) = (log_one_minus(a, t1), log_one_minus(a, t2));
            (a1.0 - a2.0, a1.1 - a2.1 - 2.0 * u * self.height)
        }
    }

    /// Σ_{n=−R}^{R} Λ(s + nL) at height z as (re, im), given (sin, cos)
    /// of θ₁ and θ₂: the copies with s + nL ≤ 0 and those beyond are each a
    /// progression in e^{∓u(s + nL)} of ratio q = e^{−uL}
    /// ([`log_progression`]).
    fn lambda_copies(
        &self,
        s: f64,
        reach: i64,
        q: f64,
        theta1: (f64, f64),
        theta2: (f64, f64),
        ratio: bool,
    ) -> (f64, f64) {
        let (l, u) = (self.period, std::f64::consts::PI / self.gap);
        // The last copy at or before the edge: s + nL ≤ 0 for n ≤ last.
        let last = ((-s / l).floor() as i64).clamp(-reach - 1, reach);
        let conjugate = |(sin, cos): (f64, f64)| (-sin, cos);
        let (mut re, mut im) = (0.0, 0.0);
        // Each side's two progressions: as one ratio where that holds.
        let side = |a: f64, t1: (f64, f64), t2: (f64, f64), count: usize| {
            if ratio {
                log_ratio_progression(a, q, t1, t2, count)
            } else {
                let a1 = log_progression(a, q, t1, count);
                let a2 = log_progression(a, q, t2, count);
                (a1.0 - a2.0, a1.1 - a2.1)
            }
        };
        let before = (last + reach + 1) as usize;
        if before > 0 {
            // e^{u(s + nL)} for n = last, last − 1, …, −R.
            let b = (u * (s + last as f64 * l)).exp();
            (re, im) = side(b, conjugate(theta1), conjugate(theta2), before);
        }
        let after = (reach - last) as usize;
        if after > 0 {
            // e^{−u(s + nL)} for n = last + 1, …, R.
            let a = (-u * (s + (last + 1) as f64 * l)).exp();
            let (r, i) = side(a, theta1, theta2, after);
            re += r;
            im += i - after as f64 * 2.0 * u * self.height;
        }
        (re, im)
    }

    /// The field (E_x, E_z) at (x, z), d < z < h, at time t.
    pub fn field(&self, x: f64, z: f64, t: f64) -> (f64, f64) {
        let (l, u) = (self.period, std::f64::consts::PI / self.gap);
        let q = (-u * l).exp();
        if q >= 0.5 {
            // A period under 0.22 h: copy by copy.
            return self.field_copy_by_copy(x, z, t);
        }
        let theta1 = (u * (z + self.height)).sin_cos();
        let theta2 = (u * (z - self.height)).sin_cos();
        let ratio = self.ratio_holds(q) && z > self.height && z < self.gap;
        let mut ex = 0.0;
        let mut ez = 4.0 * std::f64::consts::PI * self.k * self.background * self.height / self.gap;
        for p in &self.patches {
            let (w, c, reach) = self.placed(p, x, t);
            let a = self.lambda_copies(c + 0.5 * w, reach, q, theta1, theta2, ratio);
            let b = self.lambda_copies(c - 0.5 * w, reach, q, theta1, theta2, ratio);
            let scale = 2.0 * self.k * (p.density - self.background);
            ex += scale * (a.0 - b.0);
            ez -= scale * (a.1 - b.1);
        }
        (ex, ez)
    }

    /// Patch `p`'s width w, its centre's offset c from x at time t (within
    /// half a period), and the copies ±R summed: beyond R periods a copy
    /// adds e^{−u(RL − w)}; 39.2 = ln 10¹⁷.
    fn placed(&self, p: &Patch, x: f64, t: f64) -> (f64, f64, i64) {
        let (l, u) = (self.period, std::f64::consts::PI / self.gap);
        let w = p.end - p.start;
        let mid = 0.5 * (p.start + p.end) + self.speed * t - x;
        let c = mid - (mid / l).round() * l;
        let reach = ((39.2 / u + w) / l).ceil() as i64 + 1;
        (w, c, reach)
    }

    /// [`LatentImage::field`] summing Λ copy by copy (two logarithms each):
    /// for periods too short for the progressions, and the reference they
    /// are tested against.
    pub fn field_copy_by_copy(&self, x: f64, z: f64, t: f64) -> (f64, f64) {
        let l = self.period;
        let mut ex = 0.0;
        let mut ez = 4.0 * std::f64::consts::PI * self.k * self.background * self.height / self.gap;
        for p in &self.patches {
            let (w, c, reach) = self.placed(p, x, t);
            let (mut re, mut im) = (0.0, 0.0);
            for n in -reach..=reach {
                let s = c + n as f64 * l;
                let (a, b) = (self.lambda(s + 0.5 * w, z), self.lambda(s - 0.5 * w, z));
                re += a.0 - b.0;
                im += a.1 - b.1;
            }
            let scale = 2.0 * self.k * (p.density - self.background);
            ex += scale * re;
            ez -= scale * im;
        }
        (ex, ez)
    }
}
