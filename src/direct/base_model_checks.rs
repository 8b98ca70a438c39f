//! The checks of a base-parameter model read from its file: the base parameters and their
//! map, the fit's numbers, the logs' findings and the fit's own findings, each named by its
//! field (what [`Document::validate`] runs for a [`BaseModel`]).

use super::base_model::BaseModel;
use crate::document::{
    check_bounded, check_bounded_rows, check_condition, check_magnitudes, invalid, Document,
};
use crate::error::Result;

impl BaseModel {
    /// The base parameters, their map and the layout: sizes that agree, each parameter kept or
    /// dropped once.
    pub(super) fn validate_base(&self) -> Result<()> {
        let m = self;
        let p = m.base.kept.len();
        if m.theta.len() != p
            || m.stderr.len() != p
            || m.base.k.shape() != (p, m.base.dropped.len())
            || p + m.base.dropped.len() != m.base.layout.len()
        {
            return Err(invalid(
                Self::WHAT,
                "the base parameters, their map and the layout disagree in size".into(),
            ));
        }
        let n = m.joint_names.len();
        let layout = &m.base.layout;
        let expected = 10 * layout.nbodies + layout.nv * layout.friction.names().len();
        if layout.nv != n || layout.names.len() != expected {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "base.layout is for {} joints and {} bodies with joint terms [{}]: {expected} parameter names expected, {} given, for a model of {n} joints",
                    layout.nv,
                    layout.nbodies,
                    layout.friction.names().join(", "),
                    layout.names.len()
                ),
            ));
        }
        crate::document::check_joint_names(Self::WHAT, &m.joint_names)?;
        // kept and dropped: each parameter once, in ascending order
        let ascending = |v: &[usize]| v.windows(2).all(|w| w[0] < w[1]);
        let mut seen = vec![false; layout.len()];
        let each_once = m
            .base
            .kept
            .iter()
            .chain(&m.base.dropped)
            .all(|&i| i < seen.len() && !std::mem::replace(&mut seen[i], true));
        if !(ascending(&m.base.kept) && ascending(&m.base.dropped) && each_once) {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "base.kept and base.dropped must list each of the {} parameters once, each in ascending order",
                    layout.len()
                ),
            ));
        }
        Ok(())
    }

    /// The fit's numbers: bounded, one a joint where they are per joint, magnitudes and
    /// correlations where they are due.
    pub(super) fn validate_numbers(&self) -> Result<()> {
        let m = self;
        let (p, n) = (m.base.kept.len(), m.joint_names.len());
        // no number beyond any robot's
        let kind = "a base-parameter model";
        for (field, values) in [
            ("theta", &m.theta),
            ("stderr", &m.stderr),
            ("sigma", &m.sigma),
            ("residual_rms", &m.residual_rms),
        ] {
            check_bounded(Self::WHAT, kind, field, values.as_slice())?;
        }
        check_bounded_rows(Self::WHAT, kind, "base.k", &m.base.k)?;
        if m.residual_rms.len() != n || m.sigma.len() != n {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "residual_rms has {} entries and sigma {}, expected one per joint ({n})",
                    m.residual_rms.len(),
                    m.sigma.len()
                ),
            ));
        }
        check_magnitudes(Self::WHAT, "stderr", &m.stderr, true)?;
        if !m.correlation.is_empty() {
            crate::document::check_correlation(Self::WHAT, "correlation", &m.correlation, p)?;
        }
        if !(m.residual_correlation.is_empty() || m.residual_correlation.len() == n) {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "residual_correlation has {} entries, expected one per joint ({n}) or none",
                    m.residual_correlation.len()
                ),
            ));
        }
        if let Some(i) = m
            .residual_correlation
            .iter()
            .position(|f| !(f.is_finite() && *f >= 1.0 && *f <= 1e6))
        {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "residual_correlation[{i}] is {}; expected a factor from 1 to 1e6",
                    crate::error::shown(m.residual_correlation[i])
                ),
            ));
        }
        Ok(())
    }

    /// What the preprocessing found in the logs fitted to, and the checks of the logs against
    /// the robot's model.
    pub(super) fn validate_logs(&self) -> Result<()> {
        let m = self;
        let n = m.joint_names.len();
        // the findings of the one log fitted to, or of each of several
        let flat = super::log_findings::LogFindings {
            log: "the log".into(),
            glitches: m.log_glitches.clone(),
            dropouts: m.log_dropouts.clone(),
            torque_saturation: m.log_torque_saturation.clone(),
            position_wraps: m.log_position_wraps.clone(),
            held_columns: m.log_held_columns.clone(),
            stamp_jitter: m.log_stamp_jitter.clone(),
            position_rounding: m.position_rounding.clone(),
            period_average: m.log_period_average.clone(),
        };
        let flat_name = |f: &str| match f {
            "position_rounding" => f.to_string(),
            f => format!("log_{f}"),
        };
        if let Some(problem) = flat.problem(n, flat_name) {
            return Err(invalid(Self::WHAT, problem));
        }
        if m.logs.len() > super::drive_gains::MAX_RUNS || (!m.logs.is_empty() && !flat.is_empty()) {
            return Err(invalid(
                Self::WHAT,
                format!(
                    "logs: {} logs' findings{}; expected at most {} logs, and a model of several logs keeps each one's findings there, none in the log_* fields",
                    m.logs.len(),
                    if flat.is_empty() { "" } else { " beside findings in the log_* fields" },
                    super::drive_gains::MAX_RUNS
                ),
            ));
        }
        if let Some(problem) = (m.logs.iter().enumerate())
            .find_map(|(k, l)| l.problem(n, |f| format!("logs[{k}].{f}")))
        {
            return Err(invalid(Self::WHAT, problem));
        }
        if let Some(problem) = super::run_checks::data_checks_problem(
            &m.torque_columns,
            m.torque_lag.as_ref(),
            &m.position_range,
            &m.joint_names,
            str::to_string,
        )
        .or_else(|| {
            super::run_checks::problem(&m.run_checks, &m.joint_names, m.samples, m.logs.len())
        })
        .or_else(|| {
            // as many runs as the model names by its logs, or checks
            let (offset, runs) = (
                m.base.layout.friction.offset,
                m.logs.len().max(m.run_checks.len()),
            );
            (m.log_offsets.as_ref())
                .and_then(|o| o.problem(n, runs, offset))
                .or_else(|| m.log_agreement.as_ref().and_then(|a| a.problem(n, runs)))
        }) {
            return Err(invalid(Self::WHAT, problem));
        }
        Ok(())
    }

    /// The findings of the fit's own checks, the drive gains and the weights.
    pub(super) fn validate_findings(&self) -> Result<()> {
        let m = self;
        let n = m.joint_names.len();
        if let Some(w) = &m.weak_excitation {
            let unknown = (w.motion.iter())
                .find(|j| !m.joint_names.contains(&j.joint))
                .map(|j| format!("joint '{}' is not one of the model's", j.joint));
            let cond = (w.cond != m.cond)
                .then(|| format!("cond {} is not the model's {}", w.cond, m.cond));
            if let Some(problem) = unknown.or(cond).or_else(|| w.problem()) {
                return Err(invalid(Self::WHAT, format!("weak_excitation: {problem}")));
            }
        }
        if let Some(problem) =
            super::noise_fit::problem_in_model(&m.noise_fit, m.weighting, &m.sigma, &m.joint_names)
        {
            return Err(invalid(Self::WHAT, format!("noise_fit: {problem}")));
        }
        if let Some(problem) = (m.position_offsets.as_ref()).and_then(|o| o.problem(&m.joint_names))
        {
            return Err(invalid(Self::WHAT, format!("position_offsets: {problem}")));
        }
        if let Some((i, problem)) = (m.unmodelled_friction.iter().enumerate())
            .find_map(|(i, f)| f.problem(&m.joint_names).map(|p| (i, p)))
        {
            return Err(invalid(
                Self::WHAT,
                format!("unmodelled_friction[{i}]: {problem}"),
            ));
        }
        if let Some((i, problem)) = (m.run_offsets.iter().enumerate())
            .find_map(|(i, o)| o.problem(&m.joint_names, m.logs.len()).map(|p| (i, p)))
        {
            return Err(invalid(Self::WHAT, format!("run_offsets[{i}]: {problem}")));
        }
        m.check_joint_term_rms()?;
        if let Some(problem) =
            (m.drive_gains.as_ref()).and_then(|g| g.problem(Self::WHAT, n, &m.correlation))
        {
            return Err(invalid(Self::WHAT, problem));
        }
        check_magnitudes(Self::WHAT, "residual_rms", &m.residual_rms, false)?;
        check_magnitudes(Self::WHAT, "sigma", &m.sigma, false)?;
        if let Some(j) = m.sigma.iter().position(|&s| s == 0.0) {
            return Err(invalid(
                Self::WHAT,
                format!("sigma[{j}] is 0, expected a positive noise level (a weight)"),
            ));
        }
        check_condition(Self::WHAT, "cond", m.cond)
    }
}
