//! How far the nominal passes missed the planned operating point ([`Miss`]).
//!
//! Every nominal pass of a tracking robot misses the operating point alike, so the mean torque
//! over them is the torque at the measured point; the model keeps how far it was and what
//! carried T* to the planned point (docs/method.md, "Closed-loop identification").

use serde::{Deserialize, Serialize};

use crate::error::Result;

/// How far the nominal passes missed the planned operating point, and what that did to T*.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Miss {
    /// Per joint, the mean state at the nominal crossings less the planned operating point
    /// (rad, rad/s, rad/s^2; m for a prismatic joint).
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// The same in units of the largest perturbation the experiments gave each joint's
    /// variable ([`super::LocalModel::perturbations`]): past 1 the correction extrapolates beyond the
    /// region the matrices were identified over. NaN (`null`) where that perturbation is 0.
    #[serde(with = "crate::json::stderr_vec")]
    pub q_perturbations: Vec<f64>,
    #[serde(with = "crate::json::stderr_vec")]
    pub qd_perturbations: Vec<f64>,
    #[serde(with = "crate::json::stderr_vec")]
    pub qdd_perturbations: Vec<f64>,
    /// Per joint, the standard errors of the measured `q`, `qd`, `qdd` miss (the positions'
    /// reading error, counting what every pass repeats, see [`super::repeated_reading`]):
    /// below about 3 of them a miss may be the measurement's own error, which no refinement
    /// removes. Empty for a model saved before they were stored.
    #[serde(default, with = "crate::json::stderr_vec")]
    pub q_stderr: Vec<f64>,
    #[serde(default, with = "crate::json::stderr_vec")]
    pub qd_stderr: Vec<f64>,
    #[serde(default, with = "crate::json::stderr_vec")]
    pub qdd_stderr: Vec<f64>,
    /// Per joint, which of its `[q, qd, qdd]` misses were corrected: those beyond
    /// 3 standard errors of their measurement (a
    /// smaller one may be the measurement's own error; its possible size counts in T*'s
    /// standard error instead).
    pub corrected: Vec<[bool; 3]>,
    /// The mean torque at the nominal crossings (N m): the torque at the measured point.
    pub measured_torque: Vec<f64>,
    /// Its standard error from the readings' scatter (N m), which counts noise only: as an
    /// estimate of T* at the planned point it is off by the correction.
    #[serde(with = "crate::json::stderr_vec")]
    pub measured_stderr: Vec<f64>,
    /// The correction `D* dqdd + H* dqd + G* dq` at the mean miss (its corrected components),
    /// subtracted from
    /// `measured_torque` to give the model's `torque` (N m).
    pub correction: Vec<f64>,
    /// The part of the model's `torque_stderr` that the matrices' uncertainty gives the
    /// correction (N m); NaN where a weighted entry's standard error is unknown.
    #[serde(with = "crate::json::stderr_vec")]
    pub correction_stderr: Vec<f64>,
}

/// Misses past this many perturbations are named in a warning: the first-order correction
/// extrapolates past the region its matrices were identified over.
pub const MISS_WARNING: f64 = 1.0;

impl Miss {
    /// The largest miss in perturbation units: `(joint, variable name, value)`.
    pub fn largest(&self) -> Option<(usize, &'static str, f64)> {
        largest_of([
            &self.q_perturbations,
            &self.qd_perturbations,
            &self.qdd_perturbations,
        ])
    }

    /// The miss of `q`, `qd`, `qdd` per joint in units of its standard errors; empty for a
    /// model saved before they were stored.
    pub fn in_stderr(&self) -> [Vec<f64>; 3] {
        let z = |x: &[f64], s: &[f64]| -> Vec<f64> {
            match s.len() == x.len() {
                true => x.iter().zip(s).map(|(x, s)| x / s).collect(),
                false => vec![],
            }
        };
        [
            z(&self.q, &self.q_stderr),
            z(&self.qd, &self.qd_stderr),
            z(&self.qdd, &self.qdd_stderr),
        ]
    }

    /// The largest miss in units of its standard errors: `(joint, variable name, value)`;
    /// None for a model saved before they were stored.
    pub fn largest_in_stderr(&self) -> Option<(usize, &'static str, f64)> {
        let [q, qd, qdd] = self.in_stderr();
        largest_of([&q, &qd, &qdd])
    }

    /// Checks a stored miss of `n` joints (`what` names the document).
    pub(crate) fn check(&self, what: &str, n: usize) -> Result<()> {
        if self.corrected.len() != n {
            return Err(crate::document::invalid(
                what,
                format!(
                    "miss.corrected has {} entries for {n} joints",
                    self.corrected.len()
                ),
            ));
        }
        for (field, v) in [
            ("q", &self.q),
            ("qd", &self.qd),
            ("qdd", &self.qdd),
            ("q_perturbations", &self.q_perturbations),
            ("qd_perturbations", &self.qd_perturbations),
            ("qdd_perturbations", &self.qdd_perturbations),
            ("measured_torque", &self.measured_torque),
            ("measured_stderr", &self.measured_stderr),
            ("correction", &self.correction),
            ("correction_stderr", &self.correction_stderr),
        ] {
            if v.len() != n {
                return Err(crate::document::invalid(
                    what,
                    format!("miss.{field} has {} entries for {n} joints", v.len()),
                ));
            }
            crate::document::check_bounded(what, "a local model", &format!("miss.{field}"), v)?;
        }
        for (field, v) in [
            ("q_stderr", &self.q_stderr),
            ("qd_stderr", &self.qd_stderr),
            ("qdd_stderr", &self.qdd_stderr),
        ] {
            if !v.is_empty() && v.len() != n {
                return Err(crate::document::invalid(
                    what,
                    format!("miss.{field} has {} entries for {n} joints", v.len()),
                ));
            }
            crate::document::check_magnitudes(what, &format!("miss.{field}"), v, true)?;
        }
        crate::document::check_magnitudes(
            what,
            "miss.measured_stderr",
            &self.measured_stderr,
            true,
        )?;
        crate::document::check_magnitudes(
            what,
            "miss.correction_stderr",
            &self.correction_stderr,
            true,
        )
    }
}

/// The entry of largest magnitude among the finite ones of `parts` (`q`, `qd`, `qdd`, one
/// value per joint): `(joint, variable name, value)`.
fn largest_of(parts: [&[f64]; 3]) -> Option<(usize, &'static str, f64)> {
    let mut best: Option<(usize, &'static str, f64)> = None;
    for (name, v) in ["q", "qd", "qdd"].into_iter().zip(parts) {
        for (j, &x) in v.iter().enumerate().filter(|(_, x)| x.is_finite()) {
            if best.is_none_or(|b| x.abs() > b.2.abs()) {
                best = Some((j, name, x));
            }
        }
    }
    best
}
