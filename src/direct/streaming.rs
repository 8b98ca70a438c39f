//! Base-parameter least squares that scale to 10^5-10^6 samples in one pass over the data and
//! without the whole regressor in memory.
//!
//! The system `[Phi_base | tau]` is split by joint: the rows of joint `j` (one per sample) are
//! reduced, chunk by chunk and in parallel, to their `(p + 1) x (p + 1)` triangular QR factor
//! `R_j` (a TSQR per joint), over only the columns those rows can have nonzero (the bodies the
//! joint carries, its own friction). Those `nv` factors hold everything the fits need, exactly:
//! - any per-joint weighting `1 / sigma_j`: the weighted system's factor is the QR of the
//!   stacked `R_j / sigma_j`, so OLS and then WLS need no second pass over the samples;
//! - the per-joint residuals of any `theta`: `|tau_j - Phi_j theta| = |R_j [theta; -1]|`.
//!
//! Columns of data that a joint's rows alone carry (a drive gain's logged current,
//! [`super::drive_gains`]) come in beside the base columns, `extra` of them a joint
//! ([`JointFactors::with_columns`]): unknowns `p + nv extra` in all.
//!
//! QR keeps the conditioning of the regressor (normal equations would square it).
//! Memory: per worker (about two per core), one chunk of every joint, at most `nv * (CHUNK + p +
//! 1) * (p + 1)` values (1.9 MB for a 6-dof arm with 36 base parameters, 3.9 MB for a 7-dof
//! arm with friction), plus the `nv` factors; never the whole regressor.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::factor::{
    qr_in_place, qr_in_place_scratch, recommended_block_size,
};
use faer::{Mat, MatMut, Par};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::base::BaseParameters;
use crate::algorithms::batch::{regressor_group, LaneData};
use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::regression::{least_squares, LeastSquares};
use crate::states::States;

/// Samples per chunk.
pub const CHUNK: usize = 1024;

/// The most runs whose offsets one fit takes ([`JointFactors::with_runs`]): each adds a column
/// to every joint's factor (50 runs make a 6-joint arm's fit about 4 times as costly).
pub const MAX_OFFSET_RUNS: usize = 50;

/// A friction term of a joint: `qd`, `sign(qd)` or 1, on that joint's rows only.
#[derive(Clone, Copy, Debug)]
enum Term {
    Viscous,
    Coulomb,
    Offset,
    Armature,
}

/// The columns that joint `j`'s rows can have nonzero: the base columns of the bodies the
/// joint carries (its subtree; a joint's torque does not depend on the bodies before it) and
/// the joint's own friction terms. Reducing only those saves about half the QR work on a chain.
#[derive(Clone, Debug)]
struct JointColumns {
    /// The base column of each active column, ascending.
    base: Vec<usize>,
    /// `(active column, inertial regressor column)`.
    inertial: Vec<(usize, usize)>,
    /// `(active column, friction term)`.
    friction: Vec<(usize, Term)>,
}

impl JointColumns {
    /// One per degree of freedom.
    fn new(model: &Model, base: &BaseParameters) -> Vec<Self> {
        let ni = PARAMS_PER_BODY * model.nbodies();
        let terms = base.layout.friction.names();
        (0..model.nv)
            .map(|j| {
                let carried = |body: usize| {
                    model
                        .bodies
                        .iter()
                        .enumerate()
                        .any(|(i, b)| b.dof == j && (i..b.subtree_end).contains(&body))
                };
                let mut out = JointColumns {
                    base: Vec::new(),
                    inertial: Vec::new(),
                    friction: Vec::new(),
                };
                for (c, &col) in base.kept.iter().enumerate() {
                    let a = out.base.len();
                    if col < ni {
                        if carried(col / PARAMS_PER_BODY) {
                            out.inertial.push((a, col));
                            out.base.push(c);
                        }
                        continue;
                    }
                    let (joint, t) = ((col - ni) / terms.len(), (col - ni) % terms.len());
                    if joint == j {
                        let term = match terms[t] {
                            "viscous" => Term::Viscous,
                            "coulomb" => Term::Coulomb,
                            "armature" => Term::Armature,
                            _ => Term::Offset,
                        };
                        out.friction.push((a, term));
                        out.base.push(c);
                    }
                }
                out
            })
            .collect()
    }
}

