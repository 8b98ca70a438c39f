//! Drive gains identified with the base parameters from logged motor currents and a known
//! payload (src/direct/drive_gains.rs): the gains and the robot's torques come back; the joint
//! fit equals a dense least-squares solution of the same system (nalgebra's SVD); runs that do
//! not fix the scale, and payloads no robot carries, are refused; a signal counting the other
//! way is named; the noise bias bound holds; saved gains are checked on load. (Against numpy's
//! least squares: tests/python/test_drive_gains.py.)

mod common;

use common::gain_logs::{
    currents, dense_least_squares, dense_logs, logs, motion, payload, states, truth, GAINS,
};
use common::{refused_on_load, torques_with_friction, Rng};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::direct::{
    identify_drive_gains, identify_drive_gains_with, regressor_matrix, BaseModel, BaseOptions,
    GainEstimator, GainRun,
};
use perturbid_rs::document::Document;
use perturbid_rs::rehearsal::Payload;
use perturbid_rs::{Gravity, States, TorqueModel};

#[test]
fn the_gains_and_the_robots_torques_come_back_from_currents_with_a_known_payload() {
    let logs = logs(1e-4, true);
    let truth = &logs.truth;
    let fit = identify_drive_gains(truth, &logs.runs(), &BaseOptions::default()).unwrap();
    let g = fit.gains();
    for (j, truth) in GAINS.iter().enumerate() {
        // within its standard errors of the truth, less the bias the noise can give it
        let (k, se, bias) = (g.gain[j], g.stderr[j], g.noise_bias[j]);
        assert!(
            (k - truth).abs() < 4.0 * se + bias * truth && (k / truth - 1.0).abs() < 1e-2,
            "joint {j}: {k} +- {se} (bias up to {bias}), truth {truth}"
        );
        assert!(
            g.noise_bias[j] < 2e-3 && g.payload_torque_rms[j] > 0.01,
            "{g:?}"
        );
    }
    assert_eq!((g.runs, g.loaded_runs), (2, 1));
    // the runs agree with one robot and the payload: the joint fit leaves what each run does
    assert!(
        g.agreement.iter().all(|a| (0.95..1.2).contains(a)),
        "{:?}",
        g.agreement
    );
    assert!(
        g.warnings(&truth.joint_names).is_empty(),
        "{:?}",
        g.warnings(&truth.joint_names)
    );
    // the model is the robot alone's, in torques: on a third motion, unloaded
    let c = motion(5);
    let tau = torques_with_friction(truth, &c, &mut Rng(0), |_| 0.0);
    let predicted = fit.model.on(truth).unwrap().predict(&states(&c)).unwrap();
    let rms = (tau
        .iter()
        .zip(&predicted)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / tau.len() as f64)
        .sqrt();
    assert!(rms < 0.02, "RMS {rms} N m");
    // its own residuals are those of the joint fit, in N m
    for (j, r) in fit.model.residual_rms.iter().enumerate() {
        assert!(
            *r > 0.5 * 1e-4 * GAINS[j] && *r < 2.0 * 1e-4 * GAINS[j],
            "{j}: {r}"
        );
    }
    // saved with the model and read back whole
    assert_eq!(
        BaseModel::from_json(&fit.model.to_json()).unwrap(),
        fit.model
    );
}

