//! Least squares over physically consistent parameters: `min |A theta - y|^2` subject to every
//! body's pseudo-inertia being positive definite and the friction and armature coefficients
//! being non-negative.
//!
//! Solver: the problem is convex (a quadratic over a product of positive semi-definite cones
//! and half-lines), and is solved by a primal log-barrier interior-point method: Newton steps
//! on `t f(theta) - sum log det J_b - sum log c` with a backtracking line search that stays
//! inside, `t` growing tenfold until the duality gap bound (the constraints' dimension over
//! `t`) is below the tolerance. Newton's method is affine invariant, so the very different
//! scales of masses, first moments and inertias do not slow it; every iterate is strictly
//! consistent. Chosen over Clarabel's SDP cones because Clarabel's SDP support links BLAS and
//! LAPACK, which every wheel would have to carry. Two alternatives were tried here and
//! dropped: a log-Cholesky parametrisation with Levenberg-Marquardt stalls where the solution
//! lies on the boundary (a body whose inertia is a flat disc, the usual case for a lumped
//! rotor: the exponential that keeps the eigenvalues positive flattens the cost; on the lumped
//! A465 5000 iterations stopped at 1.1 N m RMS where the optimum is 4e-5), and ADMM with the
//! eigenvalue-clipping projection crawls along directions the data hardly see (20000 iterations
//! still 1e-4 above the optimum on 40 noisy samples).
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
    /// Newton steps at most, over all barrier weights (default 2000).
    pub max_iterations: usize,
    /// Stop when the duality gap bound is below this fraction of the cost (default 1e-10).
    pub tolerance: f64,
}

