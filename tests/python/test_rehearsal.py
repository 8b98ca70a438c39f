"""The true robot from Python: documents, simulate on any reference, the effects checked against
independent computations (Pinocchio for the rigid body, the formulas, rounding)."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr


def reference(n=6, duration=2.0, rate=200.0):
    t = np.arange(int(duration * rate) + 1) / rate
    a = 0.3 + 0.05 * np.arange(n)
    w = 1.0 + 0.3 * np.arange(n)
    q = 0.1 * np.arange(n) + a * np.sin(np.outer(t, w))
    qd = a * w * np.cos(np.outer(t, w))
    qdd = -a * w * w * np.sin(np.outer(t, w))
    return t, q, qd, qdd


def test_stribeck_friction_and_offsets_on_sampled_arrays_against_pinocchio(tmp_path):
    robot = pr.robots.a465()
    urdf = tmp_path / "a465.urdf"
    urdf.write_text(pr.robots.a465_urdf())
    pm = pin.buildModelFromUrdf(str(urdf))
    pm.armature = np.asarray(robot.armature)  # URDF has no armature element
    pd = pm.createData()
    spec = {
        "joint_offsets": [0.01, -0.02, 0.0, 0.0, 0.03, 0.0],
        "friction": {"coulomb": [0.3] * 6, "stribeck": [0.2] * 6, "stribeck_velocity": [0.05] * 6},
    }
    true = pr.TrueRobot(spec)
    assert pr.TrueRobot.from_json(true.to_json()).to_json() == true.to_json()
    t, q, qd, qdd = reference()
    rec = pr.simulate(robot, (t, q, qd, qdd), true_robot=true)
    assert isinstance(rec, pr.Recording)
    np.testing.assert_array_equal(rec.q, q)  # the encoders read the reference
    offsets = np.array(spec["joint_offsets"])
    for i in range(0, len(t), 13):
        rigid = pin.rnea(pm, pd, q[i] - offsets, qd[i], qdd[i])
        v = qd[i]
        friction = np.sign(v) * (0.3 + 0.2 * np.exp(-((v / 0.05) ** 2)))
        np.testing.assert_allclose(rec.tau[i], rigid + friction, atol=1e-9)


def test_quantised_encoders_round_and_a_fourier_excitation_runs(tmp_path):
    robot = pr.robots.a465()
    traj = pr.FourierTrajectory(np.full((6, 3), 0.05), np.zeros((6, 3)), np.zeros(6), base_frequency=0.2)
    counts = 4096 * 100
    true = pr.TrueRobot({"sensors": {"encoder_counts": [counts] * 6}})
    path = tmp_path / "true.json"
    true.save(path)
    assert json.loads(path.read_text())["format"] == "perturbid-true-robot/1"
    rec = pr.simulate(robot, traj, true_robot=pr.TrueRobot.load(path), rate=500.0, periods=1.0)
    exact = pr.simulate(robot, traj, friction=None, rate=500.0)
    step = 2 * np.pi / counts
    np.testing.assert_array_equal(rec.q, np.round(exact.q / step) * step)
    assert len(rec.t) == 5 * 500 + 1


def test_closed_loop_tracking_error_shrinks_as_gains_grow():
    robot = pr.robots.a465()
    t, q, qd, qdd = reference(duration=1.0, rate=500.0)
    errors = []
    for kp in (25.0, 100.0, 400.0):
        true = pr.TrueRobot({
            "payload": {"link": "link6", "mass": 2.0, "com": [0, 0, 0.05]},
            "controller": {"kp": [kp] * 6, "kd": [2 * kp**0.5] * 6, "substeps": 4},
        })
        rec = pr.simulate(robot, (t, q, qd, qdd), true_robot=true)
        errors.append(np.sqrt(np.mean((rec.q - q) ** 2)))
    assert errors[2] < errors[1] < errors[0] and errors[2] < 0.3 * errors[0], errors


def test_bad_true_robots_are_refused():
    robot = pr.robots.a465()
    with pytest.raises(pr.InputError, match="unknown field `frictoin`"):
        pr.TrueRobot({"frictoin": {}})
    with pytest.raises(pr.InputError, match="friction.viscous"):
        pr.simulate(robot, reference(), true_robot=pr.TrueRobot({"friction": {"viscous": [0.1, 0.2]}}))
    with pytest.raises(pr.InputError, match="come from the true robot"):
        pr.simulate(robot, reference(), torque_noise=0.1, true_robot=pr.TrueRobot())
    t, q, qd, qdd = reference()
    with pytest.raises(pr.InputError, match="t"):
        pr.simulate(robot, (t[::-1], q, qd, qdd))
    with pytest.raises(pr.InputError, match="periods"):
        pr.simulate(robot, pr.FourierTrajectory(np.ones((6, 1)), np.ones((6, 1)), np.zeros(6)), periods=1e12)
    # an excitation beyond the robot's limits is not run, as a plan is not: no robot could
    fast = pr.FourierTrajectory(np.full((6, 1), 50.0), np.zeros((6, 1)), np.zeros(6))
    with pytest.raises(pr.InputError, match=r"^the excitation: joint 'joint1' at t = 0\.0000 s: velocity 50\.000000 rad/s is outside"):
        pr.simulate(robot, fast)
    # rate and periods mean nothing for arrays or a plan (they set their own times): refused
    with pytest.raises(pr.InputError, match="rate: 500 given with arrays"):
        pr.simulate(robot, (t, q, qd, qdd), rate=500.0)
    plan = pr.plan_experiments(robot, pr.OperatingPoint(q[0], np.zeros(6), np.zeros(6)), experiments=["G_static"])
    with pytest.raises(pr.InputError, match="periods: 2 given with a plan"):
        pr.simulate(robot, plan, periods=2.0)
    with pytest.raises(pr.InputError, match=r"quantization\[0\]: 1e-320; expected 0 \(none\)"):
        pr.simulate(robot, plan, quantization=1e-320)
