//! The joint-torque regressor of many samples on the lanes.

use super::kinematics::{act_inv, forward, turned};
use super::{dispatch, samples, LaneBuffers, LaneData, LaneKernel, Trig};
use crate::algorithms::regressor::{joint_torque_regressor, PARAMS_PER_BODY};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::{Body, JointKind, Model};
use crate::simd::{
    serial, write_rows_with_zeros, Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes,
};
use nalgebra::Vector3;

/// The joint-torque regressor of a batch, [`LaneData::width`] samples at a time: `out`
/// (row-major `k x nv x 10 nbodies`, N m per parameter unit) holds for every sample the matrix
/// that [`crate::algorithms::regressor::joint_torque_regressor`] gives, up to rounding.
///
/// `q`, `qd`, `qdd`: row-major `k x nv` (rad, rad/s, rad/s^2), finite (checked by the caller, as
/// for [`super::rnea_batch`]); `gravity` includes gravity. Runs on the instruction set of
/// `data`.
pub fn regressor_batch(
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
    let kernel = Regressor {
        k,
        x: [q, qd, qdd],
        gravity,
        out: Some(out),
    };
    dispatch(model, data, kernel)
}

/// The joint-torque regressors of a group of 1 to [`LaneData::width`] samples, left in `data`
/// and read with [`LaneData::regressor_entry`]: the building block for work that reduces the
/// regressor as it is made (the streaming identification), without the copy into a row-major
/// array that [`regressor_batch`] makes.
///
/// `q`, `qd`, `qdd`: row-major `g x nv` (rad, rad/s, rad/s^2), finite (checked by the caller).
/// Returns `g`.
pub fn regressor_group(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
) -> Result<usize> {
    let nv = model.nv;
    let k = samples(nv, q.len(), &[("qd", qd.len(), nv), ("qdd", qdd.len(), nv)])?;
    if k == 0 || k > data.width() {
        return Err(Error::shape(
            "q",
            format!("1 to {} samples of {nv} joints", data.width()),
            format!("{k} samples"),
        ));
    }
    let kernel = Regressor {
        k,
        x: [q, qd, qdd],
        gravity,
        out: None,
    };
    dispatch(model, data, kernel)?;
    Ok(k)
}

/// The regressors of `k` samples, into `out` (row-major) or, with `out` `None` and at most one
/// group of samples, left in the buffers.
struct Regressor<'a> {
    k: usize,
    x: [&'a [f64]; 3],
    gravity: Gravity,
    out: Option<&'a mut [f64]>,
}

impl LaneKernel for Regressor<'_> {
    type Output = Result<()>;

    #[inline(always)]
    fn wide<const W: usize>(mut self, model: &Model, data: &mut LaneBuffers<W>) -> Result<()> {
        let nv = model.nv;
        let p = PARAMS_PER_BODY * model.nbodies();
        let mut first = 0;
        let mut finite = self.out.is_some();
        let stores = data.stores(self.out.as_deref().map_or(0, <[f64]>::len));
        while first < self.k {
            data.load(model, self.x, first, Trig::InPlace);
            regressor_lanes(model, data, self.gravity);
            if let Some(out) = self.out.as_deref_mut() {
                let used = (self.k - first).min(W);
                let out = &mut out[first * nv * p..];
                let (y, zeros) = (&data.regressor, Some(&data.regressor_zeros));
                finite &= write_rows_with_zeros(y, zeros, used, out, nv * p, stores);
            }
            first += W;
        }
        data.finite = finite;
        Ok(())
    }

    fn scalar(mut self, model: &Model, data: &mut Data) -> Result<()> {
        let nv = model.nv;
        let p = PARAMS_PER_BODY * model.nbodies();
        let mut y = std::mem::take(&mut data.regressor);
        let result = (0..self.k).try_for_each(|s| {
            let r = s * nv..(s + 1) * nv;
            let [q, qd, qdd] = self.x.map(|x| &x[r.clone()]);
            joint_torque_regressor(model, data, q, qd, qdd, self.gravity, &mut y)?;
            if let Some(out) = self.out.as_deref_mut() {
                crate::algorithms::row_major::copy_row_major(&y, &mut out[s * nv * p..][..nv * p]);
            }
            Ok(())
        });
        data.regressor = y; // back in place even after an error
        result
    }
}

