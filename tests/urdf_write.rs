//! Writing a robot back as URDF (`urdf::write_urdf`): an unchanged robot is its own file, new
//! parameters read back as the model has them, the links moving with a body keep their own
//! inertials where the body allows it, a payload becomes a link of its own, and what a URDF
//! written this way could not hold is refused.

mod common;

use common::Rng;
use nalgebra::{Matrix3, Vector3};
use perturbid_rs::rehearsal::Payload;
use perturbid_rs::spatial::Inertia;
use perturbid_rs::urdf::{write_urdf, WriteOptions};
use perturbid_rs::{model_from_urdf_str, robots, Data, Gravity, LoadOptions, Model};

/// The written text less the comment it opens with.
fn without_header(text: &str) -> String {
    let start = text
        .find("<!-- Written by perturbid_rs")
        .expect("the header");
    let end = start + text[start..].find("-->\n").expect("its end") + 4;
    format!("{}{}", &text[..start], &text[end..])
}

/// The torques of two models at the same random states agree to `tol` of their size.
fn same_torques(a: &Model, b: &Model, tol: f64) {
    let mut rng = Rng(7);
    let (mut da, mut db) = (Data::new(a), Data::new(b));
    for _ in 0..20 {
        let q = rng.vector(a.nv, 1.0);
        let v = rng.vector(a.nv, 2.0);
        let w = rng.vector(a.nv, 3.0);
        perturbid_rs::rnea(a, &mut da, &q, &v, &w, Gravity::Included).unwrap();
        perturbid_rs::rnea(b, &mut db, &q, &v, &w, Gravity::Included).unwrap();
        let (ta, tb) = (da.tau.clone(), db.tau.clone());
        let scale = ta.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (x, y) in ta.iter().zip(&tb) {
            assert!((x - y).abs() <= tol * scale, "{ta:?} vs {tb:?}");
        }
    }
}

/// Another rigid body near `i`: heavier, its centre moved, its inertia turned and grown.
fn changed(i: &Inertia, rng: &mut Rng) -> Inertia {
    let r = nalgebra::Rotation3::from_euler_angles(rng.uniform(-0.3, 0.3), 0.2, -0.1).into_inner();
    Inertia::new(
        i.mass * rng.uniform(1.1, 1.4),
        i.com + Vector3::new(0.01, -0.02, 0.015),
        r * i.inertia_com * r.transpose() * 1.2 + Matrix3::identity() * 1e-4,
    )
}

fn reread(model: &Model, text: &str) -> Model {
    model_from_urdf_str(text, "written", &model_options(model)).unwrap()
}

fn model_options(model: &Model) -> LoadOptions {
    let mut o = LoadOptions::default();
    if model.name.contains("panda") {
        o.lock.insert("panda_finger_joint1".into(), 0.0);
    }
    o.check_triangle_inequality = !model.source.contains("lumped");
    o
}

#[test]
fn an_unchanged_robot_is_written_as_its_own_file() {
    for variant in ["physical", "kinsheel2010", "kinsheel2010_lumped"] {
        let model = robots::a465::model(variant).unwrap();
        let written = write_urdf(&model, &WriteOptions::default()).unwrap();
        assert_eq!(
            without_header(&written.text),
            robots::a465::urdf(variant).unwrap()
        );
        assert!(
            written.notes.is_empty() && written.warnings.is_empty(),
            "{written:?}"
        );
    }
    let Some(path) = common::panda_urdf() else {
        eprintln!("skipped the Panda: example-robot-data's panda.urdf is not installed");
        return;
    };
    let model = common::panda_model().unwrap();
    let written = write_urdf(&model, &WriteOptions::default()).unwrap();
    assert_eq!(
        without_header(&written.text),
        std::fs::read_to_string(path).unwrap()
    );
}

#[test]
fn new_inertias_friction_and_armature_read_back_as_the_model_has_them() {
    let mut rng = Rng(3);
    let mut model = robots::a465::model("kinsheel2010").unwrap();
    for b in &mut model.bodies {
        b.inertia = changed(&b.inertia, &mut rng);
    }
    model.refresh();
    for j in 0..model.nv {
        model.limits[j].damping = 0.5 + j as f64;
        model.limits[j].friction = 0.25 * j as f64;
        model.armature[j] *= 0.9;
    }
    let written = write_urdf(&model, &WriteOptions::default()).unwrap();
    println!("{}", written.text);
    let back = reread(&model, &written.text);
    same_torques(&model, &back, 1e-12);
    for j in 0..model.nv {
        assert_eq!(back.limits[j].damping, model.limits[j].damping);
        assert_eq!(back.limits[j].friction, model.limits[j].friction);
        assert_eq!(back.armature[j], model.armature[j]);
    }
    assert_eq!(written.notes.len(), 12, "{:?}", written.notes);
    // joints' limits and origins as the file has them
    let source = robots::a465::urdf("kinsheel2010").unwrap();
    for needle in ["<limit ", "<origin xyz=\"0 0 0.33\"", "<axis "] {
        assert_eq!(
            written.text.matches(needle).count(),
            source.matches(needle).count(),
            "{needle}"
        );
    }
}

