//! The evidence tables of docs/parameters.md: the robot's parameters from local models at a few
//! operating points against the direct method at equal robot time, on a true A465 with a
//! payload the nominal model does not know, each unconstrained and physically consistent; and
//! the consistent fit on the real Panda log (when it is there).
//!
//! `cargo run --release --example parameters_evidence [-- PANDA_CSV PANDA_URDF]`
//!
//! Deterministic: the same numbers on every run.

use perturbid_rs::direct::{
    design_excitation, identify_base_parameters, identify_consistent_parameters, BaseModel,
    BaseOptions, ConsistentOptions, ExcitationOptions, FrictionTerms,
};
use perturbid_rs::local::{
    identify_local, identify_parameters_from_local, plan_experiments, suggest_operating_points,
    FromLocalOptions, IdentifyOptions, PlanOptions,
};
use perturbid_rs::rehearsal::{rehearse, rehearse_plan, TrueRobot};
use perturbid_rs::robots::a465;
use perturbid_rs::{
    mass_matrix, parallel, Data, Document, Gravity, Model, OperatingPoint, States, TorqueModel,
};

const TRUE_ROBOT: &str = r#"{"format": "perturbid-true-robot/1", "seed": 3,
  "payload": {"link": "link6", "mass": 1.5, "com": [0.0, 0.02, 0.08], "inertia": [0.004, 0, 0, 0.004, 0, 0.002]},
  "friction": {"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], "coulomb": [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]},
  "sensors": {"torque_noise": [0.05, 0.05, 0.05, 0.02, 0.02, 0.02]}}"#;

/// Held-out states within the limits (seeded), and the true robot's torques there.
struct HeldOut {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau: Vec<f64>,
    truth: Model,
}

fn held_out(nominal: &Model, robot: &TrueRobot, k: usize) -> Result<HeldOut, perturbid_rs::Error> {
    let truth = robot.rigid_body_model(nominal)?;
    let n = nominal.nv;
    let mut seed = 0x5eedu64;
    let mut u = |lo: f64, hi: f64| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    let (mut q, mut qd, mut qdd) = (vec![], vec![], vec![]);
    for _ in 0..k {
        for l in &nominal.limits {
            q.push(u(0.8 * l.lower, 0.8 * l.upper));
            qd.push(u(-1.0, 1.0));
            qdd.push(u(-3.0, 3.0));
        }
    }
    let states = States::new(n, &q, Some(&qd), Some(&qdd))?;
    let mut tau = vec![0.0; k * n];
    parallel::rnea(
        &truth,
        &mut parallel::Workspace::new(&truth),
        &states,
        Gravity::Included,
        &mut tau,
    )?;
    let f = robot.friction.clone();
    let (v, c) = (f.viscous.unwrap_or_default(), f.coulomb.unwrap_or_default());
    for (i, t) in tau.iter_mut().enumerate() {
        *t += v[i % n] * qd[i] + c[i % n] * qd[i].signum();
    }
    Ok(HeldOut {
        q,
        qd,
        qdd,
        tau,
        truth,
    })
}

