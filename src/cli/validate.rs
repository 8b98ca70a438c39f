//! `perturbid validate`: a saved model against a recorded log (positions and torques are
//! enough; the log is preprocessed as for identification).

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{load_robot, refuse_overwriting_inputs, PreprocessArgs};
use super::progress::Progress;
use crate::direct::position_offsets::check_position_offsets_in_validation;
use crate::direct::position_range::check_position_range;
use crate::direct::torque_columns::check_torque_columns;
use crate::direct::torque_lag::{check_torque_lag, validation_findings};
use crate::error::{Error, Result};
use crate::io::{OutputSet, Table};
use crate::model_file::ModelFile;
use crate::svg::{line_plot, Series};
use crate::torque_model::TorqueModel;
use crate::validation::{stored_stderr, validate};

/// What is validated: a saved model, or a robot's own parameters.
enum Subject {
    File(ModelFile),
    Robot(Box<crate::model::Model>),
}

/// Whether MODEL names a robot (a URDF file: its first character `<`; or a built-in robot's
/// name where no such file exists) rather than a saved model (JSON).
fn is_a_robot(model: &std::path::Path) -> Result<bool> {
    if !model.exists() {
        return Ok(crate::robots::builtin(&model.display().to_string()).is_ok());
    }
    use std::io::Read;
    let io = |source| Error::Io {
        path: model.display().to_string(),
        source,
    };
    // the first bytes tell: a model file is read whole later
    let mut head = Vec::new();
    (std::fs::File::open(model).map_err(io)?)
        .take(4096)
        .read_to_end(&mut head)
        .map_err(io)?;
    let text = String::from_utf8_lossy(&head);
    Ok(text
        .trim_start_matches('\u{feff}')
        .trim_start()
        .starts_with('<'))
}

#[derive(Args)]
pub(crate) struct ValidateArgs {
    /// A saved model: local (perturbid identify), base-parameter (perturbid identify-direct,
    /// perturbid parameters) or globally linearised; or a robot (a URDF file or a built-in
    /// name), whose own parameters are validated: its links' inertials and armature through
    /// inverse dynamics, and its joints' <dynamics> friction (damping * qd + friction *
    /// sign(qd)), with gravity (a vendor's URDF, or one identify-direct --urdf wrote).
    model: PathBuf,
    /// The log CSV: t, q1..qN, tau1..tauN (qd, qdd optional: without qdd the log is
    /// preprocessed as for identification).
    data: PathBuf,
    /// The robot, for a base-parameter model (URDF file or built-in name). With a robot as
    /// MODEL it may be given (as a pipeline's defaults give it) and must have MODEL's joints.
    #[arg(long)]
    robot: Option<String>,
    /// Joints of --robot (or of MODEL, a robot) held still, as when the model was identified
    /// (JOINT=VALUE, repeat).
    #[arg(long = "lock", value_name = "JOINT=VALUE", value_parser = super::files::parse_lock)]
    lock: Vec<(String, f64)>,
    #[command(flatten)]
    preprocessing: PreprocessArgs,
    /// Output folder: residuals.csv (t, measured - predicted per joint), validation.json (the
    /// per-joint table, and `log_glitches` and `log_dropouts`: the samples of the log replaced
    /// as glitches and the rows removed as dropouts before preprocessing, when there were any;
    /// `log_torque_saturation`, its torques that read clipped, warned of; `log_position_wraps`,
    /// steps of whole turns taken out of its positions; `log_held_columns`, its columns logged
    /// at a lower rate and read again at their values' arrivals; `log_stamp_jitter`, its time
    /// stamps found jittering over a regular clock; `log_period_average`, what averaging it
    /// over its excitation's periods found (`--average-periods`, `--period`), and `noise_fit`,
    /// the errors' cost against the noise its periods measured;
    /// for a base-parameter model `torque_columns`, each torque column of the log against the
    /// robot's model, `torque_lag`, its torques shifted against its positions, and
    /// `position_range`, the joints whose positions leave their limits, and `position_offsets`,
    /// the joints' zero offsets against the model's parameters, whose findings are warned of;
    /// for a local model `extrapolation`, where the log's states go beyond the perturbations it
    /// was identified over, warned of too)
    /// and validation.svg (measured and predicted
    /// torques, and residuals).
    #[arg(long, default_value = "validation")]
    out: PathBuf,
    /// The log's tau columns hold the signal the model's drive gains were identified for
    /// (motor currents; a model from identify-gains): each is multiplied by its joint's gain,
    /// and the validation is in torques.
    #[arg(long)]
    signal: bool,
}

