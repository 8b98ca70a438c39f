//! Base parameters: the identifiable linear combinations of the full parameters, found by a
//! column-pivoted QR of the regressor stacked over random states.

use faer::linalg::solvers::ColPivQr;
use faer::Mat;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::parameters::{regressor_matrix, ParameterLayout};
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;

/// The base parameters of a layout: `theta_base = theta[kept] + K theta[dropped]`, and
/// `Phi theta = Phi[:, kept] theta_base` for every state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseParameters {
    pub layout: ParameterLayout,
    /// Indices (ascending) of the full parameters kept as base columns.
    pub kept: Vec<usize>,
    /// Indices (ascending) of the full parameters that are combinations of the kept columns.
    pub dropped: Vec<usize>,
    /// `len(kept) x len(dropped)`: `Phi[:, dropped[d]] = sum_i K[i, d] Phi[:, kept[i]]`.
    #[serde(with = "crate::json::rows")]
    pub k: DMatrix<f64>,
    /// Relative tolerance on `|R_ii| / |R_00|` that decided the rank.
    pub tolerance: f64,
    /// Whether the map is the robot's own, found on states that excite every direction its
    /// kinematics allows ([`Self::from_random_states`]): then it holds at every state and
    /// [`Self::check_on`] checks it against a robot. A map found on data that leave some of
    /// the robot's base parameters unidentified (from local models at a few points) merges
    /// those directions too, and holds only on such data. Files without it: false.
    #[serde(default)]
    pub structural: bool,
}

/// Default relative rank tolerance of the pivoted QR.
pub const BASE_TOLERANCE: f64 = 1e-8;

/// The random states at which [`BaseParameters::check_on`] checks a saved map.
pub const MAP_CHECK_STATES: usize = 3;

/// The largest relative mismatch [`BaseParameters::check_on`] accepts between a dropped column
/// and its combination of kept columns.
pub const MAP_TOLERANCE: f64 = 1e-6;

/// `samples` random states of `model` (row-major `samples x nv` positions, velocities and
/// accelerations; rad, rad/s, rad/s^2), seeded: positions uniform within the limits, or +-pi
/// where unlimited; speeds and accelerations uniform within their limits, or +-1.
fn random_states(model: &Model, samples: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut q, mut qd, mut qdd) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..samples {
        for lim in &model.limits {
            let (lo, hi) = if lim.lower.is_finite() && lim.upper.is_finite() {
                (lim.lower, lim.upper)
            } else {
                (-std::f64::consts::PI, std::f64::consts::PI)
            };
            q.push(rng.random_range(lo..=hi));
            let v = if lim.velocity.is_finite() {
                lim.velocity
            } else {
                1.0
            };
            qd.push(rng.random_range(-v..=v));
            let a = if lim.acceleration.is_finite() {
                lim.acceleration
            } else {
                1.0
            };
            qdd.push(rng.random_range(-a..=a));
        }
    }
    (q, qd, qdd)
}

impl BaseParameters {
    /// Number of base parameters.
    pub fn len(&self) -> usize {
        self.kept.len()
    }

    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// The base parameters of a full parameter vector.
    pub fn from_full(&self, theta: &DVector<f64>) -> Result<DVector<f64>> {
        if theta.len() != self.layout.len() {
            return Err(Error::shape(
                "theta",
                format!("{} full parameters", self.layout.len()),
                format!("{}", theta.len()),
            ));
        }
        let kept = DVector::from_iterator(self.kept.len(), self.kept.iter().map(|&i| theta[i]));
        let dropped =
            DVector::from_iterator(self.dropped.len(), self.dropped.iter().map(|&i| theta[i]));
        Ok(kept + &self.k * dropped)
    }

