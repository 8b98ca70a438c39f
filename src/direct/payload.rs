//! A payload's inertial parameters identified from a log of the robot carrying it, against a
//! model of the robot without it (docs/method.md, section 8d).
//!
//! A payload rigidly fixed to one moving body `b` adds its ten inertial parameters `pi` (mass,
//! first moment and rotational inertia about the body's joint frame, Pinocchio's order: `m,
//! mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz`) to that body's, and the joint torques change by
//! that body's ten columns of the regressor:
//!
//! ```text
//! tau - tau_ref(q, qd, qdd) = Phi_b(q, qd, qdd) pi + F(qd) phi + e
//! ```
//!
//! `tau_ref` the robot's torques without the payload ([`Reference`]: a base-parameter model
//! identified from the robot alone, or the URDF's own parameters), `F phi` the joint terms
//! fitted beside it (each joint's viscous, Coulomb and offset terms, as far as asked for: a
//! sensor zeroed anew, friction the reference does not hold). One least-squares problem,
//! reduced per joint in one pass over the samples as the base parameters' is
//! ([`super::streaming`]), gives `pi` and `phi`, OLS and then WLS. Its standard errors are
//! inflated for residuals correlated from sample to sample ([`super::residual_correlation`]),
//! and a base-parameter reference's own uncertainty is carried into them:
//! `Cov(pi) += G Phi_base Cov(theta) Phi_base^T G^T`, `G` the weighted least-squares operator.
//! The payload's mass, centre of mass and inertia about it follow from `pi`, with standard
//! errors by the exact first-order (delta) rule.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::base::{BaseParameters, BASE_TOLERANCE};
use super::identify::{BaseModel, Weighting};
use super::parameters::{regressor_blocks, FrictionTerms, ParameterLayout};
use super::payload_estimate as estimate;
pub use super::payload_quantities::{in_link_frame, parameters_of_payload, payload_of_parameters};
use super::residual_correlation::{combine, long_run_factors, SAMPLES, SAMPLES_A_RUN};
use super::streaming::JointFactors;
use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::error::{shown, Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::rehearsal::Payload;
use crate::spatial::Se3;
use crate::states::States;

/// Standard errors a mass must lie above 0 by for the payload to count as seen (below it the
/// centre of mass, a first moment over the mass, is not determined).
pub const SEEN: f64 = 3.0;

/// The mass's standard error, relative to it, beyond which it is named as loosely determined.
pub const LOOSE_MASS: f64 = 0.05;

/// A centre of mass coordinate's standard error beyond which it is named as loosely
/// determined: this fraction of the centre's distance from the joint frame, or [`LOOSE_COM`]
/// metres where that is larger.
pub const LOOSE_COM_FRACTION: f64 = 0.1;

/// See [`LOOSE_COM_FRACTION`] (m).
pub const LOOSE_COM: f64 = 0.005;

/// An inertia entry's standard error, relative to the payload's largest principal moment,
/// beyond which the inertia is named as loosely determined.
pub const LOOSE_INERTIA: f64 = 0.25;

/// What the payload's torques are measured against.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// The URDF's own inertial parameters (and armature), taken as exact: their errors go into
    /// the payload unseen. No friction: fit the joint terms beside the payload.
    Urdf,
    /// A base-parameter model of the robot without the payload (its friction and offsets
    /// included), whose parameters' uncertainty is carried into the payload's.
    Model(&'a BaseModel),
}

/// How a payload's inertia about its centre of mass is taken ([`PayloadOptions::inertia`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PayloadInertia {
    /// Fitted with the mass and the centre of mass: all ten parameters.
    #[default]
    Fitted,
    /// Taken as 0 (a point mass): the mass and centre of mass alone are fitted, for logs that
    /// determine a small payload's inertia loosely or not at all (slow motion, or poses held
    /// still), and the payload given has no inertia about its centre.
    PointMass,
}

impl PayloadInertia {
    /// Its name on the command line and in files: `fitted`, `point_mass`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fitted => "fitted",
            Self::PointMass => "point_mass",
        }
    }

    /// The choice of `name` ([`Self::name`]).
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "fitted" => Ok(Self::Fitted),
            "point_mass" => Ok(Self::PointMass),
            other => Err(Error::InvalidArgument {
                argument: "inertia".into(),
                message: format!("'{other}', expected 'fitted' or 'point_mass'"),
            }),
        }
    }
}

