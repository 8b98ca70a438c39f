//! Clipped torques in a log: found where a drive or sensor cut the torque off at a value, with
//! how far the torque went beyond it; not found in torques logged in steps, at rest, or in the
//! real Panda log.

mod common;

use common::{a465_log, fit_physical, panda_log, A465Log};
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::logs::torque_saturation::{find_torque_saturation, warning, MIN_RUN};
use perturbid_rs::Recording;

fn recording(log: &A465Log, tau: Vec<f64>) -> Recording {
    let t: Vec<f64> = (0..log.q.len() / 6).map(|i| i as f64 * 1e-3).collect();
    Recording::new("log.csv", 6, t, log.q.clone(), tau, None, None).unwrap()
}

/// The excursions of `y` beyond `level` (above it when `upper`) of at least `MIN_RUN` samples,
/// and the largest distance beyond it: what clipping at `level` hides.
fn excursions(y: &[f64], level: f64, upper: bool) -> (usize, f64) {
    let beyond = |v: f64| if upper { v >= level } else { v <= level };
    let (mut count, mut run, mut largest) = (0, 0, 0.0f64);
    for &v in y.iter().chain([&f64::NAN]) {
        if beyond(v) {
            run += 1;
            largest = largest.max((v - level).abs());
        } else {
            count += usize::from(run >= MIN_RUN);
            run = 0;
        }
    }
    (count, largest)
}

/// The log's torques with joint `j`'s clipped 25 % inside its range, at the top (`upper`) or
/// the bottom; the clipped torques, the joint's torques as they were and the level.
fn clipped(log: &A465Log, j: usize, upper: bool) -> (Vec<f64>, Vec<f64>, f64) {
    let column: Vec<f64> = log.tau.iter().skip(j).step_by(6).copied().collect();
    let top = column.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let bottom = column.iter().copied().fold(f64::INFINITY, f64::min);
    let level = if upper {
        top - 0.25 * (top - bottom)
    } else {
        bottom + 0.25 * (top - bottom)
    };
    let mut tau = log.tau.clone();
    for v in tau.iter_mut().skip(j).step_by(6) {
        *v = if upper { v.min(level) } else { v.max(level) };
    }
    (tau, column, level)
}

#[test]
fn a_torque_clipped_at_a_value_is_found_with_how_far_beyond_it_went() {
    let log = a465_log();
    let j = 1;
    let (tau, column, level) = clipped(&log, j, true);
    let found = find_torque_saturation(&recording(&log, tau.clone()));
    assert_eq!(found.len(), 1, "{found:?}");
    let c = &found[0];
    assert_eq!((c.joint, c.upper, c.level), (j, true, level));
    let (runs, largest) = excursions(&column, level, true);
    assert!(runs >= 1 && c.runs <= runs, "{} of {runs}", c.runs);
    assert!(c.runs * 2 >= runs, "{} of {runs} excursions found", c.runs);
    // the quadratic through the sides estimates the excursion hidden by the clip
    assert!(
        c.beyond > 0.3 * largest && c.beyond < 2.0 * largest,
        "{} against {largest}",
        c.beyond
    );
    let said = warning(&found, &["j1".into(), "j2".into()], "log.csv").unwrap();
    assert!(
        said.contains("log 'log.csv': the torque of 'j2' reads exactly")
            && said.contains("its largest value")
            && said.contains("clipped"),
        "{said}"
    );
    // preprocessing keeps it, found in the log as logged
    let pre = preprocess(&recording(&log, tau), &PreprocessOptions::default()).unwrap();
    assert_eq!(pre.torque_saturation, found);
}

#[test]
fn torques_logged_in_steps_or_held_at_rest_are_not_taken_for_clipped() {
    let log = a465_log();
    assert!(find_torque_saturation(&recording(&log, log.tau.clone())).is_empty());
    // logged in steps from 1e-3 to 2 N m: the top step is held a while at every peak
    for step in [1e-3, 0.01, 0.1, 0.5, 2.0] {
        let tau: Vec<f64> = log.tau.iter().map(|v| (v / step).round() * step).collect();
        let found = find_torque_saturation(&recording(&log, tau));
        assert!(found.is_empty(), "step {step}: {found:?}");
    }
    // the robot at rest for its first and last second: its torques held, some at an extreme
    let mut rest = log.tau.clone();
    let k = rest.len() / 6;
    for s in (0..1000).chain(k - 1000..k) {
        for j in 0..6 {
            let edge = if s < 1000 { 1000 } else { k - 1001 };
            rest[s * 6 + j] = log.tau[edge * 6 + j] + if j == 2 { 50.0 } else { 0.0 };
        }
    }
    let found = find_torque_saturation(&recording(&log, rest));
    assert!(found.is_empty(), "{found:?}");
}

