//! The experiment plan (the paper's Table 1): for an operating point, the nominal, G-static,
//! G-dynamic, H and D experiments, each a continuous trajectory that starts and ends at rest and
//! passes the perturbed operating point K times.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::perturbation::{Design, Sizes};
use crate::choice::choice;
use crate::operating_point::OperatingPoint;
use crate::trajectory::Trajectory;

choice! {
    /// The kind of an experiment (docs/method.md, section 3); named `nominal`, `G_static`, `G`,
    /// `H`, `D` in files and messages.
    #[derive(PartialOrd, Ord, Serialize, Deserialize)]
    pub enum ExperimentKind ("experiments") {
        /// Step 1: K crossings of P itself; `T*` is the mean torque.
        #[serde(rename = "nominal")]
        Nominal = "nominal",
        /// Step 2: at rest at `q* + dq_k`; `tau_k - tau_rest(q*) = Gs dq_k`.
        #[serde(rename = "G_static")]
        GStatic = "G_static",
        /// Extension: crossings of `(q* + dq_k, qd*, qdd*)`; `tau_k - T* = G* dq_k`.
        #[serde(rename = "G")]
        GDynamic = "G",
        /// Step 3: crossings of `(q*, qd* + dqd_k, qdd*)`; `tau_k - T* = H* dqd_k`.
        #[serde(rename = "H")]
        H = "H",
        /// Step 4: crossings of `(q*, qd*, qdd* + dqdd_k)`; `tau_k - T* = D* dqdd_k`.
        #[serde(rename = "D")]
        D = "D",
    }
}

impl ExperimentKind {
    /// Which state variable the experiment perturbs: 0 = position, 1 = velocity,
    /// 2 = acceleration, `None` for the nominal experiment.
    pub fn perturbed(self) -> Option<usize> {
        match self {
            ExperimentKind::Nominal => None,
            ExperimentKind::GStatic | ExperimentKind::GDynamic => Some(0),
            ExperimentKind::H => Some(1),
            ExperimentKind::D => Some(2),
        }
    }

    /// The perturbation's name in messages: `dq`, `dqd` or `dqdd` (`dq` for the nominal, which
    /// perturbs nothing).
    pub fn perturbation_name(self) -> &'static str {
        match self.perturbed() {
            Some(2) => "dqdd",
            Some(1) => "dqd",
            _ => "dq",
        }
    }

    /// The matrix the experiment estimates: `Gs`, `G*`, `H*` or `D*` (`T*` for the nominal).
    pub fn estimate_name(self) -> &'static str {
        match self {
            ExperimentKind::Nominal => "T*",
            ExperimentKind::GStatic => "Gs",
            ExperimentKind::GDynamic => "G*",
            ExperimentKind::H => "H*",
            ExperimentKind::D => "D*",
        }
    }
}

/// A planned crossing: the time (s from the start of the experiment) and the state the robot
/// passes then.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Crossing {
    pub time: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

/// One experiment: its perturbations, its crossings and its trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    pub kind: ExperimentKind,
    /// `K x N` planned perturbations of the perturbed variable (zeros for the nominal one).
    #[serde(with = "crate::json::rows")]
    pub deltas: DMatrix<f64>,
    /// The K crossings in time order.
    pub crossings: Vec<Crossing>,
    /// G-static only: the rest posture at `q*` the static torques are measured against.
    pub reference: Option<Crossing>,
    /// Half-width (s) of the window around each crossing time in which the planned trajectory is
    /// exactly the crossing's quadratic (or the rest posture).
    pub window: f64,
    pub trajectory: Trajectory,
    /// A refined plan's departure of the commanded trajectory from the crossings, learned from
    /// the recordings of earlier rounds ([`super::refine`]); `None` where the trajectory passes
    /// the crossings themselves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commanded: Option<Commanded>,
}

