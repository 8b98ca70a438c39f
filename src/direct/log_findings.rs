//! What the preprocessing found in each log a base-parameter model was fitted to, kept with the
//! model ([`super::BaseModel::logs`]) where there were several logs: an identification from
//! several excitation runs (`identify-direct LOG LOG ...`) or drive gains from runs with and
//! without a payload (`identify-gains`). A model fitted to one log keeps them in its `log_*`
//! fields, as before there were several.

use serde::{Deserialize, Serialize};

use super::BaseModel;
use crate::recording::Recording;

/// One log's findings, named by the log (its path as given).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogFindings {
    /// The log: its path as given on the command line, or the recording's name.
    pub log: String,
    /// Samples taken for glitches and replaced ([`crate::log_screening`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub glitches: Vec<crate::log_screening::LogGlitch>,
    /// Rows removed first: dropouts and frozen readings ([`crate::log_dropouts`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropouts: Vec<crate::log_dropouts::LogDropout>,
    /// Torques that read clipped ([`crate::torque_saturation`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_saturation: Vec<crate::torque_saturation::TorqueSaturation>,
    /// Steps of whole turns taken back out of the positions ([`crate::position_wraps`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_wraps: Vec<crate::position_wraps::PositionWrap>,
    /// Columns logged at a lower rate, read again at their values' arrivals
    /// ([`crate::held_columns`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_columns: Vec<crate::held_columns::HeldColumn>,
    /// Time stamps found jittering over the regular clock ([`crate::stamp_jitter`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp_jitter: Option<crate::stamp_jitter::StampJitter>,
    /// Per joint whose positions lie on a grid, the noise their rounding left in qd and qdd
    /// ([`crate::position_rounding`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_rounding: Vec<crate::position_rounding::PositionRounding>,
}

impl LogFindings {
    /// What the preprocessing of `rec` found, named `log`.
    pub fn of(log: &str, rec: &Recording) -> Self {
        Self {
            log: log.into(),
            glitches: rec.glitches.clone(),
            dropouts: rec.dropouts.clone(),
            torque_saturation: rec.torque_saturation.clone(),
            position_wraps: rec.position_wraps.clone(),
            held_columns: rec.held_columns.clone(),
            stamp_jitter: rec.stamp_jitter.clone(),
            position_rounding: rec.position_rounding.clone(),
        }
    }

    /// What is wrong with the findings for `n` joints, each field named by `field` (its name
    /// here, such as `glitches`, to the document's); None where nothing is.
    pub(crate) fn problem(&self, n: usize, field: impl Fn(&str) -> String) -> Option<String> {
        fn first<T>(
            items: &[T],
            name: String,
            problem: impl Fn(&T) -> Option<String>,
        ) -> Option<String> {
            (items.iter().enumerate())
                .find_map(|(i, x)| problem(x).map(|p| format!("{name}[{i}]: {p}")))
        }
        if self.log.is_empty() || self.log.len() > 4096 {
            return Some(format!(
                "{}: {} characters, expected a log's name of 1 to 4096",
                field("log"),
                self.log.len()
            ));
        }
        first(&self.glitches, field("glitches"), |g| g.problem(n))
            .or_else(|| first(&self.dropouts, field("dropouts"), |d| d.problem(n)))
            .or_else(|| first(&self.held_columns, field("held_columns"), |h| h.problem(n)))
            .or_else(|| {
                (self.stamp_jitter.as_ref())
                    .and_then(|j| j.problem(n))
                    .map(|p| format!("{}: {p}", field("stamp_jitter")))
            })
            .or_else(|| {
                first(&self.position_wraps, field("position_wraps"), |w| {
                    w.problem(n)
                })
            })
            .or_else(|| {
                first(&self.torque_saturation, field("torque_saturation"), |c| {
                    c.problem(n)
                })
            })
            .or_else(|| {
                first(&self.position_rounding, field("position_rounding"), |r| {
                    r.problem(n)
                })
            })
    }

    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.glitches.is_empty()
            && self.dropouts.is_empty()
            && self.torque_saturation.is_empty()
            && self.position_wraps.is_empty()
            && self.held_columns.is_empty()
            && self.stamp_jitter.is_none()
            && self.position_rounding.is_empty()
    }
}

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
            position_rounding: rec.position_rounding.clone(),
            ..self
        }
    }
}
