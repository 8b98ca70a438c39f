//! `perturbid_rs.Robot`: a robot model with its dynamics, on numpy arrays.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn};
use pyo3::prelude::*;

use super::arrays::{read_batch, to_numpy};
use super::linearization::PyLinearization;
use crate::algorithms::batch::{mass_matrix_batch, regressor_batch, rnea_lanes, LaneData, LANES};
use crate::error::Result;
use crate::{robots, urdf, Data, Model};

type ArrayLike<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// A robot model (immutable) with the dynamics algorithms.
///
/// Build it with `Robot.from_urdf(path)`, `Robot.from_urdf_string(text)` or
/// `perturbid_rs.robots.a465()`. Every method takes numpy float64 arrays (anything
/// convertible): one sample as shape `(n,)` or a batch of `k` samples as shape `(k, n)`, and
/// returns arrays shaped to match. Units: rad, rad/s, rad/s^2 and N m for revolute joints;
/// m, m/s, m/s^2 and N for prismatic ones. Gravity is 9.81 m/s^2 along -z of the base frame.
#[pyclass(name = "Robot", module = "perturbid_rs", frozen)]
pub(crate) struct PyRobot {
    pub(crate) model: Model,
    work: Mutex<Work>,
}

/// The work buffers of one thread: a [`Data`] for the one-sample algorithms and a [`LaneData`]
/// for the multi-sample kernel.
pub(crate) struct Work {
    pub(crate) data: Data,
    lanes: LaneData,
}

impl Work {
    fn new(model: &Model) -> Self {
        Self {
            data: Data::new(model),
            lanes: LaneData::new(model),
        }
    }
}

/// Samples `first..first + len` of a batch: one row-major `len x n` slice per argument.
struct Chunk<'a> {
    first: usize,
    len: usize,
    /// Missing arguments are empty.
    columns: [&'a [f64]; 3],
    /// Whether the call was given single samples (errors then name no sample).
    single: bool,
}

impl Chunk<'_> {
    /// Fails on the first non-finite argument value, naming the argument (`names`, in order)
    /// and the sample: one fast pass over the chunk, a sample at a time only to find a bad one.
    fn check_finite(&self, model: &Model, names: &[&str]) -> Result<()> {
        let n = model.nv;
        let bad = |c: &&[f64]| c.iter().fold(false, |bad, v| bad | !v.is_finite());
        if self.columns.iter().any(bad) {
            for i in 0..self.len {
                for (name, column) in names.iter().zip(&self.columns) {
                    model
                        .check_vector(name, &column[i * n..(i + 1) * n])
                        .map_err(|e| self.at(i, e))?;
                }
            }
        }
        Ok(())
    }

    /// An error raised at sample `i` of the chunk, renamed for its sample in the batch.
    fn at(&self, i: usize, e: crate::error::Error) -> crate::error::Error {
        if self.single {
            e
        } else {
            e.in_sample(self.first + i)
        }
    }
}

impl PyRobot {
    fn new(model: Model) -> Self {
        let work = Mutex::new(Work::new(&model));
        Self { model, work }
    }

