//! The `perturbid` command line end to end on small cases, and its errors on bad input.

use perturbid_rs::io::Table;
use perturbid_rs::local::LocalModel;
use perturbid_rs::logs::recording_table;
use perturbid_rs::robots::a465;
use perturbid_rs::simulation::{simulate_samples, SimulationOptions};
use perturbid_rs::trajectory::FourierTrajectory;
use perturbid_rs::Document;
use perturbid_rs::{mass_matrix, Data};

mod cli_support;

use std::process::Command;

use cli_support::{
    bin, fails, nothing_written, ok, plan_nominal_and_d, s, table2_op, tmp, warnings_of, write,
};

#[test]
fn plan_simulate_identify_predict() {
    let d = tmp("local");
    let op = table2_op(&d);
    let out = ok(&[
        "plan",
        "a465",
        "--op",
        s(&op),
        "--out",
        s(&d.join("plan")),
        "--design",
        "orthogonal",
        "--experiments",
        "nominal,H,D,G",
    ]);
    assert!(out.contains("plan.json"), "{out}");
    let header = std::fs::read_to_string(d.join("plan/D.csv")).unwrap();
    assert!(
        header.starts_with("t,q1,q2,q3,q4,q5,q6,qd1,"),
        "{}",
        &header[..40]
    );
    ok(&[
        "simulate",
        "a465",
        s(&d.join("plan/plan.json")),
        "--out",
        s(&d.join("rec")),
        "--no-gravity",
    ]);
    let out = ok(&[
        "identify",
        s(&d.join("plan/plan.json")),
        s(&d.join("rec")),
        "--out",
        s(&d.join("model.json")),
    ]);
    assert!(
        out.contains("D*: cond(X) 1.000") && out.contains("T* (N m)"),
        "{out}"
    );
    // the torque noise of the nominal passes and each separated regression, one line an
    // experiment
    let noise: Vec<&str> = out
        .lines()
        .skip_while(|l| !l.starts_with("torque noise (N m;"))
        .skip(1)
        .collect();
    assert_eq!(noise.len(), 4, "{out}");
    for x in ["nominal ", "G ", "H ", "D "] {
        assert!(
            noise
                .iter()
                .any(|l| l.trim_start().starts_with(x) && l.matches(" / ").count() == 6),
            "{out}"
        );
    }
    let model =
        LocalModel::from_json(&std::fs::read_to_string(d.join("model.json")).unwrap()).unwrap();
    let m = a465::model("kinsheel2010").unwrap();
    let mut data = Data::new(&m);
    mass_matrix(&m, &mut data, &a465::TABLE2_Q).unwrap();
    let dm = &model.d.as_ref().unwrap().matrix;
    assert!((dm - &data.m).norm() < 1e-8 * data.m.norm());
    // files given one by one in the plan's order work too
    let files: Vec<String> = ["nominal", "H", "D", "G"]
        .iter()
        .map(|k| d.join(format!("rec/{k}.csv")).display().to_string())
        .collect();
    let (plan_json, model2) = (d.join("plan/plan.json"), d.join("model2.json"));
    let mut args = vec!["identify", s(&plan_json)];
    args.extend(files.iter().map(String::as_str));
    args.extend(["--out", s(&model2), "--estimator", "combined"]);
    ok(&args);
    // predict at the plan's D trajectory states
    let out = ok(&[
        "predict",
        s(&d.join("model.json")),
        s(&d.join("plan/D.csv")),
        "--out",
        s(&d.join("pred.csv")),
    ]);
    assert!(out.contains("predicted torques"), "{out}");
    let pred = Table::parse(
        "pred",
        &std::fs::read_to_string(d.join("pred.csv")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        pred.columns,
        ["t", "tau1", "tau2", "tau3", "tau4", "tau5", "tau6"]
    );
    // with --stderr: the same torques and, after them, the library's standard errors
    ok(&[
        "predict",
        s(&d.join("model.json")),
        s(&d.join("plan/D.csv")),
        "--out",
        s(&d.join("pred_se.csv")),
        "--stderr",
    ]);
    let with_se = Table::parse(
        "pred_se",
        &std::fs::read_to_string(d.join("pred_se.csv")).unwrap(),
    )
    .unwrap();
    assert_eq!(with_se.columns.len(), 13);
    assert_eq!(with_se.columns[7], "tau1_stderr");
    // states at the operating point and one with joint 2 half a radian off: predicted and
    // validated, and the one beyond the perturbations the model was identified over said so
    let mut far = String::from("t,q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6,qdd1,qdd2,qdd3,qdd4,qdd5,qdd6,tau1,tau2,tau3,tau4,tau5,tau6\n");
    for (i, off) in [0.0, 0.0, 0.5].iter().enumerate() {
        let mut q = a465::TABLE2_Q.to_vec();
        q[1] += off;
        let row: Vec<String> = [vec![i as f64 * 1e-3], q, a465::TABLE2_QD.to_vec()]
            .into_iter()
            .flatten()
            .chain(a465::TABLE2_QDD)
            // torques that change (a column of one value while moving is a dead channel)
            .chain((0..6).map(|j| 0.1 + 0.01 * (i + j) as f64))
            .map(|x| x.to_string())
            .collect();
        far.push_str(&(row.join(",") + "\n"));
    }
    write(&d.join("far.csv"), &far);
    for (command, out) in [("predict", "far_pred.csv"), ("validate", "far_validation")] {
        let (model, far, out) = (d.join("model.json"), d.join("far.csv"), d.join(out));
        let said = warnings_of(&[command, s(&model), s(&far), "--out", s(&out)]);
        assert!(
            said.contains("1 of 3 states lie beyond the perturbations")
                && said.contains("q of 'joint2' +0.5000 rad"),
            "{said}"
        );
    }
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("far_validation/validation.json")).unwrap(),
    )
    .unwrap();
    let x = &v["extrapolation"];
    assert_eq!(
        (x["beyond"].as_u64(), x["joint"].as_str()),
        (Some(1), Some("joint2"))
    );
    let reach = x["largest"].as_f64().unwrap();
    let range = model.perturbations.as_ref().unwrap().q[1];
    assert!((reach - 0.5 / range).abs() < 1e-9, "{x}");
    let model = LocalModel::load(d.join("model.json")).unwrap();
    let states =
        Table::parse("D", &std::fs::read_to_string(d.join("plan/D.csv")).unwrap()).unwrap();
    let col = |t: &Table, name: &str| -> Vec<f64> {
        let c = t.columns.iter().position(|c| c == name).unwrap();
        (0..t.rows())
            .map(|r| t.values[r * t.columns.len() + c])
            .collect()
    };
    let pick = |names: &[&str]| -> Vec<f64> {
        let cols: Vec<Vec<f64>> = names.iter().map(|n| col(&states, n)).collect();
        (0..states.rows())
            .flat_map(|r| cols.iter().map(move |c| c[r]))
            .collect()
    };
    let (q, qd, qdd) = (
        pick(&["q1", "q2", "q3", "q4", "q5", "q6"]),
        pick(&["qd1", "qd2", "qd3", "qd4", "qd5", "qd6"]),
        pick(&["qdd1", "qdd2", "qdd3", "qdd4", "qdd5", "qdd6"]),
    );
    let se = model
        .predict_stderr(&perturbid_rs::States::new(6, &q, Some(&qd), Some(&qdd)).unwrap())
        .unwrap();
    for j in 0..6 {
        assert_eq!(
            col(&with_se, &format!("tau{}", j + 1)),
            col(&pred, &format!("tau{}", j + 1))
        );
        let got = col(&with_se, &format!("tau{}_stderr", j + 1));
        for (r, g) in got.iter().enumerate() {
            let want = se[r * 6 + j];
            assert!(
                (g - want).abs() <= 1e-12 * want.abs() && want > 0.0,
                "{g} against {want}"
            );
        }
    }
    // an output that is an input is refused, also spelled another way, and the input survives
    let before = std::fs::read(d.join("plan/D.csv")).unwrap();
    let other_spelling = d.join("plan/../plan/D.csv");
    fails(
        &[
            "predict",
            s(&d.join("model.json")),
            s(&d.join("plan/D.csv")),
            "--out",
            s(&other_spelling),
        ],
        &["--out: ", "is also an input; writing it would destroy"],
    );
    assert_eq!(std::fs::read(d.join("plan/D.csv")).unwrap(), before);
    // recordings written over the plan's trajectories are refused, the plan survives
    fails(
        &[
            "simulate",
            "a465",
            s(&d.join("plan/plan.json")),
            "--out",
            s(&d.join("plan")),
        ],
        &[
            "nominal.csv belongs to the output set 'plan'",
            "plan.manifest.json",
            "choose another output folder",
        ],
    );
    assert_eq!(std::fs::read(d.join("plan/D.csv")).unwrap(), before);
    // a set whose writing was killed between its renames is refused by every reader
    let manifest = d.join("rec/recordings.manifest.json");
    let complete = std::fs::read_to_string(&manifest).unwrap();
    assert!(complete.contains("\"state\": \"complete\""), "{complete}");
    write(&manifest, &complete.replace("\"complete\"", "\"writing\""));
    fails(
        &[
            "identify",
            s(&d.join("plan/plan.json")),
            s(&d.join("rec")),
            "--out",
            s(&d.join("model3.json")),
        ],
        &[
            ".csv belongs to an output set whose writing was interrupted (see ",
            "recordings.manifest.json",
            "run the command that wrote it again",
        ],
    );
    assert!(!d.join("model3.json").exists());
}