impl Default for ConsistentOptions {
    fn default() -> Self {
        Self {
            prior_weight: 1e-6,
            max_iterations: 2000,
            tolerance: 1e-10,
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
    /// False when the iteration limit stopped the fit first (the parameters are consistent
    /// all the same, only less close to the optimum).
    pub converged: bool,
    /// The constraints the solution presses against: bodies whose pseudo-inertia is at the
    /// boundary (smallest eigenvalue below 1e-6 of the largest) and coefficients driven to
    /// about zero from a negative unconstrained value.
    pub active: Vec<String>,
    pub report: ConsistencyReport,
}

/// Newton steps per barrier weight at most.
const NEWTON_STEPS: usize = 60;

/// The pseudo-inertia of each unit parameter: `J = sum_k theta_k basis[k]`.
fn pseudo_inertia_basis() -> [Matrix4<f64>; 10] {
    std::array::from_fn(|k| {
        let mut e = [0.0; 10];
        e[k] = 1.0;
        pseudo_inertia(&e)
    })
}

/// `theta` moved strictly inside the constraints: each pseudo-inertia's eigenvalues raised to
/// at least 1e-6 of its largest, each coefficient to at least 1e-6 of its size (or 1e-9).
fn push_inside(layout: &ParameterLayout, squares: &[usize], theta: &mut DVector<f64>) {
    for b in 0..layout.nbodies {
        let p: [f64; 10] = theta.as_slice()[10 * b..10 * b + 10]
            .try_into()
            .expect("10 per body");
        // parameters that are not finite are left to the solver's own checks
        let Some(eig) = crate::decomposition::symmetric_eigen(pseudo_inertia(&p)) else {
            continue;
        };
        let largest = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let lo = (1e-6 * largest).max(1e-12);
        let clipped = eig.eigenvalues.map(|v| v.max(lo));
        let j = eig.eigenvectors * Matrix4::from_diagonal(&clipped) * eig.eigenvectors.transpose();
        theta.as_mut_slice()[10 * b..10 * b + 10]
            .copy_from_slice(&parameters_of_pseudo_inertia(&j));
    }
    for &i in squares {
        theta[i] = theta[i].max(1e-6 * theta[i].abs()).max(1e-9);
    }
}

/// The barrier `-sum_b log det J_b - sum log c`, `None` outside the interior.
fn barrier_value(
    layout: &ParameterLayout,
    squares: &[usize],
    basis: &[Matrix4<f64>; 10],
    theta: &DVector<f64>,
) -> Option<f64> {
    let mut v = 0.0;
    for b in 0..layout.nbodies {
        let j = (0..10).fold(Matrix4::zeros(), |m, k| m + basis[k] * theta[10 * b + k]);
        let ch = nalgebra::Cholesky::new(j)?;
        v -= 2.0 * ch.l().diagonal().iter().map(|x| x.ln()).sum::<f64>();
    }
    for &i in squares {
        if theta[i] <= 0.0 {
            return None;
        }
        v -= theta[i].ln();
    }
    v.is_finite().then_some(v)
}

/// The barrier's gradient and Hessian: for a body, `-tr(J^-1 B_k)` and
/// `tr(J^-1 B_k J^-1 B_l)`; for a coefficient `-1/c` and `1/c^2`. `None` outside the interior.
fn barrier(
    layout: &ParameterLayout,
    squares: &[usize],
    basis: &[Matrix4<f64>; 10],
    theta: &DVector<f64>,
) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let p = theta.len();
    let mut g = DVector::zeros(p);
    let mut h = DMatrix::zeros(p, p);
    for b in 0..layout.nbodies {
        let j = (0..10).fold(Matrix4::zeros(), |m, k| m + basis[k] * theta[10 * b + k]);
        let inv = nalgebra::Cholesky::new(j)?.inverse();
        let m: [Matrix4<f64>; 10] = std::array::from_fn(|k| inv * basis[k]);
        for k in 0..10 {
            g[10 * b + k] = -m[k].trace();
            for l in k..10 {
                let v = (m[k] * m[l]).trace();
                h[(10 * b + k, 10 * b + l)] = v;
                h[(10 * b + l, 10 * b + k)] = v;
            }
        }
    }
    for &i in squares {
        if theta[i] <= 0.0 {
            return None;
        }
        g[i] = -1.0 / theta[i];
        h[(i, i)] = 1.0 / (theta[i] * theta[i]);
    }
    Some((g, h))
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
    check_system(p, a, y, constant, prior, options)?;
    let s = prior_weights(a, options.prior_weight);
    let theta0 = DVector::from_column_slice(prior);
    let (theta_u, least) = unconstrained(a, y, &theta0, &s, options.prior_weight.sqrt())?;
    let unconstrained_cost = (a * &least - y).norm_squared() + constant;
    let (theta, iterations, converged) =
        barrier_solve(layout, a, y, &theta0, &s, &theta_u, options)?;
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

/// Refuses shapes that disagree, options out of range and non-finite entries.
fn check_system(
    p: usize,
    a: &DMatrix<f64>,
    y: &DVector<f64>,
    constant: f64,
    prior: &[f64],
    options: &ConsistentOptions,
) -> Result<()> {
    if a.ncols() != p || a.nrows() != y.len() || prior.len() != p || a.nrows() == 0 {
        return Err(Error::shape(
            "consistent least squares",
            format!("A with {p} columns (the layout's), y as long as A has rows, a prior of {p}"),
            format!(
                "A {} x {}, y {}, prior {}",
                a.nrows(),
                a.ncols(),
                y.len(),
                prior.len()
            ),
        ));
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
        return Err(Error::numerical(
            "consistent least squares",
            "the system or the prior holds a non-finite number",
        ));
    }
    Ok(())
}

/// The prior's weight per parameter, times `sqrt(prior_weight)`: its column norm in `a` (the
/// mean of the others where the column is zero up to rounding: 1e-8 of the largest).
fn prior_weights(a: &DMatrix<f64>, prior_weight: f64) -> Vec<f64> {
    let p = a.ncols();
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
    let w = prior_weight.sqrt();
    norms
        .iter()
        .map(|&v| w * if v > 0.0 { v } else { mean })
        .collect()
}

/// The unconstrained solution nearest to the prior `theta0` (prior weights `s`, `w` the root
/// of the prior's weight), and the least-squares solution of the data alone.
///
/// With every column scaled to unit norm (theta_i = phi_i / n_i) the prior rows are
/// w (phi - phi0), and the stacked problem [A N^-1; w I] phi = [y; w phi0] is solved by an SVD
/// (normal equations would square a condition number that gravity and inertia columns already
/// make large).
fn unconstrained(
    a: &DMatrix<f64>,
    y: &DVector<f64>,
    theta0: &DVector<f64>,
    s: &[f64],
    w: f64,
) -> Result<(DVector<f64>, DVector<f64>)> {
    let p = a.ncols();
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
    Ok((theta_u, least))
}

/// The primal log-barrier method: minimises t f(theta) - sum_b log det J_b - sum log c over the
/// interior, by damped Newton steps, for t growing tenfold until the duality gap (constraint
/// dimensions) / t is below the tolerance. Returns theta, the Newton steps taken and whether
/// the gap closed.
fn barrier_solve(
    layout: &ParameterLayout,
    a: &DMatrix<f64>,
    y: &DVector<f64>,
    theta0: &DVector<f64>,
    s: &[f64],
    theta_u: &DVector<f64>,
    options: &ConsistentOptions,
) -> Result<(DVector<f64>, usize, bool)> {
    let p = layout.len();
    let h = a.transpose() * a
        + DMatrix::from_diagonal(&DVector::from_iterator(p, s.iter().map(|v| v * v)));
    let rhs =
        a.transpose() * y + DVector::from_iterator(p, (0..p).map(|i| s[i] * s[i] * theta0[i]));
    let objective = |t: &DVector<f64>| {
        (a * t - y).norm_squared()
            + (0..p)
                .map(|i| (s[i] * (t[i] - theta0[i])).powi(2))
                .sum::<f64>()
    };
    let squares: Vec<usize> = (10 * layout.nbodies..p)
        .filter(|&i| !layout.names[i].ends_with(".offset"))
        .collect();
    let dims = (4 * layout.nbodies + squares.len()) as f64;
    let basis = pseudo_inertia_basis();
    // a strictly feasible start: the unconstrained solution pushed inside
    let mut theta = theta_u.clone();
    push_inside(layout, &squares, &mut theta);
    let f0 = objective(&theta);
    // the gap is measured against the cost, or 1e-12 of |y|^2 for data a model fits exactly
    let floor = 1e-12 * (y.norm_squared() + 1e-300);
    let mut t = dims / f0.max(floor).max(1e-300);
    let (mut iterations, mut converged) = (0, false);
    'outer: while iterations < options.max_iterations {
        // Newton's method on a self-concordant function needs a few tens of steps at most
        for _ in 0..NEWTON_STEPS {
            crate::interrupt::check("consistent least squares")?;
            if iterations >= options.max_iterations {
                break 'outer;
            }
            iterations += 1;
            let Some((bg, bh)) = barrier(layout, &squares, &basis, &theta) else {
                return Err(Error::Internal {
                    context: "consistent least squares".into(),
                    message: "an iterate left the interior".into(),
                });
            };
            // backtracking: stay inside, decrease the barrier objective
            let value = |x: &DVector<f64>| -> Option<f64> {
                let b = barrier_value(layout, &squares, &basis, x)?;
                Some(t * objective(x) + b)
            };
            let system = NewtonSystem {
                h: &h,
                rhs: &rhs,
                bg: &bg,
                bh: &bh,
                t,
            };
            match system.step(&theta, &value)? {
                Some(next) => theta = next,
                None => break,
            }
        }
        let f = objective(&theta);
        if dims / t <= options.tolerance * f.max(floor) {
            converged = true;
            break;
        }
        t *= 10.0;
    }
    Ok((theta, iterations, converged))
}

/// The Newton system of the barrier objective at an iterate: the data's Hessian `h` and
/// right-hand side `rhs`, the barrier's gradient `bg` and Hessian `bh`, the data's weight `t`.
struct NewtonSystem<'a> {
    h: &'a DMatrix<f64>,
    rhs: &'a DVector<f64>,
    bg: &'a DVector<f64>,
    bh: &'a DMatrix<f64>,
    t: f64,
}