/// How a payload is identified ([`identify_payload`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PayloadOptions {
    /// The URDF link the payload is fixed to (a moving body's own, or one behind fixed joints
    /// such as a flange or tool frame), in whose frame the payload is given.
    pub link: String,
    /// Each joint's terms fitted beside the payload (viscous, Coulomb, offset, armature): on a
    /// base-parameter reference a change of them (a sensor zeroed anew), on the URDF the terms
    /// themselves.
    pub terms: FrictionTerms,
    /// OLS, or WLS with weights from the per-joint residuals of the OLS fit (default).
    pub weighting: Weighting,
    /// Gravity in the torques (default on); a base-parameter reference must agree.
    pub gravity: Gravity,
    /// How the payload's inertia about its centre of mass is taken (default: fitted).
    pub inertia: PayloadInertia,
    /// Several logs one after the other: the samples of each, in order, adding up to all
    /// (empty for one log). Each log is checked alone against the robot's model, and its
    /// residuals are read as a time series of their own.
    pub runs: Vec<usize>,
    /// The logs' names for the findings (one a log, or none: `run r`).
    pub log_names: Vec<String>,
    /// A physically consistent payload: the least squares over the ten parameters whose
    /// pseudo-inertia is positive semi-definite (a rigid body), the joint terms free
    /// (default false: the plain least squares, which can leave a loosely determined inertia
    /// no rigid body's).
    pub consistent: bool,
}

impl PayloadOptions {
    /// The defaults for `link` and `reference`: WLS, gravity on, and the joint terms the
    /// reference lacks: an offset a joint on a base-parameter model (a torque sensor zeroed
    /// anew between the logs), viscous, Coulomb and offset on the URDF.
    pub fn new(link: &str, reference: &Reference<'_>) -> Self {
        Self {
            link: link.to_string(),
            terms: match reference {
                Reference::Urdf => FrictionTerms::ALL,
                Reference::Model(_) => FrictionTerms {
                    offset: true,
                    ..FrictionTerms::NONE
                },
            },
            weighting: Weighting::Wls,
            gravity: Gravity::Included,
            inertia: PayloadInertia::Fitted,
            runs: vec![],
            log_names: vec![],
            consistent: false,
        }
    }
}

/// Standard errors of a payload's mass (kg), centre of mass (m) and inertia about it (kg m^2,
/// `[ixx, ixy, ixz, iyy, iyz, izz]`), as [`Payload`] holds them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadStderr {
    pub mass: f64,
    pub com: [f64; 3],
    pub inertia: [f64; 6],
}

