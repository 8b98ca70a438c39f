//! Loading robots, CSV and JSON files for the subcommands.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::model::Model;
use crate::{robots, urdf};

/// The robot of a subcommand: a URDF file or a built-in name, and the joints to hold still.
#[derive(clap::Args)]
pub(crate) struct RobotArg {
    /// The robot: a URDF file, or a built-in robot (a465, a465:physical, ...).
    pub(crate) robot: String,
    /// Hold a joint at a position (rad or m) and leave it out of the model, e.g. a gripper's
    /// finger: --lock panda_finger_joint1=0.02. Repeat for several joints; a joint that mimics
    /// a locked one is locked with it.
    #[arg(long = "lock", value_name = "JOINT=VALUE", value_parser = parse_lock)]
    pub(crate) lock: Vec<(String, f64)>,
}

impl RobotArg {
    /// The robot, with the joints locked, warning on stderr about light joints left free.
    pub(crate) fn load(&self) -> Result<Model> {
        load_robot(&self.robot, &self.lock)
    }

    /// The robot's file (for the check that no output overwrites an input).
    pub(crate) fn path(&self) -> &Path {
        Path::new(&self.robot)
    }
}

/// `JOINT=VALUE` of `--lock`.
pub(crate) fn parse_lock(text: &str) -> std::result::Result<(String, f64), String> {
    let (joint, value) = text
        .split_once('=')
        .ok_or_else(|| format!("'{text}': expected JOINT=VALUE, e.g. panda_finger_joint1=0.02"))?;
    let v: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("'{value}' in '{text}' is not a number (rad or m)"))?;
    if !v.is_finite() || joint.trim().is_empty() {
        return Err(format!(
            "'{text}': expected a joint name and a finite value"
        ));
    }
    Ok((joint.trim().to_string(), v))
}

/// A URDF path or a built-in robot name, with joints locked; warns on stderr about the light
/// joints left free ([`Model::light_joints`]).
pub(crate) fn load_robot(robot: &str, lock: &[(String, f64)]) -> Result<Model> {
    let p = Path::new(robot);
    let options = urdf::LoadOptions {
        lock: lock.iter().cloned().collect(),
        ..urdf::LoadOptions::default()
    };
    let model = if p.exists() || robot.ends_with(".urdf") || robot.contains('/') {
        urdf::model_from_urdf_file(p, &options)?
    } else {
        robots::builtin_with(robot, &options)?
    };
    for w in model.light_joint_warnings() {
        eprintln!("perturbid: warning: {w}");
    }
    Ok(model)
}

/// A JSON document from a file, parsed by `parse`; errors are prefixed with the path.
pub(crate) fn load_json<T>(path: &Path, parse: impl Fn(&str) -> Result<T>) -> Result<T> {
    let text = crate::io::read_document(path)?;
    parse(&text).map_err(|e| match e {
        Error::Json { context, message } => Error::Json {
            context: format!("{} ({context})", path.display()),
            message,
        },
        other => other,
    })
}

/// Whether a file argument is JSON written out in place of a file's name: it starts with `{`
/// and no file of that name exists.
pub(crate) fn is_inline_json(arg: &Path) -> bool {
    arg.to_str()
        .is_some_and(|s| s.trim_start().starts_with('{'))
        && !arg.exists()
}

/// The logs `recs` read from `paths` (the command's `DATA`) as one set to fit: each log's last
/// `validate` fraction held out (`--validate`); several logs are stacked, one is read in place
/// (a long log is not copied).
pub(crate) fn log_set<'a>(
    recs: &'a [crate::logs::recording::Recording],
    paths: &[PathBuf],
    validate: f64,
) -> Result<crate::logs::log_set::LogSet<'a>> {
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    crate::logs::log_set::LogSet::new(recs.iter().collect(), names, validate, "DATA", "--validate")
}

/// The library's error about a log's columns (`q`, `qd`, `qdd`, `tau`: a dead torque
/// channel, for one) as one about the file `path` it was read from, which the library's
/// functions do not know.
pub(crate) fn in_log(path: &Path) -> impl Fn(Error) -> Error + '_ {
    move |e| crate::logs::log_set::in_log(&path.display().to_string(), e)
}

