//! The standard errors of a local model's predictions: the coefficients' correlation against
//! `(X^T W X)^-1` formed directly, and the predicted standard errors against the scatter of the
//! predictions over identifications of many noisy simulations.

mod common;

use common::{a465_excitation, table2, torques, Rng};
use nalgebra::DMatrix;
use perturbid_rs::direct::{
    identify_base_parameters, BaseModel, BaseOptions, FrictionTerms, Weighting,
};
use perturbid_rs::local::noise::weighted_least_squares;
use perturbid_rs::local::{
    identify_local, plan_experiments, Estimator, ExperimentKind, IdentifyOptions, LocalModel,
    PlanOptions,
};
use perturbid_rs::regression::least_squares;
use perturbid_rs::robots::a465;
use perturbid_rs::{simulate_plan, Document, Friction, Gravity, SimulationOptions, States};

const NOISE: f64 = 0.3;

fn correlation_of(c: &DMatrix<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(c.nrows(), c.ncols(), |a, b| {
        c[(a, b)] / (c[(a, a)] * c[(b, b)]).sqrt()
    })
}

fn max_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax()
}

/// The correlation least squares reports is `(X^T X)^-1` scaled to a unit diagonal, for
/// columns of very different scales; a weighted fit's is `(X^T W X)^-1`'s, per output.
#[test]
fn coefficient_correlations_are_those_of_the_inverse_normal_matrix() {
    let mut rng = Rng(7);
    let (k, p) = (40, 5);
    let scales = [1.0, 1e-3, 30.0, 0.2, 5e2];
    let x = DMatrix::from_fn(k, p, |i, j| {
        scales[j] * (rng.uniform(-0.5, 0.5) + 0.3 * (i % 3) as f64 * (j % 2) as f64)
    });
    let y = DMatrix::from_fn(k, 2, |_, _| rng.uniform(0.0, 1.0));
    let names: Vec<String> = (0..p).map(|j| format!("x{j}")).collect();
    let fit = least_squares(&x, &y, "test", &names).unwrap();
    let direct = correlation_of(&(x.transpose() * &x).try_inverse().unwrap());
    assert!(
        max_diff(&fit.correlation, &direct) < 1e-9,
        "{} against {direct}",
        fit.correlation
    );
    // off-diagonal entries that matter, so the comparison says something
    assert!(direct.iter().any(|v| v.abs() > 0.2 && v.abs() < 0.999));
    // rows of unequal noise: output 0's weights differ from output 1's
    let u = DMatrix::from_fn(k, 2, |i, c| {
        if c == 0 {
            1e-4 * (1 + i % 5) as f64
        } else {
            1e-4
        }
    });
    let weighted = weighted_least_squares(&x, &y, &u, "test", &names).unwrap();
    assert_eq!(weighted.correlation.len(), 2);
    let a = weighted.common[0];
    let w = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(k, |i, _| 1.0 / (a + u[(i, 0)])));
    let direct = correlation_of(&(x.transpose() * w * &x).try_inverse().unwrap());
    assert!(
        max_diff(&weighted.correlation[0], &direct) < 1e-9,
        "{} against {direct}",
        weighted.correlation[0]
    );
    assert!(max_diff(&weighted.correlation[1], &fit.correlation) < 1e-12);
}

