//! Friction the direct fit leaves out (src/direct/unmodelled_friction.rs): a fit without some
//! friction terms is made again with them, and the joints whose torques show them are named
//! with their coefficients, which match the friction the log was made with; the fraction of
//! the residual they take off is the two fits' own; a joint without friction is not named, and
//! neither is a log without any.

mod common;

use common::{a465_excitation, a465_log, normal, panda_preprocessed, refused_on_load, Rng};
use perturbid_rs::direct::unmodelled_friction::finding;
use perturbid_rs::direct::{
    identify_base_parameters, BaseModel, BaseOptions, FrictionTerms, UnmodelledFriction,
};
use perturbid_rs::document::Document;
use perturbid_rs::{parallel, Gravity, Model, States};

fn physical() -> Model {
    perturbid_rs::robots::a465::model("physical").unwrap()
}

fn fit(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: &[f64],
    friction: FrictionTerms,
) -> BaseModel {
    let states = States::new(model.nv, q, Some(qd), Some(qdd)).unwrap();
    let options = BaseOptions {
        friction,
        ..BaseOptions::default()
    };
    identify_base_parameters(model, &states, tau, &options).unwrap()
}

const VISCOUS: FrictionTerms = FrictionTerms {
    viscous: true,
    ..FrictionTerms::NONE
};

/// The term `term` of `found`'s joint, if named.
fn term(found: &UnmodelledFriction, term: &str) -> Option<(f64, f64)> {
    (found.terms.iter())
        .find(|t| t.term == term)
        .map(|t| (t.coefficient, t.stderr))
}

#[test]
fn friction_left_out_is_found_with_the_coefficients_the_log_was_made_with() {
    // every joint: 0.3 N m s/rad viscous and 0.8 N m Coulomb friction, 0.03 N m of noise
    let log = a465_log();
    let model = physical();
    let none = fit(
        &model,
        &log.q,
        &log.qd,
        &log.qdd,
        &log.tau,
        FrictionTerms::NONE,
    );
    let all = fit(
        &model,
        &log.q,
        &log.qd,
        &log.qdd,
        &log.tau,
        FrictionTerms::ALL,
    );
    assert!(
        all.unmodelled_friction.is_empty(),
        "{:?}",
        all.unmodelled_friction
    );
    let found = &none.unmodelled_friction;
    assert_eq!(
        found.iter().map(|f| f.joint.as_str()).collect::<Vec<_>>(),
        model
            .joint_names
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>()
    );
    let table = all.parameter_table();
    for (j, f) in found.iter().enumerate() {
        for (name, truth) in [("viscous", 0.3), ("coulomb", 0.8)] {
            let (c, se) = term(f, name).unwrap_or_else(|| panic!("{f:?}"));
            assert!(
                (c - truth).abs() < 4.0 * se && se < 0.05,
                "{name} {c} +- {se}: {f:?}"
            );
            // the fit with every term is the one the check made (12,000 samples, all refitted)
            let row = table
                .iter()
                .find(|r| r.name == format!("{}.{name}", f.joint));
            assert!((row.unwrap().value - c).abs() < 1e-9 * c.abs(), "{row:?}");
        }
        assert_eq!(term(f, "offset"), None, "no offset in the log: {f:?}");
        // the fraction of the residual the terms take off, from the two fits' residuals
        let expected = 1.0 - (all.residual_rms[j] / none.residual_rms[j]).powi(2);
        assert!(
            (f.explained - expected).abs() < 1e-9,
            "{} {expected}",
            f.explained
        );
        assert!((f.residual_rms - none.residual_rms[j]).abs() < 1e-12);
        assert!((f.remaining_rms - all.residual_rms[j]).abs() < 1e-12);
    }
    let warnings = none.warnings().join("\n");
    assert!(
        warnings.contains("shows in the torques of 6 joint(s)")
            && warnings.contains("--friction viscous,coulomb on the command line"),
        "{warnings}"
    );
    // with the viscous term fitted, Coulomb friction is what is left, and both are asked for
    let viscous = fit(&model, &log.q, &log.qd, &log.qdd, &log.tau, VISCOUS);
    assert_eq!(viscous.unmodelled_friction.len(), 6);
    for f in &viscous.unmodelled_friction {
        assert_eq!(f.terms.len(), 1, "{f:?}");
        let (c, se) = term(f, "coulomb").unwrap();
        assert!((c - 0.8).abs() < 4.0 * se, "{f:?}");
    }
    let said = finding(&viscous.unmodelled_friction, VISCOUS).unwrap();
    assert!(said.contains("friction=['viscous', 'coulomb']"), "{said}");
}

/// An A465 excitation's samples and torques of the physical model with `friction(joint, qd)`
/// added and 0.03 N m of normal noise.
fn log_with(friction: impl Fn(usize, f64) -> f64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let model = physical();
    let mut rng = Rng(4);
    let t: Vec<f64> = (0..5000).map(|i| i as f64 * 2e-3).collect();
    let s = a465_excitation(&mut rng).sample(&t);
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let mut tau = vec![0.0; s.q.len()];
    let mut ws = parallel::Workspace::new(&model);
    parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap();
    for (i, x) in tau.iter_mut().enumerate() {
        *x += friction(i % 6, s.qd[i]) + 0.03 * normal(&mut rng);
    }
    (s.q, s.qd, s.qdd, tau)
}

