//! A payload identified from a log of the robot carrying it (src/direct/payload.rs): exact
//! on noise-free torques against the URDF, within its standard errors against a model
//! identified from a log without it (whose own uncertainty it carries), the delta rule's
//! Jacobian against finite differences, no payload named as none, a payload the joints cannot
//! see refused naming its parameters, and references that disagree with the log refused.
//! (Against Pinocchio's torques: tests/python/test_payload.py.)

mod common;

use common::gain_logs::{carrying, motion, payload, states, truth};
use common::{torques_with_friction, Rng};
use perturbid_rs::direct::payload::{parameters_of_payload, payload_of_parameters};
use perturbid_rs::direct::{
    identify_base_parameters, identify_payload, BaseOptions, FrictionTerms, PayloadOptions,
    Reference,
};
use perturbid_rs::rehearsal::Payload;
use perturbid_rs::{Error, Gravity, Model};

/// The torques of `truth` with `p` fixed on (none where None) along motion `seed`, with the
/// common friction and `noise` N m of white noise.
fn loaded_torques(truth: &Model, p: Option<&Payload>, seed: u64, noise: f64) -> Vec<f64> {
    let robot = carrying(truth, p);
    let s = motion(seed);
    torques_with_friction(&robot, &s, &mut Rng(seed + 100), |r| {
        noise * common::normal(r)
    })
}

#[test]
fn a_payload_comes_back_exactly_from_noise_free_torques_against_the_urdf() {
    let (truth, p) = (truth(), payload());
    let s = motion(4);
    let tau = loaded_torques(&truth, Some(&p), 4, 0.0);
    let reference = Reference::Urdf;
    let options = PayloadOptions::new("link6", &reference);
    assert_eq!(options.terms, FrictionTerms::ALL);
    let fit = identify_payload(&truth, reference, &states(&s), &tau, &options).unwrap();
    let want = parameters_of_payload(&p);
    for (i, (a, b)) in fit.parameters().iter().zip(&want).enumerate() {
        assert!(
            (a - b).abs() < 1e-8 * (1.0 + b.abs()),
            "{}: {a} vs {b}",
            fit.names[i]
        );
    }
    let got = fit.usable_payload().expect("a payload");
    assert!((got.mass - p.mass).abs() < 1e-8);
    for i in 0..3 {
        assert!((got.com[i] - p.com[i]).abs() < 1e-8, "{:?}", got.com);
    }
    for i in 0..6 {
        assert!(
            (got.inertia[i] - p.inertia[i]).abs() < 1e-8,
            "{:?}",
            got.inertia
        );
    }
    // the friction the truth has (0.3 N m s/rad, 0.8 N m), fitted beside it
    for j in 0..6 {
        let at = |t: &str| {
            fit.names
                .iter()
                .position(|n| *n == format!("joint{}.{t}", j + 1))
        };
        assert!((fit.theta[at("viscous").unwrap()] - 0.3).abs() < 1e-8);
        assert!((fit.theta[at("coulomb").unwrap()] - 0.8).abs() < 1e-8);
    }
    assert!(fit.findings.is_empty(), "{:?}", fit.findings);
    assert_eq!(fit.reference, "urdf");
    assert!(fit.stderr_of_reference.iter().all(|s| *s == 0.0));
    // the robot carrying it, on another motion: its torques
    let other = motion(5);
    let predicted = fit.predict(&truth, reference, &states(&other)).unwrap();
    let want = loaded_torques(&truth, Some(&p), 5, 0.0);
    for (a, b) in predicted.iter().zip(&want) {
        assert!((a - b).abs() < 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
    }
    // against the kind of reference it was identified against only
    let alone = identify_base_parameters(
        &truth,
        &states(&other),
        &loaded_torques(&truth, None, 5, 0.01),
        &BaseOptions::default(),
    )
    .unwrap();
    let e = fit
        .predict(&truth, Reference::Model(&alone), &states(&other))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("identified against the URDF's parameters"),
        "{e}"
    );
}

