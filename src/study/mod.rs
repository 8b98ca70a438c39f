//! Studies: when does the local model beat the global one? A declarative study (robots,
//! operating points given or sampled in speed classes, true robots, noise levels, local plan
//! designs, K and perturbation sizes, seeds, evaluation distances, methods) is resolved into
//! cases ([`Study`]); each case ([`run_case`]) plans, rehearses and identifies every method on
//! its true robot and measures the models against the true plant near the point; the journal
//! makes a study resumable; the report summarises it. [`run_study`] runs a study on the cores
//! of this machine; from Python the same cases run on a Dask cluster (`perturbid_rs.study`).
//! See docs/study.md.

mod case;
mod config;
pub mod journal;
mod plan;
mod report;

pub use case::{run_case, CaseResult, Measure};
pub use config::{
    DirectSpec, EvaluationSpec, LocalSpec, Method, PointSpec, RobotSpec, SampleSpec, SpeedClass,
    StudyConfig, TrueRobotSpec,
};
pub use plan::{Case, Study, StudyPoint, StudyRobot};
pub use report::{quantile, rows, summarise, write as write_report, SummaryRow, RESULT_COLUMNS};

use std::path::Path;

use rayon::prelude::*;

use crate::error::Result;

/// The indices of the cases of `study` that the journal in `out` does not hold yet.
pub fn pending(study: &Study, out: &Path) -> Result<Vec<usize>> {
    let done = journal::read(out)?;
    let mut todo = Vec::new();
    for i in 0..study.len() {
        let c = study.case(i)?;
        if !done.contains_key(&study.case_id(&c)) {
            todo.push(i);
        }
    }
    Ok(todo)
}

/// The journal's results for the cases of `study`, in case order (cases of other studies or
/// of an earlier version of this one are left out); with the number of cases still missing.
pub fn collected(study: &Study, out: &Path) -> Result<(Vec<CaseResult>, usize)> {
    let done = journal::read(out)?;
    let mut results = Vec::new();
    let mut missing = 0;
    for i in 0..study.len() {
        let c = study.case(i)?;
        match done.get(&study.case_id(&c)) {
            Some(r) => results.push(CaseResult {
                index: i,
                ..r.clone()
            }),
            None => missing += 1,
        }
    }
    Ok((results, missing))
}

/// Runs the cases `indices` of `study` on every core (rayon), in batches of four per thread;
/// `on_batch` hears each batch's results in index order on the calling thread (and may stop
/// the run with an error). Stops on Ctrl-C between batches.
pub fn run_cases(
    study: &Study,
    indices: &[usize],
    on_batch: &mut dyn FnMut(Vec<CaseResult>) -> Result<()>,
) -> Result<()> {
    let batch = 4 * rayon::current_num_threads().max(1);
    for chunk in indices.chunks(batch) {
        crate::interrupt::check("study")?;
        let results: Vec<CaseResult> = chunk
            .par_iter()
            .map(|&i| crate::error::catch_panics("study case", || run_case(study, i)))
            .collect::<Result<_>>()?;
        on_batch(results)?;
    }
    Ok(())
}

/// Runs the cases of `study` that the journal in `out` does not hold, on every core,
/// appending each batch of finished cases to the journal; then writes the report into `out`
/// and returns its Markdown summary. `progress` hears (cases done, cases in the study) on the
/// calling thread. Stops on Ctrl-C between batches (what finished is kept in the journal).
pub fn run_study(
    study: &Study,
    out: &Path,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<String> {
    let todo = pending(study, out)?;
    let total = study.len();
    let mut done = total - todo.len();
    progress(done, total);
    run_cases(study, &todo, &mut |results| {
        journal::append(out, &results)?;
        done += results.len();
        progress(done, total);
        Ok(())
    })?;
    let (results, missing) = collected(study, out)?;
    debug_assert_eq!(missing, 0);
    write_report(study, &results, out)
}
