//! Linear least squares on faer, with the statistics an identification needs: the condition
//! number of the design, residual RMS and coefficient standard errors, and a rank-deficient
//! design reported with the directions it does not excite.

use faer::linalg::solvers::Svd;
use faer::{Mat, MatRef};
use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};

/// The least-squares solution of `Y ~= X A^T` (`X`: K x p regressors, `Y`: K x m outputs).
#[derive(Clone, Debug, PartialEq)]
pub struct LeastSquares {
    /// `A`, m x p: output `i` = `sum_j A[i, j] x_j`.
    pub coef: DMatrix<f64>,
    /// Condition number (2-norm, ratio of extreme singular values) of `X` after scaling each
    /// column to unit norm, so it does not depend on units; 1 for an orthogonal design.
    pub cond: f64,
    /// Per output, the RMS of the residuals `Y - X A^T` (m).
    pub residual_rms: DVector<f64>,
    /// Standard error of every coefficient, m x p: `sigma_i sqrt((X^T X)^-1_jj)` with
    /// `sigma_i^2 = |r_i|^2 / (K - p)`. NaN when K = p (no residual degrees of freedom).
    pub stderr: DMatrix<f64>,
    /// Number of rows K.
    pub rows: usize,
    /// The diagonal of `(X^T X)^-1` (p): with a noise level `sigma`, the standard errors are
    /// `sigma * sqrt(cov_diag)` (computed from scaled columns, so the standard errors stay
    /// finite where `cov_diag` itself leaves f64's range: 0 or inf).
    pub cov_diag: Vec<f64>,
    /// The leverage of every row (K): the diagonal of the hat matrix `X (X^T X)^-1 X^T`, in
    /// [0, 1], summing to p. A residual's variance is `sigma^2 (1 - leverage)` for noise of
    /// equal variance.
    pub leverage: Vec<f64>,
    /// The correlation of the coefficients of any one output, p x p: `(X^T X)^-1` scaled to a
    /// unit diagonal (the design's alone, the same for every output; with the standard errors
    /// of an output's row, `diag(se) R diag(se)` is its coefficients' covariance).
    pub correlation: DMatrix<f64>,
    /// The right singular vector of `X`'s smallest singular value after scaling each column to
    /// unit norm (p, unit norm, its largest entry positive): the combination of the scaled
    /// coefficients the data determine least well, `cond / s_max` times less precisely than
    /// an orthogonal design of the same column norms would.
    pub weakest: Vec<f64>,
}

/// Relative singular-value threshold below which a design counts as rank deficient.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// Solves `Y ~= X A^T` by a thin SVD of the column-scaled `X` (one decomposition for all m
/// outputs). `context` and `columns` (the names of X's p columns) go into the error when `X`
/// does not have full column rank, which names the missing directions. Fails on shapes that do
/// not match, K < p, or non-finite entries.
pub fn least_squares(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    context: &str,
    columns: &[String],
) -> Result<LeastSquares> {
    let (k, p) = x.shape();
    let scale = check_system(x, y, context, columns)?;
    let xs = Mat::<f64>::from_fn(k, p, |i, j| x[(i, j)] / scale[j]);
    let svd = Svd::new_thin(xs.as_ref())
        .map_err(|e| Error::numerical(context, format!("the SVD did not converge: {e:?}")))?;
    let (u, v) = (svd.U(), svd.V());
    let s: Vec<f64> = (0..p).map(|i| svd.S().column_vector()[i]).collect();
    let smax = s.iter().cloned().fold(0.0, f64::max);
    let smin = s.iter().cloned().fold(f64::INFINITY, f64::min);
    refuse_weak_directions(k, v, &s, &scale, context, columns)?;
    let solution = solve(x, y, u, v, &s, &scale, context)?;
    let leverage = (0..k)
        .map(|r| (0..p).map(|i| u[(r, i)] * u[(r, i)]).sum())
        .collect();
    let cov_scaled = &solution.cov_scaled;
    // (X^T X)^-1 of the scaled X is V S^-2 V^T; its correlation is that of the unscaled one
    let correlation = DMatrix::from_fn(p, p, |a, b| {
        if a == b {
            return 1.0;
        }
        let c: f64 = (0..p).map(|i| v[(a, i)] * v[(b, i)] / (s[i] * s[i])).sum();
        (c / (cov_scaled[a] * cov_scaled[b]).sqrt()).clamp(-1.0, 1.0)
    });
    Ok(LeastSquares {
        weakest: weakest_direction(v, &s),
        cond: smax / smin,
        rows: k,
        leverage,
        correlation,
        coef: solution.coef,
        residual_rms: solution.residual_rms,
        stderr: solution.stderr,
        cov_diag: solution.cov_diag,
    })
}

