//! The local model identified from a plan and one recording per experiment, in named stages:
//! the recordings read ([`read_experiments`]), T* and the operating point
//! ([`NominalPoint`]), the regressions ([`Regressions`]), the estimator's choice and the
//! diagnostics.

use super::diagnose::{
    compare_combined, diagnose, disagreement_warning, mass_matrix_warning, unperturbed_deviation,
};
use super::diagnostics::{BlockAgreement, Diagnostics, Unmeasured};
use super::flat_channels::flat_torque_warning;
use super::friction_aware::friction_aware_h;
use super::glitches;
use super::identify::{match_recordings, ExperimentValues, IdentifyOptions};
use super::model::{Estimate, Estimator, LocalModel};
use super::nominal_point::NominalPoint;
use super::plan::{ExperimentKind, Plan};
use super::quantisation;
use super::regressions::{RegressionFindings, Regressions};
use super::torque_offsets;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::logs::log_dropouts::LogDropout;
use crate::logs::log_screening::LogGlitch;
use crate::logs::recording::Recording;

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
    let delay = options.fit.torque_delay;
    if !(delay.is_finite() && delay.abs() <= MAX_TORQUE_DELAY) {
        return Err(Error::invalid(
            "torque_delay",
            format!("{delay} s; expected a finite delay within +-{MAX_TORQUE_DELAY} s"),
        ));
    }
    let read = read_experiments(plan, recordings, options)?;
    identify_read(plan, read, options)
}

/// The stages of [`identify_local`] after the recordings were read.
pub(super) fn identify_read(
    plan: &Plan,
    read: ReadExperiments,
    options: &IdentifyOptions,
) -> Result<LocalModel> {
    let point = NominalPoint::of(plan, &read.values)?;
    let mut fits = Regressions::new(plan, &read.values, &point);
    let d = fits.separated(ExperimentKind::D, "dqdd")?;
    let (h, coulomb) = match (options.friction_aware_h, fits.find(ExperimentKind::H)) {
        (true, Some(v)) => {
            let e = plan
                .experiment(ExperimentKind::H)
                .expect("values of a planned experiment");
            let (h, c, h_noise, warnings) = friction_aware_h(plan, e, v)?;
            fits.noise.extend(h_noise);
            fits.warnings.extend(warnings);
            (Some(h), Some(c))
        }
        (true, None) => {
            return Err(Error::invalid(
                "friction_aware_h",
                "the plan has no H experiment",
            ))
        }
        (false, _) => (fits.separated(ExperimentKind::H, "dqd")?, None),
    };
    let g = fits.separated(ExperimentKind::GDynamic, "dq")?;
    let g_static = fits.separated(ExperimentKind::GStatic, "dq")?;
    let combined = match (&d, &h, &g) {
        (Some(_), Some(_), Some(_)) => Some(fits.combined()?),
        _ => None,
    };
    let mut estimates = Estimates {
        d,
        h,
        g,
        g_static,
        combined,
    };
    let flat = estimates.unclaim_flat_torques(plan, &read.values);
    let disagreement = (estimates.combined.as_ref()).map_or_else(Vec::new, |c| {
        compare_combined(c, [&estimates.d, &estimates.h, &estimates.g], plan.n())
    });
    let (d, h, g) = estimates.chosen(options.estimator, plan.n())?;
    let found = fits.findings();
    let nominal = point.nominal.map(|i| read.values[i].clone());
    let diagnostics = model_diagnostics(plan, options, read, &point, found, flat, disagreement, &d);
    let mut model = LocalModel {
        format: LocalModel::tag(),
        robot: plan.robot.clone(),
        joint_names: plan.joint_names.clone(),
        op: point.op,
        planned_op: plan.op.clone(),
        estimator: options.estimator,
        torque: point.torque,
        torque_stderr: point.torque_stderr,
        d,
        h,
        g,
        g_static: estimates.g_static,
        combined: estimates.combined,
        coulomb,
        perturbations: super::Perturbations::of_plan(plan),
        diagnostics,
        drive_gains: None,
        miss: None,
    };
    if let Some(nominal) = nominal {
        model.carry_to_plan(&nominal, &point.var, &point.common, &point.rounding)?;
        model
            .diagnostics
            .warnings
            .extend(super::carry_to_plan::miss_warning(&model));
    }
    Ok(model)
}

/// The largest torque delay accepted (s): far past any drive's or sensor's.
pub const MAX_TORQUE_DELAY: f64 = 0.05;

/// What the experiments' recordings gave, in the plan's order of experiments.
pub(super) struct ReadExperiments {
    pub(super) values: Vec<ExperimentValues>,
    pub(super) names: Vec<String>,
    pub(super) dropouts: Vec<LogDropout>,
    pub(super) held: Vec<LogGlitch>,
    pub(super) warnings: Vec<String>,
}

/// Each experiment's recording matched, checked against the plan, repaired and read at its
/// crossings.
pub(super) fn read_experiments(
    plan: &Plan,
    recordings: &[Recording],
    options: &IdentifyOptions,
) -> Result<ReadExperiments> {
    let n = plan.n();
    let mut out = ReadExperiments {
        values: vec![],
        names: vec![],
        dropouts: vec![],
        held: vec![],
        warnings: vec![],
    };
    for (e, r) in plan
        .experiments
        .iter()
        .zip(match_recordings(plan, recordings)?)
    {
        crate::interrupt::check("identification")?;
        if r.n != n {
            return Err(Error::recording(
                r.name.clone(),
                format!(
                    "{} joints; the plan (experiment '{}') has {n}",
                    r.n,
                    e.kind.name()
                ),
            ));
        }
        let read = super::repaired_recording::read_experiment(e, r, &plan.joint_names, options)?;
        out.warnings.extend(read.warnings);
        out.held.extend(read.held);
        out.dropouts.extend(read.dropouts);
        out.values.push(read.values);
        out.names.push(r.name.clone());
    }
    Ok(out)
}

