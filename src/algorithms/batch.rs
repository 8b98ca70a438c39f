//! Inverse dynamics of many samples: the recursive Newton-Euler algorithm of [`super::rnea`]
//! run on [`LANES`] samples side by side. Every quantity is stored as a structure of arrays
//! (one `[f64; LANES]` per scalar), so each operation of the recursion acts on a short vector of
//! samples that the compiler maps onto SIMD registers; the model's constants (placements,
//! axes, inertias) are shared by the lanes.

use crate::error::Result;
pub use crate::lanes::LANES;
use crate::lanes::{sin_cos, L, R, S, V};
use crate::model::{JointKind, Model};
use crate::spatial::Se3;

/// Work buffers of [`rnea_lanes`] for one model (allocate once, reuse).
#[derive(Clone, Debug)]
pub struct LaneData {
    rot: Vec<R>,
    pos: Vec<V>,
    v: Vec<S>,
    a: Vec<S>,
    f: Vec<S>,
    qb: Vec<L>,
    vb: Vec<L>,
    ab: Vec<L>,
}

impl LaneData {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        Self {
            rot: vec![R::default(); nb],
            pos: vec![V::default(); nb],
            v: vec![S::default(); nb],
            a: vec![S::default(); nb],
            f: vec![S::default(); nb],
            qb: vec![L::default(); nb],
            vb: vec![L::default(); nb],
            ab: vec![L::default(); nb],
        }
    }
}

/// Inverse dynamics `tau = M(q) qdd + c(q, qd) + g(q)` of a batch, [`LANES`] samples at a time.
///
/// - `q` (rad or m), `qd` (rad/s or m/s), `qdd` (rad/s^2 or m/s^2): row-major `k x nv`
///   (sample `s`, dof `j` at `s * nv + j`); `qd` or `qdd` `None` for zeros. All arguments
///   must hold the same `k` samples and finite values: check them first (as the Python batch
///   API does with [`Model::check_vector`]); this kernel does not.
/// - `gravity`: include `g(q)`.
/// - `tau`: row-major `k x nv` output (N m or N).
///
/// Equal to [`crate::rnea`] sample by sample up to rounding.
///
/// On x86-64 processors with AVX2 and FMA (checked at run time) the kernel runs compiled for
/// them; elsewhere with the baseline instruction set.
pub fn rnea_lanes(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: bool,
    tau: &mut [f64],
) -> Result<()> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the processor supports the features `rnea_lanes_avx2` is compiled for.
        return unsafe { rnea_lanes_avx2(model, data, q, qd, qdd, gravity, tau) };
    }
    rnea_lanes_body(model, data, q, qd, qdd, gravity, tau)
}

/// [`rnea_lanes_body`] compiled for AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn rnea_lanes_avx2(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: bool,
    tau: &mut [f64],
) -> Result<()> {
    rnea_lanes_body(model, data, q, qd, qdd, gravity, tau)
}

#[inline(always)]
fn rnea_lanes_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: bool,
    tau: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    let k = q.len() / nv.max(1);
    let expect = |name: &str, len: usize| -> Result<()> {
        if len != k * nv || q.len() % nv.max(1) != 0 {
            return Err(crate::error::Error::Shape {
                argument: name.into(),
                expected: format!("{k} samples x {nv} values like q"),
                got: format!("{len} values"),
            });
        }
        Ok(())
    };
    expect("q", q.len())?;
    expect("tau", tau.len())?;
    if let Some(x) = qd {
        expect("qd", x.len())?;
    }
    if let Some(x) = qdd {
        expect("qdd", x.len())?;
    }
    let g = model.base_acceleration(gravity);
    let mut first = 0;
    while first < k {
        // the last group repeats its final sample in the unused lanes
        let lane = |l: usize| (first + l).min(k - 1);
        for (i, b) in model.bodies.iter().enumerate() {
            let get = |x: &[f64], l: usize| b.multiplier * x[lane(l) * nv + b.dof];
            data.qb[i] = L(std::array::from_fn(|l| get(q, l) + b.offset));
            data.vb[i] = L(std::array::from_fn(|l| qd.map_or(0.0, |x| get(x, l))));
            data.ab[i] = L(std::array::from_fn(|l| qdd.map_or(0.0, |x| get(x, l))));
        }
        group(model, data, &g);
        // contract body torques onto the dofs and write the lanes in use
        let used = (k - first).min(LANES);
        for s in first..first + used {
            tau[s * nv..(s + 1) * nv].fill(0.0);
        }
        for (i, b) in model.bodies.iter().enumerate() {
            let t = if b.kind == JointKind::Revolute {
                data.f[i].ang.dot_const(&b.axis)
            } else {
                data.f[i].lin.dot_const(&b.axis)
            };
            for l in 0..used {
                tau[(first + l) * nv + b.dof] += b.multiplier * t.0[l];
            }
        }
        first += LANES;
    }
    Ok(())
}

