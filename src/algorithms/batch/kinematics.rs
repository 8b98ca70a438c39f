//! The pieces the multi-sample kernels share: joint poses, the forward pass of twists and
//! accelerations, base-frame poses and motion subspaces, on `W` lanes.

use super::LaneBuffers;
use crate::model::{AlignedRevolute, Body, JointKind, Model, TurnedFrame};
use crate::simd::{
    serial, sin_cos, write_rows, Lanes, Rotation3Lanes, SpatialLanes, Stores, Vector3Lanes,
};
use crate::spatial::{Inertia, Motion, Se3};

/// The pose of body `b` in its parent (rotation by rows, translation) for the lane coordinates
/// `x` (rad or m; see `Body::pose_in_parent`), `(s, c)` the sine and cosine of `x` (used for a
/// revolute joint only).
#[inline(always)]
pub(crate) fn pose<const W: usize>(
    b: &Body,
    x: Lanes<W>,
    (s, c): (Lanes<W>, Lanes<W>),
) -> (Rotation3Lanes<W>, Vector3Lanes<W>) {
    let p: &Se3 = &b.placement;
    match b.kind {
        JointKind::Revolute => {
            let c1 = Lanes::splat(1.0) - c;
            let t = &b.pose_terms;
            let mut rot = Rotation3Lanes::default();
            for (r, row) in serial(rot.0.iter_mut().enumerate()) {
                let mut e = [Lanes::default(); 3];
                for (k, ek) in serial(e.iter_mut().enumerate()) {
                    let r0 = Lanes::splat(p.rotation[(r, k)]);
                    *ek = s.mul_add_s(t.r1[(r, k)], c1.mul_add_s(t.r2[(r, k)], r0));
                }
                *row = Vector3Lanes {
                    x: e[0],
                    y: e[1],
                    z: e[2],
                };
            }
            (rot, Vector3Lanes::splat(&p.translation))
        }
        JointKind::Prismatic => {
            // (no `map` closure: LLVM kept it out of line, a call per prismatic joint)
            let rot = Rotation3Lanes([
                Vector3Lanes::splat(&p.rotation.row(0).transpose()),
                Vector3Lanes::splat(&p.rotation.row(1).transpose()),
                Vector3Lanes::splat(&p.rotation.row(2).transpose()),
            ]);
            let t1 = &b.pose_terms.t1;
            (
                rot,
                Vector3Lanes::of(t1, x).add(&Vector3Lanes::splat(&p.translation)),
            )
        }
    }
}

/// A motion given in the parent's frame expressed in the child's (pose `rot`, `pos`).
#[inline(always)]
pub(crate) fn act_inv<const W: usize>(
    rot: &Rotation3Lanes<W>,
    pos: &Vector3Lanes<W>,
    m: &SpatialLanes<W>,
) -> SpatialLanes<W> {
    SpatialLanes {
        ang: rot.tr_mul(&m.ang),
        lin: rot.tr_mul(&m.lin.sub(&pos.cross(&m.ang))),
    }
}

/// Momentum `I m` of a body of (constant) inertia `inertia` moving with twist `m`.
#[inline(always)]
pub(crate) fn apply<const W: usize>(inertia: &Inertia, m: &SpatialLanes<W>) -> SpatialLanes<W> {
    // lin = mass (v - c x w) = mass (v + w x c)
    let lin = m
        .ang
        .cross_const(&inertia.com)
        .add(&m.lin)
        .scale(inertia.mass);
    // ang = I_c w + c x lin
    let c = &inertia.com;
    let cx = Vector3Lanes {
        x: lin.z.mul_add_s(c.y, lin.y * -c.z),
        y: lin.x.mul_add_s(c.z, lin.z * -c.x),
        z: lin.y.mul_add_s(c.x, lin.x * -c.y),
    };
    SpatialLanes {
        ang: m.ang.mul_const(&inertia.inertia_com).add(&cx),
        lin,
    }
}

