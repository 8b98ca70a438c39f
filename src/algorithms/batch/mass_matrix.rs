//! Joint-space mass matrices of many samples on the lanes (the composite rigid body algorithm
//! in the base frame).

use super::kinematics::{store_pose_in_base, store_turned_pose_in_base};
use super::{armature_inertia, dispatch, samples, LaneBuffers, LaneData, LaneKernel, Trig};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::simd::{
    serial, write_rows_with_zeros, Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes,
};
use crate::spatial::SplitInertia;
use nalgebra::Vector3;

/// Joint-space mass matrices `M(q)` of a batch, [`LaneData::width`] samples at a time: the
/// composite rigid body algorithm in the base frame, as [`crate::mass_matrix`], equal to it up
/// to rounding.
///
/// `q`: row-major `k x nv` (rad or m), finite (checked by the caller, as for
/// [`super::rnea_batch`]). `out`: row-major `k x nv x nv` (kg m^2, kg m or kg), both triangles
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

/// A composite inertia per lane as [`Composite`], its rotational inertia about the origin by its
/// six distinct entries (diagonal `[xx, yy, zz]`, upper `[xy, xz, yz]`; kg m^2): the mass
/// matrix's, a quarter fewer adds, loads and stores a body than the full 3x3 (measured
/// in-process on a Zen 4: AVX2 mass matrices 1.5-5 % faster, AVX-512 level to 1 %).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SymmetricComposite<const W: usize> {
    pub(crate) mass: f64,
    pub(crate) h: Vector3Lanes<W>,
    pub(crate) diag: [Lanes<W>; 3],
    pub(crate) upper: [Lanes<W>; 3],
}

