//! `perturbid identify-payload` end to end: a payload comes back from a simulated log of the
//! A465 carrying it, against a model identified from a log without it and against the URDF;
//! the payload.json it writes is the document true robots and `identify-gains --payload`
//! read; a log without a payload writes none and says why; bad arguments are refused by name
//! with nothing written.

mod cli_support;

use cli_support::{
    a465_log_carrying as log, fails, nothing_written, ok, s, tmp, warnings_of, write,
};
use perturbid_rs::rehearsal::Payload;

use cli_support::TRUE_PAYLOAD;

fn payload_in(dir: &std::path::Path) -> Payload {
    let text = std::fs::read_to_string(dir.join("payload.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn a_payload_comes_back_against_a_model_of_the_robot_alone_and_against_the_urdf() {
    let d = tmp("payload");
    let alone = log(&d, "alone.csv", None, 2);
    let loaded = log(&d, "loaded.csv", Some(TRUE_PAYLOAD), 3);
    let model = d.join("base.json");
    ok(&["identify-direct", "a465", s(&alone), "--out", s(&model)]);
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&loaded),
        "--link",
        "link6",
        "--model",
        s(&model),
        "--out",
        s(&d.join("p1")),
    ]);
    assert!(
        out.contains("payload on 'link6' from")
            && out.contains("against the model of the robot alone"),
        "{out}"
    );
    assert!(out.contains("joint1.offset"), "{out}");
    // the robot carrying it, on the last 30 % of the log: errors at the noise's level
    let at = out
        .find("validation of the robot carrying the payload on the last")
        .expect(&out);
    for line in out[at..].lines().skip(1).take(6) {
        let rms: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
        assert!(rms < 0.2, "{line}\n{out}");
    }
    let p = payload_in(&d.join("p1"));
    let truth: Payload = serde_json::from_str(TRUE_PAYLOAD).unwrap();
    assert!((p.mass - truth.mass).abs() < 0.01, "{p:?}");
    for i in 0..3 {
        assert!((p.com[i] - truth.com[i]).abs() < 2e-3, "{p:?}");
    }
    assert!(p.problem("payload").is_none());
    // the fit's document: every estimate with its standard error and the reference's share
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("p1/payload_fit.json")).unwrap())
            .unwrap();
    assert_eq!(fit["reference"], "base_model");
    let share = fit["stderr_of_reference"][0].as_f64().unwrap();
    assert!(
        share > 0.0 && share <= fit["stderr"][0].as_f64().unwrap(),
        "{fit}"
    );
    // what identify-gains reads as a known payload
    let as_given = std::fs::read_to_string(d.join("p1/payload.json")).unwrap();
    let inline: Payload = serde_json::from_str(&as_given).unwrap();
    assert_eq!(inline, p);

    // against the URDF (the simulation's own robot), consistent: friction fitted beside it
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&loaded),
        "--link",
        "link6",
        "--consistent",
        "--out",
        s(&d.join("p2")),
    ]);
    assert!(
        out.contains("against the URDF's parameters, consistent"),
        "{out}"
    );
    assert!(
        out.contains("joint2.viscous") && out.contains("joint2.coulomb"),
        "{out}"
    );
    let q = payload_in(&d.join("p2"));
    assert!((q.mass - truth.mass).abs() < 0.01, "{q:?}");
    // as a point mass
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&loaded),
        "--link",
        "link6",
        "--model",
        s(&model),
        "--inertia",
        "point_mass",
        "--out",
        s(&d.join("p3")),
    ]);
    assert!(
        out.contains("inertia about the centre of mass: 0 (a point mass)"),
        "{out}"
    );
    assert!(!out.contains("ixx"), "{out}");
    let r = payload_in(&d.join("p3"));
    assert!(
        (r.mass - truth.mass).abs() < 0.01 && r.inertia == [0.0; 6],
        "{r:?}"
    );

    // a log without the payload: none is seen, none written, and said so
    let none = d.join("none");
    let warned = warnings_of(&[
        "identify-payload",
        "a465",
        s(&alone),
        "--link",
        "link6",
        "--model",
        s(&model),
        "--out",
        s(&none),
    ]);
    assert!(warned.contains("no payload on 'link6' is seen"), "{warned}");
    assert!(!none.join("payload.json").exists() && none.join("payload_fit.json").exists());
    // and a fresh fit into a folder that held a payload removes it
    let warned = warnings_of(&[
        "identify-payload",
        "a465",
        s(&alone),
        "--link",
        "link6",
        "--model",
        s(&model),
        "--out",
        s(&d.join("p1")),
    ]);
    assert!(warned.contains("no payload"), "{warned}");
    assert!(!d.join("p1/payload.json").exists());
}

