//! The two forward-dynamics algorithms, the articulated-body algorithm and the mass matrix
//! with a Cholesky factorisation, against each other and against inverse dynamics
//! (`aba(q, qd, rnea(q, qd, qdd)) == qdd`), on random trees with prismatic joints, the A465
//! with armature, a 60-dof tree and a mimic coupling.

mod common;

use common::{a465_with_armature, mimic_pair, random_tree_urdf, Rng};
use perturbid_rs::algorithms::aba::ABA_FROM_DOF;
use perturbid_rs::{
    aba, forward_dynamics, forward_dynamics_crba, model_from_urdf_str, rnea, robots, Data, Gravity,
    LoadOptions, Model,
};
use proptest::prelude::*;

fn check(model: &Model, rng: &mut Rng) {
    let n = model.nv;
    let mut data = Data::new(model);
    for gravity in [Gravity::Included, Gravity::Excluded] {
        let (q, qd, qdd) = (rng.vector(n, 3.0), rng.vector(n, 2.0), rng.vector(n, 2.0));
        rnea(model, &mut data, &q, &qd, &qdd, gravity).unwrap();
        let tau = data.tau.as_slice().to_vec();
        aba(model, &mut data, &q, &qd, &tau, gravity).unwrap();
        let by_aba = data.qdd.clone();
        forward_dynamics_crba(model, &mut data, &q, &qd, &tau, gravity).unwrap();
        let by_crba = data.qdd.clone();
        forward_dynamics(model, &mut data, &q, &qd, &tau, gravity).unwrap();
        let chosen = data.qdd.clone();
        let scale = 1.0 + qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for j in 0..n {
            // the round trip goes through M^-1, whose condition number the tolerance allows for
            assert!(
                (by_aba[j] - qdd[j]).abs() < 1e-8 * scale,
                "aba joint {j}: {} vs {}",
                by_aba[j],
                qdd[j]
            );
            assert!(
                (by_aba[j] - by_crba[j]).abs() < 1e-8 * scale,
                "aba {} vs crba {} at joint {j}",
                by_aba[j],
                by_crba[j]
            );
        }
        let expected = if n >= ABA_FROM_DOF { &by_aba } else { &by_crba };
        assert_eq!(&chosen, expected, "forward_dynamics picks by size");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn aba_equals_crba_and_inverts_rnea_on_random_trees(seed in any::<u64>(), nlinks in 1usize..16) {
        let text = random_tree_urdf(seed, nlinks);
        let model = model_from_urdf_str(&text, "random", &LoadOptions::default()).unwrap();
        check(&model, &mut Rng(seed ^ 0xABA));
    }
}

#[test]
fn aba_equals_crba_on_fixed_robots() {
    let mut rng = Rng(5);
    for model in [
        robots::builtin("a465:physical").unwrap(),
        a465_with_armature(),
        model_from_urdf_str(&mimic_pair(true), "mimic", &LoadOptions::default()).unwrap(),
        model_from_urdf_str(&random_tree_urdf(60, 60), "tree60", &LoadOptions::default()).unwrap(),
    ] {
        check(&model, &mut rng);
    }
}

#[test]
fn a_joint_moving_no_inertia_is_an_error_naming_it() {
    // the end link is a point mass on j2's axis: nothing resists j2's acceleration
    let text = r#"<robot name="r"><link name="base"/>
      <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
      <link name="tip"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="tip"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    </robot>"#;
    let model = model_from_urdf_str(text, "r", &LoadOptions::default()).unwrap();
    let mut data = Data::new(&model);
    let e = aba(
        &model,
        &mut data,
        &[0.0; 2],
        &[0.0; 2],
        &[0.0; 2],
        Gravity::Included,
    )
    .unwrap_err();
    assert!(e.to_string().contains("j2"), "{e}");
}
