//! The true robot of a rehearsal, as one JSON document (`perturbid-true-robot/1`): how the
//! simulated robot differs from the model the plan was made with, what its joints add to the
//! torques, what its sensors do to the log, and how it tracks the reference. Every field is
//! optional; an empty document `{"format": "perturbid-true-robot/1"}` is the nominal model,
//! frictionless, with perfect sensors and perfect tracking. See `docs/rehearsal.md`.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::document::{invalid, Document};
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::payload::{Payload, MAX_COM_OFFSET};
use crate::model::Model;

/// One harmonic of a joint position: `amplitude * sin(order * q + phase)` (q in rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    /// Cycles per radian of joint travel (> 0; a 6-pole-pair motor behind a 100:1 gear
    /// cogs at 600).
    pub order: f64,
    /// N m for cogging and position-dependent friction; a fraction of the torque for ripple.
    pub amplitude: f64,
    /// rad.
    #[serde(default)]
    pub phase: f64,
}

/// An error of one link's inertial parameters: its mass and rotational inertia scaled by
/// `1 + mass` and `1 + inertia`, its centre of mass moved by `com` (m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkError {
    pub link: String,
    #[serde(default)]
    pub mass: f64,
    #[serde(default)]
    pub com: [f64; 3],
    #[serde(default)]
    pub inertia: f64,
}

/// Joint friction (per joint; N m, N m s/rad, rad/s; absent = 0). With speed `v` of joint j
/// at time `t` (s from the start of the recording):
///
/// ```text
/// level(q) = coulomb (v > 0) or coulomb_negative (v < 0)  +  sum of position harmonics at q
/// f = (1 + drift t) * (viscous v + sign(v) (level(q) + stribeck exp(-(v / stribeck_velocity)^2)))
/// ```
///
/// and `f = 0` at zero speed, except where a joint touches zero speed at one sample without
/// stopping: there `sign(v)` is the direction of the motion around it (see
/// [`crate::simulation::directions_of_motion`]). `coulomb_negative` defaults to `coulomb`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    pub viscous: Option<Vec<f64>>,
    pub coulomb: Option<Vec<f64>>,
    pub coulomb_negative: Option<Vec<f64>>,
    pub stribeck: Option<Vec<f64>>,
    pub stribeck_velocity: Option<Vec<f64>>,
    /// Per joint, harmonics of q added to the Coulomb level (N m).
    pub position: Option<Vec<Vec<Harmonic>>>,
    /// Per joint, relative change of the whole friction per second of recording (1/s).
    pub drift: Option<Vec<f64>>,
}

/// What the sensors do to the log (per joint; absent = perfect).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensors {
    /// Encoder counts per revolution of the joint (the logged position is rounded to whole
    /// counts, `2 pi / counts` rad each); 0 = exact.
    pub encoder_counts: Option<Vec<f64>>,
    /// Standard deviation of the torque noise (N m).
    pub torque_noise: Option<Vec<f64>>,
    /// Correlation of successive torque noise samples, in [0, 1): 0 is white noise, 0.9 a
    /// slowly wandering (AR(1)) one of the same standard deviation.
    pub torque_noise_correlation: Option<Vec<f64>>,
    /// Torque resolution (N m per count; the logged torque is rounded to whole counts); 0 =
    /// exact.
    pub torque_resolution: Option<Vec<f64>>,
    /// Standard deviation (s) of the time at which a sample is really taken around its stamp.
    #[serde(default)]
    pub jitter: f64,
    /// Constant delay (s) of the torque channel behind the positions.
    #[serde(default)]
    pub delay: f64,
}

/// A joint controller tracking the reference: `u = tau_ff + kp (q_ref - q_enc) + kd (qd_ref -
/// qd)` per sample, held for the sample period, with `tau_ff` the computed torque of the
/// nominal model along the reference (switch off with `feedforward: false`). The plant (the
/// true robot with its friction, ripple and cogging) is integrated with a fixed-step 4th-order
/// Runge-Kutta scheme, `substeps` steps per sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Controller {
    /// N m / rad.
    pub kp: Vec<f64>,
    /// N m s / rad.
    pub kd: Vec<f64>,
    #[serde(default = "default_substeps")]
    pub substeps: usize,
    #[serde(default = "yes")]
    pub feedforward: bool,
    /// The drives' torque limits (N m, or N for a prismatic joint; one positive value per
    /// joint): the command is clipped to `+-effort`, applied and logged so, as a saturated
    /// drive's is; the joints then fall behind the reference. Absent: no limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effort: Option<Vec<f64>>,
}

