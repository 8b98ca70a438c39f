//! A joint's zero offset in the log: positions logged a constant away from the robot's own
//! (an encoder zeroed elsewhere after maintenance, another convention for a joint's zero). The
//! direct method fits such a log without a word: the base parameters absorb what they can, and
//! the fit only gets worse (docs/method.md, section 8).
//!
//! The check estimates every joint's offset `d` together with the base parameters, by
//! Gauss-Newton on the fit: `tau = Phi(q + d, qd, qdd) theta`, linearised about the current
//! `d` by the derivative of the fitted torques in each joint's position (a forward difference),
//! refitting `theta` at each step, each step at most [`MAX_STEP`] in any joint. On the samples it
//! checks ([`SAMPLES`] evenly spread), rows weighted by the fit's `sigma` as the fit weighs
//! them. A joint whose offset the parameters absorb (a vertical base axis, whose turning moves
//! no weight; the last joint of a chain, whose turning only turns its own link's parameters) is
//! left out: its derivative lies within the regressor's columns. The offsets are a finding
//! where they leave at most [`FINDING_RATIO`] of the weighted residual RMS the fit leaves as
//! logged (what a single offset explains is its own, not the model's other errors): on the real
//! Panda log the estimates (at most 0.018 rad, its sixth joint left out as not determined to
//! [`MAX_STDERR`]) leave 0.97 of it; 0.1 rad added to its second joint left 0.43, and is
//! estimated to 2 mrad of what was added. It costs about as much as (2 + N) regressors of
//! [`SAMPLES`] samples a step.
//!
//! A saved model validated on a new log gets the same check with its parameters held
//! ([`check_position_offsets_in_validation`]): a joint zeroed elsewhere since the model was
//! identified (after maintenance, a new encoder) is then named against the model rather than
//! only seen as a larger validation error.

use nalgebra::{DMatrix, DVector};

use super::base_model::BaseModel;
pub use super::findings::position_offsets::*;

/// The step (rad or m) of the forward difference of the fitted torques in a position.
const STEP: f64 = 1e-6;
use super::parameters::regressor_blocks;
use crate::error::Result;
use crate::{Model, States};

/// Estimates the joint offsets of the log (`states`: rad, rad/s, rad/s^2; `tau`: row-major `k x
/// nv`, N m) that `fit` (identified from it on `model`) was identified from. Joints whose offset
/// the parameters absorb are left out, and so, one at a time from the least determined, are
/// joints whose standard error exceeds [`MAX_STDERR`] (a pair of parallel axes can turn
/// together as the parameters absorb, though neither alone does). None where the log has
/// fewer samples than the fit has parameters and joints, no joint's offset is determined, or a
/// number is not finite.
pub fn check_position_offsets(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
) -> Result<Option<PositionOffsets>> {
    check(model, fit, states, tau, Parameters::Refitted)
}

/// Estimates the joint offsets of a new log (`states`, `tau` as [`check_position_offsets`]'s)
/// against the saved `fit` of `model`, its parameters held: what to add to the log's positions
/// for the model to predict its torques best. A joint whose offset does not change the
/// model's torques (a vertical base axis) is left out, and so are joints not determined to
/// [`MAX_STDERR`] (the standard errors inflated by the fit's own factor). None as
/// [`check_position_offsets`].
pub fn check_position_offsets_in_validation(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
) -> Result<Option<PositionOffsets>> {
    check(model, fit, states, tau, Parameters::Held)
}

/// Whether the parameters are refitted with the offsets (the fit's own log) or held (a saved
/// model against a new log).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Parameters {
    Refitted,
    Held,
}

