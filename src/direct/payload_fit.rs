//! An identified payload ([`super::payload::identify_payload`]): its estimates with their
//! standard errors, the payload they make in its link's frame, what the fit cannot vouch for,
//! and the torques of the robot carrying it.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::parameters::{regressor_blocks, FrictionTerms};
use super::payload_quantities::{in_link_frame, payload_of_parameters};
use super::payload_reference::{Columns, PayloadInertia, Reference, ReferenceParts};
use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::error::{shown, Error, Result};
use crate::gravity::Gravity;
use crate::model::payload::Payload;
use crate::model::Model;
use crate::spatial::Se3;
use crate::states::States;

/// Standard errors a mass must lie above 0 by for the payload to count as seen (below it the
/// centre of mass, a first moment over the mass, is not determined).
pub const SEEN: f64 = 3.0;

/// The mass's standard error, relative to it, beyond which it is named as loosely determined.
pub const LOOSE_MASS: f64 = 0.05;

/// A centre of mass coordinate's standard error beyond which it is named as loosely
/// determined: this fraction of the centre's distance from the joint frame, or [`LOOSE_COM`]
/// metres where that is larger.
pub const LOOSE_COM_FRACTION: f64 = 0.1;

/// See [`LOOSE_COM_FRACTION`] (m).
pub const LOOSE_COM: f64 = 0.005;

/// An inertia entry's standard error, relative to the payload's largest principal moment,
/// beyond which the inertia is named as loosely determined.
pub const LOOSE_INERTIA: f64 = 0.25;

/// Standard errors of a payload's mass (kg), centre of mass (m) and inertia about it (kg m^2,
/// `[ixx, ixy, ixz, iyy, iyz, izz]`), as [`Payload`] holds them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadStderr {
    pub mass: f64,
    pub com: [f64; 3],
    pub inertia: [f64; 6],
}

