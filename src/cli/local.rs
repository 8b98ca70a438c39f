//! `perturbid plan`, `simulate` and `identify`: the paper's method on files.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use serde::Deserialize;

use super::files::{load_json, RobotArg};
use super::out_dir;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::local::plan_files::{plan_files, recording_files};
use crate::local::{
    identify_local, identify_local_rounds, identify_local_rounds_with_delay, plan_experiments,
    refine_plan, CrossingTimes, Design, Estimator, ExperimentKind, IdentifyOptions, LocalModel,
    OperatingPoint, Plan, PlanOptions, Size,
};
use crate::logs::recording::Recording;
use crate::logs::save_recording;
use crate::rehearsal::{rehearse, rehearse_plan, TrueRobot};
use crate::simulation::{simulate_plan, simulate_samples, Friction, SimulationOptions};
use crate::trajectory::FourierTrajectory;

#[derive(Args)]
pub(crate) struct PlanArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// The operating point: a JSON file, or the JSON itself, {"q": [...], "qd": [...], "qdd":
    /// [...]} (rad, rad/s, rad/s^2).
    #[arg(long, required_unless_present = "refine", conflicts_with = "refine")]
    op: Option<PathBuf>,
    /// Refine a plan instead of planning anew: the folder of <experiment>.csv the robot
    /// recorded running --plan. The output is the next round's plan, each experiment
    /// commanded off its crossings by what the robot missed them by (an iterative learning
    /// update; docs/method.md, "Closed-loop identification"); the plan's crossings,
    /// perturbations and options stay.
    #[arg(long, value_name = "RECORDINGS_DIR", requires = "plan")]
    refine: Option<PathBuf>,
    /// The plan the recordings of --refine ran (plan.json).
    #[arg(long, value_name = "PLAN.json", requires = "refine")]
    plan: Option<PathBuf>,
    #[command(flatten)]
    columns: super::files::ColumnArgs,
    /// Output folder: plan.json and <experiment>.csv (t, q1..qN, qd1..qN, qdd1..qN).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Perturbation design: random (the paper's draws) or orthogonal (cond(X) = 1).
    #[arg(long, value_enum, default_value_t = Design::Random)]
    design: Design,
    /// Perturbations per experiment (default 2N, in +- pairs).
    #[arg(long)]
    n: Option<usize>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Sampling rate of the trajectories (Hz).
    #[arg(long, default_value_t = 1000.0)]
    rate: f64,
    /// Experiments, comma separated, from nominal, G_static, G, H, D.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "nominal,G_static,G,H,D"
    )]
    experiments: Vec<ExperimentKind>,
    /// Position perturbation: fraction of the joint range (default 0.01) ...
    #[arg(long, default_value_t = 0.01)]
    dq_fraction: f64,
    /// ... velocity perturbation: fraction of the speed limit ...
    #[arg(long, default_value_t = 0.05)]
    dqd_fraction: f64,
    /// ... acceleration perturbation: fraction of the acceleration limit.
    #[arg(long, default_value_t = 0.05)]
    dqdd_fraction: f64,
    /// Absolute position perturbation for every joint (rad), instead of the fraction.
    #[arg(long)]
    dq: Option<f64>,
    /// Absolute velocity perturbation (rad/s).
    #[arg(long)]
    dqd: Option<f64>,
    /// Absolute acceleration perturbation (rad/s^2).
    #[arg(long)]
    dqdd: Option<f64>,
    /// Half-width of each crossing window (s).
    #[arg(long, default_value_t = 0.05)]
    window: f64,
    /// How long each static posture is held (s).
    #[arg(long, default_value_t = 1.0)]
    dwell: f64,
    /// Keep the velocity perturbations below 0.9 |qd*| of each joint, so that no joint
    /// reverses between H passes and friction cancels from H*.
    #[arg(long)]
    keep_velocity_sign: bool,
    /// Plan enough H passes (2 (N + 2), in +- pairs) for `identify --friction-aware-h`.
    #[arg(long)]
    friction_aware_h: bool,
    /// The step of the robot's encoders for every joint (rad or m a count; 4,096 counts a
    /// revolution: 0.001534), when known: the planner warns of perturbations they would not
    /// resolve, with the window that would.
    #[arg(long)]
    encoder_step: Option<f64>,
    /// The standard deviation of the robot's torque samples for every joint (N m), when known:
    /// the planner predicts from the model whether the identification will find each
    /// experiment's torques responding beyond that noise, and warns of those it would not, with
    /// the perturbation size that would resolve them.
    #[arg(long)]
    torque_noise: Option<f64>,
    /// What the torque readings vary by from pass to pass beyond the samples' noise, for every
    /// joint (N m a reading, a standard deviation: noise slower than a window, repeatability;
    /// `perturbid identify` reports it as `passes`), with --torque-noise: added to every
    /// reading in the prediction.
    #[arg(long, requires = "torque_noise")]
    torque_pass_noise: Option<f64>,
    /// A local model this robot's earlier identification saved: its nominal passes' noise, per
    /// joint (the samples' and what varied from pass to pass beyond it), is taken as
    /// --torque-noise and --torque-pass-noise. Repeat it to pool several identifications
    /// (root mean square per joint): one has only K - 1 degrees of freedom a joint.
    #[arg(long, value_name = "MODEL", conflicts_with_all = ["torque_noise", "torque_pass_noise"])]
    noise_from: Vec<PathBuf>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OpFile {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
}

