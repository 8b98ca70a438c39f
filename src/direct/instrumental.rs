//! The instrumental-variable fit of base parameters and drive gains over the per-joint factors
//! of a streaming fit ([`super::streaming`]), for a logged signal whose noise sits in columns
//! of the regressor ([`super::drive_gains`]; docs/method.md, section 8c).
//!
//! Least squares on `X beta = y`, `X = [Phi_base | S]` with `S` the joints' signal columns,
//! takes the signal's noise for part of the data it explains, and the gains come out biased
//! towards 0. Instrumental variables solve `Z^T X beta = Z^T y` instead, with instruments `Z`
//! that follow the signal but not its noise: here `Z = [Phi_base | S_hat]`, `S_hat` the signal
//! predicted from the positions by a first fit, `(y - Phi_base theta_0) / c_0` in each joint's
//! rows (`c_0` the signal's coefficient, `-K_0`). `Phi_base` and `tau_L` come from the
//! positions, so `S_hat` is uncorrelated with the signal's noise and the estimate is
//! consistent whatever `theta_0` was; the first fit's bias costs only precision.
//!
//! Everything comes from the factors, without a second pass over the samples: each joint's
//! rows `A_j = [Phi_j | s_j | y_j]` have `R_j`, and `S_hat`'s column is a combination of them,
//! so `R_j` times that combination is its factor. The QR of the weighted stack `[Z | S | y] =
//! Q R` gives `Z^T X = R_11^T M` and `Z^T y = R_11^T b` with `M = [R_11[:, ..p] | R_12]` and
//! `b = R_13`, so the estimate solves the square `M beta = b` (conditioned as `X`, not
//! squared) and its covariance is `sigma^2 M^-1 M^-T`.

use nalgebra::{DMatrix, DVector};

use super::streaming::{triangular_of_stacked, JointFactors};
use crate::error::{Error, Result};
use crate::regression::{least_squares, LeastSquares};

/// The instrumental-variable estimate over `factors` (one column of data a joint: the signal)
/// with joint `j`'s rows weighted by `1 / sigma[j]`, the instruments predicted by the first
/// fit's unknowns `first` (`p + nv`: the base parameters, then each joint's signal
/// coefficient, none 0). `names` label the unknowns for a rank-deficiency error.
///
/// Returns the estimate as a [`LeastSquares`]: `coef` (`1 x (p + nv)`), `stderr` from the
/// weighted residuals of the estimate (`sigma_w^2 = |W (y - X beta)|^2 / (K nv - p - nv)`),
/// `residual_rms` per joint, unweighted (N m, [`JointFactors::residual_rms`]), `cov_diag`
/// and `correlation` of `M^-1 M^-T`, `cond` of the column-scaled `M`, `rows`; `leverage`
/// and `weakest` as the square solve leaves them.
pub(super) fn instrumental(
    factors: &JointFactors,
    sigma: &[f64],
    first: &[f64],
    names: &[String],
) -> Result<LeastSquares> {
    let nv = factors.factors.len();
    let p = factors.parameters;
    let unknowns = p + nv;
    let context = "drive-gain identification (instrumental variables)";
    if factors.extra != 1 || first.len() != unknowns || names.len() != unknowns {
        return Err(Error::shape(
            context,
            format!("one column of data a joint and {unknowns} first-fit unknowns and names"),
            format!(
                "{} columns a joint, {} unknowns, {} names",
                factors.extra,
                first.len(),
                names.len()
            ),
        ));
    }
    if let Some(j) = (0..nv).find(|&j| !(first[p + j].is_finite() && first[p + j] != 0.0)) {
        return Err(Error::numerical(
            context,
            format!(
                "the first fit's coefficient of joint {}'s signal is {}: no instrument can be predicted from it",
                j + 1,
                first[p + j]
            ),
        ));
    }
    // each joint's factor with the predicted signal's column: [Phi_j | s_hat_j | s_j | y_j]
    let augmented: Vec<DMatrix<f64>> = (factors.factors.iter().zip(&factors.active))
        .enumerate()
        .map(|(j, (r, active))| {
            let nj = active.len();
            let theta = DVector::from_iterator(nj, active.iter().map(|&c| first[c]));
            let predicted = (r.column(nj + 1) - r.columns(0, nj) * theta) / first[p + j];
            let mut a = DMatrix::zeros(r.nrows(), nj + 3);
            a.columns_mut(0, nj).copy_from(&r.columns(0, nj));
            a.set_column(nj, &predicted);
            a.columns_mut(nj + 1, 2).copy_from(&r.columns(nj, 2));
            a
        })
        .collect();
    // stacked as [Phi_base | S_hat | S | y]: Z's columns first
    let r = triangular_of_stacked(&augmented, sigma, unknowns + nv + 1, |j, c| {
        let nj = factors.active[j].len();
        match c {
            c if c < nj => factors.active[j][c],
            c if c == nj => p + j,
            c if c == nj + 1 => unknowns + j,
            _ => unknowns + nv,
        }
    });
    let m = DMatrix::from_fn(unknowns, unknowns, |i, c| {
        r[(i, if c < p { c } else { c + nv })]
    });
    let b = DMatrix::from_fn(unknowns, 1, |i, _| r[(i, unknowns + nv)]);
    let mut iv = least_squares(&m, &b, context, names)?;
    let coef: Vec<f64> = iv.coef.row(0).iter().copied().collect();
    let rms = factors.residual_rms(&coef)?;
    let k = factors.samples as f64;
    let weighted: f64 = (rms.iter().zip(sigma))
        .map(|(r, s)| k * (r / s).powi(2))
        .sum();
    let rows = factors.samples * nv;
    let s = (weighted / rows.saturating_sub(unknowns).max(1) as f64).sqrt();
    iv.stderr = DMatrix::from_fn(1, unknowns, |_, c| s * iv.cov_diag[c].sqrt());
    iv.rows = rows;
    iv.residual_rms = DVector::from_vec(rms);
    Ok(iv)
}
