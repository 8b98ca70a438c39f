//! SIMD arithmetic for the multi-sample kernels: the lane types (several samples side by side,
//! one per vector lane), `sin`/`cos` of every lane, and the run-time choice of instruction set.

mod isa;
mod lanes;
mod sin_cos;

pub use isa::Isa;
pub(crate) use lanes::{Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes};
pub(crate) use sin_cos::sin_cos;
