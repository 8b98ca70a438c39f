//! The paper's experiment run on the built-in A465: plan, rehearse and identify at Table 2's
//! operating point, the direct method beside it, and the curves of Figs. 3-5.

use nalgebra::DMatrix;
use serde::Serialize;

use crate::data::Data;
use crate::direct::{
    design_excitation, identify_base_parameters, identify_global_linear, BaseOptions,
    ExcitationOptions, FrictionTerms, Weighting,
};
use crate::error::Result;
use crate::gravity::Gravity;
use crate::local::{
    identify_local, plan_experiments, Design, IdentifyOptions, LocalModel, OperatingPoint,
    PlanOptions,
};
use crate::mass_matrix;
use crate::robots::a465;
use crate::simulation::{simulate_plan, simulate_samples, Friction, SimulationOptions};
use crate::states::States;
use crate::torque_model::TorqueModel;

/// The paper's Table 3 "direct method" row (first column of D).
pub const TABLE3_DIRECT: [f64; 6] = [4.73, -0.26, 1.68, -0.87, 0.39, -1.95];
/// The paper's Table 3 "perturbation method" row.
pub const TABLE3_PERTURBATION: [f64; 6] = [9.95, 0.0, 0.0, -1.37, 0.0, -0.27];

/// Options of [`reproduce`].
#[derive(Clone, Debug, PartialEq)]
pub struct PaperOptions {
    pub seed: u64,
    /// Torque noise (N m) of the simulated measurements (default 0: the paper's simulation).
    pub torque_noise: f64,
    /// Budget of each excitation design (default 800 evaluations).
    pub design_evaluations: usize,
    /// Excitation seeds of the direct method (`seed`, `seed + 1`, ...; default 10): Table 3's
    /// direct rows and the figures give the median and the range over them.
    pub excitation_seeds: usize,
    /// Run the built-in study for the section "when to use which method" (about a minute on
    /// 2 cores; default true).
    pub study: bool,
}

impl Default for PaperOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            torque_noise: 0.0,
            design_evaluations: 800,
            excitation_seeds: 10,
            study: true,
        }
    }
}

/// One of Figs. 3-5: torques of a joint along a trajectory through the operating point.
#[derive(Clone, Debug, Serialize)]
pub struct Figure {
    pub joint: usize,
    /// The direct method's excitation: `default` or `around_op`.
    pub excitation: String,
    pub t: Vec<f64>,
    pub actual: Vec<f64>,
    pub local: Vec<f64>,
    /// Median over the excitation seeds, and the lowest and highest.
    pub global_linear: Vec<f64>,
    pub global_linear_min: Vec<f64>,
    pub global_linear_max: Vec<f64>,
    /// Median over the excitation seeds.
    pub base_parameters: Vec<f64>,
}

/// RMS errors (N m) of the models along the figure trajectory: within `near` s of the operating
/// point, and over the whole trajectory.
#[derive(Clone, Debug, Serialize)]
pub struct FigureErrors {
    pub joint: usize,
    pub excitation: String,
    pub near: f64,
    pub local_near: f64,
    pub global_linear_near: f64,
    pub base_parameters_near: f64,
    pub local_all: f64,
    pub global_linear_all: f64,
    pub base_parameters_all: f64,
}

