//! The method on what a real robot records: friction that steps where a joint's velocity
//! reverses near a crossing, clocks offset from the plan's. Each effect is checked against the
//! model identified without it.

mod common;

use common::{a465_orthogonal_at_table2, linearized, mat, rel, table2};
use nalgebra::DMatrix;
use perturbid_rs::local::{
    identify_local, plan_experiments, CrossingTimes, IdentifyOptions, LocalModel, PlanOptions,
    ReversalHandling,
};
use perturbid_rs::robots::a465;
use perturbid_rs::{simulate_plan, Friction, Gravity, Model, OperatingPoint, SimulationOptions};

fn rehearse(model: &Model, friction: Friction, options: &IdentifyOptions) -> LocalModel {
    let plan = plan_experiments(model, &table2(), &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(model);
    sim.gravity = Gravity::Included;
    sim.friction = friction;
    let recs = simulate_plan(model, &plan, &sim).unwrap();
    identify_local(&plan, &recs, options).unwrap()
}

/// At the paper's operating point joints 5 and 6 move slowly (0.011 and 0.014 rad/s) and the
/// D perturbations reverse them within the plan's fit window: Coulomb, asymmetric Coulomb and
/// Stribeck friction must still cancel from D* and G* (to 1e-6 of the friction-free model).
#[test]
fn friction_steps_near_crossings_do_not_reach_d_and_g() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let options = IdentifyOptions::default();
    let clean = rehearse(&model, Friction::none(n), &options);
    assert!(
        clean.diagnostics.warnings.is_empty(),
        "{:?}",
        clean.diagnostics
    );
    let coulomb = Friction::viscous_coulomb(vec![0.0; n], vec![0.3; n]);
    let mut asymmetric = coulomb.clone();
    asymmetric.coulomb_negative = vec![0.5, 0.1, 0.4, 0.2, 0.45, 0.15];
    let mut stribeck = Friction::viscous_coulomb(vec![0.8; n], vec![0.3; n]);
    stribeck.stribeck = vec![0.2; n];
    stribeck.stribeck_velocity = vec![0.05; n];
    for (what, friction) in [
        ("Coulomb", coulomb),
        ("asymmetric Coulomb", asymmetric),
        ("Stribeck", stribeck),
    ] {
        let m = rehearse(&model, friction, &options);
        let (d, g) = (rel(mat(&m.d), mat(&clean.d)), rel(mat(&m.g), mat(&clean.g)));
        assert!(d < 1e-6, "{what}: D* moved by {d:.2e} relative");
        assert!(g < 1e-6, "{what}: G* moved by {g:.2e} relative");
        // the reversals were seen and avoided, not modelled
        let r = &m.diagnostics.reversals;
        assert!(
            r.iter()
                .any(|r| r.experiment == "D" && r.joint == model.joint_names[4]),
            "{what}: joint 5's reversals in D not found: {r:?}"
        );
        assert!(r.iter().all(|r| r.handling == ReversalHandling::Narrowed));
        assert!(
            m.diagnostics.warnings.is_empty(),
            "{:?}",
            m.diagnostics.warnings
        );
    }
}

/// A joint at rest at the operating point reverses exactly at every D crossing: no window can
/// leave the step out, so it is fitted (exact for Coulomb friction) and the user is warned.
#[test]
fn a_reversal_at_the_crossing_is_modelled_and_warned() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let mut qd = a465::TABLE2_QD.to_vec();
    qd[4] = 0.0;
    let op = OperatingPoint::new(a465::TABLE2_Q.to_vec(), qd, a465::TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.friction = Friction::none(n);
    let clean = identify_local(
        &plan,
        &simulate_plan(&model, &plan, &sim).unwrap(),
        &IdentifyOptions::default(),
    )
    .unwrap();
    let mut asymmetric = Friction::viscous_coulomb(vec![0.0; n], vec![0.3; n]);
    asymmetric.coulomb_negative = vec![0.5; n];
    sim.friction = asymmetric;
    let m = identify_local(
        &plan,
        &simulate_plan(&model, &plan, &sim).unwrap(),
        &IdentifyOptions::default(),
    )
    .unwrap();
    let d = rel(mat(&m.d), mat(&clean.d));
    assert!(d < 1e-6, "D* moved by {d:.2e} relative");
    let w = &m.diagnostics.warnings;
    assert!(
        w.iter().any(
            |w| w.starts_with("experiment 'D': the velocity reverses too close to")
                && w.contains(&format!("joint '{}'", model.joint_names[4]))
        ),
        "{w:?}"
    );
    assert!(m
        .diagnostics
        .reversals
        .iter()
        .any(|r| r.handling == ReversalHandling::Step));
}

