//! The noise weighting and a fit's residuals judged against the noise measured apart
//! (src/direct/noise_fit.rs, src/direct/torque_noise.rs; docs/method.md, section 8f): the
//! standard errors against the spread of estimates over many noise draws, the cost against
//! its chi-square or F distribution, on white noise and on logs averaged over their periods.

mod common;

use common::{a465_excitation, normal, torques_with_friction, Rng};
use perturbid_rs::direct::{
    identify_base_parameters, BaseModel, BaseOptions, FrictionTerms, TorqueNoise, Weighting,
};
use perturbid_rs::logs::period_average::PeriodOptions;
use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
use perturbid_rs::robots::a465;
use perturbid_rs::trajectory::{FourierTrajectory, Samples};
use perturbid_rs::{Document, Error, Recording, States};

/// A different noise level on each joint (N m), so that the weighting matters.
const SIGMA: [f64; 6] = [0.05, 0.2, 0.1, 0.02, 0.03, 0.01];

fn viscous_and_coulomb(weighting: Weighting, noise: Option<TorqueNoise>) -> BaseOptions {
    BaseOptions {
        friction: FrictionTerms {
            viscous: true,
            coulomb: true,
            ..FrictionTerms::NONE
        },
        weighting,
        noise,
        ..BaseOptions::default()
    }
}

/// The excitation sampled at `rate` for `seconds`, its torques with friction, and Gaussian
/// noise of [`SIGMA`] a joint added to them (seeded by `seed`).
fn noisy(traj: &FourierTrajectory, rate: f64, seconds: f64, seed: u64) -> (Samples, Vec<f64>) {
    coloured(traj, rate, seconds, seed, 0.0)
}

/// [`noisy`] with the noise of each joint low-pass filtered, `e_i = a e_(i-1) + sqrt(1 - a^2)
/// w_i` (`a` 0: white), its level kept.
fn coloured(
    traj: &FourierTrajectory,
    rate: f64,
    seconds: f64,
    seed: u64,
    a: f64,
) -> (Samples, Vec<f64>) {
    let model = a465::model("kinsheel2010").unwrap();
    let t: Vec<f64> = (0..(seconds * rate).round() as usize)
        .map(|i| i as f64 / rate)
        .collect();
    let s = traj.sample(&t);
    let mut tau = torques_with_friction(&model, &s, &mut Rng(0), |_| 0.0);
    let mut rng = Rng(seed);
    let mut e = [0.0; 6];
    for (i, x) in tau.iter_mut().enumerate() {
        let j = i % 6;
        e[j] = a * e[j] + (1.0 - a * a).sqrt() * normal(&mut rng);
        *x += SIGMA[j] * e[j];
    }
    (s, tau)
}

