//! T* at the planned operating point when the nominal passes missed it.
//!
//! A robot under a position controller misses its plan, and every nominal pass misses the
//! operating point alike (the tracking error repeats with the reference), so averaging the
//! passes does not remove the miss: the mean torque is the torque at the measured point, not
//! at the planned one. The model carries it to the planned point to first order with its own
//! D*, H*, G*: each nominal reading is corrected by
//! `D* (qdd_k - qdd*) + H* (qd_k - qd*) + G* (q_k - q*)` before the mean. Its standard error counts the corrected readings' scatter (torque
//! noise, and the state's measurement noise through the matrices), the matrices' own
//! uncertainty times the mean miss (with their correlation within a row), and the encoder
//! rounding that repeats in every pass. docs/method.md, "Closed-loop identification".

use super::crossing_values::ExperimentValues;
use super::miss::{Miss, MISS_WARNING};
use super::model::LocalModel;
use super::nominal_point::mean_stderr;
use crate::error::Result;
use crate::states::States;

impl LocalModel {
    /// Carries T* from the point the nominal passes `nominal` measured (the model's `op`) to
    /// the planned one, with the model's D*, H*, G*; records the [`Miss`]. `band` marks the
    /// joints whose states were read by the band of their encoder counts (their rounding
    /// repeats in every pass and does not average out) and `rounding` the floor the torque's
    /// logged steps put under T*'s standard error. Nothing changes without D, H or G.
    pub(super) fn carry_to_plan(
        &mut self,
        nominal: &ExperimentValues,
        band: &[bool],
        rounding: &[f64],
    ) -> Result<()> {
        let (Some(d), Some(h), Some(g)) = (&self.d, &self.h, &self.g) else {
            return Ok(());
        };
        let n = self.n();
        let p = &self.planned_op;
        let k = nominal.crossings.len();
        // each reading corrected to the planned point
        let corrected: Vec<Vec<f64>> = (nominal.crossings.iter())
            .map(|c| {
                (0..n)
                    .map(|i| {
                        let mut x = c.tau[i];
                        for j in 0..n {
                            x -= d.matrix[(i, j)] * (c.qdd[j] - p.qdd[j])
                                + h.matrix[(i, j)] * (c.qd[j] - p.qd[j])
                                + g.matrix[(i, j)] * (c.q[j] - p.q[j]);
                        }
                        x
                    })
                    .collect()
            })
            .collect();
        let torque: Vec<f64> = (0..n)
            .map(|i| corrected.iter().map(|c| c[i]).sum::<f64>() / k as f64)
            .collect();
        let correction_stderr = self.correction_stderr()?;
        let mut stderr = Vec::with_capacity(n);
        for i in 0..n {
            let scatter = mean_stderr(corrected.iter().map(|c| c[i]), torque[i], k);
            // encoder rounding that every pass repeats, through the matrices
            let repeated: f64 = (0..n)
                .filter(|&j| band[j])
                .map(|j| {
                    let var = |v: usize| {
                        (nominal.crossings.iter())
                            .map(|c| c.state_stderr[v][j].powi(2))
                            .sum::<f64>()
                            / k as f64
                    };
                    g.matrix[(i, j)].powi(2) * var(0)
                        + h.matrix[(i, j)].powi(2) * var(1)
                        + d.matrix[(i, j)].powi(2) * var(2)
                })
                .sum();
            let se = (scatter.powi(2) + repeated + correction_stderr[i].powi(2)).sqrt();
            stderr.push(if se.is_nan() { se } else { se.max(rounding[i]) });
        }
        let units = |miss: &[f64], size: Option<&Vec<f64>>| -> Vec<f64> {
            (0..n)
                .map(|j| match size.map(|s| s[j]) {
                    Some(s) if s > 0.0 => miss[j] / s,
                    _ => f64::NAN,
                })
                .collect()
        };
        let diff =
            |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x - y).collect() };
        let (mq, mqd, mqdd) = (
            diff(&self.op.q, &p.q),
            diff(&self.op.qd, &p.qd),
            diff(&self.op.qdd, &p.qdd),
        );
        let sizes = self.perturbations.as_ref();
        let miss = Miss {
            q_perturbations: units(&mq, sizes.map(|s| &s.q)),
            qd_perturbations: units(&mqd, sizes.map(|s| &s.qd)),
            qdd_perturbations: units(&mqdd, sizes.map(|s| &s.qdd)),
            q: mq,
            qd: mqd,
            qdd: mqdd,
            correction: (self.torque.iter().zip(&torque))
                .map(|(m, t)| m - t)
                .collect(),
            measured_torque: std::mem::replace(&mut self.torque, torque),
            measured_stderr: std::mem::replace(&mut self.torque_stderr, stderr),
            correction_stderr,
        };
        self.miss = Some(miss);
        Ok(())
    }

    /// The standard error the matrices' uncertainty gives the correction at the mean miss:
    /// [`LocalModel::predict_stderr`] at the measured point without T*'s own.
    fn correction_stderr(&self) -> Result<Vec<f64>> {
        let mut without_t = self.clone();
        without_t.torque_stderr = vec![0.0; self.n()];
        without_t.drive_gains = None;
        let op = &self.op;
        let states = States::new(self.n(), &op.q, Some(&op.qd), Some(&op.qdd))?;
        super::prediction_uncertainty::predict_stderr(&without_t, &states)
    }
}

/// A warning when the nominal passes missed the operating point by more than
/// [`MISS_WARNING`] perturbations somewhere: T* there rests on an extrapolated correction.
pub(super) fn miss_warning(model: &LocalModel) -> Option<String> {
    let miss = model.miss.as_ref()?;
    let (j, var, x) = miss.largest()?;
    (x.abs() > MISS_WARNING).then(|| {
        format!(
            "the nominal passes missed the operating point by up to {:.1} perturbations ({var} of joint '{}'): T* was carried to the planned point with D*, H*, G* to first order, past the region they were identified over; make the passes reach the point (stiffer tracking, or the references shifted against the miss) and identify again",
            x.abs(),
            model.joint_names[j]
        )
    })
}
