//! Hertz–Mindlin contacts for rigid bodies of overlapping spheres: between
//! spheres of *different* bodies and between spheres and walls (seed 000,
//! "Modeling the dynamics of irregularly shaped particles": bodies touch
//! through their spheres; the short-range issue's contact law).
//!
//! - Neighbour search: a half Verlet list over all world-frame sphere
//!   centres ([`crate::neighbor::VerletList`]) grouped by body, so that it
//!   lists only pairs of spheres of different bodies. Every listed pair carries its contact history (tangential and
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

use std::ops::Range;

use glam::DVec3;
use mote_geom::DE;
use mote_run::parallel::for_each_block;

use super::interaction::{BodyInteraction, BodyView};
use crate::boundary::Boundary;
use crate::boundary::MinimumImage;
use crate::force::granular::history::{block_firsts, history_of, split_blocks, PAIR_ROW};
use crate::force::granular::{ContactForce, ContactLaw, History, PairHistories, Wall};
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
    /// Sphere centres wrapped into the box (periodic boundaries only).
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
    /// The touching pairs' wrenches of each block of rows, in pair order.
    pair_wrenches: Vec<Vec<PairWrench>>,
    /// The sphere–wall contacts' wrenches of each block of spheres.
    wall_wrenches: Vec<Vec<WallWrench>>,
}

/// One touching pair's wrenches on its two bodies: the contact force at
/// each sphere's centre plus the law's torque about it.
#[derive(Debug, Clone, Copy)]
struct PairWrench {
    a: u32,
    b: u32,
    on_a: DE,
    on_b: DE,
}

/// One sphere–wall contact's wrench on the body, and its force on the sphere.
#[derive(Debug, Clone, Copy)]
struct WallWrench {
    body: u32,
    wall: u32,
    on_body: DE,
    force: DVec3,
}

/// Where one evaluation's wrenches go, in the order they come: the bodies'
/// wrenches and the walls' forces, with the contacts counted.
struct Totals<'a> {
    wrench: &'a mut [DE],
    wall_force: &'a mut [DVec3],
    contacts: usize,
    wall_contacts: usize,
}

impl Totals<'_> {
    fn pair(&mut self, w: &PairWrench) {
        let (a, b) = (w.a as usize, w.b as usize);
        self.wrench[a].omega += w.on_a.omega;
        self.wrench[a].v += w.on_a.v;
        self.wrench[b].omega += w.on_b.omega;
        self.wrench[b].v += w.on_b.v;
        self.contacts += 1;
    }

    fn wall(&mut self, w: &WallWrench) {
        let a = w.body as usize;
        self.wrench[a].omega += w.on_body.omega;
        self.wrench[a].v += w.on_body.v;
        self.wall_force[w.wall as usize] -= w.force;
        self.wall_contacts += 1;
    }
}

/// Spheres per block of the parallel wall loop.
const WALL_BLOCK: usize = 1024;

/// Keeps the rows of `width` entries (one per wall) of the spheres with
/// `keep[s]`.
fn retain_rows<T>(v: &mut Vec<T>, keep: &[bool], width: usize) {
    let mut slot = 0;
    v.retain(|_| {
        let k = keep.get(slot / width).copied().unwrap_or(false);
        slot += 1;
        k
    });
}

/// Numbers per carried sphere–wall row: slot, ξ (3), ψ (3).
const WALL_ROW: usize = 7;

impl RigidContacts {
    /// Blocks of sphere rows of the parallel pair loop: one per 1024
    /// spheres, each holding an equal share of the listed pairs. The
    /// wrenches are summed in pair order whatever the blocks, so their
    /// number only sets how the work spreads over threads.
    fn blocks(n: usize) -> usize {
        (n / 1024).clamp(1, 256)
    }

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
    /// Refreshes the list (which lists no two spheres of one body); after
    /// a rebuild carries the histories of pairs still listed.
    fn refresh(&mut self, centres: &[DVec3], body: &[u32], r_max: f64, boundary: &Boundary) {
        let cutoff = 2.0 * r_max;
        if self.list.cutoff != cutoff || !self.list.half {
            let skin = self.skin;
            self.list = VerletList::half(cutoff, skin);
        }
        self.list.set_groups(body);
        let rebuilt = if boundary.is_periodic() {
            self.list
                .update_wrapping(centres, boundary, &mut self.wrapped)
        } else {
            self.list.update(centres, boundary)
        };
        if rebuilt || self.pairs.rows() != centres.len() {
            self.pairs.carry_to(&self.list.start, &self.list.neighbors);
        }
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

    /// The pairs of sphere rows `rows` (entries from `base` on in
    /// `history` and `touching`): advances their histories and writes the
    /// touching pairs' wrenches to `out` in pair order.
    fn block(
        &self,
        list: &PairHistories,
        rows: Range<usize>,
        history: &mut [History],
        touching: &mut [bool],
        out: &mut impl FnMut(PairWrench),
    ) {
        let world = self.view.world;
        let (centres, body) = (&world.sphere_centre, &world.sphere_body);
        let dt = self.view.step.dt;
        let base = list.starts()[rows.start] as usize;
        for s in rows {
            let a = body[s];
            for k in list.range(s) {
                let (o, kb) = (list.partner(k) as usize, k - base);
                let Some(c) = self.contact(s, o, dt, &mut history[kb]) else {
                    if touching[kb] {
                        touching[kb] = false;
                        history[kb] = History::default();
                    }
                    continue;
                };
                touching[kb] = true;
                let b = body[o];
                let on_a = self.view.wrench_at(a as usize, centres[s], c.force);
                let on_b = self.view.wrench_at(b as usize, centres[o], -c.force);
                out(PairWrench {
                    a,
                    b,
                    on_a: DE::new(on_a.omega + c.torque_i, on_a.v),
                    on_b: DE::new(on_b.omega + c.torque_j, on_b.v),
                });
            }
        }
    }
}

/// The sphere–wall contacts of one evaluation.
struct WallContacts<'a> {
    view: &'a BodyView<'a>,
    law: &'a ContactLaw,
    walls: &'a [Wall],
    /// Each plane wall's normal and offset n·p at the evaluation's time
    /// (`None` for a cylinder).
    planes: Vec<Option<(DVec3, f64)>>,
}