/// An identified payload ([`super::payload::identify_payload`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadFit {
    pub robot: String,
    pub joint_names: Vec<String>,
    /// The link the payload is fixed to, in whose frame [`Self::payload`] is given.
    pub link: String,
    /// The link of the body it moves with (`link` itself, or for a link behind fixed joints,
    /// such as a flange or tool frame, its parent body's), in whose joint frame
    /// [`Self::theta`]'s ten parameters are.
    pub body: String,
    /// `urdf` or `base_model`: what the torques were measured against ([`Reference`]).
    pub reference: String,
    /// Whether the torques included gravity.
    pub gravity: Gravity,
    /// The joint terms fitted beside the payload.
    pub terms: FrictionTerms,
    /// The unknowns: the payload's ten parameters (`payload.m`, `payload.mcx`, ... `payload.Izz`)
    /// and then each joint's terms (`joint1.offset`, ...).
    pub names: Vec<String>,
    /// Their estimates: kg, kg m, kg m^2 about the link's joint frame; the joint terms in N m
    /// s/rad, N m, N m and kg m^2 (N s/m, N, N and kg for a prismatic joint).
    pub theta: Vec<f64>,
    /// Their standard errors, with the reference model's share ([`Self::stderr_of_reference`]).
    pub stderr: Vec<f64>,
    /// The reference model's share of the standard errors alone: its parameters' uncertainty
    /// carried through the fit (0 for the URDF, taken as exact; NaN for a base-parameter model
    /// that stores no correlation of its parameters).
    pub stderr_of_reference: Vec<f64>,
    /// The correlation of the estimates (with [`Self::stderr`], their covariance).
    #[serde(with = "crate::json::rows")]
    pub correlation: DMatrix<f64>,
    /// The payload: mass, centre of mass and inertia about it in the link's joint frame (the
    /// document `identify-gains --payload` and true robots read). None where the mass is not
    /// above 0 by [`SEEN`] standard errors (no payload seen; its centre of mass would be a
    /// ratio of noise).
    pub payload: Option<Payload>,
    /// The payload's standard errors (with it).
    pub payload_stderr: Option<PayloadStderr>,
    /// Why the least-squares estimate is no rigid body anyone could bolt on (a negative
    /// principal moment, the triangle inequality broken), None where it is one: the data
    /// determine its inertia too loosely, or the model errs. Of the unconstrained estimate
    /// also where the consistent one is given ([`Self::consistent`]).
    pub not_a_rigid_body: Option<String>,
    /// How the inertia about the centre of mass was taken: fitted, or 0 for a point mass
    /// (then its standard errors are 0: it was not estimated).
    pub inertia: PayloadInertia,
    /// Whether [`Self::theta`] and [`Self::payload`] are the physically consistent estimate
    /// ([`super::PayloadOptions::consistent`]); its standard errors are the unconstrained fit's,
    /// which hold where no constraint is active.
    pub consistent: bool,
    /// For a consistent estimate, the weighted residual sum of squares over the unconstrained
    /// fit's (1: the constraint cost nothing; None for a plain fit).
    pub residual_growth: Option<f64>,
    /// Per joint, the RMS (N m, or N) of the torques less the reference's: what the payload
    /// and the joint terms are fitted to.
    pub reference_rms: Vec<f64>,
    /// Per joint, the RMS of the payload's torques alone over the log (N m, or N).
    pub payload_torque_rms: Vec<f64>,
    /// Per joint, the RMS of the residuals the fit leaves (N m, or N).
    pub residual_rms: Vec<f64>,
    /// The per-joint noise levels the rows were weighted by (N m; all 1 for OLS).
    pub sigma: Vec<f64>,
    /// cond of the weighted regressor of the unknowns, columns scaled to unit norm.
    pub cond: f64,
    /// Samples fitted.
    pub samples: usize,
    /// Per joint, the residuals' long-run variance factor ([`super::residual_correlation`]);
    /// the fit's standard errors are inflated by the square root of the largest.
    pub residual_correlation: Vec<f64>,
    /// Each torque column of the log against the robot's model, as every direct fit checks
    /// its log ([`super::check_torque_columns`]): where one reads wrong (other units, sign or
    /// joint) the payload is not vouched for.
    pub torque_columns: Vec<super::TorqueColumn>,
    /// The joints whose positions leave their limits ([`super::position_range`]).
    pub position_range: Vec<super::position_range::JointRange>,
    /// Over several logs, their names (`run r` where none was given) and each one's checks
    /// alone against the robot's model (empty for one log): where one log's torque column
    /// reads wrong, the payload is not vouched for.
    pub logs: Vec<String>,
    pub run_checks: Vec<super::RunChecks>,
    /// What the fit cannot vouch for, in words (each also warned of by the front ends).
    pub findings: Vec<String>,
    /// With an offset of each log's own ([`super::PayloadOptions::offset_per_run`]): each
    /// log's offset less the logs' mean, per joint, with standard errors (the joint terms'
    /// offset is the mean); None otherwise.
    pub log_offsets: Option<super::log_offsets::LogOffsets>,
    /// The residuals judged against the torques' noise measured apart
    /// ([`super::PayloadOptions::noise`], [`super::noise_fit`]); beyond it or below, a finding.
    /// For the noise weighting the standard errors come from it. None without a noise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_fit: Option<super::NoiseFit>,
}

