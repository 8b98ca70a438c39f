//! Loading robots, CSV and JSON files for the subcommands.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::{read_text, Table};
use crate::model::Model;
use crate::{robots, urdf};

/// A URDF path or a built-in robot name.
pub(crate) fn load_robot(robot: &str) -> Result<Model> {
    let p = Path::new(robot);
    if p.exists() || robot.ends_with(".urdf") || robot.contains('/') {
        urdf::model_from_urdf_file(p, &urdf::LoadOptions::default())
    } else {
        robots::builtin(robot)
    }
}

/// A CSV table from a file.
pub(crate) fn load_table(path: &Path) -> Result<Table> {
    Table::parse(&path.display().to_string(), &read_text(path)?)
}

/// A JSON document from a file, parsed by `parse`; errors are prefixed with the path.
pub(crate) fn load_json<T>(path: &Path, parse: impl Fn(&str) -> Result<T>) -> Result<T> {
    let text = read_text(path)?;
    parse(&text).map_err(|e| match e {
        Error::Json { context, message } => Error::Json {
            context: format!("{} ({context})", path.display()),
            message,
        },
        other => other,
    })
}

/// Refuses an output file that is one of the inputs (it would be destroyed before, or while,
/// it is read): `--out` equal to an input, also through another spelling of the same path.
pub(crate) fn refuse_overwriting_inputs(out: &Path, inputs: &[&Path]) -> Result<()> {
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    match inputs.iter().find(|i| same(out, i)) {
        Some(input) => Err(Error::InvalidArgument {
            argument: "--out".into(),
            message: format!(
                "{} is also an input; writing it would destroy {}: choose another output",
                out.display(),
                input.display()
            ),
        }),
        None => Ok(()),
    }
}
