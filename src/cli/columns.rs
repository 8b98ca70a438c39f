//! `perturbid columns ROBOT LOG [--column ...] [--ignore-columns ...]`: how a log's columns
//! are read as a recording's, before a command reads it so (docs/logs.md).

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::files::{ColumnArgs, RobotArg};
use crate::error::Result;

#[derive(Args)]
pub(crate) struct ColumnsArgs {
    #[command(flatten)]
    robot: RobotArg,
    /// The log: a CSV, its columns named as the tool that wrote it names them.
    log: PathBuf,
    #[command(flatten)]
    columns: ColumnArgs,
}

pub(crate) fn run(a: ColumnsArgs) -> Result<String> {
    let model = a.robot.load()?;
    let joints = &model.joint_names;
    let (table, read) = a.columns.map()?.read_explained(&a.log, joints)?;
    // refused as every command that reads the log would refuse it
    let rec = crate::logs::read_recording(&table, joints)?;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} columns, {} rows; read as a recording of {} joints ({}):",
        a.log.display(),
        read.header.len(),
        table.rows(),
        joints.len(),
        joints.join(", ")
    );
    for k in &read.selection.keep {
        let source = &read.header[k.source];
        let scale = if k.scale == 1.0 {
            String::new()
        } else {
            format!(" x {}", crate::error::shown(k.scale))
        };
        let from = if *source == k.name {
            String::new()
        } else {
            format!(" <- {source}")
        };
        let line = format!("  {:<10}{from}{scale}", k.name);
        let _ = writeln!(out, "{}", line.trim_end());
    }
    let signals: Vec<&str> = [
        ("q", true),
        ("qd", rec.qd.is_some()),
        ("qdd", rec.qdd.is_some()),
        ("tau", true),
    ]
    .iter()
    .filter(|(_, present)| *present)
    .map(|(name, _)| *name)
    .collect();
    let _ = writeln!(
        out,
        "t from {} s to {} s; {}{}",
        crate::error::shown(rec.t[0]),
        crate::error::shown(rec.t[rec.t.len() - 1]),
        signals.join(", "),
        if rec.qdd.is_some() {
            " (taken as logged, unless --preprocess)"
        } else {
            " (preprocessed by the commands that fit)"
        }
    );
    if let Some(note) = crate::io::column_map::left_out_note(&a.log, &read.left_out) {
        let _ = writeln!(out, "{note}");
    }
    Ok(out)
}
