//! The estimators of a payload fit ([`super::payload`]), each on the weighted problem the
//! joint factors reduce, `|R11 theta - z|^2 + rho^2` over `theta` = the payload's ten
//! parameters (Pinocchio's order) and the joint terms:
//! - least squares;
//! - a point mass: the inertia about the centre of mass taken as 0, so that the inertia about
//!   the joint frame follows from the mass and first moment (`I_o = (|h|^2 / m) 1 - h h^T / m`),
//!   which are fitted with the joint terms by Gauss-Newton (for logs that determine a small
//!   payload's inertia loosely, or not at all: a robot moved slowly, or held still at poses);
//! - a rigid body: least squares over payloads whose pseudo-inertia is positive semi-definite.
//!
//! Each gives `theta` and its covariance per unit of residual variance, `P (P^T N P)^-1 P^T`
//! with `N = R11^T R11` and `P` the derivative of `theta` by the estimator's own unknowns (the
//! identity for least squares), from which the fit's standard errors and the reference
//! model's share of them follow alike.

use nalgebra::{DMatrix, DVector};

use super::parameters::{FrictionTerms, ParameterLayout};
use super::streaming::JointFactors;
use crate::algorithms::regressor::{PARAMETER_NAMES, PARAMS_PER_BODY};
use crate::error::{Error, Result};
use crate::regression::{least_squares, LeastSquares};

/// Gauss-Newton steps at most for a point mass (a handful suffice: the inertia's share of the
/// torques is small beside the mass's).
pub const POINT_MASS_STEPS: usize = 50;

/// An estimate of the unknowns.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// The payload's ten parameters and the joint terms.
    pub theta: Vec<f64>,
    /// Their covariance per unit of residual variance: `P (P^T N P)^-1 P^T`.
    pub unit_covariance: DMatrix<f64>,
    /// The residual variance per unit weight: the weighted residual sum of squares over the
    /// rows less the estimator's unknowns.
    pub variance: f64,
    /// cond of the estimator's weighted, column-scaled regressor.
    pub cond: f64,
    /// For a rigid body, the weighted residual sum of squares over least squares' (None
    /// otherwise).
    pub residual_growth: Option<f64>,
}

/// `(X^T X)^-1` of a least-squares fit, from its correlation and `cov_diag`.
fn unscaled_inverse(ls: &LeastSquares) -> DMatrix<f64> {
    let p = ls.cov_diag.len();
    DMatrix::from_fn(p, p, |a, b| {
        ls.correlation[(a, b)] * (ls.cov_diag[a] * ls.cov_diag[b]).sqrt()
    })
}

/// The rows of the weighted problem, and `rows - unknowns` (at least 1).
fn freedom(factors: &JointFactors, unknowns: usize) -> f64 {
    (factors.samples * factors.factors.len())
        .saturating_sub(unknowns)
        .max(1) as f64
}

/// Least squares with the rows of joint `j` weighted by `1 / sigma[j]`; `names` label the
/// unknowns for a rank-deficiency error.
pub fn least_squares_estimate(
    factors: &JointFactors,
    sigma: &[f64],
    names: &[String],
) -> Result<Estimate> {
    let ls = factors.solve(sigma, names)?;
    let (_, _, rho) = factors.reduced(sigma)?;
    Ok(Estimate {
        theta: ls.coef.iter().copied().collect(),
        unit_covariance: unscaled_inverse(&ls),
        variance: rho * rho / freedom(factors, names.len()),
        cond: ls.cond,
        residual_growth: None,
    })
}

