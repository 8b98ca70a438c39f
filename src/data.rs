//! Preallocated work buffers and results of the algorithms, one per [`Model`] (Pinocchio's
//! `Data`). Create it once with [`Data::new`] and reuse it for every sample: the algorithms do
//! not allocate.

use nalgebra::{DMatrix, DVector, Matrix6, Vector6};

use crate::model::Model;
use crate::spatial::{Force, Motion, OriginInertia, Se3};

/// Buffers and results. Results are in degree-of-freedom coordinates (`nv`), in the units of the
/// joints (rad, m, N m, N).
#[derive(Clone, Debug)]
pub struct Data {
    /// Joint torques from [`crate::rnea`] (`nv`).
    pub tau: DVector<f64>,
    /// Gravity torque `g(q)` from [`crate::gravity_torque`] (`nv`).
    pub g: DVector<f64>,
    /// Bias torque `c(q, qd) + g(q)` from [`crate::bias_torque`] (`nv`).
    pub bias: DVector<f64>,
    /// Mass matrix `M(q)` from [`crate::mass_matrix`] or [`crate::rnea_derivatives`] (`nv x nv`,
    /// both triangles filled).
    pub m: DMatrix<f64>,
    /// Accelerations from [`crate::forward_dynamics`] (`nv`).
    pub qdd: DVector<f64>,
    /// `d tau / d q` from [`crate::rnea_derivatives`] (`nv x nv`, row = torque, column = joint).
    pub dtau_dq: DMatrix<f64>,
    /// `d tau / d qd` from [`crate::rnea_derivatives`] (`nv x nv`).
    pub dtau_dv: DMatrix<f64>,

    // Body coordinates (one per body; equal to the dof ones for uncoupled models).
    pub(crate) qb: Vec<f64>,
    pub(crate) vb: Vec<f64>,
    pub(crate) ab: Vec<f64>,
    // Local-frame recursion.
    pub(crate) li_mi: Vec<Se3>,
    pub(crate) v: Vec<Motion>,
    pub(crate) a: Vec<Motion>,
    pub(crate) f: Vec<Force>,
    /// Composite inertias in the base frame (mass matrix).
    pub(crate) ycrb: Vec<OriginInertia>,
    // World-frame recursion of the derivatives.
    pub(crate) o_mi: Vec<Se3>,
    pub(crate) ov: Vec<Motion>,
    pub(crate) oa_gf: Vec<Motion>,
    pub(crate) of: Vec<Force>,
    pub(crate) o_ycrb: Vec<Matrix6<f64>>,
    pub(crate) do_ycrb: Vec<Matrix6<f64>>,
    pub(crate) j: Vec<Vector6<f64>>,
    pub(crate) dvdq: Vec<Vector6<f64>>,
    pub(crate) dadq: Vec<Vector6<f64>>,
    pub(crate) dadv: Vec<Vector6<f64>>,
    pub(crate) dfda: Vec<Vector6<f64>>,
    pub(crate) dfdq: Vec<Vector6<f64>>,
    pub(crate) dfdv: Vec<Vector6<f64>>,
    pub(crate) dytj: Vec<Vector6<f64>>,
    // Body-level results (coupled models only).
    pub(crate) tau_b: DVector<f64>,
    pub(crate) m_b: DMatrix<f64>,
    pub(crate) dq_b: DMatrix<f64>,
    pub(crate) dv_b: DMatrix<f64>,
    // Cholesky factor scratch for forward dynamics.
    pub(crate) chol: DMatrix<f64>,
    /// Motion subspaces of the bodies in the base frame (regressor).
    pub(crate) s_world: Vec<Motion>,
    /// Scratch for the joint-torque regressor (`nv x 10 nbodies`).
    pub(crate) regressor: DMatrix<f64>,
    /// Articulated-body inertias and bias forces, `U = IA S` and `1 / D` of [`crate::aba`]
    /// (body frames).
    pub(crate) aba_ia: Vec<Matrix6<f64>>,
    pub(crate) aba_pa: Vec<Vector6<f64>>,
    pub(crate) aba_u: Vec<Vector6<f64>>,
    pub(crate) aba_dinv: Vec<f64>,
    pub(crate) aba_c: Vec<Motion>,
}

impl Data {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        let nb = model.nbodies();
        let v6 = vec![Vector6::zeros(); nb];
        let m6 = vec![Matrix6::zeros(); nb];
        // body-level results are only needed when bodies and dofs differ
        let nc = if model.coupled { nb } else { 0 };
        Self {
            tau: DVector::zeros(n),
            g: DVector::zeros(n),
            bias: DVector::zeros(n),
            m: DMatrix::zeros(n, n),
            qdd: DVector::zeros(n),
            dtau_dq: DMatrix::zeros(n, n),
            dtau_dv: DMatrix::zeros(n, n),
            qb: vec![0.0; nb],
            vb: vec![0.0; nb],
            ab: vec![0.0; nb],
            li_mi: vec![Se3::identity(); nb],
            v: vec![Motion::zeros(); nb],
            a: vec![Motion::zeros(); nb],
            f: vec![Force::zeros(); nb],
            ycrb: vec![OriginInertia::default(); nb],
            o_mi: vec![Se3::identity(); nb],
            ov: vec![Motion::zeros(); nb],
            oa_gf: vec![Motion::zeros(); nb],
            of: vec![Force::zeros(); nb],
            o_ycrb: m6.clone(),
            do_ycrb: m6,
            j: v6.clone(),
            dvdq: v6.clone(),
            dadq: v6.clone(),
            dadv: v6.clone(),
            dfda: v6.clone(),
            dfdq: v6.clone(),
            dfdv: v6.clone(),
            dytj: v6,
            tau_b: DVector::zeros(nc),
            m_b: DMatrix::zeros(nc, nc),
            dq_b: DMatrix::zeros(nc, nc),
            dv_b: DMatrix::zeros(nc, nc),
            chol: DMatrix::zeros(n, n),
            regressor: DMatrix::zeros(n, 10 * model.nbodies()),
            s_world: vec![Motion::zeros(); model.nbodies()],
            aba_ia: vec![Matrix6::zeros(); nb],
            aba_pa: vec![Vector6::zeros(); nb],
            aba_u: vec![Vector6::zeros(); nb],
            aba_dinv: vec![0.0; nb],
            aba_c: vec![Motion::zeros(); nb],
        }
    }

    /// Whether these buffers have `model`'s sizes (degrees of freedom, bodies, and the body-level
    /// results of a coupled model), as [`Data::new`] makes them.
    pub(crate) fn fits(&self, model: &Model) -> bool {
        let nc = if model.coupled { model.nbodies() } else { 0 };
        self.tau.len() == model.nv && self.qb.len() == model.nbodies() && self.m_b.nrows() == nc
    }

    /// Fails unless [`Data::fits`] `model` (as `LaneData`'s check): the one-sample algorithms
    /// would index past buffers made for a smaller model.
    pub(crate) fn check(&self, model: &Model) -> crate::error::Result<()> {
        if self.fits(model) {
            return Ok(());
        }
        Err(crate::error::Error::shape(
            "data",
            format!(
                "buffers for this model ({} dofs, {} bodies): Data::new(&model)",
                model.nv,
                model.nbodies()
            ),
            format!(
                "buffers for {} dofs and {} bodies",
                self.tau.len(),
                self.qb.len()
            ),
        ))
    }
}