pub(crate) fn run(a: ValidateArgs) -> Result<String> {
    refuse_overwriting_inputs(&a.out, &[&a.model, &a.data])?;
    let (file, joints, robot) = subject(&a)?;
    let progress = Progress::new();
    let mut out = String::new();
    let gains = match &file {
        Subject::File(f) if a.signal => {
            Some(super::files::model_gains(f, &a.model, "--signal").map(|g| &g.gain[..])?)
        }
        _ => None,
    };
    let rec = a
        .preprocessing
        .read(&a.data, &joints, &progress, &mut out)?;
    let rec = match gains {
        Some(g) => {
            let _ = writeln!(
                out,
                "the log's signal times the model's drive gains: torques"
            );
            rec.in_torques(g)?
        }
        None => rec,
    };
    let n = joints.len();
    // with the Coulomb term's column filtered as the torques were
    let states = rec.states()?;
    crate::torque_model::refuse_flat_torques(
        &states,
        &rec.tau,
        &joints,
        crate::torque_model::FOR_A_VALIDATION,
    )
    .map_err(super::files::in_log(&a.data))?;
    progress.update("predicting");
    let predicted = match &file {
        Subject::File(ModelFile::Base(fit)) => fit
            .on(robot.as_ref().expect("checked above"))?
            .predict(&states)?,
        Subject::File(ModelFile::Local(m)) => m.predict(&states)?,
        Subject::File(ModelFile::GlobalLinear(m)) => m.predict(&states)?,
        Subject::Robot(r) => crate::robot_torques::RobotTorques::new(r).predict(&states)?,
    };
    progress.update("the predictions' standard errors");
    let stderr = match &file {
        Subject::File(ModelFile::Base(fit)) => {
            stored_stderr(fit.predict_stderr(robot.as_ref().expect("checked above"), &states))?
        }
        Subject::File(ModelFile::Local(m)) => stored_stderr(m.predict_stderr(&states))?,
        Subject::File(ModelFile::GlobalLinear(_)) => {
            Err("a globally linearised model stores no covariance of its coefficients".into())
        }
        Subject::Robot(_) => Err("a robot's own parameters come with no standard errors".into()),
    };
    // a local model at states beyond the perturbations it was identified over
    let extrapolation = match &file {
        Subject::File(ModelFile::Local(m)) => m.extrapolation(&states)?,
        _ => None,
    };
    let mut v = validate(&joints, &predicted, &rec.tau)?;
    if let Ok(se) = &stderr {
        v = v.with_model_stderr(se)?;
    }
    let checks = LogChecks::of(&file, robot.as_ref(), &states, &rec.tau, &progress)?;
    progress.done();
    warn(&a, &file, &checks, &rec, &joints, extrapolation.as_ref());
    // the residuals, the table and the figure, as one output set
    let mut columns = vec!["t".to_string()];
    columns.extend(joints.iter().map(|j| format!("residual_{j}")));
    let mut table = Table::new("", columns);
    for s in 0..v.samples {
        let mut row = vec![rec.t[s]];
        row.extend_from_slice(&v.residuals[s * n..(s + 1) * n]);
        table.push(&row);
    }
    let mut set = OutputSet::new(&a.out, "validation");
    set.add("residuals.csv", table.to_csv())?;
    // the errors against the noise the log's periods measured (no parameters fitted to them;
    // the model's own uncertainty, its s.e., not counted)
    let rms: Vec<f64> = v.joints.iter().map(|j| j.rms).collect();
    let noise_fit = (rec.period_average.as_ref())
        .and_then(|a| crate::direct::TorqueNoise::from_period_average(a, &joints).ok())
        .and_then(|n| crate::direct::NoiseFit::of(&n, &rms, v.samples, 0));
    let json = validation_json(
        &v,
        &rec,
        &checks,
        extrapolation.as_ref(),
        noise_fit.as_ref(),
    );
    set.add(
        "validation.json",
        serde_json::to_string_pretty(&json).expect("serialisable"),
    )?;
    set.add(
        "validation.svg",
        figure(
            &joints,
            &rec.t,
            &rec.tau,
            &predicted,
            stderr.as_deref().ok(),
        ),
    )?;
    set.commit()?;
    summary(&a, &v, &rec, &rms, noise_fit.as_ref(), &stderr, &mut out);
    Ok(out)
}

