//! Joint drive gains identified with the base parameters, for robots that log their motors'
//! currents (or torques computed from them with nominal gains) instead of joint torques
//! (docs/method.md, section 8c; the approach of Gautier & Briot, "Global identification of joint
//! drive gains and dynamic parameters of robots", 2014).
//!
//! Joint `j`'s logged signal `i_j` is its torque over a gain `K_j` (N m, or N for a prismatic
//! joint, per unit of the signal: a torque constant times a gear ratio). In a run with a known
//! payload bolted onto a link, the joint torques are the robot's and the payload's `tau_L`:
//!
//! ```text
//! K_j i_j = Phi_base,j(q, qd, qdd) theta + tau_L,j     (tau_L = 0 in a run without it)
//! ```
//!
//! linear in the base parameters `theta` and the gains `K`, so one least-squares problem over
//! every run gives both: `Phi_base theta - diag(i) K = -tau_L`, reduced per joint as the plain
//! fit is ([`super::streaming`], the signal a column of data of each joint's rows), OLS then
//! WLS. The payload fixes the scale: with the same payload (or none) in every run, `theta` and
//! `K` could be scaled together and the data would not tell, so such runs are refused.
//!
//! The signal's noise sits in columns of the regressor, where it biases the least-squares
//! gains towards 0: [`DriveGains::noise_bias`] estimates by how much, taking every residual
//! for the signal's noise. [`GainEstimator::Instrumental`] removes the bias, by instrumental
//! variables ([`super::instrumental`]).

use super::base::BaseParameters;
use super::base_model::BaseModel;
use super::base_options::{BaseOptions, Weighting};
pub use super::findings::drive_gains::*;
use super::identify::fit_with_factors;
use super::streaming::JointFactors;
use crate::error::{shown, Error, Result};
use crate::model::payload::Payload;
use crate::model::Model;
use crate::regression::LeastSquares;
use crate::states::States;

/// An identification of drive gains: the base-parameter model of the robot alone (SI units:
/// its predictions are torques), with the gains in [`BaseModel::drive_gains`].
#[derive(Clone, Debug, PartialEq)]
pub struct DriveGainFit {
    pub model: BaseModel,
}

impl DriveGainFit {
    /// The gains (always present in a fit).
    pub fn gains(&self) -> &DriveGains {
        self.model
            .drive_gains
            .as_ref()
            .expect("a drive-gain fit holds its gains")
    }
}

/// The payload's torques alone (row-major `k x nv`, N m or N) at `states`: the robot's model
/// with every body massless but the payload's link, which holds only the payload.
fn payload_torques(
    model: &Model,
    payload: &Payload,
    states: &States<'_>,
    options: &BaseOptions,
) -> Result<Vec<f64>> {
    let (b, inertia) = payload.in_body(model)?;
    let mut alone = model.clone();
    for body in &mut alone.bodies {
        body.inertia = crate::spatial::Inertia::zeros();
    }
    alone.bodies[b].inertia = inertia;
    alone.armature.iter_mut().for_each(|a| *a = 0.0);
    alone.refresh();
    let mut tau = vec![0.0; states.len() * model.nv];
    let mut ws = crate::algorithms::parallel::Workspace::new(&alone);
    crate::algorithms::parallel::rnea(&alone, &mut ws, states, options.gravity, &mut tau)?;
    Ok(tau)
}

/// The payload as its link's body and ten inertial parameters (None: no payload, or one of no
/// mass), for telling runs' payloads apart.
fn load_of(model: &Model, payload: Option<&Payload>) -> Result<Option<(usize, [f64; 10])>> {
    let Some(p) = payload.filter(|p| p.mass > 0.0) else {
        return Ok(None);
    };
    let (b, i) = p.in_body(model)?;
    Ok(Some((
        b,
        crate::algorithms::regressor::dynamic_parameters(&i),
    )))
}