#[test]
fn bad_arguments_are_refused_by_name_with_nothing_written() {
    let d = tmp("payload-bad");
    let loaded = log(&d, "loaded.csv", Some(TRUE_PAYLOAD), 3);
    let out = d.join("out");
    let run = |extra: &[&str], needles: &[&str]| {
        let mut args = vec!["identify-payload", "a465", s(&loaded), "--out", s(&out)];
        args.extend_from_slice(extra);
        fails(&args, needles);
        nothing_written(&d, "out");
    };
    run(
        &["--link", "base_link"],
        &["'base_link' is fixed to the base", "link6"],
    );
    run(
        &["--link", "link6", "--signal"],
        &["--signal", "needs --model"],
    );
    run(&["--link", "link6", "--terms", "sticky"], &["sticky"]);
    run(
        &["--link", "link6", "--inertia", "sphere"],
        &["sphere", "point_mass"],
    );
    run(
        &["--link", "link6", "--validate", "1"],
        &["--validate", "[0, 1)"],
    );
    // a model that is not a base-parameter model
    let local = d.join("local.json");
    std::fs::copy(d.join("loaded.csv.true.json"), &local).unwrap();
    run(&["--link", "link6", "--model", s(&local)], &[s(&local)]);
    // a model without drive gains for --signal
    let alone = log(&d, "alone.csv", None, 2);
    let model = d.join("base.json");
    ok(&["identify-direct", "a465", s(&alone), "--out", s(&model)]);
    run(
        &["--link", "link6", "--model", s(&model), "--signal"],
        &["holds no drive gains"],
    );
}

#[test]
fn several_logs_are_fitted_together_and_each_is_checked_alone() {
    let d = tmp("payload-several");
    let a = log(&d, "a.csv", Some(TRUE_PAYLOAD), 3);
    let b = log(&d, "b.csv", Some(TRUE_PAYLOAD), 4);
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&a),
        s(&b),
        "--link",
        "link6",
        "--out",
        s(&d.join("p")),
    ]);
    assert!(out.contains("of each log"), "{out}");
    let p = payload_in(&d.join("p"));
    assert!((p.mass - 1.5).abs() < 0.01, "{p:?}");
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("p/payload_fit.json")).unwrap())
            .unwrap();
    assert_eq!(fit["logs"][1], s(&b));
    assert_eq!(fit["run_checks"].as_array().unwrap().len(), 2);
    // the second log's torques read 0.2 N m high (its sensors zeroed anew): an offset each,
    // against a model of the robot alone, validated each with its own
    let text = std::fs::read_to_string(&b).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let taus: Vec<usize> = (header.split(',').enumerate())
        .filter(|(_, c)| c.trim().starts_with("tau"))
        .map(|(i, _)| i)
        .collect();
    let mut shifted = vec![header.to_string()];
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
        for &c in &taus {
            let v: f64 = cells[c].trim().parse().unwrap();
            cells[c] = format!("{}", v + 0.2);
        }
        shifted.push(cells.join(","));
    }
    let zeroed = d.join("zeroed.csv");
    write(&zeroed, &(shifted.join("\n") + "\n"));
    let alone = log(&d, "alone.csv", None, 2);
    let model = d.join("base.json");
    ok(&["identify-direct", "a465", s(&alone), "--out", s(&model)]);
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&a),
        s(&zeroed),
        "--link",
        "link6",
        "--model",
        s(&model),
        "--offset-per-log",
        "--out",
        s(&d.join("z")),
    ]);
    let at = out
        .find("each log's torque offset less the logs' mean")
        .expect(&out);
    let row = out[at..].lines().nth(2).unwrap();
    assert!(row.starts_with(&format!("  {}: 0.1", s(&zeroed))), "{out}");
    let p = payload_in(&d.join("z"));
    assert!((p.mass - 1.5).abs() < 0.01, "{p:?}");
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("z/payload_fit.json")).unwrap())
            .unwrap();
    assert!(
        fit["log_offsets"]["deviations"][0][1].as_f64().unwrap() > 0.09,
        "{fit}"
    );
    fails(
        &[
            "identify-payload",
            "a465",
            s(&a),
            "--link",
            "link6",
            "--offset-per-log",
            "--out",
            s(&d.join("y")),
        ],
        &["--offset-per-log", "2 to 50 logs"],
    );
    // the second log's shoulder torque in mN m: named by its log, and no payload written
    let text = std::fs::read_to_string(&b).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let col = header.split(',').position(|c| c.trim() == "tau2").unwrap();
    let mut scaled = vec![header.to_string()];
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
        let v: f64 = cells[col].trim().parse().unwrap();
        cells[col] = format!("{}", v * 1000.0);
        scaled.push(cells.join(","));
    }
    let units = d.join("units.csv");
    write(&units, &(scaled.join("\n") + "\n"));
    let warned = warnings_of(&[
        "identify-payload",
        "a465",
        s(&a),
        s(&units),
        "--link",
        "link6",
        "--out",
        s(&d.join("q")),
    ]);
    assert!(
        warned.contains(&format!(
            "log '{}': the torque of joint 'joint2' reads",
            s(&units)
        )),
        "{warned}"
    );
    assert!(!warned.contains(&format!("log '{}'", s(&a))), "{warned}");
    assert!(!d.join("q/payload.json").exists());
}
