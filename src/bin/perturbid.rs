//! The `perturbid` command line.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use perturbid_rs::{robots, urdf, Model};

#[derive(Parser)]
#[command(
    name = "perturbid",
    version,
    about = "Robot dynamics identification about an operating point"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a robot's joints, limits and masses.
    Info {
        /// A URDF file, or a built-in robot: a465, a465:kinsheel2010, a465:physical.
        robot: String,
    },
}

fn load(robot: &str) -> perturbid_rs::Result<Model> {
    if std::path::Path::new(robot).exists() {
        urdf::model_from_urdf_file(robot, &urdf::LoadOptions::default())
    } else {
        robots::builtin(robot)
    }
}

fn fmt_limit(x: f64) -> String {
    if x.is_infinite() {
        "-".to_string()
    } else {
        format!("{x:.4}")
    }
}

/// Runs a subcommand; returns what it prints on standard output.
fn run(cli: Cli) -> perturbid_rs::Result<String> {
    use std::fmt::Write;
    let mut out = String::new();
    match cli.command {
        Command::Info { robot } => {
            let model = load(&robot)?;
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
        }
    }
    Ok(out)
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(text) => {
            // A closed pipe (`perturbid info a465 | head`) is not an error worth a panic.
            let _ = std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("perturbid: {e}");
            ExitCode::FAILURE
        }
    }
}
