//! Several logs fitted together: each log's first samples to fit to and its last to validate
//! on, stacked one after the other (one log is read in place: a long log is not copied), with
//! the samples of each log's part, so that a fit reads each log's residuals as a time series
//! of its own and can fit an offset of each log's own. What `perturbid identify-direct`,
//! `perturbid identify-payload` and Python's fits over a list of Recordings share.

use crate::error::{shown, Error, Result};
use crate::limits::MAX_LOGS;
use crate::logs::recording::Recording;
use crate::logs::stacked_states::StackedStates;
use crate::states::States;

/// Logs fitted together, each split into the samples to fit to and those to validate on.
#[derive(Debug)]
pub struct LogSet<'a> {
    recs: Vec<&'a Recording>,
    names: Vec<String>,
    /// Per log, the first sample validated on (its length where none is).
    splits: Vec<usize>,
    states: Vec<States<'a>>,
    /// The logs' parts to fit to and to validate on, stacked: for two logs or more.
    stacked: Option<(StackedStates, StackedStates)>,
}

/// Samples of a fit: states and data (torques, or a logged signal), `nv` values a sample.
pub type Part<'a> = (States<'a>, &'a [f64]);

impl<'a> LogSet<'a> {
    /// The logs `recs` (with velocities and accelerations), named in errors by `names` (their
    /// paths, or Recordings' names), each log's last `validate` fraction of samples held out
    /// (0: none). `argument` names the logs and `validate_argument` the fraction in errors.
    ///
    /// Errors: no log or more than [`MAX_LOGS`]; a fraction that leaves a log nothing to fit
    /// to, or nothing to validate on, naming the log; a log without velocities and
    /// accelerations, or of other joints than the first's, and two logs that share samples (a
    /// log given twice), naming them.
    pub fn new(
        recs: Vec<&'a Recording>,
        names: Vec<String>,
        validate: f64,
        argument: &str,
        validate_argument: &str,
    ) -> Result<Self> {
        if recs.is_empty() || recs.len() > MAX_LOGS {
            return Err(Error::invalid(
                argument,
                format!("{} logs, expected 1 to {MAX_LOGS}", recs.len()),
            ));
        }
        if names.len() != recs.len() {
            return Err(Error::Internal {
                context: "a set of logs".into(),
                message: format!("{} names for {} logs", names.len(), recs.len()),
            });
        }
        let splits = fit_splits(validate, &recs, &names, validate_argument)?;
        let states = (recs.iter().zip(&names))
            .map(|(r, name)| r.states().map_err(|e| in_log(name, e)))
            .collect::<Result<Vec<_>>>()?;
        let mut set = LogSet {
            recs,
            names,
            splits,
            states,
            stacked: None,
        };
        if set.len() > 1 {
            set.stacked = Some((set.stack(false, argument)?, set.stack(true, argument)?));
        }
        Ok(set)
    }

    /// The number of logs.
    pub fn len(&self) -> usize {
        self.recs.len()
    }

    /// Whether the set holds no log (never: [`Self::new`] refuses none).
    pub fn is_empty(&self) -> bool {
        self.recs.is_empty()
    }

    /// The logs, in their order.
    pub fn recordings(&self) -> &[&'a Recording] {
        &self.recs
    }

    /// The logs' names, in their order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Per log, the first sample validated on (its length where none is).
    pub fn splits(&self) -> &[usize] {
        &self.splits
    }

    /// Each log's part (fit or held out), stacked.
    fn stack(&self, held: bool, argument: &str) -> Result<StackedStates> {
        let parts: Vec<Part<'_>> = self.parts(held).filter(|(s, _)| !s.is_empty()).collect();
        if parts.is_empty() {
            return Ok(StackedStates::default());
        }
        StackedStates::of_named(&parts, &self.names, argument)
    }

    /// Each log's samples to fit to (or, `held`, to validate on), in place.
    fn parts(&self, held: bool) -> impl Iterator<Item = Part<'_>> + '_ {
        (self.states.iter().zip(&self.recs).zip(&self.splits)).map(move |((s, r), &split)| {
            let nv = s.nv();
            let rows = if held { split..r.len() } else { 0..split };
            (
                s.slice(rows.clone()),
                &r.tau[rows.start * nv..rows.end * nv],
            )
        })
    }

    /// The one log's part, in place.
    fn only(&self, held: bool) -> Result<Part<'_>> {
        self.parts(held).next().ok_or_else(|| Error::Internal {
            context: "a set of logs".into(),
            message: "no log".into(),
        })
    }

    /// The samples to fit to: one log's first ones in place, or every log's stacked.
    pub fn train(&self) -> Result<Part<'_>> {
        match &self.stacked {
            None => self.only(false),
            Some((t, _)) => Ok((t.states()?, &t.data[..])),
        }
    }

    /// The samples held out to validate on (none where the fraction is 0).
    pub fn held(&self) -> Result<Part<'_>> {
        match &self.stacked {
            None => self.only(true),
            Some((_, h)) if h.runs.is_empty() => {
                let (train, _) = self.train()?;
                Ok((train.slice(0..0), &[][..]))
            }
            Some((_, h)) => Ok((h.states()?, &h.data[..])),
        }
    }

    /// The samples each log gives the fit, in order: a fit's runs, so that each log's
    /// residuals are a time series of their own (empty for one log: one run).
    pub fn runs(&self) -> Vec<usize> {
        match self.len() {
            1 => vec![],
            _ => self.splits.clone(),
        }
    }

    /// The samples each log holds out, in order.
    pub fn held_runs(&self) -> Vec<usize> {
        (self.recs.iter().zip(&self.splits))
            .map(|(r, s)| r.len() - s)
            .collect()
    }

    /// `e` naming the log where the set holds one (several logs' errors name theirs).
    pub fn in_data(&self, e: Error) -> Error {
        match self.len() {
            1 => in_log(&self.names[0], e),
            _ => e,
        }
    }
}

