//! The study's outputs from its journal: the tidy results table (one row per case, method,
//! metric and distance), the summary (median and 90 % interval over points and seeds), a
//! Markdown summary and the figure of error against distance.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::case::CaseResult;
use super::plan::Study;
use crate::error::Result;
use crate::io::{csv_text, OutputSet};

/// The columns of results.csv.
pub const RESULT_COLUMNS: [&str; 16] = [
    "case",
    "case_id",
    "robot",
    "point",
    "speed_class",
    "true_robot",
    "noise",
    "design",
    "k",
    "perturbation",
    "seed",
    "method",
    "metric",
    "distance",
    "value",
    "note",
];

/// The tidy rows of `results` (in case order), as text fields in [`RESULT_COLUMNS`] order.
pub fn rows(study: &Study, results: &[CaseResult]) -> Result<Vec<Vec<String>>> {
    let mut out = Vec::new();
    for r in results {
        let c = study.case(r.index)?;
        let robot = &study.robots[c.robot];
        let point = &robot.points[c.point];
        for m in &r.measures {
            out.push(vec![
                r.index.to_string(),
                r.id.clone(),
                robot.name.clone(),
                point.name.clone(),
                point.speed_class.clone(),
                study.true_robots[c.true_robot].0.clone(),
                c.noise.map_or(String::new(), |v| format!("{v}")),
                c.design.name().to_string(),
                c.k.map_or(String::new(), |v| v.to_string()),
                format!("{}", c.perturbation),
                c.seed.to_string(),
                m.method.name().to_string(),
                m.metric.clone(),
                m.distance.map_or(String::new(), |v| format!("{v}")),
                format!("{}", m.value),
                m.note.clone().unwrap_or_default(),
            ]);
        }
    }
    Ok(out)
}

/// One line of the summary: a group and its statistics over points and seeds.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SummaryRow {
    /// robot, speed_class, true_robot, noise, design, k, perturbation, method, metric, distance
    pub group: Vec<String>,
    pub count: usize,
    pub median: f64,
    pub p05: f64,
    pub p95: f64,
}

/// The columns of summary.csv.
pub const SUMMARY_COLUMNS: [&str; 14] = [
    "robot",
    "speed_class",
    "true_robot",
    "noise",
    "design",
    "k",
    "perturbation",
    "method",
    "metric",
    "distance",
    "count",
    "median",
    "p05",
    "p95",
];

/// Quantile `p` of sorted `v` (linear interpolation).
pub fn quantile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let x = p * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < v.len() {
        v[i] * (1.0 - f) + v[i + 1] * f
    } else {
        v[i]
    }
}

/// The summary of tidy `rows`: per group (every column but case, point, seed, value), the
/// count, the median and the 5 % and 95 % quantiles. Failures are counted as their own metric.
pub fn summarise(rows: &[Vec<String>]) -> Vec<SummaryRow> {
    let mut groups: BTreeMap<Vec<String>, Vec<f64>> = BTreeMap::new();
    for r in rows {
        // robot, speed_class, true_robot, noise, design, k, perturbation, method, metric, distance
        let key: Vec<String> = [2, 4, 5, 6, 7, 8, 9, 11, 12, 13]
            .iter()
            .map(|&i| r[i].clone())
            .collect();
        let v: f64 = r[14].parse().unwrap_or(f64::NAN);
        if v.is_finite() {
            groups.entry(key).or_default().push(v);
        }
    }
    groups
        .into_iter()
        .map(|(group, mut v)| {
            v.sort_by(f64::total_cmp);
            SummaryRow {
                group,
                count: v.len(),
                median: quantile(&v, 0.5),
                p05: quantile(&v, 0.05),
                p95: quantile(&v, 0.95),
            }
        })
        .collect()
}

/// Writes results.csv, summary.csv, summary.md, error_vs_distance.svg and study.json into
/// `out` as one output set. Returns the Markdown summary.
pub fn write(study: &Study, results: &[CaseResult], out: &Path) -> Result<String> {
    let rows = rows(study, results)?;
    let summary = summarise(&rows);
    let mut set = OutputSet::new(out, "study");
    set.add("results.csv", csv_text(&RESULT_COLUMNS, &rows))?;
    set.add(
        "summary.csv",
        csv_text(
            &SUMMARY_COLUMNS,
            summary.iter().map(|s| {
                s.group.iter().cloned().chain([
                    s.count.to_string(),
                    format!("{}", s.median),
                    format!("{}", s.p05),
                    format!("{}", s.p95),
                ])
            }),
        ),
    )?;
    let md = markdown(study, &summary, results.len());
    set.add("summary.md", md.clone())?;
    set.add("error_vs_distance.svg", figure(&summary))?;
    set.add(
        "study.json",
        serde_json::to_string_pretty(&study.config).expect("serialisable"),
    )?;
    set.commit()?;
    Ok(md)
}

