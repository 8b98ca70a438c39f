//! The identified base parameters as a table a person reads: full names, values, standard
//! errors, relative standard deviations, and whether each is one physical parameter or a
//! combination.

use serde::Serialize;

use super::identify::BaseModel;

/// One base parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParameterRow {
    /// The kept parameter's name, then `+ c * other` for each parameter merged into it.
    pub name: String,
    /// Value (SI units of the kept parameter: kg, kg m, kg m^2, N m s/rad, N m).
    pub value: f64,
    /// Standard error; `None` when unknown (no residual degree of freedom).
    pub std: Option<f64>,
    /// `std / |value|`; `None` when either is unknown or the value is zero.
    pub relative_std: Option<f64>,
    /// Whether other parameters are merged into it: then only the combination is identifiable,
    /// not the physical parameter it is named after.
    pub combination: bool,
}

impl BaseModel {
    /// The table of the base parameters (see [`ParameterRow`]).
    pub fn parameter_table(&self) -> Vec<ParameterRow> {
        let names = self.base.names();
        (0..self.theta.len())
            .map(|i| {
                let value = self.theta[i];
                let std = Some(self.stderr[i]).filter(|s| s.is_finite());
                ParameterRow {
                    combination: (0..self.base.dropped.len())
                        .any(|d| self.base.k[(i, d)].abs() > 1e-9),
                    name: names[i].clone(),
                    value,
                    relative_std: std.filter(|_| value != 0.0).map(|s| s / value.abs()),
                    std,
                }
            })
            .collect()
    }
}
