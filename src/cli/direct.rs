//! `perturbid excite`, `identify-direct` and `predict`.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{load_robot, refuse_overwriting_inputs, PreprocessArgs, RobotArg};
use super::out_dir;
use super::progress::Progress;
use crate::direct::{
    design_excitation, identify_base_parameters, BaseOptions, Criterion, ExcitationOptions,
    FrictionTerms, Weighting,
};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::io::{write_atomic, OutputSet, Table};
use crate::logs::log_set::LogSet;
use crate::logs::{read_states, samples_table};
use crate::model_file::ModelFile;
use crate::states::States;
use crate::torque_model::TorqueModel;

#[derive(Args)]
pub(crate) struct ExciteArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// Output folder: excitation.json (the coefficients) and excitation.csv (one period, t, q, qd, qdd).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Harmonics per joint (L).
    #[arg(long, default_value_t = 5)]
    harmonics: usize,
    /// Base frequency (Hz).
    #[arg(long, default_value_t = 0.1)]
    base_frequency: f64,
    /// cond (of the base regressor) or logdet (of its information matrix).
    #[arg(long, value_enum, default_value_t = Criterion::Cond)]
    criterion: Criterion,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Budget of criterion evaluations.
    #[arg(long, default_value_t = 2000)]
    max_evaluations: usize,
    /// Sampling rate of excitation.csv (Hz).
    #[arg(long, default_value_t = 1000.0)]
    rate: f64,
    /// Fraction of the limits the excitation may use.
    #[arg(long, default_value_t = 0.9)]
    margin: f64,
    /// Workspace constraints (JSON): points on named links kept above a plane (the floor, a
    /// table) or inside a box, e.g. [{"frame": "panda_hand", "point": [0, 0, 0.1], "region":
    /// {"above": {"normal": [0, 0, 1], "offset": 0}}, "margin": 0.05}].
    #[arg(long)]
    workspace: Option<PathBuf>,
    /// Do not hold the joint torques within the URDF's effort limits (times --margin).
    #[arg(long)]
    no_effort_limits: bool,
}

pub(crate) fn excite(a: ExciteArgs) -> Result<String> {
    let model = a.robot.load()?;
    let o = ExcitationOptions {
        harmonics: a.harmonics,
        base_frequency: a.base_frequency,
        criterion: a.criterion,
        seed: a.seed,
        max_evaluations: a.max_evaluations,
        margin: a.margin,
        workspace: match &a.workspace {
            Some(path) => crate::direct::workspace_from_json(
                &crate::io::read_document(path)?,
                &path.display().to_string(),
            )?,
            None => vec![],
        },
        effort: !a.no_effort_limits,
        ..ExcitationOptions::default()
    };
    let progress = Progress::new();
    let mut report = |e: usize, best: f64| {
        progress.update(&format!(
            "excitation design: {e}/{} evaluations, best {best:.4}",
            a.max_evaluations
        ))
    };
    let design = design_excitation(&model, &o, Some(&mut report))?;
    progress.done();
    let dir = out_dir(&a.out);
    let traj = &design.trajectory;
    let mut set = OutputSet::new(&dir, "excitation");
    set.add(
        "excitation.json",
        serde_json::to_string_pretty(traj).expect("serialisable"),
    )?;
    set.add(
        "excitation.csv",
        samples_table(&traj.sample_periods(1.0, a.rate)?, "").to_csv(),
    )?;
    set.commit()?;
    for w in design.warnings(&model) {
        eprintln!("perturbid: warning: {w}");
    }
    let mut out = format!(
        "excitation: {} harmonics of {} Hz (period {:.1} s), cond(Phi_base) {:.2} after {} evaluations\n-> {} and {}\n",
        a.harmonics,
        a.base_frequency,
        traj.period(),
        design.cond,
        design.evaluations,
        dir.join("excitation.json").display(),
        dir.join("excitation.csv").display()
    );
    if !design.margins.is_empty() {
        out.push_str("smallest slack over a period (beyond each margin):\n");
        for (what, slack) in &design.margins {
            out.push_str(&format!("  {what:<48} {slack:>10.4}\n"));
        }
    }
    Ok(out)
}

