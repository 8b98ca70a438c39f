//! [`States`]: the joint states of many samples, a view checked once (shapes and finiteness)
//! and then read by every batched algorithm without further checks.

use std::borrow::Cow;
use std::ops::Range;

use crate::error::{Error, Result};
use crate::finite::first_non_finite;

/// The joint states of `k` samples of a robot with `nv` degrees of freedom, borrowed from
/// row-major `k x nv` arrays: sample `s`, joint `j` at index `s * nv + j`.
///
/// - `q`: positions (rad or m), always present;
/// - `qd`: velocities (rad/s or m/s), `None` for zeros;
/// - `qdd`: accelerations (rad/s^2 or m/s^2), `None` for zeros.
///
/// Built by [`States::new`] (a batch) or [`States::single`] (one sample), which check the
/// shapes and that every value is finite; algorithms taking a `States` rely on both. Errors
/// about a sample of a batch name it as `q[s]`, those of a single sample as `q`.
///
/// ```
/// use perturbid_rs::States;
/// let q = [0.1, 0.2, 0.3, 0.4]; // two samples of a 2-dof robot
/// let states = States::new(2, &q, None, None).unwrap();
/// assert_eq!(states.len(), 2);
/// assert_eq!(states.sample(1).q, &[0.3, 0.4]);
/// assert!(States::new(2, &[0.0, f64::NAN], None, None).is_err());
/// ```
#[derive(Clone, Copy, Debug)]
pub struct States<'a> {
    nv: usize,
    k: usize,
    /// Index of the first sample in the batch this view was cut from (for error messages).
    first: usize,
    single: bool,
    q: &'a [f64],
    qd: Option<&'a [f64]>,
    qdd: Option<&'a [f64]>,
    /// The Coulomb friction term's regressor column, where not `sign(qd)`
    /// ([`States::with_coulomb`]).
    coulomb: Option<&'a [f64]>,
}

/// One sample of [`States`]: slices of `nv` values, `None` for zeros.
#[derive(Clone, Copy, Debug)]
pub struct State<'a> {
    pub q: &'a [f64],
    pub qd: Option<&'a [f64]>,
    pub qdd: Option<&'a [f64]>,
}

impl<'a> States<'a> {
    /// A batch of `q.len() / nv` samples; `qd` and `qdd` must hold as many (or be `None`).
    ///
    /// Fails with [`Error::Shape`] when `nv` is zero or an array does not hold a whole number
    /// of samples like `q`, and with [`Error::NonFiniteInput`] naming the argument, sample and
    /// joint of the first NaN or infinity.
    pub fn new(
        nv: usize,
        q: &'a [f64],
        qd: Option<&'a [f64]>,
        qdd: Option<&'a [f64]>,
    ) -> Result<Self> {
        Self::build(nv, q, qd, qdd, false)
    }

    /// One sample: `q`, `qd`, `qdd` of `nv` values each (`None` for zeros).
    pub fn single(
        nv: usize,
        q: &'a [f64],
        qd: Option<&'a [f64]>,
        qdd: Option<&'a [f64]>,
    ) -> Result<Self> {
        let states = Self::build(nv, q, qd, qdd, true)?;
        if states.k != 1 {
            return Err(Error::shape(
                "q",
                format!("{nv} values (one per degree of freedom)"),
                format!("{} values", q.len()),
            ));
        }
        Ok(states)
    }

    fn build(
        nv: usize,
        q: &'a [f64],
        qd: Option<&'a [f64]>,
        qdd: Option<&'a [f64]>,
        single: bool,
    ) -> Result<Self> {
        if nv == 0 {
            return Err(Error::shape(
                "q",
                "a robot with at least one degree of freedom",
                "a robot with none",
            ));
        }
        let k = q.len() / nv;
        if k * nv != q.len() {
            return Err(Error::shape(
                "q",
                format!("a whole number of samples of {nv} joints"),
                format!("{} values", q.len()),
            ));
        }
        for (name, x) in [("qd", qd), ("qdd", qdd)] {
            if let Some(x) = x {
                if x.len() != q.len() {
                    return Err(Error::shape(
                        name,
                        format!("{k} samples x {nv} joints, like q"),
                        format!("{} values", x.len()),
                    ));
                }
            }
        }
        let states = Self {
            nv,
            k,
            first: 0,
            single,
            q,
            qd,
            qdd,
            coulomb: None,
        };
        states.check_finite()?;
        Ok(states)
    }

