//! Errors in the regressors of the separated and combined regressions (docs/method.md,
//! section 4).
//!
//! The regressions `Y = X A^T` take the measured perturbations as `X`: q, qd, qdd read from the
//! positions at every crossing, less the operating point (or the reference posture) read the
//! same way. Their errors `U` move the estimate by `-(X^+ U) A^T` to first order (`X^+` the
//! pseudo-inverse), an error of the regressors that the residuals show only in part: the part
//! of `U` along the columns of `X` is absorbed by the estimate itself. Where the positions are
//! rounded to coarse encoder counts (`super::rounded_positions`) that part is most of it (the
//! rounding of a joint's staircase shrinks or stretches its measured perturbations), and D*
//! erred by up to 11 of the residuals' standard errors.
//!
//! So every standard error is at least what these errors give: with the standard errors of
//! each crossing's values (`row_var`, independent from crossing to crossing) and of the point
//! they are taken from (`common_var`, the same in every row),
//! `var(A_ip) >= sum_k B_pk^2 sum_l A_il^2 row_var_kl + (sum_k B_pk)^2 sum_l A_il^2 common_var_l`
//! with `B = X^+`. It is a floor, not an added variance, like the torque's rounding
//! ([`super::quantisation::floor_stderr`]).

use nalgebra::DMatrix;

use crate::error::{Error, Result};
use crate::regression::{column_norms, LeastSquares, RANK_TOLERANCE};

/// Raises the standard errors of `fit`, the solution of `Y ~= X A^T` with `x` (K x p) its
/// regressors, to at least those that errors of the regressors give to first order (see the
/// module documentation): `row_var` (K x p) the variance of each entry's own error,
/// `common_var` (p) the variance of an error shared by every row of a column (the point the
/// perturbations are measured from), in the squared units of `x`'s columns. Non-finite
/// variances count as 0; standard errors that are NaN (no residual degree of freedom, an
/// unmeasured row) stay NaN.
pub fn floor_stderr(
    fit: &mut LeastSquares,
    x: &DMatrix<f64>,
    row_var: &DMatrix<f64>,
    common_var: &[f64],
) -> Result<()> {
    let (k, p) = x.shape();
    if row_var.shape() != (k, p) || common_var.len() != p || fit.coef.ncols() != p {
        return Err(Error::shape(
            "errors of the regressors",
            format!("{k} x {p} variances and {p} common ones, like X"),
            format!(
                "{} x {} and {} ({} coefficients a row)",
                row_var.nrows(),
                row_var.ncols(),
                common_var.len(),
                fit.coef.ncols()
            ),
        ));
    }
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    // X^+ from the columns scaled to unit norm (their units differ by orders of magnitude in
    // the combined regression): X^+ = D^-1 (X D^-1)^+
    let norms = column_norms(x);
    if norms.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Ok(()); // a column without perturbation: the regression has refused it already
    }
    let scaled = DMatrix::from_fn(k, p, |i, c| x[(i, c)] / norms[c]);
    let b = crate::decomposition::pseudo_inverse(scaled, RANK_TOLERANCE).ok_or_else(|| {
        Error::numerical(
            "errors of the regressors",
            "the regressors are not finite, or their SVD did not converge",
        )
    })?;
    let sums: Vec<f64> = (0..p)
        .map(|c| b.row(c).iter().sum::<f64>() / norms[c])
        .collect();
    for i in 0..fit.coef.nrows() {
        let a2: Vec<f64> = fit.coef.row(i).iter().map(|v| v * v).collect();
        let per_row: Vec<f64> = (0..k)
            .map(|r| (0..p).map(|l| a2[l] * finite(row_var[(r, l)])).sum())
            .collect();
        let common: f64 = (0..p).map(|l| a2[l] * finite(common_var[l])).sum();
        for c in 0..p {
            let own: f64 = (0..k)
                .map(|r| (b[(c, r)] / norms[c]).powi(2) * per_row[r])
                .sum();
            let floor = (own + sums[c].powi(2) * common).sqrt();
            let se = &mut fit.stderr[(i, c)];
            if se.is_finite() && floor.is_finite() {
                *se = se.max(floor);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regression::least_squares;

    #[test]
    fn the_floor_is_the_spread_of_refits_with_perturbed_regressors() {
        // Y = X A^T exactly; X measured with independent errors of known variance: the
        // floor equals the first-order spread of A over many draws of the errors, found by
        // refitting (Monte Carlo)
        let (k, p) = (12, 3);
        let x = DMatrix::from_fn(k, p, |i, c| ((i * 7 + c * 3) as f64).sin() + 0.3 * c as f64);
        let a = DMatrix::from_row_slice(2, p, &[2.0, -1.0, 0.5, 0.3, 4.0, -2.0]);
        let y = &x * a.transpose();
        let row_sd = DMatrix::from_fn(k, p, |i, c| 1e-4 * (1.0 + ((i + c) % 3) as f64));
        let common_sd = [2e-4, 0.0, 1e-4];
        let mut fit = least_squares(&x, &y, "test", &["a".into(), "b".into(), "c".into()]).unwrap();
        fit.stderr.fill(0.0);
        let var = row_sd.map(|v| v * v);
        floor_stderr(&mut fit, &x, &var, &common_sd.map(|v| v * v)).unwrap();
        let mut seed = 11u64;
        let mut normal = || {
            // Box-Muller from a linear congruential generator
            let mut u = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (u1, u2) = (u(), u());
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        };
        let draws = 4000;
        let mut ss = DMatrix::zeros(2, p);
        for _ in 0..draws {
            let common: Vec<f64> = common_sd.iter().map(|s| s * normal()).collect();
            let xm = DMatrix::from_fn(k, p, |i, c| {
                x[(i, c)] + row_sd[(i, c)] * normal() + common[c]
            });
            let refit =
                least_squares(&xm, &y, "test", &["a".into(), "b".into(), "c".into()]).unwrap();
            ss += (&refit.coef - &a).map(|v| v * v);
        }
        for i in 0..2 {
            for c in 0..p {
                let spread = (ss[(i, c)] / draws as f64).sqrt();
                let ratio = fit.stderr[(i, c)] / spread;
                assert!(
                    (ratio - 1.0).abs() < 0.06,
                    "({i}, {c}): floor {} spread {spread}",
                    fit.stderr[(i, c)]
                );
            }
        }
        // NaN standard errors stay NaN; a wrong shape is an error
        fit.stderr[(0, 0)] = f64::NAN;
        floor_stderr(&mut fit, &x, &var, &[0.0; 3]).unwrap();
        assert!(fit.stderr[(0, 0)].is_nan());
        assert!(floor_stderr(&mut fit, &x, &var, &[0.0; 2]).is_err());
    }
}
