//! The operating point `P = (q*, qd*, qdd*)` at which the local model is identified.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::{check_finite_vector, Model};

/// An operating point: joint positions `q` (rad or m), velocities `qd` (rad/s or m/s) and
/// accelerations `qdd` (rad/s^2 or m/s^2), each of length N (the robot's degrees of freedom).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperatingPoint {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl OperatingPoint {
    /// Checks that the three vectors have the same length and finite entries.
    ///
    /// ```
    /// use perturbid_rs::OperatingPoint;
    /// let op = OperatingPoint::new(vec![0.1, 0.2], vec![0.0, 0.5], vec![1.0, 0.0])?;
    /// assert_eq!(op.n(), 2);
    /// assert!(OperatingPoint::new(vec![0.1], vec![0.0, 0.5], vec![1.0]).is_err()); // lengths differ
    /// # Ok::<(), perturbid_rs::Error>(())
    /// ```
    pub fn new(q: Vec<f64>, qd: Vec<f64>, qdd: Vec<f64>) -> Result<Self> {
        let n = q.len();
        if n == 0 {
            return Err(Error::invalid(
                "q",
                "an operating point needs at least one joint",
            ));
        }
        check_finite_vector("q", &q, n)?;
        check_finite_vector("qd", &qd, n)?;
        check_finite_vector("qdd", &qdd, n)?;
        Ok(Self { q, qd, qdd })
    }

    /// Number of joints.
    pub fn n(&self) -> usize {
        self.q.len()
    }

    /// Checks that the point fits `model`: N entries, the posture inside the position limits,
    /// the speeds and accelerations inside their limits.
    pub fn check(&self, model: &Model) -> Result<()> {
        model.check_vector("operating point q", &self.q)?;
        model.check_vector("operating point qd", &self.qd)?;
        model.check_vector("operating point qdd", &self.qdd)?;
        for (j, lim) in model.limits.iter().enumerate() {
            let name = &model.joint_names[j];
            let bad = |what: &str, value: f64, range: String| {
                Error::invalid(
                    format!("operating point {what}[{j}] (joint '{name}')"),
                    format!("{} is outside {range}", crate::error::shown(value)),
                )
            };
            if self.q[j] < lim.lower || self.q[j] > lim.upper {
                return Err(bad(
                    "q",
                    self.q[j],
                    format!("the position limits [{}, {}]", lim.lower, lim.upper),
                ));
            }
            if self.qd[j].abs() > lim.velocity {
                return Err(bad(
                    "qd",
                    self.qd[j],
                    format!("the velocity limit +-{}", lim.velocity),
                ));
            }
            if self.qdd[j].abs() > lim.acceleration {
                return Err(bad(
                    "qdd",
                    self.qdd[j],
                    format!("the acceleration limit +-{}", lim.acceleration),
                ));
            }
        }
        Ok(())
    }
}
