//! The identified local model `tau ~= T* + D* dqdd + H* dqd + G* dq` near the operating point,
//! with its uncertainty; saved as JSON.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::diagnostics::Diagnostics;
use super::reach::{Extrapolation, Perturbations};
use crate::choice::choice;
use crate::document::{
    check_bounded, check_bounded_rows, check_condition, check_correlation, check_magnitude,
    check_magnitude_rows, check_magnitudes, invalid, Document,
};
use crate::error::{Error, Result};
use crate::operating_point::OperatingPoint;
use crate::regression::LeastSquares;
use crate::states::States;
use crate::torque_model::predict_linear;
use crate::torque_model::{torque_at, Expansion, TorqueModel};

/// One identified matrix with its statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Estimate {
    /// N x N (row = torque, column = joint); N x 3N `[D H G]` for the combined estimate.
    #[serde(with = "crate::json::rows")]
    pub matrix: DMatrix<f64>,
    /// cond(X) of the design, columns scaled to unit norm (see [`crate::regression`]).
    pub cond: f64,
    /// Per-joint RMS of the regression residuals (N m).
    pub residual_rms: Vec<f64>,
    /// Standard error of every entry of `matrix` (same shape); NaN (`null` in JSON) where the
    /// regression had no residual degree of freedom.
    #[serde(with = "crate::json::stderr_rows")]
    pub stderr: DMatrix<f64>,
    /// Crossings (rows) used.
    pub crossings: usize,
    /// Per row of `matrix` (torque), the correlation of its entries (m x m for m columns, unit
    /// diagonal): with the row's standard errors `se`, `diag(se) R diag(se)` is its covariance,
    /// which [`LocalModel::predict_stderr`] needs. The design's under the row's weights;
    /// floors raised on the standard errors (errors in variables, quantisation) keep it.
    /// Empty in a model saved before it was stored.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        with = "crate::json::matrices"
    )]
    pub correlation: Vec<DMatrix<f64>>,
}

impl Estimate {
    /// The estimate of a weighted fit whose standard errors may have been floored since: `fit`,
    /// with the correlation of each output's coefficients `correlation` (one per output).
    pub(crate) fn of_fit(fit: LeastSquares, correlation: Vec<DMatrix<f64>>) -> Self {
        Self {
            cond: fit.cond,
            residual_rms: fit.residual_rms.iter().copied().collect(),
            crossings: fit.rows,
            matrix: fit.coef,
            stderr: fit.stderr,
            correlation,
        }
    }

    /// Columns `first..first + count` of the estimate (a block `D`, `H` or `G` of the combined
    /// one), with the correlations among them; the fit's statistics as they are.
    pub(crate) fn columns(&self, first: usize, count: usize) -> Self {
        Self {
            matrix: self.matrix.columns(first, count).into_owned(),
            stderr: self.stderr.columns(first, count).into_owned(),
            cond: self.cond,
            residual_rms: self.residual_rms.clone(),
            crossings: self.crossings,
            correlation: (self.correlation.iter())
                .map(|r| r.view((first, first), (count, count)).into_owned())
                .collect(),
        }
    }
}

choice! {
    /// Which estimate fills `D`, `H` and `G`.
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum Estimator ("estimator") {
        /// One regression per experiment with its own perturbed variable (the paper).
        Separated = "separated",
        /// All crossings stacked, `Gamma = [D H G] [dqdd; dqd; dq]`, with the measured deltas of
        /// every variable (absorbs tracking errors; docs/method.md, section 4).
        Combined = "combined",
    }
}

/// The Coulomb friction steps of the joints, from the friction-aware H regression: for joint
/// `j`, the jump of its friction torque where its velocity changes sign (N m: the Coulomb level
/// for positive speeds plus the one for negative speeds, twice the level when symmetric).
/// `None` for a joint that no pair of H passes reversed (not identifiable from the data).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoulombSteps {
    pub joint_names: Vec<String>,
    pub step: Vec<Option<f64>>,
    /// Standard error of each step (N m).
    pub stderr: Vec<Option<f64>>,
}

