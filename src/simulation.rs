//! Measurement simulation: the torques a robot would log along a trajectory, with friction,
//! noise and encoder quantisation, so a user can rehearse before touching the robot.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::algorithms::parallel;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::logs::recording::Recording;
use crate::model::Model;
use crate::states::States;
use crate::trajectory::{FourierTrajectory, Samples};

/// Joint friction as a function of the joint speed alone, per joint (SI: N m for revolute
/// joints, N for prismatic ones; speeds in rad/s or m/s):
///
/// ```text
/// qd > 0:  tau_f =  viscous qd + coulomb          + stribeck exp(-(qd / stribeck_velocity)^2)
/// qd < 0:  tau_f =  viscous qd - coulomb_negative - stribeck exp(-(qd / stribeck_velocity)^2)
/// qd = 0:  tau_f = 0
/// ```
///
/// `coulomb_negative` differs from `coulomb` for asymmetric Coulomb friction; `stribeck` is the
/// breakaway excess (static minus Coulomb level), 0 for none. At exactly zero speed the friction
/// carries no torque: a rehearsal defines it rather than leaving it to the sign of a rounding
/// error (a real joint at rest holds anything up to its breakaway level). Along a trajectory
/// the simulations apply it in the joint's direction of motion instead
/// ([`directions_of_motion`]), so that a joint
/// touching zero speed at one sample without stopping keeps its friction there.
#[derive(Clone, Debug, PartialEq)]
pub struct Friction {
    /// N m s/rad.
    pub viscous: Vec<f64>,
    /// Coulomb level for positive speeds (N m, >= 0).
    pub coulomb: Vec<f64>,
    /// Coulomb level for negative speeds (N m, >= 0; the torque is `-coulomb_negative`).
    pub coulomb_negative: Vec<f64>,
    /// Stribeck excess at zero speed (N m, >= 0).
    pub stribeck: Vec<f64>,
    /// Stribeck speed (rad/s, > 0 where `stribeck` is not 0).
    pub stribeck_velocity: Vec<f64>,
}

impl Friction {
    /// No friction.
    pub fn none(n: usize) -> Self {
        Self::viscous_coulomb(vec![0.0; n], vec![0.0; n])
    }

    /// Viscous and symmetric Coulomb friction (`coulomb_negative = coulomb`, no Stribeck).
    pub fn viscous_coulomb(viscous: Vec<f64>, coulomb: Vec<f64>) -> Self {
        let n = viscous.len();
        Self {
            viscous,
            coulomb_negative: coulomb.clone(),
            coulomb,
            stribeck: vec![0.0; n],
            stribeck_velocity: vec![1.0; n],
        }
    }

    /// The URDF's `<dynamics damping friction>` of every joint (viscous and symmetric Coulomb).
    pub fn from_model(model: &Model) -> Self {
        Self::viscous_coulomb(
            model.limits.iter().map(|l| l.damping).collect(),
            model.limits.iter().map(|l| l.friction).collect(),
        )
    }

    /// Friction torque of joint `j` at speed `qd`; see the type's documentation.
    pub fn torque(&self, j: usize, qd: f64) -> f64 {
        self.torque_moving(j, qd, crate::parameters::sign0(qd))
    }

    /// Friction torque of joint `j` at speed `qd` moving in `direction` (the sign of `qd`, or
    /// where `qd` is zero the direction of motion around it, [`directions_of_motion`]: 1, -1,
    /// or 0 at rest).
    pub fn torque_moving(&self, j: usize, qd: f64, direction: f64) -> f64 {
        let stribeck = |level: f64| {
            if self.stribeck[j] == 0.0 {
                level
            } else {
                level + self.stribeck[j] * (-(qd / self.stribeck_velocity[j]).powi(2)).exp()
            }
        };
        if direction > 0.0 {
            self.viscous[j] * qd + stribeck(self.coulomb[j])
        } else if direction < 0.0 {
            self.viscous[j] * qd - stribeck(self.coulomb_negative[j])
        } else {
            0.0
        }
    }

    /// Checks the lengths (`n` each), finiteness and signs.
    pub fn check(&self, n: usize) -> Result<()> {
        for (what, v) in [
            ("friction viscous", &self.viscous),
            ("friction coulomb", &self.coulomb),
            ("friction coulomb_negative", &self.coulomb_negative),
            ("friction stribeck", &self.stribeck),
            ("friction stribeck_velocity", &self.stribeck_velocity),
        ] {
            crate::model::check_finite_vector(what, v, n)?;
            if let Some(j) = v.iter().position(|x| x.abs() > crate::limits::MAX_FRICTION) {
                return Err(Error::invalid(
                    format!("{what}[{j}]"),
                    format!(
                        "{}; expected at most {} in magnitude (docs/limits.md)",
                        crate::error::shown(v[j]),
                        crate::error::shown(crate::limits::MAX_FRICTION)
                    ),
                ));
            }
            if what != "friction viscous" {
                if let Some(j) = v.iter().position(|&x| x < 0.0) {
                    return Err(Error::invalid(
                        format!("{what}[{j}]"),
                        format!(
                            "{}; expected a level >= 0 (the sign follows the speed)",
                            v[j]
                        ),
                    ));
                }
            }
        }
        if let Some(j) =
            (0..n).find(|&j| self.stribeck[j] != 0.0 && self.stribeck_velocity[j] <= 0.0)
        {
            return Err(Error::invalid(
                format!("friction stribeck_velocity[{j}]"),
                format!(
                    "{}; expected a positive speed where stribeck[{j}] = {} is not 0",
                    self.stribeck_velocity[j], self.stribeck[j]
                ),
            ));
        }
        Ok(())
    }
}

