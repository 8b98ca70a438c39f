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

use super::base::BaseParameters;
use super::base_options::Weighting;
use super::parameters::regressor_blocks;
use super::payload_estimate as estimate;
use super::payload_fit::rigid_body_problem;
pub use super::payload_fit::{
    PayloadFit, PayloadStderr, LOOSE_COM, LOOSE_COM_FRACTION, LOOSE_INERTIA, LOOSE_MASS, SEEN,
};
pub use super::payload_quantities::{in_link_frame, parameters_of_payload, payload_of_parameters};
use super::payload_reference::{unknowns, Columns, ReferenceParts};
pub use super::payload_reference::{PayloadInertia, PayloadOptions, Reference};
use super::residual_correlation::{combine, long_run_factors, SAMPLES, SAMPLES_A_RUN};
use super::streaming::JointFactors;
use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Se3;
use crate::states::States;

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
    let fixed = check_payload_inputs(model, states, tau, options)?;
    let problem = PayloadProblem::new(model, &reference, states, options)?;
    let (y, cross) = problem.reference_residuals(tau)?;
    let fitted = problem.fit(&y, fixed)?;
    let (theta, e, sigma, rms) = (fitted.e.theta.clone(), &fitted.e, fitted.sigma, fitted.rms);
    let pi = DVector::from_column_slice(&theta);
    let series = problem.residual_series(&y, &pi)?;
    let longest = series.correlation.iter().fold(1.0f64, |a, &f| a.max(f));
    let k = states.len();
    // the residuals against the noise, where known; the noise weighting's variance the
    // noise's (with its correlation, or the residuals' longer one), scaled where they exceed it
    let noise_fit =
        (options.noise.as_ref()).and_then(|n| super::NoiseFit::of(n, &rms, k, theta.len()));
    let variance = match (options.weighting, &noise_fit, &options.noise) {
        (Weighting::Noise, Some(n), _) => n.scale().powi(2) * n.noise.correlation.max(longest),
        (Weighting::Noise, None, Some(noise)) => {
            return Err(Error::invalid(
                "noise",
                format!(
                    "{}: standard errors cannot be had from it; give more samples, or weight otherwise (wls)",
                    super::NoiseFit::why_not(noise, k, model.nv, theta.len())
                ),
            ));
        }
        _ => e.variance * longest,
    };
    let (cov, stderr_of_reference) = problem.covariance(&reference, e, &sigma, &cross, variance);
    let m = problem.columns.len(model.nv);
    let stderr: Vec<f64> = (0..m).map(|a| cov[(a, a)].max(0.0).sqrt()).collect();
    let correlation = DMatrix::from_fn(m, m, |a, b| {
        let d = stderr[a] * stderr[b];
        match (a == b, d > 0.0 && d.is_finite()) {
            (true, _) => 1.0,
            (false, true) => cov[(a, b)] / d,
            (false, false) => 0.0,
        }
    });
    let nv = model.nv;
    let reference_rms: Vec<f64> = (0..nv)
        .map(|j| {
            let s: f64 = y.iter().skip(j).step_by(nv).map(|v| v * v).sum();
            (s / k.max(1) as f64).sqrt()
        })
        .collect();
    // each log's offset less the logs' mean, where each has its own
    let offset_runs = problem.offset_runs;
    let log_offsets = (offset_runs.len() > 1).then(|| {
        super::log_offsets::LogOffsets::of_fit(
            &theta,
            &stderr,
            &correlation,
            problem.unknowns.len(),
            nv,
            offset_runs.len(),
        )
    });
    let mut fit = PayloadFit {
        robot: model.name.clone(),
        joint_names: model.joint_names.clone(),
        link: options.link.clone(),
        body: model.bodies[problem.body].link.clone(),
        reference: match reference {
            Reference::Urdf => "urdf".into(),
            Reference::Model(_) => "base_model".into(),
        },
        gravity: options.gravity,
        terms: options.terms,
        names: fitted.names,
        theta,
        stderr,
        stderr_of_reference,
        correlation,
        payload: None,
        payload_stderr: None,
        not_a_rigid_body: fitted.not_a_rigid_body,
        inertia: options.inertia,
        consistent: options.consistent,
        residual_growth: e.residual_growth,
        reference_rms,
        payload_torque_rms: series.payload_torque_rms,
        residual_rms: rms,
        sigma,
        cond: e.cond,
        samples: k,
        residual_correlation: series.correlation,
        torque_columns: vec![],
        position_range: vec![],
        logs: match options.runs.len() {
            0 | 1 => vec![],
            n => (0..n)
                .map(|r| crate::logs::stacked_states::run_name(&options.log_names, r))
                .collect(),
        },
        run_checks: vec![],
        findings: vec![],
        log_offsets,
        noise_fit,
    };
    check_the_logs(&mut fit, model, states, tau, options)?;
    fit.judge(&cov, &problem.pose);
    Ok(fit)
}