/// The local model at an operating point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LocalModel {
    pub format: String,
    pub robot: String,
    pub joint_names: Vec<String>,
    /// The operating point as measured at the nominal crossings (mean): how closely the
    /// robot followed the plan (a diagnostic; noisier than the plan it estimates).
    pub op: OperatingPoint,
    /// The operating point the plan asked for, which the nominal passes crossed: `torque`
    /// holds there and predictions are deltas from it.
    pub planned_op: OperatingPoint,
    pub estimator: Estimator,
    /// `T*` (N m): the torque at the planned operating point, the mean torque at the nominal
    /// crossings carried there from the point they measured by D*, H*, G* ([`Self::miss`]).
    pub torque: Vec<f64>,
    /// Standard error of `T*`: the scatter of the carried readings / sqrt(K), with what the
    /// matrices' uncertainty and repeated encoder rounding give the carrying; NaN (`null` in
    /// JSON) with one nominal crossing.
    #[serde(with = "crate::json::stderr_vec")]
    pub torque_stderr: Vec<f64>,
    /// `D*`, `H*`, `G*` (dynamic) and `Gs` (static), when their experiment was run.
    pub d: Option<Estimate>,
    pub h: Option<Estimate>,
    pub g: Option<Estimate>,
    pub g_static: Option<Estimate>,
    /// The combined estimate `[D H G]` (N x 3N), when the G, H and D experiments were run.
    pub combined: Option<Estimate>,
    /// The Coulomb steps found by the friction-aware H regression
    /// ([`crate::local::IdentifyOptions::friction_aware_h`]), when it was used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coulomb: Option<CoulombSteps>,
    /// The largest perturbation of each joint's `q`, `qd` and `qdd` the experiments gave: the
    /// region the linear expansion was identified over ([`Self::reach`]). `None` in a model
    /// saved before it was stored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub perturbations: Option<Perturbations>,
    /// What happened during the identification: clock offsets, velocity reversals near
    /// crossings, warnings (see [`Diagnostics`]).
    #[serde(default)]
    pub diagnostics: Diagnostics,
    /// The drive gains the recordings' signal was multiplied by, where they logged motor
    /// currents (`perturbid identify --gains-from`): the model is in torques, and the gains'
    /// standard errors enter its predictions' ([`Self::predict_stderr`]), not its
    /// coefficients'. None for recordings of torques.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_gains: Option<SignalGains>,
    /// How far the nominal passes missed the planned operating point, and the correction that
    /// carried T* to it ([`super::miss`]). `None` without the G, H and D experiments (T* is
    /// then the mean at the nominal crossings), or in a model saved before it was stored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub miss: Option<super::miss::Miss>,
}

/// The drive gains a local model's recordings were put in torques by ([`LocalModel::drive_gains`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SignalGains {
    /// Per joint, N m (or N) per unit of the signal (`crate::direct::DriveGains::gain`).
    pub gain: Vec<f64>,
    /// Their standard errors.
    pub stderr: Vec<f64>,
}

impl From<&crate::direct::DriveGains> for SignalGains {
    /// The gains of a drive-gain identification and their standard errors.
    fn from(g: &crate::direct::DriveGains) -> Self {
        Self {
            gain: g.gain.clone(),
            stderr: g.stderr.clone(),
        }
    }
}

impl SignalGains {
    /// Checks `n` gains, finite, other than 0 and bounded, and their standard errors.
    fn check(&self, what: &str, n: usize) -> Result<()> {
        for (field, len) in [("gain", self.gain.len()), ("stderr", self.stderr.len())] {
            if len != n {
                return Err(invalid(
                    what,
                    format!("drive_gains.{field} has {len} entries, expected one per joint ({n})"),
                ));
            }
        }
        if let Some(j) = self.gain.iter().position(|g| *g == 0.0) {
            return Err(invalid(
                what,
                format!("drive_gains.gain[{j}] is 0, expected a gain other than 0"),
            ));
        }
        check_bounded(what, "drive gains", "drive_gains.gain", &self.gain)?;
        check_magnitudes(what, "drive_gains.stderr", &self.stderr, false)?;
        check_bounded(what, "drive gains", "drive_gains.stderr", &self.stderr)
    }
}

impl LocalModel {
    /// Number of joints.
    pub fn n(&self) -> usize {
        self.torque.len()
    }

