//! `perturbid identify-gains` end to end: logs of currents with and without a known payload
//! give the gains and a model of the robot alone; bad payloads are refused by name with
//! nothing written.

mod cli_support;

use cli_support::{fails, nothing_written, ok, s, tmp, warnings_of, write};
use nalgebra::DMatrix;
use perturbid_rs::direct::BaseModel;
use perturbid_rs::logs::recording_table;
use perturbid_rs::rehearsal::{Payload, TrueRobot};
use perturbid_rs::trajectory::FourierTrajectory;
use perturbid_rs::{parallel, Document, Gravity, Recording, States};

const GAINS: [f64; 6] = [42.0, 65.0, 38.0, 9.0, 7.5, 4.0];
const PAYLOAD: &str = r#"{"link": "link6", "mass": 2.0, "com": [0.02, -0.01, 0.08], "inertia": [0.004, 0, 0, 0.004, 0, 0.002]}"#;

/// A log of the A465's currents along a seeded excitation (8 s at 500 Hz), with viscous
/// friction and a deterministic 1e-4 A of noise, with the payload where given.
fn log(path: &std::path::Path, seed: u64, payload: Option<&Payload>) {
    let truth = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let robot = match payload {
        Some(p) => TrueRobot {
            payload: Some(p.clone()),
            ..TrueRobot::default()
        }
        .rigid_body_model(&truth)
        .unwrap(),
        None => truth,
    };
    let c =
        |r: usize, c: usize| (((seed as usize * 31 + r * 7 + c * 13) as f64) * 0.37).sin() * 0.12;
    let traj = FourierTrajectory::new(
        2.0 * std::f64::consts::PI * 0.125,
        vec![0.2, 0.3, -0.4, 0.1, 0.5, -0.2],
        DMatrix::from_fn(6, 5, c),
        DMatrix::from_fn(6, 5, |r, k| c(r + 6, k)),
    )
    .unwrap();
    let t: Vec<f64> = (0..4000).map(|i| i as f64 * 2e-3).collect();
    let x = traj.sample(&t);
    let states = States::new(6, &x.q, Some(&x.qd), Some(&x.qdd)).unwrap();
    let mut tau = vec![0.0; x.q.len()];
    parallel::rnea(
        &robot,
        &mut parallel::Workspace::new(&robot),
        &states,
        Gravity::Included,
        &mut tau,
    )
    .unwrap();
    let current: Vec<f64> = (tau.iter().enumerate())
        .map(|(i, v)| {
            (v + 0.3 * x.qd[i]) / GAINS[i % 6] + 1e-4 * ((i as f64 * 0.618_034).fract() - 0.5) * 3.4
        })
        .collect();
    let rec = Recording::new("log", 6, t, x.q, current, Some(x.qd), Some(x.qdd)).unwrap();
    write(path, &recording_table(&rec, "").to_csv());
}

/// `perturbid identify-gains` on `dir`'s alone.csv and loaded.csv with `payload`, viscous
/// friction, into `dir/out`; its stdout.
fn identify_gains(dir: &std::path::Path, payload: &str, out: &str) -> String {
    identify_gains_by(dir, payload, out, "least_squares")
}

/// [`identify_gains`] by `estimator`.
fn identify_gains_by(dir: &std::path::Path, payload: &str, out: &str, estimator: &str) -> String {
    ok(&[
        "identify-gains",
        "--estimator",
        estimator,
        "a465",
        s(&dir.join("alone.csv")),
        "--loaded",
        s(&dir.join("loaded.csv")),
        "--payload",
        payload,
        "--friction",
        "viscous",
        "--out",
        s(&dir.join(out)),
    ])
}

