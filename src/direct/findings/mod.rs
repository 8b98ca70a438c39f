//! What the direct method's checks find, as types that a [`super::BaseModel`] holds: each
//! beside the check that finds it would make the model and the check use each other.

pub mod drive_gains;
pub mod log_agreement;
pub mod position_offsets;
pub mod runs;
pub mod unmodelled_friction;
