//! The Barnes–Hut walk (Barnes & Hut 1986, Nature 324, 446) shared by tree
//! gravity and tree Coulomb: for every particle the potential
//! ψ_i = Σ_{j≠i} s_j / (|r_j − r_i|² + ε²)^{1/2} and its gradient
//! g_i = Σ_{j≠i} s_j (r_j − r_i) / (|r_j − r_i|² + ε²)^{3/2}, with distant
//! cells replaced by their quadrupole expansions ([`Multipole`]).
//!
//! Opening criterion: a cell of side ℓ whose expansion centre c lies a
//! distance δ from its geometric centre is accepted for a target when the
//! target is farther from c than ℓ/θ + δ (Barnes 1994's `bmax` correction,
//! which bounds the error of cells whose mass sits in a corner), and never
//! when the cell and the target overlap. θ = 0 gives the direct sum.
//!
//! The walk is done per group of ≤ `group_size` neighbouring particles
//! (Barnes 1990, J. Comput. Phys. 87, 161): the criterion is applied to the
//! group's bounding box, so one walk yields an interaction list (cells and
//! particles) valid for every particle of the group, and the particle loops
//! over those lists run 8 lanes at a time in structure-of-arrays form. Every
//! particle's sums run over its group's lists in a fixed order, whichever
//! thread handles the group, so results are bit-identical for every thread
//! count.

use glam::DVec3;
use mote_geom::lanes::{Lane, Lanes as Eight};
use mote_geom::simd::{isa, Isa};
use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
use super::avx512;
use super::multipole::Multipole;
use super::octree::Octree;

/// Lanes of the list loops.
pub(super) const LANES: usize = 8;
/// Where padding entries sit: far enough to contribute nothing, near
/// enough that r⁻⁷ stays a normal number.
const FAR: f64 = 1e30;

/// Interaction counts of the last evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WalkCounts {
    /// Particle–particle interactions.
    pub particle: u64,
    /// Particle–cell (multipole) interactions.
    pub cell: u64,
}

/// A Barnes–Hut evaluator: the octree, the cells' expansions, scratch.
#[derive(Debug, Clone)]
pub struct BarnesHut {
    /// Opening angle θ.
    pub theta: f64,
    /// Plummer softening ε² (0 for the bare 1/r).
    pub eps2: f64,
    /// Most particles that share one walk.
    pub group_size: usize,
    /// The octree of the last build.
    pub tree: Octree,
    /// Expansions of the cells, indexed like `tree.nodes`.
    pub multipoles: Vec<Multipole>,
    open2: Vec<f64>,
    walk: Vec<WalkNode>,
    strength: Vec<f64>,
    groups: Vec<usize>,
    grad: Vec<DVec3>,
    psi: Vec<f64>,
    /// Whether cells act through their dipole moments: needed for charges
    /// of both signs; for masses the dipole about the centre of mass vanishes
    /// and is skipped.
    pub dipoles: bool,
    /// Interaction counts of the last evaluation.
    pub counts: WalkCounts,
}

impl BarnesHut {
    /// Leaves of at most 16 particles, groups of at most 64 (timed on a
    /// Plummer sphere of 10⁵ at θ = 0.5; 8/32, 16/32, 8/64 and 32/128 were
    /// no faster).
    pub fn new(theta: f64, softening: f64) -> Self {
        assert!(theta >= 0.0, "opening angle must not be negative");
        Self {
            theta,
            eps2: softening * softening,
            group_size: 64,
            tree: Octree::new(16),
            multipoles: Vec::new(),
            open2: Vec::new(),
            walk: Vec::new(),
            strength: Vec::new(),
            groups: Vec::new(),
            grad: Vec::new(),
            psi: Vec::new(),
            dipoles: true,
            counts: WalkCounts::default(),
        }
    }

