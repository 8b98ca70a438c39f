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

/// Counting the floating-point operations of the lane kernels (build with the `count-flops`
/// feature): every add, subtract and multiply of a lane counts 1, a fused multiply-add
/// 2, per lane in use or not. For the flop counts behind the fraction of peak in
/// benches/README.md (`cargo run --release --features count-flops --example flop_count`).
#[cfg(feature = "count-flops")]
pub mod flops {
    use std::cell::Cell;

    thread_local! {
        static COUNT: Cell<u64> = const { Cell::new(0) };
    }

    pub(crate) fn add(n: usize) {
        COUNT.with(|c| c.set(c.get() + n as u64));
    }

    /// The operations counted on this thread since the last call, and a restart from zero.
    pub fn take() -> u64 {
        COUNT.with(|c| c.replace(0))
    }
}
