//! Inverse dynamics of many samples: the recursive Newton-Euler algorithm of [`super::rnea`]
//! run on [`LANES`] samples side by side. Every quantity is stored as a structure of arrays
//! (one `[f64; LANES]` per scalar), so each operation of the recursion acts on a short vector of
//! samples that the compiler maps onto SIMD registers; the model's constants (placements,
//! axes, inertias) are shared by the lanes.

use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::error::Result;
use crate::gravity::Gravity;
pub use crate::lanes::LANES;
use crate::lanes::{simd_dispatch, sin_cos, Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes};
use crate::model::{JointKind, Model};
use crate::spatial::Se3;

/// Work buffers of [`rnea_lanes`] for one model (allocate once, reuse).
#[derive(Clone, Debug)]
pub struct LaneData {
    rot: Vec<Rotation3Lanes>,
    o_rot: Vec<Rotation3Lanes>,
    o_pos: Vec<Vector3Lanes>,
    o_s: Vec<SpatialLanes>,
    pos: Vec<Vector3Lanes>,
    v: Vec<SpatialLanes>,
    a: Vec<SpatialLanes>,
    f: Vec<SpatialLanes>,
    qb: Vec<Lanes>,
    vb: Vec<Lanes>,
    ab: Vec<Lanes>,
    /// The regressor of the loaded lanes, column-major `nv x 10 nbodies` (see
    /// [`regressor_batch`] and [`regressor_group`]), kept so that no call allocates.
    regressor: Vec<Lanes>,
    nv: usize,
}

impl LaneData {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        Self {
            rot: vec![Rotation3Lanes::default(); nb],
            o_rot: vec![Rotation3Lanes::default(); nb],
            o_pos: vec![Vector3Lanes::default(); nb],
            o_s: vec![SpatialLanes::default(); nb],
            pos: vec![Vector3Lanes::default(); nb],
            v: vec![SpatialLanes::default(); nb],
            a: vec![SpatialLanes::default(); nb],
            f: vec![SpatialLanes::default(); nb],
            qb: vec![Lanes::default(); nb],
            vb: vec![Lanes::default(); nb],
            ab: vec![Lanes::default(); nb],
            regressor: vec![Lanes::default(); model.nv * PARAMS_PER_BODY * nb],
            nv: model.nv,
        }
    }

    /// Entry `(joint, parameter)` (N m per parameter unit) of the regressor of sample `sample`
    /// of the group last given to [`regressor_group`]. Panics past the group's `LANES` samples
    /// or the model's sizes, like slice indexing.
    #[inline]
    pub fn regressor_entry(&self, sample: usize, joint: usize, parameter: usize) -> f64 {
        self.regressor[joint + parameter * self.nv].0[sample]
    }
}

simd_dispatch! {
/// Inverse dynamics `tau = M(q) qdd + c(q, qd) + g(q)` of a batch, [`LANES`] samples at a time.
///
/// - `q` (rad or m), `qd` (rad/s or m/s), `qdd` (rad/s^2 or m/s^2): row-major `k x nv`
///   (sample `s`, dof `j` at `s * nv + j`); `qd` or `qdd` `None` for zeros. All arguments
///   must hold the same `k` samples and finite values: check them first (a [`crate::States`]
///   is checked once for all); this kernel does not.
/// - `gravity`: include `g(q)`.
/// - `tau`: row-major `k x nv` output (N m or N).
///
/// Equal to [`crate::rnea`] sample by sample up to rounding.
///
/// On x86-64 processors with AVX2 and FMA (checked at run time) the kernel runs compiled for
/// them; elsewhere with the baseline instruction set.
pub fn rnea_lanes, rnea_lanes_avx2 => rnea_lanes_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: Gravity,
    tau: &mut [f64],
) -> Result<()>
}

