//! Joint positions logged within one turn (src/logs/position_wraps.rs): a joint that passes the end
//! of the range steps by a whole turn between two samples. The steps are found where the
//! wrapped log has them, taken back out before preprocessing, and the fit is the unwrapped
//! log's; a glitch of about a turn is stepped over and back, other steps are left alone; a log
//! taken as logged with wrapped positions passes the derivative check; saved wraps are checked
//! on load.

mod common;

use common::{a465_log, a465_noisy_log, fit_preprocessed, moved_in_stderr, refused_on_load};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use perturbid_rs::logs::position_wraps::{unwrap_positions, warning};
use perturbid_rs::logs::preprocess::PreprocessOptions;
use perturbid_rs::Recording;
use std::f64::consts::{PI, TAU};

const N: usize = 6;

fn identify(rec: &Recording) -> (Recording, BaseModel) {
    fit_preprocessed(rec, &PreprocessOptions::default())
}

/// `q` wrapped into [-pi, pi).
fn wrapped(q: f64) -> f64 {
    (q + PI).rem_euclid(TAU) - PI
}

/// Joint 1 of the test log moved by an offset to sweep back and forth across pi, logged
/// within [-pi, pi): every crossing of pi is a step of a turn, found where the log has it,
/// and the fit is the unwrapped log's.
#[test]
fn a_joint_logged_within_one_turn_is_unwrapped() {
    let clean = a465_noisy_log();
    // the joint's range centred on pi
    let (lo, hi) = (0..clean.len()).fold((f64::MAX, f64::MIN), |(lo, hi), i| {
        (lo.min(clean.q[i * N]), hi.max(clean.q[i * N]))
    });
    let offset = PI - 0.5 * (lo + hi);
    let mut shifted = clean.clone();
    for i in 0..clean.len() {
        shifted.q[i * N] += offset;
    }
    let mut rec = shifted.clone();
    for i in 0..rec.len() {
        rec.q[i * N] = wrapped(shifted.q[i * N]);
    }
    // where the log steps: the samples whose turn, floor((q + pi) / 2 pi), changes
    let turn = |q: f64| ((q + PI) / TAU).floor() as i64;
    let expected: Vec<(usize, i64)> = (1..rec.len())
        .filter(|&i| turn(shifted.q[i * N]) != turn(shifted.q[(i - 1) * N]))
        .map(|i| (i, turn(shifted.q[i * N]) - turn(shifted.q[(i - 1) * N])))
        .collect();
    assert!(expected.len() >= 2, "{expected:?}");
    let (unwrapped, wraps) = unwrap_positions(&rec);
    let found: Vec<(usize, i64)> = wraps.iter().map(|w| (w.sample, w.turns)).collect();
    assert_eq!(found, expected);
    assert!(wraps
        .iter()
        .all(|w| w.joint == 0 && w.time == rec.t[w.sample]));
    assert!(wraps.iter().all(|w| w.problem(N).is_none()));
    // whole turns off the shifted log's positions at most, to rounding
    for (a, b) in unwrapped.q.iter().zip(&shifted.q) {
        let turns = ((a - b) / TAU).round();
        assert!((a - b - turns * TAU).abs() < 1e-12, "{a} {b}");
    }
    let (p, fit) = identify(&rec);
    assert_eq!(p.position_wraps, wraps);
    let (_, reference) = identify(&shifted);
    let moved = moved_in_stderr(&fit, &reference);
    assert!(moved < 1e-6, "{moved}");
    let names: Vec<String> = (1..=N).map(|j| format!("j{j}")).collect();
    let w = warning(&wraps, "log", &names, "before preprocessing").unwrap();
    assert!(
        w.contains(&format!("{} step(s)", wraps.len()))
            && w.contains(&format!(
                "'j1' at t = {:.4} s (sample {})",
                wraps[0].time, wraps[0].sample
            )),
        "{w}"
    );
}

/// A single sample off by a turn and a bit steps there and back (two wraps, leaving a glitch
/// of the bit); steps that are not whole turns, and a log without steps, are left alone.
#[test]
fn only_steps_of_whole_turns_are_wraps() {
    let clean = a465_noisy_log();
    let mut spike = clean.clone();
    spike.q[5000 * N + 2] += TAU + 0.1;
    let (out, wraps) = unwrap_positions(&spike);
    let found: Vec<(usize, usize, i64)> =
        wraps.iter().map(|w| (w.joint, w.sample, w.turns)).collect();
    assert_eq!(found, [(2, 5000, -1), (2, 5001, 1)]);
    assert!((out.q[5000 * N + 2] - clean.q[5000 * N + 2] - 0.1).abs() < 1e-12);
    assert_eq!(out.q[5001 * N..], clean.q[5001 * N..]);
    let mut step = clean.clone();
    for i in 6000..clean.len() {
        step.q[i * N + 3] += 3.0;
    }
    let (out, wraps) = unwrap_positions(&step);
    assert!(wraps.is_empty() && out == step);
    let (out, wraps) = unwrap_positions(&clean);
    assert!(wraps.is_empty() && out == clean);
}

/// A log taken as logged, its velocities and accelerations logged and its positions wrapped:
/// the check of its derivative columns sees the motion, not the steps.
#[test]
fn wrapped_positions_pass_the_derivative_check() {
    let log = a465_log();
    let t: Vec<f64> = (0..log.q.len() / N).map(|i| i as f64 * 1e-3).collect();
    let q: Vec<f64> = log.q.iter().map(|&x| wrapped(x + 2.9)).collect();
    assert!(q.windows(N + 1).any(|w| (w[N] - w[0]).abs() > PI));
    let rec = Recording::new(
        "log.csv",
        N,
        t,
        q,
        log.tau.clone(),
        Some(log.qd.clone()),
        Some(log.qdd.clone()),
    )
    .unwrap();
    perturbid_rs::logs::derivative_columns::check_logged_derivatives(&rec).unwrap();
}

#[test]
fn saved_wraps_are_checked_on_load() {
    let clean = a465_noisy_log();
    let mut rec = clean.clone();
    for i in 0..rec.len() {
        rec.q[i * N] = wrapped(clean.q[i * N] + PI - 0.5 * (clean.q[0] + clean.q[N * 3000]));
    }
    let (p, fit) = identify(&rec);
    let fit = BaseModel {
        log_position_wraps: p.position_wraps,
        ..fit
    };
    assert!(!fit.log_position_wraps.is_empty());
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 2] = [
        (
            |v| v["log_position_wraps"][0]["joint"] = 6.into(),
            "log_position_wraps[0]: joint 6",
        ),
        (
            |v| v["log_position_wraps"][0]["turns"] = 0.into(),
            "log_position_wraps[0]: turns 0",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}
