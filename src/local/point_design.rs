//! Which operating points to add so that local models there identify every base parameter:
//! greedy D-optimal selection among random candidates within the joint limits.

use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::parameters::FromLocalOptions;
use crate::algorithms::linearization_regressor::linearization_regressor;
use crate::direct::base::{BaseParameters, BASE_TOLERANCE};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::operating_point::OperatingPoint;
use crate::parameters::ParameterLayout;

/// One suggested point and what the design reaches with it.
#[derive(Clone, Debug, PartialEq)]
pub struct SuggestedPoint {
    pub op: OperatingPoint,
    /// Base parameters identified by the given points and the suggestions so far.
    pub rank: usize,
    /// `log det` of the information matrix (on the robot's base parameters, plus a small
    /// ridge) after adding this point.
    pub log_det: f64,
}

/// The rows a local model at `op` contributes (as `options.use_*` select), unweighted, on the
/// columns `kept` of the full layout.
fn rows_at(
    robot: &Model,
    layout: &ParameterLayout,
    kept: &[usize],
    op: &OperatingPoint,
    options: &FromLocalOptions,
) -> Result<DMatrix<f64>> {
    let r = linearization_regressor(robot, layout, &op.q, &op.qd, &op.qdd, options.gravity)?;
    let mut blocks: Vec<&DMatrix<f64>> = vec![];
    if options.use_torque {
        blocks.push(&r.torque);
    }
    if options.use_d {
        blocks.push(&r.d);
    }
    if options.use_h {
        blocks.push(&r.h);
    }
    if options.use_g {
        blocks.push(&r.g);
    }
    if options.use_g_static {
        blocks.push(&r.g_static);
    }
    let rows: usize = blocks.iter().map(|b| b.nrows()).sum();
    let mut out = DMatrix::zeros(rows, kept.len());
    let mut at = 0;
    for b in blocks {
        for i in 0..b.nrows() {
            for (c, &k) in kept.iter().enumerate() {
                out[(at + i, c)] = b[(i, k)];
            }
        }
        at += b.nrows();
    }
    Ok(out)
}

fn log_det(a: &DMatrix<f64>, ridge: f64) -> f64 {
    let n = a.nrows();
    let m = a + DMatrix::identity(n, n) * ridge;
    match m.cholesky() {
        Some(c) => 2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
        None => f64::NEG_INFINITY,
    }
}

/// Up to `count` operating points to add to `existing` (points where local models are already
/// identified, possibly none), chosen greedily from `candidates` random points (positions
/// within 80 % of each joint's range, speeds and accelerations within half their limits, or
/// +-0.5 rad/s and +-1 rad/s^2 where unlimited; seeded) to maximise the information on the
/// robot's base parameters (D-optimality: `log det` of `sum X^T X` over the rows the local
/// models give, `X` unweighted, with a ridge of 1e-9 of its trace). Returns `count` points
/// (fewer if the candidates run out), each with the rank the design reaches with it.
///
/// Errors: `candidates` or `count` of 0 or above 10,000, or candidates whose information
/// matrices (`p x p` each, `p` base parameters) would exceed [`crate::limits::MAX_VALUES`].
pub fn suggest_operating_points(
    robot: &Model,
    existing: &[OperatingPoint],
    options: &FromLocalOptions,
    candidates: usize,
    count: usize,
    seed: u64,
) -> Result<Vec<SuggestedPoint>> {
    crate::limits::check_count("candidates", candidates, 1, 10_000)?;
    crate::limits::check_count("count", count, 1, 10_000)?;
    let layout = ParameterLayout::new(robot, options.friction.for_model(robot));
    let base = BaseParameters::from_random_states(
        robot,
        &layout,
        options.gravity,
        20 * layout.len(),
        BASE_TOLERANCE,
        1,
    )?;
    let p = base.len();
    crate::limits::check_values("candidates", (candidates * p) as f64 * p as f64, || {
        format!("the information matrices of {candidates} candidates on {p} base parameters")
    })?;
    let mut info = DMatrix::zeros(p, p);
    for op in existing {
        if op.n() != robot.nv {
            return Err(Error::shape(
                "existing operating point",
                format!("{} joints", robot.nv),
                format!("{} joints", op.n()),
            ));
        }
        let x = rows_at(robot, &layout, &base.kept, op, options)?;
        info += x.transpose() * &x;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut pool = Vec::with_capacity(candidates);
    for _ in 0..candidates {
        crate::interrupt::check("operating point design")?;
        let (mut q, mut qd, mut qdd) = (vec![], vec![], vec![]);
        for l in &robot.limits {
            let (lo, hi) = if l.lower.is_finite() && l.upper.is_finite() {
                let mid = 0.5 * (l.lower + l.upper);
                let half = 0.4 * (l.upper - l.lower);
                (mid - half, mid + half)
            } else {
                (-std::f64::consts::PI, std::f64::consts::PI)
            };
            q.push(rng.random_range(lo..=hi));
            let v = if l.velocity.is_finite() {
                0.5 * l.velocity
            } else {
                0.5
            };
            qd.push(rng.random_range(-v..=v));
            let a = if l.acceleration.is_finite() {
                0.5 * l.acceleration
            } else {
                1.0
            };
            qdd.push(rng.random_range(-a..=a));
        }
        let op = OperatingPoint::new(q, qd, qdd)?;
        let x = rows_at(robot, &layout, &base.kept, &op, options)?;
        pool.push((op, x.transpose() * &x));
    }
    let mut out = vec![];
    for _ in 0..count {
        let ridge = 1e-9
            * (info.trace() + pool.iter().map(|c| c.1.trace()).sum::<f64>() / pool.len() as f64);
        let best = pool
            .iter()
            .enumerate()
            .map(|(i, (_, c))| (i, log_det(&(&info + c), ridge)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((i, value)) = best else { break };
        let (op, c) = pool.swap_remove(i);
        info += c;
        let sv = crate::decomposition::svd(info.clone(), false, false)
            .map_or_else(|| nalgebra::DVector::zeros(0), |s| s.singular_values);
        let top = sv.iter().cloned().fold(0.0, f64::max);
        // singular values of X^T X are squares: 1e-16 here is the QR's 1e-8
        let rank = sv.iter().filter(|&&s| s > 1e-16 * top).count();
        out.push(SuggestedPoint {
            op,
            rank,
            log_det: value,
        });
        if pool.is_empty() {
            break;
        }
    }
    Ok(out)
}
