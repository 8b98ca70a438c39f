//! Python: `LocalModel`, the paper's local model at an operating point with its uncertainty and
//! diagnostics (mirrors `crate::local::LocalModel`).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::arrays::{at_states, matrix_to_numpy as mat, read_batch, to_numpy, vec1, ArrayLike};
use super::errors::warn_all;
use super::operating_point::PyOperatingPoint;
use crate::document::Document;
use crate::local::{Estimate, Estimator, LocalModel, ReversalHandling};

/// The local model `tau ~= T* + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)` at an operating
/// point, with its uncertainty.
///
/// - `torque` (`T*`, `(n,)`), `D`, `H`, `G`, `G_static` (`(n, n)`, row = torque, column =
///   joint; None when the plan had no such experiment);
/// - `cond`: dict of cond(X) per estimate (columns scaled to unit norm);
/// - `stderr`: dict of standard errors, same shapes ('torque', 'D', 'H', 'G', 'G_static');
/// - `residual_rms`: dict of per-joint regression residual RMS (N m);
/// - `planned_op`: the operating point of the plan, which the nominal passes crossed: T* holds
///   there and `predict` expands about it; `op`: the point as measured at the nominal crossings
///   (a diagnostic of the tracking; noisier than the plan);
/// - `diagnostics`: clock offsets, velocity reversals met at crossings, warnings;
/// - `coulomb`: the Coulomb steps of the friction-aware H regression, when used.
#[pyclass(name = "LocalModel", module = "perturbid_rs", frozen)]
pub(crate) struct PyLocalModel {
    pub model: LocalModel,
}

