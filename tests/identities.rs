//! Algorithms checked against each other and against finite differences, on the A465 and on
//! random kinematic trees with revolute, continuous, prismatic and fixed joints.

mod common;

use common::{a465_with_armature, mimic_pair, random_tree_urdf, rel_err, Rng};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::Gravity;
use perturbid_rs::{
    bias_torque, forward_dynamics, gravity_torque, linearize, mass_matrix, model_from_urdf_str,
    rnea, rnea_derivatives, robots, Data, LoadOptions, Model,
};
use proptest::prelude::*;

fn tau(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64], gravity: Gravity) -> DVector<f64> {
    let mut data = Data::new(model);
    rnea(model, &mut data, q, qd, qdd, gravity).unwrap();
    data.tau.clone()
}

/// Central-difference Jacobian of tau along q (`which = 0`) or qd (`which = 1`).
fn fd_jacobian(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64], which: usize) -> DMatrix<f64> {
    let n = model.nv;
    let h = 1e-6;
    let mut jac = DMatrix::zeros(n, n);
    for j in 0..n {
        let (mut qp, mut qm, mut vp, mut vm) = (q.to_vec(), q.to_vec(), qd.to_vec(), qd.to_vec());
        if which == 0 {
            qp[j] += h;
            qm[j] -= h;
        } else {
            vp[j] += h;
            vm[j] -= h;
        }
        let d = (tau(model, &qp, &vp, qdd, Gravity::Included)
            - tau(model, &qm, &vm, qdd, Gravity::Included))
            / (2.0 * h);
        jac.set_column(j, &d);
    }
    jac
}

fn check_all_identities(model: &Model, rng: &mut Rng) {
    let n = model.nv;
    let mut data = Data::new(model);
    let q = rng.vector(n, 1.5);
    let qd = rng.vector(n, 2.0);
    let qdd = rng.vector(n, 3.0);
    // M qdd = rnea(q, 0, qdd) - g(q)
    mass_matrix(model, &mut data, &q).unwrap();
    let m = data.m.clone();
    assert!((&m - m.transpose()).amax() < 1e-12);
    gravity_torque(model, &mut data, &q).unwrap();
    let lhs = &m * DVector::from_column_slice(&qdd);
    let rhs = tau(model, &q, &vec![0.0; n], &qdd, Gravity::Included) - &data.g;
    assert!((lhs - &rhs).amax() < 1e-9 * rhs.amax().max(1.0));
    // rnea = M qdd + bias
    bias_torque(model, &mut data, &q, &qd, Gravity::Included).unwrap();
    let full = tau(model, &q, &qd, &qdd, Gravity::Included);
    let recomposed = &m * DVector::from_column_slice(&qdd) + &data.bias;
    assert!((&full - recomposed).amax() < 1e-9 * full.amax().max(1.0));
    // forward_dynamics(rnea(q, qd, qdd)) = qdd
    forward_dynamics(
        model,
        &mut data,
        &q,
        &qd,
        full.as_slice(),
        Gravity::Included,
    )
    .unwrap();
    let back = data.qdd.clone();
    assert!(
        (back - DVector::from_column_slice(&qdd)).amax() < 1e-8,
        "forward dynamics round trip"
    );
    // the derivatives: tau and M agree with rnea and crba, dq and dv with finite differences
    rnea_derivatives(model, &mut data, &q, &qd, &qdd, Gravity::Included).unwrap();
    assert!((&data.tau - &full).amax() < 1e-10 * full.amax().max(1.0));
    assert!(rel_err(&data.m, &m) < 1e-12);
    let fd_q = fd_jacobian(model, &q, &qd, &qdd, 0);
    let fd_v = fd_jacobian(model, &q, &qd, &qdd, 1);
    assert!(
        rel_err(&data.dtau_dq, &fd_q) < 1e-6,
        "dtau/dq\n{}\nvs fd\n{}",
        data.dtau_dq,
        fd_q
    );
    assert!(
        rel_err(&data.dtau_dv, &fd_v) < 1e-6,
        "dtau/dqd\n{}\nvs fd\n{}",
        data.dtau_dv,
        fd_v
    );
    // the linearisation is made of those pieces; Gs is the gravity stiffness
    let lin = linearize(model, &mut data, &q, &qd, &qdd, Gravity::Included).unwrap();
    assert!(rel_err(&lin.h, &fd_v) < 1e-6);
    let zero = vec![0.0; n];
    assert!(rel_err(&lin.g_static, &fd_jacobian(model, &q, &zero, &zero, 0)) < 1e-6);
}

