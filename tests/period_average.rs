//! Averaging a log over the periods of its excitation (src/logs/period_average/,
//! src/logs/excitation_start.rs; docs/method.md, section 8e), against the excitation's own
//! analytic positions, velocities and accelerations, the robot's own torques and the noise
//! put in.

mod common;

use common::{a465_excitation, torques_with_friction, Rng};
use perturbid_rs::direct::{identify_base_parameters, BaseOptions, FrictionTerms};
use perturbid_rs::logs::excitation_start::excitation_start;
use perturbid_rs::logs::period_average::PeriodOptions;
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::robots::a465;
use perturbid_rs::trajectory::{FourierTrajectory, Samples};
use perturbid_rs::Recording;

const RATE: f64 = 500.0;
const PERIOD: f64 = 10.0;

/// `periods` periods of the excitation at 500 Hz after `lead_in` s at rest at its start.
fn samples(traj: &FourierTrajectory, lead_in: f64, periods: f64) -> Samples {
    let count = ((lead_in + periods * PERIOD) * RATE).round() as usize;
    let t: Vec<f64> = (0..count).map(|i| i as f64 / RATE).collect();
    let mut s = traj.sample(
        &t.iter()
            .map(|t| (t - lead_in).max(0.0))
            .collect::<Vec<f64>>(),
    );
    s.t = t;
    for i in 0..s.len() {
        if s.t[i] < lead_in {
            for j in 0..6 {
                s.qd[i * 6 + j] = 0.0;
                s.qdd[i * 6 + j] = 0.0;
            }
        }
    }
    s
}

/// A log of `s` on the paper's A465 with viscous and Coulomb friction, torques with white
/// noise of `noise` N m (uniform, that standard deviation).
fn log(s: &Samples, noise: f64, seed: u64) -> Recording {
    let model = a465::model("kinsheel2010").unwrap();
    let half = noise * 3f64.sqrt();
    let tau = torques_with_friction(&model, s, &mut Rng(seed), |r| r.uniform(-half, half));
    Recording::new(
        "excitation log",
        6,
        s.t.clone(),
        s.q.clone(),
        tau,
        None,
        None,
    )
    .unwrap()
}

fn averaged(periods: PeriodOptions) -> PreprocessOptions {
    PreprocessOptions {
        rate: RATE,
        decimate: 1,
        periods: Some(periods),
        ..PreprocessOptions::default()
    }
}

/// A direct fit with viscous and Coulomb friction, the terms the logs are made with.
fn viscous_and_coulomb() -> BaseOptions {
    BaseOptions {
        friction: FrictionTerms {
            viscous: true,
            coulomb: true,
            ..FrictionTerms::NONE
        },
        ..BaseOptions::default()
    }
}

