//! A recording: what a robot logs while it runs a trajectory.

use crate::error::{shown, Error, Result};
use crate::io::table::time_hint;

/// Sampled measurements of one run, row-major (`q[i * n + j]` is joint `j` at sample `i`).
///
/// `t` in s (strictly increasing), `q` in rad (or m), `tau` in N m (or N); the optional `qd`
/// (rad/s) and `qdd` (rad/s^2) when the robot logs them.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// What the recording is (a file name, or the experiment it rehearses): used in messages.
    pub name: String,
    pub n: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub tau: Vec<f64>,
    pub qd: Option<Vec<f64>>,
    pub qdd: Option<Vec<f64>>,
    /// The experiment of a plan this recording is a run of (`nominal`, `G_static`, `G`, `H`,
    /// `D`), when it says; see [`Recording::experiment`].
    pub experiment: Option<String>,
    /// Samples of the log this recording was preprocessed from that were taken for glitches
    /// and replaced first ([`crate::logs::log_screening`]); empty for a recording as logged.
    pub glitches: Vec<crate::logs::findings::log_screening::LogGlitch>,
    /// Runs of rows of the log this recording was preprocessed from in which every joint of a
    /// signal read exactly 0 while the robot moved, removed first
    /// ([`crate::logs::log_dropouts::find_dropouts`]); empty for a recording as logged.
    pub dropouts: Vec<crate::logs::findings::log_dropouts::LogDropout>,
    /// Per joint whose logged positions lie on a grid and whose velocity the preprocessing
    /// derived from them, the noise their rounding leaves in qd and qdd
    /// ([`crate::logs::position_rounding`]); empty for a recording as logged.
    pub position_rounding: Vec<crate::logs::findings::position_rounding::PositionRounding>,
    /// Per joint and side, the torques of the log this recording was preprocessed from that
    /// read clipped ([`crate::logs::torque_saturation`]); empty for a recording as logged.
    pub torque_saturation: Vec<crate::logs::findings::torque_saturation::TorqueSaturation>,
    /// Steps of whole turns in the positions of the log this recording was preprocessed from,
    /// taken back out first ([`crate::logs::position_wraps`]); empty for a recording as logged.
    pub position_wraps: Vec<crate::logs::findings::position_wraps::PositionWrap>,
    /// Columns of the log this recording was preprocessed from that were logged at a lower
    /// rate and held on its grid, read again at their values' arrivals first
    /// ([`crate::logs::held_columns`]); empty for a recording as logged.
    pub held_columns: Vec<crate::logs::findings::held_columns::HeldColumn>,
    /// The Coulomb friction term's regressor column of every joint (row-major `k x n`, within
    /// [-2, 2]: a filter overshoots): `sign(qd)` low-pass filtered as `tau` was, which a direct fit of these torques
    /// uses in place of `sign(qd)` ([`crate::States::with_coulomb`]): filtered torques step
    /// smoothly at a velocity reversal, and `sign(qd)` does not (on the A465 at 10 Hz, the
    /// Coulomb coefficients came out 6 % low and the viscous ones 50 % high without it). Set
    /// by [`crate::logs::preprocess::preprocess`] where it filters; None otherwise.
    pub coulomb: Option<Vec<f64>>,
    /// The time stamps of the log this recording was preprocessed from, found jittering while
    /// its samples were taken on a regular clock ([`crate::logs::stamp_jitter`]); None for a
    /// recording as logged, or stamps found sound.
    pub stamp_jitter: Option<crate::logs::findings::stamp_jitter::StampJitter>,
    /// What averaging the log over the periods of its excitation found (the periods averaged
    /// and left out, each signal's noise from their spread; [`crate::logs::period_average`]); None
    /// for a recording as logged, or one preprocessed by the filter.
    pub period_average: Option<crate::logs::period_average::PeriodAverage>,
}