#[test]
fn identities_hold_on_the_a465() {
    let mut rng = Rng(1);
    for variant in ["kinsheel2010", "physical"] {
        let model = robots::a465::model(variant).unwrap();
        for _ in 0..20 {
            check_all_identities(&model, &mut rng);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn identities_hold_on_random_trees(seed in any::<u64>(), nlinks in 1usize..9) {
        let text = random_tree_urdf(seed, nlinks);
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        let mut rng = Rng(seed ^ 0xABCD);
        check_all_identities(&model, &mut rng);
    }
}

#[test]
fn gravity_off_removes_exactly_g() {
    let model = robots::builtin("a465:physical").unwrap();
    let mut rng = Rng(3);
    let mut data = Data::new(&model);
    let (q, qd, qdd) = (rng.vector(6, 1.0), rng.vector(6, 1.0), rng.vector(6, 1.0));
    gravity_torque(&model, &mut data, &q).unwrap();
    let diff = tau(&model, &q, &qd, &qdd, Gravity::Included)
        - tau(&model, &q, &qd, &qdd, Gravity::Excluded);
    assert!((diff - &data.g).amax() < 1e-12);
    let lin = linearize(&model, &mut data, &q, &qd, &qdd, Gravity::Excluded).unwrap();
    assert!(lin.g_static.amax() == 0.0);
}

#[test]
fn wrong_lengths_and_nan_are_errors_not_panics() {
    let model = robots::builtin("a465").unwrap();
    let mut data = Data::new(&model);
    let e = rnea(
        &model,
        &mut data,
        &[0.0; 5],
        &[0.0; 6],
        &[0.0; 6],
        Gravity::Included,
    )
    .unwrap_err();
    assert!(e.to_string().contains("q: expected 6 values"), "{e}");
    let e = rnea(
        &model,
        &mut data,
        &[0.0; 6],
        &[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0],
        &[0.0; 6],
        Gravity::Included,
    )
    .unwrap_err();
    assert!(e.to_string().contains("qd: entry 1 is NaN"), "{e}");
    let e = forward_dynamics(
        &model,
        &mut data,
        &[0.0; 6],
        &[0.0; 6],
        &[0.0; 7],
        Gravity::Included,
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("tau:"), "{e}");
}

#[test]
fn mimic_joint_is_the_chain_rule_of_the_uncoupled_model() {
    let coupled = model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap();
    let free = model_from_urdf_str(&mimic_pair(false), "free", &LoadOptions::default()).unwrap();
    assert_eq!(coupled.nv, 2);
    assert_eq!(coupled.joint_names, ["a", "c"]);
    // C maps (a, c) velocities to (a, b, c)
    let c = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 2.0, 0.0, 0.0, 1.0]);
    let mut rng = Rng(11);
    for _ in 0..10 {
        let (q, qd, qdd) = (rng.vector(2, 1.0), rng.vector(2, 1.0), rng.vector(2, 1.0));
        let qf = [q[0], 2.0 * q[0] + 0.1, q[1]];
        let qdf = [qd[0], 2.0 * qd[0], qd[1]];
        let qddf = [qdd[0], 2.0 * qdd[0], qdd[1]];
        let expected = c.transpose() * tau(&free, &qf, &qdf, &qddf, Gravity::Included);
        let got = tau(&coupled, &q, &qd, &qdd, Gravity::Included);
        assert!((got - &expected).amax() < 1e-12);
        let (mut dc, mut df) = (Data::new(&coupled), Data::new(&free));
        mass_matrix(&coupled, &mut dc, &q).unwrap();
        mass_matrix(&free, &mut df, &qf).unwrap();
        assert!((&dc.m - c.transpose() * &df.m * &c).amax() < 1e-12);
        // derivatives of the coupled model against finite differences
        rnea_derivatives(&coupled, &mut dc, &q, &qd, &qdd, Gravity::Included).unwrap();
        assert!(rel_err(&dc.dtau_dq, &fd_jacobian(&coupled, &q, &qd, &qdd, 0)) < 1e-6);
        assert!(rel_err(&dc.dtau_dv, &fd_jacobian(&coupled, &q, &qd, &qdd, 1)) < 1e-6);
        assert!((&dc.m - c.transpose() * &df.m * &c).amax() < 1e-12);
    }
    let mut rng = Rng(5);
    check_all_identities(&coupled, &mut rng);
}

