//! The robot's parameters from local models (the paper's claim, section 9 of docs/method.md):
//! T* (the whole torque at the point), D* = M(q*), and H*, G*, Gs where identified are all
//! linear in the inertial and friction parameters, so local models at one or more operating
//! points stack into one linear system ([`crate::algorithms::linearization_regressor`]),
//! solved by weighted least squares with the models' standard errors.

use nalgebra::{DMatrix, DVector};

use super::model::{Estimate, Estimator, LocalModel};
use crate::algorithms::linearization_regressor::linearization_regressor;
use crate::direct::base::{BaseParameters, BASE_TOLERANCE};
use crate::direct::{
    consistent_least_squares, BaseModel, ConsistentFit, ConsistentOptions, FrictionTerms,
    ParameterLayout, Weighting,
};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::regression::least_squares;

/// Options of [`identify_parameters_from_local`].
#[derive(Clone, Debug, PartialEq)]
pub struct FromLocalOptions {
    /// Joint terms to identify with the inertial parameters (default none; the armature is
    /// added when the robot model has one, [`FrictionTerms::for_model`]).
    pub friction: FrictionTerms,
    /// Whether the local models' torques include gravity (default true).
    pub gravity: Gravity,
    /// Which parts of the local models to use (default all: T*, D*, H*, G*, Gs).
    pub use_torque: bool,
    pub use_d: bool,
    pub use_h: bool,
    pub use_g: bool,
    pub use_g_static: bool,
    /// Also fit physically consistent parameters (see [`crate::direct::consistent`]), with
    /// these options; `None` (default) for the unconstrained fit only.
    pub consistent: Option<ConsistentOptions>,
}

impl Default for FromLocalOptions {
    fn default() -> Self {
        Self {
            friction: FrictionTerms::NONE,
            gravity: Gravity::Included,
            use_torque: true,
            use_d: true,
            use_h: true,
            use_g: true,
            use_g_static: true,
            consistent: None,
        }
    }
}

/// The result: the identified parameters as a base-parameter model (predict, linearize, save
/// like any), and what these points could identify.
#[derive(Clone, Debug, PartialEq)]
pub struct ParametersFromLocal {
    /// The combinations the points identify, their values and standard errors.
    pub model: BaseModel,
    /// How many independent combinations the points identify.
    pub rank: usize,
    /// How many base parameters the robot has (identified from states spread over its
    /// workspace): `rank == robot_rank` means every one was reached.
    pub robot_rank: usize,
    /// The robot's base parameters that these points cannot separate from the others (by the
    /// name of the robot's base column); empty when `rank == robot_rank`.
    pub unidentified: Vec<String>,
    /// Rows of the stacked system used.
    pub rows: usize,
    /// The consistent fit of the same rows, when asked for; the robot's own parameters are
    /// its prior (they decide what the points do not).
    pub consistent: Option<ConsistentFit>,
}

/// Weight floor: standard errors below this fraction of the block's largest entry (noise-free
/// models) are raised to it, so that no row gets an infinite weight.
const WEIGHT_FLOOR: f64 = 1e-9;

/// Refuses a model of `models` that is another one again (the same document: estimates,
/// standard errors and operating point, bit for bit), naming both: its estimates' noise would
/// count as independent twice. Two models identified at one point from other recordings pass.
fn refuse_repeated_models(models: &[LocalModel]) -> Result<()> {
    let texts: Vec<String> = models.iter().map(|m| m.to_json()).collect();
    let mut seen: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for (b, text) in texts.iter().enumerate() {
        if let Some(&a) = seen.get(text.as_str()) {
            return Err(Error::invalid(
                format!("models[{b}]"),
                format!(
                    "the same local model as models[{a}] (the same estimates at the same operating point): give each model once (its noise would count as independent twice)"
                ),
            ));
        }
        seen.insert(text, b);
    }
    Ok(())
}

/// How many operating points `models` were identified at (planned points that differ in any
/// value).
pub fn operating_points(models: &[LocalModel]) -> usize {
    let mut points: Vec<&super::OperatingPoint> = vec![];
    for m in models {
        if !points.iter().any(|p| **p == m.planned_op) {
            points.push(&m.planned_op);
        }
    }
    points.len()
}