#[test]
fn links_without_an_inertial_and_one_line_links_get_one() {
    let mut rng = Rng(11);
    for seed in 0..6 {
        let text = common::random_tree_urdf(seed, 7).replace(
            "<link name=\"l3\"><inertial>",
            "<link name=\"l3\"   ><inertial>",
        );
        let mut model = model_from_urdf_str(&text, "tree", &LoadOptions::default()).unwrap();
        for b in &mut model.bodies {
            b.inertia = changed(&b.inertia, &mut rng);
        }
        model.refresh();
        let written = write_urdf(&model, &WriteOptions::default()).unwrap();
        let back = model_from_urdf_str(&written.text, "tree", &LoadOptions::default()).unwrap();
        same_torques(&model, &back, 1e-11);
    }
    // a tree of 400 links, some behind fixed joints: written and read back alike
    let text = common::random_tree_urdf(42, 400);
    let mut model = model_from_urdf_str(&text, "tree", &LoadOptions::default()).unwrap();
    for b in &mut model.bodies {
        b.inertia = changed(&b.inertia, &mut rng);
    }
    model.refresh();
    let started = std::time::Instant::now();
    let written = write_urdf(&model, &WriteOptions::default()).unwrap();
    println!(
        "{} bodies written in {:?}",
        model.nbodies(),
        started.elapsed()
    );
    let back = model_from_urdf_str(&written.text, "tree", &LoadOptions::default()).unwrap();
    same_torques(&model, &back, 1e-10);
    // a massless link of its own (its mass on a fixed child) and one written <link/>
    let text = r#"<robot name="two">
  <link name="base"/>
  <link name="arm"/>
  <link name="tip"><inertial><mass value="1"/><origin xyz="0.5 0 0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="f" type="fixed"><parent link="arm"/><child link="tip"/></joint>
</robot>
"#;
    let mut model = model_from_urdf_str(text, "two", &LoadOptions::default()).unwrap();
    let tip = model.bodies[0].inertia;
    model.bodies[0].inertia = tip.add(&Inertia::new(
        0.5,
        Vector3::new(0.1, 0.0, 0.0),
        Matrix3::identity() * 1e-3,
    ));
    model.refresh();
    let written = write_urdf(&model, &WriteOptions::default()).unwrap();
    assert!(
        written.text.contains("<link name=\"arm\">\n    <inertial>"),
        "{}",
        written.text
    );
    let back = model_from_urdf_str(&written.text, "two", &LoadOptions::default()).unwrap();
    same_torques(&model, &back, 1e-12);
    // the tip keeps its own inertial: the arm's is the rest, 0.5 kg at 0.1 m
    assert!(
        written.text.contains("<mass value=\"0.5\"/>"),
        "{}",
        written.text
    );
    assert!(
        written.text.contains("<mass value=\"1\"/>"),
        "{}",
        written.text
    );

    // lighter than the tip: the tip's inertial moves into the arm, said in a note
    model.bodies[0].inertia = Inertia::new(
        0.8,
        Vector3::new(0.45, 0.0, 0.0),
        Matrix3::identity() * 0.02,
    );
    model.refresh();
    let written = write_urdf(&model, &WriteOptions::default()).unwrap();
    assert!(
        written
            .warnings
            .iter()
            .any(|n| n.contains("'tip': its <inertial> (1 kg) moved into link 'arm'")),
        "{:?}",
        written.warnings
    );
    let back = model_from_urdf_str(&written.text, "two", &LoadOptions::default()).unwrap();
    same_torques(&model, &back, 1e-12);
    assert!(
        !written.text.contains("<mass value=\"1\"/>"),
        "{}",
        written.text
    );
}

