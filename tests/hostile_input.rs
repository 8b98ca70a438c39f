//! Careless and hostile input gets one of our errors, of the right kind, naming what is wrong:
//! never a panic, a stack overflow or a silent reinterpretation.
// Errors carry their context by value (the library allows the same).
#![allow(clippy::result_large_err)]

mod common;

use std::collections::BTreeMap;

use common::mimic_pair;
use perturbid_rs::io::Table;
use perturbid_rs::local::{
    plan_experiments, ExperimentKind, OperatingPoint, PlanOptions, Size, Sizes,
};
use perturbid_rs::robots::a465::{TABLE2_Q, TABLE2_QD, TABLE2_QDD};
use perturbid_rs::urdf::{MAX_XML_DEPTH, MAX_XML_ELEMENTS};
use perturbid_rs::{
    catch_panics, model_from_urdf_str, robots, Document, ErrorKind, LoadOptions, Plan,
};

fn load(urdf: &str) -> perturbid_rs::Result<perturbid_rs::Model> {
    model_from_urdf_str(urdf, "arm.urdf", &LoadOptions::default())
}

fn with_limit(limit: &str, kind: &str) -> String {
    format!(
        r#"<robot name="r"><link name="a"/>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j1" type="{kind}"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>{limit}</joint></robot>"#
    )
}

#[test]
fn unusable_limits_are_model_errors_naming_the_joint_and_line() {
    for (limit, says) in [
        (
            r#"<limit lower="1" upper="-1" effort="1" velocity="1"/>"#,
            "lower (1) is above upper (-1)",
        ),
        (
            r#"<limit lower="0" upper="0" effort="1" velocity="1"/>"#,
            "cannot move",
        ),
        (
            r#"<limit lower="-1" upper="1" effort="1" velocity="-1"/>"#,
            "velocity -1",
        ),
        (
            r#"<limit lower="-1" upper="1" effort="1" velocity="0"/>"#,
            "velocity 0",
        ),
        (
            r#"<limit lower="-1" upper="1" effort="-2" velocity="1"/>"#,
            "effort -2 N m is negative",
        ),
        (
            r#"<limit lower="-1" upper="1" effort="1" velocity="1" acceleration="0"/>"#,
            "acceleration 0",
        ),
    ] {
        let mut urdf = with_limit(limit, "revolute");
        if limit.contains("acceleration") {
            // URDF 1.2 is the first version with acceleration limits
            urdf = urdf.replace(r#"name="r">"#, r#"name="r" version="1.2">"#);
        }
        let e = load(&urdf).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Model, "{e}");
        let text = e.to_string();
        assert!(
            text.starts_with("arm.urdf:3: joint 'j1' <limit>: "),
            "{text}"
        );
        assert!(text.contains(says), "{text}");
    }
    // a continuous joint may leave velocity and effort out (zeros from the parser): no limit
    let m = load(&with_limit(
        r#"<limit effort="0" velocity="0"/>"#,
        "continuous",
    ))
    .unwrap();
    assert!(m.limits[0].velocity.is_infinite() && m.limits[0].effort.is_infinite());
    // effort 0 means "not given" on any joint
    let m = load(&with_limit(
        r#"<limit lower="-1" upper="1" effort="0" velocity="1"/>"#,
        "revolute",
    ))
    .unwrap();
    assert!(m.limits[0].effort.is_infinite());
}

#[test]
fn a_robot_without_a_moving_joint_is_refused() {
    let fixed = with_limit("", "fixed");
    let e = load(&fixed).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Model);
    assert!(e.to_string().contains("has no moving joint"), "{e}");
    // every joint locked: the same
    let mut lock = BTreeMap::new();
    lock.insert("a".to_string(), 0.0);
    lock.insert("c".to_string(), 0.0);
    let options = LoadOptions {
        lock,
        ..LoadOptions::default()
    };
    let e = model_from_urdf_str(&mimic_pair(true), "m.urdf", &options).unwrap_err();
    assert!(e.to_string().contains("has no moving joint"), "{e}");
}

#[test]
fn a_urdf_of_too_many_elements_is_refused_before_parsing() {
    // flat, within the document's byte bound, but the parsers would hold gigabytes of it
    let gazebo = r#"<gazebo reference="a"><material>x</material></gazebo>"#;
    let many = with_limit("", "continuous").replace(
        "</robot>",
        &format!("{}</robot>", gazebo.repeat(MAX_XML_ELEMENTS / 2)),
    );
    let e = load(&many).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Model);
    assert!(
        e.to_string()
            .contains(&format!("more than {MAX_XML_ELEMENTS} elements")),
        "{e}"
    );
    // self-closing elements count too; a few thousand load
    let some = with_limit("", "continuous").replace(
        "</robot>",
        &format!("{}</robot>", "<gazebo/>".repeat(5_000)),
    );
    load(&some).unwrap();
}

#[test]
fn deep_nesting_is_refused_before_parsing() {
    // far deeper than any parser's recursion can take
    let depth = 200_000;
    let mut urdf = String::from(r#"<robot name="r"><link name="a">"#);
    urdf.push_str(&"<x>".repeat(depth));
    urdf.push_str(&"</x>".repeat(depth));
    urdf.push_str("</link></robot>");
    let e = load(&urdf).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Model);
    let text = e.to_string();
    assert!(
        text.contains(&format!("at most {MAX_XML_DEPTH} levels")),
        "{text}"
    );
    // comments, CDATA and quoted '>' do not count as elements
    let ok = with_limit(
        r#"<!-- <a><b><c> --><limit lower="-1" upper="1" effort="1" velocity="1"/><![CDATA[<<<]]>"#,
        "revolute",
    )
    .replace(r#"<robot name="r">"#, r#"<robot name="r>s">"#);
    load(&ok).unwrap();
}

/// A chain of `n` links, every `every`-th joint revolute and the rest fixed.
fn chain(n: usize, every: usize) -> String {
    let mut urdf = String::from(r#"<robot name="chain"><link name="l0"/>"#);
    for i in 1..=n {
        let kind = if i % every == 0 { "revolute" } else { "fixed" };
        urdf.push_str(&format!(
            r#"<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j{i}" type="{kind}"><parent link="l{}"/><child link="l{i}"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#,
            i - 1
        ));
    }
    urdf.push_str("</robot>");
    urdf
}

#[test]
fn a_long_chain_loads() {
    // 5,000 links, 1,000 of them moving (the most a model may have): the loader used to be
    // quadratic (line numbers, the mass check)
    let urdf = chain(5000, 5);
    let m = load(&urdf).unwrap();
    assert_eq!(m.nv, 1000);
    // an error deep in the file names its line
    let bad = urdf.replace(
        r#"name="j4000" type="revolute""#,
        r#"name="j4000" type="floating""#,
    );
    let e = load(&bad).unwrap_err().to_string();
    assert!(e.starts_with("arm.urdf:4001: joint 'j4000'"), "{e}");
    // one moving body more is refused before any buffer of n^2 values is made
    let e = load(&chain(1001, 1)).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Model);
    assert_eq!(
        e.to_string(),
        "arm.urdf: robot 'chain' has 1001 moving bodies; at most 1000 are supported (each sample's regressor has 10 n^2 values; docs/limits.md)"
    );
}

#[test]
fn csv_headers_are_checked_in_one_pass() {
    let e = Table::parse("log.csv", "# a comment\n\nt,q1,q1\n0,1,2\n").unwrap_err();
    assert_eq!(e.to_string(), "log.csv: line 3: column 'q1' appears twice");
    let wide: Vec<String> = (0..200_000).map(|i| format!("c{i}")).collect();
    let zeros = vec!["0"; wide.len()].join(",");
    let t = Table::parse("wide.csv", &format!("{}\n{zeros}\n", wide.join(","))).unwrap();
    assert_eq!(t.columns.len(), 200_000);
    // a table written with another separator reads as one column: said so
    for (sep, name) in [(";", "semicolons"), ("\t", "tabs"), (" ", "spaces")] {
        let text = format!("t{sep}q1{sep}tau1\n0{sep}1,5{sep}2\n");
        let e = Table::parse("log.csv", &text).unwrap_err().to_string();
        assert!(
            e.starts_with("log.csv: line 1: one column named")
                && e.contains(&format!("separated by {name}")),
            "{e}"
        );
    }
}

#[test]
fn documents_refuse_unknown_keys_with_their_path() {
    let model = robots::builtin("a465").unwrap();
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let text = plan.to_json();
    // a misspelled top-level key
    let e = Plan::from_json(&text.replacen("\"rate\"", "\"rat\"", 1)).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input);
    assert!(e.to_string().contains("unknown field `rat`"), "{e}");
    // an extra key deep inside: the path says where
    let deep = text.replacen("\"crossings\": [", "\"crosings\": 1, \"crossings\": [", 1);
    let e = Plan::from_json(&deep).unwrap_err().to_string();
    assert!(
        e.contains("at experiments[0]") && e.contains("unknown field `crosings`"),
        "{e}"
    );
    // trailing content is not ignored
    assert!(Plan::from_json(&format!("{text} {{}}")).is_err());
    Plan::from_json(&text).unwrap();
}

