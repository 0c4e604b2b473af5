//! The FRBI's free step ([`super::frbi::free_step`]), its kick and the
//! world frame for eight bodies at once — in AVX-512 where the CPU has it,
//! else portably (AVX2 on the x86-64-v3 build, NEON on aarch64): the free
//! step, the kick and the world frame four bodies at a time on
//! [`mote_geom::lanes::Four`] (their 3 × 3 matrices of eight lanes would
//! be eighteen AVX2 registers, and spilled, the free step ran 21 % slower;
//! the kick gained 6 % from four once `Four` was one AVX register
//! an operation). The same operations
//! in the same order, one body per lane; no operation is fused or
//! reassociated, so every lane gets the bits the scalar step gives, on
//! every path (tested).
//!
//! Groups with a rotation vector near a half turn (|r|² > 10¹⁰⁰, where the
//! rotation matrix takes another formula) go through the scalar step; so
//! does the factor tan(φ/2)/φ of a lane whose turn in the step is not
//! small (φ = |ω|τ ≥ 10⁻³, where it is not the series).
use glam::DVec3;
use mote_geom::{Inertia, DE};

use super::frbi::{free_step, react, FreeFlight, SpinUpdate};

/// Bodies per group.
pub const LANES: usize = 8;

/// A group of eight bodies: their templates' inertia and their state, in
/// place in the bodies' arrays.
pub struct Group<'a> {
    pub inertia: [&'a Inertia; LANES],
    pub rotation: &'a mut [DVec3; LANES],
    pub position: &'a mut [DVec3; LANES],
    pub omega: &'a mut [DVec3; LANES],
    pub velocity: &'a [DVec3; LANES],
}

/// [`free_step`] of eight bodies: the rotation vectors, positions and
/// angular velocities of the group advance by `dt`.
pub fn free_step8(g: &mut Group, dt: f64, flight: FreeFlight, spin: SpinUpdate) {
    #[cfg(target_arch = "x86_64")]
    {
        let vector = mote_geom::simd::has_avx512()
            && flight == FreeFlight::Straight
            && g.rotation.iter().all(|r| r.dot(*r) <= 1e100);
        // SAFETY: the CPU has AVX-512F.
        if vector && unsafe { avx512::lanes(g, dt, spin) } {
            return;
        }
    }
    let vector = flight == FreeFlight::Straight && g.rotation.iter().all(|r| r.dot(*r) <= 1e100);
    if vector && portable::lanes(g, dt, spin) {
        return;
    }
    for l in 0..LANES {
        let (r, x, w) = (&mut g.rotation[l], &mut g.position[l], &mut g.omega[l]);
        free_step(g.inertia[l], r, x, w, g.velocity[l], dt, flight, spin);
    }
}

/// [`react`] of eight bodies: `omega` and `velocity` take the impulses
/// `(angular, linear)` at the rotations `rotation`.
pub fn react8(
    inertia: [&Inertia; LANES],
    rotation: &[DVec3; LANES],
    omega: &mut [DVec3; LANES],
    velocity: &mut [DVec3; LANES],
    impulse: &[DE; LANES],
) {
    #[cfg(target_arch = "x86_64")]
    if mote_geom::simd::has_avx512() && rotation.iter().all(|r| r.dot(*r) <= 1e100) {
        // SAFETY: the CPU has AVX-512F.
        unsafe { avx512::react(inertia, rotation, omega, velocity, impulse) };
        return;
    }
    if rotation.iter().all(|r| r.dot(*r) <= 1e100) {
        portable::react(inertia, rotation, omega, velocity, impulse);
        return;
    }
    for l in 0..LANES {
        react(
            inertia[l],
            rotation[l],
            &mut omega[l],
            &mut velocity[l],
            impulse[l],
        );
    }
}

