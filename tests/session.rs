//! A whole session's log, the plan's experiments run one after the other with moves and pauses
//! between them, split into one recording per experiment (`local::session`): the model from
//! the split log is the one from the separate recordings; out of order or missing runs are named.

mod common;

use common::{a465_noisy_runs, worst_in_stderr};
use perturbid_rs::local::{
    gaps_in_runs, identify_local, position_misfit, repeated_runs, split_session, CrossingTimes,
    IdentifyOptions, SplitOptions,
};
use perturbid_rs::Recording;

/// One log of `recs` in the given order, on one clock starting at 1000 s: a homing move of 2 s
/// from elsewhere first, and between two runs a smooth move of `pause` s from one's last
/// posture to the next one's first (torques held), all at the runs' sample interval.
fn session(recs: &[&Recording], pause: f64) -> Recording {
    let n = recs[0].n;
    let dt = recs[0].t[1] - recs[0].t[0];
    let (mut t, mut q, mut tau) = (vec![], vec![], vec![]);
    let mut now = 1000.0;
    let step = |t: &mut Vec<f64>, now: &mut f64| {
        t.push(*now);
        *now += dt;
    };
    let moving = |from: &[f64],
                  to: &[f64],
                  torque: &[f64],
                  seconds: f64,
                  t: &mut Vec<f64>,
                  q: &mut Vec<f64>,
                  tau: &mut Vec<f64>,
                  now: &mut f64| {
        let k = (seconds / dt).round() as usize;
        for i in 0..k {
            let s = 0.5 - 0.5 * (std::f64::consts::PI * i as f64 / k as f64).cos();
            q.extend((0..n).map(|j| from[j] + s * (to[j] - from[j])));
            tau.extend_from_slice(torque);
            step(t, now);
        }
    };
    let elsewhere: Vec<f64> = recs[0].q[..n].iter().map(|v| v + 0.4).collect();
    moving(
        &elsewhere,
        &recs[0].q[..n],
        &recs[0].tau[..n],
        2.0,
        &mut t,
        &mut q,
        &mut tau,
        &mut now,
    );
    for (k, r) in recs.iter().enumerate() {
        for i in 0..r.len() {
            q.extend_from_slice(&r.q[i * n..(i + 1) * n]);
            tau.extend_from_slice(&r.tau[i * n..(i + 1) * n]);
            step(&mut t, &mut now);
        }
        let last = &r.q[(r.len() - 1) * n..];
        let next = recs.get(k + 1).map_or(last, |x| &x.q[..n]);
        let held = &r.tau[(r.len() - 1) * n..];
        moving(
            last,
            next,
            held,
            pause + 0.3 * k as f64,
            &mut t,
            &mut q,
            &mut tau,
            &mut now,
        );
    }
    Recording::new("session.csv", n, t, q, tau, None, None).unwrap()
}

#[test]
fn a_session_log_splits_into_the_runs_that_identify_as_the_separate_recordings() {
    let (plan, recs) = a465_noisy_runs();
    let log = session(&recs.iter().collect::<Vec<_>>(), 1.5);
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    assert_eq!(split.len(), plan.experiments.len());
    // each experiment ran once (H's passes follow D's plan within the position check, and are
    // not taken for a second run of D)
    let repeated = repeated_runs(&plan, &log, &split).unwrap();
    assert!(repeated.is_empty(), "{repeated:?}");
    assert!(gaps_in_runs(&plan, &log, &split).is_empty());
    // the first run starts after the 2 s homing move, at 1002 s of the log
    assert!((split[0].1 - 1002.0).abs() < 2e-3, "{}", split[0].1);
    for ((run, _), e) in split.iter().zip(&plan.experiments) {
        assert_eq!(run.experiment.as_deref(), Some(e.kind.name()));
        assert_eq!(run.name, format!("session.csv [{}]", e.kind.name()));
        // the run on the plan's clock, with the margin either side
        let (first, last) = (run.t[0], run.t[run.len() - 1]);
        assert!((first + 0.2).abs() < 2e-3, "{first}");
        assert!((last - e.trajectory.end() - 0.2).abs() < 2e-3, "{last}");
    }
    let split: Vec<Recording> = split.into_iter().map(|(r, _)| r).collect();
    let from_log = identify_local(&plan, &split, &IdentifyOptions::default()).unwrap();
    for o in &from_log.diagnostics.offsets {
        assert!(o.offset.abs() < 2e-3, "{o:?}");
    }
    let separate = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let worst = worst_in_stderr(&from_log, &separate);
    assert!(worst < 0.05, "{worst}");
}