#[test]
fn excite_identify_direct_predict() {
    let d = tmp("direct");
    let out = ok(&[
        "excite",
        "a465",
        "--out",
        s(&d),
        "--max-evaluations",
        "200",
        "--rate",
        "100",
    ]);
    assert!(out.contains("cond(Phi_base)"), "{out}");
    let traj: FourierTrajectory =
        serde_json::from_str(&std::fs::read_to_string(d.join("excitation.json")).unwrap()).unwrap();
    assert_eq!(traj.harmonics(), 5);
    // simulated as it was designed, within the limits (between its design's samples too);
    // edited by hand beyond them, it is refused, as a plan is: no robot runs it
    ok(&[
        "simulate",
        "a465",
        s(&d.join("excitation.json")),
        "--rate",
        "7919",
        "--out",
        s(&d.join("dense.csv")),
    ]);
    let mut fast = traj.clone();
    fast.a[(1, 0)] *= 100.0;
    write(&d.join("fast.json"), &serde_json::to_string(&fast).unwrap());
    fails(
        &[
            "simulate",
            "a465",
            s(&d.join("fast.json")),
            "--out",
            s(&d.join("fast.csv")),
        ],
        &[
            "the excitation: joint 'joint2' at t = ",
            "is outside",
            "design it again for it (perturbid excite)",
        ],
    );
    assert!(!d.join("fast.csv").exists());
    // a recording with qd and qdd, noise-free: identification without preprocessing is exact
    let model = a465::model("kinsheel2010").unwrap();
    let samples = traj.sample_periods(1.0, 100.0).unwrap();
    let mut rec =
        simulate_samples(&model, &samples, &SimulationOptions::new(&model), 0, "x").unwrap();
    rec.qd = Some(samples.qd.clone());
    rec.qdd = Some(samples.qdd.clone());
    write(&d.join("log.csv"), &recording_table(&rec, "").to_csv());
    let out = ok(&[
        "identify-direct",
        "a465",
        s(&d.join("log.csv")),
        "--out",
        s(&d.join("base.json")),
        "--friction",
        "none",
        "--validate",
        "0.3",
    ]);
    assert!(
        out.contains("base parameters from") && out.contains("validation"),
        "{out}"
    );
    // the held-out table: RMS, relative RMS and the predictions' standard errors' RMS
    let held_out: Vec<&str> = (out.lines())
        .skip_while(|l| !l.starts_with("validation on the last"))
        .skip(1)
        .take(6)
        .collect();
    assert!(
        held_out.iter().all(|l| l.split_whitespace().count() == 4
            && l.split_whitespace().nth(3).unwrap().parse::<f64>().is_ok()),
        "{out}"
    );
    // the parameter table, in full, as CSV and JSON beside the model
    assert!(
        out.contains("rel. std") && out.contains("parameter table -> "),
        "{out}"
    );
    let fit = perturbid_rs::direct::BaseModel::load(d.join("base.json")).unwrap();
    let csv = std::fs::read_to_string(d.join("base.parameters.csv")).unwrap();
    assert!(csv.starts_with("parameter,value,std,relative_std,combination\n"));
    assert_eq!(csv.lines().count(), fit.theta.len() + 1);
    let names = fit.base.names();
    // read back as any CSV reader would: the full names, whatever they hold
    let read: Vec<String> = csv::Reader::from_reader(csv.as_bytes())
        .records()
        .map(|r| r.unwrap()[0].to_string())
        .collect();
    assert_eq!(read, names, "{csv:.300}");
    assert!(out.contains(&names[0]), "full names printed");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("base.parameters.json")).unwrap())
            .unwrap();
    let rows = json.as_array().unwrap();
    assert_eq!(rows.len(), fit.theta.len());
    assert!(
        rows.iter().any(|r| r["combination"] == true)
            && rows.iter().any(|r| r["combination"] == false)
    );
    let r0 = &rows[0];
    let (value, std) = (r0["value"].as_f64().unwrap(), r0["std"].as_f64().unwrap());
    let relative = std / value.abs();
    assert!((r0["relative_std"].as_f64().unwrap() - relative).abs() < 1e-12 * (1.0 + relative));
    let out = ok(&[
        "predict",
        s(&d.join("base.json")),
        s(&d.join("log.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("pred.csv")),
    ]);
    let worst: f64 = out
        .lines()
        .skip(2)
        .filter_map(|l| l.split_whitespace().last()?.parse::<f64>().ok())
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "{out}");
    fails(
        &["predict", s(&d.join("base.json")), s(&d.join("log.csv"))],
        &["--robot"],
    );
    // a dead torque channel (0 throughout while the robot moves) is refused by the fit and by
    // a validation, each naming the file, the joint and what it would have done
    let mut dead = rec.clone();
    for s in 0..dead.len() {
        dead.tau[s * 6 + 3] = 0.0;
    }
    write(&d.join("dead.csv"), &recording_table(&dead, "").to_csv());
    let dead_csv = d.join("dead.csv").display().to_string();
    let which = "tau: the torque of joint 'joint4' (column 4) is 0 N m in all";
    fails(
        &[
            "identify-direct",
            "a465",
            &dead_csv,
            "--out",
            s(&d.join("dead.json")),
        ],
        &[&dead_csv, which, "a fit would take it for a torque"],
    );
    fails(
        &[
            "validate",
            s(&d.join("base.json")),
            &dead_csv,
            "--robot",
            "a465",
            "--out",
            s(&d.join("dead_validation")),
        ],
        &[&dead_csv, which, "a validation against it would report"],
    );
    assert!(!d.join("dead.json").exists() && !d.join("dead_validation").exists());
    // --stderr: after the torques, the library's standard errors
    let compared = ok(&[
        "predict",
        s(&d.join("base.json")),
        s(&d.join("log.csv")),
        "--robot",
        "a465",
        "--stderr",
        "--out",
        s(&d.join("pred_se.csv")),
    ]);
    let with_se = Table::read(&d.join("pred_se.csv")).unwrap();
    assert_eq!(with_se.columns.len(), 13);
    assert_eq!(with_se.columns[12], "tau6_stderr");
    let log = Table::read(&d.join("log.csv")).unwrap();
    let pick = |t: &Table, names: Vec<String>| -> Vec<f64> {
        let w = t.columns.len();
        let cols: Vec<usize> = (names.iter())
            .map(|n| t.columns.iter().position(|c| c == n).unwrap())
            .collect();
        (0..t.rows())
            .flat_map(|r| {
                cols.iter()
                    .map(move |c| t.values[r * w + c])
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let named = |prefix: &str, suffix: &str| -> Vec<String> {
        (1..=6).map(|j| format!("{prefix}{j}{suffix}")).collect()
    };
    let (q, qd, qdd) = (
        pick(&log, named("q", "")),
        pick(&log, named("qd", "")),
        pick(&log, named("qdd", "")),
    );
    let base = perturbid_rs::direct::BaseModel::load(d.join("base.json")).unwrap();
    let robot = a465::model("kinsheel2010").unwrap();
    let states = perturbid_rs::States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let want = base.predict_stderr(&robot, &states).unwrap();
    let got = pick(&with_se, named("tau", "_stderr"));
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 1e-12 * w && *w > 0.0, "{g} against {w}");
    }
    // and the comparison with the log's torques weighs each joint's error against them
    assert!(
        compared.contains("the RMS of the predictions' standard errors"),
        "{compared}"
    );
    for j in 0..6 {
        let line = (compared.lines())
            .find(|l| l.trim_start().starts_with(&format!("joint{} ", j + 1)))
            .unwrap();
        let fields: Vec<&str> = line.split_whitespace().collect();
        let column: Vec<f64> = got.iter().skip(j).step_by(6).copied().collect();
        let rms = (column.iter().map(|v| v * v).sum::<f64>() / column.len() as f64).sqrt();
        let shown: f64 = fields[2].parse().unwrap();
        assert!(
            fields.len() == 3 && (shown - rms).abs() <= 5e-5,
            "{line}: {rms}"
        );
    }
    // a globally linearised model stores no covariance: refused, nothing written
    let op = perturbid_rs::OperatingPoint::new(vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]).unwrap();
    // states that excite every coefficient (the log's few harmonics do not)
    let noise = |i: usize, salt: u64| {
        let mut z = (i as u64).wrapping_mul(0x9E3779B97F4A7C15) ^ salt;
        z ^= z >> 29;
        z = z.wrapping_mul(0xBF58476D1CE4E5B9);
        z ^= z >> 32;
        (z % 10_000) as f64 / 10_000.0 - 0.5
    };
    let (lq, lqd, lqdd): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        (0..360).map(|i| noise(i, 1)).collect(),
        (0..360).map(|i| noise(i, 2)).collect(),
        (0..360).map(|i| noise(i, 3)).collect(),
    );
    let lin_tau: Vec<f64> = (0..360)
        .map(|i| lq[i] + 0.5 * lqd[i] + 0.1 * lqdd[i] + 0.01 * noise(i, 4))
        .collect();
    let lin_states = perturbid_rs::States::new(6, &lq, Some(&lqd), Some(&lqdd)).unwrap();
    perturbid_rs::direct::identify_global_linear(&op, &lin_states, &lin_tau)
        .unwrap()
        .save(d.join("global.json"))
        .unwrap();
    fails(
        &[
            "predict",
            s(&d.join("global.json")),
            s(&d.join("log.csv")),
            "--stderr",
            "--out",
            s(&d.join("pred_global.csv")),
        ],
        &[
            "--stderr: ",
            "globally linearised model, which stores no covariance",
        ],
    );
    assert!(!d.join("pred_global.csv").exists());
    // a measured torque of 1e308 (its square overflows) and a position past its joint's
    // limits: the error's RMS stays a number, and the state is said to be one the robot
    // cannot take
    let text = std::fs::read_to_string(d.join("log.csv")).unwrap();
    let mut lines: Vec<Vec<String>> = text
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let col = |name: &str| lines[0].iter().position(|c| c == name).unwrap();
    let (tau1, q2) = (col("tau1"), col("q2"));
    lines[4][tau1] = "1e308".into();
    lines[6][q2] = "10".into();
    let edited: Vec<String> = lines.iter().map(|l| l.join(",")).collect();
    write(&d.join("edited.csv"), &(edited.join("\n") + "\n"));
    let run = bin()
        .args([
            "predict",
            s(&d.join("base.json")),
            s(&d.join("edited.csv")),
            "--robot",
            "a465",
            "--out",
            s(&d.join("pred2.csv")),
        ])
        .output()
        .unwrap();
    let (so, se) = (
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
    );
    assert!(run.status.success(), "{se}");
    let k = (lines.len() - 1) as f64;
    let joint1 = so
        .lines()
        .find(|l| l.trim_start().starts_with("joint1"))
        .unwrap();
    let rms: f64 = joint1.split_whitespace().last().unwrap().parse().unwrap();
    assert!((rms / (1e308 / k.sqrt()) - 1.0).abs() < 1e-6, "{so}");
    assert!(
        se.contains("perturbid: warning: '") && se.contains("joint2"),
        "{se}"
    );
    // validation on the log with qdd: exact; on a raw log (positions and torques at 1 kHz,
    // five periods): preprocessed as for identification, close
    let out = ok(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("log.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("validation")),
    ]);
    assert!(
        out.contains("rel. RMS") && out.contains("mean (N m)") && out.contains("joint6"),
        "{out}"
    );
    assert!(
        out.contains("model s.e. RMS") && out.contains("the model's own uncertainty"),
        "{out}"
    );
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("validation/validation.json")).unwrap(),
    )
    .unwrap();
    for j in v["joints"].as_array().unwrap() {
        assert!(j["rms"].as_f64().unwrap() < 1e-6, "{j}");
        assert!(j["model_stderr_rms"].as_f64().unwrap() >= 0.0, "{j}");
    }
    // the figure draws the predictions' band of +- 2 standard errors
    let svg = std::fs::read_to_string(d.join("validation/validation.svg")).unwrap();
    assert_eq!(svg.matches("<polygon").count(), 6, "one band a joint");
    let residuals = std::fs::read_to_string(d.join("validation/residuals.csv")).unwrap();
    assert!(
        residuals.starts_with("t,residual_joint1,"),
        "{residuals:.80}"
    );
    assert_eq!(residuals.lines().count(), samples.t.len() + 1);
    let svg = std::fs::read_to_string(d.join("validation/validation.svg")).unwrap();
    assert_eq!(svg.matches("measured and predicted torque").count(), 6);
    let raw_samples = traj.sample_periods(5.0, 1000.0).unwrap();
    let raw = simulate_samples(
        &model,
        &raw_samples,
        &SimulationOptions::new(&model),
        0,
        "raw",
    )
    .unwrap();
    assert!(raw.qdd.is_none());
    write(&d.join("raw.csv"), &recording_table(&raw, "").to_csv());
    let out = ok(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("raw.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("raw_validation")),
    ]);
    assert!(out.contains("preprocessed: 1000 Hz"), "{out}");
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("raw_validation/validation.json")).unwrap(),
    )
    .unwrap();
    for j in v["joints"].as_array().unwrap() {
        assert!(j["relative_rms"].as_f64().unwrap() < 0.02, "{j}");
    }
    fails(
        &["validate", s(&d.join("base.json")), s(&d.join("raw.csv"))],
        &["--robot", "base-parameter model"],
    );
    // the raw log has no zero offset against the model; with the elbow's positions 0.1 rad
    // off (a joint zeroed elsewhere since), it is named and estimated in validation.json
    let clean = &v["position_offsets"];
    let ratio = clean["unexplained_with_offsets"].as_f64().unwrap()
        / clean["unexplained"].as_f64().unwrap();
    assert!(ratio > 0.8, "{clean}");
    let mut moved = raw.clone();
    for row in moved.q.chunks_mut(6) {
        row[2] += 0.1;
    }
    write(&d.join("moved.csv"), &recording_table(&moved, "").to_csv());
    let err = warnings_of(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("moved.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("moved_validation")),
    ]);
    assert!(
        err.contains("with the positions of joint(s) 'joint3' -0.")
            && err.contains("not those of the log the model was identified from"),
        "{err}"
    );
    let moved_v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("moved_validation/validation.json")).unwrap(),
    )
    .unwrap();
    let offsets = &moved_v["position_offsets"];
    let i = (offsets["joints"].as_array().unwrap().iter())
        .position(|j| j == "joint3")
        .unwrap();
    let d3 = offsets["offsets"][i].as_f64().unwrap();
    assert!((d3 + 0.1).abs() < 0.01, "{offsets}");
    // a glitch in the raw log (joint 2's torque at sample 2000 read 50 N m off): replaced
    // before preprocessing, warned of on stderr and listed in validation.json and the model
    let mut spiked = raw.clone();
    spiked.tau[2000 * 6 + 1] += 50.0;
    write(
        &d.join("spiked.csv"),
        &recording_table(&spiked, "").to_csv(),
    );
    let run = warnings_of;
    let warned = run(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("spiked.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("spiked_validation")),
    ]);
    assert!(
        warned.contains("taken for glitches") && warned.contains("tau of 'joint2'"),
        "{warned}"
    );
    let spiked_v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("spiked_validation/validation.json")).unwrap(),
    )
    .unwrap();
    let listed = spiked_v["log_glitches"].as_array().unwrap();
    assert!(
        listed
            .iter()
            .any(|g| g["sample"] == 2000 && g["joint"] == 1 && g["signal"] == "tau"),
        "{listed:?}"
    );
    for (a, b) in spiked_v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .zip(v["joints"].as_array().unwrap())
    {
        let (a, b) = (a["rms"].as_f64().unwrap(), b["rms"].as_f64().unwrap());
        assert!((a - b).abs() < 0.01 * b + 1e-9, "{a} against {b}");
    }
    // joint 3's torque clipped 20 % below its largest value: warned of by name, kept in the
    // model and in validation.json
    let mut clipped = raw.clone();
    let top = clipped
        .tau
        .iter()
        .skip(2)
        .step_by(6)
        .copied()
        .fold(f64::MIN, f64::max);
    let bottom = clipped
        .tau
        .iter()
        .skip(2)
        .step_by(6)
        .copied()
        .fold(f64::MAX, f64::min);
    let level = top - 0.2 * (top - bottom);
    clipped
        .tau
        .iter_mut()
        .skip(2)
        .step_by(6)
        .for_each(|v| *v = v.min(level));
    write(
        &d.join("clipped.csv"),
        &recording_table(&clipped, "").to_csv(),
    );
    let (log, base_out) = (d.join("clipped.csv"), d.join("clipped_base.json"));
    let (base_json, validation_out) = (d.join("base.json"), d.join("clipped_validation"));
    for warned in [
        run(&["identify-direct", "a465", s(&log), "--out", s(&base_out)]),
        run(&[
            "validate",
            s(&base_json),
            s(&log),
            "--robot",
            "a465",
            "--out",
            s(&validation_out),
        ]),
    ] {
        assert!(
            warned.contains("the torque of 'joint3' reads exactly")
                && warned.contains("its largest value")
                && warned.contains("clipped"),
            "{warned}"
        );
    }
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("clipped_base.json")).unwrap())
            .unwrap();
    let validation: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("clipped_validation/validation.json")).unwrap(),
    )
    .unwrap();
    for listed in [
        &base["log_torque_saturation"],
        &validation["log_torque_saturation"],
    ] {
        assert_eq!(listed[0]["joint"], 2, "{listed}");
        assert_eq!(listed[0]["level"].as_f64(), Some(level), "{listed}");
    }
    assert!(!run(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("spiked.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("spiked_validation_again")),
    ])
    .contains("clipped"));
    let warned = run(&[
        "identify-direct",
        "a465",
        s(&d.join("spiked.csv")),
        "--out",
        s(&d.join("spiked_base.json")),
        "--friction",
        "none",
    ]);
    assert!(!warned.contains("torque column"), "{warned}");
    let fit = perturbid_rs::direct::BaseModel::load(d.join("spiked_base.json")).unwrap();
    assert!(fit
        .log_glitches
        .iter()
        .any(|g| g.sample == 2000 && g.joint == 1 && g.value == spiked.tau[2000 * 6 + 1]));
    assert_eq!(fit.torque_columns.len(), 6);
    // the shoulder's and the elbow's torque columns swapped in the file: named on stderr,
    // and kept in the model
    let mut swapped = raw.clone();
    for row in swapped.tau.chunks_mut(6) {
        row.swap(1, 2);
    }
    write(
        &d.join("swapped.csv"),
        &recording_table(&swapped, "").to_csv(),
    );
    let warned = run(&[
        "identify-direct",
        "a465",
        s(&d.join("swapped.csv")),
        "--out",
        s(&d.join("swapped_base.json")),
        "--friction",
        "none",
    ]);
    assert!(
        warned.contains("the torque column of joint 'joint2' follows the model of joint 'joint3'"),
        "{warned}"
    );
    let fit = perturbid_rs::direct::BaseModel::load(d.join("swapped_base.json")).unwrap();
    assert_eq!(fit.torque_columns[2].follows, "joint2");
    // the clean log's model validated against the swapped log: the swap named there too, and
    // each column's check in validation.json; against the clean log, nothing said
    let warned = run(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("swapped.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("swapped_validation")),
    ]);
    for (a, b) in [("joint2", "joint3"), ("joint3", "joint2")] {
        let said = format!("the torque column of joint '{a}' follows the model of joint '{b}'");
        assert!(warned.contains(&said), "{warned}");
    }
    assert!(warned.contains("swapped.csv"), "{warned}");
    let listed: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("swapped_validation/validation.json")).unwrap(),
    )
    .unwrap();
    let columns = listed["torque_columns"].as_array().unwrap();
    assert_eq!(columns.len(), 6);
    assert_eq!(columns[1]["follows"], "joint3");
    assert!(listed.get("position_range").is_none(), "{listed}");
    // the log's positions in degrees: named as such, and the joints in validation.json
    let mut degrees = raw.clone();
    degrees.q.iter_mut().for_each(|q| *q = q.to_degrees());
    write(
        &d.join("degrees.csv"),
        &recording_table(&degrees, "").to_csv(),
    );
    let warned = run(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("degrees.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("degrees_validation")),
    ]);
    assert!(
        warned.contains("the log's positions look like degrees (convert them to rad)"),
        "{warned}"
    );
    let listed: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("degrees_validation/validation.json")).unwrap(),
    )
    .unwrap();
    let ranges = listed["position_range"].as_array().unwrap();
    assert!(
        ranges.len() >= 2 && ranges.iter().all(|r| r["degrees"] == true),
        "{ranges:?}"
    );
    assert!(!run(&[
        "validate",
        s(&d.join("base.json")),
        s(&d.join("raw.csv")),
        "--robot",
        "a465",
        "--out",
        s(&d.join("raw_validation_again")),
    ])
    .contains("torque column"));
    assert_eq!(v["torque_columns"].as_array().unwrap().len(), 6);
    // and the torques' lag behind the positions: none in the clean log
    assert!(
        v["torque_lag"]["samples"].as_i64().unwrap().abs() <= 1,
        "{v}"
    );
}

