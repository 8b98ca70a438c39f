//! The robot's parameters from local models: the regressor of the linearisation against the
//! robot's own linearisation and finite differences of the torque regressor, and the recovery
//! of the base parameters from exact local models at a few operating points.

mod common;

use common::{exact_local, linearized, random_op, table2, Rng};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::algorithms::linearization_regressor::linearization_regressor;
use perturbid_rs::direct::{regressor_matrix, FrictionTerms, ParameterLayout};
use perturbid_rs::local::{identify_parameters_from_local, FromLocalOptions, LocalModel};
use perturbid_rs::robots::a465;
use perturbid_rs::{linearize, mass_matrix, Data, Document, Gravity, OperatingPoint, States};

#[test]
fn the_linearisation_regressor_is_exact() {
    let model = a465::model("physical").unwrap();
    let n = model.nv;
    let terms = FrictionTerms {
        viscous: true,
        coulomb: true,
        offset: true,
        armature: false,
    };
    let layout = ParameterLayout::new(&model, terms);
    let theta = layout.model_parameters(&model);
    let mut rng = Rng(11);
    let op = random_op(&model, &mut rng);
    let reg = linearization_regressor(&model, &layout, &op.q, &op.qd, &op.qdd, Gravity::Included)
        .unwrap();
    // Y theta == the robot's own linearisation (friction zero in the URDF)
    let lin = linearized(&model, &op);
    let vec = |m: &DMatrix<f64>| {
        DVector::from_iterator(n * n, (0..n).flat_map(|i| (0..n).map(move |j| m[(i, j)])))
    };
    let close = |a: DVector<f64>, b: DVector<f64>, what: &str| {
        assert!(
            (&a - &b).norm() < 1e-10 * (1.0 + b.norm()),
            "{what}: {:e}",
            (&a - &b).norm()
        );
    };
    close(&reg.torque * &theta, lin.torque.clone(), "torque");
    close(&reg.d * &theta, vec(&lin.d), "D");
    close(&reg.h * &theta, vec(&lin.h), "H");
    close(&reg.g * &theta, vec(&lin.g), "G");
    close(&reg.g_static * &theta, vec(&lin.g_static), "G_static");
    // column by column against central differences of the torque regressor
    let phi = |q: &[f64], qd: &[f64], qdd: &[f64]| {
        regressor_matrix(
            &model,
            &layout,
            &States::new(n, q, Some(qd), Some(qdd)).unwrap(),
            Gravity::Included,
        )
        .unwrap()
    };
    let eps = 1e-6;
    for j in 0..n {
        for (what, var, block) in [("G", 0, &reg.g), ("H", 1, &reg.h), ("D", 2, &reg.d)] {
            let mut x = [op.q.clone(), op.qd.clone(), op.qdd.clone()];
            if var == 1 && x[1][j].abs() < 2.0 * eps {
                continue; // the Coulomb column steps at zero speed
            }
            x[var][j] += eps;
            let up = phi(&x[0], &x[1], &x[2]);
            x[var][j] -= 2.0 * eps;
            let down = phi(&x[0], &x[1], &x[2]);
            let fd = (up - down) / (2.0 * eps);
            for i in 0..n {
                let e = (fd.row(i) - block.row(i * n + j)).amax();
                assert!(
                    e < 1e-6 * (1.0 + fd.row(i).amax()),
                    "{what}({i},{j}): {e:e}"
                );
            }
        }
    }
}