/// The forward pass on the loaded coordinates: every body's pose in its parent (`rot`, `pos`;
/// for an axis-aligned revolute joint only the cosine and sine of its turn, `cos_sin`: see
/// [`aligned_to_parent`] and [`aligned_pose_in_base`] for what takes them), twist `v` and
/// acceleration `a` (gravity included as a base acceleration `g`) in its frame.
#[inline(always)]
pub(crate) fn forward<const W: usize>(model: &Model, data: &mut LaneBuffers<W>, g: &Motion) {
    let base = SpatialLanes {
        ang: Vector3Lanes::splat(&g.angular),
        lin: Vector3Lanes::splat(&g.linear),
    };
    for (i, b) in serial(model.bodies.iter().enumerate()) {
        if let Some(al) = &b.pose_terms.aligned {
            aligned_forward(b, al, data, i, &base);
            continue;
        }
        let x = data.qb[i];
        // (a prismatic joint's pose takes no sine or cosine: none computed)
        let sc = match b.kind {
            JointKind::Revolute => sin_cos(x),
            JointKind::Prismatic => (Lanes::default(), Lanes::default()),
        };
        let (rot, pos) = pose(b, x, sc);
        let (mut v, mut a) = match b.parent {
            Some(p) => (
                act_inv(&rot, &pos, &data.v[p]),
                act_inv(&rot, &pos, &data.a[p]),
            ),
            None => (SpatialLanes::default(), act_inv(&rot, &pos, &base)),
        };
        // joint twist vj = S qd and acceleration S qdd
        let (vj, aj) = (
            Vector3Lanes::of(&b.axis, data.vb[i]),
            Vector3Lanes::of(&b.axis, data.ab[i]),
        );
        match b.kind {
            JointKind::Revolute => {
                v.ang = v.ang.add(&vj);
                // a += S qdd + v x (vj, 0) = (w x vj, vlin x vj)
                a.ang = a.ang.add(&aj).add(&v.ang.cross(&vj));
                a.lin = a.lin.add(&v.lin.cross(&vj));
            }
            JointKind::Prismatic => {
                v.lin = v.lin.add(&vj);
                // v x (0, vj) = (0, w x vj)
                a.lin = a.lin.add(&aj).add(&v.ang.cross(&vj));
            }
        }
        data.rot[i] = rot;
        data.pos[i] = pos;
        data.v[i] = v;
        data.a[i] = a;
    }
}

/// The forward step of body `i`, whose revolute joint is axis-aligned (`al`): `R = R0 Rot_k`,
/// with `R0` a signed permutation, so that the parent's twist and acceleration are read by
/// index, permuted, and turned about one axis (5 products a vector instead of a 3x3 one), and
/// the joint's own terms touch one or two components. Stores `v`, `a` and `cos_sin` of body
/// `i` (not `rot`, `pos`); the parent's motion is `base` (with no twist) for a root body.
#[inline(always)]
fn aligned_forward<const W: usize>(
    b: &Body,
    al: &AlignedRevolute,
    data: &mut LaneBuffers<W>,
    i: usize,
    base: &SpatialLanes<W>,
) {
    let (s, c) = sin_cos(data.qb[i]);
    let s = s * al.sign;
    data.cos_sin[i] = [c, s];
    let turn = al.turn([c, s]);
    let pos = &b.placement.translation;
    let still = SpatialLanes::default();
    let (vp, ap) = match b.parent {
        Some(p) => (&data.v[p], &data.a[p]),
        None => (&still, base),
    };
    // by role (k, a, b): k the joint axis
    let [mut vang, vlin] = aligned_in_child(al, pos, &turn, vp);
    let [mut aang, mut alin] = aligned_in_child(al, pos, &turn, ap);
    // the joint: v += w e_k, a += qdd e_k + v x (w e_k), where (v x e_k) = (0, v_b, -v_a)
    let w = data.vb[i] * al.sign;
    vang[0] = vang[0] + w;
    aang[0] = data.ab[i].mul_add_s(al.sign, aang[0]);
    aang[1] = vang[2].mul_add(w, aang[1]);
    aang[2] = vang[1].neg_mul_add(w, aang[2]);
    alin[1] = vlin[2].mul_add(w, alin[1]);
    alin[2] = vlin[1].neg_mul_add(w, alin[2]);
    let (v, a) = (&mut data.v[i], &mut data.a[i]);
    for (j, &r) in al.roles.iter().enumerate() {
        *v.ang.at_mut(r) = vang[j];
        *v.lin.at_mut(r) = vlin[j];
        *a.ang.at_mut(r) = aang[j];
        *a.lin.at_mut(r) = alin[j];
    }
}

impl AlignedRevolute {
    /// `Rot_k^T`'s entries times `R0`'s signs, `[c s_a, s s_b, s s_a, c s_b]`, from the turn's
    /// `[cos x, sign sin x]` (as the forward pass keeps them): what [`aligned_in_child`] takes.
    #[inline(always)]
    pub(crate) fn turn<const W: usize>(&self, [c, s]: [Lanes<W>; 2]) -> [Lanes<W>; 4] {
        let [sa, sb] = [self.signs[1], self.signs[2]];
        [c * sa, s * sb, s * sa, c * sb]
    }
}

