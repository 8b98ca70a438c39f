//! Logs written by other tools (src/io/column_map.rs): a UR-style log (time stamps in
//! milliseconds, positions in degrees as `actual_q_0..`, currents counting the other way,
//! target positions and a robot mode in words beside them) read with `--column` and
//! `--ignore-columns` gives the same models as the recording it was made from, in every
//! command that reads a log, and in a pipeline; a map that does not fit its log is refused
//! naming the entry.

mod cli_support;

use cli_support::{excitation_log, fails, ok, plan_nominal_and_d, s, tmp, write};
use perturbid_rs::io::Table;
use std::path::Path;

/// `rec` (a recording CSV of the six-joint A465: t, q1..q6, [qd, qdd,] tau1..tau6) written
/// the way another tool would: `timestamp` in ms, `actual_q_<i>` in degrees, `actual_qd_<i>`
/// and `actual_qdd_<i>` where present, `actual_current_<i>` = -tau / 10, `target_q_<i>` and
/// a `robot_mode` in words.
fn foreign(rec: &Path, out: &Path) {
    let t = Table::read(rec).unwrap();
    let col = |name: &str| t.column(t.index(name).unwrap());
    let has_qd = t.index("qd1").is_some();
    let mut header = vec!["timestamp".to_string()];
    let mut columns = vec![col("t").iter().map(|v| v * 1e3).collect::<Vec<f64>>()];
    let mut per_joint = |var: &str, name: &str, scale: f64| {
        for j in 0..6 {
            header.push(format!("{name}_{j}"));
            columns.push(
                col(&format!("{var}{}", j + 1))
                    .iter()
                    .map(|v| v * scale)
                    .collect(),
            );
        }
    };
    per_joint("q", "actual_q", 180.0 / std::f64::consts::PI);
    if has_qd {
        per_joint("qd", "actual_qd", 1.0);
        per_joint("qdd", "actual_qdd", 1.0);
    }
    per_joint("q", "target_q", 1.0);
    if t.index("tau1").is_some() {
        per_joint("tau", "actual_current", -0.1);
    }
    let mut text = header.join(",") + ",robot_mode\n";
    for r in 0..t.rows() {
        let row: Vec<String> = columns.iter().map(|c| format!("{:?}", c[r])).collect();
        text += &(row.join(",") + ",RUNNING\n");
    }
    write(out, &text);
}

/// The map that reads [`foreign`]'s logs back, as command-line arguments.
const MAP: [&str; 10] = [
    "--column",
    "t=timestamp*ms",
    "--column",
    "q=actual_q_{i}*deg",
    "--column",
    "qd=actual_qd_{i}",
    "--column",
    "qdd=actual_qdd_{i}",
    "--ignore-columns",
    "target_q_*,robot_mode",
];

/// The map for a log with positions and currents only.
const LOG_MAP: [&str; 8] = [
    "--column",
    "t=timestamp*ms",
    "--column",
    "q=actual_q_{i}*deg",
    "--column",
    "tau=actual_current_{i}*-10",
    "--ignore-columns",
    "target_q_*,robot_mode",
];

fn theta(path: &Path) -> Vec<f64> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    serde_json::from_value(v["theta"].clone()).unwrap()
}

fn close(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= 1e-9 * scale, "{x} against {y}");
    }
}