#[test]
fn against_a_model_of_the_robot_alone_the_payload_lies_within_its_standard_errors() {
    let (truth, p) = (truth(), payload());
    let (a, b) = (motion(3), motion(4));
    let noise = 0.02;
    let alone = loaded_torques(&truth, None, 3, noise);
    let model =
        identify_base_parameters(&truth, &states(&a), &alone, &BaseOptions::default()).unwrap();
    let loaded = loaded_torques(&truth, Some(&p), 4, noise);
    let reference = Reference::Model(&model);
    let options = PayloadOptions::new("link6", &reference);
    let fit = identify_payload(&truth, reference, &states(&b), &loaded, &options).unwrap();
    let want = parameters_of_payload(&p);
    let mut worst: f64 = 0.0;
    for (i, want) in want.iter().enumerate() {
        let z = (fit.theta[i] - want) / fit.stderr[i];
        worst = worst.max(z.abs());
        // the reference's share is part of the whole, and not nothing
        assert!(fit.stderr_of_reference[i] > 0.0 && fit.stderr_of_reference[i] <= fit.stderr[i]);
    }
    assert!(
        worst < 4.0,
        "{worst} standard errors: {:?} vs {want:?}",
        fit.theta
    );
    let got = fit.payload.as_ref().unwrap();
    let se = fit.payload_stderr.as_ref().unwrap();
    assert!(
        (got.mass - p.mass).abs() < 4.0 * se.mass && se.mass < 0.02,
        "{got:?} {se:?}"
    );
    for i in 0..3 {
        assert!(
            (got.com[i] - p.com[i]).abs() < 4.0 * se.com[i],
            "{got:?} {se:?}"
        );
    }
    // the residuals are the noise's
    for r in &fit.residual_rms {
        assert!(
            (0.8 * noise..1.3 * noise).contains(r),
            "{:?}",
            fit.residual_rms
        );
    }
    assert!(
        fit.payload_torque_rms[1] > 1.0,
        "{:?}",
        fit.payload_torque_rms
    );
    // 0.02 N m of noise leave its small inertia (0.004 kg m^2) undetermined: the least-squares
    // estimate is no rigid body, and is said not to be usable
    assert!(fit.not_a_rigid_body.is_some() && fit.usable_payload().is_none());
    assert!(
        fit.findings.iter().any(|f| f
            .starts_with("the payload's inertia about its centre of mass is loosely determined")),
        "{:?}",
        fit.findings
    );
    assert!(
        fit.findings
            .iter()
            .any(|f| f.contains("identify it consistent")),
        "{:?}",
        fit.findings
    );

    // the consistent estimate is a rigid body, costs little more, and keeps the mass and centre
    let consistent = PayloadOptions {
        consistent: true,
        ..options
    };
    let c = identify_payload(&truth, reference, &states(&b), &loaded, &consistent).unwrap();
    let cp = c.usable_payload().expect("a rigid body");
    assert!(cp.problem("payload").is_none(), "{cp:?}");
    let growth = c.residual_growth.unwrap();
    assert!((1.0..1.01).contains(&growth), "{growth}");
    assert!((cp.mass - p.mass).abs() < 4.0 * se.mass, "{cp:?}");
    for i in 0..3 {
        assert!(
            (cp.com[i] - p.com[i]).abs() < 4.0 * se.com[i] + 1e-3,
            "{cp:?} {se:?}"
        );
    }
    assert!(
        c.findings
            .iter()
            .any(|f| f.starts_with("the least-squares estimate is no rigid body")),
        "{:?}",
        c.findings
    );
    // its residuals are the fit's own for its parameters: weighted, no lower than the
    // unconstrained fit's, and higher by the growth
    let weighted =
        |r: &[f64]| -> f64 { r.iter().zip(&fit.sigma).map(|(r, s)| (r / s).powi(2)).sum() };
    let (wc, wu) = (weighted(&c.residual_rms), weighted(&fit.residual_rms));
    assert!(
        wc >= wu * (1.0 - 1e-9) && (wc / wu - growth).abs() < 1e-6,
        "{wc} vs {wu}, growth {growth}"
    );
}