/// The operating point of `--op`: a JSON file, or (where no such file exists) the JSON itself
/// when it starts with `{`, as `--help` shows it.
fn load_op(arg: &Path) -> Result<OperatingPoint> {
    let parse = |text: &str| {
        let op: OpFile = serde_json::from_str(text).map_err(|e| Error::Json {
            context: "operating point".into(),
            message: format!(
                "{}; expected {{\"q\": [...], \"qd\": [...], \"qdd\": [...]}}",
                crate::json::describe_error(&e, text)
            ),
        })?;
        OperatingPoint::new(op.q, op.qd, op.qdd)
    };
    match arg.to_str() {
        Some(text) if super::files::is_inline_json(arg) => parse(text).map_err(|e| match e {
            Error::Json { message, .. } => Error::Json {
                context: "--op (the operating point given as JSON)".into(),
                message,
            },
            other => other,
        }),
        _ => load_json(arg, parse),
    }
}

/// The nominal passes' noise the saved local models of `model` at `paths` report, pooled, as
/// the planner's `torque_noise` and `torque_pass_noise` ([`LocalModel::pooled_nominal_noise`]);
/// refused, naming the file, for a model of other joints or without it, or a joint noise-free
/// in one file and noisy in another.
fn noise_from(paths: &[PathBuf], model: &crate::model::Model) -> Result<(Vec<f64>, Vec<f64>)> {
    let mut models = Vec::with_capacity(paths.len());
    for path in paths {
        let local = LocalModel::load(path)?;
        let refuse = |message: String| Error::Json {
            context: format!("{} (--noise-from)", path.display()),
            message,
        };
        if local.joint_names != model.joint_names {
            return Err(refuse(format!(
                "a local model of joints [{}] of '{}'; the robot '{}' has [{}]",
                local.joint_names.join(", "),
                local.robot,
                model.name,
                model.joint_names.join(", ")
            )));
        }
        local.nominal_noise().map_err(|e| refuse(e.to_string()))?;
        models.push(local);
    }
    LocalModel::pool_nominal_noise(&models.iter().collect::<Vec<_>>(), |i| {
        format!("{} (--noise-from)", paths[i].display())
    })
}

fn size(abs: Option<f64>, fraction: f64, n: usize) -> Size {
    match abs {
        Some(v) => Size::Absolute(vec![v; n]),
        None => Size::Fraction(fraction),
    }
}

