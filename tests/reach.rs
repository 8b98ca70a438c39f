//! The region a local model was identified over: its stored perturbations against the plan's
//! crossings, the reach of a state, the summary `predict` warns with, and why it warns: inside
//! the region the model's error is within its standard errors, far beyond it is not.

mod common;

use common::{table2, torques};
use perturbid_rs::local::{
    identify_local, plan_experiments, ExperimentKind, IdentifyOptions, LocalModel, PlanOptions,
    REACH_LIMIT,
};
use perturbid_rs::robots::a465;
use perturbid_rs::{simulate_plan, Document, Friction, Gravity, Model, Plan, SimulationOptions};
use perturbid_rs::{OperatingPoint, States};

fn identified(noise: f64) -> (Model, Plan, LocalModel) {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.gravity = Gravity::Included;
    sim.friction = Friction::none(n);
    sim.torque_noise = vec![noise; n];
    sim.seed = 3;
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let local = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    (model, plan, local)
}

/// States at the operating point moved by `dq`, `dqd`, `dqdd` scaled by each of `scales`.
fn moved(op: &OperatingPoint, [dq, dqd, dqdd]: [&[f64]; 3], scales: &[f64]) -> [Vec<f64>; 3] {
    let at = |x0: &[f64], d: &[f64]| -> Vec<f64> {
        scales
            .iter()
            .flat_map(|s| x0.iter().zip(d).map(move |(x, d)| x + s * d))
            .collect()
    };
    [at(&op.q, dq), at(&op.qd, dqd), at(&op.qdd, dqdd)]
}

#[test]
fn the_perturbations_are_the_largest_the_plans_crossings_make() {
    let (model, plan, local) = identified(0.05);
    let n = model.nv;
    let p = local
        .perturbations
        .clone()
        .expect("stored by identify_local");
    let op = &plan.op;
    // from the crossings themselves (not the deltas stored beside them)
    let largest = |kind, pick: fn(&perturbid_rs::local::Crossing) -> &Vec<f64>, x0: &[f64]| {
        let e = plan.experiment(kind).unwrap();
        (0..n)
            .map(|j| {
                e.crossings
                    .iter()
                    .map(|c| (pick(c)[j] - x0[j]).abs())
                    .fold(0.0, f64::max)
            })
            .collect::<Vec<f64>>()
    };
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    assert!(close(
        &p.q,
        &largest(ExperimentKind::GDynamic, |c| &c.q, &op.q)
    ));
    assert!(close(&p.qd, &largest(ExperimentKind::H, |c| &c.qd, &op.qd)));
    assert!(close(
        &p.qdd,
        &largest(ExperimentKind::D, |c| &c.qdd, &op.qdd)
    ));
    assert!(p.q.iter().chain(&p.qd).chain(&p.qdd).all(|v| *v > 0.0));

    // reach: 0 at the point, at most 1 at every crossing and 1 at the largest, linear beyond
    let g = plan.experiment(ExperimentKind::GDynamic).unwrap();
    let mut q: Vec<f64> = op.q.clone();
    let (mut qd, mut qdd) = (op.qd.clone(), op.qdd.clone());
    for c in &g.crossings {
        q.extend(&c.q);
        qd.extend(&c.qd);
        qdd.extend(&c.qdd);
    }
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let reach = local.reach(&states).unwrap();
    assert_eq!(reach[0], 0.0);
    let at_crossings = &reach[1..];
    assert!(at_crossings.iter().all(|r| *r <= 1.0 + 1e-12), "{reach:?}");
    let top = at_crossings.iter().copied().fold(0.0, f64::max);
    assert!((top - 1.0).abs() < 1e-12, "{top}");
    assert!(local.extrapolation(&states).unwrap().is_none());

    // a G crossing's perturbation scaled by 4, and a velocity where H never went
    let dq: Vec<f64> = (0..n).map(|j| g.crossings[2].q[j] - op.q[j]).collect();
    let zero = vec![0.0; n];
    let [q, qd, mut qdd] = moved(op, [&dq, &zero, &zero], &[4.0, 0.5]);
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let reach = local.reach(&states).unwrap();
    assert!((reach[0] - 4.0 * at_crossings[2]).abs() < 1e-9, "{reach:?}");
    assert!((reach[1] - 0.5 * at_crossings[2]).abs() < 1e-9, "{reach:?}");
    let x = local.extrapolation(&states).unwrap().unwrap();
    assert_eq!((x.beyond, x.states), (1, 2));
    assert_eq!(x.variable, "q");
    let j = model
        .joint_names
        .iter()
        .position(|n| *n == x.joint)
        .unwrap();
    assert!((x.deviation - 4.0 * dq[j]).abs() < 1e-12);
    assert_eq!(x.perturbation, p.q[j]);
    assert!((x.largest - reach[0]).abs() < 1e-12);
    let says = x.message();
    assert!(
        says.contains("1 of 2 states lie beyond") && says.contains(&format!("'{}'", x.joint)),
        "{says}"
    );
    // joint 4's acceleration 10 times D's largest
    qdd[n + 3] = op.qdd[3] + 10.0 * p.qdd[3];
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let x = local.extrapolation(&states).unwrap().unwrap();
    assert_eq!((x.beyond, x.variable.as_str()), (2, "qdd"));
    assert!((x.largest - 10.0).abs() < 1e-9, "{}", x.largest);
    assert!(x.largest > REACH_LIMIT);
}