impl WallContacts<'_> {
    /// The spheres from `first` on against every wall (history slot
    /// s·walls + w, from the first sphere's on in `history` and
    /// `touching`): advances their histories and writes the contacts'
    /// wrenches to `out` in sphere order.
    fn block(
        &self,
        first: usize,
        history: &mut [History],
        touching: &mut [bool],
        out: &mut impl FnMut(WallWrench),
    ) {
        let n_walls = self.walls.len();
        let (view, t, dt) = (self.view, self.view.step.time, self.view.step.dt);
        let (world, bodies) = (view.world, view.bodies);
        let (centres, radius, body) = (
            &world.sphere_centre,
            &world.sphere_radius,
            &world.sphere_body,
        );
        for (slot, (h, touch)) in history.iter_mut().zip(touching).enumerate() {
            let (s, w) = (first + slot / n_walls, slot % n_walls);
            let (x, rs, wall) = (centres[s], radius[s], &self.walls[w]);
            let (gap, nrm) = match self.planes[w] {
                Some((normal, offset)) => (x.dot(normal) - offset, normal),
                None => wall.gap(x, t),
            };
            if gap >= rs || gap <= -rs {
                if *touch {
                    *touch = false;
                    *h = History::default();
                }
                continue;
            }
            *touch = true;
            let a = body[s] as usize;
            let delta = rs - gap;
            let arm = rs - 0.5 * delta;
            let p = x - nrm * arm;
            let v_rel = view.point_velocity(a, p) - wall.surface_velocity(x, gap, nrm, t);
            let c = self.law.force(
                delta,
                nrm,
                v_rel,
                bodies.omega[a],
                arm,
                0.0,
                rs,
                bodies.template(a).mass(),
                dt,
                h,
            );
            let on_a = view.wrench_at(a, x, c.force);
            out(WallWrench {
                body: a as u32,
                wall: w as u32,
                on_body: DE::new(on_a.omega + c.torque_i, on_a.v),
                force: c.force,
            });
        }
    }
}

/// A block of one evaluation's parallel section: rows of sphere pairs, or
/// spheres against the walls, with the histories it advances and the
/// buffer its wrenches go to.
enum ContactBlock<'h> {
    Pairs {
        rows: Range<usize>,
        history: &'h mut [History],
        touching: &'h mut [bool],
        out: &'h mut Vec<PairWrench>,
    },
    Walls {
        first: usize,
        history: &'h mut [History],
        touching: &'h mut [bool],
        out: &'h mut Vec<WallWrench>,
    },
}

impl BodyInteraction for RigidContacts {
    fn name(&self) -> &str {
        "contacts"
    }