/// `e` from reading the samples of the log `name`, naming the log: an error in the samples'
/// arrays (`q`, `qd`, `qdd`, `tau`) becomes the log's.
pub fn in_log(name: &str, e: Error) -> Error {
    match e {
        Error::InvalidArgument { argument, message }
            if ["q", "qd", "qdd", "tau"].contains(&argument.as_str()) =>
        {
            Error::recording(name, format!("{argument}: {message}"))
        }
        e => e,
    }
}

/// Refuses a fraction of samples to validate on (given as `argument`) outside [0, 1): what a
/// front end checks before it reads any log.
pub fn check_fraction(fraction: f64, argument: &str) -> Result<()> {
    if (0.0..1.0).contains(&fraction) {
        return Ok(());
    }
    Err(Error::invalid(
        argument,
        format!("{}; expected a fraction in [0, 1)", shown(fraction)),
    ))
}

/// Per log, the first sample validated on: the last `fraction` of its samples held out.
/// Errors: a fraction outside [0, 1), or one that leaves a log nothing to fit to, or (above 0)
/// nothing to validate on, naming the log where there are several.
fn fit_splits(
    fraction: f64,
    recs: &[&Recording],
    names: &[String],
    argument: &str,
) -> Result<Vec<usize>> {
    check_fraction(fraction, argument)?;
    let mut splits = Vec::with_capacity(recs.len());
    for (rec, name) in recs.iter().zip(names) {
        let k = rec.len();
        let split = ((1.0 - fraction) * k as f64).round() as usize;
        let of = match recs.len() {
            1 => String::new(),
            _ => format!(" of {name}"),
        };
        let problem = match split {
            s if fraction > 0.0 && s >= k => {
                Some("leaves none to validate on; give a larger fraction, or 0 for none")
            }
            0 => Some("leaves none to fit to; give a smaller fraction"),
            _ => None,
        };
        if let Some(problem) = problem {
            return Err(Error::invalid(
                argument,
                format!("{} of {k} samples{of} {problem}", shown(fraction)),
            ));
        }
        splits.push(split);
    }
    Ok(splits)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log of 2 joints and `k` samples whose values count from `start`.
    fn log(name: &str, k: usize, start: f64) -> Recording {
        let t: Vec<f64> = (0..k).map(|i| i as f64 * 1e-3).collect();
        let v = |scale: f64| -> Vec<f64> {
            (0..2 * k)
                .map(|i| scale * (start + i as f64).sin())
                .collect()
        };
        Recording::new(name, 2, t, v(1.0), v(3.0), Some(v(0.5)), Some(v(0.25)))
            .expect("a valid log")
    }

    #[test]
    fn several_logs_are_split_and_stacked_in_their_order() {
        let (a, b) = (log("a", 40, 0.0), log("b", 60, 1000.0));
        let names = vec!["a.csv".to_string(), "b.csv".to_string()];
        let set = LogSet::new(vec![&a, &b], names, 0.25, "DATA", "--validate").unwrap();
        assert_eq!(set.splits(), &[30, 45]);
        assert_eq!(set.runs(), vec![30, 45]);
        assert_eq!(set.held_runs(), vec![10, 15]);
        let (train, tau) = set.train().unwrap();
        assert_eq!(train.len(), 75);
        // b's first fitted sample follows a's last fitted one
        assert_eq!(&tau[..60], &a.tau[..60]);
        assert_eq!(&tau[60..], &b.tau[..90]);
        let (held, tau) = set.held().unwrap();
        assert_eq!(held.len(), 25);
        assert_eq!(&tau[..20], &a.tau[60..]);
        assert_eq!(&tau[20..], &b.tau[90..]);
    }

    #[test]
    fn one_log_is_read_in_place_and_its_errors_name_it() {
        let a = log("a", 40, 0.0);
        let set = LogSet::new(vec![&a], vec!["a.csv".into()], 0.0, "DATA", "--validate").unwrap();
        assert_eq!(set.runs(), Vec::<usize>::new());
        let (train, tau) = set.train().unwrap();
        assert_eq!((train.len(), tau.as_ptr()), (40, a.tau.as_ptr()));
        assert!(set.held().unwrap().0.is_empty());
        let e = Error::invalid("tau", "dead");
        assert_eq!(set.in_data(e).to_string(), "a.csv: tau: dead");
    }

    #[test]
    fn fractions_that_leave_a_log_nothing_are_refused_naming_it() {
        let (a, b) = (log("a", 40, 0.0), log("b", 3, 1000.0));
        let names = || vec!["a.csv".to_string(), "b.csv".to_string()];
        let e = LogSet::new(vec![&a, &b], names(), 0.1, "DATA", "--validate").unwrap_err();
        assert!(
            e.to_string()
                .contains("--validate: 0.1 of 3 samples of b.csv leaves none to validate on"),
            "{e}"
        );
        let e = LogSet::new(vec![&a, &b], names(), 1.0, "DATA", "--validate").unwrap_err();
        assert!(
            e.to_string().contains("expected a fraction in [0, 1)"),
            "{e}"
        );
        let e = LogSet::new(vec![], vec![], 0.0, "DATA", "--validate").unwrap_err();
        assert!(e.to_string().contains("0 logs, expected 1 to 1000"), "{e}");
    }
}
