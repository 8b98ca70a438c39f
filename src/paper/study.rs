//! The small built-in study of the paper's report ("when to use which method"): the A465 at
//! the paper's point and at sampled slow and fast points, on three true robots (the ideal
//! one, one whose effects the base-parameter model can represent, one with effects it
//! cannot), over seeds. About a minute on 2 cores; `perturbid study` runs the same file
//! (`perturbid paper` writes it as `study.toml` beside the report).

use serde::Serialize;

use crate::error::Result;
use crate::study::{quantile, rows, run_cases, Study, StudyConfig};

/// The study, as the TOML a user would write.
pub const PAPER_STUDY: &str = r#"name = "when to use which method (A465)"
seeds = 8
methods = ["local_separated", "local_friction_aware", "direct_wls", "global_linear"]

[[robots]]
name = "a465"

[[points]]                   # Kinsheel & Taha (2010), Table 2: a slow point
name = "paper"
q = [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0]
qd = [0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140]
qdd = [-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710]

[sample_points]
count = 2
speed_classes = ["slow", "fast"]

[[true_robots]]
name = "ideal"               # the model itself: gravity excluded, no friction, no noise

[[true_robots]]
name = "modelled_effects"    # viscous and Coulomb friction and a payload: within the base model
document = { gravity = false, payload = { link = "link6", mass = 1.0, com = [0.0, 0.0, 0.06], inertia = [0.002, 0, 0, 0.002, 0, 0.001] }, friction = { viscous = [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], coulomb = [1.0, 0.8, 0.6, 0.4, 0.2, 0.1] }, sensors = { torque_noise = [0.02, 0.02, 0.02, 0.01, 0.01, 0.01] } }

[[true_robots]]
name = "unmodelled_effects"  # Stribeck friction, position-dependent friction, torque ripple
document = { gravity = false, friction = { viscous = [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], coulomb = [1.0, 0.8, 0.6, 0.4, 0.2, 0.1], stribeck = [1.0, 0.8, 0.6, 0.4, 0.2, 0.1], stribeck_velocity = [0.05, 0.05, 0.05, 0.05, 0.05, 0.05], position = [[{ order = 3, amplitude = 0.5 }], [{ order = 3, amplitude = 0.4 }], [{ order = 3, amplitude = 0.3 }], [{ order = 3, amplitude = 0.2 }], [{ order = 3, amplitude = 0.1 }], [{ order = 3, amplitude = 0.05 }]] }, ripple = [[{ order = 2, amplitude = 0.03 }], [{ order = 2, amplitude = 0.03 }], [{ order = 2, amplitude = 0.03 }], [{ order = 2, amplitude = 0.03 }], [{ order = 2, amplitude = 0.03 }], [{ order = 2, amplitude = 0.03 }]], sensors = { torque_noise = [0.02, 0.02, 0.02, 0.01, 0.01, 0.01] } }

[direct]                     # the paper's excitation, as much robot time as the local plan
harmonics = 10
base_frequency = 0.05
max_evaluations = 200

[evaluation]
distances = [0.5, 1, 2, 4]
samples = 16
"#;

/// One line of the study's table: a method in a group, `rms_rel` by distance (median, 5 %,
/// 95 %), and how often it failed.
#[derive(Clone, Debug, Serialize)]
pub struct StudyLine {
    pub true_robot: String,
    pub speed_class: String,
    pub method: String,
    /// (distance, median, p05, p95) of the relative RMS error.
    pub rms_rel: Vec<(f64, f64, f64, f64)>,
    /// (median, p05, p95) of the relative error of H at P.
    pub h_rel: Option<(f64, f64, f64)>,
    pub cases: usize,
    pub failed: usize,
}

/// Runs the built-in study (every core); `progress` hears cases done and the total.
pub fn when_to_use(progress: &mut dyn FnMut(usize, usize)) -> Result<Vec<StudyLine>> {
    let config: StudyConfig = crate::io::config::parse_toml("built-in study", PAPER_STUDY)?;
    let study = Study::resolve(config, std::path::Path::new("."), "built-in study")?;
    let indices: Vec<usize> = (0..study.len()).collect();
    let mut results = Vec::new();
    let total = study.len();
    run_cases(&study, &indices, &mut |batch| {
        results.extend(batch);
        progress(results.len(), total);
        Ok(())
    })?;
    let table = rows(&study, &results)?;
    // columns: 4 speed_class, 5 true_robot, 11 method, 12 metric, 13 distance, 14 value
    let mut groups: std::collections::BTreeMap<(String, String, String), Vec<&Vec<String>>> =
        Default::default();
    for r in &table {
        groups
            .entry((r[5].clone(), r[4].clone(), r[11].clone()))
            .or_default()
            .push(r);
    }
    let mut out = Vec::new();
    for ((true_robot, speed_class, method), rs) in groups {
        let stats = |metric: &str, distance: &str| -> Option<(f64, f64, f64)> {
            let mut v: Vec<f64> = rs
                .iter()
                .filter(|r| r[12] == metric && r[13] == distance)
                .filter_map(|r| r[14].parse().ok())
                .collect();
            v.sort_by(f64::total_cmp);
            (!v.is_empty()).then(|| (quantile(&v, 0.5), quantile(&v, 0.05), quantile(&v, 0.95)))
        };
        let rms_rel = study
            .config
            .evaluation
            .distances
            .iter()
            .filter_map(|d| stats("rms_rel", &format!("{d}")).map(|(m, a, b)| (*d, m, a, b)))
            .collect();
        let cases: std::collections::BTreeSet<&str> = rs.iter().map(|r| r[0].as_str()).collect();
        out.push(StudyLine {
            true_robot,
            speed_class,
            method,
            rms_rel,
            h_rel: stats("H_rel", ""),
            cases: cases.len(),
            failed: rs.iter().filter(|r| r[12] == "failed").count(),
        });
    }
    Ok(out)
}