fn default_substeps() -> usize {
    10
}

fn yes() -> bool {
    true
}

/// The true robot; see the module documentation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrueRobot {
    pub format: String,
    /// Seed of every random effect (noise, jitter, random parameter errors).
    #[serde(default)]
    pub seed: u64,
    /// Gravity acts (default; `true` in the file), or is left out as if it were compensated
    /// exactly (`false`).
    #[serde(default)]
    pub gravity: Gravity,
    #[serde(default)]
    pub payload: Option<Payload>,
    #[serde(default)]
    pub link_errors: Vec<LinkError>,
    /// Relative standard deviation of random errors of every link's mass, centre of mass
    /// (relative to its distance from the joint axis origin) and inertia (seeded).
    #[serde(default)]
    pub parameter_error: f64,
    /// Joint zero offsets (rad): the encoder reads `q_true + offset`.
    #[serde(default)]
    pub joint_offsets: Option<Vec<f64>>,
    #[serde(default)]
    pub friction: FrictionSpec,
    /// Per joint, torque ripple: the applied torque is `u (1 + sum of harmonics at q)`.
    #[serde(default)]
    pub ripple: Option<Vec<Vec<Harmonic>>>,
    /// Per joint, cogging torque added to the applied torque (N m).
    #[serde(default)]
    pub cogging: Option<Vec<Vec<Harmonic>>>,
    #[serde(default)]
    pub sensors: Sensors,
    /// Closed-loop tracking; absent: the joints follow the reference exactly.
    #[serde(default)]
    pub controller: Option<Controller>,
}

impl Default for TrueRobot {
    fn default() -> Self {
        TrueRobot {
            format: Self::tag(),
            seed: 0,
            gravity: Gravity::Included,
            payload: None,
            link_errors: vec![],
            parameter_error: 0.0,
            joint_offsets: None,
            friction: FrictionSpec::default(),
            ripple: None,
            cogging: None,
            sensors: Sensors::default(),
            controller: None,
        }
    }
}

/// Sum of `harmonics` at `q`.
pub(crate) fn harmonics_at(harmonics: &[Harmonic], q: f64) -> f64 {
    harmonics
        .iter()
        .map(|h| h.amplitude * (h.order * q + h.phase).sin())
        .sum()
}

fn finite_all(what: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(invalid(
            TrueRobot::WHAT,
            format!("{what}[{i}] is {}, expected a finite number", v[i]),
        )),
        None => Ok(()),
    }
}

impl Document for TrueRobot {
    const FORMAT: &'static str = "perturbid-true-robot";
    const VERSION: u32 = 1;
    const WHAT: &'static str = "true robot";

    /// Checks every number is finite and in range (lengths are checked against the robot in
    /// [`TrueRobot::check`]).
    fn validate(&self) -> Result<()> {
        self.validate_joint_arrays()?;
        self.validate_sensors()?;
        self.validate_effects()?;
        self.validate_inertials()?;
        if let Some(c) = &self.controller {
            c.validate()?;
        }
        Ok(())
    }
}

