//! `Recording` in Python: what a robot logs (mirrors `crate::logs::recording`).

use std::path::PathBuf;
use std::sync::Arc;

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;

use super::arrays::{rows, vec1, vector, ArrayLike};
use crate::error::{Error, Result};
use crate::logs::recording::Recording;

/// A recording of one run: `t` (s, `(m,)`, increasing), `q` (rad, `(m, n)`), `tau` (N m,
/// `(m, n)`), and optionally `qd`, `qdd` when the robot logs them.
#[pyclass(name = "Recording", module = "perturbid_rs", frozen)]
#[derive(Clone)]
pub(crate) struct PyRecording {
    pub rec: Arc<Recording>,
    /// The columns of the log that `ignore_columns` left out (`Recording.load`,
    /// `from_dataframe`); empty otherwise.
    pub left_out: Vec<String>,
}

impl From<Recording> for PyRecording {
    fn from(rec: Recording) -> Self {
        Self {
            rec: Arc::new(rec),
            left_out: vec![],
        }
    }
}

/// A dropout as a Python dict: `experiment` (when it has one), `signal`, `first_sample`,
/// `samples`, `from`, `to`.
/// A glitch of a log as a dict (its keys in [`PyRecording::glitches`]; `experiment` too
/// where it has one).
pub(crate) fn glitch_dict<'py>(
    py: Python<'py>,
    g: &crate::logs::log_screening::LogGlitch,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let e = pyo3::types::PyDict::new(py);
    if let Some(x) = &g.experiment {
        e.set_item("experiment", x)?;
    }
    e.set_item("signal", &g.signal)?;
    e.set_item("joint", g.joint)?;
    e.set_item("sample", g.sample)?;
    e.set_item("time", g.time)?;
    e.set_item("value", g.value)?;
    e.set_item("noise_levels", g.noise_levels)?;
    e.set_item("replaced_by", g.replaced_by)?;
    e.set_item("repeats_previous", g.repeats_previous)?;
    e.set_item("held", g.held)?;
    Ok(e)
}

pub(crate) fn dropout_dict<'py>(
    py: Python<'py>,
    d: &crate::logs::log_dropouts::LogDropout,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let e = pyo3::types::PyDict::new(py);
    if let Some(x) = &d.experiment {
        e.set_item("experiment", x)?;
    }
    e.set_item("signal", &d.signal)?;
    e.set_item("first_sample", d.first_sample)?;
    e.set_item("samples", d.samples)?;
    e.set_item("from", d.from)?;
    e.set_item("to", d.to)?;
    if let Some(j) = d.joint {
        e.set_item("joint", j)?;
        e.set_item("value", d.value)?;
        e.set_item("noise_levels", d.noise_levels)?;
        e.set_item("to_end", d.to_end)?;
    }
    Ok(e)
}

pub(crate) fn matrix_rows(
    name: &str,
    a: &ArrayLike<'_>,
    m: usize,
    n: Option<usize>,
) -> Result<(usize, Vec<f64>)> {
    let shape = a.shape().to_vec();
    match shape.as_slice() {
        [rows, cols] if *rows == m && n.is_none_or(|n| n == *cols) => {
            Ok((*cols, a.as_array().iter().copied().collect()))
        }
        _ => Err(Error::shape(
            name,
            format!(
                "shape ({m}, {}) like t",
                n.map_or("n".to_string(), |n| n.to_string())
            ),
            format!("shape {shape:?}"),
        )),
    }
}

impl PyRecording {
    /// A checked recording from numpy arrays.
    pub(crate) fn build(
        t: ArrayLike<'_>,
        q: ArrayLike<'_>,
        tau: ArrayLike<'_>,
        qd: Option<ArrayLike<'_>>,
        qdd: Option<ArrayLike<'_>>,
        name: &str,
    ) -> Result<Recording> {
        let t = vector("t", &t)?;
        let m = t.len();
        let (n, q) = matrix_rows("q", &q, m, None)?;
        let (_, tau) = matrix_rows("tau", &tau, m, Some(n))?;
        let qd = qd
            .map(|a| matrix_rows("qd", &a, m, Some(n)).map(|r| r.1))
            .transpose()?;
        let qdd = qdd
            .map(|a| matrix_rows("qdd", &a, m, Some(n)).map(|r| r.1))
            .transpose()?;
        Recording::new(name, n, t, q, tau, qd, qdd)
    }
}

