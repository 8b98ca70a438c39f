//! The separated least-squares identification of the local model (docs/method.md, section 4) from a
//! plan and one recording per experiment.

use nalgebra::DMatrix;

use super::clock::{align, check_sample_interval, lagged_half};
use super::crossing::{
    samples_needed, values_in_windows, CrossingValues, FitOptions, SignalScales, TorqueFit,
};
use super::diagnose::{
    compare_combined, diagnose, disagreement_warning, mass_matrix_warning, unperturbed_deviation,
};
use super::diagnostics::{Reversal, ReversalHandling, TorqueNoise, Unmeasured};
use super::errors_in_variables;
use super::flat_channels::{flat, flat_torque_warning};
pub use super::flat_channels::{flat_torques, window_torques};
use super::friction_aware::friction_aware_h;
use super::glitches;
use super::model::{Estimate, Estimator, LocalModel};
use super::noise::{nominal_noise, reading_variance, sample_variance, weighted_least_squares};
use super::plan::{Experiment, ExperimentKind, Plan};
use super::quantisation;
use super::response;
use super::reversals::narrowed_window;
use super::rounded_positions::{self, Resolution};
use super::torque_offsets;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;
use crate::operating_point::OperatingPoint;

/// Where the crossing times come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CrossingTimes {
    /// The plan's times, the recording's clock starting with the plan (t = 0 at the plan's
    /// start). A recording whose clock is offset reads every crossing at the wrong time: 1 ms
    /// makes H* wrong by far more than its noise.
    Planned,
    /// The plan's times shifted by the offset between plan and recording found in the
    /// recorded positions (least squares against the planned trajectory, sub-sample). An
    /// offset larger than `max_shift` s is refused: the recording is then likely not a run of
    /// the experiment, or its clock needs to be fixed first. The offsets are in the model's
    /// diagnostics.
    Detected { max_shift: f64 },
}

impl CrossingTimes {
    /// The default tolerance of [`CrossingTimes::Detected`] (s).
    pub const DEFAULT_MAX_SHIFT: f64 = 0.5;
}

/// Options of [`identify_local`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdentifyOptions {
    pub times: CrossingTimes,
    pub fit: FitOptions,
    pub estimator: Estimator,
    /// Identify H* with the friction-aware regression (default false): the differences of
    /// the +- pairs of the H experiment, `tau(qd* + d) - tau(qd* - d) = 2 H* d + c_j s_j`,
    /// where the rigid-body terms even in `d` cancel exactly and `s_j = sign(d_j)` marks the
    /// pairs that reverse joint j (its Coulomb step, `c_j` = the sum of its two Coulomb levels).
    /// Exact for viscous and (asymmetric) Coulomb friction; needs the plan's H perturbations in
    /// pairs, at least N + 1 of them (`PlanOptions::friction_aware_h`). The Coulomb levels are
    /// in [`LocalModel::coulomb`].
    pub friction_aware_h: bool,
}

impl Default for IdentifyOptions {
    /// Crossing times aligned with each recording's clock (offsets up to 0.5 s), the default
    /// fit, the separated estimator.
    fn default() -> Self {
        Self {
            times: CrossingTimes::Detected {
                max_shift: CrossingTimes::DEFAULT_MAX_SHIFT,
            },
            fit: FitOptions::default(),
            estimator: Estimator::Separated,
            friction_aware_h: false,
        }
    }
}

/// The values read at every crossing of one experiment (and its reference posture).
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentValues {
    pub kind: ExperimentKind,
    /// Offset (s) added to the planned times.
    pub offset: f64,
    pub crossings: Vec<CrossingValues>,
    pub reference: Option<CrossingValues>,
    /// The crossings at which a joint's velocity reverses within the fit window, and how its
    /// torque was read there.
    pub reversals: Vec<Reversal>,
    /// Per joint, the value (N m) every torque sample read for this experiment had, when all
    /// of them (every crossing's window and the reference posture's) had the same one: a torque
    /// signal that did not change (see [`flat_torques`]).
    pub flat_torque: Vec<Option<f64>>,
    /// Per joint, the step (N m) of the grid the torque samples read for this experiment lie
    /// on, if any (see [`super::quantisation::torque_steps`]).
    pub torque_step: Vec<Option<f64>>,
    /// Per joint, the encoder step (rad) of the recording's positions where the state of at
    /// least one crossing (or the reference posture) was read by the band of half a step
    /// ([`super::rounded_positions`]); None otherwise.
    pub position_step: Vec<Option<f64>>,
}

