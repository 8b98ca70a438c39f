//! The parameter vector of a robot: 10 inertial parameters per moving body (Pinocchio's order
//! `m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz`, about the body's joint frame) followed
//! by the friction terms of every joint switched on ([`FrictionTerms`]), named by
//! [`ParameterLayout`]. The regressors of the dynamics and the fits of the identification all
//! use this order.

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::model::Model;
use crate::spatial::Inertia;

/// Number of inertial parameters per body.
pub const PARAMS_PER_BODY: usize = 10;

/// Names of the 10 parameters of a body, in order: `m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz,
/// Izz`.
pub const PARAMETER_NAMES: [&str; 10] = [
    "m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz",
];

/// The 10 inertial parameters of a body in Pinocchio's order `[m, m cx, m cy, m cz, Ixx, Ixy,
/// Iyy, Ixz, Iyz, Izz]` (kg, kg m, kg m^2), the inertia about the body (joint) frame's origin.
pub fn dynamic_parameters(inertia: &Inertia) -> [f64; 10] {
    let h = inertia.com * inertia.mass;
    let i = inertia.inertia_origin();
    [
        inertia.mass,
        h.x,
        h.y,
        h.z,
        i[(0, 0)],
        i[(0, 1)],
        i[(1, 1)],
        i[(0, 2)],
        i[(1, 2)],
        i[(2, 2)],
    ]
}

/// The inertia with the 10 parameters `p` (the inverse of [`dynamic_parameters`]); `None` when
/// the mass is not positive (the centre of mass `h / m` is then undefined). The rotational
/// inertia need not be one a rigid body can have: the algorithms are linear in it.
pub fn inertia_from_parameters(p: &[f64; 10]) -> Option<Inertia> {
    let m = p[0];
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let com = nalgebra::Vector3::new(p[1], p[2], p[3]) / m;
    let origin = nalgebra::Matrix3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]);
    let shift = (nalgebra::Matrix3::identity() * com.norm_squared() - com * com.transpose()) * m;
    Some(Inertia::new(m, com, origin - shift))
}

/// The inertial parameters of every moving body, stacked (`10 * nbodies`), so that
/// `Phi theta = rnea` for the model's own inertias.
pub fn model_parameters(model: &Model) -> DVector<f64> {
    DVector::from_iterator(
        PARAMS_PER_BODY * model.nbodies(),
        model
            .bodies
            .iter()
            .flat_map(|b| dynamic_parameters(&b.inertia)),
    )
}

/// Which per-joint friction parameters are identified with the inertial ones.
///
/// ```
/// use perturbid_rs::parameters::FrictionTerms;
/// let terms: FrictionTerms = "all".parse()?;
/// assert_eq!(terms.to_string(), "viscous,coulomb,offset");
/// assert!("stiction".parse::<FrictionTerms>().is_err()); // named in the error, with the choices
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
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
                    return Err(Error::invalid(
                        "friction",
                        format!(
                            "'{other}' is not a joint term; expected viscous, coulomb, offset, armature, all (the three friction terms) or none"
                        ),
                    ))
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
///
/// ```
/// use perturbid_rs::parameters::{FrictionTerms, ParameterLayout};
/// let model = perturbid_rs::robots::builtin("a465")?;
/// let layout = ParameterLayout::new(&model, "viscous,coulomb".parse()?);
/// assert_eq!(layout.len(), 10 * 6 + 2 * 6); // ten inertial parameters a body, two terms a joint
/// assert_eq!(layout.names[0], format!("{}.m", model.bodies[0].link));
/// assert_eq!(layout.friction, FrictionTerms { viscous: true, coulomb: true, ..FrictionTerms::NONE });
/// # Ok::<(), perturbid_rs::Error>(())
/// ```
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

/// `sign(x)` with `sign(0) = 0`: the Coulomb column of the friction terms (no torque at
/// exactly zero speed).
///
/// ```
/// use perturbid_rs::parameters::sign0;
/// assert_eq!((sign0(-0.3), sign0(0.0), sign0(2.0)), (-1.0, 0.0, 1.0));
/// ```
pub fn sign0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}
