//! Point charges between two parallel conducting planes, periodic along
//! the planes.
//!
//! The planes are z = 0 (potential V₀) and z = h (potential V_h); the box
//! is periodic along x and y with sides L_x and L_y. The potential splits
//! into the uniform bias field and the field of the charges with the planes
//! grounded:
//!
//! φ(r) = V₀ + (V_h − V₀) z/h + φ_q(r),   E_bias = −(V_h − V₀)/h ẑ.
//!
//! **Images.** A charge q at (x, y, z′) between grounded planes induces the
//! mirror charges +q at (x, y, 2nh + z′), n ≠ 0, and −q at (x, y, 2nh − z′),
//! all n (Jackson, *Classical Electrodynamics*, 3rd ed., §2.1 and problem
//! 3.20). Every charge with its first mirror −q at −z′ repeated with period
//! 2h along z is the image series, so φ_q is the potential of a
//! three-dimensional periodic system of 2N charges in the cell
//! L_x × L_y × 2h. The cell is neutral; its dipole moment along z is
//! summed column by column in the image series, which is the tin-foil
//! Ewald sum (no surface term: Hautman, Halley & Rhee, J. Chem. Phys. 91,
//! 467 (1989)); tin-foil makes φ_q periodic and odd in z, so φ_q = 0 on
//! z = 0 and z = h exactly. The method is [`Ewald`] on the doubled cell, to
//! a requested RMS force error: O(N^{3/2}) per evaluation, every image
//! and every lateral copy included, rather than an image series cut off
//! after n terms whose tail falls only as 1/n² for the force — or P3M
//! ([`P3mCoulomb`]) on the same doubled cell, O(N log N), for the toning
//! nip at scale ([`ConductingPlanes::with_p3m`]).
//!
//! **Energy and forces.** The electrostatic energy of the charges at fixed
//! potentials is U = ½ E_doubled + Σ q_i φ_bias(z_i), half the doubled
//! system's energy (the images mirror the charges); F_i = −∂U/∂r_i is the
//! doubled system's force on charge i (its image's force is the mirror
//! of it) plus q_i E_bias. Each charge feels its own images: between the
//! planes alone (a = z/h) F_z = −k q²/(4h²) [ψ₁(a) − ψ₁(1 − a)] with the
//! trigamma function ψ₁.
//!
//! **The planes.** The surface charge of plane 0 has the Fourier
//! components (k ≠ 0; A = L_x L_y)
//! σ₀(k) = −(1/A) Σ q_i sinh(k(h − z_i))/sinh(kh) e^{−ik·ρ_i},
//! σ₀(0) = −(1/A) Σ q_i (1 − z_i/h) + ε₀ E_bias,z, and plane h
//! the same with z_i → h − z_i and the bias with the other sign. Each plane
//! is pulled towards the gap by the Maxwell stress σ²/2ε₀:
//! F₀ = +A Σ_k |σ₀(k)|²/(2ε₀) ẑ, F_h = −A Σ_k |σ_h(k)|²/(2ε₀) ẑ; a
//! conductor carries no shear stress, and the lateral image forces on the
//! charges cancel in pairs. F₀ + F_h = −Σ F_i: the check that every force
//! has its reaction.

use glam::DVec3;

use super::ewald::Ewald;
use super::p3m::{P3mCoulomb, Request};
use super::{Interaction, State};
use crate::boundary::Boundary;

/// How the doubled cell's charges are summed.
#[derive(Debug, Clone)]
enum DoubledCell {
    Ewald(Ewald),
    /// P3M over the doubled cell z ∈ [−h, h) (the charges at z, their
    /// mirrors at −z).
    P3m {
        solver: Box<P3mCoulomb>,
        cell: Boundary,
    },
}

