//! The paper's method end to end in Rust: plan, simulate, identify, checked against the analytic
//! linearisation of the dynamics core, exact identities and the paper's Table 3.

mod common;

use common::{mat, rel, table2, Rng};
use nalgebra::{DMatrix, DVector};
use perturbid_rs::error::Limit;
use perturbid_rs::local::{
    identify_local, plan_experiments, CrossingTimes, Design, Estimator, ExperimentKind,
    IdentifyOptions, LocalModel, OperatingPoint, Plan, PlanOptions, Size, Sizes,
};
use perturbid_rs::regression::least_squares;
use perturbid_rs::robots::a465;
use perturbid_rs::Document;
use perturbid_rs::Gravity;
use perturbid_rs::{
    linearize, rnea, simulate_plan, Data, Error, Friction, Linearization, Model, Recording,
    SimulationOptions,
};

fn noise_free(model: &Model, gravity: Gravity) -> SimulationOptions {
    let mut sim = SimulationOptions::new(model);
    sim.gravity = gravity;
    sim.friction = Friction::none(model.nv);
    sim
}

fn identify(
    model: &Model,
    op: &OperatingPoint,
    plan_opts: &PlanOptions,
    sim: &SimulationOptions,
) -> (Plan, LocalModel) {
    let plan = plan_experiments(model, op, plan_opts).unwrap();
    let recs = simulate_plan(model, &plan, sim).unwrap();
    let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    (plan, m)
}

fn truth(model: &Model, op: &OperatingPoint, gravity: Gravity) -> Linearization {
    let mut data = Data::new(model);
    linearize(model, &mut data, &op.q, &op.qd, &op.qdd, gravity).unwrap()
}

/// The paper's experiment: D* = M(q*) and H* = d tau/d qd to 1e-9, T* = tau(P), Table 3's row.
#[test]
fn a465_table2_noise_free_d_h_exact() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let lin = truth(&model, &op, Gravity::Excluded);
    for design in [Design::Random, Design::Orthogonal] {
        let (_, m) = identify(
            &model,
            &op,
            &PlanOptions {
                design,
                ..PlanOptions::default()
            },
            &noise_free(&model, Gravity::Excluded),
        );
        assert!(
            rel(mat(&m.d), &lin.d) < 1e-9,
            "{design:?}: D* {:e}",
            rel(mat(&m.d), &lin.d)
        );
        assert!(
            rel(mat(&m.h), &lin.h) < 1e-9,
            "{design:?}: H* {:e}",
            rel(mat(&m.h), &lin.h)
        );
        let t = DVector::from_vec(m.torque.clone());
        assert!((&t - &lin.torque).norm() < 1e-9 * lin.torque.norm());
        // Table 3, "perturbation method" row, and Table 2's Tn (gravity excluded).
        for i in 0..6 {
            assert!(
                (mat(&m.d)[(i, 0)] - a465::TABLE3_D_COLUMN1[i]).abs() < 0.005,
                "D{}1",
                i + 1
            );
            assert!(
                (m.torque[i] - a465::TABLE2_TORQUE[i]).abs() < 0.01,
                "T{}",
                i + 1
            );
        }
        if design == Design::Orthogonal {
            for e in [&m.d, &m.h, &m.g, &m.g_static] {
                assert!((e.as_ref().unwrap().cond - 1.0).abs() < 1e-9);
            }
        }
    }
}

/// `|G_est - G*| <= |R| / sigma_min(X)`, R the exact remainder `tau(q* + dq_k) - T* - G* dq_k`
/// computed by RNEA; and the error falls as the size squared (symmetric pairs cancel even
/// orders). Same for Gs at rest with gravity.
#[test]
fn g_within_the_taylor_bound() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let lin = truth(&model, &op, Gravity::Included);
    let mut data = Data::new(&model);
    let mut errors = vec![];
    for scale in [1.0, 0.5] {
        let opts = PlanOptions {
            sizes: Sizes {
                position: Size::Fraction(0.01 * scale),
                ..Sizes::default()
            },
            ..PlanOptions::default()
        };
        let (plan, m) = identify(&model, &op, &opts, &noise_free(&model, Gravity::Included));
        for (kind, est, exact, qd, qdd, t0) in [
            (
                ExperimentKind::GDynamic,
                mat(&m.g),
                &lin.g,
                &op.qd,
                &op.qdd,
                lin.torque.clone(),
            ),
            (
                ExperimentKind::GStatic,
                mat(&m.g_static),
                &lin.g_static,
                &vec![0.0; 6],
                &vec![0.0; 6],
                {
                    perturbid_rs::gravity_torque(&model, &mut data, &op.q).unwrap();
                    data.g.clone()
                },
            ),
        ] {
            let x = &plan.experiment(kind).unwrap().deltas;
            let mut r = DMatrix::zeros(x.nrows(), 6);
            for k in 0..x.nrows() {
                let q: Vec<f64> = (0..6).map(|j| op.q[j] + x[(k, j)]).collect();
                rnea(&model, &mut data, &q, qd, qdd, Gravity::Included).unwrap();
                let rem = &data.tau - &t0 - exact * x.row(k).transpose();
                r.set_row(k, &rem.transpose());
            }
            let smin = x.clone().svd(false, false).singular_values.min();
            let bound = r.norm() / smin;
            let err = (est - exact).norm();
            assert!(
                err <= bound * 1.0001 + 1e-9,
                "{kind:?} scale {scale}: error {err:e} > bound {bound:e}"
            );
            errors.push(err);
        }
    }
    // halving the size quarters the error (even orders cancel, the cubic term remains)
    for i in 0..2 {
        let ratio = errors[i + 2] / errors[i];
        assert!((0.2..0.3).contains(&ratio), "error ratio {ratio}");
    }
}

/// Other operating points (random, inside the limits) of both A465 variants.
#[test]
fn other_operating_points() {
    let mut rng = Rng(7);
    for variant in ["kinsheel2010", "physical"] {
        let model = a465::model(variant).unwrap();
        for _ in 0..3 {
            let q: Vec<f64> = (0..6)
                .map(|j| 0.6 * rng.uniform(model.limits[j].lower, model.limits[j].upper))
                .collect();
            let op = OperatingPoint::new(q, rng.vector(6, 0.5), rng.vector(6, 1.5)).unwrap();
            let lin = truth(&model, &op, Gravity::Included);
            let (_, m) = identify(
                &model,
                &op,
                &PlanOptions {
                    design: Design::Orthogonal,
                    ..PlanOptions::default()
                },
                &noise_free(&model, Gravity::Included),
            );
            assert!(
                rel(mat(&m.d), &lin.d) < 1e-9,
                "{variant} D {:e}",
                rel(mat(&m.d), &lin.d)
            );
            assert!(
                rel(mat(&m.h), &lin.h) < 1e-9,
                "{variant} H {:e}",
                rel(mat(&m.h), &lin.h)
            );
            assert!(
                rel(mat(&m.g), &lin.g) < 0.02,
                "{variant} G {:e}",
                rel(mat(&m.g), &lin.g)
            );
        }
    }
}

/// Table 2's posture and accelerations at speeds of 0.3 to 0.5 rad/s, away from zero: Coulomb
/// friction keeps its sign and viscous friction gives H* a diagonal to measure.
fn table2_moving() -> OperatingPoint {
    OperatingPoint::new(
        a465::TABLE2_Q.to_vec(),
        vec![0.4, -0.35, 0.3, 0.5, -0.4, 0.45],
        a465::TABLE2_QDD.to_vec(),
    )
    .unwrap()
}