#[test]
fn the_joint_fit_is_the_dense_least_squares_solution() {
    // [Phi_base | -diag(i)] [theta; K] = -tau_L, built whole
    let logs = dense_logs();
    let truth = &logs.truth;
    let (fit, x, rhs) = logs.ols_and_dense(GainEstimator::LeastSquares);
    let theta = dense_least_squares(&x, &rhs);
    let p_base = fit.model.theta.len();
    let g = fit.gains();
    for j in 0..6 {
        let rel = (g.gain[j] - theta[p_base + j]).abs() / theta[p_base + j].abs();
        assert!(
            rel < 1e-8,
            "gain {j}: {} against {}",
            g.gain[j],
            theta[p_base + j]
        );
    }
    for (c, (t, d)) in fit.model.theta.iter().zip(&theta).enumerate() {
        assert!(
            (t - d).abs() < 1e-7 * d.abs().max(1.0),
            "theta[{c}]: {t} against {d}"
        );
    }
    // the predicted signal and its standard error on a third motion, from the dense
    // covariance s^2 (X^T X)^-1 of [theta; K] (inflated as the model's) and the gradient of
    // i_j = Phi_j theta / K_j
    let cols = x.ncols();
    let scale: Vec<f64> = (0..cols).map(|c| x.column(c).norm()).collect();
    let xs = DMatrix::from_fn(x.nrows(), cols, |r, c| x[(r, c)] / scale[c]);
    let residual = &rhs - &x * DVector::from_column_slice(&theta);
    let s2 = residual.norm_squared() / (x.nrows() - cols) as f64;
    let inverse = (xs.transpose() * &xs).try_inverse().unwrap();
    let inflation = fit.model.stderr_inflation().powi(2);
    let cov = DMatrix::from_fn(cols, cols, |a, b| {
        inverse[(a, b)] / (scale[a] * scale[b]) * s2 * inflation
    });
    let c = motion(8);
    let third = states(&c);
    let signal = fit.model.predict_signal(truth, &third).unwrap();
    let tau = fit.model.predict(truth, &third).unwrap();
    let se = fit.model.predict_signal_stderr(truth, &third).unwrap();
    let phi = fit.model.base.select(
        &regressor_matrix(truth, &fit.model.base.layout, &third, Gravity::Included).unwrap(),
    );
    for r in (0..phi.nrows()).step_by(397) {
        let j = r % 6;
        assert_eq!(signal[r], tau[r] / g.gain[j]);
        let mut grad = DVector::zeros(cols);
        for a in 0..p_base {
            grad[a] = phi[(r, a)] / g.gain[j];
        }
        grad[p_base + j] = -tau[r] / g.gain[j].powi(2);
        let dense = grad.dot(&(&cov * &grad)).sqrt();
        assert!(
            (se[r] / dense - 1.0).abs() < 1e-6,
            "row {r}: {} against {dense}",
            se[r]
        );
    }
    // torques alone, the gains' covariance left out, would say otherwise
    let naive = fit.model.predict_stderr(truth, &third).unwrap();
    let apart = (0..se.len())
        .map(|r| naive[r] / g.gain[r % 6].abs() / se[r])
        .fold(1.0f64, |m, v| m.max(v.max(1.0 / v)));
    assert!(apart > 1.05, "{apart}");
    // a state too large to compute with is refused, naming the joint and sample
    let huge = vec![1e160; 6];
    let zeros = vec![0.0; 6];
    let far = States::new(6, &zeros, Some(&huge), Some(&zeros)).unwrap();
    let e = (fit.model.predict_signal_stderr(truth, &far))
        .unwrap_err()
        .to_string();
    assert!(e.contains("at sample 0 overflows"), "{e}");
}

