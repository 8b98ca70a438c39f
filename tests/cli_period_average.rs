//! Averaging logs over their excitation's periods from the command line (`--average-periods
//! EXCITATION`, `--period`): the start found in a log that begins at rest, the model saving
//! what was found, and the options that do not go together refused by name.

mod cli_support;

use cli_support::{excite_a465, fails, ok, s, tmp, write};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::Document;

#[test]
fn a_log_is_averaged_over_its_excitations_periods_and_the_model_keeps_what_was_found() {
    let d = tmp("cli-periods");
    let exc = d.join("exc");
    excite_a465(&exc, 2);
    let excitation = exc.join("excitation.json");
    let raw = d.join("raw.csv");
    ok(&[
        "simulate",
        "a465",
        s(&excitation),
        "--out",
        s(&raw),
        "--rate",
        "500",
        "--periods",
        "4",
        "--torque-noise",
        "0.02",
        "--seed",
        "3",
    ]);
    // 2.5 s at rest where the excitation starts, before it: the logger ran first
    let text = std::fs::read_to_string(&raw).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let row = |r: &[f64], shift: f64| -> String {
        let mut r = r.to_vec();
        r[0] += shift;
        r.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
            + "\n"
    };
    let mut log = format!("{header}\n");
    for i in 0..1250 {
        log += &row(&rows[0], i as f64 / 500.0);
    }
    for r in &rows {
        log += &row(r, 2.5);
    }
    let path = d.join("log.csv");
    write(&path, &log);
    let model = d.join("model.json");
    let out = ok(&[
        "identify-direct",
        "a465",
        s(&path),
        "--friction",
        "none",
        "--average-periods",
        s(&excitation),
        "--decimate",
        "5",
        "--out",
        s(&model),
    ]);
    assert!(
        out.contains("averaged over 4 periods of 10 s from t = 2.5 s (0 left out)"),
        "{out}"
    );
    assert!(
        out.contains("residual RMS over the averaged torques' noise, a joint: "),
        "{out}"
    );
    let m = BaseModel::load(&model).unwrap();
    let a = m.log_period_average.as_ref().expect("kept with the model");
    assert_eq!((a.periods, a.harmonics, a.samples), (4, 5, 10000));
    assert!((a.start - 2.5).abs() < 1e-6, "{}", a.start);
    // white noise of 0.02 N m keeps sqrt(201 / 5000) of itself in the band, halved by 4 periods
    let expected = 0.02 * (201.0f64 / 5000.0).sqrt();
    for (j, x) in a.torque_noise.iter().enumerate() {
        assert!(
            (x / expected - 1.0).abs() < 0.2,
            "joint {}: {x} against {expected}",
            j + 1
        );
    }
    for (r, n) in m.residual_rms.iter().zip(a.averaged_torque_noise()) {
        assert!(*r < 1.5 * n, "residual {r} against the averaged noise {n}");
    }
    // the model validated on the log averaged alike
    let out = ok(&[
        "validate",
        s(&model),
        s(&path),
        "--robot",
        "a465",
        "--average-periods",
        s(&excitation),
        "--decimate",
        "5",
    ]);
    assert!(out.contains("averaged over 4 periods"), "{out}");
    assert!(
        out.contains("RMS over the averaged torques' noise, a joint: "),
        "{out}"
    );
    // periods given by hand, from the start found
    let out = ok(&[
        "validate",
        s(&model),
        s(&path),
        "--robot",
        "a465",
        "--period",
        "10",
        "--period-harmonics",
        "5",
        "--period-start",
        "2.5",
        "--skip-periods",
        "1",
    ]);
    assert!(
        out.contains("averaged over 3 periods of 10 s from t = 12.5 s"),
        "{out}"
    );
    // what does not go together
    let base = ["validate", s(&model), s(&path), "--robot", "a465"];
    for (extra, says) in [
        (
            vec!["--average-periods", s(&excitation), "--period", "10"],
            "brings its own period and harmonics",
        ),
        (
            vec!["--average-periods", s(&excitation), "--period-start", "1"],
            "--period-start does not apply",
        ),
        (vec!["--period", "10"], "--period needs --period-harmonics"),
        (
            vec!["--skip-periods", "1"],
            "give --period or --average-periods EXCITATION too",
        ),
        (
            vec!["--period", "10", "--period-harmonics", "5", "--trim", "1"],
            "--trim drops a filter's transients",
        ),
        (
            vec!["--period", "9", "--period-harmonics", "5"],
            "does not repeat with that period",
        ),
        (vec!["--average-periods", s(&model)], "not an excitation"),
    ] {
        let args: Vec<&str> = base.iter().copied().chain(extra).collect();
        fails(&args, &[says]);
    }
}
