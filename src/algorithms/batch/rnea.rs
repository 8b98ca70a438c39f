//! Inverse dynamics of many samples on the lanes.

use super::kinematics::{aligned_to_parent, apply, contract_torques, forward};
use super::{dispatch, samples, LaneBuffers, LaneData, LaneKernel, Trig};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::model::Model;
use crate::simd::{serial, SpatialLanes};

/// Inverse dynamics `tau = M(q) qdd + c(q, qd) + g(q)` of a batch, [`LaneData::width`] samples
/// at a time (8 on AVX2, in pairs of registers).
///
/// - `q` (rad or m), `qd` (rad/s or m/s), `qdd` (rad/s^2 or m/s^2): row-major `k x nv`
///   (sample `s`, dof `j` at `s * nv + j`); `qd` or `qdd` `None` for zeros. All arguments
///   must hold the same `k` samples and finite values: check them first (a [`crate::States`]
///   is checked once for all); this kernel does not.
/// - `gravity`: include `g(q)`.
/// - `tau`: row-major `k x nv` output (N m or N).
///
/// Equal to [`crate::rnea`] sample by sample up to rounding. Runs on the instruction set of
/// `data` ([`LaneData::isa`]).
pub fn rnea_batch(
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
    let kernel = Rnea {
        k,
        x: [q, qd.unwrap_or(&[]), qdd.unwrap_or(&[])],
        gravity,
        tau,
    };
    dispatch(model, data, kernel)
}

/// The former name of [`rnea_batch`], kept for code written against it.
#[deprecated(note = "named like its siblings now: use rnea_batch")]
#[inline]
pub fn rnea_lanes(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: Gravity,
    tau: &mut [f64],
) -> Result<()> {
    rnea_batch(model, data, q, qd, qdd, gravity, tau)
}

struct Rnea<'a> {
    k: usize,
    x: [&'a [f64]; 3],
    gravity: Gravity,
    tau: &'a mut [f64],
}

impl LaneKernel for Rnea<'_> {
    type Output = Result<()>;
    const PAIRS_ON_AVX2: bool = true;

    #[inline(always)]
    fn wide<const W: usize>(self, model: &Model, data: &mut LaneBuffers<W>) -> Result<()> {
        let g = model.base_acceleration(self.gravity);
        let mut first = 0;
        // vouched for: torques checked in registers as they are written (the armature's share
        // added in the lanes)
        let mut finite = true;
        let stores = data.stores(self.tau.len());
        while first < self.k {
            data.load(model, self.x, first, Trig::InPlace);
            forward(model, data, &g);
            wrenches(model, data);
            let used = (self.k - first).min(W);
            let (f, qdd) = (&data.f, &data.ab);
            finite &= contract_torques(model, f, qdd, &mut data.tau, first, used, self.tau, stores);
            first += W;
        }
        let qdd = self.x[2];
        if model.coupled && !qdd.is_empty() {
            let nv = model.nv;
            for (t, a) in self.tau.chunks_mut(nv).zip(qdd.chunks(nv)) {
                finite &= model.add_armature_torque(a, t);
            }
        }
        data.finite = finite;
        Ok(())
    }

    fn scalar(self, model: &Model, data: &mut Data) -> Result<()> {
        let nv = model.nv;
        let zeros = vec![0.0; nv];
        for (s, t) in self.tau.chunks_mut(nv).enumerate() {
            let r = s * nv..(s + 1) * nv;
            crate::algorithms::rnea::rnea(
                model,
                data,
                &self.x[0][r.clone()],
                if self.x[1].is_empty() {
                    &zeros
                } else {
                    &self.x[1][r.clone()]
                },
                if self.x[2].is_empty() {
                    &zeros
                } else {
                    &self.x[2][r.clone()]
                },
                self.gravity,
            )?;
            t.copy_from_slice(data.tau.as_slice());
        }
        Ok(())
    }
}

/// The backward pass after [`forward`]: body wrenches
/// `f = I a + v x* (I v)`, accumulated from the leaves into `data.f` (each in its body's
/// frame).
#[inline(always)]
pub(crate) fn wrenches<const W: usize>(model: &Model, data: &mut LaneBuffers<W>) {
    for (i, b) in serial(model.bodies.iter().enumerate()) {
        let (v, a) = (&data.v[i], &data.a[i]);
        let (ia, h) = (apply(&b.inertia, a), apply(&b.inertia, v));
        data.f[i] = ia.add(&v.cross_force(&h));
    }
    for i in serial((0..model.nbodies()).rev()) {
        let b = &model.bodies[i];
        if let (Some(p), Some(al)) = (b.parent, &b.pose_terms.aligned) {
            let (head, tail) = data.f.split_at_mut(i);
            aligned_to_parent(al, data.cos_sin[i], &tail[0], &mut head[p]);
        } else if let Some(p) = b.parent {
            let (rot, pos, f) = (&data.rot[i], &data.pos[i], data.f[i]);
            let lin = rot.mul(&f.lin);
            let ang = rot.mul(&f.ang).add(&pos.cross(&lin));
            data.f[p] = data.f[p].add(&SpatialLanes { ang, lin });
        }
    }
}