/// The motion `m` of an aligned joint's parent (in the parent's frame, in memory) in the
/// child's frame, `R^T (m.ang, m.lin - p x m.ang)` with `R = R0 Rot_k`, by role `(k, a, b)`:
/// `[angular, linear]`. `turn` holds `[c s_a, s s_b, s s_a, c s_b]` (cosine, sine, and the
/// signs of `R0`'s columns a and b).
#[inline(always)]
fn aligned_in_child<const W: usize>(
    al: &AlignedRevolute,
    pos: &nalgebra::Vector3<f64>,
    turn: &[Lanes<W>; 4],
    m: &SpatialLanes<W>,
) -> [[Lanes<W>; 3]; 2] {
    let (ang, lin) = (&m.ang, &m.lin);
    let mut raw = [[Lanes::default(); 3]; 2];
    for (j, &r) in al.rows.iter().enumerate() {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        raw[0][j] = *ang.at(r);
        // (lin - p x ang)[r] = lin[r] - p[r1] ang[r2] + p[r2] ang[r1]
        raw[1][j] = ang
            .at(r1)
            .mul_add_s(pos[r2], ang.at(r2).mul_add_s(-pos[r1], *lin.at(r)));
    }
    let [x, y] = raw;
    [turned(x, al.signs[0], turn), turned(y, al.signs[0], turn)]
}

/// `Rot_k^T R0^T v` by role `(k, a, b)` for an aligned joint, from `x`, the components of `v`
/// that `R0` sends to the roles (`v[rows[j]]`, unsigned): `R0^T v = (s_k x_0, s_a x_1, s_b
/// x_2)`, and `Rot_k^T` turns `(a, b)` by -angle; `turn` as [`AlignedRevolute::turn`] gives it
/// (the signs `s_a`, `s_b` folded in). No closure, no `map`: one compiled out of line would
/// lose the instruction set.
#[inline(always)]
pub(crate) fn turned<const W: usize>(
    x: [Lanes<W>; 3],
    sign_k: f64,
    turn: &[Lanes<W>; 4],
) -> [Lanes<W>; 3] {
    let [ca, sb, sa, cb] = *turn;
    [
        x[0] * sign_k,
        ca.mul_add(x[1], sb * x[2]),
        cb.mul_sub(x[2], sa * x[1]),
    ]
}

/// The backward step of an aligned joint (see [`aligned_forward`]): adds body `i`'s wrench
/// `f` (its frame) to its parent's `fp` (the parent's frame), `(R f.ang + p x R f.lin,
/// R f.lin)`, turning about one axis and permuting into the parent's components by index.
/// `cos_sin` as the forward step stored it.
#[inline(always)]
pub(crate) fn aligned_to_parent<const W: usize>(
    al: &AlignedRevolute,
    [c, s]: [Lanes<W>; 2],
    f: &SpatialLanes<W>,
    fp: &mut SpatialLanes<W>,
) {
    let [k, a, b] = al.roles;
    let (fa, fl) = (&f.ang, &f.lin);
    // Rot_k by role: (x_k, c x_a - s x_b, s x_a + c x_b)
    let y = [
        *fl.at(k),
        c.mul_sub(*fl.at(a), s * *fl.at(b)),
        s.mul_add(*fl.at(a), c * *fl.at(b)),
    ];
    let ra = [
        *fa.at(k),
        c.mul_sub(*fa.at(a), s * *fa.at(b)),
        s.mul_add(*fa.at(a), c * *fa.at(b)),
    ];
    // z = Rot f.ang + p' x y with p' = R0^T p by role
    let p = al.p_roles;
    let z = [
        y[2].mul_add_s(p[1], y[1].mul_add_s(-p[2], ra[0])),
        y[0].mul_add_s(p[2], y[2].mul_add_s(-p[0], ra[1])),
        y[1].mul_add_s(p[0], y[0].mul_add_s(-p[1], ra[2])),
    ];
    // R0 x = sum_j s_j x_j e_{r_j}
    for (j, &r) in al.rows.iter().enumerate() {
        *fp.lin.at_mut(r) = y[j].mul_add_s(al.signs[j], *fp.lin.at(r));
        *fp.ang.at_mut(r) = z[j].mul_add_s(al.signs[j], *fp.ang.at(r));
    }
}