/// The terms and weighting of a direct fit (`identify-direct`, `identify-gains`).
#[derive(Args)]
pub(crate) struct FitArgs {
    /// Joint terms, comma separated from viscous, coulomb, offset, armature; or none (the
    /// armature is added when the robot has one).
    #[arg(long, default_value = "viscous,coulomb,offset")]
    friction: FrictionTerms,
    /// wls (weights from the per-joint residuals), ols, or noise: weights from the torques'
    /// noise the periods of a log averaged over them measured (--average-periods, --period;
    /// several logs' pooled), the standard errors from that noise. An averaged log's residuals are judged
    /// against its noise with any weighting.
    #[arg(long, value_enum, default_value_t = Weighting::Wls)]
    weighting: Weighting,
    /// The torques exclude gravity (the robot's controller compensates it in what it logs).
    #[arg(long)]
    no_gravity: bool,
}

impl FitArgs {
    pub(crate) fn options(&self) -> BaseOptions {
        BaseOptions {
            friction: self.friction,
            weighting: self.weighting,
            gravity: Gravity::from(!self.no_gravity),
            ..BaseOptions::default()
        }
    }
}

#[derive(Args)]
pub(crate) struct IdentifyDirectArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// The recording CSV: t, q1..qN, tau1..tauN, optional qd1..qN (and qdd1..qN, which skips
    /// preprocessing unless --preprocess is given). Several: the logs of several runs (other
    /// excitations, other days), each read and preprocessed alone and fitted together; each
    /// one's findings are kept in the model's `logs`.
    #[arg(required = true)]
    data: Vec<PathBuf>,
    /// Where to write the base-parameter model (JSON).
    #[arg(long, default_value = "base_model.json")]
    out: PathBuf,
    #[command(flatten)]
    fit: FitArgs,
    #[command(flatten)]
    preprocessing: PreprocessArgs,
    /// Fit on the first (1 - FRACTION) of the samples (of each log) and report the errors on
    /// the rest.
    #[arg(long, default_value_t = 0.3)]
    validate: f64,
    /// Physically consistent parameters (every link a possible rigid body, friction and
    /// armature >= 0; the URDF's own parameters decide what the data do not): the consistent
    /// model is saved, and the residual growth over the unconstrained fit is reported.
    #[arg(long)]
    consistent: bool,
    /// With --consistent: also write the identified robot as URDF here, the robot's own file
    /// with every link's new inertial and every joint's new friction and armature
    /// (`<dynamics damping friction armature>`), the rest kept as that file has it. A link
    /// moving with another's body (behind a fixed joint) keeps its inertial where the body
    /// allows it. Torque offsets have no place in a URDF and stay in the model.
    #[arg(long, value_name = "PATH")]
    urdf: Option<PathBuf>,
    /// Several logs: fit a torque offset of each log's own (a sensor zeroed anew, a drive
    /// warmed up between them) beside the parameters, whose offset terms are then the logs'
    /// mean; needs the offset among --friction. Each log is validated with its own offset.
    #[arg(long)]
    offset_per_log: bool,
}