/// Identifies the drive gains and the base parameters of `model` from `runs` (at least two, at
/// most [`MAX_RUNS`], not all with the same payload): see the module docs. `options` as for
/// [`super::identify_base_parameters`], whose checks of the data (torque columns, lag, offsets,
/// friction, excitation) the model gets on the signal scaled by the gains.
///
/// Errors: runs of other joints or without velocities, signals of the wrong shape or flat,
/// payloads that are no rigid body or on no moving link, every run with the same payload, and
/// data that do not determine the gains (rank deficiency, naming them).
pub fn identify_drive_gains(
    model: &Model,
    runs: &[GainRun<'_>],
    options: &BaseOptions,
) -> Result<DriveGainFit> {
    identify_drive_gains_with(model, runs, options, GainEstimator::LeastSquares)
}

/// [`identify_drive_gains`] by `estimator`: by instrumental variables, the least-squares fit
/// comes first (its gains kept in [`DriveGains::least_squares_gain`], its bias estimate in
/// [`DriveGains::noise_bias`]) and predicts the instruments; the model's parameters, standard
/// errors, correlation, residuals and every check of the data are then the instrumental
/// estimate's.
pub fn identify_drive_gains_with(
    model: &Model,
    runs: &[GainRun<'_>],
    options: &BaseOptions,
    estimator: GainEstimator,
) -> Result<DriveGainFit> {
    let nv = model.nv;
    let k = check_runs(model, runs, options)?;
    let (stacked, rhs, loaded) = stack_runs(model, runs, options)?;
    let signal = &stacked.data;
    let states = stacked.states()?;
    crate::torque_model::refuse_flat_torques(
        &states,
        signal,
        &model.joint_names,
        "a fit would take it for a signal that does not follow the motion",
    )?;

    // the joint fit of base parameters and gains: OLS, then WLS on its residuals
    let base = super::base_solve::base_parameters(model, options)?;
    let p = base.len();
    // each run is read alone too (the agreement), so each must determine the parameters
    if let Some((r, run)) = (runs.iter().enumerate()).find(|(_, run)| run.states.len() <= p) {
        return Err(bad_runs(format!(
            "run {r} has {} samples; at least {} are needed to read it against the others",
            run.states.len(),
            p + 1
        )));
    }
    let factors =
        JointFactors::with_columns(model, &base, &states, &rhs, &[signal], options.gravity)?;
    let names: Vec<String> = base
        .names()
        .into_iter()
        .chain(model.joint_names.iter().map(|j| format!("{j}.drive_gain")))
        .collect();
    let mut sigma = vec![1.0; nv];
    let mut ls = factors.solve(&sigma, &names)?;
    let mut rms = factors.residual_rms(ls.coef.as_slice())?;
    if options.weighting == Weighting::Wls {
        sigma = rms
            .iter()
            .map(|&s| if s.is_finite() && s > 0.0 { s } else { 1.0 })
            .collect();
        ls = factors.solve(&sigma, &names)?;
        rms = factors.residual_rms(ls.coef.as_slice())?;
    }
    let ls_coef: Vec<f64> = ls.coef.row(0).iter().copied().collect();
    let ls_gain: Vec<f64> = ls_coef[p..].iter().map(|c| -c).collect();
    refuse_undetermined(model, &ls_gain, &rms)?;
    // by instrumental variables the model is theirs; the least-squares fit keeps the gains'
    // noise bias (below)
    let iv = match estimator {
        GainEstimator::LeastSquares => None,
        GainEstimator::Instrumental => Some(super::instrumental::instrumental(
            &factors, &sigma, &ls_coef, &names,
        )?),
    };
    let fit = iv.as_ref().unwrap_or(&ls);
    let coef: Vec<f64> = fit.coef.row(0).iter().copied().collect();
    let fit_rms: Vec<f64> = match &iv {
        Some(iv) => iv.residual_rms.iter().copied().collect(),
        None => rms.clone(),
    };
    let gain: Vec<f64> = coef[p..].iter().map(|c| -c).collect();
    refuse_undetermined(model, &gain, &fit_rms)?;

    // the robot alone: its torques are the gains' times the signal less the payload's
    let tau: Vec<f64> = (0..k * nv)
        .map(|x| gain[x % nv] * signal[x] + rhs[x])
        .collect();
    // each run's residuals a time series of their own
    let options = &BaseOptions {
        runs: stacked.runs.clone(),
        ..options.clone()
    };
    let (mut model_fit, _) = fit_with_factors(model, &states, &tau, options)?;
    let inflation = model_fit.stderr_inflation();
    let stderr: Vec<f64> = fit.stderr.row(0).iter().map(|s| s * inflation).collect();
    model_fit.theta = coef[..p].to_vec();
    model_fit.stderr = stderr[..p].to_vec();
    model_fit.correlation = fit.correlation.view((0, 0), (p, p)).into_owned();
    model_fit.residual_rms = fit_rms.clone();
    model_fit.sigma = sigma;
    let noise_bias = noise_bias(model, &ls, p, &rms, &model_fit.sigma, &ls_gain, k)?;
    let agreement = agreement(model, &base, runs, signal, &fit_rms, &gain, options)?;
    let payload_torque_rms = (loaded.squares.iter())
        .map(|sum| (sum / loaded.rows.max(1) as f64).sqrt())
        .collect();
    model_fit.drive_gains = Some(DriveGains {
        gain,
        stderr: stderr[p..].to_vec(),
        noise_bias,
        payload_torque_rms,
        agreement,
        cond: ls.cond,
        runs: runs.len(),
        loaded_runs: loaded.runs,
        estimator,
        // the fit's coefficients are -K: the gains' correlation with the parameters is the
        // negated one
        correlation: nalgebra::DMatrix::from_fn(nv, p + nv, |j, a| {
            let r = fit.correlation[(p + j, a)];
            if a < p {
                -r
            } else {
                r
            }
        }),
        least_squares_gain: match estimator {
            GainEstimator::LeastSquares => Vec::new(),
            GainEstimator::Instrumental => ls_gain,
        },
    });
    Ok(DriveGainFit { model: model_fit })
}

/// An error in the runs given.
fn bad_runs(message: String) -> Error {
    Error::InvalidArgument {
        argument: "runs".into(),
        message,
    }
}

/// The options and runs checked before any work: their count, joints, derivatives, signals,
/// payloads (not all alike) and total size. Returns the number of samples in all.
fn check_runs(model: &Model, runs: &[GainRun<'_>], options: &BaseOptions) -> Result<usize> {
    let nv = model.nv;
    let bad = bad_runs;
    if options.weighting == Weighting::Noise || options.noise.is_some() {
        // the torques are the gains times the signal: a noise in its units is not known
        // before the gains are
        return Err(Error::invalid(
            "weighting",
            "the noise weighting is not taken with drive gains: the torques are the gains times the logged signal, so their noise is not known before the gains are; weight from the residuals (wls) or not (ols)",
        ));
    }
    if options.offset_per_run {
        // each loaded run's mean payload torque, part of what sets the gains' scale, would
        // go into that run's offset
        return Err(Error::invalid(
            "offset_per_run",
            "not taken with drive gains: an offset of each run's own would take up each loaded run's mean payload torque, part of what sets the gains' scale",
        ));
    }
    if !(2..=MAX_RUNS).contains(&runs.len()) {
        return Err(bad(format!(
            "{} runs given, expected 2 to {MAX_RUNS}: one without the payload (or with another) and one with it",
            runs.len()
        )));
    }
    let mut loads = Vec::with_capacity(runs.len());
    for (r, run) in runs.iter().enumerate() {
        let s = &run.states;
        let at = |e: Error| bad(format!("run {r}: {e}"));
        crate::torque_model::check_joints(s, nv).map_err(at)?;
        if s.qd().is_none() || s.qdd().is_none() {
            return Err(bad(format!(
                "run {r} has no velocities and accelerations: preprocess its log first"
            )));
        }
        s.check_companion("signal", run.signal, nv).map_err(at)?;
        if let Some(problem) = run.payload.and_then(|p| p.problem("payload")) {
            return Err(bad(format!("run {r}: {problem}")));
        }
        loads.push(load_of(model, run.payload).map_err(at)?);
    }
    // the runs are held together, about ten values a joint and sample
    let k: usize = runs.iter().map(|r| r.states.len()).sum();
    if (k * nv) as f64 * 10.0 > crate::limits::MAX_VALUES {
        return Err(bad(format!(
            "{k} samples of {nv} joints in all: more than the {} values the fit may hold (about ten a joint and sample); decimate the logs (preprocess at a lower rate)",
            crate::limits::MAX_VALUES
        )));
    }
    if loads.iter().all(|l| *l == loads[0]) {
        return Err(bad(format!(
            "every run carries {}: the gains' scale is not determined (the parameters and the gains could grow together); run the motion once more with a known payload bolted on, and give it as that run's payload",
            match &runs[0].payload {
                Some(p) if p.mass > 0.0 => format!("the same payload ({} kg on '{}')", p.mass, p.link),
                _ => "no payload".into(),
            }
        )));
    }
    Ok(k)
}

/// The payloads' squared torques per joint summed over the loaded runs' samples, with the
/// counts of those samples and runs.
struct LoadedTorques {
    squares: Vec<f64>,
    rows: usize,
    runs: usize,
}

/// The runs one after the other: states, the signal (its column's coefficient is -K) and the
/// right-hand side -tau_L, with the payloads' torques summed.
fn stack_runs<'a>(
    model: &Model,
    runs: &[GainRun<'a>],
    options: &BaseOptions,
) -> Result<(
    crate::logs::stacked_states::StackedStates,
    Vec<f64>,
    LoadedTorques,
)> {
    let nv = model.nv;
    let parts: Vec<(States<'_>, &[f64])> = runs.iter().map(|r| (r.states, r.signal)).collect();
    let stacked = crate::logs::stacked_states::StackedStates::of(&parts)?;
    let mut rhs = vec![0.0; stacked.data.len()];
    // per joint, the payloads' squared torques summed over the loaded runs' samples
    let (mut loaded_squares, mut loaded_rows, mut loaded_runs) = (vec![0.0; nv], 0, 0);
    let mut first = 0;
    for run in runs {
        let s = &run.states;
        if let Some(p) = run.payload.filter(|p| p.mass > 0.0) {
            let tau = payload_torques(model, p, s, options)?;
            let rows = &mut rhs[first * nv..(first + s.len()) * nv];
            for (x, (t, r)) in tau.iter().zip(rows).enumerate() {
                loaded_squares[x % nv] += t * t;
                *r = -t;
            }
            loaded_rows += s.len();
            loaded_runs += 1;
        }
        first += s.len();
    }
    let loaded = LoadedTorques {
        squares: loaded_squares,
        rows: loaded_rows,
        runs: loaded_runs,
    };
    Ok((stacked, rhs, loaded))
}

/// Refuses gains that are not finite and non-zero, or residuals that are not finite.
fn refuse_undetermined(model: &Model, gain: &[f64], rms: &[f64]) -> Result<()> {
    match (0..model.nv).find(|&j| !(gain[j].is_finite() && gain[j] != 0.0 && rms[j].is_finite())) {
        Some(j) => Err(Error::numerical(
            "drive-gain identification",
            format!(
                "joint '{}': gain {} with residual RMS {}: the signal does not determine it (a signal of 0 or one too large for f64 arithmetic?)",
                model.joint_names[j],
                shown(gain[j]),
                shown(rms[j])
            ),
        )),
        None => Ok(()),
    }
}

/// The gains' noise bias from the least-squares fit `ls` of `p` base parameters and the gains
/// (residual RMS `rms`, weights `sigma`, gains `ls_gain`, `k` samples).
///
/// Errors in the columns bias least squares by -(X^T W^2 X)^-1 Sigma_uu theta, Sigma_uu holding
/// k (noise / sigma)^2 at each joint's signal column (its rows weighted by 1 / sigma); the
/// gains share one scale with each other and the parameters, so every joint's noise biases
/// every gain. The noise taken for the whole residual, rms / |K|. (The fit's coefficients are
/// -K: their covariance is K's.)
fn noise_bias(
    model: &Model,
    ls: &LeastSquares,
    p: usize,
    rms: &[f64],
    sigma: &[f64],
    ls_gain: &[f64],
    k: usize,
) -> Result<Vec<f64>> {
    let nv = model.nv;
    let cov =
        |a: usize, b: usize| ls.correlation[(a, b)] * (ls.cov_diag[a] * ls.cov_diag[b]).sqrt();
    (0..nv)
        .map(|m| {
            let sum: f64 = (0..nv)
                .map(|j| {
                    let w = rms[j] / sigma[j];
                    cov(p + m, p + j) * k as f64 * w * w / ls_gain[j]
                })
                .sum();
            let bias = sum / ls_gain[m];
            if bias.is_finite() {
                Ok(bias.max(0.0))
            } else {
                Err(Error::numerical(
                    "drive-gain identification",
                    format!(
                        "joint '{}': its signal is explained whole by the model's other columns, so its gain is not determined",
                        model.joint_names[m]
                    ),
                ))
            }
        })
        .collect::<Result<Vec<f64>>>()
}

/// Per joint, how well the runs agree: the joint fit's residual (in signal units) over each
/// run's signal fitted alone.
fn agreement(
    model: &Model,
    base: &BaseParameters,
    runs: &[GainRun<'_>],
    signal: &[f64],
    fit_rms: &[f64],
    gain: &[f64],
    options: &BaseOptions,
) -> Result<Vec<f64>> {
    let nv = model.nv;
    let k = signal.len() / nv;
    // each run's signal fitted alone, joint by joint, for the agreement
    let mut alone = vec![0.0; nv];
    for run in runs {
        let f = JointFactors::new(model, base, &run.states, run.signal, options.gravity)?;
        for (a, r) in alone.iter_mut().zip(&f.factors) {
            *a += beyond_the_rest(r).powi(2);
        }
    }
    Ok((0..nv)
        .map(|j| {
            let scale: f64 = (0..k).map(|s| signal[s * nv + j].powi(2)).sum::<f64>() / k as f64;
            let floor = 1e-9 * scale.sqrt();
            let own = (alone[j] / k as f64).sqrt();
            (fit_rms[j] / gain[j].abs() + floor) / (own + floor)
        })
        .collect())
}

/// The norm of the last column of the triangular factor `r` (`n x n`) beyond the span of the
/// others: the residual of the least-squares fit of that column on them, by SVD (the others
/// may be rank deficient: columns zero in a joint's rows).
fn beyond_the_rest(r: &nalgebra::DMatrix<f64>) -> f64 {
    let n = r.ncols();
    let (a, b) = (
        r.columns(0, n - 1).into_owned(),
        r.column(n - 1).into_owned(),
    );
    let svd = a.clone().svd(true, true);
    let tol = 1e-10 * svd.singular_values.max();
    match svd.solve(&b, tol) {
        Ok(x) => (b - a * x).norm(),
        Err(_) => b.norm(),
    }
}
