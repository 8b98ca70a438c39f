//! The command line on a real robot's terms: joints locked, the excitation kept within the
//! workspace and the effort limits.

mod cli_support;

use cli_support::{bin, fails, ok, s, tmp, write, ARM_WITH_FINGER};

/// `--lock JOINT=VALUE` wherever a robot is loaded; a free gripper finger is warned about.
#[test]
fn lock_joints_and_warn_about_free_fingers() {
    let d = tmp("lock");
    let urdf = d.join("arm.urdf");
    write(&urdf, ARM_WITH_FINGER);
    let out = bin().args(["info", s(&urdf)]).output().unwrap();
    let se = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success());
    assert!(
        se.contains("warning: joint 'finger_joint' moves 0.020 kg")
            && se.contains("--lock finger_joint=VALUE on the command line"),
        "{se}"
    );
    let out = bin()
        .args(["info", s(&urdf), "--lock", "finger_joint=0.01"])
        .output()
        .unwrap();
    assert!(out.status.success() && out.stderr.is_empty());
    assert!(String::from_utf8_lossy(&out.stdout).contains("1 degrees of freedom"));
    // the built-in robots take locks too; bad locks are one-line errors
    let out = ok(&["info", "a465", "--lock", "joint6=0.3"]);
    assert!(out.contains("5 degrees of freedom"), "{out}");
    fails(
        &["info", "a465", "--lock", "joint6"],
        &["--lock", "JOINT=VALUE"],
    );
    fails(
        &["info", "a465", "--lock", "joint6=abc"],
        &["'abc'", "not a number"],
    );
    fails(&["info", "a465", "--lock", "elbow=0"], &["elbow"]);
}

/// `excite --workspace`: the constraints' slack printed; a bad document is a one-line error
/// with the JSON path of the culprit.
#[test]
fn excite_within_a_workspace() {
    let d = tmp("workspace");
    let ws = d.join("ws.json");
    write(
        &ws,
        r#"[{"frame": "link6", "region": {"above": {"normal": [0, 0, 1], "offset": 0.3}}, "margin": 0.02}]"#,
    );
    let out = ok(&[
        "excite",
        "a465",
        "--workspace",
        s(&ws),
        "--max-evaluations",
        "60",
        "--out",
        s(&d.join("x")),
    ]);
    let line = out
        .lines()
        .find(|l| l.contains("link6 above the plane (m)"))
        .unwrap_or_else(|| panic!("{out}"));
    let slack: f64 = line.split_whitespace().last().unwrap().parse().unwrap();
    assert!(slack >= 0.0, "{out}");
    write(&ws, r#"[{"frame": "link6", "region": {"under": {}}}]"#);
    fails(
        &[
            "excite",
            "a465",
            "--workspace",
            s(&ws),
            "--out",
            s(&d.join("y")),
        ],
        &["ws.json", "[0].region", "unknown variant `under`"],
    );
}