/// Refuses an output file that is one of the inputs (it would be destroyed before, or while,
/// it is read): `--out` equal to an input, also through another spelling of the same path.
pub(crate) fn refuse_overwriting_inputs(out: &Path, inputs: &[&Path]) -> Result<()> {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    match inputs.iter().find(|i| same(out, i)) {
        Some(input) => Err(Error::invalid(
            "--out",
            format!(
                "{} is also an input; writing it would destroy {}: choose another output",
                out.display(),
                input.display()
            ),
        )),
        None => Ok(()),
    }
}

/// Refuses a file of `paths` given twice (under any two paths to it: `a.csv`, `./a.csv`, a
/// link), as `argument`, naming it; `what` is what each file is (`log`, `local model`). Paths
/// that do not resolve (a missing file) are left to the reading to name.
pub(crate) fn refuse_repeated_paths(paths: &[&Path], argument: &str, what: &str) -> Result<()> {
    let files: Vec<Option<PathBuf>> = paths.iter().map(|p| p.canonicalize().ok()).collect();
    let mut seen: std::collections::HashMap<&PathBuf, usize> = std::collections::HashMap::new();
    for (b, file) in files.iter().enumerate() {
        let Some(file) = file else { continue };
        if let Some(&a) = seen.get(file) {
            return Err(Error::invalid(
                argument,
                format!(
                    "{} is given twice{}: each {what} once (its noise would count as independent twice)",
                    paths[a].display(),
                    match paths[a].as_os_str() == paths[b].as_os_str() {
                        true => String::new(),
                        false => format!(" (again as {})", paths[b].display()),
                    }
                ),
            ));
        }
        seen.insert(file, b);
    }
    Ok(())
}

/// How a log from another tool is read ([`crate::io::column_map`]).
#[derive(clap::Args, Clone, Debug, Default)]
pub(crate) struct ColumnArgs {
    /// A log from another tool: read its column SOURCE as TARGET (t; q, qd, qdd or tau for
    /// every joint, SOURCE then holding {i} for the joint's index from 0, {j} for its number
    /// from 1 or {joint} for its name; or one joint's, q3), its values times SCALE (a number,
    /// -1 for a signal counting the other way, or deg, ms, us, ns): --column
    /// t=timestamp*ms --column q=actual_q_{i}. Repeat for each.
    #[arg(long = "column", value_name = "TARGET=SOURCE[*SCALE]")]
    column: Vec<String>,
    /// Columns of the log to leave out (currents, temperatures, states in words: they need
    /// not hold numbers): names, or the start of names followed by '*', separated by commas;
    /// the output lists those left out. A column --column names is read all the same.
    #[arg(long = "ignore-columns", value_name = "NAME[,NAME...]")]
    ignore_columns: Vec<String>,
}

impl ColumnArgs {
    /// The map the options give.
    pub(crate) fn map(&self) -> Result<crate::io::ColumnMap> {
        crate::io::ColumnMap::new(&self.column, &self.ignore_columns)
    }

    /// The table of the log `path` for the joints `joints`, its columns read by the map; the
    /// columns left out are listed in `out`.
    pub(crate) fn table(
        &self,
        path: &Path,
        joints: &[String],
        out: &mut String,
    ) -> Result<crate::io::Table> {
        let (table, left_out) = self.map()?.read(path, joints)?;
        if let Some(note) = crate::io::column_map::left_out_note(path, &left_out) {
            out.push_str(&note);
            out.push('\n');
        }
        Ok(table)
    }

    /// [`Self::table`] read as a recording.
    pub(crate) fn load(
        &self,
        path: &Path,
        joints: &[String],
        out: &mut String,
    ) -> Result<crate::logs::recording::Recording> {
        crate::logs::read_recording(&self.table(path, joints, out)?, joints)
    }
}