/// What to simulate. Noise levels are standard deviations per joint; zero switches a term off.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationOptions {
    /// Gravity on (default) or off (as if compensated).
    pub gravity: Gravity,
    pub friction: Friction,
    /// Gaussian noise on the logged torques (N m).
    pub torque_noise: Vec<f64>,
    /// Gaussian noise on the logged positions (rad), applied before quantisation.
    pub position_noise: Vec<f64>,
    /// Encoder resolution (rad per count); 0 = none. Positions are rounded to whole counts.
    pub quantization: Vec<f64>,
    pub seed: u64,
}

impl SimulationOptions {
    /// Gravity on, the model's URDF friction, no noise, no quantisation, seed 0.
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        Self {
            gravity: Gravity::Included,
            friction: Friction::from_model(model),
            torque_noise: vec![0.0; n],
            position_noise: vec![0.0; n],
            quantization: vec![0.0; n],
            seed: 0,
        }
    }

    fn check(&self, n: usize) -> Result<()> {
        self.friction.check(n)?;
        // the largest: far past any sensor, so that a slip of the exponent is an error, not
        // a recording of noise (1e300 N m) or of a robot that never moved (1e300 rad a count)
        use crate::limits::{MAX_TORQUE_NOISE, POSITION_RESOLUTION};
        for (what, v, range) in [
            ("torque_noise", &self.torque_noise, (0.0, MAX_TORQUE_NOISE)),
            ("position_noise", &self.position_noise, (0.0, 1.0)),
            ("quantization", &self.quantization, POSITION_RESOLUTION),
        ] {
            crate::model::check_finite_vector(what, v, n)?;
            // a resolution is 0 (none) or in its range
            if let Some((j, expected)) = crate::limits::outside_sensor_range(v, range) {
                return Err(Error::invalid(
                    format!("{what}[{j}]"),
                    format!("{}; expected {expected}", crate::error::shown(v[j])),
                ));
            }
        }
        Ok(())
    }
}

/// Speeds within this fraction of a joint's largest speed along a trajectory are rounding
/// errors of zero (a Fourier series summed at its rest point leaves about 1e-17 rad/s, of
/// either sign), not motion.
pub const ROUNDING_SPEED: f64 = 1e-12;

/// The direction each joint moves in at each sample of the speeds `qd` (row-major, `n` per
/// sample, successive in time; returned in the same layout): the sign of its speed (1, -1), and
/// where that speed is zero (within [`ROUNDING_SPEED`] of the joint's largest), the direction
/// of its neighbours when every neighbour it has (one at either end) moves the same way. Such
/// a joint touches zero speed at that instant without stopping, and its friction, continuous
/// over a sample as a real joint's is, keeps its sign: applied there as at rest (or with the
/// sign of a rounding error), it would log a one-sample dip of the Coulomb level that no robot
/// shows (and that the log screening rightly takes for a glitch). 0 at rest (a neighbour at
/// zero speed too) and at a reversal (neighbours moving opposite ways).
pub fn directions_of_motion(qd: &[f64], n: usize) -> Vec<f64> {
    use crate::parameters::sign0;
    let k = qd.len().checked_div(n).unwrap_or(0);
    let mut own = vec![0.0; k * n];
    for j in 0..n {
        let fastest = (0..k).map(|i| qd[i * n + j].abs()).fold(0.0, f64::max);
        for i in 0..k {
            let v = qd[i * n + j];
            if v.abs() > ROUNDING_SPEED * fastest {
                own[i * n + j] = sign0(v);
            }
        }
    }
    let mut out = own.clone();
    for i in 0..k {
        for j in 0..n {
            if own[i * n + j] != 0.0 {
                continue;
            }
            let before = (i > 0).then(|| own[(i - 1) * n + j]);
            let after = (i + 1 < k).then(|| own[(i + 1) * n + j]);
            out[i * n + j] = match (before, after) {
                (Some(b), Some(a)) if a == b => a,
                (None, Some(s)) | (Some(s), None) => s,
                _ => 0.0,
            };
        }
    }
    out
}