/// What MODEL is (a saved model, or a robot validated with its own parameters), its joints,
/// and the robot a base-parameter model needs (or the robot itself).
fn subject(a: &ValidateArgs) -> Result<(Subject, Vec<String>, Option<crate::model::Model>)> {
    let file = if is_a_robot(&a.model)? {
        if a.signal {
            return Err(Error::invalid(
                "--signal",
                format!(
                    "{} is a robot, validated with its own parameters: --signal is for a saved model with drive gains",
                    a.model.display()
                ),
            ));
        }
        let own = load_robot(&a.model.display().to_string(), &a.lock)?;
        // --robot (a pipeline's defaults give it to every step) must be the same robot
        if let Some(r) = &a.robot {
            let other = load_robot(r, &a.lock)?;
            if other.joint_names != own.joint_names {
                return Err(Error::invalid(
                    "--robot",
                    format!(
                        "'{r}' has joints {:?}, MODEL {} {:?}: a robot given as MODEL is validated with its own parameters, and --robot, where given, must be the same robot",
                        other.joint_names,
                        a.model.display(),
                        own.joint_names
                    ),
                ));
            }
        }
        Subject::Robot(Box::new(own))
    } else {
        Subject::File(ModelFile::load(&a.model)?)
    };
    let joints = match &file {
        Subject::File(f) => f.joint_names().to_vec(),
        Subject::Robot(r) => r.joint_names.clone(),
    };
    let robot = match (&file, &a.robot) {
        (Subject::Robot(r), _) => Some((**r).clone()),
        (Subject::File(ModelFile::Base(_)), None) => {
            return Err(Error::invalid(
                "--robot",
                format!(
                    "{} is a base-parameter model: give the robot it was identified for",
                    a.model.display()
                ),
            ))
        }
        (_, Some(r)) => Some(load_robot(r, &a.lock)?),
        (_, None) => None,
    };
    Ok((file, joints, robot))
}

/// The log's torque columns against the robot's own model, as every direct fit checks its
/// own log: swapped columns, another sign or other units show here by name, not only as large
/// errors.
struct LogChecks {
    position_range: Vec<crate::direct::position_range::JointRange>,
    torque_columns: Vec<crate::direct::torque_columns::TorqueColumn>,
    torque_lag: Option<crate::direct::torque_lag::TorqueLag>,
    offsets: Option<crate::direct::position_offsets::PositionOffsets>,
}

impl LogChecks {
    fn of(
        file: &Subject,
        robot: Option<&crate::model::Model>,
        states: &crate::states::States<'_>,
        tau: &[f64],
        progress: &Progress,
    ) -> Result<Self> {
        let (position_range, torque_columns, torque_lag, offsets) = match (file, robot) {
            (Subject::File(ModelFile::Base(fit)), Some(r)) => {
                progress.update("checking the torque columns");
                (
                    check_position_range(r, states),
                    check_torque_columns(r, states, tau, fit.gravity)?,
                    check_torque_lag(r, states, tau, fit.gravity)?,
                    check_position_offsets_in_validation(r, fit, states, tau)?,
                )
            }
            // a robot's own: its columns, lag and range as a base-parameter model's; the zero
            // offsets are estimated against a fit's parameters, which a robot has not
            (Subject::Robot(r), _) => {
                progress.update("checking the torque columns");
                (
                    check_position_range(r, states),
                    check_torque_columns(r, states, tau, crate::gravity::Gravity::Included)?,
                    check_torque_lag(r, states, tau, crate::gravity::Gravity::Included)?,
                    None,
                )
            }
            _ => (vec![], vec![], None, None),
        };
        Ok(Self {
            position_range,
            torque_columns,
            torque_lag,
            offsets,
        })
    }
}