#[test]
fn where_least_squares_gives_a_rigid_body_the_consistent_estimate_is_the_same() {
    let (truth, p) = (truth(), payload());
    let s = motion(4);
    let tau = loaded_torques(&truth, Some(&p), 4, 1e-4);
    let reference = Reference::Urdf;
    let plain = PayloadOptions::new("link6", &reference);
    let consistent = PayloadOptions {
        consistent: true,
        ..plain.clone()
    };
    let a = identify_payload(&truth, reference, &states(&s), &tau, &plain).unwrap();
    let b = identify_payload(&truth, reference, &states(&s), &tau, &consistent).unwrap();
    assert!(a.not_a_rigid_body.is_none(), "{:?}", a.not_a_rigid_body);
    for i in 0..a.theta.len() {
        assert!(
            (a.theta[i] - b.theta[i]).abs() < 1e-6 * (1.0 + a.theta[i].abs()),
            "{}: {} vs {}",
            a.names[i],
            a.theta[i],
            b.theta[i]
        );
    }
    assert!((b.residual_growth.unwrap() - 1.0).abs() < 1e-6);
}

#[test]
fn the_delta_rules_jacobian_is_the_finite_differences_of_the_payloads_quantities() {
    let pi = parameters_of_payload(&payload());
    let (u, jac) = payload_of_parameters(&pi);
    assert!((u[0] - 2.0).abs() < 1e-15 && (u[3] - 0.08).abs() < 1e-15);
    for c in 0..10 {
        let h = 1e-6 * (1.0 + pi[c].abs());
        let (mut up, mut down) = (pi, pi);
        up[c] += h;
        down[c] -= h;
        let (a, b) = (payload_of_parameters(&up).0, payload_of_parameters(&down).0);
        for r in 0..10 {
            let fd = (a[r] - b[r]) / (2.0 * h);
            assert!(
                (fd - jac[(r, c)]).abs() < 1e-7 * (1.0 + fd.abs()),
                "d{r}/d{c}: {fd} vs {}",
                jac[(r, c)]
            );
        }
    }
}

#[test]
fn a_log_without_the_payload_says_no_payload_is_seen() {
    let truth = truth();
    let s = motion(4);
    let tau = loaded_torques(&truth, None, 4, 0.02);
    let reference = Reference::Urdf;
    let fit = identify_payload(
        &truth,
        reference,
        &states(&s),
        &tau,
        &PayloadOptions::new("link6", &reference),
    )
    .unwrap();
    assert!(fit.payload.is_none() && fit.usable_payload().is_none());
    assert!(
        fit.findings
            .iter()
            .any(|f| f.starts_with("no payload on 'link6' is seen")),
        "{:?}",
        fit.findings
    );
    // a URDF heavier than the robot at the link: a negative mass, named as the reference's
    let mut heavy = truth.clone();
    let b = heavy.bodies.iter().position(|b| b.link == "link6").unwrap();
    heavy.bodies[b].inertia.mass += 0.5;
    heavy.refresh();
    let fit = identify_payload(
        &heavy,
        reference,
        &states(&s),
        &tau,
        &PayloadOptions::new("link6", &reference),
    )
    .unwrap();
    assert!(fit.payload.is_none());
    assert!(
        fit.findings.iter().any(|f| f.contains("negative mass")
            && f.contains("the URDF's parameters is heavier")
            && f.contains("identify a model of the robot alone")),
        "{:?}",
        fit.findings
    );
}