#[test]
fn the_panda_hand_and_fingers_keep_theirs_where_the_body_allows_it() {
    let Some(model) = common::panda_model() else {
        eprintln!("skipped: example-robot-data's panda.urdf is not installed");
        return;
    };
    let last = model.bodies.len() - 1;
    assert_eq!(model.bodies[last].link, "panda_link7");
    // heavier: the hand and fingers keep theirs, link 7 takes the rest
    let mut heavier = model.clone();
    heavier.bodies[last].inertia = changed(&model.bodies[last].inertia, &mut Rng(1));
    heavier.refresh();
    let written = write_urdf(&heavier, &WriteOptions::default()).unwrap();
    assert_eq!(written.notes.len(), 1, "{:?}", written.notes);
    same_torques(&heavier, &reread(&heavier, &written.text), 1e-11);
    // the fingers unlocked still move mass, and visuals are kept
    let unlocked = model_from_urdf_str(&written.text, "w", &LoadOptions::default()).unwrap();
    assert_eq!(unlocked.nv, 8);
    let source = std::fs::read_to_string(common::panda_urdf().unwrap()).unwrap();
    assert_eq!(
        written.text.matches("<visual").count(),
        source.matches("<visual").count()
    );

    // lighter than link 7's own share: the hand (fixed) gives its inertial up, the fingers
    // (locked) keep theirs
    let mut lighter = model.clone();
    let i = model.bodies[last].inertia;
    lighter.bodies[last].inertia = Inertia::new(0.6, i.com, i.inertia_com);
    lighter.refresh();
    match write_urdf(&lighter, &WriteOptions::default()) {
        Ok(written) => {
            assert!(
                written
                    .warnings
                    .iter()
                    .any(|n| n.contains("'panda_hand': its <inertial>")),
                "{:?}",
                written.warnings
            );
            same_torques(&lighter, &reread(&lighter, &written.text), 1e-11);
        }
        Err(e) => panic!("{e}"),
    }
    // lighter than the fingers: every link's inertial moves into link 7, and the fingers'
    // joints are said to move no mass in this file
    let mut lightest = model.clone();
    lightest.bodies[last].inertia = Inertia::new(0.01, i.com, i.inertia_com * 0.01);
    lightest.refresh();
    let written = write_urdf(&lightest, &WriteOptions::default()).unwrap();
    assert_eq!(written.warnings.len(), 3, "{:?}", written.warnings);
    assert!(
        written.warnings[1].contains("'panda_leftfinger'")
            && written.warnings[1].contains("carries no mass"),
        "{:?}",
        written.warnings
    );
    same_torques(&lightest, &reread(&lightest, &written.text), 1e-11);
    let e = model_from_urdf_str(&written.text, "w", &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("panda_finger_joint1"), "{e}");
    // a body that is no rigid body itself: nothing is written
    let mut broken = model.clone();
    broken.bodies[last].inertia = Inertia::new(1.5, i.com, -i.inertia_com);
    broken.refresh();
    let e = write_urdf(&broken, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("link 'panda_link7'")
            && e.contains("panda_leftfinger")
            && e.contains("no rigid body"),
        "{e}"
    );
}

#[test]
fn a_payload_is_a_link_of_its_own() {
    let model = robots::a465::model("physical").unwrap();
    let payload = Payload {
        link: "link6".into(),
        mass: 1.5,
        com: [0.01, -0.02, 0.08],
        inertia: [0.004, 0.0001, 0.0, 0.005, -0.0002, 0.003],
    };
    let options = WriteOptions {
        payload: Some(&payload),
        payload_link: "drill",
        note: "payload from a test -- of comments",
    };
    let written = write_urdf(&model, &options).unwrap();
    assert!(written
        .text
        .contains("<joint name=\"drill_joint\" type=\"fixed\">"));
    assert!(written.text.contains("from a test - - of comments"));
    let back = reread(&model, &written.text);
    assert_eq!(
        back.frame("drill").unwrap().body,
        Some(model.bodies.len() - 1)
    );
    // the payload as a true robot carries it
    let mut carrying = model.clone();
    let (b, inertia) = payload.in_body(&model).unwrap();
    carrying.bodies[b].inertia = carrying.bodies[b].inertia.add(&inertia);
    carrying.refresh();
    same_torques(&carrying, &back, 1e-12);
    // on a link taken already, or no rigid body
    for (name, p, expected) in [
        (
            "link3",
            payload.clone(),
            "a link of the robot has this name",
        ),
        ("", payload.clone(), "non-empty"),
        (
            "tool",
            Payload {
                mass: 0.0,
                ..payload.clone()
            },
            "nothing to attach",
        ),
        (
            "tool",
            Payload {
                link: "base_link".into(),
                ..payload.clone()
            },
            "fixed to the base",
        ),
        (
            "tool",
            Payload {
                inertia: [0.001, 0.0, 0.0, 0.001, 0.0, 0.01],
                ..payload.clone()
            },
            "triangle",
        ),
    ] {
        let options = WriteOptions {
            payload: Some(&p),
            payload_link: name,
            note: "",
        };
        let e = write_urdf(&model, &options).unwrap_err().to_string();
        assert!(e.contains(expected), "{name}: {e}");
    }
}

