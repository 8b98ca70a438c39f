//! Base-parameter least squares that scale to 10^5-10^6 samples without the whole regressor
//! in memory: the weighted system `[Phi_base | tau]` is reduced chunk by chunk (in parallel) to
//! its `(p + 1) x (p + 1)` triangular factor by QR, and the factors are reduced again (TSQR).
//! Memory: one chunk's regressor per thread (`CHUNK * nv * (P + 1)` values; about 9 MB for a
//! 7-dof arm with friction) plus `(p + 1)^2` per chunk. QR keeps the conditioning of the
//! regressor (normal equations would square it).

use faer::linalg::solvers::Qr;
use faer::Mat;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::base::BaseParameters;
use super::parameters::{fill_regressor, Batch};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::regression::{least_squares, LeastSquares};

/// Samples per chunk.
pub const CHUNK: usize = 2048;

/// The regressor's base columns of samples `range`, rows weighted by `1 / sigma[joint]`, with
/// the weighted torques as an extra last column.
fn chunk_system(
    model: &Model,
    base: &BaseParameters,
    batch: &Batch<'_>,
    tau: &[f64],
    gravity: bool,
    sigma: &[f64],
    range: std::ops::Range<usize>,
) -> Result<DMatrix<f64>> {
    let nv = model.nv;
    let rows = range.len() * nv;
    let mut full = DMatrix::zeros(rows, base.layout.len());
    let start = range.start;
    fill_regressor(model, &base.layout, batch, gravity, range, &mut full, 0)?;
    let p = base.len();
    let mut out = DMatrix::zeros(rows, p + 1);
    for r in 0..rows {
        let w = 1.0 / sigma[r % nv];
        for (c, &col) in base.kept.iter().enumerate() {
            out[(r, c)] = w * full[(r, col)];
        }
        out[(r, p)] = w * tau[start * nv + r];
    }
    Ok(out)
}

/// The upper-triangular factor (at most `cols` rows) of a QR of `a`.
fn triangular(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    let f = Mat::<f64>::from_fn(m, n, |i, j| a[(i, j)]);
    let qr = Qr::new(f.as_ref());
    let r = qr.thin_R();
    DMatrix::from_fn(r.nrows(), n, |i, j| if j >= i { r[(i, j)] } else { 0.0 })
}

/// Solves the weighted base-parameter least squares over all samples; `names` label the base
/// columns for a rank-deficiency error. Returns the solution with `stderr` for the weighted
/// problem (`sigma_w^2 (W^T W)^-1`) and `residual_rms` left empty (see [`residual_rms`]).
pub fn solve(
    model: &Model,
    base: &BaseParameters,
    batch: &Batch<'_>,
    tau: &[f64],
    gravity: bool,
    sigma: &[f64],
    names: &[String],
) -> Result<LeastSquares> {
    let nv = model.nv;
    let k = batch.samples(nv)?;
    let p = base.len();
    if k * nv <= p {
        return Err(Error::RankDeficient {
            context: "base-parameter identification".into(),
            rows: k * nv,
            cols: p,
            rank: k * nv,
            missing: format!(
                "{k} samples x {nv} joints cannot determine {p} base parameters; add samples"
            ),
        });
    }
    let chunks: Vec<std::ops::Range<usize>> = (0..k)
        .step_by(CHUNK)
        .map(|s| s..(s + CHUNK).min(k))
        .collect();
    let factors: Vec<DMatrix<f64>> = chunks
        .into_par_iter()
        .map(|range| {
            chunk_system(model, base, batch, tau, gravity, sigma, range).map(|a| triangular(&a))
        })
        .collect::<Result<_>>()?;
    let height: usize = factors.iter().map(|f| f.nrows()).sum();
    let mut stacked = DMatrix::zeros(height, p + 1);
    let mut row = 0;
    for f in &factors {
        stacked.view_mut((row, 0), f.shape()).copy_from(f);
        row += f.nrows();
    }
    let r = if height > p + 1 {
        triangular(&stacked)
    } else {
        stacked
    };
    // [R11 z; 0 rho]: min |W theta - y| solves R11 theta = z with residual norm |rho|
    let r11 = r.view((0, 0), (p, p)).into_owned();
    let z = r.view((0, p), (p, 1)).into_owned();
    let rho = if r.nrows() > p { r[(p, p)] } else { 0.0 };
    let mut ls = least_squares(&r11, &z, "base-parameter identification", names)?;
    let dof = (k * nv - p) as f64;
    let s = (rho * rho / dof).sqrt();
    ls.stderr = DMatrix::from_fn(1, p, |_, j| s * ls.cov_diag[j].sqrt());
    ls.rows = k * nv;
    ls.residual_rms = DVector::zeros(0);
    Ok(ls)
}

/// Per-joint RMS of the unweighted residuals `tau - Phi_base theta` (N m), streamed.
pub fn residual_rms(
    model: &Model,
    base: &BaseParameters,
    batch: &Batch<'_>,
    tau: &[f64],
    gravity: bool,
    theta: &[f64],
) -> Result<Vec<f64>> {
    let nv = model.nv;
    let k = batch.samples(nv)?;
    let ones = vec![1.0; nv];
    let p = base.len();
    let theta = DVector::from_column_slice(theta);
    let sums: Vec<Vec<f64>> = (0..k)
        .step_by(CHUNK)
        .map(|s| s..(s + CHUNK).min(k))
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|range| {
            let a = chunk_system(model, base, batch, tau, gravity, &ones, range)?;
            let r = a.column(p) - a.columns(0, p) * &theta;
            let mut acc = vec![0.0; nv];
            for (i, v) in r.iter().enumerate() {
                acc[i % nv] += v * v;
            }
            Ok(acc)
        })
        .collect::<Result<_>>()?;
    Ok((0..nv)
        .map(|j| (sums.iter().map(|s| s[j]).sum::<f64>() / k as f64).sqrt())
        .collect())
}
