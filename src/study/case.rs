//! One case of a study: the local methods planned, rehearsed on the true robot and identified
//! at the point; the direct methods on an excitation rehearsed on the same true robot; every
//! model measured against the true plant near the point.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use nalgebra::DMatrix;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use super::config::Method;
use super::plan::{Case, Study};
use crate::direct::{
    design_excitation, identify_base_parameters, identify_global_linear, BaseOptions,
    ExcitationDesign, ExcitationOptions, Weighting,
};
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::local::{
    identify_local, plan_experiments, IdentifyOptions, OperatingPoint, PlanOptions, Sizes,
};
use crate::model::Model;
use crate::rehearsal::{rehearse, rehearse_plan, true_torques, TrueRobot};
use crate::states::States;
use crate::torque_model::TorqueModel;

/// One number a case measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measure {
    pub method: Method,
    /// `rms_rel`, `max_rel` (with a distance), `D_rel`, `H_rel`, `G_rel`, `robot_time` (s),
    /// or `failed` (value 1, the reason in `note`).
    pub metric: String,
    /// Distance from P in multiples of the perturbation size, for `rms_rel` and `max_rel`.
    pub distance: Option<f64>,
    pub value: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// What one case measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseResult {
    pub index: usize,
    pub id: String,
    pub measures: Vec<Measure>,
}

/// Runs case `index` of `study`.
pub fn run_case(study: &Study, index: usize) -> Result<CaseResult> {
    let case = study.case(index)?;
    let id = study.case_id(&case);
    let robot = &study.robots[case.robot];
    let model = robot.model()?;
    let p = &robot.points[case.point];
    let op = OperatingPoint::new(p.q.clone(), p.qd.clone(), p.qdd.clone())?;
    let plant = true_robot(study, &case, model.nv);
    let mut out = Vec::new();
    let methods = &study.config.methods;
    let sizes = Sizes {
        position: crate::local::Size::Fraction(0.01 * case.perturbation),
        velocity: crate::local::Size::Fraction(0.05 * case.perturbation),
        acceleration: crate::local::Size::Fraction(0.05 * case.perturbation),
    };
    let scale = sizes.resolve_for(&model)?;
    // the true plant at P and its linearisation, and the evaluation states
    let truth = Truth::new(&model, &plant, &op, &scale, study, &case)?;
    let mut fitted: Vec<(Method, Box<dyn TorqueModel>, f64)> = Vec::new();
    let mut local_time = None;
    for (method, friction_aware) in [
        (Method::LocalSeparated, false),
        (Method::LocalCombined, false),
        (Method::LocalFrictionAware, true),
    ] {
        if !(methods.contains(&method) || method == Method::LocalSeparated && needs_time(study)) {
            continue;
        }
        let result = (|| -> Result<(crate::local::LocalModel, f64)> {
            let plan = plan_experiments(
                &model,
                &op,
                &PlanOptions {
                    design: case.design,
                    count: case.k,
                    seed: case.seed,
                    sizes: sizes.clone(),
                    friction_aware_h: friction_aware,
                    ..PlanOptions::default()
                },
            )?;
            let time: f64 = plan.experiments.iter().map(|e| e.duration()).sum();
            let recordings = rehearse_plan(&model, &plant, &plan)?;
            let options = IdentifyOptions {
                estimator: if method == Method::LocalCombined {
                    crate::local::Estimator::Combined
                } else {
                    crate::local::Estimator::Separated
                },
                friction_aware_h: friction_aware,
                ..IdentifyOptions::default()
            };
            Ok((identify_local(&plan, &recordings, &options)?, time))
        })();
        match result {
            Ok((m, time)) => {
                if method == Method::LocalSeparated {
                    local_time = Some(time);
                }
                if methods.contains(&method) {
                    fitted.push((method, Box::new(m), time));
                }
            }
            Err(e) => out.push(failed(method, &e)),
        }
    }
    let direct: Vec<Method> = [
        Method::DirectOls,
        Method::DirectWls,
        Method::DirectAveraged,
        Method::GlobalLinear,
    ]
    .into_iter()
    .filter(|m| methods.contains(m))
    .collect();
    if !direct.is_empty() {
        match direct_models(study, &case, &model, &plant, &op, local_time) {
            Ok(models) => {
                for (m, tm, time) in models {
                    if !direct.contains(&m) {
                        continue;
                    }
                    match tm {
                        Ok(tm) => fitted.push((m, tm, time)),
                        Err(e) => out.push(failed(m, &e)),
                    }
                }
            }
            Err(e) => out.extend(direct.iter().map(|m| failed(*m, &e))),
        }
    }
    for (method, m, time) in &fitted {
        out.push(measure(*method, "robot_time", None, *time));
        match truth.measure(*method, m.as_ref()) {
            Ok(v) => out.extend(v),
            Err(e) => out.push(failed(*method, &e)),
        }
    }
    Ok(CaseResult {
        index,
        id,
        measures: out,
    })
}