/// The checks of a payload fit's inputs that need no regressor; the noise levels that weight
/// its rows, where the weighting takes them from a noise.
fn check_payload_inputs(
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    options: &PayloadOptions,
) -> Result<Option<Vec<f64>>> {
    let nv = model.nv;
    crate::torque_model::check_joints(states, nv)?;
    states.check_companion("tau", tau, nv)?;
    if states.qd().is_none() || states.qdd().is_none() {
        return Err(Error::invalid(
            "states",
            "the log has no velocities and accelerations: preprocess it first",
        ));
    }
    crate::torque_model::refuse_flat_torques(
        states,
        tau,
        &model.joint_names,
        crate::torque_model::FOR_A_FIT,
    )?;
    super::runs::check_runs(&options.runs, states.len())?;
    let fixed = super::base_options::weights(
        options.weighting,
        options.noise.as_ref(),
        &model.joint_names,
    )?;
    if !(options.log_names.is_empty() || options.log_names.len() == options.runs.len()) {
        return Err(Error::invalid(
            "log_names",
            format!(
                "{} names for {} logs, expected one a log or none",
                options.log_names.len(),
                options.runs.len()
            ),
        ));
    }
    if options.consistent && options.inertia == PayloadInertia::PointMass {
        return Err(Error::invalid(
            "consistent",
            "not with a point mass, which is a rigid body already",
        ));
    }
    Ok(fixed)
}

/// The log against the robot's model, as every direct fit checks its log: a torque column in
/// other units, of another sign or joint, and positions beyond the limits (a log in degrees)
/// are named before what the payload makes of them.
fn check_the_logs(
    fit: &mut PayloadFit,
    model: &Model,
    states: &States<'_>,
    tau: &[f64],
    options: &PayloadOptions,
) -> Result<()> {
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
    fit.findings
        .extend((fit.noise_fit.as_ref()).and_then(|n| n.finding(&fit.joint_names)));
    Ok(())
}

/// A payload fit's unknowns and the reference they are fitted against.
struct PayloadProblem<'a> {
    model: &'a Model,
    states: &'a States<'a>,
    options: &'a PayloadOptions,
    /// The body the payload's link moves with, and the link's pose in it.
    body: usize,
    pose: Se3,
    reference: ReferenceParts<'a>,
    /// The unknowns: the payload body's ten parameters and the joint terms.
    unknowns: BaseParameters,
    /// The logs with a torque offset each (empty without).
    offset_runs: &'a [usize],
    columns: Columns,
}

/// The unknowns fitted, with what the fit found of its rows.
struct FittedPayload {
    e: estimate::Estimate,
    names: Vec<String>,
    /// Each joint's weight (its rows' noise level, 1 for ordinary least squares).
    sigma: Vec<f64>,
    rms: Vec<f64>,
    not_a_rigid_body: Option<String>,
}

/// The residuals' correlation from sample to sample and the payload's own torques, over the
/// first samples of each log.
struct ResidualSeries {
    correlation: Vec<f64>,
    payload_torque_rms: Vec<f64>,
}