/// An identified payload ([`identify_payload`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadFit {
    pub robot: String,
    pub joint_names: Vec<String>,
    /// The link the payload is fixed to, in whose frame [`Self::payload`] is given.
    pub link: String,
    /// The link of the body it moves with (`link` itself, or for a link behind fixed joints,
    /// such as a flange or tool frame, its parent body's), in whose joint frame
    /// [`Self::theta`]'s ten parameters are.
    pub body: String,
    /// `urdf` or `base_model`: what the torques were measured against ([`Reference`]).
    pub reference: String,
    /// Whether the torques included gravity.
    pub gravity: Gravity,
    /// The joint terms fitted beside the payload.
    pub terms: FrictionTerms,
    /// The unknowns: the payload's ten parameters (`payload.m`, `payload.mcx`, ... `payload.Izz`)
    /// and then each joint's terms (`joint1.offset`, ...).
    pub names: Vec<String>,
    /// Their estimates: kg, kg m, kg m^2 about the link's joint frame; the joint terms in N m
    /// s/rad, N m, N m and kg m^2 (N s/m, N, N and kg for a prismatic joint).
    pub theta: Vec<f64>,
    /// Their standard errors, with the reference model's share ([`Self::stderr_of_reference`]).
    pub stderr: Vec<f64>,
    /// The reference model's share of the standard errors alone: its parameters' uncertainty
    /// carried through the fit (0 for the URDF, taken as exact; NaN for a base-parameter model
    /// that stores no correlation of its parameters).
    pub stderr_of_reference: Vec<f64>,
    /// The correlation of the estimates (with [`Self::stderr`], their covariance).
    #[serde(with = "crate::json::rows")]
    pub correlation: DMatrix<f64>,
    /// The payload: mass, centre of mass and inertia about it in the link's joint frame (the
    /// document `identify-gains --payload` and true robots read). None where the mass is not
    /// above 0 by [`SEEN`] standard errors (no payload seen; its centre of mass would be a
    /// ratio of noise).
    pub payload: Option<Payload>,
    /// The payload's standard errors (with it).
    pub payload_stderr: Option<PayloadStderr>,
    /// Why the least-squares estimate is no rigid body anyone could bolt on (a negative
    /// principal moment, the triangle inequality broken), None where it is one: the data
    /// determine its inertia too loosely, or the model errs. Of the unconstrained estimate
    /// also where the consistent one is given ([`Self::consistent`]).
    pub not_a_rigid_body: Option<String>,
    /// How the inertia about the centre of mass was taken: fitted, or 0 for a point mass
    /// (then its standard errors are 0: it was not estimated).
    pub inertia: PayloadInertia,
    /// Whether [`Self::theta`] and [`Self::payload`] are the physically consistent estimate
    /// ([`PayloadOptions::consistent`]); its standard errors are the unconstrained fit's,
    /// which hold where no constraint is active.
    pub consistent: bool,
    /// For a consistent estimate, the weighted residual sum of squares over the unconstrained
    /// fit's (1: the constraint cost nothing; None for a plain fit).
    pub residual_growth: Option<f64>,
    /// Per joint, the RMS (N m, or N) of the torques less the reference's: what the payload
    /// and the joint terms are fitted to.
    pub reference_rms: Vec<f64>,
    /// Per joint, the RMS of the payload's torques alone over the log (N m, or N).
    pub payload_torque_rms: Vec<f64>,
    /// Per joint, the RMS of the residuals the fit leaves (N m, or N).
    pub residual_rms: Vec<f64>,
    /// The per-joint noise levels the rows were weighted by (N m; all 1 for OLS).
    pub sigma: Vec<f64>,
    /// cond of the weighted regressor of the unknowns, columns scaled to unit norm.
    pub cond: f64,
    /// Samples fitted.
    pub samples: usize,
    /// Per joint, the residuals' long-run variance factor ([`super::residual_correlation`]);
    /// the fit's standard errors are inflated by the square root of the largest.
    pub residual_correlation: Vec<f64>,
    /// Each torque column of the log against the robot's model, as every direct fit checks
    /// its log ([`super::check_torque_columns`]): where one reads wrong (other units, sign or
    /// joint) the payload is not vouched for.
    pub torque_columns: Vec<super::TorqueColumn>,
    /// The joints whose positions leave their limits ([`super::position_range`]).
    pub position_range: Vec<super::position_range::JointRange>,
    /// Over several logs, their names (`run r` where none was given) and each one's checks
    /// alone against the robot's model (empty for one log): where one log's torque column
    /// reads wrong, the payload is not vouched for.
    pub logs: Vec<String>,
    pub run_checks: Vec<super::RunChecks>,
    /// What the fit cannot vouch for, in words (each also warned of by the front ends).
    pub findings: Vec<String>,
}

/// The reference's regressor layout, its parameters over it, and for a base-parameter model
/// its base parameters (whose columns of that layout it keeps).
struct ReferenceParts<'a> {
    layout: ParameterLayout,
    theta: DVector<f64>,
    base: Option<&'a BaseParameters>,
}

impl<'a> ReferenceParts<'a> {
    /// Of `reference` for `model`, read with `gravity`: refused for a model of another robot or
    /// identified with gravity the other way.
    fn of(model: &Model, reference: &Reference<'a>, gravity: Gravity) -> Result<Self> {
        Ok(match *reference {
            Reference::Urdf => {
                let layout = ParameterLayout::new(model, FrictionTerms::NONE.for_model(model));
                let theta = layout.model_parameters(model);
                Self {
                    layout,
                    theta,
                    base: None,
                }
            }
            Reference::Model(fit) => {
                fit.check(model)?;
                if fit.gravity != gravity {
                    return Err(Error::InvalidArgument {
                        argument: "gravity".into(),
                        message: format!(
                            "the reference model was identified with gravity {} of its torques, the payload's log is read with it {}: both must agree",
                            if fit.gravity.is_included() { "in" } else { "out" },
                            if gravity.is_included() { "in" } else { "out" }
                        ),
                    });
                }
                Self {
                    layout: fit.base.layout.clone(),
                    theta: DVector::from_column_slice(&fit.theta),
                    base: Some(&fit.base),
                }
            }
        })
    }

    /// The reference's torques of the regressor block `phi` (of [`Self::layout`]).
    fn torques(&self, phi: &DMatrix<f64>) -> DVector<f64> {
        match self.base {
            Some(b) => b.select(phi) * &self.theta,
            None => phi * &self.theta,
        }
    }
}