/// How a recording is preprocessed (the same for identification and validation).
#[derive(clap::Args)]
pub(crate) struct PreprocessArgs {
    #[command(flatten)]
    pub(crate) columns: ColumnArgs,
    /// Preprocess even when the file has qdd columns.
    #[arg(long)]
    preprocess: bool,
    /// Preprocessing: uniform rate (Hz), low-pass cutoff (Hz), decimation, trim (s).
    #[arg(long, default_value_t = 1000.0)]
    rate: f64,
    #[arg(long, default_value_t = 10.0)]
    cutoff: f64,
    #[arg(long, default_value_t = 10)]
    decimate: usize,
    /// Seconds dropped at both ends of a filtered log (default 0.5; not with periods).
    #[arg(long)]
    trim: Option<f64>,
    /// At a gap in the log (longer than 20 median sample intervals), preprocess the parts on
    /// either side separately instead of refusing the log; nothing is interpolated across it.
    #[arg(long)]
    split_at_gaps: bool,
    /// Average each log over the periods of this excitation (excitation.json from `perturbid
    /// excite`) in place of the low-pass filter: its period and harmonics, its start in each
    /// log found from the positions (docs/method.md, section 8e).
    #[arg(long, value_name = "EXCITATION")]
    average_periods: Option<PathBuf>,
    /// Average each log over periods of this many seconds (with --period-harmonics), from its
    /// first sample or --period-start, in place of the low-pass filter.
    #[arg(long, value_name = "SECONDS")]
    period: Option<f64>,
    /// The harmonics of the excitation's base frequency the positions hold (with --period).
    #[arg(long, value_name = "L")]
    period_harmonics: Option<usize>,
    /// The log's time (s) at which a period starts (with --period; default its first sample).
    #[arg(long, value_name = "T")]
    period_start: Option<f64>,
    /// Whole periods left out at the start of each log before averaging (a transient).
    #[arg(long, default_value_t = 0, value_name = "K")]
    skip_periods: usize,
}

/// How a log is averaged over periods, from the command line.
enum Periods {
    None,
    Given(crate::logs::period_average::PeriodOptions),
    Excitation(Box<crate::trajectory::FourierTrajectory>, PathBuf),
}

impl PreprocessArgs {
    /// The recording of `path` for the joints `joints`, preprocessed when it has no qdd
    /// columns (or `--preprocess` asks); says so in `out`.
    pub(crate) fn read(
        &self,
        path: &Path,
        joints: &[String],
        progress: &super::progress::Progress,
        out: &mut String,
    ) -> Result<crate::logs::recording::Recording> {
        let mut recs = self.read_logs(&[path], joints, "DATA", progress, out)?;
        Ok(recs.pop().expect("one log read"))
    }

    /// [`Self::read`] of every log of `paths`, the logs of one fit. Refused, as `argument`: a
    /// file given twice (the same file under two paths; before any is read), and two logs
    /// that share samples as read, positions and torques bit for bit
    /// ([`crate::logs::repeated_samples`]: a copy, or a part of a log given again).
    pub(crate) fn read_logs(
        &self,
        paths: &[&Path],
        joints: &[String],
        argument: &str,
        progress: &super::progress::Progress,
        out: &mut String,
    ) -> Result<Vec<crate::logs::recording::Recording>> {
        refuse_repeated_paths(paths, argument, "log")?;
        // the options checked, and an excitation read, once for all the logs
        let periods = self.periods()?;
        // each log preprocessed as it is read (one log as read is held at a time), its
        // samples as read printed for the comparison
        let mut recs = Vec::with_capacity(paths.len());
        let mut prints = Vec::with_capacity(paths.len());
        for path in paths {
            progress.update(&format!("reading {}", path.display()));
            let rec = self.columns.load(path, joints, out)?;
            if paths.len() > 1 {
                prints.push(crate::logs::repeated_samples::SamplePrints::of(
                    rec.n,
                    &[&rec.q, &rec.tau],
                )?);
            }
            recs.push(self.prepare(rec, path, &periods, joints, progress, out)?);
        }
        let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        crate::logs::repeated_samples::refuse_shared_samples(
            &prints,
            &names,
            argument,
            "data rows",
        )?;
        Ok(recs)
    }