/// How far a refined experiment's trajectory is commanded off its crossings, so that a robot
/// that tracks it with the errors it showed passes them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Commanded {
    /// Per crossing, in order, the commanded state less the crossing's.
    pub crossings: Vec<StateOffset>,
    /// G-static only: the same for the reference posture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<StateOffset>,
    /// How many rounds of recordings refined it.
    pub rounds: usize,
}

/// A state's offset per joint: rad, rad/s, rad/s^2 (m for a prismatic joint).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateOffset {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl Experiment {
    /// The state the trajectory is commanded through at crossing `k` (`None`: the reference
    /// posture): the crossing's, plus the refinement's offset.
    pub fn commanded_state(&self, k: Option<usize>) -> Option<[Vec<f64>; 3]> {
        let c = match k {
            Some(k) => self.crossings.get(k)?,
            None => self.reference.as_ref()?,
        };
        let offset = self.commanded.as_ref().and_then(|m| match k {
            Some(k) => m.crossings.get(k),
            None => m.reference.as_ref(),
        });
        let add = |a: &[f64], b: Option<&Vec<f64>>| -> Vec<f64> {
            a.iter()
                .enumerate()
                .map(|(j, x)| x + b.map_or(0.0, |b| b[j]))
                .collect()
        };
        Some([
            add(&c.q, offset.map(|o| &o.q)),
            add(&c.qd, offset.map(|o| &o.qd)),
            add(&c.qdd, offset.map(|o| &o.qdd)),
        ])
    }
}

impl Experiment {
    /// Duration (s).
    pub fn duration(&self) -> f64 {
        self.trajectory.end() - self.trajectory.start()
    }

    /// True when the perturbations come in +- pairs (rows `2i` and `2i + 1` opposite), as the
    /// planner's symmetric designs: then the even-order terms and a constant offset of the
    /// torque changes leave the separated estimates unbiased.
    pub fn in_pairs(&self) -> bool {
        let d = &self.deltas;
        d.nrows().is_multiple_of(2)
            && (0..d.nrows() / 2)
                .all(|i| (0..d.ncols()).all(|j| d[(2 * i, j)] == -d[(2 * i + 1, j)]))
    }

    /// The condition number of the perturbations `deltas` with every joint's column scaled to
    /// unit norm (what the experiment's regression reports as cond(X)): 1 for an orthogonal
    /// design. None for the nominal experiment (no perturbation) or a design that leaves a joint
    /// unperturbed.
    pub fn design_cond(&self) -> Option<f64> {
        let s = crate::regression::scaled_singular_values(&self.deltas)?;
        Some(s[0] / s[s.len() - 1])
    }
}

/// The condition number of a planned experiment's perturbations above which the planner warns
/// (a random 6 x 6 design exceeds it about one time in four; an orthogonal design has 1).
pub const DESIGN_COND_WARNING: f64 = 30.0;