impl Recording {
    /// Checks and builds a recording of `n` joints: `t` of length K >= 2, strictly increasing;
    /// `q`, `tau` (and `qd`, `qdd` when given) of length `K n`; every value finite. Errors name
    /// the sample (0-based) and joint.
    ///
    /// ```
    /// use perturbid_rs::Recording;
    /// let t = vec![0.0, 0.001, 0.002];
    /// let rec = Recording::new("log.csv", 1, t, vec![0.0, 0.1, 0.2], vec![1.0, 1.1, 1.2], None, None)?;
    /// assert_eq!(rec.len(), 3);
    /// let back = Recording::new("log.csv", 1, vec![0.0, 0.002, 0.001], vec![0.0; 3], vec![0.0; 3], None, None);
    /// assert!(back.unwrap_err().to_string().contains("log.csv")); // time that steps back, named
    /// # Ok::<(), perturbid_rs::Error>(())
    /// ```
    pub fn new(
        name: impl Into<String>,
        n: usize,
        t: Vec<f64>,
        q: Vec<f64>,
        tau: Vec<f64>,
        qd: Option<Vec<f64>>,
        qdd: Option<Vec<f64>>,
    ) -> Result<Self> {
        let r = Self {
            name: name.into(),
            n,
            t,
            q,
            tau,
            qd,
            qdd,
            experiment: None,
            glitches: vec![],
            dropouts: vec![],
            position_rounding: vec![],
            torque_saturation: vec![],
            position_wraps: vec![],
            held_columns: vec![],
            coulomb: None,
            stamp_jitter: None,
            period_average: None,
        };
        r.check()?;
        Ok(r)
    }