    fn part<'a>(e: &'a Option<Estimate>, name: &str) -> Result<&'a DMatrix<f64>> {
        e.as_ref().map(|e| &e.matrix).ok_or_else(|| {
            Error::invalid(
                "predict",
                format!("the model has no {name}: its plan had no {name} experiment"),
            )
        })
    }

    /// Predicted torques (row-major `k x N`, N m) at the `k` samples of `states`:
    /// `T* + D* (qdd - qdd*) + H* (qd - qd*) + G* (q - q*)`, expanded about the planned
    /// operating point: the robot passed it at every nominal crossing and T* is the torque
    /// there. The point measured at the nominal crossings (`op`) is an estimate of it whose
    /// noise (encoder quantisation reaches qdd through two derivatives) would enter every
    /// prediction; it is kept as a diagnostic.
    pub fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        let parts = [
            Self::part(&self.d, "D")?,
            Self::part(&self.h, "H")?,
            Self::part(&self.g, "G")?,
        ];
        predict_linear(states, &self.torque, parts, &self.planned_op)
    }

    /// Per sample of `states` (`k` values), its largest deviation from the planned operating
    /// point over the joints and `q`, `qd`, `qdd`, in units of the largest perturbation the
    /// experiments gave that joint's variable ([`super::reach`]): at most 1 inside the region
    /// the model was identified over. Refused for a model saved before its perturbations were
    /// stored (identify it again).
    pub fn reach(&self, states: &States<'_>) -> Result<Vec<f64>> {
        let p = self.perturbations.as_ref().ok_or_else(|| {
            Error::invalid(
                "reach",
                "the model was saved before its perturbations were stored: identify it again",
            )
        })?;
        Ok(Extrapolation::of(p, &self.planned_op, &self.joint_names, states)?.0)
    }

    /// Where the samples of `states` leave the region the model was identified over (reach
    /// above [`super::REACH_LIMIT`]): `None` when none does, or when the model does not store
    /// its perturbations (saved before they were). What predictions there rest on is
    /// [`Extrapolation::message`].
    pub fn extrapolation(&self, states: &States<'_>) -> Result<Option<Extrapolation>> {
        match &self.perturbations {
            Some(p) => Ok(Extrapolation::of(p, &self.planned_op, &self.joint_names, states)?.1),
            None => Ok(None),
        }
    }

    /// The torque noise of the nominal passes, per joint in `joint_names`' order (N m, or N
    /// for a prismatic joint): the samples' standard deviation about their windows' fits, and
    /// what the readings scattered by from pass to pass beyond it (0 where not estimated: fewer
    /// than 2 nominal crossings), from [`Diagnostics::noise`]: what the planner's prediction
    /// takes as [`super::PlanOptions::torque_noise`] and
    /// [`super::PlanOptions::torque_pass_noise`] for the robot's next plan. A joint whose
    /// samples scatter less than 1e-9 N m (rounding: data without noise) gets 0 for both. Refused when a joint
    /// has no nominal entry (a plan without a nominal experiment, or a model identified before
    /// they were reported) or two.
    pub fn nominal_noise(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let nominal = super::ExperimentKind::Nominal.name();
        let mut samples = Vec::with_capacity(self.joint_names.len());
        let mut passes = Vec::with_capacity(self.joint_names.len());
        for joint in &self.joint_names {
            let found: Vec<&super::TorqueNoise> = (self.diagnostics.noise.iter())
                .filter(|e| e.experiment == nominal && &e.joint == joint)
                .collect();
            let [entry] = found[..] else {
                return Err(Error::invalid(
                    "diagnostics.noise",
                    format!(
                        "the local model of '{}' has {} entries of the nominal passes' noise for joint '{joint}'; expected one (a model identified from a plan with a nominal experiment, by a version that reports it)",
                        self.robot,
                        found.len()
                    ),
                ));
            };
            let noisy = entry.samples >= 1e-9;
            samples.push(if noisy { entry.samples } else { 0.0 });
            passes.push(if noisy {
                entry.passes.unwrap_or(0.0)
            } else {
                0.0
            });
        }
        Ok((samples, passes))
    }

    /// [`Self::nominal_noise`] pooled over several identifications of one robot's joints (the
    /// same `joint_names`, in order): per joint the root mean square of each model's samples'
    /// noise and of its noise from pass to pass, every model weighted alike. One
    /// identification's nominal noise has `K - 1` degrees of freedom a joint (11 by default),
    /// so a plan predicted from it alone is optimistic where a joint's noise came out low; a
    /// few pooled give the planner a steadier number. Refused without models, with models of
    /// other joints (naming the first that differs, by index), without nominal entries, or
    /// when a joint is noise-free in one model and noisy in another (a simulation without
    /// noise among a robot's identifications: its zeros would pull the pool down unseen).
    pub fn pooled_nominal_noise(models: &[&LocalModel]) -> Result<(Vec<f64>, Vec<f64>)> {
        Self::pool_nominal_noise(models, |i| format!("models[{i}]"))
    }

    /// [`Self::pooled_nominal_noise`] with `name(i)` naming model `i` in its errors (a file
    /// on the command line).
    pub(crate) fn pool_nominal_noise(
        models: &[&LocalModel],
        name: impl Fn(usize) -> String,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        let Some(first) = models.first() else {
            return Err(Error::invalid(
                "models",
                "no local model to pool the nominal noise of; expected at least one",
            ));
        };
        let n = first.joint_names.len();
        let (mut samples, mut passes) = (vec![0.0; n], vec![0.0; n]);
        // per joint the first model read without noise and the first read with it
        let (mut quiet, mut noisy) = (vec![None; n], vec![None; n]);
        for (i, m) in models.iter().enumerate() {
            if m.joint_names != first.joint_names {
                return Err(Error::invalid(
                    name(i),
                    format!(
                        "a local model of joints [{}] of '{}'; {} is of [{}] of '{}': pool identifications of one robot's joints",
                        m.joint_names.join(", "),
                        m.robot,
                        name(0),
                        first.joint_names.join(", "),
                        first.robot
                    ),
                ));
            }
            let (s, p) = m
                .nominal_noise()
                .map_err(|e| Error::invalid(name(i), e.to_string()))?;
            for j in 0..n {
                samples[j] += s[j] * s[j];
                passes[j] += p[j] * p[j];
                let seen = if s[j] == 0.0 {
                    &mut quiet[j]
                } else {
                    &mut noisy[j]
                };
                seen.get_or_insert((i, s[j]));
                if let (Some((q, _)), Some((k, level))) = (quiet[j], noisy[j]) {
                    return Err(Error::invalid(
                        name(q.max(k)),
                        format!(
                            "{} read no torque noise in the nominal passes at joint '{}' (data without noise: a simulation?) and {} read {level:.3e}; pool identifications of one robot's recordings",
                            name(q),
                            first.joint_names[j],
                            name(k)
                        ),
                    ));
                }
            }
        }
        let rms = |v: Vec<f64>| -> Vec<f64> {
            v.into_iter()
                .map(|s| (s / models.len() as f64).sqrt())
                .collect()
        };
        Ok((rms(samples), rms(passes)))
    }
}