/// Row-major entries of a matrix (entry `(i, j)` at `i * n + j`).
fn entries(m: &DMatrix<f64>) -> Vec<f64> {
    (0..m.nrows())
        .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
        .collect()
}

/// The robot's inertial (and friction) parameters from local models at one or more operating
/// points: see the module documentation. Each model's T*, D*, H*, G*, Gs (as `options` says,
/// where identified) is a block of rows, each row divided by its standard error; the
/// combinations the rows determine are found by a column-pivoted QR, and solved by least
/// squares. The operating points are the models' planned ones (where T* holds). Rows a model
/// marks as not measured (`diagnostics.unmeasured`: a torque that did not change) are left
/// out.
///
/// Errors: no model, a model for other joints than `robot`'s, a model given twice (the same
/// document again).
pub fn identify_parameters_from_local(
    robot: &Model,
    models: &[LocalModel],
    options: &FromLocalOptions,
) -> Result<ParametersFromLocal> {
    let nv = robot.nv;
    if models.is_empty() {
        return Err(Error::invalid("models", "no local model given"));
    }
    refuse_repeated_models(models)?;
    let layout = ParameterLayout::new(robot, options.friction.for_model(robot));
    let mut stacked = Rows::default();
    for (i, m) in models.iter().enumerate() {
        stacked.push_model(robot, &layout, i, m, options)?;
    }
    let Rows { x, y, w, joint } = stacked;
    let rows = x.len();
    let p = layout.len();
    let phi = DMatrix::from_fn(rows, p, |r, c| x[r][c]);
    // the pivoted QR wants at least as many rows as columns: zero rows change nothing
    let padded = if rows < p {
        phi.clone().resize_vertically(p, 0.0)
    } else {
        phi.clone()
    };
    let base = BaseParameters::from_regressor(layout.clone(), &padded, BASE_TOLERANCE)?;
    let columns = base.names();
    let ls = least_squares(
        &base.select(&phi),
        &DMatrix::from_column_slice(rows, 1, &y),
        "parameters from local models",
        &columns,
    )?;
    // residuals in N m (unweighted), by the torque row they belong to
    let phi_base = base.select(&phi);
    let residual_rms = |theta_base: &[f64]| {
        let fitted = &phi_base * DVector::from_column_slice(theta_base);
        let mut ss = vec![0.0; nv];
        let mut count = vec![0usize; nv];
        for r in 0..rows {
            ss[joint[r]] += ((y[r] - fitted[r]) * w[r]).powi(2);
            count[joint[r]] += 1;
        }
        (0..nv)
            .map(|j| (ss[j] / count[j].max(1) as f64).sqrt())
            .collect::<Vec<f64>>()
    };
    let robot_base = BaseParameters::from_random_states(
        robot,
        &layout,
        options.gravity,
        20 * p,
        BASE_TOLERANCE,
        1,
    )?;
    let unidentified = unidentified(&layout, &padded, &base, &robot_base)?;
    let rank = base.len();
    // the data's map is the robot's where they identify every base parameter
    let base = BaseParameters {
        structural: rank == robot_base.len(),
        ..base
    };
    let unchecked = BaseModel::without_checks(robot, base, options.gravity, Weighting::Wls, &ls);
    let model = BaseModel {
        residual_rms: residual_rms(&unchecked.theta),
        ..unchecked
    };
    let consistent = match &options.consistent {
        None => None,
        Some(c) => {
            let solution = consistent_least_squares(
                &layout,
                &phi,
                &DVector::from_column_slice(&y),
                0.0,
                layout.model_parameters(robot).as_slice(),
                c,
            )?;
            let theta_c: Vec<f64> = model
                .base
                .from_full(&DVector::from_column_slice(&solution.theta))?
                .iter()
                .copied()
                .collect();
            let consistent_model = BaseModel {
                residual_rms: residual_rms(&theta_c),
                theta: theta_c,
                ..model.clone()
            };
            Some(ConsistentFit {
                layout: layout.clone(),
                solution,
                model: consistent_model,
                unconstrained: model.clone(),
            })
        }
    };
    Ok(ParametersFromLocal {
        model,
        rank,
        robot_rank: robot_base.len(),
        unidentified,
        rows,
        consistent,
    })
}