#[test]
fn payloads_the_joints_cannot_see_and_references_that_disagree_are_refused() {
    let (truth, p) = (truth(), payload());
    let s = motion(4);
    let tau = loaded_torques(&truth, Some(&p), 4, 0.0);
    let reference = Reference::Urdf;
    let fit = |link: &str| {
        identify_payload(
            &truth,
            reference,
            &states(&s),
            &tau,
            &PayloadOptions::new(link, &reference),
        )
    };
    // on the first link only the first joint's torque sees it: its mass and most moments
    // are not determined
    match fit("link1") {
        Err(Error::RankDeficient {
            context, missing, ..
        }) => {
            assert!(
                context.contains("payload identification on 'link1'"),
                "{context}"
            );
            assert!(missing.contains("payload.m"), "{missing}");
        }
        other => panic!("{other:?}"),
    }
    let e = fit("base_link").unwrap_err().to_string();
    assert!(
        e.contains("'base_link' is fixed to the base") && e.contains("link6"),
        "{e}"
    );
    // a reference identified with gravity left out of the torques
    let a = motion(3);
    let alone = loaded_torques(&truth, None, 3, 0.01);
    let model =
        identify_base_parameters(&truth, &states(&a), &alone, &BaseOptions::default()).unwrap();
    let options = PayloadOptions {
        gravity: Gravity::Excluded,
        ..PayloadOptions::new("link6", &Reference::Model(&model))
    };
    let e = identify_payload(
        &truth,
        Reference::Model(&model),
        &states(&s),
        &tau,
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("gravity") && e.contains("must agree"), "{e}");
    // a reference of another robot
    let panda_like = perturbid_rs::robots::a465::model("physical").unwrap();
    let mut other = panda_like.clone();
    other.joint_names[0] = "waist".into();
    let e = identify_payload(
        &other,
        Reference::Model(&model),
        &states(&s),
        &tau,
        &PayloadOptions::new("link6", &Reference::Model(&model)),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("identified for"), "{e}");
    // states without accelerations
    let q_only = perturbid_rs::States::new(6, &s.q, Some(&s.qd), None).unwrap();
    let e = identify_payload(
        &truth,
        reference,
        &q_only,
        &tau,
        &PayloadOptions::new("link6", &reference),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("preprocess"), "{e}");
}

#[test]
fn a_torque_column_in_other_units_is_named_before_the_payload_made_of_it() {
    let (truth, p) = (truth(), payload());
    let s = motion(4);
    let mut tau = loaded_torques(&truth, Some(&p), 4, 0.01);
    // the shoulder's torque logged in mN m
    for v in tau.iter_mut().skip(1).step_by(6) {
        *v *= 1000.0;
    }
    let reference = Reference::Urdf;
    let fit = identify_payload(
        &truth,
        reference,
        &states(&s),
        &tau,
        &PayloadOptions::new("link6", &reference),
    )
    .unwrap();
    assert!(
        fit.findings[0].starts_with("the torque of joint 'joint2' reads")
            && fit.findings[0].contains("units"),
        "{:?}",
        fit.findings
    );
    // and what the fit made of it is not to be used
    assert!(fit.payload.is_some() && fit.usable_payload().is_none());
}

/// The A465 with a tool frame `tool0` fixed to link 6, turned and offset.
fn a465_with_tool_frame() -> Model {
    let urdf = perturbid_rs::robots::a465::urdf("kinsheel2010").unwrap();
    let tool = r#"<joint name="tool_joint" type="fixed"><parent link="link6"/><child link="tool0"/>
<origin xyz="0.01 -0.02 0.1" rpy="0.3 -0.2 0.5"/></joint><link name="tool0"/></robot>"#;
    let urdf = urdf.replace("</robot>", tool);
    perturbid_rs::urdf::model_from_urdf_str(&urdf, "a465 with tool0", &Default::default()).unwrap()
}

