//! Studies: a small study agrees with the methods called one by one and with the true plant's
//! analytic linearisation; identical seeds give identical files; a rerun skips finished
//! cases and a journal cut short resumes; bad configurations name the line.

use std::path::Path;

use perturbid_rs::data::Data;
use perturbid_rs::local::{
    identify_local, plan_experiments, IdentifyOptions, OperatingPoint, PlanOptions,
};
use perturbid_rs::rehearsal::{rehearse_plan, TrueRobot};
use perturbid_rs::study::{run_study, Study, StudyConfig};
use perturbid_rs::{linearize, Gravity};

const STUDY: &str = r#"
name = "test"
seeds = 2
methods = ["local_separated", "direct_ols", "global_linear"]

[[robots]]
name = "a465"

[[points]]
name = "paper"
q = [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0]
qd = [0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140]
qdd = [-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710]

[direct]
max_evaluations = 40
periods = 1

[evaluation]
distances = [1, 4]
samples = 4
"#;

#[path = "common/temp_dir.rs"]
mod temp_dir;

fn tmp(name: &str) -> temp_dir::TempDir {
    temp_dir::TempDir::new(&format!("study-{name}"))
}

fn study() -> Study {
    let config: StudyConfig = perturbid_rs::io::config::parse_toml("s.toml", STUDY).unwrap();
    Study::resolve(config, Path::new("."), "s.toml").unwrap()
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

/// (method, metric, distance) -> value for one case, from results.csv.
fn values(csv: &str, case: usize) -> Vec<(String, String, String, f64)> {
    let mut r = csv::Reader::from_reader(csv.as_bytes());
    r.records()
        .map(|x| x.unwrap())
        .filter(|x| x[0] == case.to_string())
        .map(|x| {
            (
                x[11].to_string(),
                x[12].to_string(),
                x[13].to_string(),
                x[14].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn a_study_agrees_with_the_methods_one_by_one() {
    let s = study();
    assert_eq!(s.len(), 2);
    let out = tmp("agree");
    let mut seen = vec![];
    run_study(&s, &out, &mut |d, t| seen.push((d, t))).unwrap();
    assert_eq!(seen.first(), Some(&(0, 2)));
    assert_eq!(seen.last(), Some(&(2, 2)));
    let csv = read(&out.join("results.csv"));
    for case in 0..2 {
        let c = s.case(case).unwrap();
        let v = values(&csv, case);
        let get = |m: &str, k: &str| {
            v.iter()
                .find(|x| x.0 == m && x.1 == k && x.2.is_empty())
                .map(|x| x.3)
        };
        // the local method called by hand: plan, rehearse on the ideal robot, identify
        let model = perturbid_rs::robots::builtin("a465").unwrap();
        let p = &s.robots[0].points[0];
        let op = OperatingPoint::new(p.q.clone(), p.qd.clone(), p.qdd.clone()).unwrap();
        let plan = plan_experiments(
            &model,
            &op,
            &PlanOptions {
                design: c.design,
                seed: c.seed,
                ..PlanOptions::default()
            },
        )
        .unwrap();
        let ideal = TrueRobot {
            gravity: perturbid_rs::Gravity::Excluded,
            seed: c.seed,
            ..TrueRobot::default()
        };
        let recs = rehearse_plan(&model, &ideal, &plan).unwrap();
        let local = identify_local(&plan, &recs, &IdentifyOptions::default()).unwrap();
        // the true plant's linearisation, analytic (the study differentiates the plant numerically)
        let mut data = Data::new(&model);
        let lin = linearize(&model, &mut data, &op.q, &op.qd, &op.qdd, Gravity::Excluded).unwrap();
        let rel =
            |a: &nalgebra::DMatrix<f64>, b: &nalgebra::DMatrix<f64>| (a - b).norm() / b.norm();
        let d_rel = rel(&local.d.as_ref().unwrap().matrix, &lin.d);
        let g_rel = rel(&local.g.as_ref().unwrap().matrix, &lin.g);
        let study_d = get("local_separated", "D_rel").unwrap();
        let study_g = get("local_separated", "G_rel").unwrap();
        assert!(
            (study_d - d_rel).abs() <= 1e-6 * d_rel.max(1e-3),
            "D_rel {study_d} vs {d_rel}"
        );
        assert!(
            (study_g - g_rel).abs() <= 1e-6 * g_rel.max(1e-3),
            "G_rel {study_g} vs {g_rel}"
        );
        let time: f64 = plan.experiments.iter().map(|e| e.duration()).sum();
        assert_eq!(get("local_separated", "robot_time"), Some(time));
        // noise-free on the model itself: the base-parameter model is exact
        assert!(get("direct_ols", "D_rel").unwrap() < 1e-6);
        // the relative errors grow with distance for the local model (linearisation)
        let at = |d: &str| {
            v.iter()
                .find(|x| x.0 == "local_separated" && x.1 == "rms_rel" && x.2 == d)
                .unwrap()
                .3
        };
        assert!(at("4") > at("1"), "{v:?}");
    }
    let summary = read(&out.join("summary.csv"));
    assert!(summary.starts_with("robot,speed_class,true_robot,noise,design,k,perturbation,method,metric,distance,count,median,p05,p95\n"));
    assert!(read(&out.join("summary.md")).contains("| local_separated |"));
    let figure = read(&out.join("error_vs_distance.svg"));
    assert!(figure.starts_with("<svg"));
    // a median curve and its 5-95 % band for every method of the panel
    assert_eq!(
        figure.matches("<polygon").count(),
        figure.matches("<polyline").count()
    );
    assert!(figure.contains("<polygon"));
}

#[test]
fn identical_seeds_identical_files_and_reruns_resume() {
    let s = study();
    let (a, b) = (tmp("same-a"), tmp("same-b"));
    run_study(&s, &a, &mut |_, _| {}).unwrap();
    run_study(&s, &b, &mut |_, _| {}).unwrap();
    for f in ["results.csv", "summary.csv", "summary.md"] {
        assert_eq!(read(&a.join(f)), read(&b.join(f)), "{f}");
    }
    // a rerun finds every case done
    let mut first = None;
    run_study(&s, &a, &mut |d, _| {
        first.get_or_insert(d);
    })
    .unwrap();
    assert_eq!(first, Some(2));
    // a journal cut short in its last line: that case is rerun, the result is the same
    let journal = a.join("cases.jsonl");
    let text = read(&journal);
    let cut = text.trim_end().rfind('\n').unwrap() + 30;
    std::fs::write(&journal, &text[..cut]).unwrap();
    let mut first = None;
    run_study(&s, &a, &mut |d, _| {
        first.get_or_insert(d);
    })
    .unwrap();
    assert_eq!(first, Some(1));
    assert_eq!(read(&a.join("results.csv")), read(&b.join("results.csv")));
    // a journal line that is not a result, before the last: named
    std::fs::write(&journal, format!("garbage\n{}", read(&journal))).unwrap();
    let e = run_study(&s, &a, &mut |_, _| {}).unwrap_err().to_string();
    assert!(e.contains("cases.jsonl") && e.contains("line 1"), "{e}");
}

#[test]
fn bad_configurations_name_the_place() {
    let parse = |t: &str| -> String {
        match perturbid_rs::io::config::parse_toml::<StudyConfig>("s.toml", t) {
            Err(e) => e.to_string(),
            Ok(c) => Study::resolve(c, Path::new("."), "s.toml")
                .unwrap_err()
                .to_string(),
        }
    };
    let e = parse(&STUDY.replace("seeds = 2", "seeds = 2\nseed = 1"));
    assert!(
        e.starts_with("s.toml:4:1: ") && e.contains("unknown field `seed`"),
        "{e}"
    );
    let e = parse(&format!(
        "{STUDY}\n[sample_points]\ncount = 1000000000000\n"
    ));
    assert!(
        e.contains("sample_points.count: 1000000000000; at most 10000"),
        "{e}"
    );
    let e = parse(&format!("{STUDY}\n[local]\nk = [4, 99999999]\n"));
    assert!(e.contains("local.k: 99999999; at most 10000"), "{e}");
    let e = parse(&STUDY.replace("seeds = 2", "seeds = 0"));
    assert!(e.contains("s.toml, seeds: 0; expected 1..="), "{e}");
    let e = parse(&STUDY.replace("distances = [1, 4]", "distances = [1, -4]"));
    assert!(e.contains("evaluation.distances: -4"), "{e}");
    let e = parse(&STUDY.replace("name = \"a465\"", "name = \"b999\""));
    assert!(e.contains("unknown robot 'b999'"), "{e}");
    let e = parse(&STUDY.replace("q = [0.7854, ", "q = ["));
    assert!(
        e.contains("no operating point for robot 'a465' (6 joints)"),
        "{e}"
    );
    let e = parse(&STUDY.replace(
        "methods = [\"local_separated\",",
        "methods = [\"local_magic\",",
    ));
    assert!(
        e.starts_with("s.toml:4:") && e.contains("local_magic"),
        "{e}"
    );
    // a value listed twice would run its cases twice; multiples of the perturbations past
    // 100; a point outside the robot's limits
    for (from, to, says) in [
        (
            "distances = [1, 4]",
            "distances = [1, 4, 1]",
            "evaluation.distances: '1' is listed twice",
        ),
        (
            "methods = [\"local_separated\",",
            "methods = [\"local_separated\", \"local_separated\",",
            "methods: 'local_separated' is listed twice",
        ),
        (
            "name = \"a465\"",
            "name = \"a465\"\n[[robots]]\nname = \"a465\"",
            "robots: 'a465' is listed twice",
        ),
        (
            "distances = [1, 4]",
            "distances = [1, 1e308]",
            "evaluation.distances: 1e308; expected at most 100",
        ),
        (
            "samples = 4",
            "samples = 4\n[local]\nperturbation = [1, 500]",
            "local.perturbation: 500; expected at most 100",
        ),
        (
            "samples = 4",
            "samples = 4\n[sample_points]\ncount = 2\nspeed_classes = []",
            "sample_points.speed_classes: an empty list",
        ),
        (
            "q = [0.7854, ",
            "q = [1e308, ",
            "points 'paper': operating point q[0] (joint 'joint1'): 1e308 is outside",
        ),
        // names label the report: blank or multi-line ones would leave rows unreadable
        (
            "name = \"test\"",
            "name = \"  \"",
            "s.toml, name: name \"  \": expected a name to show in the report, on one line",
        ),
        (
            "name = \"paper\"",
            "name = \"pa\\nper\"",
            "points: name \"pa\\nper\": expected a name",
        ),
    ] {
        let e = parse(&STUDY.replace(from, to));
        assert!(e.contains(says), "{says}: {e}");
    }
    let e = parse(&format!("{STUDY}\n[[true_robots]]\nname = \"x\"\ndocument = {{ payload = {{ link = \"nowhere\", mass = 1.0, com = [0,0,0], inertia = [0,0,0,0,0,0] }} }}\n"));
    assert!(
        e.contains("true_robots 'x'") && e.contains("nowhere"),
        "{e}"
    );
}

#[test]
fn true_robots_sweep_over_their_parameters() {
    let text = format!(
        "{STUDY}\n[[true_robots]]\nname = \"payload\"\ndocument = {{ gravity = false, payload = {{ link = \"link6\", mass = 1.0, com = [0, 0, 0.06], inertia = [0.002, 0, 0, 0.002, 0, 0.001] }} }}\nsweep = {{ \"payload.mass\" = [0.5, 2.0], \"friction.viscous\" = [[0.1, 0.1, 0.1, 0.1, 0.1, 0.1]] }}\n"
    );
    let config: StudyConfig = perturbid_rs::io::config::parse_toml("s.toml", &text).unwrap();
    let s = Study::resolve(config, Path::new("."), "s.toml").unwrap();
    let names: Vec<&str> = s.true_robots.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "payload[friction.viscous=[0.1,0.1,0.1,0.1,0.1,0.1],payload.mass=0.5]",
            "payload[friction.viscous=[0.1,0.1,0.1,0.1,0.1,0.1],payload.mass=2.0]"
        ]
    );
    assert_eq!(s.true_robots[1].1.payload.as_ref().unwrap().mass, 2.0);
    assert_eq!(
        s.true_robots[0].1.friction.viscous.as_deref(),
        Some(&[0.1; 6][..])
    );
    assert_eq!(s.len(), 4); // 1 point x 2 true robots x 2 seeds
                            // a path that does not fit the document is named
    let bad = |sweep: &str| -> String {
        let t = format!("{STUDY}\n[[true_robots]]\nname = \"p\"\nsweep = {sweep}\n");
        let c: StudyConfig = perturbid_rs::io::config::parse_toml("s.toml", &t).unwrap();
        Study::resolve(c, Path::new("."), "s.toml")
            .unwrap_err()
            .to_string()
    };
    let e = bad("{ \"friction.viscous.7\" = [1.0] }");
    assert!(
        e.contains("true_robots 'p[friction.viscous.7=1.0]'") && e.contains("friction.viscous"),
        "{e}"
    );
    let e = bad("{ \"seed.x\" = [1.0] }");
    assert!(
        e.contains("s.toml, true_robots 'p', sweep: 'seed.x'")
            && e.contains("neither a table nor a list"),
        "{e}"
    );
    let e = bad("{ \"payload.weight\" = [1.0] }");
    assert!(
        e.contains("true_robots 'p[payload.weight=1.0]'") && e.contains("weight"),
        "{e}"
    );
    let e = bad("{ \"seed\" = [] }");
    assert!(e.contains("'seed' has no values"), "{e}");
}

/// The averaged direct method (Swevers' way) on a true robot with friction, a payload, torque
/// noise and encoder counts: it fits, its linearisation at the point about as close to the
/// plant's as the filtered log's by WLS on the reference states, and within one excitation
/// period it fails alone, saying why.
#[test]
fn the_averaged_direct_method_runs_on_a_noisy_robot_and_fails_alone_on_one_period() {
    let d = tmp("averaged");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/a465_true_robot.json"),
        d.join("robot.json"),
    )
    .unwrap();
    let config = |periods: u32| {
        STUDY
            .replace(
                r#"methods = ["local_separated", "direct_ols", "global_linear"]"#,
                r#"methods = ["direct_wls", "direct_averaged"]"#,
            )
            .replace("seeds = 2", "seeds = 1")
            .replace("periods = 1", &format!("periods = {periods}"))
            + "\n[[true_robots]]\nname = \"noisy\"\nfile = \"robot.json\"\n"
    };
    for (periods, fits) in [(3, true), (1, false)] {
        let text = config(periods);
        let config: StudyConfig = perturbid_rs::io::config::parse_toml("s.toml", &text).unwrap();
        let s = Study::resolve(config, &d, "s.toml").unwrap();
        let out = d.join(format!("out{periods}"));
        run_study(&s, &out, &mut |_, _| {}).unwrap();
        let csv = read(&out.join("results.csv"));
        let v = values(&csv, 0);
        let get = |m: &str, k: &str| {
            v.iter()
                .find(|x| x.0 == m && x.1 == k && x.2.is_empty())
                .map(|x| x.3)
        };
        match fits {
            true => {
                let (avg, wls) = (get("direct_averaged", "D_rel"), get("direct_wls", "D_rel"));
                let (avg, wls) = (avg.expect("averaged D_rel"), wls.expect("WLS D_rel"));
                assert!(avg < 2.0 * wls + 0.01, "averaged {avg}, WLS {wls}");
            }
            false => {
                assert_eq!(get("direct_averaged", "failed"), Some(1.0), "{v:?}");
                assert!(
                    csv.contains("at least 2 are needed to average them"),
                    "{csv}"
                );
            }
        }
    }
}
