//! What the checks of a log find, as types that a [`super::recording::Recording`] holds: each
//! beside the check that finds it would make the recording and the check use each other.

pub mod held_columns;
pub mod log_dropouts;
pub mod log_screening;
pub mod position_rounding;
pub mod position_wraps;
pub mod stamp_jitter;
pub mod torque_saturation;
