//! The local model's regressions: each perturbed experiment's separated fit of its torque
//! changes against its state changes (docs/method.md, section 4), and the combined fit of all
//! of them at once, with the noise, offsets and warnings each finds on the way.

use nalgebra::DMatrix;

use super::diagnostics::TorqueNoise;
use super::errors_in_variables;
use super::identify::{reading_variances, state, ExperimentValues};
use super::model::Estimate;
use super::noise::{nominal_noise, reading_variance, sample_variance, weighted_least_squares};
use super::nominal_point::NominalPoint;
use super::plan::{Experiment, ExperimentKind, Plan};
use super::quantisation;
use super::response;
use super::rounded_positions::{self, Resolution};
use super::torque_offsets::{self, TorqueOffset};
use crate::error::Result;
use crate::regression::LeastSquares;

/// What the regressions found besides their estimates.
pub(super) struct RegressionFindings {
    pub(super) noise: Vec<TorqueNoise>,
    pub(super) warnings: Vec<String>,
    pub(super) offsets: Vec<TorqueOffset>,
}

/// The regressions of one identification, and what they found.
pub(super) struct Regressions<'a> {
    plan: &'a Plan,
    values: &'a [ExperimentValues],
    point: &'a NominalPoint,
    /// The noise from pass to pass the nominal passes show.
    passes: Option<response::PassNoise>,
    /// The torques' noise per experiment and joint (the nominal experiment's first).
    pub(super) noise: Vec<TorqueNoise>,
    pub(super) warnings: Vec<String>,
    /// Torque offsets between an experiment's crossings and T*.
    pub(super) offsets: Vec<TorqueOffset>,
}

impl<'a> Regressions<'a> {
    pub(super) fn new(
        plan: &'a Plan,
        values: &'a [ExperimentValues],
        point: &'a NominalPoint,
    ) -> Self {
        let nominal = point.nominal.map(|i| &values[i]);
        Self {
            plan,
            values,
            point,
            passes: nominal
                .and_then(|v| response::PassNoise::of(v.crossings.iter().map(|c| &c.tau[..]))),
            noise: nominal.map_or(vec![], |v| nominal_noise(v, &plan.joint_names)),
            warnings: vec![],
            offsets: vec![],
        }
    }

    /// What the regressions found, once they are done.
    pub(super) fn findings(self) -> RegressionFindings {
        RegressionFindings {
            noise: self.noise,
            warnings: self.warnings,
            offsets: self.offsets,
        }
    }

