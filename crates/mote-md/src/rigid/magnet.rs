//! The magnetic roller of a magnetic brush and the moments it induces in
//! soft-magnetic carrier beads.
//!
//! **The roller.** A roller with N poles (n = N/2 pole pairs) turning at
//! angular velocity Ω about an axis along y at (x_a, z_a) has outside its
//! surface the two-dimensional multipole field (harmonic: curl- and
//! divergence-free; the pole pattern's fundamental)
//!
//! B_r = B₀ (R/r)^{n+1} cos n(θ − Ωt),   B_θ = B₀ (R/r)^{n+1} sin n(θ − Ωt),
//!
//! in polar coordinates about the axis, B₀ the field at radius R (the shell
//! surface). In complex form, w = (x − x_a) + i(z − z_a):
//! B_x − iB_z = B₀ R^{n+1} e^{inΩt} w^{−(n+1)}, so that the field turns in
//! the track plane at every point, with frequency nΩ/2π, and its magnitude
//! B₀(R/r)^{n+1} decays away from the shell; ∂_x(B_x − iB_z) = F′(w),
//! ∂_z(B_x − iB_z) = iF′(w), F′ = −(n + 1)F/w.
//!
//! **Induced moments.** A sphere of volume V and relative permeability μ_r
//! in a field B takes the moment m = 3Vβ B/μ₀, β = (μ_r − 1)/(μ_r + 2)
//! (Jackson §5.11), at most M_s V (saturation). With `iterations` > 0 the
//! moments see each other's dipole fields too (mutual induction by fixed
//! point, m_i = α(B(x_i) + Σ_j B_j(x_i))). Each moment feels
//! F = (m·∇)B of the roller and the dipole–dipole forces of the others
//! ([`crate::force::dipolar::dipole_pair`], as between permanent dipoles)
//! (minimum image along the periodic axes); the moments are taken as
//! isotropic, along the local field, so they exert no torque.
//!
//! The sums over the other moments run eight partners at a time on
//! [`Lanes`]: each lane the scalar law's operations in their order, the
//! eight terms then added one by one in order of the partners, so a body's
//! field and force have the bits of the loop over pairs.
//!
//! **Cut-off.** The sums run over all pairs (cost N² a pass), or with
//! `cutoff` r_c over the moments within r_c (minimum image), found each
//! step by a [`VerletList`] without skin, each body's partners in
//! increasing order: a cut-off beyond every pair gives the bits of all
//! pairs. Truncating the dipole sum leaves out the field of the moments
//! beyond r_c (in the nip's slab, the chains' far field, which falls off
//! as 1/r³ and partly cancels); docs/toning-nip.md measures what it
//! changes.

use std::f64::consts::PI;

use glam::DVec3;
use mote_geom::lanes::{Lanes, LANES, V3};
use mote_geom::DE;
use rayon::prelude::*;

use super::interaction::{BodyInteraction, BodyView};
use crate::boundary::Boundary;
use crate::force::dipolar::{dipole_field_lanes, dipole_pair_force_lanes};
use crate::neighbor::VerletList;

/// μ₀ in SI.
pub const MU0: f64 = 4.0e-7 * PI;

/// The roller's field as a function of place and time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticRoller {
    /// B₀: the field's magnitude at radius R.
    pub field: f64,
    /// N, the number of poles (even).
    pub poles: u32,
    /// R: the radius at which B₀ is given (the shell's outer surface).
    pub radius: f64,
    /// Ω: the roller's angular velocity (rad/s).
    pub angular_velocity: f64,
    /// The axis (x_a, z_a).
    pub axis: [f64; 2],
}

impl MagneticRoller {
    /// F(w) = B_x − iB_z and F′(w) as ((re, im), (re, im)).
    #[inline]
    fn complex_field(&self, x: f64, z: f64, t: f64) -> ((f64, f64), (f64, f64)) {
        let n = (self.poles / 2) as f64;
        let (wx, wz) = (x - self.axis[0], z - self.axis[1]);
        let r = wx.hypot(wz);
        let theta = wz.atan2(wx);
        // B₀ R^{n+1} e^{inΩt} r^{−(n+1)} e^{−i(n+1)θ}.
        let mag = self.field * (self.radius / r).powf(n + 1.0);
        let (s, c) = (n * self.angular_velocity * t - (n + 1.0) * theta).sin_cos();
        let f = (mag * c, mag * s);
        // F′ = −(n + 1) F/w, 1/w = (wx − i wz)/r².
        let (ix, iz) = (wx / (r * r), -wz / (r * r));
        let d = (
            -(n + 1.0) * (f.0 * ix - f.1 * iz),
            -(n + 1.0) * (f.0 * iz + f.1 * ix),
        );
        (f, d)
    }