#[test]
fn runs_that_do_not_fix_the_scale_and_payloads_no_robot_carries_are_refused() {
    let truth = truth();
    let (a, b) = (motion(3), motion(4));
    let p = payload();
    let (ia, ib) = (
        currents(&truth, &a, None, 0.0, 1),
        currents(&truth, &b, Some(&p), 0.0, 2),
    );
    let o = BaseOptions::default();
    let run = |s, i, payload| GainRun {
        states: states(s),
        signal: i,
        payload,
    };
    let said = |runs: &[GainRun<'_>]| {
        identify_drive_gains(&truth, runs, &o)
            .unwrap_err()
            .to_string()
    };
    let e = said(&[run(&a, &ia, None), run(&b, &ib, None)]);
    assert!(
        e.contains("every run carries no payload") && e.contains("not determined"),
        "{e}"
    );
    let e = said(&[run(&a, &ia, Some(&p)), run(&b, &ib, Some(&p))]);
    assert!(e.contains("the same payload (2 kg on 'link6')"), "{e}");
    let e = said(&[run(&b, &ib, Some(&p))]);
    assert!(e.contains("1 runs given, expected 2"), "{e}");
    let nowhere = Payload {
        link: "gripper".into(),
        ..payload()
    };
    let e = said(&[run(&a, &ia, None), run(&b, &ib, Some(&nowhere))]);
    assert!(
        e.contains("run 1") && e.contains("'gripper' is not a link of") && e.contains("link6"),
        "{e}"
    );
    let negative = Payload {
        mass: -1.0,
        ..payload()
    };
    let e = said(&[run(&a, &ia, None), run(&b, &ib, Some(&negative))]);
    assert!(e.contains("payload.mass is -1"), "{e}");
    let flat = Payload {
        inertia: [0.004, 0.0, 0.0, 0.004, 0.0, 0.009],
        ..payload()
    };
    let e = said(&[run(&a, &ia, None), run(&b, &ib, Some(&flat))]);
    assert!(e.contains("run 1: payload ([ixx"), "{e}");
    let short = &ib[..ib.len() - 6];
    let e = said(&[run(&a, &ia, None), run(&b, short, Some(&p))]);
    assert!(e.contains("run 1") && e.contains("signal"), "{e}");
    let no_velocity = GainRun {
        states: States::new(6, &b.q, None, None).unwrap(),
        signal: &ib,
        payload: Some(&p),
    };
    let e = said(&[run(&a, &ia, None), no_velocity]);
    assert!(e.contains("run 1 has no velocities"), "{e}");
}

#[test]
fn a_signal_that_counts_the_other_way_gets_a_negative_gain_and_is_named() {
    let mut logs = logs(1e-4, true);
    for i in logs
        .ia
        .iter_mut()
        .chain(logs.ib.iter_mut())
        .skip(1)
        .step_by(6)
    {
        *i = -*i;
    }
    let truth = &logs.truth;
    let fit = identify_drive_gains(truth, &logs.runs(), &BaseOptions::default()).unwrap();
    let g = fit.gains();
    assert!((g.gain[1] / -GAINS[1] - 1.0).abs() < 1e-2, "{g:?}");
    let w = g.warnings(&truth.joint_names);
    assert!(
        w.len() == 1 && w[0].contains("'joint2' is negative"),
        "{w:?}"
    );
}

#[test]
fn a_run_logged_without_the_payload_given_is_named() {
    // both runs of the robot alone, the second given as loaded: the fit goes through, and the
    // residuals say that the runs and the payload do not agree
    let logs = logs(1e-4, false);
    let fit = identify_drive_gains(&logs.truth, &logs.runs(), &BaseOptions::default()).unwrap();
    let g = fit.gains();
    assert!(g.agreement.iter().any(|a| *a > 10.0), "{:?}", g.agreement);
    let w = fit.model.warnings();
    assert!(
        w.iter()
            .any(|w| w.contains("the runs do not agree with the payload as given")),
        "{w:?}"
    );
}

#[test]
fn the_noise_bias_says_what_a_noisy_signal_does_to_the_gains() {
    // currents noisy against the part the payload explains: the gains come out low by about
    // what the estimate says (every residual here is the signal's noise)
    let logs = logs(5e-4, true);
    let truth = &logs.truth;
    let fit = identify_drive_gains(truth, &logs.runs(), &BaseOptions::default()).unwrap();
    let g = fit.gains();
    let mut warned = 0;
    for (j, truth) in GAINS.iter().enumerate() {
        let low = 1.0 - g.gain[j] / truth;
        assert!(
            (low - g.noise_bias[j]).abs() < 3.0 * g.stderr[j] / truth,
            "joint {j}: {low} low, estimated {} (s.e. {})",
            g.noise_bias[j],
            g.stderr[j] / truth
        );
        warned += usize::from(g.noise_bias[j] > 0.01);
    }
    // the base joint and the wrist's roll joints, which the payload loads least
    assert_eq!(warned, 3, "{g:?}");
    let w = g.warnings(&truth.joint_names);
    assert!(
        w.iter().filter(|w| w.contains("biased towards 0")).count() == warned,
        "{w:?}"
    );
}

