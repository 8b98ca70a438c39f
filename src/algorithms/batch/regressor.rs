//! The joint-torque regressor of many samples on the lanes.

use super::kinematics::{aligned_pose_in_base, forward, place_in_base, pose};
use super::{dispatch, samples, LaneBuffers, LaneData, LaneKernel};
use crate::algorithms::regressor::{joint_torque_regressor, PARAMS_PER_BODY};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::{Body, JointKind, Model};
use crate::simd::{serial, write_rows_with_zeros, Lanes, Vector3Lanes};

/// The joint-torque regressor of a batch, [`LaneData::width`] samples at a time: `out`
/// (row-major `k x nv x 10 nbodies`, N m per parameter unit) holds for every sample the matrix
/// that [`crate::algorithms::regressor::joint_torque_regressor`] gives, up to rounding.
///
/// `q`, `qd`, `qdd`: row-major `k x nv` (rad, rad/s, rad/s^2), finite (checked by the caller, as
/// for [`super::rnea_lanes`]); `gravity` includes gravity. Runs on the instruction set of
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
        return Err(Error::Shape {
            argument: "q".into(),
            expected: format!("1 to {} samples of {nv} joints", data.width()),
            got: format!("{k} samples"),
        });
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
            data.load(model, self.x, first);
            // the entries left zero are the same for every group: cleared once per call
            regressor_lanes(model, data, self.gravity, first == 0);
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
                crate::algorithms::parallel::copy_row_major(&y, &mut out[s * nv * p..][..nv * p]);
            }
            Ok(())
        });
        data.regressor = y; // back in place even after an error
        result
    }
}

/// The joint-torque regressor (see [`crate::algorithms::regressor::joint_torque_regressor`]) of
/// the loaded group of lanes: `data.regressor` row-major `nv x 10 nbodies`, one lane per
/// sample. `gravity` includes gravity. The entries of a degree of freedom that does not move
/// the body of the column stay as they were: `clear` zeroes them first (needed on the first
/// group of a call; a coupled model, whose entries accumulate, clears every time).
#[inline(always)]
fn regressor_lanes<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    gravity: Gravity,
    clear: bool,
) {
    let cols_all = PARAMS_PER_BODY * model.nbodies();
    forward(model, data, &model.base_acceleration(gravity));
    let mut out = std::mem::take(&mut data.regressor);
    if clear || model.coupled {
        out.fill(Lanes::default());
    }
    for i in serial(0..model.nbodies()) {
        let b = &model.bodies[i];
        match (&b.pose_terms.aligned, b.parent) {
            // the forward pass kept cos and sin, not the pose in the parent
            (Some(al), Some(parent)) => {
                aligned_pose_in_base(model, data, i, al, parent, data.cos_sin[i]);
            }
            (Some(_), None) => {
                let (rot, pos) = pose(b, data.qb[i]);
                place_in_base(model, data, i, &rot, &pos);
            }
            _ => {
                let (rot, pos) = (data.rot[i], data.pos[i]);
                place_in_base(model, data, i, &rot, &pos);
            }
        }
        // read in place (a copy of the pose would go through memcpy)
        let (r, p) = (&data.o_rot[i], &data.o_pos[i]);
        // the body's wrench per unit of each parameter, in its own frame about its origin
        // (`world_body_regressor` in the body frame): mass `(0, c)`, first moment along `e_k`
        // `(e_k x c, al x e_k + w w_k - e_k |w|^2)`, rotational inertia `(I_q al + w x I_q w,
        // 0)`, with `c` the origin's acceleration; these are dotted with each ancestor's motion
        // subspace brought into that frame, which is cheaper than turning the ten columns into
        // the base frame once the body has few ancestors
        let (v, a) = (&data.v[i], &data.a[i]);
        let (w, al) = (v.ang, a.ang);
        let c = a.lin.add(&w.cross(&v.lin));
        let w2 = w.dot(&w);
        let u = unit_inertia_columns(&w, &al);
        let first = PARAMS_PER_BODY * i;
        let mut j = Some(i);
        while let Some(k) = j {
            let bk = &model.bodies[k];
            let at = bk.dof * cols_all + first;
            let row = &mut out[at..at + PARAMS_PER_BODY];
            let y = if k == i {
                // its own joint's subspace is a constant of the model in its own frame
                own_columns(b, &c, &w, &al, w2, &u)
            } else {
                // ancestor k's motion subspace in the body's frame, about the body's origin
                let sk = &data.o_s[k];
                let sa = r.tr_mul(&sk.ang);
                let sl = r.tr_mul(&sk.lin.add(&sk.ang.cross(p)));
                // the first-moment entries at once: sl x al - sa x c + w (sl . w) - sl |w|^2
                let fm = sl
                    .cross(&al)
                    .sub(&sa.cross(&c))
                    .add(&w.mul_lanes(sl.dot(&w)))
                    .sub(&sl.mul_lanes(w2));
                [
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
                ]
            };
            if model.coupled {
                for (o, y) in row.iter_mut().zip(&y) {
                    *o = y.mul_add_s(bk.multiplier, *o);
                }
            } else {
                row.copy_from_slice(&y);
            }
            j = bk.parent;
        }
    }
    data.regressor = out;
}

/// The regressor entries of body `b`'s own joint (see `regressor_lanes`): its motion subspace
/// in its own frame is the axis, through the origin (revolute) or as a translation
/// (prismatic).
#[inline(always)]
fn own_columns<const W: usize>(
    b: &Body,
    c: &Vector3Lanes<W>,
    w: &Vector3Lanes<W>,
    al: &Vector3Lanes<W>,
    w2: Lanes<W>,
    u: &[Vector3Lanes<W>; 6],
) -> [Lanes<W>; PARAMS_PER_BODY] {
    let a = &b.axis;
    match b.kind {
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
            let fm = w
                .mul_lanes(w.dot_const(a))
                .sub(&al.cross_const(a))
                .sub(&Vector3Lanes::of(a, w2));
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