#[test]
fn a_payload_on_a_tool_frame_is_given_in_that_frame() {
    let truth = a465_with_tool_frame();
    // the payload given in the tool frame: its com 5 cm along the tool's z
    let on_tool = Payload {
        link: "tool0".into(),
        mass: 1.2,
        com: [0.0, 0.01, 0.05],
        inertia: [0.003, 0.0002, 0.0, 0.004, 0.0, 0.002],
    };
    let s = motion(4);
    let fit = |link: &str, noise: f64| {
        let tau = loaded_torques(&truth, Some(&on_tool), 4, noise);
        let reference = Reference::Urdf;
        identify_payload(
            &truth,
            reference,
            &states(&s),
            &tau,
            &PayloadOptions::new(link, &reference),
        )
        .unwrap()
    };
    // noise-free: the payload as given, in the tool's frame
    let exact = fit("tool0", 0.0);
    assert_eq!(
        (exact.link.as_str(), exact.body.as_str()),
        ("tool0", "link6")
    );
    let p = exact.usable_payload().unwrap();
    assert!((p.mass - 1.2).abs() < 1e-8);
    for i in 0..3 {
        assert!((p.com[i] - on_tool.com[i]).abs() < 1e-8, "{p:?}");
    }
    for i in 0..6 {
        assert!((p.inertia[i] - on_tool.inertia[i]).abs() < 1e-8, "{p:?}");
    }
    // noisy: one regression (the body's ten parameters), given in either frame
    let (tool, six) = (fit("tool0", 0.02), fit("link6", 0.02));
    for (a, b) in tool.theta.iter().zip(&six.theta) {
        assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()));
    }
    let pose = perturbid_rs::spatial::Se3::from_xyz_rpy([0.01, -0.02, 0.1], [0.3, -0.2, 0.5]);
    let (pt, ps) = (
        tool.payload.as_ref().unwrap(),
        six.payload.as_ref().unwrap(),
    );
    let c = pose.rotation * nalgebra::Vector3::from(pt.com) + pose.translation;
    let r = pose.rotation;
    let sym =
        |v: &[f64; 6]| nalgebra::Matrix3::new(v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5]);
    let turned = r * sym(&pt.inertia) * r.transpose();
    for i in 0..3 {
        assert!((ps.com[i] - c[i]).abs() < 1e-12, "{ps:?} vs {c:?}");
    }
    assert!((turned - sym(&ps.inertia)).norm() < 1e-12);
    // the standard errors turn with the frame: the mass's alike, the total variance of the
    // centre and the inertia's trace alike
    let (st, ss) = (tool.payload_stderr.unwrap(), six.payload_stderr.unwrap());
    assert!((st.mass - ss.mass).abs() < 1e-12);
    let total = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
    assert!(
        (total(&st.com) / total(&ss.com) - 1.0).abs() < 1e-9,
        "{st:?} {ss:?}"
    );
    assert!(((pt.mass - 1.2) / st.mass).abs() < 4.0);
}