impl PayloadFit {
    /// The torques (row-major `k x nv`, N m, or N for a prismatic joint) of the robot
    /// carrying the payload at `states` (rad, rad/s, rad/s^2; a Coulomb column where the
    /// torques are filtered): `reference`'s (the one the payload was identified against), the
    /// payload's and the joint terms fitted beside it. Refused for a robot of other joints or
    /// without the payload's body, and a reference of another kind than the fit's.
    pub fn predict(
        &self,
        model: &Model,
        reference: Reference<'_>,
        states: &States<'_>,
    ) -> Result<Vec<f64>> {
        let nv = model.nv;
        let bad = |message: String| Error::InvalidArgument {
            argument: "payload fit".into(),
            message,
        };
        if model.joint_names != self.joint_names {
            return Err(bad(format!(
                "identified for joints [{}], not '{}''s",
                self.joint_names.join(", "),
                model.name
            )));
        }
        let kind = match reference {
            Reference::Urdf => "urdf",
            Reference::Model(_) => "base_model",
        };
        if kind != self.reference {
            return Err(bad(format!(
                "identified against the {}, not against the {}: predict with the reference it was identified against",
                describe(&self.reference),
                describe(kind)
            )));
        }
        let body = (model.bodies.iter())
            .position(|b| b.link == self.body)
            .ok_or_else(|| bad(format!("the robot has no body '{}'", self.body)))?;
        // states of no log fitted: each joint's offset the logs' mean
        let columns = Columns {
            body,
            terms: self.terms.names(),
            runs: (self.log_offsets.as_ref())
                .map_or(0, |o| o.deviations.first().map_or(0, Vec::len)),
        };
        if columns.len(nv) != self.theta.len() {
            return Err(bad(format!(
                "{} estimates, not the {} of the payload and its joint terms on this robot",
                self.theta.len(),
                columns.len(nv)
            )));
        }
        crate::torque_model::check_joints(states, nv)?;
        let parts = ReferenceParts::of(model, &reference, self.gravity)?;
        let mut row = vec![0.0; self.theta.len()];
        let mut out = Vec::with_capacity(states.len() * nv);
        regressor_blocks(model, &parts.layout, states, self.gravity, |range, phi| {
            let base = parts.torques(phi);
            for (i, s) in range.clone().enumerate() {
                for j in 0..nv {
                    let r = i * nv + j;
                    columns.row(phi, r, states, s, j, &mut row);
                    let own: f64 = row.iter().zip(&self.theta).map(|(a, b)| a * b).sum();
                    out.push(base[r] + own);
                }
            }
            Ok(())
        })?;
        crate::torque_model::check_prediction(&out, nv)?;
        Ok(out)
    }

    /// The payload's ten parameters (Pinocchio's order, about the link's joint frame).
    pub fn parameters(&self) -> [f64; 10] {
        std::array::from_fn(|i| self.theta[i])
    }

