//! Frozen readings (src/logs/frozen_readings.rs): one joint's column holding its last value for
//! longer than a held reading while the joint moves (a stalled message stream). Found with
//! their rows, removed before preprocessing so that the fit is the clean log's without those
//! rows (and far off unremoved); a whole message stalled is listed once; a joint at rest,
//! positions printed coarsely, torques on a coarse grid and the real Panda log are left alone;
//! a column frozen over much of the log is refused, naming it; saved frozen readings are
//! checked on load.

mod common;

use common::{a465_noisy_log, fit_preprocessed, moved_in_stderr, panda_log, refused_on_load};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use perturbid_rs::logs::frozen_readings::{find_frozen_readings, MIN_FROZEN};
use perturbid_rs::logs::log_dropouts::{dropout_warning, BRIDGED_BY_PREPROCESSING};
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::Recording;

const N: usize = 6;

/// The direct method's base parameters of `rec`, preprocessed (split at gaps; glitches,
/// dropouts and frozen readings screened when `screen`), with the preprocessed recording.
fn identify(rec: &Recording, screen: bool) -> (Recording, BaseModel) {
    let options = PreprocessOptions {
        screen_glitches: screen,
        split_at_gaps: true,
        ..PreprocessOptions::default()
    };
    fit_preprocessed(rec, &options)
}

/// `rec` without its rows `rows`.
fn without_rows(rec: &Recording, rows: std::ops::Range<usize>) -> Recording {
    let keep: Vec<usize> = (0..rec.len()).filter(|i| !rows.contains(i)).collect();
    let take = |x: &[f64]| -> Vec<f64> {
        keep.iter()
            .flat_map(|&i| x[i * N..(i + 1) * N].to_vec())
            .collect()
    };
    let t = keep.iter().map(|&i| rec.t[i]).collect();
    Recording::new("cut", N, t, take(&rec.q), take(&rec.tau), None, None).unwrap()
}

/// `rec` with `signal`'s column of joint `j` holding its value of row `rows.start` over `rows`.
fn frozen(rec: &Recording, signal: &str, j: usize, rows: std::ops::Range<usize>) -> Recording {
    let mut out = rec.clone();
    let column = if signal == "q" {
        &mut out.q
    } else {
        &mut out.tau
    };
    let held = column[rows.start * N + j];
    for i in rows {
        column[i * N + j] = held;
    }
    out
}

/// One joint's positions frozen for 50 ms while it moves: 10 standard errors off unremoved;
/// removed, the fit is the clean log's without those rows.
#[test]
fn a_frozen_position_is_removed_with_its_rows() {
    let clean = a465_noisy_log();
    let (_, reference) = identify(&clean, true);
    let rec = frozen(&clean, "q", 2, 5000..5050);
    let found = find_frozen_readings(&rec).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    let f = &found[0];
    assert_eq!(
        (f.signal.as_str(), f.joint, f.first_sample, f.samples),
        ("q", Some(2), 5000, 50)
    );
    assert_eq!((f.from, f.to), (rec.t[5000], rec.t[5049]));
    assert_eq!(f.value, Some(clean.q[5000 * N + 2]));
    assert!(f.noise_levels.is_some_and(|z| z > 100.0), "{f:?}");
    assert!(f.problem(N).is_none());
    // unremoved, far off; removed, the clean log's fit without those rows, exactly
    let (_, unremoved) = identify(&rec, false);
    assert!(
        moved_in_stderr(&unremoved, &reference) > 5.0,
        "{}",
        moved_in_stderr(&unremoved, &reference)
    );
    let (p, fit) = identify(&rec, true);
    assert_eq!(p.dropouts, found);
    let (_, cut) = identify(&without_rows(&clean, 5000..5050), true);
    assert!(
        moved_in_stderr(&fit, &cut) < 1e-6,
        "{}",
        moved_in_stderr(&fit, &cut)
    );
    // 50 rows are a gap: refused unless split, naming what was removed
    let e = preprocess(&rec, &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gap") && e.contains("after removing 1 frozen reading(s)"),
        "{e}"
    );
    // 15 rows are bridged, and told of by the warning with the joint's name
    let short = frozen(&clean, "q", 2, 5000..5015);
    let p = preprocess(&short, &PreprocessOptions::default()).unwrap();
    assert_eq!(p.dropouts.len(), 1, "{:?}", p.dropouts);
    assert_eq!(p.dropouts[0].samples, 15);
    let names: Vec<String> = (1..=N).map(|j| format!("j{j}")).collect();
    let w = dropout_warning(&p.dropouts, "log", &names, BRIDGED_BY_PREPROCESSING).unwrap();
    assert!(
        w.contains("1 frozen reading(s)")
            && w.contains("q of 'j3' held")
            && w.contains("for 15 rows from sample 5000")
            && !w.contains("dropout(s)"),
        "{w}"
    );
}