/// The per-joint triangular factors of `[Phi_base | tau]` over a batch (see the module docs).
#[derive(Clone, Debug)]
pub struct JointFactors {
    /// Number of samples reduced.
    pub samples: usize,
    /// Number of base parameters `p`.
    pub parameters: usize,
    /// Columns per joint beside the base columns (`e`; 0 for a plain fit): its columns of data,
    /// then its runs' offsets ([`JointFactors::with_runs`]); joint `j`'s column `c` is unknown
    /// `p + j e + c`.
    pub extra: usize,
    /// The base columns that joint `j`'s rows can have nonzero (`n_j` of them, ascending).
    pub active: Vec<Vec<usize>>,
    /// `R_j`, `(n_j + e + 1) x (n_j + e + 1)` upper triangular, one per joint, over the columns
    /// `active[j]`, then the joint's `e` columns of data and then the torque:
    /// `R_j^T R_j = A_j^T A_j` for the rows `A_j = [Phi_base[:, active[j]] | X_j | tau]` of
    /// joint `j`.
    pub factors: Vec<DMatrix<f64>>,
}

/// The samples a fit reduces, row-major over the whole batch: the states `x` (`[q, qd, qdd,
/// coulomb]`, `coulomb` the Coulomb term's column, [`States::coulomb_at`]), the joints'
/// columns of data `extra` (each `k x nv`) and the torques `tau`; `gravity` in the regressor.
/// Where the runs' offsets are fitted ([`JointFactors::with_runs`]), `starts` holds each run's
/// first sample (the first 0), and each joint's rows carry one column a run after the first.
#[derive(Clone, Copy)]
struct Batch<'a> {
    x: [&'a [f64]; 4],
    extra: &'a [&'a [f64]],
    starts: &'a [usize],
    tau: &'a [f64],
    gravity: Gravity,
}

impl Batch<'_> {
    /// The runs' offset columns a joint: one a run after the first (0 without runs).
    fn run_columns(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }
}

/// One worker's buffers: a `Data`, the regressor of one sample, and per joint a column-major
/// `(n_j + 1 + CHUNK) x (n_j + 1)` matrix whose top rows carry the factor so far (zeros at
/// first) and whose other rows take the next chunk.
struct Worker {
    lanes: LaneData,
    stacks: Vec<Mat<f64>>,
    q_coeff: Mat<f64>,
    scratch: MemBuffer,
}

impl Worker {
    fn new(model: &Model, columns: &[JointColumns], extra: usize) -> Self {
        let widest = columns
            .iter()
            .map(|c| c.base.len() + extra + 1)
            .max()
            .unwrap_or(1);
        let block = recommended_block_size::<f64>(widest + CHUNK, widest);
        Self {
            lanes: LaneData::new(model),
            stacks: columns
                .iter()
                .map(|c| {
                    let n = c.base.len() + extra + 1;
                    Mat::zeros(n + CHUNK, n)
                })
                .collect(),
            q_coeff: Mat::zeros(block, widest),
            scratch: MemBuffer::new(qr_in_place_scratch::<f64>(
                widest + CHUNK,
                widest,
                block,
                Par::Seq,
                Default::default(),
            )),
        }
    }

