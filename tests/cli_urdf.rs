//! The identified robot as URDF from the command line: `identify-direct --consistent --urdf`
//! writes a file whose torques, friction and armature are the saved model's, and
//! `identify-payload --urdf` the robot carrying the payload it found; what cannot be written
//! is refused by name with nothing written.

mod cli_support;

use cli_support::{excitation_log, fails, nothing_written, ok, s, tmp};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::{model_from_urdf_file, robots, Data, Document, Gravity, LoadOptions, States};

#[test]
fn the_consistent_robot_written_as_urdf_predicts_what_its_model_does() {
    let d = tmp("urdf-direct");
    let log = excitation_log(&d, 4);
    let urdf = d.join("identified.urdf");
    let out = ok(&[
        "identify-direct",
        "a465",
        s(&log),
        "--friction",
        "viscous,coulomb",
        "--consistent",
        "--out",
        s(&d.join("consistent.json")),
        "--urdf",
        s(&urdf),
    ]);
    assert!(out.contains("the identified robot as URDF ->"), "{out}");
    assert!(out.contains("link 'link3': a new <inertial>"), "{out}");
    assert!(out.contains("joint 'joint2': <dynamics> damping="), "{out}");
    let model = BaseModel::load(d.join("consistent.json")).unwrap();
    let written = model_from_urdf_file(&urdf, &LoadOptions::default()).unwrap();
    let nominal = robots::a465::model("kinsheel2010").unwrap();
    // at random states: the URDF's rigid bodies, armature and friction are the model's
    let n = 6;
    let mut seed = 5u64;
    let mut next = |scale: f64| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        scale * (2.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
    };
    let k = 50;
    let q: Vec<f64> = (0..k * n).map(|_| next(1.5)).collect();
    let qd: Vec<f64> = (0..k * n).map(|_| next(2.0)).collect();
    let qdd: Vec<f64> = (0..k * n).map(|_| next(4.0)).collect();
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let predicted = model.predict(&nominal, &states).unwrap();
    let mut data = Data::new(&written);
    for r in 0..k {
        let rows = r * n..(r + 1) * n;
        perturbid_rs::rnea(
            &written,
            &mut data,
            &q[rows.clone()],
            &qd[rows.clone()],
            &qdd[rows.clone()],
            Gravity::Included,
        )
        .unwrap();
        for j in 0..n {
            let l = &written.limits[j];
            let v = qd[r * n + j];
            let tau = data.tau[j] + l.damping * v + l.friction * v.signum();
            let p = predicted[r * n + j];
            assert!(
                (tau - p).abs() <= 1e-8 * p.abs().max(1.0),
                "sample {r} joint {j}: {tau} vs {p}"
            );
        }
    }
    // everything but the inertials and dynamics as the built-in file has it
    let text = std::fs::read_to_string(&urdf).unwrap();
    let source = robots::a465::urdf("kinsheel2010").unwrap();
    assert_eq!(
        text.matches("<limit").count(),
        source.matches("<limit").count()
    );
    assert!(text.contains(&format!("from {}", s(&log))), "{text}");

    // the URDF validated against the log as a model: as good as the saved model, and the
    // built-in robot the log came from as good; another robot's parameters worse
    let rms = |dir: &str| -> Vec<f64> {
        let v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(d.join(dir).join("validation.json")).unwrap(),
        )
        .unwrap();
        v["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j["rms"].as_f64().unwrap())
            .collect()
    };
    ok(&["validate", s(&urdf), s(&log), "--out", s(&d.join("v_urdf"))]);
    ok(&[
        "validate",
        s(&d.join("consistent.json")),
        s(&log),
        "--robot",
        "a465",
        "--out",
        s(&d.join("v_model")),
    ]);
    let warned =
        cli_support::warnings_of(&["validate", "a465", s(&log), "--out", s(&d.join("v_a465"))]);
    assert!(warned.contains("gives its joints no friction"), "{warned}");
    ok(&[
        "validate",
        "a465:physical",
        s(&log),
        "--out",
        s(&d.join("v_physical")),
    ]);
    let (by_urdf, by_model, by_a465, by_physical) = (
        rms("v_urdf"),
        rms("v_model"),
        rms("v_a465"),
        rms("v_physical"),
    );
    for j in 0..6 {
        assert!(
            (by_urdf[j] - by_model[j]).abs() < 1e-6 * by_model[j].max(1e-3),
            "{by_urdf:?} vs {by_model:?}"
        );
        assert!(by_a465[j] < 0.05, "{by_a465:?}");
    }
    assert!(
        by_physical.iter().sum::<f64>() > 10.0 * by_a465.iter().sum::<f64>(),
        "{by_physical:?}"
    );
    // --robot beside a robot (a pipeline's defaults): the same robot's joints, or refused
    ok(&[
        "validate",
        s(&urdf),
        s(&log),
        "--robot",
        "a465",
        "--out",
        s(&d.join("v_same")),
    ]);
    assert_eq!(rms("v_same"), by_urdf);
    let arm = d.join("arm.urdf");
    cli_support::write(
        &arm,
        r#"<robot name="arm"><link name="base"/>
  <link name="upper"><inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="2" effort="50"/></joint></robot>"#,
    );
    fails(
        &[
            "validate",
            "a465",
            s(&log),
            "--robot",
            s(&arm),
            "--out",
            s(&d.join("v_bad")),
        ],
        &["--robot", "must be the same robot", "shoulder"],
    );
    fails(
        &[
            "validate",
            "a465",
            s(&log),
            "--signal",
            "--out",
            s(&d.join("v_bad")),
        ],
        &["--signal", "is a robot, validated with its own parameters"],
    );
    nothing_written(&d, "v_bad");

    // refused: base parameters name no link's own, and the robot's file is not overwritten
    fails(
        &[
            "identify-direct",
            "a465",
            s(&log),
            "--out",
            s(&d.join("b.json")),
            "--urdf",
            s(&d.join("b.urdf")),
        ],
        &["--urdf", "needs --consistent"],
    );
    assert!(!d.join("b.json").exists() && !d.join("b.urdf").exists());
    let robot = d.join("robot.urdf");
    std::fs::write(&robot, source).unwrap();
    fails(
        &[
            "identify-direct",
            s(&robot),
            s(&log),
            "--consistent",
            "--out",
            s(&d.join("c.json")),
            "--urdf",
            s(&robot),
        ],
        &[s(&robot)],
    );
    assert_eq!(std::fs::read_to_string(&robot).unwrap(), source);
}