#[test]
fn a_document_of_too_many_arrays_is_refused_before_parsing() {
    use perturbid_rs::limits::MAX_JSON_CONTAINERS;
    let model = robots::builtin("a465").unwrap();
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let text = plan_experiments(&model, &op, &PlanOptions::default())
        .unwrap()
        .to_json();
    // empty rows past the bound: the parser would hold 80 bytes for each 4 of text
    let rows = format!("[{}[0]]", "[0],".repeat(MAX_JSON_CONTAINERS));
    let edited = text.replacen("\"rate\"", &format!("\"junk\": {rows}, \"rate\""), 1);
    let e = Plan::from_json(&edited).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input);
    assert!(
        e.to_string().contains(&format!(
            "more than {MAX_JSON_CONTAINERS} arrays and objects"
        )),
        "{e}"
    );
    // brackets inside strings (escaped quotes too) are not counted
    let brackets = format!("\"\\\"{}\"", "[".repeat(MAX_JSON_CONTAINERS + 1));
    let edited = text.replacen("\"rate\"", &format!("\"junk\": {brackets}, \"rate\""), 1);
    let e = Plan::from_json(&edited).unwrap_err().to_string();
    assert!(e.contains("unknown field `junk`"), "{e}");
}

#[test]
fn buffers_made_for_another_model_are_refused_not_indexed() {
    use perturbid_rs::{
        aba, forward_dynamics, gravity_torque, linearize, mass_matrix, rnea, rnea_derivatives,
        Data, Gravity,
    };
    let a465 = robots::builtin("a465").unwrap();
    let pair = model_from_urdf_str(&mimic_pair(true), "<pair>", &LoadOptions::default()).unwrap();
    assert_ne!(pair.nv, a465.nv);
    // the A465's algorithms on the small model's buffers: an index past their end would panic
    let mut small = Data::new(&pair);
    let z = vec![0.1; a465.nv];
    let errors = [
        rnea(&a465, &mut small, &z, &z, &z, Gravity::Included).err(),
        gravity_torque(&a465, &mut small, &z).err(),
        mass_matrix(&a465, &mut small, &z).err(),
        rnea_derivatives(&a465, &mut small, &z, &z, &z, Gravity::Included).err(),
        linearize(&a465, &mut small, &z, &z, &z, Gravity::Included).err(),
        forward_dynamics(&a465, &mut small, &z, &z, &z, Gravity::Included).err(),
        aba(&a465, &mut small, &z, &z, &z, Gravity::Included).err(),
    ];
    for (i, e) in errors.into_iter().enumerate() {
        let e = e.unwrap_or_else(|| panic!("algorithm {i} took another model's buffers"));
        assert_eq!(e.kind(), ErrorKind::Input, "algorithm {i}: {e}");
        assert!(
            e.to_string()
                .contains("data: expected buffers for this model (6 dofs"),
            "{e}"
        );
    }
    // and the other way round (larger buffers than the model needs are refused too)
    let mut large = Data::new(&a465);
    let zp = vec![0.1; pair.nv];
    assert!(rnea(&pair, &mut large, &zp, &zp, &zp, Gravity::Included).is_err());
    // the right buffers still work after the refusals
    assert!(rnea(&a465, &mut Data::new(&a465), &z, &z, &z, Gravity::Included).is_ok());
}

#[test]
fn a_panic_at_the_boundary_becomes_an_internal_error() {
    let e = catch_panics("Robot.rnea", || -> perturbid_rs::Result<()> {
        panic!("boom")
    })
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Internal);
    assert_eq!(
        e.to_string(),
        "internal error in Robot.rnea: boom (a bug in perturbid_rs: please report it)"
    );
}

#[test]
fn sizes_from_input_are_bounded_before_allocation() {
    use perturbid_rs::direct::{design_excitation, ExcitationOptions};
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
    use perturbid_rs::Recording;
    let model = robots::builtin("a465").unwrap();
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    for (options, says) in [
        (
            PlanOptions {
                rate: 1e12,
                ..PlanOptions::default()
            },
            "rate: 1e12;",
        ),
        (
            PlanOptions {
                count: Some(1_000_000_000_000),
                ..PlanOptions::default()
            },
            "n (perturbations per experiment): 1000000000000; expected 2 to 100000",
        ),
        (
            PlanOptions {
                window: f64::INFINITY,
                ..PlanOptions::default()
            },
            "window: inf",
        ),
        (
            PlanOptions {
                experiments: vec![],
                ..PlanOptions::default()
            },
            "experiments: none asked for",
        ),
    ] {
        let e = plan_experiments(&model, &op, &options).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Input);
        assert!(e.to_string().starts_with(says), "{e}");
    }
    for (options, says) in [
        (
            ExcitationOptions {
                harmonics: 1_000_000_000,
                ..ExcitationOptions::default()
            },
            "harmonics: 1000000000; expected 1 to 1000",
        ),
        (
            ExcitationOptions {
                max_evaluations: 0,
                ..ExcitationOptions::default()
            },
            "max_evaluations: 0",
        ),
        (
            ExcitationOptions {
                base_frequency: f64::NAN,
                ..ExcitationOptions::default()
            },
            "base_frequency: NaN",
        ),
    ] {
        let e = design_excitation(&model, &options, None).unwrap_err();
        assert!(e.to_string().starts_with(says), "{e}");
    }
    // a log resampled at an absurd rate is refused, not allocated
    let t: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
    let rec = Recording::new("log", 1, t, vec![0.0; 100], vec![0.0; 100], None, None).unwrap();
    let options = PreprocessOptions {
        rate: 1e15,
        ..PreprocessOptions::default()
    };
    let e = preprocess(&rec, &options).unwrap_err().to_string();
    assert!(e.starts_with("rate: 1e15;"), "{e}");
    // within every bound by itself, too many values together: a plan held for an hour a
    // posture at 10 MHz, an excitation criterion over a million samples a period
    let options = PlanOptions {
        rate: 1e7,
        dwell: 3600.0,
        experiments: vec![ExperimentKind::GStatic],
        ..PlanOptions::default()
    };
    let e = plan_experiments(&model, &op, &options).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input);
    let e = e.to_string();
    assert!(
        e.starts_with("experiment 'G_static' of the plan: 4")
            && e.contains(" s at 10000000 Hz give 4.")
            && e.ends_with("samples of 25 values (1.170e13 values); at most 1e8 samples and 2^28 values (2 GiB) are made (docs/limits.md)"),
        "{e}"
    );
    let options = ExcitationOptions {
        samples: 1_000_000,
        ..ExcitationOptions::default()
    };
    let e = design_excitation(&model, &options, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("samples: the criterion's regressor of 1000000 samples of 6 joints and ")
            && e.ends_with("values; at most 2^28 (2 GiB) are made (docs/limits.md)"),
        "{e}"
    );
}

