//! Positions logged in coarse encoder counts under velocities derived from them
//! (`src/logs/position_rounding.rs`): the noise the preprocessing's chain leaves in qd and qdd is
//! estimated from the grid the positions lie on, checked here against the true noise (the
//! same log preprocessed without the rounding), warned of in a direct fit, and checked on load.

use nalgebra::DMatrix;
use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions};
use perturbid_rs::logs::position_rounding::{warning, NOISE_RATIO};
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::robots::a465;
use perturbid_rs::simulation::{simulate_samples, SimulationOptions};
use perturbid_rs::trajectory::FourierTrajectory;
use perturbid_rs::{Document, Recording, States};

/// 20 s of a 5-harmonic excitation of the A465 at 1 kHz, its positions rounded to
/// `counts` a revolution (0: not rounded), torques without noise.
fn log(counts: f64) -> Recording {
    let model = a465::model("kinsheel2010").unwrap();
    let a = DMatrix::from_fn(6, 5, |i, l| 0.12 * (((i * 5 + l) as f64) * 1.7).sin());
    let b = DMatrix::from_fn(6, 5, |i, l| 0.12 * (((i * 5 + l) as f64) * 2.3).cos());
    let traj = FourierTrajectory::new(0.2 * std::f64::consts::PI, vec![0.1; 6], a, b).unwrap();
    let samples = traj.sample_periods(2.0, 1000.0).unwrap();
    let mut o = SimulationOptions::new(&model);
    o.quantization = vec![
        if counts > 0.0 {
            std::f64::consts::TAU / counts
        } else {
            0.0
        };
        6
    ];
    simulate_samples(&model, &samples, &o, 0, "log").unwrap()
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

#[test]
fn the_rounding_noise_in_derived_accelerations_is_estimated_and_warned_of() {
    let options = PreprocessOptions::default();
    let exact = preprocess(&log(0.0), &options).unwrap();
    assert!(exact.position_rounding.is_empty());
    let names: Vec<String> = (1..=6).map(|j| format!("joint{j}")).collect();
    for (counts, warned) in [(4096.0, true), (40960.0, false), (409600.0, false)] {
        let rounded = preprocess(&log(counts), &options).unwrap();
        let found = &rounded.position_rounding;
        assert_eq!(found.len(), 6, "{counts}: {found:?}");
        let (qd, qdd) = (rounded.qd.as_ref().unwrap(), exact.qd.as_ref().unwrap());
        let (qdd_r, qdd_e) = (rounded.qdd.as_ref().unwrap(), exact.qdd.as_ref().unwrap());
        for r in found {
            let j = r.joint;
            assert!((r.step * counts / std::f64::consts::TAU - 1.0).abs() < 1e-9);
            // the true noise: the rounded log's derived signals minus the exact log's
            let column = |x: &[f64]| -> Vec<f64> { x.iter().skip(j).step_by(6).copied().collect() };
            let true_ratio = |a: &[f64], b: &[f64]| {
                let (a, b) = (column(a), column(b));
                let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
                rms(&d) / rms(&b)
            };
            let (t_qd, t_qdd) = (true_ratio(qd, qdd), true_ratio(qdd_r, qdd_e));
            // the white model of the rounding: within a factor 2 of the truth
            for (est, truth) in [(r.qd_ratio, t_qd), (r.qdd_ratio, t_qdd)] {
                assert!(
                    est > 0.5 * truth && est < 2.0 * truth,
                    "{counts} counts, joint {j}: estimated {est:.4}, true {truth:.4}"
                );
            }
        }
        let w = warning(found, &names);
        assert_eq!(w.is_some(), warned, "{counts}: {w:?}");
        if warned {
            let w = w.unwrap();
            assert!(
                w.starts_with(
                    "positions logged in coarse counts, with velocities derived from them"
                ) && w.contains("'joint3' in steps of 1.534e-3 leave"),
                "{w}"
            );
            assert!(found.iter().any(|r| r.qdd_ratio >= NOISE_RATIO));
        }
    }
    // a glitch of the log (a count missed by 20), replaced by its neighbours' fit before
    // preprocessing, is off the grid: the grid is read from the log as logged
    let mut glitched = log(4096.0);
    glitched.q[6 * 5000 + 2] += 20.0 * std::f64::consts::TAU / 4096.0;
    let screened = preprocess(&glitched, &options).unwrap();
    assert!(!screened.glitches.is_empty());
    assert_eq!(screened.position_rounding.len(), 6);
    // a logged velocity channel: qdd comes from it, and the positions' rounding is not measured
    let coarse = log(4096.0);
    let with_qd = Recording::new(
        "log",
        6,
        coarse.t.clone(),
        coarse.q.clone(),
        coarse.tau.clone(),
        exact_velocities(&coarse),
        None,
    )
    .unwrap();
    assert!(preprocess(&with_qd, &options)
        .unwrap()
        .position_rounding
        .is_empty());
}

/// The exact velocities of [`log`]'s samples.
fn exact_velocities(rec: &Recording) -> Option<Vec<f64>> {
    let a = DMatrix::from_fn(6, 5, |i, l| 0.12 * (((i * 5 + l) as f64) * 1.7).sin());
    let b = DMatrix::from_fn(6, 5, |i, l| 0.12 * (((i * 5 + l) as f64) * 2.3).cos());
    let traj = FourierTrajectory::new(0.2 * std::f64::consts::PI, vec![0.1; 6], a, b).unwrap();
    Some(traj.sample(&rec.t).qd)
}

#[test]
fn a_direct_fit_on_coarse_positions_says_so_and_its_file_is_checked() {
    let model = a465::model("kinsheel2010").unwrap();
    let rec = preprocess(&log(4096.0), &PreprocessOptions::default()).unwrap();
    let states = States::new(6, &rec.q, rec.qd.as_deref(), rec.qdd.as_deref()).unwrap();
    let fit = identify_base_parameters(&model, &states, &rec.tau, &BaseOptions::default()).unwrap();
    let fit = BaseModel {
        position_rounding: rec.position_rounding.clone(),
        ..fit
    };
    let w = fit.warnings();
    assert!(
        w.iter()
            .any(|w| w.starts_with("positions logged in coarse counts")
                && w.contains("bias the parameters of those terms toward zero")),
        "{w:?}"
    );
    let back = BaseModel::from_json(&fit.to_json()).unwrap();
    assert_eq!(back.position_rounding, fit.position_rounding);
    let mut v: serde_json::Value = serde_json::from_str(&fit.to_json()).unwrap();
    v["position_rounding"][0]["joint"] = serde_json::json!(9);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("position_rounding[0]: joint 9 of a model of 6 joints"),
        "{e}"
    );
    v["position_rounding"][0]["joint"] = serde_json::json!(0);
    v["position_rounding"][0]["step"] = serde_json::json!(-1.0);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("position_rounding[0]: step -1"), "{e}");
}