/// Body `i`'s pose in the base frame for its loaded coordinate, stored with the motion subspace
/// there (`o_rot`, `o_pos`, `o_s`, as by [`place_in_base`]). A revolute joint with an
/// axis-aligned placement below another body takes columns of its parent's base rotation,
/// scaled by the cosine and sine (no 3x3 product); the others go through [`pose`] and
/// [`place_in_base`]. Every revolute joint's sine and cosine are read from
/// `data.sin_cos` (loaded with [`super::Trig::Loaded`]).
#[inline(always)]
pub(crate) fn store_pose_in_base<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    i: usize,
) {
    let b = &model.bodies[i];
    // (set for revolute joints only)
    let (Some(al), Some(parent)) = (&b.pose_terms.aligned, b.parent) else {
        let (rot, pos) = pose(b, data.qb[i], data.sin_cos[i]);
        place_in_base(model, data, i, &rot, &pos);
        return;
    };
    let (s, c) = data.sin_cos[i];
    aligned_pose_in_base(model, data, i, al, parent, [c, s * al.sign]);
}

/// Body `i`'s turned frame (`t`, see [`TurnedFrame`]) in the base frame for its loaded
/// coordinate, stored as [`store_pose_in_base`] stores a frame (`o_rot`, `o_pos`, `o_s`); the
/// parent's stored frame must be its turned one if it has one. A revolute joint's sine and
/// cosine are read from `data.sin_cos`. The subspace is the rotation's third column (the joint
/// axis is the turned frame's z).
#[inline(always)]
pub(crate) fn store_turned_pose_in_base<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    i: usize,
    t: &TurnedFrame,
) {
    let b = &model.bodies[i];
    let column = |j: usize| Vector3Lanes::splat(&t.rot.column(j).into_owned());
    // the turned frame's x and y axes at the joint's coordinate in the parent's turned frame
    // (C Rot_z(x)'s columns c c_0 + s c_1 and c c_1 - s c_0 for a revolute joint, C's own for a
    // prismatic one), and the joint's origin there where it moves
    let (x_axis, y_axis, origin) = match b.kind {
        JointKind::Revolute => {
            let (sn, cs) = data.sin_cos[i];
            let (c0, c1) = (column(0), column(1));
            let x = c0.mul_lanes_add(cs, &c1.mul_lanes(sn));
            (x, c1.mul_lanes(cs).sub(&c0.mul_lanes(sn)), None)
        }
        JointKind::Prismatic => (
            column(0),
            column(1),
            Some(Vector3Lanes::of(&t.slide, data.qb[i]).add(&Vector3Lanes::splat(&t.pos))),
        ),
    };
    // in the base frame: those formed from the coordinate alone, then turned by the parent's
    // rotation, so that a pose waits on its parent's for one product (three dependent
    // operations a link, where the parent's rotation times C and then Rot_z took five, with
    // as many operations in all; whole builds alternated on a Zen 4: the tree's AVX2 mass
    // matrix 2-4 % faster, faster in 10 of 12 pairs; AVX-512, derivatives and linearisation
    // level)
    let (x, y, axis, p) = match b.parent {
        Some(k) => {
            let (rp, pp) = (&data.o_rot[k], &data.o_pos[k]);
            let p = match &origin {
                Some(o) => rp.mul_add(o, pp),
                None => rp.mul_const_vector_add(&t.pos, pp),
            };
            (
                rp.mul(&x_axis),
                rp.mul(&y_axis),
                rp.mul_const_vector(&t.rot.column(2).into_owned()),
                p,
            )
        }
        None => (
            x_axis,
            y_axis,
            column(2),
            origin.unwrap_or_else(|| Vector3Lanes::splat(&t.pos)),
        ),
    };
    subspace_of(b.kind, axis, &p).put(&mut data.o_s[i]);
    Rotation3Lanes::from_columns(&x, &y, &axis).put(&mut data.o_rot[i]);
    p.put(&mut data.o_pos[i]);
}