impl NewtonSystem<'_> {
    /// One damped Newton step of the barrier objective `value` from `theta`: the next iterate,
    /// or None where the step makes no progress (the decrement is rounding, or backtracking
    /// finds no decrease).
    fn step(
        &self,
        theta: &DVector<f64>,
        value: &dyn Fn(&DVector<f64>) -> Option<f64>,
    ) -> Result<Option<DVector<f64>>> {
        let p = theta.len();
        let grad = (self.h * theta - self.rhs) * (2.0 * self.t) + self.bg;
        let hess = self.h * (2.0 * self.t) + self.bh;
        // scaled to a unit diagonal for the factorisation
        let d: Vec<f64> = (0..p)
            .map(|i| 1.0 / hess[(i, i)].max(1e-300).sqrt())
            .collect();
        let scaled = DMatrix::from_fn(p, p, |i, j| hess[(i, j)] * d[i] * d[j]);
        let Some(ch) = newton_factor(scaled) else {
            return Err(Error::numerical(
                "consistent least squares",
                "the Newton system is not positive definite",
            ));
        };
        let g_scaled = DVector::from_iterator(p, (0..p).map(|i| grad[i] * d[i]));
        let step_scaled = -ch.solve(&g_scaled);
        let step = DVector::from_iterator(p, (0..p).map(|i| step_scaled[i] * d[i]));
        let decrement = -grad.dot(&step); // the Newton decrement squared
        if decrement <= 1e-9 {
            return Ok(None);
        }
        let now = value(theta).unwrap_or(f64::INFINITY);
        let mut alpha = 1.0;
        while alpha >= 1e-12 {
            let trial = theta + &step * alpha;
            if let Some(v) = value(&trial) {
                if v <= now - 0.25 * alpha * decrement {
                    return Ok(Some(trial));
                }
            }
            alpha *= 0.5;
        }
        // no progress possible at this t: rounding
        Ok(None)
    }
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
            return Err(Error::invalid(
                "robot",
                format!(
                    "the parameters are for {} bodies and {} joints; '{}' has {} and {}",
                    layout.nbodies,
                    layout.nv,
                    robot.name,
                    robot.nbodies(),
                    robot.nv
                ),
            ));
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
    let svd = crate::decomposition::svd(a, true, true).ok_or_else(|| {
        Error::numerical(
            "consistent least squares",
            "the system is not finite, or its SVD did not converge",
        )
    })?;
    let eps = relative * svd.singular_values.max();
    svd.solve(b, eps)
        .map_err(|m| Error::numerical("consistent least squares", m.to_string()))
}