/// The unknowns' regression problem: the columns of the payload's body and of the joint terms.
fn unknowns(model: &Model, body: usize, terms: FrictionTerms) -> BaseParameters {
    let layout = ParameterLayout::new(model, terms);
    let ni = PARAMS_PER_BODY * model.nbodies();
    let kept: Vec<usize> = (body * PARAMS_PER_BODY..(body + 1) * PARAMS_PER_BODY)
        .chain(ni..layout.len())
        .collect();
    BaseParameters {
        layout,
        k: DMatrix::zeros(kept.len(), 0),
        kept,
        dropped: vec![],
        tolerance: BASE_TOLERANCE,
        structural: false,
    }
}

/// The unknowns' columns: the payload body's ten and each joint's terms.
struct Columns {
    body: usize,
    terms: Vec<&'static str>,
}

impl Columns {
    /// Row `s * nv + j` (`row` of the block `phi`, sample `sample` of `states`, joint `joint`)
    /// into `out`: the payload body's ten regressor columns of the reference's regressor block
    /// (inertial columns come first in every layout) and joint `j`'s own terms.
    fn row(
        &self,
        phi: &DMatrix<f64>,
        row: usize,
        states: &States<'_>,
        sample: usize,
        joint: usize,
        out: &mut [f64],
    ) {
        let (nv, terms) = (states.nv(), &self.terms);
        for c in 0..PARAMS_PER_BODY {
            out[c] = phi[(row, self.body * PARAMS_PER_BODY + c)];
        }
        out[PARAMS_PER_BODY..].iter_mut().for_each(|v| *v = 0.0);
        let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
        for (t, name) in terms.iter().enumerate() {
            out[PARAMS_PER_BODY + joint * terms.len() + t] = match *name {
                "viscous" => qd[sample * nv + joint],
                "coulomb" => states.coulomb_at(sample, joint),
                "armature" => qdd[sample * nv + joint],
                _ => 1.0,
            };
        }
    }
}

