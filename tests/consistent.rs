//! Physical consistency: the check of a parameter set, and consistent fits that are consistent
//! and no worse than needed.

mod common;

use common::Rng;
use perturbid_rs::direct::{
    identify_consistent_parameters, BaseOptions, ConsistentOptions, FrictionTerms, ParameterLayout,
    Weighting,
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

/// The lumped fit's links are inconsistent; a consistent robot (with or without an armature)
/// reproduces its torques: the inconsistency lies in directions the torques cannot see.
#[test]
fn the_lumped_a465_has_a_consistent_twin() {
    let lumped = robots::a465::model("kinsheel2010_lumped").unwrap();
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
        assert!(s.report.is_consistent(), "{terms}: {:?}", s.report);
        assert!(rms < 1e-4, "{terms}: {rms} N m");
        // the robot rebuilt from the parameters has the fit's torques
        let robot = fit.robot(&lumped).unwrap();
        let mut again = vec![0.0; tau.len()];
        parallel::rnea(
            &robot,
            &mut parallel::Workspace::new(&robot),
            &states,
            Gravity::Included,
            &mut again,
        )
        .unwrap();
        let predicted = fit.model.on(&lumped).unwrap().predict(&states).unwrap();
        let e = again
            .iter()
            .zip(&predicted)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(e < 1e-8, "{terms}: rebuilt robot vs base model {e}");
    }
}

/// Noisy torques from a consistent robot with few samples: the unconstrained fit is not a
/// robot, the consistent one is, and its residual is no larger than the truth's (which is
/// feasible), nor smaller than the unconstrained minimum.
#[test]
fn a_consistent_fit_is_consistent_and_no_worse_than_needed() {
    use perturbid_rs::direct::{consistent_least_squares, regressor_matrix, ParameterLayout};
    let truth = robots::a465::model("physical").unwrap();
    let (q, qd, qdd, mut tau) = data(&truth, 40, 9);
    let mut rng = Rng(10);
    for t in tau.iter_mut() {
        *t += rng.uniform(-2.0, 2.0);
    }
    let states = States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let terms: FrictionTerms = "viscous,coulomb".parse().unwrap();
    let layout = ParameterLayout::new(&truth, terms);
    let phi = regressor_matrix(&truth, &layout, &states, Gravity::Included).unwrap();
    let y = nalgebra::DVector::from_column_slice(&tau);
    // a prior far from the truth: the data must do the work
    let mut prior = layout.model_parameters(&truth);
    prior.iter_mut().for_each(|v| *v *= 1.3);
    let sol = consistent_least_squares(
        &layout,
        &phi,
        &y,
        0.0,
        prior.as_slice(),
        &ConsistentOptions::default(),
    )
    .unwrap();
    assert!(sol.report.is_consistent(), "{:?}", sol.report);
    let truth_cost = (&phi * layout.model_parameters(&truth) - &y).norm_squared();
    let ridge_cost =
        (&phi * nalgebra::DVector::from_column_slice(&sol.unconstrained_theta) - &y).norm_squared();
    let unconstrained_report =
        perturbid_rs::direct::check_physical_consistency(&layout, &sol.unconstrained_theta)
            .unwrap();
    assert!(
        !unconstrained_report.is_consistent(),
        "the noise should make it inconsistent"
    );
    assert!(!sol.active.is_empty());
    assert!(sol.cost >= sol.unconstrained_cost * (1.0 - 1e-9));
    assert!(sol.unconstrained_cost <= ridge_cost * (1.0 + 1e-9));
    assert!(
        sol.cost <= truth_cost * (1.0 + 1e-4),
        "consistent {} vs the truth's {truth_cost}",
        sol.cost
    );
    // more than a projection of the unconstrained solution: strictly better than clipping it
    let mut clipped = sol.unconstrained_theta.clone();
    for b in 0..layout.nbodies {
        let p: [f64; 10] = clipped[10 * b..10 * b + 10].try_into().unwrap();
        let eig = perturbid_rs::direct::consistency::pseudo_inertia(&p).symmetric_eigen();
        let j = eig.eigenvectors
            * nalgebra::Matrix4::from_diagonal(&eig.eigenvalues.map(|v| v.max(0.0)))
            * eig.eigenvectors.transpose();
        clipped[10 * b..10 * b + 10]
            .copy_from_slice(&perturbid_rs::direct::consistency::parameters_of_pseudo_inertia(&j));
    }
    let clipped_cost = (&phi * nalgebra::DVector::from_column_slice(&clipped) - &y).norm_squared();
    assert!(
        sol.cost < clipped_cost,
        "{} vs clipping {clipped_cost}",
        sol.cost
    );
    println!(
        "unconstrained {:.4} consistent {:.4} truth {truth_cost:.4} clipped {clipped_cost:.4}, {} iterations",
        sol.unconstrained_cost, sol.cost, sol.iterations
    );
}