/// The world frame of eight bodies of one template (sphere centres
/// `centres0` and dipole `dipole0` in the body frame): sphere centres
/// x + M b into `centres` (body after body) and dipoles M m₀ into
/// `dipole`, M = `rotation_matrix(r)`, bit for bit as
/// `WorldFrame::update` computes them. False, with nothing written, where
/// a rotation is near a half turn.
pub fn world8(
    rotation: &[DVec3; LANES],
    position: &[DVec3; LANES],
    centres0: &[DVec3],
    dipole0: DVec3,
    centres: &mut [DVec3],
    dipole: &mut [DVec3; LANES],
) -> bool {
    assert_eq!(
        centres.len(),
        LANES * centres0.len(),
        "eight bodies' spheres"
    );
    #[cfg(target_arch = "x86_64")]
    if mote_geom::simd::has_avx512() && rotation.iter().all(|r| r.dot(*r) <= 1e100) {
        // SAFETY: the CPU has AVX-512F.
        unsafe { avx512::world(rotation, position, centres0, dipole0, centres, dipole) };
        return true;
    }
    if rotation.iter().all(|r| r.dot(*r) <= 1e100) {
        portable::world(rotation, position, centres0, dipole0, centres, dipole);
        return true;
    }
    false
}

/// The eight-lane arithmetic.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use glam::DVec3;
    use mote_geom::{Inertia, DE, EPSILON};

    use super::{Group, LANES};
    use crate::rigid::frbi::SpinUpdate;

    type S = __m512d;

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn splat(v: f64) -> S {
        _mm512_set1_pd(v)
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn add(a: S, b: S) -> S {
        _mm512_add_pd(a, b)
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn sub(a: S, b: S) -> S {
        _mm512_sub_pd(a, b)
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn mul(a: S, b: S) -> S {
        _mm512_mul_pd(a, b)
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn div(a: S, b: S) -> S {
        _mm512_div_pd(a, b)
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn lanes_of(v: S) -> [f64; LANES] {
        // SAFETY: __m512d and [f64; 8] have the same size and any bits are valid.
        unsafe { std::mem::transmute::<S, [f64; LANES]>(v) }
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn from_lanes(v: [f64; LANES]) -> S {
        // SAFETY: as above.
        unsafe { std::mem::transmute::<[f64; LANES], S>(v) }
    }

    /// Eight vectors, one per lane.
    #[derive(Clone, Copy)]
    struct V {
        x: S,
        y: S,
        z: S,
    }

    /// The helpers below are AVX-512 functions (`#[target_feature]`), inlined
    /// into [`lanes`].
    impl V {
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn of(v: &[DVec3; LANES]) -> Self {
            let coordinate = |k: usize| from_lanes(std::array::from_fn(|l| v[l][k]));
            Self {
                x: coordinate(0),
                y: coordinate(1),
                z: coordinate(2),
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn splat(v: DVec3) -> Self {
            Self {
                x: splat(v.x),
                y: splat(v.y),
                z: splat(v.z),
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn write(self, out: &mut [DVec3; LANES]) {
            let (x, y, z) = (lanes_of(self.x), lanes_of(self.y), lanes_of(self.z));
            for l in 0..LANES {
                out[l] = DVec3::new(x[l], y[l], z[l]);
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn add(self, o: V) -> V {
            V {
                x: add(self.x, o.x),
                y: add(self.y, o.y),
                z: add(self.z, o.z),
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn sub(self, o: V) -> V {
            V {
                x: sub(self.x, o.x),
                y: sub(self.y, o.y),
                z: sub(self.z, o.z),
            }
        }

        /// Component by component (glam's `DVec3 * DVec3`).
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn mul(self, o: V) -> V {
            V {
                x: mul(self.x, o.x),
                y: mul(self.y, o.y),
                z: mul(self.z, o.z),
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn scale(self, s: S) -> V {
            V {
                x: mul(self.x, s),
                y: mul(self.y, s),
                z: mul(self.z, s),
            }
        }

        /// (x·x' + y·y') + z·z', glam's order.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn dot(self, o: V) -> S {
            add(add(mul(self.x, o.x), mul(self.y, o.y)), mul(self.z, o.z))
        }

        /// glam's `cross`, term for term.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn cross(self, o: V) -> V {
            V {
                x: sub(mul(self.y, o.z), mul(o.y, self.z)),
                y: sub(mul(self.z, o.x), mul(o.z, self.x)),
                z: sub(mul(self.x, o.y), mul(o.x, self.y)),
            }
        }
    }

    /// Eight 3 × 3 matrices by columns.
    #[derive(Clone, Copy)]
    struct M {
        x: V,
        y: V,
        z: V,
    }

    impl M {
        /// glam's `mul_vec3`: ((x_axis v.x) + (y_axis v.y)) + (z_axis v.z).
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn apply(&self, v: V) -> V {
            self.x
                .scale(v.x)
                .add(self.y.scale(v.y))
                .add(self.z.scale(v.z))
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn mul(&self, o: &M) -> M {
            M {
                x: self.apply(o.x),
                y: self.apply(o.y),
                z: self.apply(o.z),
            }
        }

        #[inline]
        #[target_feature(enable = "avx512f")]
        fn transpose(&self) -> M {
            M {
                x: V {
                    x: self.x.x,
                    y: self.y.x,
                    z: self.z.x,
                },
                y: V {
                    x: self.x.y,
                    y: self.y.y,
                    z: self.z.y,
                },
                z: V {
                    x: self.x.z,
                    y: self.y.z,
                    z: self.z.z,
                },
            }
        }

        /// P (d ⊙ Pᵀ x): the inertia (or its inverse) of principal moments d
        /// with principal axes P, applied to x.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn sandwich(&self, d: V, x: V) -> V {
            self.apply(d.mul(self.transpose().apply(x)))
        }
    }

    /// The matrix of x ↦ x * r, as `frbi::matrix` (all lanes |r|² ≤ 10¹⁰⁰).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn matrix(r: V) -> M {
        let rr = r.dot(r);
        let one = splat(1.0);
        let s = div(one, add(one, rr));
        let c = mul(sub(one, rr), s);
        let t = mul(splat(2.0), s);
        let (x, y, z) = (r.x, r.y, r.z);
        let txx = mul(mul(t, x), x);
        let tyy = mul(mul(t, y), y);
        let tzz = mul(mul(t, z), z);
        let (xy, xz, yz) = (mul(x, y), mul(x, z), mul(y, z));
        M {
            x: V {
                x: add(c, txx),
                y: mul(t, add(xy, z)),
                z: mul(t, sub(xz, y)),
            },
            y: V {
                x: mul(t, sub(xy, z)),
                y: add(c, tyy),
                z: mul(t, add(yz, x)),
            },
            z: V {
                x: mul(t, add(xz, y)),
                y: mul(t, sub(yz, x)),
                z: add(c, tzz),
            },
        }
    }

    /// `DE::exp_rotation(ω, τ)` = ωτ tan(φ/2)/φ, φ = |ωτ|: the series
    /// (1 + φ²/12 + φ⁴/120)/2 of `mote_geom`'s `half_tan_over` where φ < 10⁻³,
    /// the scalar function in the other lanes.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn exp_rotation(w: V, tau: f64) -> V {
        let wt = w.scale(splat(tau));
        let phi = _mm512_sqrt_pd(wt.dot(wt));
        let p2 = mul(phi, phi);
        let series = mul(
            splat(0.5),
            add(
                add(splat(1.0), div(p2, splat(12.0))),
                div(mul(p2, p2), splat(120.0)),
            ),
        );
        let r = wt.scale(series);
        let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(phi, splat(1e-3));
        if small == 0xff {
            return r;
        }
        let mut out = [DVec3::ZERO; LANES];
        r.write(&mut out);
        let mut omega = [DVec3::ZERO; LANES];
        w.write(&mut omega);
        for l in 0..LANES {
            if small & (1 << l) == 0 {
                out[l] = DE::exp_rotation(omega[l], tau);
            }
        }
        V::of(&out)
    }

    /// `compose_rotations(r1, r2)`: 1/s, or 1/ε where |s| < ε, selected.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn compose(r1: V, r2: V) -> V {
        let s = sub(splat(1.0), r1.dot(r2));
        let abs = _mm512_abs_pd(s);
        let tiny = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(abs, splat(EPSILON));
        let big_s = _mm512_mask_blend_pd(tiny, div(splat(1.0), s), splat(1.0 / EPSILON));
        r1.add(r2).sub(r1.cross(r2)).scale(big_s)
    }

    /// The templates' principal axes A (columns), moments J and 1/J, one
    /// template for the whole group (the common case) broadcast.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn principal(inertia: &[&Inertia; LANES]) -> (M, V, V) {
        let shared = inertia.iter().all(|i| std::ptr::eq(*i, inertia[0]));
        let (a, j) = if shared {
            let i = inertia[0];
            let a = M {
                x: V::splat(i.axes[0]),
                y: V::splat(i.axes[1]),
                z: V::splat(i.axes[2]),
            };
            (a, V::splat(DVec3::from(i.moments)))
        } else {
            let a = M {
                x: V::of(&inertia.map(|i| i.axes[0])),
                y: V::of(&inertia.map(|i| i.axes[1])),
                z: V::of(&inertia.map(|i| i.axes[2])),
            };
            (a, V::of(&inertia.map(|i| DVec3::from(i.moments))))
        };
        let one = splat(1.0);
        let j_inv = V {
            x: div(one, j.x),
            y: div(one, j.y),
            z: div(one, j.z),
        };
        (a, j, j_inv)
    }

    /// `mote_geom::rotate(x, r)` for a constant x, term for term:
    /// (x(1 − r·r) + (2 x·r) r − 2 x × r) / (1 + r·r) (all |r|² ≤ 10¹⁰⁰).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn rotate(x: DVec3, r: V) -> V {
        let x = V::splat(x);
        let rr = r.dot(r);
        let (one, two) = (splat(1.0), splat(2.0));
        let num = x
            .scale(sub(one, rr))
            .add(r.scale(mul(two, x.dot(r))))
            .sub(x.cross(r).scale(two));
        let den = add(one, rr);
        V {
            x: div(num.x, den),
            y: div(num.y, den),
            z: div(num.z, den),
        }
    }

    /// [`super::world8`]'s arithmetic: `rotation_matrix(r)` by columns
    /// (the images of the axes), then x + M b and M m₀.
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn world(
        rotation: &[DVec3; LANES],
        position: &[DVec3; LANES],
        centres0: &[DVec3],
        dipole0: DVec3,
        centres: &mut [DVec3],
        dipole: &mut [DVec3; LANES],
    ) {
        let r = V::of(rotation);
        let m = M {
            x: rotate(DVec3::X, r),
            y: rotate(DVec3::Y, r),
            z: rotate(DVec3::Z, r),
        };
        let x = V::of(position);
        let count = centres0.len();
        let mut lanes = [DVec3::ZERO; LANES];
        for (s, b) in centres0.iter().enumerate() {
            x.add(m.apply(V::splat(*b))).write(&mut lanes);
            for (l, c) in lanes.iter().enumerate() {
                centres[l * count + s] = *c;
            }
        }
        m.apply(V::splat(dipole0)).write(dipole);
    }

    /// `frbi::react` on eight lanes (all |r|² ≤ 10¹⁰⁰).
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn react(
        inertia: [&Inertia; LANES],
        rotation: &[DVec3; LANES],
        omega: &mut [DVec3; LANES],
        velocity: &mut [DVec3; LANES],
        impulse: &[DE; LANES],
    ) {
        let (a, _, j_inv) = principal(&inertia);
        let p = matrix(V::of(rotation)).mul(&a);
        let angular = V::of(&impulse.map(|h| h.omega));
        p.sandwich(j_inv, angular).add(V::of(omega)).write(omega);
        let inverse_mass = V {
            x: from_lanes(inertia.map(|i| 1.0 / i.mass)),
            y: from_lanes(inertia.map(|i| 1.0 / i.mass)),
            z: from_lanes(inertia.map(|i| 1.0 / i.mass)),
        };
        V::of(velocity)
            .add(V::of(&impulse.map(|h| h.v)).mul(inverse_mass))
            .write(velocity);
    }

    /// The free step of `frbi::free_step` (straight flight) on eight lanes;
    /// false, with the group untouched, if a new rotation vector is near a
    /// half turn (its matrix needs the scalar formula).
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn lanes(g: &mut Group, dt: f64, spin: SpinUpdate) -> bool {
        let (a, j, j_inv) = principal(&g.inertia);
        let tau = 0.5 * dt;
        let w = V::of(g.omega);
        let rotation = V::of(g.rotation);
        let p = matrix(rotation).mul(&a);
        let l = p.sandwich(j, w);
        let r_c = exp_rotation(w, tau);
        let p_c = matrix(r_c).mul(&p);
        let dl = l.sub(p_c.sandwich(j, w));
        let dw = p.sandwich(j_inv, dl);
        let w_c = w.add(dw);
        let rotation = compose(rotation, exp_rotation(w_c, dt));
        let rr = rotation.dot(rotation);
        if _mm512_cmp_pd_mask::<_CMP_GT_OQ>(rr, splat(1e100)) != 0 {
            return false;
        }
        let position = V::of(g.position).add(V::of(g.velocity).scale(splat(dt)));
        let omega = match spin {
            SpinUpdate::Seed => w_c.add(dw),
            SpinUpdate::KeepMomentum => matrix(rotation).mul(&a).sandwich(j_inv, l),
        };
        rotation.write(g.rotation);
        position.write(g.position);
        omega.write(g.omega);
        true
    }
}

/// The same arithmetic on [`Lanes`], for every CPU: each operation the
/// scalar step's, in its order, so every lane has its bits (the tests
/// below hold both paths to them).
mod portable {
    use glam::DVec3;
    use mote_geom::lanes::{Four, Lane};
    use mote_geom::{Inertia, DE, EPSILON};

    use super::{Group, LANES};
    use crate::rigid::frbi::SpinUpdate;

    /// N vectors, one per lane (the layer's, glam's operations term for
    /// term).
    use mote_geom::lanes::V3 as V;

    /// N 3 × 3 matrices by columns.
    #[derive(Clone, Copy)]
    struct M<L> {
        x: V<L>,
        y: V<L>,
        z: V<L>,
    }

    impl<L: Lane> M<L> {
        /// glam's `mul_vec3`: ((x_axis v.x) + (y_axis v.y)) + (z_axis v.z).
        #[inline(always)]
        fn apply(&self, v: V<L>) -> V<L> {
            self.x
                .scale(v.x)
                .add(self.y.scale(v.y))
                .add(self.z.scale(v.z))
        }

        #[inline(always)]
        fn mul(&self, o: &Self) -> Self {
            M {
                x: self.apply(o.x),
                y: self.apply(o.y),
                z: self.apply(o.z),
            }
        }

        #[inline(always)]
        fn transpose(&self) -> Self {
            let column = |x: L, y: L, z: L| V { x, y, z };
            M {
                x: column(self.x.x, self.y.x, self.z.x),
                y: column(self.x.y, self.y.y, self.z.y),
                z: column(self.x.z, self.y.z, self.z.z),
            }
        }

        /// P (d ⊙ Pᵀ x).
        #[inline(always)]
        fn sandwich(&self, d: V<L>, x: V<L>) -> V<L> {
            self.apply(d.mul(self.transpose().apply(x)))
        }
    }

    /// The matrix of x ↦ x * r, as `frbi::matrix` (all lanes |r|² ≤ 10¹⁰⁰).
    #[inline(always)]
    fn matrix<L: Lane>(r: V<L>) -> M<L> {
        let rr = r.dot(r);
        let one = L::splat(1.0);
        let s = one / (one + rr);
        let c = (one - rr) * s;
        let t = L::splat(2.0) * s;
        let (x, y, z) = (r.x, r.y, r.z);
        let (xy, xz, yz) = (x * y, x * z, y * z);
        M {
            x: V {
                x: c + t * x * x,
                y: t * (xy + z),
                z: t * (xz - y),
            },
            y: V {
                x: t * (xy - z),
                y: c + t * y * y,
                z: t * (yz + x),
            },
            z: V {
                x: t * (xz + y),
                y: t * (yz - x),
                z: c + t * z * z,
            },
        }
    }

    /// `DE::exp_rotation(ω, τ)`: the series of `half_tan_over` where
    /// φ = |ωτ| < 10⁻³, the scalar function in the other lanes.
    #[inline(always)]
    fn exp_rotation<L: Lane>(w: V<L>, tau: f64) -> V<L> {
        let wt = w.scale(L::splat(tau));
        let phi = wt.dot(wt).sqrt();
        let p2 = phi * phi;
        let series = L::splat(0.5) * ((L::splat(1.0) + p2 / 12.0) + p2 * p2 / 120.0);
        let r = wt.scale(series);
        let all = (1u16 << L::N) - 1;
        let small = u16::from(phi.bits_below(1e-3));
        if small == all {
            return r;
        }
        let (mut out, mut omega) = ([DVec3::ZERO; LANES], [DVec3::ZERO; LANES]);
        r.write(&mut out);
        w.write(&mut omega);
        for l in 0..L::N {
            if small & (1 << l) == 0 {
                out[l] = DE::exp_rotation(omega[l], tau);
            }
        }
        V::of(&out)
    }

    /// `compose_rotations(r1, r2)`: 1/s, or 1/ε where |s| < ε.
    #[inline(always)]
    fn compose<L: Lane>(r1: V<L>, r2: V<L>) -> V<L> {
        let s = L::splat(1.0) - r1.dot(r2);
        let big_s = s.map(|s| {
            if s.abs() < EPSILON {
                1.0 / EPSILON
            } else {
                1.0 / s
            }
        });
        r1.add(r2).sub(r1.cross(r2)).scale(big_s)
    }

    /// The templates' principal axes A (columns), moments J and 1/J.
    #[inline(always)]
    fn principal<L: Lane>(inertia: &[&Inertia]) -> (M<L>, V<L>, V<L>) {
        let a = M {
            x: V::from_fn(|l| inertia[l].axes[0]),
            y: V::from_fn(|l| inertia[l].axes[1]),
            z: V::from_fn(|l| inertia[l].axes[2]),
        };
        let j = V::from_fn(|l| DVec3::from(inertia[l].moments));
        let one = L::splat(1.0);
        let j_inv = V {
            x: one / j.x,
            y: one / j.y,
            z: one / j.z,
        };
        (a, j, j_inv)
    }

    /// `mote_geom::rotate(x, r)` for a constant x, term for term.
    #[inline(always)]
    fn rotate<L: Lane>(x: DVec3, r: V<L>) -> V<L> {
        let x = V::splat(x);
        let rr = r.dot(r);
        let (one, two) = (L::splat(1.0), L::splat(2.0));
        let num = x
            .scale(one - rr)
            .add(r.scale(two * x.dot(r)))
            .sub(x.cross(r).scale(two));
        let den = one + rr;
        V {
            x: num.x / den,
            y: num.y / den,
            z: num.z / den,
        }
    }

    /// [`super::world8`]'s arithmetic (all |r|² ≤ 10¹⁰⁰).
    pub(super) fn world(
        rotation: &[DVec3; LANES],
        position: &[DVec3; LANES],
        centres0: &[DVec3],
        dipole0: DVec3,
        centres: &mut [DVec3],
        dipole: &mut [DVec3; LANES],
    ) {
        // Four bodies at a time: a matrix of four lanes is nine registers.
        let count = centres0.len();
        for half in 0..2 {
            let at = 4 * half..4 * half + 4;
            let r = V::<Four>::of(&rotation[at.clone()]);
            let m = M {
                x: rotate(DVec3::X, r),
                y: rotate(DVec3::Y, r),
                z: rotate(DVec3::Z, r),
            };
            let x = V::of(&position[at.clone()]);
            let mut lanes = [DVec3::ZERO; 4];
            for (s, b) in centres0.iter().enumerate() {
                x.add(m.apply(V::splat(*b))).write(&mut lanes);
                for (l, c) in lanes.iter().enumerate() {
                    centres[(4 * half + l) * count + s] = *c;
                }
            }
            m.apply(V::splat(dipole0)).write(&mut dipole[at]);
        }
    }

    /// `frbi::react` on eight bodies, four lanes at a time (all |r|² ≤
    /// 10¹⁰⁰).
    pub(super) fn react(
        inertia: [&Inertia; LANES],
        rotation: &[DVec3; LANES],
        omega: &mut [DVec3; LANES],
        velocity: &mut [DVec3; LANES],
        impulse: &[DE; LANES],
    ) {
        for half in 0..2 {
            let at = 4 * half..4 * half + 4;
            let (a, _, j_inv) = principal::<Four>(&inertia[at.clone()]);
            let p = matrix(V::<Four>::of(&rotation[at.clone()])).mul(&a);
            let angular = V::from_fn(|l| impulse[4 * half + l].omega);
            (p.sandwich(j_inv, angular).add(V::of(&omega[at.clone()])))
                .write(&mut omega[at.clone()]);
            let inverse_mass = Four::from_fn(|l| 1.0 / inertia[4 * half + l].mass);
            V::<Four>::of(&velocity[at.clone()])
                .add(V::from_fn(|l| impulse[4 * half + l].v).scale(inverse_mass))
                .write(&mut velocity[at]);
        }
    }

    /// The new rotation vectors, positions and angular velocities of the
    /// first N bodies of a group's arrays (`frbi::free_step`, straight
    /// flight); `None` if a new rotation vector is near a half turn.
    #[allow(clippy::type_complexity)]
    #[inline(always)]
    fn step<L: Lane>(
        inertia: &[&Inertia],
        (rotation, position, omega, velocity): (&[DVec3], &[DVec3], &[DVec3], &[DVec3]),
        dt: f64,
        spin: SpinUpdate,
    ) -> Option<(V<L>, V<L>, V<L>)> {
        let (a, j, j_inv) = principal::<L>(inertia);
        let tau = 0.5 * dt;
        let w = V::of(omega);
        let rotation = V::of(rotation);
        let p = matrix(rotation).mul(&a);
        let l = p.sandwich(j, w);
        let r_c = exp_rotation(w, tau);
        let p_c = matrix(r_c).mul(&p);
        let dl = l.sub(p_c.sandwich(j, w));
        let dw = p.sandwich(j_inv, dl);
        let w_c = w.add(dw);
        let rotation = compose(rotation, exp_rotation(w_c, dt));
        // Not `bits_below`: a NaN lane goes on, as in the scalar step.
        let rr = rotation.dot(rotation);
        if (0..L::N).any(|l| rr.lane(l) > 1e100) {
            return None;
        }
        let position = V::of(position).add(V::of(velocity).scale(L::splat(dt)));
        let omega = match spin {
            SpinUpdate::Seed => w_c.add(dw),
            SpinUpdate::KeepMomentum => matrix(rotation).mul(&a).sandwich(j_inv, l),
        };
        Some((rotation, position, omega))
    }

    /// The free step of `frbi::free_step` (straight flight) on the eight
    /// bodies of a group, four lanes at a time; false, with the group
    /// untouched, if a new rotation vector is near a half turn.
    pub(super) fn lanes(g: &mut Group, dt: f64, spin: SpinUpdate) -> bool {
        let half = |k: usize| {
            let at = 4 * k..4 * k + 4;
            step::<Four>(
                &g.inertia[at.clone()],
                (
                    &g.rotation[at.clone()],
                    &g.position[at.clone()],
                    &g.omega[at.clone()],
                    &g.velocity[at],
                ),
                dt,
                spin,
            )
        };
        let (Some(first), Some(second)) = (half(0), half(1)) else {
            return false;
        };
        for (k, (rotation, position, omega)) in [first, second].into_iter().enumerate() {
            let at = 4 * k..4 * k + 4;
            rotation.write(&mut g.rotation[at.clone()]);
            position.write(&mut g.position[at.clone()]);
            omega.write(&mut g.omega[at]);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mote_geom::rotation_matrix;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn vector(rng: &mut Xoshiro256PlusPlus, scale: f64) -> DVec3 {
        DVec3::new(rng.gen(), rng.gen(), rng.gen()) * (2.0 * scale) - DVec3::splat(scale)
    }

    /// Every lane of the eight-body step (and kick) has the scalar step's
    /// bits: one
    /// or two templates per group, slow and fast turns (the series and the
    /// scalar tan(φ/2)/φ), rotation vectors up to near a half turn, both
    /// spin updates and both free flights.
    #[test]
    fn eight_bodies_step_as_eight_scalar_steps_bit_for_bit() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let template = |rng: &mut Xoshiro256PlusPlus| {
            let m = rotation_matrix(vector(rng, 1.0));
            let moments = [
                rng.gen_range(0.5..2.0),
                rng.gen_range(0.5..2.0),
                rng.gen_range(0.5..2.0),
            ];
            Inertia::new(moments, [m.x_axis, m.y_axis, m.z_axis], 1.0)
        };
        let (t1, t2) = (template(&mut rng), template(&mut rng));
        let dt = 1e-3;
        let mut groups = 0;
        for case in 0..400 {
            let mixed = case % 2 == 1;
            let fast = case % 3 == 0;
            let spin = if case % 5 == 0 {
                SpinUpdate::Seed
            } else {
                SpinUpdate::KeepMomentum
            };
            let flight = if case % 7 == 0 {
                FreeFlight::Screw
            } else {
                FreeFlight::Straight
            };
            let mut rotation: [DVec3; LANES] = std::array::from_fn(|_| vector(&mut rng, 3.0));
            let mut position: [DVec3; LANES] = std::array::from_fn(|_| vector(&mut rng, 10.0));
            let mut omega: [DVec3; LANES] =
                std::array::from_fn(|_| vector(&mut rng, if fast { 10.0 } else { 0.5 }));
            let velocity: [DVec3; LANES] = std::array::from_fn(|_| vector(&mut rng, 1.0));
            if case % 11 == 0 {
                rotation[3] = DVec3::new(1e60, 0.0, 0.0);
            }
            let mut scalar = (rotation, position, omega);
            let mut g = Group {
                inertia: std::array::from_fn(|l| if mixed && l % 3 == 0 { &t2 } else { &t1 }),
                rotation: &mut rotation,
                position: &mut position,
                omega: &mut omega,
                velocity: &velocity,
            };
            for l in 0..LANES {
                let (r, x, w) = (&mut scalar.0[l], &mut scalar.1[l], &mut scalar.2[l]);
                free_step(g.inertia[l], r, x, w, g.velocity[l], dt, flight, spin);
            }
            free_step8(&mut g, dt, flight, spin);
            for l in 0..LANES {
                assert_eq!(
                    g.rotation[l].to_array().map(f64::to_bits),
                    scalar.0[l].to_array().map(f64::to_bits),
                    "case {case}, lane {l}: rotation"
                );
                assert_eq!(
                    g.position[l].to_array().map(f64::to_bits),
                    scalar.1[l].to_array().map(f64::to_bits),
                    "case {case}, lane {l}: position"
                );
                assert_eq!(
                    g.omega[l].to_array().map(f64::to_bits),
                    scalar.2[l].to_array().map(f64::to_bits),
                    "case {case}, lane {l}: angular velocity"
                );
            }
            // The kick: eight lanes against eight scalar `react`s.
            let impulse: [DE; LANES] =
                std::array::from_fn(|_| DE::new(vector(&mut rng, 1e-3), vector(&mut rng, 1e-3)));
            let mut kicked = (*g.omega, velocity);
            let mut scalar_kicked = kicked;
            react8(
                g.inertia,
                g.rotation,
                &mut kicked.0,
                &mut kicked.1,
                &impulse,
            );
            for l in 0..LANES {
                let (w, v) = (&mut scalar_kicked.0[l], &mut scalar_kicked.1[l]);
                react(g.inertia[l], g.rotation[l], w, v, impulse[l]);
            }
            let bits = |v: &[DVec3; LANES]| v.map(|v| v.to_array().map(f64::to_bits));
            assert_eq!(
                bits(&kicked.0),
                bits(&scalar_kicked.0),
                "case {case}: kicked ω"
            );
            assert_eq!(
                bits(&kicked.1),
                bits(&scalar_kicked.1),
                "case {case}: kicked v"
            );
            groups += 1;
        }
        assert_eq!(groups, 400);
    }

    /// The world frame of eight bodies (sphere centres and dipoles) has the
    /// bits of `x + rotation_matrix(r) b` body by body; a rotation near a
    /// half turn leaves the group to the scalar code.
    #[test]
    fn eight_world_frames_as_eight_scalar_ones_bit_for_bit() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let centres0: Vec<DVec3> = (0..3).map(|_| vector(&mut rng, 1.0)).collect();
        let dipole0 = vector(&mut rng, 2.0);
        for case in 0..200 {
            let scale = [0.1, 3.0, 1e20][case % 3];
            let mut rotation: [DVec3; LANES] = std::array::from_fn(|_| vector(&mut rng, scale));
            if case % 7 == 0 {
                rotation[5] = DVec3::new(0.0, 1e60, 0.0);
            }
            let position: [DVec3; LANES] = std::array::from_fn(|_| vector(&mut rng, 10.0));
            let mut centres = vec![DVec3::ZERO; LANES * centres0.len()];
            let mut dipole = [DVec3::ZERO; LANES];
            let vector_path = world8(
                &rotation,
                &position,
                &centres0,
                dipole0,
                &mut centres,
                &mut dipole,
            );
            let near_half_turn = rotation.iter().any(|r| r.dot(*r) > 1e100);
            assert_eq!(vector_path, !near_half_turn, "case {case}");
            if !vector_path {
                continue;
            }
            for l in 0..LANES {
                let m = rotation_matrix(rotation[l]);
                for (s, b) in centres0.iter().enumerate() {
                    let want = position[l] + m * *b;
                    let got = centres[l * centres0.len() + s];
                    assert_eq!(
                        got.to_array().map(f64::to_bits),
                        want.to_array().map(f64::to_bits),
                        "case {case}, body {l}, sphere {s}"
                    );
                }
                let want = m * dipole0;
                assert_eq!(
                    dipole[l].to_array().map(f64::to_bits),
                    want.to_array().map(f64::to_bits),
                    "case {case}, body {l}: dipole"
                );
            }
        }
    }
}