impl TrueRobot {
    /// The per-joint arrays of friction, offsets and sensors: finite, of a sign and size a
    /// robot can have (docs/limits.md).
    fn validate_joint_arrays(&self) -> Result<()> {
        let bad = |m: String| invalid(Self::WHAT, m);
        let f = &self.friction;
        let s = &self.sensors;
        let arrays: [(&str, &Option<Vec<f64>>, bool); 12] = [
            ("friction.viscous", &f.viscous, false),
            ("friction.coulomb", &f.coulomb, true),
            ("friction.coulomb_negative", &f.coulomb_negative, true),
            ("friction.stribeck", &f.stribeck, true),
            ("friction.stribeck_velocity", &f.stribeck_velocity, true),
            ("friction.drift", &f.drift, false),
            ("joint_offsets", &self.joint_offsets, false),
            ("sensors.encoder_counts", &s.encoder_counts, true),
            ("sensors.torque_noise", &s.torque_noise, true),
            (
                "sensors.torque_noise_correlation",
                &s.torque_noise_correlation,
                true,
            ),
            ("sensors.torque_resolution", &s.torque_resolution, true),
            ("controller", &None, true),
        ];
        for (what, v, non_negative) in arrays {
            if let Some(v) = v {
                finite_all(what, v)?;
                if non_negative {
                    if let Some(i) = v.iter().position(|&x| x < 0.0) {
                        return Err(bad(format!("{what}[{i}] is {}, expected >= 0", v[i])));
                    }
                }
                if what.ends_with("drift") {
                    if let Some(i) = v.iter().position(|&x| x.abs() > 1.0) {
                        return Err(bad(format!(
                            "{what}[{i}] is {} per second, expected within +-1",
                            v[i]
                        )));
                    }
                }
            }
        }
        // friction and joint offsets within what a robot can have (docs/limits.md)
        use std::f64::consts::PI;
        for (what, v, max) in [
            ("friction.viscous", &f.viscous, crate::limits::MAX_FRICTION),
            ("friction.coulomb", &f.coulomb, crate::limits::MAX_FRICTION),
            (
                "friction.coulomb_negative",
                &f.coulomb_negative,
                crate::limits::MAX_FRICTION,
            ),
            (
                "friction.stribeck",
                &f.stribeck,
                crate::limits::MAX_FRICTION,
            ),
            (
                "friction.stribeck_velocity",
                &f.stribeck_velocity,
                crate::limits::MAX_FRICTION,
            ),
            ("joint_offsets", &self.joint_offsets, PI),
        ] {
            let values = v.as_deref().unwrap_or_default();
            if let Some(i) = values.iter().position(|x| x.abs() > max) {
                return Err(bad(format!(
                    "{what}[{i}] is {}, expected at most {} in magnitude",
                    crate::error::shown(values[i]),
                    if max == PI {
                        "pi (rad or m)".to_string()
                    } else {
                        crate::error::shown(max)
                    }
                )));
            }
        }
        Ok(())
    }

    /// The simulated sensors' ranges (docs/limits.md).
    fn validate_sensors(&self) -> Result<()> {
        let bad = |m: String| invalid(Self::WHAT, m);
        let s = &self.sensors;
        // an encoder of 0 counts (none) or a
        // step of 1e-12 to 1 rad; a torque resolution of 0 (none) or 1e-12 to 1e6 N m
        use crate::limits::{MAX_TORQUE_NOISE, POSITION_RESOLUTION, TORQUE_RESOLUTION};
        // whole counts a revolution with steps in POSITION_RESOLUTION: 7 to 10^12
        let counts = (7.0, 1e12);
        debug_assert!(std::f64::consts::TAU / counts.0 <= POSITION_RESOLUTION.1);
        debug_assert!(std::f64::consts::TAU / counts.1 >= POSITION_RESOLUTION.0);
        for (what, v, (low, high)) in [
            ("sensors.encoder_counts", &s.encoder_counts, counts),
            (
                "sensors.torque_noise",
                &s.torque_noise,
                (0.0, MAX_TORQUE_NOISE),
            ),
            (
                "sensors.torque_resolution",
                &s.torque_resolution,
                TORQUE_RESOLUTION,
            ),
        ] {
            let values = v.as_deref().unwrap_or_default();
            if let Some((i, expected)) = crate::limits::outside_sensor_range(values, (low, high)) {
                return Err(bad(format!(
                    "{what}[{i}] is {}, expected {expected}",
                    crate::error::shown(values[i])
                )));
            }
        }
        if let Some(c) = &s.torque_noise_correlation {
            if let Some(i) = c.iter().position(|&x| x >= 1.0) {
                return Err(bad(format!(
                    "sensors.torque_noise_correlation[{i}] is {}, expected in [0, 1)",
                    c[i]
                )));
            }
        }
        // a second is far past any sensor's timing; past it the log's first and last torques
        // would be held (the recording does not reach that far) and the rest invented
        if !((0.0..=1.0).contains(&s.jitter) && (0.0..=1.0).contains(&s.delay)) {
            return Err(bad(format!(
                "sensors.jitter {} s and sensors.delay {} s must be in [0, 1] s",
                crate::error::shown(s.jitter),
                crate::error::shown(s.delay)
            )));
        }
        Ok(())
    }

