//! Hertz–Mindlin contacts for rigid bodies of overlapping spheres: between
//! spheres of *different* bodies and between spheres and walls (seed 000,
//! "Modeling the dynamics of irregularly shaped particles": bodies touch
//! through their spheres; the short-range issue's contact law).
//!
//! - Neighbour search: a half Verlet list over all world-frame sphere
//!   centres ([`crate::neighbor::VerletList`]); after each rebuild the pairs
//!   of one body are dropped, so the loop sees only pairs of different
//!   bodies. Every listed pair carries its contact history (tangential and
//!   rolling elongations) beside the list; a rebuild carries the histories
//!   of pairs still listed over by merging the sorted partner lists.
//! - Walls: the granular [`Wall`]s, with one history per (sphere, wall).
//! - The law is [`ContactLaw::force`] with R* of the two spheres and, for
//!   the damping, m* = m_a m_b/(m_a + m_b) of the two *bodies* (m* = m_a
//!   against a wall). This is the common choice: LAMMPS `fix rigid` with the
//!   granular pair styles passes, per atom, the mass of the body the atom
//!   belongs to, and LIGGGHTS multisphere does the same.
//! - Velocities at the contact point come from the bodies' dE(ω, v)
//!   ([`BodyView::point_velocity`]); each contact force is put into the two
//!   bodies' wrenches at the sphere centres ([`BodyView::wrench_at`]) plus
//!   the law's torque about each sphere centre, which together are the
//!   force applied at the contact point (and the rolling couple), so the
//!   pair's total force and torque about any point vanish.
//! - The FRBI evaluates forces once per step at t + Δt/2; successive
//!   evaluations are Δt apart (for a constant step; for a varying step the
//!   mean of two steps), and the tangential history advances by the time
//!   since the previous evaluation, which is stored.

use glam::DVec3;
use mote_geom::DE;

use super::interaction::{BodyInteraction, BodyView};
use crate::boundary::Boundary;
use crate::boundary::MinimumImage;
use crate::force::granular::history::{history_of, PAIR_ROW};
use crate::force::granular::{ContactForce, ContactLaw, History, PairHistories, Wall, WallShape};
use crate::neighbor::VerletList;

/// Contact parameters shared by all sphere pairs and walls. Stiffness comes
/// from the law's E*, G*; the per-pair effective radius and mass are taken
/// from the spheres and bodies.
#[derive(Debug)]
pub struct RigidContacts {
    /// The law between spheres of two bodies.
    pub law: ContactLaw,
    /// The law between a sphere and a wall.
    pub wall_law: ContactLaw,
    pub walls: Vec<Wall>,
    /// Periodic axes (with their box) for the sphere–sphere search; bodies
    /// are not wrapped, their spheres are wrapped for the search only.
    pub boundary: Boundary,
    state: ContactState,
}

/// The mutable part: neighbour list, histories, wall forces.
#[derive(Debug, Clone, Default)]
struct ContactState {
    list: VerletList,
    skin: f64,
    /// Wrapped sphere centres (periodic boundaries only).
    wrapped: Vec<DVec3>,
    /// Pairs of spheres of different bodies, with their histories.
    pairs: PairHistories,
    /// history[s · walls + w]: sphere s against wall w.
    wall_history: Vec<History>,
    wall_touching: Vec<bool>,
    wall_force: Vec<DVec3>,
    contacts: usize,
    wall_contacts: usize,
    /// Sphere–wall histories of a resumed run, put in place at the next evaluation.
    pending_walls: Vec<(usize, History)>,
}

/// Numbers per carried sphere–wall row: slot, ξ (3), ψ (3).
const WALL_ROW: usize = 7;

impl RigidContacts {
    /// Contacts with law `law` between bodies and `wall_law` against
    /// `walls`; `skin` is the Verlet skin of the sphere search.
    pub fn new(law: ContactLaw, wall_law: ContactLaw, walls: Vec<Wall>, skin: f64) -> Self {
        let n_walls = walls.len();
        Self {
            law,
            wall_law,
            walls,
            boundary: Boundary::open(),
            state: ContactState {
                skin,
                wall_force: vec![DVec3::ZERO; n_walls],
                ..Default::default()
            },
        }
    }

    /// Search with periodic axes (x, y of a slab, for example).
    pub fn with_boundary(mut self, boundary: Boundary) -> Self {
        self.boundary = boundary;
        self
    }