pub(crate) fn plan(a: PlanArgs) -> Result<String> {
    let op_arg = match (&a.op, &a.refine) {
        (_, Some(dir)) => return refine(&a, dir),
        (Some(op), None) => op,
        (None, None) => {
            return Err(Error::invalid(
                "--op",
                "expected the operating point (or --refine with the recordings of a plan)",
            ))
        }
    };
    let model = a.robot.load()?;
    let op = load_op(op_arg)?;
    let n = model.nv;
    let mut o = PlanOptions {
        design: a.design,
        count: a.n,
        seed: a.seed,
        rate: a.rate,
        window: a.window,
        dwell: a.dwell,
        experiments: a.experiments,
        keep_velocity_sign: a.keep_velocity_sign,
        friction_aware_h: a.friction_aware_h,
        encoder_step: a.encoder_step.map(|s| vec![s; n]),
        torque_noise: a.torque_noise.map(|s| vec![s; n]),
        torque_pass_noise: a.torque_pass_noise.map(|s| vec![s; n]),
        ..PlanOptions::default()
    };
    o.sizes.position = size(a.dq, a.dq_fraction, n);
    o.sizes.velocity = size(a.dqd, a.dqd_fraction, n);
    o.sizes.acceleration = size(a.dqdd, a.dqdd_fraction, n);
    if !a.noise_from.is_empty() {
        let (samples, passes) = noise_from(&a.noise_from, &model)?;
        if samples.iter().all(|s| *s == 0.0) {
            let files: Vec<String> = a
                .noise_from
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            let (verb, whose) = if files.len() == 1 {
                ("reports", "its")
            } else {
                ("report", "their")
            };
            eprintln!(
                "perturbid: warning: {} {verb} no torque noise in {whose} nominal passes (data without noise?): nothing is predicted",
                files.join(", ")
            );
        }
        (o.torque_noise, o.torque_pass_noise) = (Some(samples), Some(passes));
    }
    let plan = plan_experiments(&model, &op, &o)?;
    for w in &plan.warnings {
        eprintln!("perturbid: warning: {w}");
    }
    let set = plan_files(&plan, &out_dir(&a.out))?;
    let mut out = String::new();
    for e in &plan.experiments {
        let name = format!("{}.csv", e.kind.name());
        let cond = e
            .design_cond()
            .map_or(String::new(), |c| format!(", cond(X) {c:>6.2}"));
        let _ = writeln!(
            out,
            "{:<9} {:>3} crossings, {:>7.2} s{cond:<17}  -> {}",
            e.kind.name(),
            e.crossings.len(),
            e.duration(),
            set.path_of(&name).display()
        );
    }
    let _ = writeln!(out, "plan -> {}", set.path_of("plan.json").display());
    set.commit()?;
    Ok(out)
}

/// `plan --refine`: the next round's plan from the recordings of the round `--plan` planned.
fn refine(a: &PlanArgs, dir: &Path) -> Result<String> {
    let plan_path = a.plan.as_deref().ok_or_else(|| {
        Error::invalid(
            "--refine",
            "needs the plan the recordings ran: --plan PLAN.json",
        )
    })?;
    let plan = Plan::load(plan_path)?;
    let model = a.robot.load()?;
    crate::simulation::check_plan_robot(&model, &plan)?;
    let files: Vec<PathBuf> = (plan.experiments.iter())
        .map(|e| dir.join(format!("{}.csv", e.kind.name())))
        .collect();
    let out = out_dir(&a.out);
    let inputs: Vec<&Path> = (files.iter().map(PathBuf::as_path))
        .chain([plan_path, a.robot.path()])
        .collect();
    let outputs = std::iter::once("plan.json".to_string()).chain(
        plan.experiments
            .iter()
            .map(|e| format!("{}.csv", e.kind.name())),
    );
    for name in outputs {
        super::files::refuse_overwriting_inputs(&out.join(name), &inputs)?;
    }
    let mut notes = String::new();
    let recs: Vec<Recording> = files
        .iter()
        .map(|f| a.columns.load(f, &plan.joint_names, &mut notes))
        .collect::<Result<_>>()?;
    let refined = refine_plan(&plan, &recs, &IdentifyOptions::default(), Some(&model))?;
    let set = plan_files(&refined, &out)?;
    let mut text = notes;
    for e in &refined.experiments {
        let name = format!("{}.csv", e.kind.name());
        let Some(c) = &e.commanded else { continue };
        let largest = |f: &dyn Fn(&crate::local::plan::StateOffset) -> &Vec<f64>| {
            (c.crossings.iter().chain(&c.reference))
                .flat_map(|o| f(o).iter().map(|v| v.abs()))
                .fold(0.0, f64::max)
        };
        let _ = writeln!(
            text,
            "{:<9} refined {} time(s): commanded off its crossings by up to {:.2e} rad, {:.2e} rad/s, {:.2e} rad/s^2 -> {}",
            e.kind.name(),
            c.rounds,
            largest(&|o| &o.q),
            largest(&|o| &o.qd),
            largest(&|o| &o.qdd),
            set.path_of(&name).display()
        );
    }
    let _ = writeln!(text, "plan -> {}", set.path_of("plan.json").display());
    set.commit()?;
    Ok(text)
}

