//! Drive gains by instrumental variables (src/direct/instrumental.rs): on currents noisy enough
//! to bias least squares by several per cent, the instrumental gains come back within their
//! standard errors and the least-squares ones, kept beside them, are the biased ones; the
//! estimate equals the dense instrumental-variable solution `(Z^T X)^-1 Z^T y` (nalgebra's LU)
//! with the instruments predicted by the dense least-squares fit; saved gains keep their
//! estimator and are checked on load. (Against numpy over Pinocchio's regressor:
//! tests/python/test_drive_gains.py.)

mod common;

use common::gain_logs::{dense_least_squares, dense_logs, logs, GAINS};
use common::refused_on_load;
use nalgebra::DMatrix;
use perturbid_rs::direct::{
    identify_drive_gains, identify_drive_gains_with, BaseModel, BaseOptions, GainEstimator,
};
use perturbid_rs::document::Document;

#[test]
fn instrumental_variables_remove_the_bias_the_noise_gives_least_squares() {
    let logs = logs(5e-4, true);
    let truth = &logs.truth;
    let o = BaseOptions::default();
    let ls = identify_drive_gains(truth, &logs.runs(), &o).unwrap();
    let iv =
        identify_drive_gains_with(truth, &logs.runs(), &o, GainEstimator::Instrumental).unwrap();
    let (l, g) = (ls.gains(), iv.gains());
    assert_eq!(
        (l.estimator, g.estimator),
        (GainEstimator::LeastSquares, GainEstimator::Instrumental)
    );
    assert!(l.least_squares_gain.is_empty());
    // the least-squares fit is the first step, kept whole
    assert_eq!(g.least_squares_gain, l.gain);
    assert_eq!(g.noise_bias, l.noise_bias);
    let mut biased = 0;
    for (j, truth) in GAINS.iter().enumerate() {
        let (k, se) = (g.gain[j], g.stderr[j]);
        assert!(
            (k - truth).abs() < 3.5 * se,
            "joint {j}: {k} +- {se}, truth {truth}"
        );
        // what least squares lost is what its bias estimate says (every residual noise here)
        let shift = 1.0 - l.gain[j] / k;
        assert!(
            (shift - l.noise_bias[j]).abs() < 0.25 * l.noise_bias[j] + 2e-3,
            "joint {j}: least squares {shift} low, estimated {}",
            l.noise_bias[j]
        );
        if l.noise_bias[j] > 0.01 {
            biased += 1;
            assert!(
                (l.gain[j] - truth).abs() > 3.0 * (k - truth).abs(),
                "joint {j}: least squares {} against {k}, truth {truth}",
                l.gain[j]
            );
            // the price: a larger variance
            // the price: a larger variance (the standard errors before their inflation for
            // correlated residuals, which least squares' biased gains leave in the torques)
            let (own, theirs) = (
                se / iv.model.stderr_inflation(),
                l.stderr[j] / ls.model.stderr_inflation(),
            );
            assert!(own > theirs, "joint {j}: {own} against {theirs}");
        }
    }
    assert_eq!(biased, 3, "{l:?}");
    // no bias to warn of, and the robot's model is the instrumental one
    let w = iv.model.warnings();
    assert!(!w.iter().any(|w| w.contains("biased towards 0")), "{w:?}");
    assert!(ls
        .model
        .warnings()
        .iter()
        .any(|w| w.contains("estimate by instrumental variables")));
    assert_ne!(iv.model.theta, ls.model.theta);
    for (j, r) in iv.model.residual_rms.iter().enumerate() {
        assert!(
            (r / (5e-4 * GAINS[j]) - 1.0).abs() < 0.1,
            "joint {j}: residual {r} N m for noise {}",
            5e-4 * GAINS[j]
        );
    }
    assert_eq!(BaseModel::from_json(&iv.model.to_json()).unwrap(), iv.model);
}