    /// The force the spheres exert on each wall at the last evaluation.
    pub fn wall_forces(&self) -> Vec<(String, DVec3)> {
        let s = &self.state;
        self.walls
            .iter()
            .zip(&s.wall_force)
            .map(|(w, f)| (w.name.clone(), *f))
            .collect()
    }

    /// Touching sphere pairs and sphere–wall contacts at the last evaluation.
    pub fn contact_counts(&self) -> (usize, usize) {
        let s = &self.state;
        (s.contacts, s.wall_contacts)
    }

    /// Number of neighbour-list builds so far.
    pub fn list_builds(&self) -> u64 {
        self.state.list.builds
    }

    /// The contact history of spheres (a, b) of different bodies, if listed.
    pub fn history(&self, a: usize, b: usize) -> Option<History> {
        self.state.pairs.get(a, b)
    }
}

impl ContactState {
    /// Refreshes the list; after a rebuild drops same-body pairs and carries
    /// the histories of pairs still listed.
    fn refresh(&mut self, centres: &[DVec3], body: &[u32], r_max: f64, boundary: &Boundary) {
        let cutoff = 2.0 * r_max;
        if self.list.cutoff != cutoff || !self.list.half {
            let skin = self.skin;
            self.list = VerletList::half(cutoff, skin);
        }
        let pos: &[DVec3] = if boundary.is_periodic() {
            self.wrapped.clear();
            self.wrapped
                .extend(centres.iter().map(|c| boundary.wrap(*c)));
            &self.wrapped
        } else {
            centres
        };
        let rebuilt = self.list.update(pos, boundary);
        if !rebuilt && self.pairs.rows() == centres.len() {
            return;
        }
        let n = centres.len();
        let mut start = Vec::with_capacity(n + 1);
        let mut partner = Vec::with_capacity(self.list.neighbors.len());
        start.push(0u32);
        for (s, &bs) in body.iter().enumerate().take(n) {
            partner.extend(self.list.of(s).iter().filter(|&&j| body[j as usize] != bs));
            start.push(partner.len() as u32);
        }
        self.pairs.carry_to(&start, &partner);
    }
}

/// The sphere pairs of one evaluation: the bodies, the law and the
/// search positions (wrapped on periodic axes, with the minimum image).
struct SpherePairs<'a> {
    view: &'a BodyView<'a>,
    law: &'a ContactLaw,
    pos: &'a [DVec3],
    image: Option<&'a MinimumImage>,
}

impl SpherePairs<'_> {
    /// The separation of the centres of spheres `s` and `o` (the minimum
    /// image on periodic axes).
    #[inline(always)]
    fn separation(&self, s: usize, o: usize) -> DVec3 {
        match self.image {
            Some(image) => image.apply(self.pos[s] - self.pos[o]),
            None => self.pos[s] - self.pos[o],
        }
    }

    /// The contact between spheres `s` and `o` of different bodies (the
    /// force on `s`, its torques), with `history` advanced by `dt`; `None`
    /// when they do not touch (the history untouched).
    #[inline(always)]
    fn contact(&self, s: usize, o: usize, dt: f64, history: &mut History) -> Option<ContactForce> {
        let (world, bodies) = (self.view.world, self.view.bodies);
        let (centres, radius, body) = (
            &world.sphere_centre,
            &world.sphere_radius,
            &world.sphere_body,
        );
        let d = self.separation(s, o);
        let reach = radius[s] + radius[o];
        let r2 = d.length_squared();
        if r2 >= reach * reach {
            return None;
        }
        let r = r2.sqrt();
        let nrm = d / r;
        let delta = reach - r;
        let (arm_s, arm_o) = (radius[s] - 0.5 * delta, radius[o] - 0.5 * delta);
        let (a, b) = (body[s] as usize, body[o] as usize);
        let (xa, va, wa) = (bodies.position[a], bodies.velocity[a], bodies.omega[a]);
        // The contact point relative to each body's centre (true centres,
        // not wrapped: arms from the unwrapped spheres).
        let ps = centres[s] - nrm * arm_s - xa;
        let po = centres[o] + nrm * arm_o - bodies.position[b];
        let v_rel = va + wa.cross(ps) - bodies.velocity[b] - bodies.omega[b].cross(po);
        let (ma, mb) = (bodies.template(a).mass(), bodies.template(b).mass());
        Some(self.law.force(
            delta,
            nrm,
            v_rel,
            wa - bodies.omega[b],
            arm_s,
            arm_o,
            radius[s] * radius[o] / reach,
            ma * mb / (ma + mb),
            dt,
            history,
        ))
    }
}