#[test]
fn gains_and_the_robot_alone_from_logs_of_currents() {
    let d = tmp("gains");
    let payload: Payload = serde_json::from_str(PAYLOAD).unwrap();
    log(&d.join("alone.csv"), 1, None);
    log(&d.join("loaded.csv"), 2, Some(&payload));
    write(&d.join("payload.json"), PAYLOAD);
    let run = |payload: &str, out: &str| identify_gains(&d, payload, out);
    let out = run(s(&d.join("payload.json")), "model.json");
    assert!(
        out.contains("drive gains by least squares from 2 runs (1 with 2 kg on 'link6')"),
        "{out}"
    );
    let model = BaseModel::load(d.join("model.json")).unwrap();
    // each run's log named with what its preprocessing found
    let logs: Vec<&str> = model.logs.iter().map(|l| l.log.as_str()).collect();
    assert_eq!(logs, [s(&d.join("alone.csv")), s(&d.join("loaded.csv"))]);
    let g = model.drive_gains.as_ref().unwrap();
    for (gain, truth) in g.gain.iter().zip(GAINS) {
        assert!((gain / truth - 1.0).abs() < 1e-2, "{out}");
        assert!(out.contains(&format!("{gain:.6}")), "{out}");
    }
    // by instrumental variables: the least-squares gains beside them
    let out = identify_gains_by(&d, s(&d.join("payload.json")), "iv.json", "instrumental");
    assert!(
        out.contains("drive gains by instrumental variables") && out.contains("least squares\n"),
        "{out}"
    );
    let iv = BaseModel::load(d.join("iv.json")).unwrap();
    let ivg = iv.drive_gains.as_ref().unwrap();
    assert_eq!(ivg.least_squares_gain, g.gain);
    for ((gain, ls), truth) in ivg.gain.iter().zip(&g.gain).zip(GAINS) {
        assert!((gain / truth - 1.0).abs() < 1e-2, "{out}");
        assert!(out.contains(&format!("{gain:.6} ")), "{out}");
        assert!(out.contains(&format!("{ls:.6}\n")), "{out}");
    }
    fails(
        &[
            "identify-gains",
            "a465",
            s(&d.join("alone.csv")),
            "--loaded",
            s(&d.join("loaded.csv")),
            "--payload",
            PAYLOAD,
            "--estimator",
            "bayes",
        ],
        &["'bayes'", "instrumental"],
    );
    // the payload given inline: the same model
    let out = run(PAYLOAD, "inline.json");
    assert!(out.contains("base parameters of the robot alone"), "{out}");
    assert_eq!(BaseModel::load(d.join("inline.json")).unwrap(), model);
    // and in a pipeline, written out as a table (it was taken for a string)
    write(
        &d.join("p.toml"),
        "[[step]]\nrun = \"identify-gains\"\nrobot = \"a465\"\nruns = [\"alone.csv\"]\nloaded = [\"loaded.csv\"]\nfriction = \"viscous\"\nout = \"table.json\"\npayload = { link = \"link6\", mass = 2.0, com = [0.02, -0.01, 0.08], inertia = [0.004, 0, 0, 0.004, 0, 0.002] }\n",
    );
    ok(&["run", s(&d.join("p.toml"))]);
    assert_eq!(BaseModel::load(d.join("table.json")).unwrap(), model);
    // a third run of the robot alone: its currents predicted, and validated in torques
    log(&d.join("third.csv"), 3, None);
    let model_path = d.join("model.json");
    let m = s(&model_path);
    let out = ok(&[
        "predict",
        m,
        s(&d.join("third.csv")),
        "--robot",
        "a465",
        "--signal",
        "--stderr",
        "--out",
        s(&d.join("currents.csv")),
    ]);
    assert!(
        out.contains("predicted signals (torques over the drive gains)")
            && out.contains("(signal units)"),
        "{out}"
    );
    let predicted = perturbid_rs::io::Table::read(&d.join("currents.csv")).unwrap();
    let logged = perturbid_rs::io::Table::read(&d.join("third.csv")).unwrap();
    for j in 1..=6 {
        let col = |t: &perturbid_rs::io::Table, name: String| t.column(t.index(&name).unwrap());
        let (p, l) = (
            col(&predicted, format!("signal{j}")),
            col(&logged, format!("tau{j}")),
        );
        let rms =
            (p.iter().zip(&l).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / p.len() as f64).sqrt();
        assert!(rms < 1e-3, "joint {j}: {rms} A");
        assert!(predicted.index(&format!("signal{j}_stderr")).is_some());
    }
    let out = ok(&[
        "validate",
        m,
        s(&d.join("third.csv")),
        "--robot",
        "a465",
        "--signal",
        "--out",
        s(&d.join("validation")),
    ]);
    assert!(
        out.contains("the log's signal times the model's drive gains: torques"),
        "{out}"
    );
    // a model without gains has no signal
    ok(&[
        "identify-direct",
        "a465",
        s(&d.join("third.csv")),
        "--out",
        s(&d.join("plain.json")),
    ]);
    fails(
        &[
            "predict",
            s(&d.join("plain.json")),
            s(&d.join("third.csv")),
            "--robot",
            "a465",
            "--signal",
            "--out",
            s(&d.join("x.csv")),
        ],
        &["--signal", "plain.json' holds no drive gains"],
    );
    nothing_written(&d, "x.csv");
}

