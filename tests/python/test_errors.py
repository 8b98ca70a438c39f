"""Bad input raises a clear exception of the library's hierarchy; nothing crashes."""

from __future__ import annotations

import numpy as np
import pytest

import perturbid_rs as pr


@pytest.fixture
def robot():
    return pr.robots.a465()


def test_hierarchy():
    for cls in (pr.ModelError, pr.InputError, pr.NumericalError, pr.FileError, pr.InternalError):
        assert issubclass(cls, pr.PerturbidError)
    assert issubclass(pr.PerturbidError, Exception)
    # caught as Python users expect
    assert issubclass(pr.InputError, ValueError)
    assert issubclass(pr.FileError, OSError)
    assert issubclass(pr.NumericalError, ArithmeticError)
    assert issubclass(pr.InternalError, RuntimeError)
    assert not issubclass(pr.ModelError, ValueError)
    with pytest.raises(ValueError, match="q: expected shape"):
        pr.robots.a465().rnea([0.0] * 5, [0.0] * 6, [0.0] * 6)
    with pytest.raises(OSError, match="no-such.urdf"):
        pr.Robot.from_urdf("no-such.urdf")


def test_unusable_limits_and_robots_are_model_errors():
    urdf = """<robot name="r"><link name="a"/>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j1" type="{kind}"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>{limit}</joint></robot>"""
    bad = urdf.format(kind="revolute", limit='<limit lower="-1" upper="1" effort="1" velocity="-3"/>')
    with pytest.raises(pr.ModelError, match=r"<string>:3: joint 'j1' <limit>: velocity -3 .* is not positive"):
        pr.Robot.from_urdf_string(bad)
    bad = urdf.format(kind="revolute", limit='<limit lower="1" upper="-1" effort="1" velocity="1"/>')
    with pytest.raises(pr.ModelError, match=r"lower \(1\) is above upper \(-1\)"):
        pr.Robot.from_urdf_string(bad)
    with pytest.raises(pr.ModelError, match="has no moving joint"):
        pr.Robot.from_urdf_string(urdf.format(kind="fixed", limit=""))
    robot = pr.Robot.from_urdf_string(urdf.format(kind="revolute", limit='<limit lower="-1" upper="1" effort="1" velocity="1"/>'))
    with pytest.raises(pr.ModelError, match="has no moving joint"):
        pr.Robot.from_urdf_string(urdf.format(kind="revolute", limit='<limit lower="-1" upper="1" effort="1" velocity="1"/>'), lock={"j1": 0.0})
    assert robot.n == 1


def test_wrong_shapes(robot):
    z = np.zeros(6)
    with pytest.raises(pr.InputError, match=r"q: expected shape \(6,\) or \(k, 6\), got shape \[5\]"):
        robot.rnea(np.zeros(5), z, z)
    with pytest.raises(pr.InputError, match="qd: expected shape"):
        robot.rnea(z, np.zeros((2, 3, 6)), z)
    with pytest.raises(pr.InputError, match="qdd: expected shape \\(3, 6\\) like the first argument"):
        robot.rnea(np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((4, 6)))
    with pytest.raises(pr.InputError, match="like the first argument"):
        robot.rnea(np.zeros((1, 6)), z, z)


def test_non_finite_input(robot):
    z = np.zeros(6)
    bad = z.copy()
    bad[2] = np.nan
    with pytest.raises(pr.InputError, match="qd: entry 2 is NaN"):
        robot.rnea(z, bad, z)
    with pytest.raises(pr.InputError, match="tau: entry 2 is NaN"):
        robot.forward_dynamics(z, z, bad)
    batch = np.zeros((3, 6))
    batch[1, 4] = np.inf
    with pytest.raises(pr.InputError, match=r"qdd\[1\]: entry 4 is inf"):
        robot.rnea(np.zeros((3, 6)), np.zeros((3, 6)), batch)
    with pytest.raises(pr.InputError, match=r"qd\[1\]: entry 4 is inf"):
        robot.linearize(np.zeros((3, 6)), batch, np.zeros((3, 6)))
    # a large batch (parallel chunks, multi-sample kernel) names the sample too
    big = np.zeros((5000, 6))
    big[4321, 5] = -np.inf
    with pytest.raises(pr.InputError, match=r"q\[4321\]: entry 5 is -inf"):
        robot.gravity(big)
    with pytest.raises(pr.InputError, match=r"q\[4321\]: entry 5 is -inf"):
        robot.mass_matrix(big)
    with pytest.raises(pr.InputError, match=r"qd\[4321\]: entry 5 is -inf"):
        robot.bias(np.zeros((5000, 6)), big)
    with pytest.raises(pr.InputError, match=r"qdd\[4321\]: entry 5 is -inf"):
        robot.regressor(np.zeros((5000, 6)), np.zeros((5000, 6)), big)
    with pytest.raises(pr.InputError, match=r"qd\[1\]: entry 4 is inf"):
        robot.regressor(np.zeros((3, 6)), batch, np.zeros((3, 6)))
    # the robot still works after errors
    assert robot.regressor(z, z, z).shape == (6, 60)