/// Identifies the payload fixed to `options.link` from `states` (rad, rad/s, rad/s^2, with
/// velocities and accelerations; a Coulomb column where the torques were filtered,
/// [`States::with_coulomb`]) and the torques `tau` measured with it (row-major `k x nv`, N m,
/// or N for a prismatic joint), against `reference`: see the module documentation.
///
/// Errors: states of other joints or without velocities, torques of another shape or flat, a
/// link that is no moving body's, a reference identified for another robot or with gravity
/// the other way, and data that do not determine the payload (a rank deficiency naming the
/// parameters: a payload on a link whose motion the joints' torques cannot tell apart, or a
/// log that moves too little).
pub fn identify_payload(
    model: &Model,
    reference: Reference<'_>,
    states: &States<'_>,
    tau: &[f64],
    options: &PayloadOptions,
) -> Result<PayloadFit> {
    let nv = model.nv;
    crate::torque_model::check_joints(states, nv)?;
    states.check_companion("tau", tau, nv)?;
    if states.qd().is_none() || states.qdd().is_none() {
        return Err(Error::InvalidArgument {
            argument: "states".into(),
            message: "the log has no velocities and accelerations: preprocess it first".into(),
        });
    }
    crate::torque_model::refuse_flat_torques(
        states,
        tau,
        &model.joint_names,
        crate::torque_model::FOR_A_FIT,
    )?;
    super::runs::check_runs(&options.runs, states.len())?;
    if !(options.log_names.is_empty() || options.log_names.len() == options.runs.len()) {
        return Err(Error::InvalidArgument {
            argument: "log_names".into(),
            message: format!(
                "{} names for {} logs, expected one a log or none",
                options.log_names.len(),
                options.runs.len()
            ),
        });
    }
    let (body, pose) =
        crate::rehearsal::link_in_body(model, &options.link).map_err(|e| match e {
            Error::InvalidArgument { message, .. } => Error::InvalidArgument {
                argument: "link".into(),
                message,
            },
            other => other,
        })?;
    let parts = ReferenceParts::of(model, &reference, options.gravity)?;
    let (ref_layout, ref_theta, base_of_reference) = (&parts.layout, &parts.theta, parts.base);
    let problem = unknowns(model, body, options.terms);
    let columns = Columns {
        body,
        terms: options.terms.names(),
    };
    let m = problem.len();
    let p_ref = base_of_reference.map_or(0, |b| b.len());
    // pass 1: the torques less the reference's, and per joint the cross products of the
    // unknowns' columns with the reference's base columns (for its share of the errors)
    let k = states.len();
    let mut y = Vec::with_capacity(k * nv);
    let mut cross = vec![DMatrix::<f64>::zeros(m, p_ref); nv];
    let mut row = vec![0.0; m];
    regressor_blocks(model, ref_layout, states, options.gravity, |range, phi| {
        let rows_ref = base_of_reference.map(|b| b.select(phi));
        let predicted = match &rows_ref {
            Some(rows) => rows * ref_theta,
            None => phi * ref_theta,
        };
        for (i, s) in range.clone().enumerate() {
            for j in 0..nv {
                y.push(tau[s * nv + j] - predicted[i * nv + j]);
            }
        }
        // per joint, the block's rows of the unknowns' and the reference's columns: one
        // product each
        if let Some(f) = &rows_ref {
            let len = range.len();
            for (j, cross) in cross.iter_mut().enumerate() {
                let mut a = DMatrix::zeros(len, m);
                for (i, s) in range.clone().enumerate() {
                    columns.row(phi, i * nv + j, states, s, j, &mut row);
                    a.row_mut(i).copy_from_slice(&row);
                }
                let b = DMatrix::from_fn(len, p_ref, |i, c| f[(i * nv + j, c)]);
                cross.gemm_tr(1.0, &a, &b, 1.0);
            }
        }
        Ok(())
    })?;
    if let Some(j) = (0..nv).find(|&j| y.iter().skip(j).step_by(nv).any(|v| !v.is_finite())) {
        return Err(Error::Numerical {
            operation: "payload identification".into(),
            message: format!(
                "the torques of joint '{}' less the reference's overflow: the torques or states are too large for f64 arithmetic; rescale the log to SI units",
                model.joint_names[j]
            ),
        });
    }
    // pass 2: the unknowns' least squares, OLS then WLS
    let factors = JointFactors::new(model, &problem, states, &y, options.gravity)?;
    let names: Vec<String> = (crate::algorithms::regressor::PARAMETER_NAMES.iter())
        .map(|n| format!("payload.{n}"))
        .chain(problem.names().into_iter().skip(PARAMS_PER_BODY))
        .collect();
    let in_context = |e: Error| match e {
        Error::RankDeficient {
            rows,
            cols,
            rank,
            missing,
            ..
        } => Error::RankDeficient {
            context: format!("payload identification on '{}'", options.link),
            rows,
            cols,
            rank,
            missing,
        },
        other => other,
    };
    if options.consistent && options.inertia == PayloadInertia::PointMass {
        return Err(Error::InvalidArgument {
            argument: "consistent".into(),
            message: "not with a point mass, which is a rigid body already".into(),
        });
    }
    let estimate = |sigma: &[f64]| match options.inertia {
        PayloadInertia::Fitted => estimate::least_squares_estimate(&factors, sigma, &names),
        PayloadInertia::PointMass => estimate::point_mass_estimate(&factors, sigma, &names),
    };
    let mut sigma = vec![1.0; nv];
    let mut e = estimate(&sigma).map_err(in_context)?;
    let mut rms = factors.residual_rms(&e.theta)?;
    if options.weighting == Weighting::Wls {
        sigma = rms.iter().map(|&s| if s > 0.0 { s } else { 1.0 }).collect();
        e = estimate(&sigma).map_err(in_context)?;
        rms = factors.residual_rms(&e.theta)?;
    }
    let not_a_rigid_body = rigid_body_problem(&options.link, &e.theta);
    if options.consistent {
        e = estimate::rigid_body_estimate(&factors, &sigma, &e)?;
        rms = factors.residual_rms(&e.theta)?;
    }
    let theta = e.theta.clone();
    let pi = DVector::from_column_slice(&theta);
    // the residuals' correlation from sample to sample, and the payload's torques, over the
    // first samples of each log (each log's residuals a time series of its own)
    let whole = [k];
    let runs: &[usize] = if options.runs.len() > 1 {
        &options.runs
    } else {
        &whole
    };
    let head = (SAMPLES / runs.len()).max(SAMPLES_A_RUN);
    let (mut factors_of_runs, mut payload_squares, mut heads) = (vec![], vec![0.0; nv], 0);
    let pi_payload = pi.rows(0, PARAMS_PER_BODY).into_owned();
    let mut first = 0;
    for &len in runs {
        let rows = first..first + len.min(head);
        let part = states.slice(rows.clone());
        let mut residuals = Vec::with_capacity(rows.len() * nv);
        regressor_blocks(model, ref_layout, &part, options.gravity, |range, phi| {
            for (i, s) in range.clone().enumerate() {
                for j in 0..nv {
                    let r = i * nv + j;
                    columns.row(phi, r, &part, s, j, &mut row);
                    let fitted: f64 = row.iter().zip(pi.iter()).map(|(a, b)| a * b).sum();
                    residuals.push(y[(rows.start + s) * nv + j] - fitted);
                    let own: f64 = (0..PARAMS_PER_BODY).map(|c| row[c] * pi_payload[c]).sum();
                    payload_squares[j] += own * own;
                }
            }
            Ok(())
        })?;
        factors_of_runs.push((long_run_factors(&residuals, nv), len));
        heads += rows.len();
        first += len;
    }
    let head = heads;
    let residual_correlation = combine(&factors_of_runs, nv);
    let inflation = residual_correlation
        .iter()
        .fold(1.0f64, |a, &f| a.max(f))
        .sqrt();
    // covariance: the fit's (inflated), and the reference's carried through
    let mut cov = &e.unit_covariance * (e.variance * inflation * inflation);
    let stderr_of_reference = match reference {
        Reference::Urdf => vec![0.0; m],
        Reference::Model(fit) if fit.correlation.shape() != (p_ref, p_ref) => vec![f64::NAN; m],
        Reference::Model(fit) => {
            // the estimator's linearised operator on the torques: unit covariance A^T W
            let mut weighted = DMatrix::<f64>::zeros(m, p_ref);
            for (j, c) in cross.iter().enumerate() {
                weighted += c / (sigma[j] * sigma[j]);
            }
            let g = &e.unit_covariance * weighted;
            let ref_cov = DMatrix::from_fn(p_ref, p_ref, |a, b| {
                fit.stderr[a] * fit.correlation[(a, b)] * fit.stderr[b]
            });
            let carried = &g * ref_cov * g.transpose();
            cov += &carried;
            (0..m).map(|a| carried[(a, a)].max(0.0).sqrt()).collect()
        }
    };
    let stderr: Vec<f64> = (0..m).map(|a| cov[(a, a)].max(0.0).sqrt()).collect();
    let correlation = DMatrix::from_fn(m, m, |a, b| {
        let d = stderr[a] * stderr[b];
        match (a == b, d > 0.0 && d.is_finite()) {
            (true, _) => 1.0,
            (false, true) => cov[(a, b)] / d,
            (false, false) => 0.0,
        }
    });
    let reference_rms: Vec<f64> = (0..nv)
        .map(|j| {
            let s: f64 = y.iter().skip(j).step_by(nv).map(|v| v * v).sum();
            (s / k.max(1) as f64).sqrt()
        })
        .collect();
    let payload_torque_rms: Vec<f64> = payload_squares
        .iter()
        .map(|s| (s / head.max(1) as f64).sqrt())
        .collect();
    let mut fit = PayloadFit {
        robot: model.name.clone(),
        joint_names: model.joint_names.clone(),
        link: options.link.clone(),
        body: model.bodies[body].link.clone(),
        reference: match reference {
            Reference::Urdf => "urdf".into(),
            Reference::Model(_) => "base_model".into(),
        },
        gravity: options.gravity,
        terms: options.terms,
        names,
        theta,
        stderr,
        stderr_of_reference,
        correlation,
        payload: None,
        payload_stderr: None,
        not_a_rigid_body,
        inertia: options.inertia,
        consistent: options.consistent,
        residual_growth: e.residual_growth,
        reference_rms,
        payload_torque_rms,
        residual_rms: rms,
        sigma,
        cond: e.cond,
        samples: k,
        residual_correlation,
        torque_columns: vec![],
        position_range: vec![],
        logs: match options.runs.len() {
            0 | 1 => vec![],
            n => (0..n)
                .map(|r| crate::stacked_states::run_name(&options.log_names, r))
                .collect(),
        },
        run_checks: vec![],
        findings: vec![],
    };
    // the log against the robot's model, as every direct fit checks its log: a torque column
    // in other units, of another sign or joint, and positions beyond the limits (a log in
    // degrees) are named before what the payload makes of them
    fit.torque_columns =
        super::torque_columns::check_torque_columns(model, states, tau, options.gravity)?;
    fit.position_range = super::position_range::check_position_range(model, states);
    fit.run_checks =
        super::check_runs_against_model(model, states, tau, &options.runs, options.gravity)?;
    fit.findings = match fit.run_checks.is_empty() {
        true => {
            let mut f = super::torque_columns::findings(&fit.torque_columns);
            f.extend(super::position_range::finding(&fit.position_range));
            f
        }
        // each log named by its own findings; the stacked samples' columns where no log's
        // are named (what makes the payload not vouched for is always said)
        false => {
            let mut f = super::run_checks::findings(&fit.run_checks, &fit.logs);
            if !fit.run_checks.iter().any(|c| c.columns_wrong()) {
                f.extend(super::torque_columns::findings(&fit.torque_columns));
            }
            f
        }
    };
    fit.judge(&cov, &pose);
    Ok(fit)
}

