//! Every bad URDF gets its own error, naming the source, line and element.

use perturbid_rs::{model_from_urdf_file, model_from_urdf_str, Error, LoadOptions};

const LINK: &str = r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;
const LIMIT: &str = r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#;

fn robot(body: &str) -> String {
    format!("<robot name=\"bad\">\n<link name=\"base\"/>\n<link name=\"a\">{LINK}</link>\n<link name=\"b\">{LINK}</link>\n{body}\n</robot>\n")
}

fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!("<joint name=\"{name}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{child}\"/><axis xyz=\"0 0 1\"/>{extra}</joint>\n")
}

fn load(text: &str) -> Error {
    model_from_urdf_str(text, "bad.urdf", &LoadOptions::default()).unwrap_err()
}

fn good_chain() -> String {
    joint("j1", "revolute", "base", "a", LIMIT) + &joint("j2", "revolute", "a", "b", LIMIT)
}

#[test]
fn a_good_chain_loads() {
    let m = model_from_urdf_str(&robot(&good_chain()), "ok.urdf", &LoadOptions::default()).unwrap();
    assert_eq!(m.nv, 2);
}

#[test]
fn floating_and_planar_joints_are_refused_with_their_line() {
    for kind in ["floating", "planar"] {
        let text = robot(
            &(joint("j1", kind, "base", "a", "") + &joint("j2", "revolute", "a", "b", LIMIT)),
        );
        let e = load(&text);
        assert!(matches!(e, Error::UnsupportedJoint { .. }), "{e}");
        assert!(
            e.to_string()
                .starts_with("bad.urdf:5: joint 'j1' is of type"),
            "{e}"
        );
    }
}

#[test]
fn two_roots_are_refused() {
    let text = robot(&joint("j1", "revolute", "base", "a", LIMIT));
    let e = load(&text);
    assert!(matches!(e, Error::RootCount { .. }), "{e}");
    assert!(e.to_string().contains("base, b"), "{e}");
}

#[test]
fn a_cycle_is_refused() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            + &joint("j2", "revolute", "a", "b", LIMIT)
            + &joint("j3", "revolute", "b", "a", LIMIT)),
    );
    // a is the child of j1 and j3: reported as a duplicate child first
    assert!(matches!(load(&text), Error::DuplicateChild { .. }));
    let text = format!("<robot name=\"c\"><link name=\"x\">{LINK}</link><link name=\"y\">{LINK}</link>{}{}</robot>",
        joint("j1", "revolute", "x", "y", LIMIT), joint("j2", "revolute", "y", "x", LIMIT));
    assert!(matches!(load(&text), Error::Cycle { .. }));
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            + &format!("<link name=\"c\">{LINK}</link>")
            + &joint("j2", "revolute", "b", "c", LIMIT)
            + &joint("j3", "revolute", "c", "b", LIMIT)),
    );
    let e = load(&text);
    assert!(matches!(e, Error::Cycle { .. }), "{e}");
    assert!(e.to_string().contains("b, c"), "{e}");
}

#[test]
fn a_link_that_is_a_child_twice_is_refused() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            + &joint("j2", "revolute", "base", "a", LIMIT)),
    );
    let e = load(&text);
    assert!(matches!(e, Error::DuplicateChild { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("link 'a' is the child of joint 'j1' and again of joint 'j2'"),
        "{e}"
    );
}

#[test]
fn an_unknown_link_is_refused() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            + &joint("j2", "revolute", "a", "nowhere", LIMIT)),
    );
    let e = load(&text);
    assert!(matches!(e, Error::UnknownLink { .. }), "{e}");
    assert!(
        e.to_string()
            .contains("bad.urdf:6: joint 'j2' names child link 'nowhere'"),
        "{e}"
    );
}

fn with_inertia(ixx: f64, iyy: f64, izz: f64, mass: f64) -> String {
    let inertial = format!(
        r#"<inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>"#
    );
    format!(
        "<robot name=\"i\">\n<link name=\"base\"/>\n<link name=\"a\">{inertial}</link>\n{}</robot>",
        joint("j1", "revolute", "base", "a", LIMIT)
    )
}

