//! SIMD arithmetic for the multi-sample kernels: the lane types (several samples side by side,
//! one per vector lane), `sin`/`cos` of every lane, the transpose of lanes into the rows of an
//! output and of the input's rows into lanes, loops kept from a second vectorisation, and the
//! run-time choice of instruction set.

mod isa;
mod lanes;
mod read_rows;
mod rows;
mod serial;
mod sin_cos;

pub use isa::Isa;
pub(crate) use lanes::{Lanes, Rotation3Lanes, SpatialLanes, Vector3Lanes};
pub(crate) use read_rows::read_rows;
pub(crate) use rows::{store_fence, write_rows, write_rows_with_zeros, Stores, ZeroPattern};
pub(crate) use serial::serial;
pub(crate) use sin_cos::sin_cos;

#[cfg(feature = "count-flops")]
pub mod flops;
