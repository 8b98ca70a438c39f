//! A log's velocity columns against the derivative of its positions, and a log's acceleration
//! columns (taken as logged) against the derivative of its velocities: refused where they are
//! in other units, of the opposite sign, another joint's or unrelated, naming the joints; small
//! scale errors, a filtered estimate's lag, noise and a still joint pass, as does the real Panda
//! log. The command line and the local method's recorded derivatives refuse such a log.

mod common;

use common::{a465_log, panda_log, A465Log};
use perturbid_rs::logs::derivative_columns::check_logged_derivatives;
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::{ErrorKind, Recording};

/// The log with its velocities edited by `edit` (row-major, 6 a sample), preprocessed.
fn preprocessed(log: &A465Log, edit: impl Fn(&mut Vec<f64>)) -> perturbid_rs::Result<Recording> {
    let t: Vec<f64> = (0..log.q.len() / 6).map(|i| i as f64 * 1e-3).collect();
    let mut qd = log.qd.clone();
    edit(&mut qd);
    let rec = Recording::new(
        "log.csv",
        6,
        t,
        log.q.clone(),
        log.tau.clone(),
        Some(qd),
        None,
    )?;
    preprocess(&rec, &PreprocessOptions::default())
}

fn column(qd: &mut [f64], j: usize, mut f: impl FnMut(f64) -> f64) {
    qd.iter_mut().skip(j).step_by(6).for_each(|v| *v = f(*v));
}

#[test]
fn velocities_that_are_not_the_positions_derivative_are_refused_by_joint() {
    let log = a465_log();
    preprocessed(&log, |_| {}).unwrap();
    let refused = |edit: &dyn Fn(&mut Vec<f64>), says: &[&str]| {
        let Err(e) = preprocessed(&log, edit) else {
            panic!("accepted")
        };
        assert_eq!(e.kind(), ErrorKind::Input, "{e}");
        let e = e.to_string();
        assert!(
            e.starts_with("log.csv: logged velocities that are not"),
            "{e}"
        );
        for s in says {
            assert!(e.contains(s), "'{s}' not in {e}");
        }
        e
    };
    refused(
        &|qd| qd.iter_mut().for_each(|v| *v = v.to_degrees()),
        &[
            "joints 1, 2, 3, 4, 5, 6: 57.296 times",
            "degrees per second read as rad/s",
        ],
    );
    let e = refused(
        &|qd| column(qd, 3, |v| -v),
        &["joint 4: the opposite sign of its positions' derivative (scale -1.000)"],
    );
    assert!(!e.contains("joint 1") && !e.contains("joints"), "{e}");
    refused(
        &|qd| {
            for s in 0..qd.len() / 6 {
                qd.swap(s * 6 + 1, s * 6 + 2);
            }
        },
        &[
            "joint 2: follows the positions of joint 3",
            "joint 3: follows the positions of joint 2",
            "columns swapped or mislabelled",
        ],
    );
    // a motor-side velocity before a 100:1 gear
    refused(
        &|qd| column(qd, 0, |v| 100.0 * v),
        &["joint 1: 100.000 times"],
    );
    // joint 5's column holds its position
    let q5: Vec<f64> = log.q.iter().skip(4).step_by(6).copied().collect();
    refused(
        &|qd| {
            for (s, v) in q5.iter().enumerate() {
                qd[s * 6 + 4] = *v;
            }
        },
        &["joint 5: follows no joint's positions"],
    );
}

#[test]
fn a_velocity_estimate_slightly_off_late_or_of_a_still_joint_passes() {
    let log = a465_log();
    // 5 % off and 10 ms late (a drive's filtered estimate)
    preprocessed(&log, |qd| {
        let late: Vec<f64> = (0..qd.len()).map(|i| qd[i.saturating_sub(60)]).collect();
        *qd = late.iter().map(|v| 1.05 * v).collect();
    })
    .unwrap();
    // joint 6 held still, its velocity column noise
    let mut still = A465Log {
        q: log.q.clone(),
        qd: log.qd.clone(),
        qdd: log.qdd.clone(),
        tau: log.tau.clone(),
    };
    let first = still.q[5];
    column(&mut still.q, 5, |_| first);
    let noise: Vec<f64> = {
        let mut rng = common::Rng(4);
        (0..still.q.len() / 6)
            .map(|_| 1e-4 * rng.uniform(-1.0, 1.0))
            .collect()
    };
    preprocessed(&still, |qd| {
        for (s, v) in noise.iter().enumerate() {
            qd[s * 6 + 5] = *v;
        }
    })
    .unwrap();
}