/// Every joint's position frozen for 40 rows (the whole message stalled): found per joint,
/// told of once; a run at the log's end cannot be judged and is kept.
#[test]
fn a_whole_message_stalled_is_listed_once() {
    let clean = a465_noisy_log();
    let mut rec = clean.clone();
    for j in 0..N {
        rec = frozen(&rec, "q", j, 8000..8040);
    }
    let found = find_frozen_readings(&rec).unwrap();
    assert_eq!(found.len(), N, "{found:?}");
    assert!(
        found
            .iter()
            .all(|f| (f.signal.as_str(), f.first_sample, f.samples) == ("q", 8000, 40)),
        "{found:?}"
    );
    let refs: Vec<_> = found.iter().collect();
    let w = perturbid_rs::logs::frozen_readings::describe(&refs, &[], "before preprocessing");
    assert!(
        w.starts_with("1 frozen reading(s)")
            && w.contains("q of joint 1, joint 2, joint 3, joint 4, joint 5, joint 6 held their values for 40 rows from sample 8000"),
        "{w}"
    );
    // a position run at the log's end, without logged velocities to say the joint moved, is kept
    let end = frozen(&clean, "q", 2, clean.len() - 60..clean.len());
    assert!(find_frozen_readings(&end).unwrap().is_empty());
}

/// `rec` with velocities logged: the central differences of its positions (one-sided at the
/// ends), which move on where a position column is frozen.
fn with_velocities(rec: &Recording) -> Recording {
    let k = rec.len();
    let qd = (0..k * N)
        .map(|x| {
            let (i, j) = (x / N, x % N);
            let (a, b) = (i.saturating_sub(1), (i + 1).min(k - 1));
            (rec.q[b * N + j] - rec.q[a * N + j]) / (rec.t[b] - rec.t[a])
        })
        .collect();
    let mut out = rec.clone();
    out.qd = Some(qd);
    out
}

/// A stream that stops before the log does, its last value logged to the end: the torque of
/// one joint over the last 60 rows is found (to the end, no jump), its rows removed, and the
/// fit is the clean log's without them; so are positions whose logged velocities go on. A
/// joint that comes to rest at the end, its positions printed with four decimals and its
/// velocity reading noise, is kept.
#[test]
fn a_stream_that_stops_before_the_log_is_removed_from_the_end() {
    let clean = a465_noisy_log();
    let k = clean.len();
    let rec = frozen(&clean, "tau", 3, k - 60..k);
    let found = find_frozen_readings(&rec).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    let f = &found[0];
    assert_eq!(
        (
            f.signal.as_str(),
            f.joint,
            f.first_sample,
            f.samples,
            f.to_end
        ),
        ("tau", Some(3), k - 60, 60, true)
    );
    assert_eq!(
        (f.noise_levels, f.value),
        (None, Some(clean.tau[(k - 60) * N + 3]))
    );
    assert!(f.problem(N).is_none());
    let (p, fit) = identify(&rec, true);
    assert_eq!(p.dropouts, found);
    let (_, cut) = identify(&without_rows(&clean, k - 60..k), true);
    assert!(
        moved_in_stderr(&fit, &cut) < 1e-6,
        "{}",
        moved_in_stderr(&fit, &cut)
    );
    let refs: Vec<_> = found.iter().collect();
    let w = perturbid_rs::logs::frozen_readings::describe(&refs, &[], "before preprocessing");
    assert!(
        w.contains("tau of joint 4 held")
            && w.contains(
                "to the end of its stretch of the log (the stream stopped before the log did)"
            ),
        "{w}"
    );
    // positions frozen while the logged velocities go on
    let moving = with_velocities(&clean);
    let mut rec = frozen(&moving, "q", 1, k - 40..k);
    rec.qd = moving.qd.clone();
    let found = find_frozen_readings(&rec).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].signal.as_str(), found[0].joint, found[0].samples),
        ("q", Some(1), 40)
    );
    // at rest at the end: positions printed coarsely repeat, velocities read noise about 0
    let mut rest = with_velocities(&clean);
    let mut rng = common::Rng(3);
    let held = (clean.q[(k - 300) * N + 1] * 1e4).round() / 1e4;
    for i in k - 300..k {
        rest.q[i * N + 1] = held;
        rest.qd.as_mut().unwrap()[i * N + 1] = 1e-3 * common::normal(&mut rng);
    }
    assert!(find_frozen_readings(&rest).unwrap().is_empty());
    // a saved reading to the end with noise levels, or of rows of zeros, is refused
    let mut bad = f.clone();
    bad.noise_levels = Some(20.0);
    assert!(bad
        .problem(N)
        .unwrap()
        .contains("to_end belongs to a frozen reading"));
}

