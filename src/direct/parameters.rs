//! The parameter vector of the direct method: 10 inertial parameters per moving body
//! (Pinocchio's order) followed by the friction parameters per joint, and the regressor of a
//! batch of samples for it.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::algorithms::regressor::{
    joint_torque_regressor, model_parameters, PARAMETER_NAMES, PARAMS_PER_BODY,
};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;

/// Which per-joint friction parameters are identified with the inertial ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionTerms {
    /// Viscous friction `fv qd` (N m s/rad).
    pub viscous: bool,
    /// Coulomb friction `fc sign(qd)` (N m).
    pub coulomb: bool,
    /// A constant torque offset (N m), e.g. a sensor bias.
    pub offset: bool,
    /// The armature `Ia qdd` (kg m^2): the motor's rotor inertia reflected to the joint, a
    /// parameter of its own per joint (Pinocchio's `armature`) rather than lumped into a link.
    #[serde(default)]
    pub armature: bool,
}

impl FrictionTerms {
    pub const NONE: FrictionTerms = FrictionTerms {
        viscous: false,
        coulomb: false,
        offset: false,
        armature: false,
    };
    /// Viscous, Coulomb and offset (the friction terms; the armature is asked for by name).
    pub const ALL: FrictionTerms = FrictionTerms {
        viscous: true,
        coulomb: true,
        offset: true,
        armature: false,
    };

    /// The terms named in `names` (`viscous`, `coulomb`, `offset`, `armature`; `all` for the
    /// three friction terms, `none` or nothing for none).
    pub fn from_names<S: AsRef<str>>(names: &[S]) -> Result<Self> {
        let mut f = FrictionTerms::NONE;
        for n in names {
            match n.as_ref().trim() {
                "viscous" => f.viscous = true,
                "coulomb" => f.coulomb = true,
                "offset" => f.offset = true,
                "armature" => f.armature = true,
                "all" => {
                    f.viscous = true;
                    f.coulomb = true;
                    f.offset = true;
                }
                "none" | "" => {}
                other => {
                    return Err(Error::InvalidArgument {
                        argument: "friction".into(),
                        message: format!(
                            "'{other}' is not a joint term; expected viscous, coulomb, offset, armature, all (the three friction terms) or none"
                        ),
                    })
                }
            }
        }
        Ok(f)
    }

    /// These terms, with the armature added when `model` has one: a robot model with rotor
    /// inertia needs the armature column for `Phi theta = tau`, so every identification takes
    /// it.
    pub fn for_model(self, model: &Model) -> Self {
        Self {
            armature: self.armature || model.has_armature(),
            ..self
        }
    }

    /// Names of the terms switched on, in column order (`viscous`, `coulomb`, `offset`,
    /// `armature`).
    pub fn names(&self) -> Vec<&'static str> {
        [
            ("viscous", self.viscous),
            ("coulomb", self.coulomb),
            ("offset", self.offset),
            ("armature", self.armature),
        ]
        .into_iter()
        .filter_map(|(n, on)| on.then_some(n))
        .collect()
    }
}

/// Comma-separated names, as [`FrictionTerms::from_names`] reads them.
impl std::str::FromStr for FrictionTerms {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self> {
        Self::from_names(&text.split(',').collect::<Vec<_>>())
    }
}

/// The names of the terms switched on, comma separated; `none` for none.
impl std::fmt::Display for FrictionTerms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.names().join(",") {
            names if names.is_empty() => f.write_str("none"),
            names => f.write_str(&names),
        }
    }
}

/// The full parameter layout for a model: `10 * nbodies` inertial parameters (body after body)
/// and then, joint after joint, the friction terms switched on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterLayout {
    pub nv: usize,
    pub nbodies: usize,
    pub friction: FrictionTerms,
    /// A name for every parameter, e.g. `link2.mcx` or `joint3.viscous`.
    pub names: Vec<String>,
}

