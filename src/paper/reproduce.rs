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
    /// Budget of the excitation design (default 800 evaluations).
    pub design_evaluations: usize,
}

impl Default for PaperOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            torque_noise: 0.0,
            design_evaluations: 800,
        }
    }
}

/// One of Figs. 3-5: torques of a joint along a trajectory through the operating point.
#[derive(Clone, Debug, Serialize)]
pub struct Figure {
    pub joint: usize,
    pub t: Vec<f64>,
    pub actual: Vec<f64>,
    pub local: Vec<f64>,
    pub global_linear: Vec<f64>,
    pub base_parameters: Vec<f64>,
}

/// RMS errors (N m) of the models along the figure trajectory: within `near` s of the operating
/// point, and over the whole trajectory.
#[derive(Clone, Debug, Serialize)]
pub struct FigureErrors {
    pub joint: usize,
    pub near: f64,
    pub local_near: f64,
    pub global_linear_near: f64,
    pub base_parameters_near: f64,
    pub local_all: f64,
    pub global_linear_all: f64,
    pub base_parameters_all: f64,
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
    #[serde(skip)]
    pub local_model: Option<LocalModel>,
}

fn column0(m: &DMatrix<f64>) -> Vec<f64> {
    m.column(0).iter().copied().collect()
}

/// Runs the reproduction. `progress` hears each step's name.
pub fn reproduce(options: &PaperOptions, progress: &mut dyn FnMut(&str)) -> Result<PaperResult> {
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
    let d_local = &local.d.as_ref().expect("planned").matrix;

    progress("direct method: designing the Fourier excitation (10 harmonics of 0.05 Hz)");
    let ex = ExcitationOptions {
        harmonics: 10,
        base_frequency: 0.05,
        max_evaluations: options.design_evaluations,
        seed: options.seed,
        ..ExcitationOptions::default()
    };
    let design = design_excitation(&model, &ex, None)?;
    progress("direct method: simulating the excitation and fitting both direct models");
    let samples = design.trajectory.sample_periods(1.0, 50.0);
    let rec = simulate_samples(&model, &samples, &sim, 99, "excitation")?;
    let batch = States::new(model.nv, &samples.q, Some(&samples.qd), Some(&samples.qdd))?;
    let global = identify_global_linear(&op, &batch, &rec.tau)?;
    let base = identify_base_parameters(
        &model,
        &batch,
        &rec.tau,
        &BaseOptions {
            friction: FrictionTerms::NONE,
            weighting: Weighting::Ols,
            gravity: Gravity::Excluded,
            seed: options.seed,
            ..BaseOptions::default()
        },
    )?;
    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &op.q)?;
    let actual = data.m.clone();
    let m_base = base.mass_matrix(&model, &op.q)?;

    progress("figures: torques along a trajectory through the operating point");
    // q(s) = q* + qd* s + qdd* s^2 / 2 for s in [-3, 3] s: passes P at s = 0
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
    let global_tau = global.predict(&states)?;
    let base_tau = base.on(&model)?.predict(&states)?;
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
    for joint in [2usize, 3, 4] {
        let j = joint - 1;
        let f = Figure {
            joint,
            t: ts.clone(),
            actual: pick(&actual_tau, j),
            local: pick(&local_tau, j),
            global_linear: pick(&global_tau, j),
            base_parameters: pick(&base_tau, j),
        };
        let is_near = |t: f64| t.abs() <= near;
        let all = |_: f64| true;
        errors.push(FigureErrors {
            joint,
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
    let d_stderr = &local.d.as_ref().expect("planned").stderr;
    Ok(PaperResult {
        torque_identified: local.torque.clone(),
        torque_paper: a465::TABLE2_TORQUE.to_vec(),
        d_actual: column0(&actual),
        d_actual_paper: a465::TABLE3_D_COLUMN1.to_vec(),
        d_perturbation: column0(d_local),
        d_perturbation_stderr: column0(d_stderr),
        d_perturbation_paper: TABLE3_PERTURBATION.to_vec(),
        d_global_linear: column0(&global.d),
        d_base_parameters: column0(&m_base),
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
        excitation_cond: design.cond,
        excitation_harmonics: ex.harmonics,
        excitation_frequency: ex.base_frequency,
        base_parameters: base.theta.len(),
        figures,
        errors,
        op,
        local_model: Some(local),
    })
}