/// How to read the torque of each joint at the crossing at plan time `tp` (the recording's
/// clock: `tp + offset`) so that no velocity reversal enters the fit: the full window where no
/// joint reverses within it; a window narrowed to 0.9 of the distance to the reversal where
/// that still holds `min_half` s; else a step at the reversal (see [`TorqueFit`]). The
/// reversals are appended to `found`.
#[allow(clippy::too_many_arguments)]
fn torque_fits(
    experiment: &Experiment,
    joint_names: &[String],
    tp: f64,
    offset: f64,
    half: f64,
    min_half: f64,
    crossing: Option<usize>,
    found: &mut Vec<Reversal>,
) -> Vec<TorqueFit> {
    let traj = &experiment.trajectory;
    (0..traj.n)
        .map(|j| {
            let Some((tr, narrowed)) = narrowed_window(traj, j, tp, half, min_half) else {
                return TorqueFit::Window(half);
            };
            let (fit, handling, window) = if let Some(narrowed) = narrowed {
                (
                    TorqueFit::Window(narrowed),
                    ReversalHandling::Narrowed,
                    narrowed,
                )
            } else {
                let slope = traj.segment_at(tr).eval(j, tr).2.signum();
                let fit = TorqueFit::Step {
                    reversal: tr + offset,
                    slope,
                };
                (fit, ReversalHandling::Step, half)
            };
            found.push(Reversal {
                experiment: experiment.kind.name().to_string(),
                crossing,
                joint: joint_names
                    .get(j)
                    .cloned()
                    .unwrap_or_else(|| format!("{}", j + 1)),
                at: tr - tp,
                handling,
                window,
            });
            fit
        })
        .collect()
}

/// Reads the values at every crossing of `experiment` from `rec`. `joint_names` name the
/// joints in diagnostics.
pub fn experiment_values(
    experiment: &Experiment,
    rec: &Recording,
    joint_names: &[String],
    options: &IdentifyOptions,
) -> Result<ExperimentValues> {
    let half = options.fit.window.unwrap_or(experiment.window);
    crate::limits::check_range("window", half, 0.0, 60.0)?;
    if !(half.is_finite() && half > 0.0) {
        return Err(Error::InvalidArgument {
            argument: "window".into(),
            message: format!("{half}; expected a positive number of seconds"),
        });
    }
    check_sample_interval(rec, half, &options.fit)?;
    let steps = rounded_positions::position_steps(rec);
    let offset = match options.times {
        CrossingTimes::Planned => 0.0,
        CrossingTimes::Detected { max_shift } => {
            align(experiment, rec, joint_names, &steps, max_shift)?
        }
    };
    // the narrowest torque window that still holds enough samples at the recording's rate
    let dt = (rec.t[rec.len() - 1] - rec.t[0]) / (rec.len() - 1) as f64;
    let half = match options.fit.window {
        None => lagged_half(half, offset, dt),
        Some(_) => half,
    };
    let min_half = 0.5 * samples_needed(&options.fit) as f64 * dt;
    let name = experiment.kind.name();
    let mut reversals = vec![];
    // every window: the crossings' in order, then the reference posture's, each with its
    // joints' torque fits
    let windows: Vec<(f64, Option<usize>, String, Vec<TorqueFit>)> = experiment
        .crossings
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                c.time,
                Some(k),
                format!("experiment '{name}', crossing {k}"),
            )
        })
        .chain(experiment.reference.iter().map(|c| {
            let what = format!("experiment '{name}', reference posture");
            (c.time, None, what)
        }))
        .map(|(tp, crossing, what)| {
            let fits = torque_fits(
                experiment,
                joint_names,
                tp,
                offset,
                half,
                min_half,
                crossing,
                &mut reversals,
            );
            (tp, crossing, what, fits)
        })
        .collect();
    let centres: Vec<f64> = windows.iter().map(|w| w.0 + offset).collect();
    let torques = window_torques(rec, &centres, half);
    let in_clock: Vec<(f64, Vec<TorqueFit>, String)> = windows
        .into_iter()
        .map(|(tp, _, what, fits)| (tp + offset, fits, what))
        .collect();
    let scales = SignalScales {
        position_step: steps,
        torque_step: quantisation::torque_steps(&torques),
        noise: vec![],
    };
    let (mut values, scales) = values_in_windows(rec, &in_clock, half, scales, &options.fit)?;
    let reference = match experiment.reference {
        Some(_) => values.pop(),
        None => None,
    };
    let crossings = values;
    let position_step = (0..rec.n)
        .map(|j| {
            let banded = crossings
                .iter()
                .chain(&reference)
                .any(|c| c.position_band[j]);
            scales.position_step[j].filter(|_| banded)
        })
        .collect();
    Ok(ExperimentValues {
        kind: experiment.kind,
        offset,
        crossings,
        reference,
        reversals,
        flat_torque: flat(&torques),
        torque_step: scales.torque_step,
        position_step,
    })
}

