//! `perturbid parameters`: the robot's base parameters from local models.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{refuse_overwriting_inputs, RobotArg};
use crate::direct::FrictionTerms;
use crate::document::Document;
use crate::error::Result;
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
    let fit = identify_parameters_from_local(&robot, &models, &options)?;
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
    let _ = writeln!(
        out,
        "{} of the robot's {} base parameters identified from {} operating point(s), {} equations, cond {:.3e} -> {}",
        fit.rank,
        fit.robot_rank,
        models.len(),
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