    /// Builds the tree over the sources s_j at `position` and their
    /// expansions, about each cell's centre of |s| (the centre of mass for
    /// gravity, so the dipole vanishes).
    pub fn build(&mut self, position: &[DVec3], strength: &[f64]) {
        assert_eq!(position.len(), strength.len());
        self.tree.build(position);
        let order = &self.tree.order;
        self.strength.clear();
        self.strength
            .extend(order.iter().map(|&i| strength[i as usize]));
        let (pos, s) = (&self.tree.position, &self.strength);
        let theta = self.theta;
        self.tree
            .nodes
            .par_iter()
            .map(|node| {
                let range = node.range();
                let mut w = 0.0;
                let mut c = DVec3::ZERO;
                for k in range.clone() {
                    w += s[k].abs();
                    c += s[k].abs() * pos[k];
                }
                let centre = if w > 0.0 { c / w } else { node.centre };
                let mut m = Multipole::about(centre);
                for k in range {
                    m.add_charge(s[k], pos[k]);
                }
                let reach = 2.0 * node.half / theta + (centre - node.centre).length();
                (m, reach * reach)
            })
            .unzip_into_vecs(&mut self.multipoles, &mut self.open2);
        self.walk.clear();
        self.walk.extend(
            self.tree
                .nodes
                .iter()
                .zip(&self.multipoles)
                .zip(&self.open2)
                .map(|((node, m), &open2)| WalkNode {
                    expansion_centre: m.centre,
                    open2,
                    centre: node.centre,
                    half: node.half,
                    child: node.child,
                    children: node.children,
                    first: node.first,
                    count: node.count,
                }),
        );
        self.tree.groups(self.group_size, &mut self.groups);
    }

    /// Evaluates ψ (if `potential`) and ∇ψ at every particle of the last build.
    pub fn evaluate(&mut self, potential: bool) {
        let n = self.tree.len();
        self.grad.clear();
        self.grad.resize(n, DVec3::ZERO);
        self.psi.clear();
        self.psi.resize(n, 0.0);
        let mut slices = Vec::with_capacity(self.groups.len());
        let (mut grad, mut psi) = (&mut self.grad[..], &mut self.psi[..]);
        for &g in &self.groups {
            let count = self.tree.nodes[g].count as usize;
            let (g_head, g_tail) = grad.split_at_mut(count);
            let (p_head, p_tail) = psi.split_at_mut(count);
            slices.push((g, g_head, p_head));
            grad = g_tail;
            psi = p_tail;
        }
        let walker = Walker {
            tree: &self.tree,
            multipoles: &self.multipoles,
            walk: &self.walk,
            strength: &self.strength,
            eps2: self.eps2,
            isa: isa(),
        };
        let dipoles = self.dipoles;
        let counts = slices
            .into_par_iter()
            .map_init(Lists::default, |lists, (g, grad, psi)| {
                match (potential, dipoles) {
                    (true, true) => walker.group::<true, true>(g, lists, grad, psi),
                    (true, false) => walker.group::<true, false>(g, lists, grad, psi),
                    (false, true) => walker.group::<false, true>(g, lists, grad, psi),
                    (false, false) => walker.group::<false, false>(g, lists, grad, psi),
                }
            })
            .reduce(WalkCounts::default, |a, b| WalkCounts {
                particle: a.particle + b.particle,
                cell: a.cell + b.cell,
            });
        self.counts = counts;
    }

    /// Caller's index of the k-th particle in tree order.
    #[inline]
    pub fn index(&self, k: usize) -> usize {
        self.tree.order[k] as usize
    }

    /// ∇ψ in tree order (see [`BarnesHut::index`]).
    pub fn gradient(&self) -> &[DVec3] {
        &self.grad
    }

    /// ψ in tree order (after `evaluate(true)`).
    pub fn potential(&self) -> &[f64] {
        &self.psi
    }

    /// Sources in tree order.
    pub fn strength(&self) -> &[f64] {
        &self.strength
    }
}

/// What the walk reads of a node, in one 80-byte record.
#[derive(Debug, Clone, Copy)]
struct WalkNode {
    expansion_centre: DVec3,
    /// Squared opening distance (ℓ/θ + δ)².
    open2: f64,
    centre: DVec3,
    half: f64,
    child: u32,
    children: u32,
    first: u32,
    count: u32,
}

/// Eight particles of an interaction list, structure of arrays.
#[derive(Clone, Copy)]
pub(super) struct ParticleBlock {
    pub x: [f64; LANES],
    pub y: [f64; LANES],
    pub z: [f64; LANES],
    pub s: [f64; LANES],
    /// Tree-order index, as f64 so the comparison shares the lanes.
    pub id: [f64; LANES],
}

const EMPTY_PARTICLES: ParticleBlock = ParticleBlock {
    x: [FAR; LANES],
    y: [FAR; LANES],
    z: [FAR; LANES],
    s: [0.0; LANES],
    id: [-1.0; LANES],
};

/// Eight cells of an interaction list: centre, monopole, dipole,
/// quadrupole [xx, yy, zz, xy, xz, yz].
#[derive(Clone, Copy)]
pub(super) struct CellBlock {
    pub c: [[f64; LANES]; 13],
}