/// Consistent parameters from local models: exact local models of a consistent robot give a
/// consistent fit that reproduces M(q) at a held-out point.
#[test]
fn consistent_parameters_from_local_models() {
    use perturbid_rs::local::{identify_parameters_from_local, FromLocalOptions};
    let model = robots::a465::model("kinsheel2010").unwrap();
    let mut rng = Rng(5);
    let ops: Vec<_> = (0..4)
        .map(|_| common::random_op(&model, &mut rng))
        .collect();
    let models: Vec<_> = ops
        .iter()
        .map(|op| common::exact_local(&model, op))
        .collect();
    let options = FromLocalOptions {
        use_g: false,
        use_g_static: false,
        consistent: Some(ConsistentOptions::default()),
        ..FromLocalOptions::default()
    };
    let out = identify_parameters_from_local(&model, &models, &options).unwrap();
    let fit = out.consistent.unwrap();
    assert!(fit.solution.report.is_consistent());
    let q = [0.3, -0.4, 0.9, 0.2, -0.7, 1.1];
    let m = fit.model.mass_matrix(&model, &q).unwrap();
    let mut data = perturbid_rs::Data::new(&model);
    perturbid_rs::mass_matrix(&model, &mut data, &q).unwrap();
    let e = (&m - &data.m).norm() / data.m.norm();
    assert!(e < 1e-6, "M(q) of the consistent fit: {e:e}");
}

/// Physical consistency: the CAD-estimated A465 is consistent, the first paper fit (rotor
/// inertias lumped into each link's Izz) is not; a negative mass, a negative friction and an
/// inertia breaking the triangle inequality are named; the pseudo-inertia test agrees with the
/// triangle inequalities on random diagonal inertias.
#[test]
fn physical_consistency_is_checked_per_link() {
    use perturbid_rs::direct::check_physical_consistency;
    let friction = FrictionTerms {
        viscous: true,
        coulomb: true,
        offset: true,
        armature: false,
    };
    let physical = robots::a465::model("physical").unwrap();
    let layout = ParameterLayout::new(&physical, friction);
    let theta = layout.model_parameters(&physical);
    let report = check_physical_consistency(&layout, theta.as_slice()).unwrap();
    assert!(report.is_consistent(), "{report:?}");
    let fitted = robots::a465::model("kinsheel2010_lumped").unwrap();
    let theta_fitted = layout.model_parameters(&fitted);
    let report = check_physical_consistency(&layout, theta_fitted.as_slice()).unwrap();
    assert!(!report.is_consistent());
    let worst = report
        .bodies
        .iter()
        .map(|b| b.relative_min)
        .fold(0.0, f64::min);
    assert!(worst < -0.5, "the lumped rotor inertias: {worst}");
    // a negative mass and a negative Coulomb coefficient, named
    let mut bad = theta.clone();
    bad[10] = -1.0;
    let c = layout
        .names
        .iter()
        .position(|n| n == "joint2.coulomb")
        .unwrap();
    bad[c] = -0.1;
    let report = check_physical_consistency(&layout, bad.as_slice()).unwrap();
    assert_eq!(
        report.bodies[1].problem.as_deref(),
        Some("mass -1 kg is negative")
    );
    assert_eq!(
        report.negative_friction,
        vec![("joint2.coulomb".to_string(), -0.1)]
    );
    // against the triangle inequalities: a point mass at the origin plus a diagonal inertia
    let mut rng = Rng(3);
    for _ in 0..200 {
        let d = [
            rng.uniform(0.0, 1.0),
            rng.uniform(0.0, 1.0),
            rng.uniform(0.0, 1.0),
        ];
        let triangle = d[0] + d[1] >= d[2] && d[1] + d[2] >= d[0] && d[0] + d[2] >= d[1];
        let mut t = theta.clone();
        t.as_mut_slice()[..10]
            .copy_from_slice(&[1.0, 0.0, 0.0, 0.0, d[0], 0.0, d[1], 0.0, 0.0, d[2]]);
        let r = check_physical_consistency(&layout, t.as_slice()).unwrap();
        assert_eq!(r.bodies[0].problem.is_none(), triangle, "{d:?}");
    }
    assert!(check_physical_consistency(&layout, &theta.as_slice()[1..]).is_err());
}
