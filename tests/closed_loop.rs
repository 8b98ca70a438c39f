//! The local method on a robot that tracks its plan under a controller (docs/method.md,
//! "Closed-loop identification"): T* carried from the point the nominal passes measured to the
//! planned one, with an uncertainty that covers the truth; the miss reported; advice between
//! the estimators from held-out crossings. Truth is the true robot's own expansion, itself
//! checked against the rigid-body linearisation.

mod common;

use common::{rel, table2};
use perturbid_rs::direct::torque_delay::{estimate_torque_delay, DelayOptions};
use perturbid_rs::local::{
    identify_local, identify_local_rounds, identify_local_with_delay, plan_experiments,
    ExperimentKind, IdentifyOptions, LocalModel, Perturbations, PlanOptions,
};
use perturbid_rs::rehearsal::{
    compare, local_case, realistic_robot, rehearse, rehearse_plan, true_local, Realism, TrueRobot,
};
use perturbid_rs::robots::a465;
use perturbid_rs::simulation::experiment_samples;
use perturbid_rs::{linearize, Data, Gravity, OperatingPoint};

/// Table 2's posture with every joint fast (no joint reverses within its perturbations).
fn all_fast() -> OperatingPoint {
    let p = table2();
    OperatingPoint::new(p.q, vec![0.5, -0.4, 0.45, 0.6, -0.5, 0.55], p.qdd).unwrap()
}

/// A posture of the Panda with every joint fast.
fn panda_all_fast() -> OperatingPoint {
    OperatingPoint::new(
        vec![0.3, -0.5, 0.2, -2.0, 0.3, 1.6, 0.5],
        vec![0.5, -0.4, 0.45, 0.6, -0.5, 0.55, 0.4],
        vec![1.0, -0.8, 0.9, 1.2, -1.0, 0.7, 0.8],
    )
    .unwrap()
}

/// On the nominal robot without friction the true expansion is the rigid-body linearisation.
#[test]
fn the_true_expansion_of_a_frictionless_robot_is_its_linearisation() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = all_fast();
    let truth = true_local(&model, &TrueRobot::default(), &op).unwrap();
    let lin = linearize(
        &model,
        &mut Data::new(&model),
        &op.q,
        &op.qd,
        &op.qdd,
        Gravity::Included,
    )
    .unwrap();
    assert!(rel(&truth.d, &lin.d) < 1e-8, "D {}", rel(&truth.d, &lin.d));
    assert!(rel(&truth.h, &lin.h) < 1e-6, "H {}", rel(&truth.h, &lin.h));
    assert!(rel(&truth.g, &lin.g) < 1e-6, "G {}", rel(&truth.g, &lin.g));
    let t = nalgebra::DVector::from_vec(truth.torque.clone());
    assert!((t - &lin.torque).norm() < 1e-9 * lin.torque.norm());
}

/// The plan rehearsed on `robot` with the nominal experiment's reference moved by `shift[j]`
/// planned position perturbations on joint j (its passes then miss P in q alike, as a
/// tracking robot's do), identified by default.
fn shifted_nominal(
    robot: &TrueRobot,
    shift: &[f64],
) -> (LocalModel, perturbid_rs::rehearsal::TrueLocal) {
    let model = a465::model("kinsheel2010").unwrap();
    let op = all_fast();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let sizes = Perturbations::of_plan(&plan).unwrap();
    let recordings: Vec<_> = (plan.experiments.iter().enumerate())
        .map(|(i, e)| {
            let mut reference = experiment_samples(&model, &plan, e).unwrap();
            if e.kind == ExperimentKind::Nominal {
                for (x, j) in reference.q.iter_mut().zip((0..6).cycle()) {
                    *x += shift[j] * sizes.q[j];
                }
            }
            rehearse(&model, robot, &reference, i as u64, e.kind.name())
                .unwrap()
                .for_experiment(e.kind.name())
        })
        .collect();
    let local = identify_local(&plan, &recordings, &IdentifyOptions::default()).unwrap();
    (local, true_local(&model, robot, &op).unwrap())
}