/// The warnings of the log `a.data`, on standard error.
fn warn(
    a: &ValidateArgs,
    file: &Subject,
    checks: &LogChecks,
    rec: &crate::logs::Recording,
    joints: &[String],
    extrapolation: Option<&crate::local::reach::Extrapolation>,
) {
    let rounding = crate::logs::position_rounding::warning(&rec.position_rounding, joints)
        .map(|w| format!("{w}{}", crate::logs::position_rounding::IN_A_VALIDATION));
    for w in validation_findings(
        &checks.position_range,
        &checks.torque_columns,
        checks.torque_lag.as_ref(),
        checks.offsets.as_ref(),
    )
    .into_iter()
    .chain(rounding)
    .chain(match file {
        Subject::Robot(r) if !crate::robot_torques::RobotTorques::new(r).has_friction() => {
            Some(crate::robot_torques::NO_FRICTION.to_string())
        }
        _ => None,
    })
    .chain(extrapolation.map(|x| x.message()))
    {
        eprintln!("perturbid: warning: log '{}': {w}", a.data.display());
    }
}

/// validation.json: the validation, with what the log's preprocessing and checks found.
fn validation_json(
    v: &crate::validation::Validation,
    rec: &crate::logs::Recording,
    checks: &LogChecks,
    extrapolation: Option<&crate::local::reach::Extrapolation>,
    noise_fit: Option<&crate::direct::NoiseFit>,
) -> serde_json::Value {
    let mut json = serde_json::to_value(v).expect("serialisable");
    if !rec.glitches.is_empty() {
        json["log_glitches"] = serde_json::to_value(&rec.glitches).expect("serialisable");
    }
    if !rec.dropouts.is_empty() {
        json["log_dropouts"] = serde_json::to_value(&rec.dropouts).expect("serialisable");
    }
    if !rec.held_columns.is_empty() {
        json["log_held_columns"] = serde_json::to_value(&rec.held_columns).expect("serialisable");
    }
    if let Some(j) = &rec.stamp_jitter {
        json["log_stamp_jitter"] = serde_json::to_value(j).expect("serialisable");
    }
    if !rec.position_wraps.is_empty() {
        json["log_position_wraps"] =
            serde_json::to_value(&rec.position_wraps).expect("serialisable");
    }
    if !rec.torque_saturation.is_empty() {
        json["log_torque_saturation"] =
            serde_json::to_value(&rec.torque_saturation).expect("serialisable");
    }
    if !checks.torque_columns.is_empty() {
        json["torque_columns"] =
            serde_json::to_value(&checks.torque_columns).expect("serialisable");
    }
    if let Some(lag) = &checks.torque_lag {
        json["torque_lag"] = serde_json::to_value(lag).expect("serialisable");
    }
    if !checks.position_range.is_empty() {
        json["position_range"] =
            serde_json::to_value(&checks.position_range).expect("serialisable");
    }
    if let Some(x) = extrapolation {
        json["extrapolation"] = serde_json::to_value(x).expect("serialisable");
    }
    if let Some(o) = &checks.offsets {
        json["position_offsets"] = serde_json::to_value(o).expect("serialisable");
    }
    if let Some(a) = &rec.period_average {
        json["log_period_average"] = serde_json::to_value(a).expect("serialisable");
    }
    if let Some(n) = noise_fit {
        json["noise_fit"] = serde_json::to_value(n).expect("serialisable");
    }
    if !rec.position_rounding.is_empty() {
        json["position_rounding"] =
            serde_json::to_value(&rec.position_rounding).expect("serialisable");
    }
    json
}

