//! `identify-direct` over several logs checks each log alone against the robot's model (its
//! torque columns, its torques' lag, its positions against the limits) and names the log
//! whose data are wrong: checked over the stacked samples only, one wrong log among right
//! ones hides (docs/method.md, "Several logs").

mod cli_support;

use cli_support::{excitation_log, s, tmp, warnings_of};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use std::path::{Path, PathBuf};

/// A copy of `log` named `name` in `dir` with its data rows (values as text, the header's
/// columns) changed by `edit`, which may also change the header.
fn edited(
    log: &Path,
    dir: &Path,
    name: &str,
    edit: impl Fn(&mut Vec<String>, &mut Vec<Vec<String>>),
) -> PathBuf {
    let text = std::fs::read_to_string(log).unwrap();
    let mut lines = text.lines();
    let mut header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    edit(&mut header, &mut rows);
    let body: Vec<String> = rows.iter().map(|r| r.join(",")).collect();
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!("{}\n{}\n", header.join(","), body.join("\n")),
    )
    .unwrap();
    path
}

/// `identify-direct` of the two logs: its warnings and the model it wrote.
fn fit(dir: &Path, a: &Path, b: &Path) -> (String, BaseModel) {
    let out = dir.join("m.json");
    let warned = warnings_of(&[
        "identify-direct",
        "a465",
        s(a),
        s(b),
        "--out",
        s(&out),
        "--validate",
        "0",
    ]);
    (warned, BaseModel::load(&out).unwrap())
}

/// The warnings that name `log` as a log checked alone.
fn named(warned: &str, log: &Path) -> Vec<String> {
    let tag = format!("log '{}': ", s(log));
    warned
        .lines()
        .filter(|l| l.contains(&tag))
        .map(String::from)
        .collect()
}

#[test]
fn each_log_is_checked_against_the_model_alone() {
    let d = tmp("run-checks");
    let logs = [7, 8].map(|seed| excitation_log(&d, seed));
    // two right logs: each one's checks kept, nothing named, no lag read across the join
    let (warned, model) = fit(&d, &logs[0], &logs[1]);
    assert!(
        named(&warned, &logs[0]).is_empty() && named(&warned, &logs[1]).is_empty(),
        "{warned}"
    );
    assert_eq!(model.run_checks.len(), 2);
    assert!(model.torque_lag.is_none());
    let samples: usize = model.run_checks.iter().map(|c| c.samples).sum();
    assert_eq!(samples, model.samples);
    for c in &model.run_checks {
        assert_eq!(c.torque_lag.as_ref().map(|l| l.samples), Some(0), "{c:?}");
        assert_eq!(c.torque_columns.len(), 6);
        assert!(c.position_range.is_empty() && !c.columns_wrong(), "{c:?}");
    }

    // the shoulder's torque of the second log in mN m: named, at its scale; the whole data's
    // check alone finds nothing wrong with the column (read over both logs, its gain is below
    // what the check judges)
    let units = edited(&logs[1], &d, "units.csv", |_, rows| {
        for r in rows.iter_mut() {
            r[8] = format!("{}", r[8].parse::<f64>().unwrap() * 1000.0);
        }
    });
    let (warned, model) = fit(&d, &logs[0], &units);
    let found = named(&warned, &units);
    assert!(
        found.len() == 1
            && found[0].contains("the torque of joint 'joint2' reads ")
            && found[0].contains("times the robot's model torque"),
        "{warned}"
    );
    assert!(named(&warned, &logs[0]).is_empty(), "{warned}");
    assert!(model.torque_columns[1]
        .finding(&model.torque_columns)
        .is_none());
    assert!(model.run_checks[1].columns_wrong() && !model.run_checks[0].columns_wrong());
    let scale = model.run_checks[1].torque_columns[1].scale;
    assert!((scale / 1000.0 - 1.0).abs() < 0.01, "{scale}");

    // the first two torque columns of the second log swapped (by its header)
    let swapped = edited(&logs[1], &d, "swapped.csv", |header, _| header.swap(7, 8));
    let (warned, _) = fit(&d, &logs[0], &swapped);
    let found = named(&warned, &swapped);
    assert!(
        found
            .iter()
            .any(|w| w.contains("follows the model of joint") && w.contains("swapped")),
        "{warned}"
    );
    assert!(named(&warned, &logs[0]).is_empty(), "{warned}");

    // the second log's torques logged 0.1 s (20 rows at 200 Hz) after their positions: its
    // lag is named, in the preprocessed log's samples (100 Hz)
    let late = edited(&logs[1], &d, "late.csv", |_, rows| {
        let torques: Vec<Vec<String>> = rows.iter().map(|r| r[7..].to_vec()).collect();
        for (i, r) in rows.iter_mut().enumerate().skip(20) {
            r.splice(7.., torques[i - 20].iter().cloned());
        }
        rows.drain(..20);
    });
    let (warned, model) = fit(&d, &logs[0], &late);
    let found = named(&warned, &late);
    assert!(
        found
            .iter()
            .any(|w| w.contains("better shifted by 10 sample(s)")
                && w.contains("logged 10 sample(s) after")),
        "{warned}"
    );
    assert_eq!(
        model.run_checks[0].torque_lag.as_ref().map(|l| l.samples),
        Some(0)
    );

    // the second log's shoulder 5 rad past its limits for a stretch
    let beyond = edited(&logs[1], &d, "beyond.csv", |_, rows| {
        for r in rows[1000..1100].iter_mut() {
            r[2] = format!("{}", r[2].parse::<f64>().unwrap() + 5.0);
        }
    });
    let (warned, model) = fit(&d, &logs[0], &beyond);
    let found = named(&warned, &beyond);
    assert!(
        found.len() == 1 && found[0].contains("leave the URDF's joint limits: 'joint2'"),
        "{warned}"
    );
    assert!(model.run_checks[0].position_range.is_empty());
    assert_eq!(model.run_checks[1].position_range.len(), 1);
    // named once, by the log, not again over the whole data
    assert_eq!(
        warned.matches("leave the URDF's joint limits").count(),
        1,
        "{warned}"
    );
}

