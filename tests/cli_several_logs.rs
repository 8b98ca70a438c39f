//! `identify-direct` over several logs (runs of two excitations): each log preprocessed alone
//! and the fit over them all, equal to the library's fit of the preprocessed recordings one
//! after the other; each log's first samples fitted and its last validated on; what the
//! preprocessing found in each kept in the model's `logs`, named by the log and checked on
//! load; drive gains keep their runs' findings alike.

mod cli_support;

use cli_support::{excitation_log, fails, ok, s, tmp, warnings_of};
use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions};
use perturbid_rs::document::Document;
use perturbid_rs::logs::load_recording;
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::logs::stacked_states::StackedStates;
use std::path::Path;

#[test]
fn several_logs_are_fitted_together_each_preprocessed_alone() {
    let d = tmp("several-logs");
    let logs = [1, 2].map(|seed| excitation_log(&d, seed));
    // both logs into `out`, validated on the last `fraction` of each
    let both = |out: &Path, fraction: &str| {
        ok(&[
            "identify-direct",
            "a465",
            s(&logs[0]),
            s(&logs[1]),
            "--out",
            s(out),
            "--validate",
            fraction,
        ])
    };
    let model_path = d.join("both.json");
    let out = both(&model_path, "0");
    assert!(
        out.matches("preprocessed: ").count() == 2 && out.contains("samples of 2 logs"),
        "{out}"
    );
    let fit = BaseModel::load(&model_path).unwrap();
    // the library's fit of the two preprocessed recordings, one after the other
    let robot = perturbid_rs::robots::builtin("a465").unwrap();
    let recs: Vec<_> = (logs.iter())
        .map(|l| {
            preprocess(
                &load_recording(l, &robot.joint_names).unwrap(),
                &PreprocessOptions::default(),
            )
            .unwrap()
        })
        .collect();
    let states: Vec<_> = recs.iter().map(|r| r.states().unwrap()).collect();
    let parts: Vec<_> = states
        .iter()
        .zip(&recs)
        .map(|(s, r)| (*s, &r.tau[..]))
        .collect();
    let stacked = StackedStates::of(&parts).unwrap();
    let expected = identify_base_parameters(
        &robot,
        &stacked.states().unwrap(),
        &stacked.data,
        &BaseOptions::default(),
    )
    .unwrap();
    assert_eq!(fit.samples, recs[0].len() + recs[1].len());
    let scale = expected.theta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in fit.theta.iter().zip(&expected.theta) {
        assert!((a - b).abs() <= 1e-9 * scale, "{a} against {b}");
    }
    // each log's findings, named by it; none in the one-log fields
    assert_eq!(fit.logs.len(), 2);
    assert_eq!(fit.logs[1].log, s(&logs[1]));
    assert!(fit.log_glitches.is_empty() && fit.position_rounding.is_empty());
    // checked on load: a finding of a joint the robot lacks, findings in both places
    let text = fit.to_json();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["logs"][1]["glitches"] = serde_json::json!([{"signal": "tau", "joint": 9, "sample": 3, "time": 0.03, "value": 1.0, "noise_levels": 20.0, "replaced_by": 0.0, "repeats_previous": false, "held": null, "experiment": null}]);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("logs[1].glitches[0]"), "{e}");
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["log_glitches"] = serde_json::json!([{"signal": "tau", "joint": 0, "sample": 3, "time": 0.03, "value": 1.0, "noise_levels": 20.0, "replaced_by": 0.0, "repeats_previous": false, "held": null, "experiment": null}]);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("keeps each one's findings there, none in the log_* fields"),
        "{e}"
    );
    // validation on each log's last samples
    let out = both(&d.join("v.json"), "0.3");
    let held: usize = recs
        .iter()
        .map(|r| r.len() - ((0.7 * r.len() as f64).round() as usize))
        .sum();
    assert!(
        out.contains(&format!(
            "validation on the last {held} samples of each log"
        )),
        "{out}"
    );
    // and each log's own RMS, of its held-out samples
    assert!(out.contains("per log, per joint RMS (N m):"), "{out}");
    for log in &logs {
        let line = (out.lines())
            .find(|l| l.starts_with(&format!("  {}: ", s(log))))
            .unwrap_or_else(|| panic!("{out}"));
        let rms: Vec<f64> = (line.rsplit(": ").next().unwrap().split(' '))
            .map(|x| x.parse().unwrap())
            .collect();
        // 0.01 N m of noise, filtered
        assert!(
            rms.len() == 6 && rms.iter().all(|&r| r > 0.0 && r < 0.05),
            "{line}"
        );
    }
    // a log that fails is named
    let bad = d.join("bad.csv");
    std::fs::write(
        &bad,
        "t,q1,q2,q3,q4,q5,q6,tau1,tau2,tau3,tau4,tau5,tau6\n0,0,0,0,0,0,0,0,0,0,0,0,0\n",
    )
    .unwrap();
    fails(
        &[
            "identify-direct",
            "a465",
            s(&logs[0]),
            s(&bad),
            "--out",
            s(&d.join("x.json")),
        ],
        &["bad.csv"],
    );
    assert!(!d.join("x.json").exists());
}