/// Relative RMS torque error of `fit` on the held-out states, and the relative error of M(q)
/// over them (Frobenius, all states together).
fn errors(
    fit: &BaseModel,
    nominal: &Model,
    h: &HeldOut,
) -> Result<(f64, f64), perturbid_rs::Error> {
    let n = nominal.nv;
    let states = States::new(n, &h.q, Some(&h.qd), Some(&h.qdd))?;
    let p = fit.on(nominal)?.predict(&states)?;
    let num: f64 = p.iter().zip(&h.tau).map(|(a, b)| (a - b).powi(2)).sum();
    let den: f64 = h.tau.iter().map(|b| b * b).sum();
    let (mut dm, mut mm) = (0.0, 0.0);
    let mut data = Data::new(&h.truth);
    for s in 0..h.q.len() / n {
        let q = &h.q[s * n..(s + 1) * n];
        mass_matrix(&h.truth, &mut data, q)?;
        let m = fit.mass_matrix(nominal, q)?;
        dm += (&m - &data.m).norm_squared();
        mm += data.m.norm_squared();
    }
    Ok(((num / den).sqrt(), (dm / mm).sqrt()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let nominal = a465::model("kinsheel2010")?;
    let n = nominal.nv;
    let robot = TrueRobot::from_json(TRUE_ROBOT)?;
    let held = held_out(&nominal, &robot, 300)?;
    let terms: FrictionTerms = "viscous,coulomb".parse()?;
    let consistent = ConsistentOptions::default();

    // local models at the paper's point and three suggested ones
    let start = OperatingPoint::new(
        a465::TABLE2_Q.to_vec(),
        a465::TABLE2_QD.to_vec(),
        a465::TABLE2_QDD.to_vec(),
    )?;
    let from_local = FromLocalOptions {
        friction: terms,
        use_g: false,
        use_g_static: false,
        consistent: Some(consistent.clone()),
        ..FromLocalOptions::default()
    };
    let mut ops = vec![start.clone()];
    for p in suggest_operating_points(&nominal, &[start], &from_local, 60, 3, 7)? {
        ops.push(p.op);
    }
    println!("| method | robot time (s) | torque error, unconstrained | consistent | M(q) error, unconstrained | consistent | residual growth |");
    println!("|---|---|---|---|---|---|---|");
    let mut local_time = 0.0;
    let mut models = vec![];
    for op in &ops {
        let plan = plan_experiments(&nominal, op, &PlanOptions::default())?;
        local_time += plan.experiments.iter().map(|e| e.duration()).sum::<f64>();
        let recs = rehearse_plan(&nominal, &robot, &plan)?;
        models.push(identify_local(&plan, &recs, &IdentifyOptions::default())?);
    }
    let out = identify_parameters_from_local(&nominal, &models, &from_local)?;
    let c = out.consistent.as_ref().ok_or("no consistent fit")?;
    let (eu, mu) = errors(&out.model, &nominal, &held)?;
    let (ec, mc) = errors(&c.model, &nominal, &held)?;
    println!(
        "| local models at {} points ({} of {} base parameters) | {local_time:.0} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.3} |",
        ops.len(), out.rank, out.robot_rank, 100.0 * eu, 100.0 * ec, 100.0 * mu, 100.0 * mc, c.residual_growth()
    );
    // the direct method at the same robot time
    let design = design_excitation(
        &nominal,
        &ExcitationOptions {
            friction: terms,
            ..ExcitationOptions::default()
        },
        None,
    )?;
    let traj = &design.trajectory;
    // at equal robot time, and with one period only
    let mut direct_active = vec![];
    for periods in [(local_time / traj.period()).max(1.0), 1.0] {
        let s = traj.sample_periods(periods, 100.0).unwrap();
        let rec = rehearse(&nominal, &robot, &s, 0, "excitation")?;
        let states = States::new(n, &rec.q, Some(&s.qd), Some(&s.qdd))?;
        let options = BaseOptions {
            friction: terms,
            ..BaseOptions::default()
        };
        let unconstrained = identify_base_parameters(&nominal, &states, &rec.tau, &options)?;
        let fit =
            identify_consistent_parameters(&nominal, &states, &rec.tau, &options, &consistent)?;
        let (eu, mu) = errors(&unconstrained, &nominal, &held)?;
        let (ec, mc) = errors(&fit.model, &nominal, &held)?;
        println!(
            "| direct method, {:.1} periods of the designed excitation | {:.0} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.3} |",
            periods, periods * traj.period(), 100.0 * eu, 100.0 * ec, 100.0 * mu, 100.0 * mc, fit.residual_growth()
        );
        direct_active = fit.solution.active.clone();
    }
    println!();
    println!("active constraints, local: {:?}", c.solution.active);
    println!(
        "active constraints, direct (one period): {:?}",
        direct_active
    );

    // the real Panda log
    let mut args = std::env::args().skip(1);
    if let (Some(csv), Some(urdf)) = (args.next(), args.next()) {
        panda(&csv, &urdf)?;
    }
    Ok(())
}

fn panda(csv: &str, urdf: &str) -> Result<(), Box<dyn std::error::Error>> {
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
    use perturbid_rs::{LoadOptions, Recording};
    let text = std::fs::read_to_string(csv)?;
    let (mut t, mut q, mut qd, mut tau) = (vec![], vec![], vec![], vec![]);
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse())
            .collect::<Result<_, _>>()?;
        t.push(v[0]);
        q.extend_from_slice(&v[1..8]);
        qd.extend_from_slice(&v[8..15]);
        tau.extend_from_slice(&v[15..22]);
    }
    let lock = [("panda_finger_joint1".to_string(), 0.0)].into();
    let model = perturbid_rs::model_from_urdf_file(
        urdf,
        &LoadOptions {
            lock,
            ..LoadOptions::default()
        },
    )?;
    let rec = preprocess(
        &Recording::new("panda", 7, t, q, tau, Some(qd), None)?,
        &PreprocessOptions::default(),
    )?;
    let n = 7;
    let k = rec.len();
    let split = (0.7 * k as f64) as usize * n;
    let (qd, qdd) = (rec.qd.as_ref().ok_or("qd")?, rec.qdd.as_ref().ok_or("qdd")?);
    let fit_states = States::new(n, &rec.q[..split], Some(&qd[..split]), Some(&qdd[..split]))?;
    let val_states = States::new(n, &rec.q[split..], Some(&qd[split..]), Some(&qdd[split..]))?;
    let fit = identify_consistent_parameters(
        &model,
        &fit_states,
        &rec.tau[..split],
        &BaseOptions::default(),
        &ConsistentOptions::default(),
    )?;
    let rel = |m: &BaseModel| -> Result<Vec<f64>, perturbid_rs::Error> {
        let p = m.on(&model)?.predict(&val_states)?;
        Ok((0..n)
            .map(|j| {
                let (mut e, mut s) = (0.0f64, 0.0f64);
                for (i, t) in rec.tau[split..]
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| i % n == j)
                {
                    e += (p[i] - t).powi(2);
                    s += t * t;
                }
                100.0 * (e / s).sqrt()
            })
            .collect())
    };
    let (u, c) = (rel(&fit.unconstrained)?, rel(&fit.model)?);
    println!();
    println!("| Panda, last 30 % held out | joint 1 | 2 | 3 | 4 | 5 | 6 | 7 |");
    println!("|---|---|---|---|---|---|---|---|");
    let row = |name: &str, v: &[f64]| {
        println!(
            "| {name} | {} |",
            v.iter()
                .map(|x| format!("{x:.1} %"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    };
    row("unconstrained", &u);
    row("consistent", &c);
    println!();
    println!(
        "Panda: residual growth {:.3}, {} Newton steps, {} constraints active: {:?}",
        fit.residual_growth(),
        fit.solution.iterations,
        fit.solution.active.len(),
        fit.solution.active
    );
    Ok(())
}
