//! The analytic derivatives of the inverse dynamics and the local model `T*, D*, H*, G*, Gs`
//! of many samples on the lanes: the base-frame recursion of [`crate::rnea_derivatives`]
//! (Carpentier & Mansard, RSS 2018), one sample per lane.

use super::kinematics::{store_pose_in_base, store_turned_pose_in_base};
use super::mass_matrix::{transformed, Composite};
use super::{
    armature_inertia, armature_torques, dispatch, samples, LaneBuffers, LaneData, LaneKernel, Trig,
};
use crate::data::Data;
use crate::error::Result;
use crate::gravity::Gravity;
use crate::linearization::{linearize_into, Linearization};
use crate::model::Model;
use crate::simd::{
    serial, write_rows, write_rows_with_zeros, Lanes, Rotation3Lanes, SpatialLanes, Stores,
    Vector3Lanes, ZeroPattern,
};

/// Where [`derivatives_batch`] writes, row-major over `k` samples.
#[derive(Debug)]
pub struct DerivativesOut<'a> {
    /// `tau`, `k x nv` (N m or N).
    pub tau: &'a mut [f64],
    /// `d tau / d q`, `k x nv x nv` (entry `(i, j)` of a sample is `d tau_i / d q_j`).
    pub dtau_dq: &'a mut [f64],
    /// `d tau / d qd`, `k x nv x nv`.
    pub dtau_dv: &'a mut [f64],
    /// `d tau / d qdd = M(q)`, `k x nv x nv`.
    pub m: &'a mut [f64],
}

/// Where [`linearize_batch`] (and [`crate::parallel::linearize`]) write: row-major buffers of
/// `k` samples.
#[derive(Debug)]
pub struct LinearizationsOut<'a> {
    /// `T*`, `k x nv` (N m).
    pub torque: &'a mut [f64],
    /// `D* = M(q*)`, `k x nv x nv`.
    pub d: &'a mut [f64],
    /// `H* = d tau / d qd`, `k x nv x nv`.
    pub h: &'a mut [f64],
    /// `G* = d tau / d q`, `k x nv x nv`.
    pub g: &'a mut [f64],
    /// `Gs = d g / d q` at rest, `k x nv x nv`.
    pub g_static: &'a mut [f64],
}

/// Inverse dynamics and its partial derivatives (see [`crate::rnea_derivatives`]) of a batch,
/// [`LaneData::width`] samples at a time, equal to the one-sample algorithm up to rounding.
///
/// `q`, `qd`, `qdd`: row-major `k x nv` (rad, rad/s, rad/s^2 or m, m/s, m/s^2), finite (checked
/// by the caller). `gravity` includes gravity in `tau` and `d tau / d q`. Runs on the
/// instruction set of `data`.
pub fn derivatives_batch(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: DerivativesOut<'_>,
) -> Result<()> {
    let (n, nn) = (model.nv, model.nv * model.nv);
    let k = samples(
        n,
        q.len(),
        &[
            ("qd", qd.len(), n),
            ("qdd", qdd.len(), n),
            ("tau", out.tau.len(), n),
            ("d tau / d q", out.dtau_dq.len(), nn),
            ("d tau / d qd", out.dtau_dv.len(), nn),
            ("M", out.m.len(), nn),
        ],
    )?;
    let kernel = Derivatives {
        k,
        x: [q, qd, qdd],
        gravity,
        out: [out.tau, out.m, out.dtau_dq, out.dtau_dv],
        g_static: None,
    };
    dispatch(model, data, kernel)
}