    pub(crate) fn work(&self) -> MutexGuard<'_, Work> {
        self.work
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Evaluates `f` on the chunks of the batch `args` with the GIL released, in parallel
    /// (rayon, one [`Work`] per chunk, so no per-sample allocation) for large batches; `f`
    /// writes the chunk's results (`out_dims` values per sample, row-major) into its slice.
    fn map_chunks<'py, F>(
        &self,
        py: Python<'py>,
        args: &[(&str, &ArrayLike<'py>)],
        out_dims: &[usize],
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&Model, &mut Work, &Chunk<'_>, &mut [f64]) -> Result<()> + Send + Sync,
    {
        let (out, k, single) = self.run_chunks(py, args, out_dims.iter().product(), f)?;
        to_numpy(py, out, k, single, out_dims)
    }

    /// [`PyRobot::map_chunks`] returning the results as one row-major buffer of `size` values
    /// per sample, with the number of samples and whether the call was given single samples.
    fn run_chunks<'py, F>(
        &self,
        py: Python<'py>,
        args: &[(&str, &ArrayLike<'py>)],
        size: usize,
        f: F,
    ) -> PyResult<(Vec<f64>, usize, bool)>
    where
        F: Fn(&Model, &mut Work, &Chunk<'_>, &mut [f64]) -> Result<()> + Send + Sync,
    {
        let n = self.model.nv;
        let batch = read_batch(n, args)?;
        let mut out = vec![0.0; batch.k * size];
        py.detach(|| -> Result<()> {
            let run = |work: &mut Work, first: usize, out: &mut [f64]| -> Result<()> {
                let len = out.len() / size.max(1);
                let mut columns: [&[f64]; 3] = [&[]; 3];
                for (c, column) in columns.iter_mut().zip(&batch.columns) {
                    *c = &column[first * n..(first + len) * n];
                }
                f(
                    &self.model,
                    work,
                    &Chunk {
                        first,
                        len,
                        columns,
                        single: batch.single,
                    },
                    out,
                )
            };
            if batch.k < PARALLEL_BATCH || size == 0 {
                return run(&mut self.work(), 0, &mut out);
            }
            use rayon::prelude::*;
            out.par_chunks_mut(PARALLEL_CHUNK * size)
                .enumerate()
                .try_for_each(|(c, o)| run(&mut Work::new(&self.model), c * PARALLEL_CHUNK, o))
        })?;
        Ok((out, batch.k, batch.single))
    }

    /// [`PyRobot::map_chunks`] one sample at a time: `f` gets the sample's arguments and
    /// writes its `out_dims` values.
    fn map_samples<'py, F>(
        &self,
        py: Python<'py>,
        args: &[(&str, &ArrayLike<'py>)],
        out_dims: &[usize],
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&Model, &mut Data, [&[f64]; 3], &mut [f64]) -> Result<()> + Send + Sync,
    {
        let n = self.model.nv;
        let size: usize = out_dims.iter().product();
        self.map_chunks(py, args, out_dims, |m, w, chunk, out| {
            for (i, o) in out.chunks_mut(size.max(1)).enumerate() {
                let mut rows: [&[f64]; 3] = [&[]; 3];
                for (row, column) in rows.iter_mut().zip(&chunk.columns) {
                    if !column.is_empty() {
                        *row = &column[i * n..(i + 1) * n];
                    }
                }
                f(m, &mut w.data, rows, o).map_err(|e| chunk.at(i, e))?;
            }
            Ok(())
        })
    }

    /// Inverse dynamics of a batch with `qd` and `qdd` optional (zeros), by the multi-sample
    /// kernel; the arguments' finiteness is checked first, sample by sample.
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        args: &[(&str, &ArrayLike<'py>)],
        gravity: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        let names: Vec<&str> = args.iter().map(|a| a.0).collect();
        self.map_chunks(py, args, &[n], |m, w, chunk, out| {
            chunk.check_finite(m, &names)?;
            let [q, qd, qdd] = chunk.columns;
            fn opt(x: &[f64]) -> Option<&[f64]> {
                (!x.is_empty()).then_some(x)
            }
            /// Sample `i` of `x`, or `zeros` for a missing argument.
            fn row<'a>(x: &'a [f64], zeros: &'a [f64], i: usize) -> &'a [f64] {
                let n = zeros.len();
                if x.is_empty() {
                    zeros
                } else {
                    &x[i * n..(i + 1) * n]
                }
            }
            if chunk.len < LANES {
                // too few samples to fill the lanes: one at a time
                let zeros = vec![0.0; n];
                for (i, o) in out.chunks_mut(n).enumerate() {
                    let (a, b, c) = (row(q, &zeros, i), row(qd, &zeros, i), row(qdd, &zeros, i));
                    crate::rnea(m, &mut w.data, a, b, c, gravity.into())?;
                    o.copy_from_slice(w.data.tau.as_slice());
                }
                return Ok(());
            }
            rnea_lanes(m, &mut w.lanes, q, opt(qd), opt(qdd), gravity.into(), out)
        })
    }
}

/// Batches of at least this many samples run in parallel (rayon), in chunks of
/// `PARALLEL_CHUNK` samples.
const PARALLEL_BATCH: usize = 4096;
const PARALLEL_CHUNK: usize = 1024;

fn copy_matrix(m: &nalgebra::DMatrix<f64>, out: &mut [f64]) {
    let n = m.ncols();
    for r in 0..m.nrows() {
        for c in 0..n {
            out[r * n + c] = m[(r, c)];
        }
    }
}

fn load_options(
    lock: Option<BTreeMap<String, f64>>,
    check_triangle_inequality: bool,
) -> urdf::LoadOptions {
    urdf::LoadOptions {
        lock: lock.unwrap_or_default(),
        check_triangle_inequality,
    }
}

#[pymethods]
impl PyRobot {
    /// Loads a robot from a URDF file.
    ///
    /// `lock` maps joint names to positions (rad or m) at which those joints are held: they
    /// become fixed (mimic joints following them too). `check_triangle_inequality=False`
    /// accepts link inertias that no rigid body has (e.g. a rotor inertia lumped about one
    /// axis). Raises `ModelError` naming the file, line and element of any problem.
    #[staticmethod]
    #[pyo3(signature = (path, lock=None, check_triangle_inequality=true))]
    fn from_urdf(
        py: Python<'_>,
        path: PathBuf,
        lock: Option<BTreeMap<String, f64>>,
        check_triangle_inequality: bool,
    ) -> PyResult<Self> {
        let options = load_options(lock, check_triangle_inequality);
        let model = py.detach(|| urdf::model_from_urdf_file(&path, &options))?;
        Ok(Self::new(model))
    }

    /// Loads a robot from URDF text; see `from_urdf`.
    #[staticmethod]
    #[pyo3(signature = (text, lock=None, check_triangle_inequality=true))]
    fn from_urdf_string(
        py: Python<'_>,
        text: &str,
        lock: Option<BTreeMap<String, f64>>,
        check_triangle_inequality: bool,
    ) -> PyResult<Self> {
        let options = load_options(lock, check_triangle_inequality);
        let model = py.detach(|| urdf::model_from_urdf_str(text, "<string>", &options))?;
        Ok(Self::new(model))
    }

    /// A built-in robot by name: "a465", "a465:kinsheel2010", "a465:physical".
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        Ok(Self::new(robots::builtin(name)?))
    }

    /// Robot name from the URDF.
    #[getter]
    fn name(&self) -> &str {
        &self.model.name
    }

    /// Number of degrees of freedom (mimic joints add none, locked joints are removed).
    #[getter]
    fn n(&self) -> usize {
        self.model.nv
    }

    /// Names of the joints of the degrees of freedom, in coordinate order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joint_names.clone()
    }

    /// Lower position limits, shape (n,) (rad or m; -inf for continuous joints).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.lower())
    }

    /// Upper position limits, shape (n,) (rad or m; +inf for continuous joints).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.upper())
    }

    /// Speed limits, shape (n,) (rad/s or m/s; inf where the URDF gives none).
    #[getter]
    fn velocity_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.velocity_limit())
    }

