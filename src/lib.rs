//! perturbid_rs: identification of robot manipulator dynamics about an operating point
//! (Kinsheel & Taha, ICARCV 2010) and by the classical direct method.
//!
//! The dynamics core follows Pinocchio's design: an immutable [`Model`] built once from a URDF
//! ([`model_from_urdf_file`], [`model_from_urdf_str`], or a built-in robot from [`robots`]), a
//! [`Data`] of preallocated buffers, and algorithms as free functions that write into it:
//! [`rnea`], [`gravity_torque`], [`bias_torque`], [`mass_matrix`], [`forward_dynamics`],
//! [`rnea_derivatives`], and [`linearize`] for the local model at an operating point.
//!
//! Units: SI throughout (rad, m, s, kg, N m). Frames: the base frame with gravity along -z;
//! spatial quantities as described in [`spatial`].
//!
//! The README's example (`tests/readme.rs` checks that it reads the same there):
//!
//! ```
//! use perturbid_rs::{parallel, rnea, robots, Data, Gravity, States};
//!
//! let model = robots::builtin("a465")?;
//! let mut data = Data::new(&model);
//! let (q, qd, qdd) = (vec![0.1; 6], vec![0.2; 6], vec![0.3; 6]);
//! rnea(&model, &mut data, &q, &qd, &qdd, Gravity::Included)?; // data.tau
//!
//! // many samples (row-major k x nv), in parallel over the cores:
//! let k = 10_000;
//! let (qs, qds, qdds) = (q.repeat(k), qd.repeat(k), qdd.repeat(k));
//! let states = States::new(model.nv, &qs, Some(&qds), Some(&qdds))?; // checked once
//! let mut ws = parallel::Workspace::new(&model); // reuse: it keeps every thread's buffers
//! let mut taus = vec![0.0; k * model.nv];
//! parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut taus)?;
//! assert!((taus[6 * (k - 1)..].iter().zip(data.tau.iter())).all(|(a, b)| (a - b).abs() < 1e-9));
//! # Ok::<(), perturbid_rs::Error>(())
//! ```

// Errors carry their context (file, line, joint, time) by value; they are the cold path.
#![allow(clippy::result_large_err)]

pub mod algorithms;
pub mod band_fit;
mod choice;
#[cfg(feature = "cli")]
pub mod cli;
pub mod data;
pub mod decomposition;
pub mod direct;
pub mod document;
pub mod error;
pub(crate) mod finite;
pub mod gravity;
pub mod interrupt;
pub mod io;
pub mod json;
pub mod limits;
pub mod linearization;
pub mod local;
pub mod logs;
pub mod model;
pub mod model_file;
pub mod operating_point;
#[cfg(feature = "cli")]
pub mod paper;
pub mod parameters;
pub mod regression;
pub mod rehearsal;
pub mod robot_torques;
pub mod robots;
pub mod signal;
pub mod simd;
pub mod simulation;
pub mod spatial;
pub mod states;
pub mod student_t;
pub mod study;
pub mod svg;
pub mod torque_model;
pub mod trajectory;
pub mod urdf;
pub mod validation;

#[cfg(feature = "python")]
mod python;

pub use algorithms::aba::aba;
#[allow(deprecated)]
pub use algorithms::batch::{
    mass_matrix_batch, regressor_batch, rnea_batch, rnea_lanes, LaneData, LANES,
};
pub use algorithms::crba::mass_matrix;
pub use algorithms::derivatives::rnea_derivatives;
pub use algorithms::forward_dynamics::{forward_dynamics, forward_dynamics_crba};
pub use algorithms::parallel;
pub use algorithms::rnea::{bias_torque, gravity_torque, rnea};
pub use data::Data;
pub use document::Document;
pub use error::{catch_panics, Error, ErrorKind, Result};
pub use gravity::Gravity;
pub use linearization::{linearize, linearize_into, Linearization};
pub use local::{identify_local, plan_experiments, LocalModel, Plan, PlanOptions};
pub use logs::Recording;
pub use model::{Body, JointKind, JointLimits, Model};
pub use model_file::ModelFile;
pub use operating_point::OperatingPoint;
pub use robot_torques::RobotTorques;
pub use simd::Isa;
pub use simulation::{simulate_plan, Friction, SimulationOptions};
pub use states::{State, States};
pub use torque_model::{Expansion, TorqueModel};
pub use urdf::{model_from_urdf_file, model_from_urdf_str, LoadOptions};
