//! `perturbid_rs.Robot`: a robot model with its dynamics, on numpy arrays.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use numpy::PyArray1;
use pyo3::prelude::*;

use super::detached;

use super::arrays::{output_array, read_batch, write_into, write_into_all};
use super::arrays::{ArrayLike, Samples};
use super::linearization::PyLinearization;
use crate::algorithms::parallel::{self, Workspace};
use crate::error::Result;
use crate::gravity::Gravity;
use crate::states::States;
use crate::{robots, urdf, Model};

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
    work: Mutex<Workspace>,
}

impl PyRobot {
    pub(crate) fn new(model: Model) -> Self {
        let work = Mutex::new(Workspace::new(&model));
        Self { model, work }
    }

    fn workspace(&self) -> MutexGuard<'_, Workspace> {
        self.work
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Runs the batch algorithm `f` of the library's engine ([`parallel`]), for the method
    /// `name` (in errors), on the states `args` (q, then qd and qdd when given), writing
    /// `out_dims` values per sample into `out` (checked, see [`output_array`]) or a new array.
    /// Large batches run with the GIL released; a few samples keep it (releasing costs more
    /// than the work).
    #[allow(clippy::too_many_arguments)]
    fn batch<'py, F>(
        &self,
        py: Python<'py>,
        name: &str,
        args: &[(&str, &Samples<'py>)],
        out_dims: &[usize],
        out: Option<Bound<'py, PyAny>>,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: FnOnce(&Model, &mut Workspace, &States<'_>, &mut [f64]) -> Result<()> + Send,
    {
        let n = self.model.nv;
        let batch = read_batch(n, args)?;
        let out = output_array(py, out, batch.k, batch.single, out_dims)?;
        let inputs: Vec<&Samples> = args.iter().map(|a| a.1).collect();
        write_into(&out, &inputs, |values| {
            compute(py, name, batch.k, n, || {
                let states = batch.states(n)?;
                f(&self.model, &mut self.workspace(), &states, values)
            })
        })?;
        Ok(out.into_any())
    }
}

/// Calls with at least this many samples times joints release the GIL.
const DETACH_FROM: usize = 256;

/// Runs `work` (for the method `name`, on `k` samples of `n` joints) with the GIL released when
/// the call is large enough to pay for it, with the GIL held otherwise; panics become errors
/// either way.
fn compute<T: Send>(
    py: Python<'_>,
    name: &str,
    k: usize,
    n: usize,
    work: impl FnOnce() -> Result<T> + Send,
) -> Result<T> {
    if k * (n + 1) < DETACH_FROM {
        crate::error::catch_panics(name, work)
    } else {
        detached(py, name, work)
    }
}

/// `physical_consistency`'s answer: consistent, per-body dicts, negative friction terms.
type Consistency<'py> = (
    bool,
    Vec<Bound<'py, pyo3::types::PyDict>>,
    Vec<(String, f64)>,
);

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
        let model = detached(py, "Robot.from_urdf", || {
            urdf::model_from_urdf_file(&path, &options)
        })?;
        super::errors::warn_all(py, &model.light_joint_warnings())?;
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
        let model = detached(py, "Robot.from_urdf_string", || {
            urdf::model_from_urdf_str(text, "<string>", &options)
        })?;
        super::errors::warn_all(py, &model.light_joint_warnings())?;
        Ok(Self::new(model))
    }

    /// A built-in robot by name: "a465", "a465:kinsheel2010", "a465:physical",
    /// "a465:kinsheel2010_lumped".
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        Ok(Self::new(robots::builtin(name)?))
    }

    /// The robot as URDF text (str), also written to `path` where given (atomically: a
    /// temporary file renamed into place).
    ///
    /// The text is the file the robot was loaded from (a built-in's own), with every link's
    /// `<inertial>` whose body's inertia differs from that file's written anew (in the link's
    /// frame: `rpy="0 0 0"`, centre of mass in m, inertia about it in kg m^2) and every
    /// joint's `<dynamics damping friction armature>` whose viscous (N m s/rad) or Coulomb
    /// (N m) friction or armature (kg m^2) differs; everything else (visuals, collisions,
    /// transmissions, comments) is kept as written. This is how an identified robot
    /// (`ConsistentFit.robot()`) goes to a simulator or a controller. Links moving with
    /// another's body keep their own inertials where the body allows it; where it does not,
    /// a fixed link's inertial moves onto the body's own link, with a warning.
    ///
    /// `payload` (a dict as `identify_payload` gives it: `link`, `mass` kg, `com` m,
    /// `inertia` [ixx, ixy, ixz, iyy, iyz, izz] kg m^2 about the centre of mass, in the
    /// link's frame) is attached as a link `payload_link` of its own, fixed to its link at
    /// the link's origin by joint `<payload_link>_joint`. `note` goes into the comment the
    /// file opens with. Raises `ModelError` where the robot's kinematics or limits differ
    /// from its file's (only inertias, friction and armature are written), where a body
    /// leaves its own link no rigid body, or where the payload's link name is taken; the text
    /// is read back and checked before it is returned.
    #[pyo3(signature = (path=None, *, payload=None, payload_link="payload", note=""))]
    fn to_urdf(
        &self,
        py: Python<'_>,
        path: Option<PathBuf>,
        payload: Option<Bound<'_, PyAny>>,
        payload_link: &str,
        note: &str,
    ) -> PyResult<String> {
        let payload = match &payload {
            Some(p) => super::payload_argument::payload_argument("payload", p)?,
            None => None,
        };
        let written = detached(py, "Robot.to_urdf", || {
            let options = urdf::WriteOptions {
                payload: payload.as_ref(),
                payload_link,
                note,
            };
            let written = urdf::write_urdf(&self.model, &options)?;
            if let Some(path) = &path {
                crate::io::write_atomic(path, written.text.as_bytes())?;
            }
            Ok::<_, crate::error::Error>(written)
        })?;
        super::errors::warn_all(py, &written.warnings)?;
        Ok(written.text)
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

    /// Armature (the motor's rotor inertia reflected to the joint), shape (n,), kg m^2 or kg:
    /// from `<dynamics armature>` or a Drake `<transmission>` (`rotor_inertia * gear_ratio^2`);
    /// adds `armature * qdd` to every torque and `armature` to the diagonal of M, as
    /// Pinocchio's `model.armature`.
    #[getter]
    fn armature<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.armature.clone())
    }

    /// Total mass of the moving links (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.model.moving_mass()
    }

    /// Inverse dynamics `tau = M(q) qdd + c(q, qd) [+ g(q)]` (rigid bodies, no friction).
    /// q, qd, qdd: (n,) or (k, n). Returns tau with the same shape.
    #[pyo3(signature = (q, qd, qdd, gravity=true, out=None))]
    fn rnea<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        qdd: Samples<'py>,
        gravity: bool,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        let args = [("q", &q), ("qd", &qd), ("qdd", &qdd)];
        self.batch(py, "Robot.rnea", &args, &[n], out, |m, w, s, out| {
            parallel::rnea(m, w, s, gravity.into(), out)
        })
    }

    /// The torques the robot's own parameters give, as `validate` compares them with a log's:
    /// `rnea(q, qd, qdd)` (with gravity and each joint's armature) plus each joint's URDF
    /// friction, `damping * qd + friction * sign(qd)` (`sign(0) = 0`). q, qd, qdd: (n,) or
    /// (k, n) (rad, rad/s, rad/s^2); returns N m (N for a prismatic joint), shaped alike.
    #[pyo3(signature = (q, qd, qdd, out=None))]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        qdd: Samples<'py>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        let args = [("q", &q), ("qd", &qd), ("qdd", &qdd)];
        self.batch(py, "Robot.predict", &args, &[n], out, |m, w, s, out| {
            crate::robot_torques::RobotTorques::new(m).predict_into(w, s, out)
        })
    }

    /// Gravity torque g(q): the torque holding the robot at rest. q: (n,) or (k, n).
    #[pyo3(signature = (q, out=None))]
    fn gravity<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.batch(
            py,
            "Robot.gravity",
            &[("q", &q)],
            &[self.model.nv],
            out,
            |m, w, s, out| parallel::rnea(m, w, s, Gravity::Included, out),
        )
    }

    /// Bias torque c(q, qd) [+ g(q)]: the inverse dynamics at zero acceleration.
    #[pyo3(signature = (q, qd, gravity=true, out=None))]
    fn bias<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        gravity: bool,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        self.batch(
            py,
            "Robot.bias",
            &[("q", &q), ("qd", &qd)],
            &[n],
            out,
            |m, w, s, out| parallel::rnea(m, w, s, gravity.into(), out),
        )
    }

    /// Joint-space mass matrix M(q), symmetric positive definite. q: (n,) or (k, n); returns
    /// (n, n) or (k, n, n).
    #[pyo3(signature = (q, out=None))]
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        self.batch(
            py,
            "Robot.mass_matrix",
            &[("q", &q)],
            &[n, n],
            out,
            parallel::mass_matrix,
        )
    }

    /// Joint-torque regressor Phi(q, qd, qdd): `Phi @ theta == rnea(q, qd, qdd)` with `theta`
    /// the 10 inertial parameters of every moving body in Pinocchio's order
    /// `[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]` (kg, kg m, kg m^2; about the body's
    /// joint frame), body after body (see `parameters`). With `friction` (a comma-separated
    /// string or list from 'viscous', 'coulomb', 'offset', 'armature'), those columns follow,
    /// joint after joint: `qd_j`, `sign(qd_j)` (0 at rest), `1`, `qdd_j` in the rows of joint j
    /// (N m s/rad, N m, N m, kg m^2). `Phi @ theta == rnea` needs the 'armature' column when
    /// the robot has an armature.
    /// Returns (n, p) or (k, n, p), p = 10 b + (number of terms) n.
    #[pyo3(signature = (q, qd, qdd, gravity=true, friction=None, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        qdd: Samples<'py>,
        gravity: bool,
        friction: Option<Bound<'py, PyAny>>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (n, p) = (self.model.nv, 10 * self.model.nbodies());
        let args = [("q", &q), ("qd", &qd), ("qdd", &qdd)];
        let Some(friction) = friction else {
            return self.batch(
                py,
                "Robot.regressor",
                &args,
                &[n, p],
                out,
                |m, w, s, out| parallel::regressor(m, w, s, gravity.into(), out),
            );
        };
        let terms = super::arrays::friction_terms(Some(&friction))?;
        let layout = crate::direct::ParameterLayout::new(&self.model, terms);
        let total = layout.len();
        self.batch(
            py,
            "Robot.regressor",
            &args,
            &[n, total],
            out,
            |m, _, s, out| {
                crate::direct::regressor_blocks(m, &layout, s, gravity.into(), |range, phi| {
                    let rows = &mut out[range.start * n * total..range.end * n * total];
                    for (r, row) in rows.chunks_mut(total).enumerate() {
                        for (c, x) in row.iter_mut().enumerate() {
                            *x = phi[(r, c)];
                        }
                    }
                    Ok(())
                })
            },
        )
    }

    /// Physical consistency of a full parameter vector `theta` (default: the model's own
    /// inertial parameters; with `friction` terms, as `regressor(..., friction=...)` orders
    /// them): per body a dict `link`, `mass`, `eigenvalues` of the pseudo-inertia (ascending),
    /// `relative_min` (smallest over largest; below -1e-9 is inconsistent) and `problem` (None
    /// when consistent); returns `(consistent, bodies, negative_friction)` with
    /// `negative_friction` a list of (name, value).
    #[pyo3(signature = (theta=None, friction=None))]
    fn physical_consistency<'py>(
        &self,
        py: Python<'py>,
        theta: Option<ArrayLike<'py>>,
        friction: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Consistency<'py>> {
        let terms = super::arrays::friction_terms(friction.as_ref())?;
        let layout = crate::direct::ParameterLayout::new(&self.model, terms);
        let theta: Vec<f64> = match theta {
            Some(t) => super::arrays::vector("theta", &t)?,
            None => layout.model_parameters(&self.model).as_slice().to_vec(),
        };
        let report = crate::direct::check_physical_consistency(&layout, &theta)?;
        let bodies = report
            .bodies
            .iter()
            .map(|b| {
                let d = pyo3::types::PyDict::new(py);
                d.set_item("link", &b.link)?;
                d.set_item("mass", b.mass)?;
                d.set_item("eigenvalues", b.eigenvalues.to_vec())?;
                d.set_item("relative_min", b.relative_min)?;
                d.set_item("problem", b.problem.clone())?;
                Ok(d)
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((
            report.is_consistent(),
            bodies,
            report.negative_friction.clone(),
        ))
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
    #[pyo3(signature = (q, qd, tau, gravity=true, out=None))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        tau: Samples<'py>,
        gravity: bool,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.nv;
        // tau rides as the third column; the states are q and qd only
        let batch = read_batch(n, &[("q", &q), ("qd", &qd), ("tau", &tau)])?;
        let array = output_array(py, out, batch.k, batch.single, &[n])?;
        write_into(&array, &[&q, &qd, &tau], |out| {
            let work = || -> Result<()> {
                let c = &batch.columns;
                let states = if batch.single {
                    States::single(n, &c[0], Some(&c[1]), None)?
                } else {
                    States::new(n, &c[0], Some(&c[1]), None)?
                };
                let mut w = self.workspace();
                parallel::forward_dynamics(&self.model, &mut w, &states, &c[2], gravity.into(), out)
            };
            compute(py, "Robot.forward_dynamics", batch.k, n, work)
        })?;
        Ok(array.into_any())
    }

    /// Inverse dynamics and its analytic partial derivatives at (q, qd, qdd): returns
    /// `(tau, dtau_dq, dtau_dv, M)` with `tau` shaped like `q` and the matrices `(n, n)` or
    /// `(k, n, n)` (entry `[i, j]` is `d tau_i / d q_j`, `d tau_i / d qd_j`, `M[i, j]`).
    /// Pinocchio's `computeRNEADerivatives`. With `out`, a tuple of four arrays of those shapes
    /// (float64, C-contiguous, writeable) that are written and returned instead of new ones.
    #[pyo3(signature = (q, qd, qdd, gravity=true, out=None))]
    #[allow(clippy::type_complexity)]
    fn rnea_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        qdd: Samples<'py>,
        gravity: bool,
        out: Option<(
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
        )>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        Bound<'py, PyAny>,
        Bound<'py, PyAny>,
        Bound<'py, PyAny>,
    )> {
        let n = self.model.nv;
        let batch = read_batch(n, &[("q", &q), ("qd", &qd), ("qdd", &qdd)])?;
        let (k, single) = (batch.k, batch.single);
        let (o0, o1, o2, o3) = match out {
            Some((a, b, c, d)) => (Some(a), Some(b), Some(c), Some(d)),
            None => (None, None, None, None),
        };
        let tau = output_array(py, o0, k, single, &[n])?;
        let dq = output_array(py, o1, k, single, &[n, n])?;
        let dv = output_array(py, o2, k, single, &[n, n])?;
        let m = output_array(py, o3, k, single, &[n, n])?;
        write_into_all(
            [&tau, &dq, &dv, &m],
            &[&q, &qd, &qdd],
            |[tau, dtau_dq, dtau_dv, m]| {
                let work = || {
                    let states = batch.states(n)?;
                    let out = parallel::DerivativesOut {
                        tau,
                        dtau_dq,
                        dtau_dv,
                        m,
                    };
                    parallel::rnea_derivatives(
                        &self.model,
                        &mut self.workspace(),
                        &states,
                        gravity.into(),
                        out,
                    )
                };
                compute(py, "Robot.rnea_derivatives", k, n, work)
            },
        )?;
        Ok((tau.into_any(), dq.into_any(), dv.into_any(), m.into_any()))
    }

    /// The linearisation at the operating point (q, qd, qdd), computed analytically:
    /// `tau - T* ~= D dqdd + H dqd + G dq`. Returns a `Linearization` (see its attributes);
    /// with a batch (k, n) every attribute gains a leading axis k.
    #[pyo3(signature = (q, qd, qdd, gravity=true, out=None))]
    #[allow(clippy::type_complexity)]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        q: Samples<'py>,
        qd: Samples<'py>,
        qdd: Samples<'py>,
        gravity: bool,
        out: Option<(
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
            Bound<'py, PyAny>,
        )>,
    ) -> PyResult<PyLinearization> {
        let n = self.model.nv;
        let batch = read_batch(n, &[("q", &q), ("qd", &qd), ("qdd", &qdd)])?;
        let (k, single) = (batch.k, batch.single);
        let outs: [Option<Bound<'py, PyAny>>; 5] = match out {
            Some((a, b, c, d, e)) => [Some(a), Some(b), Some(c), Some(d), Some(e)],
            None => [None, None, None, None, None],
        };
        let [o_t, o_d, o_h, o_g, o_gs] = outs;
        let torque = output_array(py, o_t, k, single, &[n])?;
        let d = output_array(py, o_d, k, single, &[n, n])?;
        let h = output_array(py, o_h, k, single, &[n, n])?;
        let g = output_array(py, o_g, k, single, &[n, n])?;
        let g_static = output_array(py, o_gs, k, single, &[n, n])?;
        let arrays = [&torque, &d, &h, &g, &g_static];
        write_into_all(arrays, &[&q, &qd, &qdd], |[torque, d, h, g, g_static]| {
            let work = || {
                let states = batch.states(n)?;
                let out = parallel::LinearizationsOut {
                    torque,
                    d,
                    h,
                    g,
                    g_static,
                };
                parallel::linearize(
                    &self.model,
                    &mut self.workspace(),
                    &states,
                    gravity.into(),
                    out,
                )
            };
            compute(py, "Robot.linearize", k, n, work)
        })?;
        Ok(PyLinearization {
            torque: torque.into_any().unbind(),
            d: d.into_any().unbind(),
            h: h.into_any().unbind(),
            g: g.into_any().unbind(),
            g_static: g_static.into_any().unbind(),
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, n={}, joints={:?})",
            self.model.name, self.model.nv, self.model.joint_names
        )
    }
}

/// The URDF text of a built-in A465 variant ("kinsheel2010", "physical" or
/// "kinsheel2010_lumped").
#[pyfunction]
#[pyo3(signature = (variant="kinsheel2010"))]
pub(crate) fn a465_urdf(variant: &str) -> PyResult<&'static str> {
    Ok(robots::a465::urdf(variant)?)
}
