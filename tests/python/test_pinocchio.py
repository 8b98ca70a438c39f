"""perturbid_rs against Pinocchio on the A465 and the arms of example-robot-data: rnea, g, M,
forward dynamics and the analytic derivatives, to 1e-9 relative."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import Pair, erd_dir, pair_from_urdf, pin, relerr
import perturbid_rs as pr

TOL = 1e-9

# name: (path under example-robot-data's robots folder, joints locked in ours, in Pinocchio)
ARMS = {
    "ur3": ("ur_description/urdf/ur3_robot.urdf", None),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", None),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", None),
    "panda": (
        "panda_description/urdf/panda.urdf",
        {"panda_finger_joint1": 0.02},
        {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02},
    ),
    "kinova": ("kinova_description/robots/kinova.urdf", None),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", None),
    "z1": ("z1_description/urdf/z1.urdf", None),
    "so100": ("so_arm_description/urdf/so100.urdf", None),
    "so101": ("so_arm_description/urdf/so101.urdf", None),
    "talos_left_arm": ("talos_data/robots/talos_left_arm.urdf", None),
    # kinematic trees
    "solo12": ("solo_description/robots/solo12.urdf", None),
    "g1": ("g1_description/urdf/g1_29dof_rev_1_0.urdf", None),
}


def a465_pair(variant: str) -> Pair:
    text = pr.robots.a465_urdf(variant)
    ours = pr.robots.a465(variant)
    model = pin.buildModelFromXML(text)
    # URDF has no armature element; Pinocchio takes it as model.armature
    model.armature = np.asarray(ours.armature)
    return Pair(ours, model)


@pytest.fixture(params=["a465:kinsheel2010", "a465:physical", *ARMS])
def pair(request) -> Pair:
    name = request.param
    if name.startswith("a465"):
        return a465_pair(name.split(":")[1])
    path, lock, *pin_lock = ARMS[name]
    return pair_from_urdf(erd_dir() / path, lock=lock, pin_lock=pin_lock[0] if pin_lock else None)


def check_dynamics(p: Pair, q, qd, qdd, aba=True):
    m, d = p.model, p.data
    qp, vp, ap = p.q(q), p.v(qd), p.v(qdd)
    assert relerr(p.ours.rnea(q, qd, qdd), p.vec(pin.rnea(m, d, qp, vp, ap))) < TOL
    assert relerr(p.ours.gravity(q), p.vec(pin.computeGeneralizedGravity(m, d, qp))) < TOL
    assert relerr(p.ours.bias(q, qd), p.vec(pin.nonLinearEffects(m, d, qp, vp))) < TOL
    M = pin.crba(m, d, qp)
    M = np.triu(M) + np.triu(M, 1).T
    assert relerr(p.ours.mass_matrix(q), p.mat(M)) < TOL
    tau = p.ours.rnea(q, qd, qdd)
    if aba:
        assert relerr(p.ours.forward_dynamics(q, qd, tau), p.vec(pin.aba(m, d, qp, vp, p.v(tau)))) < 1e-8
    else:  # Pinocchio's ABA does not take mimic joints: the round trip instead
        assert relerr(p.ours.forward_dynamics(q, qd, tau), qdd) < 1e-8


def check_derivatives(p: Pair, q, qd, qdd):
    m, d = p.model, p.data
    qp, vp, ap = p.q(q), p.v(qd), p.v(qdd)
    dq, dv, da = pin.computeRNEADerivatives(m, d, qp, vp, ap)
    da = np.triu(da) + np.triu(da, 1).T
    lin = p.ours.linearize(q, qd, qdd)
    assert relerr(lin.torque, p.vec(pin.rnea(m, d, qp, vp, ap))) < TOL
    assert relerr(lin.D, p.mat(da)) < TOL
    assert relerr(lin.H, p.mat(dv)) < TOL
    assert relerr(lin.G, p.mat(dq)) < TOL
    gs = pin.computeGeneralizedGravityDerivatives(m, d, qp)
    assert relerr(lin.G_static, p.mat(gs)) < TOL
    tau, dtau_dq, dtau_dv, M = p.ours.rnea_derivatives(q, qd, qdd)
    assert relerr(tau, p.vec(pin.rnea(m, d, qp, vp, ap))) < TOL
    assert relerr(dtau_dq, p.mat(dq)) < TOL and relerr(dtau_dv, p.mat(dv)) < TOL
    assert relerr(M, p.mat(da)) < TOL


def test_dynamics_and_derivatives_match_pinocchio(pair: Pair):
    rng = np.random.default_rng(42)
    for _ in range(10):
        q, qd, qdd = pair.random_state(rng, scale=2.0)
        check_dynamics(pair, q, qd, qdd)
        check_derivatives(pair, q, qd, qdd)


def test_batches_match_single_samples(pair: Pair):
    rng = np.random.default_rng(1)
    states = [pair.random_state(rng) for _ in range(5)]
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    tau = pair.ours.rnea(Q, QD, QDD)
    assert tau.shape == (5, pair.ours.n)
    M = pair.ours.mass_matrix(Q)
    assert M.shape == (5, pair.ours.n, pair.ours.n)
    lin = pair.ours.linearize(Q, QD, QDD)
    assert lin.G.shape == (5, pair.ours.n, pair.ours.n) and lin.torque.shape == (5, pair.ours.n)
    Ys = pair.ours.regressor(Q, QD, QDD)  # 5 samples: the multi-sample kernel and one more
    for k in range(5):
        # batches of 4 or more run the multi-sample kernel: equal up to rounding
        single = pair.ours.rnea(Q[k], QD[k], QDD[k])
        np.testing.assert_allclose(tau[k], single, rtol=0, atol=1e-12 * (1 + np.abs(single).max()))
        Mk = pair.ours.mass_matrix(Q[k])
        np.testing.assert_allclose(M[k], Mk, rtol=0, atol=1e-12 * np.abs(Mk).max())
        Y = pair.ours.regressor(Q[k], QD[k], QDD[k])
        np.testing.assert_allclose(Ys[k], Y, rtol=0, atol=1e-12 * (1 + np.abs(Y).max()))
        # the rigid bodies' regressor, and the armature's own term
        assert relerr(Ys[k] @ pair.ours.parameters + pair.ours.armature * QDD[k], tau[k]) < TOL
        # the batched derivatives run on the lanes (FMA): equal to one sample up to rounding
        one = pair.ours.linearize(Q[k], QD[k], QDD[k])
        for a, b in [(lin.H[k], one.H), (lin.G[k], one.G), (lin.G_static[k], one.G_static)]:
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * (1 + np.abs(b).max()))


def test_large_batches_match_pinocchio(pair: Pair):
    """A batch large enough to run in parallel chunks through the multi-sample kernels, with a
    length that leaves a partial group of lanes: rnea, gravity, bias and M against Pinocchio."""
    rng = np.random.default_rng(2)
    k = 4096 + 1024 + 3
    states = [pair.random_state(rng) for _ in range(k)]
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    tau, g, bias = pair.ours.rnea(Q, QD, QDD), pair.ours.gravity(Q), pair.ours.bias(Q, QD)
    M = pair.ours.mass_matrix(Q)
    m, d = pair.model, pair.data
    for i in list(range(0, k, 97)) + [k - 1]:
        qp, vp, ap = pair.q(Q[i]), pair.v(QD[i]), pair.v(QDD[i])
        assert relerr(tau[i], pair.vec(pin.rnea(m, d, qp, vp, ap))) < TOL
        assert relerr(g[i], pair.vec(pin.computeGeneralizedGravity(m, d, qp))) < TOL
        assert relerr(bias[i], pair.vec(pin.nonLinearEffects(m, d, qp, vp))) < TOL
        Mp = pin.crba(m, d, qp)
        assert relerr(M[i], pair.mat(np.triu(Mp) + np.triu(Mp, 1).T)) < TOL


def test_gravity_switch_matches_pinocchio_with_zero_gravity():
    p = a465_pair("physical")
    p.model.gravity.linear = np.zeros(3)
    rng = np.random.default_rng(3)
    q, qd, qdd = p.random_state(rng)
    tau = pin.rnea(p.model, p.data, p.q(q), p.v(qd), p.v(qdd))
    assert relerr(p.ours.rnea(q, qd, qdd, gravity=False), p.vec(tau)) < TOL
    dq, dv, _ = pin.computeRNEADerivatives(p.model, p.data, p.q(q), p.v(qd), p.v(qdd))
    lin = p.ours.linearize(q, qd, qdd, gravity=False)
    assert relerr(lin.G, p.mat(dq)) < TOL
    assert np.all(lin.G_static == 0.0)


def test_mimic_joints_match_pinocchio_mimic_model():
    path = erd_dir() / "panda_description/urdf/panda.urdf"
    ours = pr.Robot.from_urdf(path)
    assert ours.n == 8 and "panda_finger_joint2" not in ours.joint_names
    p = Pair(ours, pin.buildModelFromUrdf(str(path), mimic=True))
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, qd, qdd = p.random_state(rng)
        check_dynamics(p, q, qd, qdd, aba=False)


def test_locked_joints_match_pinocchio_reduced_model():
    path = erd_dir() / "ur_description/urdf/ur5_robot.urdf"
    p = pair_from_urdf(path, lock={"elbow_joint": 0.7, "wrist_2_joint": -0.3})
    assert p.ours.n == 4
    rng = np.random.default_rng(6)
    for _ in range(5):
        q, qd, qdd = p.random_state(rng)
        check_dynamics(p, q, qd, qdd)
        check_derivatives(p, q, qd, qdd)


def test_armature_matches_pinocchio_armature():
    """`<dynamics armature>` and a Drake transmission against Pinocchio's `model.armature`."""
    text = pr.robots.a465_urdf("physical")
    text = text.replace('<joint name="joint2" type="revolute">', '<joint name="joint2" type="revolute"><dynamics damping="0" armature="0.7"/>')
    text = text.replace(
        "</robot>",
        '<transmission name="t5"><joint name="joint5"/><actuator name="m5">'
        '<rotor_inertia value="3e-5"/><gear_ratio value="100"/></actuator></transmission></robot>',
    )
    ours = pr.Robot.from_urdf_string(text)
    np.testing.assert_allclose(ours.armature, [0, 0.7, 0, 0, 0.3, 0], rtol=1e-12)
    model = pin.buildModelFromXML(text)
    model.armature = np.asarray(ours.armature)
    p = Pair(ours, model)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd, qdd = p.random_state(rng, scale=2.0)
        check_dynamics(p, q, qd, qdd)
        check_derivatives(p, q, qd, qdd)