fn needs_time(study: &Study) -> bool {
    study.config.direct.periods.is_none()
}

fn measure(method: Method, metric: &str, distance: Option<f64>, value: f64) -> Measure {
    Measure {
        method,
        metric: metric.into(),
        distance,
        value,
        note: None,
    }
}

fn failed(method: Method, e: &Error) -> Measure {
    Measure {
        method,
        metric: "failed".into(),
        distance: None,
        value: 1.0,
        note: Some(e.to_string()),
    }
}

/// The case's true robot: the document with the case's seed and noise.
fn true_robot(study: &Study, case: &Case, n: usize) -> TrueRobot {
    let mut t = study.true_robots[case.true_robot].1.clone();
    t.seed = case.seed;
    if let Some(noise) = case.noise {
        t.sensors.torque_noise = Some(vec![noise; n]);
    }
    t
}

type Designs = Mutex<HashMap<String, Arc<ExcitationDesign>>>;

/// Excitation designs are the same for every case of a robot and seed: designed once per
/// process (a worker keeps its own), at most 256 kept.
fn excitation(study: &Study, case: &Case, model: &Model) -> Result<Arc<ExcitationDesign>> {
    static DESIGNS: std::sync::OnceLock<Designs> = std::sync::OnceLock::new();
    let d = &study.config.direct;
    let r = &study.robots[case.robot];
    let key = serde_json::json!([r.name, r.urdf, r.lock, d, case.seed]).to_string();
    let cache = DESIGNS.get_or_init(Default::default);
    if let Some(found) = cache.lock().map_err(poisoned)?.get(&key) {
        return Ok(found.clone());
    }
    let design = Arc::new(design_excitation(
        model,
        &ExcitationOptions {
            harmonics: d.harmonics,
            base_frequency: d.base_frequency,
            max_evaluations: d.max_evaluations,
            seed: case.seed,
            ..ExcitationOptions::default()
        },
        None,
    )?);
    let mut c = cache.lock().map_err(poisoned)?;
    if c.len() >= 256 {
        c.clear();
    }
    c.insert(key, design.clone());
    Ok(design)
}

fn poisoned<T>(_: T) -> Error {
    Error::Internal {
        context: "study".into(),
        message: "a worker panicked while holding the excitation cache".into(),
    }
}

type Fitted = Vec<(Method, Result<Box<dyn TorqueModel>>, f64)>;

/// The direct method's models: the excitation rehearsed on the true robot for the configured
/// periods (or the local method's robot time), base parameters by OLS and WLS regressed on
/// the reference states, and the globally linearised model about P; each may fail alone.
fn direct_models(
    study: &Study,
    case: &Case,
    model: &Model,
    plant: &TrueRobot,
    op: &OperatingPoint,
    local_time: Option<f64>,
) -> Result<Fitted> {
    let d = &study.config.direct;
    let design = excitation(study, case, model)?;
    let period = design.trajectory.period();
    let periods = match (d.periods, local_time) {
        (Some(p), _) => p,
        (None, Some(t)) => t / period,
        (None, None) => 1.0,
    };
    let samples = design.trajectory.sample_periods(periods, d.rate)?;
    let time = samples.t.last().copied().unwrap_or(0.0) - samples.t[0];
    let rec = rehearse(model, plant, &samples, 1_000, "excitation")?;
    let states = States::new(model.nv, &samples.q, Some(&samples.qd), Some(&samples.qdd))?;
    let gravity = plant.gravity;
    let mut out: Fitted = Vec::new();
    for (method, weighting) in [
        (Method::DirectOls, Weighting::Ols),
        (Method::DirectWls, Weighting::Wls),
    ] {
        let fit = identify_base_parameters(
            model,
            &states,
            &rec.tau,
            &BaseOptions {
                weighting,
                gravity,
                seed: case.seed,
                ..BaseOptions::default()
            },
        );
        out.push((method, owned(fit, model), time));
    }
    let averaged = averaged_fit(study, case, model, &design.trajectory, &rec, gravity);
    out.push((Method::DirectAveraged, owned(averaged, model), time));
    let global =
        identify_global_linear(op, &states, &rec.tau).map(|g| Box::new(g) as Box<dyn TorqueModel>);
    out.push((Method::GlobalLinear, global, time));
    Ok(out)
}