#[test]
fn a_gap_in_a_log_is_not_filled_with_invented_values() {
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions};
    use perturbid_rs::Recording;
    // 1 kHz for 3 s, then nothing for 100 s, then 3 s more
    let mut t: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
    t.extend((0..3000).map(|i| 103.0 + i as f64 * 1e-3));
    let q: Vec<f64> = t.iter().map(|x| (0.3 * x).sin()).collect();
    let rec = Recording::new("arm.csv", 1, t, q.clone(), q, None, None).unwrap();
    let e = preprocess(&rec, &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("arm.csv: a gap of 100.001000 s after t = 2.999000 s"),
        "{e}"
    );
    assert!(e.contains("split the log there (split_at_gaps"), "{e}");
    // with the explicit option, each side is preprocessed on its own; the gap stays a gap
    let options = PreprocessOptions {
        split_at_gaps: true,
        ..PreprocessOptions::default()
    };
    let out = preprocess(&rec, &options).unwrap();
    assert_eq!(out.name, "arm.csv (preprocessed, 2 parts)");
    let largest_step = out.t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    assert!(largest_step > 100.0, "the gap was bridged: {largest_step}");
    assert!(
        out.t.iter().all(|t| !(3.0..=103.0).contains(t)),
        "invented samples in the gap"
    );
    // each part: 3 s at 1 kHz, 0.5 s trimmed at both ends, every 10th sample
    assert_eq!(out.len(), 2 * 200);
    for (i, &t) in out.t.iter().enumerate() {
        let qd = out.qd.as_ref().unwrap()[i];
        assert!(
            (qd - 0.3 * (0.3 * t).cos()).abs() < 1e-3,
            "qd at t = {t}: {qd}"
        );
    }
    // a part too short to trim is refused, naming it
    let mut t2 = rec.t[..3000].to_vec();
    t2.extend((0..50).map(|i| 200.0 + i as f64 * 1e-3));
    let q2: Vec<f64> = t2.iter().map(|x| (0.3 * x).sin()).collect();
    let short = Recording::new("arm.csv", 1, t2, q2.clone(), q2, None, None).unwrap();
    let e = preprocess(&short, &options).unwrap_err().to_string();
    assert!(
        e.starts_with("arm.csv: part 2 of 2 (t = 200.000000 s to 200.049000 s, between gaps): "),
        "{e}"
    );
}

/// A log whose time column is in milliseconds reads as samples 1 s apart: refused, asking
/// about the unit, before it is resampled into a log 1,000 times slower than the robot moved
/// (a short one) or refused for its size (a long one); microseconds and nanoseconds likewise,
/// each named where it gives a robot's logging rate. 2.5 Hz passes this check.
#[test]
fn a_log_timed_in_milliseconds_is_asked_about() {
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions, SLOWEST_INTERVAL};
    use perturbid_rs::Recording;
    let log = |name: &str, k: usize, dt: f64| {
        let t: Vec<f64> = (0..k).map(|i| i as f64 * dt).collect();
        let q: Vec<f64> = t.iter().map(|x| (0.3 * x).sin()).collect();
        Recording::new(name, 1, t, q.clone(), q, None, None).unwrap()
    };
    for k in [2_000, 100_000] {
        // 2 s and 100 s at 1 kHz, timed in ms
        let e = preprocess(&log("arm.csv", k, 1.0), &PreprocessOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("arm.csv: its samples are 1 s apart (the median interval; 1 Hz)")
                && e.contains("Is the time column in milliseconds (the samples would come at 1000 Hz: divide it by 1,000)? It is read in seconds"),
            "{e}"
        );
    }
    // nanoseconds (a ROS stamp, here from 0) and a rate two units would make plausible
    let e = preprocess(&log("bag.csv", 2_000, 1e6), &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Is the time column in nanoseconds (a ROS stamp) (the samples would come at 1000 Hz: divide it by 1e9)?"),
        "{e}"
    );
    let e = preprocess(&log("both.csv", 2_000, 50.0), &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("milliseconds (the samples would come at 20 Hz: divide it by 1,000) or microseconds (the samples would come at 20000 Hz: divide it by 1e6)?"),
        "{e}"
    );
    assert_eq!(SLOWEST_INTERVAL, 0.5);
    if let Err(e) = preprocess(&log("slow.csv", 200, 0.4), &PreprocessOptions::default()) {
        assert!(!e.to_string().contains("milliseconds"), "{e}");
    }
}

/// A log timed in hours (1 kHz read as 3.6 MHz) is asked about, as one in milliseconds is:
/// resampled at 1 kHz it would leave a handful of samples, refused as too short to filter.
/// One faster still, which no unit makes a robot's rate, is refused without a guess; one at
/// 100 kHz passes this check.
#[test]
fn a_log_timed_in_hours_is_asked_about() {
    use perturbid_rs::logs::preprocess::{preprocess, PreprocessOptions, FASTEST_INTERVAL};
    use perturbid_rs::Recording;
    let log = |name: &str, k: usize, dt: f64| {
        let t: Vec<f64> = (0..k).map(|i| i as f64 * dt).collect();
        let q: Vec<f64> = (0..k).map(|i| (0.3e-3 * i as f64).sin()).collect();
        Recording::new(name, 1, t, q.clone(), q, None, None).unwrap()
    };
    assert_eq!(FASTEST_INTERVAL, 1e-6);
    let e = preprocess(
        &log("arm.csv", 20_000, 1e-3 / 3600.0),
        &PreprocessOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("arm.csv: its samples are 2.7778e-7 s apart (the median interval; 3600000 Hz): faster than a robot logs its joints")
            && e.contains("minutes (the samples would come at 60000 Hz: multiply it by 60) or hours (the samples would come at 1000 Hz: multiply it by 3,600)? It is read in seconds"),
        "{e}"
    );
    let e = preprocess(
        &log("fast.csv", 20_000, 1e-12),
        &PreprocessOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("1e-12 s apart")
            && e.contains("Is the time column in another unit than seconds?"),
        "{e}"
    );
    if let Err(e) = preprocess(
        &log("quick.csv", 20_000, 1e-5),
        &PreprocessOptions::default(),
    ) {
        assert!(!e.to_string().contains("faster than"), "{e}");
    }
    // a log too short to filter says how long it is and how many samples that made
    let e = preprocess(&log("short.csv", 10, 1e-3), &PreprocessOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("short.csv: 0.009 s long, 10 samples at 1000 Hz: too short to filter"),
        "{e}"
    );
}