#[pymethods]
impl PyRecording {
    /// `experiment` says which experiment of a plan this is a run of (`nominal`, `G_static`,
    /// `G`, `H`, `D`): `identify_local` pairs recordings with experiments by it (or by a `name`
    /// that is such a name or a file named after one, `D.csv`), never by order.
    #[new]
    #[pyo3(signature = (t, q, tau, qd=None, qdd=None, name="recording", experiment=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t: ArrayLike<'_>,
        q: ArrayLike<'_>,
        tau: ArrayLike<'_>,
        qd: Option<ArrayLike<'_>>,
        qdd: Option<ArrayLike<'_>>,
        name: &str,
        experiment: Option<String>,
    ) -> PyResult<Self> {
        let mut rec = Self::build(t, q, tau, qd, qdd, name)?;
        rec.experiment = experiment;
        Ok(rec.into())
    }
    /// Reads a recording from the CSV file at `path`, as the command line does: a header
    /// `t, q1..qN, [qd1..qN, qdd1..qN,] tau1..tauN`, or the same named after the joints
    /// (`q_<joint>`, ...); `joints` are the robot's joint names in order (e.g.
    /// `robot.joint_names` or `plan.joint_names`), N of them. t in s, positions in rad or m,
    /// torques in N m or N. Named by its path, so `D.csv` pairs with experiment D in
    /// `identify_local`; `experiment` marks it explicitly. A log from another tool:
    /// `columns` reads its own names as these, a dict `{TARGET: "SOURCE[*SCALE]"}` or a list
    /// of `"TARGET=SOURCE[*SCALE]"` (TARGET `t`; `q`, `qd`, `qdd` or `tau` for every joint,
    /// SOURCE then holding `{i}` (index from 0), `{j}` (number from 1) or `{joint}` (name); or
    /// one joint's, `q3`; SCALE a number or `deg`, `ms`, `us`, `ns`), and `ignore_columns`
    /// leaves columns out (names, or starts of names ending in `*`; they need not hold
    /// numbers), as the command line's `--column` and `--ignore-columns` (docs/logs.md).
    /// Raises FileError for a file that cannot be read (or larger than 2 GiB), InputError
    /// naming the file, line and column of a bad value, a missing or unexpected column, a
    /// map that does not fit the log, or time that does not increase; TypeError for a
    /// `columns` that is neither a dict nor a list of strings.
    #[staticmethod]
    #[pyo3(signature = (path, joints, experiment=None, *, columns=None, ignore_columns=None))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        joints: Vec<String>,
        experiment: Option<String>,
        columns: Option<&Bound<'_, PyAny>>,
        ignore_columns: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let map = column_map(columns, ignore_columns)?;
        let (mut rec, left_out) = super::detached(py, "Recording.load", || {
            let (table, left_out) = map.read(&path, &joints)?;
            crate::logs::read_recording(&table, &joints).map(|rec| (rec, left_out))
        })?;
        if experiment.is_some() {
            rec.experiment = experiment;
        }
        Ok(Self {
            rec: Arc::new(rec),
            left_out,
        })
    }
    /// Writes the recording to the CSV file at `path` (atomically: a temporary file renamed
    /// into place) with the header `t, q1..qN, [qd1..qN, qdd1..qN,] tau1..tauN`; numbers
    /// written to read back exactly with `Recording.load`. What a preprocessed recording knows
    /// of its log (glitches, dropouts, position rounding) and its `experiment` are not kept:
    /// name the file after the experiment (`D.csv`).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let rec = self.rec.clone();
        Ok(super::detached(py, "Recording.save", || {
            crate::logs::save_recording(&rec, &path)
        })?)
    }
    /// Reads a recording from a pandas DataFrame by the rules of the command line's CSV files
    /// (`Recording.load`): columns `t, q1..qN, [qd1..qN, qdd1..qN,] tau1..tauN` or named after
    /// `joints` (`q_<joint>`, ...), in any order, nothing else. `t` in s, or datetimes or
    /// timedeltas (seconds from the first row, to the nanosecond), as a column or as the index
    /// named `t`. Numbers of any numeric dtype, pandas' nullable ones too (a missing value is
    /// refused with its row). Raises InputError naming the column of a bool, text, category or
    /// time column, a missing, repeated or unexpected column, a non-finite value (row and
    /// column), time that does not increase; TypeError for what is not a DataFrame. Parquet
    /// logs read through `pandas.read_parquet` (pyarrow).
    /// `columns` and `ignore_columns` as for `Recording.load` (a column left out is not
    /// converted: it may hold text).
    #[staticmethod]
    #[pyo3(signature = (frame, joints, name="dataframe", experiment=None, *, columns=None, ignore_columns=None))]
    fn from_dataframe(
        py: Python<'_>,
        frame: &Bound<'_, PyAny>,
        joints: Vec<String>,
        name: &str,
        experiment: Option<String>,
        columns: Option<&Bound<'_, PyAny>>,
        ignore_columns: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let map = column_map(columns, ignore_columns)?;
        let (columns, left_out) = super::tables::frame_columns(frame, name, &map, &joints)?;
        let mut rec = super::detached(py, "Recording.from_dataframe", || {
            crate::logs::read_recording(&crate::io::Table::from_columns(name, columns)?, &joints)
        })?;
        rec.experiment = experiment;
        Ok(Self {
            rec: Arc::new(rec),
            left_out,
        })
    }
    /// The recording as a pandas DataFrame with the columns of its CSV file: `t` (s), `q1..qN`,
    /// `qd1..qN` and `qdd1..qN` when present, `tau1..tauN`; `from_dataframe` reads it back.
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let table = crate::logs::recording_table(&self.rec, &self.rec.name);
        let columns = (0..table.columns.len())
            .map(|c| {
                let values = numpy::PyArray1::from_vec(py, table.column(c)).into_any();
                (table.columns[c].as_str(), values)
            })
            .collect();
        super::tables::dataframe(py, columns, None)
    }
    #[getter]
    fn name(&self) -> String {
        self.rec.name.clone()
    }
    /// The columns of the log `ignore_columns` left out, in the log's order (`load`,
    /// `from_dataframe`; as the command line lists them); empty for a Recording made
    /// otherwise.
    #[getter]
    fn left_out_columns(&self) -> Vec<String> {
        self.left_out.clone()
    }
    /// The experiment this recording is marked as a run of, or None.
    #[getter]
    fn experiment(&self) -> Option<String> {
        self.rec.experiment.clone()
    }
    #[getter]
    fn n(&self) -> usize {
        self.rec.n
    }
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.rec.t)
    }
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.rec.q, self.rec.n)
    }
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.rec.tau, self.rec.n)
    }
    /// The Coulomb friction term's column of every joint ((k, n), within [-2, 2]): sign(qd)
    /// low-pass filtered as `tau` was, for a direct fit of these torques (the recording given
    /// whole to identify_base_parameters, predict and validate brings it; with arrays, pass it
    /// as `coulomb=`); None where `preprocess`
    /// did not filter, or for a recording as logged.
    #[getter]
    fn coulomb<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        (self.rec.coulomb.as_ref())
            .map(|v| rows(py, v, self.rec.n))
            .transpose()
    }
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.rec
            .qd
            .as_ref()
            .map(|v| rows(py, v, self.rec.n))
            .transpose()
    }
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.rec
            .qdd
            .as_ref()
            .map(|v| rows(py, v, self.rec.n))
            .transpose()
    }
    /// The samples of the log this recording was preprocessed from that were taken for
    /// glitches and replaced first: a list of dicts `signal` (q, qd, qdd, tau), `joint`
    /// (0-based column index), `sample` (0-based row of the log), `time` (s), `value` (as
    /// logged), `noise_levels` (None beyond any scale), `replaced_by`, `repeats_previous`,
    /// `held` (the length of the held reading it belongs to, a run of one repeated value
    /// judged as a whole; None for a single glitch). Empty for a recording as logged.
    #[getter]
    fn glitches<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .glitches
            .iter()
            .map(|g| glitch_dict(py, g))
            .collect()
    }
    /// The runs of rows of the log this recording was preprocessed from that were removed:
    /// dropouts (every joint of a signal read exactly 0 while the robot moved) and frozen
    /// readings (one joint's column held one value for more than 10 samples while it moved,
    /// then jumped back). A list of dicts `signal`, `first_sample` (0-based row of the log),
    /// `samples` (rows), `from`, `to` (s); a frozen reading's also `joint` (0-based column
    /// index), `value` (the value held, in the signal's unit), `noise_levels` (how far its
    /// end jumped; None beyond any scale or at the stretch's end) and `to_end` (True where it
    /// lasts to the end of its stretch: a stream that stopped before the log did). Empty for
    /// a recording as logged.
    #[getter]
    fn dropouts<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .dropouts
            .iter()
            .map(|d| dropout_dict(py, d))
            .collect()
    }
    /// Per joint whose logged positions lie on a grid and whose velocity was derived from
    /// them, the noise their rounding left in the preprocessed qd and qdd: a list of dicts
    /// `joint` (0-based column index), `step` (rad or m), `qd_ratio`, `qdd_ratio` (RMS of the
    /// noise over RMS of the signal; from 0.1 on, `preprocess` warns). Empty for a recording
    /// as logged.
    #[getter]
    fn position_rounding<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .position_rounding
            .iter()
            .map(|r| {
                let e = pyo3::types::PyDict::new(py);
                e.set_item("joint", r.joint)?;
                e.set_item("step", r.step)?;
                e.set_item("qd_ratio", r.qd_ratio)?;
                e.set_item("qdd_ratio", r.qdd_ratio)?;
                Ok(e)
            })
            .collect()
    }
    /// Columns of the log this recording was preprocessed from that were logged at a lower
    /// rate and held on its grid (a slower stream merged into a faster one), read again at
    /// their values' arrivals first; `preprocess` warns: a list of dicts `signal`, `joint`
    /// (0-based column index), `repeated` (share of its samples, where the joint moves, that
    /// repeat the one before), `held_for` (median samples a value is held). Empty for a
    /// recording as logged.
    #[getter]
    fn held_columns<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .held_columns
            .iter()
            .map(|h| {
                let e = pyo3::types::PyDict::new(py);
                e.set_item("signal", &h.signal)?;
                e.set_item("joint", h.joint)?;
                e.set_item("repeated", h.repeated)?;
                e.set_item("held_for", h.held_for)?;
                Ok(e)
            })
            .collect()
    }
    /// The time stamps of the log this recording was preprocessed from, found jittering while
    /// its samples were taken on a regular clock (`preprocess` warns): a dict `interval` (the
    /// median interval, s), `scatter` (how far the intervals scatter about it, s), `joint`
    /// (0-based column index of the joint that tells it most clearly) and `rougher` (how many
    /// times farther from their neighbours' line its positions lie against the stamps than
    /// against the sample count); None where the stamps are sound, or for a recording as logged.
    #[getter]
    fn stamp_jitter<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<Bound<'py, pyo3::types::PyDict>>> {
        let Some(j) = &self.rec.stamp_jitter else {
            return Ok(None);
        };
        let e = pyo3::types::PyDict::new(py);
        e.set_item("interval", j.interval)?;
        e.set_item("scatter", j.scatter)?;
        e.set_item("joint", j.joint)?;
        e.set_item("rougher", j.rougher)?;
        Ok(Some(e))
    }
    /// What averaging the log over its excitation's periods found (`preprocess(...,
    /// excitation=...)` or `period=`): a dict with `period` (s), `start` (the log's time of the
    /// first period used, s), `periods` (averaged), `harmonics` (the positions'),
    /// `torque_harmonics`, `samples` (a period, before decimation), `kept_samples` (after
    /// it: the recording's), per joint
    /// `position_noise` (rad), `velocity_noise` (rad/s), `acceleration_noise` (rad/s^2) and
    /// `torque_noise` (N m) of one period's samples within their band (the average's are these
    /// over sqrt(periods): `averaged_torque_noise`), `position_beyond` (rad RMS of the averaged
    /// positions beyond the harmonics kept), `torque_drift` (per joint the F ratio of a linear
    /// trend of its torques over the periods, near 1 for noise, beyond 3 a drift; None where
    /// not judged), `torque_noise_tilt` (per joint the noise's power in the lower half of the
    /// torques' band over the upper half's, 1 for white noise; None where not judged), and
    /// `left_out`, a list of dicts `period` (0-based),
    /// `t0`, `t1` (s) and `reason`. None for a recording not averaged so.
    #[getter]
    fn period_average<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<Bound<'py, pyo3::types::PyDict>>> {
        let Some(a) = &self.rec.period_average else {
            return Ok(None);
        };
        let e = pyo3::types::PyDict::new(py);
        e.set_item("period", a.period)?;
        e.set_item("start", a.start)?;
        e.set_item("periods", a.periods)?;
        e.set_item("harmonics", a.harmonics)?;
        e.set_item("torque_harmonics", a.torque_harmonics)?;
        e.set_item("samples", a.samples)?;
        e.set_item("kept_samples", a.kept_samples)?;
        e.set_item("position_noise", a.position_noise.clone())?;
        e.set_item("velocity_noise", a.velocity_noise.clone())?;
        e.set_item("acceleration_noise", a.acceleration_noise.clone())?;
        e.set_item("torque_noise", a.torque_noise.clone())?;
        e.set_item("averaged_torque_noise", a.averaged_torque_noise())?;
        e.set_item("position_beyond", a.position_beyond.clone())?;
        e.set_item("torque_drift", a.torque_drift.clone())?;
        e.set_item("torque_noise_tilt", a.torque_noise_tilt.clone())?;
        let left = pyo3::types::PyList::empty(py);
        for l in &a.left_out {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("period", l.period)?;
            d.set_item("t0", l.t0)?;
            d.set_item("t1", l.t1)?;
            d.set_item("reason", &l.reason)?;
            left.append(d)?;
        }
        e.set_item("left_out", left)?;
        Ok(Some(e))
    }
    /// Steps of whole turns in the positions of the log this recording was preprocessed from
    /// (a joint angle logged within one turn that a continuous joint passes), taken back out
    /// first; `preprocess` warns: a list of dicts `joint` (0-based column index), `sample`
    /// (0-based row of the log: the first after the step), `time` (s), `turns` (whole turns
    /// added to the joint's positions from there on). Empty for a recording as logged.
    #[getter]
    fn position_wraps<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .position_wraps
            .iter()
            .map(|w| {
                let e = pyo3::types::PyDict::new(py);
                e.set_item("joint", w.joint)?;
                e.set_item("sample", w.sample)?;
                e.set_item("time", w.time)?;
                e.set_item("turns", w.turns)?;
                Ok(e)
            })
            .collect()
    }
    /// The torques of the log this recording was preprocessed from that read clipped (a run
    /// of samples at exactly the column's largest or smallest value that the samples either
    /// side head beyond; `preprocess` warns): a list of dicts `joint` (0-based column index),
    /// `level` (N m, the value read), `upper` (its largest value, else its smallest), `runs`,
    /// `samples`, `longest` (samples), `first_at` (s), `beyond` (N m, how far beyond `level`
    /// estimated from the slopes either side). Empty for a recording as logged.
    #[getter]
    fn torque_saturation<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
        self.rec
            .torque_saturation
            .iter()
            .map(|c| {
                let e = pyo3::types::PyDict::new(py);
                e.set_item("joint", c.joint)?;
                e.set_item("level", c.level)?;
                e.set_item("upper", c.upper)?;
                e.set_item("runs", c.runs)?;
                e.set_item("samples", c.samples)?;
                e.set_item("longest", c.longest)?;
                e.set_item("first_at", c.first_at)?;
                e.set_item("beyond", c.beyond)?;
                Ok(e)
            })
            .collect()
    }
    fn __len__(&self) -> usize {
        self.rec.len()
    }
    /// `rec[a:b]`: samples a..b as a Recording of their own (a slice with step 1; at least 2
    /// samples), with its Coulomb column and what was found in the log, for fitting one part
    /// of a log and validating on another.
    fn __getitem__(&self, index: &Bound<'_, PyAny>) -> PyResult<Self> {
        let Ok(slice) = index.cast::<pyo3::types::PySlice>() else {
            return Err(Error::invalid(
                "index",
                format!(
                    "{}; expected a slice of samples (rec[a:b]): a recording indexes rows by slices only",
                    index.repr()?
                ),
            )
            .into());
        };
        let k = self.rec.len();
        let s = slice.indices(k as isize)?;
        if s.step != 1 {
            return Err(Error::invalid(
                "index",
                format!(
                    "a slice of step {}; expected step 1 (a recording's samples stay evenly spaced and in order)",
                    s.step
                ),
            )
            .into());
        }
        let (start, stop) = (s.start as usize, (s.stop.max(s.start)) as usize);
        Ok(Self {
            rec: Arc::new(self.rec.rows(start, stop)?),
            left_out: self.left_out.clone(),
        })
    }
    /// This recording of motor currents (or another signal) in torques: each `tau` column
    /// times its joint's gain (`gains`: (n,) N m or N per unit of the signal, such as
    /// `BaseParameterModel.drive_gains["gain"]`), with its velocities, accelerations, Coulomb
    /// column and what was found in the log (the torques' clipping levels and glitches scaled
    /// alike).
    fn in_torques(&self, gains: ArrayLike<'_>) -> PyResult<Self> {
        let gains = vector("gains", &gains)?;
        Ok(Self {
            rec: Arc::new(self.rec.in_torques(&gains)?),
            left_out: self.left_out.clone(),
        })
    }
    fn __repr__(&self) -> String {
        format!(
            "Recording('{}', samples={}, joints={})",
            self.rec.name,
            self.rec.len(),
            self.rec.n
        )
    }
}