impl<const W: usize> SymmetricComposite<W> {
    #[inline(always)]
    pub(crate) fn add(&self, o: &Self) -> Self {
        let [a, b, c] = self.diag;
        let [x, y, z] = self.upper;
        Self {
            mass: self.mass + o.mass,
            h: self.h.add(&o.h),
            diag: [a + o.diag[0], b + o.diag[1], c + o.diag[2]],
            upper: [x + o.upper[0], y + o.upper[1], z + o.upper[2]],
        }
    }
    /// The momentum `Y m` of this inertia (origin form, base frame) moving with twist `m`, as
    /// `Composite::apply` in the derivatives.
    #[inline(always)]
    pub(crate) fn apply(&self, m: &SpatialLanes<W>) -> SpatialLanes<W> {
        let ([xx, yy, zz], [xy, xz, yz], a) = (self.diag, self.upper, &m.ang);
        // I a + h x lin, the sum fused into the product's multiply-adds
        let hl = self.h.cross(&m.lin);
        SpatialLanes {
            ang: Vector3Lanes {
                x: xx.mul_add(a.x, xy.mul_add(a.y, xz.mul_add(a.z, hl.x))),
                y: xy.mul_add(a.x, yy.mul_add(a.y, yz.mul_add(a.z, hl.y))),
                z: xz.mul_add(a.x, yz.mul_add(a.y, zz.mul_add(a.z, hl.z))),
            },
            lin: m.lin.scale_add(self.mass, &m.ang.cross(&self.h)),
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
    // 4 lanes on AVX2 (measured against pairs of registers, since the split inertias and the
    // turned frames: the tree 4-5 % faster, the arms level)
    const PAIRS_ON_AVX2: bool = false;

    #[inline(always)]
    fn wide<const W: usize>(self, model: &Model, data: &mut LaneBuffers<W>) -> Result<()> {
        let (nv, nb) = (model.nv, model.nbodies());
        let mut first = 0;
        // vouched for: rows checked as they are written (the armature added in the lanes)
        let mut finite = !model.coupled;
        let stores = data.stores(self.out.len());
        while first < self.k {
            data.load(model, [self.q, &[], &[]], first, Trig::Loaded);
            // base-frame poses (of the turned frames where there are: the inertias below are
            // taken in the same frames) and motion subspaces
            for i in serial(0..nb) {
                match &model.bodies[i].turned {
                    Some(t) => store_turned_pose_in_base(model, data, i, t),
                    None => store_pose_in_base(model, data, i),
                }
            }
            let (m, zeros) = (&mut data.m, &data.m_zeros);
            // only the pairs of a body and its ancestors are written: the others (`m_zeros`)
            // are zero since the buffer was made (and those in blocks of structural zeros are
            // not even read)
            // composite inertias from the leaves up: each child's arrives in its parent's
            // `data.composite`, the first to arrive (the last child in depth-first order) by
            // assignment, so nothing is cleared
            for i in serial((0..nb).rev()) {
                let b = &model.bodies[i];
                let (h, split) = match &b.turned {
                    Some(t) => (&t.h, &t.split),
                    None => (&b.origin_inertia.h, &b.split_inertia),
                };
                let mass = b.origin_inertia.mass;
                let (h, diag, upper) =
                    transformed_parts(mass, h, split, &data.o_rot[i], &data.o_pos[i]);
                let mut c = SymmetricComposite {
                    mass,
                    h,
                    diag,
                    upper,
                };
                if i + 1 < b.subtree_end {
                    c = c.add(&data.composite[i]);
                }
                let f = c.apply(&data.o_s[i]);
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
            crate::algorithms::row_major::copy_row_major(&data.m, o);
        }
        Ok(())
    }
}

/// A body's (constant) origin-form inertia expressed in the base frame, for its pose `r`, `p`
/// there (see `OriginInertia::transformed`): `mass` (kg), first moment `h` (kg m) and the
/// rotational inertia about the origin as `split` ([`SplitInertia`]), in the body's frame.
#[inline(always)]
pub(crate) fn transformed<const W: usize>(
    mass: f64,
    h: &Vector3<f64>,
    split: &SplitInertia,
    r: &Rotation3Lanes<W>,
    p: &Vector3Lanes<W>,
) -> Composite<W> {
    let (h, diag, upper) = transformed_parts(mass, h, split, r, p);
    Composite {
        mass,
        h,
        i: symmetric(diag, upper),
    }
}

/// [`transformed`]'s first moment (kg m) and rotational inertia about the origin as its diagonal
/// `[xx, yy, zz]` and upper entries `[xy, xz, yz]` (kg m^2), in the base frame.
#[inline(always)]
pub(crate) fn transformed_parts<const W: usize>(
    mass: f64,
    h: &Vector3<f64>,
    split: &SplitInertia,
    r: &Rotation3Lanes<W>,
    p: &Vector3Lanes<W>,
) -> (Vector3Lanes<W>, [Lanes<W>; 3], [Lanes<W>; 3]) {
    let hr = r.mul_const_vector(h);
    let w = p.scale_add(0.5 * mass, &hr);
    // R I R^T - w p^T - p w^T + d 1 with R I R^T = base 1 + x x^T + y y^T (x, y turned):
    // symmetric, so each entry above the diagonal is computed once
    let d = p.dot(&w).mul_add_s(2.0, Lanes::splat(split.base));
    let x = r.mul_const_vector(&split.x);
    let y = r.mul_const_vector(&split.y);
    // a function, not a closure: one compiled out of line would lose the instruction set
    #[inline(always)]
    fn entry<const W: usize>(
        [x, y, w, p]: [&Vector3Lanes<W>; 4],
        row: usize,
        c: usize,
    ) -> Lanes<W> {
        let v = x.get(row).mul_add(x.get(c), y.get(row) * y.get(c));
        w.get(row)
            .neg_mul_add(p.get(c), p.get(row).neg_mul_add(w.get(c), v))
    }
    #[inline(always)]
    fn diagonal<const W: usize>(
        [x, y, w, p]: [&Vector3Lanes<W>; 4],
        d: Lanes<W>,
        row: usize,
    ) -> Lanes<W> {
        let (xr, yr) = (x.get(row), y.get(row));
        xr.mul_add(
            xr,
            yr.mul_add(yr, (w.get(row) * p.get(row)).mul_add_s(-2.0, d)),
        )
    }
    let v = [&x, &y, &w, p];
    (
        p.scale_add(mass, &hr),
        [diagonal(v, d, 0), diagonal(v, d, 1), diagonal(v, d, 2)],
        [entry(v, 0, 1), entry(v, 0, 2), entry(v, 1, 2)],
    )
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
