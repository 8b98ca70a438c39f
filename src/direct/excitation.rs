//! Excitation design (Swevers et al. 2007): the Fourier coefficients that make the base
//! regressor best conditioned, subject to the joint limits, optimised by COBYLA (the `cobyla`
//! crate: derivative-free, with nonlinear inequality constraints).

use std::cell::RefCell;

use faer::Mat;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::base::{BaseParameters, BASE_TOLERANCE};
use super::parameters::{regressor_matrix, FrictionTerms, ParameterLayout};
use super::workspace::{CartesianConstraint, Region};
use crate::algorithms::kinematics::{forward_kinematics, point_in_base};
use crate::choice::choice;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;
use crate::trajectory::{check_limits, FourierTrajectory};

choice! {
    /// What the design minimises.
    pub enum Criterion ("criterion") {
        /// `log10 cond(Phi_base)`, the 2-norm condition number of the stacked base regressor.
        Cond = "cond",
        /// `-log det(Phi_base^T Phi_base) / p` (D-optimality).
        LogDet = "logdet" | "log_det",
    }
}

/// Options of [`design_excitation`]; the defaults are Swevers': 5 harmonics of 0.1 Hz.
#[derive(Clone, Debug, PartialEq)]
pub struct ExcitationOptions {
    pub harmonics: usize,
    /// Base frequency (Hz); the trajectory's period is its inverse.
    pub base_frequency: f64,
    pub criterion: Criterion,
    /// Start and end (every period) at rest: `qd(0) = qdd(0) = 0` (default true).
    pub rest: bool,
    /// Samples per period in the criterion's regressor (default 100).
    pub samples: usize,
    /// Fraction of the position range, speed and acceleration limits the design may use
    /// (default 0.9).
    pub margin: f64,
    /// Bounds for joints whose URDF gives none (default 1 rad/s, 4 rad/s^2).
    pub default_velocity: f64,
    pub default_acceleration: f64,
    /// Joint terms in the regressor (default viscous and Coulomb; the armature is added when
    /// the robot model has one).
    pub friction: FrictionTerms,
    /// COBYLA's budget of criterion evaluations (default 2000).
    pub max_evaluations: usize,
    pub seed: u64,
    /// Points on named links kept above a plane or inside a box (default none).
    pub workspace: Vec<CartesianConstraint>,
    /// Keep every joint's torque (the model's, gravity included) within `margin` of the
    /// URDF's effort limit where it gives one (default true).
    pub effort: bool,
}

impl Default for ExcitationOptions {
    fn default() -> Self {
        Self {
            harmonics: 5,
            base_frequency: 0.1,
            criterion: Criterion::Cond,
            rest: true,
            samples: 100,
            margin: 0.9,
            default_velocity: 1.0,
            default_acceleration: 4.0,
            friction: FrictionTerms {
                viscous: true,
                coulomb: true,
                offset: false,
                armature: false,
            },
            max_evaluations: 2000,
            seed: 0,
            workspace: Vec::new(),
            effort: true,
        }
    }
}

/// The designed excitation.
#[derive(Clone, Debug, PartialEq)]
pub struct ExcitationDesign {
    pub trajectory: FourierTrajectory,
    /// Value of the criterion at the design.
    pub value: f64,
    /// cond(Phi_base) at the design (2-norm).
    pub cond: f64,
    /// Criterion evaluations used.
    pub evaluations: usize,
    /// The workspace and effort constraints with their smallest slack over a period (checked
    /// at 1 kHz): metres kept beyond each workspace constraint's margin, and `1 - |tau| /
    /// (margin effort)` per joint with an effort limit.
    pub margins: Vec<(String, f64)>,
}

/// Progress of the design: evaluations so far and the best feasible criterion value.
pub type Progress<'a> = &'a mut dyn FnMut(usize, f64);

