//! The paper's method (Kinsheel & Taha 2010; docs/method.md, sections 2-7): experiments that pass a
//! perturbed operating point, and separated regressions of the torque changes that give the
//! local model `tau - T* = D* dqdd + H* dqd + G* dq`.
//!
//! The workflow: an [`OperatingPoint`], a [`Plan`] from [`plan_experiments`], one
//! [`crate::Recording`] per experiment (from the robot, or rehearsed with
//! [`crate::simulation::simulate_plan`]), and the [`LocalModel`] from [`identify_local`].
//!
//! ```
//! use perturbid_rs::local::{identify_local, plan_experiments, Design, IdentifyOptions};
//! use perturbid_rs::{linearize, robots, simulate_plan, Data, Friction, Gravity};
//! use perturbid_rs::{OperatingPoint, PlanOptions, SimulationOptions};
//! let model = robots::builtin("a465")?;
//! let op = OperatingPoint::new(
//!     vec![0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0],
//!     vec![0.089, -0.106, 0.022, 0.056, 0.011, 0.014],
//!     vec![-0.155, -0.5, 0.034, -0.291, -0.008, 0.171],
//! )?;
//! let options = PlanOptions { design: Design::Orthogonal, ..PlanOptions::default() };
//! let plan = plan_experiments(&model, &op, &options)?;
//! // rehearse on the model itself: gravity compensated, no friction, no noise
//! let mut sim = SimulationOptions::new(&model);
//! sim.gravity = Gravity::Excluded;
//! sim.friction = Friction::none(model.nv);
//! let recordings = simulate_plan(&model, &plan, &sim)?;
//! let local = identify_local(&plan, &recordings, &IdentifyOptions::default())?;
//! let truth = linearize(&model, &mut Data::new(&model), &op.q, &op.qd, &op.qdd, Gravity::Excluded)?;
//! let d = local.d.as_ref().expect("the plan has a D experiment");
//! assert!((&d.matrix - &truth.d).norm() < 1e-6 * truth.d.norm());
//! # Ok::<(), perturbid_rs::Error>(())
//! ```

mod carry_to_plan;
pub mod clock;
pub mod crossing;
pub mod crossing_values;
mod diagnose;
pub mod diagnostics;
pub mod errors_in_variables;
pub mod estimator_evidence;
mod flat_channels;
mod followed_plan;
mod friction_aware;
pub mod glitches;
pub mod identify;
mod identify_local;
mod identify_with_delay;
pub mod miss;
pub mod model;
mod model_summary;
pub mod noise;
mod nominal_point;
pub mod offset_search;

pub mod parameters;
pub mod perturbation;
pub mod plan;
mod plan_checks;
pub mod plan_files;
mod plan_warnings;
pub mod planning;
pub mod point_design;
mod pooled_rounds;
pub mod predicted_response;
pub(crate) mod prediction_uncertainty;
pub mod quantisation;
pub mod reach;
pub mod refine;
mod regressions;
mod repaired_recording;
pub mod repeated_reading;
pub mod response;
pub mod reversals;
pub mod rounded_positions;
pub mod session;
pub mod torque_offsets;
mod trajectory_builder;

pub use crate::operating_point::OperatingPoint;
pub use clock::{check_clock, covering_offsets, overlap_offsets, position_misfit, PositionMisfit};
pub use crossing::{
    noise_levels, values_at, values_at_with, values_in_windows, CrossingValues, FitOptions, Signal,
    SignalScales, TorqueFit, WindowGlitch,
};
pub use diagnostics::{
    BlockAgreement, ClockOffset, Diagnostics, EstimatorEvidence, Glitch, Reversal,
    ReversalHandling, TorqueNoise, Unmeasured,
};
pub use identify::{CrossingTimes, IdentifyOptions, TimesSource};
pub use identify_local::identify_local;
pub use identify_with_delay::{identify_local_rounds_with_delay, identify_local_with_delay};
pub use miss::Miss;
pub use model::{Estimate, Estimator, LocalModel, SignalGains};
pub use offset_search::{detect_offset, detect_offset_in};
pub use parameters::{identify_parameters_from_local, FromLocalOptions, ParametersFromLocal};
pub use perturbation::{Design, Size, Sizes};
pub use plan::{Crossing, Experiment, ExperimentKind, Plan, PlanOptions};
pub use planning::plan_experiments;
pub use point_design::{suggest_operating_points, SuggestedPoint};
pub use pooled_rounds::identify_local_rounds;
pub use reach::{Extrapolation, Perturbations, REACH_LIMIT};
pub use refine::refine_plan;
pub use session::{gaps_in_runs, repeated_runs, split_session, SplitOptions};