/// A slow joint (1 % of its motion) read in coarse counts (2e-3 rad): its positions'
/// derivative is mostly rounding noise, and its exact logged velocity is not taken for
/// unrelated (nor at 0.2 % of the motion in 5e-3 rad counts, tried by hand).
#[test]
fn a_slow_joint_in_coarse_counts_passes() {
    let log = a465_log();
    let mut slow = A465Log {
        q: log.q.clone(),
        qd: log.qd.clone(),
        qdd: log.qdd.clone(),
        tau: log.tau.clone(),
    };
    let k = slow.q.len() / 6;
    let mean = (0..k).map(|s| log.q[s * 6 + 5]).sum::<f64>() / k as f64;
    for s in 0..k {
        let q = mean + 0.01 * (log.q[s * 6 + 5] - mean);
        slow.q[s * 6 + 5] = (q / 2e-3).round() * 2e-3;
        slow.qd[s * 6 + 5] = 0.01 * log.qd[s * 6 + 5];
    }
    preprocessed(&slow, |_| {}).unwrap();
}

#[test]
fn the_real_panda_logs_velocities_pass() {
    let Some(rec) = panda_log() else { return };
    assert!(rec.qd.is_some());
    preprocess(&rec, &PreprocessOptions::default()).unwrap();
}

/// The log as logged at 1 kHz with its velocities and accelerations, edited by `edit`
/// (row-major, 6 a sample).
fn logged(log: &A465Log, edit: impl Fn(&mut Vec<f64>, &mut Vec<f64>)) -> Recording {
    let t: Vec<f64> = (0..log.q.len() / 6).map(|i| i as f64 * 1e-3).collect();
    let (mut qd, mut qdd) = (log.qd.clone(), log.qdd.clone());
    edit(&mut qd, &mut qdd);
    Recording::new(
        "log.csv",
        6,
        t,
        log.q.clone(),
        log.tau.clone(),
        Some(qd),
        Some(qdd),
    )
    .unwrap()
}

#[test]
fn logged_accelerations_that_are_not_the_velocities_derivative_are_refused() {
    let log = a465_log();
    check_logged_derivatives(&logged(&log, |_, _| {})).unwrap();
    let refused = |edit: &dyn Fn(&mut Vec<f64>, &mut Vec<f64>), says: &[&str]| {
        let e = check_logged_derivatives(&logged(&log, edit)).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Input, "{e}");
        let e = e.to_string();
        assert!(e.contains("log.csv"), "{e}");
        for s in says {
            assert!(e.contains(s), "{s}: {e}");
        }
    };
    refused(
        &|qd, _| column(qd, 1, |v| v.to_degrees()),
        &[
            "logged velocities that are not their positions' derivative (rad/s or m/s)",
            "joint 2: 57.296 times its positions' derivative: degrees per second read as rad/s",
        ],
    );
    refused(
        &|_, qdd| column(qdd, 1, |v| v.to_degrees()),
        &[
            "logged accelerations that are not their velocities' derivative (rad/s^2 or m/s^2)",
            "joint 2: 57.296 times its velocities' derivative: degrees per second squared read as rad/s^2",
            "--preprocess",
        ],
    );
    refused(
        &|_, qdd| {
            for s in 0..qdd.len() / 6 {
                qdd.swap(s * 6 + 2, s * 6 + 3);
            }
        },
        &[
            "joint 3: follows the velocities of joint 4",
            "joint 4: follows the velocities of joint 3",
        ],
    );
    refused(
        &|_, qdd| {
            let mut i = 0.0f64;
            column(qdd, 0, |_| {
                i += 1.0;
                (i * 0.017f64).cos()
            })
        },
        &["joint 1: follows no joint's velocities"],
    );
    refused(
        &|_, qdd| column(qdd, 4, |v| -v),
        &["joint 5: the opposite sign of its velocities' derivative"],
    );
    refused(
        &|_, qdd| column(qdd, 0, |_| 0.0),
        &["joint 1: reads 0 throughout while its velocities change"],
    );
    // found in the stretch after a gap of 2 s, too
    let mut gapped = logged(&log, |_, qdd| column(qdd, 1, |v| v.to_degrees()));
    for t in gapped.t.iter_mut().skip(6000) {
        *t += 2.0;
    }
    let e = check_logged_derivatives(&gapped).unwrap_err().to_string();
    assert!(e.contains("joint 2: 57.296"), "{e}");
}