/// A recording whose clock is offset from the plan's: the offset is found in the positions and
/// corrected by default (1, 10 and 100 ms give the offset-free model to noise level), reported
/// in the diagnostics, and refused beyond the tolerance.
#[test]
fn clock_offsets_are_found_and_corrected() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.torque_noise = vec![0.002; model.nv];
    sim.position_noise = vec![1e-5; model.nv];
    sim.seed = 7;
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let planned = IdentifyOptions {
        times: CrossingTimes::Planned,
        ..IdentifyOptions::default()
    };
    let reference = identify_local(&plan, &recs, &planned).unwrap();
    for offset in [1e-3, 1e-2, 1e-1] {
        let shifted: Vec<_> = recs
            .iter()
            .cloned()
            .map(|mut r| {
                r.t.iter_mut().for_each(|t| *t += offset);
                r
            })
            .collect();
        let m = identify_local(&plan, &shifted, &IdentifyOptions::default()).unwrap();
        for o in &m.diagnostics.offsets {
            assert!(
                (o.offset - offset).abs() < 2e-5,
                "{}: found {} for {offset}",
                o.experiment,
                o.offset
            );
        }
        for (what, a, b) in [
            ("D", &m.d, &reference.d),
            ("H", &m.h, &reference.h),
            ("G", &m.g, &reference.g),
        ] {
            let worst = (mat(a) - mat(b)).abs().max();
            let se = b.as_ref().unwrap().stderr.max();
            assert!(
                worst < 0.5 * se,
                "{what} at {offset} s: {worst:.2e} vs stderr {se:.2e}"
            );
        }
        // the same recordings read at the planned times: H* far outside its noise
        let naive = identify_local(&plan, &shifted, &planned).unwrap();
        let (wrong, right) = (
            rel(mat(&naive.h), mat(&reference.h)),
            rel(mat(&m.h), mat(&reference.h)),
        );
        // (the screening for glitches replaces the samples a misplaced Coulomb step leaves on
        // its wrong side, which makes the misaligned read less wrong: 50x, 100x before)
        assert!(
            wrong > 20.0 * right && wrong > 0.05,
            "{offset}: H* {wrong:.2e} off at planned times, {right:.2e} aligned"
        );
    }
    // beyond the tolerance: refused, naming the recording and the offset
    let far: Vec<_> = recs
        .iter()
        .cloned()
        .map(|mut r| {
            r.t.iter_mut().for_each(|t| *t += 0.6);
            r
        })
        .collect();
    let e = identify_local(&plan, &far, &IdentifyOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("simulated experiment 'nominal': its clock is +0.6000 s off the plan of experiment 'nominal'"),
        "{e}"
    );
}