def test_non_numeric_input(robot):
    with pytest.raises((TypeError, ValueError)):
        robot.rnea(["a"] * 6, np.zeros(6), np.zeros(6))


@pytest.mark.parametrize(
    "value, dtype",
    [
        # numpy's own conversion drops the imaginary part with only a warning
        (np.full(6, 0.5 + 1j), "complex128"),
        ([0.5 + 1j] * 6, "complex128"),
        (np.ones(6, bool), "bool"),
        (["1"] * 6, "<U1"),
        ([object()] * 6, "object"),
        (np.zeros(6, "datetime64[s]"), "datetime64"),
    ],
)
def test_only_real_numbers_are_taken(robot, value, dtype):
    z = np.zeros((3, 6))
    with pytest.raises(TypeError, match=f"expected real numbers .* got dtype {dtype}"):
        robot.mass_matrix(value)
    batch = np.array(value)[None].repeat(3, axis=0)
    with pytest.raises(TypeError, match="expected real numbers"):
        robot.rnea(z, batch, z)
    with pytest.raises(TypeError, match="expected real numbers"):
        robot.linearize(z, z, batch)
    # integers of any width and float32 are real numbers, converted
    for real in (np.arange(6), np.arange(6, dtype=np.uint8), np.arange(6, dtype=np.float32)):
        np.testing.assert_allclose(robot.mass_matrix(real), robot.mass_matrix(np.arange(6.0)))


def test_any_memory_layout_is_read_in_logical_order(robot):
    rng = np.random.default_rng(5)
    Q, QD, QDD = rng.uniform(-1, 1, (3, 9, 6))
    expected = robot.rnea(Q, QD, QDD)
    fortran = [np.asfortranarray(x) for x in (Q, QD, QDD)]
    np.testing.assert_array_equal(robot.rnea(*fortran), expected)
    strided = [np.repeat(x, 2, axis=0)[::2] for x in (Q, QD, QDD)]  # not contiguous
    np.testing.assert_array_equal(robot.rnea(*strided), expected)
    np.testing.assert_array_equal(robot.mass_matrix(np.asfortranarray(Q)), robot.mass_matrix(Q))
    np.testing.assert_array_equal(robot.rnea(Q.T.copy().T, QD, QDD), expected)


def test_lists_and_ints_are_accepted(robot):
    assert robot.rnea([0] * 6, [0] * 6, [0] * 6).dtype == np.float64


def test_bad_urdfs():
    with pytest.raises(pr.FileError, match="nope.urdf"):
        pr.Robot.from_urdf("/nope/nope.urdf")
    with pytest.raises(pr.ModelError, match="not a valid URDF"):
        pr.Robot.from_urdf_string("<robot name='x'><link></robot>")
    with pytest.raises(pr.ModelError, match="<string>:1: joint 'j' is of type floating"):
        pr.Robot.from_urdf_string(
            "<robot name='x'><link name='a'/><link name='b'/><joint name='j' type='floating'>"
            "<parent link='a'/><child link='b'/></joint></robot>"
        )
    with pytest.raises(pr.ModelError, match="triangle inequality"):
        pr.Robot.from_urdf_string(pr.robots.a465_urdf("kinsheel2010_lumped"))
    relaxed = pr.Robot.from_urdf_string(pr.robots.a465_urdf("kinsheel2010_lumped"), check_triangle_inequality=False)
    assert relaxed.n == 6
    with pytest.raises(pr.ModelError, match="lock 'nope'"):
        pr.Robot.from_urdf_string(pr.robots.a465_urdf("physical"), lock={"nope": 0.0})
    with pytest.raises(pr.ModelError, match="unknown robot"):
        pr.robots.a465("nope")


def test_lock_removes_the_joint():
    r = pr.Robot.from_urdf_string(pr.robots.a465_urdf("physical"), lock={"joint6": 0.3})
    assert r.n == 5 and "joint6" not in r.joint_names


from hypothesis import given, settings, strategies as st