/// The regressor's work space: for every body, the motion subspaces of its ancestors in its own
/// axes (those of the bodies on the path from the root to the current one, by depth), and the
/// constants that carry them from a parent's axes to a child's.
///
/// A body's axes are held in the order of its joint's roles (`AlignedRevolute::roles`, a cyclic
/// permutation, under which cross products keep their form) for an aligned revolute joint,
/// x, y, z otherwise: an aligned joint's transform then produces every component at a fixed
/// place (its permutation only picks which of the parent's components it reads, from memory),
/// and only the ten regressor entries go to permuted columns.
#[derive(Clone, Debug)]
pub(crate) struct Chain<const W: usize> {
    bodies: Vec<BodyAxes>,
    /// Subspaces by depth: a body at depth `d` (its ancestors' count) keeps its `d` ancestors'
    /// (parent first) from `d (d - 1) / 2` on.
    subspaces: Vec<SpatialLanes<W>>,
}

impl<const W: usize> Default for Chain<W> {
    fn default() -> Self {
        Self {
            bodies: Vec::new(),
            subspaces: Vec::new(),
        }
    }
}

/// One body's constants for [`Chain`].
#[derive(Clone, Debug)]
struct BodyAxes {
    depth: usize,
    /// The body axis held as component `j`.
    order: [usize; 3],
    /// For each component `j` of the body (aligned) or each parent axis (otherwise): where the
    /// parent holds the parent axis it comes from, and the two after it (cyclically).
    from_parent: [[usize; 3]; 3],
    /// The joint placement's translation in the parent's held axes.
    p_parent: [f64; 3],
    /// The parent's own motion subspace (angular, linear) in the parent's held axes.
    parent_subspace: [[f64; 3]; 2],
    /// The joint axis in the body's held axes.
    axis: Vector3<f64>,
}

impl<const W: usize> Chain<W> {
    pub(crate) fn new(model: &Model) -> Self {
        let mut bodies: Vec<BodyAxes> = Vec::with_capacity(model.nbodies());
        for b in &model.bodies {
            // (parents come first)
            let parent = b.parent.map(|p| (&model.bodies[p], &bodies[p]));
            let order = match &b.pose_terms.aligned {
                Some(al) => al.roles,
                None => [0, 1, 2],
            };
            let parent_order = parent.map_or([0, 1, 2], |(_, a)| a.order);
            // where the parent holds its axis r
            let held = |r: usize| parent_order.iter().position(|&o| o == r).unwrap_or(r);
            let from = |r: usize| [held(r), (held(r) + 1) % 3, (held(r) + 2) % 3];
            let from_parent = match &b.pose_terms.aligned {
                Some(al) => al.rows.map(from),
                None => [0, 1, 2].map(from),
            };
            let t = &b.placement.translation;
            let p_parent = parent_order.map(|r| t[r]);
            let parent_subspace = parent.map_or([[0.0; 3]; 2], |(pb, pa)| {
                let axis = pa.axis;
                match pb.kind {
                    JointKind::Revolute => [[axis.x, axis.y, axis.z], [0.0; 3]],
                    JointKind::Prismatic => [[0.0; 3], [axis.x, axis.y, axis.z]],
                }
            });
            let axis = Vector3::new(b.axis[order[0]], b.axis[order[1]], b.axis[order[2]]);
            bodies.push(BodyAxes {
                depth: parent.map_or(0, |(_, a)| a.depth + 1),
                order,
                from_parent,
                p_parent,
                parent_subspace,
                axis,
            });
        }
        let deepest = bodies.iter().map(|a| a.depth).max().unwrap_or(0);
        Self {
            bodies,
            subspaces: vec![SpatialLanes::default(); deepest * (deepest + 1) / 2],
        }
    }
}

/// `v` (body frame, in memory) in the held axes `order`.
#[inline(always)]
fn held<const W: usize>(v: &Vector3Lanes<W>, order: &[usize; 3]) -> Vector3Lanes<W> {
    Vector3Lanes {
        x: *v.at(order[0]),
        y: *v.at(order[1]),
        z: *v.at(order[2]),
    }
}