/// Velocity perturbations larger than |qd*| reverse joints between the H passes: the planner
/// warns, can keep them below, and the friction-aware H regression recovers H* and each
/// reversed joint's Coulomb step exactly from noise-free data, where the plain one cannot.
#[test]
fn friction_aware_h_recovers_h_and_the_coulomb_steps() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    // the warnings other than the design's (this seed's G design warns of its cond(X))
    let reversals = |plan: &perturbid_rs::local::Plan| -> Vec<String> {
        (plan.warnings.iter())
            .filter(|w| !w.contains("its perturbations have cond(X)"))
            .cloned()
            .collect()
    };
    let w = &reversals(&plan);
    assert!(
        w.len() == 1
            && w[0].starts_with(
                "experiment 'H': the velocity perturbations reverse joint(s) 'joint1'"
            ),
        "{w:?}"
    );
    // keep_velocity_sign: no reversal, no warning, and friction cancels from the plain H*
    let keep = PlanOptions {
        keep_velocity_sign: true,
        ..PlanOptions::default()
    };
    let kept = plan_experiments(&model, &op, &keep).unwrap();
    assert!(reversals(&kept).is_empty(), "{:?}", kept.warnings);
    let h = kept
        .experiment(perturbid_rs::local::ExperimentKind::H)
        .unwrap();
    for j in 0..n {
        assert!(h.deltas.column(j).amax() < op.qd[j].abs(), "joint {j}");
    }
    // the friction-aware regression on a plan made for it
    let aware = PlanOptions {
        friction_aware_h: true,
        ..PlanOptions::default()
    };
    let plan = plan_experiments(&model, &op, &aware).unwrap();
    assert!(reversals(&plan).is_empty(), "{:?}", plan.warnings);
    let h_plan = plan
        .experiment(perturbid_rs::local::ExperimentKind::H)
        .unwrap();
    assert_eq!(h_plan.crossings.len(), 2 * (n + 2));
    let mut sim = SimulationOptions::new(&model);
    sim.friction = Friction::none(n);
    let options = IdentifyOptions {
        friction_aware_h: true,
        ..IdentifyOptions::default()
    };
    let clean = identify_local(
        &plan,
        &simulate_plan(&model, &plan, &sim).unwrap(),
        &options,
    )
    .unwrap();
    let viscous = vec![0.5, 0.4, 0.3, 0.2, 0.1, 0.05];
    let mut friction = Friction::viscous_coulomb(viscous.clone(), vec![0.3; n]);
    friction.coulomb_negative = vec![0.5, 0.2, 0.4, 0.1, 0.45, 0.15];
    sim.friction = friction.clone();
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let m = identify_local(&plan, &recs, &options).unwrap();
    let expected = mat(&clean.h) + DMatrix::from_diagonal(&nalgebra::DVector::from_vec(viscous));
    let err = rel(mat(&m.h), &expected);
    assert!(err < 1e-6, "friction-aware H* off by {err:.2e}");
    let steps = m.coulomb.as_ref().unwrap();
    let mut reversed = 0;
    for j in 0..n {
        let reverses = h_plan.deltas.column(j).amax() > op.qd[j].abs();
        match steps.step[j] {
            Some(s) => {
                let truth = friction.coulomb[j] + friction.coulomb_negative[j];
                assert!((s - truth).abs() < 1e-6, "joint {j}: step {s} vs {truth}");
                reversed += 1;
            }
            None => assert!(!reverses, "joint {j} reverses but has no step"),
        }
    }
    assert!(reversed >= 1);
    // the H experiment's torque noise is reported from the friction-aware regression too
    // (noise-free data: no samples' noise; the pairs' differences fit exactly)
    let h_noise: Vec<_> = m
        .diagnostics
        .noise
        .iter()
        .filter(|e| e.experiment == "H")
        .collect();
    assert_eq!(h_noise.len(), n, "{:?}", m.diagnostics.noise);
    assert!(
        h_noise
            .iter()
            .all(|e| e.samples < 1e-9 && e.passes.is_some_and(|p| p < 1e-6)),
        "{h_noise:?}"
    );
    // the plain regression on the same data is far off
    let plain = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    assert!(rel(mat(&plain.h), &expected) > 1e-2);
}