    /// The recording's samples as [`crate::States`] (`n` joints; its `qd` and `qdd` where it
    /// has them), with its Coulomb column ([`Self::coulomb`]) where preprocessing made one.
    pub fn states(&self) -> Result<crate::States<'_>> {
        let s = crate::States::new(self.n, &self.q, self.qd.as_deref(), self.qdd.as_deref())?;
        match &self.coulomb {
            Some(c) => s.with_coulomb(c),
            None => Ok(s),
        }
    }

    /// The recording marked as a run of the experiment named `experiment`.
    pub fn for_experiment(mut self, experiment: impl Into<String>) -> Self {
        self.experiment = Some(experiment.into());
        self
    }

    /// The experiment this recording is a run of: its mark ([`Recording::for_experiment`]),
    /// or else its name when that names an experiment, as a file `D.csv` or `rec/G_static.csv`
    /// does (the stem counts). `kinds` are the experiment names to recognise.
    pub fn experiment<'a>(&'a self, kinds: &[&str]) -> Option<&'a str> {
        if let Some(e) = &self.experiment {
            return Some(e);
        }
        let stem = std::path::Path::new(&self.name)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(&self.name);
        kinds.iter().find(|k| **k == stem).map(|_| stem)
    }

    fn error(&self, message: String) -> Error {
        Error::Recording {
            recording: self.name.clone(),
            message,
        }
    }

    /// Why the time does not increase at sample `i` (the first where it does not), with how
    /// often it does not in all and what a user can do ([`time_hint`]).
    fn time_not_increasing(&self, i: usize) -> String {
        let k = self.t.len();
        let repeated = (1..k).filter(|&r| self.t[r] == self.t[r - 1]).count();
        let back = (1..k).filter(|&r| self.t[r] < self.t[r - 1]).count();
        format!(
            "time is not increasing at sample {i}: t = {} after {}{} ({repeated} repeated time stamp(s) and {back} step(s) back in all)",
            shown(self.t[i]),
            shown(self.t[i - 1]),
            time_hint(self.t[i], self.t[i - 1])
        )
    }

    fn check(&self) -> Result<()> {
        let k = self.t.len();
        if self.n == 0 {
            return Err(self.error("a recording needs at least one joint".into()));
        }
        if k < 2 {
            return Err(self.error(format!("{k} samples; a recording needs at least 2")));
        }
        if let Some(i) = self.t.iter().position(|v| !v.is_finite()) {
            return Err(self.error(format!(
                "t at sample {i} is {}, expected a finite number",
                self.t[i]
            )));
        }
        if let Some(i) = (1..k).find(|&i| self.t[i] <= self.t[i - 1]) {
            return Err(self.error(self.time_not_increasing(i)));
        }
        let columns = [
            ("q", Some(&self.q)),
            ("tau", Some(&self.tau)),
            ("qd", self.qd.as_ref()),
            ("qdd", self.qdd.as_ref()),
            ("coulomb", self.coulomb.as_ref()),
        ];
        for (what, values) in columns {
            let Some(values) = values else { continue };
            if values.len() != k * self.n {
                return Err(self.error(format!(
                    "{what} has {} values, expected {k} samples x {} joints = {}",
                    values.len(),
                    self.n,
                    k * self.n
                )));
            }
            if let Some(p) = values.iter().position(|v| !v.is_finite()) {
                return Err(self.error(format!(
                    "{what} of joint {} at sample {} (t = {}) is {}, expected a finite number",
                    p % self.n + 1,
                    p / self.n,
                    shown(self.t[p / self.n]),
                    values[p]
                )));
            }
        }
        Ok(())
    }

    /// This recording of a joint signal that is not a torque (motor currents) in torques: each
    /// `tau` column times its joint's gain (`gains`: one a joint, finite and other than 0; N m
    /// or N per unit of the signal, [`crate::direct::DriveGains`]). What was found in the log
    /// is kept, the torques' clipping levels, glitches' values and the noise their periods
    /// measured (where averaged) scaled alike (a negative gain swaps a clipping's side).
    /// Errors on gains of the wrong number or value.
    pub fn in_torques(&self, gains: &[f64]) -> Result<Self> {
        if gains.len() != self.n {
            return Err(self.error(format!(
                "{} gains for {} joints, expected one a joint",
                gains.len(),
                self.n
            )));
        }
        if let Some(j) = gains.iter().position(|g| !(g.is_finite() && *g != 0.0)) {
            return Err(self.error(format!(
                "the gain of joint {} is {}, expected a finite gain other than 0",
                j + 1,
                gains[j]
            )));
        }
        let n = self.n;
        let tau = (self.tau.iter().enumerate())
            .map(|(i, t)| t * gains[i % n])
            .collect();
        let torque_saturation = (self.torque_saturation.iter())
            .map(
                |c| crate::logs::findings::torque_saturation::TorqueSaturation {
                    level: c.level * gains[c.joint],
                    beyond: c.beyond * gains[c.joint].abs(),
                    upper: c.upper == (gains[c.joint] > 0.0),
                    ..c.clone()
                },
            )
            .collect();
        let glitches = (self.glitches.iter())
            .map(|g| match g.signal.as_str() {
                "tau" => crate::logs::findings::log_screening::LogGlitch {
                    value: g.value * gains[g.joint],
                    replaced_by: g.replaced_by * gains[g.joint],
                    ..g.clone()
                },
                _ => g.clone(),
            })
            .collect();
        // the noise its periods measured, in torques too (its ratios have no unit)
        let period_average =
            (self.period_average.as_ref()).map(|a| crate::logs::period_average::PeriodAverage {
                torque_noise: (a.torque_noise.iter().zip(gains))
                    .map(|(x, g)| x * g.abs())
                    .collect(),
                ..a.clone()
            });
        let r = Self {
            tau,
            torque_saturation,
            glitches,
            period_average,
            ..self.clone()
        };
        r.check()?;
        Ok(r)
    }

    /// Samples `start..stop` (0-based, `stop` excluded) as a recording of their own, named
    /// `name[start:stop]`: its time, positions, torques, velocities, accelerations and Coulomb
    /// column. What was found in the log it was preprocessed from (glitches, dropouts, rounding,
    /// clipping, wraps, held columns, jittering stamps) is kept: it speaks of that log's samples. Errors where the
    /// range leaves fewer than 2 samples or lies past the end.
    pub fn rows(&self, start: usize, stop: usize) -> Result<Self> {
        let k = self.len();
        if start > stop || stop > k || stop - start < 2 {
            return Err(self.error(format!(
                "samples {start}..{stop} of {k}: expected at least 2 samples within the recording"
            )));
        }
        let n = self.n;
        let cut = |v: &Vec<f64>| v[start * n..stop * n].to_vec();
        let r = Self {
            name: format!("{}[{start}:{stop}]", self.name),
            n,
            t: self.t[start..stop].to_vec(),
            q: cut(&self.q),
            tau: cut(&self.tau),
            qd: self.qd.as_ref().map(cut),
            qdd: self.qdd.as_ref().map(cut),
            coulomb: self.coulomb.as_ref().map(cut),
            experiment: self.experiment.clone(),
            glitches: self.glitches.clone(),
            dropouts: self.dropouts.clone(),
            position_rounding: self.position_rounding.clone(),
            torque_saturation: self.torque_saturation.clone(),
            position_wraps: self.position_wraps.clone(),
            held_columns: self.held_columns.clone(),
            stamp_jitter: self.stamp_jitter.clone(),
            period_average: self.period_average.clone(),
        };
        r.check()?;
        Ok(r)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}