#[test]
fn a_point_mass_comes_back_exactly_and_from_poses_held_still() {
    use perturbid_rs::direct::PayloadInertia;
    let truth = truth();
    // a point mass 8 cm out: its inertia about the joint frame is not 0, and follows from it
    let point = Payload {
        link: "link6".into(),
        mass: 1.1,
        com: [0.02, -0.01, 0.08],
        inertia: [0.0; 6],
    };
    let s = motion(4);
    let tau = loaded_torques(&truth, Some(&point), 4, 0.0);
    let reference = Reference::Urdf;
    let options = PayloadOptions {
        inertia: PayloadInertia::PointMass,
        ..PayloadOptions::new("link6", &reference)
    };
    let fit = identify_payload(&truth, reference, &states(&s), &tau, &options).unwrap();
    let p = fit.usable_payload().unwrap();
    assert!((p.mass - 1.1).abs() < 1e-9, "{p:?}");
    for i in 0..3 {
        assert!((p.com[i] - point.com[i]).abs() < 1e-9, "{p:?}");
    }
    assert_eq!(p.inertia, [0.0; 6]);
    assert_eq!(fit.inertia, PayloadInertia::PointMass);
    assert!(fit.findings.is_empty(), "{:?}", fit.findings);
    let want = parameters_of_payload(&point);
    for (a, b) in fit.theta.iter().zip(&want) {
        assert!(
            (a - b).abs() < 1e-9 * (1.0 + b.abs()),
            "{:?} vs {want:?}",
            fit.theta
        );
    }

    // poses held still: only gravity, so the inertia is not determined at all; the point
    // mass's mass and centre are, with an offset a joint beside them
    let mut rng = Rng(7);
    let poses = 40;
    let q: Vec<f64> = (0..poses)
        .flat_map(|_| {
            truth
                .limits
                .iter()
                .map(|l| rng.uniform(0.8 * l.lower, 0.8 * l.upper))
                .collect::<Vec<_>>()
        })
        .collect();
    let zeros = vec![0.0; q.len()];
    let held = perturbid_rs::States::new(6, &q, Some(&zeros), Some(&zeros)).unwrap();
    let loaded = carrying(&truth, Some(&point));
    let mut tau = vec![0.0; q.len()];
    perturbid_rs::parallel::rnea(
        &loaded,
        &mut perturbid_rs::parallel::Workspace::new(&loaded),
        &held,
        Gravity::Included,
        &mut tau,
    )
    .unwrap();
    let offsets = PayloadOptions {
        terms: FrictionTerms {
            offset: true,
            ..FrictionTerms::NONE
        },
        ..options.clone()
    };
    let fitted = PayloadOptions {
        inertia: PayloadInertia::Fitted,
        ..offsets.clone()
    };
    match identify_payload(&truth, reference, &held, &tau, &fitted) {
        Err(Error::RankDeficient { missing, .. }) => {
            assert!(missing.contains("payload.I"), "{missing}")
        }
        other => panic!("{other:?}"),
    }
    let fit = identify_payload(&truth, reference, &held, &tau, &offsets).unwrap();
    let p = fit.usable_payload().unwrap();
    assert!(
        (p.mass - 1.1).abs() < 1e-9 && (p.com[2] - 0.08).abs() < 1e-9,
        "{p:?}"
    );

    // and a point mass is a rigid body already
    let both = PayloadOptions {
        consistent: true,
        ..options
    };
    let e = identify_payload(
        &truth,
        reference,
        &states(&s),
        &tau_of(&truth, &point),
        &both,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("point mass"), "{e}");
}

fn tau_of(truth: &Model, p: &Payload) -> Vec<f64> {
    loaded_torques(truth, Some(p), 4, 0.0)
}

#[test]
fn a_point_mass_determines_a_small_payloads_mass_and_centre_better() {
    use perturbid_rs::direct::PayloadInertia;
    let (truth, p) = (truth(), payload());
    let s = motion(4);
    let tau = loaded_torques(&truth, Some(&p), 4, 0.05);
    let reference = Reference::Urdf;
    let fitted = PayloadOptions::new("link6", &reference);
    let point = PayloadOptions {
        inertia: PayloadInertia::PointMass,
        ..fitted.clone()
    };
    let a = identify_payload(&truth, reference, &states(&s), &tau, &fitted).unwrap();
    let b = identify_payload(&truth, reference, &states(&s), &tau, &point).unwrap();
    let (sa, sb) = (a.payload_stderr.unwrap(), b.payload_stderr.unwrap());
    assert!(sb.mass < sa.mass && sb.com[2] < sa.com[2], "{sa:?} {sb:?}");
    // its inertia (0.002-0.004 kg m^2, small beside a 2 kg mass 8 cm out) biases it little
    let q = b.payload.as_ref().unwrap();
    assert!(
        (q.mass - p.mass).abs() < 4.0 * sb.mass + 0.01,
        "{q:?} {sb:?}"
    );
    for i in 0..3 {
        assert!(
            (q.com[i] - p.com[i]).abs() < 4.0 * sb.com[i] + 2e-3,
            "{q:?} {sb:?}"
        );
    }
}