/// Median, lowest and highest of a vector quantity over the excitation seeds.
#[derive(Clone, Debug, Serialize)]
pub struct OverSeeds {
    pub median: Vec<f64>,
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

impl OverSeeds {
    /// Entry-wise statistics of `runs` (each of the same length, at least one).
    pub fn of(runs: &[Vec<f64>]) -> OverSeeds {
        let n = runs[0].len();
        let mut out = OverSeeds {
            median: vec![0.0; n],
            min: vec![0.0; n],
            max: vec![0.0; n],
        };
        let mut column = vec![0.0; runs.len()];
        for j in 0..n {
            for (c, r) in column.iter_mut().zip(runs) {
                *c = r[j];
            }
            column.sort_by(f64::total_cmp);
            out.median[j] = crate::study::quantile(&column, 0.5);
            out.min[j] = column[0];
            out.max[j] = column[column.len() - 1];
        }
        out
    }
}

/// The direct method over the excitation seeds, for one kind of excitation.
#[derive(Clone, Debug, Serialize)]
pub struct DirectOverSeeds {
    /// `default` (the design within the joint limits) or `around_op` (limits narrowed to
    /// q* +- 0.5 rad, like the paper's excitation, which stays near the point).
    pub excitation: String,
    pub seeds: Vec<u64>,
    /// cond(Phi_base) of each seed's design.
    pub cond: Vec<f64>,
    /// First column of D: globally linearised D_g and the base-parameter model's M(q*).
    pub d_global_linear: OverSeeds,
    pub d_base_parameters: OverSeeds,
}

/// Everything the reproduction computes.
#[derive(Clone, Debug, Serialize)]
pub struct PaperResult {
    pub op: OperatingPoint,
    /// Table 2: identified `T*` and the paper's `Tn`.
    pub torque_identified: Vec<f64>,
    pub torque_paper: Vec<f64>,
    /// Table 3, first column of D.
    pub d_actual: Vec<f64>,
    pub d_actual_paper: Vec<f64>,
    pub d_perturbation: Vec<f64>,
    pub d_perturbation_stderr: Vec<f64>,
    pub d_perturbation_paper: Vec<f64>,
    pub d_global_linear: Vec<f64>,
    pub d_base_parameters: Vec<f64>,
    pub d_direct_paper: Vec<f64>,
    /// Conditioning of the designs.
    pub cond_local: Vec<(String, f64)>,
    pub excitation_cond: f64,
    pub excitation_harmonics: usize,
    pub excitation_frequency: f64,
    pub base_parameters: usize,
    pub figures: Vec<Figure>,
    pub errors: Vec<FigureErrors>,
    /// The direct method over the excitation seeds: the default excitation, then the one
    /// around the point. `d_global_linear` and `d_base_parameters` above are the default
    /// excitation's medians.
    pub direct: Vec<DirectOverSeeds>,
    /// The built-in study ("when to use which method"), when run.
    pub study: Option<Vec<super::study::StudyLine>>,
    #[serde(skip)]
    pub local_model: Option<LocalModel>,
}

fn column0(m: &DMatrix<f64>) -> Vec<f64> {
    m.column(0).iter().copied().collect()
}

/// Runs the reproduction. `progress` hears each step's name.
pub fn reproduce(options: &PaperOptions, progress: &mut dyn FnMut(&str)) -> Result<PaperResult> {
    if !(1..=1000).contains(&options.excitation_seeds) {
        return Err(crate::error::Error::invalid(
            "excitation_seeds",
            format!("{}; expected 1..=1000", options.excitation_seeds),
        ));
    }
    let model = a465::model("kinsheel2010")?;
    let n = model.nv;
    let op = OperatingPoint::new(
        a465::TABLE2_Q.to_vec(),
        a465::TABLE2_QD.to_vec(),
        a465::TABLE2_QDD.to_vec(),
    )?;
    let mut sim = SimulationOptions::new(&model);
    sim.gravity = Gravity::Excluded; // the paper assumes gravity and friction compensated
    sim.friction = Friction::none(n);
    sim.torque_noise = vec![options.torque_noise; n];
    sim.seed = options.seed;

    progress("perturbation method: planning and simulating the nominal, G, H and D experiments");
    let plan = plan_experiments(
        &model,
        &op,
        &PlanOptions {
            design: Design::Random,
            seed: options.seed,
            ..PlanOptions::default()
        },
    )?;
    let recordings = simulate_plan(&model, &plan, &sim)?;
    let local = identify_local(&plan, &recordings, &IdentifyOptions::default())?;
    // the plan holds the D experiment, so the model holds D*
    let d = local
        .d
        .as_ref()
        .ok_or_else(|| crate::error::Error::Internal {
            context: "paper".into(),
            message: "the local model has no D* though its plan has the D experiment".into(),
        })?;
    let (d_local, d_stderr) = (d.matrix.clone(), d.stderr.clone());

    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &op.q)?;
    let actual = data.m.clone();

    // Figs. 3-5: q(s) = q* + qd* s + qdd* s^2 / 2 for s in [-3, 3] s, passing P at s = 0
    let ts: Vec<f64> = (0..=600).map(|i| -3.0 + 0.01 * i as f64).collect();
    let (mut q, mut qd, mut qdd) = (vec![], vec![], vec![]);
    for &s in &ts {
        for j in 0..n {
            q.push(op.q[j] + op.qd[j] * s + 0.5 * op.qdd[j] * s * s);
            qd.push(op.qd[j] + op.qdd[j] * s);
            qdd.push(op.qdd[j]);
        }
    }
    let states = States::new(model.nv, &q, Some(&qd), Some(&qdd))?;
    let mut actual_tau = vec![0.0; q.len()];
    let mut workspace = crate::parallel::Workspace::new(&model);
    crate::parallel::rnea(
        &model,
        &mut workspace,
        &states,
        Gravity::Excluded,
        &mut actual_tau,
    )?;
    let local_tau = local.predict(&states)?;