    /// Reduces samples `range` of `batch` into the factors.
    fn absorb(
        &mut self,
        model: &Model,
        columns: &[JointColumns],
        batch: &Batch<'_>,
        range: std::ops::Range<usize>,
    ) -> Result<()> {
        self.fill(model, columns, batch, range.clone())?;
        for a in &mut self.stacks {
            let rows = a.ncols() + range.len();
            factor_top(
                a.as_mut().get_mut(..rows, ..),
                self.q_coeff.as_mut(),
                &mut self.scratch,
            );
        }
        Ok(())
    }

    fn factors(&self) -> Vec<DMatrix<f64>> {
        self.stacks
            .iter()
            .map(|a| DMatrix::from_fn(a.ncols(), a.ncols(), |i, j| a[(i, j)]))
            .collect()
    }
}

impl Worker {
    /// Writes the rows of samples `range` of `batch` below the factors: the regressor
    /// [`LaneData::width`] samples at a time by the multi-sample kernel ([`regressor_group`]),
    /// read in place.
    fn fill(
        &mut self,
        model: &Model,
        columns: &[JointColumns],
        batch: &Batch<'_>,
        range: std::ops::Range<usize>,
    ) -> Result<()> {
        let Batch {
            x: [q, qd, qdd, coulomb],
            extra,
            starts,
            tau,
            gravity,
        } = *batch;
        let nv = model.nv;
        let (e, runs) = (extra.len(), batch.run_columns());
        // the run of the chunk's first sample, advanced as its samples pass the next start
        let mut run = starts
            .partition_point(|&f| f <= range.start)
            .saturating_sub(1);
        let mut first = range.start;
        while first < range.end {
            let used = (range.end - first).min(self.lanes.width());
            let rows = first * nv..(first + used) * nv;
            regressor_group(
                model,
                &mut self.lanes,
                &q[rows.clone()],
                &qd[rows.clone()],
                &qdd[rows],
                gravity,
            )?;
            for l in 0..used {
                let s = first + l;
                while run + 1 < starts.len() && starts[run + 1] <= s {
                    run += 1;
                }
                let row = s * nv..(s + 1) * nv;
                let (qd, qdd, coulomb) = (&qd[row.clone()], &qdd[row.clone()], &coulomb[row]);
                for (j, (a, cols)) in self.stacks.iter_mut().zip(columns).enumerate() {
                    let nj = cols.base.len();
                    let i = a.ncols() + s - range.start;
                    for &(c, col) in &cols.inertial {
                        a[(i, c)] = self.lanes.regressor_entry(l, j, col);
                    }
                    for &(c, term) in &cols.friction {
                        a[(i, c)] = match term {
                            Term::Viscous => qd[j],
                            Term::Coulomb => coulomb[j],
                            Term::Offset => 1.0,
                            Term::Armature => qdd[j],
                        };
                    }
                    for (c, x) in extra.iter().enumerate() {
                        a[(i, nj + c)] = x[s * nv + j];
                    }
                    // run r's offset less the runs' mean (the first run's the others' sum,
                    // negated): the base offset term is then the runs' mean offset
                    for c in 0..runs {
                        a[(i, nj + e + c)] = match run {
                            0 => -1.0,
                            r if r == c + 1 => 1.0,
                            _ => 0.0,
                        };
                    }
                    a[(i, nj + e + runs)] = tau[s * nv + j];
                }
            }
            first += used;
        }
        Ok(())
    }
}

/// QR of `a` in place, leaving its `R` in the top `ncols` rows with zeros below the diagonal.
fn factor_top(mut a: MatMut<'_, f64>, q_coeff: MatMut<'_, f64>, scratch: &mut MemBuffer) {
    let n = a.ncols();
    let block = q_coeff.nrows().min(a.nrows().min(n)).max(1);
    let q_coeff = q_coeff.get_mut(..block, ..a.nrows().min(n));
    qr_in_place(
        a.as_mut(),
        q_coeff,
        Par::Seq,
        MemStack::new(scratch),
        Default::default(),
    );
    for j in 0..n {
        for i in j + 1..n.min(a.nrows()) {
            a[(i, j)] = 0.0;
        }
    }
}