@settings(max_examples=150, deadline=None)
@given(
    shape=st.lists(st.integers(0, 7), min_size=0, max_size=3),
    value=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([1e300, -1e300, 0.0])),
    method=st.sampled_from(["rnea", "mass_matrix", "regressor", "linearize", "forward_dynamics", "gravity"]),
)
def test_any_array_gets_a_result_or_our_error(shape, value, method):
    """Arrays of any shape and any value through the dynamics: a finite result or one of the
    library's errors; never a crash, a PanicException or an inf/NaN handed back."""
    robot = pr.robots.a465()
    x = np.full(shape, value)
    args = {"gravity": (x,), "mass_matrix": (x,)}.get(method, (x, x, x))
    try:
        out = getattr(robot, method)(*args)
    except pr.PerturbidError as e:
        assert not isinstance(e, pr.InternalError), e
        return
    results = [out] if isinstance(out, np.ndarray) else [out.torque, out.D, out.H, out.G, out.G_static]
    assert all(np.isfinite(r).all() for r in results)


def test_a_gap_in_a_log_is_refused_or_split_never_filled():
    t = np.concatenate([np.arange(3000) * 1e-3, 103.0 + np.arange(3000) * 1e-3])
    q = np.sin(0.3 * t)[:, None]
    with pytest.raises(pr.InputError, match=r"a gap of 100\.001000 s after t = 2\.999000 s"):
        pr.preprocess(t, q, q)
    out = pr.preprocess(t, q, q, split_at_gaps=True)
    assert not np.any((out.t > 3.0) & (out.t < 103.0)), "samples invented in the gap"
    np.testing.assert_allclose(out.qd[:, 0], 0.3 * np.cos(0.3 * out.t), atol=1e-3)


def test_a_free_gripper_finger_is_warned_about():
    import warnings

    from conftest import erd_dir

    path = erd_dir() / "panda_description/urdf/panda.urdf"
    with pytest.warns(pr.PerturbidWarning, match=r"joint 'panda_finger_joint1' moves 0\.0\d\d kg .*lock=\{'panda_finger_joint1': VALUE\}"):
        robot = pr.Robot.from_urdf(path)
    assert robot.n == 8
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pr.Robot.from_urdf(path, lock={"panda_finger_joint1": 0.02}).n == 7


def test_per_joint_sizes_take_real_numbers_only(robot):
    op = pr.OperatingPoint(np.full(6, 0.3), np.full(6, 0.5), np.zeros(6))
    for dq in (0.01, np.float32(0.01), np.float64(0.01), [0.01] * 6):
        assert pr.plan_experiments(robot, op, dq=dq) is not None
    for dq in (1j, np.complex64(0.01), True, "0.01", [0.01 + 0j] * 6):
        with pytest.raises(pr.InputError, match="dq: expected a real number"):
            pr.plan_experiments(robot, op, dq=dq)


def test_scalar_arguments_refuse_bools(robot):
    # Python's bool is an int: pyo3 alone would read rate=True as 1 Hz and n=True as 1 pass
    op = pr.OperatingPoint(np.full(6, 0.3), np.full(6, 0.5), np.zeros(6))
    plan = pr.plan_experiments(robot, op, n=np.int64(12), seed=np.uint8(1), window=np.float32(0.05))
    t = np.arange(3000) / 1000.0
    q = np.zeros((3000, 6))
    calls = {
        "rate": lambda v: pr.plan_experiments(robot, op, rate=v),
        "n": lambda v: pr.plan_experiments(robot, op, n=v),
        "seed": lambda v: pr.simulate(robot, plan, seed=v),
        "harmonics": lambda v: pr.design_excitation(robot, harmonics=v),
        "order": lambda v: pr.preprocess(t, q, q, order=v),
        "cutoff": lambda v: pr.preprocess(t, q, q, cutoff=v),
        "max_shift": lambda v: pr.identify_local(plan, [], max_shift=v),
        "count": lambda v: pr.suggest_operating_points(robot, count=v),
        "tolerance": lambda v: pr.identify_base_parameters(robot, q, q, q, q, tolerance=v),
        "base_frequency": lambda v: pr.FourierTrajectory(np.zeros((6, 1)), np.zeros((6, 1)), np.zeros(6), base_frequency=v),
    }
    for name, call in calls.items():
        for value in (True, False, np.bool_(True)):
            with pytest.raises(TypeError, match=r"expected (a real number|a non-negative integer).*got a bool") as e:
                call(value)
            assert any(name in note for note in getattr(e.value, "__notes__", [])), (name, e.value)
    # counts and seeds below 0 or past 2^64: said so and named (pyo3 alone raised an
    # OverflowError naming neither)
    for name in ("n", "seed", "harmonics", "order", "count"):
        for value, said in ((-1, "a negative one"), (np.int64(-3), "a negative one"), (2**70, "one too large")):
            with pytest.raises(TypeError, match=f"expected a non-negative integer.*got {said}") as e:
                calls[name](value)
            assert any(name in note for note in getattr(e.value, "__notes__", [])), (name, e.value)