/// One group of lanes: forward pass (poses, twists, accelerations, body wrenches) then the
/// backward pass accumulating the wrenches in `data.f`.
#[inline(always)]
fn group(model: &Model, data: &mut LaneData, g: &crate::spatial::Motion) {
    let base = S {
        ang: V::splat(&g.angular),
        lin: V::splat(&g.linear),
    };
    for (i, b) in model.bodies.iter().enumerate() {
        let (rot, pos) = pose(b, data.qb[i]);
        let (vp, ap) = match b.parent {
            Some(p) => (data.v[p], data.a[p]),
            None => (S::default(), base),
        };
        let (mut v, mut a) = (act_inv(&rot, &pos, &vp), act_inv(&rot, &pos, &ap));
        // joint twist vj = S qd and acceleration S qdd
        let (vj, aj) = (V::of(&b.axis, data.vb[i]), V::of(&b.axis, data.ab[i]));
        match b.kind {
            JointKind::Revolute => {
                v.ang = v.ang.add(&vj);
                a.ang = a.ang.add(&aj);
                // a += v x vj with vj = (vj, 0): (w x vj, vlin x vj)
                a.ang = a.ang.add(&v.ang.cross(&vj));
                a.lin = a.lin.add(&v.lin.cross(&vj));
            }
            JointKind::Prismatic => {
                v.lin = v.lin.add(&vj);
                a.lin = a.lin.add(&aj);
                // v x (0, vj) = (0, w x vj)
                a.lin = a.lin.add(&v.ang.cross(&vj));
            }
        }
        // f = I a + v x* (I v)
        let (ia, h) = (apply(&b.inertia, &a), apply(&b.inertia, &v));
        data.f[i] = S {
            ang: ia.ang.add(&v.ang.cross(&h.ang)).add(&v.lin.cross(&h.lin)),
            lin: ia.lin.add(&v.ang.cross(&h.lin)),
        };
        data.rot[i] = rot;
        data.pos[i] = pos;
        data.v[i] = v;
        data.a[i] = a;
    }
    for i in (0..model.nbodies()).rev() {
        if let Some(p) = model.bodies[i].parent {
            let (rot, pos, f) = (&data.rot[i], &data.pos[i], data.f[i]);
            let lin = rot.mul(&f.lin);
            let ang = rot.mul(&f.ang).add(&pos.cross(&lin));
            data.f[p].ang = data.f[p].ang.add(&ang);
            data.f[p].lin = data.f[p].lin.add(&lin);
        }
    }
}

/// A motion given in the parent's frame expressed in the child's (pose `rot`, `pos`).
#[inline(always)]
fn act_inv(rot: &R, pos: &V, m: &S) -> S {
    S {
        ang: rot.tr_mul(&m.ang),
        lin: rot.tr_mul(&m.lin.sub(&pos.cross(&m.ang))),
    }
}

/// Momentum `I m` of a body of (constant) inertia `inertia` moving with twist `m`.
#[inline(always)]
fn apply(inertia: &crate::spatial::Inertia, m: &S) -> S {
    let com = V::splat(&inertia.com);
    let lin = m.lin.sub(&com.cross(&m.ang)).scale(inertia.mass);
    S {
        ang: m.ang.mul_const(&inertia.inertia_com).add(&com.cross(&lin)),
        lin,
    }
}

/// The pose of body `b` in its parent for the lane coordinates `x` (see `Body::pose_in_parent`).
#[inline(always)]
fn pose(b: &crate::model::Body, x: L) -> (R, V) {
    let p: &Se3 = &b.placement;
    match b.kind {
        JointKind::Revolute => {
            let (s, c) = sin_cos(x);
            let c1 = L::splat(1.0) - c;
            let t = &b.pose_terms;
            let row = |r: usize| {
                let e = |c: usize| s * t.r1[(r, c)] + c1 * t.r2[(r, c)] + p.rotation[(r, c)];
                V {
                    x: e(0),
                    y: e(1),
                    z: e(2),
                }
            };
            (R([row(0), row(1), row(2)]), V::splat(&p.translation))
        }
        JointKind::Prismatic => {
            let row = |r: usize| V {
                x: L::splat(p.rotation[(r, 0)]),
                y: L::splat(p.rotation[(r, 1)]),
                z: L::splat(p.rotation[(r, 2)]),
            };
            let t1 = &b.pose_terms.t1;
            (
                R([row(0), row(1), row(2)]),
                V::splat(&p.translation).add(&V::of(t1, x)),
            )
        }
    }
}