/// The Markdown summary: per speed class and true robot, the relative RMS error of each
/// method by distance (median [5 %, 95 %]), then D, H, G errors and robot time.
fn markdown(study: &Study, summary: &[SummaryRow], cases: usize) -> String {
    let mut md = format!(
        "# Study '{}'\n\n{cases} cases of {}; medians with the 5-95 % range over points and seeds.\n",
        study.config.name,
        study.len()
    );
    let mut sections: BTreeMap<Vec<String>, Vec<&SummaryRow>> = BTreeMap::new();
    for s in summary {
        // everything but method, metric, distance
        sections.entry(s.group[..7].to_vec()).or_default().push(s);
    }
    let cell = |s: &SummaryRow| format!("{:.3} [{:.3}, {:.3}]", s.median, s.p05, s.p95);
    for (key, rows) in sections {
        let _ =
            writeln!(
            md,
            "\n## {} / speed {} / true robot {} / noise {} / {} design, K {}, perturbation x{}\n",
            key[0],
            key[1],
            key[2],
            if key[3].is_empty() { "as documented" } else { &key[3] },
            key[4],
            if key[5].is_empty() { "default" } else { &key[5] },
            key[6]
        );
        let mut distances: Vec<String> = rows
            .iter()
            .filter(|r| r.group[8] == "rms_rel")
            .map(|r| r.group[9].clone())
            .collect();
        distances.sort_by(|a, b| {
            a.parse::<f64>()
                .unwrap_or(0.0)
                .total_cmp(&b.parse().unwrap_or(0.0))
        });
        distances.dedup();
        let mut methods: Vec<&str> = rows.iter().map(|r| r.group[7].as_str()).collect();
        methods.dedup();
        methods.sort();
        methods.dedup();
        let extra = ["D_rel", "H_rel", "G_rel", "robot_time", "failed"];
        let _ = write!(md, "| method |");
        for d in &distances {
            let _ = write!(md, " RMS error at {d} |");
        }
        for e in extra {
            let _ = write!(md, " {e} |");
        }
        let _ = write!(md, "\n|---|");
        for _ in 0..distances.len() + extra.len() {
            let _ = write!(md, "---|");
        }
        md.push('\n');
        for m in methods {
            let _ = write!(md, "| {m} |");
            let find = |metric: &str, dist: &str| {
                rows.iter()
                    .find(|r| r.group[7] == m && r.group[8] == metric && r.group[9] == dist)
            };
            for d in &distances {
                let _ = write!(
                    md,
                    " {} |",
                    find("rms_rel", d).map_or("-".into(), |s| cell(s))
                );
            }
            for e in extra {
                let text = match (e, find(e, "")) {
                    ("failed", Some(s)) => s.count.to_string(),
                    ("failed", None) => "0".into(),
                    (_, Some(s)) => cell(s),
                    (_, None) => "-".into(),
                };
                let _ = write!(md, " {text} |");
            }
            md.push('\n');
        }
    }
    md.push_str(
        "\nRMS error: RMS of predicted minus true torque over the evaluation states at that \
distance from P (multiples of the perturbation size), relative to the RMS of the true torque \
change from P. D_rel, H_rel, G_rel: relative Frobenius error of the model's D, H, G at P \
against the true plant's. robot_time: seconds of motion the method's experiments took.\n",
    );
    md
}

/// (distance, median, 5 %, 95 %) points of one method's curve.
type Curve = Vec<(f64, f64, f64, f64)>;

/// Median relative RMS error against distance on a log axis, one curve per method and
/// section, each with its 5-95 % interval over points and seeds shaded around it.
fn figure(summary: &[SummaryRow]) -> String {
    let colors = [
        "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
    ];
    let dashes = ["", "6,3", "2,2", "8,2,2,2", "4,4", "1,3"];
    let mut curves: BTreeMap<(Vec<String>, String), Curve> = BTreeMap::new();
    for s in summary.iter().filter(|s| s.group[8] == "rms_rel") {
        let d: f64 = s.group[9].parse().unwrap_or(f64::NAN);
        curves
            .entry((s.group[..7].to_vec(), s.group[7].clone()))
            .or_default()
            .push((d, s.median, s.p05, s.p95));
    }
    let mut sections: BTreeMap<Vec<String>, Vec<(String, Curve)>> = BTreeMap::new();
    for ((section, method), mut pts) in curves {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        sections.entry(section).or_default().push((method, pts));
    }
    let panels: Vec<String> = sections
        .iter()
        .map(|(key, methods)| {
            // per method: x, median, 5 %, 95 %
            let data: Vec<(String, [Vec<f64>; 4])> = methods
                .iter()
                .map(|(m, pts)| {
                    let column = |f: fn(&(f64, f64, f64, f64)) -> f64| pts.iter().map(f).collect();
                    (
                        m.clone(),
                        [
                            column(|p| p.0),
                            column(|p| p.1),
                            column(|p| p.2),
                            column(|p| p.3),
                        ],
                    )
                })
                .collect();
            let series: Vec<crate::svg::Series<'_>> = data
                .iter()
                .enumerate()
                .map(|(i, (m, [x, y, low, high]))| crate::svg::Series {
                    name: m,
                    color: colors[i % colors.len()],
                    dash: dashes[i % dashes.len()],
                    x,
                    y,
                    band: Some([low, high]),
                })
                .collect();
            // the methods' errors lie orders of magnitude apart: decades
            crate::svg::scaled_plot(
                &format!("{} / speed {} / true robot {}", key[0], key[1], key[2]),
                "distance from P (perturbation sizes)",
                "relative RMS error: median, 5-95 % shaded",
                &series,
                crate::svg::Scale::Log,
            )
        })
        .collect();
    crate::svg::stack(&panels)
}