    /// The values of experiment `kind`, if the plan has it.
    pub(super) fn find(&self, kind: ExperimentKind) -> Option<&'a ExperimentValues> {
        self.values.iter().find(|v| v.kind == kind)
    }

    fn names(&self, prefix: &str) -> Vec<String> {
        (self.plan.joint_names.iter())
            .map(|j| format!("{prefix}({j})"))
            .collect()
    }

    /// The separated estimate of experiment `kind` (columns named `prefix(joint)`): its torque
    /// changes against the changes of its perturbed variable, from T* and the operating point
    /// (or, for G static, from its reference posture). None where the plan lacks it.
    pub(super) fn separated(
        &mut self,
        kind: ExperimentKind,
        prefix: &str,
    ) -> Result<Option<Estimate>> {
        let Some(v) = self.find(kind) else {
            return Ok(None);
        };
        let n = self.plan.n();
        let var = kind.perturbed().expect("perturbed experiment");
        let k = v.crossings.len();
        let (point, joints) = (self.point, &self.plan.joint_names);
        let (base_tau, base_x): (&[f64], &[f64]) = match &v.reference {
            Some(r) => (&r.tau, &r.q),
            None => (&point.torque, &point.state[var]),
        };
        let base_var: Vec<f64> = match &v.reference {
            Some(r) => r.state_stderr[0].iter().map(|s| s * s).collect(),
            None => point.var[var].clone(),
        };
        let x = DMatrix::from_fn(k, n, |i, j| state(&v.crossings[i], var)[j] - base_x[j]);
        if let Some(j) = (0..n).find(|&j| x.column(j).iter().all(|d| *d == 0.0)) {
            if let Some(step) = v.position_step[j] {
                return Err(rounded_positions::unresolved(
                    kind.name(),
                    (k, n),
                    &format!("{prefix}({})", joints[j]),
                    &joints[j],
                    step,
                    var,
                    v.reference.is_some(),
                ));
            }
        }
        let y = DMatrix::from_fn(k, n, |i, j| v.crossings[i].tau[j] - base_tau[j]);
        let planned = (self.plan.experiment(kind)).expect("values of a planned experiment");
        self.torque_offsets(v, planned, &x, &y, base_tau);
        let (u, samples) = reading_variances(&[v], n);
        let flat = &v.flat_torque;
        let unresolved =
            response::experiment_warning(planned, &x, &y, &u, flat, self.passes.as_ref());
        self.warnings.extend(unresolved);
        let names = self.names(prefix);
        let what = format!("experiment '{}'", kind.name());
        let weighted = weighted_least_squares(&x, &y, &u, &what, &names)?;
        let (mut fit, correlation) = (weighted.fit, weighted.correlation);
        let row_var = DMatrix::from_fn(k, n, |i, j| v.crossings[i].state_stderr[var][j].powi(2));
        errors_in_variables::floor_stderr(&mut fit, &x, &row_var, &base_var)?;
        let resolutions: Vec<Resolution> = (0..n)
            .filter_map(|j| {
                let se: Vec<f64> = v.crossings.iter().map(|c| c.state_stderr[var][j]).collect();
                let dx: Vec<f64> = x.column(j).iter().copied().collect();
                Resolution::of(&joints[j], v.position_step[j]?, &se, &dx)
            })
            .collect();
        self.warnings.extend(rounded_positions::resolution_warning(
            kind.name(),
            var,
            &resolutions,
        ));
        self.torque_noise(v, &mut fit, &samples[0], &weighted.common);
        if kind == ExperimentKind::GStatic {
            self.zeros_at_rest(v, &mut fit, &samples[0]);
        }
        Ok(Some(Estimate::of_fit(fit, correlation)))
    }

    /// The offsets of experiment `v`'s torques from `base_tau` (T* or its reference's), found
    /// as the intercepts of its rows `x`, `y`: swapped or negated columns among them warned of.
    fn torque_offsets(
        &mut self,
        v: &ExperimentValues,
        planned: &Experiment,
        x: &DMatrix<f64>,
        y: &DMatrix<f64>,
        base_tau: &[f64],
    ) {
        let (kind, joints) = (v.kind, &self.plan.joint_names);
        let base_tau_var: Vec<f64> = match &v.reference {
            Some(r) => reading_variance(r, &sample_variance(&v.crossings, self.plan.n())),
            None => self.point.torque_stderr.iter().map(|s| s * s).collect(),
        };
        let mut intercepts = torque_offsets::intercepts(x, y, &base_tau_var);
        // a channel that read one value throughout is reported as unmeasured instead
        for (c, flat) in intercepts.iter_mut().zip(&v.flat_torque) {
            if flat.is_some() {
                *c = None;
            }
        }
        let found = torque_offsets::findings(kind, joints, &intercepts, base_tau);
        let swapped = torque_offsets::swapped_pairs(kind, &found, joints, base_tau);
        let negated = torque_offsets::negated(kind, &found, &swapped, joints, base_tau);
        let symmetric = planned.in_pairs();
        if let Some(w) = torque_offsets::warning(kind, &found, &swapped, &negated, symmetric) {
            self.warnings.push(w);
        }
        self.offsets.extend(found);
    }

    /// Each joint's torque noise in experiment `v` (`samples`: the samples' variance about
    /// their fits, `passes`: the common variance from pass to pass), and the floor a torque
    /// logged in steps coarser than its noise puts under `fit`'s standard errors.
    fn torque_noise(
        &mut self,
        v: &ExperimentValues,
        fit: &mut LeastSquares,
        samples: &[f64],
        passes: &[f64],
    ) {
        let joints = &self.plan.joint_names;
        for (j, ((joint, s2), a)) in joints.iter().zip(samples).zip(passes).enumerate() {
            let step = quantisation::undithered_step(v.torque_step[j], *s2);
            if let Some(q) = step {
                quantisation::floor_stderr(fit, j, quantisation::rounding_stderr(q));
            }
            self.noise.push(TorqueNoise {
                experiment: v.kind.name().to_string(),
                joint: joint.clone(),
                samples: s2.sqrt(),
                passes: Some(a.sqrt()).filter(|v| v.is_finite()),
                step,
                position_step: v.position_step[j],
            });
        }
    }

    /// At rest a torque may read exactly 0 throughout and be kept (a vertical axis, gravity
    /// compensated); one level shows no grid, but when the other torques are rounded, its 0 is
    /// likely a level of one too: its standard errors get the finest step's floor.
    fn zeros_at_rest(&mut self, v: &ExperimentValues, fit: &mut LeastSquares, samples: &[f64]) {
        let n = self.plan.n();
        let finest = (0..n)
            .filter_map(|j| quantisation::undithered_step(v.torque_step[j], samples[j]))
            .min_by(f64::total_cmp);
        let zeros: Vec<usize> = (0..n).filter(|&j| v.flat_torque[j] == Some(0.0)).collect();
        if let (Some(q), false) = (finest, zeros.is_empty()) {
            for &j in &zeros {
                quantisation::floor_stderr(fit, j, quantisation::rounding_stderr(q));
            }
            let names: Vec<&str> = (zeros.iter())
                .map(|&j| self.plan.joint_names[j].as_str())
                .collect();
            (self.warnings).push(quantisation::flat_zero_warning(v.kind.name(), &names, q));
        }
    }

    /// The combined estimate: the nominal, G, H and D crossings stacked against
    /// `[dqdd dqd dq]` from the operating point, in one fit.
    pub(super) fn combined(&self) -> Result<Estimate> {
        let (n, point) = (self.plan.n(), self.point);
        let stacked: Vec<&ExperimentValues> = (self.values.iter())
            .filter(|v| v.kind != ExperimentKind::GStatic)
            .collect();
        let rows: Vec<_> = stacked.iter().flat_map(|v| v.crossings.iter()).collect();
        let x = DMatrix::from_fn(rows.len(), 3 * n, |i, c| {
            let var = 2 - c / n; // columns: dqdd, dqd, dq
            state(rows[i], var)[c % n] - point.state[var][c % n]
        });
        let y = DMatrix::from_fn(rows.len(), n, |i, j| rows[i].tau[j] - point.torque[j]);
        let columns: Vec<String> =
            [self.names("dqdd"), self.names("dqd"), self.names("dq")].concat();
        let (u, samples) = reading_variances(&stacked, n);
        let weighted =
            weighted_least_squares(&x, &y, &u, "combined estimate (nominal, G, H, D)", &columns)?;
        let (mut fit, correlation) = (weighted.fit, weighted.correlation);
        let row_var = DMatrix::from_fn(rows.len(), 3 * n, |i, c| {
            rows[i].state_stderr[2 - c / n][c % n].powi(2)
        });
        let base_var: Vec<f64> = (0..3 * n).map(|c| point.var[2 - c / n][c % n]).collect();
        errors_in_variables::floor_stderr(&mut fit, &x, &row_var, &base_var)?;
        for j in 0..n {
            // the coarsest step any of the stacked experiments read this torque in, undithered
            let step = (stacked.iter().zip(&samples))
                .filter_map(|(v, s2)| quantisation::undithered_step(v.torque_step[j], s2[j]))
                .fold(None, |a: Option<f64>, q| Some(a.map_or(q, |a| a.max(q))));
            if let Some(q) = step {
                quantisation::floor_stderr(&mut fit, j, quantisation::rounding_stderr(q));
            }
        }
        Ok(Estimate::of_fit(fit, correlation))
    }
}