#[test]
fn a_foreign_log_gives_the_models_its_recording_gives() {
    let d = tmp("foreign-direct");
    let log = excitation_log(&d, 1);
    let ur = d.join("ur.csv");
    foreign(&log, &ur);
    let plain = d.join("plain.json");
    ok(&["identify-direct", "a465", s(&log), "--out", s(&plain)]);
    // without the map: the words of the robot's mode, then the first column the recording
    // has no place for, each with the way out
    let x = d.join("x.json");
    fails(
        &["identify-direct", "a465", s(&ur), "--out", s(&x)],
        &[
            "ur.csv",
            "line 2, column 'robot_mode': 'RUNNING' is not a number",
            "--ignore-columns 'robot_mode'",
        ],
    );
    fails(
        &[
            "identify-direct",
            "a465",
            s(&ur),
            "--out",
            s(&x),
            "--ignore-columns",
            "robot_mode",
        ],
        &["ur.csv", "no column 't' (time, s)", "--column t=NAME"],
    );
    // `columns` shows how the map reads the log, before any command reads it so
    let mut args = vec!["columns", "a465", s(&ur)];
    args.extend(LOG_MAP);
    let shown = ok(&args);
    for line in [
        "ur.csv: 20 columns, 2001 rows; read as a recording of 6 joints (joint1, joint2",
        "  t          <- timestamp x 0.001\n",
        "  q6         <- actual_q_5 x 0.017453292519943295\n",
        "  tau1       <- actual_current_0 x -10\n",
        "t from 0 s to 10 s; q, tau (preprocessed by the commands that fit)",
        "ur.csv: 7 column(s) left out (--ignore-columns): target_q_0",
    ] {
        assert!(shown.contains(line), "'{line}' not in {shown}");
    }
    fails(
        &["columns", "a465", s(&ur)],
        &["column 'robot_mode': 'RUNNING' is not a number"],
    );
    let mapped = d.join("mapped.json");
    let mut args = vec!["identify-direct", "a465", s(&ur), "--out", s(&mapped)];
    args.extend(LOG_MAP);
    let out = ok(&args);
    assert!(
        out.contains("ur.csv: 7 column(s) left out (--ignore-columns): target_q_0, target_q_1")
            && out.contains("robot_mode"),
        "{out}"
    );
    close(&theta(&mapped), &theta(&plain));
    // validate reads it so too
    let (v_plain, v_mapped) = (d.join("v_plain"), d.join("v_mapped"));
    ok(&[
        "validate",
        s(&plain),
        s(&log),
        "--robot",
        "a465",
        "--out",
        s(&v_plain),
    ]);
    let mut args = vec![
        "validate",
        s(&plain),
        s(&ur),
        "--robot",
        "a465",
        "--out",
        s(&v_mapped),
    ];
    args.extend(LOG_MAP);
    ok(&args);
    let residuals = |dir: &Path| Table::read(&dir.join("residuals.csv")).unwrap().values;
    close(&residuals(&v_mapped), &residuals(&v_plain));
    // predict: states with velocities and accelerations (the excitation's samples)
    let states = d.join("exc1/excitation.csv");
    let ur_states = d.join("ur_states.csv");
    foreign(&states, &ur_states);
    let (p_plain, p_mapped) = (d.join("p_plain.csv"), d.join("p_mapped.csv"));
    ok(&[
        "predict",
        s(&plain),
        s(&states),
        "--robot",
        "a465",
        "--out",
        s(&p_plain),
    ]);
    let mut args = vec![
        "predict",
        s(&plain),
        s(&ur_states),
        "--robot",
        "a465",
        "--out",
        s(&p_mapped),
    ];
    args.extend(MAP);
    ok(&args);
    close(
        &Table::read(&p_mapped).unwrap().values,
        &Table::read(&p_plain).unwrap().values,
    );
    // a pipeline takes the map as a table (or a list), and the patterns as a list
    let pipeline = d.join("pipeline.toml");
    write(
        &pipeline,
        &format!(
            "[[step]]\nrun = \"identify-direct\"\nrobot = \"a465\"\ndata = \"{}\"\nout = \"{}\"\ncolumn = {{ t = \"timestamp*ms\", q = \"actual_q_{{i}}*deg\", tau = \"actual_current_{{i}}*-10\" }}\nignore_columns = [\"target_q_*\", \"robot_mode\"]\n",
            s(&ur),
            s(&d.join("piped.json"))
        ),
    );
    ok(&["run", s(&pipeline)]);
    close(&theta(&d.join("piped.json")), &theta(&plain));
}

