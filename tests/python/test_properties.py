"""Identities and property tests on random kinematic trees (hypothesis), with Pinocchio as the
oracle, and the A465 reference numbers through the Python API."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st

from conftest import pair_from_text, pin, relerr
import perturbid_rs as pr


def random_tree(seed: int, nlinks: int) -> str:
    """URDF of a random tree: revolute, continuous, prismatic and fixed joints, random origins,
    axes and valid inertias (principal moments from a mass distribution, rotated)."""
    r = np.random.default_rng(seed)
    u = r.uniform
    links = ['<link name="base"/>']
    joints = []
    for k in range(1, nlinks + 1):
        a, b, c = u(0.01, 0.2, 3)
        links.append(
            f'<link name="l{k}"><inertial><origin xyz="{u(-.2,.2)} {u(-.2,.2)} {u(-.2,.2)}" rpy="{u(-3,3)} {u(-1.5,1.5)} {u(-3,3)}"/>'
            f'<mass value="{u(0.2, 3)}"/><inertia ixx="{b+c}" ixy="0" ixz="0" iyy="{a+c}" iyz="0" izz="{a+b}"/></inertial></link>'
        )
        parent = "base" if k == 1 else (lambda p: "base" if p == 0 else f"l{p}")(int(r.integers(0, k)))
        kind = "revolute" if k == 1 else ["revolute", "continuous", "prismatic", "fixed"][int(r.integers(0, 4))]
        joints.append(
            f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="l{k}"/>'
            f'<origin xyz="{u(-.3,.3)} {u(-.3,.3)} {u(0,.4)}" rpy="{u(-3,3)} {u(-1.5,1.5)} {u(-3,3)}"/>'
            f'<axis xyz="{u(-1,1)} {u(-1,1)} {u(.2,1)}"/><limit lower="-2" upper="2" effort="100" velocity="3"/></joint>'
        )
    return '<robot name="random">' + "".join(links + joints) + "</robot>"


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nlinks=st.integers(1, 10))
def test_random_trees_match_pinocchio(seed, nlinks):
    p = pair_from_text(random_tree(seed, nlinks))
    rng = np.random.default_rng(seed)
    q, qd, qdd = p.random_state(rng, scale=2.0)
    m, d = p.model, p.data
    qp, vp, ap = p.q(q), p.v(qd), p.v(qdd)
    assert relerr(p.ours.rnea(q, qd, qdd), p.vec(pin.rnea(m, d, qp, vp, ap))) < 1e-9
    M = pin.crba(m, d, qp)
    assert relerr(p.ours.mass_matrix(q), p.mat(np.triu(M) + np.triu(M, 1).T)) < 1e-9
    dq, dv, _ = pin.computeRNEADerivatives(m, d, qp, vp, ap)
    lin = p.ours.linearize(q, qd, qdd)
    assert relerr(lin.G, p.mat(dq)) < 1e-9
    assert relerr(lin.H, p.mat(dv)) < 1e-9


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), nlinks=st.integers(1, 10))
def test_identities_on_random_trees(seed, nlinks):
    robot = pr.Robot.from_urdf_string(random_tree(seed, nlinks))
    rng = np.random.default_rng(seed)
    n = robot.n
    q, qd, qdd = rng.uniform(-1.5, 1.5, (3, n))
    M = robot.mass_matrix(q)
    np.testing.assert_allclose(M, M.T, atol=1e-12)
    # M qdd = rnea(q, 0, qdd) - g(q)
    lhs = M @ qdd
    rhs = robot.rnea(q, np.zeros(n), qdd) - robot.gravity(q)
    assert relerr(lhs, rhs) < 1e-9
    # forward_dynamics(rnea(q, qd, qdd)) = qdd
    assert relerr(robot.forward_dynamics(q, qd, robot.rnea(q, qd, qdd)), qdd) < 1e-8
    # D of the linearisation is M; tau is linear in qdd exactly
    lin = robot.linearize(q, qd, qdd)
    assert relerr(lin.D, M) < 1e-12
    dqdd = rng.uniform(-1, 1, n)
    assert relerr(robot.rnea(q, qd, qdd + dqdd) - lin.torque, lin.D @ dqdd) < 1e-9


def test_a465_reference_numbers():
    robot = pr.robots.a465()
    q = np.array([0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0])
    qd = np.array([0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140])
    qdd = np.array([-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710])
    tn = np.array([-1.1883, -3.4797, -1.7304, -0.1377, -0.4466, 0.0539])
    lin = robot.linearize(q, qd, qdd, gravity=False)
    assert np.abs(lin.D[:, 0] - [9.956, 0, 0, -1.37, 0, -0.27]).max() < 0.002
    assert np.abs(lin.torque - tn).max() < 0.01
    g = pr.robots.a465("physical").gravity(q)
    assert np.abs(g - [0, -4.92, 0.71, 0, -0.05, 0]).max() < 0.006
    assert robot.n == 6 and robot.joint_names == [f"joint{i}" for i in range(1, 7)]
    assert np.allclose(robot.upper, np.radians([175, 90, 110, 180, 105, 180]))
    assert np.allclose(robot.velocity_limit, [3.1416, 3.1416, 3.1416, 2.9845, 3.0194, 2.9845])
    assert np.allclose(robot.acceleration_limit, [12.566] * 3 + [24.958] * 3)
    assert np.all(np.isinf(robot.effort_limit))
