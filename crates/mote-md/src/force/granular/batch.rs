//! The contact law over batches of touching pairs, several contacts at a
//! time in SIMD lanes.
//!
//! A step first walks its list rows and keeps the pairs that touch (a
//! third to a half of the listed pairs in a settled bed), with their
//! separation d = x_a − x_b; then [`ContactBatch::evaluate`] takes those
//! contacts `L::N` at a time (four or eight lanes, [`Lane`]): it gathers
//! both spheres' radii, masses, velocities and spins and the pair's
//! history, forms the contact's geometry and applies the law of
//! [`super::law`] — every operation the scalar [`ContactLaw::force`]'s, in
//! its order, its branches as blends — so each contact gets the scalar
//! law's bits whatever the width (tested against it, lane by lane). The
//! forces are summed afterwards, in the list's order, by the caller.
//!
//! Why lanes pay here: the law holds three square roots and three
//! divisions on one dependency chain per contact; one at a time, the core
//! waits on each, where four or eight contacts share every wait.

use glam::DVec3;
use mote_geom::lanes::{Four, Lane, V3};

use super::law::{ContactForce, ContactLaw, History};

/// The particles a batch reads, by index.
#[derive(Clone, Copy)]
pub struct Spheres<'a> {
    pub velocity: &'a [DVec3],
    pub spin: &'a [DVec3],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
}

/// The touching pairs of a block of list rows, in list order, and what
/// the law gave each.
#[derive(Debug, Clone, Default)]
pub struct ContactBatch {
    /// How many pairs the batch holds (the arrays below are longer: room
    /// for every pair of the block).
    len: usize,
    /// The pair's two spheres (a, b).
    pub ends: Vec<[u32; 2]>,
    /// The pair's entry in the list (its history's place).
    pub entry: Vec<u32>,
    /// d = x_a − x_b (nearest image).
    pub separation: Vec<DVec3>,
    /// |d|².
    pub distance2: Vec<f64>,
    /// The law's force and torques for each contact, after
    /// [`ContactBatch::evaluate`].
    pub force: Vec<ContactForce>,
}

impl ContactBatch {
    /// Empties the batch, with room for `pairs` pairs.
    pub fn clear(&mut self, pairs: usize) {
        self.len = 0;
        if self.ends.len() < pairs {
            self.ends.resize(pairs, [0; 2]);
            self.entry.resize(pairs, 0);
            self.separation.resize(pairs, DVec3::ZERO);
            self.distance2.resize(pairs, 0.0);
            self.force.resize(pairs, ContactForce::default());
        }
    }

    /// Keeps the pair (a, b) at list entry `entry` where `touching`: its
    /// numbers are written in any case and counted only then, so the
    /// filter has no branch to mispredict (whether a listed pair touches
    /// is a coin toss in a settled bed).
    #[inline(always)]
    pub fn push_if(&mut self, touching: bool, a: usize, b: usize, entry: usize, d: DVec3, r2: f64) {
        let at = self.len;
        self.ends[at] = [a as u32, b as u32];
        self.entry[at] = entry as u32;
        self.separation[at] = d;
        self.distance2[at] = r2;
        self.len += usize::from(touching);
    }

    /// The number of pairs kept.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The law for every contact of the batch: fills `force` and advances
    /// each pair's history, `history[entry − base]`. Four lanes, one AVX2
    /// register each: eight hold more values than AVX2's sixteen
    /// registers (measured 13 % slower on the settling benchmark), and
    /// eight in AVX-512 registers 43 % slower still (its square roots and
    /// divisions do not go faster by width).
    pub fn evaluate(
        &mut self,
        law: &ContactLaw,
        at: Spheres,
        dt: f64,
        history: &mut [History],
        base: usize,
    ) {
        self.evaluate_on::<Four>(law, at, dt, history, base);
    }

