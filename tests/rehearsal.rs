//! The true robot of a rehearsal: every effect against an independent computation (its
//! formula, rounding, the URDF loader, a statistic of the noise), and closed-loop tracking.

mod common;

use perturbid_rs::rehearsal::{rehearse, Controller, Harmonic, Payload, TrueRobot};
use perturbid_rs::robots::a465;
use perturbid_rs::trajectory::Samples;
use perturbid_rs::{model_from_urdf_str, rnea, Data, Document, Gravity, LoadOptions, Model};

/// A smooth reference for every joint over `duration` s at `rate` Hz: `q = q0 + a sin(w t)`.
fn reference(n: usize, duration: f64, rate: f64) -> Samples {
    let k = (duration * rate) as usize + 1;
    let mut s = Samples::with_capacity(n, k);
    for i in 0..k {
        let t = i as f64 / rate;
        s.t.push(t);
        for j in 0..n {
            let (a, w, q0) = (0.3 + 0.05 * j as f64, 1.0 + 0.3 * j as f64, 0.1 * j as f64);
            s.q.push(q0 + a * (w * t).sin());
            s.qd.push(a * w * (w * t).cos());
            s.qdd.push(-a * w * w * (w * t).sin());
        }
    }
    s
}

fn rigid(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64], gravity: Gravity) -> Vec<f64> {
    let mut data = Data::new(model);
    rnea(model, &mut data, q, qd, qdd, gravity).unwrap();
    data.tau.as_slice().to_vec()
}

fn doc(json: &str) -> TrueRobot {
    TrueRobot::from_json(json).unwrap()
}

/// Friction (asymmetric Coulomb, Stribeck, position harmonics, drift), ripple and cogging:
/// the logged torque is the command that applies the rigid-body torque plus the friction of
/// their formulas; joint offsets move the true joints, not the log.
#[test]
fn joint_effects_follow_their_formulas() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let robot = doc(r#"{
        "format": "perturbid-true-robot/1",
        "joint_offsets": [0.01, -0.02, 0.0, 0.005, 0.0, 0.03],
        "friction": {
            "viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05],
            "coulomb": [0.3, 0.3, 0.2, 0.1, 0.1, 0.05],
            "coulomb_negative": [0.4, 0.2, 0.25, 0.12, 0.08, 0.06],
            "stribeck": [0.2, 0.1, 0.1, 0.05, 0.05, 0.02],
            "stribeck_velocity": [0.05, 0.05, 0.05, 0.1, 0.1, 0.1],
            "position": [[{"order": 2, "amplitude": 0.05}], [], [], [], [], [{"order": 1, "amplitude": 0.01, "phase": 0.5}]],
            "drift": [0.01, 0.0, 0.0, 0.0, 0.0, -0.02]
        },
        "ripple": [[{"order": 6, "amplitude": 0.02}], [], [], [], [], []],
        "cogging": [[], [{"order": 12, "amplitude": 0.03, "phase": 1.0}], [], [], [], []]
    }"#);
    let r = reference(n, 2.0, 200.0);
    let rec = rehearse(&model, &robot, &r, 0, "log").unwrap();
    assert_eq!(
        rec.q, r.q,
        "exact tracking logs the reference (the encoders read it)"
    );
    let off = robot.joint_offsets.clone().unwrap();
    let f = &robot.friction;
    let (v, c, cn, s, vs, d) = (
        f.viscous.clone().unwrap(),
        f.coulomb.clone().unwrap(),
        f.coulomb_negative.clone().unwrap(),
        f.stribeck.clone().unwrap(),
        f.stribeck_velocity.clone().unwrap(),
        f.drift.clone().unwrap(),
    );
    for i in (0..r.len()).step_by(7) {
        let t = r.t[i];
        let q: Vec<f64> = (0..n).map(|j| r.q_at(i)[j] - off[j]).collect();
        let tau = rigid(&model, &q, r.qd_at(i), r.qdd_at(i), Gravity::Included);
        for j in 0..n {
            let w = r.qd_at(i)[j];
            let position = match j {
                0 => 0.05 * (2.0 * q[0]).sin(),
                5 => 0.01 * (q[5] + 0.5).sin(),
                _ => 0.0,
            };
            let level = if w > 0.0 { c[j] } else { cn[j] } + position;
            let stribeck = s[j] * (-(w / vs[j]).powi(2)).exp();
            let friction = (1.0 + d[j] * t) * (v[j] * w + w.signum() * (level + stribeck));
            let ripple = if j == 0 {
                0.02 * (6.0 * q[0]).sin()
            } else {
                0.0
            };
            let cogging = if j == 1 {
                0.03 * (12.0 * q[1] + 1.0).sin()
            } else {
                0.0
            };
            let expected = (tau[j] + friction - cogging) / (1.0 + ripple);
            let got = rec.tau[i * n + j];
            assert!(
                (got - expected).abs() < 1e-9 * (1.0 + expected.abs()),
                "joint {j} at t = {t}: {got} vs {expected}"
            );
        }
    }
}