#[test]
fn what_a_urdf_written_here_could_not_hold_is_refused() {
    let model = robots::a465::model("physical").unwrap();
    let mut moved = model.clone();
    moved.bodies[2].placement.translation.x += 0.01;
    moved.refresh();
    let e = write_urdf(&moved, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint 'joint3'") && e.contains("placement"),
        "{e}"
    );
    let mut limited = model.clone();
    limited.limits[1].velocity = 0.1;
    let e = write_urdf(&limited, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("velocity limit"), "{e}");
    let mut pushing = model.clone();
    pushing.limits[0].damping = -1.0;
    let e = write_urdf(&pushing, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("damping -1 is not a finite number >= 0"), "{e}");
    // notes and names past their bounds
    let long = "x".repeat(65_537);
    let options = WriteOptions {
        note: &long,
        ..WriteOptions::default()
    };
    let e = write_urdf(&model, &options).unwrap_err().to_string();
    assert!(
        e.contains("note") && e.contains("65537 characters, expected at most 65536"),
        "{e}"
    );
    let options = WriteOptions {
        payload_link: &long[..4097],
        ..WriteOptions::default()
    };
    let e = write_urdf(&model, &options).unwrap_err().to_string();
    assert!(
        e.contains("payload_link") && e.contains("4097 characters"),
        "{e}"
    );
    // an armature given by a transmission is not rewritten
    let text = robots::a465::urdf("physical").unwrap().replace(
        "</robot>",
        "<transmission name=\"t\"><joint name=\"joint2\"/><actuator name=\"m\"><rotor_inertia value=\"0.5\"/></actuator></transmission></robot>",
    );
    let mut geared = model_from_urdf_str(&text, "geared", &LoadOptions::default()).unwrap();
    assert_eq!(geared.armature[1], 0.5);
    geared.limits[1].damping = 0.2; // friction is written beside it
    let written = write_urdf(&geared, &WriteOptions::default()).unwrap();
    assert_eq!(
        model_from_urdf_str(&written.text, "w", &LoadOptions::default())
            .unwrap()
            .armature[1],
        0.5
    );
    geared.armature[1] = 0.6;
    let e = write_urdf(&geared, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint 'joint2'") && e.contains("<transmission>"),
        "{e}"
    );
    // a gravity a URDF cannot hold is warned of
    let mut tilted = model.clone();
    tilted.gravity = Vector3::new(0.0, -9.81, 0.0);
    let written = write_urdf(&tilted, &WriteOptions::default()).unwrap();
    assert!(
        written
            .warnings
            .iter()
            .any(|w| w.contains("gravity (0, -9.81, 0)")),
        "{written:?}"
    );
    tilted.gravity = Vector3::zeros();
    let written = write_urdf(&tilted, &WriteOptions::default()).unwrap();
    assert!(
        written
            .warnings
            .iter()
            .any(|w| w.contains("gravity (0, 0, 0)")),
        "{written:?}"
    );
    let plain = write_urdf(&model, &WriteOptions::default()).unwrap();
    assert!(plain.warnings.is_empty(), "{plain:?}");
    let mut broken = model.clone();
    broken.bodies[0].inertia.inertia_com = Matrix3::from_diagonal(&Vector3::new(0.01, 0.01, 1.0));
    broken.refresh();
    let e = write_urdf(&broken, &WriteOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("link 'link1'") && e.contains("triangle"), "{e}");
}

