//! The paper's method (Kinsheel & Taha 2010; METHOD.md sections 2-7): experiments that pass a
//! perturbed operating point, and separated regressions of the torque changes that give the
//! local model `tau - T* = D* dqdd + H* dqd + G* dq`.
//!
//! The workflow: an [`OperatingPoint`], a [`Plan`] from [`plan_experiments`], one
//! [`crate::Recording`] per experiment (from the robot, or rehearsed with
//! [`crate::simulation::simulate_plan`]), and the [`LocalModel`] from [`identify_local`].

pub mod crossing;
pub mod identify;
pub mod model;
pub mod operating_point;
pub mod perturbation;
pub mod plan;

pub use crossing::{values_at, CrossingValues, FitOptions};
pub use identify::{identify_local, CrossingTimes, IdentifyOptions};
pub use model::{Estimate, Estimator, LocalModel};
pub use operating_point::OperatingPoint;
pub use perturbation::{Design, Size, Sizes};
pub use plan::{plan_experiments, Crossing, Experiment, ExperimentKind, Plan, PlanOptions};