/// Text that is not UTF-8 is refused naming its line, its byte and what the file looks like:
/// a header with a degree sign in Latin-1, UTF-16 as some Windows tools save, binary data. A
/// document an editor saved with a UTF-8 byte-order mark first is read (RFC 8259 lets a
/// reader ignore it).
#[test]
fn text_not_in_utf8_is_named_and_a_byte_order_mark_is_ignored() {
    let d = common::temp_dir::TempDir::new("utf8");
    let joints = vec!["joint1".to_string()];
    let cases: [(&str, Vec<u8>, &str); 3] = [
        (
            "latin1.csv",
            b"t,q1,tau1\n0,1,2\n0.001,1,2 # 30\xb0\n".to_vec(),
            "line 3, byte 15 of it: byte 0xb0 is not UTF-8; the file looks like text in another encoding",
        ),
        (
            "utf16.csv",
            [0xff, 0xfe, b't', 0, b',', 0].to_vec(),
            "line 1, byte 1 of it: byte 0xff is not UTF-8; the file looks like UTF-16 text",
        ),
        (
            "binary.csv",
            [7, 1, 0, 0, 0x9f, 0x80, 0x41].to_vec(),
            "byte 0x9f is not UTF-8; the file looks like binary data, not text",
        ),
    ];
    for (name, bytes, expected) in cases {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = perturbid_rs::logs::load_recording(&path, &joints)
            .unwrap_err()
            .to_string();
        assert!(e.contains(name) && e.contains(expected), "{e}");
    }
    // a saved model with a byte-order mark first loads as without it
    let model = perturbid_rs::robots::a465::model("kinsheel2010").unwrap();
    let mut rng = 7u64;
    let mut next = || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (rng >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let k = 200;
    let (q, qd, qdd): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        (0..k * 6).map(|_| next()).collect(),
        (0..k * 6).map(|_| next()).collect(),
        (0..k * 6).map(|_| next()).collect(),
    );
    let states = perturbid_rs::States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut ws = perturbid_rs::parallel::Workspace::new(&model);
    let mut tau = vec![0.0; k * 6];
    let gravity = perturbid_rs::Gravity::Included;
    perturbid_rs::parallel::rnea(&model, &mut ws, &states, gravity, &mut tau).unwrap();
    let fit = perturbid_rs::direct::identify_base_parameters(
        &model,
        &states,
        &tau,
        &perturbid_rs::direct::BaseOptions::default(),
    )
    .unwrap();
    let path = d.join("model.json");
    fit.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, format!("\u{feff}{text}")).unwrap();
    let loaded = perturbid_rs::direct::BaseModel::load(&path).unwrap();
    assert_eq!(loaded.theta, fit.theta);
}

#[test]
fn a_hand_edited_plan_is_checked_on_load() {
    let model = robots::builtin("a465").unwrap();
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    // segments reversed in time
    let mut edited = plan.clone();
    let seg = &mut edited.experiments[1].trajectory.segments[2];
    std::mem::swap(&mut seg.t0, &mut seg.t1);
    let e = Plan::from_json(&edited.to_json()).unwrap_err().to_string();
    assert!(
        e.contains("experiments[1] ('G_static'): trajectory.segments[2] runs from"),
        "{e}"
    );
    // a duration that would need more samples than are ever made
    let mut edited = plan.clone();
    let last = edited.experiments[0]
        .trajectory
        .segments
        .last_mut()
        .unwrap();
    last.t1 = 1e12;
    let e = Plan::from_json(&edited.to_json()).unwrap_err().to_string();
    assert!(
        e.contains("at most 1e8 samples and 2^28 values (2 GiB) are made"),
        "{e}"
    );
    // a joint named twice, or not at all: a log's columns would be read twice
    let mut edited = plan.clone();
    edited.joint_names[2] = edited.joint_names[0].clone();
    let e = Plan::from_json(&edited.to_json()).unwrap_err().to_string();
    assert!(e.contains("joint_names[2] 'joint1' is named twice"), "{e}");
    let mut edited = plan.clone();
    edited.joint_names[4] = " ".into();
    let e = Plan::from_json(&edited.to_json()).unwrap_err().to_string();
    assert!(e.contains("joint_names[4] is empty"), "{e}");
    // NaN as Python's json module writes it: said so, with the position once
    let text = plan
        .to_json()
        .replacen("\"rate\": 1000.0", "\"rate\": NaN", 1);
    let e = Plan::from_json(&text).unwrap_err().to_string();
    assert!(e.contains("JSON has no NaN or Infinity"), "{e}");
    assert_eq!(e.matches("line ").count(), 1, "{e}");
    let text = plan.to_json().replacen("\"random\"", "\"randm\"", 1);
    let e = Plan::from_json(&text).unwrap_err().to_string();
    assert!(e.contains("at design: unknown variant `randm`"), "{e}");
    assert_eq!(e.matches("line ").count(), 1, "{e}");
    assert!(!e.contains("JSON has no NaN"), "{e}");
    // no experiment at all
    let mut edited = plan;
    edited.experiments.clear();
    let e = Plan::from_json(&edited.to_json()).unwrap_err().to_string();
    assert!(e.contains("the plan has no experiment"), "{e}");
}

#[test]
fn an_absurd_speed_limit_does_not_stall_the_excitation_design() {
    use perturbid_rs::direct::{design_excitation, ExcitationOptions, FrictionTerms};
    let mut model = robots::builtin("a465").unwrap();
    for l in &mut model.limits {
        l.velocity = 1e300;
    }
    let options = ExcitationOptions {
        max_evaluations: 200,
        friction: FrictionTerms::NONE,
        ..ExcitationOptions::default()
    };
    let design = design_excitation(&model, &options, None).unwrap();
    assert!(design.cond.is_finite() && design.evaluations <= 201);
}

#[test]
fn finite_inputs_that_overflow_get_errors_not_inf() {
    use perturbid_rs::{parallel, Gravity, States};
    // inertias near the top of the floating-point range
    for inertia in [
        r#"ixx="0.1" ixy="-1e308" ixz="0" iyy="0.1" iyz="0" izz="0.1""#,
        r#"ixx="1e308" ixy="0" ixz="0" iyy="1e308" iyz="0" izz="1e308""#,
    ] {
        let urdf = with_limit(
            r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
            "revolute",
        )
        .replace(
            r#"ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1""#,
            inertia,
        );
        let e = load(&urdf).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Model, "{e}");
        assert!(e.to_string().contains("link 'b'"), "{e}");
    }
    let urdf = with_limit(
        r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        "revolute",
    )
    .replace(r#"<mass value="1"/>"#, r#"<mass value="1e300"/>"#);
    assert!(load(&urdf).unwrap_err().to_string().contains("below 1e12"));
    // a state so large that the dynamics overflow: an error naming the sample, not inf
    let model = robots::builtin("a465").unwrap();
    let mut qd = vec![0.1; 5 * 6];
    qd[3 * 6 + 1] = 1e200;
    let q = vec![0.2; 5 * 6];
    let states = States::new(6, &q, Some(&qd), None).unwrap();
    let mut tau = vec![0.0; 30];
    let e = parallel::rnea(
        &model,
        &mut parallel::Workspace::new(&model),
        &states,
        Gravity::Included,
        &mut tau,
    )
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Numerical);
    assert!(e.to_string().starts_with("rnea (sample 3): tau is"), "{e}");
    // one sample through the one-sample API: the same
    let mut data = perturbid_rs::Data::new(&model);
    let e = perturbid_rs::rnea(
        &model,
        &mut data,
        &q[18..24],
        &qd[18..24],
        &[0.0; 6],
        Gravity::Included,
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("rnea: tau is"), "{e}");
    let e = perturbid_rs::linearize(
        &model,
        &mut data,
        &q[18..24],
        &qd[18..24],
        &[0.0; 6],
        Gravity::Included,
    )
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Numerical, "{e}");
}

