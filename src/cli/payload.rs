//! `perturbid identify-payload`: a payload's mass, centre of mass and inertia from a log of
//! the robot carrying it, against a model of the robot alone or its URDF.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{refuse_overwriting_inputs, PreprocessArgs, RobotArg};
use super::progress::Progress;
use crate::direct::{
    identify_payload, FrictionTerms, PayloadFit, PayloadInertia, PayloadOptions, Reference,
    Weighting,
};
use crate::error::{shown, Error, Result};
use crate::gravity::Gravity;
use crate::io::OutputSet;
use crate::model_file::ModelFile;

#[derive(Args)]
pub(crate) struct IdentifyPayloadArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// The log CSV of the robot carrying the payload: t, q1..qN, tau1..tauN (qd, qdd
    /// optional; preprocessed as for identify-direct). Several: logs of other motions with
    /// the same payload, each read, preprocessed and checked alone and fitted together.
    #[arg(required = true)]
    data: Vec<PathBuf>,
    /// The URDF link the payload is fixed to (a moving link, or one behind fixed joints such
    /// as a flange or tool frame); the payload is given in its frame.
    #[arg(long)]
    link: String,
    /// A base-parameter model of the robot without the payload (identify-direct, or
    /// identify-gains with --signal): the torques are measured against its prediction, and
    /// its parameters' uncertainty is carried into the payload's. Without it, against the
    /// URDF's own parameters, taken as exact.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Joint terms fitted beside the payload, comma separated from viscous, coulomb, offset,
    /// armature; or none. Default: offset with --model (a sensor zeroed anew), viscous,
    /// coulomb and offset without it (the URDF holds no friction to measure against).
    #[arg(long)]
    terms: Option<FrictionTerms>,
    /// wls (weights from the per-joint residuals), ols, or noise: weights from the torques'
    /// noise an averaged log's periods measured (--average-periods, --period), the standard
    /// errors from it. An averaged log's residuals are judged against its noise with any
    /// weighting.
    #[arg(long, value_enum, default_value_t = Weighting::Wls)]
    weighting: Weighting,
    /// The torques exclude gravity (the robot's controller compensates it in what it logs).
    #[arg(long)]
    no_gravity: bool,
    /// A physically consistent payload (a rigid body by construction): for a payload whose
    /// inertia the log determines loosely.
    #[arg(long)]
    consistent: bool,
    /// How the payload's inertia about its centre of mass is taken: fitted (all ten
    /// parameters), or point_mass (0: the mass and centre of mass alone fitted, for a log that
    /// determines a small payload's inertia loosely or not at all, as poses held still do).
    #[arg(long, value_enum, default_value_t = PayloadInertia::Fitted)]
    inertia: PayloadInertia,
    /// The log's tau columns hold the signal the model's drive gains were identified for
    /// (motor currents; --model from identify-gains): each is multiplied by its joint's gain.
    #[arg(long)]
    signal: bool,
    /// Fit on the first (1 - FRACTION) of the samples and report the errors of the robot
    /// carrying the payload on the rest.
    #[arg(long, default_value_t = 0.3)]
    validate: f64,
    /// Output folder: payload.json (the payload as identify-gains --payload and true robots
    /// read it; written only where the fit can vouch for it: a payload seen, a rigid body)
    /// and payload_fit.json (every estimate with its standard error, the reference's share,
    /// the residuals and the findings).
    #[arg(long, default_value = "payload")]
    out: PathBuf,
    /// Also write robot_with_payload.urdf into the output folder, where payload.json is
    /// written: ROBOT's own file (its links as it gives them) with the payload attached as a
    /// link of its own (--payload-link), fixed to --link at its origin, for a simulator or a
    /// controller's model; remove that link and its joint to take the payload off.
    #[arg(long)]
    urdf: bool,
    /// Several logs: fit a torque offset of each log's own (a sensor zeroed anew between
    /// them) beside the joint terms' offset, which is then the logs' mean; needs the offset
    /// among --terms. Each log is validated with its own offset.
    #[arg(long)]
    offset_per_log: bool,
    /// The name of the payload's link in robot_with_payload.urdf (its joint is NAME_joint).
    #[arg(long, default_value = "payload", value_name = "NAME")]
    payload_link: String,
    #[command(flatten)]
    preprocessing: PreprocessArgs,
}