/// A fit's base-parameter model with its robot, as a [`TorqueModel`].
fn owned(fit: Result<crate::direct::BaseModel>, model: &Model) -> Result<Box<dyn TorqueModel>> {
    fit.map(|fit| {
        Box::new(OwnedBase {
            fit,
            model: model.clone(),
        }) as Box<dyn TorqueModel>
    })
}

/// [`Method::DirectAveraged`]: the excitation's log `rec` averaged over the whole periods of
/// `trajectory` (at the log's rate, the torques' band to the preprocessing's default 10 Hz),
/// the base parameters weighted by the noise the periods measured, or by the residuals where
/// they measured none.
fn averaged_fit(
    study: &Study,
    case: &Case,
    model: &Model,
    trajectory: &crate::trajectory::FourierTrajectory,
    rec: &crate::Recording,
    gravity: Gravity,
) -> Result<crate::direct::BaseModel> {
    let options = crate::logs::preprocess::PreprocessOptions {
        rate: study.config.direct.rate,
        decimate: 1,
        periods: Some(crate::logs::period_average::PeriodOptions::new(
            trajectory.period(),
            trajectory.harmonics(),
        )),
        ..crate::logs::preprocess::PreprocessOptions::default()
    };
    let avg = crate::logs::preprocess::preprocess(rec, &options)?;
    let noise = (avg.period_average.as_ref())
        .and_then(|a| crate::direct::TorqueNoise::from_period_average(a, &model.joint_names).ok());
    let options = BaseOptions {
        weighting: match noise {
            Some(_) => Weighting::Noise,
            None => Weighting::Wls,
        },
        noise,
        gravity,
        seed: case.seed,
        ..BaseOptions::default()
    };
    Ok(identify_base_parameters(model, &avg.states()?, &avg.tau, &options)?.with_findings_of(&avg))
}

/// A base-parameter model with its robot, as a [`TorqueModel`].
struct OwnedBase {
    fit: crate::direct::BaseModel,
    model: Model,
}

impl TorqueModel for OwnedBase {
    fn joint_names(&self) -> &[String] {
        &self.model.joint_names
    }
    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        self.fit.on(&self.model)?.predict(states)
    }
    fn linearize(&self, op: &OperatingPoint) -> Result<crate::torque_model::Expansion> {
        self.fit.on(&self.model)?.linearize(op)
    }
}

/// States at one distance from P: (distance, q|qd|qdd row-major, true torques, RMS of the
/// true change from P).
type EvaluationSet = (f64, [Vec<f64>; 3], Vec<f64>, f64);

/// The true plant near P: its torque at P, its linearisation (central differences), and the
/// evaluation states with their true torques.
struct Truth {
    n: usize,
    op: OperatingPoint,
    d: DMatrix<f64>,
    h: DMatrix<f64>,
    g: DMatrix<f64>,
    /// Per distance: (distance, states q|qd|qdd row-major, true torques, RMS of the true
    /// change from P).
    sets: Vec<EvaluationSet>,
}