#[inline(always)]
fn rnea_lanes_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: Gravity,
    tau: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    let (v, a) = (
        qd.map_or(q.len(), <[f64]>::len),
        qdd.map_or(q.len(), <[f64]>::len),
    );
    let k = samples(
        nv,
        q.len(),
        &[("qd", v, nv), ("qdd", a, nv), ("tau", tau.len(), nv)],
    )?;
    let g = model.base_acceleration(gravity);
    let mut first = 0;
    while first < k {
        load(
            model,
            data,
            [q, qd.unwrap_or(&[]), qdd.unwrap_or(&[])],
            first,
        );
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
        if let Some(qdd) = qdd {
            let r = first * nv..(first + used) * nv;
            for (t, a) in tau[r.clone()].chunks_mut(nv).zip(qdd[r].chunks(nv)) {
                model.add_armature_torque(a, t);
            }
        }
        first += LANES;
    }
    Ok(())
}

/// The number of samples `k` in `q` (`q_len` values, `k x nv`); checks that every other argument
/// `(name, length, values per sample)` holds `k` samples too.
fn samples(nv: usize, q_len: usize, others: &[(&str, usize, usize)]) -> Result<usize> {
    let k = q_len / nv.max(1);
    let shape = |name: &str, len: usize, per: usize| crate::error::Error::Shape {
        argument: name.into(),
        expected: format!("{k} samples x {per} values, like q"),
        got: format!("{len} values"),
    };
    if k * nv != q_len {
        return Err(shape("q", q_len, nv));
    }
    match others.iter().find(|(_, len, per)| *len != k * per) {
        Some(&(name, len, per)) => Err(shape(name, len, per)),
        None => Ok(k),
    }
}

/// Loads the body coordinates of samples `first..first + LANES` of the row-major `k x nv`
/// arrays `[q, qd, qdd]` (empty for zeros) into the lanes; past the last sample the lanes repeat
/// it.
#[inline(always)]
pub(crate) fn load(model: &Model, data: &mut LaneData, x: [&[f64]; 3], first: usize) {
    let nv = model.nv;
    let k = x[0].len() / nv.max(1);
    let lane = |l: usize| (first + l).min(k.max(1) - 1);
    for (i, b) in model.bodies.iter().enumerate() {
        let get = |x: &[f64], l: usize| {
            if x.is_empty() {
                0.0
            } else {
                b.multiplier * x[lane(l) * nv + b.dof]
            }
        };
        data.qb[i] = Lanes(std::array::from_fn(|l| get(x[0], l) + b.offset));
        data.vb[i] = Lanes(std::array::from_fn(|l| get(x[1], l)));
        data.ab[i] = Lanes(std::array::from_fn(|l| get(x[2], l)));
    }
}