/// The same samples given twice to one fit are refused, naming the logs and where they agree:
/// one path twice, the same file under another path, a copy, a part of a log given again;
/// among `identify-gains`'s runs too. Nothing is written.
#[test]
fn a_log_given_twice_is_refused() {
    let d = tmp("log-twice");
    let logs = [3, 4].map(|seed| excitation_log(&d, seed));
    let out = d.join("m.json");
    let direct = |a: &Path, b: &Path, needles: &[&str]| {
        fails(
            &[
                "identify-direct",
                "a465",
                s(&logs[1]),
                s(a),
                s(b),
                "--out",
                s(&out),
            ],
            needles,
        );
        assert!(!out.exists());
    };
    direct(
        &logs[0],
        &logs[0],
        &["log3.csv is given twice: each log once"],
    );
    let dotted = d.join(".").join("log3.csv");
    direct(
        &logs[0],
        &dotted,
        &["log3.csv is given twice (again as ", "/./log3.csv)"],
    );
    // a copy, its stamps shifted by 100 s
    let text = std::fs::read_to_string(&logs[0]).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let shifted: Vec<String> = (rows.iter())
        .map(|r| {
            let (t, rest) = r.split_once(',').unwrap();
            format!("{},{rest}", t.parse::<f64>().unwrap() + 100.0)
        })
        .collect();
    let copy = d.join("copy.csv");
    std::fs::write(&copy, format!("{header}\n{}\n", shifted.join("\n"))).unwrap();
    direct(
        &logs[0],
        &copy,
        &[
            &format!(
                "log3.csv and {} hold the same {} data rows, bit for bit",
                s(&copy),
                rows.len()
            ),
            "give each run's samples once",
        ],
    );
    // data rows 501-1500 of the log as a log of their own
    let part = d.join("part.csv");
    std::fs::write(&part, format!("{header}\n{}\n", rows[500..1500].join("\n"))).unwrap();
    direct(
        &part,
        &logs[0],
        &[&format!(
            "data rows 501 to 1500 of {} (of {}) are data rows 1 to 1000 of {} (of 1000), bit for bit",
            s(&logs[0]),
            rows.len(),
            s(&part)
        )],
    );
    // a run among the unloaded and the loaded
    fails(
        &[
            "identify-gains",
            "a465",
            s(&logs[0]),
            s(&logs[1]),
            "--loaded",
            s(&copy),
            "--payload",
            r#"{"link": "link6", "mass": 2.0, "com": [0, 0, 0.05], "inertia": [0.002, 0, 0, 0.002, 0, 0.002]}"#,
            "--out",
            s(&out),
        ],
        &["RUNS", "hold the same"],
    );
    assert!(!out.exists());
    // two different runs of one excitation pass
    ok(&[
        "identify-direct",
        "a465",
        s(&logs[0]),
        s(&logs[1]),
        "--out",
        s(&out),
        "--validate",
        "0",
    ]);
}