pub(crate) fn run(a: IdentifyPayloadArgs) -> Result<String> {
    let mut inputs: Vec<&std::path::Path> = a.data.iter().map(PathBuf::as_path).collect();
    inputs.push(a.robot.path());
    inputs.extend(a.model.as_deref());
    refuse_overwriting_inputs(&a.out, &inputs)?;
    let model = a.robot.load()?;
    let file = a.model.as_ref().map(ModelFile::load).transpose()?;
    let reference = reference_of(&a, file.as_ref())?;
    let gains = signal_gains(&a, file.as_ref())?;
    let mut options = PayloadOptions::new(&a.link, &reference);
    options.terms = a.terms.unwrap_or(options.terms);
    options.weighting = a.weighting;
    options.gravity = Gravity::from(!a.no_gravity);
    options.consistent = a.consistent;
    options.inertia = a.inertia;
    options.offset_per_run = a.offset_per_log;
    crate::logs::log_set::check_fraction(a.validate, "--validate")?;
    // a link the robot lacks is named before the log is read
    crate::model::payload::Payload {
        link: a.link.clone(),
        mass: 0.0,
        com: [0.0; 3],
        inertia: [0.0; 6],
    }
    .body(&model)?;
    let progress = Progress::new();
    let mut out = String::new();
    let paths: Vec<&std::path::Path> = a.data.iter().map(PathBuf::as_path).collect();
    let mut recs =
        (a.preprocessing).read_logs(&paths, &model.joint_names, "DATA", &progress, &mut out)?;
    if let Some(g) = &gains {
        let _ = writeln!(
            out,
            "the log's signal times the model's drive gains: torques"
        );
        recs = recs
            .into_iter()
            .map(|r| r.in_torques(g))
            .collect::<Result<_>>()?;
    }
    options.noise =
        super::files::averaged_noise(&recs, &a.data, &model.joint_names, options.weighting)?;
    // each log's first samples are fitted to, its last validated on
    let set = super::files::log_set(&recs, &a.data, a.validate)?;
    let (train, held) = (set.train()?, set.held()?);
    if set.len() > 1 {
        options.runs = set.runs();
        options.log_names = set.names().to_vec();
    }
    let in_data = |e: Error| set.in_data(e);
    progress.update(&format!("identifying on {} samples", train.0.len()));
    let fit = identify_payload(&model, reference, &train.0, train.1, &options)
        .map_err(|e| crate::direct::log_offsets::as_argument(e, "--offset-per-log"))
        .map_err(in_data)?;
    let validation = (!held.0.is_empty())
        .then(|| -> Result<_> {
            progress.update("validating");
            let mut predicted = fit.predict(&model, reference, &held.0)?;
            // each log's held-out samples with its own offset, where one was fitted
            if let Some(o) = &fit.log_offsets {
                predicted = o.added(&predicted, &set.held_runs());
            }
            crate::validation::validate(&model.joint_names, &predicted, held.1)
        })
        .transpose()?;
    progress.done();
    for w in &fit.findings {
        match recs.len() {
            1 => eprintln!("perturbid: warning: log '{}': {w}", a.data[0].display()),
            // each log's findings name it
            _ => eprintln!("perturbid: warning: {w}"),
        }
    }
    write_outputs(&a, &model, &fit)?;
    out.push_str(&report(&fit, &a.out, a.urdf));
    if let Some(o) = &fit.log_offsets {
        out.push_str(&super::files::log_offsets_table(
            o,
            &a.data,
            "the joint terms' offset",
        ));
    }
    if let Some(v) = validation {
        print_validation(&v, a.data.len(), &mut out);
    }
    Ok(out)
}

/// The drive gains of the model given where --signal asks for them.
fn signal_gains(a: &IdentifyPayloadArgs, file: Option<&ModelFile>) -> Result<Option<Vec<f64>>> {
    Ok(match (a.signal, file, &a.model) {
        (false, ..) => None,
        (true, Some(f), Some(path)) => {
            Some(super::files::model_gains(f, path, "--signal")?.gain.clone())
        }
        (true, ..) => {
            return Err(Error::invalid(
                "--signal",
                "needs --model: the drive gains come from a model of identify-gains",
            ))
        }
    })
}

/// What the payload is fitted against: the base-parameter model given, or the URDF.
fn reference_of<'a>(a: &IdentifyPayloadArgs, file: Option<&'a ModelFile>) -> Result<Reference<'a>> {
    let base = match (file, &a.model) {
        (Some(ModelFile::Base(fit)), _) => Some(fit),
        (Some(_), Some(path)) => {
            return Err(Error::invalid(
                "--model",
                format!(
                    "{} is not a base-parameter model (identify-direct, identify-gains): a local or globally linearised model holds near its operating point, not along the log's motion",
                    path.display()
                ),
            ))
        }
        _ => None,
    };
    Ok(match base {
        Some(fit) => Reference::Model(fit),
        None => Reference::Urdf,
    })
}