#[test]
fn physically_invalid_inertias_are_refused() {
    for (text, needle) in [
        (with_inertia(0.1, 0.1, 0.1, -1.0), "negative"),
        (
            with_inertia(0.1, -0.1, 0.1, 1.0),
            "not positive semi-definite",
        ),
        (with_inertia(0.1, 0.1, 0.5, 1.0), "triangle inequality"),
    ] {
        let e = load(&text);
        assert!(matches!(e, Error::InvalidInertia { .. }), "{e}");
        assert!(e.to_string().starts_with("bad.urdf:3: link 'a'"), "{e}");
        assert!(e.to_string().contains(needle), "{e}");
    }
    // rounding is tolerated, and the triangle check can be turned off
    assert!(model_from_urdf_str(
        &with_inertia(0.1, 0.1, 0.2000001, 1.0),
        "x",
        &LoadOptions::default()
    )
    .is_ok());
    let relaxed = LoadOptions {
        check_triangle_inequality: false,
        ..Default::default()
    };
    assert!(model_from_urdf_str(&with_inertia(0.1, 0.1, 0.5, 1.0), "x", &relaxed).is_ok());
}

#[test]
fn a_joint_that_moves_no_mass_is_refused_but_massless_links_are_fine() {
    let text = format!("<robot name=\"z\">\n<link name=\"base\"/>\n<link name=\"a\"/>\n<link name=\"b\">{LINK}</link>\n{}{}</robot>",
        joint("j1", "revolute", "base", "a", LIMIT), joint("j2", "revolute", "base", "b", LIMIT));
    let e = load(&text);
    assert!(matches!(e, Error::MasslessSubtree { .. }), "{e}");
    assert!(e.to_string().contains("joint 'j1' moves nothing"), "{e}");
    // a massless link in the middle of a chain is fine
    let text = format!("<robot name=\"z\">\n<link name=\"base\"/>\n<link name=\"a\"/>\n<link name=\"b\">{LINK}</link>\n{}{}</robot>",
        joint("j1", "revolute", "base", "a", LIMIT), joint("j2", "revolute", "a", "b", LIMIT));
    assert!(model_from_urdf_str(&text, "ok", &LoadOptions::default()).is_ok());
}

#[test]
fn zero_and_non_finite_axes_are_refused() {
    for axis in ["0 0 0", "nan 0 1", "inf 0 0"] {
        let j = format!("<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"a\"/><axis xyz=\"{axis}\"/>{LIMIT}</joint>");
        let text = robot(&(j + &joint("j2", "revolute", "a", "b", LIMIT)));
        let e = load(&text);
        assert!(matches!(e, Error::InvalidAxis { .. }), "{axis}: {e}");
    }
}

#[test]
fn non_finite_numbers_are_refused() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            .replace("<axis", "<origin xyz=\"0 nan 0\"/><axis")
            + &joint("j2", "revolute", "a", "b", LIMIT)),
    );
    let e = load(&text);
    assert!(matches!(e, Error::NonFiniteUrdf { .. }), "{e}");
    assert!(
        e.to_string().contains("joint 'j1': origin xyz is NaN"),
        "{e}"
    );
    let e = load(&with_inertia(0.1, 0.1, 0.1, f64::INFINITY));
    assert!(e.to_string().contains("link 'a': mass is inf"), "{e}");
}

#[test]
fn revolute_without_limit_is_refused_continuous_is_not() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", "") + &joint("j2", "revolute", "a", "b", LIMIT)),
    );
    let e = load(&text);
    assert!(matches!(e, Error::MissingLimit { .. }), "{e}");
    let text = robot(
        &(joint("j1", "continuous", "base", "a", "") + &joint("j2", "revolute", "a", "b", LIMIT)),
    );
    let m = model_from_urdf_str(&text, "ok", &LoadOptions::default()).unwrap();
    assert!(m.limits[0].lower.is_infinite() && m.limits[0].velocity.is_infinite());
}

