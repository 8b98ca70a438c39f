//! Physically consistent identification: the log-Cholesky parametrisation against finite
//! differences, and consistent fits that are consistent and no worse than needed.

mod common;

use common::Rng;
use perturbid_rs::direct::{
    identify_consistent_parameters, BaseOptions, ConsistentOptions, FrictionTerms, Weighting,
};
use perturbid_rs::{parallel, robots, Gravity, Model, States, TorqueModel};

fn data(model: &Model, k: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = model.nv;
    let mut rng = Rng(seed);
    let q = rng.vector(k * n, 1.4);
    let qd = rng.vector(k * n, 1.5);
    let qdd = rng.vector(k * n, 3.0);
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut tau = vec![0.0; k * n];
    parallel::rnea(
        model,
        &mut parallel::Workspace::new(model),
        &states,
        Gravity::Included,
        &mut tau,
    )
    .unwrap();
    (q, qd, qdd, tau)
}

#[test]
fn a_consistent_truth_is_found_again_with_no_growth() {
    let truth = robots::a465::model("physical").unwrap();
    let (q, qd, qdd, tau) = data(&truth, 300, 1);
    let states = States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let options = BaseOptions {
        friction: FrictionTerms::NONE,
        weighting: Weighting::Ols,
        ..BaseOptions::default()
    };
    let fit = identify_consistent_parameters(
        &truth,
        &states,
        &tau,
        &options,
        &ConsistentOptions::default(),
    )
    .unwrap();
    let s = &fit.solution;
    println!(
        "iterations {} cost {} unconstrained {}",
        s.iterations, s.cost, s.unconstrained_cost
    );
    assert!(s.converged && s.report.is_consistent(), "{:?}", s.report);
    let predicted = fit.model.on(&truth).unwrap().predict(&states).unwrap();
    let err = predicted
        .iter()
        .zip(&tau)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-6, "torque error {err}");
}

#[test]
fn the_lumped_a465_needs_the_armature_to_be_consistent() {
    let lumped = robots::a465::model("kinsheel2010").unwrap();
    let (q, qd, qdd, tau) = data(&lumped, 400, 2);
    let states = States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    for terms in ["none", "armature"] {
        let options = BaseOptions {
            friction: terms.parse().unwrap(),
            weighting: Weighting::Ols,
            ..BaseOptions::default()
        };
        let fit = identify_consistent_parameters(
            &lumped,
            &states,
            &tau,
            &options,
            &ConsistentOptions::default(),
        )
        .unwrap();
        let s = &fit.solution;
        let rms = (s.cost / tau.len() as f64).sqrt();
        println!(
            "{terms}: iterations {} converged {} rms {rms} N m, active {:?}",
            s.iterations, s.converged, s.active
        );
        assert!(s.report.is_consistent());
        let robot = fit.robot(&lumped).unwrap();
        println!("armature {:?}", robot.armature);
    }
}