fn max_error(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Without noise the averaged period is the excitation itself: positions to 1e-12, its
/// velocities and accelerations (the series' derivatives, no numerical differences) to 1e-10,
/// and the torques within their band; the noise measured is none.
#[test]
fn the_average_of_a_noise_free_log_is_the_excitation() {
    let traj = a465_excitation(&mut Rng(21));
    let s = samples(&traj, 0.0, 3.0);
    let rec = log(&s, 0.0, 1);
    let out = preprocess(&rec, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    assert_eq!(out.len(), (PERIOD * RATE) as usize);
    let truth = traj.sample(&out.t);
    assert!(max_error(&out.q, &truth.q) < 1e-12);
    assert!(max_error(out.qd.as_ref().unwrap(), &truth.qd) < 1e-10);
    assert!(max_error(out.qdd.as_ref().unwrap(), &truth.qdd) < 1e-10);
    let a = out.period_average.as_ref().unwrap();
    assert_eq!(
        (a.periods, a.harmonics, a.torque_harmonics, a.samples),
        (3, 5, 100, 5000)
    );
    assert!(a.left_out.is_empty());
    for v in [
        &a.position_noise,
        &a.velocity_noise,
        &a.torque_noise,
        &a.position_beyond,
    ] {
        assert!(v.iter().all(|x| *x < 1e-9), "{v:?}");
    }
    // the torques of the averaged states, but for the Coulomb steps the band leaves smooth
    let model = a465::model("kinsheel2010").unwrap();
    let smooth = Samples {
        qd: truth.qd.clone(),
        ..truth.clone()
    };
    let tau = torques_with_friction(&model, &smooth, &mut Rng(0), |_| 0.0);
    let coulomb = out.coulomb.as_ref().unwrap();
    let band: Vec<f64> = (0..tau.len())
        .map(|i| tau[i] - 0.8 * truth.qd[i].signum() + 0.8 * coulomb[i])
        .collect();
    assert!(
        max_error(&out.tau, &band) < 1e-8,
        "{}",
        max_error(&out.tau, &band)
    );
}

/// The torques' noise is measured from the periods' spread (white noise of 0.05 N m keeps
/// `sqrt(201 / 5000)` of itself in a band of 100 harmonics over 5,000 samples), the average
/// carries it over `sqrt(P)`, and the base parameters fitted to the average leave a residual
/// of that noise: the model's error is none.
#[test]
fn the_noise_is_measured_from_the_periods_and_the_fit_leaves_only_it() {
    let traj = a465_excitation(&mut Rng(21));
    let s = samples(&traj, 0.0, 6.0);
    let rec = log(&s, 0.05, 7);
    let out = preprocess(&rec, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    let a = out.period_average.as_ref().unwrap();
    // noise alone does not drift
    assert!(
        a.torque_drift.iter().all(|f| f.is_some_and(|f| f < 2.0)),
        "{:?}",
        a.torque_drift
    );
    let expected = 0.05 * (201.0f64 / 5000.0).sqrt();
    for (j, x) in a.torque_noise.iter().enumerate() {
        assert!(
            (x / expected - 1.0).abs() < 0.15,
            "joint {}: {x} against {expected}",
            j + 1
        );
    }
    let model = a465::model("kinsheel2010").unwrap();
    let options = viscous_and_coulomb();
    let fit = identify_base_parameters(&model, &out.states().unwrap(), &out.tau, &options).unwrap();
    for (j, (r, n)) in fit
        .residual_rms
        .iter()
        .zip(a.averaged_torque_noise())
        .enumerate()
    {
        assert!(
            (r / n - 1.0).abs() < 0.25,
            "joint {}: residual {r} against the noise {n}",
            j + 1
        );
    }
    // the friction the log was made with, within the standard errors
    for j in 1..=6 {
        for (term, truth) in [("viscous", 0.3), ("coulomb", 0.8)] {
            let i = fit
                .base
                .names()
                .iter()
                .position(|n| *n == format!("joint{j}.{term}"))
                .unwrap();
            assert!(
                (fit.theta[i] - truth).abs() < 4.0 * fit.stderr[i] + 1e-3,
                "joint {j} {term}: {} +- {}",
                fit.theta[i],
                fit.stderr[i]
            );
        }
    }
}

/// A log that starts at rest before the excitation: its start is found, and a period in
/// which something pushed on joint 2 is left out and said, the others averaged.
#[test]
fn a_lead_in_is_found_and_a_disturbed_period_left_out() {
    let traj = a465_excitation(&mut Rng(21));
    let lead_in = 3.3;
    let s = samples(&traj, lead_in, 5.0);
    let mut rec = log(&s, 0.01, 3);
    let found = excitation_start(&rec, &traj).unwrap();
    assert!((found.start - lead_in).abs() < 1e-6, "{found:?}");
    assert_eq!(found.periods, 5);
    assert!(found.tracking_rms.iter().all(|x| *x < 1e-6));
    // a push of 0.5 N m on joint 2 for a second of the third period
    for i in 0..rec.len() {
        let t = rec.t[i] - lead_in;
        if (22.0..23.0).contains(&t) {
            rec.tau[i * 6 + 1] += 0.5;
        }
    }
    let periods = PeriodOptions {
        start: Some(found.start),
        count: Some(found.periods),
        ..PeriodOptions::new(PERIOD, 5)
    };
    let out = preprocess(&rec, &averaged(periods)).unwrap();
    let a = out.period_average.as_ref().unwrap();
    assert_eq!(a.periods, 4);
    assert_eq!(a.left_out.len(), 1, "{:?}", a.left_out);
    assert_eq!(a.left_out[0].period, 2);
    assert!(
        a.left_out[0].reason.contains("joint 2's torques"),
        "{}",
        a.left_out[0].reason
    );
    let w =
        perturbid_rs::logs::period_average::warning(&out.period_average, "log.csv", &[]).unwrap();
    assert!(
        w.contains("1 of its periods left out") && w.contains("period 3"),
        "{w}"
    );
    assert!((out.t[0] - lead_in).abs() < 1e-6);
    let truth = traj.sample(&out.t.iter().map(|t| t - lead_in).collect::<Vec<f64>>());
    assert!(max_error(out.qd.as_ref().unwrap(), &truth.qd) < 1e-6);
    // from the log's first sample instead: the periods from there repeat too (at another
    // phase), but for the first, which holds the rest, and the pushed one
    let out = preprocess(&rec, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    let a = out.period_average.as_ref().unwrap();
    assert_eq!(a.periods, 3);
    let left: Vec<(usize, bool)> = a
        .left_out
        .iter()
        .map(|l| (l.period, l.reason.contains("positions")))
        .collect();
    assert_eq!(left, [(0, true), (2, false)], "{:?}", a.left_out);
    // with two periods, one of them the rest's, nothing tells which is off: refused
    let e = refused(
        &rec.rows(0, (13.3 * RATE) as usize + 5000).unwrap(),
        &averaged(PeriodOptions::new(PERIOD, 5)),
    );
    assert!(e.contains("does not repeat with that period"), "{e}");
}

/// The error of a preprocessing expected to fail (a recording's Debug is long).
fn refused(rec: &Recording, o: &PreprocessOptions) -> String {
    match preprocess(rec, o) {
        Ok(out) => panic!("{} samples made", out.len()),
        Err(e) => e.to_string(),
    }
}

/// A period holding a gap is left out; fewer than two periods, a wrong period and options
/// out of range are refused by name.
#[test]
fn gaps_short_logs_wrong_periods_and_bad_options() {
    let traj = a465_excitation(&mut Rng(21));
    let s = samples(&traj, 0.0, 4.0);
    let rec = log(&s, 0.01, 5);
    // 0.5 s missing in the second period
    let keep: Vec<usize> = (0..rec.len())
        .filter(|&i| !(12.0..12.5).contains(&rec.t[i]))
        .collect();
    let rows = |x: &[f64]| -> Vec<f64> {
        keep.iter()
            .flat_map(|&i| x[i * 6..i * 6 + 6].to_vec())
            .collect()
    };
    let gappy = Recording::new(
        "gappy",
        6,
        keep.iter().map(|&i| rec.t[i]).collect(),
        rows(&rec.q),
        rows(&rec.tau),
        None,
        None,
    )
    .unwrap();
    let out = preprocess(&gappy, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    let a = out.period_average.as_ref().unwrap();
    assert_eq!(a.periods, 3);
    assert!(
        a.left_out[0].period == 1 && a.left_out[0].reason.contains("a gap of 0.502"),
        "{:?}",
        a.left_out
    );
    // one and a half periods
    let short = rec.rows(0, 7500).unwrap();
    let e = refused(&short, &averaged(PeriodOptions::new(PERIOD, 5)));
    assert!(
        e.contains("it holds 1 whole periods of 10 s") && e.contains("at least 2"),
        "{e}"
    );
    // the wrong period
    let e = refused(&rec, &averaged(PeriodOptions::new(9.0, 5)));
    assert!(
        e.contains("joint 1's positions differ from period to period"),
        "{e}"
    );
    for (options, says) in [
        (PeriodOptions::new(f64::NAN, 5), "a period of NaN s"),
        (PeriodOptions::new(0.0, 5), "a period of 0 s"),
        (PeriodOptions::new(1e9, 5), "a period of 1e9 s"),
        (PeriodOptions::new(PERIOD, 0), "0 harmonics"),
        (
            PeriodOptions {
                start: Some(-5.0),
                ..PeriodOptions::new(PERIOD, 5)
            },
            "before the log's first sample",
        ),
        (
            PeriodOptions {
                count: Some(1),
                ..PeriodOptions::new(PERIOD, 5)
            },
            "at least 2 periods averaged",
        ),
    ] {
        let e = refused(&rec, &averaged(options));
        assert!(e.contains(says), "{says}: {e}");
    }
    let o = PreprocessOptions {
        cutoff: Some(300.0),
        ..averaged(PeriodOptions::new(PERIOD, 5))
    };
    assert!(refused(&rec, &o).contains("expected 0 < cutoff < rate / 2"));
    let o = PreprocessOptions {
        filter_position: true,
        ..averaged(PeriodOptions::new(PERIOD, 5))
    };
    assert!(refused(&rec, &o).contains("filter_position does not apply"));
    // values past f64's range in their squares
    let huge = Recording::new(
        "huge",
        6,
        rec.t.clone(),
        rec.q.clone(),
        rec.tau.iter().map(|x| x * 1e300).collect(),
        None,
        None,
    )
    .unwrap();
    let e = refused(&huge, &averaged(PeriodOptions::new(PERIOD, 5)));
    assert!(
        e.contains("joint 1's torques") && e.contains("past f64's range"),
        "{e}"
    );
    // the excitation of another robot, or a log that is none of it
    let other = FourierTrajectory::new(
        traj.w_f,
        vec![0.0; 2],
        traj.a.rows(0, 2).into(),
        traj.b.rows(0, 2).into(),
    )
    .unwrap();
    assert!(excitation_start(&rec, &other)
        .unwrap_err()
        .to_string()
        .contains("6 joints, the log's"));
    let still = Recording::new(
        "still",
        6,
        rec.t.clone(),
        vec![0.3; rec.q.len()],
        rec.tau.clone(),
        None,
        None,
    )
    .unwrap();
    let e = excitation_start(&still, &traj).unwrap_err().to_string();
    assert!(e.contains("follows the excitation"), "{e}");
}

/// Stamps that jitter and positions in coarse encoder counts: the averaged velocities and
/// accelerations stay the excitation's, far closer to it than the filter's numerical
/// derivatives of the same log (measured: 7.5e-6 rad/s and 2.0e-5 rad/s^2 RMS against 7.0e-4
/// and 3.4e-2).
#[test]
fn jittered_stamps_and_coarse_counts_average_out() {
    let traj = a465_excitation(&mut Rng(21));
    let mut rng = Rng(9);
    let count = (4.0 * PERIOD * RATE) as usize;
    let t: Vec<f64> = (0..count)
        .map(|i| i as f64 / RATE + if i > 0 { rng.uniform(-4e-4, 4e-4) } else { 0.0 })
        .collect();
    let s = traj.sample(&t);
    let model = a465::model("kinsheel2010").unwrap();
    let tau = torques_with_friction(&model, &s, &mut rng, |r| r.uniform(-0.03, 0.03));
    // 2^14 counts a turn
    let step = std::f64::consts::TAU / 16384.0;
    let q: Vec<f64> = s.q.iter().map(|x| (x / step).round() * step).collect();
    let rec = Recording::new("coarse", 6, t, q, tau, None, None).unwrap();
    let out = preprocess(&rec, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    let truth = traj.sample(&out.t);
    let (qd, qdd) = (out.qd.as_ref().unwrap(), out.qdd.as_ref().unwrap());
    let filtered = preprocess(
        &rec,
        &PreprocessOptions {
            rate: RATE,
            decimate: 1,
            ..PreprocessOptions::default()
        },
    )
    .unwrap();
    let truth_f = traj.sample(&filtered.t);
    let rms = |a: &[f64], b: &[f64]| {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    };
    let (avg_qd, avg_qdd) = (rms(qd, &truth.qd), rms(qdd, &truth.qdd));
    let (f_qd, f_qdd) = (
        rms(filtered.qd.as_ref().unwrap(), &truth_f.qd),
        rms(filtered.qdd.as_ref().unwrap(), &truth_f.qdd),
    );
    assert!(
        avg_qd < 2e-4 && avg_qdd < 1e-3,
        "averaged: qd {avg_qd}, qdd {avg_qdd}"
    );
    assert!(
        avg_qd * 20.0 < f_qd && avg_qdd * 100.0 < f_qdd,
        "averaged {avg_qd}, {avg_qdd}; filtered {f_qd}, {f_qdd}"
    );
    // the rounding's noise is measured too: a count's uniform noise, sqrt(11 / 5000) of
    // step / sqrt(12) within 5 harmonics, at most (the excitation's slower joints round alike
    // from period to period, and show less)
    let a = out.period_average.as_ref().unwrap();
    let most = step / 12f64.sqrt() * (11.0f64 / 5000.0).sqrt();
    assert!(
        a.position_noise.iter().all(|x| *x < 1.5 * most),
        "{:?} against {most}",
        a.position_noise
    );
}

/// Friction that grows over the run (a joint warming): the drift is found on that joint and
/// said, the others' torques judged steady.
#[test]
fn torques_that_drift_over_the_periods_are_said() {
    let traj = a465_excitation(&mut Rng(21));
    let s = samples(&traj, 0.0, 6.0);
    let mut rec = log(&s, 0.02, 11);
    // joint 3's Coulomb friction from 0.8 to 1.1 N m over the minute
    let end = rec.t[rec.len() - 1];
    for i in 0..rec.len() {
        rec.tau[i * 6 + 2] += 0.3 * rec.t[i] / end * s.qd[i * 6 + 2].signum();
    }
    let out = preprocess(&rec, &averaged(PeriodOptions::new(PERIOD, 5))).unwrap();
    let a = out.period_average.as_ref().unwrap();
    let drift: Vec<f64> = a.torque_drift.iter().map(|f| f.unwrap()).collect();
    assert!(drift[2] > 10.0, "{drift:?}");
    assert!(
        (0..6).filter(|&j| j != 2).all(|j| drift[j] < 2.0),
        "{drift:?}"
    );
    let w =
        perturbid_rs::logs::period_average::warning(&out.period_average, "log.csv", &[]).unwrap();
    assert!(
        w.contains("its torques drift from period to period (joint 3 (F = "),
        "{w}"
    );
    // a saved finding is checked on load
    use perturbid_rs::Document;
    let model = a465::model("kinsheel2010").unwrap();
    let options = viscous_and_coulomb();
    let fit = identify_base_parameters(&model, &out.states().unwrap(), &out.tau, &options)
        .unwrap()
        .with_findings_of(&out);
    let text = fit.to_json();
    assert!(perturbid_rs::direct::BaseModel::from_json(&text).is_ok());
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["log_period_average"]["torque_drift"][0] = serde_json::json!(-1.0);
    let e = perturbid_rs::direct::BaseModel::from_json(&doc.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("log_period_average: torque_drift"), "{e}");
}