/// Over 200 noisy simulations of the paper's plan on the A465, the predictions' scatter at
/// states off the operating point matches the standard errors `predict_stderr` gives, for the
/// separated and the combined estimators. From each entry's standard error alone (the rows'
/// correlations left out) they would come out 2.6 times the scatter: the perturbations of a
/// design fix some combinations of a row's entries far better than each entry.
///
/// The torque noise (0.3 N m) is far above the perturbations' second-order effects, which the
/// +- pairs cancel in the estimates but not in the residuals: at 0.01 N m those residuals
/// dominate the standard errors, which then exceed the scatter from noise (up to 5 times at
/// H's perturbations; docs/method.md, section 4).
#[test]
fn predicted_standard_errors_match_the_scatter_of_predictions_over_seeds() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let deltas = |kind| plan.experiment(kind).unwrap().deltas.clone();
    let (d, h, g) = (
        deltas(ExperimentKind::D),
        deltas(ExperimentKind::H),
        deltas(ExperimentKind::GDynamic),
    );
    // the operating point, then D's, H's and G's perturbations alone and all three at once
    let row = |m: &DMatrix<f64>, i: usize, s: f64| -> Vec<f64> {
        (0..n).map(|j| s * m[(i % m.nrows(), j)]).collect()
    };
    let zero = vec![0.0; n];
    let offsets: Vec<[Vec<f64>; 3]> = vec![
        [zero.clone(), zero.clone(), zero.clone()],
        [zero.clone(), zero.clone(), row(&d, 1, 1.0)],
        [zero.clone(), row(&h, 2, 1.0), zero.clone()],
        [row(&g, 3, 1.0), zero.clone(), zero.clone()],
        [row(&g, 0, 0.7), row(&h, 5, -0.8), row(&d, 4, 0.9)],
    ];
    let m = offsets.len();
    let mut q = vec![];
    let (mut qd, mut qdd) = (vec![], vec![]);
    for [dq, dqd, dqdd] in &offsets {
        for j in 0..n {
            q.push(op.q[j] + dq[j]);
            qd.push(op.qd[j] + dqd[j]);
            qdd.push(op.qdd[j] + dqdd[j]);
        }
    }
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let seeds = 200;
    let estimators = [Estimator::Separated, Estimator::Combined];
    // per estimator: predictions and squared standard errors, m x n each, over the seeds
    let mut predictions = vec![vec![vec![]; m * n]; 2];
    let mut variances = vec![vec![0.0; m * n]; 2];
    let mut diagonal = vec![vec![0.0; m * n]; 2];
    for seed in 0..seeds {
        let mut sim = SimulationOptions::new(&model);
        sim.gravity = Gravity::Included;
        sim.friction = Friction::none(n);
        sim.torque_noise = vec![NOISE; n];
        sim.seed = 5000 + seed;
        let recs = simulate_plan(&model, &plan, &sim).unwrap();
        for (e, estimator) in estimators.iter().enumerate() {
            let options = IdentifyOptions {
                estimator: *estimator,
                ..IdentifyOptions::default()
            };
            let local = identify_local(&plan, &recs, &options).unwrap();
            let p = local.predict(&states).unwrap();
            let se = local.predict_stderr(&states).unwrap();
            let plain = uncorrelated(&local, &offsets);
            for i in 0..m * n {
                predictions[e][i].push(p[i]);
                variances[e][i] += se[i] * se[i] / seeds as f64;
                diagonal[e][i] += plain[i] / seeds as f64;
            }
        }
    }
    for (e, estimator) in estimators.iter().enumerate() {
        let mut ratios = vec![];
        for i in 0..m * n {
            let v = &predictions[e][i];
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd =
                (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
            ratios.push((sd / variances[e][i].sqrt(), sd / diagonal[e][i].sqrt()));
        }
        let mean = |f: &dyn Fn(&(f64, f64)) -> f64| {
            ratios.iter().map(f).sum::<f64>() / ratios.len() as f64
        };
        eprintln!(
            "{estimator:?}: scatter / standard error, mean {:.3} (without the correlations {:.3}); per state and joint {:?}",
            mean(&|r| r.0),
            mean(&|r| r.1),
            ratios.iter().map(|r| (r.0 * 100.0).round() / 100.0).collect::<Vec<_>>()
        );
        assert!(
            (0.85..1.1).contains(&mean(&|r| r.0)) && mean(&|r| r.1) < 0.6,
            "{estimator:?}: scatter / standard error {ratios:?}"
        );
        for (i, r) in ratios.iter().enumerate() {
            assert!(
                (0.7..1.35).contains(&r.0),
                "{estimator:?}, state {}, joint {}: scatter / standard error {}",
                i / n,
                i % n + 1,
                r.0
            );
        }
    }
}

/// The variance each prediction would be given from the entries' standard errors alone (the
/// correlations taken as the identity).
fn uncorrelated(local: &LocalModel, offsets: &[[Vec<f64>; 3]]) -> Vec<f64> {
    let n = local.n();
    let parts: Vec<(&DMatrix<f64>, Vec<usize>)> = match local.estimator {
        Estimator::Combined => vec![(&local.combined.as_ref().unwrap().stderr, vec![2, 1, 0])],
        Estimator::Separated => vec![
            (&local.d.as_ref().unwrap().stderr, vec![2]),
            (&local.h.as_ref().unwrap().stderr, vec![1]),
            (&local.g.as_ref().unwrap().stderr, vec![0]),
        ],
    };
    let mut out = vec![];
    for o in offsets {
        for j in 0..n {
            let mut v = local.torque_stderr[j].powi(2);
            for (se, vars) in &parts {
                for (b, var) in vars.iter().enumerate() {
                    for a in 0..n {
                        v += (o[*var][a] * se[(j, b * n + a)]).powi(2);
                    }
                }
            }
            out.push(v);
        }
    }
    out
}

