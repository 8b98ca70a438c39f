//! [`Document`]: the JSON files of the library (plans, models), each with a format tag and a
//! version, loaded with checks and saved atomically.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::error::{Error, Result};

/// A JSON document with a `format` field `"<FORMAT>/<VERSION>"`.
///
/// Loading checks the tag (a file of another kind or a newer version is refused by name), then
/// the document's own consistency ([`Document::validate`]); errors name the source and the line
/// and column or the field. Saving writes a temporary file and renames it into place.
///
/// ```
/// use perturbid_rs::{Document, LocalModel, Plan};
/// let err = Plan::from_json(r#"{"format": "perturbid-local-model/1"}"#).unwrap_err();
/// assert!(err.to_string().contains("expected 'perturbid-plan/1'"));
/// assert_eq!(LocalModel::tag(), "perturbid-local-model/1");
/// ```
pub trait Document: Serialize + DeserializeOwned {
    /// The kind, e.g. `perturbid-local-model`.
    const FORMAT: &'static str;
    /// The version this library writes and reads.
    const VERSION: u32;
    /// What the document is, for messages ("local model").
    const WHAT: &'static str;

    /// The full tag, `"<FORMAT>/<VERSION>"`.
    fn tag() -> String {
        format!("{}/{}", Self::FORMAT, Self::VERSION)
    }

    /// Checks the parsed document's consistency (shapes, ranges).
    fn validate(&self) -> Result<()>;

    /// Pretty-printed JSON.
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("library documents always serialise")
    }

    /// Parses and checks a document; errors name the document by `WHAT`.
    fn from_json(text: &str) -> Result<Self> {
        Self::from_json_in(text, Self::WHAT)
    }

    /// Parses and checks a document read from `source` (a path, named in errors).
    fn from_json_in(text: &str, source: &str) -> Result<Self> {
        let context = if source == Self::WHAT {
            source.to_string()
        } else {
            format!("{source} ({})", Self::WHAT)
        };
        let tag = format_tag(text, &context)?;
        if tag != Self::tag() {
            return Err(Error::Json {
                context,
                message: format!("format '{tag}', expected '{}'", Self::tag()),
            });
        }
        // the JSON path of the culprit (`experiments[2].trajectory.rate`) beside line and column
        let mut reader = serde_json::Deserializer::from_str(text);
        let doc: Self = serde_path_to_error::deserialize(&mut reader).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            Error::Json {
                context: context.clone(),
                message: crate::json::describe_error_at(&inner, text, &path),
            }
        })?;
        reader.end().map_err(|e| Error::Json {
            context: context.clone(),
            message: crate::json::describe_error(&e, text),
        })?;
        doc.validate().map_err(|e| match e {
            Error::Json { message, .. } => Error::Json { context, message },
            other => other,
        })?;
        Ok(doc)
    }

    /// Reads and checks a document file.
    fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_json_in(
            &crate::io::read_document(path)?,
            &path.display().to_string(),
        )
    }

    /// Writes the document to `path` atomically (a temporary file renamed into place).
    fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        crate::io::write_atomic(path, self.to_json().as_bytes())
    }
}

/// The `format` field of a JSON document (without parsing the rest into a type).
pub(crate) fn format_tag(text: &str, context: &str) -> Result<String> {
    #[derive(serde::Deserialize)]
    struct Tagged {
        format: Option<String>,
    }
    crate::json::check_containers(text, context)?;
    let t: Tagged = serde_json::from_str(text).map_err(|e| Error::Json {
        context: context.into(),
        message: crate::json::describe_error(&e, text),
    })?;
    t.format.ok_or_else(|| Error::Json {
        context: context.into(),
        message: "no 'format' field: not a document written by perturbid_rs".into(),
    })
}

/// Checks that every value of the field `field` of a document `what` is a magnitude (a
/// standard error, a residual, a noise level): finite and `>= 0`, or with `unknown_ok` NaN
/// (`null` in the file: no residual degree of freedom). Errors name the entry (`field[3]`).
/// Checks a document's `joint_names`: each non-empty and named once, as the robot's joints are
/// (a hand-edited copy that names a joint twice would read a log's columns twice).
pub(crate) fn check_joint_names(what: &str, names: &[String]) -> Result<()> {
    if let Some(j) = names.iter().position(|name| name.trim().is_empty()) {
        return Err(invalid(
            what,
            format!("joint_names[{j}] is empty; expected the robot's joint names"),
        ));
    }
    let mut seen = std::collections::HashSet::with_capacity(names.len());
    if let Some(j) = names.iter().position(|name| !seen.insert(name.as_str())) {
        return Err(invalid(
            what,
            format!(
                "joint_names[{j}] '{}' is named twice; expected the robot's joint names, each once",
                names[j]
            ),
        ));
    }
    Ok(())
}

pub(crate) fn check_magnitudes(
    what: &str,
    field: &str,
    values: &[f64],
    unknown_ok: bool,
) -> Result<()> {
    check_magnitudes_at(
        what,
        values.iter().copied(),
        |k| format!("{field}[{k}]"),
        unknown_ok,
    )
}

/// [`check_magnitudes`] for one value, named `field` in errors.
pub(crate) fn check_magnitude(what: &str, field: &str, value: f64, unknown_ok: bool) -> Result<()> {
    check_magnitudes_at(
        what,
        std::iter::once(value),
        |_| field.to_string(),
        unknown_ok,
    )
}

