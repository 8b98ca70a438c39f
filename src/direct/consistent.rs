//! Least squares over physically consistent parameters: `min |A theta - y|^2` subject to every
//! body's pseudo-inertia being positive definite and the friction and armature coefficients
//! being non-negative.
//!
//! Solver: the problem is convex (a quadratic over a product of positive semi-definite cones
//! and half-lines), and is solved by ADMM (the alternating direction method of multipliers, as
//! OSQP and SCS do): a least-squares step with a proximal term, then the exact projection onto
//! the constraints (each body's pseudo-inertia with its negative eigenvalues set to zero, each
//! coefficient clipped at zero) in the metric in which that projection is Euclidean, with the
//! penalty balanced between primal and dual residuals. Chosen over Clarabel's SDP cones
//! because Clarabel's SDP support links BLAS and LAPACK, which every wheel would have to carry,
//! and over a log-Cholesky parametrisation with Gauss-Newton because that one stalls where the
//! solution lies on the boundary (a body whose inertia is a flat disc, the usual case for a
//! lumped rotor): the exponential that keeps the eigenvalues positive flattens the cost, and on
//! the lumped A465 5000 Levenberg-Marquardt iterations stopped at 1.1 N m RMS where ADMM reaches
//! the optimum. The returned parameters are the projected ones: consistent by construction.
//!
//! The data determine only the base combinations of the parameters; the rest is decided by a
//! weak prior (`prior_weight`, default 1e-6 relative to each column's norm) pulling towards the
//! robot's own parameters, as CAD or a URDF give them.

use nalgebra::{DMatrix, DVector};

use nalgebra::Matrix4;

use super::consistency::{
    check_physical_consistency, parameters_of_pseudo_inertia, pseudo_inertia, ConsistencyReport,
};
use super::parameters::ParameterLayout;
use crate::error::{Error, Result};

/// Options of a consistent fit.
#[derive(Clone, Debug, PartialEq)]
pub struct ConsistentOptions {
    /// Weight of the prior (the robot's own parameters) against the data, relative to each
    /// parameter's column norm: small enough not to move what the data determine, large
    /// enough to fix what they do not (default 1e-6; from 1e-12 to 1).
    pub prior_weight: f64,
    /// ADMM iterations at most (default 20000).
    pub max_iterations: usize,
    /// Stop when the ADMM primal and dual residuals are below the square root of this fraction
    /// of the solution's size (default 1e-12).
    pub tolerance: f64,
}

impl Default for ConsistentOptions {
    fn default() -> Self {
        Self {
            prior_weight: 1e-6,
            max_iterations: 20000,
            tolerance: 1e-12,
        }
    }
}

/// A consistent least-squares solution.
#[derive(Clone, Debug, PartialEq)]
pub struct ConsistentSolution {
    /// The full parameters (`layout` order), physically consistent.
    pub theta: Vec<f64>,
    /// `|A theta - y|^2 + constant` at the solution (the weighted residual sum of squares).
    pub cost: f64,
    /// The same without the constraints (the ordinary least-squares minimum).
    pub unconstrained_cost: f64,
    /// The unconstrained solution nearest to the prior (in the same weighting).
    pub unconstrained_theta: Vec<f64>,
    pub iterations: usize,
    /// False when the iteration limit stopped the fit first.
    pub converged: bool,
    /// The constraints the solution presses against: bodies whose pseudo-inertia is at the
    /// boundary (smallest eigenvalue below 1e-6 of the largest) and coefficients driven to
    /// about zero from a negative unconstrained value.
    pub active: Vec<String>,
    pub report: ConsistencyReport,
}

/// The linear map from a body's 10 parameters to the 16 entries of its pseudo-inertia.
fn pseudo_inertia_map() -> DMatrix<f64> {
    let mut l = DMatrix::zeros(16, 10);
    for k in 0..10 {
        let mut e = [0.0; 10];
        e[k] = 1.0;
        let j = pseudo_inertia(&e);
        for (r, v) in j.iter().enumerate() {
            l[(r, k)] = *v;
        }
    }
    l
}

