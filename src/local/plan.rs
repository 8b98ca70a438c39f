//! The experiment plan (the paper's Table 1): for an operating point, the nominal, G-static,
//! G-dynamic, H and D experiments, each a continuous trajectory that starts and ends at rest and
//! passes the perturbed operating point K times.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::perturbation::{perturbations, varying_perturbations, Design, Sizes};
use super::plan_checks;
use super::plan_warnings;
use super::predicted_response;
use super::rounded_positions;
use super::trajectory_builder::TrajectoryBuilder;
use crate::choice::choice;
use crate::document::{invalid, Document};
use crate::error::{shown, Error, Result};
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::trajectory::{check_limits, SegmentKind, Trajectory, TransitionLimits};

choice! {
    /// The kind of an experiment (docs/method.md, section 3); named `nominal`, `G_static`, `G`,
    /// `H`, `D` in files and messages.
    #[derive(PartialOrd, Ord, Serialize, Deserialize)]
    pub enum ExperimentKind ("experiments") {
        /// Step 1: K crossings of P itself; `T*` is the mean torque.
        #[serde(rename = "nominal")]
        Nominal = "nominal",
        /// Step 2: at rest at `q* + dq_k`; `tau_k - tau_rest(q*) = Gs dq_k`.
        #[serde(rename = "G_static")]
        GStatic = "G_static",
        /// Extension: crossings of `(q* + dq_k, qd*, qdd*)`; `tau_k - T* = G* dq_k`.
        #[serde(rename = "G")]
        GDynamic = "G",
        /// Step 3: crossings of `(q*, qd* + dqd_k, qdd*)`; `tau_k - T* = H* dqd_k`.
        #[serde(rename = "H")]
        H = "H",
        /// Step 4: crossings of `(q*, qd*, qdd* + dqdd_k)`; `tau_k - T* = D* dqdd_k`.
        #[serde(rename = "D")]
        D = "D",
    }
}

impl ExperimentKind {
    /// Which state variable the experiment perturbs: 0 = position, 1 = velocity,
    /// 2 = acceleration, `None` for the nominal experiment.
    pub fn perturbed(self) -> Option<usize> {
        match self {
            ExperimentKind::Nominal => None,
            ExperimentKind::GStatic | ExperimentKind::GDynamic => Some(0),
            ExperimentKind::H => Some(1),
            ExperimentKind::D => Some(2),
        }
    }

    /// The perturbation's name in messages: `dq`, `dqd` or `dqdd` (`dq` for the nominal, which
    /// perturbs nothing).
    pub fn perturbation_name(self) -> &'static str {
        match self.perturbed() {
            Some(2) => "dqdd",
            Some(1) => "dqd",
            _ => "dq",
        }
    }

    /// The matrix the experiment estimates: `Gs`, `G*`, `H*` or `D*` (`T*` for the nominal).
    pub fn estimate_name(self) -> &'static str {
        match self {
            ExperimentKind::Nominal => "T*",
            ExperimentKind::GStatic => "Gs",
            ExperimentKind::GDynamic => "G*",
            ExperimentKind::H => "H*",
            ExperimentKind::D => "D*",
        }
    }
}

/// A planned crossing: the time (s from the start of the experiment) and the state the robot
/// passes then.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Crossing {
    pub time: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

/// One experiment: its perturbations, its crossings and its trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    pub kind: ExperimentKind,
    /// `K x N` planned perturbations of the perturbed variable (zeros for the nominal one).
    #[serde(with = "crate::json::rows")]
    pub deltas: DMatrix<f64>,
    /// The K crossings in time order.
    pub crossings: Vec<Crossing>,
    /// G-static only: the rest posture at `q*` the static torques are measured against.
    pub reference: Option<Crossing>,
    /// Half-width (s) of the window around each crossing time in which the planned trajectory is
    /// exactly the crossing's quadratic (or the rest posture).
    pub window: f64,
    pub trajectory: Trajectory,
}

impl Experiment {
    /// Duration (s).
    pub fn duration(&self) -> f64 {
        self.trajectory.end() - self.trajectory.start()
    }