pub(super) fn state(c: &CrossingValues, v: usize) -> &[f64] {
    match v {
        0 => &c.q,
        1 => &c.qd,
        _ => &c.qdd,
    }
}

/// The variances (N^2 m^2, one row per crossing of `experiments` in order, one column per
/// joint) that the torque samples' noise gives the torques read at the crossings, and the
/// samples' noise variance of each experiment, pooled within it, per joint (see
/// [`super::noise`]).
fn reading_variances(experiments: &[&ExperimentValues], n: usize) -> (DMatrix<f64>, Vec<Vec<f64>>) {
    let samples: Vec<Vec<f64>> = experiments
        .iter()
        .map(|v| sample_variance(&v.crossings, n))
        .collect();
    let rows: Vec<Vec<f64>> = experiments
        .iter()
        .zip(&samples)
        .flat_map(|(v, s2)| v.crossings.iter().map(|c| reading_variance(c, s2)))
        .collect();
    (DMatrix::from_fn(rows.len(), n, |i, j| rows[i][j]), samples)
}

/// Pairs each experiment of `plan` with its recording, by identity: each recording says which
/// experiment it is a run of ([`Recording::experiment`]: its mark, or a name such as `D.csv`).
/// A recording that names no experiment of the plan, two for one experiment, or an experiment
/// without one is an error naming them: the order of `recordings` does not matter.
fn match_recordings<'a>(plan: &Plan, recordings: &'a [Recording]) -> Result<Vec<&'a Recording>> {
    let kinds: Vec<&str> = plan.experiments.iter().map(|e| e.kind.name()).collect();
    let mut found: Vec<Option<&Recording>> = vec![None; kinds.len()];
    let refuse = |message: String| Error::InvalidArgument {
        argument: "recordings".into(),
        message,
    };
    for r in recordings {
        let Some(kind) = r.experiment(&kinds) else {
            return Err(refuse(format!(
                "recording '{}' does not say which experiment it is a run of (the plan has {}): mark it (Python: Recording(..., experiment='D')) or name its file after the experiment (D.csv)",
                r.name,
                plan.kinds()
            )));
        };
        let Some(i) = kinds.iter().position(|k| *k == kind) else {
            return Err(refuse(format!(
                "recording '{}' is a run of experiment '{kind}', which the plan does not have (it has {})",
                r.name,
                plan.kinds()
            )));
        };
        if let Some(first) = found[i] {
            return Err(refuse(format!(
                "recordings '{}' and '{}' are both runs of experiment '{kind}'; give one",
                first.name, r.name
            )));
        }
        found[i] = Some(r);
    }
    kinds
        .iter()
        .zip(found)
        .map(|(kind, r)| {
            r.ok_or_else(|| refuse(format!("experiment '{kind}' of the plan has no recording")))
        })
        .collect()
}