impl PayloadFit {
    /// The torques (row-major `k x nv`, N m, or N for a prismatic joint) of the robot
    /// carrying the payload at `states` (rad, rad/s, rad/s^2; a Coulomb column where the
    /// torques are filtered): `reference`'s (the one the payload was identified against), the
    /// payload's and the joint terms fitted beside it. Refused for a robot of other joints or
    /// without the payload's body, and a reference of another kind than the fit's.
    pub fn predict(
        &self,
        model: &Model,
        reference: Reference<'_>,
        states: &States<'_>,
    ) -> Result<Vec<f64>> {
        let nv = model.nv;
        let bad = |message: String| Error::InvalidArgument {
            argument: "payload fit".into(),
            message,
        };
        if model.joint_names != self.joint_names {
            return Err(bad(format!(
                "identified for joints [{}], not '{}''s",
                self.joint_names.join(", "),
                model.name
            )));
        }
        let kind = match reference {
            Reference::Urdf => "urdf",
            Reference::Model(_) => "base_model",
        };
        if kind != self.reference {
            return Err(bad(format!(
                "identified against the {}, not against the {}: predict with the reference it was identified against",
                describe(&self.reference),
                describe(kind)
            )));
        }
        let body = (model.bodies.iter())
            .position(|b| b.link == self.body)
            .ok_or_else(|| bad(format!("the robot has no body '{}'", self.body)))?;
        let columns = Columns {
            body,
            terms: self.terms.names(),
        };
        if PARAMS_PER_BODY + columns.terms.len() * nv != self.theta.len() {
            return Err(bad(format!(
                "{} estimates, not the {} of the payload and its joint terms on this robot",
                self.theta.len(),
                PARAMS_PER_BODY + columns.terms.len() * nv
            )));
        }
        crate::torque_model::check_joints(states, nv)?;
        let parts = ReferenceParts::of(model, &reference, self.gravity)?;
        let mut row = vec![0.0; self.theta.len()];
        let mut out = Vec::with_capacity(states.len() * nv);
        regressor_blocks(model, &parts.layout, states, self.gravity, |range, phi| {
            let base = parts.torques(phi);
            for (i, s) in range.clone().enumerate() {
                for j in 0..nv {
                    let r = i * nv + j;
                    columns.row(phi, r, states, s, j, &mut row);
                    let own: f64 = row.iter().zip(&self.theta).map(|(a, b)| a * b).sum();
                    out.push(base[r] + own);
                }
            }
            Ok(())
        })?;
        crate::torque_model::check_prediction(&out, nv)?;
        Ok(out)
    }

