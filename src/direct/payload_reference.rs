//! What a payload's identification ([`super::payload::identify_payload`]) is measured
//! against and solves for: the reference model of the robot without it ([`Reference`]), the
//! options, and the unknowns' columns (the payload's body's ten, and the joint terms fitted
//! beside them).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::base::{BaseParameters, BASE_TOLERANCE};
use super::base_model::BaseModel;
use super::base_options::Weighting;
use super::parameters::{FrictionTerms, ParameterLayout};
use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::choice::choice;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;

/// What the payload's torques are measured against.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// The URDF's own inertial parameters (and armature), taken as exact: their errors go into
    /// the payload unseen. No friction: fit the joint terms beside the payload.
    Urdf,
    /// A base-parameter model of the robot without the payload (its friction and offsets
    /// included), whose parameters' uncertainty is carried into the payload's.
    Model(&'a BaseModel),
}

choice! {
    /// How a payload's inertia about its centre of mass is taken ([`PayloadOptions::inertia`]).
    #[derive(Serialize, Deserialize)]
    #[serde(rename_all = "snake_case")]
    pub enum PayloadInertia ("inertia") {
        /// Fitted with the mass and the centre of mass: all ten parameters.
        Fitted = "fitted",
        /// Taken as 0 (a point mass): the mass and centre of mass alone are fitted, for logs
        /// that determine a small payload's inertia loosely or not at all (slow motion, or
        /// poses held still), and the payload given has no inertia about its centre.
        PointMass = "point_mass",
    }
}

/// How a payload is identified ([`identify_payload`](super::identify_payload)).
#[derive(Clone, Debug, PartialEq)]
pub struct PayloadOptions {
    /// The URDF link the payload is fixed to (a moving body's own, or one behind fixed joints
    /// such as a flange or tool frame), in whose frame the payload is given.
    pub link: String,
    /// Each joint's terms fitted beside the payload (viscous, Coulomb, offset, armature): on a
    /// base-parameter reference a change of them (a sensor zeroed anew), on the URDF the terms
    /// themselves.
    pub terms: FrictionTerms,
    /// OLS, WLS with weights from the per-joint residuals of the OLS fit (default), or the
    /// noise weighting by `noise`.
    pub weighting: Weighting,
    /// The torques' noise measured apart from the fit ([`super::TorqueNoise`]: from a log
    /// averaged over its excitation's periods): the weights of [`Weighting::Noise`] (which
    /// needs it, and takes its standard errors from it), and for any weighting the yardstick
    /// of the residuals ([`PayloadFit::noise_fit`](super::PayloadFit::noise_fit)). Default None.
    pub noise: Option<super::TorqueNoise>,
    /// Gravity in the torques (default on); a base-parameter reference must agree.
    pub gravity: Gravity,
    /// How the payload's inertia about its centre of mass is taken (default: fitted).
    pub inertia: PayloadInertia,
    /// Several logs one after the other: the samples of each, in order, adding up to all
    /// (empty for one log). Each log is checked alone against the robot's model, and its
    /// residuals are read as a time series of their own.
    pub runs: Vec<usize>,
    /// The logs' names for the findings (one a log, or none: `run r`).
    pub log_names: Vec<String>,
    /// A physically consistent payload: the least squares over the ten parameters whose
    /// pseudo-inertia is positive semi-definite (a rigid body), the joint terms free
    /// (default false: the plain least squares, which can leave a loosely determined inertia
    /// no rigid body's).
    pub consistent: bool,
    /// Several logs: an offset of each log's own a joint (a sensor zeroed anew between them)
    /// beside the joint terms' offset, which is then the logs' mean (default false: one
    /// offset for all). Needs 2 to [`super::streaming::MAX_OFFSET_RUNS`] logs and the offset
    /// among `terms`.
    pub offset_per_run: bool,
}

impl PayloadOptions {
    /// The defaults for `link` and `reference`: WLS, gravity on, and the joint terms the
    /// reference lacks: an offset a joint on a base-parameter model (a torque sensor zeroed
    /// anew between the logs), viscous, Coulomb and offset on the URDF.
    pub fn new(link: &str, reference: &Reference<'_>) -> Self {
        Self {
            link: link.to_string(),
            terms: match reference {
                Reference::Urdf => FrictionTerms::ALL,
                Reference::Model(_) => FrictionTerms {
                    offset: true,
                    ..FrictionTerms::NONE
                },
            },
            weighting: Weighting::Wls,
            gravity: Gravity::Included,
            inertia: PayloadInertia::Fitted,
            runs: vec![],
            log_names: vec![],
            consistent: false,
            offset_per_run: false,
            noise: None,
        }
    }
}

/// The reference's regressor layout, its parameters over it, and for a base-parameter model
/// its base parameters (whose columns of that layout it keeps).
pub(super) struct ReferenceParts<'a> {
    pub(super) layout: ParameterLayout,
    pub(super) theta: DVector<f64>,
    pub(super) base: Option<&'a BaseParameters>,
}