#[test]
fn saved_gains_are_checked_on_load() {
    let logs = logs(1e-4, true);
    let truth = &logs.truth;
    let fit = identify_drive_gains(truth, &logs.runs(), &BaseOptions::default()).unwrap();
    let json: serde_json::Value = serde_json::from_str(&fit.model.to_json()).unwrap();
    refused_on_load::<BaseModel>(
        &json,
        &[
            (
                |v| v["drive_gains"]["gain"][2] = serde_json::json!(0.0),
                "drive_gains.gain[2] is 0, expected a finite gain other than 0",
            ),
            (
                |v| v["drive_gains"]["stderr"] = serde_json::json!([1.0]),
                "drive_gains.stderr has 1 entries, expected one per joint (6)",
            ),
            (
                |v| v["drive_gains"]["noise_bias"][0] = serde_json::json!(-1.0),
                "drive_gains.noise_bias[0] is -1",
            ),
            (
                |v| v["drive_gains"]["loaded_runs"] = serde_json::json!(0),
                "at least one loaded",
            ),
            (
                |v| v["drive_gains"]["gain"][0] = serde_json::json!(1e300),
                "drive_gains.gain[0] is 1e300",
            ),
            (
                |v| v["drive_gains"]["agreement"][5] = serde_json::json!(null),
                "drive_gains.agreement[5]",
            ),
            (
                |v| v["joint_term_rms"] = serde_json::json!([1.0]),
                "joint_term_rms has 1 entries, expected one per joint and joint term",
            ),
            (
                |v| v["drive_gains"]["correlation"] = serde_json::json!([[1.0]]),
                "drive_gains.correlation is 1 x 1, expected one row per joint (6)",
            ),
            (
                |v| v["drive_gains"]["correlation"][2][0] = serde_json::json!(1.5),
                "correlation with drive_gains.correlation, row",
            ),
            (
                |v| v["correlation"] = serde_json::json!([]),
                "a column for each of the model's 0 parameters",
            ),
        ],
    );
    // a model saved before the gains' correlation was: its signal predicted, without
    // standard errors
    let mut old = json.clone();
    old["drive_gains"]
        .as_object_mut()
        .unwrap()
        .remove("correlation");
    let old = BaseModel::from_json(&old.to_string()).unwrap();
    let s = states(&logs.a);
    assert_eq!(
        old.predict_signal(truth, &s).unwrap(),
        fit.model.predict_signal(truth, &s).unwrap()
    );
    let e = old
        .predict_signal_stderr(truth, &s)
        .unwrap_err()
        .to_string();
    assert!(e.contains("a model saved before it was stored"), "{e}");
    // and a model fitted to torques has no signal
    let plain = perturbid_rs::direct::identify_base_parameters(
        truth,
        &s,
        &fit.model.predict(truth, &s).unwrap(),
        &BaseOptions::default(),
    )
    .unwrap();
    let e = plain.predict_signal(truth, &s).unwrap_err().to_string();
    assert!(e.contains("holds no drive gains"), "{e}");
}

#[test]
fn a_recording_of_currents_in_torques_keeps_what_was_found() {
    use perturbid_rs::logs::log_screening::LogGlitch;
    use perturbid_rs::logs::torque_saturation::TorqueSaturation;
    let t: Vec<f64> = (0..4).map(|i| i as f64 * 0.01).collect();
    let q = vec![0.1; 8];
    let current = vec![1.0, 2.0, -1.0, 0.5, 3.0, -2.0, 0.0, 1.0];
    let mut rec =
        perturbid_rs::Recording::new("log", 2, t, q, current, Some(vec![0.2; 8]), None).unwrap();
    rec.torque_saturation = vec![TorqueSaturation {
        joint: 1,
        level: 2.0,
        upper: true,
        runs: 1,
        samples: 2,
        longest: 2,
        first_at: 0.01,
        beyond: 0.3,
        spans: vec![],
    }];
    rec.glitches = vec![LogGlitch {
        signal: "tau".into(),
        joint: 0,
        sample: 2,
        time: 0.02,
        value: 9.0,
        noise_levels: Some(40.0),
        replaced_by: 3.0,
        repeats_previous: false,
        held: None,
        experiment: None,
    }];
    let torques = rec.in_torques(&[10.0, -4.0]).unwrap();
    assert_eq!(
        torques.tau,
        vec![10.0, -8.0, -10.0, -2.0, 30.0, 8.0, 0.0, -4.0]
    );
    assert_eq!(torques.qd, rec.qd);
    let c = &torques.torque_saturation[0];
    assert_eq!((c.level, c.beyond, c.upper), (-8.0, 1.2, false));
    let g = &torques.glitches[0];
    assert_eq!(
        (g.value, g.replaced_by, g.noise_levels),
        (90.0, 30.0, Some(40.0))
    );
    for (gains, says) in [
        (vec![1.0], "1 gains for 2 joints"),
        (vec![1.0, 0.0], "the gain of joint 2 is 0"),
        (vec![f64::NAN, 1.0], "the gain of joint 1 is NaN"),
    ] {
        let e = rec.in_torques(&gains).unwrap_err().to_string();
        assert!(e.contains(says), "{e}");
    }
}