/// The motion `m` held in the parent's axes, in body `b`'s held axes (`axes`), for the pose the
/// forward pass left (`data`, body `i`).
#[inline(always)]
fn to_child<const W: usize>(
    b: &Body,
    axes: &BodyAxes,
    data: &LaneBuffers<W>,
    i: usize,
    turn: &[Lanes<W>; 4],
    m: &SpatialLanes<W>,
) -> SpatialLanes<W> {
    let f = &axes.from_parent;
    match &b.pose_terms.aligned {
        Some(al) => {
            let x = [*m.ang.at(f[0][0]), *m.ang.at(f[1][0]), *m.ang.at(f[2][0])];
            let y = [
                raw_lin(axes, m, 0),
                raw_lin(axes, m, 1),
                raw_lin(axes, m, 2),
            ];
            let ([ax, ay, az], [lx, ly, lz]) =
                (turned(x, al.signs[0], turn), turned(y, al.signs[0], turn));
            SpatialLanes {
                ang: Vector3Lanes {
                    x: ax,
                    y: ay,
                    z: az,
                },
                lin: Vector3Lanes {
                    x: lx,
                    y: ly,
                    z: lz,
                },
            }
        }
        None => {
            // the parent's motion in its natural axes, then the general transform
            let natural = SpatialLanes {
                ang: Vector3Lanes {
                    x: *m.ang.at(f[0][0]),
                    y: *m.ang.at(f[1][0]),
                    z: *m.ang.at(f[2][0]),
                },
                lin: Vector3Lanes {
                    x: *m.lin.at(f[0][0]),
                    y: *m.lin.at(f[1][0]),
                    z: *m.lin.at(f[2][0]),
                },
            };
            act_inv(&data.rot[i], &data.pos[i], &natural)
        }
    }
}

/// `(m.lin - p x m.ang)` at the parent's held axis `from_parent[j][0]` (with the two after it),
/// `p` the joint placement in the parent's held axes. A function, not a closure: one compiled
/// out of line would lose the instruction set.
#[inline(always)]
fn raw_lin<const W: usize>(axes: &BodyAxes, m: &SpatialLanes<W>, j: usize) -> Lanes<W> {
    let (p, [q, q1, q2]) = (&axes.p_parent, axes.from_parent[j]);
    m.ang
        .at(q1)
        .mul_add_s(p[q2], m.ang.at(q2).mul_add_s(-p[q1], *m.lin.at(q)))
}

