//! `perturbid run PIPELINE.toml`: the example pipeline gives what the same commands typed by
//! hand give; mistakes are found before anything runs and named by line and column.

mod cli_support;
use cli_support::*;

use std::path::Path;

fn example(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples")
            .join(name),
    )
    .unwrap()
}

#[test]
fn the_example_pipeline_equals_the_commands_by_hand() {
    let d = tmp("pipeline-example");
    // the example and its input, in a folder of their own (relative paths follow the file)
    write(&d.join("p.toml"), &example("a465_direct_pipeline.toml"));
    write(
        &d.join("a465_true_robot.json"),
        &example("a465_true_robot.json"),
    );
    let run = bin().args(["run", s(&d.join("p.toml"))]).output().unwrap();
    assert!(run.status.success(), "{run:?}");
    // a clean rehearsal warns of nothing (its friction at the excitation's rests once logged
    // a one-sample dip that the log screening took for glitches)
    let warned = String::from_utf8_lossy(&run.stderr);
    assert!(!warned.contains("warning"), "{warned}");
    let out = String::from_utf8_lossy(&run.stdout);
    for k in 1..=6 {
        assert!(out.contains(&format!("== step {k}/6: ")), "{out}");
    }
    let o = d.join("out/a465_direct");
    for f in [
        "excitation.json",
        "log.csv",
        "base.json",
        "base.parameters.csv",
        "held_out/log.csv",
        "validation/residuals.csv",
        "validation/validation.svg",
    ] {
        assert!(o.join(f).is_file(), "{f} missing");
    }
    // the commands it prints with --dry-run, run by hand from the same folder
    let dry = ok(&["run", s(&d.join("p.toml")), "--dry-run"]);
    let lines: Vec<&str> = dry.lines().collect();
    assert_eq!(lines.len(), 6, "{dry}");
    assert!(lines[0].starts_with("perturbid excite "), "{dry}");
    let h = tmp("pipeline-by-hand");
    std::fs::create_dir_all(h.join("out/a465_direct")).unwrap();
    write(
        &h.join("a465_true_robot.json"),
        &example("a465_true_robot.json"),
    );
    let dir = s(&d).to_string() + "/";
    for line in &lines {
        // the same arguments, with the other folder's paths: no word holds a space here
        let args: Vec<String> = line
            .split(' ')
            .skip(1)
            .map(|w| w.replace(&dir, &(s(&h).to_string() + "/")))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        ok(&args);
    }
    for f in ["base.json", "validation/residuals.csv"] {
        assert_eq!(
            std::fs::read(o.join(f)).unwrap(),
            std::fs::read(h.join("out/a465_direct").join(f)).unwrap(),
            "{f} differs from the commands by hand"
        );
    }
}

#[test]
fn mistakes_are_found_before_anything_runs() {
    let d = tmp("pipeline-mistakes");
    let p = d.join("p.toml");
    let first = "[defaults]\nrobot = \"a465\"\n\n[[step]]\nrun = \"excite\"\nmax_evaluations = 20\nout = \"x\"\n\n";
    let cases: &[(&str, &[&str])] = &[
        // a wrong key in step 2: step 1 must not have run
        (
            "[[step]]\nrun = \"identify-direct\"\ndata = \"x/log.csv\"\nweigting = \"ols\"\n",
            &[
                "p.toml:12:12",
                "'weigting' is not an argument of 'identify-direct'",
                "weighting",
            ],
        ),
        (
            "[[step]]\nrun = \"fly\"\n",
            &["p.toml:10:7", "'fly' is not a command", "identify-direct"],
        ),
        (
            "[[step]]\nrun = \"run\"\n",
            &["'run' is not a command a pipeline can run"],
        ),
        ("[[step]]\nout = \"y\"\n", &["step 2", "no 'run' key"]),
        (
            "[[step]]\nrun = \"identify-direct\"\ndata = \"x/log.csv\"\nconsistent = \"yes\"\n",
            &[
                "p.toml:12:14",
                "'consistent' is a switch: write consistent = true",
            ],
        ),
        (
            "[[step]]\nrun = \"identify-direct\"\ndata = \"x/log.csv\"\nrate = true\n",
            &["p.toml:12:8", "'rate' takes a value, not true/false"],
        ),
        (
            "[[step]]\nrun = \"identify-direct\"\ndata = \"x/log.csv\"\nrate = \"fast\"\n",
            &["step 2", "invalid value 'fast' for '--rate <RATE>'"],
        ),
        (
            "[[step]]\nrun = \"identify-direct\"\n",
            &["step 2", "<DATA>"],
        ),
        (
            "[[step]]\nrun = \"identify-direct\"\ndata = \"x/log.csv\"\nrate = nan\n",
            &["p.toml:12:8", "expected a finite number"],
        ),
        (
            "[[step]]\nrun = \"info\"\nextra = [1, {a = 2}]\n",
            &["p.toml:11:9", "'extra' is not an argument"],
        ),
        (
            "[[step]]\nrun = \"info\"\n[oops]\n",
            &["p.toml:11:2", "unknown field `oops`"],
        ),
        ("[[step]\n", &["p.toml:9:"]),
    ];
    for (second, needles) in cases {
        write(&p, &format!("{first}{second}"));
        fails(&["run", s(&p)], needles);
        nothing_written(&d, "x");
    }
    write(
        &p,
        "[defaults]\nrobot = \"a465\"\nperiods = 3\n\n[[step]]\nrun = \"info\"\n",
    );
    fails(
        &["run", s(&p)],
        &["p.toml:3:11", "default 'periods' is taken by no step"],
    );
    write(&p, "[defaults]\nrobot = \"a465\"\n");
    fails(&["run", s(&p)], &["p.toml", "step"]);
    write(&p, "step = []\n");
    fails(&["run", s(&p)], &["no [[step]]: nothing to run"]);
}

