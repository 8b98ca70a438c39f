//! Glitches in a whole log, found and replaced before preprocessing (src/logs/log_screening.rs):
//! spikes and rows of zeros leave the direct method's parameters where the clean log puts
//! them (and move them by many standard errors unscreened); velocity reversals' Coulomb steps
//! and clean noise are left alone; a replaced value is the cubic fit of the others in its
//! window, checked against an independent least-squares fit; windows stop at gaps; rows of
//! zeros while the robot moves (dropouts) are removed, and zeros at rest kept; saved glitches
//! and dropouts are checked on load; the real Panda log loses nothing but stale positions.

mod common;

use common::{
    a465_noisy_log, fit_preprocessed, moved_in_stderr, panda_log, panda_model, refused_on_load,
};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions};
use perturbid_rs::document::Document;
use perturbid_rs::logs::log_dropouts::find_dropouts;
use perturbid_rs::logs::log_screening::{screen_recording, warning, LogGlitch, HALF_WINDOW};
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::{Recording, States};

fn identify(rec: &Recording, screen: bool) -> (Recording, BaseModel) {
    let options = PreprocessOptions {
        screen_glitches: screen,
        ..PreprocessOptions::default()
    };
    fit_preprocessed(rec, &options)
}

/// Each glitch `found` was replaced in `screened` near the `clean` log's value (its noise:
/// 1e-5 rad for positions, 0.15 N m for torques).
fn replaced_near_clean(found: &[LogGlitch], screened: &Recording, clean: &Recording) {
    let n = clean.n;
    for g in found {
        let (x, y) = match g.signal.as_str() {
            "q" => (
                screened.q[g.sample * n + g.joint],
                clean.q[g.sample * n + g.joint],
            ),
            _ => (
                screened.tau[g.sample * n + g.joint],
                clean.tau[g.sample * n + g.joint],
            ),
        };
        assert_eq!(x, g.replaced_by);
        let tolerance = if g.signal == "q" { 1e-5 } else { 0.15 };
        assert!((x - y).abs() < tolerance, "{g:?}: {x} against {y}");
    }
}

#[test]
fn a_clean_log_with_velocity_reversals_is_left_alone() {
    let rec = a465_noisy_log();
    // the torques step at velocity reversals (Coulomb friction of 0.8 N m, 27 noise levels)
    let reversals = (1..rec.len())
        .filter(|&i| {
            (0..6).any(|j| {
                let (a, b) = (rec.tau[(i - 1) * 6 + j], rec.tau[i * 6 + j]);
                (a - b).abs() > 1.2
            })
        })
        .count();
    assert!(reversals > 10, "{reversals}");
    let (screened, found) = screen_recording(&rec).unwrap();
    assert!(found.is_empty(), "{found:?}");
    assert_eq!(screened, rec);
}

#[test]
fn spikes_and_a_row_of_zeros_are_replaced_and_leave_the_parameters_alone() {
    let clean = a465_noisy_log();
    let (_, reference) = identify(&clean, true);
    let mut rec = clean.clone();
    let n = 6;
    rec.tau[4000 * n + 1] += 50.0; // a torque spike
    rec.tau[5000 * n + 2] = 1e300; // beyond any scale
    rec.q[6000 * n + 2] += 0.05; // a position spike
    for j in 0..n {
        rec.q[7000 * n + j] = 0.0; // a row of positions read as zeros
    }
    rec.tau[8000 * n + 4] += 3.0; // two neighbouring samples
    rec.tau[8001 * n + 4] -= 2.0;
    let (screened, found) = screen_recording(&rec).unwrap();
    let mut at: Vec<(String, usize, usize)> = found
        .iter()
        .map(|g| (g.signal.clone(), g.joint, g.sample))
        .collect();
    at.sort();
    let mut expected: Vec<(String, usize, usize)> = vec![
        ("tau".into(), 1, 4000),
        ("tau".into(), 2, 5000),
        ("q".into(), 2, 6000),
        ("tau".into(), 4, 8000),
        ("tau".into(), 4, 8001),
    ];
    expected.extend((0..n).map(|j| ("q".to_string(), j, 7000)));
    expected.sort();
    assert_eq!(at, expected);
    let g = found.iter().find(|g| g.sample == 5000).unwrap();
    assert_eq!((g.value, g.noise_levels), (1e300, None));
    // replaced near the clean values (a few noise levels), and nothing else touched
    replaced_near_clean(&found, &screened, &clean);
    let changed = |a: &[f64], b: &[f64]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    assert_eq!(
        changed(&screened.q, &rec.q) + changed(&screened.tau, &rec.tau),
        found.len()
    );
    // the parameters: where the clean log puts them when screened, far off when not
    let (p, screened_fit) = identify(&rec, true);
    assert_eq!(p.glitches, found);
    assert!(
        moved_in_stderr(&screened_fit, &reference) < 0.05,
        "{}",
        moved_in_stderr(&screened_fit, &reference)
    );
    let mut unscreened = clean.clone();
    unscreened.q[6000 * n + 2] += 0.05;
    let (p, unscreened_fit) = identify(&unscreened, false);
    assert!(p.glitches.is_empty());
    assert!(
        moved_in_stderr(&unscreened_fit, &reference) > 3.0,
        "{}",
        moved_in_stderr(&unscreened_fit, &reference)
    );
}