/// Identifies the local model from `plan` and `recordings` (one per experiment of the plan, in
/// any order, each saying which experiment it is a run of, each with the plan's N joints).
///
/// `T*` is the mean torque at the nominal crossings, and the model's operating point the mean
/// state there. For G, H and D: `Y` rows `tau_k - T*`, `X` rows the measured deltas of the
/// perturbed variable from that point; G-static: `tau_k - tau_ref` against `q_k - q_ref` at the
/// reference posture. One least-squares solve each (faer SVD). The combined estimate stacks the
/// nominal, G, H and D crossings against `[dqdd dqd dq]`.
pub fn identify_local(
    plan: &Plan,
    recordings: &[Recording],
    options: &IdentifyOptions,
) -> Result<LocalModel> {
    let n = plan.n();
    let mut values = Vec::new();
    let mut recording_names: Vec<String> = Vec::new();
    let (mut dropouts, mut dropout_warnings) = (vec![], vec![]);
    let mut held_readings = vec![];
    for (e, r) in plan
        .experiments
        .iter()
        .zip(match_recordings(plan, recordings)?)
    {
        crate::interrupt::check("identification")?;
        if r.n != n {
            return Err(Error::Recording {
                recording: r.name.clone(),
                message: format!(
                    "{} joints; the plan (experiment '{}') has {n}",
                    r.n,
                    e.kind.name()
                ),
            });
        }
        let read = super::repaired_recording::read_experiment(e, r, &plan.joint_names, options)?;
        dropout_warnings.extend(read.warnings);
        held_readings.extend(read.held);
        dropouts.extend(read.dropouts);
        let v = read.values;
        values.push(v);
        recording_names.push(r.name.clone());
    }
    let find = |kind| values.iter().find(|v: &&ExperimentValues| v.kind == kind);
    let names = |prefix: &str| -> Vec<String> {
        plan.joint_names
            .iter()
            .map(|j| format!("{prefix}({j})"))
            .collect()
    };

    // T* and the measured operating point
    let nominal = find(ExperimentKind::Nominal);
    let needs_nominal = values.iter().any(|v| {
        matches!(
            v.kind,
            ExperimentKind::GDynamic | ExperimentKind::H | ExperimentKind::D
        )
    });
    let (torque, torque_stderr, op) = match nominal {
        Some(v) => {
            let k = v.crossings.len() as f64;
            let mean = |f: &dyn Fn(&CrossingValues) -> &[f64]| -> Vec<f64> {
                (0..n)
                    .map(|j| v.crossings.iter().map(|c| f(c)[j]).sum::<f64>() / k)
                    .collect()
            };
            let tau = mean(&|c| &c.tau);
            let samples = sample_variance(&v.crossings, n);
            let se = (0..n)
                .map(|j| {
                    let ss: f64 = v
                        .crossings
                        .iter()
                        .map(|c| (c.tau[j] - tau[j]).powi(2))
                        .sum();
                    let rounding = quantisation::undithered_step(v.torque_step[j], samples[j])
                        .map_or(0.0, |q| quantisation::rounding_stderr(q) / k.sqrt());
                    if k > 1.0 {
                        (ss / (k - 1.0) / k).sqrt().max(rounding)
                    } else {
                        f64::NAN
                    }
                })
                .collect();
            let op = OperatingPoint {
                q: mean(&|c| &c.q),
                qd: mean(&|c| &c.qd),
                qdd: mean(&|c| &c.qdd),
            };
            (tau, se, op)
        }
        None if needs_nominal => return Err(Error::InvalidArgument {
            argument: "plan".into(),
            message:
                "the plan has no nominal experiment, which the G, H and D regressions need for T*"
                    .into(),
        }),
        None => (vec![f64::NAN; n], vec![f64::NAN; n], plan.op.clone()),
    };
    let op_state = [op.q.clone(), op.qd.clone(), op.qdd.clone()];
    // the variance of the operating point's error, the mean of the nominal crossings': noise
    // averages over their K passes (/ K), but positions read by their band are rounded the same
    // way in every pass of one trajectory, and need not average out
    let op_var: [Vec<f64>; 3] = std::array::from_fn(|var| {
        (0..n)
            .map(|j| {
                nominal.map_or(0.0, |v| {
                    let k = v.crossings.len().max(1) as f64;
                    let mean = v
                        .crossings
                        .iter()
                        .map(|c| c.state_stderr[var][j].powi(2))
                        .sum::<f64>()
                        / k;
                    if v.crossings.iter().any(|c| c.position_band[j]) {
                        mean
                    } else {
                        mean / k
                    }
                })
            })
            .collect()
    });

    let passes =
        nominal.and_then(|v| response::PassNoise::of(v.crossings.iter().map(|c| &c.tau[..])));
    let noise =
        std::cell::RefCell::new(nominal.map_or(vec![], |v| nominal_noise(v, &plan.joint_names)));
    let extra_warnings = std::cell::RefCell::new(vec![]);
    let offsets_found = std::cell::RefCell::new(vec![]);
    let separated = |kind: ExperimentKind, prefix: &str| -> Result<Option<Estimate>> {
        let Some(v) = find(kind) else { return Ok(None) };
        let var = kind.perturbed().expect("perturbed experiment");
        let k = v.crossings.len();
        let (base_tau, base_x): (&[f64], &[f64]) = match &v.reference {
            Some(r) => (&r.tau, &r.q),
            None => (&torque, &op_state[var]),
        };
        let base_var: Vec<f64> = match &v.reference {
            Some(r) => r.state_stderr[0].iter().map(|s| s * s).collect(),
            None => op_var[var].clone(),
        };
        let x = DMatrix::from_fn(k, n, |i, j| state(&v.crossings[i], var)[j] - base_x[j]);
        if let Some(j) = (0..n).find(|&j| x.column(j).iter().all(|d| *d == 0.0)) {
            if let Some(step) = v.position_step[j] {
                return Err(rounded_positions::unresolved(
                    kind.name(),
                    (k, n),
                    &format!("{prefix}({})", plan.joint_names[j]),
                    &plan.joint_names[j],
                    step,
                    var,
                    v.reference.is_some(),
                ));
            }
        }
        let y = DMatrix::from_fn(k, n, |i, j| v.crossings[i].tau[j] - base_tau[j]);
        let base_tau_var: Vec<f64> = match &v.reference {
            Some(r) => reading_variance(r, &sample_variance(&v.crossings, n)),
            None => torque_stderr.iter().map(|s| s * s).collect(),
        };
        let mut intercepts = torque_offsets::intercepts(&x, &y, &base_tau_var);
        // a channel that read one value throughout is reported as unmeasured instead
        for (c, flat) in intercepts.iter_mut().zip(&v.flat_torque) {
            if flat.is_some() {
                *c = None;
            }
        }
        let found = torque_offsets::findings(kind, &plan.joint_names, &intercepts, base_tau);
        let swapped = torque_offsets::swapped_pairs(kind, &found, &plan.joint_names, base_tau);
        let negated = torque_offsets::negated(kind, &found, &swapped, &plan.joint_names, base_tau);
        let planned = plan
            .experiment(kind)
            .expect("values of a planned experiment");
        let symmetric = planned.in_pairs();
        if let Some(w) = torque_offsets::warning(kind, &found, &swapped, &negated, symmetric) {
            extra_warnings.borrow_mut().push(w);
        }
        offsets_found.borrow_mut().extend(found);
        let (u, samples) = reading_variances(&[v], n);
        let flat = &v.flat_torque;
        let unresolved = response::experiment_warning(planned, &x, &y, &u, flat, passes.as_ref());
        extra_warnings.borrow_mut().extend(unresolved);
        let weighted = weighted_least_squares(
            &x,
            &y,
            &u,
            &format!("experiment '{}'", kind.name()),
            &names(prefix),
        )?;
        let (mut fit, correlation) = (weighted.fit, weighted.correlation);
        let row_var = DMatrix::from_fn(k, n, |i, j| v.crossings[i].state_stderr[var][j].powi(2));
        errors_in_variables::floor_stderr(&mut fit, &x, &row_var, &base_var)?;
        let resolutions: Vec<Resolution> = (0..n)
            .filter_map(|j| {
                let se: Vec<f64> = v.crossings.iter().map(|c| c.state_stderr[var][j]).collect();
                let dx: Vec<f64> = x.column(j).iter().copied().collect();
                Resolution::of(&plan.joint_names[j], v.position_step[j]?, &se, &dx)
            })
            .collect();
        extra_warnings
            .borrow_mut()
            .extend(rounded_positions::resolution_warning(
                kind.name(),
                var,
                &resolutions,
            ));
        for (j, ((joint, s2), a)) in plan
            .joint_names
            .iter()
            .zip(&samples[0])
            .zip(&weighted.common)
            .enumerate()
        {
            let step = quantisation::undithered_step(v.torque_step[j], *s2);
            if let Some(q) = step {
                quantisation::floor_stderr(&mut fit, j, quantisation::rounding_stderr(q));
            }
            noise.borrow_mut().push(TorqueNoise {
                experiment: kind.name().to_string(),
                joint: joint.clone(),
                samples: s2.sqrt(),
                passes: Some(a.sqrt()).filter(|v| v.is_finite()),
                step,
                position_step: v.position_step[j],
            });
        }
        // at rest a torque may read exactly 0 throughout and be kept (a vertical axis, gravity
        // compensated); one level shows no grid, but when the other torques are rounded, its
        // 0 is likely a level of one too
        if kind == ExperimentKind::GStatic {
            let finest = (0..n)
                .filter_map(|j| quantisation::undithered_step(v.torque_step[j], samples[0][j]))
                .min_by(f64::total_cmp);
            let zeros: Vec<usize> = (0..n).filter(|&j| v.flat_torque[j] == Some(0.0)).collect();
            if let (Some(q), false) = (finest, zeros.is_empty()) {
                for &j in &zeros {
                    quantisation::floor_stderr(&mut fit, j, quantisation::rounding_stderr(q));
                }
                let names: Vec<&str> = zeros
                    .iter()
                    .map(|&j| plan.joint_names[j].as_str())
                    .collect();
                extra_warnings
                    .borrow_mut()
                    .push(quantisation::flat_zero_warning(kind.name(), &names, q));
            }
        }
        Ok(Some(Estimate::of_fit(fit, correlation)))
    };
    let d = separated(ExperimentKind::D, "dqdd")?;
    let (h, coulomb) = match (options.friction_aware_h, find(ExperimentKind::H)) {
        (true, Some(v)) => {
            let e = plan
                .experiment(ExperimentKind::H)
                .expect("values of a planned experiment");
            let (h, c, h_noise, warnings) = friction_aware_h(plan, e, v)?;
            noise.borrow_mut().extend(h_noise);
            extra_warnings.borrow_mut().extend(warnings);
            (Some(h), Some(c))
        }
        (true, None) => {
            return Err(Error::InvalidArgument {
                argument: "friction_aware_h".into(),
                message: "the plan has no H experiment".into(),
            })
        }
        (false, _) => (separated(ExperimentKind::H, "dqd")?, None),
    };
    let g = separated(ExperimentKind::GDynamic, "dq")?;
    let g_static = separated(ExperimentKind::GStatic, "dq")?;

    let combined = if d.is_some() && h.is_some() && g.is_some() {
        let stacked: Vec<&ExperimentValues> = values
            .iter()
            .filter(|v| v.kind != ExperimentKind::GStatic)
            .collect();
        let rows: Vec<&CrossingValues> = stacked.iter().flat_map(|v| v.crossings.iter()).collect();
        let x = DMatrix::from_fn(rows.len(), 3 * n, |i, c| {
            let var = 2 - c / n; // columns: dqdd, dqd, dq
            state(rows[i], var)[c % n] - op_state[var][c % n]
        });
        let y = DMatrix::from_fn(rows.len(), n, |i, j| rows[i].tau[j] - torque[j]);
        let columns: Vec<String> = [names("dqdd"), names("dqd"), names("dq")].concat();
        let (u, samples) = reading_variances(&stacked, n);
        let weighted =
            weighted_least_squares(&x, &y, &u, "combined estimate (nominal, G, H, D)", &columns)?;
        let (mut fit, correlation) = (weighted.fit, weighted.correlation);
        let row_var = DMatrix::from_fn(rows.len(), 3 * n, |i, c| {
            rows[i].state_stderr[2 - c / n][c % n].powi(2)
        });
        let base_var: Vec<f64> = (0..3 * n).map(|c| op_var[2 - c / n][c % n]).collect();
        errors_in_variables::floor_stderr(&mut fit, &x, &row_var, &base_var)?;
        for j in 0..n {
            // the coarsest step any of the stacked experiments read this torque in, undithered
            let step = (stacked.iter().zip(&samples))
                .filter_map(|(v, s2)| quantisation::undithered_step(v.torque_step[j], s2[j]))
                .fold(None, |a: Option<f64>, q| Some(a.map_or(q, |a| a.max(q))));
            if let Some(q) = step {
                quantisation::floor_stderr(&mut fit, j, quantisation::rounding_stderr(q));
            }
        }
        Some(Estimate::of_fit(fit, correlation))
    } else {
        None
    };

    // a torque that did not change gives a row of zeros with standard errors of zero: claim
    // no certainty for it
    let mut d = d;
    let mut h = h;
    let mut g = g;
    let mut g_static = g_static;
    let mut combined = combined;
    let mut flat_warnings = vec![];
    let mut unmeasured = vec![];
    for v in &values {
        let Some(estimate) = (match v.kind {
            ExperimentKind::D => d.as_mut(),
            ExperimentKind::H => h.as_mut(),
            ExperimentKind::GDynamic => g.as_mut(),
            ExperimentKind::GStatic => g_static.as_mut(),
            ExperimentKind::Nominal => None,
        }) else {
            continue;
        };
        let mut flat = vec![];
        for (j, value) in v.flat_torque.iter().enumerate() {
            // at rest a torque can be exactly 0 in every posture (gravity compensated, or a
            // joint about a vertical axis): only a moving robot's torque must change
            let at_rest = v.kind == ExperimentKind::GStatic;
            let Some(value) = value.filter(|&x| !(at_rest && x == 0.0)) else {
                continue;
            };
            estimate.stderr.row_mut(j).fill(f64::NAN);
            if v.kind != ExperimentKind::GStatic {
                if let Some(c) = combined.as_mut() {
                    c.stderr.row_mut(j).fill(f64::NAN);
                }
            }
            flat.push((plan.joint_names[j].as_str(), value));
            unmeasured.push(Unmeasured {
                experiment: v.kind.name().to_string(),
                joint: plan.joint_names[j].clone(),
                value,
            });
        }
        if !flat.is_empty() {
            flat_warnings.push(flat_torque_warning(v.kind, &flat));
        }
    }
    let disagreement = combined
        .as_ref()
        .map_or_else(Vec::new, |c| compare_combined(c, [&d, &h, &g], n));
    let (d, h, g) = match (options.estimator, &combined) {
        (Estimator::Separated, _) => (d, h, g),
        (Estimator::Combined, Some(c)) => {
            let block = |b: usize| Some(c.columns(b * n, n));
            (block(0), block(1), block(2))
        }
        (Estimator::Combined, None) => {
            return Err(Error::InvalidArgument {
                argument: "estimator".into(),
                message: "the combined estimator needs the nominal, G, H and D experiments".into(),
            })
        }
    };
    let mut diagnostics = diagnose(&values);
    diagnostics.dropouts = dropouts;
    diagnostics.held_readings = held_readings;
    diagnostics.warnings.append(&mut dropout_warnings);
    for (v, name) in values.iter().zip(&recording_names) {
        let (found, warnings) = glitches::report(v, name, &plan.joint_names);
        diagnostics.glitches.extend(found);
        diagnostics.warnings.extend(warnings);
    }
    let deviation = unperturbed_deviation(&values, &op_state, &op_var);
    if let Some(w) = disagreement_warning(&disagreement, options.estimator, deviation) {
        diagnostics.warnings.push(w);
    }
    if let Some(w) = d
        .as_ref()
        .and_then(|d| mass_matrix_warning(d, &plan.joint_names))
    {
        diagnostics.warnings.push(w);
    }
    diagnostics.warnings.extend(flat_warnings);
    diagnostics.unmeasured = unmeasured;
    let mut torque_offsets = offsets_found.into_inner();
    torque_offsets.sort_by_key(|t| values.iter().position(|v| v.kind.name() == t.experiment));
    diagnostics.torque_offsets = torque_offsets;
    let mut noise = noise.into_inner();
    // in the plan's order of experiments
    noise.sort_by_key(|e| values.iter().position(|v| v.kind.name() == e.experiment));
    diagnostics.warnings.extend(quantisation::warnings(&noise));
    diagnostics.warnings.extend(extra_warnings.into_inner());
    (diagnostics.warnings).extend(super::followed_plan::warnings(plan, &values, &op_state));
    let nominal_offsets = torque_offsets::nominal_warning(&diagnostics.torque_offsets);
    diagnostics.warnings.extend(nominal_offsets);
    diagnostics.noise = noise;
    diagnostics.combined = disagreement;
    diagnostics.unperturbed_deviation = deviation;
    Ok(LocalModel {
        format: LocalModel::tag(),
        robot: plan.robot.clone(),
        joint_names: plan.joint_names.clone(),
        op,
        planned_op: plan.op.clone(),
        estimator: options.estimator,
        torque,
        torque_stderr,
        d,
        h,
        g,
        g_static,
        combined,
        coulomb,
        perturbations: super::Perturbations::of_plan(plan),
        diagnostics,
        drive_gains: None,
    })
}