/// The orthogonal design (`cond(X) = 1`, what the design warning advises) with the friction-aware
/// H regression: the planner draws H magnitudes that vary (its Hadamard columns put every joint
/// at one magnitude, where the Coulomb step sign(d) is proportional to the velocity change),
/// and a plan made without it is refused by name rather than as a rank deficiency.
#[test]
fn the_orthogonal_design_serves_the_friction_aware_h_regression() {
    use perturbid_rs::local::{Design, ExperimentKind};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let mut sim = SimulationOptions::new(&model);
    sim.friction = Friction::none(n);
    let clean_plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let clean = identify_local(
        &clean_plan,
        &simulate_plan(&model, &clean_plan, &sim).unwrap(),
        &IdentifyOptions::default(),
    )
    .unwrap();
    let viscous = vec![0.5, 0.4, 0.3, 0.2, 0.1, 0.05];
    sim.friction = Friction::viscous_coulomb(viscous.clone(), vec![0.3; n]);
    let options = IdentifyOptions {
        friction_aware_h: true,
        ..IdentifyOptions::default()
    };
    let aware = PlanOptions {
        design: Design::Orthogonal,
        friction_aware_h: true,
        count: Some(32),
        ..PlanOptions::default()
    };
    let plan = plan_experiments(&model, &op, &aware).unwrap();
    let h = plan.experiment(ExperimentKind::H).unwrap();
    assert!(h.design_cond().unwrap() < 1.0 + 1e-9);
    let m = identify_local(
        &plan,
        &simulate_plan(&model, &plan, &sim).unwrap(),
        &options,
    )
    .unwrap();
    let expected = mat(&clean.h) + DMatrix::from_diagonal(&nalgebra::DVector::from_vec(viscous));
    let err = rel(mat(&m.h), &expected);
    assert!(err < 1e-6, "friction-aware H* off by {err:.2e}");
    let steps = m.coulomb.as_ref().unwrap();
    assert!(
        steps.step.iter().flatten().all(|s| (s - 0.6).abs() < 1e-6),
        "{steps:?}"
    );
    // the same design planned without friction_aware_h: Hadamard columns, refused by name
    let plain = plan_experiments(
        &model,
        &op,
        &PlanOptions {
            friction_aware_h: false,
            ..aware
        },
    )
    .unwrap();
    let e = identify_local(
        &plain,
        &simulate_plan(&model, &plain, &sim).unwrap(),
        &options,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(
            "the H perturbations of joint 'joint1' reverse it at one magnitude in every pair"
        ),
        "{e}"
    );
}

/// `predict` expands about the planned operating point, which every nominal pass crossed and
/// where T* holds; with coarse encoders the point measured at the crossings is a noisy
/// estimate of it (qdd through two derivatives of quantised positions) that would bias every
/// prediction.
#[test]
fn predict_expands_about_the_planned_operating_point() {
    use perturbid_rs::{linearize, Data, States};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.friction = Friction::none(n);
    sim.gravity = Gravity::Excluded;
    sim.quantization = vec![2e-3; n];
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let moved = (0..n)
        .map(|j| (m.op.qdd[j] - op.qdd[j]).abs())
        .fold(0.0, f64::max);
    assert!(moved > 1e-2, "the measured point should differ: {moved:e}");
    let at = |o: &OperatingPoint| {
        let s = States::new(n, &o.q, Some(&o.qd), Some(&o.qdd)).unwrap();
        m.predict(&s).unwrap()
    };
    let truth = |o: &OperatingPoint| {
        linearize(
            &model,
            &mut Data::new(&model),
            &o.q,
            &o.qd,
            &o.qdd,
            Gravity::Excluded,
        )
        .unwrap()
        .torque
        .as_slice()
        .to_vec()
    };
    let err = |a: &[f64], b: &[f64]| (0..n).map(|j| (a[j] - b[j]).abs()).fold(0.0, f64::max);
    // at the planned point: T* itself, and the true torque there to quantisation level
    let here = at(&op);
    assert!(err(&here, &m.torque) < 1e-12);
    assert!(
        err(&here, &truth(&op)) < 1e-3,
        "{:.2e}",
        err(&here, &truth(&op))
    );
    // about the measured point instead, the same model would be off by the D*, H*, G* times
    // the measurement error of the point
    let d = mat(&m.d);
    let dqdd = nalgebra::DVector::from_iterator(n, (0..n).map(|j| op.qdd[j] - m.op.qdd[j]));
    assert!((d * dqdd).amax() > 100.0 * err(&here, &truth(&op)));
}

