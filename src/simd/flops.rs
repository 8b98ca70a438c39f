//! Counting the floating-point operations of the lane kernels (build with the `count-flops`
//! feature): every add, subtract and multiply of a lane counts 1, a fused multiply-add
//! 2, per lane in use or not. For the flop counts behind the fraction of peak in
//! benches/README.md (`cargo run --release --features count-flops --example flop_count`).

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