/// The upper-triangular factor (`ncols x ncols`, zero rows added when `a` is short) of a QR of
/// `a`.
pub(crate) fn triangular(a: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = a.shape();
    let mut f = Mat::<f64>::from_fn(m.max(n), n, |i, j| if i < m { a[(i, j)] } else { 0.0 });
    let block = recommended_block_size::<f64>(m.max(n), n);
    let mut q_coeff = Mat::zeros(block, n);
    let mut scratch = MemBuffer::new(qr_in_place_scratch::<f64>(
        m.max(n),
        n,
        block,
        Par::Seq,
        Default::default(),
    ));
    factor_top(f.as_mut(), q_coeff.as_mut(), &mut scratch);
    DMatrix::from_fn(n, n, |i, j| f[(i, j)])
}

/// The upper-triangular factor (`width x width`) of every joint's factor `factors[j]` (any
/// number of rows) stacked, its rows divided by `sigma[j]` and its column `c` placed in column
/// `column(j, c)` (`< width`) of the stack: `R^T R = sum_j F_j^T F_j / sigma_j^2` over the
/// scattered columns.
pub(super) fn triangular_of_stacked(
    factors: &[DMatrix<f64>],
    sigma: &[f64],
    width: usize,
    column: impl Fn(usize, usize) -> usize,
) -> DMatrix<f64> {
    let height: usize = factors.iter().map(|r| r.nrows()).sum();
    let mut stacked = DMatrix::zeros(height, width);
    let mut row = 0;
    for (j, (r, s)) in factors.iter().zip(sigma).enumerate() {
        for c in 0..r.ncols() {
            let to = column(j, c);
            for i in 0..r.nrows() {
                stacked[(row + i, to)] = r[(i, c)] / s;
            }
        }
        row += r.nrows();
    }
    triangular(&stacked)
}

/// Merges two sets of per-joint factors (QR of each stacked pair).
fn merge(a: Vec<DMatrix<f64>>, b: Vec<DMatrix<f64>>) -> Vec<DMatrix<f64>> {
    a.into_iter()
        .zip(b)
        .map(|(ra, rb)| {
            let n = ra.ncols();
            let mut s = DMatrix::zeros(2 * n, n);
            s.rows_mut(0, n).copy_from(&ra);
            s.rows_mut(n, n).copy_from(&rb);
            triangular(&s)
        })
        .collect()
}

impl JointFactors {
    /// Reduces the base regressor and torques of every sample of `states` (rad, rad/s,
    /// rad/s^2) and `tau` (row-major `k x nv`, N m), in parallel chunks of [`CHUNK`] samples.
    /// `gravity` includes gravity in the regressor.
    pub fn new(
        model: &Model,
        base: &BaseParameters,
        states: &States<'_>,
        tau: &[f64],
        gravity: Gravity,
    ) -> Result<Self> {
        Self::with_columns(model, base, states, tau, &[], gravity)
    }

    /// [`JointFactors::new`] with `extra` columns of data per joint beside the base columns:
    /// each row-major `k x nv`, joint `j`'s rows reading its entry `j` of each
    /// (`extra[c][s * nv + j]` at sample `s`), as unknowns `p + j e + c` (`e = extra.len()`,
    /// at most 4).
    pub fn with_columns(
        model: &Model,
        base: &BaseParameters,
        states: &States<'_>,
        tau: &[f64],
        extra: &[&[f64]],
        gravity: Gravity,
    ) -> Result<Self> {
        Self::with_runs(model, base, states, tau, extra, &[], gravity)
    }