#[test]
fn runs_out_of_order_missing_or_of_other_joints_are_named() {
    let (plan, recs) = a465_noisy_runs();
    let kinds: Vec<&str> = recs
        .iter()
        .map(|r| r.experiment.as_deref().unwrap())
        .collect();
    let at = |k: &str| kinds.iter().position(|x| *x == k).unwrap();
    let o = SplitOptions::default();
    // D run before H: H is found, and then no room is left for D after it
    let mut swapped: Vec<&Recording> = recs.iter().collect();
    swapped.swap(at("H"), at("D"));
    let e = split_session(&plan, &session(&swapped, 1.0), &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("experiment 'D': its run") && e.contains("in the plan's order"),
        "{e}"
    );
    // H never run: D's run fits D better, and nothing before it follows H's plan
    let missing: Vec<&Recording> = recs
        .iter()
        .filter(|r| r.experiment.as_deref() != Some("H"))
        .collect();
    let e = split_session(&plan, &session(&missing, 1.0), &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("experiment 'H': its run") && e.contains("where experiment 'D' fits better"),
        "{e}"
    );
    // a log of five joints
    let log = session(&recs.iter().collect::<Vec<_>>(), 1.0);
    let five = Recording::new(
        "five.csv",
        5,
        log.t.clone(),
        log.q.chunks(6).flat_map(|r| r[..5].to_vec()).collect(),
        log.tau.chunks(6).flat_map(|r| r[..5].to_vec()).collect(),
        None,
        None,
    )
    .unwrap();
    let e = split_session(&plan, &five, &o).unwrap_err().to_string();
    assert!(
        e.contains("five.csv: 5 joint columns; the plan is of 6 joints"),
        "{e}"
    );
    // the robot standing still all along: no stretch follows the nominal passes
    let first = log.q[..6].to_vec();
    let still = Recording::new(
        "still.csv",
        6,
        log.t.clone(),
        log.t.iter().flat_map(|_| first.clone()).collect(),
        log.tau.clone(),
        None,
        None,
    )
    .unwrap();
    let e = split_session(&plan, &still, &o).unwrap_err().to_string();
    assert!(
        e.contains("experiment 'nominal': no stretch of the log after 1000 s follows its plan")
            && e.contains("moved 0.0000 RMS"),
        "{e}"
    );
    let e = split_session(&plan, &log, &SplitOptions { margin: -1.0 })
        .unwrap_err()
        .to_string();
    assert!(e.contains("margin"), "{e}");
}

#[test]
fn a_runs_position_check_reads_the_runs_own_samples_however_long_the_session() {
    let (plan, recs) = a465_noisy_runs();
    // about 6 minutes of moves between the runs
    let log = session(&recs.iter().collect::<Vec<_>>(), 60.0);
    assert!(log.len() > 300_000, "{}", log.len());
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    for ((_, d), e) in split.iter().zip(&plan.experiments) {
        // the run with a second of the log either side, on the log's clock
        let rows: Vec<usize> = (0..log.len())
            .filter(|&i| {
                log.t[i] >= e.trajectory.start() + d - 1.0
                    && log.t[i] <= e.trajectory.end() + d + 1.0
            })
            .collect();
        let n = log.n;
        let excerpt = Recording::new(
            "excerpt.csv",
            n,
            rows.iter().map(|&i| log.t[i]).collect(),
            rows.iter()
                .flat_map(|&i| log.q[i * n..(i + 1) * n].to_vec())
                .collect(),
            rows.iter()
                .flat_map(|&i| log.tau[i * n..(i + 1) * n].to_vec())
                .collect(),
            None,
            None,
        )
        .unwrap();
        let in_log = position_misfit(e, &log, *d).unwrap();
        assert_eq!(in_log, position_misfit(e, &excerpt, *d).unwrap());
    }
}

#[test]
fn a_session_log_given_as_one_experiments_recording_is_named_or_read_at_its_run() {
    let (plan, recs) = a465_noisy_runs();
    let log = session(&recs.iter().collect::<Vec<_>>(), 20.0);
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    // the session on a clock from 0, given as D's recording
    let at = plan
        .experiments
        .iter()
        .position(|e| e.kind.name() == "D")
        .unwrap();
    let run = split[at].1 - 1000.0;
    assert!(run > 60.0, "{run}");
    let mut whole = log.clone();
    whole.t.iter_mut().for_each(|t| *t -= 1000.0);
    whole.experiment = Some("D".into());
    let mut given = recs.clone();
    given[at] = whole;
    let e = identify_local(&plan, &given, &IdentifyOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("'D' best with its clock {run:+.3} s ahead"))
            && e.contains("perturbid split, Plan.split_session"),
        "{e}"
    );
    // with the tolerance raised, the run itself (the nominal passes repeat every 0.3 s: a
    // grid of max_shift / 200 found a repetition 1.2 s early)
    let o = IdentifyOptions {
        times: CrossingTimes::Detected {
            max_shift: 1.1 * run,
        },
        ..IdentifyOptions::default()
    };
    let model = identify_local(&plan, &given, &o).unwrap();
    let found = model
        .diagnostics
        .offsets
        .iter()
        .find(|x| x.experiment == "D")
        .unwrap();
    assert!((found.offset - run).abs() < 2e-3, "{found:?} {run}");
}