#[test]
fn bad_payloads_and_runs_are_refused_by_name() {
    let d = tmp("gains-bad");
    log(&d.join("alone.csv"), 1, None);
    let args = |payload: &str, out: &str| -> Vec<String> {
        [
            "identify-gains",
            "a465",
            s(&d.join("alone.csv")),
            "--loaded",
            s(&d.join("alone.csv")),
            "--payload",
            payload,
            "--out",
            out,
        ]
        .map(String::from)
        .to_vec()
    };
    let out = d.join("model.json");
    let run = |payload: &str, needles: &[&str]| {
        let a = args(payload, s(&out));
        let a = strs(&a);
        fails(&a, needles);
        nothing_written(&d, "model.json");
    };
    run(
        r#"{"link": "tool0", "mass": 1.0}"#,
        &["'tool0' is not a link of", "link6"],
    );
    run(
        r#"{"link": "link6", "mass": -1.0}"#,
        &["--payload", "payload.mass is -1"],
    );
    run(
        r#"{"link": "link6", "mass": 1.0, "colour": "red"}"#,
        &["--payload", "unknown field `colour`"],
    );
    run(
        &d.join("missing.json").display().to_string(),
        &["missing.json"],
    );
    // a log without the payload given as loaded: fitted, and said
    write(&d.join("p.json"), PAYLOAD);
    log(&d.join("other.csv"), 2, None);
    let mut a = args(s(&d.join("p.json")), s(&out));
    a[4] = s(&d.join("other.csv")).into();
    let a = strs(&a);
    let e = warnings_of(&a);
    assert!(
        e.contains("the runs do not agree with the payload as given"),
        "{e}"
    );
    // payloads neither one for all the loaded runs nor one for each
    let mut a = args(s(&d.join("p.json")), s(&d.join("mismatch.json")));
    a.extend(["--payload".into(), s(&d.join("p.json")).into()]);
    a.extend(["--loaded".into(), s(&d.join("other.csv")).into()]);
    a.extend(["--loaded".into(), s(&d.join("other.csv")).into()]);
    let a = strs(&a);
    fails(&a, &["--payload", "2 payloads for 3 --loaded runs"]);
    nothing_written(&d, "mismatch.json");
}

/// `a` as the command line's words.
fn strs(a: &[String]) -> Vec<&str> {
    a.iter().map(String::as_str).collect()
}