    /// Names of the base parameters: the kept parameter's name, `+ c * other` for every dropped
    /// parameter merged into it (coefficients below `1e-9` left out).
    pub fn names(&self) -> Vec<String> {
        self.kept
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let mut s = self.layout.names[c].clone();
                for (d, &dc) in self.dropped.iter().enumerate() {
                    let v = self.k[(i, d)];
                    if v.abs() > 1e-9 {
                        s.push_str(&format!(
                            " {} {:.4} {}",
                            if v < 0.0 { '-' } else { '+' },
                            v.abs(),
                            self.layout.names[dc]
                        ));
                    }
                }
                s
            })
            .collect()
    }

    /// The base columns of a full regressor.
    pub fn select(&self, phi: &DMatrix<f64>) -> DMatrix<f64> {
        phi.select_columns(self.kept.iter())
    }

    /// Base parameters of `layout` for `model` from `samples` random states (uniform positions
    /// within the limits, or +-pi where unlimited; speeds and accelerations uniform in +-1 rad/s
    /// and +-1 rad/s^2 scaled to the limits when given), seeded; with or without `gravity`.
    pub fn from_random_states(
        model: &Model,
        layout: &ParameterLayout,
        gravity: Gravity,
        samples: usize,
        tolerance: f64,
        seed: u64,
    ) -> Result<Self> {
        let values = (samples * model.nv) as f64 * layout.len() as f64;
        crate::limits::check_values("base parameters", values, || {
            format!(
                "the regressor of {samples} random states of {} joints and {} parameters (the direct method is for models of up to about 100 joints)",
                model.nv,
                layout.len()
            )
        })?;
        let (q, qd, qdd) = random_states(model, samples, seed);
        let phi = regressor_matrix(
            model,
            layout,
            &States::new(model.nv, &q, Some(&qd), Some(&qdd))?,
            gravity,
        )?;
        Ok(Self {
            structural: true,
            ..Self::from_regressor(layout.clone(), &phi, tolerance)?
        })
    }

    /// Checks that this map is `model`'s (a [`Self::structural`] one; others pass): at
    /// [`MAP_CHECK_STATES`] seeded random states its regressor (with or without `gravity`, as
    /// the map was found) has each dropped column equal to the combination of kept columns
    /// that `k` says, to [`MAP_TOLERANCE`] of the columns' sizes (columns below 1e-6 of the
    /// largest are zeros but for rounding). A map saved from a robot with other kinematics
    /// (the same joint and link names, other lengths or axes) or a hand-edited `k` fails,
    /// naming the worst dropped parameter: base parameters found on one robot mean other
    /// combinations on the other.
    pub fn check_on(&self, model: &Model, gravity: Gravity) -> Result<()> {
        if self.layout.nv != model.nv || self.layout.nbodies != model.nbodies() {
            return Err(Error::invalid(
                "robot",
                format!(
                    "the base parameters are for {} joints and {} bodies, '{}' has {} and {}",
                    self.layout.nv,
                    self.layout.nbodies,
                    model.name,
                    model.nv,
                    model.nbodies()
                ),
            ));
        }
        if self.dropped.is_empty() || !self.structural {
            return Ok(());
        }
        let (q, qd, qdd) = random_states(model, MAP_CHECK_STATES, 0x6d6170);
        let phi = regressor_matrix(
            model,
            &self.layout,
            &States::new(model.nv, &q, Some(&qd), Some(&qdd))?,
            gravity,
        )?;
        let kept = self.select(&phi);
        let norms: Vec<f64> = self.kept.iter().map(|&c| phi.column(c).norm()).collect();
        // a column below this is zero but for rounding (a structural zero)
        let floor = 1e-6 * phi.column_iter().map(|c| c.norm()).fold(0.0, f64::max);
        let worst = self
            .dropped
            .iter()
            .enumerate()
            .map(|(d, &c)| {
                let combination = &kept * self.k.column(d);
                let size = phi.column(c).norm()
                    + (0..self.kept.len())
                        .map(|i| self.k[(i, d)].abs() * norms[i])
                        .sum::<f64>();
                let miss = (phi.column(c) - combination).norm();
                (
                    c,
                    if size > 0.0 {
                        miss / size.max(floor)
                    } else {
                        0.0
                    },
                )
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((c, miss)) if miss > MAP_TOLERANCE || miss.is_nan() => Err(Error::invalid(
                "robot",
                format!(
                    "the saved base parameters do not hold for '{}': its regressor's column '{}' differs from the combination of kept columns the model saved by {} of their size (at most {MAP_TOLERANCE:e} on the robot the model was identified on). Was the model identified on other kinematics (link lengths, axes), or its base.k edited?",
                    model.name,
                    self.layout.names[c],
                    crate::error::shown(miss)
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Base parameters from a stacked regressor `phi` (rows >= columns) by a column-pivoted QR
    /// (faer): a column is kept when `|R_ii| > tolerance |R_00|`.
    pub fn from_regressor(
        layout: ParameterLayout,
        phi: &DMatrix<f64>,
        tolerance: f64,
    ) -> Result<Self> {
        let (m, p) = phi.shape();
        if p != layout.len() || m < p {
            return Err(Error::shape(
                "regressor",
                format!("at least {p} rows and {} columns", layout.len()),
                format!("{m} x {p}"),
            ));
        }
        let a = Mat::<f64>::from_fn(m, p, |i, j| phi[(i, j)]);
        let qr = ColPivQr::new(a.as_ref());
        let r = qr.R();
        let perm: Vec<usize> = qr.P().arrays().0.to_vec();
        let r00 = r[(0, 0)].abs();
        let rank = (0..p)
            .take_while(|&i| r[(i, i)].abs() > tolerance * r00)
            .count();
        if rank == 0 {
            return Err(Error::numerical("base parameters", "the regressor is zero"));
        }
        // K (pivot order) = R11^-1 R12
        let r11 = DMatrix::from_fn(rank, rank, |i, j| if j >= i { r[(i, j)] } else { 0.0 });
        let r12 = DMatrix::from_fn(rank, p - rank, |i, j| r[(i, rank + j)]);
        let kp = r11
            .solve_upper_triangular(&r12)
            .ok_or_else(|| Error::numerical("base parameters", "singular triangular factor"))?;
        let mut kept: Vec<(usize, usize)> = (0..rank).map(|i| (perm[i], i)).collect();
        let mut dropped: Vec<(usize, usize)> = (rank..p).map(|i| (perm[i], i - rank)).collect();
        kept.sort();
        dropped.sort();
        let k = DMatrix::from_fn(rank, p - rank, |i, d| kp[(kept[i].1, dropped[d].1)]);
        Ok(Self {
            layout,
            kept: kept.iter().map(|x| x.0).collect(),
            dropped: dropped.iter().map(|x| x.0).collect(),
            k,
            tolerance,
            structural: false,
        })
    }
}
