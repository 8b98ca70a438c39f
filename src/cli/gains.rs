//! `perturbid identify-gains`: drive gains and base parameters from logs of motor currents,
//! some of them with a known payload ([`crate::direct::drive_gains`]).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use clap::Args;

use super::direct::FitArgs;
use super::files::{
    in_log, is_inline_json, load_json, refuse_overwriting_inputs, PreprocessArgs, RobotArg,
};
use super::progress::Progress;
use crate::direct::{identify_drive_gains_with, GainEstimator, GainRun};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::logs::recording::Recording;
use crate::model::payload::Payload;
use crate::model_file::ModelFile;

#[derive(Args)]
pub(crate) struct IdentifyGainsArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// Recording CSVs of the robot alone: t, q1..qN, and in tau1..tauN each joint's logged
    /// signal (motor current, A, or a torque computed with nominal gains); optional qd, qdd.
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// A recording CSV of a run with a payload bolted on (repeat for more).
    #[arg(long, required = true)]
    loaded: Vec<PathBuf>,
    /// The payload of the --loaded runs: a JSON file, or the JSON itself, {"link": "link6",
    /// "mass": 2.0, "com": [0, 0, 0.08], "inertia": [ixx, ixy, ixz, iyy, iyz, izz]} (kg, m,
    /// kg m^2 about its centre of mass, in the link's frame).
    /// Once for every --loaded run, or once for each in their order (a heavier payload in
    /// one run and a lighter one in another determine the gains better).
    #[arg(long, required = true)]
    payload: Vec<PathBuf>,
    /// Where to write the base-parameter model with its drive gains (JSON).
    #[arg(long, default_value = "base_model.json")]
    out: PathBuf,
    /// How the gains are estimated: least_squares (the smallest variance, biased towards 0 by
    /// the signal's noise, as the table's noise bias says) or instrumental (instrumental
    /// variables, the signal predicted by the least-squares fit for instrument: unbiased by
    /// the signal's noise, at a larger variance).
    #[arg(long, default_value = "least_squares")]
    estimator: GainEstimator,
    #[command(flatten)]
    fit: FitArgs,
    #[command(flatten)]
    preprocessing: PreprocessArgs,
}

/// The payload of `--payload`: a JSON file, or the JSON itself.
pub(crate) fn load_payload(arg: &Path) -> Result<Payload> {
    let parse = |text: &str| -> Result<Payload> {
        let p: Payload = serde_json::from_str(text).map_err(|e| Error::Json {
            context: "payload".into(),
            message: format!(
                "{}; expected {{\"link\": ..., \"mass\": kg, \"com\": [x, y, z], \"inertia\": [ixx, ixy, ixz, iyy, iyz, izz]}}",
                crate::json::describe_error(&e, text)
            ),
        })?;
        match p.problem("payload") {
            Some(message) => Err(Error::Json {
                context: "payload".into(),
                message,
            }),
            None => Ok(p),
        }
    };
    match arg.to_str() {
        Some(text) if is_inline_json(arg) => parse(text).map_err(|e| match e {
            Error::Json { message, .. } => Error::Json {
                context: "--payload (given as JSON)".into(),
                message,
            },
            other => other,
        }),
        _ => load_json(arg, parse),
    }
}

