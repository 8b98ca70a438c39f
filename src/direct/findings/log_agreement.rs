//! How well each log agrees with the others under one model. (the checks that find them: [`crate::direct::log_agreement`]).

use serde::{Deserialize, Serialize};

use crate::error::shown;

/// [`LogAgreement::ratio`] beyond which the logs are warned of as disagreeing.
pub const AGREEMENT: f64 = 2.0;

/// The least number of independent samples (the samples over the residuals' long-run
/// factor) a joint needs per log and base parameter to be judged: with as many, a log's own
/// fit takes up at most about half the noise, and agreeing logs stay below a ratio of 1.5.
pub const JUDGED_SAMPLES: f64 = 2.0;

/// Per joint and log, one model's residuals against each log's own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogAgreement {
    /// Per joint, the RMS over the logs of the fit's residuals (less their mean on each log)
    /// over the RMS of each log's own fit's residuals; None where not judged (too few
    /// independent samples, or a log whose own fit its samples do not determine).
    pub ratio: Vec<Option<f64>>,
    /// Per log (the fit's order), per joint: the fit's residual RMS on it, less their mean
    /// (N m or N).
    pub fitted_rms: Vec<Vec<f64>>,
    /// Per log, per joint: its own fit's residual RMS (N m or N); None for a log whose samples
    /// do not determine the parameters.
    pub own_rms: Vec<Option<Vec<f64>>>,
}

impl LogAgreement {
    /// The finding, logs named by `names` (`run r` where none is given), joints by
    /// `joint_names`: the joints whose ratio is [`AGREEMENT`] or more, the log where the fit
    /// leaves most over its own named; a drift of the logs' offsets named among the causes
    /// unless `offsets_fitted` (an offset of each log's own). None where none is.
    pub fn finding(
        &self,
        names: &[String],
        joint_names: &[String],
        offsets_fitted: bool,
    ) -> Option<String> {
        let name = |r: usize| crate::logs::stacked_states::run_name(names, r);
        let own = |r: usize, j: usize| self.own_rms[r].as_ref().map_or(f64::NAN, |o| o[j]);
        let apart: Vec<String> = (self.ratio.iter().enumerate())
            .filter_map(|(j, r)| r.filter(|r| *r >= AGREEMENT).map(|r| (j, r)))
            .map(|(j, ratio)| {
                let worst = (0..self.own_rms.len())
                    .max_by(|&a, &b| {
                        let at = |r: usize| self.fitted_rms[r][j] / own(r, j);
                        at(a).total_cmp(&at(b))
                    })
                    .unwrap_or(0);
                format!(
                    "'{}' {:.1} times (most on '{}': {:.4} against its own {:.4} N m)",
                    joint_names.get(j).map_or("?", String::as_str),
                    ratio,
                    name(worst),
                    self.fitted_rms[worst][j],
                    own(worst, j)
                )
            })
            .collect();
        (!apart.is_empty()).then(|| {
            format!(
                "the logs do not agree with one robot: one model over all of them leaves residuals (less each log's mean) larger than each log's own fit leaves at {} (near 1 expected): a payload or tool mounted in some logs and not in others, a robot changed between them, or another robot's log{}; the model describes none of them. Fit the logs one by one to find the odd one",
                apart.join(", "),
                match offsets_fitted {
                    true => "",
                    false => " (or torque offsets that drifted between them, which bend the parameters: with an offset of each log's own, --offset-per-log or offset_per_log=True, logs that differ only so agree)",
                }
            )
        })
    }

    /// What is wrong with the entry of a model read from a file, for `nv` joints and `runs`
    /// runs (0 where the model names none): other shapes, values negative or beyond 1e9.
    pub(crate) fn problem(&self, nv: usize, runs: usize) -> Option<String> {
        let logs = self.own_rms.len();
        let shaped = self.fitted_rms.len() == logs
            && self.fitted_rms.iter().all(|r| r.len() == nv)
            && self.own_rms.iter().flatten().all(|r| r.len() == nv);
        if self.ratio.len() != nv
            || !shaped
            || !(2..=crate::limits::MAX_LOGS).contains(&logs)
            || (runs > 0 && runs != logs)
        {
            return Some(format!(
                "log_agreement: expected a ratio a joint ({nv}) and two RMS a joint and log (2 to {} logs{})",
                crate::limits::MAX_LOGS,
                if runs > 0 { format!(", as the model's {runs}") } else { String::new() }
            ));
        }
        let bad = |v: f64| v.is_nan() || !(0.0..=1e9).contains(&v);
        let all = (self.ratio.iter().flatten())
            .chain(self.own_rms.iter().flatten().flatten())
            .chain(self.fitted_rms.iter().flatten());
        all.copied().find(|v| bad(*v)).map(|v| {
            format!(
                "log_agreement: {}, expected a magnitude (or null where not judged)",
                shown(v)
            )
        })
    }
}