struct Problem<'a> {
    model: &'a Model,
    base: BaseParameters,
    o: &'a ExcitationOptions,
    w_f: f64,
    lower: Vec<f64>,
    upper: Vec<f64>,
    vel: Vec<f64>,
    acc: Vec<f64>,
    /// Criterion sample times and (finer) limit check times.
    t_fit: Vec<f64>,
    t_check: Vec<f64>,
    /// The workspace constraints' points: (body, point in its frame).
    points: Vec<(Option<usize>, nalgebra::Vector3<f64>)>,
    /// `margin * effort` of the joints whose effort limit binds.
    effort: Vec<Option<f64>>,
}

impl Problem<'_> {
    fn free_per_joint(&self) -> usize {
        let l = self.o.harmonics;
        if self.o.rest {
            2 * (l - 1) + 1
        } else {
            2 * l + 1
        }
    }

    /// The trajectory of a decision vector (rest constraints eliminated).
    fn trajectory(&self, x: &[f64]) -> FourierTrajectory {
        let (n, l, f) = (self.model.nv, self.o.harmonics, self.free_per_joint());
        let mut a = DMatrix::zeros(n, l);
        let mut b = DMatrix::zeros(n, l);
        let mut q0 = vec![0.0; n];
        for i in 0..n {
            let xi = &x[i * f..(i + 1) * f];
            if self.o.rest {
                for k in 1..l {
                    a[(i, k)] = xi[k - 1];
                    b[(i, k)] = xi[l - 1 + k - 1];
                }
                a[(i, 0)] = -(1..l).map(|k| a[(i, k)]).sum::<f64>();
                b[(i, 0)] = -(1..l).map(|k| (k + 1) as f64 * b[(i, k)]).sum::<f64>();
            } else {
                for k in 0..l {
                    a[(i, k)] = xi[k];
                    b[(i, k)] = xi[l + k];
                }
            }
            q0[i] = xi[f - 1];
        }
        FourierTrajectory {
            w_f: self.w_f,
            q0,
            a,
            b,
        }
    }

    /// Constraint values (>= 0 when satisfied): per joint, the normalised slack of position
    /// (both sides), speed and acceleration over the check grid.
    /// Every constraint's smallest slack over a period (>= 0 where met): per joint position
    /// (upper, lower), speed and acceleration as fractions of their ranges; then per workspace
    /// constraint the distance kept (m); then per joint with a binding effort limit
    /// `1 - |tau| / (margin effort)`.
    fn constraints(&self, traj: &FourierTrajectory) -> Vec<f64> {
        let n = self.model.nv;
        let extra = self.points.len() + self.effort.iter().flatten().count();
        let mut out = vec![f64::INFINITY; 4 * n + extra];
        let cartesian = !self.points.is_empty();
        let torque = self.effort.iter().any(Option::is_some);
        let mut data = (cartesian || torque).then(|| crate::data::Data::new(self.model));
        let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for &t in &self.t_check {
            for i in 0..n {
                let (qi, vi, ai) = traj.eval(i, t);
                (q[i], v[i], a[i]) = (qi, vi, ai);
                let span = (self.upper[i] - self.lower[i]).max(1e-9);
                out[4 * i] = out[4 * i].min((self.upper[i] - qi) / span);
                out[4 * i + 1] = out[4 * i + 1].min((qi - self.lower[i]) / span);
                out[4 * i + 2] = out[4 * i + 2].min(1.0 - vi.abs() / self.vel[i]);
                out[4 * i + 3] = out[4 * i + 3].min(1.0 - ai.abs() / self.acc[i]);
            }
            let Some(data) = data.as_mut() else { continue };
            let mut c = 4 * n;
            if cartesian {
                if forward_kinematics(self.model, data, &q).is_err() {
                    return vec![-1.0; out.len()];
                }
                for (k, (body, point)) in self.points.iter().enumerate() {
                    let p = point_in_base(data, *body, point);
                    out[c] = out[c].min(self.o.workspace[k].slack(&p));
                    c += 1;
                }
            }
            if torque {
                if crate::algorithms::rnea::rnea(self.model, data, &q, &v, &a, Gravity::Included)
                    .is_err()
                {
                    return vec![-1.0; out.len()];
                }
                for (i, e) in self.effort.iter().enumerate() {
                    if let Some(e) = e {
                        out[c] = out[c].min(1.0 - data.tau[i].abs() / e);
                        c += 1;
                    }
                }
            }
        }
        out
    }

    /// Names of the constraints in [`Problem::constraints`]'s order, with their unit.
    fn constraint_names(&self) -> Vec<String> {
        let names = &self.model.joint_names;
        let mut out = vec![];
        for j in names {
            for what in [
                "upper position limit",
                "lower position limit",
                "speed limit",
                "acceleration limit",
            ] {
                out.push(format!("{j} {what} (fraction)"));
            }
        }
        for w in &self.o.workspace {
            let region = match &w.region {
                Region::Above { .. } => "above the plane",
                Region::Inside { .. } => "inside the box",
            };
            out.push(format!("{} {region} (m)", w.frame));
        }
        for (j, e) in names.iter().zip(&self.effort) {
            if e.is_some() {
                out.push(format!("{j} effort limit (fraction)"));
            }
        }
        out
    }

    /// (criterion, cond) of a trajectory.
    fn criterion(&self, traj: &FourierTrajectory) -> (f64, f64) {
        let s = traj.sample(&self.t_fit);
        let states = States::new(self.model.nv, &s.q, Some(&s.qd), Some(&s.qdd));
        let phi = match states.and_then(|states| {
            regressor_matrix(self.model, &self.base.layout, &states, Gravity::Included)
        }) {
            Ok(p) => self.base.select(&p),
            Err(_) => return (f64::INFINITY, f64::INFINITY),
        };
        let m = Mat::<f64>::from_fn(phi.nrows(), phi.ncols(), |i, j| phi[(i, j)]);
        let sv = match m.singular_values() {
            Ok(sv) => sv,
            Err(_) => return (f64::INFINITY, f64::INFINITY),
        };
        let (max, min) = sv
            .iter()
            .fold((0.0f64, f64::INFINITY), |(a, b), &v| (a.max(v), b.min(v)));
        let cond = if min > 0.0 { max / min } else { f64::INFINITY };
        let value = match self.o.criterion {
            Criterion::Cond => cond.log10(),
            Criterion::LogDet => {
                -sv.iter().map(|v| 2.0 * v.max(1e-300).ln()).sum::<f64>() / sv.len() as f64
            }
        };
        (value, cond)
    }
}