impl PyLocalModel {
    fn parts(&self) -> [(&'static str, &Option<Estimate>); 4] {
        let m = &self.model;
        [
            ("D", &m.d),
            ("H", &m.h),
            ("G", &m.g),
            ("G_static", &m.g_static),
        ]
    }
    fn get<'py>(
        &self,
        py: Python<'py>,
        e: &Option<Estimate>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        e.as_ref().map(|e| mat(py, &e.matrix)).transpose()
    }
    /// `f` of the model at the states `q`, `qd`, `qdd` (as `at_states`), with a
    /// PerturbidWarning where they reach beyond the perturbations it was identified over.
    fn near_point<'py>(
        &self,
        py: Python<'py>,
        states: [&ArrayLike<'py>; 3],
        name: &str,
        f: fn(&LocalModel, &crate::states::States<'_>) -> crate::error::Result<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.model;
        let mut beyond = None;
        let out = at_states(py, m.n(), states, name, |s| {
            beyond = m.extrapolation(s)?;
            f(m, s)
        })?;
        let warnings: Vec<String> = beyond.map(|x| x.message()).into_iter().collect();
        warn_all(py, &warnings)?;
        Ok(out)
    }
}

#[pymethods]
impl PyLocalModel {
    /// What happened during the identification: `offsets` (dict experiment -> clock offset
    /// in s found between the recording and the plan), `reversals` (list of dicts:
    /// `experiment`, `crossing` (None for the reference posture), `joint`, `at` (s from the
    /// crossing), `handling` ('narrowed' or 'step'), `window` (s)), `combined` (dict block ->
    /// (relative difference, largest difference in standard errors) of the combined estimate
    /// against the separated one), `unperturbed_deviation` (how far the variables an experiment
    /// did not perturb stray, in standard errors of their measurement: ~1 for noise, far above
    /// for tracking errors), `estimator_evidence` (dict `crossings`, `separated`, `combined`,
    /// `p_value`: each estimator's RMS error predicting the crossings left out of its fit, the
    /// evidence the advice between them rests on; absent without the G, H and D experiments),
    /// `unmeasured` (list of dicts: `experiment`, `joint`, `value` in N m,
    /// for torques that read one value throughout), `noise` (list of dicts, the nominal
    /// passes' first (their `passes` is what `plan_experiments(torque_pass_noise=)` takes),
    /// then each separated regression's: `experiment`, `joint`, `samples` (N m, one torque sample's noise), `passes` (N m, what varied from pass
    /// to pass beyond it, or None), `step` (N m, the step the torque was logged in where it is
    /// coarser than its noise: the standard errors of its rows include the rounding; else
    /// None)), `glitches` (list of dicts: `experiment`, `crossing` (None for the reference
    /// posture), `signal` ('q', 'qd', 'qdd' or 'tau'), `joint`, `sample` (0-based index in its
    /// recording), `time` (s, the recording's clock), `value` (as recorded), `noise_levels`
    /// (how far off the fit of its window's other samples, or None beyond any scale: a million
    /// times the spread of the window's values),
    /// `replaced` (True: an isolated glitch replaced by that fit; False: kept, one of more than
    /// 3 in its window)), `dropouts` (list of dicts: `experiment`, `signal`, `first_sample`
    /// (0-based row of its recording), `samples`, `from`, `to` (s), and for a frozen reading
    /// `joint`, `value`, `noise_levels`: rows in which every joint of a signal read exactly 0
    /// while the robot moved, or one joint's column held one value for more than 10 samples
    /// and then jumped back, removed before the windows were read), `held_readings` (list of dicts: `experiment` and the keys of
    /// `Recording.glitches`: samples of one joint's reading held while it moved, replaced
    /// before the windows were read), `torque_offsets` (list of dicts: `experiment` ('D', 'G'
    /// or 'G_static'), `joint`, `offset` (N m) and `stderr` (N m): torques that do not return
    /// to T*, or to G-static's reference, between the experiment's perturbations; each
    /// experiment's with a warning naming columns that look swapped), `warnings` (list of
    /// str).
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = &self.model.diagnostics;
        let out = PyDict::new(py);
        let offsets = PyDict::new(py);
        for o in &d.offsets {
            offsets.set_item(&o.experiment, o.offset)?;
        }
        out.set_item("offsets", offsets)?;
        let reversals = d
            .reversals
            .iter()
            .map(|r| {
                let e = PyDict::new(py);
                e.set_item("experiment", &r.experiment)?;
                e.set_item("crossing", r.crossing)?;
                e.set_item("joint", &r.joint)?;
                e.set_item("at", r.at)?;
                let handling = match r.handling {
                    ReversalHandling::Narrowed => "narrowed",
                    ReversalHandling::Step => "step",
                };
                e.set_item("handling", handling)?;
                e.set_item("window", r.window)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("reversals", reversals)?;
        let combined = PyDict::new(py);
        for b in &d.combined {
            combined.set_item(&b.block, (b.relative, b.standard_errors))?;
        }
        out.set_item("combined", combined)?;
        out.set_item("unperturbed_deviation", d.unperturbed_deviation)?;
        if let Some(t) = &d.torque_delay {
            let delay = PyDict::new(py);
            delay.set_item("delay", t.delay)?;
            delay.set_item("stderr", t.stderr)?;
            delay.set_item("rows", t.rows)?;
            delay.set_item("unexplained", t.unexplained)?;
            delay.set_item("unexplained_at_zero", t.unexplained_at_zero)?;
            out.set_item("torque_delay", delay)?;
        }
        if let Some(e) = &d.estimator_evidence {
            let evidence = PyDict::new(py);
            evidence.set_item("crossings", e.crossings)?;
            evidence.set_item("separated", e.separated)?;
            evidence.set_item("combined", e.combined)?;
            evidence.set_item("p_value", e.p_value)?;
            out.set_item("estimator_evidence", evidence)?;
        }
        let unmeasured = d
            .unmeasured
            .iter()
            .map(|u| {
                let e = PyDict::new(py);
                e.set_item("experiment", &u.experiment)?;
                e.set_item("joint", &u.joint)?;
                e.set_item("value", u.value)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("unmeasured", unmeasured)?;
        let noise = d
            .noise
            .iter()
            .map(|e| {
                let entry = PyDict::new(py);
                entry.set_item("experiment", &e.experiment)?;
                entry.set_item("joint", &e.joint)?;
                entry.set_item("samples", e.samples)?;
                entry.set_item("passes", e.passes)?;
                entry.set_item("step", e.step)?;
                entry.set_item("position_step", e.position_step)?;
                Ok(entry)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("noise", noise)?;
        let glitches = d
            .glitches
            .iter()
            .map(|g| {
                let e = PyDict::new(py);
                e.set_item("experiment", &g.experiment)?;
                e.set_item("crossing", g.crossing)?;
                e.set_item("signal", &g.signal)?;
                e.set_item("joint", &g.joint)?;
                e.set_item("sample", g.sample)?;
                e.set_item("time", g.time)?;
                e.set_item("value", g.value)?;
                e.set_item("noise_levels", g.noise_levels)?;
                e.set_item("replaced", g.replaced)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("glitches", glitches)?;
        let dropouts = d
            .dropouts
            .iter()
            .map(|r| super::recording::dropout_dict(py, r))
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("dropouts", dropouts)?;
        let held = d
            .held_readings
            .iter()
            .map(|g| super::recording::glitch_dict(py, g))
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("held_readings", held)?;
        let offsets = d
            .torque_offsets
            .iter()
            .map(|t| {
                let e = PyDict::new(py);
                e.set_item("experiment", &t.experiment)?;
                e.set_item("joint", &t.joint)?;
                e.set_item("offset", t.offset)?;
                e.set_item("stderr", t.stderr)?;
                Ok(e)
            })
            .collect::<PyResult<Vec<_>>>()?;
        out.set_item("torque_offsets", offsets)?;
        out.set_item("warnings", d.warnings.clone())?;
        Ok(out)
    }

    /// The Coulomb steps from the friction-aware H regression (None when it was not used):
    /// dict joint name -> step (N m; the two Coulomb levels summed) or None where no pair of H
    /// passes reversed the joint.
    #[getter]
    fn coulomb<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(c) = &self.model.coulomb else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        for (name, step) in c.joint_names.iter().zip(&c.step) {
            out.set_item(name, *step)?;
        }
        Ok(Some(out))
    }

    /// The model as a tidy table (pandas): one row per entry, columns `term` ('T', 'D', 'H',
    /// 'G', 'G_static'), `torque` (the joint whose torque the row is), `joint` (the joint
    /// whose change multiplies the entry; empty for T*), `value` and `std` (NaN where
    /// unknown). Units: N m for T*; N m s^2/rad, N m s/rad, N m/rad for D*, H*, G* (m in
    /// place of rad for prismatic joints).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.model;
        type Part<'a> = (
            &'a str,
            &'a nalgebra::DMatrix<f64>,
            &'a nalgebra::DMatrix<f64>,
        );
        let parts: Vec<Part<'_>> = self
            .parts()
            .iter()
            .filter_map(|(k, e)| e.as_ref().map(|e| (*k, &e.matrix, &e.stderr)))
            .collect();
        super::tables::linear_model_frame(py, &m.joint_names, &m.torque, &m.torque_stderr, &parts)
    }
    #[getter]
    fn torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        vec1(py, &self.model.torque)
    }
    #[getter(D)]
    fn d<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.d)
    }
    #[getter(H)]
    fn h<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.h)
    }
    #[getter(G)]
    fn g<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.g)
    }
    #[getter(G_static)]
    fn g_static<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.g_static)
    }
    /// The drive gains the recordings' signal was put in torques by, where they logged motor
    /// currents (`perturbid identify --gains-from`), else None: dict `gain` and `stderr`,
    /// (n,) each (N m or N per unit of the signal). Their standard errors are in
    /// `predict_stderr`'s, not in the coefficients'.
    #[getter]
    fn drive_gains<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        (self.model.drive_gains.as_ref())
            .map(|g| {
                let d = PyDict::new(py);
                d.set_item("gain", vec1(py, &g.gain))?;
                d.set_item("stderr", vec1(py, &g.stderr))?;
                Ok(d)
            })
            .transpose()
    }
    /// The combined estimate `[D H G]`, shape `(n, 3n)`, or None.
    #[getter]
    fn combined<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.get(py, &self.model.combined)
    }
    #[getter]
    fn cond<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, e.cond)?;
            }
        }
        Ok(d)
    }
    #[getter]
    fn stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("torque", vec1(py, &self.model.torque_stderr))?;
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, mat(py, &e.stderr)?)?;
            }
        }
        Ok(d)
    }
    /// Per term ('D', 'H', 'G', 'G_static', and 'combined' where identified), the correlation
    /// of each row's entries: an (n, m, m) array for m columns (n; 3 n for 'combined'); with
    /// the row's standard errors `se` (`stderr`), `diag(se) R diag(se)` is its covariance. A
    /// model saved before the correlations were stored has none.
    #[getter]
    fn correlation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let combined = ("combined", &self.model.combined);
        for (k, e) in self.parts().into_iter().chain([combined]) {
            let Some(e) = e.as_ref().filter(|e| !e.correlation.is_empty()) else {
                continue;
            };
            let m = e.matrix.ncols();
            let values: Vec<f64> = (e.correlation.iter())
                .flat_map(|r| r.transpose().iter().copied().collect::<Vec<_>>())
                .collect();
            d.set_item(
                k,
                to_numpy(py, values, e.correlation.len(), false, &[m, m])?,
            )?;
        }
        Ok(d)
    }
    #[getter]
    fn residual_rms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, e) in self.parts() {
            if let Some(e) = e {
                d.set_item(k, vec1(py, &e.residual_rms))?;
            }
        }
        Ok(d)
    }
    #[getter]
    fn op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.model.op.clone(),
        }
    }
    #[getter]
    fn planned_op(&self) -> PyOperatingPoint {
        PyOperatingPoint {
            op: self.model.planned_op.clone(),
        }
    }
    #[getter]
    fn joint_names<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, &self.model.joint_names)
    }
    #[getter]
    fn estimator(&self) -> &'static str {
        match self.model.estimator {
            Estimator::Separated => "separated",
            Estimator::Combined => "combined",
        }
    }
    /// The model at `op` (an OperatingPoint): dict `torque` (n,, its prediction there), `D`,
    /// `H`, `G` (n, n; the same everywhere), `G_static` (n, n, or None without that
    /// experiment): the question every identified model answers the same way.
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        op: &PyOperatingPoint,
    ) -> PyResult<Bound<'py, PyDict>> {
        let e = crate::torque_model::TorqueModel::linearize(&self.model, &op.op)?;
        super::arrays::expansion_dict(py, &e)
    }
    /// Predicted torques (N m) at `q`, `qd`, `qdd`: shape `(n,)` each or a batch `(k, n)`;
    /// `T* + D (qdd - qdd*) + H (qd - qd*) + G (q - q*)` about the planned operating point.
    fn predict<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.near_point(
            py,
            [&q, &qd, &qdd],
            "LocalModel.predict",
            LocalModel::predict,
        )
    }
    /// The standard errors (N m) of the torques `predict` gives at `q`, `qd`, `qdd` (shapes as
    /// there): from those of `T*` and of the matrices' entries with their correlation within
    /// each row. NaN for a joint where the model holds an unknown standard error that the
    /// state weights. Raises InputError for a model saved before the correlations were stored
    /// (identify it again) or without the D, H or G experiment.
    fn predict_stderr<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let name = "LocalModel.predict_stderr";
        self.near_point(py, [&q, &qd, &qdd], name, LocalModel::predict_stderr)
    }
    /// How far each state lies from the planned operating point in units of the perturbations
    /// the model was identified over: per state (a float for `(n,)` inputs, `(k,)` for a
    /// batch) the largest `|x_j - x*_j| / perturbations[x][j]` over the joints and `x` in `q`,
    /// `qd`, `qdd` (inf where a joint's variable was never perturbed and the state moves it).
    /// At most 1 inside the identified region; `predict` warns (PerturbidWarning) where states
    /// exceed 1.5. Raises InputError for a model saved before its perturbations were stored.
    fn reach<'py>(
        &self,
        py: Python<'py>,
        q: ArrayLike<'py>,
        qd: ArrayLike<'py>,
        qdd: ArrayLike<'py>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.n();
        let batch = read_batch(n, &[("q", &q), ("qd", &qd), ("qdd", &qdd)])?;
        let states = batch.states(n)?;
        let out = super::detached(py, "LocalModel.reach", || self.model.reach(&states))?;
        to_numpy(py, out, batch.k, batch.single, &[])
    }
    /// The largest perturbation the experiments gave each joint: dict `q` (rad; of the G
    /// experiment), `qd` (rad/s; H), `qdd` (rad/s^2; D), each `(n,)` (m, m/s, m/s^2 for a
    /// prismatic joint): the region the model was identified over. None for a model saved
    /// before they were stored.
    /// How far the nominal passes missed the planned operating point, and what carried T* to
    /// it: a dict of `(n,)` arrays `q`, `qd`, `qdd` (measured - planned: rad, rad/s, rad/s^2),
    /// `q_perturbations`, `qd_perturbations`, `qdd_perturbations` (the same in units of the
    /// largest planned perturbation; NaN where that is 0), `q_stderr`, `qd_stderr`, `qdd_stderr`
    /// (the standard errors of the measured miss; empty for a model saved before they were
    /// stored), `measured_torque` and
    /// `measured_stderr` (N m: the mean at the nominal crossings, before the correction),
    /// `correction` and `correction_stderr` (N m: subtracted to give `torque`, and its matrices'
    /// share of `torque_stderr`), `corrected` (per joint, which of its `[q, qd, qdd]` misses
    /// were corrected: those beyond 3 standard errors of their measurement). None without the
    /// G, H and D experiments.
    #[getter]
    fn miss<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(m) = &self.model.miss else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        for (k, v) in [
            ("q", &m.q),
            ("qd", &m.qd),
            ("qdd", &m.qdd),
            ("q_perturbations", &m.q_perturbations),
            ("qd_perturbations", &m.qd_perturbations),
            ("qdd_perturbations", &m.qdd_perturbations),
            ("q_stderr", &m.q_stderr),
            ("qd_stderr", &m.qd_stderr),
            ("qdd_stderr", &m.qdd_stderr),
            ("measured_torque", &m.measured_torque),
            ("measured_stderr", &m.measured_stderr),
            ("correction", &m.correction),
            ("correction_stderr", &m.correction_stderr),
        ] {
            out.set_item(k, vec1(py, v))?;
        }
        let corrected: Vec<Vec<bool>> = m.corrected.iter().map(|c| c.to_vec()).collect();
        out.set_item("corrected", corrected)?;
        Ok(Some(out))
    }
    #[getter]
    fn perturbations<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(p) = &self.model.perturbations else {
            return Ok(None);
        };
        let out = PyDict::new(py);
        for (k, v) in [("q", &p.q), ("qd", &p.qd), ("qdd", &p.qdd)] {
            out.set_item(k, vec1(py, v))?;
        }
        Ok(Some(out))
    }
    /// The torque noise of the nominal passes: a tuple of two `(n,)` arrays (N m, or N for a
    /// prismatic joint), the samples' standard deviation about their windows' fits and what
    /// the readings varied by from pass to pass beyond it (0 where not estimated), for the
    /// robot's next plan: `plan_experiments(..., torque_noise=samples,
    /// torque_pass_noise=passes)`. Raises InputError for a model without them (a plan
    /// without a nominal experiment, or identified before they were reported).
    fn nominal_noise<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (samples, passes) = self.model.nominal_noise()?;
        Ok((vec1(py, &samples), vec1(py, &passes)))
    }
    /// `nominal_noise()` pooled over several identifications of one robot's joints (a
    /// sequence of LocalModel): per joint the root mean square of each model's, every model
    /// weighted alike; two (n,) arrays (N m). One identification's nominal noise has K - 1
    /// degrees of freedom a joint, so a plan predicted from one alone is optimistic where a
    /// joint's noise came out low. Raises InputError without models, for models of other
    /// joints (`models[i]` named), without nominal entries, or when a joint is noise-free in
    /// one model and noisy in another (a simulation without noise among recorded runs).
    #[staticmethod]
    fn pooled_nominal_noise<'py>(
        py: Python<'py>,
        models: Vec<PyRef<'py, Self>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let models: Vec<&LocalModel> = models.iter().map(|m| &m.model).collect();
        let (samples, passes) = LocalModel::pooled_nominal_noise(&models)?;
        Ok((vec1(py, &samples), vec1(py, &passes)))
    }
    /// The model as JSON text (matrices as lists of rows).
    fn to_json(&self) -> String {
        Document::to_json(&self.model)
    }
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self {
            model: <LocalModel as Document>::from_json(text)?,
        })
    }
    /// Writes the model to `path` as JSON (atomically: a temporary file renamed into place),
    /// the document `perturbid identify` writes (`local_model.json`). Raises FileError when it
    /// cannot be written.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        Ok(super::detached(py, "LocalModel.save", || {
            Document::save(&self.model, &path)
        })?)
    }
    /// A model saved by `save` or by `perturbid identify`, checked as `from_json` checks it.
    /// Raises FileError for a file that cannot be read, InputError naming the file and field
    /// of a document that is not a local model.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let model = super::detached(py, "LocalModel.load", || LocalModel::load(&path))?;
        Ok(Self { model })
    }
    fn __repr__(&self) -> String {
        let parts: Vec<String> = self
            .parts()
            .iter()
            .filter_map(|(k, e)| e.as_ref().map(|e| format!("{k}: cond {:.3}", e.cond)))
            .collect();
        format!(
            "LocalModel(robot='{}', {} estimator, {})",
            self.model.robot,
            self.estimator(),
            parts.join(", ")
        )
    }
}