    /// The payload's ten parameters (Pinocchio's order, about the link's joint frame).
    pub fn parameters(&self) -> [f64; 10] {
        std::array::from_fn(|i| self.theta[i])
    }

    /// The payload, its standard errors and the findings, from the estimates and their
    /// covariance `cov` (over [`Self::names`]).
    /// `pose`: the link's in the frame of the body it moves with.
    fn judge(&mut self, cov: &DMatrix<f64>, pose: &Se3) {
        let pi = self.parameters();
        let (m, se_m) = (pi[0], self.stderr[0]);
        if m < -SEEN * se_m {
            self.findings.push(format!(
                "the payload on '{}' comes out with a negative mass, {} +- {} kg (below 0 by more than {SEEN} standard errors): the {} is heavier at this link than the robot that made the log; {}",
                self.link,
                shown(m),
                shown(se_m),
                describe(&self.reference),
                match self.reference.as_str() {
                    "urdf" => "identify a model of the robot alone from a log without the payload, and give it as the reference",
                    _ => "was the model identified on this robot, with the same tool flange, and the log taken with the payload on?",
                }
            ));
            return;
        }
        if !(m > SEEN * se_m && m > 0.0) {
            self.findings.push(format!(
                "no payload on '{}' is seen: its mass comes out {} +- {} kg (not above 0 by {SEEN} standard errors), so its centre of mass and inertia are not determined; was it mounted while the log was taken, on this link?",
                self.link,
                shown(m),
                shown(se_m)
            ));
            return;
        }
        let (u, jac) = payload_of_parameters(&pi);
        let block = cov.view((0, 0), (PARAMS_PER_BODY, PARAMS_PER_BODY));
        let (u, cu) = in_link_frame(&u, &(&jac * block * jac.transpose()), pose);
        let se = |i: usize| cu[(i, i)].max(0.0).sqrt();
        let mut payload = Payload {
            link: self.link.clone(),
            mass: u[0],
            com: [u[1], u[2], u[3]],
            inertia: [u[4], u[5], u[6], u[7], u[8], u[9]],
        };
        let mut stderr = PayloadStderr {
            mass: se(0),
            com: [se(1), se(2), se(3)],
            inertia: std::array::from_fn(|i| se(4 + i)),
        };
        let point_mass = self.inertia == PayloadInertia::PointMass;
        if point_mass {
            // 0 by assumption, not estimated (what is left is rounding)
            payload.inertia = [0.0; 6];
            stderr.inertia = [0.0; 6];
        }
        if stderr.mass > LOOSE_MASS * payload.mass {
            self.findings.push(format!(
                "the payload's mass is loosely determined: {} +- {} kg",
                shown(payload.mass),
                shown(stderr.mass)
            ));
        }
        let distance = payload.com.iter().map(|c| c * c).sum::<f64>().sqrt();
        let com_bound = (LOOSE_COM_FRACTION * distance).max(LOOSE_COM);
        if stderr.com.iter().any(|s| s.is_nan() || *s > com_bound) {
            self.findings.push(format!(
                "the payload's centre of mass is loosely determined: [{}] +- [{}] m; a motion that turns the link about more axes, and faster, determines it better",
                payload.com.map(shown).join(", "),
                stderr.com.map(shown).join(", ")
            ));
        }
        let s = payload.spatial_inertia().inertia_com;
        let largest = crate::decomposition::symmetric_eigen(s).map_or(f64::NAN, |e| {
            (e.eigenvalues.iter()).fold(0.0f64, |a, v| a.max(v.abs()))
        });
        if !point_mass
            && (stderr.inertia.iter())
                .any(|v| v.is_nan() || largest.is_nan() || *v > LOOSE_INERTIA * largest)
        {
            self.findings.push(format!(
                "the payload's inertia about its centre of mass is loosely determined: standard errors up to {} kg m^2 against a largest principal moment of {} kg m^2 (a small payload's inertia moves the joint torques little; a motion that turns the link faster about each axis determines it better)",
                shown(stderr.inertia.iter().fold(0.0f64, |a, v| a.max(*v))),
                shown(largest)
            ));
        }
        match (&self.not_a_rigid_body, self.consistent) {
            (Some(reason), false) => self.findings.push(format!(
                "the estimate is no rigid body: {reason}; the data determine its inertia too loosely (or the reference model errs), and the estimate is not to be used as it is: identify it consistent (a rigid body by construction)"
            )),
            (Some(reason), true) => self.findings.push(format!(
                "the least-squares estimate is no rigid body ({reason}): the consistent one given lies on the boundary of rigid bodies, its inertia what the data allow more than what they determine"
            )),
            (None, _) => {}
        }
        // a consistent estimate is a rigid body by construction; checked all the same
        if self.consistent {
            if let Some(reason) = payload.problem("the consistent payload") {
                self.findings.push(reason.clone());
                self.not_a_rigid_body = Some(reason);
                self.consistent = false;
            }
        }
        self.payload = Some(payload);
        self.payload_stderr = Some(stderr);
    }

