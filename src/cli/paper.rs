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
}

pub(crate) fn run(a: PaperArgs) -> Result<String> {
    let progress = Progress::new();
    let mut step = |s: &str| progress.update(s);
    let r = reproduce(
        &PaperOptions {
            seed: a.seed,
            torque_noise: a.noise,
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
        ("direct, globally linearised", &r.d_global_linear),
        ("direct, base parameters", &r.d_base_parameters),
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
    let _ = writeln!(
        out,
        "\nwrote {} files to {}, report: {}",
        files.len(),
        a.out.display(),
        a.out.join("report.md").display()
    );
    Ok(out)
}