impl<'a> PayloadProblem<'a> {
    fn new(
        model: &'a Model,
        reference: &Reference<'a>,
        states: &'a States<'a>,
        options: &'a PayloadOptions,
    ) -> Result<Self> {
        let (body, pose) =
            crate::model::payload::link_in_body(model, &options.link).map_err(|e| match e {
                Error::InvalidArgument { message, .. } => Error::InvalidArgument {
                    argument: "link".into(),
                    message,
                },
                other => other,
            })?;
        let parts = ReferenceParts::of(model, reference, options.gravity)?;
        let offset_runs: &[usize] = match options.offset_per_run {
            true => {
                super::log_offsets::check_options(&super::BaseOptions {
                    runs: options.runs.clone(),
                    friction: options.terms,
                    ..Default::default()
                })?;
                &options.runs
            }
            false => &[],
        };
        Ok(Self {
            model,
            states,
            options,
            body,
            pose,
            reference: parts,
            unknowns: unknowns(model, body, options.terms),
            offset_runs,
            columns: Columns {
                body,
                terms: options.terms.names(),
                runs: offset_runs.len(),
            },
        })
    }

    /// The log of sample `s`, for its own offset's columns.
    fn run_of(&self, s: usize) -> Option<usize> {
        let mut first = 0;
        self.offset_runs.iter().position(|&len| {
            first += len;
            s < first
        })
    }