/// The payload that carries a Ctrl-C out of COBYLA's loop.
struct Interrupted;

/// Designs a Fourier excitation for `model` (docs/method.md, section 8): COBYLA minimises the
/// criterion over the coefficients and offsets subject to the limits (times `margin`), from a
/// seeded random feasible start. `progress` is called every 100 evaluations. The result is
/// checked against the full limits at 1 kHz over one period.
pub fn design_excitation(
    model: &Model,
    options: &ExcitationOptions,
    progress: Option<Progress<'_>>,
) -> Result<ExcitationDesign> {
    check_options(options)?;
    let p = Problem::new(model, options)?;
    let (x, bounds) = feasible_start(&p);
    let (x, evaluations) = search(&p, x, &bounds, progress)?;
    finish(p, &x, evaluations)
}

/// The options' counts and ranges, before any work.
fn check_options(o: &ExcitationOptions) -> Result<()> {
    use crate::limits::{
        check_count, check_range, MAX_EVALUATIONS, MAX_FIT_SAMPLES, MAX_HARMONICS,
    };
    check_count("harmonics", o.harmonics, 1, MAX_HARMONICS)?;
    check_count("samples", o.samples, 1, MAX_FIT_SAMPLES)?;
    check_count("max_evaluations", o.max_evaluations, 1, MAX_EVALUATIONS)?;
    // a period of at most 1000 s: the design checks its limits at 1 kHz over a period
    let (low, high) = crate::limits::BASE_FREQUENCY;
    check_range("base_frequency", o.base_frequency, low, high)?;
    check_range(
        "default_velocity",
        o.default_velocity,
        f64::MIN_POSITIVE,
        1e6,
    )?;
    check_range(
        "default_acceleration",
        o.default_acceleration,
        f64::MIN_POSITIVE,
        1e9,
    )?;
    if o.harmonics == 0 || (o.rest && o.harmonics < 2) {
        return Err(Error::invalid(
            "harmonics",
            format!("{}; need at least 2 to start at rest", o.harmonics),
        ));
    }
    if !(o.base_frequency.is_finite() && o.base_frequency > 0.0) {
        return Err(Error::invalid(
            "base_frequency",
            format!("{} Hz; expected a positive number", o.base_frequency),
        ));
    }
    if !(o.margin > 0.0 && o.margin <= 1.0) {
        return Err(Error::invalid(
            "margin",
            format!("{}; expected a fraction in (0, 1]", o.margin),
        ));
    }
    Ok(())
}

