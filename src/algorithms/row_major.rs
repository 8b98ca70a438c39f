//! A matrix written into a row-major slice: how the batched kernels hand a sample's matrix
//! (a regressor, a mass matrix, a derivative) to their outputs.

use nalgebra::DMatrix;

/// `m` written row by row into `out` (`nrows * ncols` values).
#[inline]
pub(crate) fn copy_row_major(m: &DMatrix<f64>, out: &mut [f64]) {
    let n = m.ncols();
    for r in 0..m.nrows() {
        for c in 0..n {
            out[r * n + c] = m[(r, c)];
        }
    }
}