/// The common-mode claim: gravity and friction change T* and G, not D*; H* only by the
/// viscous slope. Velocities stay away from zero so Coulomb friction keeps its sign.
#[test]
fn common_mode_gravity_and_friction() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2_moving();
    let opts = PlanOptions {
        sizes: Sizes {
            velocity: Size::Absolute(vec![0.1; 6]),
            ..Sizes::default()
        },
        ..PlanOptions::default()
    };
    let (_, rigid) = identify(&model, &op, &opts, &noise_free(&model, Gravity::Excluded));
    let mut sim = noise_free(&model, Gravity::Included);
    let viscous = vec![2.0, 1.5, 1.0, 0.5, 0.4, 0.3];
    sim.friction = Friction::viscous_coulomb(viscous.clone(), vec![3.0, 2.5, 2.0, 1.0, 0.8, 0.5]);
    let (_, full) = identify(&model, &op, &opts, &sim);
    assert!(rel(mat(&full.d), mat(&rigid.d)) < 1e-9);
    let h_expected = mat(&rigid.h) + DMatrix::from_diagonal(&DVector::from_vec(viscous));
    assert!(rel(mat(&full.h), &h_expected) < 1e-9);
    // ... while the nominal torque moved by gravity and friction
    assert!(
        (DVector::from_vec(full.torque.clone()) - DVector::from_vec(rigid.torque.clone())).norm()
            > 1.0
    );
}

/// Perturbations too small for the torque noise give estimates of noise: each is named (with
/// how much larger the perturbations must be), and none at the paper's sizes where the torques
/// respond beyond the noise.
#[test]
fn estimates_of_noise_alone_are_warned_of() {
    let model = a465::model("kinsheel2010").unwrap();
    // Table 2's posture at speeds where viscous friction gives H* a diagonal to measure
    let op = table2_moving();
    let mut sim = noise_free(&model, Gravity::Included);
    sim.friction = Friction::viscous_coulomb(vec![2.0, 1.5, 1.0, 0.5, 0.4, 0.3], vec![0.0; 6]);
    sim.torque_noise = vec![0.05; 6];
    let unresolved = |m: &LocalModel| -> Vec<String> {
        m.diagnostics
            .warnings
            .iter()
            .filter(|w| w.contains("responded to the perturbations beyond its noise"))
            .cloned()
            .collect()
    };
    let paper_sizes = PlanOptions {
        sizes: Sizes {
            velocity: Size::Absolute(vec![0.1; 6]),
            ..Sizes::default()
        },
        ..PlanOptions::default()
    };
    let (_, paper) = identify(&model, &op, &paper_sizes, &sim);
    assert_eq!(unresolved(&paper), Vec::<String>::new());
    // Table 2's slow speeds without friction or noise: H* is a small Coriolis term under the
    // velocity-squared terms the +- pairs cancel; read by the pairs it is a response
    let (_, slow) = identify(
        &model,
        &table2(),
        &PlanOptions::default(),
        &noise_free(&model, Gravity::Included),
    );
    assert_eq!(unresolved(&slow), Vec::<String>::new());
    let tiny = PlanOptions {
        sizes: Sizes {
            position: Size::Fraction(1e-8),
            velocity: Size::Fraction(1e-8),
            acceleration: Size::Fraction(1e-8),
        },
        ..PlanOptions::default()
    };
    let (_, noise) = identify(&model, &op, &tiny, &sim);
    let found = unresolved(&noise);
    for (experiment, estimate) in [("G_static", "Gs"), ("G", "G*"), ("H", "H*"), ("D", "D*")] {
        assert!(
            found.iter().any(
                |w| w.starts_with(&format!("experiment '{experiment}': no joint"))
                    && w.contains(&format!("so {estimate} is not resolved"))
            ),
            "{experiment}: {found:#?}"
        );
    }
    // the friction-aware H regression reads its pairs' differences too
    let aware = PlanOptions {
        friction_aware_h: true,
        ..tiny.clone()
    };
    let plan = plan_experiments(&model, &op, &aware).unwrap();
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let options = IdentifyOptions {
        friction_aware_h: true,
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &recs, &options).unwrap();
    assert!(
        unresolved(&m)
            .iter()
            .any(|w| w.starts_with("experiment 'H': no joint")),
        "{:#?}",
        m.diagnostics.warnings
    );
    let plan = plan_experiments(
        &model,
        &op,
        &PlanOptions {
            friction_aware_h: true,
            ..paper_sizes.clone()
        },
    )
    .unwrap();
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let m = identify_local(&plan, &recs, &options).unwrap();
    assert_eq!(unresolved(&m), Vec::<String>::new());
    // the values are still there, with standard errors that say the same
    let d = noise.d.as_ref().unwrap();
    assert!(d
        .matrix
        .iter()
        .zip(d.stderr.iter())
        .all(|(v, s)| v.abs() < 6.0 * s));
}

/// With torque noise the D* error falls about as 1/sqrt(K).
#[test]
fn noise_error_falls_as_one_over_sqrt_k() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let lin = truth(&model, &op, Gravity::Included);
    let mut mean_err = vec![];
    for k in [16, 64, 256] {
        let mut acc = 0.0;
        let seeds = 12;
        for seed in 0..seeds {
            let opts = PlanOptions {
                experiments: vec![ExperimentKind::Nominal, ExperimentKind::D],
                design: Design::Orthogonal,
                count: Some(k),
                seed,
                ..PlanOptions::default()
            };
            let mut sim = noise_free(&model, Gravity::Included);
            sim.torque_noise = vec![0.05; 6];
            sim.seed = 100 + seed;
            let (_, m) = identify(&model, &op, &opts, &sim);
            acc += (mat(&m.d) - &lin.d).norm();
        }
        mean_err.push(acc / seeds as f64);
    }
    for i in 0..2 {
        let ratio = mean_err[i] / mean_err[i + 1]; // K x4 -> error /2
        assert!((1.6..2.5).contains(&ratio), "errors {mean_err:?}");
    }
}

#[test]
fn plan_trajectories_pass_the_crossings_c2_from_rest_to_rest() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    assert_eq!(plan.experiments.len(), 5);
    for e in &plan.experiments {
        assert_eq!(e.crossings.len(), 12);
        let s = e.trajectory.sample(plan.rate);
        let last = s.len() - 1;
        for j in 0..6 {
            assert_eq!(s.qd_at(0)[j], 0.0);
            assert_eq!(s.qdd_at(0)[j], 0.0);
            assert!(s.qd_at(last)[j].abs() < 1e-9 && s.qdd_at(last)[j].abs() < 1e-9);
            assert!((s.q_at(last)[j] - plan.op.q[j]).abs() < 1e-9);
        }
        for c in &e.crossings {
            let i = (c.time * plan.rate).round() as usize;
            assert!((s.t[i] - c.time).abs() < 1e-12, "crossing on the grid");
            for j in 0..6 {
                assert!((s.q_at(i)[j] - c.q[j]).abs() < 1e-12);
                assert!((s.qd_at(i)[j] - c.qd[j]).abs() < 1e-12);
                assert!((s.qdd_at(i)[j] - c.qdd[j]).abs() < 1e-12);
            }
        }
        for w in e.trajectory.segments.windows(2) {
            assert_eq!(w[0].t1, w[1].t0);
            for j in 0..6 {
                let (a, b) = (w[0].eval(j, w[0].t1), w[1].eval(j, w[1].t0));
                assert!(
                    (a.0 - b.0).abs() < 1e-9
                        && (a.1 - b.1).abs() < 1e-9
                        && (a.2 - b.2).abs() < 1e-8,
                    "C2 at {}",
                    w[0].t1
                );
            }
        }
        // the planned perturbations are exactly the crossing deltas
        if let Some(v) = e.kind.perturbed() {
            for (k, c) in e.crossings.iter().enumerate() {
                let (x, x0) = match v {
                    0 => (&c.q, &plan.op.q),
                    1 => (&c.qd, &plan.op.qd),
                    _ => (&c.qdd, &plan.op.qdd),
                };
                for j in 0..6 {
                    assert!((x[j] - x0[j] - e.deltas[(k, j)]).abs() < 1e-12);
                }
            }
        }
    }
}