#[test]
fn files_written_in_other_hands_keep_their_form() {
    let source = robots::a465::urdf("physical").unwrap();
    let variants: Vec<(&str, String)> = vec![
        ("CRLF line ends", source.replace('\n', "\r\n")),
        ("tabs", source.replace("  ", "\t")),
        ("single quotes", source.replace('"', "'")),
        (
            "a comment and a named visual with '>' inside a link",
            source.replace(
                "<link name=\"link2\">",
                "<link name=\"link2\"><!-- <inertial> in a comment --><visual name=\"a>b\"><geometry><box size=\"1 1 1\"/></geometry></visual>",
            ),
        ),
        (
            "an inertial written on one line",
            source.replace("<link name=\"link3\">\n    <inertial>", "<link name=\"link3\"><inertial>"),
        ),
        ("no declaration", source.replace("<?xml version=\"1.0\"?>", "")),
        (
            "a <dynamics> with a namespace of its own",
            source.replace(
                "<child link=\"link4\"/>",
                "<child link=\"link4\"/><dynamics xmlns:g=\"urn:g\" g:spring='1' friction=\"0.1\"></dynamics>",
            ),
        ),
    ];
    let payload = Payload {
        link: "link6".into(),
        mass: 0.5,
        com: [0.0, 0.0, 0.05],
        inertia: [1e-3, 0.0, 0.0, 1e-3, 0.0, 1e-3],
    };
    for (what, text) in variants {
        let mut model = model_from_urdf_str(&text, "odd -- name-", &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let mut rng = Rng(5);
        for b in &mut model.bodies {
            b.inertia = changed(&b.inertia, &mut rng);
        }
        model.refresh();
        model.limits[3].damping = 0.7;
        let options = WriteOptions {
            payload: Some(&payload),
            payload_link: "tool \"<&>\" é",
            note: "a note --> that tries to close the comment",
        };
        let written = write_urdf(&model, &options).unwrap_or_else(|e| panic!("{what}: {e}"));
        let back = model_from_urdf_str(&written.text, "back", &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{what}: {e}\n{}", written.text));
        assert!(back.frame("tool \"<&>\" é").is_some(), "{what}");
        let mut carrying = model.clone();
        let (b, inertia) = payload.in_body(&model).unwrap();
        carrying.bodies[b].inertia = carrying.bodies[b].inertia.add(&inertia);
        carrying.refresh();
        same_torques(&carrying, &back, 1e-12);
        if what == "CRLF line ends" {
            assert_eq!(
                written.text.matches('\n').count(),
                written.text.matches("\r\n").count()
            );
        }
        assert!(!written.text.contains("a note -->"), "{what}");
        if what.starts_with("a <dynamics>") {
            assert!(
                written.text.contains("<dynamics xmlns:g=\"urn:g\" g:spring='1' friction=\"0.1\" damping=\"0.7\"></dynamics>"),
                "{}",
                written.text
            );
        }
        if what.starts_with("a comment") {
            assert!(written.text.contains("<visual name=\"a>b\">"), "{what}");
        }
    }
}

#[test]
fn the_real_pandas_identified_urdf_predicts_its_second_half_better_than_the_vendors() {
    let Some((model, rec)) = common::panda_preprocessed() else {
        return;
    };
    use perturbid_rs::direct::{
        identify_consistent_parameters, BaseOptions, ConsistentOptions, FrictionTerms,
    };
    use perturbid_rs::{RobotTorques, TorqueModel};
    let n = model.nv;
    let k = rec.len() / 2;
    let states = rec.states().unwrap();
    let (first, held) = (states.slice(0..k), states.slice(k..rec.len()));
    let (tau_first, tau_held) = (&rec.tau[..k * n], &rec.tau[k * n..]);
    let options = BaseOptions {
        friction: FrictionTerms {
            viscous: true,
            coulomb: true,
            ..FrictionTerms::NONE
        },
        ..BaseOptions::default()
    };
    let fit = identify_consistent_parameters(
        &model,
        &first,
        tau_first,
        &options,
        &ConsistentOptions::default(),
    )
    .unwrap();
    let written = write_urdf(&fit.robot(&model).unwrap(), &WriteOptions::default()).unwrap();
    for w in &written.warnings {
        println!("warning: {w}");
    }
    let identified = reread(&model, &written.text);
    let rms = |m: &Model| -> Vec<f64> {
        let p = RobotTorques::new(m).predict(&held).unwrap();
        let rows = held.len();
        (0..n)
            .map(|j| {
                let s: f64 = (0..rows)
                    .map(|i| (p[i * n + j] - tau_held[i * n + j]).powi(2))
                    .sum();
                (s / rows as f64).sqrt()
            })
            .collect()
    };
    let (vendor, ours) = (rms(&model), rms(&identified));
    println!(
        "second half, RMS a joint (N m): vendor's URDF {vendor:.3?}, identified URDF {ours:.3?}"
    );
    // the identified file, read as any tool reads it, predicts motion it was not fitted to
    assert!(
        ours.iter().sum::<f64>() < 0.5 * vendor.iter().sum::<f64>(),
        "{ours:?} vs {vendor:?}"
    );
    // and it is the consistent model's own prediction there
    let by_model = fit.model.predict(&model, &held).unwrap();
    let by_file = RobotTorques::new(&identified).predict(&held).unwrap();
    let scale = by_model.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    assert!(by_model
        .iter()
        .zip(&by_file)
        .all(|(a, b)| (a - b).abs() < 1e-8 * scale));
}