/// The joint-torque regressor (see [`crate::algorithms::regressor::joint_torque_regressor`]) of
/// the loaded group of lanes: `data.regressor` row-major `nv x 10 nbodies`, one lane per
/// sample. `gravity` includes gravity. The entries of a degree of freedom that does not move
/// the body of the column (`LaneBuffers::regressor_zeros`) are never written: zero since the
/// buffer was made. A coupled model's entries accumulate, so its buffer is cleared every
/// group.
#[inline(always)]
fn regressor_lanes<const W: usize>(model: &Model, data: &mut LaneBuffers<W>, gravity: Gravity) {
    forward(model, data, &model.base_acceleration(gravity));
    let mut out = std::mem::take(&mut data.regressor);
    let mut chain = std::mem::take(&mut data.chain);
    if model.coupled {
        out.fill(Lanes::default());
    }
    for i in serial(0..model.nbodies()) {
        let b = &model.bodies[i];
        let axes = &chain.bodies[i];
        // the body's wrench per unit of each parameter, in its own frame about its origin
        // (`world_body_regressor` in the body frame) and its held axes: mass `(0, c)`, first
        // moment along `e_k` `(e_k x c, al x e_k + w w_k - e_k |w|^2)`, rotational inertia
        // `(I_q al + w x I_q w, 0)`, with `c` the origin's acceleration; these are dotted with
        // each ancestor's motion subspace in the same axes, carried down from the parent's
        // (one motion transform a pair: 16 operations for an aligned joint)
        let (v, a) = (&data.v[i], &data.a[i]);
        let (w, al) = (held(&v.ang, &axes.order), held(&a.ang, &axes.order));
        let c = held(&a.lin, &axes.order).add(&w.cross(&held(&v.lin, &axes.order)));
        let u = unit_inertia_columns(&w, &al);
        let moments = first_moment_map(&w, &al);
        let first = PARAMS_PER_BODY * i;
        // its own joint's subspace is a constant of the model in its own frame
        let own = own_columns(b.kind, &axes.axis, &c, &moments, &u);
        put(model, &mut out, i, first, axes.order[0], &own);
        let Some(parent) = b.parent else { continue };
        let d = axes.depth;
        let (above, below) = chain.subspaces.split_at_mut(d * (d - 1) / 2);
        let from = &above[(d - 1) * d.saturating_sub(2) / 2..];
        let to = &mut below[..d];
        let turn = match &b.pose_terms.aligned {
            Some(al) => al.turn(data.cos_sin[i]),
            None => [Lanes::default(); 4],
        };
        // (a leaf's subspaces are not needed further down)
        let keep = b.subtree_end > i + 1;
        let mut j = Some(parent);
        for e in serial(0..d) {
            let Some(k) = j else { break };
            let s = if e == 0 {
                let [pa, pl] = &axes.parent_subspace;
                let own = SpatialLanes {
                    ang: Vector3Lanes::splat(&Vector3::new(pa[0], pa[1], pa[2])),
                    lin: Vector3Lanes::splat(&Vector3::new(pl[0], pl[1], pl[2])),
                };
                to_child(b, axes, data, i, &turn, &own)
            } else {
                to_child(b, axes, data, i, &turn, &from[e - 1])
            };
            if keep {
                to[e] = s;
            }
            let (sa, sl) = (&s.ang, &s.lin);
            // the first-moment entries at once: sl x al - sa x c + w (sl . w) - sl |w|^2, as
            // K sl + c x sa (15 operations a pair where the terms one by one took 32)
            let fm = moments.mul_add(sl, &c.cross(sa));
            let y = [
                sl.dot(&c),
                fm.x,
                fm.y,
                fm.z,
                sa.dot(&u[0]),
                sa.dot(&u[1]),
                sa.dot(&u[2]),
                sa.dot(&u[3]),
                sa.dot(&u[4]),
                sa.dot(&u[5]),
            ];
            put(model, &mut out, k, first, axes.order[0], &y);
            j = model.bodies[k].parent;
        }
    }
    data.chain = chain;
    data.regressor = out;
}

/// The ten entries `y` (in the held axes' order) into body columns `first..first + 10` of body
/// `k`'s degree of freedom's row of the regressor `out` (row-major `nv x 10 nbodies`), at the
/// columns of the held axes `[r, r + 1, r + 2]` (cyclically; `r` the first); for a coupled
/// model times the body's multiplier, added. (A function, not a closure: one compiled out of
/// line would lose the instruction set.)
#[inline(always)]
fn put<const W: usize>(
    model: &Model,
    out: &mut [Lanes<W>],
    k: usize,
    first: usize,
    r: usize,
    y: &[Lanes<W>; PARAMS_PER_BODY],
) {
    // one copy per permutation, so that every column is a constant (measured: the columns
    // read from a table, with their bounds checks, took as many instructions as the entries'
    // arithmetic)
    match r {
        0 => put_held::<W, 0>(model, out, k, first, y),
        1 => put_held::<W, 1>(model, out, k, first, y),
        _ => put_held::<W, 2>(model, out, k, first, y),
    }
}

/// The regressor column (within the body's ten) of each of the ten entries computed in the
/// held axes `[r, r + 1, r + 2]` (cyclically): mass, first moment along each held axis,
/// rotational inertia of each pair (columns `[Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` from 4 on).
const fn held_columns(r: usize) -> [usize; PARAMS_PER_BODY] {
    let o = [r, (r + 1) % 3, (r + 2) % 3];
    let pair = [[4, 5, 7], [5, 6, 8], [7, 8, 9]];
    [
        0,
        1 + o[0],
        1 + o[1],
        1 + o[2],
        pair[o[0]][o[0]],
        pair[o[0]][o[1]],
        pair[o[1]][o[1]],
        pair[o[0]][o[2]],
        pair[o[1]][o[2]],
        pair[o[2]][o[2]],
    ]
}