#[test]
fn options_that_mean_nothing_are_refused() {
    use perturbid_rs::direct::{identify_base_parameters, BaseOptions};
    use perturbid_rs::States;
    let model = robots::builtin("a465").unwrap();
    let q = vec![0.1; 60];
    let states = States::new(6, &q, Some(&q), Some(&q)).unwrap();
    for tolerance in [f64::NAN, -1.0, 1.0] {
        let options = BaseOptions {
            tolerance,
            ..BaseOptions::default()
        };
        let e = identify_base_parameters(&model, &states, &q, &options).unwrap_err();
        assert!(e.to_string().starts_with("tolerance: "), "{e}");
    }
    // runs that are not the samples' (10 of them)
    for (runs, says) in [
        (vec![4, 5], "runs: runs of 9 samples in all, for 10 samples"),
        (vec![0, 10], "runs: run 0 has no samples"),
        (vec![1; 1001], "runs: 1001 runs, expected at most 1000"),
    ] {
        let options = BaseOptions {
            runs,
            ..BaseOptions::default()
        };
        let e = identify_base_parameters(&model, &states, &q, &options).unwrap_err();
        assert!(e.to_string().starts_with(says), "{e}");
    }
}

mod fuzz {
    //! Arbitrary and mutated text through every reader: a result or one of our errors, never a
    //! panic. Bounded for CI (`PROPTEST_CASES` raises the count for a release run).
    use super::*;
    use perturbid_rs::local::LocalModel;
    use proptest::prelude::*;

    fn a_urdf() -> String {
        mimic_pair(true)
    }

    /// `text` with the bytes in `cuts` removed and `insert` put at `at`.
    fn mutate(text: &str, at: usize, cut: usize, insert: &str) -> String {
        let mut chars: Vec<char> = text.chars().collect();
        let at = at % (chars.len() + 1);
        let end = (at + cut).min(chars.len());
        chars.splice(at..end, insert.chars());
        chars.into_iter().collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        #[test]
        fn urdf_reader(at in 0usize..4000, cut in 0usize..40, insert in ".{0,12}") {
            let text = mutate(&a_urdf(), at, cut, &insert);
            let _ = model_from_urdf_str(&text, "fuzz.urdf", &LoadOptions::default());
        }

        #[test]
        fn csv_reader(text in "[a-z0-9,.\\-#eE\\n ]{0,200}") {
            let _ = Table::parse("fuzz.csv", &text);
        }

        #[test]
        fn json_documents(at in 0usize..3000, cut in 0usize..30, insert in "[\\[\\]{}\",:0-9a-z.eE-]{0,10}") {
            let model = robots::builtin("a465").unwrap();
            let op = OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
            let options = PlanOptions { experiments: vec![perturbid_rs::local::ExperimentKind::D], ..PlanOptions::default() };
            let plan = plan_experiments(&model, &op, &options).unwrap();
            let text = mutate(&plan.to_json(), at, cut, &insert);
            let _ = Plan::from_json(&text);
            let _ = LocalModel::from_json(&text);
            let _ = perturbid_rs::ModelFile::from_json(&text, "fuzz.json");
        }
    }
}