#[test]
fn plans_breaking_limits_are_refused_with_joint_and_time() {
    let model = a465::model("kinsheel2010").unwrap();
    // joint 2 (shoulder) 0.01 rad inside its upper limit: a 1 % of range position step breaks it
    let mut q = a465::TABLE2_Q.to_vec();
    q[1] = model.limits[1].upper - 0.01;
    let op = OperatingPoint::new(q, a465::TABLE2_QD.to_vec(), a465::TABLE2_QDD.to_vec()).unwrap();
    let err = plan_experiments(&model, &op, &PlanOptions::default()).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(&err, Error::LimitViolation(v) if matches!(v.limit, Limit::Position { .. })),
        "{msg}"
    );
    assert!(
        msg.contains("shoulder") || msg.contains("joint2") || msg.contains(&model.joint_names[1]),
        "{msg}"
    );
    assert!(msg.contains("t = ") && msg.contains("experiment"), "{msg}");
    // velocity near its limit: the H experiment exceeds it
    let mut qd = a465::TABLE2_QD.to_vec();
    qd[0] = 0.99 * model.limits[0].velocity;
    let op = OperatingPoint::new(a465::TABLE2_Q.to_vec(), qd, a465::TABLE2_QDD.to_vec()).unwrap();
    let err = plan_experiments(&model, &op, &PlanOptions::default()).unwrap_err();
    assert!(
        matches!(&err, Error::LimitViolation(v) if matches!(v.limit, Limit::Velocity(_))),
        "{err}"
    );
    assert!(err.to_string().contains(&model.joint_names[0]));
    // an operating point outside the limits, and bad options
    let mut q = a465::TABLE2_Q.to_vec();
    q[2] = 3.0;
    let op = OperatingPoint::new(q, vec![0.0; 6], vec![0.0; 6]).unwrap();
    assert!(plan_experiments(&model, &op, &PlanOptions::default())
        .unwrap_err()
        .to_string()
        .contains("joint"));
    let bad = PlanOptions {
        count: Some(7),
        ..PlanOptions::default()
    };
    assert!(plan_experiments(&model, &table2(), &bad)
        .unwrap_err()
        .to_string()
        .contains("even number"));
    assert!(OperatingPoint::new(vec![0.0; 6], vec![0.0; 5], vec![0.0; 6]).is_err());
}

#[test]
fn recordings_with_problems_get_clear_errors() {
    let t = vec![0.0, 0.001, 0.002];
    let e = Recording::new(
        "r",
        1,
        vec![0.0, 0.002, 0.001],
        vec![0.0; 3],
        vec![0.0; 3],
        None,
        None,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("not increasing at sample 2")
            && e.to_string()
                .contains("a step back (logs joined end to end")
            && e.to_string()
                .contains("0 repeated time stamp(s) and 1 step(s) back in all"),
        "{e}"
    );
    // a repeated stamp, twice: named as such, and counted
    let e = Recording::new(
        "r",
        1,
        vec![0.0, 0.001, 0.001, 0.002, 0.002],
        vec![0.0; 5],
        vec![0.0; 5],
        None,
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("not increasing at sample 2: t = 0.001 after 0.001: a repeated time stamp")
            && e.contains("drop the repeated rows")
            && e.contains("2 repeated time stamp(s) and 0 step(s) back in all"),
        "{e}"
    );
    let e = Recording::new(
        "r",
        1,
        t.clone(),
        vec![0.0, f64::NAN, 0.0],
        vec![0.0; 3],
        None,
        None,
    )
    .unwrap_err();
    assert!(e.to_string().contains("q of joint 1 at sample 1"), "{e}");
    let e = Recording::new("r", 2, t.clone(), vec![0.0; 3], vec![0.0; 6], None, None).unwrap_err();
    assert!(
        e.to_string().contains("expected 3 samples x 2 joints"),
        "{e}"
    );
    assert!(Recording::new("r", 1, vec![0.0], vec![0.0], vec![0.0], None, None).is_err());

    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mut recs = simulate_plan(&model, &plan, &noise_free(&model, Gravity::Included)).unwrap();
    // too short: cut the D recording in half
    let d = plan
        .experiments
        .iter()
        .position(|e| e.kind == ExperimentKind::D)
        .unwrap();
    let r = &recs[d];
    let half = r.len() / 2;
    recs[d] = Recording::new(
        "cut",
        6,
        r.t[..half].to_vec(),
        r.q[..half * 6].to_vec(),
        r.tau[..half * 6].to_vec(),
        None,
        None,
    )
    .unwrap()
    .for_experiment("D");
    let e = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("cut: experiment 'D', crossing")
            && e.to_string().contains("too short"),
        "{e}"
    );
    // too few samples per window: decimate to 50 Hz
    let r = simulate_plan(&model, &plan, &noise_free(&model, Gravity::Included))
        .unwrap()
        .remove(d);
    let keep: Vec<usize> = (0..r.len()).step_by(20).collect();
    recs[d] = Recording::new(
        "sparse",
        6,
        keep.iter().map(|&i| r.t[i]).collect(),
        keep.iter()
            .flat_map(|&i| r.q[i * 6..i * 6 + 6].to_vec())
            .collect(),
        keep.iter()
            .flat_map(|&i| r.tau[i * 6..i * 6 + 6].to_vec())
            .collect(),
        None,
        None,
    )
    .unwrap()
    .for_experiment("D");
    let e = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap_err();
    assert!(
        e.to_string().starts_with("sparse: its median sample interval is 0.02 s, so a crossing window of +-0.05 s holds at most 5 samples where the fits need 9"),
        "{e}"
    );
    // a missing recording is named
    recs.pop();
    let e = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "recordings: experiment 'D' of the plan has no recording"
    );
}

/// Recordings are matched with experiments by identity, never by order: shuffled recordings
/// give the same model; unmarked, unknown and doubled ones are refused by name.
#[test]
fn recordings_are_matched_by_experiment_not_order() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let recs = simulate_plan(&model, &plan, &noise_free(&model, Gravity::Excluded)).unwrap();
    let options = IdentifyOptions::default();
    let model_in_order = identify_local(&plan, &recs, &options).unwrap();
    let mut shuffled = recs.clone();
    shuffled.reverse();
    shuffled.swap(0, 2);
    assert_eq!(
        identify_local(&plan, &shuffled, &options).unwrap(),
        model_in_order
    );
    // a file named after its experiment needs no mark
    let mut named = recs.clone();
    for r in &mut named {
        r.name = format!("rec/{}.csv", r.experiment.take().unwrap());
    }
    named.reverse();
    assert_eq!(
        identify_local(&plan, &named, &options).unwrap(),
        model_in_order
    );
    let refused = |recs: &[Recording], says: &str| {
        let e = identify_local(&plan, recs, &options)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e}");
    };
    let mut unmarked = recs.clone();
    unmarked[1].experiment = None;
    refused(&unmarked, "does not say which experiment it is a run of");
    let mut unknown = recs.clone();
    unknown[1].experiment = Some("E".into());
    refused(
        &unknown,
        "a run of experiment 'E', which the plan does not have",
    );
    let mut doubled = recs.clone();
    doubled[1].experiment = Some("D".into());
    refused(&doubled, "are both runs of experiment 'D'");
}

