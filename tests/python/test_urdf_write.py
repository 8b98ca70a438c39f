"""A robot written back as URDF (Robot.to_urdf): Pinocchio reads the file written, and its
torques and friction are the identified robot's; a payload attached as a link of its own is
Pinocchio's payload added to the inertia of the link's joint; an unchanged robot writes its
own file; bad arguments are refused by name."""

import re

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import erd_dir, pair_from_urdf
from test_drive_gains import motion, pin_torques

HAND_PAYLOAD = {"link": "panda_hand", "mass": 0.9, "com": [0.0, 0.01, 0.08],
                "inertia": [0.002, 0.0, 0.0001, 0.003, 0.0, 0.001]}


def heavier(text, factor):
    """The URDF with every mass and inertia scaled: another rigid robot."""
    def scale(m):
        return f'{m.group(1)}="{float(m.group(2)) * factor!r}"'
    return re.sub(r'\b(value|ixx|ixy|ixz|iyy|iyz|izz)="([^"]+)"', scale, text)


def without_header(text):
    return re.sub(r"<!-- Written by perturbid_rs.*?-->\n", "", text, count=1, flags=re.S)


def test_pinocchio_reads_the_identified_robot_as_it_predicts(tmp_path):
    source = pr.robots.a465_urdf("physical")
    truth = pin.buildModelFromXML(heavier(source, 1.3))
    t, q, qd, qdd = motion(1)
    tau = pin_torques(truth, q, qd, qdd) + 0.3 * qd + 0.5 * np.sign(qd)
    nominal = pr.Robot.from_urdf_string(source)
    fit = pr.identify_consistent_parameters(nominal, q, qd, qdd, tau, friction="viscous,coulomb",
                                            weighting="ols")
    assert "joint1.coulomb" in fit.names  # names comma separated, as the command line's
    robot = fit.robot()
    path = tmp_path / "identified.urdf"
    text = robot.to_urdf(path, note="from a test")
    assert path.read_text() == text and "from a test" in text
    written = pin.buildModelFromUrdf(str(path))
    # what the fit found (its weak prior pulls by a few parts in a million)
    assert np.allclose(written.damping, 0.3, atol=1e-4) and np.allclose(written.friction, 0.5, atol=1e-4)
    t2, q2, qd2, qdd2 = motion(2)
    ours = fit.model.predict(q2, qd2, qdd2)
    pins = pin_torques(written, q2, qd2, qdd2) + written.damping * qd2 + written.friction * np.sign(qd2)
    assert np.allclose(pins, ours, rtol=1e-9, atol=1e-9)
    # and the robot identified is the truth's (noise-free torques)
    assert np.allclose(pins, pin_torques(truth, q2, qd2, qdd2) + 0.3 * qd2 + 0.5 * np.sign(qd2),
                       rtol=1e-4, atol=1e-4)


def test_a_payload_is_pinocchios_payload_on_the_hands_joint():
    path = erd_dir() / "panda_description/urdf/panda.urdf"
    lock = {"panda_finger_joint1": 0.0}
    pin_lock = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
    pair = pair_from_urdf(path, lock=lock, pin_lock=pin_lock)
    text = pair.ours.to_urdf(payload=HAND_PAYLOAD, payload_link="gripper_load")
    assert '<joint name="gripper_load_joint" type="fixed">' in text
    # Pinocchio's model with the payload added through the hand frame's placement
    expected = pair.model.copy()
    frame = expected.frames[expected.getFrameId("panda_hand")]
    xx, xy, xz, yy, yz, zz = HAND_PAYLOAD["inertia"]
    inertia = pin.Inertia(HAND_PAYLOAD["mass"], np.array(HAND_PAYLOAD["com"]),
                          np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
    expected.inertias[frame.parentJoint] = expected.inertias[frame.parentJoint] + frame.placement.act(inertia)
    full = pin.buildModelFromXML(text)
    qref = pin.neutral(full)
    written = pin.buildReducedModel(full, [full.getJointId(n) for n in pin_lock], qref)
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, v, a = pair.random_state(rng, 2.0)
        want = pin.rnea(expected, expected.createData(), pair.q(q), pair.v(v), pair.v(a))
        got = pin.rnea(written, written.createData(), pair.q(q), pair.v(v), pair.v(a))
        assert np.allclose(got, want, rtol=1e-10, atol=1e-10)
    # everything else as the file has it: visuals, collisions
    source = path.read_text()
    for tag in ("<visual", "<collision", "<limit", "<safety_controller"):
        assert text.count(tag) == source.count(tag), tag


def test_an_unchanged_robot_writes_its_own_file():
    text = pr.Robot.builtin("a465").to_urdf()
    assert without_header(text) == pr.robots.a465_urdf("kinsheel2010")


def test_bad_arguments_are_refused_by_name(tmp_path):
    robot = pr.Robot.builtin("a465")
    with pytest.raises(pr.InputError, match="payload.*unknown key 'weight'"):
        robot.to_urdf(payload={"link": "link6", "mass": 1.0, "weight": 2})
    with pytest.raises(pr.ModelError, match="payload link 'link2'.*a link of the robot"):
        robot.to_urdf(payload={"link": "link6", "mass": 1.0}, payload_link="link2")
    with pytest.raises(pr.ModelError, match="is not a link of"):
        robot.to_urdf(payload={"link": "gripper", "mass": 1.0})
    with pytest.raises(pr.FileError):
        robot.to_urdf(tmp_path)  # a folder
    assert list(tmp_path.iterdir()) == []


def test_a_robot_validated_as_a_model_is_pinocchios_torques_and_friction(tmp_path):
    """Robot.predict is Pinocchio's rnea plus the URDF's <dynamics> friction; validate takes a
    Robot as a model and warns where its file gives no friction."""
    text = pr.robots.a465_urdf("physical").replace(
        '<axis xyz="0 1.0 0"/>', '<axis xyz="0 1.0 0"/>\n    <dynamics damping="0.4" friction="0.7"/>')
    robot = pr.Robot.from_urdf_string(text)
    assert np.count_nonzero(robot.damping) >= 1
    model = pin.buildModelFromXML(text)
    t, q, qd, qdd = motion(3)
    want = pin_torques(model, q, qd, qdd) + model.damping * qd + model.friction * np.sign(qd)
    assert np.allclose(robot.predict(q, qd, qdd), want, rtol=1e-10, atol=1e-10)
    assert robot.predict(q[0], qd[0], qdd[0]).shape == (6,)
    v = pr.validate(robot, q, qd, qdd, want + 0.01, t=t)
    assert np.allclose(v.rms, 0.01) and np.allclose(v.mean, 0.01)
    bare = pr.Robot.from_urdf_string(pr.robots.a465_urdf("physical"))
    with pytest.warns(pr.PerturbidWarning, match="gives its joints no friction"):
        v = pr.validate(bare, q, qd, qdd, want, t=t)
    assert v.rms.max() > 0.1