impl<'a> Problem<'a> {
    /// The search's limits (times the margin), sample times and constraints for `model`.
    fn new(model: &'a Model, o: &'a ExcitationOptions) -> Result<Problem<'a>> {
        let n = model.nv;
        let layout = ParameterLayout::new(model, o.friction.for_model(model));
        let values = (o.samples * n) as f64 * layout.len() as f64;
        crate::limits::check_values("samples", values, || {
            format!(
                "the criterion's regressor of {} samples of {n} joints and {} parameters",
                o.samples,
                layout.len()
            )
        })?;
        let base = BaseParameters::from_random_states(
            model,
            &layout,
            Gravity::Included,
            200.max(layout.len()),
            BASE_TOLERANCE,
            o.seed,
        )?;
        if o.samples * n < base.len() {
            return Err(Error::invalid(
                "samples",
                format!(
                    "{} samples x {n} joints cannot determine {} base parameters",
                    o.samples,
                    base.len()
                ),
            ));
        }
        let w_f = 2.0 * std::f64::consts::PI * o.base_frequency;
        let period = 1.0 / o.base_frequency;
        let m = o.margin;
        let (mut lower, mut upper) = (vec![0.0; n], vec![0.0; n]);
        for (i, lim) in model.limits.iter().enumerate() {
            let (lo, hi) = if lim.lower.is_finite() && lim.upper.is_finite() {
                (lim.lower, lim.upper)
            } else {
                (-std::f64::consts::PI, std::f64::consts::PI)
            };
            let (c, h) = (0.5 * (lo + hi), 0.5 * (hi - lo) * m);
            (lower[i], upper[i]) = (c - h, c + h);
        }
        // The speeds the excitation can use. A Fourier series of L harmonics that stays within a
        // position half-range h moves at most h w_f L fast (Bernstein's inequality): a speed limit
        // above that cannot be reached, and taken as it is (1e300 from a careless URDF) it would
        // only scale the search (its bounds and first step) into overflow. Accelerations enter the
        // constraints only, as ratios to their limits, where a huge limit does no harm.
        let given = |limit: f64, default: f64| if limit.is_finite() { limit } else { default };
        let vel: Vec<f64> = (0..n)
            .map(|i| {
                let reach = 0.5 * (upper[i] - lower[i]) * w_f * o.harmonics as f64;
                (m * given(model.limits[i].velocity, o.default_velocity)).min(reach)
            })
            .collect();
        let acc: Vec<f64> = (0..n)
            .map(|i| m * given(model.limits[i].acceleration, o.default_acceleration))
            .collect();
        Ok(Problem {
            model,
            base,
            o,
            w_f,
            vel,
            acc,
            lower,
            upper,
            t_fit: (0..o.samples)
                .map(|k| period * k as f64 / o.samples as f64)
                .collect(),
            t_check: (0..400).map(|k| period * k as f64 / 400.0).collect(),
            points: o
                .workspace
                .iter()
                .map(|w| w.resolve(model))
                .collect::<Result<_>>()?,
            effort: model
                .limits
                .iter()
                .map(|l| (o.effort && l.effort.is_finite()).then_some(m * l.effort))
                .collect(),
        })
    }
}