#[test]
fn bad_inputs_get_one_line_errors_and_no_output() {
    let d = tmp("errors");
    let plan = plan_nominal_and_d(&d);
    let model = d.join("model.json");
    let csv = |name: &str, text: &str| -> String {
        let p = d.join(name);
        write(&p, text);
        p.display().to_string()
    };
    let header = "t,q1,q2,q3,q4,q5,q6,tau1,tau2,tau3,tau4,tau5,tau6";
    let row = |t: f64| format!("{t},0,0,0,0,0,0,0,0,0,0,0,0");
    // a missing file
    fails(
        &[
            "identify",
            s(&plan),
            s(&d.join("nope.csv")),
            s(&d.join("nope2.csv")),
            "--out",
            s(&model),
        ],
        &["nope.csv"],
    );
    // a missing column
    let f = csv(
        "missing.csv",
        "t,q1,q2,q3,q4,q5,tau1,tau2,tau3,tau4,tau5,tau6\n0,0,0,0,0,0,0,0,0,0,0,0\n",
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["missing.csv", "missing column(s) q6"],
    );
    // an extra column
    let f = csv("extra.csv", &format!("{header},x\n{},1\n", row(0.0)));
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["extra.csv", "unexpected column 'x'"],
    );
    // a non-number, with its line and column
    let f = csv(
        "word.csv",
        &format!("{header}\n{}\n0.001,0,0,zero,0,0,0,0,0,0,0,0,0\n", row(0.0)),
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["word.csv", "line 3, column 'q3'", "'zero' is not a number"],
    );
    // NaN
    let f = csv(
        "nan.csv",
        &format!("{header}\n0,0,0,0,0,0,0,NaN,0,0,0,0,0\n"),
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["nan.csv", "line 2, column 'tau1'", "finite"],
    );
    // time not increasing
    let f = csv(
        "time.csv",
        &format!("{header}\n{}\n{}\n{}\n", row(0.0), row(0.002), row(0.001)),
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &[
            "time.csv",
            "line 4, column 't': time does not increase (t = 0.001 after 0.002 on line 3): a step back (logs joined end to end, or rows out of order); split the log there, or sort its rows by time",
        ],
    );
    // ... after a huge time: the number in exponent form, not 301 digits
    let f = csv(
        "huge_time.csv",
        &format!("{header}\n{}\n{}\n", row(1e300), row(0.001)),
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["huge_time.csv", "(t = 0.001 after 1e300 on line 2)"],
    );
    // a header in capitals
    let f = csv(
        "caps.csv",
        &format!("{}\n{}\n{}\n", header.to_uppercase(), row(0.0), row(0.001)),
    );
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &[
            "caps.csv",
            "no column 't' (time, s) (names are lower case: t, q1, tau1, ...)",
        ],
    );
    // one log for a plan of two experiments: the session split named
    fails(
        &["identify", s(&plan), &f, "--out", s(&model)],
        &[
            "1 files for 2 experiments",
            "perturbid split PLAN LOG --out FOLDER",
        ],
    );
    // fewer joints than the robot has
    let f = csv("few.csv", "t,q1,q2,tau1,tau2\n0,0,0,0,0\n0.1,0,0,0,0\n");
    fails(
        &["identify", s(&plan), &f, &f, "--out", s(&model)],
        &["few.csv", "the robot has 6 joints"],
    );
    // an unknown robot; a bad operating point; a plan breaking the limits
    fails(&["info", "a466"], &["unknown robot 'a466'", "a465"]);
    write(
        &d.join("bad_op.json"),
        r#"{"q": [0, 0], "qd": [0, 0], "qdd": [0, 0]}"#,
    );
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&d.join("bad_op.json")),
            "--out",
            s(&d.join("p2")),
        ],
        &["operating point q", "6"],
    );
    write(
        &d.join("edge.json"),
        r#"{"q": [0, 1.5705, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0], "qdd": [0, 0, 0, 0, 0, 0]}"#,
    );
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&d.join("edge.json")),
            "--out",
            s(&d.join("p3")),
        ],
        &["joint2", "t = ", "outside"],
    );
    assert!(!d.join("p3/plan.json").exists());
    write(&d.join("broken.json"), "{\"robot\": ");
    fails(
        &[
            "simulate",
            "a465",
            s(&d.join("broken.json")),
            "--out",
            s(&d.join("r")),
        ],
        &["broken.json", "line 1"],
    );
    nothing_written(&d, "model.json");
    // usage errors exit with 2 and no panic
    let out = bin().args(["plan"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn paper_reproduction() {
    let d = tmp("paper");
    // three excitation seeds and no study: quick (README's command runs the whole report)
    let quick = ["--excitation-seeds", "3", "--no-study"];
    let out = ok(&["paper", "--out", s(&d), quick[0], quick[1], quick[2]]);
    assert!(out.contains("Table 3"), "{out}");
    for f in [
        "report.md",
        "table2.csv",
        "table3.csv",
        "results.json",
        "fig3_joint2.svg",
        "fig4_joint3.svg",
        "fig5_joint4.svg",
        "figures.csv",
    ] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    let t3 = std::fs::read_to_string(d.join("table3.csv")).unwrap();
    let row = |name: &str| -> Vec<f64> {
        let line = t3
            .lines()
            .find(|l| l.starts_with(&format!("{name},")))
            .unwrap();
        line.split(',')
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    // docs/a465.md: the first column of M(q*) within 0.002 of the paper's "actual" row
    for (a, p) in row("actual").iter().zip(a465::TABLE3_D_COLUMN1) {
        assert!((a - p).abs() < 0.002, "actual {a} vs {p}");
    }
    // the perturbation method: the paper's row to its printed digits
    for (a, p) in row("perturbation").iter().zip(row("perturbation_paper")) {
        assert!((a - p).abs() < 0.006, "perturbation {a} vs {p}");
    }
    let t2 = Table::parse(
        "t2",
        &std::fs::read_to_string(d.join("table2.csv")).unwrap(),
    )
    .unwrap();
    for (t, p) in t2.column(4).iter().zip(t2.column(5)) {
        assert!((t - p).abs() < 0.01, "T* {t} vs Tn {p}");
    }
    let report = std::fs::read_to_string(d.join("report.md")).unwrap();
    assert!(
        report.contains("## Table 2") && report.contains("![fig3_joint2.svg](fig3_joint2.svg)")
    );
    // the direct rows over the seeds, both excitations, the exact wording of agreement
    assert!(report.contains("median of 3 excitations"), "{report}");
    assert!(d.join("fig3_joint2_around_op.svg").is_file());
    // M(q*)'s D11 = 9.9553 rounds to 9.96 where the paper prints 9.95 (its "actual" row: 9.956)
    assert!(
        report.contains("Rounded to the paper's printed precision (two decimals) it differs from the paper's row in D11 9.955 against 9.95."),
        "{report}"
    );
    assert!(!report.contains("three digits") && !report.contains("When to use"));
    let (lo, med, hi) = (
        row("direct_global_linear_min"),
        row("direct_global_linear_median"),
        row("direct_global_linear_max"),
    );
    assert!(
        lo[0] <= med[0] && med[0] <= hi[0] && lo[0] < hi[0],
        "{lo:?} {med:?} {hi:?}"
    );
    // deterministic: a second run writes the same numbers
    let d2 = tmp("paper2");
    ok(&["paper", "--out", s(&d2), quick[0], quick[1], quick[2]]);
    assert_eq!(t3, std::fs::read_to_string(d2.join("table3.csv")).unwrap());
}

/// Ctrl-C stops long work within a second, with status 130, one line, and nothing written.
#[cfg(unix)]
#[test]
fn ctrl_c_stops_long_work_and_writes_nothing() {
    let d = tmp("ctrl-c");
    let out = d.join("excitation");
    let child = bin()
        .args([
            "excite",
            "a465",
            "--max-evaluations",
            "1000000",
            "--out",
            s(&out),
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let sent = std::time::Instant::now();
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let result = child.wait_with_output().unwrap();
    assert!(
        sent.elapsed() < std::time::Duration::from_secs(5),
        "took {:?}",
        sent.elapsed()
    );
    assert_eq!(result.status.code(), Some(130));
    let se = String::from_utf8_lossy(&result.stderr);
    let last = se.trim_end().lines().last().unwrap_or_default();
    assert_eq!(
        last, "perturbid: excitation design: interrupted; nothing was written",
        "{se}"
    );
    assert!(!out.exists(), "an interrupted run wrote {}", out.display());
}

/// Usage errors are one line too, with clap's message and where to read more (status 2).
#[test]
fn usage_errors_are_one_line() {
    for (args, says) in [
        (
            &["plan", "a465", "--op", "op.json", "--design", "latin"][..],
            "invalid value 'latin' for '--design <DESIGN>' [possible values: random, orthogonal]",
        ),
        (&["bogus"][..], "unrecognized subcommand 'bogus'"),
        (
            &["plan"][..],
            "the following required arguments were not provided: --op <OP> <ROBOT>",
        ),
    ] {
        let out = bin().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let se = String::from_utf8_lossy(&out.stderr);
        assert_eq!(se, format!("perturbid: {says} (see perturbid --help)\n"));
    }
}

/// The direct method rehearsed from the command line: excite, simulate the excitation on a true
/// robot, identify-direct from the log it wrote.
#[test]
fn excite_simulate_on_a_true_robot_identify_direct() {
    let d = tmp("true-robot");
    ok(&[
        "excite",
        "a465",
        "--out",
        s(&d),
        "--max-evaluations",
        "100",
        "--rate",
        "100",
    ]);
    let true_robot = d.join("true.json");
    write(
        &true_robot,
        r#"{"format": "perturbid-true-robot/1",
            "payload": {"link": "link6", "mass": 1.0, "com": [0, 0, 0.05]},
            "friction": {"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05]}}"#,
    );
    let out = ok(&[
        "simulate",
        "a465",
        s(&d.join("excitation.json")),
        "--true-robot",
        s(&true_robot),
        "--periods",
        "2",
        "--out",
        s(&d.join("log.csv")),
    ]);
    assert!(
        out.contains("excitation: ") && out.contains("log.csv"),
        "{out}"
    );
    let out = ok(&[
        "identify-direct",
        "a465",
        s(&d.join("log.csv")),
        "--friction",
        "viscous",
        "--out",
        s(&d.join("base.json")),
    ]);
    assert!(out.contains("base parameters from"), "{out}");
    // the identified mass matrix is the true robot's (to the preprocessing's accuracy), not
    // the nominal model's
    let fit = perturbid_rs::direct::BaseModel::load(d.join("base.json")).unwrap();
    let model = a465::model("kinsheel2010").unwrap();
    let truth = perturbid_rs::rehearsal::TrueRobot::load(&true_robot)
        .unwrap()
        .rigid_body_model(&model)
        .unwrap();
    let q = a465::TABLE2_Q;
    let m = fit.mass_matrix(&model, &q).unwrap();
    let (mut dt, mut dn) = (Data::new(&truth), Data::new(&model));
    mass_matrix(&truth, &mut dt, &q).unwrap();
    mass_matrix(&model, &mut dn, &q).unwrap();
    let err = (&m - &dt.m).norm() / dt.m.norm();
    let nominal = (&dn.m - &dt.m).norm() / dt.m.norm();
    assert!(
        err < 0.2 * nominal,
        "fit {err:.2e} vs nominal {nominal:.2e} off the truth"
    );
    // physically consistent: every link of the saved model's parameters a possible body
    let out = ok(&[
        "identify-direct",
        "a465",
        s(&d.join("log.csv")),
        "--friction",
        "viscous",
        "--consistent",
        "--out",
        s(&d.join("consistent.json")),
    ]);
    assert!(
        out.contains("physically consistent: the weighted residual grows by a factor"),
        "{out}"
    );
    let c = perturbid_rs::direct::BaseModel::load(d.join("consistent.json")).unwrap();
    let mc = c.mass_matrix(&model, &q).unwrap();
    assert!((&mc - &dt.m).norm() / dt.m.norm() < 0.2 * nominal);
    // the noise options belong in the document
    fails(
        &[
            "simulate",
            "a465",
            s(&d.join("excitation.json")),
            "--true-robot",
            s(&true_robot),
            "--torque-noise",
            "0.1",
        ],
        &["--true-robot: ", "come from the true-robot document"],
    );
    // a document that is neither a plan nor an excitation
    fails(
        &["simulate", "a465", s(&true_robot)],
        &[
            "true.json",
            "a 'perturbid-true-robot/1' document; expected a plan",
        ],
    );
}

/// The planner's warning on stderr, and the friction-aware H regression from the command line.
#[test]
fn plan_warns_and_identify_friction_aware_h() {
    let d = tmp("friction-aware");
    let op = table2_op(&d);
    // plans the A465 at Table 2 into `out` with `extra` arguments; its warnings
    let plan = |out: &str, extra: &[&str]| {
        let o = bin()
            .args(["plan", "a465", "--op", s(&op), "--out", s(&d.join(out))])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let err = plan("plain", &["--experiments", "nominal,H"]);
    assert!(
        err.starts_with(
            "perturbid: warning: experiment 'H': the velocity perturbations reverse joint(s)"
        ),
        "{err}"
    );
    // the encoders' step, when given, is checked against the D experiment's perturbations
    let err = plan(
        "coarse",
        &[
            "--experiments",
            "nominal,D",
            "--design",
            "orthogonal",
            "--encoder-step",
            "0.001534",
        ],
    );
    assert!(
        err.contains("perturbid: warning: experiment 'D': its encoders would measure the perturbations of joint(s) 'joint1'")
            && err.contains("a crossing window of about 0.1")
            && err.contains(" s (window, --window; now 0.05 s)"),
        "{err}"
    );
    // the torque samples' noise, when given, is checked against each experiment's responses:
    // at Table 2's slow speeds the model's H* is too small for 0.05 N m, D* is not
    let err = plan(
        "noisy",
        &["--experiments", "nominal,H,D", "--torque-noise", "0.05"],
    );
    assert!(
        err.contains("perturbid: warning: experiment 'H': with torque samples of up to 0.05 N m")
            && err.contains("times larger, or"),
        "{err}"
    );
    assert!(
        !err.contains("experiment 'D': with torque samples"),
        "{err}"
    );
    // readings that vary from pass to pass by 3 N m beyond that hide D* too
    let err = plan(
        "drifting",
        &[
            "--experiments",
            "nominal,H,D",
            "--torque-noise",
            "0.05",
            "--torque-pass-noise",
            "3",
        ],
    );
    assert!(
        err.contains("experiment 'D': with torque samples of up to 0.05 N m (standard deviation) and readings varying by up to 3 N m from pass to pass"),
        "{err}"
    );
    // and it needs the samples' noise
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&op),
            "--out",
            s(&d.join("refused")),
            "--torque-pass-noise",
            "0.5",
        ],
        &["--torque-noise"],
    );
    // or the nominal passes' noise an identification of the robot saved with its model
    let white = d.join("white");
    ok(&[
        "plan",
        "a465",
        "--op",
        s(&op),
        "--out",
        s(&white),
        "--experiments",
        "nominal,D",
    ]);
    let (plan_json, rec, model) = (
        white.join("plan.json"),
        d.join("white_rec"),
        d.join("white.json"),
    );
    ok(&[
        "simulate",
        "a465",
        s(&plan_json),
        "--out",
        s(&rec),
        "--torque-noise",
        "0.05",
    ]);
    ok(&["identify", s(&plan_json), s(&rec), "--out", s(&model)]);
    let from_model = ["--experiments", "nominal,D", "--noise-from", s(&model)];
    let err = plan(
        "from_model",
        &[&from_model[..], &["--dqdd-fraction", "1e-6"]].concat(),
    );
    let noise_up_to = |err: &str| -> f64 {
        err.split("experiment 'D': with torque samples of up to ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{err}"))
    };
    let up_to = noise_up_to(&err);
    assert!((up_to / 0.05 - 1.0).abs() < 0.15, "{err}");
    let err = plan("from_model_default", &from_model);
    assert!(
        !err.contains("experiment 'D': with torque samples"),
        "{err}"
    );
    // a model of data without noise has none to give, and says so
    let (quiet_rec, quiet) = (d.join("quiet_rec"), d.join("quiet.json"));
    ok(&["simulate", "a465", s(&plan_json), "--out", s(&quiet_rec)]);
    ok(&["identify", s(&plan_json), s(&quiet_rec), "--out", s(&quiet)]);
    let err = plan(
        "from_quiet",
        &["--experiments", "nominal,D", "--noise-from", s(&quiet)],
    );
    assert!(
        err.contains("quiet.json reports no torque noise in its nominal passes"),
        "{err}"
    );
    // several are pooled, the root mean square per joint (one twice: itself); a noise-free
    // one among noisy ones would pull the pool down unseen: refused, both files named
    let err = plan(
        "pooled",
        &[
            &from_model[..],
            &["--noise-from", s(&model), "--dqdd-fraction", "1e-6"],
        ]
        .concat(),
    );
    let pooled = noise_up_to(&err);
    assert!(
        (pooled / up_to - 1.0).abs() < 1e-6,
        "{pooled} {up_to}: {err}"
    );
    let quiet_out = d.join("pooled_quiet");
    fails(
        &[
            &["plan", "a465", "--op", s(&op), "--out", s(&quiet_out)][..],
            &from_model[..],
            &["--noise-from", s(&quiet)],
        ]
        .concat(),
        &[
            "quiet.json (--noise-from) read no torque noise in the nominal passes at joint 'joint1' (data without noise: a simulation?) and ",
            "white.json (--noise-from) read ",
        ],
    );
    assert!(!quiet_out.exists());
    // of other joints, or given with the noise itself: refused
    fails(
        &[
            "plan",
            "a465",
            "--lock",
            "joint6=0",
            "--op",
            s(&op),
            "--out",
            s(&d.join("refused")),
            "--noise-from",
            s(&model),
        ],
        &[
            "white.json (--noise-from)",
            "the robot 'a465_kinsheel2010' has [joint1",
        ],
    );
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&op),
            "--out",
            s(&d.join("refused")),
            "--noise-from",
            s(&model),
            "--torque-noise",
            "0.05",
        ],
        &["--noise-from", "cannot be used with"],
    );
    assert!(!d.join("refused").exists());
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&op),
            "--out",
            s(&d.join("refused")),
            "--torque-noise=-0.05",
        ],
        &["torque_noise[0]", "-0.05"],
    );
    assert!(!d.join("refused").exists());
    ok(&[
        "plan",
        "a465",
        "--op",
        s(&op),
        "--out",
        s(&d.join("plan")),
        "--experiments",
        "nominal,H",
        "--friction-aware-h",
    ]);
    ok(&[
        "simulate",
        "a465",
        s(&d.join("plan/plan.json")),
        "--out",
        s(&d.join("rec")),
    ]);
    let out = ok(&[
        "identify",
        s(&d.join("plan/plan.json")),
        s(&d.join("rec")),
        "--friction-aware-h",
        "--out",
        s(&d.join("model.json")),
    ]);
    assert!(
        out.contains("H*: cond(X)") && out.contains("clock offsets: nominal"),
        "{out}"
    );
    let model = LocalModel::load(d.join("model.json")).unwrap();
    assert!(model.coulomb.is_some());
}

