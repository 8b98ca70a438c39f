//! The identified base parameters as a table a person reads: full names, values, standard
//! errors, relative standard deviations, and whether each is one physical parameter or a
//! combination.

use serde::Serialize;

use super::base_model::BaseModel;
use crate::states::States;

/// One base parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParameterRow {
    /// The kept parameter's name, then `+ c * other` for each parameter merged into it.
    pub name: String,
    /// Value (SI units of the kept parameter: kg, kg m, kg m^2, N m s/rad, N m).
    pub value: f64,
    /// Standard error; `None` when unknown (no residual degree of freedom).
    pub std: Option<f64>,
    /// `std / |value|`; `None` when either is unknown or the value is zero.
    pub relative_std: Option<f64>,
    /// Whether other parameters are merged into it: then only the combination is identifiable,
    /// not the physical parameter it is named after.
    pub combination: bool,
}

impl BaseModel {
    /// The table of the base parameters (see [`ParameterRow`]).
    pub fn parameter_table(&self) -> Vec<ParameterRow> {
        let names = self.base.names();
        (0..self.theta.len())
            .map(|i| {
                let value = self.theta[i];
                let std = Some(self.stderr[i]).filter(|s| s.is_finite());
                ParameterRow {
                    combination: (0..self.base.dropped.len())
                        .any(|d| self.base.k[(i, d)].abs() > 1e-9),
                    name: names[i].clone(),
                    value,
                    relative_std: std.filter(|_| value != 0.0).map(|s| s / value.abs()),
                    std,
                }
            })
            .collect()
    }
}

/// [`BaseModel::joint_term_rms`] of `states` for the joint terms `terms` (their names).
pub(super) fn joint_term_rms(states: &States<'_>, terms: Vec<&str>) -> Vec<f64> {
    let (k, nv) = (states.len(), states.nv());
    let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
    let mut sums = vec![0.0; nv * terms.len()];
    for s in 0..k {
        for j in 0..nv {
            for (t, term) in terms.iter().enumerate() {
                let x = match *term {
                    "viscous" => qd[s * nv + j],
                    "coulomb" => states.coulomb_at(s, j),
                    "armature" => qdd[s * nv + j],
                    _ => 1.0,
                };
                sums[j * terms.len() + t] += x * x;
            }
        }
    }
    sums.iter().map(|x| (x / k.max(1) as f64).sqrt()).collect()
}

/// A joint term's torque (its coefficient times its column's RMS) below this fraction of its
/// joint's residual RMS is negligible: a negative one is not warned of however many standard
/// errors it lies below 0 (on an hour's log, a model's small mismatches lie many below).
pub const NEGLIGIBLE_TERM: f64 = 0.1;

impl BaseModel {
    /// Checks a saved [`Self::joint_term_rms`]: one per joint and joint term of the layout,
    /// or none; finite and >= 0.
    pub(super) fn check_joint_term_rms(&self) -> crate::error::Result<()> {
        use crate::document::{check_magnitudes, invalid, Document};
        let terms = self.joint_names.len() * self.base.layout.friction.names().len();
        let rms = &self.joint_term_rms;
        if !(rms.is_empty() || rms.len() == terms) {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "joint_term_rms has {} entries, expected one per joint and joint term ({terms}) or none",
                    rms.len()
                ),
            ));
        }
        check_magnitudes(Self::WHAT, "joint_term_rms", rms, false)
    }

    /// Whether base parameter `i`, where it is a joint term, gives a torque below
    /// [`NEGLIGIBLE_TERM`] of its joint's residual RMS ([`Self::joint_term_rms`]; false where
    /// not stored).
    fn negligible(&self, i: usize) -> bool {
        let layout = &self.base.layout;
        let (ni, terms) = (10 * layout.nbodies, layout.friction.names().len());
        let Some(col) = self.base.kept.get(i).and_then(|c| c.checked_sub(ni)) else {
            return false;
        };
        let (Some(rms), Some(residual)) = (
            self.joint_term_rms
                .get(col)
                .filter(|_| self.joint_term_rms.len() == layout.nv * terms),
            self.residual_rms.get(col / terms.max(1)),
        ) else {
            return false;
        };
        self.theta[i].abs() * rms < NEGLIGIBLE_TERM * residual
    }
}

impl BaseModel {
    /// What a person should know before trusting the fit: torque columns that do not read as
    /// the robot's model says they should ([`super::torque_columns`]: swapped, of the opposite
    /// sign, in other units), torques out of step with their positions
    /// ([`super::torque_lag`]), joints whose zeros in the data look offset
    /// ([`super::position_offsets`]), friction the fit leaves out that shows in its residuals
    /// ([`super::unmodelled_friction`]), data that excite the base parameters weakly
    /// ([`super::weak_excitation`]), residuals beyond or below the torques' noise measured apart
    /// ([`super::noise_fit`]), runs of a fit over several logs whose residuals differ in
    /// mean ([`super::runs`]: a torque offset that drifted), positions logged in counts so coarse that their
    /// rounding shows in the derived velocities ([`crate::logs::position_rounding`]; in each log of
    /// several, named), and friction or
    /// armature coefficients identified on their own (not in a combination), negative beyond
    /// three standard errors and not negligible (a torque at least [`NEGLIGIBLE_TERM`] of the
    /// joint's residual RMS). No joint has them; the data hold an effect the model lacks, or
    /// are not what it assumes. The drive gains' findings ([`super::drive_gains`]) where the
    /// model has them. A consistent fit keeps them at zero. Over several runs, each run's
    /// torque columns, lag and position range are checked alone and named by its log
    /// ([`super::run_checks`]). Where a torque column is found wrong (of the whole data or of
    /// a run), offsets, friction and the runs' differing means are not named: fitted to such
    /// a log they take up part of what is wrong with it.
    pub fn warnings(&self) -> Vec<String> {
        self.warnings_with(true)
    }

