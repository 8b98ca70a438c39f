//! Finiteness of large arrays: the first value that is NaN or infinite, found in one
//! branch-free pass (over the cores for large arrays).

/// The index of the first value of `x` that is NaN or infinite: one branch-free pass (over the
/// cores for large arrays), a second one only to find a bad value.
pub(crate) fn first_non_finite(x: &[f64]) -> Option<usize> {
    use rayon::prelude::*;
    if x.len() < 1 << 16 {
        return first_non_finite_here(x);
    }
    if x.par_chunks(1 << 14).any(any_non_finite) {
        x.iter().position(|v| !v.is_finite())
    } else {
        None
    }
}

/// [`first_non_finite`] on the calling thread.
pub(crate) fn first_non_finite_here(x: &[f64]) -> Option<usize> {
    if any_non_finite(x) {
        x.iter().position(|v| !v.is_finite())
    } else {
        None
    }
}

/// Whether any value is NaN or infinite: `v - v` is +0 for a finite value and NaN otherwise,
/// so the bits of the differences, or-ed together, are zero only if every value is finite (a
/// form the compiler vectorises without 64-bit integer compares).
#[allow(clippy::eq_op)] // `v - v` is the test, not a mistake
fn any_non_finite(x: &[f64]) -> bool {
    x.iter().fold(0u64, |bits, v| bits | (v - v).to_bits()) != 0
}