fn check(
    model: &Model,
    fit: &BaseModel,
    states: &States<'_>,
    tau: &[f64],
    parameters: Parameters,
) -> Result<Option<PositionOffsets>> {
    let n = model.nv;
    let k = states.len();
    states.check_companion("tau", tau, n)?;
    let m = k.min(SAMPLES);
    let p = fit.theta.len();
    if m * n < 2 * (p + n) || fit.sigma.len() != n {
        return Ok(None);
    }
    let rows = crate::states::SpreadRows::new(k, SAMPLES, n);
    let pick = |x: &[f64]| rows.pick(x);
    let weight: Vec<f64> = fit.sigma.iter().map(|s| 1.0 / s).collect();
    let measured = pick(tau);
    let problem = Problem {
        model,
        fit,
        q: pick(states.q()),
        qd: pick(&states.qd_or_zeros()),
        qdd: pick(&states.qdd_or_zeros()),
        coulomb: states.coulomb().map(pick),
        y: DVector::from_fn(m * n, |r, _| measured[r] * weight[r % n]),
        weight,
        parameters,
    };
    let Some(logged) = problem.residual(&vec![0.0; n])? else {
        return Ok(None);
    };
    let inflation = fit.stderr_inflation();
    let mut left_out = vec![false; n];
    // the standard errors of the joints left out as undetermined, when they were
    let mut undetermined: Vec<Option<f64>> = vec![None; n];
    loop {
        let Some(found) = problem.gauss_newton(&left_out)? else {
            return Ok(None);
        };
        let stderr: Vec<f64> = found.stderr.iter().map(|s| s * inflation).collect();
        let worst = (0..found.free.len())
            .filter(|&c| stderr[c] > MAX_STDERR || stderr[c].is_nan())
            .max_by(|&a, &b| stderr[a].total_cmp(&stderr[b]));
        if let Some(c) = worst {
            left_out[found.free[c]] = true;
            undetermined[found.free[c]] = Some(stderr[c]).filter(|s| s.is_finite());
            continue;
        }
        let reasons = (0..n).filter(|j| !found.free.contains(j)).map(|j| LeftOut {
            joint: model.joint_names[j].clone(),
            why: if left_out[j] {
                WhyLeftOut::Undetermined
            } else {
                WhyLeftOut::Absorbed
            },
            stderr: undetermined[j],
        });
        let rms = |norm: f64| norm / ((m * n) as f64).sqrt();
        let offsets = PositionOffsets {
            joints: found
                .free
                .iter()
                .map(|&j| model.joint_names[j].clone())
                .collect(),
            offsets: found.free.iter().map(|&j| found.d[j]).collect(),
            stderr,
            unexplained: rms(logged),
            unexplained_with_offsets: rms(found.residual),
            left_out: reasons.collect(),
        };
        return Ok(offsets
            .problem(&model.joint_names)
            .is_none()
            .then_some(offsets));
    }
}

/// The samples checked, weighted, and what the fit's regressor is built from.
struct Problem<'a> {
    model: &'a Model,
    fit: &'a BaseModel,
    /// Positions, velocities and accelerations of the samples (row-major, rad, rad/s, rad/s^2).
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    /// The Coulomb term's column where the states give one ([`States::with_coulomb`]).
    coulomb: Option<Vec<f64>>,
    /// The torques (row-major), each joint's weighted by `weight`.
    y: DVector<f64>,
    /// `1 / sigma` per joint.
    weight: Vec<f64>,
    /// Refitted at each step, or the fit's held.
    parameters: Parameters,
}

/// Offsets found by [`Problem::gauss_newton`].
struct Found {
    /// The joints estimated.
    free: Vec<usize>,
    /// Every joint's offset (0 for the others).
    d: Vec<f64>,
    /// The standard errors of `free`'s (not inflated).
    stderr: Vec<f64>,
    /// The weighted residual's norm with the offsets, the parameters refitted.
    residual: f64,
}

