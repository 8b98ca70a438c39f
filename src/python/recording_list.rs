//! Several Recordings fitted together (runs one after the other: `identify_base_parameters`,
//! `identify_consistent_parameters`): the list read, its Recordings as one set of logs,
//! the fit's option of an offset a log, and what each one's preprocessing found kept in the
//! model's `logs`.

use std::sync::Arc;

use pyo3::prelude::*;

use super::samples::Given;
use crate::direct::{BaseModel, BaseOptions};
use crate::error::{Error, Result};
use crate::logs::log_set::LogSet;
use crate::logs::recording::Recording;

/// `options` with an offset a log where `offset_per_log` asks for one: refused unless the
/// data are a list of two or more Recordings (`listed`, their number) and the joint terms have
/// the offset, named as Python's argument.
pub(crate) fn with_offset_per_log(
    options: BaseOptions,
    offset_per_log: bool,
    listed: Option<usize>,
) -> Result<BaseOptions> {
    if !offset_per_log {
        return Ok(options);
    }
    let most = crate::direct::streaming::MAX_OFFSET_RUNS;
    let problem = match listed {
        Some(k) if !(2..=most).contains(&k) => Some(format!(
            "an offset of each log's own needs 2 to {most} Recordings, got {k}"
        )),
        None => Some("an offset of each log's own needs a list of Recordings (logs) as q".into()),
        _ if !options.friction.offset => Some(
            "an offset of each log's own needs the offset among the joint terms (friction='all', or a list with 'offset')".into(),
        ),
        _ => None,
    };
    match problem {
        Some(message) => Err(Error::InvalidArgument {
            argument: "offset_per_log".into(),
            message,
        }),
        None => Ok(BaseOptions {
            offset_per_run: true,
            ..options
        }),
    }
}

/// The Recordings given as `q` (a list or tuple of them: runs to fit together), with nothing
/// else given beside them (they carry their own); None for arrays or one Recording.
pub(crate) fn recordings_given(
    q: &Bound<'_, PyAny>,
    given: &Given<'_>,
) -> PyResult<Option<Vec<Arc<Recording>>>> {
    let Some(recs) = super::recording::recordings_of(q)? else {
        return Ok(None);
    };
    if let Some(name) = given.first_given() {
        return Err(Error::invalid(
            name,
            "given with a list of Recordings as q, which carry their own: pass the list alone",
        )
        .into());
    }
    Ok(Some(recs))
}

/// The Recordings `recs` (preprocessed: with velocities and accelerations) as one set of logs
/// fitted together whole, each one's logged derivatives checked as a log's, and `options`
/// with their runs (each one's residuals a time series of their own). Errors name the
/// Recording.
pub(crate) fn recording_set<'a>(
    model: &crate::model::Model,
    recs: &'a [Arc<Recording>],
    options: &BaseOptions,
) -> Result<(LogSet<'a>, BaseOptions)> {
    for (i, r) in recs.iter().enumerate() {
        let at = |e: Error| Error::invalid("q", format!("Recording {i} ('{}'): {e}", r.name));
        if r.n != model.nv || r.qd.is_none() || r.qdd.is_none() {
            return Err(at(Error::invalid(
                "q",
                format!(
                    "{} joints{}, expected the robot's {} with velocities and accelerations: preprocess it first (perturbid_rs.preprocess)",
                    r.n,
                    if r.qdd.is_none() { " without velocities and accelerations" } else { "" },
                    model.nv
                ),
            )));
        }
        crate::logs::derivative_columns::check_logged_derivatives(r).map_err(at)?;
    }
    let names: Vec<String> = (recs.iter().enumerate())
        .map(|(i, r)| format!("Recording {i} ('{}')", r.name))
        .collect();
    let set = LogSet::new(
        recs.iter().map(Arc::as_ref).collect(),
        names,
        0.0,
        "q",
        "validate",
    )?;
    // each Recording's residuals a time series of their own (all its samples are fitted to)
    let options = BaseOptions {
        runs: set.splits().to_vec(),
        ..options.clone()
    };
    Ok((set, options))
}

/// `fit` with what each of the Recordings `recs` it was fitted to found in its preprocessing,
/// in its `logs` (named by it).
pub(crate) fn with_logs(fit: BaseModel, recs: &[Arc<Recording>]) -> BaseModel {
    fit.with_findings_of_each(recs.iter().map(|r| (r.name.as_str(), r.as_ref())))
}