#[test]
fn locked_joint_is_the_full_model_with_that_joint_held() {
    let free = model_from_urdf_str(&mimic_pair(false), "free", &LoadOptions::default()).unwrap();
    let mut options = LoadOptions::default();
    options.lock.insert("b".to_string(), 0.7);
    let locked = model_from_urdf_str(&mimic_pair(false), "locked", &options).unwrap();
    assert_eq!(locked.joint_names, ["a", "c"]);
    let mut rng = Rng(12);
    for _ in 0..10 {
        let (q, qd, qdd) = (rng.vector(2, 1.0), rng.vector(2, 1.0), rng.vector(2, 1.0));
        let full = tau(
            &free,
            &[q[0], 0.7, q[1]],
            &[qd[0], 0.0, qd[1]],
            &[qdd[0], 0.0, qdd[1]],
            Gravity::Included,
        );
        let got = tau(&locked, &q, &qd, &qdd, Gravity::Included);
        assert!((got[0] - full[0]).abs() < 1e-12 && (got[1] - full[2]).abs() < 1e-12);
    }
    // locking the leader locks its follower too
    let mut options = LoadOptions::default();
    options.lock.insert("a".to_string(), 0.3);
    let both = model_from_urdf_str(&mimic_pair(true), "both", &options).unwrap();
    assert_eq!(both.joint_names, ["c"]);
    let mut options = LoadOptions::default();
    options.lock.insert("b".to_string(), 0.3);
    let e = model_from_urdf_str(&mimic_pair(true), "m.urdf", &options).unwrap_err();
    assert!(e.to_string().contains("lock that joint instead"), "{e}");
    let mut options = LoadOptions::default();
    options.lock.insert("zz".to_string(), 0.3);
    assert!(model_from_urdf_str(&mimic_pair(true), "m.urdf", &options).is_err());
}

#[test]
fn linearize_into_reuses_its_buffer_and_checks_its_size() {
    let model = robots::builtin("a465").unwrap();
    let mut data = Data::new(&model);
    let mut rng = Rng(21);
    let (q, qd, qdd) = (rng.vector(6, 1.0), rng.vector(6, 1.0), rng.vector(6, 1.0));
    let mut out = perturbid_rs::Linearization::zeros(6);
    perturbid_rs::linearize_into(
        &model,
        &mut data,
        &q,
        &qd,
        &qdd,
        Gravity::Included,
        &mut out,
    )
    .unwrap();
    assert_eq!(
        out,
        linearize(&model, &mut data, &q, &qd, &qdd, Gravity::Included).unwrap()
    );
    let mut wrong = perturbid_rs::Linearization::zeros(5);
    let e = perturbid_rs::linearize_into(
        &model,
        &mut data,
        &q,
        &qd,
        &qdd,
        Gravity::Included,
        &mut wrong,
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("out: expected a Linearization of 6 joints"),
        "{e}"
    );
}