/// The runs are placed on the plan's clock to well below a sample, by the clock search of a
/// single recording: the log's clock 0.37 ms off the plan's samples, each run's time stamps come
/// out on the plan's within 1 us on these noisy positions (the split's own search, a grid
/// refined to 1 ms or finer, left the nominal run 50 us off).
#[test]
fn a_session_off_the_plans_sample_clock_splits_onto_it_below_a_sample() {
    let (plan, recs) = a465_noisy_runs();
    let mut log = session(&recs.iter().collect::<Vec<_>>(), 1.5);
    for t in &mut log.t {
        *t += 0.37e-3;
    }
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    for ((run, d), rec) in split.iter().zip(&recs) {
        // the run's sample nearest the recording's 100th is that sample, at its time
        let at = rec.t[100];
        let nearest = run
            .t
            .iter()
            .map(|t| t - at)
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap();
        assert!(nearest.abs() < 1e-5, "{}: {nearest} (d = {d})", run.name);
    }
}

/// An experiment run twice (H rerun after it, then D): the split takes one run and names the
/// other stretch, where it took one without a word; each of the others ran once.
#[test]
fn an_experiment_run_twice_is_named_with_both_stretches() {
    let (plan, recs) = a465_noisy_runs();
    let h = plan
        .experiments
        .iter()
        .position(|e| e.kind.name() == "H")
        .unwrap();
    let mut order: Vec<&Recording> = recs.iter().collect();
    order.insert(h + 1, &recs[h]);
    let log = session(&order, 1.5);
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    let repeated = repeated_runs(&plan, &log, &split).unwrap();
    assert_eq!(repeated.len(), 1, "{repeated:?}");
    // runs that are not the split's, one each, are refused, not indexed
    let e = repeated_runs(&plan, &log, &split[1..])
        .unwrap_err()
        .to_string();
    assert!(e.contains("4 runs for the plan's 5 experiments"), "{e}");
    let taken = split[h].1 + plan.experiments[h].trajectory.start();
    assert!(
        repeated[0].starts_with("experiment 'H' seems to have run twice in session.csv: its plan is followed also from ")
            && repeated[0].contains(&format!("the run from {} s", (taken * 1e3).round() / 1e3)),
        "{}",
        repeated[0]
    );
}

/// A stretch of a run without samples, lost or skipped by a step of the log's clock, is named
/// with the experiment, its length and where it lies in the log and on the plan's clock; a gap
/// between the runs is none of a run's.
#[test]
fn a_gap_inside_a_run_is_named() {
    let (plan, recs) = a465_noisy_runs();
    let log = session(&recs.iter().collect::<Vec<_>>(), 1.5);
    let split = split_session(&plan, &log, &SplitOptions::default()).unwrap();
    let n = log.n;
    let without = |from: f64, to: f64, step: f64| {
        let keep: Vec<usize> = (0..log.len())
            .filter(|&i| log.t[i] < from || log.t[i] >= to)
            .collect();
        let rows = |v: &[f64]| -> Vec<f64> {
            keep.iter()
                .flat_map(|&i| v[i * n..(i + 1) * n].to_vec())
                .collect()
        };
        let t = keep
            .iter()
            .map(|&i| log.t[i] + if log.t[i] >= to { step } else { 0.0 })
            .collect();
        Recording::new(
            "session.csv",
            n,
            t,
            rows(&log.q),
            rows(&log.tau),
            None,
            None,
        )
        .unwrap()
    };
    // 0.3 s lost in the middle of the third experiment's run
    let (e, d) = (&plan.experiments[2], split[2].1);
    let middle = d + 0.5 * (e.trajectory.start() + e.trajectory.end());
    let lost = without(middle, middle + 0.3, 0.0);
    let runs = split_session(&plan, &lost, &SplitOptions::default()).unwrap();
    let w = gaps_in_runs(&plan, &lost, &runs);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(&format!(
            "experiment '{}': session.csv has no sample for 0.3",
            e.kind.name()
        )) && w[0].contains("samples were lost there, or the log's clock stepped"),
        "{w:?}"
    );
    // the log's clock stepping 5 s forward there: named alike
    let stepped = without(middle, middle + 0.001, 5.0);
    let runs = split_session(&plan, &stepped, &SplitOptions::default()).unwrap();
    let w = gaps_in_runs(&plan, &stepped, &runs);
    assert!(
        w.iter().any(|w| w.contains("has no sample for 5.00")),
        "{w:?}"
    );
    // 0.3 s lost between the second and the third runs: no run's
    let between = split[1].1 + plan.experiments[1].trajectory.end() + 0.5;
    let outside = without(between, between + 0.3, 0.0);
    let runs = split_session(&plan, &outside, &SplitOptions::default()).unwrap();
    assert!(gaps_in_runs(&plan, &outside, &runs).is_empty());
}
