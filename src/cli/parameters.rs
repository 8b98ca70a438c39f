//! `perturbid parameters`: the robot's base parameters from local models.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{refuse_overwriting_inputs, RobotArg};
use crate::direct::FrictionTerms;
use crate::document::Document;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::local::{identify_parameters_from_local, FromLocalOptions, LocalModel};

#[derive(Args)]
pub(crate) struct ParametersArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// Local models (local_model.json from `perturbid identify`), at one or more operating
    /// points.
    #[arg(required = true)]
    models: Vec<PathBuf>,
    /// Where to write the identified base parameters (a base-parameter model, JSON).
    #[arg(long, default_value = "parameters.json")]
    out: PathBuf,
    /// Joint terms to identify too, comma separated from viscous, coulomb, offset, armature;
    /// or none (the armature is added when the robot has one).
    #[arg(long, default_value = "none")]
    friction: FrictionTerms,
    /// The models' torques exclude gravity.
    #[arg(long)]
    no_gravity: bool,
    /// Save physically consistent parameters instead (every link a possible rigid body,
    /// friction and armature >= 0; the URDF's own parameters decide what the points do not).
    #[arg(long)]
    consistent: bool,
}

pub(crate) fn run(a: ParametersArgs) -> Result<String> {
    let mut inputs: Vec<&std::path::Path> = a.models.iter().map(PathBuf::as_path).collect();
    inputs.push(a.robot.path());
    refuse_overwriting_inputs(&a.out, &inputs)?;
    let paths: Vec<&std::path::Path> = a.models.iter().map(PathBuf::as_path).collect();
    super::files::refuse_repeated_paths(&paths, "MODELS", "local model")?;
    let robot = a.robot.load()?;
    let models: Vec<LocalModel> = a
        .models
        .iter()
        .map(LocalModel::load)
        .collect::<Result<_>>()?;
    let options = FromLocalOptions {
        friction: a.friction,
        gravity: Gravity::from(!a.no_gravity),
        consistent: a.consistent.then(crate::direct::ConsistentOptions::default),
        ..FromLocalOptions::default()
    };
    // an error about one model names its file
    let fit = identify_parameters_from_local(&robot, &models, &options).map_err(|e| match e {
        Error::InvalidArgument { argument, message } => {
            let file = |arg: &str| {
                (arg.strip_prefix("models["))
                    .and_then(|r| r.strip_suffix(']'))
                    .and_then(|i| i.parse::<usize>().ok())
                    .and_then(|i| a.models.get(i))
                    .map(|p| p.display().to_string())
            };
            // "models[a]" in the message too
            let message = (0..a.models.len()).rev().fold(message, |m, i| {
                m.replace(&format!("models[{i}]"), &a.models[i].display().to_string())
            });
            Error::InvalidArgument {
                argument: file(&argument).unwrap_or(argument),
                message,
            }
        }
        other => other,
    })?;
    let mut out = String::new();
    match &fit.consistent {
        Some(c) => {
            c.model.save(&a.out)?;
            let _ = writeln!(
                out,
                "physically consistent: the weighted residual grows by a factor {:.4} over the unconstrained fit; {} constraint(s) active{}",
                c.residual_growth(),
                c.solution.active.len(),
                if c.solution.active.is_empty() { String::new() } else { format!(": {}", c.solution.active.join("; ")) }
            );
        }
        None => fit.model.save(&a.out)?,
    }
    let _ =
        writeln!(
        out,
        "{} of the robot's {} base parameters identified from {}, {} equations, cond {:.3e} -> {}",
        fit.rank,
        fit.robot_rank,
        match (models.len(), crate::local::parameters::operating_points(&models)) {
            (m, p) if m == p => format!("{p} operating point(s)"),
            (m, p) => format!("{m} local models at {p} operating point(s)"),
        },
        fit.rows,
        fit.model.cond,
        a.out.display()
    );
    if !fit.unidentified.is_empty() {
        let _ = writeln!(
            out,
            "not separated by these points (add operating points): {}",
            fit.unidentified.join("; ")
        );
    }
    Ok(out)
}