    let seeds = options.excitation_seeds;
    progress(&format!(
        "direct method: {seeds} excitations (10 harmonics of 0.05 Hz) within the limits and {seeds} around the point, designed, simulated and fitted"
    ));
    let runs = direct_runs(&model, &sim, &op, options, &states)?;
    crate::interrupt::check("paper")?;
    let (figures, errors, direct) = figures(&runs, &ts, &actual_tau, &local_tau, n);
    let study = if options.study {
        progress("the built-in study: when to use which method");
        Some(super::study::when_to_use(&mut |done, total| {
            progress(&format!("the built-in study: {done} of {total} cases"))
        })?)
    } else {
        None
    };
    Ok(PaperResult {
        torque_identified: local.torque.clone(),
        torque_paper: a465::TABLE2_TORQUE.to_vec(),
        d_actual: column0(&actual),
        d_actual_paper: a465::TABLE3_D_COLUMN1.to_vec(),
        d_perturbation: column0(&d_local),
        d_perturbation_stderr: column0(&d_stderr),
        d_perturbation_paper: TABLE3_PERTURBATION.to_vec(),
        d_global_linear: direct[0].d_global_linear.median.clone(),
        d_base_parameters: direct[0].d_base_parameters.median.clone(),
        d_direct_paper: TABLE3_DIRECT.to_vec(),
        cond_local: [
            ("D", &local.d),
            ("H", &local.h),
            ("G", &local.g),
            ("G_static", &local.g_static),
        ]
        .iter()
        .filter_map(|(k, e)| e.as_ref().map(|e| (k.to_string(), e.cond)))
        .collect(),
        excitation_cond: crate::study::quantile(&sorted(&direct[0].cond), 0.5),
        excitation_harmonics: 10,
        excitation_frequency: 0.05,
        base_parameters: runs[0].base_parameters,
        figures,
        errors,
        direct,
        study,
        op,
        local_model: Some(local),
    })
}

/// The direct method's runs: one per excitation seed, within the limits (variant 0) and
/// around the point (variant 1), in parallel.
fn direct_runs(
    model: &crate::model::Model,
    sim: &SimulationOptions,
    op: &OperatingPoint,
    options: &PaperOptions,
    states: &States<'_>,
) -> Result<Vec<DirectRun>> {
    let seeds = options.excitation_seeds;
    let around = around_op(model, op, 0.5);
    let jobs: Vec<(usize, u64)> = (0..2)
        .flat_map(|v| (0..seeds as u64).map(move |s| (v, options.seed + s)))
        .collect();
    use rayon::prelude::*;
    jobs.par_iter()
        .map(|&(v, seed)| {
            crate::error::catch_panics("paper direct method", || {
                direct_run(
                    model,
                    (v, if v == 0 { model } else { &around }),
                    sim,
                    op,
                    seed,
                    options.design_evaluations,
                    states,
                )
            })
        })
        .collect::<Result<_>>()
}