#[test]
fn logged_accelerations_with_noise_lag_or_small_errors_pass() {
    let log = a465_log();
    let mut rng = common::Rng(7);
    let noise: Vec<f64> = (0..log.q.len()).map(|_| rng.uniform(-1.0, 1.0)).collect();
    // velocities with 0.02 rad/s of noise, accelerations 5 % off and 10 ms late with 1 rad/s^2
    check_logged_derivatives(&logged(&log, |qd, qdd| {
        for (v, e) in qd.iter_mut().zip(&noise) {
            *v += 0.02 * e;
        }
        let late: Vec<f64> = (0..qdd.len()).map(|i| qdd[i.saturating_sub(60)]).collect();
        *qdd = late
            .iter()
            .zip(noise.iter().rev())
            .map(|(a, e)| 1.05 * a + e)
            .collect();
    }))
    .unwrap();
    // too short to filter: not judged
    let short = logged(&log, |_, qdd| column(qdd, 1, |v| v.to_degrees()));
    let few = Recording::new(
        "few",
        6,
        short.t[..500].to_vec(),
        short.q[..3000].to_vec(),
        short.tau[..3000].to_vec(),
        Some(short.qd.as_ref().unwrap()[..3000].to_vec()),
        Some(short.qdd.as_ref().unwrap()[..3000].to_vec()),
    )
    .unwrap();
    check_logged_derivatives(&few).unwrap();
}

/// The command line takes a log with acceleration columns as logged: one in deg/s^2 is refused
/// naming the file (and identified, preprocessed on request, where the accelerations are
/// derived again).
#[test]
fn the_command_line_refuses_a_log_whose_accelerations_are_not_the_velocities_derivative() {
    let dir = std::env::temp_dir().join(format!(
        "perturbid-derivative-columns-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let log = a465_log();
    let rec = logged(&log, |_, qdd| column(qdd, 1, |v| v.to_degrees()));
    let path = dir.join("degrees.csv");
    perturbid_rs::logs::save_recording(&rec, &path).unwrap();
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_perturbid"))
            .args(["identify-direct", "a465", path.to_str().unwrap(), "--out"])
            .arg(dir.join("model.json"))
            .args(extra)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (success, stderr) = run(&[]);
    assert!(!success, "{stderr}");
    assert!(
        stderr.contains("degrees.csv")
            && stderr.contains("joint 2: 57.296 times its velocities' derivative"),
        "{stderr}"
    );
    assert!(!dir.join("model.json").exists());
    let (success, stderr) = run(&["--preprocess"]);
    assert!(success, "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The local method reads a recording's own velocities and accelerations on request
/// (`recorded_derivatives`): one whose accelerations are in deg/s^2 is refused, naming it.
#[test]
fn recorded_derivatives_of_the_local_method_are_checked() {
    use perturbid_rs::local::{identify_local, FitOptions, IdentifyOptions};
    let (plan, mut recordings) = common::a465_noisy_runs();
    let options = IdentifyOptions {
        fit: FitOptions {
            recorded_derivatives: true,
            ..FitOptions::default()
        },
        ..IdentifyOptions::default()
    };
    // the planned velocities and accelerations logged beside the simulated positions
    for (r, e) in recordings.iter_mut().zip(&plan.experiments) {
        let planned = e.trajectory.sample(plan.rate);
        assert_eq!(planned.t, r.t);
        r.qd = Some(planned.qd);
        r.qdd = Some(planned.qdd);
    }
    identify_local(&plan, &recordings, &options).unwrap();
    let d = recordings
        .iter_mut()
        .find(|r| r.experiment.as_deref() == Some("D"))
        .unwrap();
    column(d.qdd.as_mut().unwrap(), 2, |v| v.to_degrees());
    let name = d.name.clone();
    let e = identify_local(&plan, &recordings, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&name)
            && e.contains("joint 3: 57.3")
            && e.contains("times its velocities' derivative")
            && e.contains("without recorded_derivatives"),
        "{e}"
    );
}