#[test]
fn identify_payload_writes_the_robot_carrying_it() {
    let d = tmp("urdf-payload");
    let log = cli_support::a465_log_carrying(&d, "loaded.csv", Some(cli_support::TRUE_PAYLOAD), 3);
    let out_dir = d.join("p");
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&log),
        "--link",
        "link6",
        "--urdf",
        "--payload-link",
        "drill",
        "--out",
        s(&out_dir),
    ]);
    assert!(out.contains("robot_with_payload.urdf"), "{out}");
    let written = model_from_urdf_file(
        out_dir.join("robot_with_payload.urdf"),
        &LoadOptions::default(),
    )
    .unwrap();
    let nominal = robots::a465::model("kinsheel2010").unwrap();
    let payload: perturbid_rs::rehearsal::Payload =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("payload.json")).unwrap())
            .unwrap();
    let (b, inertia) = payload.in_body(&nominal).unwrap();
    let moved = written.bodies[b].inertia;
    let expected = nominal.bodies[b].inertia.add(&inertia);
    assert!(
        (moved.mass - expected.mass).abs() < 1e-12,
        "{moved:?} vs {expected:?}"
    );
    assert!((moved.com - expected.com).norm() < 1e-12);
    assert!((moved.inertia_com - expected.inertia_com).norm() < 1e-12);
    assert_eq!(written.frame("drill").unwrap().body, Some(b));
    // perturbid urdf with that payload.json writes the same robot
    let again = d.join("again.urdf");
    let out = ok(&[
        "urdf",
        "a465",
        "--payload",
        s(&out_dir.join("payload.json")),
        "--payload-link",
        "drill",
        "--out",
        s(&again),
    ]);
    assert!(out.contains("link 'drill': the payload"), "{out}");
    let strip = |t: String| {
        t.lines()
            .filter(|l| !l.contains("<!-- Written by"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(
        strip(std::fs::read_to_string(&again).unwrap()),
        strip(std::fs::read_to_string(out_dir.join("robot_with_payload.urdf")).unwrap())
    );
    // and a built-in robot's own file, with nothing attached
    let own = d.join("physical.urdf");
    ok(&["urdf", "a465:physical", "--out", s(&own)]);
    assert_eq!(
        strip(std::fs::read_to_string(&own).unwrap()) + "\n",
        robots::a465::urdf("physical").unwrap()
    );
    fails(
        &[
            "urdf",
            "a465",
            "--payload",
            r#"{"link": "link9", "mass": 1}"#,
            "--out",
            s(&d.join("bad.urdf")),
        ],
        &["'link9' is not a link of"],
    );
    assert!(!d.join("bad.urdf").exists());
    // a link name the robot has: refused before anything is written
    fails(
        &[
            "identify-payload",
            "a465",
            s(&log),
            "--link",
            "link6",
            "--urdf",
            "--payload-link",
            "link2",
            "--out",
            s(&d.join("q")),
        ],
        &["payload link 'link2'", "a link of the robot has this name"],
    );
    nothing_written(&d, "q");
}