/// A payload on a link is the same robot as the URDF with that payload attached to the link
/// by a fixed joint (merged by the loader).
#[test]
fn a_payload_is_the_urdf_with_the_payload_attached() {
    let model = a465::model("kinsheel2010").unwrap();
    let payload = Payload {
        link: "link6".into(),
        mass: 1.5,
        com: [0.02, -0.01, 0.08],
        inertia: [0.004, 0.0001, 0.0, 0.005, 0.0002, 0.003],
    };
    let robot = TrueRobot {
        payload: Some(payload),
        ..TrueRobot::default()
    };
    let truth = robot.rigid_body_model(&model).unwrap();
    let urdf = a465::urdf("kinsheel2010").unwrap().replace(
        "</robot>",
        r#"<link name="tool"><inertial><origin xyz="0.02 -0.01 0.08"/><mass value="1.5"/>
           <inertia ixx="0.004" ixy="0.0001" ixz="0" iyy="0.005" iyz="0.0002" izz="0.003"/></inertial></link>
           <joint name="tool_mount" type="fixed"><parent link="link6"/><child link="tool"/></joint></robot>"#,
    );
    // the A465's lumped rotor inertias break the triangle inequality, as the built-in model does
    let options = LoadOptions {
        check_triangle_inequality: false,
        ..LoadOptions::default()
    };
    let attached = model_from_urdf_str(&urdf, "a465+tool", &options).unwrap();
    let r = reference(model.nv, 0.5, 20.0);
    for i in 0..r.len() {
        let (q, qd, qdd) = (r.q_at(i), r.qd_at(i), r.qdd_at(i));
        let a = rigid(&truth, q, qd, qdd, Gravity::Included);
        let b = rigid(&attached, q, qd, qdd, Gravity::Included);
        for j in 0..model.nv {
            assert!((a[j] - b[j]).abs() < 1e-10, "{j}: {} vs {}", a[j], b[j]);
        }
    }
    // and a link that does not exist is named with the ones that do
    let wrong = TrueRobot {
        payload: Some(Payload {
            link: "gripper".into(),
            mass: 1.0,
            com: [0.0; 3],
            inertia: [0.0; 6],
        }),
        ..TrueRobot::default()
    };
    let e = wrong.rigid_body_model(&model).unwrap_err().to_string();
    assert!(
        e.contains("'gripper' is not a link of") && e.contains("link6"),
        "{e}"
    );
}