/// Under encoder quantisation the combined estimator's H* and G* are far off (the measured
/// deviations of the variables an experiment did not perturb leak the large D* into them)
/// while the separated ones hold: the model says so, in a warning and in its diagnostics.
#[test]
fn the_combined_estimate_reports_when_it_is_not_to_be_trusted() {
    use perturbid_rs::local::Estimator;
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let truth = linearized(&model, &op);
    let mut sim = SimulationOptions::new(&model);
    sim.friction = Friction::none(n);
    let combined = IdentifyOptions {
        estimator: Estimator::Combined,
        ..IdentifyOptions::default()
    };
    // noise-free: the two agree, no warning
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let m = identify_local(&plan, &recs, &combined).unwrap();
    assert!(
        m.diagnostics.warnings.is_empty(),
        "{:?}",
        m.diagnostics.warnings
    );
    assert!(m.diagnostics.combined.iter().all(|b| b.relative < 1e-6));
    // 100,000 counts per revolution
    sim.quantization = vec![std::f64::consts::TAU / 1e5; n];
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let separated = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let m = identify_local(&plan, &recs, &combined).unwrap();
    assert!(rel(mat(&separated.h), &truth.h) < 0.05);
    assert!(rel(mat(&m.h), &truth.h) > 1.0, "the combined H* is far off");
    let w = &m.diagnostics.warnings;
    assert!(
        w.iter().any(|w| w.starts_with("the model's D, H, G (estimator 'combined') disagree with the separated estimate in H by")
            && w.contains("which the combined regression takes for motion")
            && w.ends_with("trust it (estimator 'separated')")),
        "{w:?}"
    );
    let evidence = m.diagnostics.estimator_evidence.as_ref().unwrap();
    assert_eq!(evidence.favours_combined(), Some(false), "{evidence:?}");
    let h = m
        .diagnostics
        .combined
        .iter()
        .find(|b| b.block == "H")
        .unwrap();
    assert!(h.relative > 1.0, "{h:?}");
    // the separated model, favoured by the evidence, advises nothing
    let w = &separated.diagnostics.warnings;
    assert!(!w.iter().any(|w| w.contains("disagree")), "{w:?}");
}

/// A robot that tracks its plan under a PD controller with a payload its model lacks: the
/// crossings deviate from the plan in every variable, the separated regressions are biased by
/// it and the combined one accounts for it (the paper's case for it); the model tells which to
/// trust.
#[test]
fn closed_loop_tracking_errors_favour_the_combined_estimate() {
    use perturbid_rs::local::Estimator;
    use perturbid_rs::rehearsal::{rehearse_plan, Controller, Payload, TrueRobot};
    use perturbid_rs::{linearize, Data};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let robot = TrueRobot {
        payload: Some(Payload {
            link: "link6".into(),
            mass: 0.5,
            com: [0.0, 0.0, 0.05],
            inertia: [0.0; 6],
        }),
        controller: Some(Controller {
            kp: vec![400.0; n],
            kd: vec![40.0; n],
            substeps: 2,
            feedforward: true,
            effort: None,
        }),
        ..TrueRobot::default()
    };
    let recs = rehearse_plan(&model, &robot, &plan).unwrap();
    let true_model = robot.rigid_body_model(&model).unwrap();
    let error = |m: &LocalModel| {
        let t = linearize(
            &true_model,
            &mut Data::new(&true_model),
            &m.op.q,
            &m.op.qd,
            &m.op.qdd,
            Gravity::Included,
        )
        .unwrap();
        [
            rel(mat(&m.d), &t.d),
            rel(mat(&m.h), &t.h),
            rel(mat(&m.g), &t.g),
        ]
    };
    let separated = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let combined = identify_local(
        &plan,
        &recs,
        &IdentifyOptions {
            estimator: Estimator::Combined,
            ..IdentifyOptions::default()
        },
    )
    .unwrap();
    let (s, c) = (error(&separated), error(&combined));
    assert!(
        c[1] < 0.1 * s[1] && c[2] < 0.1 * s[2],
        "separated {s:?}, combined {c:?}"
    );
    assert!(separated.diagnostics.unperturbed_deviation.unwrap() > 10.0);
    let w = &separated.diagnostics.warnings;
    assert!(
        w.iter().any(|w| w.starts_with(
            "the model's D, H, G (estimator 'separated') disagree with the combined estimate"
        ) && w.contains("(tracking errors)")
            && w.ends_with("trust it (estimator 'combined')")),
        "{w:?}"
    );
    // the combined model, favoured by the evidence, never advises the estimator it used
    let w = &combined.diagnostics.warnings;
    assert!(!w.iter().any(|w| w.contains("disagree")), "{w:?}");
}