/// Options that would be ignored or would invent data are refused, their values shown as
/// given: `--periods` and `--rate` with a plan (its experiments run once at the plan's rate),
/// a `--validate` fraction that leaves no sample to validate on, an excitation's sampling
/// rate of 0 (one row at t = NaN before) and a base frequency whose period allocated without
/// bound.
#[test]
fn options_that_would_be_ignored_or_invent_data_are_refused() {
    let d = tmp("ignored");
    let plan = plan_nominal_and_d(&d);
    let rec = d.join("rec");
    for (option, value) in [("--periods", "2"), ("--rate", "500")] {
        fails(
            &[
                "simulate",
                "a465",
                s(&plan),
                "--out",
                s(&rec),
                option,
                value,
            ],
            &[option, "given for a plan", "plan's rate (1000 Hz"],
        );
        nothing_written(&d, "rec");
    }
    let exc = d.join("exc");
    for (option, value, says) in [
        ("--rate", "0", "rate: 0; expected a positive finite number"),
        ("--base-frequency", "1e-300", "base_frequency: 1e-300;"),
    ] {
        fails(
            &[
                "excite",
                "a465",
                "--max-evaluations",
                "2",
                "--out",
                s(&exc),
                option,
                value,
            ],
            &[says],
        );
        nothing_written(&d, "exc");
    }
    ok(&[
        "excite",
        "a465",
        "--max-evaluations",
        "20",
        "--out",
        s(&exc),
    ]);
    let log = d.join("log.csv");
    ok(&[
        "simulate",
        "a465",
        s(&exc.join("excitation.json")),
        "--out",
        s(&log),
        "--rate",
        "200",
    ]);
    fails(
        &[
            "identify-direct",
            "a465",
            s(&log),
            "--preprocess",
            "--validate",
            "1e-9",
            "--out",
            s(&d.join("base.json")),
        ],
        &["--validate: 1e-9 of", "leaves none to validate on"],
    );
}