const EMPTY_CELLS: CellBlock = {
    let mut c = [[0.0; LANES]; 13];
    c[0] = [FAR; LANES];
    c[1] = [FAR; LANES];
    c[2] = [FAR; LANES];
    CellBlock { c }
};

/// Interaction lists of one group, in blocks of LANES (the last block
/// padded with far, empty entries).
#[derive(Default)]
struct Lists {
    particles: Vec<ParticleBlock>,
    n_particles: usize,
    cells: Vec<CellBlock>,
    n_cells: usize,
    stack: Vec<usize>,
}

impl Lists {
    fn clear(&mut self) {
        self.particles.clear();
        self.cells.clear();
        self.n_particles = 0;
        self.n_cells = 0;
    }

    #[inline]
    fn push_particle(&mut self, r: DVec3, s: f64, id: usize) {
        let lane = self.n_particles % LANES;
        if lane == 0 {
            self.particles.push(EMPTY_PARTICLES);
        }
        let b = self.particles.last_mut().unwrap();
        b.x[lane] = r.x;
        b.y[lane] = r.y;
        b.z[lane] = r.z;
        b.s[lane] = s;
        b.id[lane] = id as f64;
        self.n_particles += 1;
    }

    #[inline]
    fn push_cell(&mut self, m: &Multipole) {
        let lane = self.n_cells % LANES;
        if lane == 0 {
            self.cells.push(EMPTY_CELLS);
        }
        let b = self.cells.last_mut().unwrap();
        let q = &m.quadrupole;
        let row = [
            m.centre.x, m.centre.y, m.centre.z, m.monopole, m.dipole.x, m.dipole.y, m.dipole.z,
            q[0], q[1], q[2], q[3], q[4], q[5],
        ];
        for (v, x) in b.c.iter_mut().zip(row) {
            v[lane] = x;
        }
        self.n_cells += 1;
    }
}

#[derive(Clone, Copy)]
struct Walker<'a> {
    tree: &'a Octree,
    multipoles: &'a [Multipole],
    walk: &'a [WalkNode],
    strength: &'a [f64],
    eps2: f64,
    isa: Isa,
}

impl Walker<'_> {
    /// Walks the tree for group `g` and sums over its lists.
    fn group<const POT: bool, const DIP: bool>(
        &self,
        g: usize,
        lists: &mut Lists,
        grad: &mut [DVec3],
        psi: &mut [f64],
    ) -> WalkCounts {
        let nodes = &self.tree.nodes;
        let pos = &self.tree.position;
        let range = nodes[g].range();
        let (mut lo, mut hi) = (pos[range.start], pos[range.start]);
        for r in &pos[range.clone()] {
            lo = lo.min(*r);
            hi = hi.max(*r);
        }
        let (box_centre, box_half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        lists.clear();
        lists.stack.clear();
        lists.stack.push(0);
        while let Some(k) = lists.stack.pop() {
            let node = &self.walk[k];
            let c = node.expansion_centre;
            let gap = (lo - c).max(c - hi).max(DVec3::ZERO);
            let overlaps = (node.centre - box_centre)
                .abs()
                .cmple(DVec3::splat(node.half) + box_half)
                .all();
            if !overlaps && gap.length_squared() > node.open2 {
                lists.push_cell(&self.multipoles[k]);
            } else if node.children == 0 {
                for j in node.first as usize..(node.first + node.count) as usize {
                    lists.push_particle(pos[j], self.strength[j], j);
                }
            } else {
                let first = node.child as usize;
                lists
                    .stack
                    .extend((first..first + node.children as usize).rev());
            }
        }
        let counts = WalkCounts {
            particle: (lists.n_particles * range.len()) as u64,
            cell: (lists.n_cells * range.len()) as u64,
        };
        for (k, i) in range.enumerate() {
            let (pl, cl) = match self.isa {
                // SAFETY: the CPU supports AVX-512F (`isa`).
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => unsafe {
                    (
                        avx512::particles::<POT>(pos[i], i as f64, &lists.particles, self.eps2),
                        avx512::cells::<POT, DIP>(pos[i], &lists.cells, self.eps2),
                    )
                },
                Isa::Portable => (
                    particles::<POT>(pos[i], i as f64, &lists.particles, self.eps2),
                    cells::<POT, DIP>(pos[i], &lists.cells, self.eps2),
                ),
            };
            let (p1, g1) = fold(pl);
            let (p2, g2) = fold(cl);
            grad[k] = g1 + g2;
            psi[k] = p1 + p2;
        }
        counts
    }
}

