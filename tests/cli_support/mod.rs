//! What the command-line tests share: running the binary and checking its output.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_perturbid"))
}

#[path = "../common/temp_dir.rs"]
mod temp_dir;
pub use temp_dir::TempDir;

/// A fresh directory for one test's files, removed when the test is done with it (kept when
/// the test fails, for a look at what it wrote: the failure message names it).
pub fn tmp(name: &str) -> TempDir {
    TempDir::new(&format!("cli-{name}"))
}

/// Runs and expects success; returns stdout.
pub fn ok(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    let (so, se) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "perturbid {args:?} failed: {se}");
    so.into_owned()
}

/// Runs and expects success; returns stderr (the warnings).
pub fn warnings_of(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    let se = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "perturbid {args:?} failed: {se}");
    se
}

/// Runs and expects a one-line error containing every `needles`, no panic; returns stderr.
pub fn fails(args: &[&str], needles: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    let se = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "perturbid {args:?} should fail");
    assert!(
        !se.contains("panicked") && !se.contains("RUST_BACKTRACE"),
        "panic: {se}"
    );
    assert!(
        se.starts_with("perturbid: ") && se.trim_end().lines().count() == 1,
        "not one line: {se}"
    );
    for n in needles {
        assert!(se.contains(n), "'{n}' not in: {se}");
    }
    se
}

pub fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// No file named `name` and no temporary file in `dir`.
/// Writes the paper's Table 2 operating point to `dir/op.json` and returns its path.
pub fn table2_op(dir: &Path) -> PathBuf {
    let op = dir.join("op.json");
    write(
        &op,
        r#"{"q": [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0], "qd": [0.089, -0.106, 0.022, 0.056, 0.011, 0.014], "qdd": [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171]}"#,
    );
    op
}

/// Plans the nominal and D experiments of the A465 at Table 2 into `dir/plan`; returns the
/// path of its plan.json.
pub fn plan_nominal_and_d(dir: &Path) -> PathBuf {
    let op = table2_op(dir);
    let plan_dir = dir.join("plan");
    ok(&[
        "plan",
        "a465",
        "--op",
        s(&op),
        "--out",
        s(&plan_dir),
        "--experiments",
        "nominal,D",
    ]);
    plan_dir.join("plan.json")
}

pub fn nothing_written(dir: &Path, name: &str) {
    assert!(!dir.join(name).exists(), "{name} was written");
    let tmp = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .any(|e| e.file_name().to_string_lossy().ends_with(".tmp"));
    assert!(!tmp, "a temporary file was left in {}", dir.display());
}

/// A one-joint arm with a light prismatic finger (0.02 kg): the case of `--lock`.
pub const ARM_WITH_FINGER: &str = r#"<robot name="arm">
  <link name="base"/>
  <link name="upper"><inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="finger"><inertial><mass value="0.02"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="2" effort="50"/></joint>
  <joint name="finger_joint" type="prismatic"><parent link="upper"/><child link="finger"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" velocity="0.2" effort="20"/></joint>
</robot>"#;

/// An excitation of the A465 designed with `seed` (30 evaluations, sampled at 100 Hz) into
/// `dir/exc<seed>/`, and its log simulated at 200 Hz with 0.01 N m of torque noise into
/// `dir/log<seed>.csv`; returns the log's path.
pub fn excitation_log(dir: &Path, seed: u64) -> PathBuf {
    let exc = dir.join(format!("exc{seed}"));
    excite_a465(&exc, seed);
    let log = dir.join(format!("log{seed}.csv"));
    ok(&[
        "simulate",
        "a465",
        s(&exc.join("excitation.json")),
        "--out",
        s(&log),
        "--rate",
        "200",
        "--torque-noise",
        "0.01",
        "--seed",
        &seed.to_string(),
    ]);
    log
}

/// A 1.5 kg payload on the A465's last link, as a true robot's `payload` (JSON).
pub const TRUE_PAYLOAD: &str = r#"{"link": "link6", "mass": 1.5, "com": [0.01, 0.0, 0.06], "inertia": [0.004, 0, 0, 0.004, 0, 0.002]}"#;

/// The excitation of seed 1 (designed with 30 evaluations at 100 Hz) simulated at 500 Hz for
/// two periods on a true A465 with friction, 0.02 N m of torque noise and `payload` (JSON, or
/// none) into `dir/name`.
pub fn a465_log_carrying(dir: &Path, name: &str, payload: Option<&str>, seed: u64) -> PathBuf {
    let exc = dir.join("exc");
    if !exc.join("excitation.json").exists() {
        excite_a465(&exc, 1);
    }
    let truth = dir.join(format!("{name}.true.json"));
    let payload = payload.map_or(String::new(), |p| format!(r#""payload": {p},"#));
    write(
        &truth,
        &format!(
            r#"{{"format": "perturbid-true-robot/1", "seed": {seed}, {payload}
 "friction": {{"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], "coulomb": [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]}},
 "sensors": {{"torque_noise": [0.02, 0.02, 0.02, 0.01, 0.01, 0.01]}}}}"#
        ),
    );
    let out = dir.join(name);
    ok(&[
        "simulate",
        "a465",
        s(&exc.join("excitation.json")),
        "--true-robot",
        s(&truth),
        "--rate",
        "500",
        "--periods",
        "2",
        "--out",
        s(&out),
    ]);
    out
}

/// An excitation of the A465 designed with `seed` (30 evaluations, sampled at 100 Hz) into
/// the folder `exc`.
pub fn excite_a465(exc: &Path, seed: u64) {
    let seed = seed.to_string();
    ok(&[
        "excite",
        "a465",
        "--out",
        s(exc),
        "--max-evaluations",
        "30",
        "--rate",
        "100",
        "--seed",
        &seed,
    ]);
}