/// Nominal passes that miss P alike (by 0.3 of the position perturbations): their mean
/// torque is off the truth by far more than its scatter says; T* carried to the planned point
/// by the model's own matrices is within 3 of its standard errors, which count the
/// correction's uncertainty.
#[test]
fn t_star_is_carried_across_a_miss_of_the_nominal_passes() {
    let model = a465::model("kinsheel2010").unwrap();
    let (mut inside, mut count, mut raw_worst) = (0, 0, 0.0f64);
    for seed in 0..3 {
        let realism = Realism {
            seed,
            bandwidth: None,
            delay: 0.0,
            ..Realism::default()
        };
        let robot = realistic_robot(&model, &all_fast().q, &realism).unwrap();
        let (local, truth) = shifted_nominal(&robot, &[0.3; 6]);
        let miss = local.miss.as_ref().unwrap();
        for j in 0..6 {
            assert!((miss.q_perturbations[j] - 0.3).abs() < 0.01, "{miss:?}");
            assert!((miss.measured_torque[j] - miss.correction[j] - local.torque[j]).abs() < 1e-9);
            count += 1;
            inside += usize::from(
                (local.torque[j] - truth.torque[j]).abs() <= 3.0 * local.torque_stderr[j],
            );
            raw_worst = raw_worst
                .max((miss.measured_torque[j] - truth.torque[j]).abs() / miss.measured_stderr[j]);
        }
        let summary = local.summary("model.json");
        assert!(summary.contains("the nominal passes missed the operating point by (in perturbations, per joint): q +0.30"), "{summary}");
        assert!(!local
            .diagnostics
            .warnings
            .iter()
            .any(|w| w.contains("missed the operating point")));
    }
    assert!(
        inside as f64 >= 0.9 * count as f64,
        "{inside} of {count} within 3 standard errors"
    );
    assert!(
        raw_worst > 10.0,
        "the mean at the nominal crossings is off by {raw_worst:.1} of its own standard errors"
    );
}