/// One group of lanes: forward pass (poses, twists, accelerations, body wrenches) then the
/// backward pass accumulating the wrenches in `data.f`.
#[inline(always)]
fn group(model: &Model, data: &mut LaneData, g: &crate::spatial::Motion) {
    forward(model, data, g);
    for (i, b) in model.bodies.iter().enumerate() {
        // f = I a + v x* (I v)
        let (v, a) = (&data.v[i], &data.a[i]);
        let (ia, h) = (apply(&b.inertia, a), apply(&b.inertia, v));
        data.f[i] = SpatialLanes {
            ang: ia.ang.add(&v.ang.cross(&h.ang)).add(&v.lin.cross(&h.lin)),
            lin: ia.lin.add(&v.ang.cross(&h.lin)),
        };
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

/// The forward pass on the loaded coordinates: every body's pose in its parent (`rot`, `pos`),
/// twist `v` and acceleration `a` (gravity included as a base acceleration `g`) in its frame.
#[inline(always)]
fn forward(model: &Model, data: &mut LaneData, g: &crate::spatial::Motion) {
    let base = SpatialLanes {
        ang: Vector3Lanes::splat(&g.angular),
        lin: Vector3Lanes::splat(&g.linear),
    };
    for (i, b) in model.bodies.iter().enumerate() {
        let (rot, pos) = pose(b, data.qb[i]);
        let (vp, ap) = match b.parent {
            Some(p) => (data.v[p], data.a[p]),
            None => (SpatialLanes::default(), base),
        };
        let (mut v, mut a) = (act_inv(&rot, &pos, &vp), act_inv(&rot, &pos, &ap));
        // joint twist vj = S qd and acceleration S qdd
        let (vj, aj) = (
            Vector3Lanes::of(&b.axis, data.vb[i]),
            Vector3Lanes::of(&b.axis, data.ab[i]),
        );
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
        data.rot[i] = rot;
        data.pos[i] = pos;
        data.v[i] = v;
        data.a[i] = a;
    }
}

simd_dispatch! {
/// The joint-torque regressor of a batch, [`LANES`] samples at a time: `out` (row-major
/// `k x nv x 10 nbodies`, N m per parameter unit) holds for every sample the matrix that
/// [`crate::algorithms::regressor::joint_torque_regressor`] gives, up to rounding.
///
/// `q`, `qd`, `qdd`: row-major `k x nv` (rad, rad/s, rad/s^2), finite (checked by the caller, as
/// for [`rnea_lanes`]); `gravity` includes gravity. Uses AVX2 and FMA when the processor has
/// them.
pub fn regressor_batch, regressor_batch_avx2 => regressor_batch_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: &mut [f64],
) -> Result<()>
}

#[inline(always)]
fn regressor_batch_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    let p = PARAMS_PER_BODY * model.nbodies();
    let k = samples(
        nv,
        q.len(),
        &[
            ("qd", qd.len(), nv),
            ("qdd", qdd.len(), nv),
            ("regressor output", out.len(), nv * p),
        ],
    )?;
    let mut first = 0;
    while first < k {
        group_regressor(model, data, [q, qd, qdd], first, gravity);
        for l in 0..(k - first).min(LANES) {
            let o = &mut out[(first + l) * nv * p..(first + l + 1) * nv * p];
            for r in 0..nv {
                for c in 0..p {
                    o[r * p + c] = data.regressor_entry(l, r, c);
                }
            }
        }
        first += LANES;
    }
    Ok(())
}

/// Loads the samples `first..first + LANES` of `[q, qd, qdd]` (see [`load`]) and leaves their
/// regressors in `data.regressor`.
#[inline(always)]
fn group_regressor(
    model: &Model,
    data: &mut LaneData,
    x: [&[f64]; 3],
    first: usize,
    gravity: Gravity,
) {
    let mut y = std::mem::take(&mut data.regressor);
    load(model, data, x, first);
    regressor_lanes(model, data, gravity, &mut y);
    data.regressor = y;
}

simd_dispatch! {
/// The joint-torque regressors of a group of 1 to [`LANES`] samples, left in `data` and read
/// with [`LaneData::regressor_entry`]: the building block for work that reduces the regressor
/// as it is made (the streaming identification), without the copy into a row-major array that
/// [`regressor_batch`] makes.
///
/// `q`, `qd`, `qdd`: row-major `g x nv` (rad, rad/s, rad/s^2), finite (checked by the caller).
/// Returns `g`. Uses AVX2 and FMA when the processor has them.
pub fn regressor_group, regressor_group_avx2 => regressor_group_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<usize>
}

#[inline(always)]
fn regressor_group_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<usize> {
    let nv = model.nv;
    let k = samples(nv, q.len(), &[("qd", qd.len(), nv), ("qdd", qdd.len(), nv)])?;
    if k == 0 || k > LANES {
        return Err(crate::error::Error::Shape {
            argument: "q".into(),
            expected: format!("1 to {LANES} samples of {nv} joints"),
            got: format!("{k} samples"),
        });
    }
    group_regressor(model, data, [q, qd, qdd], 0, gravity);
    Ok(k)
}

