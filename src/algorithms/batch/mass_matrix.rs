//! Joint-space mass matrices of many samples on the lanes (the composite rigid body algorithm
//! in the base frame).

use super::kinematics::store_pose_in_base;
use super::{armature_inertia, dispatch, samples, LaneBuffers, LaneData, LaneKernel, Trig};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::simd::{
    serial, write_rows_with_zeros, Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes,
};
use crate::spatial::OriginInertia;

/// Joint-space mass matrices `M(q)` of a batch, [`LaneData::width`] samples at a time (8 on
/// AVX2, in pairs of registers): the composite rigid body algorithm in the base frame, as
/// [`crate::mass_matrix`], equal to it up to rounding.
///
/// `q`: row-major `k x nv` (rad or m), finite (checked by the caller, as for
/// [`super::rnea_lanes`]). `out`: row-major `k x nv x nv` (kg m^2, kg m or kg), both triangles
/// written. Runs on the instruction set of `data`.
pub fn mass_matrix_batch(
    model: &Model,
    data: &mut LaneData,
    q: &[f64],
    out: &mut [f64],
) -> Result<()> {
    let nv = model.nv;
    let k = samples(nv, q.len(), &[("mass matrix output", out.len(), nv * nv)])?;
    dispatch(model, data, MassMatrix { k, q, out })
}

struct MassMatrix<'a> {
    k: usize,
    q: &'a [f64],
    out: &'a mut [f64],
}

/// A composite inertia per lane in origin form (mass, first moment `h`, rotational inertia `i`
/// about the origin, by rows); the mass is the same in every lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Composite<const W: usize> {
    pub(crate) mass: f64,
    pub(crate) h: Vector3Lanes<W>,
    pub(crate) i: Rotation3Lanes<W>,
}

impl<const W: usize> Composite<W> {
    /// The composite of two bodies (inertias in one frame).
    #[inline(always)]
    pub(crate) fn add(&self, o: &Self) -> Self {
        Self {
            mass: self.mass + o.mass,
            h: self.h.add(&o.h),
            i: self.i.add(&o.i),
        }
    }
}

impl<const W: usize> Default for Composite<W> {
    fn default() -> Self {
        Self {
            mass: 0.0,
            h: Vector3Lanes::default(),
            i: Rotation3Lanes::default(),
        }
    }
}

impl LaneKernel for MassMatrix<'_> {
    type Output = Result<()>;
    const PAIRS_ON_AVX2: bool = true;

    #[inline(always)]
    fn wide<const W: usize>(self, model: &Model, data: &mut LaneBuffers<W>) -> Result<()> {
        let (nv, nb) = (model.nv, model.nbodies());
        let mut first = 0;
        // vouched for: rows checked as they are written (the armature added in the lanes)
        let mut finite = !model.coupled;
        let stores = data.stores(self.out.len());
        while first < self.k {
            data.load(model, [self.q, &[], &[]], first, Trig::Loaded);
            // base-frame poses and motion subspaces
            for i in serial(0..nb) {
                store_pose_in_base(model, data, i);
            }
            let (m, zeros) = (&mut data.m, &data.m_zeros);
            // only the pairs of a body and its ancestors are written, the same in every group:
            // the others are cleared once per call (and those in blocks of structural zeros
            // are not even read: `m_zeros`)
            if first == 0 {
                m.fill(Lanes::default());
            }
            // composite inertias from the leaves up: each child's arrives in its parent's
            // `data.composite`, the first to arrive (the last child in depth-first order) by
            // assignment, so nothing is cleared
            for i in serial((0..nb).rev()) {
                let b = &model.bodies[i];
                let mut c = transformed(&b.origin_inertia, &data.o_rot[i], &data.o_pos[i]);
                if i + 1 < b.subtree_end {
                    c = c.add(&data.composite[i]);
                }
                let s = &data.o_s[i];
                let f = SpatialLanes {
                    ang: c.i.mul(&s.ang).add(&c.h.cross(&s.lin)),
                    lin: s.lin.scale_add(c.mass, &s.ang.cross(&c.h)),
                };
                let mut j = Some(i);
                while let Some(k) = j {
                    let mik = data.o_s[k].dot(&f);
                    m[i * nb + k] = mik;
                    m[k * nb + i] = mik;
                    j = model.bodies[k].parent;
                }
                match b.parent {
                    Some(p) if b.subtree_end == model.bodies[p].subtree_end => {
                        data.composite[p] = c
                    }
                    Some(p) => data.composite[p] = data.composite[p].add(&c),
                    None => {}
                }
            }
            // onto the degrees of freedom (mimic couplings), for the lanes in use
            let used = (self.k - first).min(W);
            let out = &mut self.out[first * nv * nv..];
            if model.coupled {
                for l in 0..used {
                    let o = &mut out[l * nv * nv..(l + 1) * nv * nv];
                    o.fill(0.0);
                    for (i, bi) in model.bodies.iter().enumerate() {
                        for (j, bj) in model.bodies.iter().enumerate() {
                            o[bi.dof * nv + bj.dof] +=
                                bi.multiplier * bj.multiplier * m[i * nb + j].0[l];
                        }
                    }
                    finite &= model.add_armature_inertia(o);
                }
            } else {
                armature_inertia(model, m);
                finite &= write_rows_with_zeros(m, Some(zeros), used, out, nv * nv, stores);
            }
            first += W;
        }
        data.finite = finite;
        Ok(())
    }

    fn scalar(self, model: &Model, data: &mut Data) -> Result<()> {
        let nv = model.nv;
        for (s, o) in self.out.chunks_mut(nv * nv).enumerate() {
            crate::algorithms::crba::mass_matrix(model, data, &self.q[s * nv..(s + 1) * nv])?;
            crate::algorithms::parallel::copy_row_major(&data.m, o);
        }
        Ok(())
    }
}