type Edit<'a> = &'a dyn Fn(&mut serde_json::Value);

/// The correlations survive a JSON round trip; a model saved without them predicts but refuses
/// `predict_stderr` with the reason; hand-edited correlations that are no correlations are
/// refused on loading, naming the estimate, matrix, row and column.
#[test]
fn correlations_are_saved_and_checked_on_loading() {
    let common::Table2Local {
        model, op, local, ..
    } = common::table2_local();
    let n = model.nv;
    for e in [
        &local.d,
        &local.h,
        &local.g,
        &local.g_static,
        &local.combined,
    ] {
        let e = e.as_ref().unwrap();
        assert_eq!(e.correlation.len(), n);
        assert_eq!(
            e.correlation[0].shape(),
            (e.matrix.ncols(), e.matrix.ncols())
        );
    }
    let text = local.to_json();
    let back = LocalModel::from_json(&text).unwrap();
    assert_eq!(back, local);
    let states = States::new(n, &op.q, Some(&op.qd), Some(&op.qdd)).unwrap();
    // at the operating point the prediction's standard error is T*'s
    let se = back.predict_stderr(&states).unwrap();
    for j in 0..n {
        assert!(
            (se[j] - local.torque_stderr[j]).abs() <= 1e-15 * se[j],
            "{se:?}"
        );
    }

    let edited = |f: &dyn Fn(&mut serde_json::Value)| -> Result<LocalModel, String> {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        f(&mut v);
        LocalModel::from_json(&v.to_string()).map_err(|e| e.to_string())
    };
    // saved before the correlations were stored
    let old = edited(&|v| {
        for k in ["d", "h", "g", "g_static", "combined"] {
            v[k].as_object_mut().unwrap().remove("correlation");
        }
    })
    .unwrap();
    assert!(old.predict(&states).is_ok());
    let e = old.predict_stderr(&states).unwrap_err().to_string();
    assert!(
        e.contains("holds no correlation") && e.contains("identify it again"),
        "{e}"
    );
    // unknown standard errors (null): T*'s makes its joint's NaN everywhere; an entry's only
    // where the state weights it
    let unknown = edited(&|v| {
        v["torque_stderr"][0] = serde_json::Value::Null;
        v["d"]["stderr"][1][2] = serde_json::Value::Null;
    })
    .unwrap();
    let se = unknown.predict_stderr(&states).unwrap();
    assert!(
        se[0].is_nan() && se[1..].iter().all(|v| v.is_finite()),
        "{se:?}"
    );
    let mut qdd = op.qdd.clone();
    qdd[2] += 0.1;
    let off = States::new(n, &op.q, Some(&op.qd), Some(&qdd)).unwrap();
    let se = unknown.predict_stderr(&off).unwrap();
    assert!(se[0].is_nan() && se[1].is_nan(), "{se:?}");
    assert!(se[2..].iter().all(|v| v.is_finite() && *v > 0.0), "{se:?}");
    // deltas whose squares overflow are refused, not reported as unknown
    let mut qdd = op.qdd.clone();
    (qdd[2], qdd[3]) = (1e200, -1e200);
    let huge = States::new(n, &op.q, Some(&op.qd), Some(&qdd)).unwrap();
    let e = local.predict_stderr(&huge).unwrap_err().to_string();
    assert!(e.contains("overflows"), "{e}");
    let cases: [(&str, Edit); 5] = [
        (
            "matrix 2, row 1, column 3 is 1.5; expected a correlation in [-1, 1]",
            &|v| v["d"]["correlation"][1][0][2] = 1.5.into(),
        ),
        (
            "matrix 1, row 2, column 2 is 0.5; expected 1 on the diagonal",
            &|v| v["h"]["correlation"][0][1][1] = 0.5.into(),
        ),
        ("expected a symmetric matrix", &|v| {
            v["g"]["correlation"][0][0][1] = 0.3.into()
        }),
        ("5 matrices; expected one per torque (6) or none", &|v| {
            v["d"]["correlation"].as_array_mut().unwrap().pop();
        }),
        ("matrix 1 is not positive semi-definite", &|v| {
            // three estimates each correlated -0.9 with the others: no correlation matrix
            for (a, b) in [(0, 1), (0, 2), (1, 2)] {
                v["d"]["correlation"][0][a][b] = (-0.9).into();
                v["d"]["correlation"][0][b][a] = (-0.9).into();
            }
        }),
    ];
    for (expected, f) in cases {
        let e = edited(f).unwrap_err();
        assert!(
            e.contains(expected) && e.contains("correlation"),
            "{e}\nexpected: {expected}"
        );
    }
}