/// The local model (see [`crate::linearize`]) at every sample of a batch taken as an operating
/// point, [`LaneData::width`] samples at a time: `T*`, `D*`, `H*`, `G*` from the derivatives at
/// `(q, qd, qdd)` and `Gs` from those at `(q, 0, 0)`.
///
/// `q`, `qd`, `qdd`: row-major `k x nv`, finite (checked by the caller). Runs on the
/// instruction set of `data`.
pub fn linearize_batch(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: Gravity,
    out: LinearizationsOut<'_>,
) -> Result<()> {
    let (n, nn) = (model.nv, model.nv * model.nv);
    let k = samples(
        n,
        q.len(),
        &[
            ("qd", qd.len(), n),
            ("qdd", qdd.len(), n),
            ("torque", out.torque.len(), n),
            ("d", out.d.len(), nn),
            ("h", out.h.len(), nn),
            ("g", out.g.len(), nn),
            ("g_static", out.g_static.len(), nn),
        ],
    )?;
    let kernel = Derivatives {
        k,
        x: [q, qd, qdd],
        gravity,
        out: [out.torque, out.d, out.g, out.h],
        g_static: Some(out.g_static),
    };
    dispatch(model, data, kernel)
}

/// The derivatives of `k` samples into `out = [tau, M, d tau / d q, d tau / d qd]`, and with
/// `g_static` the derivative along `q` at rest too.
struct Derivatives<'a> {
    k: usize,
    x: [&'a [f64]; 3],
    gravity: Gravity,
    out: [&'a mut [f64]; 4],
    g_static: Option<&'a mut [f64]>,
}

/// The time derivative of a body's (composite) inertia in the base frame moving with twist
/// `v = (w, u)`, `dY = v x* Y - Y (v x) + (Y v) x-bar` (the 6x6 matrix of the recursion, per
/// lane). For `Y` in origin form (mass `m`, first moment `h`, rotational inertia `I`) it has
/// only two non-zero blocks: with `A = [w]x I`, `Y v = (hA, hL)`,
///
/// `dY = [[T, 0], [-2 [hL]x, 0]]`, `T = A + A^T - (h u^T + u h^T) + 2 (u . h) 1 - [hA]x`,
///
/// so it is kept as `T` (by rows) and `hL`; both add over composite bodies.
#[derive(Clone, Copy, Debug)]
pub(crate) struct InertiaRate<const W: usize> {
    t: Rotation3Lanes<W>,
    hl: Vector3Lanes<W>,
}

impl<const W: usize> Default for InertiaRate<W> {
    fn default() -> Self {
        Self {
            t: Rotation3Lanes::default(),
            hl: Vector3Lanes::default(),
        }
    }
}

impl<const W: usize> InertiaRate<W> {
    /// `dY` of the inertia `y` moving with twist `v`; `yv = Y v`.
    #[inline(always)]
    fn new(y: &Composite<W>, v: &SpatialLanes<W>, yv: &SpatialLanes<W>) -> Self {
        let (w, u, h) = (&v.ang, &v.lin, &y.h);
        let ir = &y.i.0; // rows of I
                         // rows of A = [w]x I: row r is sum_k [w]x[r][k] I_k
        let a = [
            ir[2].mul_lanes(w.y).sub(&ir[1].mul_lanes(w.z)),
            ir[0].mul_lanes(w.z).sub(&ir[2].mul_lanes(w.x)),
            ir[1].mul_lanes(w.x).sub(&ir[0].mul_lanes(w.y)),
        ];
        let uh2 = u.dot(h) * 2.0;
        let ha = &yv.ang;
        // the symmetric part A + A^T - h u^T - u h^T + 2 (u . h) 1, each pair once
        let sym = |r: usize, c: usize| {
            let v = a[r].get(c) + a[c].get(r);
            h.get(r)
                .neg_mul_add(u.get(c), u.get(r).neg_mul_add(h.get(c), v))
        };
        let (xy, xz, yz) = (sym(0, 1), sym(0, 2), sym(1, 2));
        // then - [hA]x: (0, hz, -hy; -hz, 0, hx; hy, -hx, 0)
        let t = Rotation3Lanes([
            Vector3Lanes {
                x: sym(0, 0) + uh2,
                y: xy + ha.z,
                z: xz - ha.y,
            },
            Vector3Lanes {
                x: xy - ha.z,
                y: sym(1, 1) + uh2,
                z: yz + ha.x,
            },
            Vector3Lanes {
                x: xz + ha.y,
                y: yz - ha.x,
                z: sym(2, 2) + uh2,
            },
        ]);
        Self { t, hl: yv.lin }
    }
    /// `dY x`.
    #[inline(always)]
    fn mul(&self, x: &SpatialLanes<W>) -> SpatialLanes<W> {
        SpatialLanes {
            ang: self.t.mul(&x.ang),
            lin: x.ang.cross(&self.hl).scale(2.0),
        }
    }
    /// `dY^T x`.
    #[inline(always)]
    fn tr_mul(&self, x: &SpatialLanes<W>) -> SpatialLanes<W> {
        SpatialLanes {
            ang: self.hl.cross(&x.lin).scale(2.0).add(&self.t.tr_mul(&x.ang)),
            lin: Vector3Lanes::default(),
        }
    }
    #[inline(always)]
    fn add_assign(&mut self, o: &Self) {
        self.t = self.t.add(&o.t);
        self.hl = self.hl.add(&o.hl);
    }
}

impl<const W: usize> Composite<W> {
    /// The momentum `Y m` of this inertia (origin form, base frame) moving with twist `m`.
    #[inline(always)]
    fn apply(&self, m: &SpatialLanes<W>) -> SpatialLanes<W> {
        SpatialLanes {
            ang: self.i.mul_add(&m.ang, &self.h.cross(&m.lin)),
            lin: m.lin.scale_add(self.mass, &m.ang.cross(&self.h)),
        }
    }
    #[inline(always)]
    fn add_assign(&mut self, o: &Self) {
        *self = self.add(o);
    }
}

/// The per-body quantities of the recursion, all in the base frame.
#[derive(Clone, Debug)]
pub(crate) struct Buffers<const W: usize> {
    ycrb: Vec<Composite<W>>,
    dycrb: Vec<InertiaRate<W>>,
    j: Vec<SpatialLanes<W>>,
    ov: Vec<SpatialLanes<W>>,
    oa: Vec<SpatialLanes<W>>,
    of: Vec<SpatialLanes<W>>,
    dvdq: Vec<SpatialLanes<W>>,
    dadq: Vec<SpatialLanes<W>>,
    dadv: Vec<SpatialLanes<W>>,
    dfda: Vec<SpatialLanes<W>>,
    dfdq: Vec<SpatialLanes<W>>,
    dfdv: Vec<SpatialLanes<W>>,
    dytj: Vec<SpatialLanes<W>>,
    /// The same at rest (for `Gs`).
    of_rest: Vec<SpatialLanes<W>>,
    dadq_rest: Vec<SpatialLanes<W>>,
    dfdq_rest: Vec<SpatialLanes<W>>,
    /// Body-level results: torques and row-major `nbodies x nbodies` matrices.
    tau: Vec<Lanes<W>>,
    m: Vec<Lanes<W>>,
    dq: Vec<Lanes<W>>,
    dv: Vec<Lanes<W>>,
    gs: Vec<Lanes<W>>,
}

impl<const W: usize> Buffers<W> {
    fn new(nb: usize) -> Self {
        let s = vec![SpatialLanes::default(); nb];
        Self {
            ycrb: vec![Composite::default(); nb],
            dycrb: vec![InertiaRate::default(); nb],
            j: s.clone(),
            ov: s.clone(),
            oa: s.clone(),
            of: s.clone(),
            dvdq: s.clone(),
            dadq: s.clone(),
            dadv: s.clone(),
            dfda: s.clone(),
            dfdq: s.clone(),
            dfdv: s.clone(),
            dytj: s.clone(),
            of_rest: s.clone(),
            dadq_rest: s.clone(),
            dfdq_rest: s,
            tau: vec![Lanes::default(); nb],
            m: vec![Lanes::default(); nb * nb],
            dq: vec![Lanes::default(); nb * nb],
            dv: vec![Lanes::default(); nb * nb],
            gs: vec![Lanes::default(); nb * nb],
        }
    }
}

impl LaneKernel for Derivatives<'_> {
    type Output = Result<()>;

    #[inline(always)]
    fn wide<const W: usize>(mut self, model: &Model, data: &mut LaneBuffers<W>) -> Result<()> {
        let mut d = data
            .derivatives
            .take()
            .unwrap_or_else(|| Box::new(Buffers::new(model.nbodies())));
        let (n, nn) = (model.nv, model.nv * model.nv);
        let minus_g = model.base_acceleration(self.gravity);
        let mut first = 0;
        // vouched for: rows checked as they are written (the armature added in the lanes)
        let mut finite = !model.coupled;
        let values = self.out.iter().map(|o| o.len()).sum::<usize>()
            + self.g_static.as_deref().map_or(0, <[f64]>::len);
        let stores = data.stores(values);
        while first < self.k {
            let used = (self.k - first).min(W);
            data.load(model, self.x, first, Trig::Loaded);
            recursion(model, data, &mut d, &minus_g, self.g_static.is_some());
            let [tau, m, dq, dv] = &mut self.out;
            if !model.coupled {
                armature_torques(model, &mut d.tau, &data.ab);
                armature_inertia(model, &mut d.m);
            }
            let zeros = &data.m_zeros;
            finite &= write_vectors(model, &d.tau, used, &mut tau[first * n..], stores);
            finite &= write_matrices(model, &d.m, zeros, used, &mut m[first * nn..], stores);
            finite &= write_matrices(model, &d.dq, zeros, used, &mut dq[first * nn..], stores);
            finite &= write_matrices(model, &d.dv, zeros, used, &mut dv[first * nn..], stores);
            // a coupled model's armature onto its degrees of freedom (not vouched for)
            for s in (first..first + used).filter(|_| model.coupled) {
                model.add_armature_torque(&self.x[2][s * n..(s + 1) * n], &mut tau[s * n..][..n]);
                model.add_armature_inertia(&mut m[s * nn..(s + 1) * nn]);
            }
            if let Some(gs) = self.g_static.as_deref_mut() {
                let gs = &mut gs[first * nn..];
                finite &= write_matrices(model, &d.gs, zeros, used, gs, stores);
            }
            first += W;
        }
        data.derivatives = Some(d);
        data.finite = finite;
        Ok(())
    }

    fn scalar(self, model: &Model, data: &mut Data) -> Result<()> {
        let (n, nn) = (model.nv, model.nv * model.nv);
        let [tau, m, dq, dv] = self.out;
        let copy = crate::algorithms::row_major::copy_row_major;
        let mut lin = Linearization::zeros(n);
        let mut gs = self.g_static;
        for s in 0..self.k {
            let r = s * n..(s + 1) * n;
            let [q, qd, qdd] = self.x.map(|x| &x[r.clone()]);
            let mr = s * nn..(s + 1) * nn;
            if let Some(gs) = gs.as_deref_mut() {
                linearize_into(model, data, q, qd, qdd, self.gravity, &mut lin)?;
                tau[r].copy_from_slice(lin.torque.as_slice());
                copy(&lin.d, &mut m[mr.clone()]);
                copy(&lin.g, &mut dq[mr.clone()]);
                copy(&lin.h, &mut dv[mr.clone()]);
                copy(&lin.g_static, &mut gs[mr]);
            } else {
                crate::rnea_derivatives(model, data, q, qd, qdd, self.gravity)?;
                tau[r].copy_from_slice(data.tau.as_slice());
                copy(&data.m, &mut m[mr.clone()]);
                copy(&data.dtau_dq, &mut dq[mr.clone()]);
                copy(&data.dtau_dv, &mut dv[mr]);
            }
        }
        Ok(())
    }
}