/// A body's (constant) origin-form inertia expressed in the base frame, for its pose `r`, `p`
/// there (see `OriginInertia::transformed`).
#[inline(always)]
pub(crate) fn transformed<const W: usize>(
    b: &OriginInertia,
    r: &Rotation3Lanes<W>,
    p: &Vector3Lanes<W>,
) -> Composite<W> {
    let hr = r.mul_const_vector(&b.h);
    let w = p.scale_add(0.5 * b.mass, &hr);
    let d = p.dot(&w) * 2.0;
    // rows of R I (I symmetric), then R I R^T - w p^T - p w^T + d 1: symmetric, so each
    // entry above the diagonal is computed once
    let ri = [
        r.0[0].mul_const(&b.i),
        r.0[1].mul_const(&b.i),
        r.0[2].mul_const(&b.i),
    ];
    // a function, not a closure: one compiled out of line would lose the instruction set
    #[inline(always)]
    fn entry<const W: usize>(
        ri: &[Vector3Lanes<W>; 3],
        r: &Rotation3Lanes<W>,
        w: &Vector3Lanes<W>,
        p: &Vector3Lanes<W>,
        row: usize,
        c: usize,
    ) -> Lanes<W> {
        let v = ri[row].dot(&r.0[c]);
        w.get(row)
            .neg_mul_add(p.get(c), p.get(row).neg_mul_add(w.get(c), v))
    }
    let i = symmetric(
        [
            entry(&ri, r, &w, p, 0, 0) + d,
            entry(&ri, r, &w, p, 1, 1) + d,
            entry(&ri, r, &w, p, 2, 2) + d,
        ],
        [
            entry(&ri, r, &w, p, 0, 1),
            entry(&ri, r, &w, p, 0, 2),
            entry(&ri, r, &w, p, 1, 2),
        ],
    );
    Composite {
        mass: b.mass,
        h: p.scale_add(b.mass, &hr),
        i,
    }
}

/// The symmetric 3x3 matrix of diagonal `[xx, yy, zz]` and upper entries `[xy, xz, yz]`.
#[inline(always)]
pub(crate) fn symmetric<const W: usize>(
    diag: [Lanes<W>; 3],
    upper: [Lanes<W>; 3],
) -> Rotation3Lanes<W> {
    let ([xx, yy, zz], [xy, xz, yz]) = (diag, upper);
    Rotation3Lanes([
        Vector3Lanes {
            x: xx,
            y: xy,
            z: xz,
        },
        Vector3Lanes {
            x: xy,
            y: yy,
            z: yz,
        },
        Vector3Lanes {
            x: xz,
            y: yz,
            z: zz,
        },
    ])
}
