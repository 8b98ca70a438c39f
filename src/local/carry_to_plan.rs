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

/// A miss component is corrected where it exceeds this many standard errors of its measurement.
pub const SIGNIFICANT_MISS: f64 = 3.0;

impl LocalModel {
    /// Carries T* from the point the nominal passes `nominal` measured (the model's `op`) to
    /// the planned one, with the model's D*, H*, G*; records the [`Miss`]. `var` is the
    /// variance of the measured point's error per variable (`q`, `qd`, `qdd`) and joint: a
    /// component of the miss within [`SIGNIFICANT_MISS`] of its standard error is not
    /// corrected (a measurement error of the point, which positions rounded alike in every
    /// pass need not average out of, would enter T* whole), and its possible size counts in
    /// T*'s standard error instead. `common` is the part of `var` every pass repeats (encoder
    /// rounding alike in every pass, see [`super::repeated_reading`]): a corrected reading
    /// keeps it whole. `rounding` is the floor the torque's logged steps put under T*'s
    /// standard error. Nothing changes without D, H or G.
    pub(super) fn carry_to_plan(
        &mut self,
        nominal: &ExperimentValues,
        var: &[Vec<f64>; 3],
        common: &[Vec<f64>; 3],
        rounding: &[f64],
    ) -> Result<()> {
        let (Some(d), Some(h), Some(g)) = (&self.d, &self.h, &self.g) else {
            return Ok(());
        };
        let n = self.n();
        let p = &self.planned_op;
        let planned = [&p.q, &p.qd, &p.qdd];
        let measured = [&self.op.q, &self.op.qd, &self.op.qdd];
        let miss: [Vec<f64>; 3] =
            std::array::from_fn(|v| (0..n).map(|j| measured[v][j] - planned[v][j]).collect());
        let corrected: Vec<[bool; 3]> = (0..n)
            .map(|j| {
                std::array::from_fn(|v| miss[v][j].abs() > SIGNIFICANT_MISS * var[v][j].sqrt())
            })
            .collect();
        let coef = |i: usize, v: usize, j: usize| match v {
            0 => g.matrix[(i, j)],
            1 => h.matrix[(i, j)],
            _ => d.matrix[(i, j)],
        };
        // each reading carried to the planned point along the corrected components
        let k = nominal.crossings.len();
        let readings: Vec<Vec<f64>> = (nominal.crossings.iter())
            .map(|c| {
                let state = [&c.q, &c.qd, &c.qdd];
                (0..n)
                    .map(|i| {
                        let mut x = c.tau[i];
                        for (j, fixed) in corrected.iter().enumerate() {
                            for v in (0..3).filter(|&v| fixed[v]) {
                                x -= coef(i, v, j) * (state[v][j] - planned[v][j]);
                            }
                        }
                        x
                    })
                    .collect()
            })
            .collect();
        let torque: Vec<f64> = (0..n)
            .map(|i| readings.iter().map(|c| c[i]).sum::<f64>() / k as f64)
            .collect();
        let correction_stderr = self.correction_stderr(&miss, &corrected)?;
        let stderr = (0..n)
            .map(|i| {
                let scatter = mean_stderr(readings.iter().map(|c| c[i]), torque[i], k);
                let mut variance = scatter.powi(2) + correction_stderr[i].powi(2);
                for (j, fixed) in corrected.iter().enumerate() {
                    for v in 0..3 {
                        // the possible size of a component left uncorrected; the error every
                        // pass repeats, through a corrected one
                        let part = if fixed[v] { common[v][j] } else { var[v][j] };
                        variance += coef(i, v, j).powi(2) * part;
                    }
                }
                let se = variance.sqrt();
                if se.is_nan() {
                    se
                } else {
                    se.max(rounding[i])
                }
            })
            .collect();
        let units = |v: usize, size: Option<&Vec<f64>>| -> Vec<f64> {
            (0..n)
                .map(|j| match size.map(|s| s[j]) {
                    Some(s) if s > 0.0 => miss[v][j] / s,
                    _ => f64::NAN,
                })
                .collect()
        };
        let sizes = self.perturbations.as_ref();
        let [q_perturbations, qd_perturbations, qdd_perturbations] = [
            units(0, sizes.map(|s| &s.q)),
            units(1, sizes.map(|s| &s.qd)),
            units(2, sizes.map(|s| &s.qdd)),
        ];
        let [mq, mqd, mqdd] = miss;
        self.miss = Some(Miss {
            q: mq,
            qd: mqd,
            qdd: mqdd,
            q_perturbations,
            qd_perturbations,
            qdd_perturbations,
            q_stderr: var[0].iter().map(|v| v.sqrt()).collect(),
            qd_stderr: var[1].iter().map(|v| v.sqrt()).collect(),
            qdd_stderr: var[2].iter().map(|v| v.sqrt()).collect(),
            corrected,
            correction: (self.torque.iter().zip(&torque))
                .map(|(m, t)| m - t)
                .collect(),
            measured_torque: std::mem::replace(&mut self.torque, torque),
            measured_stderr: std::mem::replace(&mut self.torque_stderr, stderr),
            correction_stderr,
        });
        Ok(())
    }

    /// The standard error the matrices' uncertainty gives the correction at the mean miss
    /// along its `corrected` components: [`LocalModel::predict_stderr`] there without T*'s
    /// own.
    fn correction_stderr(&self, miss: &[Vec<f64>; 3], corrected: &[[bool; 3]]) -> Result<Vec<f64>> {
        let n = self.n();
        let p = &self.planned_op;
        let at = |v: usize, base: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|j| base[j] + if corrected[j][v] { miss[v][j] } else { 0.0 })
                .collect()
        };
        let (q, qd, qdd) = (at(0, &p.q), at(1, &p.qd), at(2, &p.qdd));
        let states = States::new(n, &q, Some(&qd), Some(&qdd))?;
        super::prediction_uncertainty::stderr_of_prediction(self, &states, false)
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