#[test]
fn the_real_panda_log_is_not_clipped() {
    let Some(rec) = panda_log() else { return };
    let found = find_torque_saturation(&rec);
    assert!(found.is_empty(), "{found:?}");
}

#[test]
fn a_saved_finding_is_checked_on_load() {
    let log = a465_log();
    let (tau, _, level) = clipped(&log, 4, false);
    let found = find_torque_saturation(&recording(&log, tau));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (found[0].joint, found[0].upper, found[0].level),
        (4, false, level)
    );
    assert!(found.iter().all(|c| c.problem(6).is_none()));
    let mut bad = found[0].clone();
    bad.joint = 6;
    assert!(bad
        .problem(6)
        .unwrap()
        .contains("joint 6 is not a joint index below 6"));
    let mut bad = found[0].clone();
    bad.longest = 1;
    assert!(bad.problem(6).unwrap().contains("runs of at least 3"));
    let mut bad = found[0].clone();
    bad.level = f64::NAN;
    assert!(bad.problem(6).is_some());
    // counts at the end of their range: refused, no overflow
    let mut bad = found[0].clone();
    bad.runs = usize::MAX;
    assert!(bad.problem(6).unwrap().contains("runs of at least 3"));
}

/// Why it is warned of: the fit takes the clipped readings for torques, and the base
/// parameters move by thousands of their standard errors (joint 2's torque clipped 25 %
/// inside its range).
#[test]
fn a_clipped_torque_moves_the_fit_far_beyond_its_standard_errors() {
    let log = a465_log();
    let clean = fit_physical(&log);
    let (tau, _, _) = clipped(&log, 1, true);
    let fit = fit_physical(&A465Log { tau, ..log });
    let moved = (0..clean.theta.len())
        .map(|i| ((fit.theta[i] - clean.theta[i]) / clean.stderr[i]).abs())
        .fold(0.0, f64::max);
    // about 2,900 here
    assert!(moved > 100.0, "{moved}");
}

/// The local method: a torque clipped in a crossing's window is warned of with the crossing;
/// clipping only between the crossings, where no fit reads the torque, is not.
#[test]
fn the_local_method_names_the_crossings_a_clipped_torque_reaches() {
    use perturbid_rs::local::{identify_local, ExperimentKind, IdentifyOptions};
    let (plan, recs) = common::a465_noisy_runs();
    let clean = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    assert!(!clean
        .diagnostics
        .warnings
        .iter()
        .any(|w| w.contains("clipped")));
    let e = (plan.experiments.iter())
        .position(|e| e.kind == ExperimentKind::D)
        .unwrap();
    let rec = &recs[e];
    let j = 1;
    // joint 2's torque at each crossing, read at its nearest sample
    let at = |t: f64| {
        let s = rec.t.partition_point(|x| *x < t);
        rec.tau[s * 6 + j]
    };
    let crossings = &plan.experiments[e].crossings;
    let (k, top) = (crossings.iter().enumerate())
        .map(|(i, c)| (i, at(c.time)))
        .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
    let column_top = rec
        .tau
        .iter()
        .skip(j)
        .step_by(6)
        .copied()
        .fold(f64::MIN, f64::max);
    for (level, says) in [(top - 0.3, true), (0.5 * (top + column_top), false)] {
        let mut clipped = recs.clone();
        for v in clipped[e].tau.iter_mut().skip(j).step_by(6) {
            *v = v.min(level);
        }
        let model = identify_local(&plan, &clipped, &IdentifyOptions::default()).unwrap();
        let warned: Vec<&String> = (model.diagnostics.warnings.iter())
            .filter(|w| w.contains("clipped"))
            .collect();
        if !says {
            assert!(warned.is_empty(), "{level} above {top}: {warned:?}");
            continue;
        }
        assert_eq!(warned.len(), 1, "{warned:?}");
        assert!(
            warned[0].starts_with("experiment 'D': the torque of 'joint2' reads exactly")
                && (warned[0].contains(&format!("crossing(s) {k}"))
                    || warned[0].contains(&format!(", {k}"))),
            "crossing {k}: {}",
            warned[0]
        );
    }
}