simd_dispatch! {
/// Joint-space mass matrices `M(q)` of a batch, [`LANES`] samples at a time (the composite
/// rigid body algorithm in the base frame, as [`crate::mass_matrix`]; equal to it up to
/// rounding).
///
/// `q`: row-major `k x nv` (rad or m), finite (checked by the caller, as for [`rnea_lanes`]).
/// `out`: row-major `k x nv x nv` (kg m^2, kg m or kg), both triangles written. Uses AVX2 and
/// FMA when the processor has them.
pub fn mass_matrix_batch, mass_matrix_batch_avx2 => mass_matrix_batch_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    out: &mut [f64],
) -> Result<()>
}

/// A composite inertia per lane in origin form (mass, first moment `h`, rotational inertia `i`
/// about the origin, by rows); the mass is the same in every lane.
#[derive(Clone, Copy, Debug, Default)]
struct Composite {
    mass: f64,
    h: Vector3Lanes,
    i: Rotation3Lanes,
}

#[inline(always)]
fn mass_matrix_batch_body(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    let nb = model.nbodies();
    let k = samples(nv, q.len(), &[("mass matrix output", out.len(), nv * nv)])?;
    let mut m = vec![Lanes::default(); nb * nb]; // body-level, row-major
    let mut ic = vec![Composite::default(); nb];
    let mut first = 0;
    while first < k {
        load(model, data, [q, &[], &[]], first);
        // base-frame poses, motion subspaces and body inertias
        for (i, b) in model.bodies.iter().enumerate() {
            let (rot, pos) = pose(b, data.qb[i]);
            let (r, p) = place_in_base(model, data, i, &rot, &pos);
            ic[i] = transformed(&b.origin_inertia, &r, &p);
        }
        m.fill(Lanes::default());
        for i in (0..nb).rev() {
            let (c, s) = (&ic[i], &data.o_s[i]);
            let f = SpatialLanes {
                ang: c.i.mul(&s.ang).add(&c.h.cross(&s.lin)),
                lin: s.lin.scale(c.mass).sub(&c.h.cross(&s.ang)),
            };
            let mut j = Some(i);
            while let Some(k) = j {
                let sk = &data.o_s[k];
                let mik = sk.ang.dot(&f.ang) + sk.lin.dot(&f.lin);
                m[i * nb + k] = mik;
                m[k * nb + i] = mik;
                j = model.bodies[k].parent;
            }
            if let Some(p) = model.bodies[i].parent {
                let child = ic[i];
                let parent = &mut ic[p];
                parent.mass += child.mass;
                parent.h = parent.h.add(&child.h);
                for r in 0..3 {
                    parent.i.0[r] = parent.i.0[r].add(&child.i.0[r]);
                }
            }
        }
        // onto the degrees of freedom (mimic couplings), for the lanes in use
        for l in 0..(k - first).min(LANES) {
            let o = &mut out[(first + l) * nv * nv..(first + l + 1) * nv * nv];
            if model.coupled {
                o.fill(0.0);
                for (i, bi) in model.bodies.iter().enumerate() {
                    for (j, bj) in model.bodies.iter().enumerate() {
                        o[bi.dof * nv + bj.dof] +=
                            bi.multiplier * bj.multiplier * m[i * nb + j].0[l];
                    }
                }
            } else {
                for (x, v) in o.iter_mut().zip(&m) {
                    *x = v.0[l];
                }
            }
            model.add_armature_inertia(o);
        }
        first += LANES;
    }
    Ok(())
}

/// Body `i`'s pose in the base frame from its pose `rot`, `pos` in its parent (whose base-frame
/// pose is already in `data`): stores it with the motion subspace there (`o_rot`, `o_pos`,
/// `o_s`) and returns it.
#[inline(always)]
fn place_in_base(
    model: &Model,
    data: &mut LaneData,
    i: usize,
    rot: &Rotation3Lanes,
    pos: &Vector3Lanes,
) -> (Rotation3Lanes, Vector3Lanes) {
    let b = &model.bodies[i];
    let (r, p) = match b.parent {
        Some(k) => {
            let (rp, pp) = (&data.o_rot[k], &data.o_pos[k]);
            (rp.compose(rot), pp.add(&rp.mul(pos)))
        }
        None => (*rot, *pos),
    };
    data.o_s[i] = subspace_in(b, &r, &p);
    data.o_rot[i] = r;
    data.o_pos[i] = p;
    (r, p)
}

