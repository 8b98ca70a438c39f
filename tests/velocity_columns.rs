//! A log's velocity columns against the derivative of its positions: refused where they are in
//! other units, of the opposite sign, another joint's or unrelated, naming the joints; small
//! scale errors, a filtered estimate's lag and a still joint pass, as does the real Panda log.

mod common;

use common::{a465_log, panda_log, A465Log};
use perturbid_rs::preprocess::{preprocess, PreprocessOptions};
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
