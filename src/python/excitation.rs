//! The direct method's excitation in Python: `design_excitation` (`ExcitationDesign`),
//! mirroring `crate::direct::excitation`.

use pyo3::prelude::*;

use super::detached;
use super::direct::{friction_terms, FrictionNames};
use super::robot::PyRobot;
use super::scalars;
use super::trajectory::PyFourier;
use crate::direct::excitation::ExcitationDesign;
use crate::direct::{design_excitation as design_rs, Criterion, ExcitationOptions};
use crate::trajectory::FourierTrajectory;

/// A designed excitation: `trajectory` (a FourierTrajectory), `cond` (cond of the base
/// regressor), `value` (the criterion) and `evaluations`.
#[pyclass(name = "ExcitationDesign", module = "perturbid_rs", frozen)]
pub(crate) struct PyExcitationDesign {
    design: ExcitationDesign,
}

impl PyExcitationDesign {
    /// The designed trajectory.
    pub(crate) fn trajectory_ref(&self) -> &FourierTrajectory {
        &self.design.trajectory
    }
}

#[pymethods]
impl PyExcitationDesign {
    #[getter]
    fn trajectory(&self) -> PyFourier {
        PyFourier {
            traj: self.design.trajectory.clone(),
        }
    }
    #[getter]
    fn cond(&self) -> f64 {
        self.design.cond
    }
    #[getter]
    fn value(&self) -> f64 {
        self.design.value
    }
    /// The workspace and effort constraints with their smallest slack over a period (m beyond
    /// each workspace margin; `1 - |tau| / (margin effort)` per joint), as a dict.
    #[getter]
    fn margins(&self) -> std::collections::BTreeMap<String, f64> {
        self.design.margins.iter().cloned().collect()
    }
    #[getter]
    fn evaluations(&self) -> usize {
        self.design.evaluations
    }
    /// `trajectory.sample(t)`.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.trajectory().sample(py, t)
    }
    fn __repr__(&self) -> String {
        format!(
            "ExcitationDesign(cond={:.4}, evaluations={})",
            self.design.cond, self.design.evaluations
        )
    }
}

/// Designs a Fourier excitation for `robot` minimising `criterion` ('cond' or 'logdet') of the
/// base regressor subject to the limits (times `margin`), starting and ending at rest when
/// `rest`. COBYLA, seeded; `progress=True` logs the progress every 100 evaluations to Python's
/// `logging` (logger `perturbid_rs.excitation`, level INFO).
#[pyfunction]
#[pyo3(signature = (robot, harmonics=5, base_frequency=0.1, criterion="cond", seed=0, *, rest=true, samples=100, margin=0.9, max_evaluations=2000, friction=Some(FrictionNames::Many(vec!["viscous".into(), "coulomb".into()])), progress=false, workspace=None, effort_limits=true),
    text_signature = "(robot, harmonics=5, base_frequency=0.1, criterion='cond', seed=0, *, rest=True, samples=100, margin=0.9, max_evaluations=2000, friction=('viscous', 'coulomb'), progress=False, workspace=None, effort_limits=True)")]
#[allow(clippy::too_many_arguments)]
pub(crate) fn design_excitation(
    py: Python<'_>,
    robot: &PyRobot,
    #[pyo3(from_py_with = scalars::count)] harmonics: usize,
    #[pyo3(from_py_with = scalars::real)] base_frequency: f64,
    criterion: &str,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
    rest: bool,
    #[pyo3(from_py_with = scalars::count)] samples: usize,
    #[pyo3(from_py_with = scalars::real)] margin: f64,
    #[pyo3(from_py_with = scalars::count)] max_evaluations: usize,
    friction: Option<FrictionNames<'_>>,
    progress: bool,
    workspace: Option<Bound<'_, PyAny>>,
    effort_limits: bool,
) -> PyResult<PyExcitationDesign> {
    // workspace constraints: a list of dicts (or a JSON string), read as the JSON file is
    let workspace = match workspace {
        None => vec![],
        Some(w) => {
            let text: String = match w.extract::<String>() {
                Ok(s) => s,
                Err(_) => py.import("json")?.call_method1("dumps", (w,))?.extract()?,
            };
            crate::direct::workspace_from_json(&text, "workspace")?
        }
    };
    let mut o = ExcitationOptions {
        harmonics,
        base_frequency,
        criterion: criterion.parse::<Criterion>()?,
        seed,
        rest,
        samples,
        margin,
        max_evaluations,
        workspace,
        effort: effort_limits,
        ..ExcitationOptions::default()
    };
    o.friction = friction_terms(friction)?;
    let design = detached(py, "design_excitation", || {
        let mut report = |e: usize, best: f64| {
            if e.is_multiple_of(100) {
                log::info!(
                    target: "perturbid_rs::excitation",
                    "excitation design: {e} evaluations, best criterion {best:.4}"
                )
            }
        };
        design_rs(
            &robot.model,
            &o,
            if progress { Some(&mut report) } else { None },
        )
    })?;
    super::errors::warn_all(py, &design.warnings(&robot.model))?;
    Ok(PyExcitationDesign { design })
}