/// Σ over the particle list (skipping the particle itself and exact
/// coincidences at ε = 0) of s/r and s d/r³, r² = |d|² + ε².
#[inline]
fn particles<const POT: bool>(x: DVec3, id: f64, list: &[ParticleBlock], eps2: f64) -> Lanes {
    let mut ax = [0.0; LANES];
    let mut ay = [0.0; LANES];
    let mut az = [0.0; LANES];
    let mut ap = [0.0; LANES];
    for b in list {
        // 1/r of the block's eight by multiplications (`Lane::rsqrt`), in
        // a loop of its own so that both loops stay straight.
        let mut r2 = [0.0; LANES];
        for k in 0..LANES {
            let (dx, dy, dz) = (b.x[k] - x.x, b.y[k] - x.y, b.z[k] - x.z);
            let d2 = dx * dx + dy * dy + dz * dz + eps2;
            r2[k] = if b.id[k] == id || d2 <= 0.0 { 1.0 } else { d2 };
        }
        let inv = Eight(r2).rsqrt().0;
        for k in 0..LANES {
            let dx = b.x[k] - x.x;
            let dy = b.y[k] - x.y;
            let dz = b.z[k] - x.z;
            let r2 = dx * dx + dy * dy + dz * dz + eps2;
            let skip = b.id[k] == id || r2 <= 0.0;
            let w = if skip { 0.0 } else { b.s[k] };
            let inv = inv[k];
            let winv = w * inv;
            let winv3 = winv * inv * inv;
            ax[k] += winv3 * dx;
            ay[k] += winv3 * dy;
            az[k] += winv3 * dz;
            if POT {
                ap[k] += winv;
            }
        }
    }
    (ap, ax, ay, az)
}

/// Σ over the cell list of the quadrupole expansions (module
/// [`super::multipole`] for the formulae).
#[inline]
fn cells<const POT: bool, const DIP: bool>(x: DVec3, list: &[CellBlock], eps2: f64) -> Lanes {
    let mut ax = [0.0; LANES];
    let mut ay = [0.0; LANES];
    let mut az = [0.0; LANES];
    let mut ap = [0.0; LANES];
    for b in list {
        let c = &b.c;
        let mut r2 = [0.0; LANES];
        for (k, r2) in r2.iter_mut().enumerate() {
            let (rx, ry, rz) = (x.x - c[0][k], x.y - c[1][k], x.z - c[2][k]);
            *r2 = rx * rx + ry * ry + rz * rz + eps2;
        }
        let inv_r = Eight(r2).rsqrt().0;
        for k in 0..LANES {
            let rx = x.x - c[0][k];
            let ry = x.y - c[1][k];
            let rz = x.z - c[2][k];
            let m = c[3][k];
            let (px, py, pz) = if DIP {
                (c[4][k], c[5][k], c[6][k])
            } else {
                (0.0, 0.0, 0.0)
            };
            let (qxx, qyy, qzz, qxy, qxz, qyz) =
                (c[7][k], c[8][k], c[9][k], c[10][k], c[11][k], c[12][k]);
            let inv = inv_r[k];
            let inv2 = inv * inv;
            let inv3 = inv * inv2;
            let inv5 = inv3 * inv2;
            let pr = px * rx + py * ry + pz * rz;
            let qx = qxx * rx + qxy * ry + qxz * rz;
            let qy = qxy * rx + qyy * ry + qyz * rz;
            let qz = qxz * rx + qyz * ry + qzz * rz;
            let rqr = rx * qx + ry * qy + rz * qz;
            let radial = m * inv3 + 3.0 * pr * inv5 + 2.5 * rqr * inv5 * inv2;
            ax[k] += px * inv3 + qx * inv5 - rx * radial;
            ay[k] += py * inv3 + qy * inv5 - ry * radial;
            az[k] += pz * inv3 + qz * inv5 - rz * radial;
            if POT {
                ap[k] += m * inv + pr * inv3 + 0.5 * rqr * inv5;
            }
        }
    }
    (ap, ax, ay, az)
}

/// Per-lane sums: potential, gradient x, y, z.
pub(super) type Lanes = ([f64; LANES], [f64; LANES], [f64; LANES], [f64; LANES]);

/// Sums the lanes in a fixed order.
#[inline]
fn fold((ap, ax, ay, az): Lanes) -> (f64, DVec3) {
    let mut p = 0.0;
    let mut g = DVec3::ZERO;
    for k in 0..LANES {
        p += ap[k];
        g += DVec3::new(ax[k], ay[k], az[k]);
    }
    (p, g)
}