/// One joint's reading held or read as zeros for a few rows (its driver's message lost, the
/// last value or zeros logged in its place) while the others are fine: a burst too long for
/// the window test, judged as a run against the cubic through the samples either side.
#[test]
fn held_readings_of_one_joint_are_replaced() {
    let clean = a465_noisy_log();
    let n = 6;
    let (_, reference) = identify(&clean, true);
    let mut rec = clean.clone();
    for i in 4000..4006 {
        rec.tau[i * n + 1] = 0.0; // one joint's torque read as zeros for 6 rows
    }
    for i in 6001..6005 {
        rec.q[i * n + 1] = rec.q[6000 * n + 1]; // one joint's position held for 4 rows
    }
    // a torque held for 7 rows: over 7 ms of this slow excitation it changes by less than
    // its noise, so the repeats are indistinguishable from readings and are kept
    for i in 9001..9008 {
        rec.tau[i * n + 4] = rec.tau[9000 * n + 4];
    }
    let (_, unscreened) = identify(&rec, false);
    assert!(
        moved_in_stderr(&unscreened, &reference) > 0.3,
        "{}",
        moved_in_stderr(&unscreened, &reference)
    );
    let (screened, found) = screen_recording(&rec).unwrap();
    let at = |signal: &str, j: usize| -> Vec<usize> {
        found
            .iter()
            .filter(|g| g.signal == signal && g.joint == j)
            .map(|g| g.sample)
            .collect()
    };
    assert_eq!(at("tau", 1), (4000..4006).collect::<Vec<_>>(), "{found:?}");
    // the held run includes the reading it repeats, replaced within its noise
    assert_eq!(at("q", 1), (6000..6005).collect::<Vec<_>>(), "{found:?}");
    assert_eq!(found.len(), 11, "{found:?}");
    assert_eq!(
        screened.tau[9000 * n + 4..9008 * n + 4],
        rec.tau[9000 * n + 4..9008 * n + 4]
    );
    replaced_near_clean(&found, &screened, &clean);
    for g in &found {
        assert!(g.noise_levels.unwrap() > 10.0, "{g:?}");
        assert_eq!(g.held, Some(if g.signal == "q" { 5 } else { 6 }));
        assert_eq!(g.repeats_previous, ![4000, 6000].contains(&g.sample));
    }
    // the warning lists each held reading once, by its samples
    let warned = warning(&found, "log", &[], "before preprocessing").unwrap();
    assert!(
        warned.contains("11 sample(s) of 2 held reading(s)")
            && warned.contains("tau of joint 2 at t = 4.0011 s (samples 4000 to 4005) held 0 N m")
            && !warned.contains("sample 4001"),
        "{warned}"
    );
    let (_, fit) = identify(&rec, true);
    assert!(
        moved_in_stderr(&fit, &reference) < 0.05,
        "{}",
        moved_in_stderr(&fit, &reference)
    );
    // readings that repeat legitimately are kept: a torque on a coarse grid (0.05 N m, its
    // noise 0.03 N m), repeated many times over while the joint moves, and a joint that holds
    let mut grid = clean.clone();
    for x in &mut grid.tau {
        *x = (*x / 0.05).round() * 0.05;
    }
    let repeats = (1..grid.len())
        .filter(|&i| grid.tau[i * n] == grid.tau[(i - 1) * n])
        .count();
    assert!(repeats > 1000, "{repeats}");
    let (_, found) = screen_recording(&grid).unwrap();
    assert!(found.is_empty(), "{found:?}");
}

