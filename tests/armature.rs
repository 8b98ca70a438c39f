//! The armature (reflected rotor inertia) read from a URDF, refused where it cannot be used,
//! and identified as a parameter of its own per joint.

mod common;

use perturbid_rs::direct::{regressor_matrix, FrictionTerms, ParameterLayout};
use perturbid_rs::{model_from_urdf_str, parallel, robots, Gravity, LoadOptions, States};

fn with_joint1(extra: &str) -> String {
    robots::a465::urdf("physical").unwrap().replace(
        "<joint name=\"joint1\" type=\"revolute\">",
        &format!("<joint name=\"joint1\" type=\"revolute\">\n    {extra}"),
    )
}

fn error(text: &str) -> String {
    model_from_urdf_str(text, "arm.urdf", &LoadOptions::default())
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_armature_is_refused_with_file_line_and_joint() {
    let e = error(&with_joint1("<dynamics armature=\"-1\"/>"));
    assert_eq!(
        e,
        "arm.urdf:50: joint 'joint1' armature: -1 is negative; a rotor inertia is >= 0"
    );
    let e = error(&with_joint1("<dynamics armature=\"lots\"/>"));
    assert!(
        e.contains("arm.urdf:50:") && e.contains("'lots', expected a finite number"),
        "{e}"
    );
    let e = error(&with_joint1("<dynamics armature=\"inf\"/>"));
    assert!(e.contains("expected a finite number"), "{e}");
    // given twice: by <dynamics> and by a transmission
    let twice = with_joint1("<dynamics armature=\"1\"/>").replace(
        "</robot>",
        "<transmission name=\"t\"><joint name=\"joint1\"/><actuator name=\"m\"><rotor_inertia value=\"1e-4\"/></actuator></transmission></robot>",
    );
    let e = error(&twice);
    assert!(
        e.contains("joint 'joint1' armature: given again (first on line 50)"),
        "{e}"
    );
    // a joint that does not exist, a fixed joint
    let unknown = robots::a465::urdf("physical").unwrap().replace(
        "</robot>",
        "<transmission name=\"t\"><joint name=\"elbow\"/><actuator name=\"m\"><rotor_inertia value=\"1e-4\"/></actuator></transmission></robot>",
    );
    assert!(error(&unknown).contains("joint 'elbow' armature: no joint of this name"));
    let fixed = robots::a465::urdf("physical").unwrap().replace(
        "</robot>",
        "<link name=\"tool\"/><joint name=\"flange\" type=\"fixed\"><parent link=\"link6\"/><child link=\"tool\"/><dynamics armature=\"0.1\"/></joint></robot>",
    );
    assert!(
        error(&fixed).contains("joint 'flange' armature: the joint is fixed"),
        "{}",
        error(&fixed)
    );
    // locked by the caller: the rotor stands still, the armature goes with the joint
    let locked = LoadOptions {
        lock: [("joint1".to_string(), 0.3)].into(),
        ..LoadOptions::default()
    };
    let m =
        model_from_urdf_str(&with_joint1("<dynamics armature=\"1\"/>"), "arm", &locked).unwrap();
    assert_eq!(m.armature, vec![0.0; 5]);
    // a mimic follower
    let mimic = common::mimic_pair(true).replace("<mimic", "<dynamics armature=\"0.2\"/><mimic");
    let e = error(&mimic);
    assert!(
        e.contains("follows") && e.contains("give the armature of the driving joint"),
        "{e}"
    );
}

#[test]
fn the_armature_column_completes_the_regressor() {
    let model = common::a465_with_armature();
    let n = model.nv;
    let mut rng = common::Rng(5);
    let k = 40;
    let (q, qd, qdd) = (
        rng.vector(k * n, 1.5),
        rng.vector(k * n, 2.0),
        rng.vector(k * n, 3.0),
    );
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut tau = vec![0.0; k * n];
    parallel::rnea(
        &model,
        &mut parallel::Workspace::new(&model),
        &states,
        Gravity::Included,
        &mut tau,
    )
    .unwrap();
    let terms: FrictionTerms = "viscous,armature".parse().unwrap();
    let layout = ParameterLayout::new(&model, terms);
    assert_eq!(layout.names[60..62], ["joint1.viscous", "joint1.armature"]);
    let theta = layout.model_parameters(&model);
    let phi = regressor_matrix(&model, &layout, &states, Gravity::Included).unwrap();
    let err = (&phi * &theta)
        .iter()
        .zip(&tau)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-9, "Phi theta - tau = {err}");
    // without the column, the rigid-body regressor misses exactly armature * qdd
    let bare = ParameterLayout::new(&model, FrictionTerms::NONE);
    let phi = regressor_matrix(&model, &bare, &states, Gravity::Included).unwrap();
    let rigid = &phi * bare.model_parameters(&model);
    for (i, (r, t)) in rigid.iter().zip(&tau).enumerate() {
        assert!((t - r - model.armature[i % n] * qdd[i]).abs() < 1e-9);
    }
}