    /// True when the perturbations come in +- pairs (rows `2i` and `2i + 1` opposite), as the
    /// planner's symmetric designs: then the even-order terms and a constant offset of the
    /// torque changes leave the separated estimates unbiased.
    pub fn in_pairs(&self) -> bool {
        let d = &self.deltas;
        d.nrows().is_multiple_of(2)
            && (0..d.nrows() / 2)
                .all(|i| (0..d.ncols()).all(|j| d[(2 * i, j)] == -d[(2 * i + 1, j)]))
    }

    /// The condition number of the perturbations `deltas` with every joint's column scaled to
    /// unit norm (what the experiment's regression reports as cond(X)): 1 for an orthogonal
    /// design. None for the nominal experiment (no perturbation) or a design that leaves a joint
    /// unperturbed.
    pub fn design_cond(&self) -> Option<f64> {
        let s = crate::regression::scaled_singular_values(&self.deltas)?;
        Some(s[0] / s[s.len() - 1])
    }
}

/// The condition number of a planned experiment's perturbations above which the planner warns
/// (a random 6 x 6 design exceeds it about one time in four; an orthogonal design has 1).
pub const DESIGN_COND_WARNING: f64 = 30.0;

/// Options of [`plan_experiments`]; [`PlanOptions::default`] documents the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Experiments to plan (default: all five, in the order of [`ExperimentKind::ALL`]).
    pub experiments: Vec<ExperimentKind>,
    /// Perturbation design (default [`Design::Random`], as in the paper).
    pub design: Design,
    /// Perturbations per experiment, K (default `2 N`).
    pub count: Option<usize>,
    /// Symmetric `+-` pairs (default true): cancels the even-order terms of H and G.
    pub symmetric: bool,
    pub seed: u64,
    /// Sampling rate of the trajectories (Hz, default 1000).
    pub rate: f64,
    pub sizes: Sizes,
    /// Half-width of each crossing window (s, default 0.05): the trajectory is the crossing's
    /// quadratic on `[t_c - window, t_c + window]`.
    pub window: f64,
    /// How long each static posture is held (s, default 1.0).
    pub dwell: f64,
    /// Fraction of the speed and acceleration limits transitions may use (default 0.8).
    pub margin: f64,
    /// Speed and acceleration bounds for transitions of joints whose URDF gives none
    /// (default 1 rad/s and 4 rad/s^2).
    pub default_velocity: f64,
    pub default_acceleration: f64,
    /// Shortest transition (s, default 0.2); the longest tried is 30 s.
    pub min_transition: f64,
    /// Keep every velocity perturbation of the H experiment below `0.9 |qd*|` of its joint, so
    /// that no joint's velocity changes sign between passes and friction cancels from H*
    /// (default false: a joint whose perturbations exceed `|qd*|` gets a warning instead). A
    /// joint with `qd* = 0` cannot be perturbed so: refused, use `friction_aware_h`.
    pub keep_velocity_sign: bool,
    /// Plan enough H passes for the friction-aware H regression
    /// ([`crate::local::IdentifyOptions::friction_aware_h`]): at least `2 (N + 2)`, in +- pairs
    /// (`N + 1` pairs determine it, one more gives its standard errors).
    pub friction_aware_h: bool,
    /// The steps (rad, or m for a prismatic joint; one per joint, 0 for a joint whose step is
    /// not known) of the encoders the robot logs its positions in, when known (default none).
    /// Each experiment's crossings are then read as the identification will read them (the
    /// planned positions over each window rounded to the steps and read by their band, see
    /// [`super::rounded_positions::planned_resolution`]), and the joints whose perturbations
    /// they would resolve to worse than a tenth of their size get a warning with the window or
    /// perturbation size that would resolve them.
    pub encoder_step: Option<Vec<f64>>,
    /// The standard deviation of the robot's torque samples (N m, or N for a prismatic joint;
    /// one per joint, 0 for a joint whose noise is not known), when known (default none). Each
    /// perturbed experiment's torque changes are then predicted from the model and the
    /// identification's response test run on draws of that noise
    /// ([`super::predicted_response`]); an experiment it would find in fewer than 90 % of runs
    /// gets a warning with the perturbation size that would resolve it.
    pub torque_noise: Option<Vec<f64>>,
    /// What the robot's torque readings vary by from pass to pass beyond the samples' noise
    /// (N m, or N for a prismatic joint, a standard deviation of one crossing's reading; one
    /// per joint, 0 for none), when known (default none): noise slower than a window, a
    /// drifting sensor, the robot's repeatability, as an identification reports it
    /// ([`super::TorqueNoise::passes`]). The prediction of [`Self::torque_noise`] then adds it
    /// to every reading; it needs `torque_noise` for each joint it is given for.
    pub torque_pass_noise: Option<Vec<f64>>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            experiments: ExperimentKind::ALL.to_vec(),
            design: Design::Random,
            count: None,
            symmetric: true,
            seed: 0,
            rate: 1000.0,
            sizes: Sizes::default(),
            window: 0.05,
            dwell: 1.0,
            margin: 0.8,
            default_velocity: 1.0,
            default_acceleration: 4.0,
            min_transition: 0.2,
            keep_velocity_sign: false,
            friction_aware_h: false,
            encoder_step: None,
            torque_noise: None,
            torque_pass_noise: None,
        }
    }
}