/// A miss past the perturbations is named, with the joint and the remedy; one within them is
/// not (above).
#[test]
fn a_miss_past_the_perturbations_is_warned_of() {
    let model = a465::model("kinsheel2010").unwrap();
    let realism = Realism {
        bandwidth: None,
        delay: 0.0,
        ..Realism::default()
    };
    let robot = realistic_robot(&model, &all_fast().q, &realism).unwrap();
    let (local, _) = shifted_nominal(&robot, &[1.3, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let w = &local.diagnostics.warnings;
    assert!(
        w.iter().any(|w| w.starts_with("the nominal passes missed the operating point by up to 1.3 perturbations (q of joint 'joint1')")
            && w.contains("make the passes reach the point")),
        "{w:?}"
    );
}

/// The UR5 of example-robot-data, rehearsed as a realistic true robot under PD tracking at
/// 25 Hz (payload, link errors, asymmetric Coulomb + Stribeck + viscous friction, ripple,
/// 2^18 counts, noise, a 1.5 ms torque delay, a 7 ms clock offset) at a point where every joint
/// is fast: T* carried to the planned point is within 3 of its standard errors for at least 90
/// % of its entries. Skipped where example-robot-data is not installed.
#[test]
fn a_tracking_ur5_states_t_star_within_its_standard_errors() {
    let Some(path) = common::panda_urdf().and_then(|p| {
        Some(
            p.parent()?
                .parent()?
                .parent()?
                .join("ur_description/urdf/ur5_robot.urdf"),
        )
    }) else {
        eprintln!("skipped: example-robot-data is not installed (pip install example-robot-data)");
        return;
    };
    let model =
        perturbid_rs::model_from_urdf_file(&path, &perturbid_rs::LoadOptions::default()).unwrap();
    let op = OperatingPoint::new(
        vec![0.3, -1.0, 1.2, -0.8, 0.9, 0.4],
        vec![0.5, -0.4, 0.45, 0.6, -0.5, 0.55],
        vec![1.0, -0.8, 0.9, 1.2, -1.0, 0.7],
    )
    .unwrap();
    let robot = realistic_robot(&model, &op.q, &Realism::default()).unwrap();
    let case = local_case(
        &model,
        &robot,
        &op,
        &PlanOptions::default(),
        &IdentifyOptions::default(),
        0.007,
    )
    .unwrap();
    let inside = case.torque_errors.iter().filter(|e| e.abs() <= 3.0).count();
    assert!(
        inside as f64 >= 0.9 * 6.0,
        "T* in standard errors: {:?}",
        case.torque_errors
    );
    let miss = case.model.miss.as_ref().unwrap();
    assert!(
        miss.q.iter().any(|x| x.abs() > 1e-4),
        "the controller misses P: {miss:?}"
    );
}

/// A Panda (example-robot-data; skipped where it is not installed) that repeats its motion
/// exactly from pass to pass (PD tracking at 25 Hz, no torque noise or ripple) and logs its
/// positions in 2^18 counts per revolution: every nominal pass rounds alike, so the reading
/// error of the measured point does not average out of their mean. Over two rounds of
/// refinement T* stays within 3 of its standard errors, which count that error
/// (`local::repeated_reading`; counted as if it averaged out, T* was up to 7 standard errors
/// off), and the miss is reported in the standard errors of its measurement.
#[test]
fn rounding_every_pass_repeats_is_counted_in_t_star() {
    use perturbid_rs::local::refine_plan;
    let Some(path) = common::panda_urdf() else {
        eprintln!("skipped: example-robot-data is not installed (pip install example-robot-data)");
        return;
    };
    let mut load = perturbid_rs::LoadOptions::default();
    load.lock.insert("panda_finger_joint1".into(), 0.0);
    let model = perturbid_rs::model_from_urdf_file(&path, &load).unwrap();
    let op = panda_all_fast();
    let realism = Realism {
        ripple: 0.0,
        ..Realism::default()
    };
    let mut robot = realistic_robot(&model, &op.q, &realism).unwrap();
    robot.sensors.torque_noise = None;
    let mut options = IdentifyOptions::default();
    // the sensor's 1.5 ms less the held command's half sample
    options.fit.torque_delay = 1.0e-3;
    let mut plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let truth = true_local(&model, &robot, &op).unwrap();
    let mut errors = vec![];
    for round in 0..3 {
        let recordings = rehearse_plan(&model, &robot, &plan).unwrap();
        let local = identify_local(&plan, &recordings, &options).unwrap();
        let off: Vec<f64> = (0..7)
            .map(|j| (local.torque[j] - truth.torque[j]) / local.torque_stderr[j])
            .collect();
        eprintln!("round {round}: T* in standard errors {off:?}");
        errors.extend(off);
        let miss = local.miss.as_ref().unwrap();
        assert!(miss.qdd_stderr.iter().all(|s| *s > 0.0), "{miss:?}");
        assert!(local
            .summary("m.json")
            .contains("standard errors of its measurement"));
        if round < 2 {
            plan = refine_plan(&plan, &recordings, &options, Some(&model)).unwrap();
        }
    }
    let worst = errors.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    assert!(
        worst < 3.0,
        "T* up to {worst:.1} standard errors off: {errors:?}"
    );
}

/// The Panda of example-robot-data (skipped where it is not installed) at a point where every
/// joint is fast, open loop, with a 1.5 ms torque delay: T* read at the crossings' times is
/// off by the delay times the torque's rate, beyond its standard errors; read 1.5 ms later
/// (`FitOptions::torque_delay`), within them.
#[test]
fn a_known_torque_delay_is_read_past() {
    let Some(model) = common::panda_model() else {
        eprintln!("skipped: example-robot-data is not installed (pip install example-robot-data)");
        return;
    };
    let op = panda_all_fast();
    let worst = |delay: f64| {
        let realism = Realism {
            bandwidth: None,
            delay: 1.5e-3,
            ..Realism::default()
        };
        let robot = realistic_robot(&model, &op.q, &realism).unwrap();
        let mut options = IdentifyOptions::default();
        options.fit.torque_delay = delay;
        let case = local_case(&model, &robot, &op, &PlanOptions::default(), &options, 0.0).unwrap();
        case.torque_errors
            .iter()
            .fold(0.0f64, |a, e| a.max(e.abs()))
    };
    let (ignored, read) = (worst(0.0), worst(1.5e-3));
    assert!(
        ignored > 3.0,
        "ignored, the delay leaves T* {ignored:.1} standard errors off"
    );
    assert!(
        read < 3.0 && read < 0.6 * ignored,
        "read past, T* is {read:.1} standard errors off"
    );
}

/// A delay beyond any drive's is refused, naming the option.
#[test]
fn an_impossible_torque_delay_is_refused() {
    let model = a465::model("kinsheel2010").unwrap();
    let robot = realistic_robot(
        &model,
        &all_fast().q,
        &Realism {
            bandwidth: None,
            ..Realism::default()
        },
    )
    .unwrap();
    for delay in [0.5, f64::NAN] {
        let mut options = IdentifyOptions::default();
        options.fit.torque_delay = delay;
        let e = local_case(
            &model,
            &robot,
            &all_fast(),
            &PlanOptions::default(),
            &options,
            0.0,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("torque_delay") && e.contains("expected a finite delay within +-0.05 s"),
            "{e}"
        );
    }
}

/// A robot under soft PD tracking (10 Hz) misses P; the plan refined by its recordings twice
/// (`refine_plan`) commands the references off the crossings so that its passes go through
/// P: the miss shrinks at least 10 times, the crossings and their times are the plan's, and
/// T* at P is within 3 of its standard errors.
#[test]
fn two_rounds_of_refinement_bring_the_passes_to_p() {
    use perturbid_rs::local::refine_plan;
    use perturbid_rs::rehearsal::rehearse_plan;
    let model = a465::model("kinsheel2010").unwrap();
    let op = all_fast();
    let realism = Realism {
        bandwidth: Some(10.0),
        delay: 0.0,
        ..Realism::default()
    };
    let robot = realistic_robot(&model, &op.q, &realism).unwrap();
    let mut plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let options = IdentifyOptions::default();
    let worst_miss = |m: &LocalModel| {
        let miss = m.miss.as_ref().unwrap();
        miss.q_perturbations
            .iter()
            .chain(&miss.qd_perturbations)
            .fold(0.0f64, |a, x| a.max(x.abs()))
    };
    let mut misses = vec![];
    let mut rounds = vec![];
    for round in 0..3 {
        let recordings = rehearse_plan(&model, &robot, &plan).unwrap();
        rounds.push((plan.clone(), recordings.clone()));
        let local = identify_local(&plan, &recordings, &options).unwrap();
        misses.push(worst_miss(&local));
        let truth = true_local(&model, &robot, &op).unwrap();
        let inside = (0..6)
            .filter(|&j| (local.torque[j] - truth.torque[j]).abs() <= 3.0 * local.torque_stderr[j])
            .count();
        eprintln!(
            "round {round}: miss {:.4} perturbations, T* inside {inside} of 6",
            misses[round]
        );
        if round < 2 {
            let refined = refine_plan(&plan, &recordings, &options, Some(&model)).unwrap();
            for (a, b) in plan.experiments.iter().zip(&refined.experiments) {
                assert_eq!(a.crossings, b.crossings);
                assert_eq!(a.deltas, b.deltas);
            }
            assert_eq!(
                refined.experiments[0].commanded.as_ref().unwrap().rounds,
                round + 1
            );
            plan = refined;
        }
    }
    assert!(misses[2] < 0.1 * misses[0], "the miss went {misses:?}");
    // the three rounds pooled: three times the crossings, T* within 3 standard errors
    let pooled: Vec<_> = (rounds.iter()).map(|(p, r)| (p, r.as_slice())).collect();
    let local = identify_local_rounds(&pooled, &options).unwrap();
    let alone = identify_local(&rounds[2].0, &rounds[2].1, &options).unwrap();
    let (d, d_alone) = (local.d.as_ref().unwrap(), alone.d.as_ref().unwrap());
    assert_eq!(d.crossings, 3 * d_alone.crossings);
    let truth = true_local(&model, &robot, &op).unwrap();
    for j in 0..6 {
        let off = (local.torque[j] - truth.torque[j]).abs() / local.torque_stderr[j];
        assert!(off < 3.0, "joint {j}: T* {off:.1} standard errors off");
    }
    // a round of another plan is refused, naming it
    let other = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mixed = [pooled[0], (&other, pooled[1].1)];
    let e = identify_local_rounds(&mixed, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("round 2") && e.contains("another operating point"),
        "{e}"
    );
}

/// The recordings' torque delay, found with the robot's rigid-body model
/// (`direct::torque_delay`): on the A465 (link errors, payload, friction, ripple, counts,
/// noise; open loop) 0 where there is none and 1.5 ms where the torque lags by that, each
/// within 0.3 ms; read past, T* is within 3 of its standard errors.
#[test]
fn the_torque_delay_is_found_from_the_rigid_body_fit() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = all_fast();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    for delay in [0.0, 1.5e-3] {
        let realism = Realism {
            bandwidth: None,
            delay,
            ..Realism::default()
        };
        let robot = realistic_robot(&model, &op.q, &realism).unwrap();
        let recs = rehearse_plan(&model, &robot, &plan).unwrap();
        let local = identify_local_with_delay(
            &model,
            &plan,
            &recs,
            &IdentifyOptions::default(),
            &DelayOptions::default(),
        )
        .unwrap();
        let found = local.diagnostics.torque_delay.clone().unwrap();
        assert!(
            (found.delay - delay).abs() < 3e-4 && found.stderr > 0.0 && found.stderr < 3e-4,
            "{delay} s: {found:?}"
        );
        assert!(found.unexplained <= found.unexplained_at_zero);
        assert!(local.summary("m.json").contains("torque delay "));
        let case = compare(&model, &robot, local).unwrap();
        let worst = (case.torque_errors.iter()).fold(0.0f64, |a, e| a.max(e.abs()));
        assert!(worst < 3.0, "{delay} s: T* {worst:.1} standard errors off");
    }
    // a robot of other joints than the plan's is refused, naming it
    let mut other = plan.clone();
    other.joint_names[0] = "elsewhere".into();
    let e = identify_local_with_delay(
        &model,
        &other,
        &[],
        &IdentifyOptions::default(),
        &DelayOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("robot") && e.contains("elsewhere"), "{e}");
}

/// Under PD tracking the logged torque is the command, held over each sample period: it acts
/// half a sample after its stamp, so the delay found is the sensor's less half a sample (the
/// Panda of example-robot-data, skipped where it is not installed; 1 kHz, 1.5 ms).
#[test]
fn a_held_command_reads_half_a_sample_early() {
    let Some(model) = common::panda_model() else {
        eprintln!("skipped: example-robot-data is not installed (pip install example-robot-data)");
        return;
    };
    let op = panda_all_fast();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let robot = realistic_robot(&model, &op.q, &Realism::default()).unwrap();
    let recs = rehearse_plan(&model, &robot, &plan).unwrap();
    let refs: Vec<_> = recs.iter().collect();
    let found = estimate_torque_delay(&model, &refs, &DelayOptions::default()).unwrap();
    let expected = Realism::default().delay - 0.5 / plan.rate;
    assert!(
        (found.delay - expected).abs() < 3e-4,
        "{found:?}, expected {expected}"
    );
    // a search range the delay lies outside of says so
    let narrow = DelayOptions {
        range: 2e-4,
        ..DelayOptions::default()
    };
    let e = estimate_torque_delay(&model, &refs, &narrow)
        .unwrap_err()
        .to_string();
    assert!(e.contains("edge of the delays tried"), "{e}");
}