/// The recordings of H and D swapped (each marked as the other) are refused by the position
/// check; H's recording given for D too is said not to show D's perturbations and to follow
/// H's, with encoder noise and torque noise; the recordings as they are raise no such warning.
#[test]
fn swapped_recordings_are_named() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.torque_noise = vec![0.05; 6];
    sim.position_noise = vec![1e-5; 6];
    sim.seed = 3;
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let options = IdentifyOptions::default();
    let follows = |m: &LocalModel| -> Vec<String> {
        (m.diagnostics.warnings.iter())
            .filter(|w| w.contains("do not follow the plan's"))
            .cloned()
            .collect()
    };
    let as_recorded = identify_local(&plan, &recs, &options).unwrap();
    assert!(
        follows(&as_recorded).is_empty(),
        "{:?}",
        follows(&as_recorded)
    );
    // swapped both ways: D's recording moves the third joint less than a quarter of what H's
    // plan moves it, and the position check refuses it as a run of H
    let mut swapped = recs.clone();
    for r in &mut swapped {
        r.experiment = match r.experiment.as_deref() {
            Some("H") => Some("D".into()),
            Some("D") => Some("H".into()),
            other => other.map(str::to_string),
        };
    }
    let e = identify_local(&plan, &swapped, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("do not follow the plan of experiment 'H'")
            && e.contains("'joint3' moved 0.0014 RMS where the plan moves it 0.0078 RMS"),
        "{e}"
    );
    // H's run given for D too (it moves more than D's plan, which the position check allows):
    // its perturbations do not follow D's plan, and follow H's
    let mut twice = recs.clone();
    let h = twice
        .iter()
        .position(|r| r.experiment.as_deref() == Some("H"))
        .unwrap();
    let d = twice
        .iter()
        .position(|r| r.experiment.as_deref() == Some("D"))
        .unwrap();
    twice[d] = Recording {
        experiment: Some("D".into()),
        ..twice[h].clone()
    };
    let w = follows(&identify_local(&plan, &twice, &options).unwrap());
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("experiment 'D': the perturbations its recording shows (dqdd)")
            && w[0].contains("it follows the plan of experiment 'H' instead")
            && w[0].contains("are the recordings of 'D' and 'H' swapped?"),
        "{w:?}"
    );
}

#[test]
fn rank_deficient_design_names_the_missing_direction() {
    let x = DMatrix::from_row_slice(
        4,
        3,
        &[
            1.0, 1.0, 0.0, -1.0, -1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, -1.0,
        ],
    );
    let y = DMatrix::from_element(4, 2, 1.0);
    let names: Vec<String> = ["dq(a)", "dq(b)", "dq(c)"].map(String::from).to_vec();
    let e = least_squares(&x, &y, "experiment 'G'", &names).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::RankDeficient { rank: 2, .. }), "{msg}");
    assert!(msg.contains("0.707 dq(a) - 0.707 dq(b)"), "{msg}");
    // Phi theta = tau: an exact linear system is solved exactly
    let x = DMatrix::from_fn(10, 3, |i, j| {
        ((i * 7 + j * 3) % 5) as f64 - 2.0 + 0.1 * j as f64
    });
    let a = DMatrix::from_row_slice(2, 3, &[1.0, -2.0, 0.5, 3.0, 0.0, -1.0]);
    let ls = least_squares(&x, &(&x * a.transpose()), "exact", &names).unwrap();
    assert!((ls.coef - a).norm() < 1e-12);
    assert!(ls.residual_rms.norm() < 1e-12);
}

/// Outputs far from 1 are fitted as well as outputs near it: the coefficients, residuals and
/// standard errors scale with the outputs (a torque column of 1e300 N m squared to inf before),
/// and a fit whose coefficients would overflow is an error, not an infinity.
#[test]
fn least_squares_scales_with_the_outputs_and_refuses_overflow() {
    let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let x = DMatrix::from_fn(12, 3, |i, j| {
        ((i * 5 + j * 7) % 11) as f64 - 5.0 + 0.3 * j as f64
    });
    let y = DMatrix::from_fn(12, 2, |i, c| {
        (x[(i, 0)] - 2.0 * x[(i, 1)] + c as f64 * x[(i, 2)]) + ((i * 3 + c) % 4) as f64 * 0.1
    });
    let base = least_squares(&x, &y, "base", &names).unwrap();
    for scale in [1e-300, 1e-100, 1e100, 1e300] {
        let ls = least_squares(&x, &(&y * scale), "scaled", &names).unwrap();
        assert!(
            ls.stderr.iter().all(|s| s.is_finite() && *s > 0.0),
            "{scale:e}: {}",
            ls.stderr
        );
        for (a, b) in ls.coef.iter().zip(base.coef.iter()) {
            assert!(
                (a / scale - b).abs() <= 1e-12 * b.abs().max(1.0),
                "{scale:e}: {a:e} {b:e}"
            );
        }
        for (a, b) in ls.stderr.iter().zip(base.stderr.iter()) {
            assert!((a / scale - b).abs() <= 1e-10 * b, "{scale:e}: {a:e} {b:e}");
        }
        for (a, b) in ls.residual_rms.iter().zip(base.residual_rms.iter()) {
            assert!((a / scale - b).abs() <= 1e-10 * b, "{scale:e}: {a:e} {b:e}");
        }
    }
    // so do regressors: a column of 1e-200 is not taken for zeros, nor one of 1e200 for inf
    for scale in [1e-200, 1e200] {
        let ls = least_squares(&(&x * scale), &y, "scaled", &names).unwrap();
        for (a, b) in ls.coef.iter().zip(base.coef.iter()) {
            assert!(
                (a * scale - b).abs() <= 1e-12 * b.abs().max(1.0),
                "{scale:e}: {a:e} {b:e}"
            );
        }
        assert!((ls.cond - base.cond).abs() <= 1e-10 * base.cond);
    }
    // regressors of 1e-300 against outputs of 1e300: coefficients past f64
    let e = least_squares(&(&x * 1e-300), &(&y * 1e300), "experiment 'D'", &names).unwrap_err();
    assert!(matches!(e, Error::Numerical { .. }), "{e}");
    assert!(
        e.to_string().contains("experiment 'D'") && e.to_string().contains("overflow"),
        "{e}"
    );
}

#[test]
fn detected_crossing_times_recover_a_shifted_log() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let recs: Vec<Recording> = simulate_plan(&model, &plan, &noise_free(&model, Gravity::Excluded))
        .unwrap()
        .into_iter()
        .map(|mut r| {
            r.t.iter_mut().for_each(|t| *t += 0.137);
            r
        })
        .collect();
    let opts = IdentifyOptions {
        times: CrossingTimes::Detected { max_shift: 0.5 },
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &recs, &opts).unwrap();
    let lin = truth(&model, &op, Gravity::Excluded);
    assert!(
        rel(mat(&m.d), &lin.d) < 1e-8,
        "{:e}",
        rel(mat(&m.d), &lin.d)
    );
}

#[test]
fn combined_estimator_and_json_round_trip() {
    let model = a465::model("kinsheel2010").unwrap();
    let op = table2();
    let plan = plan_experiments(
        &model,
        &op,
        &PlanOptions {
            design: Design::Orthogonal,
            ..PlanOptions::default()
        },
    )
    .unwrap();
    let recs = simulate_plan(&model, &plan, &noise_free(&model, Gravity::Included)).unwrap();
    let opts = IdentifyOptions {
        estimator: Estimator::Combined,
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &recs, &opts).unwrap();
    let lin = truth(&model, &op, Gravity::Included);
    assert_eq!(m.combined.as_ref().unwrap().matrix.shape(), (6, 18));
    assert!(
        rel(mat(&m.d), &lin.d) < 1e-3,
        "{:e}",
        rel(mat(&m.d), &lin.d)
    );
    assert!(
        rel(mat(&m.g), &lin.g) < 2e-3,
        "{:e}",
        rel(mat(&m.g), &lin.g)
    );
    // predict: T* at P, and the local model's own linear law
    let p = m
        .predict(&perturbid_rs::States::single(op.n(), &op.q, Some(&op.qd), Some(&op.qdd)).unwrap())
        .unwrap();
    assert!((DVector::from_vec(p) - &lin.torque).norm() < 1e-6);
    let back = LocalModel::from_json(&m.to_json()).unwrap();
    assert!(back == m, "the JSON round trip changed the model");
    let plan_back = Plan::from_json(&plan.to_json()).unwrap();
    assert!(plan_back == plan, "the JSON round trip changed the plan");
    let e = LocalModel::from_json("{\"format\": 3}").unwrap_err();
    assert!(e.to_string().contains("line 1"), "{e}");
    let broken = m.to_json().replace(LOCAL_FORMAT, "something-else/9");
    assert!(LocalModel::from_json(&broken)
        .unwrap_err()
        .to_string()
        .contains("format"));
}