impl BodyInteraction for RigidContacts {
    fn name(&self) -> &str {
        "contacts"
    }

    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let t = view.step.time;
        let world = view.world;
        let bodies = view.bodies;
        let centres = &world.sphere_centre;
        let radius = &world.sphere_radius;
        let body = &world.sphere_body;
        let n = centres.len();
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let st = &mut self.state;
        st.refresh(centres, body, r_max, &self.boundary);
        let dt = view.step.dt;
        let image = self.boundary.image();
        let periodic = self.boundary.is_periodic();
        let pos: &[DVec3] = if periodic { &st.wrapped } else { centres };
        let law = &self.law;
        let mut contacts = 0usize;

        // Sphere–sphere.
        let pairs = SpherePairs {
            view,
            law,
            pos,
            image: periodic.then_some(&image),
        };
        for s in 0..n {
            let (a, range) = (body[s] as usize, st.pairs.range(s));
            for k in range {
                let o = st.pairs.partner(k) as usize;
                let Some(c) = pairs.contact(s, o, dt, &mut st.pairs.history[k]) else {
                    if st.pairs.touching[k] {
                        st.pairs.touching[k] = false;
                        st.pairs.history[k] = History::default();
                    }
                    continue;
                };
                st.pairs.touching[k] = true;
                let b = body[o] as usize;
                let wa_ = view.wrench_at(a, centres[s], c.force);
                wrench[a].omega += wa_.omega + c.torque_i;
                wrench[a].v += wa_.v;
                let wb_ = view.wrench_at(b, centres[o], -c.force);
                wrench[b].omega += wb_.omega + c.torque_j;
                wrench[b].v += wb_.v;
                contacts += 1;
            }
        }
        st.contacts = contacts;

