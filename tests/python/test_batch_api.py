"""The batched methods without waste: results written into the caller's arrays (`out=`),
checked strictly, and the same numbers as without; the instruction set reported."""

from __future__ import annotations

import numpy as np
import pytest

import perturbid_rs as pr


@pytest.fixture(scope="module")
def robot() -> pr.Robot:
    return pr.Robot.builtin("a465")


def states(k: int, n: int = 6, seed: int = 0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (3, k, n))


@pytest.mark.parametrize("k", [None, 1, 5, 4097])
def test_out_is_written_and_returned_and_equals_a_new_result(robot, k):
    q, qd, qdd = states(k or 1)
    if k is None:
        q, qd, qdd = q[0], qd[0], qdd[0]
    lead = () if k is None else (k,)
    n, p = robot.n, robot.parameters.size
    calls = [
        ("rnea", (q, qd, qdd), lead + (n,)),
        ("gravity", (q,), lead + (n,)),
        ("bias", (q, qd), lead + (n,)),
        ("mass_matrix", (q,), lead + (n, n)),
        ("regressor", (q, qd, qdd), lead + (n, p)),
        ("forward_dynamics", (q, qd, qdd), lead + (n,)),
    ]
    for name, args, shape in calls:
        out = np.full(shape, np.nan)
        got = getattr(robot, name)(*args, out=out)
        assert got is out, name
        np.testing.assert_array_equal(out, getattr(robot, name)(*args), err_msg=name)
    outs = tuple(np.full(lead + s, np.nan) for s in [(n,), (n, n), (n, n), (n, n)])
    got = robot.rnea_derivatives(q, qd, qdd, out=outs)
    assert all(a is b for a, b in zip(got, outs))
    for a, b in zip(outs, robot.rnea_derivatives(q, qd, qdd)):
        np.testing.assert_array_equal(a, b)
    outs = tuple(np.full(lead + s, np.nan) for s in [(n,), (n, n), (n, n), (n, n), (n, n)])
    lin = robot.linearize(q, qd, qdd, out=outs)
    assert all(a is b for a, b in zip((lin.torque, lin.D, lin.H, lin.G, lin.G_static), outs))
    new = robot.linearize(q, qd, qdd)
    for a, b in zip(outs, (new.torque, new.D, new.H, new.G, new.G_static)):
        np.testing.assert_array_equal(a, b)


def test_friction_columns_go_into_out_too(robot):
    q, qd, qdd = states(3)
    want = robot.regressor(q, qd, qdd, friction="viscous,coulomb")
    out = np.empty_like(want)
    assert robot.regressor(q, qd, qdd, friction="viscous,coulomb", out=out) is out
    np.testing.assert_array_equal(out, want)


def test_a_wrong_out_is_refused_with_what_was_expected(robot):
    q, qd, qdd = states(4)
    cases = [
        (np.zeros((4, 5)), "shape [4, 6]"),  # wrong shape
        (np.zeros((6,)), "shape [4, 6]"),  # a single sample's shape for a batch
        (np.zeros((4, 6), dtype=np.float32), "dtype float32"),
        (np.zeros((6, 4)).T, "not C-contiguous"),
        ([[0.0] * 6] * 4, "a list"),
    ]
    for out, words in cases:
        with pytest.raises(pr.InputError, match="out") as e:
            robot.rnea(q, qd, qdd, out=out)
        assert words in str(e.value), str(e.value)
    ro = np.zeros((4, 6))
    ro.flags.writeable = False
    with pytest.raises(pr.InputError, match="out"):
        robot.rnea(q, qd, qdd, out=ro)
    # the input's own memory: numpy refuses to lend it for writing while it is read
    q = np.ascontiguousarray(q)
    with pytest.raises(pr.InputError, match="share no memory with the inputs"):
        robot.rnea(q, qd, qdd, out=q)
    # small arguments are copied rather than borrowed: an output that is one of them is still
    # refused, in every method and for a single sample too
    with pytest.raises(pr.InputError, match="share no memory with the inputs"):
        robot.forward_dynamics(q[0], qd[0], np.zeros(6), out=q[0])
    with pytest.raises(pr.InputError, match="share no memory with the inputs"):
        robot.rnea_derivatives(q, qd, qdd, out=(qd, np.zeros((4, 6, 6)),
                                                np.zeros((4, 6, 6)), np.zeros((4, 6, 6))))
    with pytest.raises(pr.InputError, match="share no memory with the inputs"):
        robot.linearize(q[1], qd[1], qdd[1], out=(qdd[1], *(np.zeros((6, 6)) for _ in range(4))))
    # one array for two outputs is refused too
    m = np.zeros((4, 6, 6))
    with pytest.raises(pr.InputError, match="each other"):
        robot.rnea_derivatives(q, qd, qdd, out=(np.zeros((4, 6)), m, m, np.zeros((4, 6, 6))))
    # rnea_derivatives wants all four (pyo3's own message names `out`)
    with pytest.raises(ValueError, match="out"):
        robot.rnea_derivatives(q, qd, qdd, out=(np.zeros((4, 6)),))


def test_the_instruction_set_is_reported():
    assert pr.simd_isa() in {"avx512", "avx2+fma", "scalar"}


def test_perturbid_simd_caps_the_instruction_set_and_the_results_agree():
    """PERTURBID_SIMD names the widest set to use (as on a machine without AVX-512); a value
    naming none is reported on stderr and not used; every path gives the same torques."""
    import json
    import os
    import subprocess
    import sys

    code = ("import json, numpy as np, perturbid_rs as pr\n"
            "r = pr.Robot.from_urdf_string(pr.robots.a465_urdf('kinsheel2010'), "
            "check_triangle_inequality=False)\n"
            "x = np.random.default_rng(3).uniform(-2, 2, (3, 37, 6))\n"
            "print(pr.simd_isa()); print(json.dumps(r.rnea(*x).tolist()))")

    def run(value):
        env = {k: v for k, v in os.environ.items() if k != "PERTURBID_SIMD"}
        if value is not None:
            env["PERTURBID_SIMD"] = value
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, check=True)
        isa, tau = done.stdout.splitlines()
        return isa, np.array(json.loads(tau)), done.stderr

    widest, tau, _ = run(None)
    lanes = {"avx512": 8, "avx2+fma": 4, "avx2": 4, "scalar": 1}
    for cap in ["scalar", "avx2", "AVX2+FMA", "avx512"]:
        isa, t, err = run(cap)
        assert lanes[isa] <= lanes[cap.lower()], (cap, isa)
        np.testing.assert_allclose(t, tau, rtol=1e-12, atol=1e-9)
        assert err == ""
    isa, t, err = run("sse9")
    assert isa == widest and "PERTURBID_SIMD" in err and "sse9" in err


def test_a_result_past_a_gibibyte_is_allocated_by_numpy_and_equal(robot):
    """Results past 1 GiB come from numpy's allocator (a MemoryError, not a crash, when the
    memory is not there): the A465 regressor of 380,000 samples is 1.1 GB."""
    k = 380_000
    q, qd, qdd = states(k)
    y = robot.regressor(q, qd, qdd)
    assert y.shape == (k, 6, robot.parameters.size) and y.flags.c_contiguous
    for s in [0, k // 2, k - 1]:
        np.testing.assert_allclose(y[s], robot.regressor(q[s], qd[s], qdd[s]), rtol=0, atol=1e-12 * (1 + np.abs(y[s]).max()))
    del y