/// Encoders round to whole counts; torques to whole resolution steps; the torque noise has
/// its standard deviation and correlation; a delay of two samples shifts the torque by two
/// samples; jitter moves the position by the speed times the jitter.
#[test]
fn sensors_quantise_delay_and_add_noise_as_specified() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let r = reference(n, 20.0, 500.0);
    let clean = rehearse(&model, &TrueRobot::default(), &r, 0, "clean").unwrap();
    let counts = 4096.0 * 100.0;
    let robot = doc(&format!(
        r#"{{"format": "perturbid-true-robot/1", "seed": 3,
            "sensors": {{"encoder_counts": [{counts}, {counts}, {counts}, {counts}, {counts}, {counts}],
                         "torque_resolution": [0.01, 0.01, 0.01, 0.01, 0.01, 0.01]}}}}"#
    ));
    let rec = rehearse(&model, &robot, &r, 0, "quantised").unwrap();
    let step = std::f64::consts::TAU / counts;
    for i in 0..rec.q.len() {
        assert_eq!(rec.q[i], (r.q[i] / step).round() * step);
        assert_eq!(rec.tau[i], (clean.tau[i] / 0.01).round() * 0.01);
    }
    // coloured noise: standard deviation 0.05, lag-1 correlation 0.9
    let robot = doc(r#"{"format": "perturbid-true-robot/1", "seed": 5,
        "sensors": {"torque_noise": [0.05, 0.05, 0.05, 0.05, 0.05, 0.05],
                    "torque_noise_correlation": [0.9, 0.9, 0.9, 0.0, 0.0, 0.0]}}"#);
    let rec = rehearse(&model, &robot, &r, 0, "noisy").unwrap();
    for j in [0, 3] {
        let e: Vec<f64> = (0..rec.len())
            .map(|i| rec.tau[i * n + j] - clean.tau[i * n + j])
            .collect();
        let var = e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64;
        let lag1 = e.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (e.len() - 1) as f64 / var;
        assert!(
            (var.sqrt() - 0.05).abs() < 0.005,
            "joint {j}: std {}",
            var.sqrt()
        );
        let rho = if j == 0 { 0.9 } else { 0.0 };
        assert!(
            (lag1 - rho).abs() < 0.03,
            "joint {j}: lag-1 correlation {lag1}"
        );
    }
    // a torque delay of exactly two samples
    let robot = doc(r#"{"format": "perturbid-true-robot/1", "sensors": {"delay": 0.004}}"#);
    let rec = rehearse(&model, &robot, &r, 0, "delayed").unwrap();
    for i in 2..rec.len() {
        for j in 0..n {
            let (a, b) = (rec.tau[i * n + j], clean.tau[(i - 2) * n + j]);
            assert!(
                (a - b).abs() < 1e-9 * (1.0 + b.abs()),
                "{i} {j}: {a} vs {b}"
            );
        }
        assert_eq!(
            rec.q[i * n..(i + 1) * n],
            clean.q[i * n..(i + 1) * n],
            "positions are not delayed"
        );
    }
    // jitter of 0.1 ms: (q_log - q_ref) / qd estimates the sampling-time error
    let robot =
        doc(r#"{"format": "perturbid-true-robot/1", "seed": 9, "sensors": {"jitter": 1e-4}}"#);
    let rec = rehearse(&model, &robot, &r, 0, "jittered").unwrap();
    let eps: Vec<f64> = (1..rec.len() - 1)
        .filter(|&i| r.qd[i * n].abs() > 0.1)
        .map(|i| (rec.q[i * n] - r.q[i * n]) / r.qd[i * n])
        .collect();
    let sd = (eps.iter().map(|x| x * x).sum::<f64>() / eps.len() as f64).sqrt();
    assert!((sd - 1e-4).abs() < 1e-5, "jitter estimated at {sd:e} s");
}

/// Closed loop: with the true robot equal to the model and the computed-torque feed-forward,
/// the robot tracks almost exactly; with a payload the model does not know, the tracking error
/// shrinks as the gains grow, and the log shows it.
#[test]
fn tracking_error_shrinks_as_gains_grow() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let r = reference(n, 2.0, 500.0);
    let rms_error = |kp: f64, payload: f64| -> f64 {
        let robot = TrueRobot {
            payload: (payload > 0.0).then(|| Payload {
                link: "link6".into(),
                mass: payload,
                com: [0.0, 0.0, 0.05],
                inertia: [0.001, 0.0, 0.0, 0.001, 0.0, 0.001],
            }),
            controller: Some(Controller {
                kp: vec![kp; n],
                kd: vec![2.0 * kp.sqrt(); n],
                substeps: 4,
                feedforward: true,
                effort: None,
            }),
            ..TrueRobot::default()
        };
        let rec = rehearse(&model, &robot, &r, 0, "tracked").unwrap();
        let ss: f64 = rec.q.iter().zip(&r.q).map(|(a, b)| (a - b).powi(2)).sum();
        (ss / rec.q.len() as f64).sqrt()
    };
    let exact = rms_error(100.0, 0.0);
    let errors: Vec<f64> = [25.0, 100.0, 400.0]
        .iter()
        .map(|&kp| rms_error(kp, 2.0))
        .collect();
    // its own feed-forward, held over each sample: only the hold lags
    assert!(exact < 0.05 * errors[1], "{exact:e} vs {errors:?}");
    assert!(
        errors[0] > 1e-4,
        "a payload the model does not know: {errors:?}"
    );
    assert!(
        errors[1] < 0.5 * errors[0] && errors[2] < 0.5 * errors[1],
        "the error should shrink as the gains grow: {errors:?}"
    );
}