impl Document for LocalModel {
    const FORMAT: &'static str = "perturbid-local-model";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "local model";

    /// Checks every shape against the number of joints, and that standard errors and
    /// residuals are magnitudes (`>= 0`, or unknown) and condition numbers at least 1.
    fn validate(&self) -> Result<()> {
        self.validate_point()?;
        self.validate_estimates()?;
        self.validate_diagnostics()
    }
}

impl LocalModel {
    /// T*, the operating points and the per-joint parts: one entry a joint, within bounds.
    fn validate_point(&self) -> Result<()> {
        let m = self;
        let bad = |message: String| invalid(Self::WHAT, message);
        let n = m.n();
        for (what, len) in [
            ("joint_names", m.joint_names.len()),
            ("torque_stderr", m.torque_stderr.len()),
            ("op.q", m.op.q.len()),
            ("op.qd", m.op.qd.len()),
            ("op.qdd", m.op.qdd.len()),
            ("planned_op.q", m.planned_op.q.len()),
            ("planned_op.qd", m.planned_op.qd.len()),
            ("planned_op.qdd", m.planned_op.qdd.len()),
        ] {
            if len != n {
                return Err(bad(format!("{what} has {len} entries, torque has {n}")));
            }
        }
        // standard errors and residuals are magnitudes: unknown (NaN, `null`) or >= 0
        check_magnitudes(Self::WHAT, "torque_stderr", &m.torque_stderr, true)?;
        crate::document::check_joint_names(Self::WHAT, &m.joint_names)?;
        if let Some(p) = &m.perturbations {
            p.check(Self::WHAT, n)?;
        }
        if let Some(g) = &m.drive_gains {
            g.check(Self::WHAT, n)?;
        }
        if let Some(miss) = &m.miss {
            miss.check(Self::WHAT, n)?;
        }
        // and no number beyond any robot's
        let kind = "a local model";
        for (field, v) in [
            ("torque", &m.torque),
            ("torque_stderr", &m.torque_stderr),
            ("op.q", &m.op.q),
            ("op.qd", &m.op.qd),
            ("op.qdd", &m.op.qdd),
            ("planned_op.q", &m.planned_op.q),
            ("planned_op.qd", &m.planned_op.qd),
            ("planned_op.qdd", &m.planned_op.qdd),
        ] {
            check_bounded(Self::WHAT, kind, field, v.as_slice())?;
        }
        Ok(())
    }