/// Body `b`'s motion subspace in the base frame, for its base-frame pose `r`, `p`.
#[inline(always)]
fn subspace_in(b: &crate::model::Body, r: &Rotation3Lanes, p: &Vector3Lanes) -> SpatialLanes {
    let axis = r.mul_const_vector(&b.axis);
    match b.kind {
        JointKind::Revolute => SpatialLanes {
            ang: axis,
            lin: p.cross(&axis),
        },
        JointKind::Prismatic => SpatialLanes {
            ang: Vector3Lanes::default(),
            lin: axis,
        },
    }
}

/// A body's (constant) origin-form inertia expressed in the base frame, for its pose `r`, `p`
/// there (see `OriginInertia::transformed`).
#[inline(always)]
fn transformed(
    b: &crate::spatial::OriginInertia,
    r: &Rotation3Lanes,
    p: &Vector3Lanes,
) -> Composite {
    let hr = r.mul_const_vector(&b.h);
    let w = hr.add(&p.scale(0.5 * b.mass));
    let d = p.dot(&w) * 2.0;
    let ri = [0, 1, 2].map(|row| r.0[row].mul_const(&b.i)); // rows of R I (I symmetric)
    let pw = [p.x, p.y, p.z];
    let ww = [w.x, w.y, w.z];
    let mut i = Rotation3Lanes::default();
    for row in 0..3 {
        let e = |c: usize| {
            let v = ri[row].dot(&r.0[c]) - ww[row] * pw[c] - pw[row] * ww[c];
            if c == row {
                v + d
            } else {
                v
            }
        };
        i.0[row] = Vector3Lanes {
            x: e(0),
            y: e(1),
            z: e(2),
        };
    }
    Composite {
        mass: b.mass,
        h: hr.add(&p.scale(b.mass)),
        i,
    }
}

/// The joint-torque regressor (see [`crate::algorithms::regressor::joint_torque_regressor`]) of
/// the loaded group of lanes (see [`load`]): `out` column-major `nv x 10 nbodies`, one lane per
/// sample, every entry written. `gravity` includes gravity.
#[inline(always)]
pub(crate) fn regressor_lanes(
    model: &Model,
    data: &mut LaneData,
    gravity: Gravity,
    out: &mut [Lanes],
) {
    let nv = model.nv;
    forward(model, data, &model.base_acceleration(gravity));
    out.fill(Lanes::default());
    for i in 0..model.nbodies() {
        let (rot, pos) = (data.rot[i], data.pos[i]);
        let (r, p) = place_in_base(model, data, i, &rot, &pos);
        // the body's 10 columns in the base frame (see `world_body_regressor`)
        let (v, a) = (&data.v[i], &data.a[i]);
        let (w, al) = (v.ang, a.ang);
        let ac = r.mul(&a.lin.add(&w.cross(&v.lin)));
        let (ww, alw) = (r.mul(&w), r.mul(&al));
        let w2 = w.x * w.x + w.y * w.y + w.z * w.z;
        let mut cols = [SpatialLanes::default(); 10];
        cols[0] = SpatialLanes {
            ang: p.cross(&ac),
            lin: ac,
        };
        let wk = [w.x, w.y, w.z];
        for (k, &wkk) in wk.iter().enumerate() {
            let rk = r.column(k);
            let lin = alw
                .cross(&rk)
                .add(&ww.mul_lanes(wkk))
                .sub(&rk.mul_lanes(w2));
            cols[1 + k] = SpatialLanes {
                ang: rk.cross(&ac).add(&p.cross(&lin)),
                lin,
            };
        }
        // I_q x for the unit inertias of [Ixx, Ixy, Iyy, Ixz, Iyz, Izz], then rotated
        let z = Lanes::default();
        let unit = |x: &Vector3Lanes| {
            [
                Vector3Lanes { x: x.x, y: z, z },
                Vector3Lanes { x: x.y, y: x.x, z },
                Vector3Lanes { x: z, y: x.y, z },
                Vector3Lanes {
                    x: x.z,
                    y: z,
                    z: x.x,
                },
                Vector3Lanes {
                    x: z,
                    y: x.z,
                    z: x.y,
                },
                Vector3Lanes { x: z, y: z, z: x.z },
            ]
        };
        let (ia, iw) = (unit(&al), unit(&w));
        for q in 0..6 {
            cols[4 + q].ang = r.mul(&ia[q].add(&w.cross(&iw[q])));
        }
        // project on the motion subspaces of the body and its ancestors
        let first = PARAMS_PER_BODY * i * nv;
        let mut j = Some(i);
        while let Some(k) = j {
            let bk = &model.bodies[k];
            let sk = &data.o_s[k];
            let at = |c: usize| first + c * nv + bk.dof;
            for (c, f) in cols[..4].iter().enumerate() {
                let t = sk.ang.dot(&f.ang) + sk.lin.dot(&f.lin);
                out[at(c)] = out[at(c)] + t * bk.multiplier;
            }
            for (c, f) in cols[4..].iter().enumerate() {
                let t = sk.ang.dot(&f.ang);
                out[at(4 + c)] = out[at(4 + c)] + t * bk.multiplier;
            }
            j = bk.parent;
        }
    }
}