const LOCAL_FORMAT: &str = "perturbid-local-model/1";

/// A regression without residual degrees of freedom (K = N) has unknown standard errors: NaN
/// in Rust, `null` in the saved model, NaN again when loaded.
#[test]
fn unknown_standard_errors_survive_a_json_round_trip() {
    let model = a465::model("kinsheel2010").unwrap();
    let opts = PlanOptions {
        experiments: vec![ExperimentKind::Nominal, ExperimentKind::D],
        symmetric: false,
        count: Some(6),
        ..PlanOptions::default()
    };
    let (_, m) = identify(
        &model,
        &table2(),
        &opts,
        &noise_free(&model, Gravity::Excluded),
    );
    let d = m.d.as_ref().unwrap();
    assert!(d.stderr.iter().all(|s| s.is_nan()), "{}", d.stderr);
    let text = m.to_json();
    assert!(text.contains("null"));
    let back = LocalModel::from_json(&text).unwrap();
    assert!(back.d.as_ref().unwrap().stderr.iter().all(|s| s.is_nan()));
    assert_eq!(back.d.as_ref().unwrap().matrix, d.matrix);
    // a number beyond any robot's (a slip of the exponent, corruption) is refused by entry:
    // one such entry of D* disabled the block's other rows in the parameters fit and left
    // residuals of 1e19 without a word
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 3] = [
        (
            |v| v["d"]["matrix"][5][1] = 1e20.into(),
            "d.matrix[5][1] is 1e20; numbers of a local model are at most 1e9 in size",
        ),
        (
            |v| v["torque"][2] = (-2e9).into(),
            "torque[2] is -2e9; numbers",
        ),
        (|v| v["op"]["q"][0] = 1e300.into(), "op.q[0] is 1e300"),
    ];
    common::refused_on_load::<LocalModel>(&value, &edits);
}

/// The warning about a D* no mass matrix has (tested on constructed estimates in
/// `src/local/diagnose.rs`) stays silent on a sound identification with noise, over seeds:
/// with 3 standard errors a pair and the plan's 6 residual degrees of freedom it warned on 3
/// of 12 seeds.
#[test]
fn a_sound_d_star_raises_no_mass_matrix_warning() {
    use perturbid_rs::local::IdentifyOptions;
    use perturbid_rs::{simulate_plan, SimulationOptions};
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let plan = plan_experiments(&model, &common::table2(), &PlanOptions::default()).unwrap();
    let cases = [(0.0, 0), (0.1, 0)]
        .into_iter()
        .chain((0..12).map(|seed| (0.01, seed)));
    for (noise, seed) in cases {
        let mut sim = SimulationOptions::new(&model);
        sim.torque_noise = vec![noise; n];
        sim.seed = seed;
        let recs = simulate_plan(&model, &plan, &sim).unwrap();
        let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
        assert!(
            !m.diagnostics.warnings.iter().any(|w| w.contains("D* is")),
            "noise {noise}, seed {seed}: {:?}",
            m.diagnostics.warnings
        );
    }
}