#[derive(Args)]
pub(crate) struct SimulateArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// What the robot runs: a plan (plan.json from `perturbid plan`) or a Fourier excitation
    /// (excitation.json from `perturbid excite`).
    input: PathBuf,
    /// A plan: the output folder, one <experiment>.csv per experiment (t, q1..qN,
    /// tau1..tauN). An excitation: the log file (default log.csv), which `perturbid
    /// identify-direct` reads.
    #[arg(long)]
    out: Option<PathBuf>,
    /// The true robot (JSON, docs/rehearsal.md): parameter errors, friction, ripple, sensors,
    /// closed-loop tracking. Replaces the options below.
    #[arg(long)]
    true_robot: Option<PathBuf>,
    /// An excitation: periods to run (default 1; a plan's experiments run once).
    #[arg(long)]
    periods: Option<f64>,
    /// An excitation: sampling rate of the log (Hz; default 1000; a plan's experiments are
    /// sampled at the plan's rate).
    #[arg(long)]
    rate: Option<f64>,
    /// Leave gravity out of the torques (as if compensated).
    #[arg(long)]
    no_gravity: bool,
    /// Leave the URDF's friction (<dynamics damping friction>) out.
    #[arg(long)]
    no_friction: bool,
    /// Gaussian torque noise (N m, standard deviation).
    #[arg(long, default_value_t = 0.0)]
    torque_noise: f64,
    /// Gaussian position noise (rad, standard deviation).
    #[arg(long, default_value_t = 0.0)]
    position_noise: f64,
    /// Encoder resolution (rad per count; 0 = none).
    #[arg(long, default_value_t = 0.0)]
    quantization: f64,
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

/// What `simulate` runs.
enum Reference {
    Plan(Box<Plan>),
    Excitation(FourierTrajectory),
}

fn load_reference(path: &Path) -> Result<Reference> {
    let text = crate::io::read_document(path)?;
    let context = path.display().to_string();
    crate::json::check_containers(&text, &context)?;
    if let Ok(tag) = crate::document::format_tag(&text, &context) {
        if tag.starts_with(Plan::FORMAT) {
            return Ok(Reference::Plan(Box::new(Plan::from_json_in(
                &text, &context,
            )?)));
        }
        return Err(Error::Json {
            context,
            message: format!(
                "a '{tag}' document; expected a plan (perturbid plan) or an excitation (perturbid excite)"
            ),
        });
    }
    let t = super::files::excitation_of(&text, context, "neither a plan nor an excitation")?;
    Ok(Reference::Excitation(t))
}

