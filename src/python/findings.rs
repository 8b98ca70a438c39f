//! What the direct method's checks found, as Python dicts: the torque columns, the torques'
//! lag, the joints' zero offsets and their range (`BaseParameterModel` and `Validation` share
//! them).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::direct::position_offsets::PositionOffsets;
use crate::direct::position_range::JointRange;
use crate::direct::{DriveGains, TorqueColumn, TorqueLag};

/// The joints' zero offsets as a dict (`BaseParameterModel.position_offsets`,
/// `Validation.position_offsets`), with its `finding`.
pub(crate) fn position_offsets_dict<'py>(
    py: Python<'py>,
    o: &PositionOffsets,
    finding: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let e = PyDict::new(py);
    e.set_item("joints", &o.joints)?;
    e.set_item("offsets", &o.offsets)?;
    e.set_item("stderr", &o.stderr)?;
    e.set_item("unexplained", o.unexplained)?;
    e.set_item("unexplained_with_offsets", o.unexplained_with_offsets)?;
    let left_out = (o.left_out.iter())
        .map(|l| {
            let d = PyDict::new(py);
            d.set_item("joint", &l.joint)?;
            d.set_item("why", serde_json::to_value(l.why).expect("a name").as_str())?;
            d.set_item("stderr", l.stderr)?;
            Ok(d)
        })
        .collect::<PyResult<Vec<_>>>()?;
    e.set_item("left_out", left_out)?;
    e.set_item("finding", finding)?;
    Ok(e)
}

/// The torque columns' checks as dicts (see `BaseParameterModel.torque_columns`), each with
/// its `finding` among `columns`.
pub(crate) fn torque_column_dicts<'py>(
    py: Python<'py>,
    columns: &[TorqueColumn],
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    columns
        .iter()
        .map(|c| {
            let e = PyDict::new(py);
            e.set_item("joint", &c.joint)?;
            e.set_item("scale", c.scale)?;
            e.set_item("explained", c.explained)?;
            e.set_item("follows", &c.follows)?;
            e.set_item("follows_explained", c.follows_explained)?;
            e.set_item("gravity_rms", c.gravity_rms)?;
            e.set_item("finding", c.finding(columns))?;
            Ok(e)
        })
        .collect()
}

/// Joints whose positions leave their limits as dicts (see
/// `BaseParameterModel.position_range`).
pub(crate) fn position_range_dicts<'py>(
    py: Python<'py>,
    ranges: &[JointRange],
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    ranges
        .iter()
        .map(|r| {
            let e = PyDict::new(py);
            e.set_item("joint", &r.joint)?;
            e.set_item("min", r.min)?;
            e.set_item("max", r.max)?;
            e.set_item("lower", r.lower)?;
            e.set_item("upper", r.upper)?;
            e.set_item("degrees", r.degrees)?;
            Ok(e)
        })
        .collect()
}

/// The torques' lag as a dict (see `BaseParameterModel.torque_lag`).
pub(crate) fn torque_lag_dict<'py>(
    py: Python<'py>,
    lag: &TorqueLag,
) -> PyResult<Bound<'py, PyDict>> {
    let e = PyDict::new(py);
    e.set_item("samples", lag.samples)?;
    e.set_item("joints", &lag.joints)?;
    e.set_item("unexplained", lag.unexplained)?;
    e.set_item("unexplained_at_lag", lag.unexplained_at_lag)?;
    e.set_item("finding", lag.finding())?;
    Ok(e)
}

/// Each run's checks as dicts (see `BaseParameterModel.run_checks`), each named by `names`
/// (`run r` where none is given).
pub(crate) fn run_check_dicts<'py>(
    py: Python<'py>,
    checks: &[crate::direct::RunChecks],
    names: &[String],
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    (checks.iter().enumerate())
        .map(|(r, c)| {
            let name = crate::logs::stacked_states::run_name(names, r);
            let e = PyDict::new(py);
            e.set_item("log", &name)?;
            e.set_item("samples", c.samples)?;
            e.set_item(
                "torque_columns",
                torque_column_dicts(py, &c.torque_columns)?,
            )?;
            let lag = c.torque_lag.as_ref().map(|l| torque_lag_dict(py, l));
            e.set_item("torque_lag", lag.transpose()?)?;
            e.set_item(
                "position_range",
                position_range_dicts(py, &c.position_range)?,
            )?;
            e.set_item("findings", c.findings(&name))?;
            Ok(e)
        })
        .collect()
}

/// The gains as a dict (see `BaseParameterModel.drive_gains`).
pub(crate) fn gains_dict<'py>(py: Python<'py>, g: &DriveGains) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("gain", super::arrays::vec1(py, &g.gain))?;
    d.set_item("stderr", super::arrays::vec1(py, &g.stderr))?;
    d.set_item("noise_bias", super::arrays::vec1(py, &g.noise_bias))?;
    d.set_item(
        "payload_torque_rms",
        super::arrays::vec1(py, &g.payload_torque_rms),
    )?;
    d.set_item("agreement", super::arrays::vec1(py, &g.agreement))?;
    d.set_item("cond", g.cond)?;
    d.set_item("runs", g.runs)?;
    d.set_item("loaded_runs", g.loaded_runs)?;
    d.set_item("estimator", g.estimator.name())?;
    match g.least_squares_gain.is_empty() {
        true => d.set_item("least_squares_gain", py.None())?,
        false => d.set_item(
            "least_squares_gain",
            super::arrays::vec1(py, &g.least_squares_gain),
        )?,
    }
    Ok(d)
}