    /// Whether a torque column is found wrong, of the whole data or of a run of several
    /// ([`super::torque_columns::findings`]): the offsets', friction's and runs' means'
    /// findings are then not named.
    pub fn columns_found_wrong(&self) -> bool {
        self.run_checks.iter().any(|c| c.columns_wrong())
            || !super::torque_columns::findings(&self.torque_columns).is_empty()
    }

    /// Whether the logs agree with one robot: the finding of [`Self::log_agreement`], if any;
    /// none for drive gains (their runs differ by a payload, and have their own agreement) and
    /// where a torque column is found wrong (a log that does not read as the robot disagrees
    /// by that).
    pub fn log_agreement_finding(&self) -> Option<String> {
        let names = self.log_names();
        (self.log_agreement.as_ref())
            .filter(|_| self.drive_gains.is_none() && !self.columns_found_wrong())
            .and_then(|a| a.finding(&names, &self.joint_names, self.log_offsets.is_some()))
    }

    /// The joints' zero offsets' finding ([`super::position_offsets`]), if any: none where a
    /// torque column is found wrong, of the whole data or of a run (fitted to such a log,
    /// offsets take up part of what is wrong with it).
    pub fn position_offsets_finding(&self) -> Option<String> {
        (self.position_offsets.as_ref())
            .filter(|_| !self.run_checks.iter().any(|c| c.columns_wrong()))
            .and_then(|o| o.finding_beside(&self.torque_columns, false))
    }

    /// [`Self::warnings`] without those of the logs' own findings (position rounding) that
    /// the preprocessing of the fitted Recordings gave already: what Python's fit of
    /// Recordings warns of (the model's `warnings` still lists them all).
    pub fn fit_warnings(&self) -> Vec<String> {
        self.warnings_with(false)
    }

    /// The warnings, with the logs' findings or without.
    fn warnings_with(&self, log_findings: bool) -> Vec<String> {
        let log_names = self.log_names();
        // over several runs each run's, named; the whole data's columns besides only where no
        // run's is found wrong (a wrong column in every log is named log by log)
        let each = super::run_checks::findings(&self.run_checks, &log_names);
        let runs_wrong = self.run_checks.iter().any(|c| c.columns_wrong());
        let columns = match self.run_checks.is_empty() {
            true => super::torque_lag::log_findings(
                &self.position_range,
                &self.torque_columns,
                self.torque_lag.as_ref(),
            ),
            false if runs_wrong => each,
            false => each
                .into_iter()
                .chain(super::torque_columns::findings(&self.torque_columns))
                .collect(),
        };
        let columns_wrong = self.columns_found_wrong();
        let negative = self
            .parameter_table()
            .into_iter()
            .enumerate()
            .filter(|(i, r)| {
                !r.combination
                    && [".viscous", ".coulomb", ".armature"]
                        .iter()
                        .any(|t| r.name.ends_with(t))
                    && !self.negligible(*i)
            })
            .filter_map(|(_, r)| {
                let std = r.std?;
                (r.value + 3.0 * std < 0.0).then(|| {
                    format!(
                        "{} = {:.4} +- {:.4} is negative beyond 3 standard errors: no joint has that; the data hold an effect the model lacks or are not what it assumes (fit physically consistent parameters to keep it at zero)",
                        r.name, r.value, std
                    )
                })
            });
        let rounding =
            crate::logs::position_rounding::warning(&self.position_rounding, &self.joint_names)
                .map(|w| format!("{w}{}", crate::logs::position_rounding::IN_A_FIT));
        // of each of several logs, named
        let rounding = rounding.into_iter().chain(self.logs.iter().filter_map(|l| {
            crate::logs::position_rounding::warning(&l.position_rounding, &self.joint_names).map(
                |w| {
                    format!(
                        "'{}': {w}{}",
                        l.log,
                        crate::logs::position_rounding::IN_A_FIT
                    )
                },
            )
        }));
        let offsets = self.position_offsets_finding();
        // friction terms fitted to a log that does not read as the robot's model take up
        // part of what is wrong with it, as offsets do: the columns first
        let friction = super::findings::unmodelled_friction::finding(
            &self.unmodelled_friction,
            self.base.layout.friction,
        )
        .filter(|_| !columns_wrong);
        let weak = (self.weak_excitation.as_ref()).map(|w| w.finding());
        // residuals against the noise measured apart: a model error, or an overstated noise
        let noise = (self.noise_fit.as_ref()).and_then(|f| f.finding(&self.joint_names));
        // a noise that is not white, which the judgement against it takes flat
        let colour = (self
            .noise_fit
            .as_ref()
            .and(self.log_period_average.as_ref()))
        .and_then(|a| {
            crate::logs::period_average::noise_colour::finding(
                &a.torque_noise_tilt,
                a.periods,
                a.torque_harmonics,
                &self.joint_names,
            )
        });
        let drifted = (self.run_offsets.iter())
            .filter(|_| !columns_wrong)
            .map(|o| o.finding(&log_names));
        let gains = (self.drive_gains.iter()).flat_map(|g| g.warnings(&self.joint_names));
        let disagree = self.log_agreement_finding();
        columns
            .into_iter()
            .chain(gains)
            .chain(offsets)
            .chain(friction)
            .chain(weak)
            .chain(noise)
            .chain(colour)
            .chain(disagree)
            .chain(drifted)
            .chain(rounding.filter(|_| log_findings))
            .chain(negative)
            .collect()
    }
}