/// A robot in closed loop (400 N m/rad) with friction, a payload, torque noise and encoder
/// counts lags its reference by two samples in G, but its commanded torque turns into the next
/// transition at the planned segment's end: the reading windows keep clear of that kink by the
/// lag, and no sample there is taken for a glitch (before, the last samples of 11 windows of
/// 12 were, and the identification warned of a common cause).
#[test]
fn a_controllers_lag_does_not_read_the_next_transition() {
    use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
    use perturbid_rs::Document;
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let robot = TrueRobot::from_json(
        r#"{"format": "perturbid-true-robot/1", "seed": 2,
            "payload": {"link": "link6", "mass": 1.0, "com": [0.0, 0.0, 0.06],
                        "inertia": [0.002, 0, 0, 0.002, 0, 0.001]},
            "friction": {"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05],
                         "coulomb": [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]},
            "sensors": {"torque_noise": [0.05, 0.05, 0.05, 0.02, 0.02, 0.02],
                        "encoder_counts": [409600, 409600, 409600, 409600, 409600, 409600]},
            "controller": {"kp": [400, 400, 400, 400, 400, 400],
                           "kd": [40, 40, 40, 40, 40, 40]}}"#,
    )
    .unwrap();
    let recs = rehearse_plan(&model, &robot, &plan).unwrap();
    let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let lag = (m.diagnostics.offsets.iter())
        .map(|o| o.offset.abs())
        .fold(0.0, f64::max);
    assert!(lag > 1.5 / plan.rate, "{:?}", m.diagnostics.offsets);
    let w = &m.diagnostics.warnings;
    assert!(!w.iter().any(|w| w.contains("taken for glitches")), "{w:?}");
    // a window given by hand is read as given: there the kink is taken for glitches
    let given = IdentifyOptions {
        fit: perturbid_rs::local::FitOptions {
            window: Some(plan.experiments[0].window),
            ..Default::default()
        },
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &recs, &given).unwrap();
    let w = &m.diagnostics.warnings;
    assert!(w.iter().any(|w| w.contains("taken for glitches")), "{w:?}");
}

