//! Whether a plan's perturbations will move the torques beyond the torque sensor's noise,
//! predicted before the robot runs (our extension; docs/method.md, section 4).
//!
//! The identification tests each experiment's torque changes against their noise
//! ([`super::response`]) and warns of an experiment none of whose torques responded: after the
//! robot time is spent. Given the noise of the torque samples, the planner predicts that test:
//! the robot's model gives each crossing's torque change (rigid bodies and armature; no
//! friction), the crossing's reading (a fit over its window, narrowed before a velocity
//! reversal as the identification narrows it: [`reading_gains`]) gives its noise, and the test is run on [`DRAWS`] seeded draws of that noise (drawn in each
//! joint's few coordinates that the test reads, so a draw costs the same for any number of
//! crossings; checked against the test on whole rows of noise). An experiment that
//! would pass in fewer than [`DETECTION`] of them is warned of, with how much larger the
//! perturbations would have to be, and how precise its estimate would be.
//!
//! Noise slower than a window (a drifting sensor, the robot's repeatability) adds to every
//! reading from pass to pass without showing in the samples' scatter about their fit; given it
//! (as an identification reports it, [`super::TorqueNoise::passes`]), each reading's noise is
//! both together, and the test reads it from the nominal passes as the identification does.

use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

use super::crossing::FitOptions;
use super::plan::{Crossing, Experiment, ExperimentKind};
use super::response::{
    design_basis, half_differences, resolved, shown_factor, test, Response, Sums,
};
use super::reversals::reading_gains;
use crate::data::Data;
use crate::error::{shown, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::operating_point::OperatingPoint;

/// The fraction of runs in which the identification should find the experiment's response;
/// a plan predicted below it is warned of.
pub const DETECTION: f64 = 0.9;

/// How many draws of the noise the prediction runs the identification's test on.
pub const DRAWS: usize = 200;

/// The largest factor on the perturbations [`Prediction::factor`] looks for: past it no
/// perturbation a robot can make would do (the planner refuses sizes below 1e-9).
pub const MAX_FACTOR: f64 = 1e12;

/// An experiment's predicted response to its perturbations under a torque noise.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The fraction of [`DRAWS`] runs in which the identification's test finds a response.
    pub detected: f64,
    /// The factor on the torque changes (about the factor on the perturbations) at which the
    /// test would find it in [`DETECTION`] of the runs: 1 when it already does, infinite when
    /// no factor up to [`MAX_FACTOR`] does (the model's torques barely change).
    pub factor: f64,
    /// The estimate's standard errors over its size (RMS over the entries, Frobenius), as the
    /// model gives both; infinite when the model's estimate is zero.
    pub relative_error: f64,
    /// Each joint's reading noise (N m or N, the standard error of one crossing's torque:
    /// the samples' noise through the window's fit and the noise from pass to pass together).
    pub reading: Vec<f64>,
}