#[test]
fn dropouts_are_removed_and_zeros_at_rest_kept() {
    let clean = a465_noisy_log();
    let n = 6;
    let (_, reference) = identify(&clean, true);
    // fifteen rows of torques read as zeros while the robot moves (bridged: under 20 intervals)
    let mut rec = clean.clone();
    for x in &mut rec.tau[7000 * n..7015 * n] {
        *x = 0.0;
    }
    let found = find_dropouts(&rec);
    assert_eq!(found.len(), 1, "{found:?}");
    let d = &found[0];
    assert_eq!(
        (d.signal.as_str(), d.first_sample, d.samples),
        ("tau", 7000, 15)
    );
    assert_eq!((d.from, d.to), (rec.t[7000], rec.t[7014]));
    let (p, fit) = identify(&rec, true);
    assert_eq!(p.dropouts, found);
    assert!(
        moved_in_stderr(&fit, &reference) < 0.1,
        "{}",
        moved_in_stderr(&fit, &reference)
    );
    let (p, fit) = identify(&rec, false);
    assert!(p.dropouts.is_empty());
    assert!(
        moved_in_stderr(&fit, &reference) > 1.0,
        "{}",
        moved_in_stderr(&fit, &reference)
    );
    // a hundred rows leave a gap: refused naming it and the dropout, or split on request
    let mut long = clean.clone();
    for x in &mut long.tau[7000 * n..7100 * n] {
        *x = 0.0;
    }
    let e = preprocess(&long, &PreprocessOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("gap") && e.to_string().contains("after removing 1 dropout"),
        "{e}"
    );
    let split = preprocess(
        &long,
        &PreprocessOptions {
            split_at_gaps: true,
            ..PreprocessOptions::default()
        },
    )
    .unwrap();
    assert_eq!(split.dropouts.len(), 1);
    // zeros while the robot stands still are readings (no gravity, say): kept
    let mut rest = clean.clone();
    let held: Vec<f64> = rest.q[6999 * n..7000 * n].to_vec();
    for i in 7000..=7010 {
        rest.q[i * n..(i + 1) * n].copy_from_slice(&held);
    }
    for x in &mut rest.tau[7000 * n..7010 * n] {
        *x = 0.0;
    }
    assert!(find_dropouts(&rest).is_empty());
    // a hold between two postures: logged velocities read 0 while the positions stand still,
    // though the rows either side of it move
    let mut hold = clean.clone();
    let at: Vec<f64> = hold.q[7000 * n..7001 * n].to_vec();
    for i in 7000..7010 {
        hold.q[i * n..(i + 1) * n].copy_from_slice(&at);
    }
    let mut qd = vec![0.1; hold.len() * n];
    for x in &mut qd[7000 * n..7010 * n] {
        *x = 0.0;
    }
    hold.qd = Some(qd);
    assert_ne!(hold.q[6999 * n..7000 * n], hold.q[7010 * n..7011 * n]);
    assert!(find_dropouts(&hold).is_empty());
    // the same hold read by noisy encoders (1e-5 rad, the whole log): the positions change
    // within it, by their noise alone
    let mut noisy = hold.clone();
    let mut rng = common::Rng(3);
    for x in &mut noisy.q {
        *x += 1e-5 * common::normal(&mut rng);
    }
    assert_ne!(noisy.q[7000 * n..7001 * n], noisy.q[7009 * n..7010 * n]);
    assert!(find_dropouts(&noisy).is_empty());
    // a row of zero positions is a dropout of positions; one row alone is no dropout
    let mut q = clean.clone();
    for x in &mut q.q[3000 * n..3002 * n] {
        *x = 0.0;
    }
    for x in &mut q.q[5000 * n..5001 * n] {
        *x = 0.0;
    }
    let found = find_dropouts(&q);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        (
            found[0].signal.as_str(),
            found[0].first_sample,
            found[0].samples
        ),
        ("q", 3000, 2)
    );
}

/// A replaced value is the least-squares cubic in time through the other samples of its
/// window (its glitch left out), computed here independently by an SVD solve.
#[test]
fn a_glitch_is_replaced_by_the_cubic_through_the_others() {
    let mut rec = a465_noisy_log();
    let (n, i, j) = (6, 3000, 3);
    rec.tau[i * n + j] -= 20.0;
    let (_, found) = screen_recording(&rec).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    let others: Vec<usize> = (i - HALF_WINDOW..=i + HALF_WINDOW)
        .filter(|&m| m != i)
        .collect();
    let v = DMatrix::from_fn(others.len(), 4, |r, d| {
        (rec.t[others[r]] - rec.t[i]).powi(d as i32)
    });
    let y = DVector::from_iterator(others.len(), others.iter().map(|&m| rec.tau[m * n + j]));
    let c = v.svd(true, true).solve(&y, 1e-14).unwrap();
    assert!(
        (found[0].replaced_by - c[0]).abs() < 1e-9,
        "{} against {}",
        found[0].replaced_by,
        c[0]
    );
    assert!(found[0].noise_levels.unwrap() > 100.0);
    assert!(!found[0].repeats_previous);
}