/// A torque logged in steps coarser than its noise (0.05 N m against 0.002 N m): the rounding,
/// much the same from pass to pass, hid from the regression's residuals, and D* entries erred
/// by up to 700 of their standard errors. Detected, the step sets a floor under the standard
/// errors (a rounding error of a step / sqrt(12) at every crossing), is reported in
/// diagnostics.noise and warned about; a torque that is only noisy shows no step.
#[test]
fn torques_rounded_without_dithering_get_standard_errors_that_cover_the_rounding() {
    use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
    use perturbid_rs::Document;
    let (model, _, plan, truth) = a465_orthogonal_at_table2();
    let robot = |seed: usize, resolution: f64| {
        let spec = format!(
            r#"{{"format": "perturbid-true-robot/1", "seed": {seed}, "sensors": {{"torque_noise": [0.002, 0.002, 0.002, 0.002, 0.002, 0.002], "torque_resolution": [{r}, {r}, {r}, {r}, {r}, {r}]}}}}"#,
            r = resolution
        );
        TrueRobot::from_json(&spec).unwrap()
    };
    let identify = |robot: &TrueRobot| {
        let recordings = rehearse_plan(&model, robot, &plan).unwrap();
        identify_local(&plan, &recordings, &IdentifyOptions::default()).unwrap()
    };
    let mut worst: f64 = 0.0;
    for seed in 0..12 {
        let m = identify(&robot(100 + seed, 0.05));
        // repeated steps of the grid, where a torque levels off as its joint arrives at rest,
        // are readings, not held ones
        assert!(
            m.diagnostics.held_readings.is_empty(),
            "{:?}",
            m.diagnostics.held_readings
        );
        let d = m.d.as_ref().unwrap();
        for ((e, se), t) in d.matrix.iter().zip(&d.stderr).zip(&truth.d) {
            if se.is_finite() {
                worst = worst.max((e - t).abs() / se);
            }
        }
        let named = |x: &perturbid_rs::local::TorqueNoise| {
            x.experiment == "D" && x.step.is_some_and(|q| (q - 0.05).abs() < 1e-9)
        };
        assert!(
            m.diagnostics.noise.iter().any(named),
            "{:?}",
            m.diagnostics.noise
        );
        assert!(
            (m.diagnostics.warnings.iter()).any(|w| w
                .starts_with("experiment 'D': the torque of joint(s) 'joint")
                && w.contains("(steps of 0.05 N m, scatter ")),
            "{:?}",
            m.diagnostics.warnings
        );
    }
    assert!(worst < 4.0, "D* erred by {worst:.1} standard errors");
    // at rest joints 1, 4 and 6 read exactly 0 in every sample (a vertical axis, no gravity
    // load): one level shows no grid, but the other torques' steps say it is likely a level of
    // one, so their Gs rows are no longer exact (standard errors of 0 before) and are warned of
    let m = identify(&robot(100, 0.05));
    let gs = m.g_static.as_ref().unwrap();
    for j in [0, 3, 5] {
        assert!(
            gs.stderr.row(j).iter().all(|se| *se > 1e-4),
            "{}",
            gs.stderr
        );
    }
    assert!(
        (m.diagnostics.warnings.iter()).any(|w| w.starts_with(
            "experiment 'G_static': the torque of joint(s) 'joint1', 'joint4', 'joint6' read exactly 0 in every sample at rest"
        ) && w.contains("(the finest 0.05 N m)")),
        "{:?}",
        m.diagnostics.warnings
    );
    // noise alone (a resolution of 0: none) is no grid
    let m = identify(&robot(100, 0.0));
    assert!(m.diagnostics.noise.iter().all(|x| x.step.is_none()));
    assert!(!m
        .diagnostics
        .warnings
        .iter()
        .any(|w| w.contains("steps coarser")));
}