/// A plan: the operating point and its experiments, for one robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// `perturbid-plan/1`.
    pub format: String,
    /// Robot name and joint names (the plan is only valid for this robot).
    pub robot: String,
    pub joint_names: Vec<String>,
    pub op: OperatingPoint,
    /// Sampling rate (Hz) of the trajectories.
    pub rate: f64,
    pub design: Design,
    pub seed: u64,
    pub experiments: Vec<Experiment>,
    /// What the planner found the user should know (each also given as a Python warning and
    /// printed by the command line), e.g. velocity perturbations that reverse a joint.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

impl Plan {
    /// Number of joints.
    pub fn n(&self) -> usize {
        self.op.n()
    }

    /// The experiments' names in order, comma separated (for messages).
    pub fn kinds(&self) -> String {
        self.experiments
            .iter()
            .map(|e| e.kind.name())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The experiment of `kind`, if planned.
    pub fn experiment(&self, kind: ExperimentKind) -> Option<&Experiment> {
        self.experiments.iter().find(|e| e.kind == kind)
    }
}

impl Document for Plan {
    const FORMAT: &'static str = "perturbid-plan";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "plan";

    /// Checks that every experiment is for the plan's joints and the rate is positive; that each
    /// trajectory is finite, smooth and passes its crossings; that the crossings are the
    /// operating point moved by the perturbations (`plan_checks`); and that no
    /// experiment is planned twice.
    fn validate(&self) -> Result<()> {
        let plan = self;
        let n = plan.n();
        let bad = |m: String| invalid(Self::WHAT, m);
        if plan.joint_names.len() != n || plan.op.qd.len() != n || plan.op.qdd.len() != n {
            return Err(bad(format!(
                "the operating point and joint names disagree on the number of joints ({n})"
            )));
        }
        for e in &plan.experiments {
            if e.trajectory.n != n || e.deltas.ncols() != n || e.trajectory.segments.is_empty() {
                return Err(bad(format!(
                    "experiment '{}' is not for {n} joints",
                    e.kind.name()
                )));
            }
            if e.trajectory.segments.iter().any(|s| s.coeffs.len() != n) {
                return Err(bad(format!(
                    "experiment '{}' has a segment that is not for {n} joints",
                    e.kind.name()
                )));
            }
        }
        if !(plan.rate.is_finite() && plan.rate > 0.0 && plan.rate <= crate::limits::MAX_RATE) {
            return Err(bad(format!(
                "rate {} Hz; expected a positive number up to {:e}",
                plan.rate,
                crate::limits::MAX_RATE
            )));
        }
        if plan.experiments.is_empty() {
            return Err(bad("the plan has no experiment".into()));
        }
        crate::document::check_joint_names(Self::WHAT, &plan.joint_names)?;
        for (k, e) in plan.experiments.iter().enumerate() {
            let at = |what: &str| format!("experiments[{k}] ('{}'): {what}", e.kind.name());
            // segments in time order, end to end, finite: what sampling walks through
            let mut previous: Option<f64> = None;
            for (i, seg) in e.trajectory.segments.iter().enumerate() {
                let ordered = seg.t0.is_finite() && seg.t1.is_finite() && seg.t0 <= seg.t1;
                let joined = previous.is_none_or(|t| (seg.t0 - t).abs() <= 1e-9 * t.abs().max(1.0));
                if !ordered || !joined {
                    return Err(bad(at(&format!(
                        "trajectory.segments[{i}] runs from {} to {} s; segments must be finite, in time order and end to end",
                        seg.t0, seg.t1
                    ))));
                }
                if seg.coeffs.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(bad(at(&format!(
                        "trajectory.segments[{i}] has a coefficient that is not finite"
                    ))));
                }
                previous = Some(seg.t1);
            }
            // t, q, qd, qdd and the torques a recording of it adds
            crate::limits::sample_count(&at("trajectory"), e.duration(), plan.rate, 1 + 4 * n)?;
            e.trajectory
                .check_smooth()
                .map_err(|m| bad(at(&format!("trajectory: {m}"))))?;
            if e.deltas.nrows() != e.crossings.len() && e.kind != ExperimentKind::Nominal {
                return Err(bad(at(&format!(
                    "{} perturbations for {} crossings",
                    e.deltas.nrows(),
                    e.crossings.len()
                ))));
            }
            let (start, end) = (e.trajectory.start(), e.trajectory.end());
            if let Some(k) =
                (1..e.crossings.len()).find(|&k| e.crossings[k].time < e.crossings[k - 1].time)
            {
                return Err(bad(at(&format!(
                    "crossings[{k}] at t = {} s comes before crossings[{}] at {} s; crossings are in time order",
                    shown(e.crossings[k].time),
                    k - 1,
                    shown(e.crossings[k - 1].time)
                ))));
            }
            // every crossing (and the reference posture) is a state the trajectory passes
            let named = e
                .crossings
                .iter()
                .enumerate()
                .map(|(k, c)| (format!("crossings[{k}]"), c))
                .chain(e.reference.iter().map(|c| ("reference".to_string(), c)));
            for (name, c) in named {
                if [&c.q, &c.qd, &c.qdd].iter().any(|v| v.len() != n) {
                    return Err(bad(at(&format!("{name} is not for {n} joints"))));
                }
                if !(c.time >= start && c.time <= end) {
                    return Err(bad(at(&format!(
                        "{name} at t = {} s is outside the trajectory ({} to {} s)",
                        shown(c.time),
                        shown(start),
                        shown(end)
                    ))));
                }
                let (q, qd, qdd) = e.trajectory.segment_at(c.time).state(c.time);
                for (what, planned, passed) in
                    [("q", &c.q, &q), ("qd", &c.qd, &qd), ("qdd", &c.qdd, &qdd)]
                {
                    if let Some(j) = (0..n).find(|&j| {
                        let off = (planned[j] - passed[j]).abs();
                        off.is_nan() || off > 1e-6 * (1.0 + planned[j].abs())
                    }) {
                        return Err(bad(at(&format!(
                            "{name}.{what}[{j}] is {}, but the trajectory passes {} at t = {} s: the crossing and the trajectory disagree",
                            shown(planned[j]),
                            shown(passed[j]),
                            shown(c.time)
                        ))));
                    }
                }
            }
            if !(e.window.is_finite() && e.window > 0.0) {
                return Err(bad(at(&format!("window {} s is not positive", e.window))));
            }
            plan_checks::check_planned_states(plan, e).map_err(|m| bad(at(&m)))?;
            plan_checks::check_windows(e).map_err(|m| bad(at(&m)))?;
            if let Some(first) = plan.experiments[..k].iter().position(|o| o.kind == e.kind) {
                return Err(bad(format!(
                    "experiments[{first}] and experiments[{k}] are both '{}'; a plan holds each experiment once",
                    e.kind.name()
                )));
            }
        }
        Ok(())
    }
}

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
        let readings = if nominal { o.count.unwrap_or(2 * n) } else { 0 };
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