    /// The parameter error, and the harmonics of position-dependent friction, ripple and
    /// cogging.
    fn validate_effects(&self) -> Result<()> {
        let bad = |m: String| invalid(Self::WHAT, m);
        let f = &self.friction;
        if !(self.parameter_error.is_finite() && (0.0..=0.5).contains(&self.parameter_error)) {
            return Err(bad(format!(
                "parameter_error is {}, expected a relative standard deviation in [0, 0.5]",
                self.parameter_error
            )));
        }
        for (what, h) in [
            ("friction.position", &f.position),
            ("ripple", &self.ripple),
            ("cogging", &self.cogging),
        ] {
            for (j, list) in h.iter().flatten().enumerate() {
                for (k, x) in list.iter().enumerate() {
                    if !(x.order.is_finite()
                        && x.order > 0.0
                        && x.order <= 1e5
                        && x.amplitude.is_finite()
                        && x.amplitude.abs() <= crate::limits::MAX_FRICTION
                        && x.phase.is_finite())
                    {
                        return Err(bad(format!(
                            "{what}[{j}][{k}]: order {} (expected in (0, 1e5]), amplitude {} (expected at most 1e6 in magnitude), phase {} must be finite",
                            x.order, x.amplitude, x.phase
                        )));
                    }
                }
            }
        }
        if let Some(list) = &self.ripple {
            for (j, h) in list.iter().enumerate() {
                let worst: f64 = h.iter().map(|x| x.amplitude.abs()).sum();
                if worst >= 0.5 {
                    return Err(bad(format!(
                        "ripple[{j}] can reach {worst} of the torque; expected less than 0.5"
                    )));
                }
            }
        }
        Ok(())
    }

    /// The payload and the links' inertial errors.
    fn validate_inertials(&self) -> Result<()> {
        let bad = |m: String| invalid(Self::WHAT, m);
        // a centre of mass within reach of a robot (beyond, m c^2 overflows)
        let reach = |what: &str, com: &[f64; 3]| -> Result<()> {
            finite_all(what, com)?;
            match com.iter().position(|c| c.abs() > MAX_COM_OFFSET) {
                Some(i) => Err(bad(format!(
                    "{what}[{i}] is {} m, expected at most {MAX_COM_OFFSET} m in magnitude",
                    crate::error::shown(com[i])
                ))),
                None => Ok(()),
            }
        };
        if let Some(reason) = self.payload.as_ref().and_then(|p| p.problem("payload")) {
            return Err(bad(reason));
        }
        for (i, e) in self.link_errors.iter().enumerate() {
            reach(&format!("link_errors[{i}].com"), &e.com)?;
            if !(e.mass.is_finite() && e.mass > -1.0 && e.inertia.is_finite() && e.inertia > -1.0) {
                return Err(bad(format!(
                    "link_errors[{i}] ('{}'): mass {} and inertia {} must be relative errors above -1",
                    e.link, e.mass, e.inertia
                )));
            }
        }
        Ok(())
    }
}

impl Controller {
    /// Gains, effort limits and substeps a controller can have.
    fn validate(&self) -> Result<()> {
        let bad = |m: String| invalid(TrueRobot::WHAT, m);
        let c = self;
        finite_all("controller.kp", &c.kp)?;
        finite_all("controller.kd", &c.kd)?;
        if c.kp.iter().chain(&c.kd).any(|&g| g < 0.0) {
            return Err(bad("controller gains must be >= 0".into()));
        }
        if let Some(effort) = &c.effort {
            finite_all("controller.effort", effort)?;
            if let Some(j) = effort.iter().position(|&e| e <= 0.0) {
                return Err(bad(format!(
                    "controller.effort[{j}] is {}, expected a positive torque limit (N m)",
                    effort[j]
                )));
            }
        }
        if !(1..=1000).contains(&c.substeps) {
            return Err(bad(format!(
                "controller.substeps is {}, expected 1 to 1000",
                c.substeps
            )));
        }
        Ok(())
    }
}

/// A per-joint array of the document, or `default` for every joint; its length must be `n`.
pub(crate) fn per_joint(
    what: &str,
    v: &Option<Vec<f64>>,
    n: usize,
    default: f64,
) -> Result<Vec<f64>> {
    match v {
        None => Ok(vec![default; n]),
        Some(v) if v.len() == n => Ok(v.clone()),
        Some(v) => Err(Error::shape(
            format!("true robot: {what}"),
            format!("{n} values (one per joint)"),
            format!("{} values", v.len()),
        )),
    }
}