/// `identify --torque-delay estimate --robot` finds the delay in the recordings (none here:
/// a simulation logs each torque with its positions) and prints it; without the robot, or
/// with the robot and a delay given, it refuses before any work.
#[test]
fn identify_estimates_the_torque_delay() {
    let d = tmp("torque-delay");
    let op = table2_op(&d);
    let plan = d.join("plan");
    ok(&["plan", "a465", "--op", s(&op), "--out", s(&plan)]);
    let plan_json = plan.join("plan.json");
    let rec = d.join("rec");
    ok(&[
        "simulate",
        "a465",
        s(&plan_json),
        "--out",
        s(&rec),
        "--torque-noise",
        "0.01",
    ]);
    let out_json = d.join("model.json");
    let base = ["identify", s(&plan_json), s(&rec), "--out", s(&out_json)];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    fails(&with(&["--torque-delay", "estimate"]), &["--robot"]);
    fails(
        &with(&["--torque-delay", "0.001", "--robot", "a465"]),
        &["--robot", "only --torque-delay estimate"],
    );
    fails(
        &with(&["--torque-delay", "soon"]),
        &["'soon'", "'estimate'"],
    );
    nothing_written(&d, "model.json");
    let out = ok(&with(&["--torque-delay", "estimate", "--robot", "a465"]));
    assert!(out.contains("torque delay "), "{out}");
    let model = LocalModel::from_json(&std::fs::read_to_string(&out_json).unwrap()).unwrap();
    let found = model.diagnostics.torque_delay.unwrap();
    assert!(found.delay.abs() < 1e-4, "{found:?}");
}