    /// The torques `tau` less the reference's, and per joint the cross products of the
    /// unknowns' columns with the reference's base columns (for its share of the errors).
    fn reference_residuals(&self, tau: &[f64]) -> Result<(Vec<f64>, Vec<DMatrix<f64>>)> {
        let (model, states, nv) = (self.model, self.states, self.model.nv);
        let (ref_layout, ref_theta, base) = (
            &self.reference.layout,
            &self.reference.theta,
            self.reference.base,
        );
        let m = self.columns.len(nv);
        let p_ref = base.map_or(0, |b| b.len());
        let k = states.len();
        let mut y = Vec::with_capacity(k * nv);
        let mut cross = vec![DMatrix::<f64>::zeros(m, p_ref); nv];
        let mut row = vec![0.0; m];
        regressor_blocks(
            model,
            ref_layout,
            states,
            self.options.gravity,
            |range, phi| {
                // the reference's columns of the block: its base parameters', or the URDF's all
                let rows_ref = base.map(|b| b.select(phi));
                let predicted = rows_ref.as_ref().unwrap_or(phi) * ref_theta;
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
                            self.columns.row(phi, i * nv + j, states, s, j, &mut row);
                            self.columns.run_offsets(nv, j, self.run_of(s), &mut row);
                            a.row_mut(i).copy_from_slice(&row);
                        }
                        let b = DMatrix::from_fn(len, p_ref, |i, c| f[(i * nv + j, c)]);
                        cross.gemm_tr(1.0, &a, &b, 1.0);
                    }
                }
                Ok(())
            },
        )?;
        if let Some(j) = (0..nv).find(|&j| y.iter().skip(j).step_by(nv).any(|v| !v.is_finite())) {
            return Err(Error::numerical(
                "payload identification",
                format!(
                    "the torques of joint '{}' less the reference's overflow: the torques or states are too large for f64 arithmetic; rescale the log to SI units",
                    model.joint_names[j]
                ),
            ));
        }
        Ok((y, cross))
    }

    /// The unknowns' least squares on the residuals `y`: ordinary, then weighted (by the
    /// residuals' levels, or the `fixed` noise levels), then made a rigid body if asked.
    fn fit(&self, y: &[f64], fixed: Option<Vec<f64>>) -> Result<FittedPayload> {
        let (model, options, nv) = (self.model, self.options, self.model.nv);
        let factors = JointFactors::with_runs(
            model,
            &self.unknowns,
            self.states,
            y,
            &[],
            self.offset_runs,
            options.gravity,
        )?;
        let mut names: Vec<String> = (crate::algorithms::regressor::PARAMETER_NAMES.iter())
            .map(|n| format!("payload.{n}"))
            .chain(self.unknowns.names().into_iter().skip(PARAMS_PER_BODY))
            .collect();
        for j in &model.joint_names {
            names.extend((1..self.offset_runs.len()).map(|r| format!("{j}.offset of run {r}")));
        }
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
        let estimate = |sigma: &[f64]| match options.inertia {
            PayloadInertia::Fitted => estimate::least_squares_estimate(&factors, sigma, &names),
            PayloadInertia::PointMass => estimate::point_mass_estimate(&factors, sigma, &names),
        };
        let mut sigma = vec![1.0; nv];
        let mut e = estimate(&sigma).map_err(in_context)?;
        let mut rms = factors.residual_rms(&e.theta)?;
        let weights = match (options.weighting, fixed) {
            (Weighting::Wls, _) => {
                Some(rms.iter().map(|&s| if s > 0.0 { s } else { 1.0 }).collect())
            }
            (_, fixed) => fixed,
        };
        if let Some(weights) = weights {
            sigma = weights;
            e = estimate(&sigma).map_err(in_context)?;
            rms = factors.residual_rms(&e.theta)?;
        }
        let not_a_rigid_body = rigid_body_problem(&options.link, &e.theta);
        if options.consistent {
            e = estimate::rigid_body_estimate(&factors, &sigma, &e)?;
            rms = factors.residual_rms(&e.theta)?;
        }
        Ok(FittedPayload {
            e,
            names,
            sigma,
            rms,
            not_a_rigid_body,
        })
    }

    /// The residuals' correlation from sample to sample, and the payload's torques `pi` gives,
    /// over the first samples of each log (each log's residuals a time series of its own).
    fn residual_series(&self, y: &[f64], pi: &DVector<f64>) -> Result<ResidualSeries> {
        let (model, states, options, nv) = (self.model, self.states, self.options, self.model.nv);
        let whole = [states.len()];
        let runs: &[usize] = if options.runs.len() > 1 {
            &options.runs
        } else {
            &whole
        };
        let head = (SAMPLES / runs.len()).max(SAMPLES_A_RUN);
        let (mut factors_of_runs, mut payload_squares, mut heads) = (vec![], vec![0.0; nv], 0);
        let pi_payload = pi.rows(0, PARAMS_PER_BODY).into_owned();
        let mut row = vec![0.0; self.columns.len(nv)];
        let mut first = 0;
        for &len in runs {
            let rows = first..first + len.min(head);
            let part = states.slice(rows.clone());
            let mut residuals = Vec::with_capacity(rows.len() * nv);
            let layout = &self.reference.layout;
            regressor_blocks(model, layout, &part, options.gravity, |range, phi| {
                for (i, s) in range.clone().enumerate() {
                    for j in 0..nv {
                        let r = i * nv + j;
                        self.columns.row(phi, r, &part, s, j, &mut row);
                        (self.columns).run_offsets(nv, j, self.run_of(rows.start + s), &mut row);
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
        Ok(ResidualSeries {
            correlation: combine(&factors_of_runs, nv),
            payload_torque_rms: (payload_squares.iter())
                .map(|s| (s / heads.max(1) as f64).sqrt())
                .collect(),
        })
    }

    /// The unknowns' covariance: the fit's `e` at `variance`, and the reference's carried
    /// through the estimator (`cross`, weighted by `sigma`); with the reference's share of the
    /// standard errors.
    fn covariance(
        &self,
        reference: &Reference<'_>,
        e: &estimate::Estimate,
        sigma: &[f64],
        cross: &[DMatrix<f64>],
        variance: f64,
    ) -> (DMatrix<f64>, Vec<f64>) {
        let m = self.columns.len(self.model.nv);
        let p_ref = self.reference.base.map_or(0, |b| b.len());
        let mut cov = &e.unit_covariance * variance;
        let stderr_of_reference = match reference {
            Reference::Urdf => vec![0.0; m],
            Reference::Model(fit) if fit.correlation.shape() != (p_ref, p_ref) => {
                vec![f64::NAN; m]
            }
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
        (cov, stderr_of_reference)
    }
}