#[test]
fn only_the_joint_with_friction_is_named_and_a_log_without_any_raises_nothing() {
    let model = physical();
    // Coulomb friction of 1 N m on the shoulder alone: it biases the shared parameters, so
    // every joint's residual shrinks when it is fitted, but only the shoulder has a term
    let (q, qd, qdd, tau) = log_with(|j, v| if j == 1 { v.signum() } else { 0.0 });
    let m = fit(&model, &q, &qd, &qdd, &tau, FrictionTerms::NONE);
    let found = &m.unmodelled_friction;
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].joint, "joint2");
    let (c, se) = term(&found[0], "coulomb").unwrap();
    assert!((c - 1.0).abs() < 4.0 * se, "{c} +- {se}");
    assert!(found[0].explained > 0.9, "{found:?}");
    // the rigid body alone: nothing
    let (q, qd, qdd, tau) = log_with(|_, _| 0.0);
    let m = fit(&model, &q, &qd, &qdd, &tau, FrictionTerms::NONE);
    assert!(
        m.unmodelled_friction.is_empty(),
        "{:?}",
        m.unmodelled_friction
    );
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
}

/// A base joint that turns one way throughout (its Coulomb term is its offset in these data):
/// the refit leaves the offset out, and every joint's Coulomb friction is still found.
#[test]
fn a_joint_that_never_reverses_does_not_stop_the_check() {
    let model = physical();
    let mut rng = Rng(6);
    let t: Vec<f64> = (0..5000).map(|i| i as f64 * 2e-3).collect();
    let mut s = a465_excitation(&mut rng).sample(&t);
    for (i, &ti) in t.iter().enumerate() {
        s.q[i * 6] += 0.5 * ti;
        s.qd[i * 6] += 0.5;
    }
    assert!((0..t.len()).all(|i| s.qd[i * 6] > 0.0));
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let mut tau = vec![0.0; s.q.len()];
    let mut ws = parallel::Workspace::new(&model);
    parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap();
    for (i, x) in tau.iter_mut().enumerate() {
        *x += 0.8 * s.qd[i].signum() + 0.03 * normal(&mut rng);
    }
    let m = fit(&model, &s.q, &s.qd, &s.qdd, &tau, FrictionTerms::NONE);
    let found = &m.unmodelled_friction;
    assert_eq!(found.len(), 6, "{found:?}");
    for f in found {
        let (c, se) = term(f, "coulomb").unwrap_or_else(|| panic!("{f:?}"));
        assert!((c - 0.8).abs() < 4.0 * se, "{f:?}");
        assert_eq!(term(f, "offset"), None, "{f:?}");
    }
}

#[test]
fn the_finding_is_saved_with_the_model_and_checked_on_load() {
    let log = a465_log();
    let m = fit(&physical(), &log.q, &log.qd, &log.qdd, &log.tau, VISCOUS);
    let text = m.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), m);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 4] = [
        (
            |v| v["unmodelled_friction"][0]["joint"] = "joint9".into(),
            "unmodelled_friction[0]: joint 'joint9' is not one of the model's",
        ),
        (
            |v| v["unmodelled_friction"][1]["explained"] = 1.5.into(),
            "unmodelled_friction[1]: joint 'joint2': explained 1.5",
        ),
        (
            |v| v["unmodelled_friction"][2]["terms"][0]["term"] = "stiction".into(),
            "term 'stiction', expected one of viscous, coulomb, offset",
        ),
        (
            |v| v["unmodelled_friction"][3]["terms"] = serde_json::json!([]),
            "unmodelled_friction[3]: joint 'joint4': no term",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}

#[test]
fn the_real_panda_log_shows_the_friction_a_fit_without_it_leaves_out() {
    let Some((model, rec)) = panda_preprocessed() else {
        return;
    };
    let (qd, qdd) = (rec.qd.as_deref().unwrap(), rec.qdd.as_deref().unwrap());
    let none = fit(&model, &rec.q, qd, qdd, &rec.tau, FrictionTerms::NONE);
    // friction-shaped terms take more than half of every joint's residual off
    assert_eq!(
        none.unmodelled_friction.len(),
        7,
        "{:?}",
        none.unmodelled_friction
    );
    assert!(none.unmodelled_friction.iter().all(|f| f.explained > 0.5));
    // every joint has Coulomb friction, and it is positive (it opposes the motion)
    for f in &none.unmodelled_friction {
        let (c, se) = term(f, "coulomb").unwrap_or_else(|| panic!("{f:?}"));
        assert!(c > 5.0 * se, "{f:?}");
    }
    let all = fit(&model, &rec.q, qd, qdd, &rec.tau, FrictionTerms::ALL);
    assert!(all.unmodelled_friction.is_empty());
}
