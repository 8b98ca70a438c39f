//! `simulate` in Python: rehearsal of a plan on the model (mirrors `crate::simulation`).

use pyo3::prelude::*;

use super::scalars;

use super::detached;
use pyo3::types::PyDict;

use super::arrays::{per_joint, vector, ArrayLike};
use super::excitation::PyExcitationDesign;
use super::local::PyPlan;
use super::recording::{matrix_rows, PyRecording};
use super::rehearsal::PyTrueRobot;
use super::robot::PyRobot;
use super::trajectory::PyFourier;
use crate::error::Error;
use crate::local::Plan;
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::rehearsal::{rehearse, rehearse_plan};
use crate::simulation::{
    excitation_samples, simulate_plan, simulate_samples, Friction, SimulationOptions,
};
use crate::trajectory::Samples;

/// The `friction` argument of `simulate`: a name ('urdf') or anything else (a dict).
#[derive(FromPyObject)]
pub(crate) enum FrictionArg<'py> {
    Name(String),
    Other(Bound<'py, PyAny>),
}

/// What `simulate` runs: a plan, a Fourier excitation, a designed excitation or sampled
/// arrays `(t, q, qd, qdd)`.
#[derive(FromPyObject)]
pub(crate) enum ReferenceArg<'py> {
    Plan(PyRef<'py, PyPlan>),
    Fourier(PyRef<'py, PyFourier>),
    Design(PyRef<'py, PyExcitationDesign>),
    Arrays(
        (
            ArrayLike<'py>,
            ArrayLike<'py>,
            ArrayLike<'py>,
            ArrayLike<'py>,
        ),
    ),
}

/// Simulates what the robot would log running `plan`: a Plan (one Recording per experiment,
/// in the plan's order, returned as a list), or a FourierTrajectory / ExcitationDesign
/// (`periods` periods, default 1, sampled at `rate` Hz, default 1000) or a tuple of arrays
/// `(t, q, qd, qdd)` (shapes (k,), (k, n) x 3; s, rad, rad/s, rad/s^2), each returned as one
/// Recording. `rate` and `periods` are refused with a plan or arrays, which set their own
/// times.
///
/// On the model itself: torques from the dynamics with `gravity`, `friction` ('urdf', the
/// default: the URDF's `<dynamics damping friction>`; None: none; or a dict with 'viscous',
/// 'coulomb' and optionally 'coulomb_negative', 'stribeck', 'stribeck_velocity', a number or
/// one per joint), Gaussian `torque_noise` (N m) and `position_noise` (rad) standard
/// deviations, encoder `quantization` (rad per count), seeded; the joints follow the reference
/// exactly.
///
/// With `true_robot` (a TrueRobot): everything comes from it (parameter errors, friction,
/// ripple, sensors, closed-loop tracking; docs/rehearsal.md); `gravity=False`, a `friction`
/// other than the default, noise, quantisation or a seed are then refused.
#[pyfunction]
#[pyo3(signature = (robot, plan, gravity=true, friction=Some(FrictionArg::Name("urdf".into())), torque_noise=None, position_noise=None, quantization=None, seed=0, *, true_robot=None, rate=None, periods=None),
    text_signature = "(robot, plan, gravity=True, friction='urdf', torque_noise=None, position_noise=None, quantization=None, seed=0, *, true_robot=None, rate=None, periods=None)")]
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    plan: ReferenceArg<'py>,
    gravity: bool,
    friction: Option<FrictionArg<'_>>,
    torque_noise: Option<Bound<'_, PyAny>>,
    position_noise: Option<Bound<'_, PyAny>>,
    quantization: Option<Bound<'_, PyAny>>,
    #[pyo3(from_py_with = scalars::seed)] seed: u64,
    true_robot: Option<PyRef<'py, PyTrueRobot>>,
    #[pyo3(from_py_with = scalars::real_or_none)] rate: Option<f64>,
    #[pyo3(from_py_with = scalars::real_or_none)] periods: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let default_friction = matches!(&friction, Some(FrictionArg::Name(n)) if n == "urdf");
    if true_robot.is_some()
        && (!gravity
            || !default_friction
            || torque_noise.is_some()
            || position_noise.is_some()
            || quantization.is_some()
            || seed != 0)
    {
        return Err(Error::invalid(
            "true_robot",
            "gravity, friction, noise, quantization and seed come from the true robot; leave them out",
        )
        .into());
    }
    let model = &robot.model;
    let reference = reference(model, plan, rate, periods)?;
    let one = |rec: Recording| -> PyResult<Bound<'py, PyAny>> {
        Ok(Bound::new(py, PyRecording::from(rec))?.into_any())
    };
    let many = |recs: Vec<Recording>| -> PyResult<Bound<'py, PyAny>> {
        let list: Vec<PyRecording> = recs.into_iter().map(PyRecording::from).collect();
        Ok(list.into_pyobject(py)?.into_any())
    };
    if let Some(t) = &true_robot {
        let t = t.robot.clone();
        return match reference {
            Reference::Plan(p) => many(detached(py, "simulate", || rehearse_plan(model, &t, &p))?),
            Reference::Samples(s) => one(detached(py, "simulate", || {
                rehearse(model, &t, &s, 0, "rehearsal")
            })?),
        };
    }
    let model = &robot.model;
    let n = model.nv;
    let mut o = SimulationOptions::new(model);
    o.gravity = gravity.into();
    o.seed = seed;
    o.friction = friction_of(model, &friction)?;
    for (target, name, value) in [
        (&mut o.torque_noise, "torque_noise", &torque_noise),
        (&mut o.position_noise, "position_noise", &position_noise),
        (&mut o.quantization, "quantization", &quantization),
    ] {
        if let Some(v) = value {
            *target = per_joint(name, v, n)?;
        }
    }
    match reference {
        Reference::Plan(p) => many(detached(py, "simulate", || simulate_plan(model, &p, &o))?),
        Reference::Samples(s) => one(detached(py, "simulate", || {
            simulate_samples(model, &s, &o, 0, "simulation")
        })?),
    }
}