    /// Effort limits, shape (n,) (N m or N; inf where the URDF gives none).
    #[getter]
    fn effort_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.effort_limit())
    }

    /// Acceleration limits, shape (n,) (rad/s^2 or m/s^2; URDF 1.2 `acceleration`, else inf).
    #[getter]
    fn acceleration_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.acceleration_limit())
    }

    /// Viscous friction coefficients from URDF `<dynamics damping>`, shape (n,).
    #[getter]
    fn damping<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.limits.iter().map(|l| l.damping).collect())
    }

    /// Coulomb friction from URDF `<dynamics friction>`, shape (n,).
    #[getter]
    fn friction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.limits.iter().map(|l| l.friction).collect())
    }

    /// Total mass of the moving links (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.model.moving_mass()
    }

    /// Inverse dynamics `tau = M(q) qdd + c(q, qd) [+ g(q)]` (rigid bodies, no friction).
    /// q, qd, qdd: (n,) or (k, n). Returns tau with the same shape.
    #[pyo3(signature = (q, qd, qdd, gravity=true))]
    fn rnea<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
        gravity: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.inverse_dynamics(py, &[("q", &q), ("qd", &qd), ("qdd", &qdd)], gravity)
    }

    /// Gravity torque g(q): the torque holding the robot at rest. q: (n,) or (k, n).
    fn gravity<'py>(&self, py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.inverse_dynamics(py, &[("q", &q)], true)
    }

    /// Bias torque c(q, qd) [+ g(q)]: the inverse dynamics at zero acceleration.
    #[pyo3(signature = (q, qd, gravity=true))]
    fn bias<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        gravity: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.inverse_dynamics(py, &[("q", &q), ("qd", &qd)], gravity)
    }

    /// Joint-space mass matrix M(q), symmetric positive definite. q: (n,) or (k, n); returns
    /// (n, n) or (k, n, n).
    fn mass_matrix<'py>(&self, py: Python<'py>, q: ArrayLike<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        self.map_chunks(py, &[("q", &q)], &[n, n], |m, w, chunk, out| {
            chunk.check_finite(m, &["q"])?;
            let q = chunk.columns[0];
            if chunk.len >= LANES {
                return mass_matrix_batch(m, &mut w.lanes, q, out);
            }
            // too few samples to fill the lanes: one at a time
            for (i, o) in out.chunks_mut(n * n).enumerate() {
                crate::mass_matrix(m, &mut w.data, &q[i * n..(i + 1) * n])
                    .map_err(|e| chunk.at(i, e))?;
                copy_matrix(&w.data.m, o);
            }
            Ok(())
        })
    }

    /// Joint-torque regressor Phi(q, qd, qdd): `Phi @ theta == rnea(q, qd, qdd)` with `theta`
    /// the 10 inertial parameters of every moving body in Pinocchio's order
    /// `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (kg, kg m, kg m^2; about the body's
    /// joint frame), body after body (see `parameters`). Returns (n, 10 b) or (k, n, 10 b).
    #[pyo3(signature = (q, qd, qdd, gravity=true))]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
        gravity: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (n, p) = (self.model.nv, 10 * self.model.nbodies());
        let args = [("q", &q), ("qd", &qd), ("qdd", &qdd)];
        self.map_chunks(py, &args, &[n, p], move |m, w, chunk, out| {
            chunk.check_finite(m, &["q", "qd", "qdd"])?;
            let [q, qd, qdd] = chunk.columns;
            if chunk.len >= LANES {
                return regressor_batch(m, &mut w.lanes, q, qd, qdd, gravity.into(), out);
            }
            // too few samples to fill the lanes: one at a time
            let d = &mut w.data;
            let mut y = std::mem::take(&mut d.regressor);
            let result = out.chunks_mut(n * p).enumerate().try_for_each(|(i, o)| {
                let r = i * n..(i + 1) * n;
                crate::algorithms::regressor::joint_torque_regressor(
                    m,
                    d,
                    &q[r.clone()],
                    &qd[r.clone()],
                    &qdd[r],
                    gravity.into(),
                    &mut y,
                )
                .map_err(|e| chunk.at(i, e))?;
                copy_matrix(&y, o);
                Ok(())
            });
            d.regressor = y; // back in place even after an error
            result
        })
    }

    /// The model's own inertial parameters, shape (10 b,), in the order of `regressor`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(
            py,
            crate::algorithms::regressor::model_parameters(&self.model)
                .as_slice()
                .to_vec(),
        )
    }

    /// Forward dynamics qdd = M(q)^-1 (tau - c(q, qd) [- g(q)]). Shapes as `rnea`.
    #[pyo3(signature = (q, qd, tau, gravity=true))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        tau: ArrayLike<'py>,
        gravity: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.map_samples(
            py,
            &[("q", &q), ("qd", &qd), ("tau", &tau)],
            &[self.model.nv],
            |m, d, x, out| {
                crate::forward_dynamics(m, d, x[0], x[1], x[2], gravity.into())?;
                out.copy_from_slice(d.qdd.as_slice());
                Ok(())
            },
        )
    }

    /// The linearisation at the operating point (q, qd, qdd), computed analytically:
    /// `tau - T* ~= D dqdd + H dqd + G dq`. Returns a `Linearization` (see its attributes);
    /// with a batch (k, n) every attribute gains a leading axis k.
    #[pyo3(signature = (q, qd, qdd, gravity=true))]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
        gravity: bool,
    ) -> PyResult<PyLinearization> {
        let n = self.model.nv;
        let nn = n * n;
        // one record per sample: torque (n), then D, H, G, G_static (n x n each, row-major)
        let size = n + 4 * nn;
        let args = [("q", &q), ("qd", &qd), ("qdd", &qdd)];
        let (packed, k, single) = self.run_chunks(py, &args, size, |m, w, chunk, out| {
            let mut lin = crate::Linearization::zeros(n);
            for (i, o) in out.chunks_mut(size).enumerate() {
                let [q, qd, qdd] = chunk.columns.map(|c| &c[i * n..(i + 1) * n]);
                crate::linearize_into(m, &mut w.data, q, qd, qdd, gravity.into(), &mut lin)
                    .map_err(|e| chunk.at(i, e))?;
                o[..n].copy_from_slice(lin.torque.as_slice());
                for (b, mat) in [&lin.d, &lin.h, &lin.g, &lin.g_static].iter().enumerate() {
                    copy_matrix(mat, &mut o[n + b * nn..n + (b + 1) * nn]);
                }
            }
            Ok(())
        })?;
        let part = |offset: usize, len: usize| -> Vec<f64> {
            packed
                .chunks(size.max(1))
                .flat_map(|r| r[offset..offset + len].iter().copied())
                .collect()
        };
        let matrix = |b: usize| -> PyResult<Py<PyAny>> {
            Ok(to_numpy(py, part(n + b * nn, nn), k, single, &[n, n])?.unbind())
        };
        Ok(PyLinearization {
            torque: to_numpy(py, part(0, n), k, single, &[n])?.unbind(),
            d: matrix(0)?,
            h: matrix(1)?,
            g: matrix(2)?,
            g_static: matrix(3)?,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, n={}, joints={:?})",
            self.model.name, self.model.nv, self.model.joint_names
        )
    }
}

/// The URDF text of a built-in A465 variant ("kinsheel2010" or "physical").
#[pyfunction]
#[pyo3(signature = (variant="kinsheel2010"))]
pub(crate) fn a465_urdf(variant: &str) -> PyResult<&'static str> {
    Ok(robots::a465::urdf(variant)?)
}