/// The projection of `theta` onto the constraints of `layout`: bodies by their pseudo-inertia's
/// eigenvalues clipped at zero, coefficients (not offsets) at zero.
fn project(layout: &ParameterLayout, theta: &mut DVector<f64>) {
    for b in 0..layout.nbodies {
        let p: [f64; 10] = theta.as_slice()[10 * b..10 * b + 10]
            .try_into()
            .expect("10 per body");
        let eig = pseudo_inertia(&p).symmetric_eigen();
        if eig.eigenvalues.iter().all(|v| *v >= 0.0) {
            continue;
        }
        let clipped = eig.eigenvalues.map(|v| v.max(0.0));
        let j = eig.eigenvectors * Matrix4::from_diagonal(&clipped) * eig.eigenvectors.transpose();
        let q = parameters_of_pseudo_inertia(&j);
        theta.as_mut_slice()[10 * b..10 * b + 10].copy_from_slice(&q);
    }
    for i in 10 * layout.nbodies..layout.len() {
        if !layout.names[i].ends_with(".offset") {
            theta[i] = theta[i].max(0.0);
        }
    }
}

/// Solves `min |A theta - y|^2 (+ constant)` over consistent `theta` of `layout`, with the weak
/// prior `prior` (full parameters, `layout` order): see the module documentation.
///
/// - `a`: `m x p` (`p = layout.len()`), rows already weighted; `y`: `m`.
/// - `constant`: a residual part no parameter can change (added to both costs).
///
/// Errors: shapes that disagree, non-finite entries, an interrupt.
pub fn consistent_least_squares(
    layout: &ParameterLayout,
    a: &DMatrix<f64>,
    y: &DVector<f64>,
    constant: f64,
    prior: &[f64],
    options: &ConsistentOptions,
) -> Result<ConsistentSolution> {
    let p = layout.len();
    if a.ncols() != p || a.nrows() != y.len() || prior.len() != p || a.nrows() == 0 {
        return Err(Error::Shape {
            argument: "consistent least squares".into(),
            expected: format!(
                "A with {p} columns (the layout's), y as long as A has rows, a prior of {p}"
            ),
            got: format!(
                "A {} x {}, y {}, prior {}",
                a.nrows(),
                a.ncols(),
                y.len(),
                prior.len()
            ),
        });
    }
    crate::limits::check_range("prior_weight", options.prior_weight, 1e-12, 1.0)?;
    crate::limits::check_count("max_iterations", options.max_iterations, 1, 1_000_000)?;
    crate::limits::check_range("tolerance", options.tolerance, 1e-16, 1e-2)?;
    if a.iter()
        .chain(y.iter())
        .chain(prior)
        .any(|v| !v.is_finite())
        || !constant.is_finite()
    {
        return Err(Error::Numerical {
            operation: "consistent least squares".into(),
            message: "the system or the prior holds a non-finite number".into(),
        });
    }
    // the prior's weight per parameter: its column norm (the mean of the others where the
    // column is zero up to rounding: 1e-8 of the largest)
    let norms: Vec<f64> = (0..p).map(|c| a.column(c).norm()).collect();
    let largest = norms.iter().fold(0.0f64, |m, v| m.max(*v));
    let norms: Vec<f64> = norms
        .into_iter()
        .map(|v| if v > 1e-8 * largest { v } else { 0.0 })
        .collect();
    let nonzero: Vec<f64> = norms.iter().copied().filter(|v| *v > 0.0).collect();
    let mean = if nonzero.is_empty() {
        1.0
    } else {
        nonzero.iter().sum::<f64>() / nonzero.len() as f64
    };
    let w = options.prior_weight.sqrt();
    let s: Vec<f64> = norms
        .iter()
        .map(|&v| w * if v > 0.0 { v } else { mean })
        .collect();
    let theta0 = DVector::from_column_slice(prior);

    // the unconstrained solution nearest to the prior: with every column scaled to unit norm
    // (theta_i = phi_i / n_i) the prior rows are w (phi - phi0), and the stacked problem
    // [A N^-1; w I] phi = [y; w phi0] is solved by an SVD (normal equations would square a
    // condition number that gravity and inertia columns already make large)
    let scale: Vec<f64> = s.iter().map(|v| w / v).collect(); // theta_i = scale_i phi_i
    let mut stacked = DMatrix::zeros(a.nrows() + p, p);
    let mut rhs = DVector::zeros(a.nrows() + p);
    for c in 0..p {
        stacked
            .view_mut((0, c), (a.nrows(), 1))
            .copy_from(&(a.column(c) * scale[c]));
        stacked[(a.nrows() + c, c)] = w;
        rhs[a.nrows() + c] = w * theta0[c] / scale[c];
    }
    rhs.rows_mut(0, a.nrows()).copy_from(y);
    let phi = solve_svd(stacked, &rhs, 0.0)?;
    let theta_u = DVector::from_iterator(p, (0..p).map(|c| phi[c] * scale[c]));
    let scaled = DMatrix::from_fn(a.nrows(), p, |r, c| a[(r, c)] * scale[c]);
    let least = solve_svd(
        scaled.clone(),
        &DVector::from_column_slice(y.as_slice()),
        1e-12,
    )?;
    let least = DVector::from_iterator(p, (0..p).map(|c| least[c] * scale[c]));
    let unconstrained_cost = (a * &least - y).norm_squared() + constant;

    // ADMM on min |A theta - y|^2 + |S (theta - theta0)|^2 + indicator(z in C), theta = z,
    // in the metric W = blockdiag(c_b L^T L, c_t): projecting onto C in it is the eigenvalue
    // clip of each pseudo-inertia (L maps a body's parameters to its pseudo-inertia entries)
    let l = pseudo_inertia_map();
    let nb = layout.nbodies;
    let hess_diag: Vec<f64> = (0..p)
        .map(|c| a.column(c).norm_squared() + s[c] * s[c])
        .collect();
    let trace_g: f64 = l.norm_squared();
    let mut wh = DMatrix::zeros(16 * nb + (p - 10 * nb), p); // W = wh^T wh
    for b in 0..nb {
        let c = (hess_diag[10 * b..10 * b + 10].iter().sum::<f64>() / trace_g).max(1e-300);
        wh.view_mut((16 * b, 10 * b), (16, 10))
            .copy_from(&(&l * c.sqrt()));
    }
    for (k, i) in (10 * nb..p).enumerate() {
        wh[(16 * nb + k, i)] = hess_diag[i].max(1e-300).sqrt();
    }
    let m = a.nrows();
    let rows = m + p + wh.nrows();
    let mut rhs = DVector::zeros(rows);
    rhs.rows_mut(0, m).copy_from(y);
    for i in 0..p {
        rhs[m + i] = s[i] * theta0[i];
    }
    // the least-squares step's factor for a penalty rho: [A; S; sqrt(rho) wh] = Q R
    let factor = |rho: f64| {
        let mut stacked = DMatrix::zeros(rows, p);
        stacked.view_mut((0, 0), (m, p)).copy_from(a);
        for i in 0..p {
            stacked[(m + i, i)] = s[i];
        }
        stacked
            .view_mut((m + p, 0), (wh.nrows(), p))
            .copy_from(&(&wh * rho.sqrt()));
        let qr = stacked.qr();
        (qr.q(), qr.r())
    };
    let mut rho = 1.0;
    let (mut q, mut r) = factor(rho);
    let mut z = theta_u.clone();
    project(layout, &mut z);
    let mut u = DVector::zeros(p); // scaled dual, in parameter units
    let mut theta;
    let (mut iterations, mut converged) = (0, false);
    let eps = options.tolerance.sqrt();
    while iterations < options.max_iterations {
        if iterations % 64 == 0 {
            crate::interrupt::check("consistent least squares")?;
        }
        iterations += 1;
        // theta = argmin |A t - y|^2 + |S (t - t0)|^2 + rho |wh (t - z + u)|^2
        rhs.rows_mut(m + p, wh.nrows())
            .copy_from(&(&wh * (&z - &u) * rho.sqrt()));
        let qtb = q.tr_mul(&rhs);
        theta = r
            .solve_upper_triangular(&qtb)
            .ok_or_else(|| Error::Numerical {
                operation: "consistent least squares".into(),
                message: "the ADMM step's triangular factor is singular".into(),
            })?;
        let z_old = z.clone();
        z = &theta + &u;
        project(layout, &mut z);
        u += &theta - &z;
        let primal = (&wh * (&theta - &z)).norm();
        let dual = rho * (&wh * (&z - &z_old)).norm();
        let size = (&wh * &theta).norm().max((&wh * &z).norm());
        if primal <= eps * size && dual <= eps * rho * (&wh * &u).norm().max(size) {
            converged = true;
            break;
        }
        // balance the residuals (Boyd et al. 2011, section 3.4.1)
        if primal > 10.0 * dual || dual > 10.0 * primal {
            let f = if primal > dual { 2.0 } else { 0.5 };
            rho *= f;
            u /= f;
            (q, r) = factor(rho);
        }
    }
    let theta = z;
    let data_cost = (a * &theta - y).norm_squared();
    let theta_v: Vec<f64> = theta.iter().copied().collect();
    let report = check_physical_consistency(layout, &theta_v)?;
    let mut active: Vec<String> = report
        .bodies
        .iter()
        .filter(|b| b.relative_min < 1e-6)
        .map(|b| {
            format!(
                "{}: pseudo-inertia at the boundary (smallest eigenvalue {:.1e} of the largest)",
                b.link, b.relative_min
            )
        })
        .collect();
    for i in 10 * layout.nbodies..p {
        if !layout.names[i].ends_with(".offset")
            && theta_u[i] < 0.0
            && theta_v[i] < 1e-3 * theta_u[i].abs()
        {
            active.push(format!(
                "{} = {:.2e} (unconstrained {:.4e})",
                layout.names[i], theta_v[i], theta_u[i]
            ));
        }
    }
    Ok(ConsistentSolution {
        theta: theta_v,
        cost: data_cost + constant,
        unconstrained_cost,
        unconstrained_theta: theta_u.iter().copied().collect(),
        iterations,
        converged,
        active,
        report,
    })
}

