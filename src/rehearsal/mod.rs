//! Rehearsal on a true robot: what a real robot would record along a reference, when it
//! differs from the model the experiments were planned with (payload, parameter errors, joint
//! zero offsets), its joints add friction, ripple and cogging, its sensors quantise, delay and
//! add noise, and it tracks the reference under a controller. The true robot is one JSON
//! document ([`TrueRobot`], `docs/rehearsal.md`); [`rehearse`] turns a reference (a plan's
//! trajectory, a Fourier excitation, any sampled states) into the [`crate::Recording`] the robot
//! would log, which the identifications read like a real one.
//!
//! The simpler [`crate::simulation`] (friction, white noise, quantisation, exact tracking of
//! the planned model) stays for quick rehearsals.

pub mod joint_effects;
pub mod local_case;
pub mod local_truth;
pub mod realistic;
pub mod recorded;
pub mod sensors;
pub mod tracking;
pub mod true_robot;

pub use crate::model::payload::{link_in_body, Payload};
pub use joint_effects::JointEffects;
pub use local_case::{compare, local_case, LocalCase};
pub use local_truth::{true_local, TrueLocal};
pub use realistic::{realistic_robot, tracking_controller, Realism};
pub use recorded::{rehearse, rehearse_plan, true_torques};
pub use true_robot::{Controller, FrictionSpec, Harmonic, LinkError, Sensors, TrueRobot};