pub(crate) fn simulate(a: SimulateArgs) -> Result<String> {
    let model = a.robot.load()?;
    let reference = load_reference(&a.input)?;
    let n = model.nv;
    let true_robot = match &a.true_robot {
        None => None,
        Some(path) => {
            if a.no_gravity
                || a.no_friction
                || a.torque_noise != 0.0
                || a.position_noise != 0.0
                || a.quantization != 0.0
                || a.seed != 0
            {
                return Err(Error::invalid(
                    "--true-robot",
                    "gravity, friction, noise, quantisation and seed come from the true-robot document; leave --no-gravity, --no-friction, --torque-noise, --position-noise, --quantization and --seed out",
                ));
            }
            let t = TrueRobot::load(path)?;
            t.check(&model)?;
            Some(t)
        }
    };
    let mut o = SimulationOptions::new(&model);
    o.gravity = Gravity::from(!a.no_gravity);
    if a.no_friction {
        o.friction = Friction::none(n);
    }
    o.torque_noise = vec![a.torque_noise; n];
    o.position_noise = vec![a.position_noise; n];
    o.quantization = vec![a.quantization; n];
    o.seed = a.seed;
    let plan = match reference {
        Reference::Plan(plan) => {
            if let Some((option, value)) = [("--periods", a.periods), ("--rate", a.rate)]
                .into_iter()
                .find_map(|(o, v)| v.map(|v| (o, v)))
            {
                return Err(Error::invalid(
                    option,
                    format!(
                        "{} given for a plan ({}): it applies to an excitation; a plan's experiments run once each, sampled at the plan's rate ({} Hz; perturbid plan --rate)",
                        crate::error::shown(value),
                        a.input.display(),
                        plan.rate
                    ),
                ));
            }
            plan
        }
        Reference::Excitation(traj) => {
            if traj.n() != n {
                return Err(Error::invalid(
                    "excitation",
                    format!(
                        "{} is for {} joints; robot '{}' has {n}",
                        a.input.display(),
                        traj.n(),
                        model.name
                    ),
                ));
            }
            let samples = crate::simulation::excitation_samples(
                &model,
                &traj,
                a.periods.unwrap_or(1.0),
                a.rate.unwrap_or(1000.0),
            )?;
            let rec = match &true_robot {
                Some(t) => rehearse(&model, t, &samples, 0, "excitation")?,
                None => simulate_samples(&model, &samples, &o, 0, "excitation")?,
            };
            let path = a.out.clone().unwrap_or_else(|| PathBuf::from("log.csv"));
            super::files::refuse_overwriting_inputs(&path, &[a.input.as_path()])?;
            save_recording(&rec, &path)?;
            return Ok(format!(
                "excitation: {} samples, {:.2} s -> {}\n",
                rec.len(),
                rec.t[rec.len() - 1] - rec.t[0],
                path.display()
            ));
        }
    };
    let recs = match &true_robot {
        Some(t) => rehearse_plan(&model, t, &plan)?,
        None => simulate_plan(&model, &plan, &o)?,
    };
    let set = recording_files(&plan, &recs, &out_dir(&a.out))?;
    let mut out = String::new();
    for (e, r) in plan.experiments.iter().zip(&recs) {
        let name = format!("{}.csv", e.kind.name());
        let _ = writeln!(
            out,
            "{:<9} {:>7} samples -> {}",
            e.kind.name(),
            r.len(),
            set.path_of(&name).display()
        );
    }
    set.commit()?;
    Ok(out)
}

#[derive(Args)]
pub(crate) struct IdentifyArgs {
    /// The plan (plan.json).
    plan: PathBuf,
    /// The recordings: one CSV per experiment in the plan's order, or one folder holding
    /// <experiment>.csv for each (t, q1..qN, tau1..tauN; qd, qdd optional).
    #[arg(required = true)]
    recordings: Vec<PathBuf>,
    /// Where to write the local model (JSON).
    #[arg(long, default_value = "local_model.json")]
    out: PathBuf,
    /// Take the plan's crossing times as they are (the recordings' clocks start with the
    /// plan) instead of aligning each recording with the plan from its positions (the default).
    #[arg(long)]
    planned_times: bool,
    /// Largest clock offset between a recording and the plan accepted by the alignment (s).
    #[arg(long, default_value_t = 0.5)]
    max_shift: f64,
    /// Half-width of the fits around each crossing (s; default: the plan's window).
    #[arg(long)]
    window: Option<f64>,
    /// How long after the positions the torque logs what belongs with them: seconds (a
    /// sensor's or filter's delay), or `estimate` (found in the recordings with the robot's
    /// rigid-body model, --robot; a held drive command reads as half a sample early). Each
    /// crossing's torque is read that much later.
    #[arg(long, default_value = "0", allow_hyphen_values = true, value_parser = parse_delay)]
    torque_delay: TorqueDelayArg,
    /// The robot (a URDF file, or a built-in robot) for `--torque-delay estimate`.
    #[arg(long)]
    robot: Option<String>,
    /// With --robot: hold a joint at a position and leave it out of the model (as in `plan`).
    #[arg(long = "lock", value_name = "JOINT=VALUE", value_parser = super::files::parse_lock)]
    lock: Vec<(String, f64)>,
    /// separated (the paper) or combined (all crossings in one regression).
    #[arg(long, value_enum, default_value_t = Estimator::Separated)]
    estimator: Estimator,
    /// Identify H* with the friction-aware regression (differences of the +- pairs with each
    /// joint's Coulomb step as its own column); the plan needs at least 2 (N + 1) H passes
    /// (`plan --friction-aware-h`).
    #[arg(long)]
    friction_aware_h: bool,
    /// The recordings' tau columns hold the signal of a robot's drive gains identified before
    /// (motor currents; a base-parameter model from identify-gains): each is multiplied by its
    /// joint's gain, so the local model is in torques. The gains' own standard errors are not
    /// in the local model's.
    #[arg(long, value_name = "MODEL.json")]
    gains_from: Option<PathBuf>,
    /// An earlier round of this plan to pool with these recordings: the round's plan (the
    /// first, or one `plan --refine` gave) and its folder of recordings; repeatable. Each
    /// round is read against its own plan and the crossings of all are joined (with
    /// `--torque-delay estimate`, the delay is found over every round's recordings).
    #[arg(long = "round", value_name = "PLAN.json=FOLDER", value_parser = parse_round)]
    rounds: Vec<(PathBuf, PathBuf)>,
    #[command(flatten)]
    columns: super::files::ColumnArgs,
}