    /// Each estimate: its shape, magnitudes, bounds, condition and correlations.
    fn validate_estimates(&self) -> Result<()> {
        let m = self;
        let bad = |message: String| invalid(Self::WHAT, message);
        let n = m.n();
        let kind = "a local model";
        for (what, e, cols) in [
            ("D", &m.d, n),
            ("H", &m.h, n),
            ("G", &m.g, n),
            ("G_static", &m.g_static, n),
            ("combined", &m.combined, 3 * n),
        ] {
            if let Some(e) = e {
                if e.matrix.shape() != (n, cols)
                    || e.stderr.shape() != (n, cols)
                    || e.residual_rms.len() != n
                {
                    return Err(bad(format!("{what} is not {n} x {cols}")));
                }
                check_magnitude_rows(Self::WHAT, &format!("{what}.stderr"), &e.stderr, true)?;
                let rms = format!("{what}.residual_rms");
                check_magnitudes(Self::WHAT, &rms, &e.residual_rms, false)?;
                for (field, x) in [("matrix", &e.matrix), ("stderr", &e.stderr)] {
                    let field = format!("{}.{field}", what.to_lowercase());
                    check_bounded_rows(Self::WHAT, kind, &field, x)?;
                }
                check_bounded(Self::WHAT, kind, &rms, e.residual_rms.as_slice())?;
                check_condition(Self::WHAT, &format!("{what}.cond"), e.cond)?;
                check_correlations(Self::WHAT, what, e, n)?;
            }
        }
        Ok(())
    }