/// The model's estimates before the estimator picks D*, H* and G*.
struct Estimates {
    d: Option<Estimate>,
    h: Option<Estimate>,
    g: Option<Estimate>,
    g_static: Option<Estimate>,
    combined: Option<Estimate>,
}

/// Torques that did not change in an experiment, found by [`Estimates::unclaim_flat_torques`].
struct FlatTorques {
    warnings: Vec<String>,
    unmeasured: Vec<Unmeasured>,
}

impl Estimates {
    /// A torque that did not change gives a row of zeros with standard errors of zero: no
    /// certainty is claimed for it (its standard errors NaN), and it is reported.
    fn unclaim_flat_torques(&mut self, plan: &Plan, values: &[ExperimentValues]) -> FlatTorques {
        let mut out = FlatTorques {
            warnings: vec![],
            unmeasured: vec![],
        };
        for v in values {
            let Some(estimate) = (match v.kind {
                ExperimentKind::D => self.d.as_mut(),
                ExperimentKind::H => self.h.as_mut(),
                ExperimentKind::GDynamic => self.g.as_mut(),
                ExperimentKind::GStatic => self.g_static.as_mut(),
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
                    if let Some(c) = self.combined.as_mut() {
                        c.stderr.row_mut(j).fill(f64::NAN);
                    }
                }
                flat.push((plan.joint_names[j].as_str(), value));
                out.unmeasured.push(Unmeasured {
                    experiment: v.kind.name().to_string(),
                    joint: plan.joint_names[j].clone(),
                    value,
                });
            }
            if !flat.is_empty() {
                out.warnings.push(flat_torque_warning(v.kind, &flat));
            }
        }
        out
    }

    /// D*, H* and G* by `estimator`: the separated estimates, or the combined one's blocks.
    #[allow(clippy::type_complexity)]
    fn chosen(
        &self,
        estimator: Estimator,
        n: usize,
    ) -> Result<(Option<Estimate>, Option<Estimate>, Option<Estimate>)> {
        match (estimator, &self.combined) {
            (Estimator::Separated, _) => Ok((self.d.clone(), self.h.clone(), self.g.clone())),
            (Estimator::Combined, Some(c)) => {
                let block = |b: usize| Some(c.columns(b * n, n));
                Ok((block(0), block(1), block(2)))
            }
            (Estimator::Combined, None) => Err(Error::invalid(
                "estimator",
                "the combined estimator needs the nominal, G, H and D experiments",
            )),
        }
    }
}

/// The local model's diagnostics: what the logs, the regressions and the estimates showed.
#[allow(clippy::too_many_arguments)]
fn model_diagnostics(
    plan: &Plan,
    options: &IdentifyOptions,
    read: ReadExperiments,
    point: &NominalPoint,
    fits: RegressionFindings,
    flat: FlatTorques,
    disagreement: Vec<BlockAgreement>,
    d: &Option<Estimate>,
) -> Diagnostics {
    let values = &read.values;
    let mut diagnostics = diagnose(values);
    diagnostics.dropouts = read.dropouts;
    diagnostics.held_readings = read.held;
    diagnostics.warnings.extend(read.warnings);
    for (v, name) in values.iter().zip(&read.names) {
        let (found, warnings) = glitches::report(v, name, &plan.joint_names);
        diagnostics.glitches.extend(found);
        diagnostics.warnings.extend(warnings);
    }
    let deviation = unperturbed_deviation(values, &point.state, &point.var);
    let evidence = super::estimator_evidence::held_out_evidence(values, point, plan.n());
    let advice = disagreement_warning(
        &disagreement,
        options.estimator,
        deviation,
        evidence.as_ref(),
    );
    diagnostics.estimator_evidence = evidence;
    if let Some(w) = advice {
        diagnostics.warnings.push(w);
    }
    if let Some(w) = d
        .as_ref()
        .and_then(|d| mass_matrix_warning(d, &plan.joint_names))
    {
        diagnostics.warnings.push(w);
    }
    diagnostics.warnings.extend(flat.warnings);
    diagnostics.unmeasured = flat.unmeasured;
    let in_plan_order = |experiment: &str| values.iter().position(|v| v.kind.name() == experiment);
    let mut torque_offsets = fits.offsets;
    torque_offsets.sort_by_key(|t| in_plan_order(&t.experiment));
    diagnostics.torque_offsets = torque_offsets;
    let mut noise = fits.noise;
    noise.sort_by_key(|e| in_plan_order(&e.experiment));
    diagnostics.warnings.extend(quantisation::warnings(&noise));
    diagnostics.warnings.extend(fits.warnings);
    (diagnostics.warnings).extend(super::followed_plan::warnings(plan, values, &point.state));
    let nominal_offsets = torque_offsets::nominal_warning(&diagnostics.torque_offsets);
    diagnostics.warnings.extend(nominal_offsets);
    diagnostics.noise = noise;
    diagnostics.combined = disagreement;
    diagnostics.unperturbed_deviation = deviation;
    diagnostics
}