#[test]
fn windows_stop_at_gaps_and_short_stretches_are_not_judged() {
    let mut rec = a465_noisy_log();
    let n = 6;
    // a gap of 1 s after sample 2000: every later time moves on
    for t in &mut rec.t[2001..] {
        *t += 1.0;
    }
    // a spike two samples after the gap is found, judged in a window after it
    rec.tau[2002 * n] += 30.0;
    let (_, found) = screen_recording(&rec).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].sample, found[0].joint), (2002, 0));
    // a stretch shorter than a window between two gaps is not judged
    let mut short = a465_noisy_log();
    for t in &mut short.t[2001..] {
        *t += 1.0;
    }
    for t in &mut short.t[2011..] {
        *t += 1.0;
    }
    short.tau[2005 * n] += 30.0;
    assert!(screen_recording(&short).unwrap().1.is_empty());
    // preprocessing refuses the gap before screening, as before
    let e = preprocess(&short, &PreprocessOptions::default()).unwrap_err();
    assert!(e.to_string().contains("gap"), "{e}");
}

#[test]
fn saved_log_glitches_are_checked_on_load() {
    let mut rec = a465_noisy_log();
    rec.tau[4000 * 6 + 1] += 50.0;
    for x in &mut rec.tau[7000 * 6..7004 * 6] {
        *x = 0.0;
    }
    let (p, fit) = identify(&rec, true);
    let fit = BaseModel {
        log_glitches: p.glitches,
        log_dropouts: p.dropouts,
        ..fit
    };
    assert_eq!((fit.log_glitches.len(), fit.log_dropouts.len()), (1, 1));
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 6] = [
        (
            |v| v["log_glitches"][0]["held"] = 1.into(),
            "log_glitches[0]: held 1",
        ),
        (
            |v| v["log_glitches"][0]["signal"] = "force".into(),
            "log_glitches[0]: signal 'force'",
        ),
        (
            |v| v["log_glitches"][0]["joint"] = 6.into(),
            "log_glitches[0]: joint 6",
        ),
        (
            |v| v["log_glitches"][0]["noise_levels"] = (-1.0).into(),
            "log_glitches[0]: noise_levels",
        ),
        (
            |v| v["log_dropouts"][0]["samples"] = 1.into(),
            "log_dropouts[0]: 1 samples",
        ),
        (
            |v| v["log_dropouts"][0]["to"] = 0.0.into(),
            "log_dropouts[0]: from and to",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}

/// The real Panda log (beside the repository; skipped when absent): its torques and logged
/// velocities have no glitch; the positions its logger repeated with new time stamps, where
/// far off the curve, are replaced, and that moves the identified parameters by a hundredth of
/// their standard errors at most.
#[test]
fn the_real_panda_log_loses_only_stale_positions() {
    let Some(rec) = panda_log() else {
        return;
    };
    let Some(model) = panda_model() else {
        eprintln!("SKIPPED: the Panda URDF of example-robot-data is not installed");
        return;
    };
    let (_, found) = screen_recording(&rec).unwrap();
    assert!(!found.is_empty() && found.len() < 100, "{}", found.len());
    assert!(found.iter().all(|g| g.signal == "q"), "{found:?}");
    assert!(find_dropouts(&rec).is_empty());
    let stale = found.iter().filter(|g| g.repeats_previous).count();
    assert!(stale * 10 >= found.len() * 9, "{stale} of {}", found.len());
    let fit = |screen: bool| {
        let p = preprocess(
            &rec,
            &PreprocessOptions {
                screen_glitches: screen,
                ..PreprocessOptions::default()
            },
        )
        .unwrap();
        let states = States::new(7, &p.q, p.qd.as_deref(), p.qdd.as_deref()).unwrap();
        identify_base_parameters(&model, &states, &p.tau, &BaseOptions::default()).unwrap()
    };
    let (with, without) = (fit(true), fit(false));
    assert!(
        moved_in_stderr(&with, &without) < 0.01,
        "{}",
        moved_in_stderr(&with, &without)
    );
}