    /// How the logs are averaged over periods, the options checked against each other.
    fn periods(&self) -> Result<Periods> {
        let refuse = |message: &str| Err(Error::invalid("--average-periods, --period", message));
        let periodic = self.average_periods.is_some() || self.period.is_some();
        if !periodic {
            if self.period_harmonics.is_some()
                || self.period_start.is_some()
                || self.skip_periods > 0
            {
                return refuse("--period-harmonics, --period-start and --skip-periods average over periods: give --period or --average-periods EXCITATION too");
            }
            return Ok(Periods::None);
        }
        if self.trim.is_some() {
            return refuse("--trim drops a filter's transients, and averaging over periods has none: leave it out");
        }
        let options = |period: f64, harmonics: usize| crate::logs::period_average::PeriodOptions {
            skip: self.skip_periods,
            start: self.period_start,
            ..crate::logs::period_average::PeriodOptions::new(period, harmonics)
        };
        match (&self.average_periods, self.period, self.period_harmonics) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => refuse(
                "--average-periods EXCITATION brings its own period and harmonics: give it, or --period and --period-harmonics, not both",
            ),
            (Some(_), _, _) if self.period_start.is_some() => refuse(
                "--average-periods EXCITATION finds each log's start from its positions: --period-start does not apply (give --period and --period-harmonics instead to set it)",
            ),
            (Some(path), None, None) => Ok(Periods::Excitation(
                Box::new(load_excitation(path)?),
                path.clone(),
            )),
            (None, Some(period), Some(h)) => Ok(Periods::Given(options(period, h))),
            (None, Some(_), None) => refuse("--period needs --period-harmonics L, the harmonics the excitation's positions hold"),
            (None, None, _) => unreachable!("periodic"),
        }
    }

    /// The recording `rec` as read from `path`, preprocessed when it has no qdd columns (or
    /// `--preprocess` asks), averaged over `periods` where given; says so in `out`.
    fn prepare(
        &self,
        rec: crate::logs::recording::Recording,
        path: &Path,
        periods: &Periods,
        joints: &[String],
        progress: &super::progress::Progress,
        out: &mut String,
    ) -> Result<crate::logs::recording::Recording> {
        use std::fmt::Write;
        // what the preprocessing (or, of a log taken as logged, the check of its torques) found
        let warn = |rec: &crate::logs::recording::Recording| {
            for w in crate::logs::preprocess::warnings(rec, &path.display().to_string(), joints) {
                eprintln!("perturbid: warning: {w}");
            }
        };
        if rec.qdd.is_some() && !self.preprocess && matches!(periods, Periods::None) {
            // taken as logged: its velocity and acceleration columns against the derivatives
            crate::logs::derivative_columns::check_logged_derivatives(&rec)?;
            let rec = crate::logs::recording::Recording {
                torque_saturation: crate::logs::torque_saturation::find_torque_saturation(&rec),
                ..rec
            };
            warn(&rec);
            return Ok(rec);
        }
        progress.update("preprocessing");
        let periods = match periods {
            Periods::None => None,
            Periods::Given(o) => Some(o.clone()),
            Periods::Excitation(traj, source) => Some(
                crate::logs::excitation_start::excitation_periods(&rec, traj, self.skip_periods)
                    .map_err(|e| match e {
                        Error::Recording { recording, message } => Error::Recording {
                            recording,
                            message: format!("against {}: {message}", source.display()),
                        },
                        e => e,
                    })?,
            ),
        };
        let periodic = periods.is_some();
        let o = crate::logs::preprocess::PreprocessOptions {
            rate: self.rate,
            cutoff: Some(self.cutoff),
            decimate: self.decimate,
            trim: self.trim.unwrap_or(0.5),
            split_at_gaps: self.split_at_gaps,
            periods,
            ..crate::logs::preprocess::PreprocessOptions::default()
        };
        let rec = crate::logs::preprocess::preprocess(&rec, &o)?;
        warn(&rec);
        match (&rec.period_average, periodic) {
            (Some(a), true) => {
                let noise: Vec<String> = (a.averaged_torque_noise().iter())
                    .map(|x| crate::error::shown5(*x))
                    .collect();
                let _ = writeln!(
                    out,
                    "averaged over {} periods of {} s from t = {} s ({} left out): positions' {} harmonics, torques' {} (to {} Hz), {} samples every {}th kept: {} samples; the averaged torques' noise (N m) {}",
                    a.periods,
                    crate::error::shown5(a.period),
                    crate::error::shown5(a.start),
                    a.left_out.len(),
                    a.harmonics,
                    a.torque_harmonics,
                    self.cutoff,
                    a.samples,
                    self.decimate,
                    rec.len(),
                    noise.join(", ")
                );
            }
            _ => {
                let _ = writeln!(
                    out,
                    "preprocessed: {} Hz, {} Hz zero-phase low-pass, every {}th sample, {} s trimmed: {} samples",
                    self.rate, self.cutoff, self.decimate, o.trim, rec.len()
                );
            }
        }
        Ok(rec)
    }
}