/// `--round PLAN.json=FOLDER`.
fn parse_round(text: &str) -> std::result::Result<(PathBuf, PathBuf), String> {
    match text.split_once('=') {
        Some((plan, folder)) if !plan.is_empty() && !folder.is_empty() => {
            Ok((PathBuf::from(plan), PathBuf::from(folder)))
        }
        _ => Err(format!(
            "'{text}': expected PLAN.json=FOLDER (a round's plan and its folder of recordings)"
        )),
    }
}

/// `--torque-delay`: seconds or `estimate`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum TorqueDelayArg {
    Seconds(f64),
    Estimate,
}

fn parse_delay(text: &str) -> std::result::Result<TorqueDelayArg, String> {
    match text {
        "estimate" => Ok(TorqueDelayArg::Estimate),
        _ => text
            .parse()
            .map(TorqueDelayArg::Seconds)
            .map_err(|_| format!("'{text}': expected a delay in seconds, or 'estimate'")),
    }
}

/// The recording files of `plan`'s experiments: `given` one per experiment, or one folder
/// holding `<experiment>.csv` for each.
fn recording_paths(plan: &Plan, given: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let files: Vec<PathBuf> = match given {
        [folder] if folder.is_dir() => (plan.experiments.iter())
            .map(|e| folder.join(format!("{}.csv", e.kind.name())))
            .collect(),
        _ => given.to_vec(),
    };
    if files.len() != plan.experiments.len() {
        return Err(Error::invalid(
            "RECORDINGS",
            format!(
                "{} files for {} experiments ({}); give one CSV per experiment, named after it (D.csv), or a folder of them; one log of the whole session is split into them first (perturbid split PLAN LOG --out FOLDER)",
                files.len(),
                plan.experiments.len(),
                plan.kinds()
            ),
        ));
    }
    Ok(files)
}