/// The table the command prints: each joint's errors, against the noise and the model's own
/// uncertainty where known.
fn summary(
    a: &ValidateArgs,
    v: &crate::validation::Validation,
    rec: &crate::logs::Recording,
    rms: &[f64],
    noise_fit: Option<&crate::direct::NoiseFit>,
    stderr: &std::result::Result<Vec<f64>, String>,
    out: &mut String,
) {
    let _ = writeln!(
        out,
        "{} against {} samples of {}:",
        a.model.display(),
        v.samples,
        a.data.display()
    );
    let _ = writeln!(
        out,
        "  {:<20} {:>12} {:>10} {:>12} {:>12} {:>14}",
        "joint", "RMS (N m)", "rel. RMS", "mean (N m)", "max (N m)", "model s.e. RMS"
    );
    for j in &v.joints {
        let rel = j
            .relative_rms
            .map_or("-".to_string(), |r| format!("{:.2} %", 100.0 * r));
        let se = j
            .model_stderr_rms
            .map_or("-".to_string(), |s| format!("{s:.4}"));
        let _ = writeln!(
            out,
            "  {:<20} {:>12.4} {:>10} {:>12.4} {:>12.4} {:>14}",
            j.joint, j.rms, rel, j.mean, j.max, se
        );
    }
    if let Some(avg) = &rec.period_average {
        let _ = writeln!(out, "  {}", avg.model_error_line(rms, "RMS"));
    }
    if let Some(n) = noise_fit {
        let _ = writeln!(
            out,
            "  {} (the model's own uncertainty, its s.e., not counted)",
            n.summary("the errors")
        );
    }
    match stderr {
        Ok(_) => {
            let _ = writeln!(
                out,
                "  (model s.e.: the model's own uncertainty at these states; an RMS far beyond it and the torque noise is the model's error)"
            );
        }
        Err(why) => {
            let _ = writeln!(out, "  (no model s.e.: {why})");
        }
    }
    let _ = writeln!(
        out,
        "wrote residuals.csv, validation.json, validation.svg to {}",
        a.out.display()
    );
}

/// Measured and predicted torques per joint, one panel each (measured solid, predicted
/// dashed over it, with the band of +- 2 standard errors where the model gives them), with
/// the residual.
fn figure(
    joints: &[String],
    t: &[f64],
    measured: &[f64],
    predicted: &[f64],
    stderr: Option<&[f64]>,
) -> String {
    let n = joints.len();
    let column =
        |v: &[f64], j: usize| -> Vec<f64> { v.iter().skip(j).step_by(n).copied().collect() };
    let panels: Vec<String> = (0..n)
        .map(|j| {
            let (m, p) = (column(measured, j), column(predicted, j));
            let r: Vec<f64> = m.iter().zip(&p).map(|(a, b)| a - b).collect();
            let se = stderr.map(|s| column(s, j));
            let band = se.as_ref().map(|se| {
                let side = |sign: f64| -> Vec<f64> {
                    p.iter().zip(se).map(|(p, s)| p + sign * 2.0 * s).collect()
                };
                (side(-1.0), side(1.0))
            });
            line_plot(
                &format!("{}: measured and predicted torque", joints[j]),
                "t (s)",
                "N m",
                &[
                    Series {
                        name: "measured",
                        color: "#444444",
                        dash: "",
                        x: t,
                        y: &m,
                        band: None,
                    },
                    Series {
                        name: "predicted",
                        color: "#d62728",
                        dash: "6 4",
                        x: t,
                        y: &p,
                        band: band.as_ref().map(|(lo, hi)| [&lo[..], &hi[..]]),
                    },
                    Series {
                        name: "residual",
                        color: "#1f77b4",
                        dash: "2 2",
                        x: t,
                        y: &r,
                        band: None,
                    },
                ],
            )
        })
        .collect();
    crate::svg::stack(&panels)
}