def test_masked_arrays_are_refused_not_read_through(robot):
    # a masked entry still holds a value; reading the array's memory would use it as data
    q = np.ma.masked_array(np.full(6, 0.3), mask=[0, 0, 1, 0, 0, 0])
    q.data[2] = 1e3
    for call in (lambda: robot.gravity(q), lambda: robot.mass_matrix(np.ma.masked_array(np.zeros((100, 6)))),
                 lambda: robot.rnea(np.zeros(6), q, np.zeros(6))):
        with pytest.raises(TypeError, match="masked array: its masked entries would be read as data"):
            call()
    # filled, it is an ordinary array
    np.testing.assert_allclose(robot.gravity(q.filled(0.3)), robot.gravity(np.full(6, 0.3)))
    # and an ndarray subclass that is not masked is taken
    class Tagged(np.ndarray):
        pass
    np.testing.assert_allclose(robot.gravity(np.full(6, 0.3).view(Tagged)), robot.gravity(np.full(6, 0.3)))


def test_trajectory_times_are_finite_one_dimensional_and_bounded():
    traj = pr.FourierTrajectory(np.full((6, 2), 0.1), np.zeros((6, 2)), np.zeros(6))
    with pytest.raises(pr.InputError, match=r"^t\[0\]: NaN; expected a finite time \(s\)$"):
        traj.sample(np.nan)
    with pytest.raises(pr.InputError, match=r"^t\[1\]: inf;"):
        traj.sample([0.0, np.inf])
    with pytest.raises(pr.InputError, match=r"^t: expected a 1-D array, got shape \[3, 2\]"):
        traj.sample(np.zeros((3, 2)))
    # 18 values a time: more than 2^28 values is refused before anything is allocated
    with pytest.raises(pr.InputError, match=r"^t: 20000000 times give 2\.000e7 samples of 18 values"):
        traj.sample(np.zeros(20_000_000))
    assert [a.shape for a in traj.sample(np.zeros(0))] == [(0, 6)] * 3
    q, qd, qdd = traj.sample(np.array([0.0, 1.0]))
    assert q.shape == (2, 6) and np.all(np.isfinite(q))


def test_a_robot_past_the_size_bound_is_refused_before_its_buffers(tmp_path):
    link = '<link name="l{i}"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    joint = ('<joint name="j{i}" type="revolute"><parent link="l{p}"/><child link="l{i}"/>'
             '<axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="10"/></joint>')
    n = 1001
    urdf = '<robot name="snake"><link name="l0"/>' + "".join(
        link.format(i=i) + joint.format(i=i, p=i - 1) for i in range(1, n + 1)) + "</robot>"
    with pytest.raises(pr.ModelError, match="robot 'snake' has 1001 moving bodies; at most 1000 are supported"):
        pr.Robot.from_urdf_string(urdf)


def test_the_friction_regressor_is_made_a_block_at_a_time(robot):
    # 2500 samples: three blocks of the Rust side, the last one short; each sample's rows are
    # the regressor of that sample alone
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-1, 1, (2500, 6)) for _ in range(3))
    full = robot.regressor(q, qd, qdd, friction="viscous,coulomb")
    for s in (0, 1023, 1024, 2047, 2048, 2499):
        np.testing.assert_array_equal(full[s], robot.regressor(q[s], qd[s], qdd[s], friction="viscous,coulomb"))
    out = np.empty_like(full)
    assert robot.regressor(q, qd, qdd, friction="viscous,coulomb", out=out) is out
    np.testing.assert_array_equal(out, full)


def test_simulated_friction_is_bounded(robot):
    op = pr.OperatingPoint([0.1] * 6, [0.1] * 6, [0.0] * 6)
    plan = pr.plan_experiments(robot, op, experiments=["nominal"])
    with pytest.raises(pr.InputError, match=r"friction coulomb\[2\]: 1e300; expected at most 1000000 in magnitude"):
        pr.simulate(robot, plan, friction={"coulomb": [0.1, 0.1, 1e300, 0.1, 0.1, 0.1]})