impl ParameterLayout {
    pub fn new(model: &Model, friction: FrictionTerms) -> Self {
        let mut names = Vec::new();
        for b in &model.bodies {
            names.extend(PARAMETER_NAMES.iter().map(|p| format!("{}.{p}", b.link)));
        }
        for j in &model.joint_names {
            names.extend(friction.names().iter().map(|t| format!("{j}.{t}")));
        }
        Self {
            nv: model.nv,
            nbodies: model.nbodies(),
            friction,
            names,
        }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The full parameter vector of `model` itself: its URDF inertias, friction
    /// (`<dynamics damping friction>`; offsets 0) and armature.
    pub fn model_parameters(&self, model: &Model) -> DVector<f64> {
        let mut theta = model_parameters(model).as_slice().to_vec();
        for (j, lim) in model.limits.iter().enumerate() {
            for t in self.friction.names() {
                theta.push(match t {
                    "viscous" => lim.damping,
                    "coulomb" => lim.friction,
                    "armature" => model.armature[j],
                    _ => 0.0,
                });
            }
        }
        DVector::from_vec(theta)
    }
}

/// The identification regressor of a batch: `(k nv) x layout.len()`, row `s * nv + j` the torque
/// of joint `j` at sample `s` per unit of each parameter. `gravity` includes gravity.
pub fn regressor_matrix(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
) -> Result<DMatrix<f64>> {
    let nv = model.nv;
    let k = states.len();
    let mut out = DMatrix::zeros(k * nv, layout.len());
    fill_regressor(model, layout, states, gravity, 0..k, &mut out, 0)?;
    Ok(out)
}

/// Samples in one block of [`regressor_blocks`] (a 7-joint arm's 1024 samples of 100 parameters
/// are 5.7 MB).
const REGRESSOR_BLOCK: usize = 1024;

/// The regressor of `states` a block of samples at a time, never all of it at once: calls
/// `f(range, phi)` for consecutive ranges of samples, in order, `phi` their regressor
/// (`range.len() nv x layout.len()`, rows as in [`regressor_matrix`]). Stops at Ctrl-C.
pub fn regressor_blocks(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
    mut f: impl FnMut(std::ops::Range<usize>, &DMatrix<f64>) -> Result<()>,
) -> Result<()> {
    let (k, nv) = (states.len(), model.nv);
    let mut phi = DMatrix::zeros(0, layout.len());
    for start in (0..k).step_by(REGRESSOR_BLOCK) {
        crate::interrupt::check("the regressor")?;
        let range = start..(start + REGRESSOR_BLOCK).min(k);
        if phi.nrows() != range.len() * nv {
            phi = DMatrix::zeros(range.len() * nv, layout.len());
        }
        fill_regressor(model, layout, states, gravity, range.clone(), &mut phi, 0)?;
        f(range, &phi)?;
    }
    Ok(())
}

/// Writes the regressor rows of samples `range` into `out` from row `row0` on.
pub(crate) fn fill_regressor(
    model: &Model,
    layout: &ParameterLayout,
    states: &States<'_>,
    gravity: Gravity,
    range: std::ops::Range<usize>,
    out: &mut DMatrix<f64>,
    row0: usize,
) -> Result<()> {
    let nv = model.nv;
    let ni = PARAMS_PER_BODY * model.nbodies();
    let terms = layout.friction.names();
    let mut data = Data::new(model);
    let mut y = std::mem::take(&mut data.regressor);
    let zeros = vec![0.0; nv];
    for (r, s) in range.enumerate() {
        let x = states.sample(s);
        let (q, qd, qdd) = (x.q, x.qd.unwrap_or(&zeros), x.qdd.unwrap_or(&zeros));
        joint_torque_regressor(model, &mut data, q, qd, qdd, gravity, &mut y)
            .map_err(|e| states.at(s, e))?;
        let base = row0 + r * nv;
        out.view_mut((base, 0), (nv, ni)).copy_from(&y);
        for j in 0..nv {
            for (t, name) in terms.iter().enumerate() {
                out[(base + j, ni + j * terms.len() + t)] = match *name {
                    "viscous" => qd[j],
                    "coulomb" => states.coulomb_at(s, j),
                    "armature" => qdd[j],
                    _ => 1.0,
                };
            }
        }
    }
    Ok(())
}

/// `sign(x)` with `sign(0) = 0`: the Coulomb column of the friction terms (no torque at
/// exactly zero speed).
pub fn sign0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}