#[test]
fn a_map_that_does_not_fit_its_log_is_refused_naming_the_entry() {
    let d = tmp("foreign-refused");
    let log = d.join("log.csv");
    write(&log, "t,q1,q2,q3,q4,q5,q6,tau1,tau2,tau3,tau4,tau5,tau6\n0,0,0,0,0,0,0,1,1,1,1,1,1\n0.01,0,0,0,0,0,0,1,1,1,1,1,1\n");
    let ur = d.join("ur.csv");
    foreign(&log, &ur);
    let out = s(&d.join("x.json")).to_string();
    let run = |extra: &[&str], needles: &[&str]| {
        let mut args = vec!["identify-direct", "a465", s(&ur), "--out", &out];
        args.extend(extra);
        fails(&args, needles);
    };
    // the words of the robot's mode, with the way out
    run(
        &[
            "--column",
            "t=timestamp*ms",
            "--column",
            "q=actual_q_{i}*deg",
            "--column",
            "tau=actual_current_{i}",
            "--ignore-columns",
            "target_q_*",
        ],
        &[
            "ur.csv",
            "line 2, column 'robot_mode': 'RUNNING' is not a number",
            "--ignore-columns 'robot_mode'",
        ],
    );
    for (extra, needles) in [
        (
            &["--column", "q=actual_pos_{i}"][..],
            &["--column 'q=actual_pos_{i}': no column 'actual_pos_0' for q1; the columns are: timestamp, actual_q_0"][..],
        ),
        (
            &["--column", "q=actual_q_{i}", "--column", "qd=actual_q_{i}"],
            &["--column 'qd=actual_q_{i}': column 'actual_q_0' is already read as q1 (by 'q=actual_q_{i}')"][..],
        ),
        (&["--column", "q=actual_q"], &["must say where the joint goes"]),
        (&["--column", "q=actual_q_{i}*furlong"], &["the scale 'furlong' is no factor"]),
        (&["--column", "joint1=actual_q_0"], &["the target 'joint1' is none of t, q, qd, qdd, tau"]),
        (&["--column", "q1=actual_q_0", "--column", "q=actual_q_{i}"], &["'q1=actual_q_0' and 'q=actual_q_{i}' both give q1"]),
        (&["--column", "t=timestamp*-1"], &["a time's scale must be positive"]),
        (&["--ignore-columns", "*"], &["leaving out every column is no recording"]),
    ] {
        run(extra, needles);
    }
    // a column a recording has no place for, named with the way out
    let extra = d.join("extra.csv");
    write(
        &extra,
        &std::fs::read_to_string(&log)
            .unwrap()
            .replace("tau6\n", "tau6,temp1\n")
            .replace(",1\n", ",1,30\n"),
    );
    fails(
        &["identify-direct", "a465", s(&extra), "--out", &out],
        &[
            "extra.csv: unexpected column 'temp1'",
            "--ignore-columns 'temp1'",
        ],
    );
    assert!(!d.join("x.json").exists());
}

#[test]
fn the_local_method_and_the_split_read_foreign_recordings() {
    let d = tmp("foreign-local");
    let plan = plan_nominal_and_d(&d);
    let rec = d.join("rec");
    ok(&[
        "simulate",
        "a465",
        s(&plan),
        "--out",
        s(&rec),
        "--torque-noise",
        "0.005",
    ]);
    let ur = d.join("ur");
    std::fs::create_dir_all(&ur).unwrap();
    for e in ["nominal", "D"] {
        foreign(&rec.join(format!("{e}.csv")), &ur.join(format!("{e}.csv")));
    }
    let (plain, mapped) = (d.join("plain.json"), d.join("mapped.json"));
    ok(&["identify", s(&plan), s(&rec), "--out", s(&plain)]);
    let mut args = vec!["identify", s(&plan), s(&ur), "--out", s(&mapped)];
    args.extend(LOG_MAP);
    let out = ok(&args);
    assert!(out.contains("D.csv: 7 column(s) left out"), "{out}");
    let d_star = |p: &Path| -> Vec<f64> {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        serde_json::from_value::<Vec<Vec<f64>>>(v["d"]["matrix"].clone())
            .unwrap()
            .concat()
    };
    close(&d_star(&mapped), &d_star(&plain));
    // one log of the session, split: the runs one after the other on one clock
    let session = d.join("session.csv");
    let (a, b) = (
        Table::read(&rec.join("nominal.csv")).unwrap(),
        Table::read(&rec.join("D.csv")).unwrap(),
    );
    let mut joined = a.clone();
    let (w, last) = (a.columns.len(), a.values[a.values.len() - a.columns.len()]);
    for r in 0..b.rows() {
        let mut row = b.values[r * w..(r + 1) * w].to_vec();
        row[0] += last + 2.0;
        joined.push(&row);
    }
    write(&session, &joined.to_csv());
    let ur_session = d.join("ur_session.csv");
    foreign(&session, &ur_session);
    let (split_plain, split_mapped) = (d.join("split_plain"), d.join("split_mapped"));
    ok(&["split", s(&plan), s(&session), "--out", s(&split_plain)]);
    let mut args = vec!["split", s(&plan), s(&ur_session), "--out", s(&split_mapped)];
    args.extend(LOG_MAP);
    let out = ok(&args);
    assert!(
        out.contains("ur_session.csv: 7 column(s) left out"),
        "{out}"
    );
    for e in ["nominal.csv", "D.csv"] {
        close(
            &Table::read(&split_mapped.join(e)).unwrap().values,
            &Table::read(&split_plain.join(e)).unwrap().values,
        );
    }
}
