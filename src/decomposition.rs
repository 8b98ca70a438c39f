//! Eigen- and singular-value decompositions that always end. nalgebra's iterate until they
//! converge, and a matrix holding a NaN or an infinity (a hostile input, an overflow on the
//! way) never converges: `svd()` and `symmetric_eigen()` then spin forever. These refuse such
//! a matrix and bound the iterations, and say None instead of hanging; each caller turns that
//! into an error or a diagnostic it cannot judge.

use nalgebra::allocator::Allocator;
use nalgebra::{
    DMatrix, DefaultAllocator, Dim, DimDiff, DimSub, Dyn, OMatrix, SymmetricEigen, SVD, U1,
};

/// Iterations allowed per row or column of the matrix (converging ones take a few each).
pub const ITERATIONS_PER_DIMENSION: usize = 1000;

/// The singular-value decomposition of `m` (`U` and `V^T` as asked), or None where `m` holds
/// a value that is not finite or the iterations do not converge.
pub fn svd(m: DMatrix<f64>, compute_u: bool, compute_v: bool) -> Option<SVD<f64, Dyn, Dyn>> {
    if m.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let limit = ITERATIONS_PER_DIMENSION * (1 + m.nrows().min(m.ncols()));
    SVD::try_new(m, compute_u, compute_v, f64::EPSILON, limit)
}

/// The pseudo-inverse of `m` (singular values at most `eps` taken as zero), or None where
/// [`svd`] is.
pub fn pseudo_inverse(m: DMatrix<f64>, eps: f64) -> Option<DMatrix<f64>> {
    svd(m, true, true)?.pseudo_inverse(eps).ok()
}

/// The eigendecomposition of the symmetric `m` (its lower triangle read), or None where `m`
/// holds a value that is not finite or the iterations do not converge.
pub fn symmetric_eigen<D>(m: OMatrix<f64, D, D>) -> Option<SymmetricEigen<f64, D>>
where
    D: Dim + DimSub<U1>,
    DefaultAllocator: Allocator<D, D> + Allocator<D> + Allocator<DimDiff<D, U1>>,
{
    if m.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let limit = ITERATIONS_PER_DIMENSION * (1 + m.nrows());
    SymmetricEigen::try_new(m, f64::EPSILON, limit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Matrix4};

    #[test]
    fn finite_matrices_decompose_and_the_rest_end() {
        let m = DMatrix::from_fn(7, 4, |i, j| ((i * 4 + j) as f64).sin());
        let s = svd(m.clone(), true, true).unwrap();
        let back = s.u.as_ref().unwrap()
            * DMatrix::from_diagonal(&s.singular_values)
            * s.v_t.as_ref().unwrap();
        assert!((back - &m).norm() < 1e-12 * m.norm());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut b = m.clone();
            b[(3, 2)] = bad;
            assert!(svd(b, true, true).is_none());
            let mut e = Matrix4::<f64>::identity();
            e[(1, 2)] = bad;
            assert!(symmetric_eigen(e).is_none());
        }
        // an overflow on the way (entries near the largest f64) ends too, decomposed or not
        let _ = svd(DMatrix::from_element(3, 3, 1e308), true, true);
        let i = Matrix3::new(2.0, 0.5, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 3.0);
        let e = symmetric_eigen(i).unwrap();
        let back =
            e.eigenvectors * Matrix3::from_diagonal(&e.eigenvalues) * e.eigenvectors.transpose();
        assert!((back - i).norm() < 1e-14);
    }
}