/// `theta` of a point mass `x = [m, h, terms]` (Pinocchio's order for the inertia about the
/// joint frame), and its derivative `P` by `x` (`(10 + f) x (4 + f)`).
fn point_mass_theta(x: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
    let (m, h) = (x[0], [x[1], x[2], x[3]]);
    let f = x.len() - 4;
    let n = PARAMS_PER_BODY + f;
    let mut theta = DVector::zeros(n);
    let mut p = DMatrix::zeros(n, 4 + f);
    for i in 0..4 {
        theta[i] = x[i];
        p[(i, i)] = 1.0;
    }
    for c in 0..f {
        theta[PARAMS_PER_BODY + c] = x[4 + c];
        p[(PARAMS_PER_BODY + c, 4 + c)] = 1.0;
    }
    // I_o = (|h|^2 1 - h h^T) / m, entries xx, xy, yy, xz, yz, zz: each a quadratic q(h) / m
    let (a, b, c) = (h[0], h[1], h[2]);
    let quadratic = [
        (b * b + c * c, [0.0, 2.0 * b, 2.0 * c]),
        (-a * b, [-b, -a, 0.0]),
        (a * a + c * c, [2.0 * a, 0.0, 2.0 * c]),
        (-a * c, [-c, 0.0, -a]),
        (-b * c, [0.0, -c, -b]),
        (a * a + b * b, [2.0 * a, 2.0 * b, 0.0]),
    ];
    for (e, (q, dq)) in quadratic.iter().enumerate() {
        theta[4 + e] = q / m;
        p[(4 + e, 0)] = -q / (m * m);
        for k in 0..3 {
            p[(4 + e, 1 + k)] = dq[k] / m;
        }
    }
    (theta, p)
}

/// The payload as a point mass (see the module documentation), with the rows of joint `j`
/// weighted by `1 / sigma[j]`; `names` label the ten parameters and the joint terms. Where the
/// mass comes out not above 0 (no payload), the first moment's fit with no inertia is kept.
pub fn point_mass_estimate(
    factors: &JointFactors,
    sigma: &[f64],
    names: &[String],
) -> Result<Estimate> {
    let (r11, z, rho) = factors.reduced(sigma)?;
    let n = r11.ncols();
    let f = n - PARAMS_PER_BODY;
    let kept: Vec<usize> = (0..4).chain(PARAMS_PER_BODY..n).collect();
    let own_names: Vec<String> = kept.iter().map(|&c| names[c].clone()).collect();
    let z = DVector::from_column_slice(z.as_slice());
    // the start: no inertia about the joint frame
    let start = DMatrix::from_fn(n, kept.len(), |r, c| r11[(r, kept[c])]);
    let ls = least_squares(
        &start,
        &DMatrix::from_column_slice(n, 1, z.as_slice()),
        "payload identification",
        &own_names,
    )?;
    let mut x: Vec<f64> = ls.coef.iter().copied().collect();
    for _ in 0..POINT_MASS_STEPS {
        if x[0].is_nan() || x[0] <= 0.0 {
            break;
        }
        crate::interrupt::check("payload identification")?;
        let (theta, p) = point_mass_theta(&x);
        let jac = &r11 * &p;
        let r = &z - &r11 * &theta;
        let step = least_squares(
            &jac,
            &DMatrix::from_column_slice(n, 1, r.as_slice()),
            "payload identification",
            &own_names,
        )?;
        let dx: Vec<f64> = step.coef.iter().copied().collect();
        let size = dx
            .iter()
            .zip(&x)
            .map(|(d, v)| d.abs() / (v.abs() + 1e-12))
            .fold(0.0f64, f64::max);
        x.iter_mut().zip(&dx).for_each(|(v, d)| *v += d);
        if size < 1e-13 {
            break;
        }
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::numerical(
            "payload identification",
            "the point mass's fit did not converge to finite values",
        ));
    }
    let (theta, p) = match x[0] > 0.0 {
        true => point_mass_theta(&x),
        // no payload: the fit with no inertia, its derivative the selection
        false => {
            let mut theta = DVector::zeros(n);
            let mut p = DMatrix::zeros(n, kept.len());
            for (c, &col) in kept.iter().enumerate() {
                theta[col] = x[c];
                p[(col, c)] = 1.0;
            }
            (theta, p)
        }
    };
    let residual = (&r11 * &theta - &z).norm_squared() + rho * rho;
    // the derivative's own fit at the solution gives (P^T N P)^-1
    let jac = &r11 * &p;
    let at = least_squares(
        &jac,
        &DMatrix::zeros(n, 1),
        "payload identification",
        &own_names,
    )?;
    debug_assert_eq!(theta.len(), PARAMS_PER_BODY + f);
    Ok(Estimate {
        theta: theta.iter().copied().collect(),
        unit_covariance: &p * unscaled_inverse(&at) * p.transpose(),
        variance: residual / freedom(factors, kept.len()),
        cond: at.cond,
        residual_growth: None,
    })
}