/// Refuses shapes that disagree, fewer equations than unknowns, non-finite values and a column
/// of zeros; returns X's column norms.
fn check_system(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    context: &str,
    columns: &[String],
) -> Result<Vec<f64>> {
    let (k, p) = x.shape();
    let m = y.ncols();
    if y.nrows() != k || columns.len() != p {
        return Err(Error::shape(
            format!("{context}: least squares"),
            format!("Y with {k} rows like X and {p} column names"),
            format!("Y {} x {m}, {} names", y.nrows(), columns.len()),
        ));
    }
    if p == 0 || k < p {
        return Err(Error::RankDeficient {
            context: context.into(),
            rows: k,
            cols: p,
            rank: k.min(p),
            missing: format!("{k} equations cannot determine {p} unknowns; add samples"),
        });
    }
    if let Some(i) = x.iter().chain(y.iter()).position(|v| !v.is_finite()) {
        return Err(Error::numerical(
            context,
            format!("non-finite value in the least-squares data (entry {i})"),
        ));
    }
    let scale = column_norms(x);
    if let Some(j) = scale.iter().position(|&s| s == 0.0) {
        return Err(Error::RankDeficient {
            context: context.into(),
            rows: k,
            cols: p,
            rank: p - 1,
            missing: format!("{} (the column is all zeros)", columns[j]),
        });
    }
    Ok(scale)
}