/// A base-parameter model's predicted standard errors against the scatter of its predictions
/// over 100 identifications from one A465 excitation (1,000 samples) with white torque noise,
/// at states on the trajectory and off it; the correlation survives a JSON round trip, a model
/// saved without it refuses `predict_stderr`, and a hand-edited one is refused on loading.
#[test]
fn base_model_predicted_standard_errors_match_the_scatter_over_seeds() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let traj = a465_excitation(&mut Rng(21));
    let s = traj.sample_periods(1.0, 100.0).unwrap();
    let mut rng = Rng(21);
    let exact = torques(&model, &s.q, &s.qd, &s.qdd, Gravity::Included);
    let states = States::new(n, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    // three samples of the trajectory and one off it
    let (mut q, mut qd, mut qdd) = (vec![], vec![], vec![]);
    for (i, shift) in [(37, 0.0), (250, 0.0), (611, 0.0), (420, 0.15)] {
        let r = i * n..(i + 1) * n;
        q.extend(s.q[r.clone()].iter().map(|v| v + shift));
        qd.extend(s.qd[r.clone()].iter().map(|v| v - shift));
        qdd.extend(s.qdd[r].iter().map(|v| v + 2.0 * shift));
    }
    let test = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let m = q.len();
    let options = BaseOptions {
        friction: FrictionTerms::NONE,
        weighting: Weighting::Ols,
        ..BaseOptions::default()
    };
    let seeds = 100;
    let mut predictions = vec![vec![]; m];
    let mut variances = vec![0.0; m];
    let mut last = None;
    for _ in 0..seeds {
        let tau: Vec<f64> = (exact.iter())
            .map(|t| {
                // Box-Muller
                let (u, v) = (rng.uniform(1e-12, 1.0), rng.uniform(0.0, 1.0));
                t + 0.05 * (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
            })
            .collect();
        let fit = identify_base_parameters(&model, &states, &tau, &options).unwrap();
        let p = fit.predict(&model, &test).unwrap();
        let se = fit.predict_stderr(&model, &test).unwrap();
        for i in 0..m {
            predictions[i].push(p[i]);
            variances[i] += se[i] * se[i] / seeds as f64;
        }
        last = Some(fit);
    }
    let ratios: Vec<f64> = (0..m)
        .map(|i| {
            let v = &predictions[i];
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd =
                (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
            sd / variances[i].sqrt()
        })
        .collect();
    let mean = ratios.iter().sum::<f64>() / m as f64;
    eprintln!("base-parameter model: scatter / standard error, mean {mean:.3}; {ratios:.2?}");
    assert!((0.85..1.15).contains(&mean), "{ratios:?}");
    assert!(ratios.iter().all(|r| (0.65..1.4).contains(r)), "{ratios:?}");

    let fit = last.unwrap();
    let p = fit.theta.len();
    assert_eq!(fit.correlation.shape(), (p, p));
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let edited = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        f(&mut v);
        BaseModel::from_json(&v.to_string()).map_err(|e| e.to_string())
    };
    let old = edited(&|v| {
        v.as_object_mut().unwrap().remove("correlation");
    })
    .unwrap();
    let e = old.predict_stderr(&model, &test).unwrap_err().to_string();
    assert!(
        e.contains("holds no correlation") && e.contains("identify it again"),
        "{e}"
    );
    // a parameter of unknown standard error: NaN for the joints whose rows weigh it, not 0
    let unknown = edited(&|v| v["stderr"][0] = serde_json::Value::Null).unwrap();
    let se = unknown.predict_stderr(&model, &test).unwrap();
    let known = fit.predict_stderr(&model, &test).unwrap();
    assert!(se.iter().any(|v| v.is_nan()), "{se:?}");
    for (a, b) in se.iter().zip(&known) {
        assert!(a.is_nan() || (a - b).abs() <= 1e-12 * b, "{a} against {b}");
    }
    let huge: Vec<f64> = qdd.iter().map(|v| v * 1e200).collect();
    let huge = States::new(n, &q, Some(&qd), Some(&huge)).unwrap();
    let e = fit.predict_stderr(&model, &huge).unwrap_err().to_string();
    assert!(e.contains("overflows"), "{e}");
    let e = edited(&|v| {
        v["correlation"][1][0] = 2.0.into();
        v["correlation"][0][1] = 2.0.into();
    })
    .unwrap_err();
    assert!(
        e.contains("correlation, row 1, column 2 is 2; expected a correlation in [-1, 1]"),
        "{e}"
    );
    let e = edited(&|v| {
        v["correlation"].as_array_mut().unwrap().pop();
    })
    .unwrap_err();
    assert!(
        e.contains(&format!(
            "correlation is {} x {p}; expected {p} x {p}",
            p - 1
        )),
        "{e}"
    );
}

/// A local model identified from currents put in torques by drive gains
/// (`identify --gains-from`): the gains' standard errors enter its predictions' as the
/// prediction's change with each gain (by finite differences: every coefficient of joint j's
/// row scaled by the gain) times the gain's standard error, independent of the local fit's;
/// saved, and checked on loading.
#[test]
fn the_drive_gains_standard_errors_enter_a_local_models_predictions() {
    let common::Table2Local {
        model,
        op,
        local: plain,
        ..
    } = common::table2_local();
    let n = model.nv;
    let gain = vec![42.0, 65.0, 38.0, 9.0, 7.5, -4.0];
    let stderr = vec![0.05, 0.02, 0.03, 0.01, 0.02, 0.004];
    let with = LocalModel {
        drive_gains: Some(perturbid_rs::local::SignalGains {
            gain: gain.clone(),
            stderr: stderr.clone(),
        }),
        ..plain.clone()
    };
    let (mut q, mut qd, mut qdd) = (op.q.clone(), op.qd.clone(), op.qdd.clone());
    q[1] += 0.01;
    qd[2] -= 0.05;
    qdd[0] += 0.2;
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let (se0, se) = (
        plain.predict_stderr(&states).unwrap(),
        with.predict_stderr(&states).unwrap(),
    );
    let tau = plain.predict(&states).unwrap();
    for j in 0..n {
        // the model with joint j's gain moved by h: its row's T*, D*, H*, G* scale with it
        let h = 1e-6 * gain[j].abs();
        let mut moved = plain.clone();
        let scale = (gain[j] + h) / gain[j];
        moved.torque[j] *= scale;
        for e in [&mut moved.d, &mut moved.h, &mut moved.g] {
            let e = e.as_mut().unwrap();
            for c in 0..n {
                e.matrix[(j, c)] *= scale;
            }
        }
        let slope = (moved.predict(&states).unwrap()[j] - tau[j]) / h;
        let expected = se0[j].hypot(slope * stderr[j]);
        assert!(
            (se[j] / expected - 1.0).abs() < 1e-6,
            "joint {j}: {} against {expected} (without the gains {})",
            se[j],
            se0[j]
        );
        assert!(se[j] > se0[j], "joint {j}");
    }
    let text = with.to_json();
    assert_eq!(LocalModel::from_json(&text).unwrap(), with);
    let edited = |f: &dyn Fn(&mut serde_json::Value)| -> String {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        f(&mut v);
        LocalModel::from_json(&v.to_string())
            .unwrap_err()
            .to_string()
    };
    let e = edited(&|v| v["drive_gains"]["gain"][4] = 0.0.into());
    assert!(e.contains("drive_gains.gain[4] is 0"), "{e}");
    let e = edited(&|v| v["drive_gains"]["stderr"] = serde_json::json!([0.1]));
    assert!(
        e.contains("drive_gains.stderr has 1 entries, expected one per joint (6)"),
        "{e}"
    );
    let e = edited(&|v| v["drive_gains"]["stderr"][0] = (-1.0).into());
    assert!(e.contains("drive_gains.stderr[0]"), "{e}");
    let e = edited(&|v| v["drive_gains"]["offset"] = 1.0.into());
    assert!(e.contains("unknown field `offset`"), "{e}");
}