/// Predicts the response of `experiment` (of a plan at `op`, sampled at `rate` Hz) under torque
/// samples of standard deviation `noise` (N m or N per joint; 0 for a joint whose noise is not
/// known, left out of the test), read by the default crossing fit, and a noise from pass to
/// pass of standard deviation `passes` (N m or N a reading, per joint, independent from
/// reading to reading, added to the samples' through the fit; empty or zeros for none).
/// `nominal_readings`: the nominal experiment's crossings (T* is their mean; their scatter is
/// the identification's noise from pass to pass, [`super::response::PassNoise`]; 0 without
/// one). None for the nominal experiment, or when the window is too short for the fit (the
/// identification refuses it), or no joint is tested.
pub fn predict(
    model: &Model,
    op: &OperatingPoint,
    experiment: &Experiment,
    noise: &[f64],
    passes: &[f64],
    rate: f64,
    nominal_readings: usize,
) -> Result<Option<Prediction>> {
    let n = model.nv;
    let passes_given = !passes.is_empty();
    if experiment.kind.perturbed().is_none()
        || noise.len() != n
        || (passes_given && passes.len() != n)
    {
        return Ok(None);
    }
    // each joint's reading noise per unit of the samples', over the windows the
    // identification reads (narrowed before a velocity reversal: fewer samples, more noise)
    let Some(gains) = reading_gains(experiment, rate, &FitOptions::default())? else {
        return Ok(None);
    };
    let measured: Vec<bool> = noise.iter().map(|s| *s > 0.0).collect();
    if !measured.contains(&true) {
        return Ok(None);
    }
    // the samples' part of a reading's noise (what the identification reads about the fits)
    let samples: Vec<f64> = noise.iter().zip(&gains).map(|(s, g)| s * g).collect();
    let reading: Vec<f64> = (0..n)
        .map(|j| samples[j].hypot(if passes_given { passes[j] } else { 0.0 }))
        .collect();
    let changes = torque_changes(model, op, experiment)?;
    let deltas = &experiment.deltas;
    let k = deltas.nrows();
    let paired = experiment.in_pairs() && k.is_multiple_of(2);
    let u = DMatrix::from_fn(k, n, |_, j| reading[j].powi(2));
    // the rows the test reads: +- pairs by their half-differences, where T* cancels
    let (x, w) = if paired {
        let (x, w, _) = half_differences(deltas, &changes, &u);
        (x, w)
    } else {
        (deltas.clone(), changes.clone())
    };
    let Some(q) = design_basis(&x) else {
        return Ok(None);
    };
    let (rows, columns) = q.shape();
    let joints: Vec<Option<Reduced>> = (0..n)
        .map(|j| measured[j].then(|| Reduced::new(&q, &w.column(j).into_owned())))
        .collect();
    let row: f64 = if paired { 0.5 } else { 1.0 };
    // the common offset of unpaired rows: T*'s error (the nominal readings' mean) or
    // G-static's reference reading
    let offset = match (&experiment.reference, paired) {
        (_, true) => 0.0,
        (Some(_), false) => 1.0,
        (None, false) if nominal_readings > 0 => 1.0 / (nominal_readings as f64).sqrt(),
        (None, false) => 0.0,
    };
    let draws = Draws::new(&joints, rows, nominal_readings, experiment.kind as u64)?;
    let detected = |factor: f64| -> f64 {
        let found = (0..DRAWS)
            .filter(|&d| {
                let found: Vec<Option<Response>> = joints
                    .iter()
                    .enumerate()
                    .map(|(j, joint)| {
                        let joint = joint.as_ref()?;
                        let draw = &draws.joints[d][j];
                        let sigma = reading[j] * row.sqrt();
                        let coordinates: Vec<f64> = (0..joint.changes.len())
                            .map(|i| {
                                factor * joint.changes[i]
                                    + sigma * draw.coordinates[i]
                                    + reading[j] * offset * draw.offset * joint.ones[i]
                            })
                            .collect();
                        let explained: f64 = coordinates[..columns].iter().map(|c| c * c).sum();
                        let inside: f64 = coordinates.iter().map(|c| c * c).sum();
                        let sums = Sums {
                            explained,
                            total: inside + sigma * sigma * draw.outside,
                            columns,
                            dof: rows - columns,
                        };
                        let pass = draw
                            .pass
                            .map(|v| (v * reading[j] * reading[j] * row, nominal_readings - 1));
                        let known = samples[j] * samples[j] * row;
                        Some(test(sums, known, pass))
                    })
                    .collect();
                resolved(&found) == Some(true)
            })
            .count();
        found as f64 / DRAWS as f64
    };
    let at_plan = detected(1.0);
    let factor = if at_plan >= DETECTION {
        1.0
    } else {
        // double to a factor that detects, then halve the bracket (in log) 8 times: 0.3 %
        let (mut lo, mut hi) = (1.0f64, 2.0f64);
        while hi <= MAX_FACTOR && detected(hi) < DETECTION {
            (lo, hi) = (hi, 2.0 * hi);
        }
        if hi > MAX_FACTOR {
            f64::INFINITY
        } else {
            for _ in 0..8 {
                let mid = (lo * hi).sqrt();
                if detected(mid) >= DETECTION {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            hi
        }
    };
    Ok(Some(Prediction {
        detected: at_plan,
        factor,
        relative_error: relative_error(deltas, &changes, &reading),
        reading,
    }))
}

/// The planner's check that the noise from pass to pass (`torque_pass_noise`, one per joint,
/// already checked in range) is given only for joints whose samples' noise (`torque_noise`) is:
/// the prediction reads the one against the other, as the identification does.
pub(super) fn check_pass_noise(
    model: &Model,
    noise: &Option<Vec<f64>>,
    passes: &Option<Vec<f64>>,
) -> Result<()> {
    let Some(passes) = passes else { return Ok(()) };
    let samples = noise.as_deref().unwrap_or_default();
    let unknown = |j: usize| samples.get(j).is_none_or(|s| *s == 0.0);
    match (0..passes.len()).find(|&j| passes[j] > 0.0 && unknown(j)) {
        Some(j) => Err(crate::error::Error::invalid(
            format!("torque_pass_noise[{j}]"),
            format!(
                "{} for joint '{}', whose torque_noise is not given: the prediction reads the \
                 noise from pass to pass against the samples' noise; give both",
                shown(passes[j]),
                model.joint_names.get(j).map_or("?", String::as_str)
            ),
        )),
        None => Ok(()),
    }
}

/// One joint's rows in an orthonormal basis of the span of the perturbations (first, as
/// [`design_basis`] gives it), its model's changes and the rows' common offset: the noise of
/// the rows is Gaussian coordinates there and, outside, a chi-square of the rows' remaining
/// degrees of freedom. The test needs nothing else, so a draw costs the same for 12 rows as
/// for 100,000.
struct Reduced {
    /// The model's changes' coordinates (`columns` of the design, then up to two more).
    changes: Vec<f64>,
    /// The coordinates of a row-wise constant 1 (the common offset).
    ones: Vec<f64>,
}

impl Reduced {
    fn new(q: &DMatrix<f64>, changes: &DVector<f64>) -> Self {
        let rows = q.nrows();
        let mut basis: Vec<DVector<f64>> = q.column_iter().map(|c| c.into_owned()).collect();
        for v in [changes.clone(), DVector::from_element(rows, 1.0)] {
            // Gram-Schmidt, twice for its rounding; a direction already spanned adds nothing
            let size = v.norm();
            let mut r = v;
            for _ in 0..2 {
                for b in &basis {
                    r -= b * b.dot(&r);
                }
            }
            let left = r.norm();
            if left > 1e-9 * size && left.is_finite() {
                basis.push(r / left);
            }
        }
        let ones = DVector::from_element(rows, 1.0);
        Self {
            changes: basis.iter().map(|b| b.dot(changes)).collect(),
            ones: basis.iter().map(|b| b.dot(&ones)).collect(),
        }
    }
}

/// One draw of the noise for one joint, in units of its rows' standard deviation.
struct Draw {
    /// Gaussian coordinates in the joint's [`Reduced`] basis.
    coordinates: Vec<f64>,
    /// A chi-square of the rows' degrees of freedom outside that basis.
    outside: f64,
    /// The common offset's standard Gaussian.
    offset: f64,
    /// The nominal readings' variance over a reading's (a chi-square over its degrees of
    /// freedom), None with fewer than two.
    pass: Option<f64>,
}

/// [`DRAWS`] seeded draws for each joint, kept so that every factor tried meets the same noise.
struct Draws {
    joints: Vec<Vec<Draw>>,
}

impl Draws {
    fn new(joints: &[Option<Reduced>], rows: usize, nominal: usize, seed: u64) -> Result<Self> {
        use rand_distr::ChiSquared;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let chi = |dof: usize| ChiSquared::new(dof.max(1) as f64).ok();
        let joints = (0..DRAWS)
            .map(|_| {
                joints
                    .iter()
                    .map(|joint| {
                        let m = joint.as_ref().map_or(0, |r| r.changes.len());
                        let mut gauss = || StandardNormal.sample(&mut rng);
                        let coordinates: Vec<f64> = (0..m).map(|_| gauss()).collect();
                        let offset = gauss();
                        let outside = match (rows > m).then(|| chi(rows - m)).flatten() {
                            Some(c) => c.sample(&mut rng),
                            None => 0.0,
                        };
                        let pass = (nominal >= 2)
                            .then(|| chi(nominal - 1))
                            .flatten()
                            .map(|c| c.sample(&mut rng) / (nominal - 1) as f64);
                        Draw {
                            coordinates,
                            outside,
                            offset,
                            pass,
                        }
                    })
                    .collect()
            })
            .collect();
        crate::interrupt::check("the planner's prediction")?;
        Ok(Self { joints })
    }
}

/// The model's torque change at each crossing (K x N, N m or N): `tau(crossing) - tau(op)`,
/// G-static's `g(q* + dq) - g(q*)` against its reference at rest.
fn torque_changes(
    model: &Model,
    op: &OperatingPoint,
    experiment: &Experiment,
) -> Result<DMatrix<f64>> {
    let mut data = Data::new(model);
    let mut tau = |c: &Crossing| -> Result<Vec<f64>> {
        crate::rnea(model, &mut data, &c.q, &c.qd, &c.qdd, Gravity::Included)?;
        Ok(data.tau.as_slice().to_vec())
    };
    let base = match &experiment.reference {
        Some(reference) => tau(reference)?,
        None => tau(&Crossing {
            time: 0.0,
            q: op.q.clone(),
            qd: op.qd.clone(),
            qdd: op.qdd.clone(),
        })?,
    };
    let rows = experiment
        .crossings
        .iter()
        .map(&mut tau)
        .collect::<Result<Vec<_>>>()?;
    Ok(DMatrix::from_fn(rows.len(), model.nv, |i, j| {
        rows[i][j] - base[j]
    }))
}

/// The estimate's standard errors over its size: `sqrt(sum sigma_j^2 diag((X^T X)^-1)) /
/// ||B||` with `B` the least-squares fit of the model's changes `y` on `x` and `sigma_j` each
/// joint's reading noise. Infinite when `B` is zero or `x` is singular.
fn relative_error(x: &DMatrix<f64>, y: &DMatrix<f64>, reading: &[f64]) -> f64 {
    let Some(inverse) = (x.transpose() * x).try_inverse() else {
        return f64::INFINITY;
    };
    let b = &inverse * x.transpose() * y;
    let trace: f64 = inverse.diagonal().iter().sum();
    let variance: f64 = reading.iter().map(|r| r * r * trace).sum();
    let size = b.norm();
    let ratio = variance.sqrt() / size;
    if ratio.is_finite() {
        ratio
    } else {
        f64::INFINITY
    }
}

/// The planner's warning for an experiment predicted to pass the identification's response
/// test in fewer than [`DETECTION`] of runs, or None; `noise` and `passes` as [`predict`] was
/// given them.
pub fn warning(
    kind: ExperimentKind,
    prediction: &Prediction,
    noise: &[f64],
    passes: &[f64],
) -> Option<String> {
    if prediction.detected >= DETECTION {
        return None;
    }
    let variable = kind.perturbation_name();
    let estimate = kind.estimate_name();
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |a, s| a.max(*s));
    let largest_noise = largest(noise);
    let from_pass_to_pass = match largest(passes) {
        p if p > 0.0 => format!(
            " and readings varying by up to {} N m from pass to pass",
            shown(p)
        ),
        _ => String::new(),
    };
    let largest_reading = prediction.reading.iter().fold(0.0f64, |a, s| a.max(*s));
    let precision = if prediction.relative_error.is_finite() {
        format!(
            "{estimate} would err by about {} % of its size",
            three_digits(100.0 * prediction.relative_error)
        )
    } else {
        format!("the model's {estimate} is zero here")
    };
    let friction = if kind == ExperimentKind::H {
        " (the model has no friction: a real joint's viscous friction adds to H* and may respond where the model does not)"
    } else {
        ""
    };
    let advice = if prediction.factor.is_finite() {
        format!(
            "perturbations ({variable}) about {} times larger, or {} times as many crossings, would be found in {:.0} % of runs",
            shown_factor(prediction.factor),
            shown_factor(prediction.factor * prediction.factor),
            100.0 * DETECTION
        )
    } else {
        format!(
            "the model's torques barely change with these perturbations ({variable}): not even perturbations {} times larger would resolve {estimate}",
            shown_factor(MAX_FACTOR)
        )
    };
    Some(format!(
        "experiment '{}': with torque samples of up to {} N m (standard deviation){from_pass_to_pass}, read over each crossing's window to {} N m a crossing, the robot's model predicts that the identification finds its torques responding to the perturbations in only {:.0} % of runs, and {precision}{friction}: {advice}",
        kind.name(),
        shown(largest_noise),
        three_digits(largest_reading),
        100.0 * prediction.detected
    ))
}

/// A computed value to three significant digits (exponent form outside 1e-3 to 1e4).
fn three_digits(v: f64) -> String {
    let a = v.abs();
    if (1e-3..1e4).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::local::crossing::torque_reading_gain;
    use crate::local::reversals::narrowed_window;
    use crate::local::{plan_experiments, PlanOptions};

    /// The centre's standard error of a least-squares quadratic over `2m + 1` evenly spaced
    /// samples, in closed form: `S4 / (S0 S4 - S2^2)` with `S_k = sum t^k`.
    fn quadratic_centre(m: i64) -> f64 {
        let s = |k: i32| (-m..=m).map(|i| (i as f64).powi(k)).sum::<f64>();
        (s(4) / (s(0) * s(4) - s(2) * s(2))).sqrt()
    }

    #[test]
    fn the_reading_gain_is_the_fits_standard_error_at_the_centre() {
        let quadratic = FitOptions {
            torque_degree: 2,
            ..FitOptions::default()
        };
        // 0.05 s at 1 kHz: 50 samples each side
        let g = torque_reading_gain(0.05, 1000.0, &quadratic)
            .unwrap()
            .unwrap();
        assert!((g / quadratic_centre(50) - 1.0).abs() < 1e-10, "{g}");
        // past GAIN_SAMPLES it is scaled: within 1e-3 of the closed form
        let g = torque_reading_gain(5.0, 1000.0, &quadratic)
            .unwrap()
            .unwrap();
        assert!((g / quadratic_centre(5000) - 1.0).abs() < 1e-3, "{g}");
        // degree 6 (the default): about sqrt(4.8 / n), as FitOptions documents
        let g = torque_reading_gain(0.05, 1000.0, &FitOptions::default())
            .unwrap()
            .unwrap();
        assert!((g * g * 101.0 / 4.8 - 1.0).abs() < 0.05, "{g}");
        // too few samples for the fit: no reading to predict
        assert_eq!(
            torque_reading_gain(0.003, 1000.0, &FitOptions::default()).unwrap(),
            None
        );
    }

    fn a465_plan(
        noise: Option<Vec<f64>>,
        fraction: f64,
    ) -> (Model, OperatingPoint, crate::local::Plan) {
        let model = crate::robots::a465::model("kinsheel2010").unwrap();
        use crate::robots::a465::{TABLE2_Q, TABLE2_QD, TABLE2_QDD};
        let op = OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec())
            .unwrap();
        let mut options = PlanOptions {
            torque_noise: noise,
            ..PlanOptions::default()
        };
        options.sizes.position = crate::local::Size::Fraction(fraction);
        options.sizes.velocity = crate::local::Size::Fraction(fraction);
        options.sizes.acceleration = crate::local::Size::Fraction(fraction);
        let plan = plan_experiments(&model, &op, &options).unwrap();
        (model, op, plan)
    }

    fn predicted(noise: f64, fraction: f64) -> Vec<String> {
        a465_plan(Some(vec![noise; 6]), fraction)
            .2
            .warnings
            .into_iter()
            .filter(|w| w.contains("the robot's model predicts"))
            .collect()
    }

    #[test]
    fn experiments_lost_in_the_noise_are_predicted_and_others_not() {
        // a sensor of 1e-6 N m resolves every experiment at the paper's sizes
        assert_eq!(predicted(1e-6, 0.01), Vec::<String>::new());
        // perturbations of 1e-7 of the limits under 0.05 N m: none is resolved
        let lost = predicted(0.05, 1e-7);
        for (kind, estimate) in [("G_static", "Gs"), ("G", "G*"), ("H", "H*"), ("D", "D*")] {
            let w = lost
                .iter()
                .find(|w| w.starts_with(&format!("experiment '{kind}': with torque samples")))
                .unwrap_or_else(|| panic!("{kind}: {lost:#?}"));
            assert!(w.contains(&format!("{estimate} would err by about")), "{w}");
            assert!(w.contains("times larger, or"), "{w}");
        }
        // noise alone passes for a response about FALSE_ALARM of the time
        for w in &lost {
            let rate = w.split("in only ").nth(1).and_then(|r| r.split(' ').next());
            let rate: f64 = rate.unwrap().parse().unwrap();
            assert!(rate <= 5.0, "{w}");
        }
    }

    #[test]
    fn the_factor_resolves_what_the_plan_does_not() {
        let (model, op, plan) = a465_plan(None, 1e-6);
        let noise = vec![0.05; 6];
        let d = plan.experiment(ExperimentKind::D).unwrap();
        let p = predict(&model, &op, d, &noise, &[], plan.rate, 12)
            .unwrap()
            .unwrap();
        assert!(p.detected < 0.05, "{p:?}");
        assert!(p.factor.is_finite() && p.factor > 10.0, "{p:?}");
        // the changes are linear in small perturbations: the same design scaled by the factor
        // (and 1 % more, past the bisection's step) is found in at least DETECTION of the runs
        let mut scaled = d.clone();
        let grow = p.factor * 1.01;
        scaled.deltas *= grow;
        for c in &mut scaled.crossings {
            for j in 0..6 {
                c.qdd[j] = op.qdd[j] + grow * (c.qdd[j] - op.qdd[j]);
            }
        }
        let q = predict(&model, &op, &scaled, &noise, &[], plan.rate, 12)
            .unwrap()
            .unwrap();
        assert!(q.detected >= DETECTION && q.factor == 1.0, "{q:?}");
        // the relative error falls as the perturbations grow
        assert!(
            (p.relative_error / q.relative_error / grow - 1.0).abs() < 1e-3,
            "{p:?} {q:?}"
        );
        // no joint's noise known, or the nominal experiment: nothing to predict
        assert_eq!(
            predict(&model, &op, d, &[0.0; 6], &[], plan.rate, 12).unwrap(),
            None
        );
        let nominal = plan.experiment(ExperimentKind::Nominal).unwrap();
        assert_eq!(
            predict(&model, &op, nominal, &noise, &[], plan.rate, 12).unwrap(),
            None
        );
    }

    /// The identification's test itself ([`super::super::response::responses`]) on whole rows of
    /// noise: each draw the nominal readings (T* their mean, their scatter the noise from pass
    /// to pass), G-static's reference and the experiment's readings, `draws` times; every
    /// reading errs by the samples' noise through its own window's fit (narrowed before a
    /// velocity reversal as the identification narrows it, and weighted so) and by `passes`
    /// (N m a reading).
    fn whole_rows(
        model: &Model,
        op: &OperatingPoint,
        experiment: &Experiment,
        (noise, passes): (&[f64], &[f64]),
        nominal_readings: usize,
        draws: usize,
    ) -> f64 {
        use crate::local::response::{responses, PassNoise};
        let n = model.nv;
        let options = FitOptions::default();
        let gain = |h: f64| torque_reading_gain(h, 1000.0, &options).unwrap().unwrap();
        let full = gain(experiment.window);
        let min_half = 0.5 * crate::local::crossing::samples_needed(&options) as f64 / 1000.0;
        let crossing_gain = |i: usize, j: usize| {
            let c = &experiment.crossings[i];
            let w = narrowed_window(
                &experiment.trajectory,
                j,
                c.time,
                experiment.window,
                min_half,
            );
            w.and_then(|w| w.1).map_or(full, gain)
        };
        let reading: Vec<f64> = noise
            .iter()
            .zip(passes)
            .map(|(s, p)| (s * full).hypot(*p))
            .collect();
        let k = experiment.deltas.nrows();
        let gains = DMatrix::from_fn(k, n, crossing_gain);
        let u = DMatrix::from_fn(k, n, |i, j| (noise[j] * gains[(i, j)]).powi(2));
        let row_reading = DMatrix::from_fn(k, n, |i, j| u[(i, j)].sqrt().hypot(passes[j]));
        let changes = torque_changes(model, op, experiment).unwrap();
        let x = &experiment.deltas;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
        let mut gauss = || <StandardNormal as Distribution<f64>>::sample(&StandardNormal, &mut rng);
        let found = (0..draws)
            .filter(|_| {
                let nominal: Vec<Vec<f64>> = (0..nominal_readings)
                    .map(|_| reading.iter().map(|r| r * gauss()).collect())
                    .collect();
                let passes = PassNoise::of(nominal.iter().map(Vec::as_slice));
                let base: Vec<f64> = match &experiment.reference {
                    Some(_) => reading.iter().map(|r| r * gauss()).collect(),
                    None => (0..n)
                        .map(|j| nominal.iter().map(|r| r[j]).sum::<f64>() / nominal.len() as f64)
                        .collect(),
                };
                let y = DMatrix::from_fn(k, n, |i, j| {
                    changes[(i, j)] + row_reading[(i, j)] * gauss() - base[j]
                });
                let found = responses(
                    x,
                    &y,
                    &u,
                    experiment.in_pairs(),
                    &[true; 6],
                    passes.as_ref(),
                );
                resolved(&found) == Some(true)
            })
            .count();
        found as f64 / draws as f64
    }

    /// `experiment` with its perturbations scaled by `factor` (D's torques are linear in them,
    /// G-static's nearly so at small sizes).
    fn scaled(op: &OperatingPoint, experiment: &Experiment, factor: f64) -> Experiment {
        let mut e = experiment.clone();
        e.deltas *= factor;
        for c in &mut e.crossings {
            let (moved, held) = match e.kind {
                ExperimentKind::D => (&mut c.qdd, &op.qdd),
                _ => (&mut c.q, &op.q),
            };
            for (a, h) in moved.iter_mut().zip(held) {
                *a = h + factor * (*a - h);
            }
        }
        e
    }

    /// The reduced draws stand for whole rows of noise: their detection agrees with the test
    /// run on whole rows (2,000 draws) within 0.1 (the two draws' standard deviations combine
    /// to 0.04 at one half), paired and unpaired (where T*'s error is common to the rows),
    /// from rare to sure detection, with and without the nominal passes, with and without
    /// noise from pass to pass (twice the samples' through the fit, which the nominal passes
    /// show the test when the regression has no residual, and less than that, which they may
    /// not).
    #[test]
    fn reduced_draws_detect_as_the_test_on_whole_rows() {
        let model = crate::robots::a465::model("kinsheel2010").unwrap();
        use crate::robots::a465::{TABLE2_Q, TABLE2_QD, TABLE2_QDD};
        let op = OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec())
            .unwrap();
        let noise = vec![0.05; 6];
        // the reading's noise from the samples at the default window: 0.05 sqrt(4.8 / 101)
        let pass_levels = [vec![0.0; 6], vec![0.022; 6], vec![0.005; 6]];
        for (symmetric, count, passes) in [
            (true, None, &pass_levels[0]),
            (false, None, &pass_levels[0]),
            (true, Some(24), &pass_levels[0]),
            (false, Some(9), &pass_levels[0]),
            (true, None, &pass_levels[1]),
            (false, Some(9), &pass_levels[1]),
            (true, None, &pass_levels[2]),
        ] {
            let mut options = PlanOptions {
                symmetric,
                count,
                ..PlanOptions::default()
            };
            options.sizes.acceleration = crate::local::Size::Fraction(1e-6);
            options.sizes.position = crate::local::Size::Fraction(1e-6);
            let plan = plan_experiments(&model, &op, &options).unwrap();
            let nominal = plan
                .experiment(ExperimentKind::Nominal)
                .unwrap()
                .crossings
                .len();
            // D, and G-static whose rows share its reference reading unless paired
            for kind in [ExperimentKind::D, ExperimentKind::GStatic] {
                let planned = plan.experiment(kind).unwrap();
                let p = predict(&model, &op, planned, &noise, passes, plan.rate, nominal)
                    .unwrap()
                    .unwrap();
                for f in [0.3, 0.6, 1.0, 1.5] {
                    let e = scaled(&op, planned, f * p.factor);
                    let reduced = predict(&model, &op, &e, &noise, passes, plan.rate, nominal)
                        .unwrap()
                        .unwrap()
                        .detected;
                    let whole = whole_rows(&model, &op, &e, (&noise, passes), nominal, 2000);
                    assert!(
                        (reduced - whole).abs() <= 0.1,
                        "{} symmetric {symmetric}, count {count:?}, passes {}, {f} x the factor: reduced {reduced}, whole rows {whole}",
                        kind.name(),
                        passes[0]
                    );
                }
            }
        }
        // at the default sizes D's accelerations reverse the slow wrist joints near most
        // crossings, whose torques are read over narrowed windows (up to 2.5 times the noise):
        // the prediction takes their mean square, the whole rows each crossing's own
        let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
        let d = plan.experiment(ExperimentKind::D).unwrap();
        let gains = reading_gains(d, plan.rate, &FitOptions::default())
            .unwrap()
            .unwrap();
        let full = torque_reading_gain(d.window, plan.rate, &FitOptions::default())
            .unwrap()
            .unwrap();
        assert!(
            gains[4] > 1.3 * full && gains[0] == full,
            "{gains:?} {full}"
        );
        let p = predict(&model, &op, d, &noise, &[], plan.rate, 12)
            .unwrap()
            .unwrap();
        for f in [0.3, 0.6, 1.0, 1.5] {
            let e = scaled(&op, d, f * p.factor);
            let reduced = predict(&model, &op, &e, &noise, &[], plan.rate, 12)
                .unwrap()
                .unwrap()
                .detected;
            let whole = whole_rows(&model, &op, &e, (&noise, &[0.0; 6]), 12, 2000);
            assert!(
                (reduced - whole).abs() <= 0.1,
                "default sizes, {f} x the factor: reduced {reduced}, whole rows {whole}"
            );
        }
    }

    /// 100,000 perturbations (the most a plan takes) cost the prediction's draws no more than
    /// 12 do: the rows are reduced once (the whole rows would be 200 draws of 4.8 MB each).
    #[test]
    fn the_prediction_of_many_perturbations_is_bounded() {
        let (model, op, plan) = a465_plan(None, 1e-6);
        let d = plan.experiment(ExperimentKind::D).unwrap();
        let k = crate::limits::MAX_PERTURBATIONS;
        let rows = d.deltas.nrows();
        let mut big = d.clone();
        big.deltas = DMatrix::from_fn(k, 6, |i, j| d.deltas[(i % rows, j)]);
        big.crossings = (0..k).map(|i| d.crossings[i % rows].clone()).collect();
        let noise = vec![0.05; 6];
        let few = predict(&model, &op, d, &noise, &[], plan.rate, 12)
            .unwrap()
            .unwrap();
        let many = predict(&model, &op, &big, &noise, &[], plan.rate, 12)
            .unwrap()
            .unwrap();
        // the factor needed falls as the square root of the crossings
        let expected = few.factor / (k as f64 / rows as f64).sqrt();
        assert!(
            (many.factor / expected - 1.0).abs() < 0.15,
            "{few:?} {many:?}"
        );
        assert!(many.detected > few.detected, "{few:?} {many:?}");
    }

    #[test]
    fn computed_values_are_shown_to_three_digits() {
        assert_eq!(three_digits(0.010888030388456475), "0.0109");
        assert_eq!(three_digits(1.0888030388456476), "1.09");
        assert_eq!(three_digits(123.456), "123");
        assert_eq!(three_digits(1.5e-5), "1.50e-5");
    }
}
