//! The Coulomb friction term's column filtered as the torques were (parallel filtering;
//! src/logs/preprocess.rs, `Recording::coulomb`, `States::with_coulomb`): a low-pass filtered torque
//! steps smoothly where a joint reverses, and `sign(qd)` does not. On the A465's test log at
//! 1 kHz, preprocessed at 10 Hz, the fit with the filtered column finds the friction the log
//! was made with; with `sign(qd)` the Coulomb coefficients come out low and the viscous ones
//! high, by 5 and 3 or more standard errors.

mod common;

use common::a465_log;
use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions, FrictionTerms};
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::{Recording, States};

/// The coefficient and standard error of the base parameter named `name`.
fn coefficient(fit: &BaseModel, name: &str) -> (f64, f64) {
    let i = (fit.base.names().iter())
        .position(|n| n == name)
        .unwrap_or_else(|| panic!("{name} is not a base parameter on its own"));
    (fit.theta[i], fit.stderr[i])
}

#[test]
fn a_fit_of_filtered_torques_finds_the_friction_with_the_filtered_column() {
    // every joint: 0.3 N m s/rad viscous and 0.8 N m Coulomb friction, 0.03 N m of noise
    let log = a465_log();
    let k = log.q.len() / 6;
    let t: Vec<f64> = (0..k).map(|i| i as f64 * 1e-3).collect();
    let raw = Recording::new("a465.csv", 6, t, log.q.clone(), log.tau.clone(), None, None).unwrap();
    let rec = preprocess(&raw, &PreprocessOptions::default()).unwrap();
    let coulomb = rec.coulomb.as_ref().expect("filtered");
    assert_eq!(coulomb.len(), rec.q.len());
    // a filtered sign: within the filter's overshoot, and sign(qd) itself well away from a
    // reversal (here a joint faster than 0.05 rad/s)
    let qd = rec.qd.as_ref().unwrap();
    assert!(
        coulomb.iter().all(|c| c.abs() <= 1.2),
        "beyond the overshoot"
    );
    let steady: Vec<usize> = (0..qd.len()).filter(|&i| qd[i].abs() > 0.05).collect();
    assert!(steady.len() > qd.len() / 2);
    let off = steady
        .iter()
        .filter(|&&i| (coulomb[i] - qd[i].signum()).abs() > 0.05)
        .count();
    assert!(off * 20 < steady.len(), "{off} of {}", steady.len());
    assert!(
        coulomb.iter().any(|c| c.abs() < 0.5),
        "no reversal smoothed"
    );
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let options = BaseOptions {
        friction: FrictionTerms {
            viscous: true,
            coulomb: true,
            ..FrictionTerms::NONE
        },
        ..BaseOptions::default()
    };
    let tau = &rec.tau;
    let filtered = identify_base_parameters(&model, &rec.states().unwrap(), tau, &options).unwrap();
    let plain = States::new(6, &rec.q, rec.qd.as_deref(), rec.qdd.as_deref()).unwrap();
    let signed = identify_base_parameters(&model, &plain, tau, &options).unwrap();
    for j in 1..=6 {
        let (c, c_se) = coefficient(&filtered, &format!("joint{j}.coulomb"));
        let (v, v_se) = coefficient(&filtered, &format!("joint{j}.viscous"));
        assert!(
            (c - 0.8).abs() < 4.0 * c_se + 0.005 && (v - 0.3).abs() < 4.0 * v_se + 0.005,
            "joint {j}: coulomb {c} +- {c_se}, viscous {v} +- {v_se}"
        );
        let (c, c_se) = coefficient(&signed, &format!("joint{j}.coulomb"));
        let (v, v_se) = coefficient(&signed, &format!("joint{j}.viscous"));
        assert!(
            0.8 - c > 5.0 * c_se && v - 0.3 > 3.0 * v_se,
            "joint {j} with sign(qd): coulomb {c} +- {c_se}, viscous {v} +- {v_se}"
        );
    }
    // the residual is the noise's (filtered), not the reversals' misfit
    for (a, b) in filtered.residual_rms.iter().zip(&signed.residual_rms) {
        assert!(a * 3.0 < *b, "{a} against {b}");
    }
    // its predictions take the column too
    let states = rec.states().unwrap();
    let predicted = filtered.predict(&model, &states).unwrap();
    let rms = (predicted
        .iter()
        .zip(tau)
        .map(|(p, m)| (p - m).powi(2))
        .sum::<f64>()
        / tau.len() as f64)
        .sqrt();
    assert!(rms < 0.01, "{rms}");
}

/// A column of another shape, one that is not finite or beyond the +-2 no filtered sign
/// reaches is refused, naming the sample and joint; a recording without filtering has none.
#[test]
fn a_coulomb_column_is_checked() {
    let q = vec![0.1; 12];
    let states = States::new(6, &q, Some(&q), Some(&q)).unwrap();
    let e = states.with_coulomb(&[0.5; 6]).unwrap_err().to_string();
    assert!(e.contains("coulomb"), "{e}");
    let mut c = vec![0.5; 12];
    c[9] = 2.5;
    let e = states.with_coulomb(&c).unwrap_err().to_string();
    assert!(
        e.contains("sample 1, joint 4: 2.5, expected a value within [-2, 2]"),
        "{e}"
    );
    c[9] = f64::NAN;
    assert!(states.with_coulomb(&c).is_err());
    c[9] = -1.1;
    let s = states.with_coulomb(&c).unwrap();
    assert_eq!(
        (s.coulomb_at(1, 3), s.slice(1..2).coulomb_at(0, 3)),
        (-1.1, -1.1)
    );
    assert_eq!(states.coulomb_at(1, 3), 1.0, "sign(qd) without a column");
    let t: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
    let q: Vec<f64> = t.iter().map(|x| (2.0 * x).sin()).collect();
    let raw = Recording::new("one.csv", 1, t, q.clone(), q, None, None).unwrap();
    let unfiltered = PreprocessOptions {
        cutoff: None,
        ..PreprocessOptions::default()
    };
    assert!(preprocess(&raw, &unfiltered).unwrap().coulomb.is_none());
    assert!(preprocess(&raw, &PreprocessOptions::default())
        .unwrap()
        .coulomb
        .is_some());
}