    /// The diagnostics' entries: each names an experiment and a joint of this model, with
    /// finite values and magnitudes where magnitudes are due.
    fn validate_diagnostics(&self) -> Result<()> {
        let m = self;
        let bad = |message: String| invalid(Self::WHAT, message);
        // the diagnostics' entries name an experiment and a joint of this model
        let named = m
            .diagnostics
            .noise
            .iter()
            .map(|e| (&e.experiment, &e.joint))
            .chain(
                m.diagnostics
                    .unmeasured
                    .iter()
                    .map(|u| (&u.experiment, &u.joint)),
            )
            .chain(
                m.diagnostics
                    .glitches
                    .iter()
                    .map(|g| (&g.experiment, &g.joint)),
            )
            .chain(
                m.diagnostics
                    .torque_offsets
                    .iter()
                    .map(|t| (&t.experiment, &t.joint)),
            );
        for (experiment, joint) in named {
            if !super::ExperimentKind::ALL
                .iter()
                .any(|k| k.name() == experiment.as_str())
                || !m.joint_names.contains(joint)
            {
                return Err(bad(format!(
                    "diagnostics name experiment '{experiment}' and joint '{joint}'; expected one of {} and of the model's joints ({})",
                    super::ExperimentKind::ALL
                        .iter()
                        .map(|k| k.name())
                        .collect::<Vec<_>>()
                        .join(", "),
                    m.joint_names.join(", ")
                )));
            }
        }
        for (i, g) in m.diagnostics.glitches.iter().enumerate() {
            let what = format!("diagnostics.glitches[{i}]");
            if !crate::logs::log_screening::SIGNALS.contains(&g.signal.as_str()) {
                return Err(bad(format!(
                    "{what}.signal is '{}'; expected one of q, qd, qdd, tau",
                    g.signal
                )));
            }
            for (field, v) in [("time", g.time), ("value", g.value)] {
                if !v.is_finite() {
                    return Err(bad(format!("{what}.{field} is not a finite number")));
                }
            }
            if let Some(z) = g.noise_levels {
                check_magnitude(Self::WHAT, &format!("{what}.noise_levels"), z, false)?;
            }
        }
        for (i, t) in m.diagnostics.torque_offsets.iter().enumerate() {
            let what = format!("diagnostics.torque_offsets[{i}]");
            if !t.offset.is_finite() {
                return Err(bad(format!("{what}.offset is not a finite number")));
            }
            check_magnitude(Self::WHAT, &format!("{what}.stderr"), t.stderr, false)?;
        }
        for (i, d) in m.diagnostics.dropouts.iter().enumerate() {
            let problem = d
                .problem(m.joint_names.len())
                .or_else(|| match &d.experiment {
                    Some(e) if super::ExperimentKind::ALL.iter().any(|k| k.name() == e) => None,
                    other => Some(format!(
                        "experiment {other:?} is not one of the plan's experiments"
                    )),
                });
            if let Some(p) = problem {
                return Err(bad(format!("diagnostics.dropouts[{i}]: {p}")));
            }
        }
        for (i, g) in m.diagnostics.held_readings.iter().enumerate() {
            let problem =
                g.problem(m.joint_names.len())
                    .or_else(|| match (&g.experiment, g.held) {
                        (_, None) => Some("held: expected the length of its run".to_string()),
                        (Some(e), _)
                            if super::ExperimentKind::ALL.iter().any(|k| k.name() == e) =>
                        {
                            None
                        }
                        (other, _) => Some(format!(
                            "experiment {other:?} is not one of the plan's experiments"
                        )),
                    });
            if let Some(p) = problem {
                return Err(bad(format!("diagnostics.held_readings[{i}]: {p}")));
            }
        }
        for (i, e) in m.diagnostics.noise.iter().enumerate() {
            let what = format!("diagnostics.noise[{i}]");
            check_magnitude(Self::WHAT, &format!("{what}.samples"), e.samples, false)?;
            if let Some(p) = e.passes {
                check_magnitude(Self::WHAT, &format!("{what}.passes"), p, false)?;
            }
            for (field, step, unit) in [
                ("step", e.step, "N m"),
                ("position_step", e.position_step, "rad"),
            ] {
                let Some(q) = step else { continue };
                check_magnitude(Self::WHAT, &format!("{what}.{field}"), q, false)?;
                if q == 0.0 {
                    return Err(invalid(
                        Self::WHAT,
                        format!("{what}.{field} is 0; expected a positive step ({unit}) or null"),
                    ));
                }
            }
        }
        Ok(())
    }
}

impl TorqueModel for LocalModel {
    fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    fn predict(&self, states: &States<'_>) -> Result<Vec<f64>> {
        LocalModel::predict(self, states)
    }

    fn linearize(&self, op: &OperatingPoint) -> Result<Expansion> {
        let torque = torque_at(self, op)?;
        let part = |e: &Option<Estimate>| e.as_ref().map(|e| e.matrix.clone());
        Ok(Expansion {
            torque,
            d: part(&self.d).expect("predict needs D"),
            h: part(&self.h).expect("predict needs H"),
            g: part(&self.g).expect("predict needs G"),
            g_static: part(&self.g_static),
        })
    }
}

/// Checks the correlations of an estimate `what` read from a file (`cols` columns, `n` rows):
/// none (a model saved before they were stored), or one per row, each `cols x cols`, symmetric
/// with a unit diagonal, entries in [-1, 1] and positive semi-definite (else a prediction's
/// variance could come out negative).
fn check_correlations(kind: &str, what: &str, e: &Estimate, n: usize) -> Result<()> {
    let cols = e.matrix.ncols();
    if e.correlation.is_empty() {
        return Ok(());
    }
    let bad = |message: String| invalid(kind, format!("{what}.correlation: {message}"));
    if e.correlation.len() != n {
        return Err(bad(format!(
            "{} matrices; expected one per torque ({n}) or none",
            e.correlation.len()
        )));
    }
    for (j, r) in e.correlation.iter().enumerate() {
        check_correlation(
            kind,
            &format!("{what}.correlation matrix {}", j + 1),
            r,
            cols,
        )?;
    }
    Ok(())
}