pub(crate) fn identify_gains(a: IdentifyGainsArgs) -> Result<String> {
    let logs: Vec<&PathBuf> = a.runs.iter().chain(&a.loaded).collect();
    let mut inputs: Vec<&Path> = logs.iter().map(|p| p.as_path()).collect();
    inputs.extend(a.payload.iter().map(PathBuf::as_path));
    inputs.push(a.robot.path());
    refuse_overwriting_inputs(&a.out, &inputs)?;
    let model = a.robot.load()?;
    if !(a.payload.len() == 1 || a.payload.len() == a.loaded.len()) {
        return Err(Error::invalid(
            "--payload",
            format!(
                "{} payloads for {} --loaded runs: give one for them all, or one for each in their order",
                a.payload.len(),
                a.loaded.len()
            ),
        ));
    }
    let payloads = (a.payload.iter())
        .map(|arg| {
            let p = load_payload(arg)?;
            // a payload on a link the robot lacks is named before any log is read
            p.body(&model)?;
            Ok(p)
        })
        .collect::<Result<Vec<Payload>>>()?;
    let payload_of = |loaded: usize| &payloads[loaded.min(payloads.len() - 1)];
    let progress = Progress::new();
    let mut out = String::new();
    let paths: Vec<&Path> = logs.iter().map(|p| p.as_path()).collect();
    let recordings: Vec<Recording> =
        (a.preprocessing).read_logs(&paths, &model.joint_names, "RUNS", &progress, &mut out)?;
    let states = recordings
        .iter()
        .zip(&logs)
        .map(|(r, path)| r.states().map_err(in_log(path)))
        .collect::<Result<Vec<_>>>()?;
    let runs: Vec<GainRun<'_>> = (states.into_iter().zip(&recordings).enumerate())
        .map(|(i, (states, rec))| GainRun {
            states,
            signal: &rec.tau,
            payload: (i >= a.runs.len()).then(|| payload_of(i - a.runs.len())),
        })
        .collect();
    let options = a.fit.options();
    let k: usize = runs.iter().map(|r| r.states.len()).sum();
    progress.update(&format!(
        "identifying on {k} samples of {} runs",
        runs.len()
    ));
    let estimator = a.estimator;
    let fit =
        identify_drive_gains_with(&model, &runs, &options, estimator).map_err(|e| match e {
            // an error about one run's data names its file
            Error::InvalidArgument { argument, message } if argument == "runs" => {
                let file = (0..logs.len()).find(|r| {
                    message.starts_with(&format!("run {r}:"))
                        || message.starts_with(&format!("run {r} "))
                });
                Error::InvalidArgument {
                    argument: file.map_or("runs".into(), |r| logs[r].display().to_string()),
                    message,
                }
            }
            other => other,
        })?;
    progress.done();
    // what the preprocessing found in each run's log, kept with the model
    let fit = crate::direct::BaseModel {
        logs: (recordings.iter().zip(&logs))
            .map(|(r, path)| crate::direct::LogFindings::of(&path.display().to_string(), r))
            .collect(),
        ..fit.model
    };
    for w in fit.warnings() {
        eprintln!("perturbid: warning: {w}");
    }
    fit.save(&a.out)?;
    let g = fit
        .drive_gains
        .as_ref()
        .expect("a drive-gain fit holds its gains");
    let instrumental = estimator == GainEstimator::Instrumental;
    let _ = writeln!(
        out,
        "drive gains by {} from {} runs ({} with {}), {k} samples, cond {:.3e}:",
        if instrumental {
            "instrumental variables"
        } else {
            "least squares"
        },
        g.runs,
        g.loaded_runs,
        (payloads.iter())
            .map(|p| format!("{} kg on '{}'", p.mass, p.link))
            .collect::<Vec<_>>()
            .join(", "),
        g.cond
    );
    let _ = write!(
        out,
        "  {:<16} {:>14} {:>12} {:>12} {:>16}",
        "joint", "gain", "std. error", "noise bias", "payload torque"
    );
    let _ = writeln!(out, "{}", if instrumental { "  least squares" } else { "" });
    for (j, name) in model.joint_names.iter().enumerate() {
        let _ = write!(
            out,
            "  {:<16} {:>14.6} {:>12.2e} {:>10.2} % {:>16.4}",
            name,
            g.gain[j],
            g.stderr[j],
            100.0 * g.noise_bias[j],
            g.payload_torque_rms[j]
        );
        match g.least_squares_gain.get(j) {
            Some(l) => writeln!(out, " {l:>14.6}"),
            None => writeln!(out),
        }
        .ok();
    }
    if instrumental {
        let _ = writeln!(
            out,
            "  (noise bias: of the least-squares gains, the last column; the gains are unbiased by the signal's noise)"
        );
    }
    let _ = writeln!(
        out,
        "{} base parameters of the robot alone (torques: gain x signal), cond {:.3e} -> {}",
        fit.theta.len(),
        fit.cond,
        a.out.display()
    );
    Ok(out)
}

/// The drive gains saved in the model at `path` (`--gains-from`), for a robot of joints
/// `joints`: refused, naming the file, for a model of other joints or without gains.
pub(crate) fn gains_from_file(path: &Path, joints: &[String]) -> Result<crate::direct::DriveGains> {
    let file = ModelFile::load(path)?;
    if file.joint_names() != joints {
        return Err(Error::invalid(
            "--gains-from",
            format!(
                "{}: a model of joints [{}]; the plan's are [{}]",
                path.display(),
                file.joint_names().join(", "),
                joints.join(", ")
            ),
        ));
    }
    Ok(super::files::model_gains(&file, path, "--gains-from")?.clone())
}