/// Two logs whose torque offsets differ (0.1 N m added to the second's): the joints whose
/// residuals differ in mean from log to log are warned of, naming both logs, and kept in the
/// model; the same two logs as they were are not.
#[test]
fn an_offset_that_drifted_between_logs_is_named() {
    let d = tmp("offset-drift");
    let logs = [5, 6].map(|seed| excitation_log(&d, seed));
    let text = std::fs::read_to_string(&logs[1]).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let shifted: Vec<String> = lines
        .map(|row| {
            let values: Vec<String> = (row.split(',').enumerate())
                .map(|(c, v)| match c {
                    7.. => format!("{}", v.parse::<f64>().unwrap() + 0.1),
                    _ => v.to_string(),
                })
                .collect();
            values.join(",")
        })
        .collect();
    let drifted = d.join("drifted.csv");
    std::fs::write(&drifted, format!("{header}\n{}\n", shifted.join("\n"))).unwrap();
    let out = d.join("m.json");
    let fit = |b: &Path| {
        let args = [
            "identify-direct",
            "a465",
            s(&logs[0]),
            s(b),
            "--out",
            s(&out),
            "--validate",
            "0",
        ];
        (warnings_of(&args), BaseModel::load(&out).unwrap())
    };
    let (warned, model) = fit(&drifted);
    assert!(
        warned.contains("differ in mean from log to log, from -0.")
            && warned.contains(s(&drifted))
            && warned.contains(s(&logs[0])),
        "{warned}"
    );
    assert!(!model.run_offsets.is_empty());
    for o in &model.run_offsets {
        // the second log's residuals sit above the first's
        assert!(o.means[1] > o.means[0] + 5.0 * o.stderr[0], "{o:?}");
    }
    let (warned, model) = fit(&logs[1]);
    assert!(
        model.run_offsets.is_empty() && !warned.contains("differ in mean"),
        "{warned}"
    );

    // with an offset of each log's own: the drift fitted (+-0.05 about the logs' mean, each
    // joint), not named, and each log validated with its own offset
    let both = |extra: &[&'static str]| {
        let mut args = vec![
            "identify-direct",
            "a465",
            s(&logs[0]),
            s(&drifted),
            "--out",
            s(&out),
        ];
        args.extend_from_slice(extra);
        args
    };
    let printed = ok(&both(&["--offset-per-log"]));
    let model = BaseModel::load(&out).unwrap();
    let found = model.log_offsets.as_ref().expect("the logs' offsets");
    for (d, se) in found.deviations.iter().zip(&found.stderr) {
        assert!(
            (d[1] - 0.05).abs() < 5.0 * se[1] && (d[0] + 0.05).abs() < 5.0 * se[0],
            "{d:?} {se:?}"
        );
    }
    assert!(model.run_offsets.is_empty(), "{:?}", model.run_offsets);
    // and the logs agree with one robot once each has its own offset
    let ratio = &model.log_agreement.as_ref().unwrap().ratio;
    assert!(
        ratio.iter().flatten().all(|r| *r < 1.2) && ratio.iter().any(Option::is_some),
        "{ratio:?}"
    );
    assert!(
        printed.contains("each log's torque offset less the logs' mean")
            && printed.contains("each with its own offset"),
        "{printed}"
    );
    // checked on load: deviations that do not sum to 0
    let mut v: serde_json::Value = serde_json::from_str(&model.to_json()).unwrap();
    v["log_offsets"]["deviations"][2][0] = 1.0.into();
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("log_offsets.deviations[2] sum to"), "{e}");
    // refused: one log, no offset term
    fails(
        &[
            "identify-direct",
            "a465",
            s(&logs[0]),
            "--out",
            s(&out),
            "--offset-per-log",
        ],
        &["--offset-per-log", "one log given"],
    );
    fails(
        &both(&["--offset-per-log", "--friction", "viscous,coulomb"]),
        &["--offset-per-log", "needs the offset among --friction"],
    );
}
