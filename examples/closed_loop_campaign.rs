//! The local method on rehearsed arms from example-robot-data (UR5, 6 dof; Panda, 7 dof) at
//! an operating point where every joint is fast, open loop and under PD tracking, with the
//! realistic true robot of `perturbid_rs::rehearsal::realistic_robot` (payload, link errors,
//! asymmetric Coulomb + Stribeck + viscous friction, 1 % ripple, 2^18 counts, torque noise, a
//! 1.5 ms torque delay, a 7 ms clock offset) over several seeds, and open loop with the delay
//! given to the identification (`FitOptions::torque_delay`): T* in units of its standard errors,
//! D*, H*, G* against the truth.
//!
//!     cargo run --release --example closed_loop_campaign [-- --seeds 5] [--out FILE]
//!
//! Needs example-robot-data (`pip install example-robot-data`). Prints a markdown table; with
//! `--out` writes it there (docs/closed_loop_campaign.md is this command's output).

use perturbid_rs::local::{IdentifyOptions, PlanOptions};
use perturbid_rs::rehearsal::{local_case, realistic_robot, Realism};
use perturbid_rs::{LoadOptions, Model, OperatingPoint};

fn arm(name: &str) -> Option<(Model, OperatingPoint)> {
    let root =
        std::path::PathBuf::from(std::env::var("EXAMPLE_ROBOT_DATA").ok().or_else(|| {
            let out = std::process::Command::new("python3")
                .args([
                    "-c",
                    "import sysconfig; print(sysconfig.get_paths()['purelib'])",
                ])
                .output()
                .ok()?;
            Some(format!(
                "{}/cmeel.prefix/share/example-robot-data/robots",
                String::from_utf8(out.stdout).ok()?.trim()
            ))
        })?);
    let mut options = LoadOptions::default();
    let (path, q, qd, qdd) = match name {
        "ur5" => (
            root.join("ur_description/urdf/ur5_robot.urdf"),
            vec![0.3, -1.0, 1.2, -0.8, 0.9, 0.4],
            vec![0.5, -0.4, 0.45, 0.6, -0.5, 0.55],
            vec![1.0, -0.8, 0.9, 1.2, -1.0, 0.7],
        ),
        _ => {
            options.lock.insert("panda_finger_joint1".into(), 0.0);
            (
                root.join("panda_description/urdf/panda.urdf"),
                vec![0.3, -0.5, 0.2, -2.0, 0.3, 1.6, 0.5],
                vec![0.5, -0.4, 0.45, 0.6, -0.5, 0.55, 0.4],
                vec![1.0, -0.8, 0.9, 1.2, -1.0, 0.7, 0.8],
            )
        }
    };
    let model = perturbid_rs::model_from_urdf_file(&path, &options).ok()?;
    Some((model, OperatingPoint::new(q, qd, qdd).ok()?))
}

fn main() -> perturbid_rs::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let seeds: u64 = value("--seeds").map_or(3, |s| s.parse().expect("--seeds N"));
    let mut lines = vec![
        "| arm | tracking | seeds | T* within 3 se | T* worst (se) | T* before correction, worst (se) | D* | H* | G* | D*, H*, G* within 3 se | combined D* | miss (perturbations) | advised combined | of which combined nearer |".to_string(),
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|".to_string(),
    ];
    for name in ["ur5", "panda"] {
        let Some((model, op)) = arm(name) else {
            eprintln!("skipped {name}: example-robot-data is not installed");
            continue;
        };
        for (bandwidth, read_past) in [(None, 0.0), (Some(25.0), 0.0), (None, 1.5e-3)] {
            let mut identify = IdentifyOptions::default();
            identify.fit.torque_delay = read_past;
            let mut rows = vec![];
            for seed in 0..seeds {
                let realism = Realism {
                    seed,
                    bandwidth,
                    ..Realism::default()
                };
                let robot = realistic_robot(&model, &op.q, &realism)?;
                let case = local_case(
                    &model,
                    &robot,
                    &op,
                    &PlanOptions::default(),
                    &identify,
                    0.007,
                )?;
                eprintln!(
                    "{name} {bandwidth:?} seed {seed} of {seeds}: T* in standard errors {:?}",
                    case.torque_errors
                        .iter()
                        .map(|x| (x * 10.0).round() / 10.0)
                        .collect::<Vec<_>>()
                );
                rows.push(case);
            }
            let t: Vec<f64> = rows
                .iter()
                .flat_map(|c| c.torque_errors.iter().map(|x| x.abs()))
                .collect();
            let raw: Vec<f64> = rows
                .iter()
                .flat_map(|c| {
                    let m = c.model.miss.as_ref().expect("a full plan");
                    let truth: Vec<f64> = (0..m.measured_torque.len())
                        .map(|j| c.model.torque[j] - c.torque_errors[j] * c.model.torque_stderr[j])
                        .collect();
                    (0..truth.len())
                        .map(move |j| {
                            ((m.measured_torque[j] - truth[j]) / m.measured_stderr[j]).abs()
                        })
                        .collect::<Vec<_>>()
                })
                .collect();
            let mean = |f: &dyn Fn(&perturbid_rs::rehearsal::LocalCase) -> f64| {
                rows.iter().map(f).sum::<f64>() / rows.len() as f64
            };
            let advised: Vec<_> = rows
                .iter()
                .filter(|c| {
                    c.model
                        .diagnostics
                        .warnings
                        .iter()
                        .any(|w| w.ends_with("trust it (estimator 'combined')"))
                })
                .collect();
            let worst = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
            lines.push(format!(
                "| {name} | {} | {} | {:.0} % | {:.1} | {:.1} | {:.1} % | {:.1} % | {:.1} % | {:.0} % | {:.1} % | {:.2} | {} | {} |",
                bandwidth.map_or("open loop".to_string(), |b| format!("PD {b:.0} Hz"))
                    + if read_past > 0.0 { ", delay read past" } else { "" },
                rows.len(),
                100.0 * t.iter().filter(|x| **x <= 3.0).count() as f64 / t.len() as f64,
                worst(&t),
                worst(&raw),
                100.0 * mean(&|c| c.relative[0]),
                100.0 * mean(&|c| c.relative[1]),
                100.0 * mean(&|c| c.relative[2]),
                100.0 * mean(&|c| (c.covered[0] + c.covered[1] + c.covered[2]) / 3.0),
                100.0 * mean(&|c| c.combined_relative[0]),
                mean(&|c| c.miss),
                advised.len(),
                advised.iter().filter(|c| c.combined_relative.iter().sum::<f64>() < c.relative.iter().sum::<f64>()).count(),
            ));
        }
    }
    let table = format!(
        "The local method on rehearsed arms (`cargo run --release --example closed_loop_campaign -- --seeds {seeds} --out docs/closed_loop_campaign.md` writes this file). Errors of T* in units of its standard errors (before the correction: the mean at the nominal crossings in units of its scatter's); D*, H*, G* relative to the true robot's expansion (Frobenius), averaged over the seeds; the share of their entries within 3 standard errors; the miss of the nominal passes in planned perturbations; how many runs advised the combined estimator, and in how many of those it was the nearer (summed relative errors of D, H, G).\n\n{}",
        lines.join("\n")
    );
    println!("{table}");
    if let Some(out) = value("--out") {
        std::fs::write(&out, format!("{table}\n"))
            .map_err(|e| perturbid_rs::Error::invalid(out, e.to_string()))?;
    }
    Ok(())
}