/// A motion given in the parent's frame expressed in the child's (pose `rot`, `pos`).
#[inline(always)]
fn act_inv(rot: &Rotation3Lanes, pos: &Vector3Lanes, m: &SpatialLanes) -> SpatialLanes {
    SpatialLanes {
        ang: rot.tr_mul(&m.ang),
        lin: rot.tr_mul(&m.lin.sub(&pos.cross(&m.ang))),
    }
}

/// Momentum `I m` of a body of (constant) inertia `inertia` moving with twist `m`.
#[inline(always)]
fn apply(inertia: &crate::spatial::Inertia, m: &SpatialLanes) -> SpatialLanes {
    let com = Vector3Lanes::splat(&inertia.com);
    let lin = m.lin.sub(&com.cross(&m.ang)).scale(inertia.mass);
    SpatialLanes {
        ang: m.ang.mul_const(&inertia.inertia_com).add(&com.cross(&lin)),
        lin,
    }
}

/// The pose of body `b` in its parent for the lane coordinates `x` (see `Body::pose_in_parent`).
#[inline(always)]
fn pose(b: &crate::model::Body, x: Lanes) -> (Rotation3Lanes, Vector3Lanes) {
    let p: &Se3 = &b.placement;
    match b.kind {
        JointKind::Revolute => {
            let (s, c) = sin_cos(x);
            let c1 = Lanes::splat(1.0) - c;
            let t = &b.pose_terms;
            let row = |r: usize| {
                let e = |c: usize| s * t.r1[(r, c)] + c1 * t.r2[(r, c)] + p.rotation[(r, c)];
                Vector3Lanes {
                    x: e(0),
                    y: e(1),
                    z: e(2),
                }
            };
            (
                Rotation3Lanes([row(0), row(1), row(2)]),
                Vector3Lanes::splat(&p.translation),
            )
        }
        JointKind::Prismatic => {
            let row = |r: usize| Vector3Lanes {
                x: Lanes::splat(p.rotation[(r, 0)]),
                y: Lanes::splat(p.rotation[(r, 1)]),
                z: Lanes::splat(p.rotation[(r, 2)]),
            };
            let t1 = &b.pose_terms.t1;
            (
                Rotation3Lanes([row(0), row(1), row(2)]),
                Vector3Lanes::splat(&p.translation).add(&Vector3Lanes::of(t1, x)),
            )
        }
    }
}
