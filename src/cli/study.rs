//! `perturbid study STUDY.toml`: a study on every core of this machine, resumable.

use std::path::PathBuf;

use super::progress::Progress;
use crate::error::{Error, Result};
use crate::study::{run_study, Study};

#[derive(clap::Args)]
pub(crate) struct StudyArgs {
    /// The study: a TOML file (docs/study.md).
    study: PathBuf,
    /// Output folder: results.csv (one row per case, method, metric and distance),
    /// summary.csv and summary.md (medians and 90 % intervals), error_vs_distance.svg,
    /// study.json, and the journal cases.jsonl that makes a rerun skip finished cases.
    #[arg(long, default_value = "study")]
    out: PathBuf,
    /// A Dask scheduler's address (tcp://host:8786): the cases run on its cluster. Needs the
    /// Python package (the `perturbid` that pip installs) with dask.distributed.
    #[arg(long)]
    scheduler: Option<String>,
    /// Worker threads on this machine (default: every core).
    #[arg(long)]
    threads: Option<usize>,
}

pub(crate) fn run(a: StudyArgs) -> Result<String> {
    if a.scheduler.is_some() {
        return Err(Error::invalid(
            "--scheduler",
            "this perturbid was built without Python; a Dask cluster is reached through the Python package: pip install 'perturbid_rs[dask]', then run the perturbid it installs, or perturbid_rs.study(..., client=Client(ADDRESS))",
        ));
    }
    let study = Study::from_file(&a.study)?;
    let total = study.len();
    let progress = Progress::counted(total as u64, "cases");
    let mut report = |done: usize, _: usize| progress.set_position(done as u64);
    let resumable = |e: Error| match e {
        Error::Interrupted { .. } => Error::Interrupted {
            context: format!(
                "study (the finished cases are in {}; the same command resumes)",
                crate::study::journal::path(&a.out).display()
            ),
        },
        e => e,
    };
    let md = match a.threads {
        Some(0) => return Err(Error::invalid("--threads", "0; expected at least 1")),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| Error::invalid("--threads", e.to_string()))?
            .install(|| run_study(&study, &a.out, &mut report))
            .map_err(resumable)?,
        None => run_study(&study, &a.out, &mut report).map_err(resumable)?,
    };
    progress.done();
    Ok(format!(
        "{md}\nwrote results.csv, summary.csv, summary.md, error_vs_distance.svg to {}\n",
        a.out.display()
    ))
}