#[test]
fn syntax_errors_and_missing_files_name_the_source() {
    let e = load("<robot name=\"x\"><link name=\"a\"></robot>");
    assert!(matches!(e, Error::UrdfSyntax { .. }), "{e}");
    assert!(
        e.to_string().starts_with("bad.urdf: not a valid URDF"),
        "{e}"
    );
    let e = model_from_urdf_file("/nonexistent/robot.urdf", &LoadOptions::default()).unwrap_err();
    assert!(e.to_string().starts_with("/nonexistent/robot.urdf:"), "{e}");
}

#[test]
fn mimic_of_unknown_joint_and_mimic_cycles_are_refused() {
    let text = robot(
        &(joint("j1", "revolute", "base", "a", LIMIT)
            + &joint(
                "j2",
                "revolute",
                "a",
                "b",
                &format!("{LIMIT}<mimic joint=\"ghost\"/>"),
            )),
    );
    assert!(load(&text).to_string().contains("no joint named 'ghost'"));
    let text = robot(
        &(joint(
            "j1",
            "revolute",
            "base",
            "a",
            &format!("{LIMIT}<mimic joint=\"j2\"/>"),
        ) + &joint(
            "j2",
            "revolute",
            "a",
            "b",
            &format!("{LIMIT}<mimic joint=\"j1\"/>"),
        )),
    );
    assert!(load(&text).to_string().contains("cycle"));
}

#[test]
fn limits_dynamics_and_acceleration_are_kept() {
    let extra = r#"<limit lower="-0.5" upper="0.7" effort="12" velocity="2.5"/><dynamics damping="0.3" friction="0.2"/>"#;
    let text = robot(
        &(joint("j1", "revolute", "base", "a", extra) + &joint("j2", "prismatic", "a", "b", LIMIT)),
    );
    let m = model_from_urdf_str(&text, "ok", &LoadOptions::default()).unwrap();
    let l = &m.limits[0];
    assert_eq!(
        (l.lower, l.upper, l.effort, l.velocity, l.damping, l.friction),
        (-0.5, 0.7, 12.0, 2.5, 0.3, 0.2)
    );
    assert_eq!(m.joint_kinds[1], perturbid_rs::JointKind::Prismatic);
    let a465 = perturbid_rs::robots::builtin("a465").unwrap();
    assert_eq!(a465.limits[3].acceleration, 24.958);
    assert!(a465.limits[0].effort.is_infinite());
}

#[test]
fn an_empty_robot_has_no_root() {
    let e = load("<robot name=\"empty\"></robot>");
    assert!(matches!(e, Error::RootCount { .. }), "{e}");
    assert!(e.to_string().contains("found 0"), "{e}");
}

/// A negative damping or friction would push the joint: refused with the joint and line. Huge
/// numbers are shown short in every message (1e300, not 301 digits).
#[test]
fn negative_dynamics_are_refused_and_numbers_are_shown_short() {
    for (dynamics, says) in [
        (
            r#"<dynamics damping="-0.1" friction="0"/>"#,
            "damping -0.1 is negative",
        ),
        (
            r#"<dynamics damping="0" friction="-2"/>"#,
            "friction -2 is negative",
        ),
    ] {
        let extra = format!("{LIMIT}{dynamics}");
        let e = load(&robot(
            &(joint("j1", "revolute", "base", "a", &extra)
                + &joint("j2", "revolute", "a", "b", LIMIT)),
        ));
        assert!(matches!(e, Error::InvalidDynamics { .. }), "{e}");
        assert!(
            e.to_string()
                .starts_with("bad.urdf:5: joint 'j1' <dynamics>: ")
                && e.to_string().contains(says),
            "{e}"
        );
    }
    for (extra, says) in [
        (
            r#"<limit lower="1e300" upper="-1e300" effort="1" velocity="1"/>"#,
            "lower (1e300) is above upper (-1e300)",
        ),
        (
            r#"<origin xyz="1e300 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#,
            "origin xyz is 1e300, expected a finite number below 1e12",
        ),
    ] {
        let e = load(&robot(
            &(joint("j1", "revolute", "base", "a", extra)
                + &joint("j2", "revolute", "a", "b", LIMIT)),
        ))
        .to_string();
        assert!(e.contains(says) && e.len() < 200, "{e}");
    }
}
