//! Columns logged at a lower rate and held on the log's grid (src/logs/held_columns.rs): a torque
//! and a position held for 10 samples at a time are found, read again at their values'
//! arrivals, and the fit comes back near the clean log's (from 1.7 and 1.3 standard errors
//! off); no frozen readings are made of them; coarse encoder counts, torques in coarse steps,
//! a joint at rest and the real Panda log are left alone; saved findings are checked on load.

mod common;

use common::{a465_noisy_log, fit_preprocessed, moved_in_stderr, panda_log, refused_on_load};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use perturbid_rs::logs::held_columns::{find_held_columns, warning};
use perturbid_rs::logs::preprocess::PreprocessOptions;
use perturbid_rs::Recording;

const N: usize = 6;

fn identify(rec: &Recording) -> (Recording, BaseModel) {
    fit_preprocessed(rec, &PreprocessOptions::default())
}

/// `rec` with the column of `signal` ("q" or "tau") of joint `j` held for `every` samples.
fn held(rec: &Recording, signal: &str, j: usize, every: usize) -> Recording {
    let mut out = rec.clone();
    let column = if signal == "q" {
        &mut out.q
    } else {
        &mut out.tau
    };
    let source = if signal == "q" { &rec.q } else { &rec.tau };
    for i in 0..rec.len() {
        column[i * N + j] = source[(i / every * every) * N + j];
    }
    out
}

#[test]
fn columns_held_at_a_lower_rate_are_read_again() {
    let clean = a465_noisy_log();
    let (_, reference) = identify(&clean);
    for (signal, j) in [("tau", 1), ("q", 2)] {
        let rec = held(&clean, signal, j, 10);
        let (reread, found) = find_held_columns(&rec).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        let h = &found[0];
        assert_eq!((h.signal.as_str(), h.joint, h.held_for), (signal, j, 10.0));
        assert!(h.repeated > 0.85 && h.problem(N).is_none(), "{h:?}");
        // read again: the arrivals kept, the samples between on the line joining them
        let column = |r: &Recording| -> Vec<f64> {
            let v = if signal == "q" { &r.q } else { &r.tau };
            (0..r.len()).map(|i| v[i * N + j]).collect()
        };
        let (x, y) = (column(&reread), column(&rec));
        let arrival = |i: usize| i == 0 || y[i] != y[i - 1];
        for i in (0..rec.len()).step_by(10).filter(|&i| arrival(i)) {
            assert_eq!(x[i], y[i]);
        }
        let a = (5000..6000)
            .step_by(10)
            .find(|&a| arrival(a) && arrival(a + 10))
            .unwrap();
        let i = a + 5;
        let s = (rec.t[i] - rec.t[a]) / (rec.t[a + 10] - rec.t[a]);
        assert!((x[i] - (y[a] + s * (y[a + 10] - y[a]))).abs() < 1e-12);
        // the other columns untouched
        let others = |r: &Recording| -> Vec<f64> {
            let v = if signal == "q" { &r.tau } else { &r.q };
            v.clone()
        };
        assert_eq!(others(&reread), others(&rec));
        // preprocessed: the signal the column samples, to well within what half a hold's lag
        // (4.5 ms) leaves (the rate of change times the lag); the parameters within the
        // noise of a tenth of the samples; no frozen readings made of the holds
        let (p, fit) = identify(&rec);
        let (c, _) = identify(&clean);
        assert_eq!(p.held_columns, found);
        assert!(p.dropouts.is_empty(), "{:?}", p.dropouts);
        let (got, want, rate) = match signal {
            "q" => (
                p.qd.as_ref().unwrap(),
                c.qd.as_ref().unwrap(),
                c.qdd.as_ref().unwrap().clone(),
            ),
            _ => {
                let tau: Vec<f64> = c.tau.clone();
                let dt = c.t[1] - c.t[0];
                let d: Vec<f64> = (0..tau.len())
                    .map(|i| {
                        let (lo, hi) = (i.saturating_sub(N), (i + N).min(tau.len() - N + i % N));
                        (tau[hi] - tau[lo]) / (((hi - lo) / N) as f64 * dt)
                    })
                    .collect();
                (&p.tau, &c.tau, d)
            }
        };
        let rms = |v: Vec<f64>| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        let error = rms((0..c.len())
            .map(|i| got[i * N + j] - want[i * N + j])
            .collect());
        let lag = 4.5e-3 * rms((0..c.len()).map(|i| rate[i * N + j]).collect());
        eprintln!(
            "{signal}: {error} against {lag}, moved {}",
            moved_in_stderr(&fit, &reference)
        );
        assert!(error < 0.3 * lag, "{signal}: {error} against {lag}");
        assert!(
            moved_in_stderr(&fit, &reference) < 3.0,
            "{signal}: {}",
            moved_in_stderr(&fit, &reference)
        );
    }
    let names: Vec<String> = (1..=N).map(|j| format!("j{j}")).collect();
    let (_, found) = find_held_columns(&held(&clean, "tau", 1, 10)).unwrap();
    let w = warning(&found, "log", &names).unwrap();
    assert!(
        w.contains("1 column(s) logged at a lower rate")
            && w.contains("tau of 'j2' repeats 9")
            && w.contains("each value held for 10 samples"),
        "{w}"
    );
}