/// [`check_magnitudes`] for a matrix saved as a list of rows; errors name the entry as the
/// file has it (`field[row][column]`, 0-based).
pub(crate) fn check_magnitude_rows(
    what: &str,
    field: &str,
    m: &nalgebra::DMatrix<f64>,
    unknown_ok: bool,
) -> Result<()> {
    let (row_major, at) = by_rows(field, m);
    check_magnitudes_at(what, row_major, at, unknown_ok)
}

/// The entries of a matrix saved as a list of rows, in the file's order, with the name of
/// the `k`-th (`field[row][column]`, 0-based).
fn by_rows<'a>(
    field: &'a str,
    m: &'a nalgebra::DMatrix<f64>,
) -> (
    impl Iterator<Item = f64> + 'a,
    impl Fn(usize) -> String + 'a,
) {
    let (rows, cols) = m.shape();
    let row_major = (0..rows).flat_map(move |i| (0..cols).map(move |j| m[(i, j)]));
    let at = move |k: usize| format!("{field}[{}][{}]", k / cols.max(1), k % cols.max(1));
    (row_major, at)
}

/// Checks that no value of the field `field` of a saved model `what` (one of `kind`: "a local
/// model") is beyond [`crate::limits::MAX_MODEL_VALUE`] in size: a slip of the exponent or
/// corruption, which would otherwise pass into fits and predictions unseen. NaN (an unknown,
/// `null`) is left to the field's own check. Errors name the entry (`field[3]`).
pub(crate) fn check_bounded(what: &str, kind: &str, field: &str, values: &[f64]) -> Result<()> {
    check_bounded_at(what, kind, values.iter().copied(), |k| {
        format!("{field}[{k}]")
    })
}

/// [`check_bounded`] for a matrix saved as a list of rows (`field[row][column]` in errors).
pub(crate) fn check_bounded_rows(
    what: &str,
    kind: &str,
    field: &str,
    m: &nalgebra::DMatrix<f64>,
) -> Result<()> {
    let (row_major, at) = by_rows(field, m);
    check_bounded_at(what, kind, row_major, at)
}

fn check_bounded_at(
    what: &str,
    kind: &str,
    values: impl Iterator<Item = f64>,
    at: impl Fn(usize) -> String,
) -> Result<()> {
    let limit = crate::limits::MAX_MODEL_VALUE;
    match values.enumerate().find(|(_, v)| v.abs() > limit) {
        Some((k, v)) => Err(invalid(
            what,
            format!(
                "{} is {}; numbers of {kind} are at most {limit:e} in size (beyond any robot's)",
                at(k),
                crate::error::shown(v)
            ),
        )),
        None => Ok(()),
    }
}

fn check_magnitudes_at(
    what: &str,
    values: impl Iterator<Item = f64>,
    at: impl Fn(usize) -> String,
    unknown_ok: bool,
) -> Result<()> {
    let mut values = values.enumerate();
    match values.find(|(_, x)| !((x.is_finite() && *x >= 0.0) || (unknown_ok && x.is_nan()))) {
        Some((k, x)) => Err(invalid(
            what,
            format!(
                "{} is {}, expected a finite number >= 0{}",
                at(k),
                crate::error::shown(x),
                if unknown_ok { " or null" } else { "" }
            ),
        )),
        None => Ok(()),
    }
}

/// Checks that the condition number `cond` of the field `field` of a document `what` is one:
/// at least 1 (an infinite one is a design without full rank).
pub(crate) fn check_condition(what: &str, field: &str, cond: f64) -> Result<()> {
    if cond >= 1.0 - 1e-9 {
        return Ok(());
    }
    Err(invalid(
        what,
        format!(
            "{field} is {}, expected a condition number >= 1",
            crate::error::shown(cond)
        ),
    ))
}

/// An error about a document's content (after parsing), for [`Document::validate`].
/// Checks a correlation matrix `field` of a document `what` read from a file: `cols x cols`,
/// symmetric with a unit diagonal, entries in [-1, 1], positive semi-definite (else a variance
/// formed with it could come out negative).
pub(crate) fn check_correlation(
    what: &str,
    field: &str,
    r: &nalgebra::DMatrix<f64>,
    cols: usize,
) -> Result<()> {
    if r.shape() != (cols, cols) {
        return Err(invalid(
            what,
            format!(
                "{field} is {} x {}; expected {cols} x {cols}",
                r.nrows(),
                r.ncols()
            ),
        ));
    }
    for a in 0..cols {
        for b in 0..cols {
            let v = r[(a, b)];
            let problem = if !v.is_finite() || v.abs() > 1.0 + 1e-12 {
                Some("expected a correlation in [-1, 1]")
            } else if a == b && (v - 1.0).abs() > 1e-9 {
                Some("expected 1 on the diagonal")
            } else if (v - r[(b, a)]).abs() > 1e-9 {
                Some("expected a symmetric matrix")
            } else {
                None
            };
            if let Some(p) = problem {
                return Err(invalid(
                    what,
                    format!("{field}, row {}, column {} is {v}; {p}", a + 1, b + 1),
                ));
            }
        }
    }
    let loosened = r + nalgebra::DMatrix::identity(cols, cols) * 1e-9;
    if nalgebra::Cholesky::new(loosened).is_none() {
        return Err(invalid(
            what,
            format!("{field} is not positive semi-definite: no correlation of {cols} estimates"),
        ));
    }
    Ok(())
}

pub(crate) fn invalid(what: &str, message: String) -> Error {
    Error::Json {
        context: what.into(),
        message,
    }
}