    fn check_finite(&self) -> Result<()> {
        self.arrays()
            .try_for_each(|(name, x)| self.check_values(name, x, self.nv))
    }

    /// Fails on the first value of `x` (`per_sample` values per sample, named `name`) that is
    /// not finite, naming the sample and the entry.
    fn check_values(&self, name: &str, x: &[f64], per_sample: usize) -> Result<()> {
        match first_non_finite(x) {
            Some(i) => Err(self.at(
                i / per_sample.max(1),
                Error::NonFiniteInput {
                    argument: name.into(),
                    index: i % per_sample.max(1),
                    value: x[i],
                },
            )),
            None => Ok(()),
        }
    }

    fn arrays(&self) -> impl Iterator<Item = (&'static str, &'a [f64])> {
        [("q", Some(self.q)), ("qd", self.qd), ("qdd", self.qdd)]
            .into_iter()
            .filter_map(|(n, x)| x.map(|x| (n, x)))
    }

    /// Degrees of freedom per sample.
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// Number of samples `k`.
    pub fn len(&self) -> usize {
        self.k
    }

    /// No samples.
    pub fn is_empty(&self) -> bool {
        self.k == 0
    }

    /// The index of this view's first sample in the batch it was cut from (0 for a whole batch).
    pub fn offset(&self) -> usize {
        self.first
    }

    /// Whether this is one sample given as such (not a batch of one).
    pub fn is_single(&self) -> bool {
        self.single
    }

    /// Positions, row-major `k x nv`.
    pub fn q(&self) -> &'a [f64] {
        self.q
    }

    /// Velocities, row-major `k x nv`, or `None` for zeros.
    pub fn qd(&self) -> Option<&'a [f64]> {
        self.qd
    }

    /// Accelerations, row-major `k x nv`, or `None` for zeros.
    pub fn qdd(&self) -> Option<&'a [f64]> {
        self.qdd
    }

    /// Velocities with zeros filled in where none were given.
    pub fn qd_or_zeros(&self) -> Cow<'a, [f64]> {
        self.qd
            .map_or_else(|| Cow::Owned(vec![0.0; self.q.len()]), Cow::Borrowed)
    }

    /// Accelerations with zeros filled in where none were given.
    pub fn qdd_or_zeros(&self) -> Cow<'a, [f64]> {
        self.qdd
            .map_or_else(|| Cow::Owned(vec![0.0; self.q.len()]), Cow::Borrowed)
    }

    /// Sample `s` (panics past the end, like slice indexing).
    pub fn sample(&self, s: usize) -> State<'a> {
        let r = s * self.nv..(s + 1) * self.nv;
        State {
            q: &self.q[r.clone()],
            qd: self.qd.map(|x| &x[r.clone()]),
            qdd: self.qdd.map(|x| &x[r]),
        }
    }

    /// The samples `range` (panics past the end, like slice indexing); errors raised on them
    /// still name their index in the whole batch.
    pub fn slice(&self, range: Range<usize>) -> States<'a> {
        let r = range.start * self.nv..range.end * self.nv;
        States {
            nv: self.nv,
            k: range.len(),
            first: self.first + range.start,
            single: self.single,
            q: &self.q[r.clone()],
            qd: self.qd.map(|x| &x[r.clone()]),
            qdd: self.qdd.map(|x| &x[r.clone()]),
            coulomb: self.coulomb.map(|x| &x[r]),
        }
    }

    /// These states with `coulomb` (row-major `k x nv`, each within [-2, 2]) as the regressor
    /// column of every joint's Coulomb friction term in place of `sign(qd)`: `sign(qd)`
    /// low-pass filtered as the torques were ([`crate::Recording::coulomb`]), so that the
    /// term follows the filtered torque's smoothed steps at velocity reversals (parallel
    /// filtering; a low-pass filter's overshoot takes it past 1, by 14 % for the default
    /// 4th-order Butterworth applied forwards and backwards). Errors: a shape unlike `q`'s, or
    /// a value not finite or beyond +-2, which no filtered sign reaches.
    pub fn with_coulomb(self, coulomb: &'a [f64]) -> Result<Self> {
        self.check_companion("coulomb", coulomb, self.nv)?;
        if let Some(i) = coulomb.iter().position(|v| v.abs() > 2.0) {
            return Err(Error::invalid(
                "coulomb",
                format!(
                    "sample {}, joint {}: {}, expected a value within [-2, 2] (sign(qd), filtered)",
                    self.first + i / self.nv,
                    i % self.nv + 1,
                    crate::error::shown(coulomb[i])
                ),
            ));
        }
        Ok(Self {
            coulomb: Some(coulomb),
            ..self
        })
    }

    /// The Coulomb friction term's regressor column of every joint, row-major `k x nv`, where
    /// given ([`Self::with_coulomb`]); `None` for `sign(qd)`.
    pub fn coulomb(&self) -> Option<&'a [f64]> {
        self.coulomb
    }

    /// The Coulomb term's column of joint `j` at sample `s`: the given one, or `sign(qd)`
    /// (0 at rest or without velocities).
    pub fn coulomb_at(&self, s: usize, j: usize) -> f64 {
        let i = s * self.nv + j;
        match (self.coulomb, self.qd) {
            (Some(c), _) => c[i],
            (None, Some(qd)) => crate::parameters::sign0(qd[i]),
            (None, None) => 0.0,
        }
    }

    /// An error raised at sample `s` of this view, renamed for its sample in the batch (a
    /// single sample keeps the plain argument names).
    pub fn at(&self, s: usize, e: Error) -> Error {
        if self.single {
            e
        } else {
            e.in_sample(self.first + s)
        }
    }

    /// Checks that `x` (named `name`, e.g. the torques) holds `per_sample` finite values for
    /// each sample.
    pub fn check_companion(&self, name: &str, x: &[f64], per_sample: usize) -> Result<()> {
        if x.len() != self.k * per_sample {
            return Err(Error::shape(
                name,
                format!("{} samples x {per_sample} values, like q", self.k),
                format!("{} values", x.len()),
            ));
        }
        self.check_values(name, x, per_sample)
    }
}