#[test]
fn a_failing_step_names_itself_and_keeps_what_came_before() {
    let d = tmp("pipeline-failing");
    let p = d.join("p.toml");
    write(
        &p,
        "[defaults]\nrobot = \"a465\"\n\n[[step]]\nrun = \"excite\"\nmax_evaluations = 20\nout = \"x\"\n\n[[step]]\nrun = \"identify-direct\"\ndata = \"missing.csv\"\n",
    );
    fails(
        &["run", s(&p)],
        &[
            "p.toml:9:1, step 2 (identify-direct)",
            "missing.csv",
            "steps 1-1 finished and their outputs stand",
        ],
    );
    assert!(d.join("x/excitation.json").is_file());
}

#[test]
fn locks_and_robot_files_follow_the_pipeline() {
    let d = tmp("pipeline-lock");
    write(&d.join("arm.urdf"), ARM_WITH_FINGER);
    // the robot file beside the pipeline, the lock as a table: the finger held still
    write(
        &d.join("p.toml"),
        "[defaults]\nrobot = \"arm.urdf\"\nlock = { finger_joint = 0.01 }\n\n[[step]]\nrun = \"info\"\n",
    );
    let dry = ok(&["run", s(&d.join("p.toml")), "--dry-run"]);
    assert!(dry.contains("--lock=finger_joint=0.01"), "{dry}");
    assert!(dry.contains(&format!("{}/arm.urdf", s(&d))), "{dry}");
    let out = bin().args(["run", s(&d.join("p.toml"))]).output().unwrap();
    assert!(out.status.success() && out.stderr.is_empty(), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("1 degrees of freedom"));
    // the list form means the same
    write(
        &d.join("p.toml"),
        "[[step]]\nrun = \"info\"\nrobot = \"arm.urdf\"\nlock = [\"finger_joint=0.01\"]\n",
    );
    assert!(ok(&["run", s(&d.join("p.toml"))]).contains("1 degrees of freedom"));
}

/// A pipeline's numbers reach the command as they were written, short: 1e-320 was passed as
/// 320 digits; a whole number written 2.0 is still a count.
#[test]
fn numbers_pass_to_the_commands_short() {
    let d = tmp("pipeline-numbers");
    write(
        &d.join("p.toml"),
        "[[step]]\nrun = \"excite\"\nrobot = \"a465\"\nharmonics = 2.0\nmargin = 1e-320\nbase_frequency = 0.05\n",
    );
    let dry = ok(&["run", s(&d.join("p.toml")), "--dry-run"]);
    assert!(
        dry.contains("--harmonics=2 ")
            && dry.contains("--margin=1e-320 ")
            && dry.contains("--base-frequency=0.05 "),
        "{dry}"
    );
}

/// The operating point written out, as `--help` shows it: on the command line as JSON, in a
/// pipeline as a table or a JSON string, each gives the plan its file gives (the command line
/// took the JSON for a file's name, and a pipeline for one beside it).
#[test]
fn an_operating_point_written_out_plans_as_its_file() {
    let d = tmp("pipeline-op");
    let op = table2_op(&d);
    let json = std::fs::read_to_string(&op).unwrap();
    let plan = |out: &str| std::fs::read_to_string(d.join(out).join("plan.json")).unwrap();
    ok(&["plan", "a465", "--op", s(&op), "--out", s(&d.join("file"))]);
    ok(&["plan", "a465", "--op", &json, "--out", s(&d.join("inline"))]);
    assert_eq!(plan("inline"), plan("file"));
    let q = "[0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0]";
    let qd = "[0.089, -0.106, 0.022, 0.056, 0.011, 0.014]";
    let qdd = "[-0.155, -0.5, 0.034, -0.291, -0.008, 0.171]";
    write(
        &d.join("p.toml"),
        &format!("[[step]]\nrun = \"plan\"\nrobot = \"a465\"\nop = {{ q = {q}, qd = {qd}, qdd = {qdd} }}\nout = \"table\"\n\n[[step]]\nrun = \"plan\"\nrobot = \"a465\"\nop = '{json}'\nout = \"string\"\n"),
    );
    ok(&["run", s(&d.join("p.toml"))]);
    assert_eq!(plan("table"), plan("file"));
    assert_eq!(plan("string"), plan("file"));
    // a mistake in it is named as the operating point's, and nothing is written
    fails(
        &[
            "plan",
            "a465",
            "--op",
            r#"{"q": [0.1]}"#,
            "--out",
            s(&d.join("bad")),
        ],
        &[
            "--op (the operating point given as JSON)",
            "missing field `qd`",
        ],
    );
    assert!(!d.join("bad").exists());
    // a name that is neither a file nor JSON is still read as a file, and said missing
    fails(
        &[
            "plan",
            "a465",
            "--op",
            s(&d.join("none.json")),
            "--out",
            s(&d.join("bad")),
        ],
        &["none.json", "No such file"],
    );
}