/// A seeded random start, shrunk until feasible, and the coefficients' bounds.
fn feasible_start(p: &Problem<'_>) -> (Vec<f64>, Vec<(f64, f64)>) {
    let (n, o) = (p.model.nv, p.o);
    let f = p.free_per_joint();
    let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
    let mut x = vec![0.0; n * f];
    let mut bounds = vec![(0.0, 0.0); n * f];
    for i in 0..n {
        let amp = p.vel[i] / o.harmonics as f64;
        for k in 0..f - 1 {
            x[i * f + k] = rng.random_range(-amp..=amp);
            bounds[i * f + k] = (-p.vel[i], p.vel[i]);
        }
        x[i * f + f - 1] = 0.5 * (p.lower[i] + p.upper[i]);
        bounds[i * f + f - 1] = (p.lower[i], p.upper[i]);
    }
    for _ in 0..60 {
        if p.constraints(&p.trajectory(&x)).iter().all(|&c| c >= 0.0) {
            break;
        }
        for i in 0..n {
            for k in 0..f - 1 {
                x[i * f + k] *= 0.8;
            }
        }
    }
    (x, bounds)
}

/// COBYLA from `x`: the coefficients it ends at and the number of evaluations; Ctrl-C stops it.
fn search(
    p: &Problem<'_>,
    x: Vec<f64>,
    bounds: &[(f64, f64)],
    progress: Option<Progress<'_>>,
) -> Result<(Vec<f64>, usize)> {
    let o = p.o;
    let evaluations = RefCell::new(0usize);
    let best = RefCell::new(f64::INFINITY);
    let progress = RefCell::new(progress);
    let cache: RefCell<(Vec<f64>, Vec<f64>)> = RefCell::new((Vec::new(), Vec::new()));
    let constraints_of = |x: &[f64]| -> Vec<f64> {
        let mut c = cache.borrow_mut();
        if c.0 != x {
            // COBYLA loops forever on a NaN: a non-finite constraint counts as badly broken
            let values = p
                .constraints(&p.trajectory(x))
                .into_iter()
                .map(|v| if v.is_finite() { v } else { -1e30 })
                .collect();
            *c = (x.to_vec(), values);
        }
        c.1.clone()
    };
    let objective = |x: &[f64], _: &mut ()| -> f64 {
        // Ctrl-C: unwind out of COBYLA (pure Rust, nothing of it is kept), caught below;
        // `resume_unwind` skips the panic hook, so nothing is printed
        if crate::interrupt::requested() {
            std::panic::resume_unwind(Box::new(Interrupted));
        }
        let (value, _) = p.criterion(&p.trajectory(x));
        // a singular design (inf) or a failed evaluation (NaN) is the worst value, finite
        let value = if value.is_finite() { value } else { 1e30 };
        let mut e = evaluations.borrow_mut();
        *e += 1;
        if constraints_of(x).iter().all(|&c| c >= 0.0) && value < *best.borrow() {
            *best.borrow_mut() = value;
        }
        if (*e).is_multiple_of(100) {
            if let Some(cb) = progress.borrow_mut().as_mut() {
                cb(*e, *best.borrow());
            }
        }
        value
    };
    let cons: Vec<_> = (0..p.constraint_names().len())
        .map(|c| {
            let cf = &constraints_of;
            move |x: &[f64], _: &mut ()| cf(x)[c]
        })
        .collect();
    let rhobeg = p.vel.iter().cloned().fold(f64::INFINITY, f64::min) / (4.0 * o.harmonics as f64);
    let run = || {
        cobyla::minimize(
            objective,
            &x,
            bounds,
            &cons,
            (),
            o.max_evaluations,
            cobyla::RhoBeg::All(rhobeg),
            Some(cobyla::StopTols {
                ftol_rel: 1e-6,
                ..cobyla::StopTols::default()
            }),
        )
    };
    let result = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(result) => result,
        Err(payload) if payload.is::<Interrupted>() => {
            return Err(Error::Interrupted {
                context: "excitation design".into(),
            })
        }
        Err(payload) => std::panic::resume_unwind(payload),
    };
    let x = match result {
        Ok((_, x, _)) | Err((_, x, _)) => x,
    };
    let evaluations = *evaluations.borrow();
    Ok((x, evaluations))
}