/// The consistent estimate (the payload's ten parameters a rigid body's, the joint terms
/// free) with the rows of joint `j` weighted by `1 / sigma[j]`; its covariance is least
/// squares' (`ls`, the unconstrained estimate), which holds where no constraint is active.
/// The joint terms are minimised over for every payload (a QR of `[R11 | z]` with their
/// columns first), so that the constrained problem is in the ten parameters alone
/// ([`super::consistent_least_squares`]).
pub fn rigid_body_estimate(
    factors: &JointFactors,
    sigma: &[f64],
    ls: &Estimate,
) -> Result<Estimate> {
    let (r11, z, rho) = factors.reduced(sigma)?;
    let n = r11.ncols();
    let (b, f) = (PARAMS_PER_BODY, n - PARAMS_PER_BODY);
    let mut a = DMatrix::zeros(n + 1, n + 1);
    for i in 0..n {
        for c in 0..f {
            a[(i, c)] = r11[(i, b + c)];
        }
        for c in 0..b {
            a[(i, f + c)] = r11[(i, c)];
        }
        a[(i, n)] = z[(i, 0)];
    }
    a[(n, n)] = rho;
    let t = super::streaming::triangular(&a);
    let r = t.view((f, f), (b, b)).into_owned();
    let zp = DVector::from_iterator(b, (0..b).map(|i| t[(f + i, n)]));
    let rest = t[(n, n)];
    let layout = ParameterLayout {
        nv: 0,
        nbodies: 1,
        friction: FrictionTerms::NONE,
        names: PARAMETER_NAMES
            .iter()
            .map(|n| format!("payload.{n}"))
            .collect(),
    };
    let solution = super::consistent_least_squares(
        &layout,
        &r,
        &zp,
        rest * rest,
        &[0.0; PARAMS_PER_BODY],
        // the data determine all ten (a rank deficiency was refused): the prior only keeps
        // the solver's systems regular
        &super::ConsistentOptions {
            prior_weight: 1e-12,
            ..super::ConsistentOptions::default()
        },
    )?;
    let pi = &solution.theta;
    // the joint terms that go with it: others d = others_z - coupling pi
    let mut theta = pi.clone();
    if f > 0 {
        let others = t.view((0, 0), (f, f)).into_owned();
        let coupling = t.view((0, f), (f, b)).into_owned();
        let rhs = DVector::from_iterator(f, (0..f).map(|i| t[(i, n)]))
            - coupling * DVector::from_column_slice(pi);
        let d = others
            .solve_upper_triangular(&rhs)
            .filter(|d| d.iter().all(|v| v.is_finite()))
            .ok_or_else(|| {
                Error::numerical(
                    "payload identification",
                    "the data do not determine the joint terms beside the payload",
                )
            })?;
        theta.extend(d.iter());
    }
    let growth = match (solution.unconstrained_cost, solution.cost) {
        (u, c) if u > 0.0 => c / u,
        (_, 0.0) => 1.0,
        _ => f64::INFINITY,
    };
    Ok(Estimate {
        theta,
        residual_growth: Some(growth),
        ..ls.clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_point_masss_derivative_is_its_finite_differences() {
        let x = [1.3, 0.02, -0.05, 0.11, 0.4, -0.7];
        let (theta, p) = point_mass_theta(&x);
        // a point mass: its inertia about the centre is 0, so I_o = m (|c|^2 1 - c c^T)
        let c = [x[1] / x[0], x[2] / x[0], x[3] / x[0]];
        let cc: f64 = c.iter().map(|v| v * v).sum();
        assert!((theta[4] - x[0] * (cc - c[0] * c[0])).abs() < 1e-15);
        assert!((theta[7] + x[0] * c[0] * c[2]).abs() < 1e-15);
        assert_eq!((theta[10], theta[11]), (0.4, -0.7));
        for k in 0..x.len() {
            let h = 1e-6 * (1.0 + x[k].abs());
            let (mut up, mut down) = (x, x);
            up[k] += h;
            down[k] -= h;
            let fd = (point_mass_theta(&up).0 - point_mass_theta(&down).0) / (2.0 * h);
            for r in 0..theta.len() {
                assert!(
                    (fd[r] - p[(r, k)]).abs() < 1e-7 * (1.0 + fd[r].abs()),
                    "d theta[{r}] / d x[{k}]: {} vs {}",
                    fd[r],
                    p[(r, k)]
                );
            }
        }
    }
}