/// `plan --refine` on a robot that tracks under PD control: the next round's plan commands
/// each experiment off its crossings, and its nominal passes miss P by less than the first
/// round's. Without --plan, or with --op beside it, it refuses; it never overwrites the plan
/// the recordings ran.
#[test]
fn plan_refine_commands_the_next_round_off_the_miss() {
    let d = tmp("refine");
    let op = table2_op(&d);
    let true_robot = d.join("true_robot.json");
    write(
        &true_robot,
        r#"{"format": "perturbid-true-robot/1", "controller": {"kp": [400, 400, 400, 100, 100, 100], "kd": [40, 40, 40, 10, 10, 10], "substeps": 2}}"#,
    );
    let (plan, rec) = (d.join("plan"), d.join("rec"));
    let plan_json = plan.join("plan.json");
    ok(&[
        "plan",
        "a465",
        "--op",
        s(&op),
        "--out",
        s(&plan),
        "--experiments",
        "nominal,D",
    ]);
    let simulate = |plan: &std::path::Path, rec: &std::path::Path| {
        ok(&[
            "simulate",
            "a465",
            s(plan),
            "--out",
            s(rec),
            "--true-robot",
            s(&true_robot),
        ]);
    };
    simulate(&plan_json, &rec);
    fails(&["plan", "a465", "--refine", s(&rec)], &["--plan"]);
    let refine = ["plan", "a465", "--refine", s(&rec), "--plan", s(&plan_json)];
    fails(&[&refine[..], &["--op", s(&op)]].concat(), &["--op"]);
    fails(
        &[&refine[..], &["--out", s(&plan)]].concat(),
        &["plan.json"],
    );
    let next = d.join("plan2");
    let out = ok(&[&refine[..], &["--out", s(&next)]].concat());
    assert!(
        out.contains("nominal   refined 1 time(s): commanded off its crossings by up to"),
        "{out}"
    );
    let miss = |plan: &std::path::Path, rec: &std::path::Path, name: &str| {
        let model = d.join(name);
        ok(&["identify", s(plan), s(rec), "--out", s(&model)]);
        let local = LocalModel::from_json(&std::fs::read_to_string(&model).unwrap()).unwrap();
        // the nominal passes' mean state against the plan's
        (local.op.q.iter().zip(&local.planned_op.q)).fold(0.0f64, |a, (m, p)| a.max((m - p).abs()))
    };
    let rec2 = d.join("rec2");
    simulate(&next.join("plan.json"), &rec2);
    let (before, after) = (
        miss(&plan_json, &rec, "m1.json"),
        miss(&next.join("plan.json"), &rec2, "m2.json"),
    );
    assert!(
        before > 1e-5 && after < 0.1 * before,
        "the miss went from {before} to {after} rad"
    );
    // the two rounds pooled: twice the crossings, each round read against its own plan
    let pooled = d.join("pooled.json");
    let round = format!("{}={}", plan_json.display(), rec.display());
    let next_json = next.join("plan.json");
    let identify = ["identify", s(&next_json), s(&rec2), "--out", s(&pooled)];
    ok(&[&identify[..], &["--round", &round]].concat());
    let load =
        |p: &std::path::Path| LocalModel::from_json(&std::fs::read_to_string(p).unwrap()).unwrap();
    let (both, alone) = (load(&pooled), load(&d.join("m2.json")));
    let crossings = |m: &LocalModel| m.d.as_ref().unwrap().crossings;
    assert_eq!(crossings(&both), 2 * crossings(&alone));
    fails(
        &[&identify[..], &["--round", s(&rec)]].concat(),
        &["--round", "PLAN.json=FOLDER"],
    );
    let missing = format!("{}={}", plan_json.display(), d.join("nowhere").display());
    fails(
        &[&identify[..], &["--round", &missing]].concat(),
        &["--round", "nowhere"],
    );
    // the delay estimated over both rounds' recordings
    let out = ok(&[
        &identify[..],
        &[
            "--round",
            &round,
            "--torque-delay",
            "estimate",
            "--robot",
            "a465",
        ],
    ]
    .concat());
    assert!(out.contains("torque delay "), "{out}");
}