        // Sphere–wall.
        let n_walls = self.walls.len();
        st.wall_force.clear();
        st.wall_force.resize(n_walls, DVec3::ZERO);
        st.wall_contacts = 0;
        if n_walls == 0 {
            return;
        }
        if st.wall_history.len() != n * n_walls {
            st.wall_history = vec![History::default(); n * n_walls];
            st.wall_touching = vec![false; n * n_walls];
        }
        for (slot, h) in std::mem::take(&mut st.pending_walls) {
            if slot < st.wall_history.len() {
                st.wall_history[slot] = h;
                st.wall_touching[slot] = true;
            }
        }
        let planes: Vec<Option<(DVec3, f64)>> = self
            .walls
            .iter()
            .map(|w| match w.shape {
                WallShape::Plane { point, normal } => {
                    Some((normal, (point + w.velocity * t).dot(normal)))
                }
                WallShape::Cylinder { .. } => None,
            })
            .collect();
        let wl = &self.wall_law;
        for s in 0..n {
            let (x, rs) = (centres[s], radius[s]);
            let a = body[s] as usize;
            for (w, wall) in self.walls.iter().enumerate() {
                let slot = s * n_walls + w;
                let (gap, nrm) = match planes[w] {
                    Some((normal, offset)) => (x.dot(normal) - offset, normal),
                    None => wall.gap(x, t),
                };
                if gap >= rs || gap <= -rs {
                    if st.wall_touching[slot] {
                        st.wall_touching[slot] = false;
                        st.wall_history[slot] = History::default();
                    }
                    continue;
                }
                st.wall_touching[slot] = true;
                let delta = rs - gap;
                let arm = rs - 0.5 * delta;
                let p = x - nrm * arm;
                let v_rel = view.point_velocity(a, p) - wall.surface_velocity(x, gap, nrm, t);
                let c = wl.force(
                    delta,
                    nrm,
                    v_rel,
                    bodies.omega[a],
                    arm,
                    0.0,
                    rs,
                    bodies.template(a).mass(),
                    dt,
                    &mut st.wall_history[slot],
                );
                let wr = view.wrench_at(a, x, c.force);
                wrench[a].omega += wr.omega + c.torque_i;
                wrench[a].v += wr.v;
                st.wall_force[w] -= c.force;
                st.wall_contacts += 1;
            }
        }
    }

    /// [NaN (the time of the last evaluation before dt came with the view;
    /// kept so earlier checkpoints load), number of pair rows,
    /// pair rows (a, b, shear, roll) of touching sphere pairs, wall rows
    /// (slot, shear, roll) of touching sphere–wall contacts]. Pairs that
    /// do not touch carry the zero history, so these rows are the whole state.
    fn carried_state(&self) -> Vec<f64> {
        let s = &self.state;
        let mut pairs = Vec::new();
        s.pairs.write_rows(&mut pairs);
        let mut out = vec![f64::NAN, (pairs.len() / PAIR_ROW) as f64];
        out.extend(pairs);
        for (slot, h) in s.wall_history.iter().enumerate() {
            if s.wall_touching[slot] {
                out.push(slot as f64);
                out.extend(h.shear.to_array());
                out.extend(h.roll.to_array());
            }
        }
        out
    }

    fn restore_carried_state(&mut self, state: &[f64]) -> Result<(), String> {
        let bad = || "rigid contact history: malformed carried state".to_string();
        let [_, pairs, rows @ ..] = state else {
            return if state.is_empty() { Ok(()) } else { Err(bad()) };
        };
        let n_pairs = *pairs as usize;
        if n_pairs * PAIR_ROW > rows.len()
            || !(rows.len() - n_pairs * PAIR_ROW).is_multiple_of(WALL_ROW)
        {
            return Err(bad());
        }
        let (pair_rows, wall_rows) = rows.split_at(n_pairs * PAIR_ROW);
        let s = &mut self.state;
        // The sphere count is known at the next evaluation; rows naming
        // spheres beyond it are never listed, so never placed.
        s.pairs
            .restore_rows(pair_rows, u32::MAX as usize)
            .map_err(|m| format!("rigid {m}"))?;
        s.pending_walls = wall_rows
            .chunks(WALL_ROW)
            .map(|r| (r[0] as usize, history_of(&r[1..])))
            .collect();
        Ok(())
    }

    /// The molecular virial of the sphere–sphere contacts at the view's
    /// placement: Σ (R_a − R_b)·F over touching pairs of spheres, R_a − R_b
    /// the separation of their bodies' centres in the pair's minimum image
    /// (the spheres' separation less the spheres' offsets from their
    /// centres), F the law's whole force on sphere a — elastic, damping and
    /// tangential from the carried history, which is not advanced (dt = 0).
    /// Walls add nothing (LAMMPS's fix convention).
    fn virial(&mut self, view: &BodyView<'_>) -> Option<f64> {
        let world = view.world;
        let (centres, radius, body) = (
            &world.sphere_centre,
            &world.sphere_radius,
            &world.sphere_body,
        );
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let st = &mut self.state;
        st.refresh(centres, body, r_max, &self.boundary);
        let image = self.boundary.image();
        let periodic = self.boundary.is_periodic();
        let pairs = SpherePairs {
            view,
            law: &self.law,
            pos: if periodic { &st.wrapped } else { centres },
            image: periodic.then_some(&image),
        };
        let offset = |s: usize| centres[s] - view.bodies.position[body[s] as usize];
        let mut w = 0.0;
        for s in 0..centres.len() {
            for k in st.pairs.range(s) {
                let o = st.pairs.partner(k) as usize;
                let mut history = st.pairs.history[k];
                if let Some(c) = pairs.contact(s, o, 0.0, &mut history) {
                    let between = pairs.separation(s, o) - offset(s) + offset(o);
                    w += between.dot(c.force);
                }
            }
        }
        Some(w)
    }

    /// The Hertz elastic energy Σ (8/15) E* √R* δ^{5/2} of all sphere pairs
    /// of different bodies and sphere–wall contacts at the view's placement
    /// (pairs taken from the list of the last force evaluation, whose skin
    /// covers the half step since).
    fn potential_energy(&mut self, view: &BodyView<'_>) -> f64 {
        let t = view.step.time;
        let world = view.world;
        let centres = &world.sphere_centre;
        let radius = &world.sphere_radius;
        let n = centres.len();
        let st = &mut self.state;
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        st.refresh(centres, &world.sphere_body, r_max, &self.boundary);
        let image = self.boundary.image();
        let pos: &[DVec3] = if self.boundary.is_periodic() {
            &st.wrapped
        } else {
            centres
        };
        let mut u = 0.0;
        for s in 0..n {
            for k in st.pairs.range(s) {
                let o = st.pairs.partner(k) as usize;
                let reach = radius[s] + radius[o];
                let r = image.apply(pos[s] - pos[o]).length();
                if r < reach {
                    let r_eff = radius[s] * radius[o] / reach;
                    u += self.law.elastic_energy(reach - r, r_eff);
                }
            }
        }
        for wall in &self.walls {
            for s in 0..n {
                let r = radius[s];
                let (gap, _) = wall.gap(centres[s], t);
                if gap < r && gap > -r {
                    u += self.wall_law.elastic_energy(r - gap, r);
                }
            }
        }
        u
    }
}