/// Repeats that are the signal's: positions in coarse counts (a slow joint in 2e-3 rad
/// steps), torques in 0.05 N m steps, a joint at rest, a rehearsed plan's recordings (rests
/// read exactly, torques in coarse steps) and the real Panda log: nothing is held.
#[test]
fn repeats_of_the_signal_itself_are_left_alone() {
    let clean = a465_noisy_log();
    let mut coarse = clean.clone();
    let k = clean.len();
    let mean = (0..k).map(|i| clean.q[i * N + 5]).sum::<f64>() / k as f64;
    for i in 0..k {
        let q = mean + 0.05 * (clean.q[i * N + 5] - mean);
        coarse.q[i * N + 5] = (q / 2e-3).round() * 2e-3;
    }
    for x in &mut coarse.tau {
        *x = (*x / 0.05).round() * 0.05;
    }
    let repeats = (1..k)
        .filter(|&i| coarse.q[i * N + 5] == coarse.q[(i - 1) * N + 5])
        .count();
    assert!(repeats * 2 > k, "{repeats}");
    let (out, found) = find_held_columns(&coarse).unwrap();
    assert!(found.is_empty(), "{found:?}");
    assert_eq!(out, coarse);
    // joint 1 at rest from row 4000 on, read exactly
    let mut rest = clean.clone();
    for i in 4000..k {
        rest.q[i * N] = clean.q[4000 * N];
    }
    assert!(find_held_columns(&rest).unwrap().1.is_empty());
    use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
    let (model, _, plan, _) = common::a465_orthogonal_at_table2();
    let spec = r#"{"format": "perturbid-true-robot/1", "seed": 0, "sensors": {"torque_noise": [0.002, 0.002, 0.002, 0.002, 0.002, 0.002], "torque_resolution": [0.05, 0.05, 0.05, 0.05, 0.05, 0.05]}}"#;
    for rec in rehearse_plan(&model, &TrueRobot::from_json(spec).unwrap(), &plan).unwrap() {
        let found = find_held_columns(&rec).unwrap().1;
        assert!(found.is_empty(), "{}: {found:?}", rec.name);
    }
    match panda_log() {
        Some(panda) => assert!(find_held_columns(&panda).unwrap().1.is_empty()),
        None => eprintln!(
            "SKIPPED (Panda part): ../shared/data/panda-gaz2019 is not beside the repository"
        ),
    }
}

#[test]
fn saved_held_columns_are_checked_on_load() {
    let clean = a465_noisy_log();
    let (p, fit) = identify(&held(&clean, "tau", 1, 10));
    let fit = BaseModel {
        log_held_columns: p.held_columns,
        ..fit
    };
    assert_eq!(fit.log_held_columns.len(), 1);
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 4] = [
        (
            |v| v["log_held_columns"][0]["joint"] = 6.into(),
            "log_held_columns[0]: joint 6",
        ),
        (
            |v| v["log_held_columns"][0]["signal"] = "force".into(),
            "log_held_columns[0]: signal 'force'",
        ),
        (
            |v| v["log_held_columns"][0]["repeated"] = 1.5.into(),
            "log_held_columns[0]: repeated 1.5",
        ),
        (
            |v| v["log_held_columns"][0]["held_for"] = 0.5.into(),
            "log_held_columns[0]: held_for 0.5",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}
