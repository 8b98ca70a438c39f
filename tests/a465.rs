//! The built-in A465 reproduces every number of docs/a465.md.
// The tables are compared entry by entry with the model: index loops read best.
#![allow(clippy::needless_range_loop)]

mod common;

use nalgebra::DMatrix;
use perturbid_rs::robots::a465::{
    TABLE2_Q, TABLE2_QD, TABLE2_QDD, TABLE2_TORQUE, TABLE3_D_COLUMN1,
};
use perturbid_rs::Gravity;
use perturbid_rs::{gravity_torque, mass_matrix, rnea, robots, Data};

#[test]
fn first_column_of_d_matches_table3() {
    let model = robots::builtin("a465").unwrap();
    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &TABLE2_Q).unwrap();
    for i in 0..6 {
        assert!(
            (data.m[(i, 0)] - TABLE3_D_COLUMN1[i]).abs() < 0.002,
            "D{}1 = {} vs {}",
            i + 1,
            data.m[(i, 0)],
            TABLE3_D_COLUMN1[i]
        );
    }
}

#[test]
fn nominal_torque_matches_table2() {
    let model = robots::builtin("a465:kinsheel2010").unwrap();
    let mut data = Data::new(&model);
    rnea(
        &model,
        &mut data,
        &TABLE2_Q,
        &TABLE2_QD,
        &TABLE2_QDD,
        Gravity::Excluded,
    )
    .unwrap();
    for i in 0..6 {
        assert!(
            (data.tau[i] - TABLE2_TORQUE[i]).abs() < 0.01,
            "T{} = {} vs Tn {}",
            i + 1,
            data.tau[i],
            TABLE2_TORQUE[i]
        );
    }
}

#[test]
fn full_mass_matrix_matches_reference() {
    let reference = DMatrix::from_row_slice(
        6,
        6,
        &[
            9.955, 0.0, 0.0, -1.370, 0.0, -0.271, 0.0, 7.192, 3.683, 0.0, 0.944, 0.0, 0.0, 3.683,
            3.523, 0.0, 0.942, 0.0, -1.370, 0.0, 0.0, 1.356, 0.0, 0.223, 0.0, 0.944, 0.942, 0.0,
            0.941, 0.0, -0.271, 0.0, 0.0, 0.223, 0.0, 0.446,
        ],
    );
    let model = robots::builtin("a465").unwrap();
    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &TABLE2_Q).unwrap();
    assert!((&data.m - &reference).amax() < 0.0015, "M(q*) = {}", data.m);
}

#[test]
fn mass_matrix_is_spd_everywhere_with_smallest_eigenvalue_about_0_30() {
    let model = robots::builtin("a465").unwrap();
    let mut data = Data::new(&model);
    let mut rng = common::Rng(7);
    let mut smallest = f64::INFINITY;
    for _ in 0..2000 {
        let q: Vec<f64> = (0..6)
            .map(|i| rng.uniform(model.limits[i].lower, model.limits[i].upper))
            .collect();
        mass_matrix(&model, &mut data, &q).unwrap();
        assert!((&data.m - data.m.transpose()).amax() < 1e-12);
        let eig = data.m.clone().symmetric_eigenvalues();
        smallest = smallest.min(eig.min());
    }
    assert!(
        smallest > 0.25 && smallest < 0.35,
        "smallest eigenvalue {smallest}"
    );
}

#[test]
fn gravity_of_the_physical_set_matches_reference() {
    let expected = [0.0, -4.92, 0.71, 0.0, -0.05, 0.0];
    let model = robots::builtin("a465:physical").unwrap();
    let mut data = Data::new(&model);
    gravity_torque(&model, &mut data, &TABLE2_Q).unwrap();
    for i in 0..6 {
        assert!(
            (data.g[i] - expected[i]).abs() < 0.006,
            "g{} = {}",
            i + 1,
            data.g[i]
        );
    }
}

#[test]
fn the_lumped_fit_breaks_the_triangle_inequality_so_strict_loading_refuses_it() {
    let text = robots::a465::urdf("kinsheel2010_lumped").unwrap();
    let err = perturbid_rs::model_from_urdf_str(text, "k.urdf", &Default::default()).unwrap_err();
    assert!(err.to_string().contains("triangle inequality"), "{err}");
    assert!(robots::builtin("a465:nope").is_err());
    assert!(robots::builtin("ur5").is_err());
}

/// The default A465 is the lumped fit refitted as a consistent robot with an armature: it loads
/// with every check on, every body is consistent, and its torques are the lumped model's.
#[test]
fn kinsheel2010_is_consistent_and_has_the_lumped_fits_torques() {
    use perturbid_rs::direct::{check_physical_consistency, FrictionTerms, ParameterLayout};
    let text = robots::a465::urdf("kinsheel2010").unwrap();
    let model = perturbid_rs::model_from_urdf_str(text, "k.urdf", &Default::default()).unwrap();
    let terms = FrictionTerms {
        armature: true,
        ..FrictionTerms::NONE
    };
    let layout = ParameterLayout::new(&model, terms);
    let theta = layout.model_parameters(&model);
    let report = check_physical_consistency(&layout, theta.as_slice()).unwrap();
    assert!(report.is_consistent(), "{report:?}");
    assert!(
        model.armature[0] > 5.0 && model.armature[1] > 2.0,
        "{:?}",
        model.armature
    );
    let lumped = robots::a465::model("kinsheel2010_lumped").unwrap();
    let lumped_layout = ParameterLayout::new(&lumped, FrictionTerms::NONE);
    let lumped_theta = lumped_layout.model_parameters(&lumped);
    let bad = check_physical_consistency(&lumped_layout, lumped_theta.as_slice()).unwrap();
    assert_eq!(bad.bodies.iter().filter(|b| b.problem.is_some()).count(), 6);
    let mut rng = common::Rng(77);
    let (mut a, mut b) = (Data::new(&model), Data::new(&lumped));
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let q: Vec<f64> = model
            .limits
            .iter()
            .map(|l| rng.uniform(l.lower, l.upper))
            .collect();
        let (qd, qdd) = (rng.vector(6, 2.0), rng.vector(6, 8.0));
        rnea(&model, &mut a, &q, &qd, &qdd, Gravity::Included).unwrap();
        rnea(&lumped, &mut b, &q, &qd, &qdd, Gravity::Included).unwrap();
        worst = worst.max((&a.tau - &b.tau).amax());
    }
    assert!(worst < 1e-3, "torques differ by {worst} N m");
}
