//! What the preprocessing found in one log, named by the log: what a model fitted to several
//! logs keeps of each ([`crate::direct::BaseModel::logs`]).

use serde::{Deserialize, Serialize};

use crate::logs::recording::Recording;

/// One log's findings, named by the log (its path as given).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogFindings {
    /// The log: its path as given on the command line, or the recording's name.
    pub log: String,
    /// Samples taken for glitches and replaced ([`crate::logs::log_screening`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub glitches: Vec<crate::logs::findings::log_screening::LogGlitch>,
    /// Rows removed first: dropouts and frozen readings ([`crate::logs::log_dropouts`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropouts: Vec<crate::logs::findings::log_dropouts::LogDropout>,
    /// Torques that read clipped ([`crate::logs::torque_saturation`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_saturation: Vec<crate::logs::findings::torque_saturation::TorqueSaturation>,
    /// Steps of whole turns taken back out of the positions ([`crate::logs::position_wraps`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_wraps: Vec<crate::logs::findings::position_wraps::PositionWrap>,
    /// Columns logged at a lower rate, read again at their values' arrivals
    /// ([`crate::logs::held_columns`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held_columns: Vec<crate::logs::findings::held_columns::HeldColumn>,
    /// Time stamps found jittering over the regular clock ([`crate::logs::stamp_jitter`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp_jitter: Option<crate::logs::findings::stamp_jitter::StampJitter>,
    /// Per joint whose positions lie on a grid, the noise their rounding left in qd and qdd
    /// ([`crate::logs::position_rounding`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_rounding: Vec<crate::logs::findings::position_rounding::PositionRounding>,
    /// What averaging over the excitation's periods found: the periods averaged and left
    /// out, each signal's noise ([`crate::logs::period_average`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_average: Option<crate::logs::period_average::PeriodAverage>,
}

/// The longest name of a log kept (characters): a path, or a Recording's name.
pub const MAX_NAME: usize = 4096;

impl LogFindings {
    /// What the preprocessing of `rec` found, named `log`: a name kept as given, but that an
    /// empty one reads `(unnamed)` and one past [`MAX_NAME`] characters is cut to its first
    /// `MAX_NAME - 1` and `…` (a Recording may be named anything; the model must load again).
    pub fn of(log: &str, rec: &Recording) -> Self {
        let log = match log.chars().count() {
            0 => "(unnamed)".to_string(),
            c if c > MAX_NAME => log.chars().take(MAX_NAME - 1).chain(['…']).collect(),
            _ => log.to_string(),
        };
        Self {
            log,
            glitches: rec.glitches.clone(),
            dropouts: rec.dropouts.clone(),
            torque_saturation: rec.torque_saturation.clone(),
            position_wraps: rec.position_wraps.clone(),
            held_columns: rec.held_columns.clone(),
            stamp_jitter: rec.stamp_jitter.clone(),
            position_rounding: rec.position_rounding.clone(),
            period_average: rec.period_average.clone(),
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
        let chars = self.log.chars().count();
        if chars == 0 || chars > MAX_NAME {
            return Some(format!(
                "{}: {chars} characters, expected a log's name of 1 to {MAX_NAME}",
                field("log"),
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
            .or_else(|| {
                (self.period_average.as_ref())
                    .and_then(|a| a.problem(n))
                    .map(|p| format!("{}: {p}", field("period_average")))
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
            && self.period_average.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_past_the_limit_or_empty_still_loads() {
        let rec = Recording::new(
            "r",
            1,
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            None,
            None,
        )
        .unwrap();
        let long = "é".repeat(MAX_NAME + 10);
        let f = LogFindings::of(&long, &rec);
        assert_eq!(f.log.chars().count(), MAX_NAME);
        assert!(f.log.ends_with('…') && f.log.starts_with("éé"));
        assert_eq!(f.problem(1, |x| x.to_string()), None);
        let f = LogFindings::of("", &rec);
        assert_eq!(f.log, "(unnamed)");
        assert_eq!(f.problem(1, |x| x.to_string()), None);
        // as given where it fits; past the limit refused on load
        let f = LogFindings::of(&"é".repeat(MAX_NAME), &rec);
        assert_eq!(f.log.chars().count(), MAX_NAME);
        let bad = LogFindings {
            log: "a".repeat(MAX_NAME + 1),
            ..f
        };
        let p = bad.problem(1, |x| x.to_string()).unwrap();
        assert!(
            p.contains("4097 characters, expected a log's name of 1 to 4096"),
            "{p}"
        );
    }
}
