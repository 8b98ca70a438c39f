//! A log's positions against the robot's joint limits (src/direct/position_range.rs): a log in
//! degrees is named as such, one joint from another zero as leaving the limits (not as
//! degrees); a clean log, a joint a little past its limits and a joint without limits raise
//! nothing.

mod common;

use common::{a465_log, fit_physical, refused_on_load, A465Log};
use perturbid_rs::direct::position_range::{check_position_range, finding, MARGIN};
use perturbid_rs::direct::BaseModel;
use perturbid_rs::document::Document;
use perturbid_rs::robots::a465;
use perturbid_rs::States;

/// The smallest and largest value of column `j` of the row-major `k x 6` samples `v`.
fn extent(v: &[f64], j: usize) -> (f64, f64) {
    let column: Vec<f64> = v.chunks(6).map(|row| row[j]).collect();
    let min = column.iter().copied().fold(f64::INFINITY, f64::min);
    let max = column.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (min, max)
}

#[test]
fn positions_in_degrees_are_named_and_a_clean_log_is_not() {
    let clean = a465_log();
    let m = fit_physical(&clean);
    assert!(m.position_range.is_empty(), "{:?}", m.position_range);
    let robot = a465::model("physical").unwrap();
    let degrees = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<f64>>();
    let log = A465Log {
        q: degrees(&clean.q),
        qd: degrees(&clean.qd),
        qdd: degrees(&clean.qdd),
        tau: clean.tau.clone(),
    };
    let m = fit_physical(&log);
    // every joint whose motion in degrees leaves its limits, and only those
    let beyond: Vec<String> = (0..6)
        .filter(|&j| {
            let (min, max) = extent(&log.q, j);
            let l = &robot.limits[j];
            let slack = MARGIN * (l.upper - l.lower) + 0.01;
            min < l.lower - slack || max > l.upper + slack
        })
        .map(|j| robot.joint_names[j].clone())
        .collect();
    assert!(beyond.len() >= 4, "{beyond:?}");
    let named: Vec<String> = m.position_range.iter().map(|r| r.joint.clone()).collect();
    assert_eq!(named, beyond);
    for r in &m.position_range {
        let j = robot
            .joint_names
            .iter()
            .position(|n| *n == r.joint)
            .unwrap();
        assert_eq!((r.min, r.max), extent(&log.q, j));
        assert_eq!(
            (r.lower, r.upper),
            (robot.limits[j].lower, robot.limits[j].upper)
        );
        assert!(r.degrees, "{r:?}");
    }
    let w = m.warnings();
    assert!(
        w[0].starts_with("the log's positions leave the URDF's joint limits: 'joint1' from")
            && w[0].contains("the log's positions look like degrees (convert them to rad)"),
        "{w:?}"
    );
    // saved with the model and checked on load
    let text = m.to_json();
    assert_eq!(BaseModel::from_json(&text).unwrap(), m);
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 3] = [
        (
            |v| v["position_range"][0]["joint"] = "joint9".into(),
            "position_range[0]: joint 'joint9' is not one of the model's",
        ),
        (
            |v| v["position_range"][0]["min"] = 1e9.into(),
            "position_range[0]: joint 'joint1': min above max",
        ),
        (
            |v| v["position_range"][1]["upper"] = serde_json::Value::Null,
            "position_range[1]",
        ),
    ];
    refused_on_load::<BaseModel>(&value, &edits);
}

#[test]
fn positions_from_another_zero_leave_the_limits_and_small_excursions_do_not() {
    let clean = a465_log();
    let robot = a465::model("physical").unwrap();
    // the shoulder's zero 2.5 rad off: beyond its limits, and not degrees
    let mut q = clean.q.clone();
    for row in q.chunks_mut(6) {
        row[1] += 2.5;
    }
    let states = States::new(6, &q, None, None).unwrap();
    let found = check_position_range(&robot, &states);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].joint, "joint2");
    let w = finding(&found).unwrap();
    assert!(
        w.contains("another robot or another zero") && !w.contains("look like degrees"),
        "{w}"
    );
    // limits narrowed around the clean log's motion: within MARGIN of the range no finding,
    // beyond it one
    let states = States::new(6, &clean.q, None, None).unwrap();
    let (min, max) = extent(&clean.q, 1);
    for (excess, expected) in [(0.6 * MARGIN, 0), (1.5 * MARGIN, 1)] {
        let mut narrow = robot.clone();
        // the range r such that the motion passes the upper limit by `excess` r (+ 0.01)
        let range = (max - min - 0.01) / (1.0 + excess);
        narrow.limits[1].lower = min;
        narrow.limits[1].upper = min + range;
        let found = check_position_range(&narrow, &states);
        assert_eq!(found.len(), expected, "excess {excess}: {found:?}");
    }
    // a joint without limits (continuous) is never a finding
    let mut free = robot.clone();
    free.limits[1].lower = f64::NEG_INFINITY;
    free.limits[1].upper = f64::INFINITY;
    let states = States::new(6, &q, None, None).unwrap();
    assert!(check_position_range(&free, &states).is_empty());
    assert_eq!(finding(&[]), None);
}