#[test]
fn two_loaded_runs_with_payloads_of_their_own() {
    let d = tmp("gains-two");
    let light: Payload = serde_json::from_str(PAYLOAD).unwrap();
    let heavy = Payload {
        mass: 5.0,
        com: [0.0, 0.03, 0.1],
        ..light.clone()
    };
    log(&d.join("alone.csv"), 1, None);
    log(&d.join("light.csv"), 2, Some(&light));
    log(&d.join("heavy.csv"), 3, Some(&heavy));
    let heavy_json = serde_json::to_string(&heavy).unwrap();
    // the light run and then the heavy one, given the payloads `first` and `second`
    let args = |first: &str, second: &str, out: &str| -> Vec<String> {
        [
            "identify-gains",
            "a465",
            s(&d.join("alone.csv")),
            "--loaded",
            s(&d.join("light.csv")),
            "--loaded",
            s(&d.join("heavy.csv")),
            "--payload",
            first,
            "--payload",
            second,
            "--friction",
            "viscous",
            "--out",
            s(&d.join(out)),
        ]
        .map(String::from)
        .to_vec()
    };
    let out = ok(&strs(&args(PAYLOAD, &heavy_json, "model.json")));
    assert!(
        out.contains("from 3 runs (2 with 2 kg on 'link6', 5 kg on 'link6')"),
        "{out}"
    );
    let model = BaseModel::load(d.join("model.json")).unwrap();
    let g = model.drive_gains.as_ref().unwrap();
    assert_eq!((g.runs, g.loaded_runs), (3, 2));
    for (gain, truth) in g.gain.iter().zip(GAINS) {
        assert!((gain / truth - 1.0).abs() < 1e-2, "{out}");
    }
    assert!(g.agreement.iter().all(|a| *a < 1.2), "{:?}", g.agreement);
    // in a pipeline, a list: one written out as a table, the other a file beside it
    write(&d.join("heavy.json"), &heavy_json);
    write(
        &d.join("p.toml"),
        "[[step]]\nrun = \"identify-gains\"\nrobot = \"a465\"\nruns = [\"alone.csv\"]\nloaded = [\"light.csv\", \"heavy.csv\"]\nfriction = \"viscous\"\nout = \"pipeline.json\"\npayload = [{ link = \"link6\", mass = 2.0, com = [0.02, -0.01, 0.08], inertia = [0.004, 0, 0, 0.004, 0, 0.002] }, \"heavy.json\"]\n",
    );
    ok(&["run", s(&d.join("p.toml"))]);
    assert_eq!(BaseModel::load(d.join("pipeline.json")).unwrap(), model);
    // the payloads swapped: the runs do not agree with them, and it is said
    let e = warnings_of(&strs(&args(&heavy_json, PAYLOAD, "swapped.json")));
    assert!(
        e.contains("the runs do not agree with the payload as given"),
        "{e}"
    );
}