#[test]
fn urdf_messages_say_where_and_what() {
    let urdf = with_limit(
        r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
        "revolute",
    );
    let bad_number = urdf.replace(r#"ixx="0.1""#, r#"ixx="0,1""#);
    assert_eq!(
        load(&bad_number).unwrap_err().to_string(),
        r#"arm.urdf: not a valid URDF: line 2: <inertia ixx="0,1">: '0,1' is not a number"#
    );
    let not_a_robot = "<model name=\"r\"><link name=\"a\"/></model>";
    assert_eq!(
        load(not_a_robot).unwrap_err().to_string(),
        "arm.urdf: not a valid URDF: the document's root element is <model>, expected <robot>"
    );
    let broken = urdf.replace("</joint>", "</jiont>");
    let e = load(&broken).unwrap_err().to_string();
    assert!(
        e.starts_with("arm.urdf: not a valid URDF: XML: ") && e.contains("3:"),
        "{e}"
    );
}

/// The messages users act on most, word for word: a change to any of them is deliberate.
#[test]
fn key_messages_word_for_word() {
    let says = |e: perturbid_rs::Error| e.to_string();
    // a URDF limit no joint can have
    let e = load(&with_limit(
        r#"<limit lower="-1" upper="1" effort="1" velocity="-1"/>"#,
        "revolute",
    ))
    .unwrap_err();
    assert_eq!(
        says(e),
        "arm.urdf:3: joint 'j1' <limit>: velocity -1 rad/s is not positive; a moving joint needs a positive speed limit"
    );
    // a robot that cannot move
    assert_eq!(
        says(load(&with_limit("", "fixed")).unwrap_err()),
        "arm.urdf: robot 'r' has no moving joint (every joint is fixed or locked); nothing can be identified"
    );
    // a plan that leaves the joint's range, and one too fast
    let model = robots::builtin("a465").unwrap();
    let mut q = TABLE2_Q.to_vec();
    q[1] = model.limits[1].upper - 0.01;
    let op = OperatingPoint::new(q, TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let e = plan_experiments(&model, &op, &PlanOptions::default()).unwrap_err();
    assert_eq!(
        says(e),
        "experiment 'G_static' of the plan: joint 'joint2' at t = 1.0900 s: position 1.571010 rad is outside [-1.570796, 1.570796] rad by 0.000213 rad; reduce the perturbation sizes or move the operating point away from the limit"
    );
    let mut qd = TABLE2_QD.to_vec();
    qd[0] = 0.99 * model.limits[0].velocity;
    let op = OperatingPoint::new(TABLE2_Q.to_vec(), qd, TABLE2_QDD.to_vec()).unwrap();
    let e = plan_experiments(&model, &op, &PlanOptions::default()).unwrap_err();
    assert_eq!(
        says(e),
        "experiment 'H' of the plan: joint 'joint1' at t = 3.1640 s: velocity 3.143438 rad/s is outside the limit +-3.141600 rad/s by 0.001838 rad/s; reduce the perturbation sizes or move the operating point away from the limit"
    );
    // perturbations below what any encoder reads, however they are asked for
    let table2 =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let tiny = PlanOptions {
        sizes: Sizes {
            velocity: Size::Fraction(1e-300),
            ..Sizes::default()
        },
        ..PlanOptions::default()
    };
    assert_eq!(
        says(plan_experiments(&model, &table2, &tiny).unwrap_err()),
        "velocity size[0]: perturbation size 3.1416e-300; expected at least 1e-9, a hundredth of the finest encoders' step: a smaller one moves no torque a sensor reads"
    );
    let tiny = PlanOptions {
        sizes: Sizes {
            position: Size::Absolute(vec![0.01, 0.01, 1e-12, 0.01, 0.01, 0.01]),
            ..Sizes::default()
        },
        ..PlanOptions::default()
    };
    assert!(says(plan_experiments(&model, &table2, &tiny).unwrap_err())
        .starts_with("position size[2]: perturbation size 1e-12; expected at least 1e-9"));
    let mut qd = TABLE2_QD.to_vec();
    qd[3] = 1e-12;
    let crawling = OperatingPoint::new(TABLE2_Q.to_vec(), qd, TABLE2_QDD.to_vec()).unwrap();
    let keep = PlanOptions {
        keep_velocity_sign: true,
        ..PlanOptions::default()
    };
    assert!(says(plan_experiments(&model, &crawling, &keep).unwrap_err())
        .contains("joint 'joint4' has qd* = 1e-12: every velocity perturbation of a size a sensor reads reverses it"));
    // a file of an output set whose writing was killed
    let d = common::temp_dir::TempDir::new("words");
    std::fs::write(d.join("x.csv"), "t,q1,tau1\n0,0,0\n").unwrap();
    std::fs::write(
        d.join("run.manifest.json"),
        r#"{"format": "perturbid.manifest", "version": 1, "set": "run", "state": "writing", "files": ["x.csv"], "replacing": []}"#,
    )
    .unwrap();
    let e = perturbid_rs::io::read_text(d.join("x.csv")).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::File);
    assert_eq!(
        says(e).replace(&d.display().to_string(), "DIR"),
        "DIR/x.csv belongs to an output set whose writing was interrupted (see DIR/run.manifest.json): it may mix old and new files; run the command that wrote it again"
    );
}

#[test]
fn overflow_deep_in_a_batch_names_its_sample() {
    // the batch engine checks its results block by block as it writes them (and, over
    // PARALLEL_BATCH samples, chunk by chunk on the threads): the failing sample is named
    // wherever it falls, on the calling thread and in parallel
    use perturbid_rs::{parallel, Gravity, States};
    let model = robots::builtin("a465").unwrap();
    let (n, p) = (model.nv, 10 * model.nbodies());
    for (k, bad) in [
        (300, 250),
        (
            parallel::PARALLEL_BATCH + 700,
            parallel::PARALLEL_BATCH + 613,
        ),
    ] {
        let q = vec![0.2; k * n];
        let mut qd = vec![0.1; k * n];
        qd[bad * n + 1] = 1e200;
        let qdd = vec![0.0; k * n];
        let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
        let mut ws = parallel::Workspace::new(&model);
        let mut y = vec![0.0; k * n * p];
        let e =
            parallel::regressor(&model, &mut ws, &states, Gravity::Included, &mut y).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("regressor (sample {bad}): ")),
            "{e}"
        );
        let mut tau = vec![0.0; k * n];
        let e = parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("rnea (sample {bad}): tau is")),
            "{e}"
        );
        // the same batch without the bad sample passes, every value finite
        qd[bad * n + 1] = 0.1;
        let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
        parallel::regressor(&model, &mut ws, &states, Gravity::Included, &mut y).unwrap();
        assert!(y.iter().all(|v| v.is_finite()));
    }
}

/// A Fourier excitation whose coefficients would sample to inf or NaN (finite, but their sum
/// past f64's range) is refused by joint and quantity, as are more harmonics than the limit.
#[test]
fn fourier_coefficients_past_the_range_of_f64_are_refused() {
    use nalgebra::DMatrix;
    use perturbid_rs::trajectory::FourierTrajectory;
    let ok = FourierTrajectory::new(
        1.0,
        vec![0.0; 2],
        DMatrix::zeros(2, 3),
        DMatrix::zeros(2, 3),
    );
    assert!(ok.is_ok());
    let mut a = DMatrix::zeros(2, 3);
    a[(1, 2)] = 1e308;
    let mut b = DMatrix::zeros(2, 3);
    b[(1, 2)] = 1e308;
    let e = FourierTrajectory::new(1.0, vec![0.0; 2], a, b)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("joint 2") && e.contains("beyond f64's range"),
        "{e}"
    );
    let mut a = DMatrix::zeros(2, 3);
    a[(0, 2)] = 1e306;
    let e = FourierTrajectory::new(1e3, vec![0.0; 2], a.clone(), DMatrix::zeros(2, 3))
        .unwrap_err()
        .to_string();
    assert!(e.contains("joint 1") && e.contains("accelerations"), "{e}");
    // the same coefficients at a slower pulsation sample finitely
    let t = FourierTrajectory::new(1.0, vec![0.0; 2], a, DMatrix::zeros(2, 3)).unwrap();
    let s = t.sample_periods(1.0, 10.0).unwrap();
    assert!(s.q.iter().chain(&s.qd).chain(&s.qdd).all(|v| v.is_finite()));
    let e = FourierTrajectory::new(
        1.0,
        vec![0.0],
        DMatrix::zeros(1, 1001),
        DMatrix::zeros(1, 1001),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("harmonics: 1001"), "{e}");
    // base frequencies from 1 mHz to 1 kHz, as designs take them (a period of 6e-300 s was
    // taken, and sampled accelerations of 3e299)
    let with = |w_f: f64| {
        FourierTrajectory::new(w_f, vec![0.0], DMatrix::zeros(1, 1), DMatrix::zeros(1, 1))
    };
    let tau = std::f64::consts::TAU;
    assert!(with(tau * 1e-3).is_ok() && with(tau * 1e3).is_ok());
    for (w_f, says) in [
        (1e300, "base pulsation: 1e300 rad/s (a base frequency of 1.5915494309189535e299 Hz); expected a base frequency in [0.001, 1000] Hz"),
        (1e-9, "base pulsation: 1e-9 rad/s (a base frequency of 1.5915494309189535e-10 Hz)"),
        (0.0, "base pulsation: 0 rad/s"),
    ] {
        let e = with(w_f).unwrap_err().to_string();
        assert!(e.starts_with(says), "{e}");
    }
}

