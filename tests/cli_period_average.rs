//! Averaging logs over their excitation's periods from the command line (`--average-periods
//! EXCITATION`, `--period`): the start found in a log that begins at rest, the model saving
//! what was found, and the options that do not go together refused by name.

mod cli_support;

use cli_support::{excite_a465, fails, ok, s, tmp, write};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::Document;

/// A log of 4 periods of `excitation` simulated on the A465 at 500 Hz with torque noise of
/// `noise` N m, at `out`.
fn simulated(excitation: &std::path::Path, out: &std::path::Path, seed: &str, noise: &str) {
    ok(&[
        "simulate",
        "a465",
        s(excitation),
        "--out",
        s(out),
        "--rate",
        "500",
        "--periods",
        "4",
        "--torque-noise",
        noise,
        "--seed",
        seed,
    ]);
}

/// A 2-harmonic excitation of the A465 designed into `d/exc`: its excitation.json.
fn excitation_in(d: &std::path::Path) -> std::path::PathBuf {
    let exc = d.join("exc");
    excite_a465(&exc, 2);
    exc.join("excitation.json")
}

#[test]
fn a_log_is_averaged_over_its_excitations_periods_and_the_model_keeps_what_was_found() {
    let d = tmp("cli-periods");
    let excitation = excitation_in(&d);
    let raw = d.join("raw.csv");
    simulated(&excitation, &raw, "3", "0.02");
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
    let validation = d.join("validation");
    let base = [
        "validate",
        s(&model),
        s(&path),
        "--robot",
        "a465",
        "--out",
        s(&validation),
    ];
    let out = ok(&[
        &base[..],
        &["--average-periods", s(&excitation), "--decimate", "5"],
    ]
    .concat());
    assert!(out.contains("averaged over 4 periods"), "{out}");
    assert!(
        out.contains("RMS over the averaged torques' noise, a joint: "),
        "{out}"
    );
    assert!(
        out.contains("the errors against the torques' noise measured apart: their cost over its "),
        "{out}"
    );
    // periods given by hand, from the start found
    let out = ok(&[
        &base[..],
        &[
            "--period",
            "10",
            "--period-harmonics",
            "5",
            "--period-start",
            "2.5",
            "--skip-periods",
            "1",
        ],
    ]
    .concat());
    assert!(
        out.contains("averaged over 3 periods of 10 s from t = 12.5 s"),
        "{out}"
    );
    // what does not go together
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

/// `--weighting noise`: the averaged log's rows weighted by the noise its periods measured,
/// the residuals judged against it and kept with the model; two logs' pooled noise; refused
/// for a log not averaged and for logs whose noise differs, by name.
#[test]
fn an_averaged_log_is_weighted_by_its_noise() {
    let d = tmp("cli-noise-weighting");
    let excitation = excitation_in(&d);
    let log = d.join("log.csv");
    simulated(&excitation, &log, "5", "0.02");
    let model = d.join("model.json");
    let fit = |extra: &[&str]| -> Vec<String> {
        let mut args = vec!["identify-direct", "a465", s(&log)];
        args.extend_from_slice(extra);
        args.extend(["--friction", "none", "--decimate", "5", "--out", s(&model)]);
        args.into_iter().map(String::from).collect()
    };
    let averaged = ["--period", "10", "--period-harmonics", "5"];
    let args = fit(&[&averaged[..], &["--weighting", "noise"]].concat());
    let out = ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        out.contains(
            "the residuals against the torques' noise measured apart: their cost over its "
        ),
        "{out}"
    );
    let m = BaseModel::load(&model).unwrap();
    let n = m.noise_fit.as_ref().expect("kept with the model");
    let a = m.log_period_average.as_ref().unwrap();
    assert_eq!(m.sigma, a.averaged_torque_noise());
    // the kept samples: the period's 10,000 on the 1 kHz grid, every 5th (70 % fitted to)
    assert_eq!((a.samples, a.kept_samples), (10000, 2000));
    assert!((n.noise.correlation - 2000.0 / 201.0).abs() < 1e-9);
    assert!(n.p_value > 1e-3, "{n:?}");
    // with the residuals' weighting the noise still judges them
    let args = fit(&averaged);
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let m = BaseModel::load(&model).unwrap();
    assert!(m.noise_fit.is_some() && m.sigma != a.averaged_torque_noise());
    // no noise to weight by
    let args = fit(&["--weighting", "noise"]);
    fails(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["noise needs each log averaged over its excitation's periods"],
    );
    // two logs of the same noise: weighted by their pooled noise
    let second = d.join("second.csv");
    simulated(&excitation, &second, "6", "0.02");
    let mut args = fit(&[&averaged[..], &["--weighting", "noise"]].concat());
    args.insert(3, s(&second).to_string());
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let m = BaseModel::load(&model).unwrap();
    let n = m.noise_fit.as_ref().expect("kept with the model");
    assert_eq!(n.noise.degrees_of_freedom, Some(2.0 * 3.0 * 201.0 * 6.0));
    assert!(n.p_value > 1e-3, "{n:?}");
    // one of twice the other's noise: not one weight a joint
    let louder = d.join("louder.csv");
    simulated(&excitation, &louder, "7", "0.04");
    args[3] = s(&louder).to_string();
    fails(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["the torques' noise of joint 'joint1' differs between the logs"],
    );
}
