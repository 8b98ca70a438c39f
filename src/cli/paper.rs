//! `perturbid paper --out DIR`.

use std::fmt::Write;
use std::path::PathBuf;

use clap::Args;

use super::progress::Progress;
use crate::error::Result;
use crate::paper::{reproduce, write_report, PaperOptions};

#[derive(Args)]
pub(crate) struct PaperArgs {
    /// Output folder for report.md, the tables (CSV), results.json and the figures (SVG).
    #[arg(long, default_value = "paper")]
    out: PathBuf,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Torque noise of the simulated measurements (N m; the paper's simulation has none).
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Excitation seeds of the direct method: Table 3's direct rows and Figs. 3-5 give the
    /// median and the range over them.
    #[arg(long, default_value_t = 10)]
    excitation_seeds: usize,
    /// Leave out the built-in study ("when to use which method", about a minute on 2 cores).
    #[arg(long)]
    no_study: bool,
}

pub(crate) fn run(a: PaperArgs) -> Result<String> {
    let progress = Progress::new();
    let mut step = |s: &str| progress.update(s);
    let r = reproduce(
        &PaperOptions {
            seed: a.seed,
            torque_noise: a.noise,
            excitation_seeds: a.excitation_seeds,
            study: !a.no_study,
            ..PaperOptions::default()
        },
        &mut step,
    )?;
    progress.update("writing the report");
    let files = write_report(&r, &a.out)?;
    progress.done();
    let mut out = String::from("Kinsheel & Taha (2010) on the built-in A465 (kinsheel2010), gravity and friction excluded\n\n");
    let _ = writeln!(out, "Table 2   {:>10} {:>10}", "T* ident.", "Tn paper");
    for j in 0..r.torque_identified.len() {
        let _ = writeln!(
            out,
            "joint {}   {:>10.4} {:>10.4}",
            j + 1,
            r.torque_identified[j],
            r.torque_paper[j]
        );
    }
    let _ = writeln!(
        out,
        "\nTable 3 (first column of D)      D11     D21     D31     D41     D51     D61"
    );
    for (name, v) in [
        ("actual M(q*)", &r.d_actual),
        ("perturbation, identified", &r.d_perturbation),
        ("perturbation, paper", &r.d_perturbation_paper),
        ("direct, glob. lin. (median)", &r.d_global_linear),
        ("direct, base param. (median)", &r.d_base_parameters),
        ("direct, paper", &r.d_direct_paper),
    ] {
        let _ = writeln!(
            out,
            "{name:<30} {}",
            v.iter()
                .map(|&x| format!("{:>7}", crate::paper::markdown::number(x, 3)))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    for d in &r.direct {
        let _ = writeln!(
            out,
            "D11 globally linearised over {} excitations {}: {:.2} to {:.2}",
            d.seeds.len(),
            if d.excitation == "default" {
                "within the joint limits"
            } else {
                "within q* +- 0.5 rad"
            },
            d.d_global_linear.min[0],
            d.d_global_linear.max[0]
        );
    }
    if r.study.is_some() {
        let _ = writeln!(
            out,
            "report.md ends with 'When to use which method', from a built-in study (study.toml)"
        );
    }
    let _ = writeln!(
        out,
        "\nwrote {} files to {}, report: {}",
        files.len(),
        a.out.display(),
        a.out.join("report.md").display()
    );
    Ok(out)
}