    /// Sphere pairs and sphere–wall contacts advance in one parallel
    /// section of blocks (rows of pairs with equal numbers of pairs, runs
    /// of spheres against the walls), each writing its contacts' wrenches
    /// in order; the wrenches are then summed in pair order, then sphere–
    /// wall order, so the bits are those of one serial loop on any number
    /// of threads. One thread adds them as they come, in the same order,
    /// without the buffers.
    fn add_wrenches(&mut self, view: &BodyView<'_>, wrench: &mut [DE]) {
        let world = view.world;
        let (centres, radius) = (&world.sphere_centre, &world.sphere_radius);
        let n = centres.len();
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let st = &mut self.state;
        st.refresh(centres, &world.sphere_body, r_max, &self.boundary);
        let image = self.boundary.image();
        let periodic = self.boundary.is_periodic();
        let pairs = SpherePairs {
            view,
            law: &self.law,
            pos: if periodic { &st.wrapped } else { centres },
            image: periodic.then_some(&image),
        };
        let t = view.step.time;
        let walls = WallContacts {
            view,
            law: &self.wall_law,
            walls: &self.walls,
            planes: self.walls.iter().map(|w| w.plane_at(t)).collect(),
        };
        let n_walls = self.walls.len();
        // New spheres (the first evaluation's, bodies inserted) start
        // without history against the walls.
        st.wall_history.resize(n * n_walls, History::default());
        st.wall_touching.resize(n * n_walls, false);
        for (slot, h) in st.pending_walls.drain(..) {
            if slot < st.wall_history.len() {
                st.wall_history[slot] = h;
                st.wall_touching[slot] = true;
            }
        }

        let firsts = block_firsts(st.pairs.starts(), Self::blocks(n));
        let mut history = std::mem::take(&mut st.pairs.history);
        let mut touching = std::mem::take(&mut st.pairs.touching);
        let pair_blocks = split_blocks(&mut history, &mut touching, st.pairs.starts(), &firsts);
        st.pair_wrenches
            .resize_with(pair_blocks.len(), Default::default);
        let wall_chunk = (WALL_BLOCK * n_walls).max(1);
        let wall_blocks = if n_walls == 0 {
            0
        } else {
            n.div_ceil(WALL_BLOCK)
        };
        st.wall_wrenches.resize_with(wall_blocks, Default::default);
        let mut blocks: Vec<ContactBlock> = pair_blocks
            .into_iter()
            .zip(st.pair_wrenches.iter_mut())
            .enumerate()
            .map(|(b, ((history, touching), out))| ContactBlock::Pairs {
                rows: firsts[b]..firsts[b + 1],
                history,
                touching,
                out,
            })
            .collect();
        blocks.extend(
            (st.wall_history.chunks_mut(wall_chunk))
                .zip(st.wall_touching.chunks_mut(wall_chunk))
                .zip(st.wall_wrenches.iter_mut())
                .enumerate()
                .map(|(b, ((history, touching), out))| ContactBlock::Walls {
                    first: b * WALL_BLOCK,
                    history,
                    touching,
                    out,
                }),
        );
        let list = &st.pairs;
        st.wall_force.clear();
        st.wall_force.resize(self.walls.len(), DVec3::ZERO);
        let mut totals = Totals {
            wrench,
            wall_force: &mut st.wall_force,
            contacts: 0,
            wall_contacts: 0,
        };
        if rayon::current_num_threads() < 2 {
            // One thread: the blocks in order, each contact's wrenches
            // added as they come — the order of the sums below.
            for block in &mut blocks {
                match block {
                    ContactBlock::Pairs {
                        rows,
                        history,
                        touching,
                        ..
                    } => pairs.block(list, rows.clone(), history, touching, &mut |w| {
                        totals.pair(&w)
                    }),
                    ContactBlock::Walls {
                        first,
                        history,
                        touching,
                        ..
                    } => walls.block(*first, history, touching, &mut |w| totals.wall(&w)),
                }
            }
        } else {
            for_each_block(&mut blocks, |_, block| match block {
                ContactBlock::Pairs {
                    rows,
                    history,
                    touching,
                    out,
                } => {
                    out.clear();
                    pairs.block(list, rows.clone(), history, touching, &mut |w| out.push(w))
                }
                ContactBlock::Walls {
                    first,
                    history,
                    touching,
                    out,
                } => {
                    out.clear();
                    walls.block(*first, history, touching, &mut |w| out.push(w))
                }
            });
            drop(blocks);
            st.pair_wrenches
                .iter()
                .flatten()
                .for_each(|w| totals.pair(w));
            st.wall_wrenches
                .iter()
                .flatten()
                .for_each(|w| totals.wall(w));
        }
        (st.contacts, st.wall_contacts) = (totals.contacts, totals.wall_contacts);
        st.pairs.history = history;
        st.pairs.touching = touching;
    }

    /// The histories of the spheres that stay, renumbered; the list is
    /// rebuilt at the next evaluation and carries them.
    fn bodies_changed(&mut self, kept: Option<&[bool]>) {
        let st = &mut self.state;
        st.list.invalidate();
        let Some(keep) = kept else { return };
        st.pairs.retain(keep);
        let n_walls = self.walls.len();
        if n_walls == 0 {
            return;
        }
        retain_rows(&mut st.wall_history, keep, n_walls);
        retain_rows(&mut st.wall_touching, keep, n_walls);
        let mut new_index = Vec::with_capacity(keep.len());
        let mut kept = 0;
        for &k in keep {
            new_index.push(k.then_some(kept));
            kept += usize::from(k);
        }
        st.pending_walls.retain_mut(|(slot, _)| {
            let sphere = new_index.get(*slot / n_walls).copied().flatten();
            sphere
                .inspect(|s| *slot = s * n_walls + *slot % n_walls)
                .is_some()
        });
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