/// Simulates what a robot logs along `samples` (its true `t, q, qd, qdd`): the torque
/// `tau = rnea(q, qd, qdd) + tau_f(qd)` (gravity per `options`, the friction in each
/// sample's direction of motion, [`directions_of_motion`]) plus noise, and the position
/// plus noise, quantised. The recording holds `t`, `q` and `tau` only (a robot's velocity and
/// acceleration estimates are not simulated). `stream` separates the random streams of several
/// recordings made with one seed.
pub fn simulate_samples(
    model: &Model,
    samples: &Samples,
    options: &SimulationOptions,
    stream: u64,
    name: &str,
) -> Result<Recording> {
    let n = model.nv;
    if samples.n != n {
        return Err(Error::shape(
            "samples",
            format!("{n} joints"),
            format!("{} joints", samples.n),
        ));
    }
    options.check(n)?;
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    rng.set_stream(stream);
    let gauss = Normal::new(0.0, 1.0).expect("unit normal");
    let k = samples.len();
    // the rigid-body torques of every sample at once, by the batch engine
    let states = States::new(n, &samples.q, Some(&samples.qd), Some(&samples.qdd))?;
    let mut rigid = vec![0.0; k * n];
    let mut workspace = parallel::Workspace::new(model);
    parallel::rnea(model, &mut workspace, &states, options.gravity, &mut rigid)?;
    let directions = directions_of_motion(&samples.qd, n);
    let (mut q, mut tau) = (Vec::with_capacity(k * n), Vec::with_capacity(k * n));
    for i in 0..k {
        let (qi, qdi) = (samples.q_at(i), samples.qd_at(i));
        for j in 0..n {
            let t = rigid[i * n + j]
                + options
                    .friction
                    .torque_moving(j, qdi[j], directions[i * n + j])
                + options.torque_noise[j] * gauss.sample(&mut rng);
            tau.push(t);
            let mut p = qi[j] + options.position_noise[j] * gauss.sample(&mut rng);
            if options.quantization[j] > 0.0 {
                p = (p / options.quantization[j]).round() * options.quantization[j];
            }
            q.push(p);
        }
    }
    Recording::new(name, n, samples.t.clone(), q, tau, None, None)
}

/// Refuses a plan made for other joints than `model`'s.
pub(crate) fn check_plan_robot(model: &Model, plan: &crate::local::Plan) -> Result<()> {
    if plan.joint_names != model.joint_names {
        return Err(Error::invalid(
            "plan",
            format!(
                "the plan is for joints [{}] of '{}', the robot '{}' has [{}]",
                plan.joint_names.join(", "),
                plan.robot,
                model.name,
                model.joint_names.join(", ")
            ),
        ));
    }
    Ok(())
}

/// Experiment `e` of `plan` sampled at the plan's rate, checked against `model`'s limits as
/// [`crate::local::plan_experiments`] checks a plan it makes: a plan read from a file (edited
/// by hand, or made for a robot with wider limits) runs on a robot only within its limits.
pub fn experiment_samples(
    model: &Model,
    plan: &crate::local::Plan,
    e: &crate::local::Experiment,
) -> Result<crate::trajectory::Samples> {
    let samples = e.trajectory.sample(plan.rate);
    crate::trajectory::check_limits(
        model,
        &samples,
        &format!("experiment '{}' of the plan", e.kind.name()),
        "; the plan does not suit this robot's limits: plan again for it",
    )?;
    Ok(samples)
}

/// `traj` over `periods` periods at `rate` Hz (see [`FourierTrajectory::sample_periods`]),
/// for `model`, whose joints it must have, checked against `model`'s limits as
/// [`crate::direct::design_excitation`] checks the excitations it designs: one read from a
/// file (edited by hand, or designed for a robot with wider limits) runs on a robot only
/// within its limits.
pub fn excitation_samples(
    model: &Model,
    traj: &FourierTrajectory,
    periods: f64,
    rate: f64,
) -> Result<Samples> {
    if traj.n() != model.nv {
        return Err(Error::invalid(
            "excitation",
            format!(
                "it is for {} joints; robot '{}' has {}",
                traj.n(),
                model.name,
                model.nv
            ),
        ));
    }
    let samples = traj.sample_periods(periods, rate)?;
    crate::trajectory::check_limits(
        model,
        &samples,
        "the excitation",
        "; the excitation does not suit this robot's limits: design it again for it (perturbid excite)",
    )?;
    Ok(samples)
}

/// Simulates one recording per experiment of `plan` (in the plan's order) for `model`, which
/// must have the plan's joints and whose limits every experiment must keep. Each experiment
/// gets its own random stream of `options.seed`.
pub fn simulate_plan(
    model: &Model,
    plan: &crate::local::Plan,
    options: &SimulationOptions,
) -> Result<Vec<Recording>> {
    check_plan_robot(model, plan)?;
    plan.experiments
        .iter()
        .enumerate()
        .map(|(i, e)| {
            crate::interrupt::check("simulation")?;
            simulate_samples(
                model,
                &experiment_samples(model, plan, e)?,
                options,
                i as u64,
                &format!("simulated experiment '{}'", e.kind.name()),
            )
            .map(|r| r.for_experiment(e.kind.name()))
        })
        .collect()
}