impl Truth {
    fn new(
        model: &Model,
        plant: &TrueRobot,
        op: &OperatingPoint,
        scale: &[Vec<f64>; 3],
        study: &Study,
        case: &Case,
    ) -> Result<Truth> {
        let n = model.nv;
        let at = |q: &[f64], qd: &[f64], qdd: &[f64]| -> Result<Vec<f64>> {
            true_torques(model, plant, &States::new(n, q, Some(qd), Some(qdd))?)
        };
        let tau0 = at(&op.q, &op.qd, &op.qdd)?;
        // central differences, one batch of 6n states
        let base = [&op.q, &op.qd, &op.qdd];
        let mut xs = [Vec::new(), Vec::new(), Vec::new()];
        let mut steps = Vec::new();
        for v in 0..3 {
            for j in 0..n {
                let h = 1e-6 * base[v][j].abs().max(1.0);
                steps.push(h);
                for sign in [1.0, -1.0] {
                    for (w, x) in xs.iter_mut().enumerate() {
                        let mut s = base[w].clone();
                        if w == v {
                            s[j] += sign * h;
                        }
                        x.extend(s);
                    }
                }
            }
        }
        let taus = at(&xs[0], &xs[1], &xs[2])?;
        let mut mats = [
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
        ];
        for (v, mat) in mats.iter_mut().enumerate() {
            for j in 0..n {
                let k = v * n + j;
                let (plus, minus) = (
                    &taus[2 * k * n..(2 * k + 1) * n],
                    &taus[(2 * k + 1) * n..(2 * k + 2) * n],
                );
                for i in 0..n {
                    mat[(i, j)] = (plus[i] - minus[i]) / (2.0 * steps[k]);
                }
            }
        }
        let [g, h, d] = mats;
        // evaluation states: the same for every method of the case
        let e = &study.config.evaluation;
        let mut rng = ChaCha8Rng::seed_from_u64(case.seed);
        rng.set_stream(7);
        let mut sets = Vec::new();
        for &dist in &e.distances {
            let mut x = [Vec::new(), Vec::new(), Vec::new()];
            for _ in 0..e.samples {
                let u: Vec<f64> = (0..3 * n)
                    .map(|_| StandardNormal.sample(&mut rng))
                    .collect();
                let norm = u.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-300);
                let r = dist * (3.0 * n as f64).sqrt() / norm;
                for v in 0..3 {
                    for j in 0..n {
                        x[v].push(base[v][j] + r * u[v * n + j] * scale[v][j]);
                    }
                }
            }
            let tau = at(&x[0], &x[1], &x[2])?;
            let change = (tau
                .iter()
                .enumerate()
                .map(|(i, t)| (t - tau0[i % n]).powi(2))
                .sum::<f64>()
                / tau.len() as f64)
                .sqrt();
            sets.push((dist, x, tau, change));
        }
        Ok(Truth {
            n,
            op: op.clone(),
            d,
            h,
            g,
            sets,
        })
    }

    /// A model's errors: per distance the RMS and largest torque error relative to the RMS of
    /// the true change, and its D, H, G at P against the plant's (relative, Frobenius).
    fn measure(&self, method: Method, m: &dyn TorqueModel) -> Result<Vec<Measure>> {
        let mut out = Vec::new();
        for (dist, x, tau, change) in &self.sets {
            let states = States::new(self.n, &x[0], Some(&x[1]), Some(&x[2]))?;
            let pred = m.predict(&states)?;
            let err: Vec<f64> = pred.iter().zip(tau).map(|(p, t)| p - t).collect();
            let rms = (err.iter().map(|e| e * e).sum::<f64>() / err.len() as f64).sqrt();
            let max = err.iter().fold(0.0f64, |a, e| a.max(e.abs()));
            if *change > 0.0 {
                out.push(measure(method, "rms_rel", Some(*dist), rms / change));
                out.push(measure(method, "max_rel", Some(*dist), max / change));
            }
        }
        let e = m.linearize(&self.op)?;
        for (name, est, truth) in [
            ("D_rel", &e.d, &self.d),
            ("H_rel", &e.h, &self.h),
            ("G_rel", &e.g, &self.g),
        ] {
            let norm = truth.norm();
            let rel = (est - truth).norm() / norm;
            if norm > 0.0 && rel.is_finite() {
                out.push(measure(method, name, None, rel));
            }
        }
        Ok(out)
    }
}
