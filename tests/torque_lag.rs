//! The log's torques out of step with its positions (src/direct/torque_lag.rs): torques logged
//! 40 samples after, or before, the positions they belong to are found at exactly that shift
//! and named in the fit's warnings; the clean log, one in degrees and the real Panda log fit no
//! shift better.

mod common;

use common::{a465_log, fit_physical, panda_preprocessed, refused_on_load, A465Log};
use perturbid_rs::direct::torque_lag::{check_torque_lag, LAG_RATIO, MAX_LAG};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use perturbid_rs::robots::a465;
use perturbid_rs::{Gravity, States};

/// `log` with its torques shifted by `by` samples: positive, each logged `by` samples after
/// the positions it belongs to (the first `by` rows repeat the first torque).
fn shifted(log: &A465Log, by: i64) -> A465Log {
    let n = 6;
    let k = log.q.len() / n;
    let mut tau = vec![0.0; log.tau.len()];
    for i in 0..k {
        let from = (i as i64 - by).clamp(0, k as i64 - 1) as usize;
        tau[i * n..(i + 1) * n].copy_from_slice(&log.tau[from * n..(from + 1) * n]);
    }
    A465Log {
        q: log.q.clone(),
        qd: log.qd.clone(),
        qdd: log.qdd.clone(),
        tau,
    }
}

#[test]
fn torques_out_of_step_are_found_at_their_shift() {
    let clean = a465_log();
    let m = fit_physical(&clean);
    let lag = m.torque_lag.clone().expect("checked");
    assert_eq!(lag.joints.len(), 6, "{lag:?}");
    assert!(lag.samples.abs() <= 1, "{lag:?}");
    assert!(lag.finding().is_none(), "{lag:?}");
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
    for (by, how) in [(40, "after"), (-40, "before")] {
        let m = fit_physical(&shifted(&clean, by));
        let lag = m.torque_lag.clone().unwrap();
        assert_eq!(lag.samples, by, "{lag:?}");
        assert!(
            lag.unexplained > LAG_RATIO * lag.unexplained_at_lag,
            "{lag:?}"
        );
        let w = m.warnings().join("\n");
        assert!(
            w.contains(&format!("logged 40 sample(s) {how} the positions")),
            "{w}"
        );
    }
    // a shift of one sample changes little: found, but no finding
    let lag = fit_physical(&shifted(&clean, 1)).torque_lag.unwrap();
    assert!(lag.samples.abs() <= 2 && lag.finding().is_none(), "{lag:?}");
    // positions in degrees fit no shift better
    let degrees = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let lag = fit_physical(&A465Log {
        q: degrees(&clean.q),
        qd: degrees(&clean.qd),
        qdd: degrees(&clean.qdd),
        tau: clean.tau.clone(),
    })
    .torque_lag;
    assert!(
        lag.as_ref().is_none_or(|l| l.finding().is_none()),
        "{lag:?}"
    );
    // too little to check: no accelerations, or under 40 samples
    let model = a465::model("physical").unwrap();
    let short = States::new(6, &clean.q[..6 * 400], Some(&clean.qd[..6 * 400]), None).unwrap();
    assert_eq!(
        check_torque_lag(&model, &short, &clean.tau[..6 * 400], Gravity::Included).unwrap(),
        None,
        "no accelerations"
    );
    let states = States::new(6, &clean.q, Some(&clean.qd), Some(&clean.qdd)).unwrap();
    let tiny = states.slice(0..30);
    assert_eq!(
        check_torque_lag(&model, &tiny, &clean.tau[..180], Gravity::Included).unwrap(),
        None
    );
    // a shorter log is searched a quarter of its length either way (2 s: 500 samples), its
    // edges never read past
    let head = states.slice(0..2000);
    for by in [200, -240, 450] {
        let s = shifted(&clean, by);
        let lag = check_torque_lag(&model, &head, &s.tau[..6 * 2000], Gravity::Included)
            .unwrap()
            .unwrap();
        assert_eq!(lag.samples, by, "{lag:?}");
    }
    // saved with the model and checked on load
    let m = fit_physical(&shifted(&clean, 40));
    let text = m.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), m);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    refused_on_load::<BaseModel>(
        &value,
        &[
            (
                |v| v["torque_lag"]["joints"][0] = "joint9".into(),
                "torque_lag: joint 'joint9'",
            ),
            (
                |v| v["torque_lag"]["samples"] = (MAX_LAG as i64 + 1).into(),
                "torque_lag: samples is 501",
            ),
            (
                |v| v["torque_lag"]["unexplained"] = (-1.0).into(),
                "torque_lag: unexplained",
            ),
        ],
    );
}

/// A log recorded without gravity (compensated) is checked as well.
#[test]
fn a_log_without_gravity_is_checked_too() {
    let clean = a465_log();
    let model = a465::model("kinsheel2010").unwrap();
    let n = 6;
    let mut gravity = vec![0.0; clean.tau.len()];
    perturbid_rs::parallel::rnea(
        &model,
        &mut perturbid_rs::parallel::Workspace::new(&model),
        &States::new(n, &clean.q, None, None).unwrap(),
        Gravity::Included,
        &mut gravity,
    )
    .unwrap();
    let compensated: Vec<f64> = clean.tau.iter().zip(&gravity).map(|(t, g)| t - g).collect();
    let log = shifted(
        &A465Log {
            q: clean.q.clone(),
            qd: clean.qd.clone(),
            qdd: clean.qdd.clone(),
            tau: compensated,
        },
        25,
    );
    let states = States::new(n, &log.q, Some(&log.qd), Some(&log.qdd)).unwrap();
    let lag = check_torque_lag(&model, &states, &log.tau, Gravity::Excluded)
        .unwrap()
        .unwrap();
    assert_eq!(lag.samples, 25, "{lag:?}");
    assert!(lag.finding().is_some(), "{lag:?}");
}

/// The real Panda log (beside the repository; skipped when absent): no shift fits it better.
#[test]
fn the_real_panda_log_is_in_step() {
    let Some((model, p)) = panda_preprocessed() else {
        return;
    };
    let states = States::new(7, &p.q, p.qd.as_deref(), p.qdd.as_deref()).unwrap();
    let lag = check_torque_lag(&model, &states, &p.tau, Gravity::Included)
        .unwrap()
        .unwrap();
    assert!(lag.joints.len() >= 5, "{lag:?}");
    assert!(lag.samples.abs() <= 2, "{lag:?}");
    assert!(lag.unexplained < 1.2 * lag.unexplained_at_lag, "{lag:?}");
    assert!(lag.finding().is_none(), "{lag:?}");
}
