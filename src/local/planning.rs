//! Planning the experiments at an operating point ([`plan_experiments`]): each experiment's
//! perturbations, its trajectory of quintic transitions through the crossing windows (or
//! dwells) within the limits, and the warnings of what the plan will not resolve.

use nalgebra::DMatrix;

use super::perturbation::{perturbations, varying_perturbations};
use super::plan::{Crossing, Experiment, ExperimentKind, Plan, PlanOptions};
use super::plan_warnings;
use super::predicted_response;
use super::rounded_positions;
use super::trajectory_builder::TrajectoryBuilder;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::trajectory::{check_limits, SegmentKind, Trajectory, TransitionLimits};

/// Plans the experiments at `op` for `model`.
///
/// Every experiment is one trajectory sampled at `options.rate`: from rest at `q*`, quintic
/// transitions (C2) lead into each crossing window, where the trajectory is the crossing's
/// quadratic (eq. 11) for `+-window`, and finally back to rest at `q*`. The G-static experiment
/// instead holds `q*` (the reference) and then each `q* + dq_k` at rest for `dwell`. Crossing
/// times lie on the sampling grid. Transitions are as short as the limits (times `margin`)
/// allow. The sampled plan is checked against the model's position, velocity and acceleration
/// limits; a plan that breaks one is refused with the experiment, joint, time and limit.
pub fn plan_experiments(model: &Model, op: &OperatingPoint, options: &PlanOptions) -> Result<Plan> {
    op.check(model)?;
    let setup = Setup::new(model, op, options)?;
    let mut experiments = Vec::new();
    let mut warnings = Vec::new();
    for (index, &kind) in options.experiments.iter().enumerate() {
        if options.experiments[..index].contains(&kind) {
            return Err(Error::invalid(
                "experiments",
                format!("'{}' is listed twice", kind.name()),
            ));
        }
        experiments.push(plan_experiment(&setup, index, kind, &mut warnings)?);
    }
    Ok(Plan {
        format: Plan::tag(),
        robot: model.name.clone(),
        joint_names: model.joint_names.clone(),
        op: op.clone(),
        rate: options.rate,
        design: options.design,
        seed: options.seed,
        experiments,
        warnings,
    })
}

/// What every experiment of a plan shares: the checked options, the perturbation sizes, the
/// transitions' limits and the windows in samples.
struct Setup<'a> {
    model: &'a Model,
    op: &'a OperatingPoint,
    o: &'a PlanOptions,
    /// Perturbations per experiment.
    count: usize,
    /// Position, velocity and acceleration perturbation sizes per joint.
    sizes: [Vec<f64>; 3],
    lim: TransitionLimits,
    window_samples: usize,
    dwell_samples: usize,
}