impl TrueRobot {
    /// Checks the document against `model`: every per-joint array has one entry per joint,
    /// every named link exists, the Stribeck speeds are positive where a Stribeck level is
    /// given, the controller has one gain per joint.
    pub fn check(&self, model: &Model) -> Result<()> {
        self.validate()?;
        let n = model.nv;
        let f = &self.friction;
        let s = &self.sensors;
        for (what, v) in [
            ("friction.viscous", &f.viscous),
            ("friction.coulomb", &f.coulomb),
            ("friction.coulomb_negative", &f.coulomb_negative),
            ("friction.stribeck", &f.stribeck),
            ("friction.stribeck_velocity", &f.stribeck_velocity),
            ("friction.drift", &f.drift),
            ("joint_offsets", &self.joint_offsets),
            ("sensors.encoder_counts", &s.encoder_counts),
            ("sensors.torque_noise", &s.torque_noise),
            (
                "sensors.torque_noise_correlation",
                &s.torque_noise_correlation,
            ),
            ("sensors.torque_resolution", &s.torque_resolution),
        ] {
            per_joint(what, v, n, 0.0)?;
        }
        for (what, h) in [
            ("friction.position", &f.position),
            ("ripple", &self.ripple),
            ("cogging", &self.cogging),
        ] {
            if let Some(h) = h {
                if h.len() != n {
                    return Err(Error::shape(
                        format!("true robot: {what}"),
                        format!("{n} lists of harmonics (one per joint)"),
                        format!("{} lists", h.len()),
                    ));
                }
            }
        }
        let level = per_joint("friction.stribeck", &f.stribeck, n, 0.0)?;
        let speed = per_joint("friction.stribeck_velocity", &f.stribeck_velocity, n, 0.0)?;
        if let Some(j) = (0..n).find(|&j| level[j] != 0.0 && speed[j] <= 0.0) {
            return Err(Error::invalid(
                format!("true robot: friction.stribeck_velocity[{j}]"),
                format!(
                    "{}; expected a positive speed (rad/s) where friction.stribeck[{j}] = {} is given",
                    speed[j], level[j]
                ),
            ));
        }
        if let Some(c) = &self.controller {
            for (what, g) in [("controller.kp", &c.kp), ("controller.kd", &c.kd)] {
                per_joint(what, &Some(g.clone()), n, 0.0)?;
            }
            per_joint("controller.effort", &c.effort, n, 0.0)?;
        }
        if let Some(p) = &self.payload {
            p.body(model)?;
        }
        for e in &self.link_errors {
            body_of(model, &e.link)?;
        }
        Ok(())
    }

    /// The true robot's rigid-body model: `nominal` with the payload, the link errors and the
    /// random parameter errors applied.
    pub fn rigid_body_model(&self, nominal: &Model) -> Result<Model> {
        self.check(nominal)?;
        let mut m = nominal.clone();
        if self.parameter_error > 0.0 {
            let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
            rng.set_stream(u64::MAX);
            let gauss = Normal::new(0.0, self.parameter_error).expect("finite deviation");
            for b in &mut m.bodies {
                let i = &mut b.inertia;
                let scale = |x: f64| (1.0 + x).max(0.1);
                i.mass *= scale(gauss.sample(&mut rng));
                let reach = i.com.norm().max(0.01);
                for c in 0..3 {
                    i.com[c] += reach * gauss.sample(&mut rng);
                }
                i.inertia_com *= scale(gauss.sample(&mut rng));
            }
        }
        for e in &self.link_errors {
            let i = &mut m.bodies[body_of(nominal, &e.link)?].inertia;
            i.mass *= 1.0 + e.mass;
            i.com += Vector3::from(e.com);
            i.inertia_com *= 1.0 + e.inertia;
        }
        if let Some(p) = &self.payload {
            let (b, inertia) = p.in_body(nominal)?;
            m.bodies[b].inertia = m.bodies[b].inertia.add(&inertia);
        }
        m.refresh();
        m.name = format!("{} (true robot)", nominal.name);
        Ok(m)
    }
}

/// The body that starts at URDF link `link`.
fn body_of(model: &Model, link: &str) -> Result<usize> {
    model
        .bodies
        .iter()
        .position(|b| b.link == link)
        .ok_or_else(|| {
            Error::invalid(
                "true robot: link",
                format!(
                    "'{link}' is not a moving link of '{}'; moving links: {}",
                    model.name,
                    model
                        .bodies
                        .iter()
                        .map(|b| b.link.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })
}