    #[inline(always)]
    fn evaluate_on<Width: Lane>(
        &mut self,
        law: &ContactLaw,
        at: Spheres,
        dt: f64,
        history: &mut [History],
        base: usize,
    ) {
        let n = self.len();
        let mut first = 0;
        while first < n {
            let live = (n - first).min(Width::N);
            // Lanes past the last contact repeat it: real numbers, never
            // written back.
            let at_lane = |l: usize| first + l.min(live - 1);
            let ends = |l: usize| {
                let [a, b] = self.ends[at_lane(l)];
                (a as usize, b as usize)
            };
            let slot = |l: usize| self.entry[at_lane(l)] as usize - base;
            let of = |v: &[f64], end: usize| {
                Width::from_fn(|l| {
                    let (a, b) = ends(l);
                    v[if end == 0 { a } else { b }]
                })
            };
            let vector_of = |v: &[DVec3], end: usize| {
                V3::<Width>::from_fn(|l| {
                    let (a, b) = ends(l);
                    v[if end == 0 { a } else { b }]
                })
            };
            let (ra, rb) = (of(at.radius, 0), of(at.radius, 1));
            let (ma, mb) = (of(at.mass, 0), of(at.mass, 1));
            let (va, vb) = (vector_of(at.velocity, 0), vector_of(at.velocity, 1));
            let (wa, wb) = (vector_of(at.spin, 0), vector_of(at.spin, 1));
            let d = V3::<Width>::from_fn(|l| self.separation[at_lane(l)]);
            let r2 = Width::from_fn(|l| self.distance2[at_lane(l)]);
            let mut h = HistoryLanes::from_fn(|l| history[slot(l)]);
            let c = contact(
                law,
                d,
                r2,
                [ra, rb],
                [ma, mb],
                [va, vb],
                [wa, wb],
                dt,
                &mut h,
            );
            for l in 0..live {
                history[slot(l)] = h.lane(l);
                self.force[first + l] = c.lane(l);
            }
            first += live;
        }
    }
}

/// Contacts whose geometry is formed where they are found (a sphere
/// against a wall): the law's inputs, one entry each, in the order found.
#[derive(Debug, Clone, Default)]
pub struct FormedContacts {
    /// Each contact's history, `history[slot]` of the caller's store.
    pub slot: Vec<u32>,
    pub delta: Vec<f64>,
    pub normal: Vec<DVec3>,
    pub v_rel: Vec<DVec3>,
    pub w_rel: Vec<DVec3>,
    pub arm: Vec<[f64; 2]>,
    pub r_eff: Vec<f64>,
    pub m_eff: Vec<f64>,
    /// What the law gave each, after [`FormedContacts::evaluate`].
    pub force: Vec<ContactForce>,
}

impl FormedContacts {
    pub fn clear(&mut self) {
        self.slot.clear();
        self.delta.clear();
        self.normal.clear();
        self.v_rel.clear();
        self.w_rel.clear();
        self.arm.clear();
        self.r_eff.clear();
        self.m_eff.clear();
        self.force.clear();
    }

    pub fn len(&self) -> usize {
        self.slot.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slot.is_empty()
    }

    /// Adds a contact: the arguments of [`ContactLaw::force`], its
    /// history at `slot`.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        slot: usize,
        delta: f64,
        normal: DVec3,
        v_rel: DVec3,
        w_rel: DVec3,
        arm: [f64; 2],
        r_eff: f64,
        m_eff: f64,
    ) {
        self.slot.push(slot as u32);
        self.delta.push(delta);
        self.normal.push(normal);
        self.v_rel.push(v_rel);
        self.w_rel.push(w_rel);
        self.arm.push(arm);
        self.r_eff.push(r_eff);
        self.m_eff.push(m_eff);
    }

    /// The law for every contact, four at a time ([`force_lanes`], the
    /// scalar law's bits): fills `force`, advances `history[slot]`.
    pub fn evaluate(&mut self, law: &ContactLaw, dt: f64, history: &mut [History]) {
        let n = self.len();
        self.force.resize(n, ContactForce::default());
        let mut first = 0;
        while first < n {
            let live = (n - first).min(Four::N);
            let at = |l: usize| first + l.min(live - 1);
            let scalar = |v: &[f64]| Four::from_fn(|l| v[at(l)]);
            let vector = |v: &[DVec3]| V3::<Four>::from_fn(|l| v[at(l)]);
            let slot = |l: usize| self.slot[at(l)] as usize;
            let mut h = HistoryLanes::from_fn(|l| history[slot(l)]);
            let c = force_lanes(
                law,
                scalar(&self.delta),
                vector(&self.normal),
                vector(&self.v_rel),
                vector(&self.w_rel),
                [
                    Four::from_fn(|l| self.arm[at(l)][0]),
                    Four::from_fn(|l| self.arm[at(l)][1]),
                ],
                scalar(&self.r_eff),
                scalar(&self.m_eff),
                dt,
                &mut h,
            );
            for l in 0..live {
                history[slot(l)] = h.lane(l);
                self.force[first + l] = c.lane(l);
            }
            first += live;
        }
    }
}