/// Identifies physically consistent parameters of `model` from the same data as
/// [`super::identify_base_parameters`] (same arguments, same weighting): the weighted least squares
/// over parameter sets whose every body has a positive definite pseudo-inertia and whose
/// friction and armature coefficients are non-negative (see [this module](self)). The
/// robot's own parameters serve as the weak prior that decides what the data do not.
///
/// Returns the consistent fit with the unconstrained one beside it.
pub fn identify_consistent_parameters(
    model: &crate::Model,
    states: &crate::States<'_>,
    tau: &[f64],
    options: &super::BaseOptions,
    consistent: &ConsistentOptions,
) -> Result<ConsistentFit> {
    let (fit, factors) = super::identify::fit_with_factors(model, states, tau, options)?;
    // the runs' offsets (where fitted) minimised over for every set of parameters
    let profiled = factors.profiled(&fit.sigma)?;
    let (r11, z, rho) = (&profiled.r, &profiled.z, profiled.rho);
    let base = &fit.base;
    let layout = &base.layout;
    // theta_base = B theta: B[i, kept[i]] = 1, B[i, dropped[d]] = K[i, d]
    let mut b = DMatrix::zeros(base.len(), layout.len());
    for (i, &c) in base.kept.iter().enumerate() {
        b[(i, c)] = 1.0;
        for (d, &dc) in base.dropped.iter().enumerate() {
            b[(i, dc)] = base.k[(i, d)];
        }
    }
    let prior = layout.model_parameters(model);
    let solution = consistent_least_squares(
        layout,
        &(r11 * b),
        &DVector::from_column_slice(z.as_slice()),
        rho * rho,
        prior.as_slice(),
        consistent,
    )?;
    let theta = base.from_full(&DVector::from_column_slice(&solution.theta))?;
    let theta: Vec<f64> = theta.iter().copied().collect();
    // the runs' offsets that go with the consistent parameters
    let others = profiled.others(&theta)?;
    let unknowns: Vec<f64> = theta.iter().chain(&others).copied().collect();
    let log_offsets = (fit.log_offsets.as_ref()).map(|o| super::log_offsets::LogOffsets {
        deviations: super::log_offsets::LogOffsets::deviations_of(
            &unknowns,
            theta.len(),
            model.nv,
            o.runs(),
        ),
        stderr: o.stderr.clone(),
    });
    let residual_rms = factors.residual_rms(&unknowns)?;
    // its residuals against the noise, as the unconstrained fit's were
    let noise_fit = (fit.noise_fit.as_ref())
        .and_then(|n| super::NoiseFit::of(&n.noise, &residual_rms, fit.samples, unknowns.len()));
    let consistent_model = super::BaseModel {
        residual_rms,
        noise_fit,
        theta,
        log_offsets,
        ..fit.clone()
    };
    Ok(ConsistentFit {
        layout: layout.clone(),
        solution,
        model: consistent_model,
        unconstrained: fit,
    })
}