/// Two conducting planes z = 0 and z = h held at potentials, with the
/// charges between them periodic along x and y.
#[derive(Debug, Clone)]
pub struct ConductingPlanes {
    /// Coulomb's constant k = 1/(4πε₀) of the unit system.
    pub k: f64,
    /// The gap h.
    pub gap: f64,
    /// The periods (L_x, L_y) along the planes.
    pub lateral: [f64; 2],
    /// Potentials (V₀, V_h) of the planes z = 0 and z = h.
    pub potential: [f64; 2],
    sum: DoubledCell,
}

/// What one evaluation gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlabEnergy {
    /// ½ of the doubled system's energy: the charges with their images.
    pub images: f64,
    /// Σ q φ_bias(z).
    pub bias: f64,
}

impl SlabEnergy {
    pub fn total(&self) -> f64 {
        self.images + self.bias
    }
}

impl ConductingPlanes {
    /// Planes at potentials `potential` with gap `gap` and lateral periods
    /// `lateral`; the Ewald parameters are tuned for `charge` to an RMS
    /// force error `accuracy` (force units, with k) at real-space cut-off
    /// `r_cut` (at most half the smallest of L_x, L_y, 2h).
    pub fn new(
        k: f64,
        gap: f64,
        lateral: [f64; 2],
        potential: [f64; 2],
        charge: &[f64],
        r_cut: f64,
        accuracy: f64,
    ) -> Self {
        let cell = DVec3::new(lateral[0], lateral[1], 2.0 * gap);
        let doubled: Vec<f64> = charge.iter().chain(charge).copied().collect();
        let ewald = Ewald::for_charges_in(cell, r_cut, accuracy / k.abs(), &doubled);
        Self {
            k,
            gap,
            lateral,
            potential,
            sum: DoubledCell::Ewald(ewald),
        }
    }

    /// The planes of [`ConductingPlanes::new`] with the doubled cell summed
    /// by P3M, tuned for its 2N charges (q_i and their mirrors −q_i) to
    /// `request` (its accuracy in force units, with k); or why it cannot be.
    pub fn with_p3m(
        k: f64,
        gap: f64,
        lateral: [f64; 2],
        potential: [f64; 2],
        charge: &[f64],
        request: &Request,
    ) -> Result<Self, String> {
        let cell = Boundary::periodic(
            DVec3::new(0.0, 0.0, -gap),
            DVec3::new(lateral[0], lateral[1], gap),
        );
        let (_, doubled_charge) = doubled(&[], charge);
        let solver = P3mCoulomb::tuned(k, request, &doubled_charge, &cell)?;
        Ok(Self {
            k,
            gap,
            lateral,
            potential,
            sum: DoubledCell::P3m {
                solver: Box::new(solver),
                cell,
            },
        })
    }

    /// The Ewald parameters of the doubled cell, where Ewald sums it.
    pub fn ewald(&self) -> Option<&Ewald> {
        match &self.sum {
            DoubledCell::Ewald(e) => Some(e),
            DoubledCell::P3m { .. } => None,
        }
    }

    /// How the doubled cell is summed, with its parameters: for summaries.
    pub fn describe(&self) -> String {
        match &self.sum {
            DoubledCell::Ewald(e) => format!(
                "Coulomb between conducting planes by Ewald on the doubled cell: α = {:.6}, real-space cut-off {:.6}, k-vectors to n_max = {}; estimated RMS force error {:.3e}.",
                e.alpha,
                e.r_cut,
                e.n_max,
                self.k * e.real_error.hypot(e.kspace_error)
            ),
            DoubledCell::P3m { solver, .. } => format!(
                "Between conducting planes, on the doubled cell: {}",
                solver.describe()
            ),
        }
    }

    /// The P3M list's build, for checkpoints (empty with Ewald).
    pub fn carried_state(&self) -> Vec<f64> {
        match &self.sum {
            DoubledCell::Ewald(_) => Vec::new(),
            DoubledCell::P3m { solver, .. } => solver.carried_state(),
        }
    }