/// The histories of `L::N` contacts, one per lane.
pub struct HistoryLanes<L> {
    pub shear: V3<L>,
    pub roll: V3<L>,
}

impl<L: Lane> HistoryLanes<L> {
    /// Lane l from `f(l)`.
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize) -> History) -> Self {
        HistoryLanes {
            shear: V3::from_fn(|l| f(l).shear),
            roll: V3::from_fn(|l| f(l).roll),
        }
    }

    /// Lane l.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> History {
        History {
            shear: self.shear.lane(l),
            roll: self.roll.lane(l),
        }
    }
}

/// The force and torques of `L::N` contacts, one per lane.
pub struct ForceLanes<L> {
    pub force: V3<L>,
    pub torque_i: V3<L>,
    pub torque_j: V3<L>,
}

impl<L: Lane> ForceLanes<L> {
    /// Lane l.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> ContactForce {
        ContactForce {
            force: self.force.lane(l),
            torque_i: self.torque_i.lane(l),
            torque_j: self.torque_j.lane(l),
        }
    }
}

/// One lane's contact geometry, as the sphere loop forms it before
/// calling the law: the distance r = |d|, the normal n = d/r, the overlap
/// δ = R_a + R_b − r, the lever arms R − δ/2, the relative velocity of the
/// contact point v_a − v_b − (ω_a a_a + ω_b a_b) × n, R* = R_aR_b/(R_a+R_b)
/// and m* = m_am_b/(m_a+m_b); then the law.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn contact<L: Lane>(
    law: &ContactLaw,
    d: V3<L>,
    r2: L,
    [ra, rb]: [L; 2],
    [ma, mb]: [L; 2],
    [va, vb]: [V3<L>; 2],
    [wa, wb]: [V3<L>; 2],
    dt: f64,
    history: &mut HistoryLanes<L>,
) -> ForceLanes<L> {
    let reach = ra + rb;
    let r = r2.sqrt();
    let n = d.over(r);
    let delta = reach - r;
    let (arm_a, arm_b) = (ra - delta * 0.5, rb - delta * 0.5);
    let v_rel = va
        .sub(vb)
        .sub(wa.scale(arm_a).add(wb.scale(arm_b)).cross(n));
    force_lanes(
        law,
        delta,
        n,
        v_rel,
        wa.sub(wb),
        [arm_a, arm_b],
        ra * rb / reach,
        ma * mb / (ma + mb),
        dt,
        history,
    )
}