/// [`put`] for the held axes starting at `R`.
#[inline(always)]
fn put_held<const W: usize, const R: usize>(
    model: &Model,
    out: &mut [Lanes<W>],
    k: usize,
    first: usize,
    y: &[Lanes<W>; PARAMS_PER_BODY],
) {
    let columns = const { held_columns(R) };
    let bk = &model.bodies[k];
    let at = bk.dof * PARAMS_PER_BODY * model.nbodies() + first;
    let row: &mut [Lanes<W>; PARAMS_PER_BODY] = (&mut out[at..at + PARAMS_PER_BODY])
        .try_into()
        .expect("ten columns");
    for (&s, y) in columns.iter().zip(y) {
        row[s] = if model.coupled {
            y.mul_add_s(bk.multiplier, row[s])
        } else {
            *y
        };
    }
}

/// The regressor entries of a body's own joint (see `regressor_lanes`), in its held axes: its
/// motion subspace there is the axis `a`, through the origin (revolute) or as a translation
/// (prismatic).
#[inline(always)]
fn own_columns<const W: usize>(
    kind: JointKind,
    a: &Vector3<f64>,
    c: &Vector3Lanes<W>,
    moments: &Rotation3Lanes<W>,
    u: &[Vector3Lanes<W>; 6],
) -> [Lanes<W>; PARAMS_PER_BODY] {
    match kind {
        JointKind::Revolute => {
            let fm = c.cross_const(a);
            [
                Lanes::default(),
                fm.x,
                fm.y,
                fm.z,
                u[0].dot_const(a),
                u[1].dot_const(a),
                u[2].dot_const(a),
                u[3].dot_const(a),
                u[4].dot_const(a),
                u[5].dot_const(a),
            ]
        }
        JointKind::Prismatic => {
            // a x al + w (w . a) - a |w|^2, the pairs' `K sl` for `sl = a`
            let fm = moments.mul_const_vector(a);
            let zero = Lanes::default();
            [
                c.dot_const(a),
                fm.x,
                fm.y,
                fm.z,
                zero,
                zero,
                zero,
                zero,
                zero,
                zero,
            ]
        }
    }
}

/// The matrix `K = w w^T - |w|^2 1 - [al]x` (body frame, by rows), for which
/// `K s = s x al + w (w . s) - s |w|^2`: the part of the first-moment entries linear in a
/// subspace's linear part `s`, made once a body instead of once per ancestor.
#[inline(always)]
fn first_moment_map<const W: usize>(
    w: &Vector3Lanes<W>,
    al: &Vector3Lanes<W>,
) -> Rotation3Lanes<W> {
    let (xy, xz, yz) = (w.x * w.y, w.x * w.z, w.y * w.z);
    let (xx, yy, zz) = (w.x * w.x, w.y * w.y, w.z * w.z);
    let v = |x, y, z| Vector3Lanes { x, y, z };
    Rotation3Lanes([
        v(-(yy + zz), xy + al.z, xz - al.y),
        v(xy - al.z, -(xx + zz), yz + al.x),
        v(xz + al.y, yz - al.x, -(xx + yy)),
    ])
}

/// `I_q al + w x (I_q w)` (body frame) for the unit rotational inertias `I_q` of
/// `[Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (`I_xy` has ones at (x, y) and (y, x)), with the products of
/// `w`'s components shared: 6 multiplies and 14 adds where the general form takes 72 flops.
#[inline(always)]
fn unit_inertia_columns<const W: usize>(
    w: &Vector3Lanes<W>,
    al: &Vector3Lanes<W>,
) -> [Vector3Lanes<W>; 6] {
    let (xy, xz, yz) = (w.x * w.y, w.x * w.z, w.y * w.z);
    let (xx, yy, zz) = (w.x * w.x, w.y * w.y, w.z * w.z);
    let v = |x, y, z| Vector3Lanes { x, y, z };
    [
        v(al.x, xz, -xy),
        v(al.y - xz, al.x + yz, xx - yy),
        v(-yz, al.y, xy),
        v(al.z + xy, zz - xx, al.x - yz),
        v(yy - zz, al.z - xy, al.y + xz),
        v(yz, -xz, al.z),
    ]
}
