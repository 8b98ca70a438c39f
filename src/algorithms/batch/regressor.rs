//! The joint-torque regressor of many samples on the lanes.

use super::kinematics::{aligned_pose_in_base, forward, place_in_base, pose};
use super::{dispatch, samples, LaneBuffers, LaneData, LaneKernel};
use crate::algorithms::regressor::{joint_torque_regressor, PARAMS_PER_BODY};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::simd::{
    serial, write_rows_with_zeros, Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes,
};

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
        while first < self.k {
            data.load(model, self.x, first);
            // the entries left zero are the same for every group: cleared once per call
            regressor_lanes(model, data, self.gravity, first == 0);
            if let Some(out) = self.out.as_deref_mut() {
                let used = (self.k - first).min(W);
                let out = &mut out[first * nv * p..];
                let (y, zeros) = (&data.regressor, Some(&data.regressor_zeros));
                finite &= write_rows_with_zeros(y, zeros, used, out, nv * p, data.wide_stores);
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
        // the body's 10 columns in the base frame (see `world_body_regressor`)
        let (v, a) = (&data.v[i], &data.a[i]);
        let (w, al) = (v.ang, a.ang);
        let ac = r.mul(&a.lin.add(&w.cross(&v.lin)));
        let (ww, alw) = (r.mul(&w), r.mul(&al));
        let w2 = w.dot(&w);
        // (built whole, not from zeroed arrays: the zeroing could become a memset call; no
        // closures: one compiled out of line would lose the instruction set)
        let f = FirstMoment {
            r,
            p,
            w,
            ww,
            alw,
            w2,
            ac,
        };
        let cols = [
            SpatialLanes {
                ang: p.cross(&ac),
                lin: ac,
            },
            f.column(0),
            f.column(1),
            f.column(2),
        ];
        // I_q al + w x (I_q w) for the unit inertias of [Ixx, Ixy, Iyy, Ixz, Iyz, Izz],
        // written out (the unit inertias are mostly zeros), then rotated into the base frame
        // (torques only: these columns move no mass)
        let u = unit_inertia_columns(&w, &al);
        let turned = [
            r.mul(&u[0]),
            r.mul(&u[1]),
            r.mul(&u[2]),
            r.mul(&u[3]),
            r.mul(&u[4]),
            r.mul(&u[5]),
        ];
        // project on the motion subspaces of the body and its ancestors
        let first = PARAMS_PER_BODY * i;
        let mut j = Some(i);
        while let Some(k) = j {
            let bk = &model.bodies[k];
            let sk = &data.o_s[k];
            let at = bk.dof * cols_all + first;
            let row = &mut out[at..at + PARAMS_PER_BODY];
            let y = [
                sk.dot(&cols[0]),
                sk.dot(&cols[1]),
                sk.dot(&cols[2]),
                sk.dot(&cols[3]),
                sk.ang.dot(&turned[0]),
                sk.ang.dot(&turned[1]),
                sk.ang.dot(&turned[2]),
                sk.ang.dot(&turned[3]),
                sk.ang.dot(&turned[4]),
                sk.ang.dot(&turned[5]),
            ];
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

/// What a body's first-moment columns of the regressor share (base frame): its pose `r`, `p`,
/// its angular velocity `w` (body frame) and `ww`, `alw` (angular velocity and acceleration in
/// the base frame), `w2 = |w|^2`, and `ac` its origin's acceleration (base frame).
struct FirstMoment<'a, const W: usize> {
    r: &'a Rotation3Lanes<W>,
    p: &'a Vector3Lanes<W>,
    w: Vector3Lanes<W>,
    ww: Vector3Lanes<W>,
    alw: Vector3Lanes<W>,
    w2: Lanes<W>,
    ac: Vector3Lanes<W>,
}

impl<const W: usize> FirstMoment<'_, W> {
    /// The wrench per unit of the first moment's component `k` (body frame).
    #[inline(always)]
    fn column(&self, k: usize) -> SpatialLanes<W> {
        let rk = self.r.column(k);
        let lin = self
            .ww
            .mul_lanes_add(self.w.get(k), &self.alw.cross(&rk))
            .sub(&rk.mul_lanes(self.w2));
        SpatialLanes {
            ang: rk.cross(&self.ac).add(&self.p.cross(&lin)),
            lin,
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