/// Why `predict` warns beyond the region: inside it the model errs by about its standard
/// errors (1.9 here: the fits saw the second-order terms there), while along the same
/// directions 8 times further out the neglected terms, which grow with the square while the
/// standard errors grow linearly, exceed them many times over (19 here).
#[test]
fn beyond_the_perturbations_the_error_outgrows_the_standard_errors() {
    let (model, plan, local) = identified(0.05);
    let n = model.nv;
    let op = &plan.op;
    let row = |kind, i: usize| -> Vec<f64> {
        let d = &plan.experiment(kind).unwrap().deltas;
        (0..n).map(|j| d[(i, j)]).collect()
    };
    let (dq, dqd, dqdd) = (
        row(ExperimentKind::GDynamic, 1),
        row(ExperimentKind::H, 2),
        row(ExperimentKind::D, 3),
    );
    let [q, qd, qdd] = moved(op, [&dq, &dqd, &dqdd], &[1.0, 8.0]);
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let reach = local.reach(&states).unwrap();
    assert!(reach[0] <= 1.0 + 1e-12 && reach[1] > 5.0, "{reach:?}");
    let predicted = local.predict(&states).unwrap();
    let se = local.predict_stderr(&states).unwrap();
    let truth = torques(&model, &q, &qd, &qdd, Gravity::Included);
    let worst = |s: usize| {
        (0..n)
            .map(|j| ((predicted[s * n + j] - truth[s * n + j]) / se[s * n + j]).abs())
            .fold(0.0, f64::max)
    };
    assert!(worst(0) < 4.0, "inside: {} standard errors", worst(0));
    assert!(
        worst(1) > 10.0,
        "8 times beyond: {} standard errors",
        worst(1)
    );
}

#[test]
fn the_perturbations_are_checked_on_load_and_optional() {
    let (_, _, local) = identified(0.05);
    let value: serde_json::Value = serde_json::from_str(&local.to_json()).unwrap();
    assert!(value["perturbations"]["qdd"].is_array());
    let edit = |f: fn(&mut serde_json::Value)| {
        let mut v = value.clone();
        f(&mut v);
        LocalModel::from_json(&v.to_string())
    };
    let e = edit(|v| v["perturbations"]["q"][2] = (-0.1).into()).unwrap_err();
    assert!(e.to_string().contains("perturbations.q[2] is -0.1"), "{e}");
    let e = edit(|v| {
        v["perturbations"]["qd"].as_array_mut().unwrap().pop();
    })
    .unwrap_err();
    assert!(
        e.to_string().contains("perturbations.qd has 5 entries"),
        "{e}"
    );
    let e = edit(|v| v["perturbations"]["qdd"][0] = 1e300.into()).unwrap_err();
    assert!(e.to_string().contains("perturbations.qdd[0]"), "{e}");
    // a model saved before: loads, predicts without the check, refuses reach with the reason
    let old = edit(|v| {
        v.as_object_mut().unwrap().remove("perturbations");
    })
    .unwrap();
    let op = &old.planned_op;
    let far: Vec<f64> = op.q.iter().map(|x| x + 1.0).collect();
    let states = States::new(op.q.len(), &far, Some(&op.qd), Some(&op.qdd)).unwrap();
    assert!(old.extrapolation(&states).unwrap().is_none());
    old.predict(&states).unwrap();
    let e = old.reach(&states).unwrap_err().to_string();
    assert!(e.contains("identify it again"), "{e}");
}
