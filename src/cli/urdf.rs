//! `perturbid urdf ROBOT --out FILE`: the robot as URDF (a built-in robot's own file), with a
//! payload attached as a link of its own where one is given (docs/urdf.md).

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{refuse_overwriting_inputs, RobotArg};
use crate::error::Result;

#[derive(Args)]
pub(crate) struct UrdfArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// A payload to attach (payload.json as identify-payload writes it, or the JSON itself):
    /// a link of its own (--payload-link) fixed to the payload's link at its origin.
    #[arg(long)]
    payload: Option<PathBuf>,
    /// The name of the payload's link (its joint is NAME_joint).
    #[arg(long, default_value = "payload", value_name = "NAME")]
    payload_link: String,
    /// Where to write the URDF.
    #[arg(long)]
    out: PathBuf,
}

pub(crate) fn run(a: UrdfArgs) -> Result<String> {
    let mut inputs = vec![a.robot.path()];
    inputs.extend(a.payload.as_deref());
    refuse_overwriting_inputs(&a.out, &inputs)?;
    let model = a.robot.load()?;
    let payload = a
        .payload
        .as_deref()
        .map(super::gains::load_payload)
        .transpose()?;
    let note = match &a.payload {
        Some(p) => format!(
            "Written by `perturbid urdf` with the payload of {}.",
            p.display()
        ),
        None => "Written by `perturbid urdf`.".to_string(),
    };
    let options = crate::urdf::WriteOptions {
        payload: payload.as_ref(),
        payload_link: &a.payload_link,
        note: &note,
    };
    let written = crate::urdf::write_urdf(&model, &options)?;
    for w in &written.warnings {
        eprintln!("perturbid: warning: {}: {w}", a.out.display());
    }
    crate::io::write_atomic(&a.out, written.text.as_bytes())?;
    let mut out = format!("{} as URDF -> {}\n", model.name, a.out.display());
    for note in &written.notes {
        let _ = writeln!(out, "  {note}");
    }
    Ok(out)
}
