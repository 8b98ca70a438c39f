//! A payload given to Python as a dict: `link`, `mass` (kg), `com` (m) and `inertia`
//! (`[ixx, ixy, ixz, iyy, iyz, izz]` about the centre of mass, kg m^2), in the link's frame.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::scalars;
use crate::error::Error;
use crate::model::payload::Payload;

/// A payload given as argument `argument`: None, or a dict with the keys of the true robot's
/// `payload` (`link`, `mass`, `com`, `inertia`); unknown keys, and values of another type or
/// length, refused by key (values out of range by [`Payload::problem`]).
pub(crate) fn payload_argument(
    argument: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<Option<Payload>> {
    if value.is_none() {
        return Ok(None);
    }
    let bad = |message: String| -> PyErr {
        Error::InvalidArgument {
            argument: argument.to_string(),
            message,
        }
        .into()
    };
    let Ok(dict) = value.cast::<PyDict>() else {
        return Err(bad(format!(
            "a {}, expected None or a dict with 'link', 'mass' (kg), 'com' (m) and 'inertia' ([ixx, ixy, ixz, iyy, iyz, izz] about the centre of mass, kg m^2)",
            value.get_type().name()?
        )));
    };
    let mut payload = Payload {
        link: String::new(),
        mass: f64::NAN,
        com: [0.0; 3],
        inertia: [0.0; 6],
    };
    let (mut link, mut mass) = (false, false);
    for (key, v) in dict.iter() {
        let key: String = key
            .extract()
            .map_err(|_| bad("its keys must be strings".into()))?;
        let numbers = |len: usize| -> PyResult<Vec<f64>> {
            let x: Vec<Bound<'_, PyAny>> = if v.cast::<pyo3::types::PyString>().is_ok() {
                vec![]
            } else {
                v.extract().unwrap_or_default()
            };
            let x = (x.iter())
                .map(scalars::real)
                .collect::<PyResult<Vec<f64>>>();
            match x {
                Ok(x) if x.len() == len => Ok(x),
                _ => Err(bad(format!("'{key}' must be {len} real numbers"))),
            }
        };
        match key.as_str() {
            "link" => {
                payload.link = v
                    .extract()
                    .map_err(|_| bad("'link' must be a string".into()))?;
                link = true;
            }
            "mass" => {
                payload.mass = scalars::real(&v)
                    .map_err(|_| bad("'mass' must be a real number (kg)".into()))?;
                mass = true;
            }
            "com" => payload.com.copy_from_slice(&numbers(3)?),
            "inertia" => payload.inertia.copy_from_slice(&numbers(6)?),
            other => {
                return Err(bad(format!(
                    "unknown key '{other}', expected 'link', 'mass', 'com' and 'inertia'"
                )))
            }
        }
    }
    if !(link && mass) {
        return Err(bad("'link' and 'mass' are required".into()));
    }
    Ok(Some(payload))
}