/// Hand-edited documents: unknown keys, negative levels, lengths that do not fit the robot.
#[test]
fn bad_true_robot_documents_are_refused_by_name() {
    let model = a465::model("kinsheel2010").unwrap();
    let e = TrueRobot::from_json(r#"{"format": "perturbid-true-robot/1", "frictoin": {}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `frictoin`"), "{e}");
    let e = TrueRobot::from_json(
        r#"{"format": "perturbid-true-robot/1", "friction": {"coulomb": [0.1, -0.2]}}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("friction.coulomb[1] is -0.2, expected >= 0"),
        "{e}"
    );
    // a delay or jitter past a second would hold the log's end torques and invent the rest
    for sensors in [
        r#"{"delay": 1e18}"#,
        r#"{"jitter": 2.0}"#,
        r#"{"delay": -1e-3}"#,
    ] {
        let e = TrueRobot::from_json(&format!(
            r#"{{"format": "perturbid-true-robot/1", "sensors": {sensors}}}"#
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("must be in [0, 1] s"), "{sensors}: {e}");
    }
    assert!(TrueRobot::from_json(
        r#"{"format": "perturbid-true-robot/1", "sensors": {"delay": 1.0, "jitter": 0.0}}"#
    )
    .is_ok());
    // sensors past any sensor: noise of 1e300 N m, an encoder of 3 counts a revolution (every
    // position rounded to 2 rad steps) or of 1e300 (positions over its step overflow), a
    // torque resolution of 1e-320 N m
    for (sensors, says) in [
        (
            r#"{"torque_noise": [1e300]}"#,
            "sensors.torque_noise[0] is 1e300, expected a value in [0, 1000000]",
        ),
        (
            r#"{"encoder_counts": [4096, 3]}"#,
            "sensors.encoder_counts[1] is 3, expected 0 (none) or a value in [7, 1e12]",
        ),
        (
            r#"{"encoder_counts": [1e300]}"#,
            "sensors.encoder_counts[0] is 1e300",
        ),
        (
            r#"{"torque_resolution": [0, 1e-320]}"#,
            "sensors.torque_resolution[1] is 1e-320, expected 0 (none) or a value in [1e-12, 1000000]",
        ),
    ] {
        let e = TrueRobot::from_json(&format!(
            r#"{{"format": "perturbid-true-robot/1", "sensors": {sensors}}}"#
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains(says), "{sensors}: {e}");
    }
    // friction past any joint's (1e300 N m drowns every torque) and offsets past half a turn
    for (body, says) in [
        (
            r#""friction": {"coulomb": [0.1, 1e300]}"#,
            "friction.coulomb[1] is 1e300, expected at most 1000000 in magnitude",
        ),
        (
            r#""friction": {"viscous": [-2e6]}"#,
            "friction.viscous[0] is -2000000, expected at most 1000000 in magnitude",
        ),
        (
            r#""joint_offsets": [0.0, 4.0]"#,
            "joint_offsets[1] is 4, expected at most pi (rad or m) in magnitude",
        ),
        (
            r#""cogging": [[{"order": 2, "amplitude": 1e7}]]"#,
            "cogging[0][0]: order 2 (expected in (0, 1e5]), amplitude 10000000 (expected at most 1e6 in magnitude)",
        ),
        // a payload no one could bolt on: the simulated mass matrix would not be positive
        (
            r#""payload": {"link": "link6", "mass": 1.0, "inertia": [-1, 0, 0, 0.002, 0, 0.001]}"#,
            "payload ([ixx, ixy, ixz, iyy, iyz, izz] = [-1.0, 0.0, 0.0, 0.002, 0.0, 0.001]): the inertia tensor is not positive semi-definite (principal moments -1.000000e0,",
        ),
        (
            r#""payload": {"link": "link6", "mass": 1.0, "inertia": [0.002, 0, 0, 0.002, 0, 0.01]}"#,
            "principal moments 2.000000e-3 + 2.000000e-3 < 1.000000e-2 kg m^2 break the triangle inequality",
        ),
        (
            r#""payload": {"link": "link6", "mass": 1e10}"#,
            "a mass or inertia beyond 1e9 (kg, kg m^2)",
        ),
        (
            r#""payload": {"link": "link6", "mass": 1.0, "com": [0.0, 1e300, 0.0]}"#,
            "payload.com[1] is 1e300 m, expected at most 1000 m in magnitude",
        ),
        (
            r#""link_errors": [{"link": "link3", "com": [2e3, 0.0, 0.0]}]"#,
            "link_errors[0].com[0] is 2000 m",
        ),
    ] {
        let e = TrueRobot::from_json(&format!(
            r#"{{"format": "perturbid-true-robot/1", {body}}}"#
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains(says), "{body}: {e}");
    }
    let short = doc(r#"{"format": "perturbid-true-robot/1", "friction": {"viscous": [0.1, 0.2]}}"#);
    let e = rehearse(&model, &short, &reference(6, 0.1, 100.0), 0, "x")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("friction.viscous") && e.contains("6 values"),
        "{e}"
    );
    let h = Harmonic {
        order: 0.0,
        amplitude: 1.0,
        phase: 0.0,
    };
    let bad = TrueRobot {
        cogging: Some(vec![vec![h]; 6]),
        ..TrueRobot::default()
    };
    assert!(bad
        .check(&model)
        .unwrap_err()
        .to_string()
        .contains("cogging[0][0]"));
    // an unstable controller: the divergence is named with its time
    let wild = TrueRobot {
        controller: Some(Controller {
            kp: vec![1e9; 6],
            kd: vec![0.0; 6],
            substeps: 1,
            feedforward: true,
            effort: None,
        }),
        ..TrueRobot::default()
    };
    let e = rehearse(&model, &wild, &reference(6, 1.0, 100.0), 0, "x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("diverges at t = "), "{e}");
}

/// The direct method rehearsed end to end on the true robot: a Fourier excitation run by a
/// robot with a payload and viscous and Coulomb friction (all of which the method models)
/// gives back the true robot's base parameters: its torques and mass matrix, exactly.
#[test]
fn the_direct_method_recovers_the_true_robot_from_a_rehearsed_excitation() {
    use perturbid_rs::direct::{identify_base_parameters, BaseOptions, FrictionTerms};
    use perturbid_rs::trajectory::FourierTrajectory;
    use perturbid_rs::{mass_matrix, States};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let a = nalgebra::DMatrix::from_fn(n, 5, |i, l| 0.1 * ((3 * i + 5 * l) as f64).sin());
    let b = nalgebra::DMatrix::from_fn(n, 5, |i, l| 0.1 * ((7 * i + 2 * l) as f64).cos());
    let traj = FourierTrajectory::new(
        2.0 * std::f64::consts::PI * 0.1,
        vec![0.2, 0.3, -0.4, 0.1, 0.5, -0.2],
        a,
        b,
    )
    .unwrap();
    let s = traj.sample_periods(1.0, 100.0).unwrap();
    let robot = doc(r#"{"format": "perturbid-true-robot/1",
        "payload": {"link": "link6", "mass": 1.2, "com": [0.01, 0.0, 0.06], "inertia": [0.002, 0, 0, 0.002, 0, 0.001]},
        "link_errors": [{"link": "link3", "mass": 0.1, "com": [0.01, 0.0, 0.0], "inertia": -0.2}],
        "friction": {"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], "coulomb": [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]}}"#);
    let rec = rehearse(&model, &robot, &s, 0, "excitation").unwrap();
    let fit = identify_base_parameters(
        &model,
        &States::new(n, &rec.q, Some(&s.qd), Some(&s.qdd)).unwrap(),
        &rec.tau,
        &BaseOptions {
            friction: FrictionTerms {
                viscous: true,
                coulomb: true,
                offset: false,
                armature: false,
            },
            ..BaseOptions::default()
        },
    )
    .unwrap();
    let truth = robot.rigid_body_model(&model).unwrap();
    let q = a465::TABLE2_Q;
    let mut data = Data::new(&truth);
    mass_matrix(&truth, &mut data, &q).unwrap();
    let m = fit.mass_matrix(&model, &q).unwrap();
    let err = (&m - &data.m).norm() / data.m.norm();
    assert!(err < 1e-8, "M(q*) of the fit vs the true robot: {err:e}");
    // and the nominal model is not what was identified
    let mut nominal = Data::new(&model);
    mass_matrix(&model, &mut nominal, &q).unwrap();
    assert!((&m - &nominal.m).norm() > 1e-3 * nominal.m.norm());
}

/// A joint touching zero speed without stopping keeps its friction's direction: the hand-made
/// speeds' directions by the rule (a touch, a reversal, a rest, the ends, rounding errors of
/// either sign); and along an excitation that starts and ends each period at rest (`qd = qdd =
/// 0`, where the summed series leaves speeds of about 1e-17 of either sign), the friction both
/// simulators log there is the Coulomb level of the motion around it, so that a noisy log of it
/// has no glitch for the screening to find (it had one at every period boundary).
#[test]
fn friction_keeps_its_direction_where_a_joint_touches_zero_speed() {
    use perturbid_rs::simulation::{directions_of_motion, simulate_samples, Friction};
    let qd = [
        0.0, 1.0, 0.0, 2.0, 0.0, -1.0, 0.0, 0.0, 1e-17, 3.0, -1e-17, 3.0, 0.0,
    ];
    let expected = [1., 1., 1., 1., 0., -1., 0., 0., 0., 1., 1., 1., 1.];
    assert_eq!(directions_of_motion(&qd, 1), expected);
    // two joints interleaved: each judged on its own speeds
    let two: Vec<f64> = qd.iter().flat_map(|&v| [v, -v]).collect();
    let d = directions_of_motion(&two, 2);
    for i in 0..qd.len() {
        assert_eq!(
            (d[2 * i], d[2 * i + 1]),
            (expected[i], -expected[i]),
            "sample {i}"
        );
    }

    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let mut rng = common::Rng(7);
    let e = common::a465_excitation(&mut rng);
    // the last harmonic cancels the others' speed and acceleration at t = 0
    let (w, h) = (e.w_f, e.harmonics());
    let (mut a, mut b) = (e.a.clone(), e.b.clone());
    for i in 0..n {
        a[(i, h - 1)] = -(0..h - 1).map(|l| a[(i, l)]).sum::<f64>();
        b[(i, h - 1)] = -(0..h - 1).map(|l| (l + 1) as f64 * b[(i, l)]).sum::<f64>() / h as f64;
    }
    let e = perturbid_rs::trajectory::FourierTrajectory::new(w, e.q0.clone(), a, b).unwrap();
    let s = e.sample_periods(2.0, 1000.0).unwrap();
    let boundaries = [0, 10_000, 20_000];
    for &i in &boundaries {
        for j in 0..n {
            assert!(s.qd_at(i)[j].abs() < 1e-12 && s.qdd_at(i)[j].abs() < 1e-9);
        }
    }
    let coulomb = [1.0, 0.8, 0.6, 0.4, 0.2, 0.1];
    let json = format!(
        r#"{{"format": "perturbid-true-robot/1", "friction": {{"coulomb": {coulomb:?}}}}}"#
    );
    let rehearsed = rehearse(&model, &doc(&json), &s, 0, "excitation").unwrap();
    let mut options = perturbid_rs::simulation::SimulationOptions::new(&model);
    options.friction = Friction::viscous_coulomb(vec![0.0; n], coulomb.to_vec());
    let simulated = simulate_samples(&model, &s, &options, 0, "excitation").unwrap();
    for rec in [&rehearsed, &simulated] {
        for &i in &boundaries {
            let tau = rigid(
                &model,
                s.q_at(i),
                s.qd_at(i),
                s.qdd_at(i),
                Gravity::Included,
            );
            // the direction the joint moves in at the sample next to the boundary
            let next = if i + 1 < s.len() { i + 1 } else { i - 1 };
            for j in 0..n {
                let friction = rec.tau[i * n + j] - tau[j];
                let expected = coulomb[j] * s.qd_at(next)[j].signum();
                assert!(
                    (friction - expected).abs() < 1e-9,
                    "{}: joint {j} at sample {i}: friction {friction}, expected {expected}",
                    rec.name
                );
            }
        }
    }
    let json = format!(
        r#"{{"format": "perturbid-true-robot/1", "friction": {{"coulomb": {coulomb:?}}},
            "sensors": {{"torque_noise": [0.05, 0.05, 0.05, 0.02, 0.02, 0.02]}}}}"#
    );
    let noisy = rehearse(&model, &doc(&json), &s, 0, "excitation").unwrap();
    let (_, glitches) = perturbid_rs::logs::log_screening::screen_recording(&noisy).unwrap();
    assert!(glitches.is_empty(), "{glitches:?}");
}

/// A drive's torque limit (`controller.effort`): the command is clipped there and logged so,
/// the joint falls behind the reference, and the log's preprocessing names the clipped
/// torques; the joints whose limits are not reached log what they would without one.
#[test]
fn a_saturated_drive_clips_its_command_and_the_log_shows_it() {
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let r = reference(n, 4.0, 500.0);
    let with_limits = |effort: Option<Vec<f64>>| TrueRobot {
        controller: Some(Controller {
            kp: vec![400.0; n],
            kd: vec![40.0; n],
            substeps: 4,
            feedforward: true,
            effort,
        }),
        ..TrueRobot::default()
    };
    let run = |effort| rehearse(&model, &with_limits(effort), &r, 0, "tracked").unwrap();
    let free = run(None);
    let k = r.len();
    let column = |x: &[f64], j: usize| -> Vec<f64> { (0..k).map(|i| x[i * n + j]).collect() };
    let peak = column(&free.tau, 1)
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let limit = 0.97 * peak;
    let mut effort = vec![1e6; n];
    effort[1] = limit;
    let held = run(Some(effort));
    let shoulder = column(&held.tau, 1);
    assert!(shoulder.iter().all(|x| x.abs() <= limit));
    let clipped = shoulder.iter().filter(|x| x.abs() == limit).count();
    assert!(clipped > 20, "{clipped} samples at the limit");
    // the shoulder falls behind where its drive saturates
    let error = |rec: &perturbid_rs::Recording| {
        (0..k)
            .map(|i| (rec.q[i * n + 1] - r.q[i * n + 1]).abs())
            .fold(0.0, f64::max)
    };
    assert!(
        error(&held) > 10.0 * error(&free),
        "{} vs {}",
        error(&held),
        error(&free)
    );
    // a limit no command reaches changes nothing
    let loose = run(Some(vec![10.0 * peak.max(1.0); n]));
    assert_eq!(loose.tau, free.tau);
    // the log's preprocessing finds the shoulder's clipped torques, and only those
    let p = preprocess(&held, &PreprocessOptions::default()).unwrap();
    assert!(!p.torque_saturation.is_empty(), "nothing found");
    assert!(
        p.torque_saturation
            .iter()
            .all(|s| s.joint == 1 && (s.level.abs() - limit).abs() < 1e-12),
        "{:?}",
        p.torque_saturation
    );
    // a limit that is not positive, or one short, is refused by name
    let bad = |effort: Vec<f64>| {
        rehearse(&model, &with_limits(Some(effort)), &r, 0, "tracked")
            .unwrap_err()
            .to_string()
    };
    let e = bad(vec![0.0; n]);
    assert!(
        e.contains("controller.effort[0] is 0, expected a positive torque limit"),
        "{e}"
    );
    let e = bad(vec![100.0; n - 1]);
    assert!(e.contains("controller.effort"), "{e}");
}