#[test]
fn a_local_model_in_torques_from_recordings_of_currents() {
    // the drive gains identified once, then the local method's recordings logged as currents
    let d = tmp("gains-local");
    let payload: Payload = serde_json::from_str(PAYLOAD).unwrap();
    log(&d.join("alone.csv"), 1, None);
    log(&d.join("loaded.csv"), 2, Some(&payload));
    let gains = d.join("gains.json");
    identify_gains(&d, PAYLOAD, "gains.json");
    let plan = cli_support::plan_nominal_and_d(&d);
    ok(&["simulate", "a465", s(&plan), "--out", s(&d.join("rec"))]);
    std::fs::create_dir_all(d.join("currents")).unwrap();
    let joints: Vec<String> = (1..=6).map(|j| format!("joint{j}")).collect();
    for name in ["nominal", "D"] {
        let file = format!("{name}.csv");
        let rec = perturbid_rs::logs::load_recording(&d.join("rec").join(&file), &joints).unwrap();
        let current: Vec<f64> = (rec.tau.iter().enumerate())
            .map(|(i, t)| t / GAINS[i % 6])
            .collect();
        let rec = Recording {
            tau: current,
            ..rec
        };
        write(
            &d.join("currents").join(&file),
            &recording_table(&rec, "").to_csv(),
        );
    }
    let identify = |rec: &str, out: &str, extra: &[&str]| {
        let mut args = vec!["identify", s(&plan), rec, "--out", out];
        args.extend_from_slice(extra);
        ok(&args)
    };
    identify(s(&d.join("rec")), s(&d.join("torques.json")), &[]);
    let out = identify(
        s(&d.join("currents")),
        s(&d.join("from_currents.json")),
        &["--gains-from", s(&gains)],
    );
    assert!(
        out.contains("torques: the recordings' signal times the drive gains of"),
        "{out}"
    );
    let load = |f: &str| perturbid_rs::local::LocalModel::load(d.join(f)).unwrap();
    let (a, b) = (load("torques.json"), load("from_currents.json"));
    let (da, db) = (&a.d.as_ref().unwrap().matrix, &b.d.as_ref().unwrap().matrix);
    let rel = (da - db).abs().max() / da.abs().max();
    assert!(rel < 2e-3, "D* from currents off by {rel}");
    // the model keeps the gains it was put in torques by (their errors enter its predictions')
    let g = BaseModel::load(&gains).unwrap().drive_gains.unwrap();
    let kept = b.drive_gains.as_ref().unwrap();
    assert_eq!((&kept.gain, &kept.stderr), (&g.gain, &g.stderr));
    assert!(a.drive_gains.is_none());
    fails(
        &[
            "identify",
            s(&plan),
            s(&d.join("currents")),
            "--out",
            s(&d.join("x.json")),
            "--gains-from",
            s(&d.join("torques.json")),
        ],
        &["torques.json"],
    );
    nothing_written(&d, "x.json");
}

#[test]
fn an_unknown_payload_from_a_log_of_currents_against_the_gains_model() {
    let d = tmp("gains-payload");
    let payload: Payload = serde_json::from_str(PAYLOAD).unwrap();
    log(&d.join("alone.csv"), 1, None);
    log(&d.join("loaded.csv"), 2, Some(&payload));
    identify_gains(&d, PAYLOAD, "model.json");
    // a tool the gains' runs did not carry, on a later motion
    let tool = Payload {
        link: "link6".into(),
        mass: 0.8,
        com: [0.0, 0.03, 0.05],
        inertia: [0.002, 0.0, 0.0, 0.002, 0.0, 0.001],
    };
    log(&d.join("tool.csv"), 5, Some(&tool));
    let out = ok(&[
        "identify-payload",
        "a465",
        s(&d.join("tool.csv")),
        "--link",
        "link6",
        "--model",
        s(&d.join("model.json")),
        "--signal",
        "--out",
        s(&d.join("tool")),
    ]);
    assert!(
        out.contains("signal times the model's drive gains"),
        "{out}"
    );
    let found: Payload =
        serde_json::from_str(&std::fs::read_to_string(d.join("tool/payload.json")).unwrap())
            .unwrap();
    assert!((found.mass - 0.8).abs() < 5e-3, "{found:?}\n{out}");
    for i in 0..3 {
        assert!((found.com[i] - tool.com[i]).abs() < 2e-3, "{found:?}");
    }
    // and it is a payload identify-gains takes
    let again = ok(&[
        "identify-gains",
        "a465",
        s(&d.join("alone.csv")),
        "--loaded",
        s(&d.join("tool.csv")),
        "--payload",
        s(&d.join("tool/payload.json")),
        "--friction",
        "viscous",
        "--out",
        s(&d.join("again.json")),
    ]);
    assert!(
        again.contains("(1 with 0.799") && again.contains("kg on 'link6')"),
        "{again}"
    );
    let g = BaseModel::load(d.join("again.json")).unwrap();
    for (gain, truth) in g.drive_gains.unwrap().gain.iter().zip(GAINS) {
        assert!((gain / truth - 1.0).abs() < 1e-2, "{again}");
    }
}
