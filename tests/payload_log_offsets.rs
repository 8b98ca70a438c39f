//! A payload from several logs, each with a torque offset of its own (a sensor zeroed anew
//! between them; `PayloadOptions::offset_per_run`): the payload comes back exactly from
//! noise-free torques, each log's offset less their mean is found, the robot carrying the
//! payload is predicted at the logs' mean offset, and what the option cannot take is refused.

mod common;

use common::gain_logs::{carrying, motion, payload, truth};
use common::{torques_with_friction, Rng};
use perturbid_rs::direct::payload::parameters_of_payload;
use perturbid_rs::direct::{identify_payload, FrictionTerms, PayloadOptions, Reference};
use perturbid_rs::States;

const OFFSETS: [f64; 6] = [0.4, -0.2, 0.3, 0.1, -0.15, 0.05];

#[test]
fn each_logs_offset_is_fitted_beside_the_payload() {
    let (truth, p) = (truth(), payload());
    let robot = carrying(&truth, Some(&p));
    let (a, b) = (motion(4), motion(5));
    let tau_a = torques_with_friction(&robot, &a, &mut Rng(1), |_| 0.0);
    let mut tau_b = torques_with_friction(&robot, &b, &mut Rng(2), |_| 0.0);
    for (i, t) in tau_b.iter_mut().enumerate() {
        *t += OFFSETS[i % 6];
    }
    let join = |x: &[f64], y: &[f64]| [x, y].concat();
    let (q, qd, qdd) = (join(&a.q, &b.q), join(&a.qd, &b.qd), join(&a.qdd, &b.qdd));
    let tau = join(&tau_a, &tau_b);
    let states = States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let reference = Reference::Urdf;
    let mut options = PayloadOptions::new("link6", &reference);
    options.runs = vec![a.q.len() / 6, b.q.len() / 6];
    options.log_names = vec!["monday.csv".into(), "tuesday.csv".into()];
    // one offset for both: the payload takes part of the difference
    let shared = identify_payload(&truth, reference, &states, &tau, &options).unwrap();
    assert!(shared.log_offsets.is_none());
    options.offset_per_run = true;
    let fit = identify_payload(&truth, reference, &states, &tau, &options).unwrap();
    let want = parameters_of_payload(&p);
    for (i, (x, w)) in fit.parameters().iter().zip(&want).enumerate() {
        assert!(
            (x - w).abs() < 1e-7 * (1.0 + w.abs()),
            "{}: {x} vs {w}",
            fit.names[i]
        );
    }
    let err = |f: &perturbid_rs::direct::PayloadFit| (f.parameters()[0] - p.mass).abs();
    assert!(
        err(&shared) > 1e3 * err(&fit),
        "{} vs {}",
        err(&shared),
        err(&fit)
    );
    assert!(
        fit.names.contains(&"joint3.offset of run 1".to_string()),
        "{:?}",
        fit.names
    );
    let o = fit.log_offsets.as_ref().unwrap();
    for (j, d) in o.deviations.iter().enumerate() {
        assert!(
            (d[0] + OFFSETS[j] / 2.0).abs() < 1e-7 && (d[1] - OFFSETS[j] / 2.0).abs() < 1e-7,
            "{d:?}"
        );
    }
    // the joint terms' offset is the logs' mean: the robot carrying the payload predicted
    // there, the second log's torques less half their offset
    let s_b = States::new(6, &b.q, Some(&b.qd), Some(&b.qdd)).unwrap();
    let predicted = fit.predict(&truth, reference, &s_b).unwrap();
    for (i, (x, t)) in predicted.iter().zip(&tau_b).enumerate() {
        assert!(
            (x - (t - OFFSETS[i % 6] / 2.0)).abs() < 1e-6,
            "{i}: {x} vs {t}"
        );
    }
    // refused: one log, or no offset among the joint terms
    let mut one = PayloadOptions::new("link6", &reference);
    one.offset_per_run = true;
    let e = identify_payload(&truth, reference, &states, &tau, &one)
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 to 50 logs"), "{e}");
    options.terms = FrictionTerms {
        offset: false,
        ..FrictionTerms::ALL
    };
    let e = identify_payload(&truth, reference, &states, &tau, &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs the offset among the joint terms"), "{e}");
}