/// Lanes `0..used` of the body torques `body` summed onto the degrees of freedom into the
/// row-major `out` (`used x nv`); whether every value was checked finite (see `write_rows`, and
/// there for `stores`).
#[inline(always)]
fn write_vectors<const W: usize>(
    model: &Model,
    body: &[Lanes<W>],
    used: usize,
    out: &mut [f64],
    stores: Stores,
) -> bool {
    let nv = model.nv;
    if model.coupled {
        for (l, out) in out.chunks_mut(nv).take(used).enumerate() {
            out.fill(0.0);
            for (i, b) in model.bodies.iter().enumerate() {
                out[b.dof] += b.multiplier * body[i].0[l];
            }
        }
        false
    } else {
        write_rows(body, used, out, nv, stores)
    }
}

/// Lanes `0..used` of the body-level row-major matrix `body` as `C^T body C` (the degrees of
/// freedom) into the row-major `out` (`used x nv x nv`); whether every value was checked finite
/// (`stores` as for `write_rows`). `zeros` is [`LaneBuffers::m_zeros`]: the entries that pair
/// no body with an ancestor or descendant are zero in every one of these matrices (a torque
/// moves with the coordinates and rates of its body's ancestors and subtree only), and are
/// written as zeros without being read.
#[inline(always)]
fn write_matrices<const W: usize>(
    model: &Model,
    body: &[Lanes<W>],
    zeros: &ZeroPattern,
    used: usize,
    out: &mut [f64],
    stores: Stores,
) -> bool {
    let (nb, nv) = (model.nbodies(), model.nv);
    if model.coupled {
        for (l, out) in out.chunks_mut(nv * nv).take(used).enumerate() {
            out.fill(0.0);
            for (i, bi) in model.bodies.iter().enumerate() {
                for (j, bj) in model.bodies.iter().enumerate() {
                    out[bi.dof * nv + bj.dof] +=
                        bi.multiplier * bj.multiplier * body[i * nb + j].0[l];
                }
            }
        }
        false
    } else {
        write_rows_with_zeros(body, Some(zeros), used, out, nv * nv, stores)
    }
}