/// The Cholesky factor of the Newton system `scaled` (unit diagonal), or of `scaled + lambda I`
/// for the least `lambda` of 1e-14, 1e-13, ..., 1e-8 that makes it one where rounding has left
/// the system (positive definite in exact arithmetic: a Gram matrix plus a positive diagonal
/// plus the barrier's positive semidefinite Hessian) short of positive definite: at a large
/// barrier weight the Gram matrix of ill-conditioned columns dominates, and a change of an
/// ulp in the data can tip it. The damped step is still a descent direction, and the line
/// search keeps every iterate inside and decreasing; `None` if even 1e-8 fails.
fn newton_factor(scaled: DMatrix<f64>) -> Option<nalgebra::Cholesky<f64, nalgebra::Dyn>> {
    if let Some(ch) = nalgebra::Cholesky::new(scaled.clone()) {
        return Some(ch);
    }
    (6..=14).rev().find_map(|e| {
        let lambda = 10f64.powi(-e);
        let mut damped = scaled.clone();
        for i in 0..damped.nrows() {
            damped[(i, i)] += lambda;
        }
        nalgebra::Cholesky::new(damped)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_newton_system_left_singular_by_rounding_is_damped_an_indefinite_one_refused() {
        // the Gram matrix of two columns 1e-17 apart: positive definite, singular once rounded
        let near = DMatrix::from_row_slice(2, 2, &[1.0, 1.0 - 1e-17, 1.0 - 1e-17, 1.0]);
        assert!(nalgebra::Cholesky::new(near.clone()).is_none());
        let ch = newton_factor(near.clone()).expect("damped");
        let l = ch.l();
        let back = &l * l.transpose() - &near;
        // the least damping that works: 1e-14 on the diagonal
        assert!((back[(0, 0)] - 1e-14).abs() < 1e-15, "{back}");
        assert!(back[(0, 1)].abs() < 1e-15, "{back}");
        // a system with a negative eigenvalue (-1) is no rounding's doing
        let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(newton_factor(indefinite).is_none());
        // a positive definite one is factored as it is
        let spd = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 2.0]);
        let l = newton_factor(spd.clone()).unwrap().l();
        assert!((&l * l.transpose() - spd).amax() < 1e-15);
    }
}