/// The column map of `Recording.load`'s and `from_dataframe`'s `columns` (a dict `{TARGET:
/// "SOURCE[*SCALE]"}` or a list of `"TARGET=SOURCE[*SCALE]"`) and `ignore_columns`.
fn column_map(
    columns: Option<&Bound<'_, PyAny>>,
    ignore_columns: Option<Vec<String>>,
) -> PyResult<crate::io::ColumnMap> {
    let expected = || {
        pyo3::exceptions::PyTypeError::new_err(
            "columns: expected a dict {TARGET: 'SOURCE[*SCALE]'} or a list of 'TARGET=SOURCE[*SCALE]' strings",
        )
    };
    let entries = match columns {
        None => Vec::new(),
        Some(c) => match c.cast::<pyo3::types::PyDict>() {
            Ok(d) => (d.iter())
                .map(
                    |(k, v)| match (k.extract::<String>(), v.extract::<String>()) {
                        (Ok(k), Ok(v)) => Ok(format!("{k}={v}")),
                        _ => Err(expected()),
                    },
                )
                .collect::<PyResult<Vec<String>>>()?,
            Err(_) if c.is_instance_of::<pyo3::types::PyString>() => return Err(expected()),
            Err(_) => c.extract::<Vec<String>>().map_err(|_| expected())?,
        },
    };
    Ok(crate::io::ColumnMap::new(
        &entries,
        &ignore_columns.unwrap_or_default(),
    )?)
}

/// The Recordings of `q` where it is a list or tuple of them (None where it is anything else:
/// an array of numbers); a list of which some are Recordings and some not is a TypeError.
pub(crate) fn recordings_of(
    q: &Bound<'_, PyAny>,
) -> PyResult<Option<Vec<Arc<crate::logs::recording::Recording>>>> {
    let items: Vec<Bound<'_, PyAny>> = match (
        q.cast::<pyo3::types::PyList>(),
        q.cast::<pyo3::types::PyTuple>(),
    ) {
        (Ok(l), _) => l.iter().collect(),
        (_, Ok(t)) => t.iter().collect(),
        _ => return Ok(None),
    };
    let recs: Vec<Option<Arc<crate::logs::recording::Recording>>> = (items.iter())
        .map(|x| x.cast::<PyRecording>().ok().map(|r| r.get().rec.clone()))
        .collect();
    match recs.iter().filter(|r| r.is_some()).count() {
        0 => Ok(None),
        k if k == recs.len() => Ok(Some(recs.into_iter().flatten().collect())),
        _ => Err(pyo3::exceptions::PyTypeError::new_err(
            "q: a list of Recordings (runs to fit together) or an array of positions, not a mix",
        )),
    }
}