    /// [`JointFactors::with_columns`] with an offset a joint for each of the `runs` (the
    /// samples of each, in order, adding up to all; none or two to [`MAX_OFFSET_RUNS`]) beside
    /// the offset term the base parameters hold: joint `j`'s unknowns `p + j e + c` after its
    /// `extra.len()` columns of data are, for `c = extra.len() + r - 1`, run `r`'s offset less
    /// the runs' mean (`r = 1 ..`; the first run's is minus their sum), so that the base
    /// offset term is the runs' mean offset. `e = extra.len() + runs.len() - 1`.
    pub fn with_runs(
        model: &Model,
        base: &BaseParameters,
        states: &States<'_>,
        tau: &[f64],
        extra: &[&[f64]],
        runs: &[usize],
        gravity: Gravity,
    ) -> Result<Self> {
        let nv = model.nv;
        if runs.len() == 1 || runs.len() > MAX_OFFSET_RUNS {
            return Err(Error::invalid(
                "runs",
                format!(
                    "{} runs, expected 2 to {MAX_OFFSET_RUNS} for an offset a run",
                    runs.len()
                ),
            ));
        }
        if !runs.is_empty() && (runs.contains(&0) || runs.iter().sum::<usize>() != states.len()) {
            return Err(Error::invalid(
                "runs",
                format!(
                    "runs of {} samples in all (none of 0 expected), for {} samples",
                    runs.iter().sum::<usize>(),
                    states.len()
                ),
            ));
        }
        let starts: Vec<usize> = (runs.iter())
            .scan(0, |first, &len| {
                let at = *first;
                *first += len;
                Some(at)
            })
            .collect();
        states.check_companion("tau", tau, nv)?;
        if extra.len() > 4 {
            return Err(Error::invalid(
                "extra",
                format!(
                    "{} columns of data a joint, expected at most 4",
                    extra.len()
                ),
            ));
        }
        for x in extra {
            states.check_companion("a joint's column of data", x, nv)?;
        }
        let e = extra.len() + runs.len().saturating_sub(1);
        let k = states.len();
        let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
        // the Coulomb term's column: the states' own (filtered), or sign(qd)
        let coulomb: std::borrow::Cow<[f64]> = match states.coulomb() {
            Some(c) => c.into(),
            None => (qd.iter()).map(|&v| crate::parameters::sign0(v)).collect(),
        };
        let batch = Batch {
            x: [states.q(), &qd[..], &qdd[..], &coulomb[..]],
            extra,
            starts: &starts,
            tau,
            gravity,
        };
        let p = base.len();
        let columns = JointColumns::new(model, base);
        let chunks: Vec<std::ops::Range<usize>> = (0..k)
            .step_by(CHUNK)
            .map(|s| s..(s + CHUNK).min(k))
            .collect();
        // a few workers per thread (for balance on a busy machine), each reducing a run of
        // consecutive chunks into its own factors; then the workers' factors are merged
        let groups = (2 * rayon::current_num_threads()).clamp(1, chunks.len().max(1));
        let per = chunks.len().div_ceil(groups).max(1);
        let factors = chunks
            .par_chunks(per)
            .map(|run| -> Result<Vec<DMatrix<f64>>> {
                let mut w = Worker::new(model, &columns, e);
                for range in run {
                    crate::interrupt::check("identification")?;
                    w.absorb(model, &columns, &batch, range.clone())?;
                }
                Ok(w.factors())
            })
            .try_reduce_with(|a, b| Ok(merge(a, b)))
            .transpose()?
            .unwrap_or_else(|| {
                let size = |c: &JointColumns| c.base.len() + e + 1;
                columns
                    .iter()
                    .map(|c| DMatrix::zeros(size(c), size(c)))
                    .collect()
            });
        Ok(Self {
            samples: k,
            parameters: p,
            extra: e,
            active: columns.into_iter().map(|c| c.base).collect(),
            factors,
        })
    }

    /// The number of unknowns: the `p` base parameters and the joints' columns of data,
    /// `p + nv e`.
    pub fn unknowns(&self) -> usize {
        self.parameters + self.factors.len() * self.extra
    }