/// payload.json (and the robot carrying it as URDF, where asked) and payload_fit.json, as
/// one output set.
fn write_outputs(
    a: &IdentifyPayloadArgs,
    model: &crate::model::Model,
    fit: &PayloadFit,
) -> Result<()> {
    let mut set = OutputSet::new(&a.out, "payload");
    if let Some(p) = fit.usable_payload() {
        set.add(
            "payload.json",
            serde_json::to_string_pretty(p).expect("serialisable") + "\n",
        )?;
        if a.urdf {
            let note = format!(
                "The payload identified by `perturbid identify-payload` from {}.",
                super::files::logs_named(&a.data)
            );
            let options = crate::urdf::WriteOptions {
                payload: Some(p),
                payload_link: &a.payload_link,
                note: &note,
            };
            set.add(
                "robot_with_payload.urdf",
                crate::urdf::write_urdf(model, &options)?.text,
            )?;
        }
    }
    set.add(
        "payload_fit.json",
        serde_json::to_string_pretty(fit).expect("serialisable") + "\n",
    )?;
    set.commit()?;
    Ok(())
}

/// The validation on the held-out samples of `logs` logs, per joint.
fn print_validation(v: &crate::validation::Validation, logs: usize, out: &mut String) {
    let _ = writeln!(
        out,
        "validation of the robot carrying the payload on the last {} samples{}: per joint RMS (N m) and relative RMS (%)",
        v.samples,
        if logs > 1 { " of each log" } else { "" }
    );
    for e in &v.joints {
        let _ = writeln!(
            out,
            "  {:<16} {:>10.4} {:>8}",
            e.joint,
            e.rms,
            e.relative_rms
                .map_or("-".to_string(), |r| format!("{:.2}", 100.0 * r))
        );
    }
}

/// The fit in words: the payload with its standard errors, the joint terms, the residuals.
fn report(fit: &PayloadFit, out: &std::path::Path, urdf: bool) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "payload on '{}' from {} samples against {}{}, cond {:.3e}:",
        fit.link,
        fit.samples,
        match fit.reference.as_str() {
            "urdf" => "the URDF's parameters",
            _ => "the model of the robot alone",
        },
        if fit.consistent { ", consistent" } else { "" },
        fit.cond
    );
    match (&fit.payload, &fit.payload_stderr) {
        (Some(p), Some(se)) => {
            let _ = writeln!(s, "  mass      {:>12.6} +- {:.2e} kg", p.mass, se.mass);
            for (i, axis) in ["x", "y", "z"].iter().enumerate() {
                let _ = writeln!(
                    s,
                    "  com {axis}     {:>12.6} +- {:.2e} m",
                    p.com[i], se.com[i]
                );
            }
            let point_mass = fit.inertia == PayloadInertia::PointMass;
            if point_mass {
                let _ = writeln!(s, "  inertia about the centre of mass: 0 (a point mass)");
            }
            let names = ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"];
            for (i, name) in names.iter().enumerate().filter(|_| !point_mass) {
                let _ = writeln!(
                    s,
                    "  {name}       {:>12.6} +- {:.2e} kg m^2 (about the centre of mass)",
                    p.inertia[i], se.inertia[i]
                );
            }
        }
        _ => {
            let _ = writeln!(
                s,
                "  no payload seen: mass {} +- {} kg",
                shown(fit.theta[0]),
                shown(fit.stderr[0])
            );
        }
    }
    if fit.names.len() > 10 {
        let _ = writeln!(s, "  joint terms fitted beside it:");
        for (i, name) in fit.names.iter().enumerate().skip(10) {
            let _ = writeln!(
                s,
                "    {name:<24} {:>12.6} +- {:.2e}",
                fit.theta[i], fit.stderr[i]
            );
        }
    }
    let _ = writeln!(
        s,
        "  {:<16} {:>16} {:>16} {:>14}",
        "joint", "reference RMS", "payload RMS", "residual RMS"
    );
    for (j, name) in fit.joint_names.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {name:<16} {:>16.4} {:>16.4} {:>14.4}",
            fit.reference_rms[j], fit.payload_torque_rms[j], fit.residual_rms[j]
        );
    }
    if let Some(n) = &fit.noise_fit {
        let _ = writeln!(s, "  {}", n.summary("the residuals"));
    }
    let written = match fit.usable_payload() {
        Some(_) if urdf => format!(
            "{0}/payload.json, {0}/payload_fit.json and {0}/robot_with_payload.urdf",
            out.display()
        ),
        Some(_) => format!("{0}/payload.json and {0}/payload_fit.json", out.display()),
        None => format!(
            "{}/payload_fit.json (no payload.json: the fit cannot vouch for one, see the warnings)",
            out.display()
        ),
    };
    let _ = writeln!(s, "wrote {written}");
    s
}