#[test]
fn exact_local_models_at_a_few_points_recover_the_base_parameters() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let mut rng = Rng(5);
    let ops: Vec<OperatingPoint> = (0..4).map(|_| random_op(&model, &mut rng)).collect();
    let models: Vec<LocalModel> = ops.iter().map(|op| exact_local(&model, op)).collect();
    // D* alone at one point leaves base parameters unidentified, and says which
    let d_only = FromLocalOptions {
        use_torque: false,
        use_h: false,
        ..FromLocalOptions::default()
    };
    let one = identify_parameters_from_local(&model, &models[..1], &d_only).unwrap();
    assert!(
        one.rank < one.robot_rank && !one.unidentified.is_empty(),
        "{} of {}",
        one.rank,
        one.robot_rank
    );
    assert_eq!(
        one.unidentified.len(),
        one.robot_rank - one.rank,
        "{:?}",
        one.unidentified
    );
    // its map merges the unidentified directions, so it holds on the data only: not checked
    // against the robot's regressor (that would refuse the model on its own robot)
    assert!(!one.model.base.structural);
    assert!(one.model.mass_matrix(&model, &a465::TABLE2_Q).is_ok());
    // T*, D*, H* at four points: every base parameter, to 1e-8
    let fit =
        identify_parameters_from_local(&model, &models, &FromLocalOptions::default()).unwrap();
    assert_eq!(
        fit.rank, fit.robot_rank,
        "unidentified: {:?}",
        fit.unidentified
    );
    // every base parameter identified: the data's map is the robot's, and checked as such
    assert!(fit.model.base.structural);
    assert!(fit.model.base.check_on(&model, Gravity::Included).is_ok());
    let q = a465::TABLE2_Q;
    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &q).unwrap();
    let m = fit.model.mass_matrix(&model, &q).unwrap();
    let e = (&m - &data.m).norm() / data.m.norm();
    assert!(e < 1e-8, "M(q*) {e:e}");
    let held_out = random_op(&model, &mut rng);
    let lin = linearize(
        &model,
        &mut Data::new(&model),
        &held_out.q,
        &held_out.qd,
        &held_out.qdd,
        Gravity::Included,
    )
    .unwrap();
    let states = States::new(n, &held_out.q, Some(&held_out.qd), Some(&held_out.qdd)).unwrap();
    let tau = DVector::from_vec(fit.model.predict(&model, &states).unwrap());
    assert!((&tau - &lin.torque).norm() < 1e-8 * lin.torque.norm());
    // a model for another robot is refused by name
    let other = a465::model("physical").unwrap();
    let mut wrong = models[0].clone();
    wrong.joint_names[0] = "shoulder".into();
    let e =
        identify_parameters_from_local(&other, &[wrong], &FromLocalOptions::default()).unwrap_err();
    assert!(e.to_string().contains("models[0]"), "{e}");
}

/// From one point whose D* leaves base parameters unidentified, the suggested points reach
/// every one, and exact local models there recover them.
#[test]
fn suggested_operating_points_reach_full_rank() {
    use perturbid_rs::local::suggest_operating_points;
    let model = a465::model("kinsheel2010").unwrap();
    let start = table2();
    let options = FromLocalOptions {
        use_g: false,
        use_g_static: false,
        ..FromLocalOptions::default()
    };
    let first =
        identify_parameters_from_local(&model, &[exact_local(&model, &start)], &options).unwrap();
    assert!(first.rank < first.robot_rank);
    let picks =
        suggest_operating_points(&model, std::slice::from_ref(&start), &options, 60, 3, 7).unwrap();
    assert_eq!(picks.len(), 3);
    assert!(picks.windows(2).all(|w| w[1].log_det >= w[0].log_det));
    let last = picks.last().unwrap();
    assert_eq!(
        last.rank,
        first.robot_rank,
        "{:?}",
        picks.iter().map(|p| p.rank).collect::<Vec<_>>()
    );
    for p in &picks {
        for j in 0..model.nv {
            let l = &model.limits[j];
            assert!(p.op.q[j] >= l.lower && p.op.q[j] <= l.upper);
        }
    }
    let mut models = vec![exact_local(&model, &start)];
    models.extend(picks.iter().map(|p| exact_local(&model, &p.op)));
    let fit = identify_parameters_from_local(&model, &models, &options).unwrap();
    assert_eq!(fit.rank, fit.robot_rank);
    assert!(fit.unidentified.is_empty());
}

/// A fit with as many equations as unknowns has unknown standard errors: the saved
/// base-parameter model says `null` and loads back with NaN.
#[test]
fn a_base_model_without_residual_freedom_round_trips() {
    let model = a465::model("kinsheel2010").unwrap();
    let start = table2();
    let d_only = FromLocalOptions {
        use_torque: false,
        use_h: false,
        use_g: false,
        use_g_static: false,
        ..FromLocalOptions::default()
    };
    let fit =
        identify_parameters_from_local(&model, &[exact_local(&model, &start)], &d_only).unwrap();
    let text = fit.model.to_json();
    let back = perturbid_rs::direct::BaseModel::from_json(&text).unwrap();
    assert_eq!(back.theta, fit.model.theta);
    assert_eq!(
        back.stderr.iter().map(|s| s.is_nan()).collect::<Vec<_>>(),
        fit.model
            .stderr
            .iter()
            .map(|s| s.is_nan())
            .collect::<Vec<_>>()
    );
}