/// A torque channel that reads one value throughout (dead, saturated, or far coarser than the
/// perturbations' effect) gives a row of zeros whose standard errors of zero would claim
/// certainty: the row's standard errors become NaN, a warning names the experiment, joint and
/// value, and the other rows keep their values. Without it, no warning.
#[test]
fn a_torque_channel_that_does_not_change_is_warned_about() {
    let common::Table2Local {
        model,
        plan,
        recs,
        local: clean,
        ..
    } = common::table2_local();
    let n = model.nv;
    assert!(
        !clean
            .diagnostics
            .warnings
            .iter()
            .any(|w| w.contains("same value")),
        "{:?}",
        clean.diagnostics.warnings
    );
    // joint 3's channel stuck at 12.5 N m in the D experiment's recording
    let mut stuck = recs.clone();
    let d = stuck
        .iter_mut()
        .find(|r| r.experiment.as_deref() == Some("D"))
        .unwrap();
    for i in 0..d.t.len() {
        d.tau[i * n + 2] = 12.5;
    }
    let m = identify_local(&plan, &stuck, &IdentifyOptions::default()).unwrap();
    let w: Vec<&String> = m
        .diagnostics
        .warnings
        .iter()
        .filter(|w| w.contains("same value"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", m.diagnostics.warnings);
    assert!(
        w[0].contains("experiment 'D'")
            && w[0].contains("'joint3' (12.5 N m)")
            && w[0].contains("D*"),
        "{}",
        w[0]
    );
    let est = m.d.as_ref().unwrap();
    for i in 0..n {
        for j in 0..n {
            assert_eq!(est.stderr[(i, j)].is_nan(), i == 2, "{}", est.stderr);
        }
    }
    // the other rows are those of the clean identification but for the noise, and finite
    let c = clean.d.as_ref().unwrap();
    for i in (0..n).filter(|&i| i != 2) {
        for j in 0..n {
            assert_eq!(est.matrix[(i, j)], c.matrix[(i, j)]);
        }
    }
    // recorded in the diagnostics, and left out of the robot's parameters from the model
    assert_eq!(m.diagnostics.unmeasured.len(), 1);
    let u = &m.diagnostics.unmeasured[0];
    assert_eq!(
        (u.experiment.as_str(), u.joint.as_str(), u.value),
        ("D", "joint3", 12.5)
    );
    let from = |m: &LocalModel| {
        perturbid_rs::local::identify_parameters_from_local(
            &model,
            std::slice::from_ref(m),
            &perturbid_rs::local::FromLocalOptions::default(),
        )
        .unwrap()
    };
    assert_eq!(from(&m).rows + n, from(&clean).rows);
    let back = LocalModel::from_json(&m.to_json()).unwrap();
    assert_eq!(back.diagnostics.unmeasured, m.diagnostics.unmeasured);
    // the combined estimate's row for joint 3 is no more certain
    let opts = IdentifyOptions {
        estimator: Estimator::Combined,
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &stuck, &opts).unwrap();
    let comb = m.combined.as_ref().unwrap();
    assert!(comb.stderr.row(2).iter().all(|s| s.is_nan()));
    assert!(comb.stderr.row(1).iter().all(|s| s.is_finite()));
    // there joint 3's rows of D*, H* and G* all come from the one fit: all left out
    assert_eq!(from(&m).rows + 3 * n, from(&clean).rows);
}

/// The A465 ("kinsheel2010") planned at the paper's Table 2 point and rehearsed with 0.01 N m
/// of torque noise: the model, the simulation's options, the plan and the recordings.
fn noisy_rehearsal() -> (perturbid_rs::Model, SimulationOptions, Plan, Vec<Recording>) {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.torque_noise = vec![0.01; model.nv];
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    (model, sim, plan, recs)
}

/// A recording whose stamps jitter over the regular clock its samples were taken on (a ROS
/// bag's receive time) is named with its experiment; the clean rehearsal is not.
#[test]
fn a_recording_whose_stamps_jitter_is_named() {
    let (_, _, plan, recs) = noisy_rehearsal();
    let says = |m: &LocalModel| {
        (m.diagnostics.warnings.iter())
            .filter(|w| w.contains("its time stamps jitter"))
            .cloned()
            .collect::<Vec<_>>()
    };
    let clean = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    assert!(says(&clean).is_empty(), "{:?}", says(&clean));
    let mut jittered = recs.clone();
    let d = (jittered.iter_mut())
        .find(|r| r.experiment.as_deref() == Some("D"))
        .unwrap();
    let mut rng = common::Rng(3);
    for t in &mut d.t {
        *t += 1e-4 * common::normal(&mut rng);
    }
    let m = identify_local(&plan, &jittered, &IdentifyOptions::default()).unwrap();
    let w = says(&m);
    assert!(w.len() == 1 && w[0].starts_with("experiment 'D'"), "{w:?}");
}

/// A torque column logged with the opposite sign in every recording (another sign convention
/// for that joint) leaves every experiment consistent with the nominal one, so no torque offset
/// shows it; D* does: its row of that joint is a mass matrix's negated (a negative diagonal
/// entry, symmetric and positive definite once negated), and the warning names the joint.
#[test]
fn a_torque_column_negated_in_every_recording_is_named_from_d_star() {
    let (model, _, plan, recs) = noisy_rehearsal();
    let n = model.nv;
    let run =
        |recs: &[Recording]| identify_local(&plan, recs, &IdentifyOptions::default()).unwrap();
    let d_warning = |m: &LocalModel| {
        (m.diagnostics.warnings.iter())
            .find(|w| w.starts_with("D* is"))
            .cloned()
    };
    assert_eq!(d_warning(&run(&recs)), None);
    for joint in [1, 4] {
        let mut negated = recs.clone();
        for r in &mut negated {
            for i in 0..r.t.len() {
                r.tau[i * n + joint] = -r.tau[i * n + joint];
            }
        }
        let m = run(&negated);
        let w = d_warning(&m).expect("a D* warning");
        let name = format!("'joint{}' (D(joint{0},joint{0}) = -", joint + 1);
        assert!(
            w.contains(&format!("rows of joint(s) {name}"))
                && w.contains("logged with the opposite sign to its position"),
            "{w}"
        );
        assert!(m.diagnostics.torque_offsets.is_empty());
    }
}

/// Torques that do not return to T* between an experiment's perturbations: torque columns
/// swapped in one recording, or one offset, are found with the joints and named (a swap as
/// such; one in the nominal recording by G and D alike; in H only a swap), listed in the
/// diagnostics and kept through JSON; a clean rehearsal, and a channel stuck at one value (reported as unmeasured),
/// have none. Without +- pairs the warning says the offset biases the estimate.
#[test]
fn torques_that_do_not_return_to_t_star_are_found() {
    let (model, sim, plan, recs) = noisy_rehearsal();
    let n = model.nv;
    let run =
        |recs: &[Recording]| identify_local(&plan, recs, &IdentifyOptions::default()).unwrap();
    let offsets = |m: &LocalModel| -> Vec<(String, String)> {
        m.diagnostics
            .torque_offsets
            .iter()
            .map(|t| (t.experiment.clone(), t.joint.clone()))
            .collect()
    };
    let pairs = |list: &[(&str, &str)]| -> Vec<(String, String)> {
        list.iter()
            .map(|(e, j)| (e.to_string(), j.to_string()))
            .collect()
    };
    let says = |m: &LocalModel, text: &str| m.diagnostics.warnings.iter().any(|w| w.contains(text));
    let clean = run(&recs);
    assert!(
        offsets(&clean).is_empty(),
        "{:?}",
        clean.diagnostics.torque_offsets
    );
    assert!(
        !says(&clean, "do not return"),
        "{:?}",
        clean.diagnostics.warnings
    );
    let edited = |experiment: &str, edit: &dyn Fn(&mut Recording)| {
        let mut r = recs.to_vec();
        edit(
            r.iter_mut()
                .find(|r| r.experiment.as_deref() == Some(experiment))
                .unwrap(),
        );
        run(&r)
    };
    let swap = |a: usize, b: usize| {
        move |r: &mut Recording| {
            for i in 0..r.t.len() {
                r.tau.swap(i * n + a, i * n + b);
            }
        }
    };
    // joints 3 and 6 swapped in D: T* is -1.02 and 0.05 N m there
    let m = edited("D", &swap(2, 5));
    assert_eq!(offsets(&m), pairs(&[("D", "joint3"), ("D", "joint6")]));
    let t = &m.diagnostics.torque_offsets[0];
    let gap = clean.torque[5] - clean.torque[2];
    assert!(
        (t.offset - gap).abs() < 0.01 * gap.abs(),
        "{t:?} against {gap}"
    );
    assert!(t.offset.abs() > 100.0 * t.stderr, "{t:?}");
    assert!(
        says(&m, "experiment 'D': the torques of 'joint3' (")
            && says(&m, "'joint3' and 'joint6' are off by each other's T*")
            && says(&m, "their rows of D* are each other's")
            && says(
                &m,
                "does not bias them (the perturbations come in +- pairs)"
            ),
        "{:?}",
        m.diagnostics.warnings
    );
    assert!(!says(&m, "minus twice"), "{:?}", m.diagnostics.warnings);
    let back = LocalModel::from_json(&m.to_json()).unwrap();
    assert_eq!(
        back.diagnostics.torque_offsets,
        m.diagnostics.torque_offsets
    );
    // the elbow's torque negated in D (another sign convention): off by -2 T*, and named so
    let m = edited("D", &|r: &mut Recording| {
        for i in 0..r.t.len() {
            r.tau[i * n + 2] = -r.tau[i * n + 2];
        }
    });
    assert_eq!(offsets(&m), pairs(&[("D", "joint3")]));
    let t = &m.diagnostics.torque_offsets[0];
    let opposite = -2.0 * clean.torque[2];
    assert!(
        (t.offset - opposite).abs() < 0.01 * opposite.abs(),
        "{t:?} against {opposite}"
    );
    assert!(
        says(&m, "'joint3' is off by minus twice its T*: its torque column looks negated in the D recording or in the nominal one")
            && says(&m, "its row of D* is negated too"),
        "{:?}",
        m.diagnostics.warnings
    );
    // in H only swaps are findings (its velocity-squared terms give an intercept of their
    // own): joints 3 and 6 swapped there are found, the shoulder 0.5 N m higher is not
    let m = edited("H", &swap(2, 5));
    assert_eq!(offsets(&m), pairs(&[("H", "joint3"), ("H", "joint6")]));
    assert!(
        says(&m, "their rows of H* are each other's"),
        "{:?}",
        m.diagnostics.warnings
    );
    let m = edited("H", &|r: &mut Recording| {
        for i in 0..r.t.len() {
            r.tau[i * n + 1] += 0.5;
        }
    });
    assert!(offsets(&m).is_empty(), "{:?}", m.diagnostics.torque_offsets);
    // the shoulder's torque 0.5 N m higher in G: an offset, no swap
    let m = edited("G", &|r: &mut Recording| {
        for i in 0..r.t.len() {
            r.tau[i * n + 1] += 0.5;
        }
    });
    assert_eq!(offsets(&m), pairs(&[("G", "joint2")]));
    assert!((m.diagnostics.torque_offsets[0].offset - 0.5).abs() < 0.01);
    assert!(
        says(&m, "The recordings' torques look offset") && !says(&m, "swapped"),
        "{:?}",
        m.diagnostics.warnings
    );
    // the shoulder and the elbow swapped in the nominal recording: G and D see the same
    let m = edited("nominal", &swap(1, 2));
    assert_eq!(
        offsets(&m),
        pairs(&[
            ("G", "joint2"),
            ("G", "joint3"),
            ("H", "joint2"),
            ("H", "joint3"),
            ("D", "joint2"),
            ("D", "joint3")
        ])
    );
    assert!(
        says(
            &m,
            "experiments 'G', 'H' and 'D' find the same torque offsets of 'joint2', 'joint3'"
        ) && says(&m, "the nominal recording"),
        "{:?}",
        m.diagnostics.warnings
    );
    // a channel stuck at one value is unmeasured, not an offset
    let m = edited("D", &|r: &mut Recording| {
        for i in 0..r.t.len() {
            r.tau[i * n + 2] = 12.5;
        }
    });
    assert!(offsets(&m).is_empty(), "{:?}", m.diagnostics.torque_offsets);
    assert_eq!(m.diagnostics.unmeasured.len(), 1);
    // perturbations not in +- pairs: the offset biases the estimate, and the warning says so
    let lone = PlanOptions {
        symmetric: false,
        experiments: vec![ExperimentKind::Nominal, ExperimentKind::D],
        ..PlanOptions::default()
    };
    let plan = plan_experiments(&model, &table2(), &lone).unwrap();
    let mut recs = simulate_plan(&model, &plan, &sim).unwrap();
    let d = recs
        .iter_mut()
        .find(|r| r.experiment.as_deref() == Some("D"))
        .unwrap();
    for i in 0..d.t.len() {
        d.tau[i * n] += 0.3;
    }
    let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    assert_eq!(offsets(&m), pairs(&[("D", "joint1")]));
    assert!(
        says(
            &m,
            "biases them (the perturbations do not come in +- pairs)"
        ),
        "{:?}",
        m.diagnostics.warnings
    );
    // a saved finding naming a joint the model does not have is refused on load
    let mut v: serde_json::Value = serde_json::from_str(&back.to_json()).unwrap();
    v["diagnostics"]["torque_offsets"][0]["joint"] = serde_json::json!("joint9");
    let text = v.to_string();
    let e = LocalModel::from_json(&text).unwrap_err().to_string();
    assert!(e.contains("joint 'joint9'"), "{e}");
}

/// The error of loading the plan saved as `text` after the edit `f` (which must be refused).
fn refused_plan_edit(text: &str, f: &dyn Fn(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
    f(&mut v);
    Plan::from_json(&v.to_string())
        .map(|_| ())
        .unwrap_err()
        .to_string()
}

/// A plan read from a file is what the robot will run: a hand edit that makes its trajectory
/// jump, leave f64's range, start moving, or disagree with its crossings is refused with the
/// experiment, segment or crossing and joint; a plan made for wider limits than the robot's is
/// refused when simulated on it.
#[test]
fn hand_edited_plans_are_refused_where_they_break_the_trajectory() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let text = plan.to_json();
    assert!(Plan::from_json(&text).is_ok());
    let edited = |f: &dyn Fn(&mut serde_json::Value)| refused_plan_edit(&text, f);
    // D's fourth segment with one coefficient changed: a jump at one of its ends
    let e = edited(&|v| {
        let c = &mut v["experiments"][4]["trajectory"]["segments"][3]["coeffs"][2][4];
        *c = serde_json::json!(c.as_f64().unwrap() + 1.0);
    });
    assert!(
        e.contains("experiments[4] ('D')")
            && e.contains("joint 3: the position jumps")
            && (e.contains("between segments[3] and segments[4]")
                || e.contains("between segments[2] and segments[3]")),
        "{e}"
    );
    let e = edited(&|v| {
        v["experiments"][2]["trajectory"]["segments"][5]["coeffs"][1][5] = serde_json::json!(1e308)
    });
    assert!(
        e.contains("experiments[2]") && e.contains("beyond f64's range"),
        "{e}"
    );
    let e = edited(&|v| {
        let c = &mut v["experiments"][1]["crossings"][0]["q"][0];
        *c = serde_json::json!(c.as_f64().unwrap() + 0.01);
    });
    assert!(
        e.contains("crossings[0].q[0] is")
            && e.contains("the crossing and the trajectory disagree"),
        "{e}"
    );
    let e = edited(&|v| {
        let cs = v["experiments"][3]["crossings"].as_array_mut().unwrap();
        cs.swap(0, 1);
    });
    assert!(
        e.contains("crossings[1] at t =") && e.contains("time order"),
        "{e}"
    );
    // the first segment set moving: it starts with a velocity, or jumps into the next
    let e = edited(&|v| {
        v["experiments"][0]["trajectory"]["segments"][0]["coeffs"][0][1] = serde_json::json!(0.5)
    });
    assert!(
        e.contains("jumps") || e.contains("must start and end at rest"),
        "{e}"
    );
    // a robot with a lower velocity limit on joint 2 than the plan was made for
    let mut slow = model.clone();
    slow.limits[1].velocity = 0.05;
    let e = simulate_plan(&slow, &plan, &noise_free(&slow, Gravity::Included))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint2") && e.contains("plan again for it"),
        "{e}"
    );
}

/// A plan's parts must agree: each crossing is the operating point moved by its row of
/// perturbations (G-static at rest), a nominal experiment perturbs nothing, only G-static has a
/// reference (and it must), every crossing's fit window lies in its own segment, and no
/// experiment is planned twice. A hand edit of one part is refused naming the crossing,
/// variable and joint, rather than fitted by one part (the recorded states) and diagnosed by
/// another (the planned perturbations).
#[test]
fn hand_edited_plans_are_refused_where_their_parts_disagree() {
    let model = a465::model("kinsheel2010").unwrap();
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let text = plan.to_json();
    let edited = |f: &dyn Fn(&mut serde_json::Value)| refused_plan_edit(&text, f);
    let names: Vec<&str> = plan.experiments.iter().map(|e| e.kind.name()).collect();
    assert_eq!(names, ["nominal", "G_static", "G", "H", "D"]);
    // H's perturbation of joint 3 at its fourth crossing, not its crossing
    let e = edited(&|v| v["experiments"][3]["deltas"][3][2] = serde_json::json!(-1.0));
    assert!(
        e.contains("experiments[3] ('H'): crossings[3].qd[2] is")
            && e.contains("the operating point's qd* plus deltas[3] give -0.978")
            && e.contains("disagree"),
        "{e}"
    );
    // the operating point's velocity of joint 1, not the crossings'
    let e = edited(&|v| v["op"]["qd"][0] = serde_json::json!(0.1));
    assert!(
        e.contains("experiments[0] ('nominal'): crossings[0].qd[0] is 0.089")
            && e.contains("the operating point's qd* is 0.1"),
        "{e}"
    );
    // G's velocities are the operating point's, not perturbed
    let e = edited(&|v| {
        let c = &mut v["experiments"][2]["deltas"][0][1];
        *c = serde_json::json!(c.as_f64().unwrap() + 0.01);
    });
    assert!(
        e.contains("experiments[2] ('G'): crossings[0].q[1] is"),
        "{e}"
    );
    let e = edited(&|v| v["experiments"][0]["deltas"][1][4] = serde_json::json!(0.01));
    assert!(
        e.contains("deltas[1][4] is 0.01; the nominal experiment perturbs nothing"),
        "{e}"
    );
    let e = edited(&|v| v["experiments"][1]["reference"] = serde_json::Value::Null);
    assert!(e.contains("('G_static'): it has no reference"), "{e}");
    // a reference added to H (at a time and state its trajectory passes: its first crossing)
    let e = edited(&|v| {
        v["experiments"][3]["reference"] = v["experiments"][3]["crossings"][0].clone();
    });
    assert!(
        e.contains("('H'): it has a reference; only G_static"),
        "{e}"
    );
    // a fit window wider than H's crossing windows (they are +-0.05 s): it would reach into the
    // transitions
    let e = edited(&|v| v["experiments"][3]["window"] = serde_json::json!(0.06));
    assert!(
        e.contains("('H'): crossings[0] at t =")
            && e.contains("with window +-0.06 s is not inside its segment")
            && e.contains("the fit would reach beyond"),
        "{e}"
    );
    // two crossing segments claim crossing 0 (the nominal experiment's sixth renumbered)
    let e = edited(&|v| {
        let segments = v["experiments"][0]["trajectory"]["segments"]
            .as_array_mut()
            .unwrap();
        let sixth = segments
            .iter_mut()
            .find(|s| s["type"] == "crossing" && s["index"] == 5)
            .unwrap();
        sixth["index"] = serde_json::json!(0);
    });
    assert!(
        e.contains(
            "('nominal'): crossings[0] needs exactly one trajectory segment, a 'crossing' segment with index 0"
        ),
        "{e}"
    );
    // G-static's dwell turned into a crossing window
    let e = edited(&|v| {
        let segments = v["experiments"][1]["trajectory"]["segments"]
            .as_array_mut()
            .unwrap();
        let dwell = segments.iter_mut().find(|s| s["type"] == "dwell").unwrap();
        dwell["type"] = serde_json::json!("crossing");
    });
    assert!(
        e.contains("is a 'crossing' segment with index 0, which the G_static experiment"),
        "{e}"
    );
    let e = edited(&|v| {
        let d = v["experiments"][4].clone();
        v["experiments"].as_array_mut().unwrap().push(d);
    });
    assert!(
        e.contains("experiments[4] and experiments[5] are both 'D'"),
        "{e}"
    );
}

/// Standard normal draws by Box-Muller.
fn gauss(rng: &mut Rng) -> f64 {
    let u = rng.uniform(f64::MIN_POSITIVE, 1.0);
    let v = rng.uniform(0.0, 1.0);
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// The weighted fit's standard errors match the scatter of its coefficients over noise whose
/// variance differs from row to row (`a + u_k`, the `u_k` known, `a` not), and the common
/// variance `a` it estimates is right on average. Ordinary least squares on the same data is
/// 0.5-1.5 times off (checked here, so the test can tell them apart).
#[test]
fn weighted_least_squares_standard_errors_match_the_scatter() {
    use perturbid_rs::local::noise::weighted_least_squares;
    let names: Vec<String> = ["a", "b", "c", "d"].map(String::from).to_vec();
    // symmetric pairs, as the plans' perturbations
    let x = DMatrix::from_fn(12, 4, |i, j| {
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        sign * (((i / 2 * 5 + j * 7) % 11) as f64 - 5.0 + 0.3 * j as f64)
    });
    let var: Vec<f64> = [1.0, 1.0, 4.0, 9.0, 25.0, 36.0]
        .iter()
        .flat_map(|v| [*v, *v])
        .collect();
    let u = DMatrix::from_fn(12, 1, |i, _| var[i]);
    let truth = [0.5, -1.0, 2.0, 0.25];
    for common in [0.0, 4.0] {
        let mut rng = Rng(7);
        let draws = 4000;
        let mut coef = vec![vec![]; 4];
        let mut ordinary = vec![vec![]; 4];
        let mut se2 = [0.0; 4];
        let mut ordinary_se2 = [0.0; 4];
        let mut a_sum = 0.0;
        for _ in 0..draws {
            let y = DMatrix::from_fn(12, 1, |i, _| {
                let exact: f64 = (0..4).map(|j| truth[j] * x[(i, j)]).sum();
                exact + (common + var[i]).sqrt() * gauss(&mut rng)
            });
            let w = weighted_least_squares(&x, &y, &u, "test", &names).unwrap();
            let o = least_squares(&x, &y, "test", &names).unwrap();
            for j in 0..4 {
                coef[j].push(w.fit.coef[(0, j)]);
                ordinary[j].push(o.coef[(0, j)]);
                se2[j] += w.fit.stderr[(0, j)].powi(2) / draws as f64;
                ordinary_se2[j] += o.stderr[(0, j)].powi(2) / draws as f64;
            }
            a_sum += w.common[0];
        }
        let sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
        };
        let mut worst_ordinary = 0.0f64;
        for j in 0..4 {
            let ratio = sd(&coef[j]) / se2[j].sqrt();
            assert!(
                (0.9..1.1).contains(&ratio),
                "a = {common}, column {j}: scatter / standard error {ratio}"
            );
            let r = sd(&ordinary[j]) / ordinary_se2[j].sqrt();
            worst_ordinary = worst_ordinary.max((r.ln()).abs());
        }
        // ordinary least squares is off by more than 1.28 in one column at least
        assert!(worst_ordinary > 1.28f64.ln(), "{worst_ordinary}");
        // by moments, truncated at 0: biased up where a is small against the u
        let a = a_sum / draws as f64;
        assert!(
            (a - common).abs() < 0.1 * common.max(10.0),
            "a = {common}: estimated {a} on average"
        );
    }
    // rows of equal variance: the ordinary fit, exactly
    let y = DMatrix::from_fn(12, 2, |i, c| x[(i, c)] + 0.1 * ((i * 7 + c) % 5) as f64);
    let w =
        weighted_least_squares(&x, &y, &DMatrix::from_element(12, 2, 0.3), "t", &names).unwrap();
    assert_eq!(w.fit, least_squares(&x, &y, "t", &names).unwrap());
    // variances of the wrong shape
    let e = weighted_least_squares(&x, &y, &u, "experiment 'D'", &names).unwrap_err();
    assert!(e.to_string().contains("experiment 'D'"), "{e}");
}

/// End to end on the A465 at Table 2 (0.01 N m torque noise): joint 5's torque windows are
/// narrowed at 10 of the D experiment's 12 crossings (its velocity reverses there), so its D*
/// row's values are noisier at some crossings than at others. Ordinary least squares gave that
/// row standard errors 1.1-1.25 times too small; the weighted fit's match the scatter over
/// seeds. The torque noise the diagnostics report is the simulated one.
#[test]
fn d_star_standard_errors_match_the_scatter_over_seeds() {
    let model = a465::model("kinsheel2010").unwrap();
    let n = model.nv;
    let plan = plan_experiments(&model, &table2(), &PlanOptions::default()).unwrap();
    let seeds = 300;
    let mut rows: Vec<Vec<f64>> = vec![vec![]; n];
    let mut se2 = vec![0.0; n];
    for seed in 0..seeds {
        let mut sim = noise_free(&model, Gravity::Included);
        sim.torque_noise = vec![0.01; n];
        sim.seed = 1000 + seed;
        let recs = simulate_plan(&model, &plan, &sim).unwrap();
        let m = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
        let d = m.d.as_ref().unwrap();
        for c in 0..n {
            rows[c].push(d.matrix[(4, c)]);
            se2[c] += d.stderr[(4, c)].powi(2) / seeds as f64;
        }
        for e in &m.diagnostics.noise {
            assert!(
                (e.samples - 0.01).abs() < 0.0015,
                "seed {seed}: {e:?} against 0.01 N m"
            );
        }
        // nominal, G_static, G, H, D: one entry a joint each
        assert_eq!(
            m.diagnostics.noise.len(),
            5 * n,
            "{:?}",
            m.diagnostics.noise
        );
    }
    let mut ratios = vec![];
    for c in 0..n {
        let v = &rows[c];
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        ratios.push(sd / se2[c].sqrt());
    }
    let mean_ratio = ratios.iter().sum::<f64>() / n as f64;
    eprintln!("joint 5's D* row: scatter / standard error {ratios:?}");
    assert!(
        (0.88..1.05).contains(&mean_ratio),
        "joint 5's D* row: scatter / standard error {ratios:?}"
    );
}
