//! Time stamps that jitter while the samples were taken on a regular clock (src/logs/stamp_jitter.rs):
//! found from the positions, which lie on a smooth curve against the sample count and not
//! against the stamps; a log sampled irregularly and stamped right, a regular one, encoder
//! counts and the real Panda log (whose positions' noise hides its stamps' scatter) are left
//! alone; preprocess keeps the finding (the harm it warns of: tests/python/test_direct_method.py).

mod common;

use common::{a465_excitation, a465_noisy_log, normal, panda_log, Rng};
use perturbid_rs::logs::preprocess::PreprocessOptions;
use perturbid_rs::logs::stamp_jitter::{find_stamp_jitter, warning, ROUGHER};
use perturbid_rs::Recording;

const N: usize = 6;

/// The A465's test excitation sampled every millisecond for 12 s, its positions in encoder
/// counts of 2^20 a turn and its torques with friction and 0.03 N m of noise, stamped at the
/// samples' times plus a white jitter of `jitter` s (kept in order).
fn log(jitter: f64) -> Recording {
    let model = perturbid_rs::robots::a465::model("physical").unwrap();
    let mut rng = Rng(11);
    let traj = a465_excitation(&mut rng);
    let t: Vec<f64> = (0..12_000).map(|i| i as f64 * 1e-3).collect();
    let s = traj.sample(&t);
    let tau = common::torques_with_friction(&model, &s, &mut rng, |r| 0.03 * normal(r));
    let count = 2f64.powi(20) / (2.0 * std::f64::consts::PI);
    let q = s.q.iter().map(|x| (x * count).round() / count).collect();
    let stamps = t.iter().map(|t| t + jitter * normal(&mut rng)).collect();
    Recording::new("log", N, stamps, q, tau, None, None).unwrap()
}

/// The finding's ratio computed here, independently: per joint, the mean distance of each
/// position from the straight line through its neighbours against the stamps over that
/// against the sample count; the largest.
fn ratio(rec: &Recording) -> f64 {
    (0..N)
        .map(|j| {
            let q = |i: usize| rec.q[i * N + j];
            let (mut a, mut b) = (0.0, 0.0);
            for i in 1..rec.len() - 1 {
                let (t0, t1, t2) = (rec.t[i - 1], rec.t[i], rec.t[i + 1]);
                let line = q(i - 1) + (q(i + 1) - q(i - 1)) * (t1 - t0) / (t2 - t0);
                a += (q(i) - line).abs();
                b += (q(i) - 0.5 * (q(i - 1) + q(i + 1))).abs();
            }
            a / b
        })
        .fold(0.0, f64::max)
}

#[test]
fn stamps_that_jitter_over_a_regular_clock_are_found() {
    // 30 µs and 0.1 ms: at this slow motion (0.16 rad/s RMS) and 2^20 counts a turn, 10 µs
    // moves the positions by less than a count, and is not told
    for jitter in [3e-5, 1e-4] {
        let rec = log(jitter);
        let found = find_stamp_jitter(&rec).expect("found");
        assert!((found.interval - 1e-3).abs() < 2e-5, "{found:?}");
        // the intervals, differences of two white jitters: sqrt(2) times theirs
        let expected = jitter * 2f64.sqrt();
        assert!(
            (found.scatter - expected).abs() < 0.1 * expected,
            "{found:?}"
        );
        assert!((found.rougher - ratio(&rec)).abs() < 1e-9 * ratio(&rec));
        assert!(found.rougher > 1.5 * ROUGHER, "{found:?}");
        let names: Vec<String> = (1..=N).map(|j| format!("joint{j}")).collect();
        let w = warning(&Some(found.clone()), "log.csv", &names).unwrap();
        assert!(
            w.starts_with("log 'log.csv': its time stamps jitter")
                && w.contains(&format!("the positions of 'joint{}'", found.joint + 1)),
            "{w}"
        );
        // kept by preprocess
        let p = perturbid_rs::logs::preprocess::preprocess(&rec, &PreprocessOptions::default())
            .unwrap();
        assert_eq!(p.stamp_jitter, Some(found));
    }
}

#[test]
fn sound_stamps_are_left_alone() {
    // a regular clock stamped right: each position on its neighbours' line either way
    let regular = log(0.0);
    assert!((ratio(&regular) - 1.0).abs() < 1e-6);
    assert_eq!(find_stamp_jitter(&regular), None);
    // an irregular clock (0.8 to 1.2 ms) stamped right: smooth against the stamps
    let irregular = a465_noisy_log();
    assert!(ratio(&irregular) < 0.5, "{}", ratio(&irregular));
    assert_eq!(find_stamp_jitter(&irregular), None);
    // a joint at rest and a log too short to judge
    let mut still = regular.clone();
    still.q.iter_mut().for_each(|q| *q = 0.25);
    assert_eq!(find_stamp_jitter(&still), None);
    let short = Recording::new(
        "two",
        N,
        vec![0.0, 1e-3],
        vec![0.0; 12],
        vec![0.0; 12],
        None,
        None,
    )
    .unwrap();
    assert_eq!(find_stamp_jitter(&short), None);
}

#[test]
fn the_real_panda_log_is_left_alone() {
    // its stamps scatter by 0.1 ms, but its positions' noise hides it (1.19 at the most)
    let Some(panda) = panda_log() else { return };
    assert!(ratio(&panda) < 0.7 * ROUGHER, "{}", ratio(&panda));
    assert_eq!(find_stamp_jitter(&panda), None);
}

#[test]
fn a_saved_finding_is_checked_on_load() {
    use perturbid_rs::direct::BaseModel;
    use perturbid_rs::document::Document;
    let rec = log(1e-4);
    let (p, fit) = common::fit_preprocessed(&rec, &PreprocessOptions::default());
    let fit = BaseModel {
        log_stamp_jitter: p.stamp_jitter,
        ..fit
    };
    assert!(fit.log_stamp_jitter.is_some());
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 4] = [
        (
            |v| v["log_stamp_jitter"]["joint"] = 6.into(),
            "log_stamp_jitter: joint 6",
        ),
        (
            |v| v["log_stamp_jitter"]["interval"] = 0.0.into(),
            "log_stamp_jitter: interval 0",
        ),
        (
            |v| v["log_stamp_jitter"]["scatter"] = (-1.0).into(),
            "log_stamp_jitter: scatter -1",
        ),
        (
            |v| v["log_stamp_jitter"]["rougher"] = 1.5.into(),
            "log_stamp_jitter: rougher 1.5",
        ),
    ];
    common::refused_on_load::<BaseModel>(&value, &edits);
}