/// Over the draws, each parameter's spread of estimates over the mean standard error the
/// fits gave it: the median over the parameters, and the largest.
fn spread_over_stderr(fits: &[BaseModel]) -> (f64, f64) {
    let n = fits.len() as f64;
    let mut ratios: Vec<f64> = (0..fits[0].theta.len())
        .map(|i| {
            let mean = fits.iter().map(|f| f.theta[i]).sum::<f64>() / n;
            let var = fits
                .iter()
                .map(|f| (f.theta[i] - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            let se = fits.iter().map(|f| f.stderr[i]).sum::<f64>() / n;
            var.sqrt() / se
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    (ratios[ratios.len() / 2], ratios[ratios.len() - 1])
}

/// The A465, the test excitation at 100 Hz over 10 s and its torques with [`SIGMA`]'s noise
/// (seeded by `seed`).
fn one_log(seed: u64) -> (perturbid_rs::Model, Samples, Vec<f64>) {
    let model = a465::model("kinsheel2010").unwrap();
    let traj = a465_excitation(&mut Rng(21));
    let (s, tau) = noisy(&traj, 100.0, 10.0, seed);
    (model, s, tau)
}

fn reduced_cost(f: &BaseModel) -> f64 {
    let n = f.noise_fit.as_ref().unwrap();
    n.cost / n.degrees_of_freedom
}

/// White noise of known levels: the fit weighted by them has standard errors that match the
/// spread of its estimates over 40 draws, a cost whose mean over the draws is its degrees of
/// freedom, and no finding; a third of the noise's level is found beyond the noise, three
/// times it below.
#[test]
fn with_the_noise_known_the_standard_errors_are_the_spread_of_the_estimates() {
    let model = a465::model("kinsheel2010").unwrap();
    let traj = a465_excitation(&mut Rng(21));
    let noise = TorqueNoise::white(SIGMA.to_vec());
    let options = viscous_and_coulomb(Weighting::Noise, Some(noise.clone()));
    let fits: Vec<BaseModel> = (0..40)
        .map(|d| {
            let (s, tau) = noisy(&traj, 100.0, 10.0, 100 + d);
            let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
            identify_base_parameters(&model, &states, &tau, &options).unwrap()
        })
        .collect();
    let (median, largest) = spread_over_stderr(&fits);
    assert!(
        (0.85..1.15).contains(&median),
        "median spread over stderr {median}"
    );
    assert!(largest < 1.5, "largest spread over stderr {largest}");
    let f = &fits[0];
    assert_eq!(f.sigma, SIGMA.to_vec());
    let dof = f.noise_fit.as_ref().unwrap().degrees_of_freedom;
    assert_eq!(dof, (1000 * 6 - f.theta.len()) as f64);
    // the cost's mean over the draws: its degrees of freedom, within 4 standard errors
    let mean = fits.iter().map(reduced_cost).sum::<f64>() / 40.0;
    assert!(
        (mean - 1.0).abs() < 4.0 * (2.0 / dof / 40.0).sqrt(),
        "{mean}"
    );
    let alarms = fits
        .iter()
        .filter(|f| f.noise_fit.as_ref().unwrap().p_value < 0.01)
        .count();
    assert!(alarms <= 3, "{alarms} of 40 draws below p = 0.01");
    assert!(fits
        .iter()
        .all(|f| !f.warnings().iter().any(|w| w.contains("noise"))));

    // the noise stated wrong is found, either way
    let (s, tau) = noisy(&traj, 100.0, 10.0, 7);
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    for (scale, said) in [
        (1.0 / 3.0, "exceed the torques' noise"),
        (3.0, "below the torques' noise"),
    ] {
        let stated = TorqueNoise::white(SIGMA.iter().map(|s| s * scale).collect());
        let f = identify_base_parameters(
            &model,
            &states,
            &tau,
            &viscous_and_coulomb(Weighting::Noise, Some(stated)),
        )
        .unwrap();
        assert!(
            f.warnings().iter().any(|w| w.contains(said)),
            "{:?}",
            f.warnings()
        );
        // beyond the noise the standard errors are scaled up to the residuals; below it the
        // noise's stand, too large by its scale
        let ls = identify_base_parameters(&model, &states, &tau, &options).unwrap();
        let ratio = f.stderr[0] / ls.stderr[0];
        let expected = scale * (reduced_cost(&f)).max(1.0).sqrt();
        assert!(
            (ratio / expected - 1.0).abs() < 0.05,
            "{ratio} against {expected}"
        );
    }
}

/// A model without the friction the robot has leaves residuals beyond the noise: found with
/// every weighting, its own error named a joint, and its standard errors scaled up to its
/// residuals' (within 10 % of the residual-weighted fit's).
#[test]
fn a_model_error_is_found_beyond_the_noise() {
    let (model, s, tau) = one_log(3);
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let noise = TorqueNoise::white(SIGMA.to_vec());
    for weighting in [Weighting::Noise, Weighting::Wls, Weighting::Ols] {
        let options = BaseOptions {
            friction: FrictionTerms::NONE,
            ..viscous_and_coulomb(weighting, Some(noise.clone()))
        };
        let f = identify_base_parameters(&model, &states, &tau, &options).unwrap();
        let n = f.noise_fit.as_ref().unwrap();
        assert!(
            n.p_value < 1e-10 && reduced_cost(&f) > 10.0,
            "{weighting:?}: {n:?}"
        );
        assert!(
            n.model_error.iter().all(|e| *e > 0.1),
            "{:?}",
            n.model_error
        );
        let w = f.warnings().join("\n");
        assert!(
            w.contains("exceed the torques' noise") && w.contains("joint3 "),
            "{w}"
        );
    }
}

/// The noise weighting without a noise, with one of another length or a zero level, and
/// with too few samples for its correlation, is refused by name; drive gains refuse it.
#[test]
fn a_noise_that_cannot_weight_is_refused() {
    let (model, s, tau) = one_log(3);
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let fails = |noise: Option<TorqueNoise>, said: &str| {
        let options = viscous_and_coulomb(Weighting::Noise, noise);
        match identify_base_parameters(&model, &states, &tau, &options) {
            Err(Error::InvalidArgument { message, .. }) => {
                assert!(message.contains(said), "{message}")
            }
            other => panic!(
                "expected a refusal saying '{said}', got {:?}",
                other.map(|f| f.theta)
            ),
        }
    };
    fails(None, "needs the torques' noise");
    fails(
        Some(TorqueNoise::white(vec![0.1; 5])),
        "5 noise levels, expected one a joint (6)",
    );
    let mut zero = SIGMA.to_vec();
    zero[2] = 0.0;
    fails(
        Some(TorqueNoise::white(zero)),
        "joint 'joint3': a noise level of 0",
    );
    fails(
        Some(TorqueNoise {
            correlation: 0.5,
            ..TorqueNoise::white(SIGMA.to_vec())
        }),
        "a correlation of 0.5 samples",
    );
    fails(
        Some(TorqueNoise {
            correlation: 500.0,
            ..TorqueNoise::white(SIGMA.to_vec())
        }),
        "12 independent values",
    );
    // residuals of 1e202 noise levels: a cost past f64's range is no judgement
    fails(
        Some(TorqueNoise::white(vec![1e-200; 6])),
        "the residuals are too large against the noise",
    );
    // drive gains: their torques are the gains times a signal, whose noise is not known first
    let logs = common::gain_logs::logs(1e-3, true);
    let options = viscous_and_coulomb(Weighting::Noise, Some(TorqueNoise::white(SIGMA.to_vec())));
    match perturbid_rs::direct::identify_drive_gains(&logs.truth, &logs.runs(), &options) {
        Err(Error::InvalidArgument { message, .. }) => {
            assert!(message.contains("not taken with drive gains"), "{message}")
        }
        other => panic!("expected a refusal, got {:?}", other.map(|f| f.model.theta)),
    }
}

/// 24 logs of 4 periods of the excitation at 200 Hz with noise filtered by `a` ([`coloured`]),
/// each averaged and fitted with the noise weighting by the noise its periods measured (the
/// fit keeping the average's findings).
fn averaged_fits(a: f64) -> Vec<BaseModel> {
    let model = a465::model("kinsheel2010").unwrap();
    let traj = a465_excitation(&mut Rng(21));
    let options = PreprocessOptions {
        rate: 200.0,
        decimate: 1,
        periods: Some(PeriodOptions::new(10.0, 5)),
        ..PreprocessOptions::default()
    };
    (0..24)
        .map(|d| {
            let (s, tau) = coloured(&traj, 200.0, 40.0, 500 + d, a);
            let rec = Recording::new("log", 6, s.t, s.q, tau, None, None).unwrap();
            let out = preprocess(&rec, &options).unwrap();
            let avg = out.period_average.as_ref().unwrap();
            assert_eq!(
                (avg.samples, avg.kept_samples, avg.torque_harmonics),
                (2000, 2000, 100)
            );
            let noise =
                perturbid_rs::direct::TorqueNoise::from_period_average(avg, &model.joint_names)
                    .unwrap();
            assert!((noise.correlation - 2000.0 / 201.0).abs() < 1e-12);
            assert_eq!(noise.degrees_of_freedom, Some(3.0 * 201.0 * 6.0));
            // white: the levels measured are the noise put in, the band's share of it, over
            // sqrt(4)
            for (j, x) in noise.sigma.iter().enumerate().filter(|_| a == 0.0) {
                let expected = SIGMA[j] * (201.0f64 / 2000.0).sqrt() / 2.0;
                assert!(
                    (x / expected - 1.0).abs() < 0.2,
                    "joint {j}: {x} against {expected}"
                );
            }
            let options = viscous_and_coulomb(Weighting::Noise, Some(noise));
            identify_base_parameters(&model, &out.states().unwrap(), &out.tau, &options)
                .unwrap()
                .with_findings_of(&out)
        })
        .collect()
}

/// Logs of 4 periods with white noise, averaged: the noise the periods measured weights the
/// fit, and its band-limited correlation (the noise lies in the torques' 201 harmonics' span
/// of the period's 2,000 samples) gives standard errors that match the spread of the
/// estimates over 24 logs, and a cost whose mean is its degrees of freedom (`6 x 201 - p`).
#[test]
fn an_averaged_log_weights_by_the_noise_its_periods_measured() {
    let fits = averaged_fits(0.0);
    let dof = fits[0].noise_fit.as_ref().unwrap().degrees_of_freedom;
    assert!(
        (dof - (6.0 * 201.0 - fits[0].theta.len() as f64)).abs() < 1e-9,
        "{dof}"
    );
    let (median, largest) = spread_over_stderr(&fits);
    assert!(
        (0.8..1.2).contains(&median),
        "median spread over stderr {median}"
    );
    assert!(largest < 1.6, "largest spread over stderr {largest}");
    // the cost over its degrees of freedom is F-distributed about 1 (the noise estimated
    // with 3 x 201 x 6 degrees of freedom): its mean over the logs within 4 standard errors
    let mean = fits.iter().map(reduced_cost).sum::<f64>() / 24.0;
    let spread = (2.0 / dof + 2.0 / 3618.0).sqrt() / 24f64.sqrt();
    assert!((mean - 1.0).abs() < 4.0 * spread, "{mean} +- {spread}");
    assert!(
        fits.iter()
            .filter(|f| f.noise_fit.as_ref().unwrap().p_value < 0.01)
            .count()
            <= 2
    );
    // white noise measures a tilt near 1, and is not said to be otherwise
    for f in &fits {
        let tilts = &f.log_period_average.as_ref().unwrap().torque_noise_tilt;
        assert!(
            tilts.iter().all(|t| (0.7..1.4).contains(&t.unwrap())),
            "{tilts:?}"
        );
        assert!(!f.warnings().iter().any(|w| w.contains("not white")));
    }
}

/// Noise that rises toward low frequencies (filtered to a corner near 1.6 Hz, in a band to
/// 10 Hz) holds fewer independent values than its band says: it is said not to be white,
/// naming every joint, and the standard errors take the residuals' longer correlation, so
/// that they still match the spread of the estimates (the band's alone left them short by
/// 1.8 times in the median, 2.3 at most).
#[test]
fn a_noise_that_is_not_white_is_said_and_its_correlation_taken_from_the_residuals() {
    let fits = averaged_fits(0.95);
    let (median, largest) = spread_over_stderr(&fits);
    assert!(
        (0.8..1.3).contains(&median),
        "median spread over stderr {median}"
    );
    assert!(largest < 1.8, "largest spread over stderr {largest}");
    let tilts = &fits[0]
        .log_period_average
        .as_ref()
        .unwrap()
        .torque_noise_tilt;
    assert!(tilts.iter().all(|t| t.unwrap() > 5.0), "{tilts:?}");
    let said = fits[0].warnings().join("\n");
    assert!(
        said.contains("is not white within their band") && said.contains("joint6 "),
        "{said}"
    );
}

/// A model of the noise weighting is saved with its noise's judgement and read back the same;
/// a document edited to drop it, or to weight by other levels than its noise's, is refused.
#[test]
fn the_noise_fit_is_kept_with_the_model_and_checked_on_load() {
    let (model, s, tau) = one_log(3);
    let states = States::new(6, &s.q, Some(&s.qd), Some(&s.qdd)).unwrap();
    let options = viscous_and_coulomb(Weighting::Noise, Some(TorqueNoise::white(SIGMA.to_vec())));
    let fit = identify_base_parameters(&model, &states, &tau, &options).unwrap();
    let text = fit.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), fit);
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["sigma"][1] = serde_json::json!(0.3);
    let edited = BaseModel::from_json(&doc.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        edited.contains("a sigma other than its noise's"),
        "{edited}"
    );
    doc.as_object_mut().unwrap().remove("noise_fit");
    let edited = BaseModel::from_json(&doc.to_string())
        .unwrap_err()
        .to_string();
    assert!(
        edited.contains("the noise weighting without its noise_fit"),
        "{edited}"
    );
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["noise_fit"]["p_value"] = serde_json::json!(1.5);
    let edited = BaseModel::from_json(&doc.to_string())
        .unwrap_err()
        .to_string();
    assert!(edited.contains("p in [0, 1]"), "{edited}");
}

/// Several logs' noise pooled: per joint the samples-weighted mean of the variances, the
/// independent values kept (`sum K / sum (K / c)`), the degrees of freedom summed (none where a
/// log's are known exactly); levels more than 1.5 times apart refused naming the joint and
/// logs; a log without a noise refused under the noise weighting in its name, and none
/// otherwise.
#[test]
fn several_logs_noise_is_pooled_or_refused() {
    let joints: Vec<String> = (1..=2).map(|j| format!("joint{j}")).collect();
    let a = TorqueNoise {
        sigma: vec![0.1, 0.2],
        correlation: 10.0,
        degrees_of_freedom: Some(600.0),
    };
    let b = TorqueNoise {
        sigma: vec![0.12, 0.16],
        correlation: 5.0,
        degrees_of_freedom: Some(400.0),
    };
    let p = TorqueNoise::pooled(&[("a.csv", &a, 1000), ("b.csv", &b, 3000)], &joints).unwrap();
    let expected = |x: f64, y: f64| ((1000.0 * x * x + 3000.0 * y * y) / 4000.0f64).sqrt();
    assert!((p.sigma[0] - expected(0.1, 0.12)).abs() < 1e-15);
    assert!((p.sigma[1] - expected(0.2, 0.16)).abs() < 1e-15);
    assert!((p.correlation - 4000.0 / (100.0 + 600.0)).abs() < 1e-12);
    assert_eq!(p.degrees_of_freedom, Some(1000.0));
    let known = TorqueNoise::white(vec![0.1, 0.2]);
    let q = TorqueNoise::pooled(&[("a.csv", &a, 1000), ("c.csv", &known, 10)], &joints).unwrap();
    assert_eq!(q.degrees_of_freedom, None);
    let far = TorqueNoise::white(vec![0.1, 0.5]);
    let e = TorqueNoise::pooled(&[("a.csv", &a, 1000), ("far.csv", &far, 10)], &joints)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint 'joint2' differs between the logs: 0.5 N m in far.csv, 0.2 N m in a.csv"),
        "{e}"
    );
    let none = || {
        Err(Error::InvalidArgument {
            argument: "noise".into(),
            message: "not averaged".into(),
        })
    };
    let logs = || {
        vec![
            ("a.csv".to_string(), Ok(a.clone()), 10),
            ("d.csv".to_string(), none(), 10),
        ]
    };
    let e = TorqueNoise::of_logs(logs(), &joints, true)
        .unwrap_err()
        .to_string();
    assert!(e.contains("d.csv: ") && e.contains("not averaged"), "{e}");
    assert_eq!(TorqueNoise::of_logs(logs(), &joints, false).unwrap(), None);
}

/// A payload's fit weighted by the noise known: its standard errors match the spread of its
/// estimates over 30 draws of noise of a different level on each joint (the mass and the
/// whole parameter vector), and its residuals are judged against that noise.
#[test]
fn a_payload_weighted_by_the_noise_has_the_standard_errors_of_its_spread() {
    use common::gain_logs::{carrying, motion, payload, states, truth};
    use perturbid_rs::direct::{identify_payload, PayloadOptions, Reference};
    let (truth, p) = (truth(), payload());
    let robot = carrying(&truth, Some(&p));
    let s = motion(4);
    let exact = torques_with_friction(&robot, &s, &mut Rng(0), |_| 0.0);
    let mut options = PayloadOptions::new("link6", &Reference::Urdf);
    options.weighting = Weighting::Noise;
    options.noise = Some(TorqueNoise::white(SIGMA.to_vec()));
    let fits: Vec<_> = (0..30)
        .map(|d| {
            let mut rng = Rng(900 + d);
            let tau: Vec<f64> = (exact.iter().enumerate())
                .map(|(i, t)| t + SIGMA[i % 6] * normal(&mut rng))
                .collect();
            identify_payload(&truth, Reference::Urdf, &states(&s), &tau, &options).unwrap()
        })
        .collect();
    let n = fits.len() as f64;
    let ratios: Vec<f64> = (0..fits[0].theta.len())
        .map(|i| {
            let mean = fits.iter().map(|f| f.theta[i]).sum::<f64>() / n;
            let var = fits
                .iter()
                .map(|f| (f.theta[i] - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            var.sqrt() / (fits.iter().map(|f| f.stderr[i]).sum::<f64>() / n)
        })
        .collect();
    let mut sorted = ratios.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    assert!(
        (0.85..1.15).contains(&median),
        "median spread over stderr {median}"
    );
    assert!(
        (0.6..1.5).contains(&ratios[0]),
        "the mass's spread over its stderr {}",
        ratios[0]
    );
    let f = &fits[0];
    assert_eq!(f.sigma, SIGMA.to_vec());
    let nf = f.noise_fit.as_ref().expect("judged against the noise");
    assert!(nf.p_value > 1e-3 && nf.p_value < 1.0 - 1e-3, "{nf:?}");
    // (with this noise the payload's small inertia is loosely determined, and said)
    assert!(
        !f.findings.iter().any(|w| w.contains("torques' noise")),
        "{:?}",
        f.findings
    );
}