pub(crate) fn identify_direct(a: IdentifyDirectArgs) -> Result<String> {
    check_direct_inputs(&a)?;
    let model = a.robot.load()?;
    let progress = Progress::new();
    let mut out = String::new();
    crate::logs::log_set::check_fraction(a.validate, "--validate")?;
    let paths: Vec<&std::path::Path> = a.data.iter().map(PathBuf::as_path).collect();
    let recs =
        (a.preprocessing).read_logs(&paths, &model.joint_names, "DATA", &progress, &mut out)?;
    // each log's first samples are fitted to, its last validated on
    let set = super::files::log_set(&recs, &a.data, a.validate)?;
    let (train, held) = (set.train()?, set.held()?);
    let (split, k) = (train.0.len(), train.0.len() + held.0.len());
    let in_data = |e: Error| set.in_data(e);
    // each log's residuals a time series of their own
    let options = crate::direct::BaseOptions {
        runs: set.runs(),
        offset_per_run: a.offset_per_log,
        noise: super::files::averaged_noise(&recs, &a.data, &model.joint_names, a.fit.weighting)?,
        ..a.fit.options()
    };
    refuse_offset_per_log(&a, recs.len(), options.friction.offset)?;
    progress.update(&format!("identifying on {split} samples"));
    let (fit, urdf) = fit_direct(&a, &model, &train, &options, &in_data, &mut out)?;
    progress.done();
    let fit = fit.with_findings_of_logs(&set);
    for w in fit.warnings() {
        eprintln!("perturbid: warning: {w}");
    }
    fit.save(&a.out)?;
    if let (Some(path), Some(written)) = (&a.urdf, &urdf) {
        write_identified_urdf(path, written, &mut out)?;
    }
    let _ = writeln!(
        out,
        "{} base parameters from {} samples{}, cond {:.3e} -> {}",
        fit.theta.len(),
        split,
        match recs.len() {
            1 => String::new(),
            logs => format!(" of {logs} logs"),
        },
        fit.cond,
        a.out.display()
    );
    // averaged over periods, the residual against the noise the periods measured
    if let (Some(avg), [_]) = (&fit.log_period_average, recs.as_slice()) {
        let _ = writeln!(
            out,
            "{}",
            avg.model_error_line(&fit.residual_rms, "residual RMS")
        );
    }
    if let Some(n) = &fit.noise_fit {
        let _ = writeln!(out, "{}", n.summary("the residuals"));
    }
    print_parameter_table(&fit, &a.out, &mut out)?;
    if let Some(o) = &fit.log_offsets {
        out.push_str(&super::files::log_offsets_table(
            o,
            &a.data,
            "the model's offset terms",
        ));
    }
    if split < k {
        validate_held_out(&model, &fit, &set, &mut out)?;
    }
    Ok(out)
}

/// The checks of `identify-direct`'s arguments that need no file read: outputs that are no
/// inputs, --urdf only with --consistent, the number of logs.
fn check_direct_inputs(a: &IdentifyDirectArgs) -> Result<()> {
    let mut inputs: Vec<&std::path::Path> = a.data.iter().map(PathBuf::as_path).collect();
    inputs.push(a.robot.path());
    refuse_overwriting_inputs(&a.out, &inputs)?;
    if let Some(urdf) = &a.urdf {
        if !a.consistent {
            return Err(Error::invalid(
                "--urdf",
                "needs --consistent: base parameters are sums of several links' parameters and give no link its own",
            ));
        }
        inputs.push(&a.out);
        refuse_overwriting_inputs(urdf, &inputs)?;
    }
    if a.data.len() > crate::direct::drive_gains::MAX_RUNS {
        return Err(Error::invalid(
            "DATA",
            format!(
                "{} logs, expected at most {}",
                a.data.len(),
                crate::direct::drive_gains::MAX_RUNS
            ),
        ));
    }
    Ok(())
}

/// --offset-per-log refused where it cannot be had: one log, too many, or no offset term.
fn refuse_offset_per_log(a: &IdentifyDirectArgs, logs: usize, offset: bool) -> Result<()> {
    let most = crate::direct::streaming::MAX_OFFSET_RUNS;
    let refused = match (logs, offset) {
        (1, _) => Some("one log given: an offset of each log's own needs two or more".to_string()),
        (k, _) if k > most => Some(format!(
            "{k} logs, expected at most {most} for an offset of each log's own"
        )),
        (_, false) => {
            Some("an offset of each log's own needs the offset among --friction".to_string())
        }
        _ => None,
    };
    if let Some(message) = refused.filter(|_| a.offset_per_log) {
        return Err(Error::InvalidArgument {
            argument: "--offset-per-log".into(),
            message,
        });
    }
    Ok(())
}

