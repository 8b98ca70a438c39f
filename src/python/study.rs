//! Python: the study's pieces, so that `perturbid_rs.study` can run the cases here (on every
//! core) or ship them to a Dask cluster: resolve a configuration, list the pending cases, run
//! one case, record results in the journal, write the report. Studies travel as JSON strings
//! (they pickle as they are).

use std::path::PathBuf;

use pyo3::prelude::*;

use super::detached;
use crate::error::Error;
use crate::study::{self, CaseResult, Study, StudyConfig};

fn parse_study(json: &str) -> PyResult<Study> {
    serde_json::from_str(json).map_err(|e| {
        Error::Json {
            context: "study".into(),
            message: format!("not a resolved study ({e}); make one with study_resolve"),
        }
        .into()
    })
}

/// A study configuration resolved into its cases (JSON text of the resolved study).
/// `text`: the configuration as TOML (`format='toml'`) or JSON (`format='json'`); `base`: the
/// folder relative files (URDFs, true robots) are read from; `source` names it in errors.
#[pyfunction]
#[pyo3(signature = (text, format, base, source))]
pub(crate) fn study_resolve(
    text: &str,
    format: &str,
    base: PathBuf,
    source: &str,
) -> PyResult<String> {
    let config: StudyConfig = match format {
        "toml" => crate::io::config::parse_toml(source, text)?,
        "json" => {
            crate::json::check_containers(text, source)?;
            let mut reader = serde_json::Deserializer::from_str(text);
            serde_path_to_error::deserialize(&mut reader).map_err(|e| Error::Config {
                location: source.to_string(),
                message: format!("at '{}': {}", e.path(), e.inner()),
            })?
        }
        other => {
            return Err(
                Error::invalid("format", format!("'{other}'; expected 'toml' or 'json'")).into(),
            )
        }
    };
    let s = Study::resolve(config, &base, source)?;
    Ok(serde_json::to_string(&s).expect("serialisable"))
}

/// The study configuration in the TOML file `path` resolved into its cases, as JSON: read as
/// the command line reads it (size-bounded; relative files next to it).
#[pyfunction]
pub(crate) fn study_resolve_file(path: PathBuf) -> PyResult<String> {
    let s = Study::from_file(&path)?;
    Ok(serde_json::to_string(&s).expect("serialisable"))
}

/// The number of cases of a resolved study.
#[pyfunction]
pub(crate) fn study_len(study: &str) -> PyResult<usize> {
    Ok(parse_study(study)?.len())
}

/// Indices of the cases the journal in `out` does not hold yet.
#[pyfunction]
pub(crate) fn study_pending(study: &str, out: PathBuf) -> PyResult<Vec<usize>> {
    Ok(study::pending(&parse_study(study)?, &out)?)
}

/// Runs case `index` of a resolved study (GIL released): its result as JSON.
#[pyfunction]
pub(crate) fn study_case(py: Python<'_>, study: &str, index: usize) -> PyResult<String> {
    let s = parse_study(study)?;
    let r = detached(py, "study_case", || study::run_case(&s, index))?;
    Ok(serde_json::to_string(&r).expect("serialisable"))
}

/// Appends case results (JSON, from `study_case`) to the journal in `out`.
#[pyfunction]
pub(crate) fn study_record(out: PathBuf, results: Vec<String>) -> PyResult<()> {
    let parsed: Vec<CaseResult> = results
        .iter()
        .map(|r| {
            serde_json::from_str(r).map_err(|e| Error::Json {
                context: "study_record".into(),
                message: format!("not a case result: {e}"),
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(study::journal::append(&out, &parsed)?)
}

/// Writes the report of a finished study into `out` from its journal; returns the Markdown
/// summary. Fails naming how many cases are missing.
#[pyfunction]
pub(crate) fn study_finish(py: Python<'_>, study: &str, out: PathBuf) -> PyResult<String> {
    let s = parse_study(study)?;
    let md = detached(py, "study_finish", || {
        let (results, missing) = study::collected(&s, &out)?;
        if missing > 0 {
            return Err(Error::invalid(
                "study",
                format!(
                    "{missing} of {} cases have no result in the journal yet",
                    s.len()
                ),
            ));
        }
        study::write_report(&s, &results, &out)
    })?;
    Ok(md)
}

/// Runs the pending cases of a resolved study on every core here (GIL released; Ctrl-C stops
/// between batches, finished cases stay in the journal), then writes the report.
/// `progress`: log (cases done, total) to the logger `perturbid_rs.study` at INFO.
#[pyfunction]
#[pyo3(signature = (study, out, progress=true))]
pub(crate) fn study_run(
    py: Python<'_>,
    study: &str,
    out: PathBuf,
    progress: bool,
) -> PyResult<String> {
    let s = parse_study(study)?;
    let md = detached(py, "study_run", || {
        let mut report = |done: usize, total: usize| {
            if progress {
                log::info!(target: "perturbid_rs::study", "study: {done} of {total} cases");
            }
        };
        study::run_study(&s, &out, &mut report)
    })?;
    Ok(md)
}