/// The trajectory of `x` brought within the full limits and checked at 1 kHz over a period.
fn finish(p: Problem<'_>, x: &[f64], evaluations: usize) -> Result<ExcitationDesign> {
    let (model, o, n) = (p.model, p.o, p.model.nv);
    let period = 1.0 / o.base_frequency;
    // make sure of the limits: COBYLA may end with an offset outside its bounds (narrow
    // ranges), so the offsets go back within the limits; then the amplitudes shrink about q0
    // until the full check passes
    let mut traj = p.trajectory(x);
    for i in 0..n {
        traj.q0[i] = traj.q0[i].clamp(p.lower[i], p.upper[i]);
    }
    for _ in 0..2000 {
        if p.constraints(&traj).iter().all(|&c| c >= 0.0) {
            break;
        }
        traj.a *= 0.99;
        traj.b *= 0.99;
    }
    check_limits(
        model,
        &traj.sample_periods(1.0, 1000.0)?,
        "designed excitation",
        "; lower the margin",
    )?;
    // the workspace and effort constraints, at 1 kHz over a period (the search checked 400
    // times a period), reported with their slack
    let fine = Problem {
        t_check: (0..(1000.0 * period).ceil() as usize)
            .map(|k| k as f64 / 1000.0)
            .collect(),
        ..p
    };
    let slack = fine.constraints(&traj);
    let names = fine.constraint_names();
    let margins: Vec<(String, f64)> = names.into_iter().zip(slack).skip(4 * n).collect();
    if let Some((what, s)) = margins.iter().find(|(_, s)| *s < 0.0) {
        return Err(Error::invalid(
            "workspace",
            format!(
                "the designed excitation breaks '{what}' by {:.4}: no excitation within the other limits keeps it; move the constraint, lower its margin, or give the design more evaluations",
                -s
            ),
        ));
    }
    let (value, cond) = fine.criterion(&traj);
    if !cond.is_finite() {
        return Err(Error::numerical(
            "excitation design",
            format!(
                "the best excitation found does not excite every base parameter (cond(Phi_base) {cond}): the motion the limits leave it (margin {m}) is too small or too uniform; widen the margin or the joint limits, or give the design more evaluations",
                m = crate::error::shown(o.margin)
            ),
        ));
    }
    Ok(ExcitationDesign {
        trajectory: traj,
        value,
        cond,
        evaluations,
        margins,
    })
}

impl ExcitationDesign {
    /// Joints with position limits that the excitation leaves almost still: moving over less
    /// than 2 % of their range in a period, so that their parameters are barely excited. One
    /// warning per joint.
    pub fn warnings(&self, model: &Model) -> Vec<String> {
        let s = match self.trajectory.sample_periods(1.0, 200.0) {
            Ok(s) => s,
            Err(e) => {
                return vec![format!(
                    "the excitation could not be sampled to check it: {e}"
                )]
            }
        };
        let n = model.nv;
        (0..n)
            .filter_map(|j| {
                let l = &model.limits[j];
                let range = l.upper - l.lower;
                if !range.is_finite() || range <= 0.0 {
                    return None;
                }
                let (lo, hi) = s.q.iter().skip(j).step_by(n).fold(
                    (f64::INFINITY, f64::NEG_INFINITY),
                    |(a, b), &v| (a.min(v), b.max(v)),
                );
                let used = (hi - lo) / range;
                (used < 0.02).then(|| {
                    format!(
                        "joint {} moves over {:.1} % of its range in the excitation: the parameters it alone excites are barely identified; raise its amplitude or lock the joint",
                        model.joint_names[j],
                        100.0 * used
                    )
                })
            })
            .collect()
    }
}
