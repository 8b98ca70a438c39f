//! The planner against the URDF's effort limits: a trajectory that needs more torque than a
//! joint's limit by the model is warned of with the joint, the torque and its time (the robot
//! would saturate there and clip a crossing's torques); an operating point that needs more
//! already is warned of once; a URDF without effort limits, as the A465's, gives nothing.

mod common;

use common::{table2, torques};
use perturbid_rs::local::{plan_experiments, PlanOptions};
use perturbid_rs::{model_from_urdf_str, Gravity, LoadOptions};

/// The A465 with an effort limit of `limits[j]` N m for joint j.
fn a465_with_efforts(limits: [f64; 6]) -> perturbid_rs::Model {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/robots/a465_kinsheel2010.urdf");
    let mut text = std::fs::read_to_string(path).unwrap();
    for e in limits {
        let at = text.find("<limit lower=").unwrap();
        text.replace_range(at..at + 6, &format!("<limit effort=\"{e}\" "));
        // the next joint's limit: this one no longer starts with `<limit lower=`
    }
    model_from_urdf_str(&text, "a465.urdf", &LoadOptions::default()).unwrap()
}

#[test]
fn transitions_beyond_the_effort_limits_are_warned_of_by_joint() {
    let plain = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let op = table2();
    let plan = plan_experiments(&plain, &op, &PlanOptions::default()).unwrap();
    assert!(
        !plan.warnings.iter().any(|w| w.contains("effort")),
        "{:?}",
        plan.warnings
    );
    // joint 2's largest torque along the D experiment, by the model, independently
    let d = plan
        .experiment(perturbid_rs::local::ExperimentKind::D)
        .unwrap();
    let s = d.trajectory.sample(plan.rate);
    let tau = torques(&plain, &s.q, &s.qd, &s.qdd, Gravity::Included);
    let peak = tau
        .iter()
        .skip(1)
        .step_by(6)
        .fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(peak > 20.0, "{peak}");
    // a limit half of it: warned of for joint 2 with that peak, not for joints left unlimited
    let limited = a465_with_efforts([1e6, 0.5 * peak, 1e6, 1e6, 1e6, 1e6]);
    assert_eq!(limited.effort_limit()[1], 0.5 * peak);
    let plan = plan_experiments(&limited, &op, &PlanOptions::default()).unwrap();
    let d_warning = plan
        .warnings
        .iter()
        .find(|w| w.starts_with("experiment 'D': by the model"))
        .expect("warned");
    assert!(
        d_warning.contains(&format!("'joint2' ({peak:.1} at t = "))
            && !d_warning.contains("'joint1'")
            && d_warning.contains("saturate"),
        "{d_warning}"
    );
    // a limit below what the operating point itself needs (8.4 N m on joint 2): said once
    let tight = a465_with_efforts([1e6, 5.0, 1e6, 1e6, 1e6, 1e6]);
    let plan = plan_experiments(&tight, &op, &PlanOptions::default()).unwrap();
    let held: Vec<&String> = (plan.warnings.iter())
        .filter(|w| w.contains("the operating point itself needs"))
        .collect();
    assert_eq!(held.len(), 1, "{:?}", plan.warnings);
    assert!(
        held[0].contains("'joint2' (-8.4 against 5.0)"),
        "{}",
        held[0]
    );
    assert!(!plan
        .warnings
        .iter()
        .any(|w| w.starts_with("experiment 'D': by the model")));
}