    /// The least-squares fit of the base parameters (and the joints' columns of data) with the
    /// rows of joint `j` weighted by `1 / sigma[j]` (`sigma`: `nv` values, N m; all 1 for OLS).
    /// `names` label the [`JointFactors::unknowns`] columns for a rank-deficiency error.
    /// Returns the coefficients (`1 x p`, `p` the unknowns), `cond` of the column-scaled
    /// weighted regressor, `stderr` for the weighted problem (`sigma_w^2 (W^T W)^-1`,
    /// `sigma_w^2` = weighted residual sum of squares / (K nv - p)) and `residual_rms` left
    /// empty (see [`JointFactors::residual_rms`]).
    pub fn solve(&self, sigma: &[f64], names: &[String]) -> Result<LeastSquares> {
        let nv = self.factors.len();
        let p = self.unknowns();
        let rows = self.samples * nv;
        if rows <= p {
            return Err(Error::RankDeficient {
                context: "base-parameter identification".into(),
                rows,
                cols: p,
                rank: rows,
                missing: format!(
                    "{} samples x {nv} joints cannot determine {p} unknowns; add samples",
                    self.samples
                ),
            });
        }
        let (r11, z, rho) = self.reduced(sigma)?;
        let mut ls = least_squares(&r11, &z, "base-parameter identification", names)?;
        let s = (rho * rho / (rows - p) as f64).sqrt();
        ls.stderr = DMatrix::from_fn(1, p, |_, j| s * ls.cov_diag[j].sqrt());
        ls.rows = rows;
        ls.residual_rms = DVector::zeros(0);
        Ok(ls)
    }

    /// The weighted problem reduced to `p` rows (`p` the [`JointFactors::unknowns`]):
    /// `|W (Phi_base theta - tau)|^2 = |R11 theta - z|^2 + rho^2` for every `theta`, rows of
    /// joint `j` divided by `sigma[j]`. Returns `(R11 (p x p, upper triangular), z (p x 1),
    /// rho)`.
    pub fn reduced(&self, sigma: &[f64]) -> Result<(DMatrix<f64>, DMatrix<f64>, f64)> {
        let nv = self.factors.len();
        let (p, e) = (self.unknowns(), self.extra);
        if sigma.len() != nv || sigma.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(Error::invalid(
                "sigma",
                format!("expected {nv} positive finite weights, got {sigma:?}"),
            ));
        }
        // every joint's factor, weighted and scattered onto the p base columns and the torque
        let r = triangular_of_stacked(&self.factors, sigma, p + 1, |j, c| {
            let nj = self.active[j].len();
            match c {
                c if c < nj => self.active[j][c],
                c if c < nj + e => self.parameters + j * e + c - nj,
                _ => p,
            }
        });
        // [R11 z; 0 rho]: min |W theta - y| solves R11 theta = z with residual norm |rho|
        let r11 = r.view((0, 0), (p, p)).into_owned();
        let z = r.view((0, p), (p, 1)).into_owned();
        Ok((r11, z, r[(p, p)]))
    }

    /// [`JointFactors::reduced`] with the joints' other unknowns (columns of data, runs'
    /// offsets) minimised over for every `theta` of the `p` base parameters alone:
    /// `min_d |W (Phi theta + X d - tau)|^2 = |R theta - z|^2 + rho^2` (the same as
    /// [`JointFactors::reduced`] where there are none). [`Profiled::others`] gives the `d`
    /// that minimises for a `theta`.
    pub fn profiled(&self, sigma: &[f64]) -> Result<Profiled> {
        let (r11, z, rho) = self.reduced(sigma)?;
        let (p, m) = (self.parameters, self.unknowns() - self.parameters);
        if m == 0 {
            return Ok(Profiled {
                r: r11,
                z,
                rho,
                others: DMatrix::zeros(0, 0),
                coupling: DMatrix::zeros(0, p),
                others_z: DMatrix::zeros(0, 1),
            });
        }
        // [R11 | z] with the others' columns first, and the residual's row: its QR's last
        // p + 1 rows are the problem in theta alone
        let n = p + m;
        let mut a = DMatrix::zeros(n + 1, n + 1);
        for i in 0..n {
            for c in 0..m {
                a[(i, c)] = r11[(i, p + c)];
            }
            for c in 0..p {
                a[(i, m + c)] = r11[(i, c)];
            }
            a[(i, n)] = z[(i, 0)];
        }
        a[(n, n)] = rho;
        let t = triangular(&a);
        Ok(Profiled {
            r: t.view((m, m), (p, p)).into_owned(),
            z: t.view((m, n), (p, 1)).into_owned(),
            rho: t[(n, n)].abs(),
            others: t.view((0, 0), (m, m)).into_owned(),
            coupling: t.view((0, m), (m, p)).into_owned(),
            others_z: t.view((0, n), (m, 1)).into_owned(),
        })
    }

    /// Per-joint RMS over the samples of the unweighted residuals `tau - Phi_base theta` (N m)
    /// for base parameters `theta` (the [`JointFactors::unknowns`], the joints' columns of
    /// data after the base parameters): `|R_j [theta; -1]| / sqrt(K)`.
    pub fn residual_rms(&self, theta: &[f64]) -> Result<Vec<f64>> {
        let (p, e) = (self.unknowns(), self.extra);
        if theta.len() != p {
            return Err(Error::shape(
                "theta",
                format!("{p} base parameters"),
                format!("{} values", theta.len()),
            ));
        }
        let k = self.samples.max(1) as f64;
        let data = &theta[self.parameters..];
        Ok(self
            .factors
            .iter()
            .zip(&self.active)
            .enumerate()
            .map(|(j, (r, active))| {
                let x = DVector::from_iterator(
                    r.ncols(),
                    (active.iter().map(|&c| theta[c]))
                        .chain(data[j * e..(j + 1) * e].iter().copied())
                        .chain([-1.0]),
                );
                (r * x).norm() / k.sqrt()
            })
            .collect())
    }
}