impl<'a> ReferenceParts<'a> {
    /// Of `reference` for `model`, read with `gravity`: refused for a model of another robot or
    /// identified with gravity the other way.
    pub(super) fn of(model: &Model, reference: &Reference<'a>, gravity: Gravity) -> Result<Self> {
        Ok(match *reference {
            Reference::Urdf => {
                let layout = ParameterLayout::new(model, FrictionTerms::NONE.for_model(model));
                let theta = layout.model_parameters(model);
                Self {
                    layout,
                    theta,
                    base: None,
                }
            }
            Reference::Model(fit) => {
                fit.check(model)?;
                if fit.gravity != gravity {
                    return Err(Error::invalid(
                        "gravity",
                        format!(
                            "the reference model was identified with gravity {} of its torques, the payload's log is read with it {}: both must agree",
                            if fit.gravity.is_included() { "in" } else { "out" },
                            if gravity.is_included() { "in" } else { "out" }
                        ),
                    ));
                }
                Self {
                    layout: fit.base.layout.clone(),
                    theta: DVector::from_column_slice(&fit.theta),
                    base: Some(&fit.base),
                }
            }
        })
    }

    /// The reference's torques of the regressor block `phi` (of [`Self::layout`]).
    pub(super) fn torques(&self, phi: &DMatrix<f64>) -> DVector<f64> {
        match self.base {
            Some(b) => b.select(phi) * &self.theta,
            None => phi * &self.theta,
        }
    }
}

/// The unknowns' regression problem: the columns of the payload's body and of the joint terms.
pub(super) fn unknowns(model: &Model, body: usize, terms: FrictionTerms) -> BaseParameters {
    let layout = ParameterLayout::new(model, terms);
    let ni = PARAMS_PER_BODY * model.nbodies();
    let kept: Vec<usize> = (body * PARAMS_PER_BODY..(body + 1) * PARAMS_PER_BODY)
        .chain(ni..layout.len())
        .collect();
    BaseParameters {
        layout,
        k: DMatrix::zeros(kept.len(), 0),
        kept,
        dropped: vec![],
        tolerance: BASE_TOLERANCE,
        structural: false,
    }
}

/// The unknowns' columns: the payload body's ten, each joint's terms and, with an offset a
/// log, each joint's deviations of the logs after the first.
pub(super) struct Columns {
    pub(super) body: usize,
    pub(super) terms: Vec<&'static str>,
    /// The logs with an offset each (0 without).
    pub(super) runs: usize,
}

impl Columns {
    /// Row `s * nv + j` (`row` of the block `phi`, sample `sample` of `states`, joint `joint`)
    /// into `out`: the payload body's ten regressor columns of the reference's regressor block
    /// (inertial columns come first in every layout) and joint `j`'s own terms.
    pub(super) fn row(
        &self,
        phi: &DMatrix<f64>,
        row: usize,
        states: &States<'_>,
        sample: usize,
        joint: usize,
        out: &mut [f64],
    ) {
        let (nv, terms) = (states.nv(), &self.terms);
        for c in 0..PARAMS_PER_BODY {
            out[c] = phi[(row, self.body * PARAMS_PER_BODY + c)];
        }
        out[PARAMS_PER_BODY..].iter_mut().for_each(|v| *v = 0.0);
        let (qd, qdd) = (states.qd_or_zeros(), states.qdd_or_zeros());
        for (t, name) in terms.iter().enumerate() {
            out[PARAMS_PER_BODY + joint * terms.len() + t] = match *name {
                "viscous" => qd[sample * nv + joint],
                "coulomb" => states.coulomb_at(sample, joint),
                "armature" => qdd[sample * nv + joint],
                _ => 1.0,
            };
        }
    }

    /// The columns of a log's own offset of `joint` in a row of log `run` (as
    /// [`super::streaming::JointFactors::with_runs`] has them: 1 in the log's own after the
    /// first, -1 in all for the first), into `out` after [`Self::row`]'s; nothing without
    /// them or for `None` (states of no log fitted: the logs' mean offset).
    pub(super) fn run_offsets(&self, nv: usize, joint: usize, run: Option<usize>, out: &mut [f64]) {
        let (Some(run), true) = (run, self.runs > 1) else {
            return;
        };
        let e = self.runs - 1;
        let first = PARAMS_PER_BODY + nv * self.terms.len() + joint * e;
        for (c, v) in out[first..first + e].iter_mut().enumerate() {
            *v = match run {
                0 => -1.0,
                r if r == c + 1 => 1.0,
                _ => 0.0,
            };
        }
    }

    /// The number of unknowns for `nv` joints.
    pub(super) fn len(&self, nv: usize) -> usize {
        PARAMS_PER_BODY + nv * (self.terms.len() + self.runs.saturating_sub(1))
    }
}