/// [`ContactLaw::force`] in lanes: the same operations in the same order,
/// its branches as blends of both sides.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn force_lanes<L: Lane>(
    law: &ContactLaw,
    delta: L,
    n: V3<L>,
    v_rel: V3<L>,
    w_rel: V3<L>,
    [arm_i, arm_j]: [L; 2],
    r_eff: L,
    m_eff: L,
    dt: f64,
    history: &mut HistoryLanes<L>,
) -> ForceLanes<L> {
    let zero = L::splat(0.0);
    let a = (r_eff * delta).sqrt();
    let k_n = L::splat(4.0 / 3.0 * law.e_star) * a;
    let eta = (m_eff * k_n).sqrt() * law.alpha;
    let v_n = v_rel.dot(n);
    let mut f_n = k_n * delta - eta * v_n;
    if law.limit_damping {
        // f_n < 0 → 0.
        f_n = zero.select_above(f_n, zero, f_n);
    }
    let f_c = f_n.max(0.0);
    if law.adhesion > 0.0 {
        f_n = f_n - r_eff * (2.0 * std::f64::consts::PI * law.adhesion);
    }

    let v_t = v_rel.sub(n.scale(v_n));
    let xi = history.shear;
    let len0 = xi.dot(xi);
    let projected = xi.sub(n.scale(xi.dot(n)));
    let len1 = projected.dot(projected);
    let rescaled = projected.scale((len0 / len1).sqrt());
    let projected = V3::select_above(len1, zero, rescaled, projected);
    let xi = V3::select_above(len0, zero, projected, xi);
    let xi = xi.add(v_t.scale(L::splat(dt)));
    let k_t = L::splat(8.0 * law.g_star) * a;
    let f_el = xi.scale(k_t.map(|x| -x));
    let limit = f_c * law.friction;
    let limit2 = limit * limit;
    let f_el2 = f_el.dot(f_el);
    // Sliding: the spring shortened to the friction limit, no damping.
    let scale = limit / f_el2.sqrt();
    let sliding = f_el.scale(scale);
    // Sticking: spring and damping, capped at the limit.
    let f = f_el.sub(v_t.scale(eta));
    let f2 = f.dot(f);
    let capped = f.scale(limit / f2.sqrt());
    let sticking = V3::select_above(f2, limit2, capped, f);
    let f_t = V3::select_above(f_el2, limit2, sliding, sticking);
    history.shear = V3::select_above(f_el2, limit2, xi.scale(scale), xi);

    let turn = n.cross(f_t);
    let mut out = ForceLanes {
        force: n.scale(f_n).add(f_t),
        torque_i: turn.scale(arm_i).neg(),
        torque_j: turn.scale(arm_j).neg(),
    };

    if law.rolling_friction > 0.0 {
        let mu_r = law.rolling_friction;
        let v_r = w_rel.cross(n).scale(r_eff);
        let psi = history.roll;
        let psi = psi.sub(n.scale(psi.dot(n)));
        let psi = psi.add(v_r.scale(L::splat(dt)));
        let k_r = L::splat(2.25 * mu_r * mu_r) * k_n;
        let f_r = psi.scale(k_r).neg();
        let limit = f_c * mu_r;
        let f_r2 = f_r.dot(f_r);
        let slipped = f_r.scale(limit / f_r2.sqrt());
        let over = |yes: V3<L>, no: V3<L>| V3::select_above(f_r2, limit * limit, yes, no);
        history.roll = over(slipped.over(k_r).neg(), psi);
        let f_r = over(slipped, f_r);
        let couple = n.cross(f_r).scale(r_eff);
        out.torque_i = out.torque_i.add(couple);
        out.torque_j = out.torque_j.sub(couple);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::granular::law::{Damping, Material};
    use mote_geom::lanes::Lanes;
    use rand::{Rng, SeedableRng};

    /// Contacts of every kind the law distinguishes: sticking and sliding,
    /// new (zero history) and old, loading and unloading, with and
    /// without rolling friction, adhesion and the damping limit.
    fn laws() -> Vec<ContactLaw> {
        let glass = Material {
            young: 6e10,
            poisson: 0.23,
        };
        let rubber = Material {
            young: 1e6,
            poisson: 0.45,
        };
        let mut out = Vec::new();
        for (limit, damping) in [(false, Damping::Exact), (true, Damping::TsujiFit)] {
            let mut law = ContactLaw::new(glass, rubber, 0.6, 0.4, damping, limit);
            out.push(law);
            law.rolling_friction = 0.05;
            out.push(law);
            law.adhesion = 0.02;
            out.push(law);
        }
        out
    }

    fn random_vector(rng: &mut impl Rng, scale: f64) -> DVec3 {
        DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ) * scale
    }

    /// Every lane of the batch is the scalar law's contact, bit for bit,
    /// at four and at eight lanes, with the history it leaves.
    fn lanes_match_the_scalar_law<L: Lane>() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        // Contacts that slid (their spring shortened to the friction
        // limit) and that stuck: both sides of the law's branch are tried.
        let (mut slid, mut stuck) = (0, 0);
        for law in laws() {
            let no_limit = ContactLaw {
                friction: f64::MAX,
                ..law
            };
            for _ in 0..400 {
                let ra = L::from_fn(|_| rng.gen_range(0.5e-3..2e-3));
                let rb = L::from_fn(|_| rng.gen_range(0.5e-3..2e-3));
                let ma = L::from_fn(|_| rng.gen_range(1e-6..1e-4));
                let mb = L::from_fn(|_| rng.gen_range(1e-6..1e-4));
                // Overlaps from 1e-9 to a tenth of the radii.
                let d: Vec<DVec3> = (0..L::N)
                    .map(|l| {
                        let reach = ra.lane(l) + rb.lane(l);
                        let overlap = reach * 10f64.powf(rng.gen_range(-6.0..-1.0));
                        random_vector(&mut rng, 1.0).normalize() * (reach - overlap)
                    })
                    .collect();
                let v: Vec<[DVec3; 4]> = (0..L::N)
                    .map(|_| {
                        let speed = 10f64.powf(rng.gen_range(-4.0..0.0));
                        [
                            random_vector(&mut rng, speed),
                            random_vector(&mut rng, speed),
                            random_vector(&mut rng, speed / 1e-3),
                            random_vector(&mut rng, speed / 1e-3),
                        ]
                    })
                    .collect();
                // Old contacts (a history, some large enough to slide)
                // and new ones.
                let h: Vec<History> = (0..L::N)
                    .map(|_| match rng.gen_range(0..3) {
                        0 => History::default(),
                        k => History {
                            shear: random_vector(&mut rng, 10f64.powi(-5 - k)),
                            roll: random_vector(&mut rng, 10f64.powi(-5 - k)),
                        },
                    })
                    .collect();
                let dt = 1e-6;
                let mut lanes = HistoryLanes::<L>::from_fn(|l| h[l]);
                let r2 = L::from_fn(|l| d[l].length_squared());
                let c = contact(
                    &law,
                    V3::from_fn(|l| d[l]),
                    r2,
                    [ra, rb],
                    [ma, mb],
                    [V3::from_fn(|l| v[l][0]), V3::from_fn(|l| v[l][1])],
                    [V3::from_fn(|l| v[l][2]), V3::from_fn(|l| v[l][3])],
                    dt,
                    &mut lanes,
                );
                for l in 0..L::N {
                    let (ra, rb, ma, mb) = (ra.lane(l), rb.lane(l), ma.lane(l), mb.lane(l));
                    let reach = ra + rb;
                    let r = r2.lane(l).sqrt();
                    let nrm = d[l] / r;
                    let delta = reach - r;
                    let (arm_a, arm_b) = (ra - 0.5 * delta, rb - 0.5 * delta);
                    let [va, vb, wa, wb] = v[l];
                    let v_rel = va - vb - (wa * arm_a + wb * arm_b).cross(nrm);
                    let mut free = h[l];
                    no_limit.force(
                        delta,
                        nrm,
                        v_rel,
                        wa - wb,
                        arm_a,
                        arm_b,
                        ra * rb / reach,
                        ma * mb / (ma + mb),
                        dt,
                        &mut free,
                    );
                    let mut history = h[l];
                    let want = law.force(
                        delta,
                        nrm,
                        v_rel,
                        wa - wb,
                        arm_a,
                        arm_b,
                        ra * rb / reach,
                        ma * mb / (ma + mb),
                        dt,
                        &mut history,
                    );
                    assert_eq!(c.force.lane(l), want.force, "{law:?}");
                    assert_eq!(c.torque_i.lane(l), want.torque_i, "{law:?}");
                    assert_eq!(c.torque_j.lane(l), want.torque_j, "{law:?}");
                    assert_eq!(lanes.shear.lane(l), history.shear, "{law:?}");
                    assert_eq!(lanes.roll.lane(l), history.roll, "{law:?}");
                    if free.shear == history.shear {
                        stuck += 1;
                    } else {
                        slid += 1;
                    }
                }
            }
        }
        let all = slid + stuck;
        assert!(
            slid > all / 10 && stuck > all / 10,
            "{slid} slid, {stuck} stuck"
        );
    }

    #[test]
    fn four_lanes_give_the_scalar_law_bit_for_bit() {
        lanes_match_the_scalar_law::<Four>();
    }

    #[test]
    fn eight_lanes_give_the_scalar_law_bit_for_bit() {
        lanes_match_the_scalar_law::<Lanes>();
    }
}