#[test]
fn the_instrumental_estimate_is_the_dense_one() {
    // OLS: the instruments come from the unweighted least-squares fit
    let (fit, x, y) = dense_logs().ols_and_dense(GainEstimator::Instrumental);
    let first = dense_least_squares(&x, &y);
    let (n, cols) = (6, x.ncols());
    let pb = cols - n;
    // Z: the signal's columns replaced by the signal the first fit predicts
    let predicted = x.columns(0, pb) * nalgebra::DVector::from_column_slice(&first[..pb]) - &y;
    let z = DMatrix::from_fn(x.nrows(), cols, |r, c| {
        if c < pb {
            x[(r, c)]
        } else if r % n == c - pb {
            predicted[r] / first[c]
        } else {
            0.0
        }
    });
    // (Z^T X) beta = Z^T y, columns scaled to unit norm for the LU
    let scale: Vec<f64> = (0..cols).map(|c| x.column(c).norm()).collect();
    let xs = DMatrix::from_fn(x.nrows(), cols, |r, c| x[(r, c)] / scale[c]);
    let zs = DMatrix::from_fn(z.nrows(), cols, |r, c| z[(r, c)] / scale[c]);
    let beta = (zs.transpose() * &xs)
        .lu()
        .solve(&(zs.transpose() * &y))
        .unwrap();
    let beta: Vec<f64> = (0..cols).map(|c| beta[c] / scale[c]).collect();
    let g = fit.gains();
    for j in 0..n {
        let rel = (g.gain[j] - beta[pb + j]).abs() / beta[pb + j].abs();
        assert!(
            rel < 1e-8,
            "gain {j}: {} against {}",
            g.gain[j],
            beta[pb + j]
        );
        let ls = (g.least_squares_gain[j] - first[pb + j]).abs() / first[pb + j].abs();
        assert!(ls < 1e-8, "least-squares gain {j}");
    }
    for (c, (t, d)) in fit.model.theta.iter().zip(&beta).enumerate() {
        assert!(
            (t - d).abs() < 1e-7 * d.abs().max(1.0),
            "theta[{c}]: {t} against {d}"
        );
    }
    // the standard errors: sigma^2 (Z^T X)^-1 Z^T Z (X^T Z)^-1, sigma from the residuals
    let residual = &y - &x * nalgebra::DVector::from_column_slice(&beta);
    let dof = (x.nrows() - cols) as f64;
    let s2 = residual.norm_squared() / dof;
    let inverse = (zs.transpose() * &xs).try_inverse().unwrap();
    let cov = &inverse * (zs.transpose() * &zs) * inverse.transpose() * s2;
    let inflation = fit.model.stderr_inflation();
    for j in 0..n {
        let se = cov[(pb + j, pb + j)].sqrt() / scale[pb + j] * inflation;
        assert!(
            (g.stderr[j] / se - 1.0).abs() < 1e-6,
            "gain {j}: s.e. {} against {se}",
            g.stderr[j]
        );
    }
}

#[test]
fn saved_instrumental_gains_keep_their_estimator_and_are_checked_on_load() {
    let logs = logs(1e-4, true);
    let fit = identify_drive_gains_with(
        &logs.truth,
        &logs.runs(),
        &BaseOptions::default(),
        GainEstimator::Instrumental,
    )
    .unwrap();
    let json: serde_json::Value = serde_json::from_str(&fit.model.to_json()).unwrap();
    assert_eq!(json["drive_gains"]["estimator"], "instrumental");
    refused_on_load::<BaseModel>(
        &json,
        &[
            (
                |v| v["drive_gains"]["least_squares_gain"] = serde_json::json!([1.0, 2.0]),
                "drive_gains.least_squares_gain has 2 entries, expected one per joint (6)",
            ),
            (
                |v| v["drive_gains"]["estimator"] = serde_json::json!("least_squares"),
                "has 6 entries for gains by least squares, expected none",
            ),
            (
                |v| v["drive_gains"]["estimator"] = serde_json::json!("bayes"),
                "unknown variant `bayes`",
            ),
            (
                |v| v["drive_gains"]["least_squares_gain"][3] = serde_json::json!(1e300),
                "drive_gains.least_squares_gain[3] is 1e300",
            ),
        ],
    );
    // a model saved before the estimator was: least squares
    let mut old = json.clone();
    let gains = old["drive_gains"].as_object_mut().unwrap();
    gains.remove("estimator");
    gains.remove("least_squares_gain");
    let loaded = BaseModel::from_json(&old.to_string()).unwrap();
    let g = loaded.drive_gains.unwrap();
    assert_eq!(g.estimator, GainEstimator::LeastSquares);
    assert!(g.least_squares_gain.is_empty());
}