#[test]
fn the_real_panda_log_holds_no_payload_against_a_model_of_its_first_half() {
    // the real Franka Emika Panda log (docs/data.md): a model of the robot from its first
    // half, the payload on the hand looked for in its second half, where there is none
    let Some((model, rec)) = common::panda_preprocessed() else {
        return;
    };
    let (k, n) = (rec.len(), model.nv);
    let half = k / 2;
    let states = rec.states().unwrap();
    let options = BaseOptions {
        friction: FrictionTerms::ALL,
        ..BaseOptions::default()
    };
    let alone = identify_base_parameters(
        &model,
        &states.slice(0..half),
        &rec.tau[..half * n],
        &options,
    )
    .unwrap();
    let reference = Reference::Model(&alone);
    let fit = identify_payload(
        &model,
        reference,
        &states.slice(half..k),
        &rec.tau[half * n..],
        &PayloadOptions::new("panda_hand", &reference),
    )
    .unwrap();
    assert_eq!(fit.body, "panda_link7");
    let (m, se) = (fit.theta[0], fit.stderr[0]);
    assert!(m.abs() < 3.0 * se && se < 0.05, "{m} +- {se} kg");
    assert!(fit.payload.is_none(), "{:?}", fit.payload);
    assert!(
        fit.findings
            .iter()
            .any(|f| f.starts_with("no payload on 'panda_hand' is seen")),
        "{:?}",
        fit.findings
    );
}

#[test]
fn the_references_share_of_the_errors_is_the_dense_propagation() {
    // G Phi_base Cov(theta) Phi_base^T G^T, G = (A^T W A)^-1 A^T W, built whole
    use nalgebra::{DMatrix, DVector};
    use perturbid_rs::direct::{regressor_matrix, ParameterLayout};
    let (truth, p) = (truth(), payload());
    let (a, b) = (motion(3), motion(4));
    let alone = loaded_torques(&truth, None, 3, 0.02);
    let model =
        identify_base_parameters(&truth, &states(&a), &alone, &BaseOptions::default()).unwrap();
    let k = 600;
    let sub = states(&b).slice(0..k);
    let loaded = loaded_torques(&truth, Some(&p), 4, 0.02);
    let reference = Reference::Model(&model);
    let fit = identify_payload(
        &truth,
        reference,
        &sub,
        &loaded[..k * 6],
        &PayloadOptions::new("link6", &reference),
    )
    .unwrap();
    let layout = ParameterLayout::new(&truth, FrictionTerms::NONE);
    let phi_full = regressor_matrix(&truth, &layout, &sub, Gravity::Included).unwrap();
    let body = truth.bodies.iter().position(|x| x.link == "link6").unwrap();
    // the unknowns: the payload's ten columns and an offset a joint
    let m = 16;
    let x = DMatrix::from_fn(6 * k, m, |r, c| match c {
        c if c < 10 => phi_full[(r, 10 * body + c)],
        c => f64::from(r % 6 == c - 10),
    });
    let ref_layout = &model.base.layout;
    let phi_ref = model
        .base
        .select(&regressor_matrix(&truth, ref_layout, &sub, Gravity::Included).unwrap());
    let w = DVector::from_fn(6 * k, |r, _| 1.0 / fit.sigma[r % 6].powi(2));
    let xtw = x.transpose() * DMatrix::from_diagonal(&w);
    let g = (&xtw * &x).try_inverse().unwrap() * xtw;
    let pr = model.theta.len();
    let cov = DMatrix::from_fn(pr, pr, |a, b| {
        model.stderr[a] * model.correlation[(a, b)] * model.stderr[b]
    });
    let gp = g * phi_ref;
    let carried = &gp * cov * gp.transpose();
    for i in 0..m {
        let want = carried[(i, i)].sqrt();
        let got = fit.stderr_of_reference[i];
        assert!(
            (got - want).abs() < 1e-8 * want,
            "{}: {got} vs {want}",
            fit.names[i]
        );
    }
}