pub(crate) fn identify(a: IdentifyArgs) -> Result<String> {
    let plan = Plan::load(&a.plan)?;
    let robot =
        match (a.torque_delay, &a.robot) {
            (TorqueDelayArg::Estimate, Some(r)) => Some(super::files::load_robot(r, &a.lock)?),
            (TorqueDelayArg::Estimate, None) => {
                return Err(Error::invalid(
                    "--torque-delay",
                    "estimate needs the robot's model: give --robot URDF (or a built-in robot)",
                ))
            }
            (TorqueDelayArg::Seconds(_), Some(_)) => return Err(Error::invalid(
                "--robot",
                "only --torque-delay estimate uses the robot; leave it out, or estimate the delay",
            )),
            (TorqueDelayArg::Seconds(_), None) => None,
        };
    if let [only] = a.recordings.as_slice() {
        // a ROS 2 bag's folder is not a folder of recordings
        if let Some(message) = crate::io::foreign::foreign_table(only) {
            return Err(Error::Recording {
                recording: only.display().to_string(),
                message,
            });
        }
    }
    let files = recording_paths(&plan, &a.recordings)?;
    let rounds: Vec<(Plan, Vec<PathBuf>)> = (a.rounds.iter())
        .map(|(p, folder)| {
            if !folder.is_dir() {
                return Err(Error::invalid(
                    "--round",
                    format!(
                        "{}: no such folder; expected the round's folder of recordings",
                        folder.display()
                    ),
                ));
            }
            let round = Plan::load(p)?;
            let files = recording_paths(&round, std::slice::from_ref(folder))?;
            Ok((round, files))
        })
        .collect::<Result<_>>()?;
    let inputs: Vec<&std::path::Path> = std::iter::once(a.plan.as_path())
        .chain(files.iter().map(PathBuf::as_path))
        .chain(a.gains_from.as_deref())
        .chain(a.robot.as_deref().map(Path::new))
        .chain(a.rounds.iter().map(|(p, _)| p.as_path()))
        .chain(
            rounds
                .iter()
                .flat_map(|(_, f)| f.iter().map(PathBuf::as_path)),
        )
        .collect();
    super::files::refuse_overwriting_inputs(&a.out, &inputs)?;
    let gains = a
        .gains_from
        .as_deref()
        .map(|path| super::gains::gains_from_file(path, &plan.joint_names))
        .transpose()?;
    let mut notes = String::new();
    let mut load = |plan: &Plan, files: &[PathBuf]| -> Result<Vec<Recording>> {
        (files.iter())
            .map(|f| {
                let rec = a.columns.load(f, &plan.joint_names, &mut notes)?;
                match &gains {
                    Some(g) => rec.in_torques(&g.gain),
                    None => Ok(rec),
                }
            })
            .collect()
    };
    let recs = load(&plan, &files)?;
    let earlier: Vec<(&Plan, Vec<Recording>)> = (rounds.iter())
        .map(|(p, f)| Ok((p, load(p, f)?)))
        .collect::<Result<_>>()?;
    let options = IdentifyOptions {
        times: if a.planned_times {
            CrossingTimes::Planned
        } else {
            CrossingTimes::Detected {
                max_shift: a.max_shift,
            }
        },
        fit: crate::local::FitOptions {
            window: a.window,
            torque_delay: match a.torque_delay {
                TorqueDelayArg::Seconds(s) => s,
                TorqueDelayArg::Estimate => 0.0,
            },
            ..Default::default()
        },
        estimator: a.estimator,
        friction_aware_h: a.friction_aware_h,
    };
    let all: Vec<(&Plan, &[Recording])> = (earlier.iter())
        .map(|(p, r)| (*p, r.as_slice()))
        .chain([(&plan, recs.as_slice())])
        .collect();
    let mut model: LocalModel = match &robot {
        Some(r) => identify_local_rounds_with_delay(r, &all, &options, &Default::default())?,
        None if all.len() > 1 => identify_local_rounds(&all, &options)?,
        None => identify_local(&plan, &recs, &options)?,
    };
    model.drive_gains = gains.as_ref().map(crate::local::SignalGains::from);
    model.save(&a.out)?;
    for w in &model.diagnostics.warnings {
        eprintln!("perturbid: warning: {w}");
    }
    let mut out = notes;
    let _ = writeln!(
        out,
        "local model of '{}' ({} estimator) -> {}",
        model.robot,
        a.estimator,
        a.out.display()
    );
    if let (Some(g), Some(path)) = (&gains, &a.gains_from) {
        let worst = (g.gain.iter().zip(&g.stderr))
            .map(|(k, se)| se / k.abs())
            .fold(0.0, f64::max);
        let _ = writeln!(
            out,
            "torques: the recordings' signal times the drive gains of {} (their relative standard errors, up to {:.2e}, are in the model's predictions' standard errors, not in the coefficients' below)",
            path.display(),
            worst
        );
    }
    out.push_str(&model.summary(&a.out.display().to_string()));
    Ok(out)
}