impl<'a> Setup<'a> {
    /// The options checked against `model` and `op`, before any work.
    fn new(model: &'a Model, op: &'a OperatingPoint, o: &'a PlanOptions) -> Result<Setup<'a>> {
        let n = model.nv;
        use crate::limits::{check_count, check_range, MAX_PERTURBATIONS, MAX_RATE};
        check_range("rate", o.rate, f64::MIN_POSITIVE, MAX_RATE)?;
        check_range("window", o.window, 0.0, 60.0)?;
        check_range("dwell", o.dwell, 0.0, 3600.0)?;
        check_range("min_transition", o.min_transition, 0.0, 3600.0)?;
        if let Some(k) = o.count {
            check_count("n (perturbations per experiment)", k, 2, MAX_PERTURBATIONS)?;
        }
        let per_joint = |name: &str, values: &Option<Vec<f64>>, largest: f64| -> Result<()> {
            let Some(values) = values else { return Ok(()) };
            if values.len() != n {
                return Err(Error::shape(
                    name,
                    format!("{n} values (one per joint)"),
                    format!("{} values", values.len()),
                ));
            }
            for (j, v) in values.iter().enumerate() {
                check_range(&format!("{name}[{j}]"), *v, 0.0, largest)?;
            }
            Ok(())
        };
        per_joint("encoder_step", &o.encoder_step, 1.0)?;
        per_joint(
            "torque_noise",
            &o.torque_noise,
            crate::limits::MAX_TORQUE_NOISE,
        )?;
        per_joint(
            "torque_pass_noise",
            &o.torque_pass_noise,
            crate::limits::MAX_TORQUE_NOISE,
        )?;
        predicted_response::check_pass_noise(model, &o.torque_noise, &o.torque_pass_noise)?;
        if o.experiments.is_empty() {
            return Err(Error::invalid(
                "experiments",
                "none asked for; expected some of nominal, G_static, G, H, D",
            ));
        }
        let window_samples = (o.window * o.rate).round() as usize;
        if window_samples < 2 {
            return Err(Error::invalid(
                "window",
                format!(
                    "{} s holds fewer than 2 samples each side at {} Hz",
                    o.window, o.rate
                ),
            ));
        }
        let dwell_samples = (o.dwell * o.rate).round() as usize;
        if dwell_samples < 4 {
            return Err(Error::invalid(
                "dwell",
                format!("{} s is too short at {} Hz", o.dwell, o.rate),
            ));
        }
        if !(o.margin > 0.0 && o.margin <= 1.0) {
            return Err(Error::invalid(
                "margin",
                format!("{}; expected a fraction in (0, 1]", o.margin),
            ));
        }
        Ok(Setup {
            model,
            op,
            o,
            count: o.count.unwrap_or(2 * n),
            sizes: perturbation_sizes(model, op, o)?,
            lim: transition_limits(model, o),
            window_samples,
            dwell_samples,
        })
    }
}

/// The perturbation sizes asked for, the velocity ones kept below |qd*| when the sign is kept.
fn perturbation_sizes(
    model: &Model,
    op: &OperatingPoint,
    o: &PlanOptions,
) -> Result<[Vec<f64>; 3]> {
    let mut sizes = o.sizes.resolve_for(model)?;
    if o.keep_velocity_sign {
        for (j, size) in sizes[1].iter_mut().enumerate() {
            let limit = 0.9 * op.qd[j].abs();
            if limit < crate::limits::MIN_PERTURBATION {
                return Err(Error::invalid(
                    "keep_velocity_sign",
                    format!(
                        "joint '{}' has qd* = {}: every velocity perturbation of a size a sensor reads reverses it; identify H with the friction-aware regression (friction_aware_h) instead",
                        model.joint_names[j],
                        crate::error::shown(op.qd[j])
                    ),
                ));
            }
            *size = size.min(limit);
        }
    }
    Ok(sizes)
}

/// The transitions' limits: the model's, times the margin (defaults where the model has none).
fn transition_limits(model: &Model, o: &PlanOptions) -> TransitionLimits {
    TransitionLimits {
        lower: model.lower(),
        upper: model.upper(),
        velocity: model
            .limits
            .iter()
            .map(|l| {
                o.margin
                    * if l.velocity.is_finite() {
                        l.velocity
                    } else {
                        o.default_velocity
                    }
            })
            .collect(),
        acceleration: model
            .limits
            .iter()
            .map(|l| {
                o.margin
                    * if l.acceleration.is_finite() {
                        l.acceleration
                    } else {
                        o.default_acceleration
                    }
            })
            .collect(),
    }
}

/// Experiment `index` of the plan, of `kind`: its perturbations, its trajectory through the
/// crossings (or dwells), checked against the limits, and its warnings added to `warnings`.
fn plan_experiment(
    setup: &Setup<'_>,
    index: usize,
    kind: ExperimentKind,
    warnings: &mut Vec<String>,
) -> Result<Experiment> {
    let (model, op, o, n) = (setup.model, setup.op, setup.o, setup.model.nv);
    let count = setup.count;
    let sizes = &setup.sizes;
    let seed = o.seed.wrapping_add(1000 * index as u64 + 1);
    let count = if kind == ExperimentKind::H && o.friction_aware_h {
        if !o.symmetric {
            return Err(Error::invalid(
                "friction_aware_h",
                "the friction-aware H regression needs the perturbations in +- pairs (symmetric)",
            ));
        }
        // N + 1 unknowns per torque row, and one pair more for its standard errors
        count.max(2 * (n + 2))
    } else {
        count
    };
    let deltas = match kind.perturbed() {
        None => DMatrix::zeros(count, n),
        Some(v) if kind == ExperimentKind::H && o.friction_aware_h => {
            varying_perturbations(o.design, count, &sizes[v], o.symmetric, seed)?
        }
        Some(v) => perturbations(o.design, count, &sizes[v], o.symmetric, seed)?,
    };
    if kind == ExperimentKind::H {
        warnings.extend(plan_warnings::velocity_reversal(model, op, &deltas, o));
    }
    if kind.perturbed().is_some() {
        warnings.extend(plan_warnings::design(kind, &deltas));
    }
    let (trajectory, crossings, reference, window) = lay_out(setup, kind, &deltas);
    let context = format!("experiment '{}' of the plan", kind.name());
    crate::limits::sample_count(
        &context,
        trajectory.end() - trajectory.start(),
        o.rate,
        1 + 4 * n,
    )?;
    let sampled = trajectory.sample(o.rate);
    check_limits(model, &sampled, &context, LIMITS_ADVICE)?;
    plan_warnings::effort(model, op, kind, &sampled, warnings)?;
    let experiment = Experiment {
        kind,
        deltas,
        crossings,
        reference,
        window,
        trajectory,
        commanded: None,
    };
    if let (Some(steps), Some(var)) = (&o.encoder_step, kind.perturbed()) {
        let joints =
            rounded_positions::planned_resolution(&experiment, &model.joint_names, steps, o.rate)?;
        warnings.extend(rounded_positions::planned_resolution_warning(
            kind.name(),
            var,
            &joints,
            experiment.window,
        ));
    }
    if let Some(noise) = &o.torque_noise {
        // the nominal crossings: T* is their mean, their scatter the noise between passes
        let nominal = o.experiments.contains(&ExperimentKind::Nominal);
        let readings = if nominal { setup.count } else { 0 };
        let passes = o.torque_pass_noise.as_deref().unwrap_or_default();
        let prediction =
            predicted_response::predict(model, op, &experiment, noise, passes, o.rate, readings)?;
        warnings
            .extend(prediction.and_then(|p| predicted_response::warning(kind, &p, noise, passes)));
    }
    Ok(experiment)
}

/// The trajectory of one experiment: quintic transitions into each crossing window (or dwell
/// for G-static) and back to rest at q*; with its crossings, reference dwell and fit window.
fn lay_out(
    setup: &Setup<'_>,
    kind: ExperimentKind,
    deltas: &DMatrix<f64>,
) -> (Trajectory, Vec<Crossing>, Option<Crossing>, f64) {
    let (op, o, n) = (setup.op, setup.o, setup.model.nv);
    let (window_samples, dwell_samples) = (setup.window_samples, setup.dwell_samples);
    let count = deltas.nrows();
    let mut b = TrajectoryBuilder::new(n, o.rate, &setup.lim, o.min_transition, &op.q);
    let rest_at = |q: &[f64]| Crossing {
        time: 0.0,
        q: q.to_vec(),
        qd: vec![0.0; n],
        qdd: vec![0.0; n],
    };
    let (crossings, reference, window) = if kind == ExperimentKind::GStatic {
        let reference = b.dwell(SegmentKind::Reference, rest_at(&op.q), dwell_samples);
        let crossings = (0..count)
            .map(|k| {
                let q: Vec<f64> = (0..n).map(|j| op.q[j] + deltas[(k, j)]).collect();
                b.dwell(SegmentKind::Dwell { index: k }, rest_at(&q), dwell_samples)
            })
            .collect();
        // Fit windows: the middle 80 % of each dwell.
        (
            crossings,
            Some(reference),
            0.4 * dwell_samples as f64 / o.rate,
        )
    } else {
        let crossings = (0..count)
            .map(|k| {
                let mut c = Crossing {
                    time: 0.0,
                    q: op.q.clone(),
                    qd: op.qd.clone(),
                    qdd: op.qdd.clone(),
                };
                let target = match kind.perturbed() {
                    Some(0) => &mut c.q,
                    Some(1) => &mut c.qd,
                    Some(_) => &mut c.qdd,
                    None => &mut c.q,
                };
                for j in 0..n {
                    target[j] += deltas[(k, j)];
                }
                b.crossing(k, c, window_samples)
            })
            .collect();
        (crossings, None, window_samples as f64 / o.rate)
    };
    (b.finish(&op.q), crossings, reference, window)
}

/// What a plan that breaks a limit is told to do.
const LIMITS_ADVICE: &str =
    "; reduce the perturbation sizes or move the operating point away from the limit";
