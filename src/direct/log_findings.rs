//! What the preprocessing found in each log a base-parameter model was fitted to, kept with the
//! model ([`super::BaseModel::logs`]) where there were several logs: an identification from
//! several excitation runs (`identify-direct LOG LOG ...`) or drive gains from runs with and
//! without a payload (`identify-gains`). A model fitted to one log keeps them in its `log_*`
//! fields, as before there were several.

use super::BaseModel;
pub use crate::logs::log_findings::{LogFindings, MAX_NAME};
use crate::logs::recording::Recording;

impl BaseModel {
    /// The model with what the preprocessing found in `rec`, the one log it was fitted to, in
    /// its `log_*` fields and `position_rounding`.
    pub fn with_findings_of(self, rec: &Recording) -> Self {
        Self {
            log_glitches: rec.glitches.clone(),
            log_dropouts: rec.dropouts.clone(),
            log_torque_saturation: rec.torque_saturation.clone(),
            log_position_wraps: rec.position_wraps.clone(),
            log_held_columns: rec.held_columns.clone(),
            log_stamp_jitter: rec.stamp_jitter.clone(),
            log_period_average: rec.period_average.clone(),
            position_rounding: rec.position_rounding.clone(),
            ..self
        }
    }

    /// The model with what the preprocessing found in the logs of `set` it was fitted to:
    /// one log's in the model's own fields, several logs' in [`Self::logs`], each named.
    pub fn with_findings_of_logs(self, set: &crate::logs::log_set::LogSet<'_>) -> Self {
        match set.recordings() {
            [rec] => self.with_findings_of(rec),
            recs => self.with_findings_of_each(
                set.names()
                    .iter()
                    .map(String::as_str)
                    .zip(recs.iter().copied()),
            ),
        }
    }

    /// The model with what the preprocessing found in each of the logs `logs` (its name, and
    /// the recording) in [`Self::logs`], in their order.
    pub fn with_findings_of_each<'r>(
        self,
        logs: impl IntoIterator<Item = (&'r str, &'r Recording)>,
    ) -> Self {
        Self {
            logs: (logs.into_iter())
                .map(|(name, r)| LogFindings::of(name, r))
                .collect(),
            ..self
        }
    }

    /// The names of the logs the model was fitted to, in the fit's order (their paths or
    /// Recordings' names; empty for a model of one log).
    pub fn log_names(&self) -> Vec<String> {
        self.logs.iter().map(|l| l.log.clone()).collect()
    }
}