impl Problem<'_> {
    /// The regressor's columns at `a`, for the parameters' refit (None where they are held),
    /// and the parameters; None where `a` is not finite.
    fn parameters<'a>(&self, a: &'a DMatrix<f64>) -> Option<(Option<Columns<'a>>, DVector<f64>)> {
        match self.parameters {
            Parameters::Refitted => {
                let columns = Columns::new(a)?;
                let theta = columns.coefficients(&self.y);
                Some((Some(columns), theta))
            }
            Parameters::Held => Some((None, DVector::from_column_slice(&self.fit.theta))),
        }
    }

    /// The weighted residual's norm with the offsets `d` (the parameters refitted or held);
    /// None where it is not finite.
    fn residual(&self, d: &[f64]) -> Result<Option<f64>> {
        let a = self.regressor(d)?;
        let Some((_, theta)) = self.parameters(&a) else {
            return Ok(None);
        };
        let norm = (&self.y - &a * theta).norm();
        Ok(norm.is_finite().then_some(norm))
    }

    /// The weighted base regressor at positions `q + d`.
    fn regressor(&self, d: &[f64]) -> Result<DMatrix<f64>> {
        let n = self.model.nv;
        let (rows, p) = (self.y.len(), self.fit.theta.len());
        let q: Vec<f64> = self
            .q
            .iter()
            .enumerate()
            .map(|(i, v)| v + d[i % n])
            .collect();
        let s = States::new(n, &q, Some(&self.qd), Some(&self.qdd))?;
        let s = match &self.coulomb {
            Some(c) => s.with_coulomb(c)?,
            None => s,
        };
        let mut a = DMatrix::zeros(rows, p);
        regressor_blocks(
            self.model,
            &self.fit.base.layout,
            &s,
            self.fit.gravity,
            |range, phi| {
                let block = self.fit.base.select(phi);
                let r0 = range.start * n;
                for r in 0..block.nrows() {
                    for c in 0..p {
                        a[(r0 + r, c)] = block[(r, c)] * self.weight[(r0 + r) % n];
                    }
                }
                Ok(())
            },
        )?;
        Ok(a)
    }

    /// Up to [`STEPS`] Gauss-Newton steps (each at most [`MAX_STEP`] in any joint, stopping
    /// below [`CONVERGED`]) on the offsets of the joints not `left_out` whose derivative the
    /// parameters do not absorb; None where none is left or a fit fails.
    fn gauss_newton(&self, left_out: &[bool]) -> Result<Option<Found>> {
        let n = self.model.nv;
        let rows = self.y.len();
        let p = self.fit.theta.len();
        let mut d = vec![0.0; n];
        let mut free: Vec<usize> = vec![];
        let mut stderr = vec![];
        for _ in 0..STEPS {
            crate::interrupt::check("checking the positions' zero offsets")?;
            let a = self.regressor(&d)?;
            let Some((columns, theta)) = self.parameters(&a) else {
                return Ok(None);
            };
            let fitted = &a * &theta;
            // the derivative of the fitted torques in each joint's position (a forward
            // difference), and what of it the regressor's columns cannot take
            let mut outside = Vec::with_capacity(n);
            for j in 0..n {
                if left_out[j] {
                    outside.push(None);
                    continue;
                }
                let mut e = d.clone();
                e[j] += STEP;
                let derivative = (self.regressor(&e)? * &theta - &fitted) / STEP;
                let own = derivative.norm();
                let rest = match &columns {
                    Some(columns) => &derivative - columns.fitted(&derivative),
                    None => derivative,
                };
                let determined = rest.norm() > ABSORBED * own.max(fitted.norm()) && own > 0.0;
                outside.push(determined.then_some(rest));
            }
            free = (0..n).filter(|&j| outside[j].is_some()).collect();
            if free.is_empty() {
                return Ok(None);
            }
            // the offsets' step: the residual on the derivatives' parts outside the columns
            let x = DMatrix::from_fn(rows, free.len(), |r, c| {
                outside[free[c]].as_ref().map_or(0.0, |v| v[r])
            });
            let Some(derivatives) = Columns::new(&x) else {
                return Ok(None);
            };
            let residual = &self.y - &fitted;
            let mut step = derivatives.coefficients(&residual);
            let left = (&residual - &x * &step).norm();
            let refitted = if columns.is_some() { p } else { 0 };
            let dof = rows.saturating_sub(refitted + free.len()).max(1) as f64;
            let covariance = derivatives.covariance();
            stderr = (0..free.len())
                .map(|c| (left * left / dof * covariance[(c, c)]).sqrt())
                .collect();
            let largest = step.amax();
            if largest > MAX_STEP {
                step *= MAX_STEP / largest;
            }
            for (c, &j) in free.iter().enumerate() {
                d[j] += step[c];
            }
            if largest < CONVERGED || largest.is_nan() {
                break;
            }
        }
        let Some(residual) = self.residual(&d)? else {
            return Ok(None);
        };
        Ok(Some(Found {
            free,
            d,
            stderr,
            residual,
        }))
    }
}

/// Least squares on the columns of a tall matrix `a` through their Gram matrix, scaled to unit
/// diagonal and pseudo-inverted (directions below 1e-12 of the largest dropped): cheap for the
/// few columns and many rows here, and exact enough for a diagnostic.
struct Columns<'a> {
    a: &'a DMatrix<f64>,
    scale: DVector<f64>,
    gram_inverse: DMatrix<f64>,
}

impl<'a> Columns<'a> {
    /// None where `a` is not finite.
    fn new(a: &'a DMatrix<f64>) -> Option<Self> {
        let scale = DVector::from_iterator(
            a.ncols(),
            a.column_iter().map(|c| match c.norm() {
                v if v > 0.0 && v.is_finite() => v,
                _ => 1.0,
            }),
        );
        let mut gram = a.tr_mul(a);
        for r in 0..gram.nrows() {
            for c in 0..gram.ncols() {
                gram[(r, c)] /= scale[r] * scale[c];
            }
        }
        let gram_inverse = crate::decomposition::pseudo_inverse(gram, 1e-12)?;
        Some(Self {
            a,
            scale,
            gram_inverse,
        })
    }

    /// The coefficients of the least-squares fit of `v` by the columns.
    fn coefficients(&self, v: &DVector<f64>) -> DVector<f64> {
        let scaled = self.a.tr_mul(v).component_div(&self.scale);
        (&self.gram_inverse * scaled).component_div(&self.scale)
    }

    /// The least-squares fit of `v` by the columns.
    fn fitted(&self, v: &DVector<f64>) -> DVector<f64> {
        self.a * self.coefficients(v)
    }

    /// `(A^T A)^-1`: the coefficients' covariance over the residual variance.
    fn covariance(&self) -> DMatrix<f64> {
        let mut c = self.gram_inverse.clone();
        for r in 0..c.nrows() {
            for k in 0..c.ncols() {
                c[(r, k)] /= self.scale[r] * self.scale[k];
            }
        }
        c
    }
}