/// The recursion for the loaded lanes: body-level `tau`, `M`, `d tau / d q` and
/// `d tau / d qd` into `d` (`Gs` too when `at_rest`). The matrices' pairs of bodies of which
/// neither is in the other's subtree (`LaneBuffers::m_zeros`) are never written: zero since
/// the buffers were made.
#[inline(always)]
fn recursion<const W: usize>(
    model: &Model,
    data: &mut LaneBuffers<W>,
    d: &mut Buffers<W>,
    minus_g: &crate::spatial::Motion,
    at_rest: bool,
) {
    let nb = model.nbodies();
    let base_a = SpatialLanes {
        ang: Vector3Lanes::splat(&minus_g.angular),
        lin: Vector3Lanes::splat(&minus_g.linear),
    };
    for (i, b) in serial(model.bodies.iter().enumerate()) {
        // the base-frame pose of the body's turned frame where it has one (as the mass matrix:
        // the inertia below is then taken in that frame; every other quantity here is in the
        // base frame, whatever frame the bodies are described in)
        let (h, split) = match &b.turned {
            Some(t) => {
                store_turned_pose_in_base(model, data, i, t);
                (&t.h, &t.split)
            }
            None => {
                store_pose_in_base(model, data, i);
                (&b.origin_inertia.h, &b.split_inertia)
            }
        };
        let (r, p) = (data.o_rot[i], data.o_pos[i]);
        let j = data.o_s[i];
        let (ov_p, oa_p) = match b.parent {
            Some(k) => (d.ov[k], d.oa[k]),
            None => (SpatialLanes::default(), base_a),
        };
        let vj = j.mul_lanes(data.vb[i]);
        let ov = ov_p.add(&vj);
        let oa = oa_p.add(&j.mul_lanes(data.ab[i])).add(&ov.cross(&vj));
        let y = transformed(b.origin_inertia.mass, h, split, &r, &p);
        let oh = y.apply(&ov);
        d.of[i] = y.apply(&oa).add(&ov.cross_force(&oh));
        d.ov[i] = ov;
        d.oa[i] = oa;
        d.ycrb[i] = y;
        let dy = InertiaRate::new(&y, &ov, &oh);
        d.dycrb[i] = dy;
        d.j[i] = j;
        let mut dadq = oa_p.cross(&j);
        let mut dadv = ov.cross(&j);
        if b.parent.is_some() {
            let dvdq = ov_p.cross(&j);
            dadq = dadq.add(&ov_p.cross(&dvdq));
            dadv = dadv.add(&dvdq);
            d.dvdq[i] = dvdq;
        } else {
            d.dvdq[i] = SpatialLanes::default();
        }
        d.dadq[i] = dadq;
        d.dadv[i] = dadv;
        if at_rest {
            // at rest every body accelerates with the base (gravity only): no velocity terms
            d.of_rest[i] = y.apply(&base_a);
            d.dadq_rest[i] = base_a.cross(&j);
        }
    }

    for i in serial((0..nb).rev()) {
        let b = &model.bodies[i];
        let end = b.subtree_end;
        let j = d.j[i];
        d.tau[i] = j.dot(&d.of[i]);

        // d tau / d qdd (the mass matrix)
        d.dfda[i] = d.ycrb[i].apply(&j);
        for k in serial(i..end) {
            let v = j.dot(&d.dfda[k]);
            d.m[i * nb + k] = v;
            d.m[k * nb + i] = v;
        }

        // d tau / d q
        d.dfdq[i] = d.dycrb[i].mul(&d.dvdq[i]).add(&d.ycrb[i].apply(&d.dadq[i]));
        d.dytj[i] = d.dycrb[i].tr_mul(&j);
        let (dadq, dvdq) = (d.dadq[i], d.dvdq[i]);
        for k in serial((i + 1)..end) {
            d.dq[k * nb + i] = d.dfda[k].dot_add(&dadq, d.dytj[k].dot(&dvdq));
        }
        for k in serial(i..end) {
            d.dq[i * nb + k] = j.dot(&d.dfdq[k]);
        }
        d.dfdq[i] = d.dfdq[i].add(&j.cross_force(&d.of[i]));

        // d tau / d qd
        d.dfdv[i] = d.dycrb[i].mul(&j).add(&d.ycrb[i].apply(&d.dadv[i]));
        let dadv = d.dadv[i];
        for k in serial((i + 1)..end) {
            d.dv[k * nb + i] = d.dfda[k].dot_add(&dadv, d.dytj[k].dot(&j));
        }
        for k in serial(i..end) {
            d.dv[i * nb + k] = j.dot(&d.dfdv[k]);
        }

        // d g / d q at rest: the same recursion with v = 0 (so dY = 0, dv/dq = 0) and every
        // body accelerating with the base
        if at_rest {
            d.dfdq_rest[i] = d.ycrb[i].apply(&d.dadq_rest[i]);
            let dadq = d.dadq_rest[i];
            for k in serial((i + 1)..end) {
                d.gs[k * nb + i] = d.dfda[k].dot(&dadq);
            }
            for k in serial(i..end) {
                d.gs[i * nb + k] = j.dot(&d.dfdq_rest[k]);
            }
            d.dfdq_rest[i] = d.dfdq_rest[i].add(&j.cross_force(&d.of_rest[i]));
            if let Some(p) = b.parent {
                let fi = d.of_rest[i];
                d.of_rest[p] = d.of_rest[p].add(&fi);
            }
        }

        if let Some(p) = b.parent {
            let (yi, dyi, fi) = (d.ycrb[i], d.dycrb[i], d.of[i]);
            d.ycrb[p].add_assign(&yi);
            d.dycrb[p].add_assign(&dyi);
            d.of[p] = d.of[p].add(&fi);
        }
    }
}