/// Options of [`plan_experiments`](super::plan_experiments); [`PlanOptions::default`] documents the defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Experiments to plan (default: all five, in the order of [`ExperimentKind::ALL`]).
    pub experiments: Vec<ExperimentKind>,
    /// Perturbation design (default [`Design::Random`], as in the paper).
    pub design: Design,
    /// Perturbations per experiment, K (default `2 N`).
    pub count: Option<usize>,
    /// Symmetric `+-` pairs (default true): cancels the even-order terms of H and G.
    pub symmetric: bool,
    pub seed: u64,
    /// Sampling rate of the trajectories (Hz, default 1000).
    pub rate: f64,
    pub sizes: Sizes,
    /// Half-width of each crossing window (s, default 0.05): the trajectory is the crossing's
    /// quadratic on `[t_c - window, t_c + window]`.
    pub window: f64,
    /// How long each static posture is held (s, default 1.0).
    pub dwell: f64,
    /// Fraction of the speed and acceleration limits transitions may use (default 0.8).
    pub margin: f64,
    /// Speed and acceleration bounds for transitions of joints whose URDF gives none
    /// (default 1 rad/s and 4 rad/s^2).
    pub default_velocity: f64,
    pub default_acceleration: f64,
    /// Shortest transition (s, default 0.2); the longest tried is 30 s.
    pub min_transition: f64,
    /// Keep every velocity perturbation of the H experiment below `0.9 |qd*|` of its joint, so
    /// that no joint's velocity changes sign between passes and friction cancels from H*
    /// (default false: a joint whose perturbations exceed `|qd*|` gets a warning instead). A
    /// joint with `qd* = 0` cannot be perturbed so: refused, use `friction_aware_h`.
    pub keep_velocity_sign: bool,
    /// Plan enough H passes for the friction-aware H regression
    /// ([`crate::local::IdentifyOptions::friction_aware_h`]): at least `2 (N + 2)`, in +- pairs
    /// (`N + 1` pairs determine it, one more gives its standard errors).
    pub friction_aware_h: bool,
    /// The steps (rad, or m for a prismatic joint; one per joint, 0 for a joint whose step is
    /// not known) of the encoders the robot logs its positions in, when known (default none).
    /// Each experiment's crossings are then read as the identification will read them (the
    /// planned positions over each window rounded to the steps and read by their band, see
    /// [`super::rounded_positions::planned_resolution`]), and the joints whose perturbations
    /// they would resolve to worse than a tenth of their size get a warning with the window or
    /// perturbation size that would resolve them.
    pub encoder_step: Option<Vec<f64>>,
    /// The standard deviation of the robot's torque samples (N m, or N for a prismatic joint;
    /// one per joint, 0 for a joint whose noise is not known), when known (default none). Each
    /// perturbed experiment's torque changes are then predicted from the model and the
    /// identification's response test run on draws of that noise
    /// ([`super::predicted_response`]); an experiment it would find in fewer than 90 % of runs
    /// gets a warning with the perturbation size that would resolve it.
    pub torque_noise: Option<Vec<f64>>,
    /// What the robot's torque readings vary by from pass to pass beyond the samples' noise
    /// (N m, or N for a prismatic joint, a standard deviation of one crossing's reading; one
    /// per joint, 0 for none), when known (default none): noise slower than a window, a
    /// drifting sensor, the robot's repeatability, as an identification reports it
    /// ([`super::TorqueNoise::passes`]). The prediction of [`Self::torque_noise`] then adds it
    /// to every reading; it needs `torque_noise` for each joint it is given for.
    pub torque_pass_noise: Option<Vec<f64>>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            experiments: ExperimentKind::ALL.to_vec(),
            design: Design::Random,
            count: None,
            symmetric: true,
            seed: 0,
            rate: 1000.0,
            sizes: Sizes::default(),
            window: 0.05,
            dwell: 1.0,
            margin: 0.8,
            default_velocity: 1.0,
            default_acceleration: 4.0,
            min_transition: 0.2,
            keep_velocity_sign: false,
            friction_aware_h: false,
            encoder_step: None,
            torque_noise: None,
            torque_pass_noise: None,
        }
    }
}

/// A plan: the operating point and its experiments, for one robot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// `perturbid-plan/1`.
    pub format: String,
    /// Robot name and joint names (the plan is only valid for this robot).
    pub robot: String,
    pub joint_names: Vec<String>,
    pub op: OperatingPoint,
    /// Sampling rate (Hz) of the trajectories.
    pub rate: f64,
    pub design: Design,
    pub seed: u64,
    pub experiments: Vec<Experiment>,
    /// What the planner found the user should know (each also given as a Python warning and
    /// printed by the command line), e.g. velocity perturbations that reverse a joint.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

impl Plan {
    /// Number of joints.
    pub fn n(&self) -> usize {
        self.op.n()
    }

    /// The experiments' names in order, comma separated (for messages).
    pub fn kinds(&self) -> String {
        self.experiments
            .iter()
            .map(|e| e.kind.name())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The experiment of `kind`, if planned.
    pub fn experiment(&self, kind: ExperimentKind) -> Option<&Experiment> {
        self.experiments.iter().find(|e| e.kind == kind)
    }
}