/// The multi-sample kernel equals the one-sample RNEA on every sample, on random trees (with
/// prismatic and continuous joints, angles beyond 2 pi) and on a mimic coupling, for batch
/// lengths that fill the lanes and leave partial groups, with qd and qdd given or zero.
fn check_lanes(model: &Model, rng: &mut Rng, k: usize) {
    let n = model.nv;
    let (q, qd, qdd) = (
        rng.vector(k * n, 9.0),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 2.0),
    );
    let mut lanes = perturbid_rs::LaneData::new(model);
    let mut out = vec![0.0; k * n];
    let zeros = vec![0.0; n];
    for (with_v, with_a, gravity) in [
        (true, true, Gravity::Included),
        (false, false, Gravity::Included),
        (true, false, Gravity::Excluded),
    ] {
        let (v, a) = (with_v.then_some(&qd[..]), with_a.then_some(&qdd[..]));
        perturbid_rs::rnea_batch(model, &mut lanes, &q, v, a, gravity, &mut out).unwrap();
        let mut data = Data::new(model);
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            let vs = if with_v { &qd[r.clone()] } else { &zeros[..] };
            let as_ = if with_a { &qdd[r.clone()] } else { &zeros[..] };
            rnea(model, &mut data, &q[r.clone()], vs, as_, gravity).unwrap();
            let scale = 1.0 + data.tau.amax();
            for j in 0..n {
                assert!(
                    (out[s * n + j] - data.tau[j]).abs() < 1e-12 * scale,
                    "sample {s} joint {j}: {} vs {}",
                    out[s * n + j],
                    data.tau[j]
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn lanes_equal_one_sample_rnea_on_random_trees(seed in any::<u64>(), nlinks in 1usize..9, k in 1usize..11) {
        let text = random_tree_urdf(seed, nlinks);
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        check_lanes(&model, &mut Rng(seed ^ 0x5A5A), k);
    }
}

#[test]
fn lanes_equal_one_sample_rnea_on_the_a465_and_a_mimic_pair() {
    let mut rng = Rng(8);
    for model in [
        robots::builtin("a465").unwrap(),
        model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap(),
    ] {
        for k in [1, 3, 4, 5, 8, 13] {
            check_lanes(&model, &mut rng, k);
        }
    }
    // wrong lengths are errors
    let model = robots::builtin("a465").unwrap();
    let mut lanes = perturbid_rs::LaneData::new(&model);
    let mut out = vec![0.0; 12];
    let e = perturbid_rs::rnea_batch(
        &model,
        &mut lanes,
        &[0.0; 12],
        Some(&[0.0; 6]),
        None,
        Gravity::Included,
        &mut out,
    )
    .unwrap_err();
    assert!(e.to_string().contains("qd"), "{e}");
}

/// The multi-sample regressor equals the one-sample regressor on every sample.
fn check_regressor_batch(model: &Model, rng: &mut Rng, k: usize) {
    use perturbid_rs::algorithms::regressor::joint_torque_regressor;
    let n = model.nv;
    let p = 10 * model.nbodies();
    let (q, qd, qdd) = (
        rng.vector(k * n, 9.0),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 2.0),
    );
    let mut lanes = perturbid_rs::LaneData::new(model);
    for gravity in [Gravity::Included, Gravity::Excluded] {
        let mut out = vec![f64::NAN; k * n * p];
        perturbid_rs::regressor_batch(model, &mut lanes, &q, &qd, &qdd, gravity, &mut out).unwrap();
        let mut data = Data::new(model);
        let mut y = DMatrix::zeros(n, p);
        for s in 0..k {
            let r = s * n..(s + 1) * n;
            joint_torque_regressor(
                model,
                &mut data,
                &q[r.clone()],
                &qd[r.clone()],
                &qdd[r],
                gravity,
                &mut y,
            )
            .unwrap();
            let scale = 1.0 + y.amax();
            for i in 0..n {
                for c in 0..p {
                    let got = out[s * n * p + i * p + c];
                    assert!(
                        (got - y[(i, c)]).abs() < 1e-12 * scale,
                        "sample {s} row {i} column {c}: {got} vs {}",
                        y[(i, c)]
                    );
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn regressor_batch_equals_one_sample_regressor_on_random_trees(seed in any::<u64>(), nlinks in 1usize..9, k in 1usize..11) {
        let text = random_tree_urdf(seed, nlinks);
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        check_regressor_batch(&model, &mut Rng(seed ^ 0x7777), k);
    }
}

#[test]
fn regressor_batch_equals_one_sample_regressor_on_the_a465_and_a_mimic_pair() {
    let mut rng = Rng(9);
    for model in [
        robots::builtin("a465:physical").unwrap(),
        model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap(),
    ] {
        for k in [1, 4, 7] {
            check_regressor_batch(&model, &mut rng, k);
        }
    }
}

/// The multi-sample mass matrix equals the one-sample CRBA on every sample.
fn check_mass_matrix_batch(model: &Model, rng: &mut Rng, k: usize) {
    let n = model.nv;
    let q = rng.vector(k * n, 9.0);
    let mut lanes = perturbid_rs::LaneData::new(model);
    let mut out = vec![f64::NAN; k * n * n];
    perturbid_rs::mass_matrix_batch(model, &mut lanes, &q, &mut out).unwrap();
    let mut data = Data::new(model);
    for s in 0..k {
        mass_matrix(model, &mut data, &q[s * n..(s + 1) * n]).unwrap();
        let scale = data.m.amax();
        for i in 0..n {
            for j in 0..n {
                let got = out[s * n * n + i * n + j];
                assert!(
                    (got - data.m[(i, j)]).abs() < 1e-12 * scale,
                    "sample {s} M[{i}, {j}]: {got} vs {}",
                    data.m[(i, j)]
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn mass_matrix_batch_equals_crba_on_random_trees(seed in any::<u64>(), nlinks in 1usize..9, k in 1usize..11) {
        let text = random_tree_urdf(seed, nlinks);
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        check_mass_matrix_batch(&model, &mut Rng(seed ^ 0x3333), k);
    }
}

/// An inertia edited in place and refreshed body by body (`Body::refresh`, not
/// `Model::refresh`) reaches the multi-sample mass matrix, whose turned frames hold their own
/// copy of it.
#[test]
fn an_inertia_refreshed_by_its_body_reaches_the_mass_matrix_batch() {
    let text = random_tree_urdf(7, 12);
    let mut model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
    for (i, b) in model.bodies.iter_mut().enumerate() {
        b.inertia = perturbid_rs::spatial::Inertia::new(
            0.5 + i as f64,
            nalgebra::Vector3::new(0.1, -0.05 * i as f64, 0.2),
            nalgebra::Matrix3::new(
                0.3,
                0.01,
                0.0,
                0.01,
                0.2 + 0.01 * i as f64,
                0.02,
                0.0,
                0.02,
                0.25,
            ),
        );
        b.refresh();
    }
    check_mass_matrix_batch(&model, &mut Rng(11), 9);
}

#[test]
fn mass_matrix_batch_equals_crba_on_the_a465_and_a_mimic_pair() {
    let mut rng = Rng(10);
    for model in [
        robots::builtin("a465:physical").unwrap(),
        model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap(),
    ] {
        for k in [1, 4, 6] {
            check_mass_matrix_batch(&model, &mut rng, k);
        }
    }
}

#[test]
fn armature_adds_to_the_diagonal_and_every_algorithm_agrees() {
    let model = a465_with_armature();
    let expected = [
        0.8,
        0.5,
        0.3,
        1e-5 * 101.0f64.powi(2),
        2e-5 * 1e4,
        1e-5 * 101.0f64.powi(2),
    ];
    for (a, e) in model.armature.iter().zip(expected) {
        assert!((a - e).abs() < 1e-12 * e, "{:?}", model.armature);
    }
    let bare = robots::a465::model("physical").unwrap();
    let mut rng = Rng(21);
    let n = model.nv;
    for _ in 0..10 {
        let (q, qd, qdd) = (rng.vector(n, 1.5), rng.vector(n, 2.0), rng.vector(n, 3.0));
        // tau(armature) - tau(bare) = armature * qdd, M differs by the diagonal
        let d = tau(&model, &q, &qd, &qdd, Gravity::Included)
            - tau(&bare, &q, &qd, &qdd, Gravity::Included);
        for j in 0..n {
            assert!((d[j] - model.armature[j] * qdd[j]).abs() < 1e-10);
        }
        let (mut a, mut b) = (Data::new(&model), Data::new(&bare));
        mass_matrix(&model, &mut a, &q).unwrap();
        mass_matrix(&bare, &mut b, &q).unwrap();
        let dm = &a.m - &b.m;
        assert!(
            (dm - DMatrix::from_diagonal(&DVector::from_column_slice(&model.armature))).amax()
                < 1e-12
        );
        check_all_identities(&model, &mut rng);
    }
    for k in [1, 4, 5, 13] {
        check_lanes(&model, &mut rng, k);
        check_mass_matrix_batch(&model, &mut rng, k);
    }
}