/// [`store_pose_in_base`] for body `i` below `parent` with an aligned joint `al`, given the
/// cosine and sine of its turn (`[cos x, sign sin x]`, as the forward pass keeps them).
#[inline(always)]
pub(crate) fn aligned_pose_in_base<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    i: usize,
    al: &AlignedRevolute,
    parent: usize,
    [c, s]: [Lanes<W>; 2],
) {
    let b = &model.bodies[i];
    let rp = &data.o_rot[parent];
    // R = Rp R0 Rot_k(sign x): column roles[j] of Rp R0 is signs[j] times column rows[j] of Rp
    // (read from memory by index)
    let column = |m: usize| Vector3Lanes {
        x: *rp.0[0].at(m),
        y: *rp.0[1].at(m),
        z: *rp.0[2].at(m),
    };
    let [k, a, bb] = al.roles;
    let (pa, pb) = (column(al.rows[1]), column(al.rows[2]));
    let pk = column(al.rows[0]).scale(al.signs[0]);
    let (ca, cb) = (c * al.signs[1], c * al.signs[2]);
    let (sa, sb) = (s * al.signs[1], s * al.signs[2]);
    // Rot_k e_a = cos e_a + sin e_b, Rot_k e_b = cos e_b - sin e_a
    let col_a = pa.mul_lanes_add(ca, &pb.mul_lanes(sb));
    let col_b = pb.mul_lanes(cb).sub(&pa.mul_lanes(sa));
    let p = rp.mul_const_vector_add(&b.placement.translation, &data.o_pos[parent]);
    let axis = pk.scale(al.sign);
    SpatialLanes {
        ang: axis,
        lin: p.cross(&axis),
    }
    .put(&mut data.o_s[i]);
    p.put(&mut data.o_pos[i]);
    let r = &mut data.o_rot[i];
    for (row, (ea, eb, ek)) in [
        (col_a.x, col_b.x, pk.x),
        (col_a.y, col_b.y, pk.y),
        (col_a.z, col_b.z, pk.z),
    ]
    .into_iter()
    .enumerate()
    {
        let row = &mut r.0[row];
        ea.put(row.at_mut(a));
        eb.put(row.at_mut(bb));
        ek.put(row.at_mut(k));
    }
}

/// Body `i`'s pose in the base frame from its pose `rot`, `pos` in its parent (whose base-frame
/// pose is already in `data`): stores it with the motion subspace there (`o_rot`, `o_pos`,
/// `o_s`) and returns it.
#[inline(always)]
pub(crate) fn place_in_base<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    i: usize,
    rot: &Rotation3Lanes<W>,
    pos: &Vector3Lanes<W>,
) -> (Rotation3Lanes<W>, Vector3Lanes<W>) {
    let b = &model.bodies[i];
    let (r, p) = match b.parent {
        Some(k) => {
            let (rp, pp) = (&data.o_rot[k], &data.o_pos[k]);
            (rp.compose(rot), rp.mul_add(pos, pp))
        }
        None => (*rot, *pos),
    };
    subspace_in(b, &r, &p).put(&mut data.o_s[i]);
    r.put(&mut data.o_rot[i]);
    p.put(&mut data.o_pos[i]);
    (r, p)
}

/// Body `b`'s motion subspace in the base frame, for its base-frame pose `r`, `p`.
#[inline(always)]
pub(crate) fn subspace_in<const W: usize>(
    b: &Body,
    r: &Rotation3Lanes<W>,
    p: &Vector3Lanes<W>,
) -> SpatialLanes<W> {
    subspace_of(b.kind, r.mul_const_vector(&b.axis), p)
}

/// A joint's motion subspace in the base frame from its unit axis `axis` there and its origin
/// `p` (m): `(axis, p x axis)` for a revolute joint, `(0, axis)` for a prismatic one.
#[inline(always)]
fn subspace_of<const W: usize>(
    kind: JointKind,
    axis: Vector3Lanes<W>,
    p: &Vector3Lanes<W>,
) -> SpatialLanes<W> {
    match kind {
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

/// Writes the joint torques of lanes `0..used` (samples `first..first + used`) into the
/// row-major `tau` from the body wrenches `f` (in the body frames): `tau_dof += multiplier *
/// S^T f`, plus the armature's `armature * qdd` for a model that is not coupled (`qdd` the
/// loaded body accelerations; a coupled model's is the caller's). `body_tau` (one per body) is
/// work space. Returns whether every torque written was checked finite (always false for a
/// coupled model, whose torques are not checked here). `stores` as for `write_rows`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn contract_torques<const W: usize>(
    model: &Model,
    f: &[SpatialLanes<W>],
    qdd: &[Lanes<W>],
    body_tau: &mut [Lanes<W>],
    first: usize,
    used: usize,
    tau: &mut [f64],
    stores: Stores,
) -> bool {
    let nv = model.nv;
    for ((t, b), f) in serial(body_tau.iter_mut().zip(&model.bodies).zip(f)) {
        *t = if b.kind == JointKind::Revolute {
            f.ang.dot_const(&b.axis)
        } else {
            f.lin.dot_const(&b.axis)
        };
    }
    if !model.coupled {
        super::armature_torques(model, body_tau, qdd);
        return write_rows(body_tau, used, &mut tau[first * nv..], nv, stores);
    }
    for s in first..first + used {
        tau[s * nv..(s + 1) * nv].fill(0.0);
    }
    for (b, t) in model.bodies.iter().zip(body_tau.iter()) {
        for l in 0..used {
            tau[(first + l) * nv + b.dof] += b.multiplier * t.0[l];
        }
    }
    false
}
