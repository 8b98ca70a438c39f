//! `simulate` in Python: rehearsal of a plan on the model (mirrors `crate::simulation`).

use std::sync::Arc;

use pyo3::prelude::*;

use super::detached;
use pyo3::types::PyDict;

use super::arrays::per_joint;
use super::local::PyPlan;
use super::recording::PyRecording;
use super::robot::PyRobot;
use crate::error::Error;
use crate::simulation::{simulate_plan, Friction, SimulationOptions};

/// The `friction` argument of `simulate`: a name ('urdf') or anything else (a dict).
#[derive(FromPyObject)]
pub(crate) enum FrictionArg<'py> {
    Name(String),
    Other(Bound<'py, PyAny>),
}

/// Simulates what the robot would log running every experiment of `plan`: torques from the
/// dynamics with `gravity`, `friction` ('urdf', the default: the URDF's `<dynamics damping
/// friction>`; None: none; or a dict with 'viscous' and 'coulomb', a number or one per joint), Gaussian `torque_noise` (N m) and
/// `position_noise` (rad) standard deviations, encoder `quantization` (rad per count), seeded.
/// Returns one Recording per experiment, in the plan's order.
#[pyfunction]
#[pyo3(signature = (robot, plan, gravity=true, friction=Some(FrictionArg::Name("urdf".into())), torque_noise=None, position_noise=None, quantization=None, seed=0),
    text_signature = "(robot, plan, gravity=True, friction='urdf', torque_noise=None, position_noise=None, quantization=None, seed=0)")]
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate(
    py: Python<'_>,
    robot: &PyRobot,
    plan: &PyPlan,
    gravity: bool,
    friction: Option<FrictionArg<'_>>,
    torque_noise: Option<Bound<'_, PyAny>>,
    position_noise: Option<Bound<'_, PyAny>>,
    quantization: Option<Bound<'_, PyAny>>,
    seed: u64,
) -> PyResult<Vec<PyRecording>> {
    let model = &robot.model;
    let n = model.nv;
    let mut o = SimulationOptions::new(model);
    o.gravity = gravity.into();
    o.seed = seed;
    let refuse = |what: String| {
        Error::InvalidArgument {
        argument: "friction".into(),
        message: format!("{what}; expected 'urdf', None or a dict with 'viscous', 'coulomb' and optionally 'coulomb_negative', 'stribeck', 'stribeck_velocity'"),
    }
    };
    o.friction = match &friction {
        None => Friction::none(n),
        Some(FrictionArg::Name(name)) if name == "urdf" => Friction::from_model(model),
        Some(FrictionArg::Name(name)) => return Err(refuse(format!("'{name}'")).into()),
        Some(FrictionArg::Other(f)) => {
            let d = f.cast::<PyDict>().map_err(|_| refuse(f.to_string()))?;
            let get = |k: &str| -> PyResult<Vec<f64>> {
                match d.get_item(k)? {
                    Some(v) => per_joint(&format!("friction['{k}']"), &v, n),
                    None => Ok(vec![0.0; n]),
                }
            };
            let known = [
                "viscous",
                "coulomb",
                "coulomb_negative",
                "stribeck",
                "stribeck_velocity",
            ];
            for k in d.keys() {
                let k: String = k.extract().map_err(|_| refuse(format!("key {k}")))?;
                if !known.contains(&k.as_str()) {
                    return Err(
                        refuse(format!("unknown key '{k}' (known: {})", known.join(", "))).into(),
                    );
                }
            }
            let coulomb = get("coulomb")?;
            let mut f = Friction::viscous_coulomb(get("viscous")?, coulomb.clone());
            if d.contains("coulomb_negative")? {
                f.coulomb_negative = get("coulomb_negative")?;
            }
            f.stribeck = get("stribeck")?;
            if d.contains("stribeck_velocity")? {
                f.stribeck_velocity = get("stribeck_velocity")?;
            }
            f
        }
    };
    for (target, name, value) in [
        (&mut o.torque_noise, "torque_noise", &torque_noise),
        (&mut o.position_noise, "position_noise", &position_noise),
        (&mut o.quantization, "quantization", &quantization),
    ] {
        if let Some(v) = value {
            *target = per_joint(name, v, n)?;
        }
    }
    let plan = plan.plan.clone();
    let recs = detached(py, "simulate", || simulate_plan(model, &plan, &o))?;
    Ok(recs
        .into_iter()
        .map(|r| PyRecording { rec: Arc::new(r) })
        .collect())
}