/// Refuses a design whose scaled singular values `s` fall below [`RANK_TOLERANCE`] of the
/// largest, naming (up to three of) the directions it misses.
fn refuse_weak_directions(
    k: usize,
    v: MatRef<'_, f64>,
    s: &[f64],
    scale: &[f64],
    context: &str,
    columns: &[String],
) -> Result<()> {
    let p = s.len();
    let smax = s.iter().cloned().fold(0.0, f64::max);
    let weak: Vec<usize> = (0..p).filter(|&i| s[i] <= RANK_TOLERANCE * smax).collect();
    if !weak.is_empty() {
        let mut missing = weak
            .iter()
            .take(3)
            .map(|&i| {
                describe_direction(
                    &(0..p).map(|j| v[(j, i)] / scale[j]).collect::<Vec<_>>(),
                    columns,
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        if weak.len() > 3 {
            missing.push_str(&format!("; and {} more directions", weak.len() - 3));
        }
        return Err(Error::RankDeficient {
            context: context.into(),
            rows: k,
            cols: p,
            rank: p - weak.len(),
            missing,
        });
    }
    Ok(())
}

/// The coefficients, their variances and standard errors and the residuals of the fit from
/// the SVD `u s v^T` of the column-scaled X.
struct Solution {
    coef: DMatrix<f64>,
    /// The diagonal of (X^T X)^-1 for the scaled X.
    cov_scaled: Vec<f64>,
    cov_diag: Vec<f64>,
    residual_rms: DVector<f64>,
    stderr: DMatrix<f64>,
}

/// Solves for the coefficients from the SVD; refuses coefficients or standard errors that
/// overflow.
fn solve(
    x: &DMatrix<f64>,
    y: &DMatrix<f64>,
    u: MatRef<'_, f64>,
    v: MatRef<'_, f64>,
    s: &[f64],
    scale: &[f64],
    context: &str,
) -> Result<Solution> {
    let (k, p) = x.shape();
    let m = y.ncols();
    // Y's columns scaled to a largest magnitude of 1 (a torque of 1e300 N m squares to inf)
    let yscale: Vec<f64> = (0..m)
        .map(|c| {
            let a = y.column(c).amax();
            if a > 0.0 {
                a
            } else {
                1.0
            }
        })
        .collect();
    // A^T (both scaled) = V S^-1 U^T Y
    let mut uty = vec![0.0; p * m];
    for i in 0..p {
        for c in 0..m {
            let mut acc = 0.0;
            for r in 0..k {
                acc += u[(r, i)] * (y[(r, c)] / yscale[c]);
            }
            uty[i * m + c] = acc / s[i];
        }
    }
    // coefficients for the scaled Y, unscaled X
    let mut coef = DMatrix::zeros(m, p);
    // the diagonal of (X^T X)^-1 for the scaled X; the unscaled one divides it by scale^2,
    // which can leave f64's range where the standard errors do not
    let mut cov_scaled = vec![0.0; p];
    for j in 0..p {
        for i in 0..p {
            let vji = v[(j, i)];
            for c in 0..m {
                coef[(c, j)] += vji * uty[i * m + c];
            }
            cov_scaled[j] += vji * vji / (s[i] * s[i]);
        }
        for c in 0..m {
            coef[(c, j)] /= scale[j];
        }
    }
    let cov_diag: Vec<f64> = (0..p)
        .map(|j| cov_scaled[j] / scale[j] / scale[j])
        .collect();
    let ys = DMatrix::from_fn(k, m, |r, c| y[(r, c)] / yscale[c]);
    let residual = ys - x * coef.transpose();
    let dof = (k - p) as f64;
    let mut residual_rms = DVector::zeros(m);
    let mut stderr = DMatrix::zeros(m, p);
    for c in 0..m {
        let ss = residual.column(c).norm_squared();
        residual_rms[c] = yscale[c] * (ss / k as f64).sqrt();
        let sigma = if k > p {
            yscale[c] * (ss / dof).sqrt()
        } else {
            f64::NAN
        };
        for j in 0..p {
            stderr[(c, j)] = sigma * cov_scaled[j].sqrt() / scale[j];
            coef[(c, j)] *= yscale[c];
        }
    }
    let overflow = coef.iter().any(|v| !v.is_finite())
        || residual_rms.iter().any(|v| !v.is_finite())
        || (k > p && stderr.iter().any(|v| !v.is_finite()));
    if overflow {
        return Err(Error::numerical(
            context,
            format!(
                "the fit's coefficients or standard errors overflow (outputs up to {} against regressors as small as {}): rescale the data",
                crate::error::shown(yscale.iter().cloned().fold(0.0, f64::max)),
                crate::error::shown(x.iter().fold(f64::INFINITY, |a, v| if *v != 0.0 { a.min(v.abs()) } else { a }))
            ),
        ));
    }
    Ok(Solution {
        coef,
        cov_scaled,
        cov_diag,
        residual_rms,
        stderr,
    })
}

/// The direction of the coefficients the data determine least well (the right singular vector
/// of the smallest singular value), its largest entry positive.
fn weakest_direction(v: MatRef<'_, f64>, s: &[f64]) -> Vec<f64> {
    let p = s.len();
    let least = (0..p).min_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(0);
    let mut weakest: Vec<f64> = (0..p).map(|j| v[(j, least)]).collect();
    let largest = weakest
        .iter()
        .copied()
        .fold(0.0, |a: f64, w| if w.abs() > a.abs() { w } else { a });
    if largest < 0.0 {
        weakest.iter_mut().for_each(|w| *w = -*w);
    }
    weakest
}

/// The singular values of `x` (K x p, K >= p) with every column scaled to unit norm, largest
/// first: all 1 for an orthogonal design; their extremes' ratio is [`LeastSquares::cond`], and
/// `1 / s_min` is how many times the least well determined combination of the coefficients
/// is less precise than with an orthogonal design of the same column norms. None when `x` has
/// fewer rows than columns, a column of zeros or a value that is not finite.
pub fn scaled_singular_values(x: &DMatrix<f64>) -> Option<Vec<f64>> {
    let (k, p) = x.shape();
    if k < p || p == 0 || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let norms = column_norms(x);
    if norms.contains(&0.0) {
        return None;
    }
    let xs = Mat::<f64>::from_fn(k, p, |i, j| x[(i, j)] / norms[j]);
    let mut s: Vec<f64> = xs.singular_values().ok()?;
    s.sort_by(|a, b| b.total_cmp(a));
    Some(s)
}

/// The 2-norm of every column of `x` (0 for a column of zeros), each computed on the column
/// divided by its largest magnitude: 1e-200 would square to 0 and 1e200 to inf.
pub(crate) fn column_norms(x: &DMatrix<f64>) -> Vec<f64> {
    (0..x.ncols())
        .map(|j| {
            let a = x.column(j).amax();
            if a > 0.0 {
                a * (x.column(j) / a).norm()
            } else {
                0.0
            }
        })
        .collect()
}

/// `0.71 dq1 - 0.71 dq2`: a direction in terms of named columns (the 6 largest entries, largest
/// first; entries below 5 % of the largest left out).
fn describe_direction(d: &[f64], columns: &[String]) -> String {
    let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    let max = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut terms: Vec<(usize, f64)> = d
        .iter()
        .map(|v| v / norm)
        .enumerate()
        .filter(|(_, v)| v.abs() >= 0.05 * max / norm)
        .collect();
    // largest first; equal magnitudes (to 1e-6) in column order
    terms.sort_by_key(|&(j, v)| (-(v.abs() * 1e6).round() as i64, j));
    let more = terms.len().saturating_sub(6);
    terms.truncate(6);
    let sign = if terms.first().is_some_and(|t| t.1 < 0.0) {
        -1.0
    } else {
        1.0
    };
    let mut out = String::new();
    for (i, (j, v)) in terms.iter().enumerate() {
        let v = v * sign;
        if i == 0 {
            out.push_str(&format!("{v:.3} {}", columns[*j]));
        } else {
            out.push_str(&format!(
                " {} {:.3} {}",
                if v < 0.0 { '-' } else { '+' },
                v.abs(),
                columns[*j]
            ));
        }
    }
    if more > 0 {
        out.push_str(&format!(" + ... ({more} smaller terms)"));
    }
    out
}

/// The standard error of a variance summed from known terms: rounding below 0 is 0, and a
/// sum that overflowed (inf, or NaN from inf - inf) is inf, for the caller to refuse.
pub(crate) fn root(var: f64) -> f64 {
    if var.is_finite() {
        var.max(0.0).sqrt()
    } else {
        f64::INFINITY
    }
}

/// `stderr` (row-major `k x n`) returned, or refused naming the first joint and sample whose
/// standard error overflowed (inf: [`root`]) for `operation`.
pub(crate) fn refuse_overflow(stderr: Vec<f64>, n: usize, operation: &str) -> Result<Vec<f64>> {
    match stderr.iter().position(|v| v.is_infinite()) {
        Some(i) => Err(Error::numerical(
            operation,
            format!(
                "the standard error of joint {} at sample {} overflows: the state is too large to compute with",
                i % n + 1,
                i / n
            ),
        )),
        None => Ok(stderr),
    }
}