#[test]
fn the_predicted_signals_standard_errors_match_the_scatter_over_noise_draws() {
    // 30 identifications from the same two motions, the currents' noise drawn anew each time:
    // the predicted currents on a third motion scatter as their standard errors say (the
    // torques' standard errors over |K| would say several times more on the joints the
    // payload loads least). By least squares on quiet currents; by instrumental variables on
    // noisy ones, where least squares' biased gains leave correlated residuals that inflate
    // its standard errors (docs/method.md, section 8c)
    // (measured: 0.96-1.09 by least squares; 0.77-1.55 by instrumental variables, whose
    // standard errors are asymptotic, on currents that bias least squares by 7 %)
    scatter_against_stderr(1e-4, GainEstimator::LeastSquares, 0.75..1.35);
    scatter_against_stderr(5e-4, GainEstimator::Instrumental, 0.6..1.8);
}

/// The median over a joint's samples of the predicted signal's standard error over its
/// scatter, within `bounds` for every joint.
fn scatter_against_stderr(noise: f64, estimator: GainEstimator, bounds: std::ops::Range<f64>) {
    let (truth, p) = (truth(), payload());
    let (a, b, c) = (motion(3), motion(4), motion(5));
    let third = states(&c);
    let (draws, rows) = (30, c.q.len());
    let (mut preds, mut ses, mut naive) = (vec![], vec![0.0; rows], vec![0.0; rows]);
    for d in 0..draws as u64 {
        let ia = currents(&truth, &a, None, noise, 100 + 2 * d);
        let ib = currents(&truth, &b, Some(&p), noise, 101 + 2 * d);
        let runs = common::gain_logs::alone_then_loaded([&a, &b], [&ia, &ib], &p);
        let fit =
            identify_drive_gains_with(&truth, &runs, &BaseOptions::default(), estimator).unwrap();
        let g = fit.gains().gain.clone();
        preds.push(fit.model.predict_signal(&truth, &third).unwrap());
        let se = fit.model.predict_signal_stderr(&truth, &third).unwrap();
        let torque_se = fit.model.predict_stderr(&truth, &third).unwrap();
        for r in 0..rows {
            ses[r] += se[r] / draws as f64;
            naive[r] += torque_se[r] / g[r % 6].abs() / draws as f64;
        }
    }
    let scatter: Vec<f64> = (0..rows)
        .map(|r| {
            let mean = preds.iter().map(|x| x[r]).sum::<f64>() / draws as f64;
            let var = preds.iter().map(|x| (x[r] - mean).powi(2)).sum::<f64>();
            (var / (draws - 1) as f64).sqrt()
        })
        .collect();
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut overstated = 0;
    for j in 0..6 {
        let rows_j = (j..rows).step_by(6 * 50);
        let mut own: Vec<f64> = rows_j.clone().map(|r| ses[r] / scatter[r]).collect();
        let mut theirs: Vec<f64> = rows_j.map(|r| naive[r] / scatter[r]).collect();
        let (own, theirs) = (median(&mut own), median(&mut theirs));
        assert!(bounds.contains(&own), "{estimator:?}, joint {j}: {own}");
        overstated += usize::from(theirs > 2.0);
    }
    assert!(overstated >= 2, "{overstated}");
}