#[test]
fn a_models_run_checks_are_checked_on_load() {
    let d = tmp("run-checks-load");
    let logs = [9, 10].map(|seed| excitation_log(&d, seed));
    let (_, model) = fit(&d, &logs[0], &logs[1]);
    let text = model.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), model);
    let refused = |edit: &dyn Fn(&mut serde_json::Value), needle: &str| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        edit(&mut v);
        let e = BaseModel::from_json(&v.to_string())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e}");
    };
    refused(
        &|v| v["run_checks"][0]["samples"] = 5.into(),
        "run_checks: runs of",
    );
    refused(
        &|v| v["run_checks"][1]["samples"] = 0.into(),
        "run_checks[1]: a run of 0 samples",
    );
    refused(
        &|v| v["run_checks"].as_array_mut().unwrap().truncate(1),
        "1 runs' checks, expected none or one a run (2 to 1000; the model has 2 logs)",
    );
    refused(
        &|v| v["run_checks"][1]["torque_columns"][2]["joint"] = "elsewhere".into(),
        "run_checks[1].torque_columns[2]: joint 'elsewhere' is not one of the model's joints",
    );
    refused(
        &|v| v["run_checks"][0]["torque_lag"]["samples"] = 9999.into(),
        "run_checks[0].torque_lag: samples is 9999, beyond the 500 searched",
    );
    refused(
        &|v| {
            v["run_checks"][0]["torque_columns"]
                .as_array_mut()
                .unwrap()
                .truncate(2)
        },
        "run_checks[0].torque_columns: 2 entries, expected one per joint (6) or none",
    );
    refused(
        &|v| v["run_checks"][0]["extra"] = 1.into(),
        "unknown field `extra`",
    );
}

/// A log with a payload of 0.5 kg at the flange beside one without: the logs do not agree
/// with one robot, and the warning says so, naming joints and a log; two logs of one robot
/// agree (ratios near 1, no warning).
#[test]
fn logs_of_another_payload_do_not_agree_with_one_robot() {
    let d = tmp("log-agreement");
    let logs = [11, 12].map(|seed| excitation_log(&d, seed));
    let (warned, model) = fit(&d, &logs[0], &logs[1]);
    let agreement = model.log_agreement.as_ref().expect("checked");
    assert!(!warned.contains("do not agree"), "{warned}");
    for r in &agreement.ratio {
        assert!(
            r.is_some_and(|r| (0.95..1.2).contains(&r)),
            "{:?}",
            agreement.ratio
        );
    }
    // the second excitation again, on a robot carrying a payload
    let robot = d.join("payload.json");
    std::fs::write(
        &robot,
        r#"{"format": "perturbid-true-robot/1", "seed": 3,
            "payload": {"link": "link6", "mass": 0.5, "com": [0.0, 0.0, 0.06], "inertia": [0.001, 0, 0, 0.001, 0, 0.0005]},
            "sensors": {"torque_noise": [0.01, 0.01, 0.01, 0.01, 0.01, 0.01]}}"#,
    )
    .unwrap();
    let loaded = d.join("loaded.csv");
    cli_support::ok(&[
        "simulate",
        "a465",
        s(&d.join("exc12").join("excitation.json")),
        "--true-robot",
        s(&robot),
        "--out",
        s(&loaded),
        "--rate",
        "200",
    ]);
    let (warned, model) = fit(&d, &logs[0], &loaded);
    assert!(
        warned.contains("the logs do not agree with one robot") && warned.contains("'joint2' "),
        "{warned}"
    );
    let agreement = model.log_agreement.as_ref().unwrap();
    assert!(
        agreement.ratio[1].is_some_and(|r| r > 5.0),
        "{:?}",
        agreement.ratio
    );
    // kept and checked on load
    let mut v: serde_json::Value = serde_json::from_str(&model.to_json()).unwrap();
    v["log_agreement"]["ratio"][0] = (-1.0).into();
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("log_agreement: -1, expected a magnitude"), "{e}");
    v["log_agreement"]["fitted_rms"] = serde_json::json!([[0.1]]);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("log_agreement: expected a ratio a joint"), "{e}");
}