    /// B at (x, ·, z), time t.
    pub fn at(&self, p: DVec3, t: f64) -> DVec3 {
        let ((bx, mbz), _) = self.complex_field(p.x, p.z, t);
        DVec3::new(bx, 0.0, -mbz)
    }

    /// B and (m·∇)B at `p`.
    pub fn with_gradient(&self, p: DVec3, m: DVec3, t: f64) -> (DVec3, DVec3) {
        let ((bx, mbz), (dr, di)) = self.complex_field(p.x, p.z, t);
        // ∂_x B_x = Re F′, ∂_x B_z = −Im F′, ∂_z B_x = −Im F′, ∂_z B_z = −Re F′.
        let grad = DVec3::new(m.x * dr - m.z * di, 0.0, -m.x * di - m.z * dr);
        (DVec3::new(bx, 0.0, -mbz), grad)
    }
}

/// The moments induced by the roller in bodies of given permeability.
#[derive(Clone, Debug)]
pub struct InducedDipoles {
    pub roller: MagneticRoller,
    /// α per template: m = α B (A·m²/T), 0 for non-magnetic bodies.
    pub polarisability: Vec<f64>,
    /// The largest moment per template (M_s V; infinite: no saturation).
    pub saturation: Vec<f64>,
    /// μ₀/4π for the forces between the moments (0: none).
    pub dipole_dipole: f64,
    /// Passes of mutual induction.
    pub iterations: u32,
    /// Periods along x and y (0: open).
    pub period: [f64; 2],
    /// Moments farther apart than this do not see each other (∞: all
    /// pairs); at most half a period.
    pub cutoff: f64,
}

impl InducedDipoles {
    /// α = 3Vβ/μ₀ of a body of volume V and relative permeability μ_r.
    pub fn polarisability(volume: f64, permeability: f64) -> f64 {
        3.0 * volume * (permeability - 1.0) / (permeability + 2.0) / MU0
    }

    /// d with its minimum image along the periodic axes, lane by lane:
    /// d_a − round(d_a/L_a) L_a.
    #[inline(always)]
    fn separation(&self, mut d: V3<Lanes>) -> V3<Lanes> {
        for (a, l) in [(&mut d.x, self.period[0]), (&mut d.y, self.period[1])] {
            if l > 0.0 {
                *a = *a - a.map(|x| (x / l).round()) * l;
            }
        }
        d
    }

    /// `start` + Σ_j term(d_ij, 1/d_ij², m_j) over the partners of body i
    /// in their order (all j ≠ i, or `partners`, increasing; d_ij = x_i −
    /// x_j, its minimum image): the terms of eight partners at a time,
    /// added one by one.
    #[inline(always)]
    fn row_sum(
        &self,
        at: &Places,
        i: usize,
        partners: Option<&[u32]>,
        start: DVec3,
        term: impl Fn(V3<Lanes>, Lanes, V3<Lanes>) -> V3<Lanes>,
    ) -> DVec3 {
        let xi = V3::splat(at.position(i));
        let mut sum = start;
        let mut add = |xj: V3<Lanes>, mj: V3<Lanes>, live: usize, skip: usize| {
            let d = self.separation(xi.sub(xj));
            let inv_r2 = Lanes::splat(1.0) / d.dot(d);
            let t = term(d, inv_r2, mj);
            for l in (0..live).filter(|&l| l != skip) {
                sum += t.lane(l);
            }
        };
        match partners {
            None => {
                for block in (0..at.len()).step_by(LANES) {
                    let live = (at.len() - block).min(LANES);
                    let (xj, mj) = (
                        at.lanes(&at.position, block, live),
                        at.lanes(&at.moment, block, live),
                    );
                    add(xj, mj, live, i.wrapping_sub(block));
                }
            }
            Some(list) => {
                for block in list.chunks(LANES) {
                    let (xj, mj) = (at.gather(&at.position, block), at.gather(&at.moment, block));
                    add(xj, mj, block.len(), LANES);
                }
            }
        }
        sum
    }

    /// Each magnetic body's partners within the cut-off (minimum image
    /// along the periodic axes), increasing: a full Verlet list without
    /// skin, built anew; `None` without a cut-off.
    fn partners(&self, x: &[DVec3]) -> Option<VerletList> {
        if !self.cutoff.is_finite() {
            return None;
        }
        let [lx, ly] = self.period;
        let boundary = Boundary {
            lo: DVec3::new(0.0, 0.0, f64::NEG_INFINITY),
            hi: DVec3::new(lx, ly, f64::INFINITY),
            periodic: [lx > 0.0, ly > 0.0, false],
        };
        let mut list = VerletList::new(self.cutoff, 0.0);
        list.build(x, &boundary);
        Some(list)
    }

    /// The magnetic bodies, their positions and moments at time t.
    pub fn moments(&self, view: &BodyView<'_>, t: f64) -> (Vec<usize>, Vec<DVec3>, Vec<DVec3>) {
        let (index, x, m, _) = self.moments_and_partners(view, t);
        (index, x, m)
    }

