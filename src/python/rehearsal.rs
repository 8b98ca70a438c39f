//! `TrueRobot` in Python: the true robot of a rehearsal (mirrors `crate::rehearsal`).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::document::Document;
use crate::rehearsal::TrueRobot;

/// The true robot of a rehearsal: how the simulated robot differs from the model (payload,
/// link and random parameter errors, joint zero offsets), its friction (viscous, asymmetric
/// Coulomb, Stribeck, position-dependent, drifting), ripple and cogging, its sensors (encoder
/// counts, white or coloured torque noise, torque resolution, jitter, delay) and its
/// controller (PD + computed-torque feed-forward; absent: exact tracking). Built from a dict
/// with the keys of the JSON document (docs/rehearsal.md; 'format' may be left out), or with
/// `TrueRobot.from_json` / `TrueRobot.load`. Give it to `simulate(..., true_robot=...)`.
#[pyclass(name = "TrueRobot", module = "perturbid_rs", frozen)]
#[derive(Clone)]
pub(crate) struct PyTrueRobot {
    pub robot: TrueRobot,
}

#[pymethods]
impl PyTrueRobot {
    #[new]
    #[pyo3(signature = (spec=None))]
    fn new(py: Python<'_>, spec: Option<Bound<'_, PyDict>>) -> PyResult<Self> {
        let Some(spec) = spec else {
            return Ok(Self {
                robot: TrueRobot::default(),
            });
        };
        let spec = spec.copy()?;
        if !spec.contains("format")? {
            spec.set_item("format", TrueRobot::tag())?;
        }
        let text: String = py
            .import("json")?
            .call_method1("dumps", (spec,))?
            .extract()?;
        Ok(Self {
            robot: TrueRobot::from_json(&text)?,
        })
    }
    /// The JSON document.
    fn to_json(&self) -> String {
        Document::to_json(&self.robot)
    }
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self {
            robot: TrueRobot::from_json(text)?,
        })
    }
    /// Reads a document from a file.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            robot: TrueRobot::load(&path)?,
        })
    }
    /// Writes the document to a file (atomically).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        Ok(self.robot.save(&path)?)
    }
    fn __repr__(&self) -> String {
        let r = &self.robot;
        format!(
            "TrueRobot(payload={}, controller={}, seed={})",
            r.payload
                .as_ref()
                .map_or("None".into(), |p| format!("{} kg on '{}'", p.mass, p.link)),
            if r.controller.is_some() {
                "PD"
            } else {
                "exact"
            },
            r.seed
        )
    }
}