    /// The payload ready to use: present, a rigid body, and from a log whose torque columns
    /// read as the robot's (None otherwise; see [`Self::findings`]).
    pub fn usable_payload(&self) -> Option<&Payload> {
        let columns_right = super::torque_columns::findings(&self.torque_columns).is_empty()
            && !self.run_checks.iter().any(|c| c.columns_wrong());
        self.payload
            .as_ref()
            .filter(|_| (self.consistent || self.not_a_rigid_body.is_none()) && columns_right)
    }
}

/// Why the payload of the estimates `theta` (its ten parameters first) is no rigid body, None
/// where it is one (or where its mass is not positive: no payload to judge).
fn rigid_body_problem(link: &str, theta: &[f64]) -> Option<String> {
    let pi: [f64; 10] = std::array::from_fn(|i| theta[i]);
    if pi[0].is_nan() || pi[0] <= 0.0 {
        return None;
    }
    let (u, _) = payload_of_parameters(&pi);
    Payload {
        link: link.to_string(),
        mass: u[0],
        com: [u[1], u[2], u[3]],
        inertia: [u[4], u[5], u[6], u[7], u[8], u[9]],
    }
    .problem("the payload")
}

/// A reference's kind in words.
fn describe(kind: &str) -> &'static str {
    match kind {
        "urdf" => "URDF's parameters",
        _ => "model of the robot alone",
    }
}
