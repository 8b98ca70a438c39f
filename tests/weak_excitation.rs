//! Data that excite the base parameters weakly (src/direct/weak_excitation.rs): the A465's
//! test log shrunk about its mean posture is named with its condition number, its least
//! determined combination and how far each joint moved; the log itself is not; the finding
//! is saved with the model and a hand-edited one is refused on load. (The combination and
//! cond against numpy's SVD: tests/python/test_direct_method.py.)

mod common;

use common::{a465_log, refused_on_load};
use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions};
use perturbid_rs::document::Document;
use perturbid_rs::{parallel, Gravity, States};

#[test]
fn a_log_that_moves_the_robot_little_is_named() {
    let log = a465_log();
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let n = 6;
    let k = log.q.len() / n;
    // the same motion at a quarter of its amplitude about its mean posture
    let mean: Vec<f64> = (0..n)
        .map(|j| (0..k).map(|s| log.q[s * n + j]).sum::<f64>() / k as f64)
        .collect();
    let shrink = 0.25;
    let q: Vec<f64> = (log.q.iter().enumerate())
        .map(|(i, v)| mean[i % n] + shrink * (v - mean[i % n]))
        .collect();
    let qd: Vec<f64> = log.qd.iter().map(|v| shrink * v).collect();
    let qdd: Vec<f64> = log.qdd.iter().map(|v| shrink * v).collect();
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut tau = vec![0.0; q.len()];
    let mut ws = parallel::Workspace::new(&model);
    parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap();
    // 0.03 N m of deterministic noise
    for (i, t) in tau.iter_mut().enumerate() {
        *t += 0.03 * ((i as f64 * 0.618_034).fract() - 0.5) * 3.4;
    }
    let fit = identify_base_parameters(&model, &states, &tau, &BaseOptions::default()).unwrap();
    let w = fit
        .weak_excitation
        .as_ref()
        .unwrap_or_else(|| panic!("cond {}", fit.cond));
    assert!(w.cond == fit.cond && w.cond > 2000.0, "{w:?}");
    assert!(!w.weakest.is_empty() && w.weakest.len() <= 6, "{w:?}");
    assert!(w.weakest[0].weight > 0.0, "{w:?}");
    let squares: f64 = w.weakest.iter().map(|t| t.weight * t.weight).sum();
    assert!(squares <= 1.0 + 1e-12 && squares > 0.5, "{w:?}");
    assert!((w.weakest.windows(2)).all(|p| p[0].weight.abs() >= p[1].weight.abs()));
    for (j, m) in w.motion.iter().enumerate() {
        let column = (0..k).map(|s| q[s * n + j]);
        let extent =
            column.clone().fold(f64::NEG_INFINITY, f64::max) - column.fold(f64::INFINITY, f64::min);
        assert_eq!(
            (m.joint.as_str(), m.extent),
            (model.joint_names[j].as_str(), extent)
        );
        let l = &model.limits[j];
        assert_eq!(m.range, Some(l.upper - l.lower));
    }
    let warning = fit
        .warnings()
        .into_iter()
        .find(|w| w.contains("weakly"))
        .unwrap();
    assert!(
        warning.contains(&w.weakest[0].parameter)
            && warning.contains("the joints moved over as little as"),
        "{warning}"
    );
    // saved and loaded whole; hand edits refused
    let json: serde_json::Value = serde_json::from_str(&fit.to_json()).unwrap();
    assert_eq!(BaseModel::from_json(&json.to_string()).unwrap(), fit);
    refused_on_load::<BaseModel>(
        &json,
        &[
            (
                |v| v["weak_excitation"]["cond"] = serde_json::json!(12.0),
                "weak_excitation: cond 12 is not the model's",
            ),
            (
                |v| v["weak_excitation"]["weakest"][0]["weight"] = serde_json::json!(2.0),
                "expected a number within [-1, 1]",
            ),
            (
                |v| v["weak_excitation"]["motion"][0]["joint"] = serde_json::json!("elbow"),
                "joint 'elbow' is not one of the model's",
            ),
            (
                |v| v["weak_excitation"]["motion"][1]["extent"] = serde_json::json!(-1.0),
                "joint 'joint2': an extent that is not a finite number >= 0",
            ),
        ],
    );
    // the log as it was excites them well enough
    let states = States::new(n, &log.q, Some(&log.qd), Some(&log.qdd)).unwrap();
    let full =
        identify_base_parameters(&model, &states, &log.tau, &BaseOptions::default()).unwrap();
    assert!(full.weak_excitation.is_none(), "cond {}", full.cond);
    assert!(!full.warnings().iter().any(|w| w.contains("weakly")));
}