/// The weighted problem in the base parameters alone, the joints' other unknowns minimised
/// over ([`JointFactors::profiled`]).
#[derive(Clone, Debug)]
pub struct Profiled {
    /// `R` (p x p, upper triangular), `z` (p x 1) and `rho`: `|R theta - z|^2 + rho^2`.
    pub r: DMatrix<f64>,
    pub z: DMatrix<f64>,
    pub rho: f64,
    /// The others' block (m x m, upper triangular), their coupling to theta (m x p) and their
    /// right-hand side (m x 1): `others d + coupling theta = others_z` at the minimum.
    others: DMatrix<f64>,
    coupling: DMatrix<f64>,
    others_z: DMatrix<f64>,
}

impl Profiled {
    /// The joints' other unknowns (`m`, in the order of [`JointFactors::unknowns`] after the
    /// base parameters) that minimise the residual for the base parameters `theta` (`p`).
    /// Errors: a `theta` of another length, or others the data do not determine.
    pub fn others(&self, theta: &[f64]) -> Result<Vec<f64>> {
        let p = self.coupling.ncols();
        if theta.len() != p {
            return Err(Error::shape(
                "theta",
                format!("{p} base parameters"),
                format!("{} values", theta.len()),
            ));
        }
        let rhs = &self.others_z - &self.coupling * DMatrix::from_column_slice(p, 1, theta);
        let d = (self.others.rows(0, self.others.nrows()))
            .solve_upper_triangular(&rhs)
            .filter(|d| d.iter().all(|v| v.is_finite()))
            .ok_or_else(|| Error::numerical(
                "base-parameter identification",
                "the data do not determine the joints' other unknowns (runs' offsets, columns of data)",
            ))?;
        Ok(d.iter().copied().collect())
    }
}
