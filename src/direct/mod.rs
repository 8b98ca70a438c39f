//! The classical direct method the paper compares with (Swevers et al. 2007; docs/method.md,
//! section 8): Fourier excitation ([`crate::trajectory::fourier`]) designed by [`design_excitation`],
//! the regressor of the inertial and friction parameters, base parameters by pivoted QR,
//! OLS/WLS identification, and the globally linearised model.

pub mod base;
pub mod base_linearization;
pub mod base_model;
mod base_model_checks;
pub mod base_model_on;
pub mod base_options;
pub(crate) mod base_solve;
pub mod consistency;
pub mod consistent;
pub mod drive_gains;
pub mod excitation;
pub mod findings;
pub mod global_linear;
pub mod identify;
pub mod instrumental;
pub mod log_agreement;
pub mod log_findings;
pub mod log_offsets;
pub mod noise_fit;
pub mod parameter_table;
pub mod parameters;
pub mod payload;
pub mod payload_estimate;
pub mod payload_fit;
pub mod payload_quantities;
pub mod payload_reference;
pub mod position_offsets;
pub mod position_range;
pub mod residual_correlation;
pub mod run_checks;
pub mod runs;
pub mod signal_prediction;
pub mod streaming;
pub mod torque_columns;
pub mod torque_delay;
pub mod torque_lag;
pub mod torque_noise;
pub mod unmodelled_friction;
pub mod weak_excitation;
pub mod workspace;

pub use base::BaseParameters;
pub use base_model_on::BaseModelOn;
pub use consistency::{check_physical_consistency, BodyConsistency, ConsistencyReport};
pub use consistent::{
    consistent_least_squares, identify_consistent_parameters, ConsistentFit, ConsistentOptions,
    ConsistentSolution,
};
pub use drive_gains::{
    identify_drive_gains, identify_drive_gains_with, DriveGainFit, DriveGains, GainEstimator,
    GainRun,
};
pub use excitation::{design_excitation, Criterion, ExcitationDesign, ExcitationOptions};
pub use global_linear::{identify_global_linear, GlobalLinearModel};
pub use identify::{identify_base_parameters, BaseModel, BaseOptions, Weighting};
pub use log_agreement::LogAgreement;
pub use log_findings::LogFindings;
pub use log_offsets::LogOffsets;
pub use noise_fit::NoiseFit;
pub use parameter_table::ParameterRow;
pub use parameters::{regressor_blocks, regressor_matrix, FrictionTerms, ParameterLayout};
pub use payload::{
    identify_payload, PayloadFit, PayloadInertia, PayloadOptions, PayloadStderr, Reference,
};
pub use position_offsets::{
    check_position_offsets, check_position_offsets_in_validation, PositionOffsets,
};
pub use run_checks::{check_runs_against_model, RunChecks};
pub use torque_columns::{check_torque_columns, TorqueColumn};
pub use torque_lag::{check_torque_lag, TorqueLag};
pub use torque_noise::TorqueNoise;
pub use unmodelled_friction::{check_unmodelled_friction, MissingTerm, UnmodelledFriction};
pub use weak_excitation::{check_excitation, WeakExcitation};
pub use workspace::{workspace_from_json, CartesianConstraint, Region};