/// The Fourier excitation of `path` (excitation.json from `perturbid excite`), checked.
pub(crate) fn load_excitation(path: &Path) -> Result<crate::trajectory::FourierTrajectory> {
    let text = crate::io::read_document(path)?;
    let context = path.display().to_string();
    crate::json::check_containers(&text, &context)?;
    excitation_of(
        &text,
        context,
        "not an excitation (perturbid excite writes one)",
    )
}

/// The Fourier excitation of the JSON `text` read from `context`, checked; an error says
/// `otherwise` where it is none.
pub(crate) fn excitation_of(
    text: &str,
    context: String,
    otherwise: &str,
) -> Result<crate::trajectory::FourierTrajectory> {
    use crate::trajectory::FourierTrajectory;
    let t: FourierTrajectory = serde_json::from_str(text).map_err(|e| Error::Json {
        context: context.clone(),
        message: format!("{otherwise} ({})", crate::json::describe_error(&e, text)),
    })?;
    FourierTrajectory::new(t.w_f, t.q0, t.a, t.b).map_err(|e| Error::Json {
        context,
        message: e.to_string(),
    })
}

/// `--validate FRACTION` of `identify-direct` and `identify-payload`: refused outside [0, 1).
/// The torques' noise the periods of the logs `recs` (read from `paths`) measured, where each
/// was averaged over them: the noise of the direct fit's [`crate::direct::BaseOptions::noise`]
/// (its weights for `--weighting noise`, and the yardstick of its residuals with any
/// weighting); several logs' pooled ([`crate::direct::TorqueNoise::pooled`]). None where a log
/// was not averaged. Errors, for `--weighting noise` only: a log not averaged, or whose
/// periods measured no noise, naming it; logs whose noise differs too much to pool.
pub(crate) fn averaged_noise(
    recs: &[crate::Recording],
    paths: &[PathBuf],
    joints: &[String],
    weighting: crate::direct::Weighting,
) -> Result<Option<crate::direct::TorqueNoise>> {
    let logs = (recs.iter().zip(paths))
        .map(|(rec, path)| {
            let noise = match &rec.period_average {
                Some(a) => crate::direct::TorqueNoise::from_period_average(a, joints),
                None => Err(Error::invalid(
                    "--weighting",
                    "noise needs each log averaged over its excitation's periods (--average-periods, --period), whose spread measures the noise",
                )),
            };
            let name = path.display().to_string();
            (name, noise.map_err(in_log(path)), rec.len())
        })
        .collect();
    crate::direct::TorqueNoise::of_logs(logs, joints, weighting == crate::direct::Weighting::Noise)
}

/// The logs given, for a note in a file written from them: their paths, or where they are
/// many or long, their count and the first.
pub(crate) fn logs_named(paths: &[PathBuf]) -> String {
    let all: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    let joined = all.join(", ");
    match all.first() {
        Some(first) if joined.chars().count() > 2000 => {
            let first: String = first.chars().take(1000).collect();
            format!("{} logs, the first {first}", all.len())
        }
        _ => joined,
    }
}

/// Each log's torque offset less the logs' mean (`mean` says what holds the mean), a line a
/// log (`paths`, in the fit's order) with each joint's deviation and standard error.
pub(crate) fn log_offsets_table(
    o: &crate::direct::LogOffsets,
    paths: &[PathBuf],
    mean: &str,
) -> String {
    let mut out = format!(
        "each log's torque offset less the logs' mean ({mean}), per joint (N m, +- standard error):\n"
    );
    for (r, path) in paths.iter().enumerate() {
        let each: Vec<String> = (o.deviations.iter().zip(&o.stderr))
            .map(|(d, s)| format!("{:.4} +- {:.4}", d[r], s[r]))
            .collect();
        out.push_str(&format!("  {}: {}\n", path.display(), each.join(", ")));
    }
    out
}

/// The drive gains of the saved model `file` (read from `path`) for the option `argument`
/// (`--signal`, `--gains-from`): refused for a model that holds none.
pub(crate) fn model_gains<'a>(
    file: &'a crate::model_file::ModelFile,
    path: &Path,
    argument: &str,
) -> Result<&'a crate::direct::DriveGains> {
    match file {
        crate::model_file::ModelFile::Base(fit) => fit.drive_gains.as_ref(),
        _ => None,
    }
    .ok_or_else(|| {
        Error::invalid(
            argument,
            format!(
                "'{}' holds no drive gains: only a model from identify-gains has them",
                path.display()
            ),
        )
    })
}