/// The base-parameter fit on the samples `train`, physically consistent where asked (then
/// with the identified robot as URDF where --urdf asks for it).
fn fit_direct(
    a: &IdentifyDirectArgs,
    model: &crate::model::Model,
    train: &(States<'_>, &[f64]),
    options: &crate::direct::BaseOptions,
    in_data: &dyn Fn(Error) -> Error,
    out: &mut String,
) -> Result<(crate::direct::BaseModel, Option<crate::urdf::WrittenUrdf>)> {
    let mut urdf = None;
    let fit = if a.consistent {
        let c = crate::direct::identify_consistent_parameters(
            model,
            &train.0,
            train.1,
            options,
            &crate::direct::ConsistentOptions::default(),
        )
        .map_err(in_data)?;
        let s = &c.solution;
        let _ = writeln!(
            out,
            "physically consistent: the weighted residual grows by a factor {:.4} over the unconstrained fit ({} Newton steps{}); {} constraint(s) active{}",
            c.residual_growth(),
            s.iterations,
            if s.converged { "" } else { ", stopped at the limit before converging" },
            s.active.len(),
            if s.active.is_empty() { String::new() } else { format!(": {}", s.active.join("; ")) }
        );
        if a.urdf.is_some() {
            let note = format!(
                "Identified by `perturbid identify-direct --consistent` from {}.",
                super::files::logs_named(&a.data)
            );
            let options = crate::urdf::WriteOptions {
                note: &note,
                ..Default::default()
            };
            urdf = Some(crate::urdf::write_urdf(&c.robot(model)?, &options)?);
        }
        c.model
    } else {
        identify_base_parameters(model, &train.0, train.1, options).map_err(in_data)?
    };
    Ok((fit, urdf))
}

/// The identified robot written as URDF to `path`, with its notes and warnings.
fn write_identified_urdf(
    path: &std::path::Path,
    written: &crate::urdf::WrittenUrdf,
    out: &mut String,
) -> Result<()> {
    crate::io::write_atomic(path, written.text.as_bytes())?;
    let _ = writeln!(out, "the identified robot as URDF -> {}", path.display());
    for note in &written.notes {
        let _ = writeln!(out, "  {note}");
    }
    for w in &written.warnings {
        eprintln!("perturbid: warning: {}: {w}", path.display());
    }
    Ok(())
}

/// The parameter table: printed in full and saved as CSV and JSON beside the model at `path`;
/// the names last, as a base parameter's combination of a robot's parameters runs to hundreds
/// of characters and would push every number past the terminal's edge.
fn print_parameter_table(
    fit: &crate::direct::BaseModel,
    path: &std::path::Path,
    out: &mut String,
) -> Result<()> {
    let rows = fit.parameter_table();
    let _ = writeln!(
        out,
        "{:>14} {:>12} {:>10}  base parameter",
        "value", "std. error", "rel. std"
    );
    let fmt_opt = |v: Option<f64>, percent: bool| match v {
        None => "-".to_string(),
        Some(x) if percent => format!("{:.1} %", 100.0 * x),
        Some(x) => format!("{x:.2e}"),
    };
    for r in &rows {
        let _ = writeln!(
            out,
            "{:>14.6} {:>12} {:>10}  {}",
            r.value,
            fmt_opt(r.std, false),
            fmt_opt(r.relative_std, true),
            r.name
        );
    }
    let (csv, json) = write_parameter_table(path, &rows)?;
    let _ = writeln!(
        out,
        "parameter table -> {}, {}",
        csv.display(),
        json.display()
    );
    Ok(())
}

/// The fit against the held-out samples `held`: per joint, and per log where there are
/// several.
fn validate_held_out(
    model: &crate::model::Model,
    fit: &crate::direct::BaseModel,
    set: &LogSet<'_>,
    out: &mut String,
) -> Result<()> {
    let n = model.nv;
    let held = set.held()?;
    let (held_out, k_held, held_runs) = (held.0, held.0.len(), set.held_runs());
    let mut p = fit.on(model)?.predict(&held_out)?;
    // each log's held-out samples with its own offset, where one was fitted
    if let Some(o) = &fit.log_offsets {
        p = o.added(&p, &held_runs);
    }
    let _ = writeln!(
            out,
            "validation on the last {} samples{}: per joint RMS (N m), relative RMS (%) and the RMS of the predictions' standard errors (N m)",
            k_held,
            match (set.len(), &fit.log_offsets) {
                (1, _) => "",
                (_, None) => " of each log",
                (_, Some(_)) => " of each log, each with its own offset",
            }
        );
    let mut v = crate::validation::validate(&model.joint_names, &p, held.1)?;
    if let Ok(se) = crate::validation::stored_stderr(fit.predict_stderr(model, &held_out))? {
        v = v.with_model_stderr(&se)?;
    }
    for e in &v.joints {
        let _ = writeln!(
            out,
            "  {:<16} {:>10} {:>8} {:>12}",
            e.joint,
            number(e.rms),
            e.relative_rms
                .map_or("-".to_string(), |r| format!("{:.2}", 100.0 * r)),
            e.model_stderr_rms.map_or("-".to_string(), number)
        );
    }
    // several logs: each one's own, to tell a log the model fits worse
    if set.len() > 1 {
        let _ = writeln!(out, "per log, per joint RMS (N m):");
        let mut start = 0;
        for (&k, name) in held_runs.iter().zip(set.names()) {
            let rows = start * n..(start + k) * n;
            start += k;
            if rows.is_empty() {
                continue;
            }
            let v =
                crate::validation::validate(&model.joint_names, &p[rows.clone()], &held.1[rows])?;
            let rms: Vec<String> = v.joints.iter().map(|e| number(e.rms)).collect();
            let _ = writeln!(out, "  {name}: {}", rms.join(" "));
        }
    }
    Ok(())
}

/// A torque error for a table: four decimals, or an exponent past a million.
fn number(x: f64) -> String {
    if x.abs() < 1e6 {
        format!("{x:.4}")
    } else {
        format!("{x:.4e}")
    }
}

#[derive(Args)]
pub(crate) struct PredictArgs {
    /// A saved model: a local model (perturbid identify) or a base-parameter model
    /// (perturbid identify-direct).
    model: PathBuf,
    /// States CSV: t, q1..qN, qd1..qN, qdd1..qN (tau1..tauN optional, to compare).
    data: PathBuf,
    /// Output CSV: t, tau1..tauN predicted.
    #[arg(long, default_value = "predicted.csv")]
    out: PathBuf,
    /// Also write each predicted torque's standard error, tau1_stderr..tauN_stderr (N m; NaN
    /// where the model holds an unknown one): a local or base-parameter model's, from its
    /// estimates' standard errors and their correlation.
    #[arg(long)]
    stderr: bool,
    /// The robot, for a base-parameter model (URDF file or built-in name).
    #[arg(long)]
    robot: Option<String>,
    /// Joints of --robot held still, as when the model was identified (JOINT=VALUE, repeat).
    #[arg(long = "lock", value_name = "JOINT=VALUE", value_parser = super::files::parse_lock)]
    lock: Vec<(String, f64)>,
    /// Predict the signal the model's drive gains were identified for (motor currents: a
    /// model from identify-gains), each torque over its joint's gain: columns
    /// signal1..signalN (and signal1_stderr.., from the covariance of the parameters and the
    /// gains together); tau1..tauN of the states CSV read as that signal.
    #[arg(long)]
    signal: bool,
    #[command(flatten)]
    columns: super::files::ColumnArgs,
}

pub(crate) fn predict(a: PredictArgs) -> Result<String> {
    refuse_overwriting_inputs(&a.out, &[&a.model, &a.data])?;
    let file = ModelFile::load(&a.model)?;
    let joints = file.joint_names().to_vec();
    let gains = a
        .signal
        .then(|| super::files::model_gains(&file, &a.model, "--signal").map(|g| &g.gain[..]))
        .transpose()?;
    let mut notes = String::new();
    let rows = read_states(&a.columns.table(&a.data, &joints, &mut notes)?, &joints)?;
    let states = States::new(joints.len(), &rows.q, Some(&rows.qd), Some(&rows.qdd))?;
    let (tau, stderr) = match &file {
        ModelFile::Base(fit) => {
            let robot = a.robot.as_deref().ok_or_else(|| Error::invalid(
                "--robot",
                format!(
                    "a base-parameter model needs its robot ('{}'): give --robot",
                    fit.robot
                ),
            ))?;
            let robot = load_robot(robot, &a.lock)?;
            // states the robot cannot take: predicted, and said
            let ranges = crate::direct::position_range::check_position_range(&robot, &states);
            if let Some(w) = crate::direct::position_range::finding(&ranges) {
                eprintln!("perturbid: warning: '{}': {w}", a.data.display());
            }
            if gains.is_some() {
                // the signal, its standard errors from the parameters' and gains' covariance
                let se = a.stderr.then(|| fit.predict_signal_stderr(&robot, &states));
                (fit.predict_signal(&robot, &states)?, se.transpose()?)
            } else {
                let tau = fit.on(&robot)?.predict(&states)?;
                let se = a.stderr.then(|| fit.predict_stderr(&robot, &states));
                (tau, se.transpose()?)
            }
        }
        ModelFile::Local(m) => {
            // states beyond the perturbations it was identified over: predicted, and said
            if let Some(x) = m.extrapolation(&states)? {
                eprintln!("perturbid: warning: '{}': {}", a.data.display(), x.message());
            }
            let se = a.stderr.then(|| m.predict_stderr(&states));
            (m.predict(&states)?, se.transpose()?)
        }
        ModelFile::GlobalLinear(_) if a.stderr => {
            return Err(Error::invalid(
                "--stderr",
                format!(
                    "'{}' is a globally linearised model, which stores no covariance of its coefficients: only a local or base-parameter model's predictions have standard errors",
                    a.model.display()
                ),
            ))
        }
        ModelFile::GlobalLinear(m) => (m.predict(&states)?, None),
    };
    let (name, unit) = match gains {
        Some(_) => ("signal", "signal units"),
        None => ("tau", "N m"),
    };
    let states = rows;
    let n = joints.len();
    let mut columns = vec!["t".to_string()];
    columns.extend((1..=n).map(|j| format!("{name}{j}")));
    if stderr.is_some() {
        columns.extend((1..=n).map(|j| format!("{name}{j}_stderr")));
    }
    let mut table = Table::new("", columns);
    for (i, t) in states.t.iter().enumerate() {
        let mut row = vec![*t];
        row.extend_from_slice(&tau[i * n..(i + 1) * n]);
        if let Some(se) = &stderr {
            row.extend_from_slice(&se[i * n..(i + 1) * n]);
        }
        table.push(&row);
    }
    write_atomic(&a.out, table.to_csv().as_bytes())?;
    let mut out = notes;
    let _ = writeln!(
        out,
        "{} predicted {} -> {}",
        states.t.len(),
        if gains.is_some() {
            "signals (torques over the drive gains)"
        } else {
            "torques"
        },
        a.out.display()
    );
    if let Some(meas) = &states.tau {
        let mut v = crate::validation::validate(&joints, &tau, meas)?;
        if let Some(se) = &stderr {
            v = v.with_model_stderr(se)?;
        }
        let _ = writeln!(
            out,
            "against the measured {}: per joint RMS error ({unit}){}",
            if gains.is_some() { "signal" } else { "torques" },
            if stderr.is_some() {
                format!(", and the RMS of the predictions' standard errors ({unit})")
            } else {
                String::new()
            }
        );
        for e in v.joints {
            let se = match &stderr {
                Some(_) => format!(
                    " {:>12}",
                    e.model_stderr_rms.map_or("-".to_string(), number)
                ),
                None => String::new(),
            };
            let _ = writeln!(out, "  {:<16} {:>10}{se}", e.joint, number(e.rms));
        }
    }
    Ok(out)
}

/// The parameter table beside the model file `out` (`<stem>.parameters.csv` and `.json`), as
/// one output set. Returns the two paths.
fn write_parameter_table(
    out: &std::path::Path,
    rows: &[crate::direct::ParameterRow],
) -> Result<(PathBuf, PathBuf)> {
    let dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let stem = out.file_stem().map_or("base_model".to_string(), |s| {
        s.to_string_lossy().into_owned()
    });
    let (csv_name, json_name) = (
        format!("{stem}.parameters.csv"),
        format!("{stem}.parameters.json"),
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:e}"));
    let csv = crate::io::csv_text(
        &["parameter", "value", "std", "relative_std", "combination"],
        rows.iter().map(|r| {
            [
                r.name.clone(),
                format!("{:e}", r.value),
                opt(r.std),
                opt(r.relative_std),
                r.combination.to_string(),
            ]
        }),
    );
    let mut set = OutputSet::new(dir, &format!("{stem}.parameters"));
    set.add(&csv_name, csv)?;
    set.add(
        &json_name,
        serde_json::to_string_pretty(rows).expect("serialisable"),
    )?;
    set.commit()?;
    Ok((dir.join(csv_name), dir.join(json_name)))
}