    /// Forgets the P3M list's build (the charges changed).
    pub fn forget_list(&mut self) {
        if let DoubledCell::P3m { solver, .. } = &mut self.sum {
            solver.forget_list();
        }
    }

    /// Restores [`ConductingPlanes::carried_state`].
    pub fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        match &mut self.sum {
            DoubledCell::Ewald(_) if state.is_empty() => Ok(()),
            DoubledCell::Ewald(_) => Err("planes summed by Ewald carry no list".into()),
            DoubledCell::P3m { solver, .. } => solver.restore_carried_state(state),
        }
    }

    /// The uniform field of the bias, −(V_h − V₀)/h ẑ.
    pub fn bias_field(&self) -> DVec3 {
        DVec3::new(
            0.0,
            0.0,
            -(self.potential[1] - self.potential[0]) / self.gap,
        )
    }

    /// The bias potential V₀ + (V_h − V₀) z/h.
    pub fn bias_potential(&self, z: f64) -> f64 {
        self.potential[0] + (self.potential[1] - self.potential[0]) * z / self.gap
    }

    /// The energy of the charges at `position` (0 < z < h); their forces
    /// are added to `force` if given.
    pub fn evaluate(
        &mut self,
        position: &[DVec3],
        charge: &[f64],
        force: Option<&mut [DVec3]>,
    ) -> SlabEnergy {
        let n = position.len();
        let (doubled_position, doubled_charge) = doubled(position, charge);
        let bias = position
            .iter()
            .zip(charge)
            .map(|(r, q)| q * self.bias_potential(r.z))
            .sum();
        let e = self.bias_field();
        let images = match &mut self.sum {
            DoubledCell::Ewald(ewald) => match force {
                Some(force) => {
                    let mut f = vec![DVec3::ZERO; 2 * n];
                    let u = ewald.charges(&doubled_position, &doubled_charge, Some(&mut f));
                    for ((fi, fd), q) in force.iter_mut().zip(&f[..n]).zip(charge) {
                        *fi += *fd * self.k + e * *q;
                    }
                    u
                }
                None => ewald.charges(&doubled_position, &doubled_charge, None),
            },
            DoubledCell::P3m { solver, cell } => {
                let still = vec![DVec3::ZERO; 2 * n];
                let mass = vec![1.0; 2 * n];
                let state = State::new(&doubled_position, &still, &mass, 0.0)
                    .with_charges(&doubled_charge)
                    .in_box(cell);
                // The solver's forces and energy carry k already.
                match force {
                    Some(force) => {
                        let mut f = vec![DVec3::ZERO; 2 * n];
                        solver.add_forces(&state, &mut f);
                        for ((fi, fd), q) in force.iter_mut().zip(&f[..n]).zip(charge) {
                            *fi += *fd + e * *q;
                        }
                        solver.potential_energy(&state) / self.k
                    }
                    None => solver.potential_energy(&state) / self.k,
                }
            }
        };
        SlabEnergy {
            images: 0.5 * self.k * images,
            bias,
        }
    }

    /// Adds the forces on the charges at `position` (0 < z < h) to `force`,
    /// without the energy where that costs more (P3M).
    pub fn add_forces(&mut self, position: &[DVec3], charge: &[f64], force: &mut [DVec3]) {
        let DoubledCell::P3m { solver, cell } = &mut self.sum else {
            self.evaluate(position, charge, Some(force));
            return;
        };
        let n = position.len();
        let (doubled_position, doubled_charge) = doubled(position, charge);
        let (still, mass) = (vec![DVec3::ZERO; 2 * n], vec![1.0; 2 * n]);
        let state = State::new(&doubled_position, &still, &mass, 0.0)
            .with_charges(&doubled_charge)
            .in_box(cell);
        let mut f = vec![DVec3::ZERO; 2 * n];
        solver.add_forces(&state, &mut f);
        let e = self.bias_field();
        for ((fi, fd), q) in force.iter_mut().zip(&f[..n]).zip(charge) {
            *fi += *fd + e * *q;
        }
    }

    /// The charges induced on the planes (Q₀, Q_h) by the particles alone,
    /// Q₀ = −Σ q (1 − z/h), Q_h = −Σ q z/h (Green's reciprocity).
    pub fn induced_charges(&self, position: &[DVec3], charge: &[f64]) -> [f64; 2] {
        let mut out = [0.0; 2];
        for (r, q) in position.iter().zip(charge) {
            let a = r.z / self.gap;
            out[0] -= q * (1.0 - a);
            out[1] -= q * a;
        }
        out
    }

    /// The z-components of the forces on the planes (F₀, F_h) by the
    /// Maxwell stress, with lateral modes |k| ≤ `k_max` (the sum converges
    /// as e^{−2 k z_min}, z_min the least distance of a charge from a plane).
    pub fn plane_forces(&self, position: &[DVec3], charge: &[f64], k_max: f64) -> [f64; 2] {
        let (lx, ly) = (self.lateral[0], self.lateral[1]);
        let area = lx * ly;
        let h = self.gap;
        let eps0 = 1.0 / (4.0 * std::f64::consts::PI * self.k);
        let tau = 2.0 * std::f64::consts::PI;
        let (mx, my) = (
            (k_max * lx / tau).floor() as i64,
            (k_max * ly / tau).floor() as i64,
        );
        let e_bias = self.bias_field().z;
        let mut out = [0.0; 2];
        // Uniform mode: σ₀ = ε₀E_z(0⁺), σ_h = −ε₀E_z(h⁻).
        let [q0, qh] = self.induced_charges(position, charge);
        let s0 = q0 / area + eps0 * e_bias;
        let sh = qh / area - eps0 * e_bias;
        out[0] += area * s0 * s0 / (2.0 * eps0);
        out[1] -= area * sh * sh / (2.0 * eps0);
        for nx in -mx..=mx {
            for ny in -my..=my {
                let kv = [tau * nx as f64 / lx, tau * ny as f64 / ly];
                let kk = kv[0].hypot(kv[1]);
                if (nx, ny) == (0, 0) || kk > k_max {
                    continue;
                }
                let (mut re0, mut im0, mut reh, mut imh) = (0.0, 0.0, 0.0, 0.0);
                for (r, q) in position.iter().zip(charge) {
                    let (s, c) = (kv[0] * r.x + kv[1] * r.y).sin_cos();
                    let w0 = q * sinh_ratio(kk, h - r.z, h);
                    let wh = q * sinh_ratio(kk, r.z, h);
                    re0 += w0 * c;
                    im0 -= w0 * s;
                    reh += wh * c;
                    imh -= wh * s;
                }
                out[0] += (re0 * re0 + im0 * im0) / (area * 2.0 * eps0);
                out[1] -= (reh * reh + imh * imh) / (area * 2.0 * eps0);
            }
        }
        out
    }
}

/// The doubled cell's charges: each charge q at (x, y, z), then its
/// mirror −q at (x, y, −z).
fn doubled(position: &[DVec3], charge: &[f64]) -> (Vec<DVec3>, Vec<f64>) {
    let mirrored = position.iter().map(|r| DVec3::new(r.x, r.y, -r.z));
    (
        position.iter().copied().chain(mirrored).collect(),
        charge
            .iter()
            .copied()
            .chain(charge.iter().map(|q| -q))
            .collect(),
    )
}

/// sinh(k u)/sinh(k h) for 0 ≤ u ≤ h, without overflow:
/// e^{−k(h−u)} (1 − e^{−2ku})/(1 − e^{−2kh}).
fn sinh_ratio(k: f64, u: f64, h: f64) -> f64 {
    (-k * (h - u)).exp() * (-(-2.0 * k * u).exp_m1()) / (-(-2.0 * k * h).exp_m1())
}