/// Model files edited by hand: standard errors, residuals and noise levels are magnitudes
/// (negative ones refused by field and entry), condition numbers at least 1, the operating
/// points of the joints' length; coefficients too large to predict with give an error, not inf.
#[test]
fn model_documents_hold_magnitudes_where_they_say_so() {
    use perturbid_rs::direct::{identify_base_parameters, BaseModel, BaseOptions};
    use perturbid_rs::local::{identify_local, IdentifyOptions, LocalModel};
    use perturbid_rs::{simulate_plan, SimulationOptions, States};
    let model = robots::builtin("a465").unwrap();
    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let mut sim = SimulationOptions::new(&model);
    sim.torque_noise = vec![0.01; 6];
    let recs = simulate_plan(&model, &plan, &sim).unwrap();
    let local = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
    let text = local.to_json();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        f(&mut v);
        LocalModel::from_json(&v.to_string())
    };
    for (f, says) in [
        (
            &(|v: &mut serde_json::Value| v["h"]["stderr"][2][3] = serde_json::json!(-0.5))
                as &dyn Fn(&mut serde_json::Value),
            "H.stderr[2][3] is -0.5, expected a finite number >= 0 or null",
        ),
        (
            &|v: &mut serde_json::Value| v["d"]["residual_rms"][1] = serde_json::json!(-1e19),
            "D.residual_rms[1] is -1e19, expected a finite number >= 0",
        ),
        (
            &|v: &mut serde_json::Value| v["torque_stderr"][0] = serde_json::json!(-1),
            "torque_stderr[0] is -1",
        ),
        (
            &|v: &mut serde_json::Value| v["g"]["cond"] = serde_json::json!(0.5),
            "G.cond is 0.5, expected a condition number >= 1",
        ),
        (
            &|v: &mut serde_json::Value| {
                v["planned_op"]["q"].as_array_mut().unwrap().pop();
            },
            "planned_op.q has 5 entries, torque has 6",
        ),
    ] {
        let e = edit(f).unwrap_err().to_string();
        assert!(e.contains(says), "{says}: {e}");
    }
    // an unknown standard error (null) is fine
    edit(&|v| v["d"]["stderr"][0][0] = serde_json::Value::Null).unwrap();
    // D* with an entry of 1e308: refused on load, beyond any robot's; built in memory, a
    // prediction away from the operating point overflows and is refused
    let e = edit(&|v| v["d"]["matrix"][0][0] = serde_json::json!(1e308)).unwrap_err();
    assert!(
        e.to_string()
            .contains("d.matrix[0][0] is 1e308; numbers of a local model are at most 1e9"),
        "{e}"
    );
    let mut huge = edit(&|_| {}).unwrap();
    huge.d.as_mut().unwrap().matrix[(0, 0)] = 1e308;
    let qdd: Vec<f64> = TABLE2_QDD.iter().map(|a| a + 10.0).collect();
    let states = States::single(6, &TABLE2_Q, Some(&TABLE2_QD), Some(&qdd)).unwrap();
    let e = huge.predict(&states).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Numerical, "{e}");
    assert!(
        e.to_string()
            .contains("torque of joint 1 at sample 0 is inf"),
        "{e}"
    );
    assert!(huge
        .predict(&States::single(6, &TABLE2_Q, Some(&TABLE2_QD), Some(&TABLE2_QDD)).unwrap())
        .is_ok());
    // a base-parameter model with a negative noise level
    let k = 300;
    let x = |i: usize, f: f64| ((i * 7) as f64 * f).sin();
    let q: Vec<f64> = (0..k * 6).map(|i| x(i, 0.37)).collect();
    let qd: Vec<f64> = (0..k * 6).map(|i| x(i, 0.53)).collect();
    let qdd: Vec<f64> = (0..k * 6).map(|i| x(i, 0.71)).collect();
    let states = States::new(6, &q, Some(&qd), Some(&qdd)).unwrap();
    let mut tau = vec![0.0; k * 6];
    perturbid_rs::parallel::rnea(
        &model,
        &mut perturbid_rs::parallel::Workspace::new(&model),
        &states,
        perturbid_rs::Gravity::Included,
        &mut tau,
    )
    .unwrap();
    for (i, t) in tau.iter_mut().enumerate() {
        *t += 0.01 * ((i * 13) as f64).sin();
    }
    let fit = identify_base_parameters(&model, &states, &tau, &BaseOptions::default()).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&fit.to_json()).unwrap();
    assert!(BaseModel::from_json(&v.to_string()).is_ok());
    v["sigma"][4] = serde_json::json!(-0.1);
    let e = BaseModel::from_json(&v.to_string())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sigma[4] is -0.1"), "{e}");
    // its parameter map and layout: sizes, each parameter once, numbers within any robot's
    let value: serde_json::Value = serde_json::from_str(&fit.to_json()).unwrap();
    type Edit = fn(&mut serde_json::Value);
    let edits: [(Edit, &str); 5] = [
        (
            |v| v["base"]["layout"]["nv"] = serde_json::json!(9223372036854775807u64),
            "base.layout is for 9223372036854775807 joints",
        ),
        (
            |v| v["base"]["layout"]["nbodies"] = serde_json::json!(7),
            "7 bodies with joint terms [",
        ),
        (
            |v| v["base"]["dropped"][0] = v["base"]["kept"][0].clone(),
            "must list each of the",
        ),
        (
            |v| v["base"]["k"][0][0] = serde_json::json!(1e300),
            "base.k[0][0] is 1e300; numbers of a base-parameter model are at most 1e9",
        ),
        (
            |v| v["theta"][2] = serde_json::json!(-1e20),
            "theta[2] is -1e20",
        ),
    ];
    common::refused_on_load::<BaseModel>(&value, &edits);
    // a parameter renamed: the model is refused on another robot's, and on its own
    let mut v = value.clone();
    v["base"]["layout"]["names"][0] = serde_json::json!("link9.m");
    let renamed = BaseModel::from_json(&v.to_string()).unwrap();
    let e = renamed.predict(&model, &states).unwrap_err().to_string();
    assert!(
        e.contains("the model's parameters are not the robot's: 'link9.m' where"),
        "{e}"
    );
    // its base parameters are combinations that hold for one robot's kinematics: on a robot
    // with the same names but link 3 a millimetre longer it is refused, naming a column; on
    // one with other inertias and the same kinematics it is used
    let text = perturbid_rs::robots::a465::urdf("kinsheel2010").unwrap();
    let (from, to) = ("xyz=\"0 0 0.3048\"", "xyz=\"0 0 0.3058\"");
    assert_eq!(text.matches(from).count(), 1);
    let longer = model_from_urdf_str(
        &text.replace(from, to),
        "a465.urdf",
        &LoadOptions::default(),
    )
    .unwrap();
    let e = fit.predict(&longer, &states).unwrap_err().to_string();
    assert!(
        e.contains("the saved base parameters do not hold for 'a465_kinsheel2010': its regressor's column 'link3.m' differs from the combination"),
        "{e}"
    );
    assert!(
        e.contains("Was the model identified on other kinematics"),
        "{e}"
    );
    let other_inertias = perturbid_rs::robots::a465::model("physical").unwrap();
    assert_eq!(other_inertias.joint_names, model.joint_names);
    assert!(fit.predict(&other_inertias, &states).is_ok());
    // and a combination edited by 1 % in the file is refused the same way
    let (i, d) = fit.base.k.iamax_full();
    let mut v = value.clone();
    v["base"]["k"][i][d] = serde_json::json!(fit.base.k[(i, d)] * 1.01);
    let edited = BaseModel::from_json(&v.to_string()).unwrap();
    let e = edited.predict(&model, &states).unwrap_err().to_string();
    assert!(e.contains("the saved base parameters do not hold"), "{e}");
    assert!(edited.mass_matrix(&model, &TABLE2_Q).is_err());
    assert!(fit.mass_matrix(&model, &TABLE2_Q).is_ok());
}