/// Repeats that are readings: a joint that stands still (its torque read on a coarse grid
/// repeats too), positions printed with four decimals, torques on a 0.05 N m grid.
#[test]
fn readings_that_repeat_legitimately_are_kept() {
    let clean = a465_noisy_log();
    // joint 1 stops for 300 rows and goes on from where it stopped, abruptly (its velocity
    // steps), while its torque, on a coarse grid, repeats too
    let mut rest = clean.clone();
    for i in 4000..clean.len() {
        let from = if i < 4300 { 4000 } else { i - 300 };
        rest.q[i * N] = clean.q[from * N];
    }
    for i in 4000..4300 {
        rest.tau[i * N] = (clean.tau[4000 * N] / 0.05).round() * 0.05;
    }
    assert!(find_frozen_readings(&rest).unwrap().is_empty());
    // coarse prints and grids: long runs where a joint turns, no jump at their ends
    let mut coarse = clean.clone();
    for x in &mut coarse.q {
        *x = (*x * 1e4).round() / 1e4;
    }
    for x in &mut coarse.tau {
        *x = (*x / 0.05).round() * 0.05;
    }
    let longest = (0..N)
        .map(|j| {
            let (mut best, mut run) = (0, 1);
            for i in 1..coarse.len() {
                run = if coarse.q[i * N + j] == coarse.q[(i - 1) * N + j] {
                    run + 1
                } else {
                    1
                };
                best = usize::max(best, run);
            }
            best
        })
        .max()
        .unwrap();
    assert!(longest >= MIN_FROZEN, "{longest}");
    assert!(find_frozen_readings(&coarse).unwrap().is_empty());
    // the real Panda log: positions printed with four decimals, a logger that repeats rows
    match panda_log() {
        Some(panda) => assert!(find_frozen_readings(&panda).unwrap().is_empty()),
        None => eprintln!(
            "SKIPPED (Panda part): ../shared/data/panda-gaz2019 is not beside the repository"
        ),
    }
}

/// Torques logged in 0.05 N m steps with 0.002 N m of noise along the A465's plan: runs of
/// one value for up to about 90 samples, some ending where a perturbation starts and the torque
/// ramps (a kink) or one step on: none is taken for frozen.
#[test]
fn coarse_torques_of_a_rehearsed_plan_are_kept() {
    use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
    let (model, _, plan, _) = common::a465_orthogonal_at_table2();
    let spec = r#"{"format": "perturbid-true-robot/1", "seed": 0, "sensors": {"torque_noise": [0.002, 0.002, 0.002, 0.002, 0.002, 0.002], "torque_resolution": [0.05, 0.05, 0.05, 0.05, 0.05, 0.05]}}"#;
    let robot = TrueRobot::from_json(spec).unwrap();
    let mut longest = 0;
    for rec in rehearse_plan(&model, &robot, &plan).unwrap() {
        for j in 0..N {
            let mut run = 1;
            for i in 1..rec.len() {
                run = if rec.tau[i * N + j] == rec.tau[(i - 1) * N + j] {
                    run + 1
                } else {
                    1
                };
                longest = usize::max(longest, run);
            }
        }
        let found = find_frozen_readings(&rec).unwrap();
        assert!(found.is_empty(), "{}: {found:?}", rec.name);
    }
    assert!(longest > 50, "{longest}");
}

/// An encoder whose reading freezes for 40 of every 100 rows: frozen readings over 40 % of the
/// log, refused naming the column (removing them would leave little).
#[test]
fn a_column_frozen_over_much_of_the_log_is_refused() {
    let clean = a465_noisy_log();
    let mut rec = clean.clone();
    for i in 0..rec.len() {
        if i % 100 >= 60 {
            rec.q[i * N + 1] = clean.q[(i / 100 * 100 + 60) * N + 1];
        }
    }
    let e = find_frozen_readings(&rec).unwrap_err().to_string();
    assert!(
        e.contains("column q2") && e.contains("lower rate") && e.contains("more than 25 %"),
        "{e}"
    );
    let e = preprocess(&rec, &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("column q2"), "{e}");
}

/// A frozen reading saved in a base model is checked when read back.
#[test]
fn saved_frozen_readings_are_checked_on_load() {
    let clean = a465_noisy_log();
    let rec = frozen(&clean, "q", 2, 5000..5015);
    let (p, fit) = identify(&rec, true);
    let fit = BaseModel {
        log_dropouts: p.dropouts,
        ..fit
    };
    assert_eq!(fit.log_dropouts.len(), 1);
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 4] = [
        (
            |v| v["log_dropouts"][0]["joint"] = 6.into(),
            "log_dropouts[0]: joint 6",
        ),
        (
            |v| v["log_dropouts"][0]["samples"] = 10.into(),
            "log_dropouts[0]: 10 samples; a frozen reading has at least 11",
        ),
        (
            |v| v["log_dropouts"][0]["noise_levels"] = 3.0.into(),
            "log_dropouts[0]: a frozen reading holds a finite value",
        ),
        (
            |v| {
                let d = v["log_dropouts"][0].as_object_mut().unwrap();
                d.remove("joint");
            },
            "log_dropouts[0]: value and noise_levels belong to a frozen reading",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}