/// Figs. 3-5 of each excitation (joints 2-4 along the path through P at times `ts`), their
/// errors near P and over the path, and each excitation's results over the seeds.
fn figures(
    runs: &[DirectRun],
    ts: &[f64],
    actual_tau: &[f64],
    local_tau: &[f64],
    n: usize,
) -> (Vec<Figure>, Vec<FigureErrors>, Vec<DirectOverSeeds>) {
    let pick = |v: &[f64], j: usize| -> Vec<f64> { (0..ts.len()).map(|k| v[k * n + j]).collect() };
    let rms = |a: &[f64], b: &[f64], mask: &dyn Fn(f64) -> bool| -> f64 {
        let e: Vec<f64> = ts
            .iter()
            .zip(a.iter().zip(b))
            .filter(|(t, _)| mask(**t))
            .map(|(_, (x, y))| (x - y).powi(2))
            .collect();
        (e.iter().sum::<f64>() / e.len() as f64).sqrt()
    };
    let near = 0.5;
    let mut figures = vec![];
    let mut errors = vec![];
    let mut direct = vec![];
    for (v, name) in ["default", "around_op"].iter().enumerate() {
        let these: Vec<&DirectRun> = runs.iter().filter(|r| r.variant == v).collect();
        let column = |f: &dyn Fn(&DirectRun) -> &Vec<f64>| -> Vec<Vec<f64>> {
            these.iter().map(|r| f(r).clone()).collect()
        };
        direct.push(DirectOverSeeds {
            excitation: name.to_string(),
            seeds: these.iter().map(|r| r.seed).collect(),
            cond: these.iter().map(|r| r.cond).collect(),
            d_global_linear: OverSeeds::of(&column(&|r| &r.d_global_linear)),
            d_base_parameters: OverSeeds::of(&column(&|r| &r.d_base_parameters)),
        });
        let global = OverSeeds::of(&column(&|r| &r.global_tau));
        let base = OverSeeds::of(&column(&|r| &r.base_tau));
        for joint in [2usize, 3, 4] {
            let j = joint - 1;
            let f = Figure {
                joint,
                excitation: name.to_string(),
                t: ts.to_vec(),
                actual: pick(actual_tau, j),
                local: pick(local_tau, j),
                global_linear: pick(&global.median, j),
                global_linear_min: pick(&global.min, j),
                global_linear_max: pick(&global.max, j),
                base_parameters: pick(&base.median, j),
            };
            let is_near = |t: f64| t.abs() <= near;
            let all = |_: f64| true;
            errors.push(FigureErrors {
                joint,
                excitation: name.to_string(),
                near,
                local_near: rms(&f.local, &f.actual, &is_near),
                global_linear_near: rms(&f.global_linear, &f.actual, &is_near),
                base_parameters_near: rms(&f.base_parameters, &f.actual, &is_near),
                local_all: rms(&f.local, &f.actual, &all),
                global_linear_all: rms(&f.global_linear, &f.actual, &all),
                base_parameters_all: rms(&f.base_parameters, &f.actual, &all),
            });
            figures.push(f);
        }
    }
    (figures, errors, direct)
}

fn sorted(v: &[f64]) -> Vec<f64> {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

/// The model with its position limits narrowed to `op.q +- half_width` (within its own): an
/// excitation designed on it stays near the point, as the paper's does.
fn around_op(
    model: &crate::model::Model,
    op: &OperatingPoint,
    half_width: f64,
) -> crate::model::Model {
    let mut m = model.clone();
    for (l, q) in m.limits.iter_mut().zip(&op.q) {
        l.lower = l.lower.max(q - half_width);
        l.upper = l.upper.min(q + half_width);
    }
    m
}

/// One excitation seed of the direct method.
struct DirectRun {
    variant: usize,
    seed: u64,
    cond: f64,
    base_parameters: usize,
    d_global_linear: Vec<f64>,
    d_base_parameters: Vec<f64>,
    /// Row-major torques along the figure trajectory.
    global_tau: Vec<f64>,
    base_tau: Vec<f64>,
}

/// Designs the excitation (`variant` 0: default, 1: around the point) on `design_model` (the robot, or its limits narrowed), simulates
/// one period at 50 Hz on `model`, fits the globally linearised and the base-parameter models
/// and predicts along `figure` (the figure trajectory).
fn direct_run(
    model: &crate::model::Model,
    (variant, design_model): (usize, &crate::model::Model),
    sim: &SimulationOptions,
    op: &OperatingPoint,
    seed: u64,
    evaluations: usize,
    figure: &States<'_>,
) -> Result<DirectRun> {
    let ex = ExcitationOptions {
        harmonics: 10,
        base_frequency: 0.05,
        max_evaluations: evaluations,
        seed,
        ..ExcitationOptions::default()
    };
    let design = design_excitation(design_model, &ex, None)?;
    let samples = design.trajectory.sample_periods(1.0, 50.0)?;
    let rec = simulate_samples(model, &samples, sim, 99, "excitation")?;
    let batch = States::new(model.nv, &samples.q, Some(&samples.qd), Some(&samples.qdd))?;
    let global = identify_global_linear(op, &batch, &rec.tau)?;
    let base = identify_base_parameters(
        model,
        &batch,
        &rec.tau,
        &BaseOptions {
            friction: FrictionTerms::NONE,
            weighting: Weighting::Ols,
            gravity: Gravity::Excluded,
            seed,
            ..BaseOptions::default()
        },
    )?;
    let m_base = base.mass_matrix(model, &op.q)?;
    Ok(DirectRun {
        variant,
        seed,
        cond: design.cond,
        base_parameters: base.theta.len(),
        d_global_linear: column0(&global.d),
        d_base_parameters: column0(&m_base),
        global_tau: global.predict(figure)?,
        base_tau: base.on(model)?.predict(figure)?,
    })
}