/// What [`simulate`] runs: a plan's experiments, or samples of a reference.
enum Reference {
    Plan(std::sync::Arc<Plan>),
    Samples(Samples),
}

/// The reference `plan` as samples (an excitation over `periods` at `rate`, or the arrays
/// checked as a recording is) or as a plan; `rate` and `periods` refused but for an
/// excitation.
fn reference(
    model: &Model,
    plan: ReferenceArg<'_>,
    rate: Option<f64>,
    periods: Option<f64>,
) -> PyResult<Reference> {
    let excitation = matches!(plan, ReferenceArg::Fourier(_) | ReferenceArg::Design(_));
    if let (false, Some((name, value))) = (
        excitation,
        [("rate", rate), ("periods", periods)]
            .into_iter()
            .find_map(|(o, v)| v.map(|v| (o, v))),
    ) {
        return Err(Error::invalid(
            name,
            format!(
                "{} given with {}: it applies to an excitation (FourierTrajectory or ExcitationDesign)",
                crate::error::shown(value),
                if matches!(plan, ReferenceArg::Plan(_)) {
                    "a plan, whose experiments run once each at the plan's rate"
                } else {
                    "arrays, which give the times themselves"
                }
            ),
        )
        .into());
    }
    let (periods, rate) = (periods.unwrap_or(1.0), rate.unwrap_or(1000.0));
    Ok(match plan {
        ReferenceArg::Plan(p) => Reference::Plan(p.plan.clone()),
        ReferenceArg::Fourier(f) => {
            Reference::Samples(excitation_samples(model, &f.traj, periods, rate)?)
        }
        ReferenceArg::Design(d) => Reference::Samples(excitation_samples(
            model,
            d.trajectory_ref(),
            periods,
            rate,
        )?),
        ReferenceArg::Arrays((t, q, qd, qdd)) => {
            let t = vector("t", &t)?;
            let k = t.len();
            let (n, q) = matrix_rows("q", &q, k, Some(model.nv))?;
            let (_, qd) = matrix_rows("qd", &qd, k, Some(n))?;
            let (_, qdd) = matrix_rows("qdd", &qdd, k, Some(n))?;
            // the checks of a recording: t strictly increasing, everything finite
            Recording::new(
                "reference",
                n,
                t.clone(),
                q.clone(),
                qd.clone(),
                Some(qdd.clone()),
                None,
            )?;
            Reference::Samples(Samples { n, t, q, qd, qdd })
        }
    })
}

/// The simulation's friction from the `friction` argument: 'urdf' (the model's), None or a
/// dict of per-joint values.
fn friction_of(model: &Model, friction: &Option<FrictionArg<'_>>) -> PyResult<Friction> {
    let n = model.nv;
    let refuse = |what: String| {
        Error::invalid(
            "friction",
            format!("{what}; expected 'urdf', None or a dict with 'viscous', 'coulomb' and optionally 'coulomb_negative', 'stribeck', 'stribeck_velocity'"),
        )
    };
    Ok(match friction {
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
    })
}
