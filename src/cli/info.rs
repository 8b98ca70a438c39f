//! `perturbid info ROBOT`.

use std::fmt::Write;

use clap::Args;

use super::files::RobotArg;
use crate::error::Result;

#[derive(Args)]
pub(crate) struct InfoArgs {
    #[command(flatten)]
    robot: RobotArg,
}

fn fmt_limit(x: f64) -> String {
    if x.is_infinite() {
        "-".to_string()
    } else {
        format!("{x:.4}")
    }
}

pub(crate) fn run(a: InfoArgs) -> Result<String> {
    let model = a.robot.load()?;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "robot {} ({}), {} degrees of freedom, {} moving bodies, root link '{}'",
        model.name,
        model.source,
        model.nv,
        model.nbodies(),
        model.root_link
    );
    let _ = writeln!(
        out,
        "moving mass {:.4} kg, mass fixed to the base {:.4} kg",
        model.moving_mass(),
        model.base_mass
    );
    let _ = writeln!(
        out,
        "{:<16} {:<10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "joint", "kind", "lower", "upper", "velocity", "accel", "effort"
    );
    for (i, name) in model.joint_names.iter().enumerate() {
        let l = &model.limits[i];
        let _ = writeln!(
            out,
            "{:<16} {:<10} {:>10} {:>10} {:>10} {:>10} {:>10}",
            name,
            format!("{:?}", model.joint_kinds[i]).to_lowercase(),
            fmt_limit(l.lower),
            fmt_limit(l.upper),
            fmt_limit(l.velocity),
            fmt_limit(l.acceleration),
            fmt_limit(l.effort)
        );
    }
    Ok(out)
}