/// Files are read only up to a bound: a document larger than 256 MiB is refused before it is
/// read, and a device that never ends (`/dev/zero`) is read no further than the bound instead of
/// until memory runs out.
#[test]
fn files_are_read_only_up_to_a_bound() {
    use perturbid_rs::rehearsal::TrueRobot;
    let dir = common::temp_dir::TempDir::new("big");
    let big = dir.join("big.json");
    // sparse: no disk space, 300 MiB of length
    std::fs::File::create(&big)
        .unwrap()
        .set_len(300 << 20)
        .unwrap();
    let e = Plan::load(&big).unwrap_err().to_string();
    assert!(e.contains("big.json: larger than 256 MB"), "{e}");
    let e = perturbid_rs::model_from_urdf_file(&big, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("larger than 256 MB, the most read for a document"),
        "{e}"
    );
    if std::path::Path::new("/dev/zero").exists() {
        let e = TrueRobot::load("/dev/zero").unwrap_err().to_string();
        assert!(e.starts_with("/dev/zero: larger than 256 MB"), "{e}");
    }
}

/// Numbers that would allocate without bound, divide into inf or describe no sensor are
/// refused by name, shown as given (`1e-300`, not 300 digits): an excitation's base frequency
/// (its period of 1e300 s aborted on allocation) and sampling rate, an excitation that cannot
/// move within its margin (its cond(Phi_base) of inf was saved), a simulation's noise and
/// encoder resolution, and the clock offset searched for.
#[test]
fn numbers_out_of_range_are_refused_as_given() {
    use perturbid_rs::direct::{design_excitation, ExcitationOptions};
    use perturbid_rs::local::{identify_local, CrossingTimes, IdentifyOptions};
    use perturbid_rs::trajectory::FourierTrajectory;
    use perturbid_rs::{simulate_plan, SimulationOptions};
    let model = robots::builtin("a465").unwrap();
    let n = model.nv;
    let e = design_excitation(
        &model,
        &ExcitationOptions {
            base_frequency: 1e-300,
            ..ExcitationOptions::default()
        },
        None,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "base_frequency: 1e-300; expected a finite number in [0.001, 1000]"
    );
    let e = design_excitation(
        &model,
        &ExcitationOptions {
            margin: 1e-9,
            max_evaluations: 2,
            ..ExcitationOptions::default()
        },
        None,
    )
    .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Numerical, "{e}");
    assert!(
        e.to_string()
            .contains("does not excite every base parameter")
            && e.to_string().contains("margin 1e-9"),
        "{e}"
    );
    let traj = FourierTrajectory::new(
        0.2 * std::f64::consts::PI,
        vec![0.0; n],
        nalgebra::DMatrix::from_element(n, 2, 0.1),
        nalgebra::DMatrix::zeros(n, 2),
    )
    .unwrap();
    for (periods, rate, says) in [
        (
            1.0,
            0.0,
            "rate: 0; expected a positive finite number up to 1e7",
        ),
        (1.0, -5.0, "rate: -5;"),
        (1.0, 1e300, "rate: 1e300;"),
        (f64::NAN, 100.0, "periods: NaN;"),
        (
            1e9,
            100.0,
            "periods: 1e9 periods of 10 s at 100 Hz give 1.000e12 samples",
        ),
    ] {
        let e = traj.sample_periods(periods, rate).unwrap_err().to_string();
        assert!(e.starts_with(says), "{periods} {rate}: {e}");
    }
    assert_eq!(traj.sample_periods(1.0, 100.0).unwrap().t.len(), 1001);

    let op =
        OperatingPoint::new(TABLE2_Q.to_vec(), TABLE2_QD.to_vec(), TABLE2_QDD.to_vec()).unwrap();
    let plan = plan_experiments(&model, &op, &PlanOptions::default()).unwrap();
    let set = |f: &dyn Fn(&mut SimulationOptions)| {
        let mut o = SimulationOptions::new(&model);
        f(&mut o);
        simulate_plan(&model, &plan, &o).map(|_| ())
    };
    for (e, says) in [
        (
            set(&|o| o.torque_noise = vec![1e300; n]),
            "torque_noise[0]: 1e300; expected a value in [0, 1000000]",
        ),
        (
            set(&|o| o.position_noise = vec![2.0; n]),
            "position_noise[0]: 2; expected a value in [0, 1]",
        ),
        (
            // positions divided by 1e-320 rad a count were inf
            set(&|o| o.quantization = vec![1e-320; n]),
            "quantization[0]: 1e-320; expected 0 (none) or a value in [1e-12, 1]",
        ),
        (
            // every position read 0: a robot that never moved
            set(&|o| o.quantization = vec![1e7; n]),
            "quantization[0]: 10000000; expected 0 (none)",
        ),
    ] {
        let e = e.unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Input, "{e}");
        assert!(e.to_string().starts_with(says), "{e}");
    }
    let recs = simulate_plan(&model, &plan, &SimulationOptions::new(&model)).unwrap();
    for (max_shift, says) in [
        (
            -1.0,
            "max_shift: -1; expected a positive number of seconds".to_string(),
        ),
        (f64::NAN, "max_shift: NaN;".to_string()),
    ] {
        let options = IdentifyOptions {
            times: CrossingTimes::Detected { max_shift },
            ..IdentifyOptions::default()
        };
        let e = identify_local(&plan, &recs, &options)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&says), "{e}");
    }
    // a huge tolerance searches only the offsets at which the recording holds every window
    let options = IdentifyOptions {
        times: CrossingTimes::Detected { max_shift: 1e300 },
        ..IdentifyOptions::default()
    };
    let m = identify_local(&plan, &recs, &options).unwrap();
    assert!(m.diagnostics.offsets.iter().all(|o| o.offset.abs() < 1e-9));
}

/// Accelerations 1e200 or positions 1e150 times too large (finite, but squares on the way
/// overflow): the fit ends, as
/// every decomposition on the way is bounded (nalgebra's SVD and eigensolvers spun forever
/// on the infinities), and names the log as not matching the robot. Run in a thread with a
/// deadline, so that a regression fails instead of hanging the suite.
#[test]
fn overflowing_data_ends_the_fit_instead_of_hanging_it() {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let log = common::a465_log();
        let times = |v: &[f64], s: f64| v.iter().map(|a| a * s).collect::<Vec<f64>>();
        let model = perturbid_rs::robots::a465::model("physical").unwrap();
        let fit = |q: &[f64], qdd: &[f64], tau: &[f64]| {
            let states = perturbid_rs::States::new(6, q, Some(&log.qd), Some(qdd)).unwrap();
            let options = perturbid_rs::direct::BaseOptions::default();
            perturbid_rs::direct::identify_base_parameters(&model, &states, tau, &options)
                .map(|f| f.warnings())
                .map_err(|e| e.to_string())
        };
        let _ = send.send([
            // accelerations 1e200 times too large, positions 1e150 times (both hung)
            fit(&log.q, &times(&log.qdd, 1e200), &log.tau),
            fit(&times(&log.q, 1e150), &log.qdd, &log.tau),
            // torques 1e300 times too large: residuals past f64's range, refused by joint
            fit(&log.q, &log.qdd, &times(&log.tau, 1e300)),
        ]);
    });
    let [accelerations, positions, torques] = receive
        .recv_timeout(std::time::Duration::from_secs(120))
        .expect("the fits ended within 2 minutes");
    for w in [accelerations, positions] {
        let w = w.unwrap();
        assert!(
            w.iter().any(|w| w.contains("does not match the robot")),
            "{w:?}"
        );
    }
    let e = torques.unwrap_err();
    assert!(
        e.contains("the residuals of joint 'joint1' overflow"),
        "{e}"
    );
}