/// At most `most` of `k` samples spread evenly over them, in order (rows `i k / m`, `m =
/// min(k, most)`): the samples a check on a long log reads, at a bounded cost.
pub(crate) struct SpreadRows {
    rows: Vec<usize>,
    n: usize,
}

impl SpreadRows {
    /// The rows of `k` samples of `n` values each.
    pub(crate) fn new(k: usize, most: usize, n: usize) -> Self {
        let m = k.min(most);
        Self {
            rows: (0..m).map(|i| i * k / m).collect(),
            n,
        }
    }

    /// How many rows.
    pub(crate) fn len(&self) -> usize {
        self.rows.len()
    }

    /// How many of the rows fall in each of consecutive runs of `runs` samples (of the `k`
    /// spread over; empty for one run): the picked rows' runs, in order.
    pub(crate) fn counts_in(&self, runs: &[usize]) -> Vec<usize> {
        // the rows are in order: a run's are those before its end less those before its start
        let before = |i: usize| self.rows.partition_point(|&r| r < i);
        let mut end = 0;
        (runs.iter())
            .map(|&len| {
                let start = end;
                end += len;
                before(end) - before(start)
            })
            .collect()
    }

    /// Those rows of `x` (row-major, `n` per sample).
    pub(crate) fn pick(&self, x: &[f64]) -> Vec<f64> {
        let n = self.n;
        (self.rows.iter())
            .flat_map(|&i| x[i * n..(i + 1) * n].iter().copied())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::SpreadRows;

    #[test]
    fn spread_rows_are_counted_run_by_run() {
        // 10 of 100 samples: rows 0, 10, ..., 90
        let rows = SpreadRows::new(100, 10, 1);
        assert_eq!(rows.counts_in(&[5, 30, 65]), vec![1, 3, 6]);
        assert_eq!(rows.counts_in(&[100]), vec![10]);
        assert_eq!(rows.counts_in(&[]), Vec::<usize>::new());
        // against the rows counted one by one
        let rows = SpreadRows::new(1000, 37, 2);
        let runs = [1, 200, 3, 500, 296];
        let mut start = 0;
        for (&len, count) in runs.iter().zip(rows.counts_in(&runs)) {
            let by_hand = (rows.rows.iter())
                .filter(|&&i| (start..start + len).contains(&i))
                .count();
            assert_eq!(count, by_hand);
            start += len;
        }
    }
}