    /// The payload, its standard errors and the findings, from the estimates and their
    /// covariance `cov` (over [`Self::names`]).
    /// `pose`: the link's in the frame of the body it moves with.
    pub(super) fn judge(&mut self, cov: &DMatrix<f64>, pose: &Se3) {
        let pi = self.parameters();
        let (m, se_m) = (pi[0], self.stderr[0]);
        if m < -SEEN * se_m {
            self.findings.push(format!(
                "the payload on '{}' comes out with a negative mass, {} +- {} kg (below 0 by more than {SEEN} standard errors): the {} is heavier at this link than the robot that made the log; {}",
                self.link,
                shown(m),
                shown(se_m),
                describe(&self.reference),
                match self.reference.as_str() {
                    "urdf" => "identify a model of the robot alone from a log without the payload, and give it as the reference",
                    _ => "was the model identified on this robot, with the same tool flange, and the log taken with the payload on?",
                }
            ));
            return;
        }
        if !(m > SEEN * se_m && m > 0.0) {
            self.findings.push(format!(
                "no payload on '{}' is seen: its mass comes out {} +- {} kg (not above 0 by {SEEN} standard errors), so its centre of mass and inertia are not determined; was it mounted while the log was taken, on this link?",
                self.link,
                shown(m),
                shown(se_m)
            ));
            return;
        }
        let (u, jac) = payload_of_parameters(&pi);
        let block = cov.view((0, 0), (PARAMS_PER_BODY, PARAMS_PER_BODY));
        let (u, cu) = in_link_frame(&u, &(&jac * block * jac.transpose()), pose);
        let se = |i: usize| cu[(i, i)].max(0.0).sqrt();
        let mut payload = Payload {
            link: self.link.clone(),
            mass: u[0],
            com: [u[1], u[2], u[3]],
            inertia: [u[4], u[5], u[6], u[7], u[8], u[9]],
        };
        let mut stderr = PayloadStderr {
            mass: se(0),
            com: [se(1), se(2), se(3)],
            inertia: std::array::from_fn(|i| se(4 + i)),
        };
        let point_mass = self.inertia == PayloadInertia::PointMass;
        if point_mass {
            // 0 by assumption, not estimated (what is left is rounding)
            payload.inertia = [0.0; 6];
            stderr.inertia = [0.0; 6];
        }
        if stderr.mass > LOOSE_MASS * payload.mass {
            self.findings.push(format!(
                "the payload's mass is loosely determined: {} +- {} kg",
                shown(payload.mass),
                shown(stderr.mass)
            ));
        }
        let distance = payload.com.iter().map(|c| c * c).sum::<f64>().sqrt();
        let com_bound = (LOOSE_COM_FRACTION * distance).max(LOOSE_COM);
        if stderr.com.iter().any(|s| s.is_nan() || *s > com_bound) {
            self.findings.push(format!(
                "the payload's centre of mass is loosely determined: [{}] +- [{}] m; a motion that turns the link about more axes, and faster, determines it better",
                payload.com.map(shown).join(", "),
                stderr.com.map(shown).join(", ")
            ));
        }
        let s = payload.spatial_inertia().inertia_com;
        let largest = crate::decomposition::symmetric_eigen(s).map_or(f64::NAN, |e| {
            (e.eigenvalues.iter()).fold(0.0f64, |a, v| a.max(v.abs()))
        });
        if !point_mass
            && (stderr.inertia.iter())
                .any(|v| v.is_nan() || largest.is_nan() || *v > LOOSE_INERTIA * largest)
        {
            self.findings.push(format!(
                "the payload's inertia about its centre of mass is loosely determined: standard errors up to {} kg m^2 against a largest principal moment of {} kg m^2 (a small payload's inertia moves the joint torques little; a motion that turns the link faster about each axis determines it better)",
                shown(stderr.inertia.iter().fold(0.0f64, |a, v| a.max(*v))),
                shown(largest)
            ));
        }
        match (&self.not_a_rigid_body, self.consistent) {
            (Some(reason), false) => self.findings.push(format!(
                "the estimate is no rigid body: {reason}; the data determine its inertia too loosely (or the reference model errs), and the estimate is not to be used as it is: identify it consistent (a rigid body by construction)"
            )),
            (Some(reason), true) => self.findings.push(format!(
                "the least-squares estimate is no rigid body ({reason}): the consistent one given lies on the boundary of rigid bodies, its inertia what the data allow more than what they determine"
            )),
            (None, _) => {}
        }
        // a consistent estimate is a rigid body by construction; checked all the same
        if self.consistent {
            if let Some(reason) = payload.problem("the consistent payload") {
                self.findings.push(reason.clone());
                self.not_a_rigid_body = Some(reason);
                self.consistent = false;
            }
        }
        self.payload = Some(payload);
        self.payload_stderr = Some(stderr);
    }

    /// The payload ready to use: present, a rigid body, and from a log whose torque columns
    /// read as the robot's (None otherwise; see [`Self::findings`]).
    pub fn usable_payload(&self) -> Option<&Payload> {
        let columns_right = super::torque_columns::findings(&self.torque_columns).is_empty()
            && !self.run_checks.iter().any(|c| c.columns_wrong());
        self.payload
            .as_ref()
            .filter(|_| (self.consistent || self.not_a_rigid_body.is_none()) && columns_right)
    }
}

/// Why the payload of the estimates `theta` (its ten parameters first) is no rigid body, None
/// where it is one (or where its mass is not positive: no payload to judge).
pub(super) fn rigid_body_problem(link: &str, theta: &[f64]) -> Option<String> {
    let pi: [f64; 10] = std::array::from_fn(|i| theta[i]);
    if pi[0].is_nan() || pi[0] <= 0.0 {
        return None;
    }
    let (u, _) = payload_of_parameters(&pi);
    Payload {
        link: link.to_string(),
        mass: u[0],
        com: [u[1], u[2], u[3]],
        inertia: [u[4], u[5], u[6], u[7], u[8], u[9]],
    }
    .problem("the payload")
}

/// A reference's kind in words.
fn describe(kind: &str) -> &'static str {
    match kind {
        "urdf" => "URDF's parameters",
        _ => "model of the robot alone",
    }
}