    /// [`InducedDipoles::moments`] and the partners the sums ran over.
    #[allow(clippy::type_complexity)]
    fn moments_and_partners(
        &self,
        view: &BodyView<'_>,
        t: f64,
    ) -> (Vec<usize>, Vec<DVec3>, Vec<DVec3>, Option<VerletList>) {
        let b = view.bodies;
        let index: Vec<usize> = (0..b.len())
            .filter(|&i| self.polarisability[b.kind[i] as usize] > 0.0)
            .collect();
        let x: Vec<DVec3> = index.iter().map(|&i| b.position[i]).collect();
        let alpha: Vec<f64> = index
            .iter()
            .map(|&i| self.polarisability[b.kind[i] as usize])
            .collect();
        let cap: Vec<f64> = index
            .iter()
            .map(|&i| self.saturation[b.kind[i] as usize])
            .collect();
        let external: Vec<DVec3> = x.iter().map(|p| self.roller.at(*p, t)).collect();
        let induce = |local: DVec3, k: usize| {
            let m = alpha[k] * local;
            let len = m.length();
            if len > cap[k] {
                m * (cap[k] / len)
            } else {
                m
            }
        };
        let mut m: Vec<DVec3> = external
            .iter()
            .enumerate()
            .map(|(k, b)| induce(*b, k))
            .collect();
        let k = self.dipole_dipole;
        let partners = (k > 0.0).then(|| self.partners(&x)).flatten();
        if k > 0.0 {
            let mut at = Places::of(&x);
            for _ in 0..self.iterations {
                at.set_moments(&m);
                // The field at x_i of the moments m_j:
                // k [3 d(m_j·d)/d⁵ − m_j/d³], d = x_i − x_j.
                m = (0..x.len())
                    .into_par_iter()
                    .map(|i| {
                        let near = partners.as_ref().map(|p| p.of(i));
                        let local = self.row_sum(&at, i, near, external[i], |d, inv_r2, mj| {
                            dipole_field_lanes(k, mj, d, inv_r2)
                        });
                        induce(local, i)
                    })
                    .collect();
            }
        }
        (index, x, m, partners)
    }
}

/// The magnetic bodies' places and moments by component, for the lanes.
struct Places {
    position: [Vec<f64>; 3],
    moment: [Vec<f64>; 3],
}

impl Places {
    fn of(x: &[DVec3]) -> Self {
        Self {
            position: [0, 1, 2].map(|a| x.iter().map(|p| p[a]).collect()),
            moment: Default::default(),
        }
    }

    fn set_moments(&mut self, m: &[DVec3]) {
        self.moment = [0, 1, 2].map(|a| m.iter().map(|v| v[a]).collect());
    }

    fn len(&self) -> usize {
        self.position[0].len()
    }

    fn position(&self, i: usize) -> DVec3 {
        DVec3::new(
            self.position[0][i],
            self.position[1][i],
            self.position[2][i],
        )
    }

    /// Entries `start..start + live` of `v`, one per lane (zeros after).
    #[inline(always)]
    fn lanes(&self, v: &[Vec<f64>; 3], start: usize, live: usize) -> V3<Lanes> {
        V3 {
            x: Lanes::load(&v[0], start, live),
            y: Lanes::load(&v[1], start, live),
            z: Lanes::load(&v[2], start, live),
        }
    }

    /// Entries `index` (at most eight) of `v`, one per lane (zeros after).
    #[inline(always)]
    fn gather(&self, v: &[Vec<f64>; 3], index: &[u32]) -> V3<Lanes> {
        let lane = |c: &Vec<f64>| {
            Lanes(std::array::from_fn(|l| {
                index.get(l).map_or(0.0, |&j| c[j as usize])
            }))
        };
        V3 {
            x: lane(&v[0]),
            y: lane(&v[1]),
            z: lane(&v[2]),
        }
    }
}

impl BodyInteraction for InducedDipoles {
    fn name(&self) -> &str {
        "magnetic roller"
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let t = view.step.time;
        let (index, x, m, partners) = self.moments_and_partners(view, t);
        let k = self.dipole_dipole;
        let mut at = Places::of(&x);
        at.set_moments(&m);
        let force: Vec<DVec3> = (0..x.len())
            .into_par_iter()
            .map(|i| {
                let (_, f) = self.roller.with_gradient(x[i], m[i], t);
                if k == 0.0 {
                    return f;
                }
                let mi = V3::splat(m[i]);
                let near = partners.as_ref().map(|p| p.of(i));
                self.row_sum(&at, i, near, f, |d, inv_r2, mj| {
                    dipole_pair_force_lanes(k, d, inv_r2, mi, mj)
                })
            })
            .collect();
        for (&i, f) in index.iter().zip(&force) {
            wrench[i].v += *f;
        }
    }
}