/// Positions logged in coarse encoder counts (4,096 a revolution, no noise beyond the
/// rounding): the least-squares quadratic through a joint's staircase misread the crossings'
/// accelerations by several times its own standard errors, and D* erred by up to 9.6 of its
/// standard errors (errors in the regressors, which the residuals hide). Read by the band of
/// half a count and with the regressors' errors counted, D* errs by 0.4 of its standard errors
/// RMS (9.6 at most before, 1.8 RMS), the encoder step is reported in diagnostics.noise, and
/// the joints whose perturbations the encoder cannot resolve are warned about. Finer encoders
/// (409,600 counts) stay covered; continuous positions show no step. Planned with the encoder's
/// step, the planner warns beforehand and names the window that resolves them.
#[test]
fn positions_in_coarse_encoder_counts_get_standard_errors_that_cover_them() {
    use perturbid_rs::local::Design;
    use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
    use perturbid_rs::Document;
    let (model, op, plan, truth) = a465_orthogonal_at_table2();
    let robot = |seed: usize, counts: &str| {
        let spec = format!(
            r#"{{"format": "perturbid-true-robot/1", "seed": {seed}, "sensors": {{"torque_noise": [0.01, 0.01, 0.01, 0.01, 0.01, 0.01]{counts}}}}}"#
        );
        TrueRobot::from_json(&spec).unwrap()
    };
    let counts = |c: u32| format!(r#", "encoder_counts": [{c}, {c}, {c}, {c}, {c}, {c}]"#);
    let identify = |robot: &TrueRobot| {
        let recordings = rehearse_plan(&model, robot, &plan).unwrap();
        identify_local(&plan, &recordings, &IdentifyOptions::default()).unwrap()
    };
    let seeds = 8;
    for c in [4096, 409600] {
        let step = std::f64::consts::TAU / c as f64;
        // per entry of D*, the sum of its errors in standard errors over the seeds, and their
        // sum of squares (the standard errors are Knapp-Hartung ones with 6 residual degrees of
        // freedom: Student's t tails, so the largest of 288 is no measure)
        let (mut sum, mut squares) = (DMatrix::<f64>::zeros(6, 6), 0.0);
        for seed in 0..seeds {
            let m = identify(&robot(100 + seed, &counts(c)));
            let d = m.d.as_ref().unwrap();
            let z = (&d.matrix - &truth.d).component_div(&d.stderr);
            sum += &z;
            squares += z.norm_squared();
            let named = |x: &perturbid_rs::local::TorqueNoise| {
                x.experiment == "D"
                    && x.position_step
                        .is_some_and(|q| (q / step - 1.0).abs() < 1e-6)
            };
            assert!(
                m.diagnostics.noise.iter().filter(|x| named(x)).count() == 6,
                "{:?}",
                m.diagnostics.noise
            );
            let coarse = (m.diagnostics.warnings.iter()).any(|w| {
                w.starts_with("experiment 'D': the encoders of joint(s) 'joint")
                    && w.contains("accelerations known to")
            });
            assert_eq!(coarse, c == 4096, "{:?}", m.diagnostics.warnings);
        }
        // calibrated t with 6 degrees of freedom: RMS 1.22, each entry's mean 0 +- 0.43
        let rms = (squares / (36 * seeds) as f64).sqrt();
        let bias = sum.amax() / seeds as f64;
        assert!(
            rms < 1.2,
            "{c} counts: D* erred by {rms:.2} standard errors RMS"
        );
        assert!(
            bias < 2.0,
            "{c} counts: a D* entry erred by {bias:.2} standard errors on average"
        );
    }
    // 1,024 counts: joint 6 reads one level in every window of the D experiment, so its
    // measured acceleration perturbations are all zero; the error says why
    let recordings = rehearse_plan(&model, &robot(100, &counts(1024)), &plan).unwrap();
    let e = identify_local(&plan, &recordings, &IdentifyOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("not excited: dqdd(joint6) (the column is all zeros: the encoder of joint 'joint6', in steps of 6.14e-3 rad, reads the same acceleration at every crossing"),
        "{e}"
    );
    // planned with the encoder's step, the planner warns of the D experiment beforehand and
    // names a window that resolves it; planned so, D* is within 1 % at 4,096 counts
    let step = std::f64::consts::TAU / 4096.0;
    let with_step = |window: f64| PlanOptions {
        design: Design::Orthogonal,
        window,
        encoder_step: Some(vec![step; 6]),
        ..PlanOptions::default()
    };
    let warned = plan_experiments(&model, &op, &with_step(0.05)).unwrap();
    let w: Vec<&String> = warned
        .warnings
        .iter()
        .filter(|w| w.contains("its encoders would measure"))
        .collect();
    assert!(
        w.len() == 1
            && w[0].starts_with(
                "experiment 'D': its encoders would measure the perturbations of joint(s) 'joint1'"
            )
            && w[0].contains("a crossing window of about 0.19 s (window, --window; now 0.05 s)"),
        "{w:?}"
    );
    let wide = plan_experiments(&model, &op, &with_step(0.2)).unwrap();
    assert!(
        !wide.warnings.iter().any(|w| w.contains("its encoders")),
        "{:?}",
        wide.warnings
    );
    let recordings = rehearse_plan(&model, &robot(100, &counts(4096)), &wide).unwrap();
    let m = identify_local(&wide, &recordings, &IdentifyOptions::default()).unwrap();
    assert!(
        rel(mat(&m.d), &truth.d) < 0.01,
        "{}",
        rel(mat(&m.d), &truth.d)
    );
    // the steps are checked: one per joint, each in [0, 1]
    for bad in [vec![step; 5], vec![-step; 6], vec![f64::NAN; 6]] {
        let o = PlanOptions {
            encoder_step: Some(bad),
            ..PlanOptions::default()
        };
        let e = plan_experiments(&model, &op, &o).unwrap_err();
        assert!(e.to_string().contains("encoder_step"), "{e}");
    }
    // continuous positions: no grid, no band
    let m = identify(&robot(100, ""));
    assert!(m
        .diagnostics
        .noise
        .iter()
        .all(|x| x.position_step.is_none()));
    assert!(!m
        .diagnostics
        .warnings
        .iter()
        .any(|w| w.contains("the encoders of")));
}
