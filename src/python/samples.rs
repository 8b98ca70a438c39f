//! Python: the samples a direct fit, a base-parameter model's prediction or a validation takes:
//! arrays (`q`, `qd`, `qdd`, `tau`, with the log's time `t` and the Coulomb column `coulomb`
//! where given), or a `Recording` whole in place of `q`, whose own velocities, accelerations,
//! torques, time and Coulomb column then go with it. A preprocessed recording's Coulomb column
//! (sign(qd) filtered as its torques were) cannot be forgotten that way.

use pyo3::prelude::*;

use pyo3::exceptions::PyTypeError;

use super::arrays::{rows, vec1, ArrayLike};
use super::recording::PyRecording;
use crate::error::Error;

/// The samples as the arrays the callers read (each a numpy array or array-like).
pub(crate) struct Samples<'py> {
    pub q: Bound<'py, PyAny>,
    pub qd: Bound<'py, PyAny>,
    pub qdd: Bound<'py, PyAny>,
    /// The measured torques, where the caller takes them.
    pub tau: Option<Bound<'py, PyAny>>,
    /// The log's time (s), where given or the recording's.
    pub t: Option<Bound<'py, PyAny>>,
    /// The Coulomb term's column, where given or the recording has one.
    pub coulomb: Option<Bound<'py, PyAny>>,
}

/// [`Samples`] read as arrays of real numbers.
pub(crate) struct SampleArrays<'py> {
    pub q: ArrayLike<'py>,
    pub qd: ArrayLike<'py>,
    pub qdd: ArrayLike<'py>,
    pub tau: Option<ArrayLike<'py>>,
    pub t: Option<ArrayLike<'py>>,
    pub coulomb: Option<ArrayLike<'py>>,
}

impl<'py> Samples<'py> {
    /// Each read as an array of real numbers; a TypeError names the argument.
    pub(crate) fn arrays(&self) -> PyResult<SampleArrays<'py>> {
        let read = |name: &str, b: &Bound<'py, PyAny>| -> PyResult<ArrayLike<'py>> {
            b.extract().map_err(|e: PyErr| {
                if e.is_instance_of::<PyTypeError>(b.py()) {
                    PyTypeError::new_err(format!("argument '{name}': {}", e.value(b.py())))
                } else {
                    e
                }
            })
        };
        let maybe = |name: &str, b: &Option<Bound<'py, PyAny>>| {
            b.as_ref().map(|b| read(name, b)).transpose()
        };
        Ok(SampleArrays {
            q: read("q", &self.q)?,
            qd: read("qd", &self.qd)?,
            qdd: read("qdd", &self.qdd)?,
            tau: maybe("tau", &self.tau)?,
            t: maybe("t", &self.t)?,
            coulomb: maybe("coulomb", &self.coulomb)?,
        })
    }
}

/// What a caller was given beside `q`, each None where not given.
pub(crate) struct Given<'py> {
    pub qd: Option<Bound<'py, PyAny>>,
    pub qdd: Option<Bound<'py, PyAny>>,
    pub tau: Option<Bound<'py, PyAny>>,
    pub t: Option<Bound<'py, PyAny>>,
    pub coulomb: Option<Bound<'py, PyAny>>,
}

impl Given<'_> {
    /// The name of the first of them given (a caller that takes a Recording, which carries
    /// its own, refuses it); None where none is.
    pub(crate) fn first_given(&self) -> Option<&'static str> {
        [
            ("qd", &self.qd),
            ("qdd", &self.qdd),
            ("tau", &self.tau),
            ("t", &self.t),
            ("coulomb", &self.coulomb),
        ]
        .into_iter()
        .find_map(|(name, v)| v.is_some().then_some(name))
    }
}

/// The samples of `q` (arrays, or a Recording) and `given`: with a Recording, nothing else
/// may be given (it carries its own) and it must have velocities and accelerations; with
/// arrays, `qd` and `qdd` are required, and `tau` where `wants_tau`. `wants_t`: whether the
/// caller checks a log's derivatives against its time (a recording's time is then passed).
pub(crate) fn samples<'py>(
    q: Bound<'py, PyAny>,
    given: Given<'py>,
    wants_tau: bool,
    wants_t: bool,
) -> PyResult<Samples<'py>> {
    let py = q.py();
    if super::recording::recordings_of(&q)?.is_some() {
        return Err(Error::invalid(
            "q",
            "a list of Recordings, which only the fits take (identify_base_parameters, identify_consistent_parameters: runs fitted together); give one Recording, or arrays",
        )
        .into());
    }
    let Ok(recording) = q.cast::<PyRecording>() else {
        let missing = |name: &str| {
            Error::invalid(
                name,
                "missing: with arrays as q, give qd, qdd and tau as arrays too (or a Recording as q, alone)",
            )
        };
        let tau = match given.tau {
            None if wants_tau => return Err(missing("tau").into()),
            tau => tau,
        };
        return Ok(Samples {
            qd: given.qd.ok_or_else(|| missing("qd"))?,
            qdd: given.qdd.ok_or_else(|| missing("qdd"))?,
            q,
            tau,
            t: given.t,
            coulomb: given.coulomb,
        });
    };
    if let Some(name) = given.first_given() {
        return Err(Error::invalid(
            name,
            "given with a Recording as q, which carries its own: pass the Recording alone, or arrays for all",
        )
        .into());
    }
    let rec = &recording.get().rec;
    let (Some(qd), Some(qdd)) = (&rec.qd, &rec.qdd) else {
        return Err(Error::invalid(
            "q",
            format!(
                "the Recording '{}' has no velocities and accelerations (a log as read): preprocess it first (perturbid_rs.preprocess), or read one with qd and qdd columns",
                rec.name
            ),
        )
        .into());
    };
    let n = rec.n;
    Ok(Samples {
        q: rows(py, &rec.q, n)?,
        qd: rows(py, qd, n)?,
        qdd: rows(py, qdd, n)?,
        tau: if wants_tau {
            Some(rows(py, &rec.tau, n)?)
        } else {
            None
        },
        t: wants_t.then(|| vec1(py, &rec.t)),
        coulomb: rec.coulomb.as_ref().map(|c| rows(py, c, n)).transpose()?,
    })
}