/// A consistent identification: the full parameters, the same as a base-parameter model (to
/// predict, linearise and save like any), the unconstrained fit beside it, and what the
/// constraints cost.
#[derive(Clone, Debug, PartialEq)]
pub struct ConsistentFit {
    pub layout: ParameterLayout,
    pub solution: ConsistentSolution,
    /// The consistent parameters as a base-parameter model. Its standard errors are the
    /// unconstrained fit's: they hold where no constraint is active (see
    /// `solution.active`).
    pub model: super::BaseModel,
    /// The unconstrained fit of the same data.
    pub unconstrained: super::BaseModel,
}

impl ConsistentFit {
    /// How much the weighted residual sum of squares grew by the constraints (1 = not at all).
    pub fn residual_growth(&self) -> f64 {
        let s = &self.solution;
        if s.unconstrained_cost > 0.0 {
            s.cost / s.unconstrained_cost
        } else if s.cost == 0.0 {
            1.0
        } else {
            f64::INFINITY
        }
    }

    /// `robot` with the identified parameters: every body's inertia, each joint's armature and
    /// (where identified) viscous and Coulomb friction as `<dynamics damping friction>`; usable
    /// by every algorithm and by the simulation. Torque offsets have no place in a robot model
    /// and stay in `self.model`. Fails when `robot` is not the robot of the layout.
    pub fn robot(&self, robot: &crate::model::Model) -> Result<crate::model::Model> {
        let layout = &self.layout;
        if robot.nbodies() != layout.nbodies || robot.nv != layout.nv {
            return Err(Error::InvalidArgument {
                argument: "robot".into(),
                message: format!(
                    "the parameters are for {} bodies and {} joints; '{}' has {} and {}",
                    layout.nbodies,
                    layout.nv,
                    robot.name,
                    robot.nbodies(),
                    robot.nv
                ),
            });
        }
        let mut out = robot.clone();
        let theta = &self.solution.theta;
        for (b, body) in out.bodies.iter_mut().enumerate() {
            let p: [f64; 10] = theta[10 * b..10 * b + 10].try_into().expect("10 per body");
            body.inertia =
                crate::algorithms::regressor::inertia_from_parameters(&p).ok_or_else(|| {
                    Error::Internal {
                        context: "ConsistentFit::robot".into(),
                        message: format!("a consistent body with mass {} <= 0", p[0]),
                    }
                })?;
        }
        out.refresh();
        let terms = layout.friction.names();
        for j in 0..layout.nv {
            for (t, name) in terms.iter().enumerate() {
                let v = theta[10 * layout.nbodies + j * terms.len() + t];
                match *name {
                    "viscous" => out.limits[j].damping = v,
                    "coulomb" => out.limits[j].friction = v,
                    "armature" => out.armature[j] = v,
                    _ => {}
                }
            }
        }
        Ok(out)
    }
}

/// The least-squares solution of `a x = b` by a thin SVD, singular values below `relative`
/// times the largest dropped.
fn solve_svd(a: DMatrix<f64>, b: &DVector<f64>, relative: f64) -> Result<DVector<f64>> {
    let svd = a.svd(true, true);
    let eps = relative * svd.singular_values.max();
    svd.solve(b, eps).map_err(|m| Error::Numerical {
        operation: "consistent least squares".into(),
        message: m.to_string(),
    })
}
