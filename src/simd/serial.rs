//! Loops kept serial: the multi-sample kernels are vectorised across samples already (each
//! iteration of a loop over bodies works on whole registers of lanes), and must not be
//! vectorised a second time across the loop's iterations.
//!
//! With AVX-512 enabled, LLVM's loop vectoriser does that to loops over bodies and subtree
//! entries: it gathers lane `l` of 4 or 8 bodies into one register and scatters the results
//! back, which made the 8-lane mass matrix 2x, the regressor 4x and the derivatives 1.2x slower
//! than the 4-lane AVX2 code on a Zen 4 (benches/README.md). [`serial`] wraps a loop's iterator
//! with a compiler fence at each step: no instruction is emitted, but the loop vectoriser leaves
//! a loop alone whose body may order memory.

use std::sync::atomic::{compiler_fence, Ordering};

/// `iter`, whose loop the compiler does not vectorise across iterations (see the module doc).
#[inline(always)]
pub(crate) fn serial<I: Iterator>(iter: I) -> Serial<I> {
    Serial(iter)
}

/// The iterator of [`serial`].
pub(crate) struct Serial<I>(I);

impl<I: Iterator> Iterator for Serial<I> {
    type Item = I::Item;
    #[inline(always)]
    fn next(&mut self) -> Option<I::Item> {
        compiler_fence(Ordering::SeqCst);
        self.0.next()
    }
}

impl<I: DoubleEndedIterator> DoubleEndedIterator for Serial<I> {
    #[inline(always)]
    fn next_back(&mut self) -> Option<I::Item> {
        compiler_fence(Ordering::SeqCst);
        self.0.next_back()
    }
}