/// The stacked rows of the local models: each row of the regressor and its value divided by
/// the value's standard error `w`, and the joint (torque row) it belongs to.
#[derive(Default)]
struct Rows {
    x: Vec<Vec<f64>>,
    y: Vec<f64>,
    w: Vec<f64>,
    joint: Vec<usize>,
}

impl Rows {
    /// Adds the rows of one block: `values` (row-major, `nv` or `nv x nv`) with their
    /// standard errors and the regressor's rows, less the rows of unmeasured torques.
    fn push_block(
        &mut self,
        regressor: &DMatrix<f64>,
        values: &[f64],
        stderr: &[f64],
        nv: usize,
        unmeasured: &[bool],
    ) {
        let scale = values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let floor = WEIGHT_FLOOR * scale + 1e-12;
        for (r, (&v, &se)) in values.iter().zip(stderr).enumerate() {
            let torque_row = if values.len() == nv { r } else { r / nv };
            if unmeasured.get(torque_row).copied().unwrap_or(false) {
                continue;
            }
            let se = if se.is_finite() {
                se.max(floor)
            } else {
                floor.max(scale)
            };
            self.x
                .push(regressor.row(r).iter().map(|a| a / se).collect());
            self.y.push(v / se);
            self.w.push(se);
            self.joint.push(torque_row);
        }
    }

    /// Adds the rows of model `i`, `m`, as `options` choose them.
    fn push_model(
        &mut self,
        robot: &Model,
        layout: &ParameterLayout,
        i: usize,
        m: &LocalModel,
        options: &FromLocalOptions,
    ) -> Result<()> {
        let nv = robot.nv;
        crate::interrupt::check("parameters from local models")?;
        if m.joint_names != robot.joint_names {
            return Err(Error::invalid(
                format!("models[{i}]"),
                format!(
                    "identified for joints [{}]; the robot '{}' has [{}]",
                    m.joint_names.join(", "),
                    robot.name,
                    robot.joint_names.join(", ")
                ),
            ));
        }
        let op = &m.planned_op;
        let reg = linearization_regressor(robot, layout, &op.q, &op.qd, &op.qdd, options.gravity)?;
        if options.use_torque {
            self.push_block(&reg.torque, &m.torque, &m.torque_stderr, nv, &[]);
        }
        // the rows of a torque that did not change (the combined estimate's D, H and G share
        // theirs)
        let unmeasured = |experiment: &str| -> Vec<bool> {
            let combined = m.estimator == Estimator::Combined && experiment != "G_static";
            robot
                .joint_names
                .iter()
                .map(|j| {
                    m.diagnostics.unmeasured.iter().any(|u| {
                        &u.joint == j
                            && (u.experiment == experiment
                                || (combined && u.experiment != "G_static"))
                    })
                })
                .collect()
        };
        let mut block = |e: &Option<Estimate>, r: &DMatrix<f64>, experiment: &str| {
            if let Some(e) = e {
                self.push_block(
                    r,
                    &entries(&e.matrix),
                    &entries(&e.stderr),
                    nv,
                    &unmeasured(experiment),
                );
            }
        };
        if options.use_d {
            block(&m.d, &reg.d, "D");
        }
        if options.use_h {
            block(&m.h, &reg.h, "H");
        }
        if options.use_g {
            block(&m.g, &reg.g, "G");
        }
        if options.use_g_static && options.gravity == Gravity::Included {
            block(&m.g_static, &reg.g_static, "G_static");
        }
        Ok(())
    }
}

/// Which of the robot's base columns the data cannot separate: the pivoted QR of the data
/// (`padded`, whose base is `base`) restricted to those columns drops exactly them.
fn unidentified(
    layout: &ParameterLayout,
    padded: &DMatrix<f64>,
    base: &BaseParameters,
    robot_base: &BaseParameters,
) -> Result<Vec<String>> {
    if base.len() >= robot_base.len() {
        return Ok(vec![]);
    }
    let mut masked = padded.clone();
    for c in 0..layout.len() {
        if !robot_base.kept.contains(&c) {
            masked.column_mut(c).fill(0.0);
        }
    }
    let within = BaseParameters::from_regressor(layout.clone(), &masked, BASE_TOLERANCE)?;
    let names = robot_base.names();
    Ok(robot_base
        .kept
        .iter()
        .zip(names)
        .filter(|(k, _)| within.dropped.contains(k))
        .map(|(_, n)| n)
        .collect())
}
