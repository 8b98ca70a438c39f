"""The direct method from Python: regressor against Pinocchio, base parameters, the globally
linearised model, excitation design, and the real Franka Emika Panda log."""

import json
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import erd_dir, pair_from_text, pair_from_urdf

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "panda-gaz2019"
TABLE2_Q = [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0]
# validation relative RMS (%) of the reference protocol (Pinocchio regressor + numpy), joints 1-7
PANDA_REFERENCE = [5.8, 1.1, 2.1, 1.0, 6.6, 5.9, 19.6]


def pin_parameters(pair):
    """Pinocchio's dynamic parameters of the joints, in our joint order (one body per joint)."""
    ids = [pair.model.getJointId(n) for n in pair.ours.joint_names]
    return np.concatenate([pair.model.inertias[i].toDynamicParameters() for i in ids]), ids


@pytest.mark.parametrize(
    "make",
    [
        lambda: pair_from_text(pr.robots.a465_urdf("kinsheel2010")),
        lambda: pair_from_urdf(erd_dir() / "ur_description/urdf/ur5_robot.urdf"),
        lambda: pair_from_urdf(
            erd_dir() / "panda_description/urdf/panda.urdf",
            lock={"panda_finger_joint1": 0.0},
            pin_lock={"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0},
        ),
    ],
    ids=["a465", "ur5", "panda"],
)
def test_regressor_matches_pinocchio(make):
    pair = make()
    rng = np.random.default_rng(4)
    theta_pin, ids = pin_parameters(pair)
    np.testing.assert_allclose(pair.ours.parameters, theta_pin, rtol=1e-10, atol=1e-12)
    cols = np.concatenate([np.arange(10 * (i - 1), 10 * i) for i in ids])
    for _ in range(5):
        q, qd, qdd = pair.random_state(rng, 2.0)
        ours = pair.ours.regressor(q, qd, qdd)
        theirs = pin.computeJointTorqueRegressor(pair.model, pair.data, pair.q(q), pair.v(qd), pair.v(qdd))
        theirs = theirs[np.ix_(pair.idx_v, cols)]
        np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-9 * np.abs(theirs).max())
        # the rigid bodies' regressor; the armature (the A465's rotors) adds its own term
        rigid = ours @ pair.ours.parameters + pair.ours.armature * qdd
        np.testing.assert_allclose(rigid, pair.ours.rnea(q, qd, qdd), atol=1e-9)
        full = pair.ours.regressor(q, qd, qdd, friction="armature")
        theta = np.concatenate([pair.ours.parameters, pair.ours.armature])
        np.testing.assert_allclose(full @ theta, pair.ours.rnea(q, qd, qdd), atol=1e-9)
    # a batch
    qs = np.array([pair.random_state(rng)[0] for _ in range(4)])
    assert pair.ours.regressor(qs, 0 * qs, 0 * qs).shape == (4, pair.ours.n, 10 * pair.ours.n)


def excitation(robot, harmonics, frequency, amplitude, seed):
    """Random Fourier coefficients about a posture away from the Table 2 point."""
    rng = np.random.default_rng(seed)
    n = robot.n
    q0 = np.array([0.2, 0.3, -0.4, 0.1, 0.5, -0.2])[:n]
    return pr.FourierTrajectory(
        rng.uniform(-amplitude, amplitude, (n, harmonics)),
        rng.uniform(-amplitude, amplitude, (n, harmonics)),
        q0,
        base_frequency=frequency,
    )

def log_with_friction(robot, amplitude, motion_seed, seed):
    """20 s of a Fourier excitation (0.1 Hz, 5 harmonics of `amplitude` rad drawn with
    `motion_seed`) sampled every millisecond, its torques with 0.3 N m s/rad viscous and 0.5 N m
    Coulomb friction and 0.03 N m of noise (the generator of `seed`): t, q, qd, qdd, tau and the
    generator."""
    traj = excitation(robot, 5, 0.1, amplitude, motion_seed)
    t = np.arange(0, 20, 1e-3)
    q, qd, qdd = traj.sample(t)
    rng = np.random.default_rng(seed)
    tau = robot.rnea(q, qd, qdd) + 0.5 * np.sign(qd) + 0.3 * qd + rng.normal(0.0, 0.03, q.shape)
    return t, q, qd, qdd, tau, rng



def noisy_log(step, seed):
    """The A465 through one period of the test excitation sampled every `step` s, its torques
    with 0.05 N m of white noise: robot, t, q, qd, qdd, tau and the generator."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, step)
    q, qd, qdd = traj.sample(t)
    rng = np.random.default_rng(seed)
    tau = robot.rnea(q, qd, qdd) + rng.normal(0.0, 0.05, q.shape)
    return robot, t, q, qd, qdd, tau, rng


def test_base_parameters_on_simulated_a465_are_exact():
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, 0.01)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    # 10 per body and the armature per joint: the robot has rotors, so the fit takes them
    assert len(fit.theta_base) == len(fit.names) == len(fit.kept) and len(fit.kept) + len(fit.dropped) == 66
    rng = np.random.default_rng(2)
    qh, qdh, qddh = rng.uniform(-1, 1, (3, 40, 6))
    expected = robot.rnea(qh, qdh, qddh)
    assert np.linalg.norm(fit.predict(qh, qdh, qddh) - expected) < 1e-8 * np.linalg.norm(expected)
    m_true = robot.mass_matrix(TABLE2_Q)
    assert np.linalg.norm(fit.mass_matrix(TABLE2_Q) - m_true) < 1e-8 * np.linalg.norm(m_true)
    # theta_base = theta[kept] + K theta[dropped] for the true parameters
    theta = np.concatenate([robot.parameters, robot.armature])
    np.testing.assert_allclose(fit.theta_base, theta[fit.kept] + fit.K @ theta[fit.dropped], rtol=1e-7, atol=1e-9)
    assert fit.mass_matrix(np.tile(TABLE2_Q, (2, 1))).shape == (2, 6, 6)
    # the predictions' standard errors: per joint, sqrt(z^T R z) with z its base-regressor row
    # times the parameters' standard errors and R their correlation (the JSON's), in numpy
    se = fit.predict_stderr(qh[:5], qdh[:5], qddh[:5])
    assert se.shape == (5, 6) and (se > 0).all()
    r = np.array(json.loads(fit.to_json())["correlation"])
    np.testing.assert_array_equal(fit.correlation, r)
    full = np.concatenate([robot.regressor(qh[:5], qdh[:5], qddh[:5]), qddh[:5, :, None] * np.eye(6)], axis=2)
    z = full[:, :, fit.kept] * fit.stderr
    np.testing.assert_allclose(se, np.sqrt(np.einsum("kja,ab,kjb->kj", z, r, z)), rtol=1e-9)


def test_torque_columns_are_checked_against_the_model():
    """A log whose shoulder and elbow torques are swapped, or whose elbow reads with the
    opposite sign, is named in a PerturbidWarning and in fit.torque_columns; the model's own
    torques raise nothing (checked against columns computed here by numpy least squares)."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, 0.005)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    columns = fit.torque_columns
    assert [c["joint"] for c in columns] == robot.joint_names
    assert all(c["finding"] is None for c in columns)
    # the elbow's gain and scale, independently: its column on its model's gravity torque and
    # the rest of its inverse dynamics, beside friction, an offset and a rotor's inertia
    g = robot.rnea(q, np.zeros_like(q), np.zeros_like(q))
    rest = tau - g
    j = 2
    own = np.column_stack([qd[:, j], np.sign(qd[:, j]), qdd[:, j], np.ones(len(t))])
    full = np.column_stack([g[:, j], rest[:, j], own])
    y = tau[:, j]

    def unexplained(x):
        c = np.linalg.lstsq(x, y, rcond=None)[0]
        return np.sum((y - x @ c) ** 2), c

    base, _ = unexplained(own)
    with_model, coef = unexplained(full)
    assert columns[j]["explained"] == pytest.approx((base - with_model) / base, abs=1e-6)
    assert columns[j]["scale"] == pytest.approx(coef[0], rel=1e-6)
    swapped = tau.copy()
    swapped[:, [1, 2]] = tau[:, [2, 1]]
    with pytest.warns(pr.PerturbidWarning, match="joint 'joint2' follows the model of joint 'joint3'"):
        fit = pr.identify_base_parameters(robot, q, qd, qdd, swapped, friction=None, weighting="ols")
    assert [c["follows"] for c in fit.torque_columns][1:3] == ["joint3", "joint2"]
    # the clean model validated on the swapped log names the swap too; on its own log, nothing
    clean = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    with pytest.warns(pr.PerturbidWarning, match="joint 'joint3' follows the model of joint 'joint2'"):
        v = pr.validate(clean, q, qd, qdd, swapped)
    assert [c["follows"] for c in v.torque_columns][1:3] == ["joint3", "joint2"]
    assert v.torque_columns[1]["finding"] is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = pr.validate(clean, q, qd, qdd, tau)
    assert [c["explained"] for c in v.torque_columns] == [c["explained"] for c in columns]
    # positions (and their derivatives) in degrees: no column follows the robot's model
    with pytest.warns(pr.PerturbidWarning, match="does not match the robot"):
        v = pr.validate(clean, np.degrees(q), np.degrees(qd), np.degrees(qdd), tau)
    assert all(c["explained"] < 0.5 and c["finding"] is None for c in v.torque_columns)
    # ... and leave the joint limits: named as degrees, each joint's extent as numpy finds it
    with pytest.warns(pr.PerturbidWarning, match="the log's positions look like degrees"):
        v = pr.validate(clean, np.degrees(q), np.degrees(qd), np.degrees(qdd), tau)
    assert v.position_range and all(r["degrees"] for r in v.position_range)
    for r in v.position_range:
        j = robot.joint_names.index(r["joint"])
        assert (r["min"], r["max"]) == (np.degrees(q[:, j]).min(), np.degrees(q[:, j]).max())
    with pytest.warns(pr.PerturbidWarning, match="look like degrees") as caught:
        fit = pr.identify_base_parameters(
            robot, np.degrees(q), np.degrees(qd), np.degrees(qdd), tau, friction=None, weighting="ols"
        )
    # friction terms refitted to a log that does not match the robot take up part of what is
    # wrong with it: measured, but not named while the columns are found wrong
    assert fit.unmodelled_friction
    assert not any("friction the fit leaves out" in str(w.message) for w in caught)
    assert [r["joint"] for r in fit.position_range] == [r["joint"] for r in v.position_range]
    assert clean.position_range == [] and pr.validate(clean, q, qd, qdd, tau).position_range == []
    negated = tau.copy()
    negated[:, 2] *= -1.0
    with pytest.warns(pr.PerturbidWarning, match="joint 'joint3' reads -1.000 times"):
        fit = pr.identify_base_parameters(robot, q, qd, qdd, negated, friction=None, weighting="ols")
    assert "negate" in fit.torque_columns[2]["finding"]


def test_torques_out_of_step_are_found():
    """Torques logged 30 samples after their positions: the fit finds the shift and warns;
    the fraction left unexplained as logged and at the shift is checked against numpy least
    squares of each column on its joint's model torques and friction, offset and rotor terms
    (the geometric mean over the columns); validate finds it too, and nothing on the log in
    step."""
    robot, t, q, qd, qdd, tau, rng = noisy_log(0.005, 3)
    k = len(t)
    late = tau[np.clip(np.arange(k) - 30, 0, k - 1)]
    with pytest.warns(pr.PerturbidWarning, match="logged 30 sample"):
        fit = pr.identify_base_parameters(robot, q, qd, qdd, late, friction=None, weighting="ols")
    lag = fit.torque_lag
    assert lag["samples"] == 30 and lag["finding"] is not None
    assert lag["joints"] == robot.joint_names
    g = robot.rnea(q, np.zeros_like(q), np.zeros_like(q))
    rest = robot.rnea(q, qd, qdd) - g
    reach = min(500, k // 4)
    rows = np.arange(reach, k - reach)  # consecutive: fewer than 2000

    def unexplained(shift):
        logs = []
        for j in range(robot.n):
            x = np.column_stack([g[rows, j], rest[rows, j], qd[rows, j], np.sign(qd[rows, j]), qdd[rows, j], np.ones(len(rows))])
            y = late[rows + shift, j]
            c = np.linalg.lstsq(x, y, rcond=None)[0]
            logs.append(np.log(max(np.sum((y - x @ c) ** 2) / np.sum((y - y.mean()) ** 2), 1e-15)))
        return np.exp(np.mean(logs))

    assert lag["unexplained"] == pytest.approx(unexplained(0), rel=1e-6)
    assert lag["unexplained_at_lag"] == pytest.approx(unexplained(30), rel=1e-6)
    clean = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    assert clean.torque_lag["finding"] is None
    with pytest.warns(pr.PerturbidWarning, match="logged 30 sample"):
        v = pr.validate(clean, q, qd, qdd, late)
    assert v.torque_lag["samples"] == 30
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pr.validate(clean, q, qd, qdd, tau).torque_lag["finding"] is None


def test_joint_offsets_are_estimated_with_the_parameters():
    """Positions of the A465's wrist logged 0.2 rad off its zero: the fit estimates every
    determined joint's offset (not the vertical base axis's nor the last joint's, which the
    parameters absorb), on 600 evenly spread samples; what its residual is as logged and with the offsets added is checked
    against numpy least squares of the torques on the regressor and the rotors' inertias (the
    same column space as the base parameters'); the estimates are saved with the model."""
    robot, t, q, qd, qdd, tau, rng = noisy_log(0.005, 3)
    k = len(t)
    rows = np.arange(600) * k // 600  # the samples checked: 600 evenly spread
    logged = q.copy()
    logged[:, 4] += 0.2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the offset the parameters absorb bends the wrist's rotor inertia
        fit = pr.identify_base_parameters(robot, logged, qd, qdd, tau, friction=None, weighting="ols")
    o = fit.position_offsets
    # never the vertical base axis nor the last joint; the parallel shoulder and elbow can turn
    # together as the parameters absorb, so one of them is left out as not determined
    assert set(o["joints"]) <= {"joint2", "joint3", "joint4", "joint5"} and "joint5" in o["joints"], o
    assert len(set(o["joints"]) & {"joint2", "joint3"}) == 1, o
    assert all(s <= 0.1 for s in o["stderr"]), o
    # the others are said, with why: the base axis and the last joint absorbed, the parallel
    # axis left out as undetermined (its standard error beyond 0.1 rad)
    why = {l["joint"]: l["why"] for l in o["left_out"]}
    assert set(why) | set(o["joints"]) == set(robot.joint_names) and not set(why) & set(o["joints"]), o
    assert why["joint1"] == why["joint6"] == "absorbed", o
    assert all(l["stderr"] > 0.1 for l in o["left_out"] if l["why"] == "undetermined"), o
    assert "undetermined" in why.values(), o
    assert o["finding"] is None or "joint5" in o["finding"]

    def rms(positions):
        x = robot.regressor(positions[rows], qd[rows], qdd[rows])
        x = x.reshape(-1, x.shape[-1])
        # the A465's rotor inertias: one column a joint, its acceleration in its own rows
        rotors = np.zeros((x.shape[0], robot.n))
        for j in range(robot.n):
            rotors[j :: robot.n, j] = qdd[rows, j]
        x = np.hstack([x, rotors])
        y = tau[rows].reshape(-1)
        c = np.linalg.lstsq(x, y, rcond=1e-10)[0]
        return np.sqrt(np.mean((y - x @ c) ** 2))

    assert o["unexplained"] == pytest.approx(rms(logged), rel=1e-6)
    moved = logged.copy()
    for joint, d in zip(o["joints"], o["offsets"]):
        moved[:, robot.joint_names.index(joint)] += d
    assert o["unexplained_with_offsets"] == pytest.approx(rms(moved), rel=1e-6)
    # the wrist's own offset is the one estimated (to within three standard errors)
    i = o["joints"].index("joint5")
    assert abs(o["offsets"][i] + 0.2) < 3 * o["stderr"][i] + 1e-3, o
    # saved with the model
    saved = json.loads(fit.to_json())["position_offsets"]
    assert saved == {k: v for k, v in o.items() if k != "finding"}


def test_a_new_logs_offsets_are_found_against_a_saved_fit():
    """validate() checks a new log's zero offsets against the fit's parameters, held: a joint
    zeroed elsewhere since (0.1 rad at the elbow) is named in a warning and estimated; its
    residuals with and without the offsets are the model's own predictions' (numpy)."""
    robot, t, q, qd, qdd, tau, rng = noisy_log(0.005, 5)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    assert fit.position_offsets["finding"] is None
    new_tau = robot.rnea(q, qd, qdd) + rng.normal(0.0, 0.05, q.shape)  # the same motion again
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = pr.validate(fit, q, qd, qdd, new_tau)
    assert v.position_offsets["finding"] is None and "joint1" not in v.position_offsets["joints"]
    logged = q.copy()
    logged[:, 2] += 0.1
    with pytest.warns(pr.PerturbidWarning, match=r"joint\(s\) 'joint3' -0\.1\d* rad .*not those of the log the model was identified from"):
        v = pr.validate(fit, logged, qd, qdd, new_tau)
    o = v.position_offsets
    i = o["joints"].index("joint3")
    assert abs(o["offsets"][i] + 0.1) < 3 * o["stderr"][i] + 1e-3, o
    rows = np.arange(600) * len(t) // 600

    def rms(positions):
        r = (new_tau - fit.predict(positions, qd, qdd))[rows] / fit.sigma
        return np.sqrt(np.mean(r**2))

    moved = logged.copy()
    for joint, d in zip(o["joints"], o["offsets"]):
        moved[:, robot.joint_names.index(joint)] += d
    assert o["unexplained"] == pytest.approx(rms(logged), rel=1e-6)
    assert o["unexplained_with_offsets"] == pytest.approx(rms(moved), rel=1e-6)
    assert o["unexplained_with_offsets"] < 0.5 * o["unexplained"]
    # a model of another kind (here anything with predict) has no parameters to hold
    class Predictor:
        def predict(self, q, qd, qdd):
            return fit.predict(q, qd, qdd)

    assert pr.validate(Predictor(), logged, qd, qdd, new_tau).position_offsets is None


def test_a_validation_log_with_a_wrong_or_dead_torque_column():
    """Against a saved fit, a new log whose shoulder torque reads with the opposite sign is
    named for that column only: the zero offsets that take up part of its error are estimated
    but not named (no warning, `finding` None), though on their own they would be. A column
    that reads 0 throughout while the robot moves is refused, naming its joint."""
    robot, t, q, qd, qdd, tau, rng = noisy_log(0.005, 5)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    negated = tau.copy()
    negated[:, 1] *= -1.0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        v = pr.validate(fit, q, qd, qdd, negated)
    said = [str(w.message) for w in caught]
    assert any("joint 'joint2' reads" in w and "negate the column" in w for w in said), said
    assert not any("not those of the log the model was identified from" in w for w in said), said
    assert v.position_offsets is not None and v.position_offsets["finding"] is None
    # the offsets were fitted to the column's error all the same: they leave less of it
    o = v.position_offsets
    assert o["joints"] and o["unexplained_with_offsets"] < 0.9 * o["unexplained"], o
    dead = tau.copy()
    dead[:, 3] = 0.0
    with pytest.raises(pr.InputError, match="the torque of joint 'joint4' \\(column 4\\) is 0 N m in all .* while the robot moves"):
        pr.validate(fit, q, qd, qdd, dead)


def test_a_weakly_exciting_log_is_named():
    """The test excitation scaled to +-0.05 rad excites the A465's base parameters weakly: the
    fit's cond and least determined combination are numpy's SVD of the column-scaled base
    regressor (Phi[:, kept] with the rotors' columns), each joint's extent numpy's, and the
    warning names them; the same motion at +-0.3 rad is no finding. Saved and loaded with
    the model; a hand-edited cond is refused on load."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.05, 1)
    t = np.arange(0, traj.period, 0.01)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd) + np.random.default_rng(0).normal(0.0, 0.05, q.shape)
    with pytest.warns(pr.PerturbidWarning, match="the data excite the base parameters weakly") as caught:
        fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    w = fit.weak_excitation
    assert w is not None and w["cond"] == fit.cond > 2000
    # numpy: the base regressor, its columns scaled to unit norm, and its SVD
    phi = robot.regressor(q, qd, qdd)
    rotors = qdd[:, :, None] * np.eye(6)
    full = np.concatenate([phi, rotors], axis=2).reshape(-1, 66)
    base = full[:, fit.kept]
    scaled = base / np.linalg.norm(base, axis=0)
    _, sv, vt = np.linalg.svd(scaled, full_matrices=False)
    assert w["cond"] == pytest.approx(sv[0] / sv[-1], rel=1e-6)
    weakest = vt[-1] * np.sign(vt[-1][np.argmax(np.abs(vt[-1]))])
    kept_names = [n.split(" ")[0] for n in fit.names]
    order = np.argsort(-np.abs(weakest))
    named = [t["parameter"].removesuffix(" (merged)") for t in w["weakest"]]
    assert named == [kept_names[i] for i in order[: len(named)]]
    for term, i in zip(w["weakest"], order):
        assert term["weight"] == pytest.approx(weakest[i], abs=1e-6)
        assert term["parameter"].endswith(" (merged)") == (" + " in fit.names[i] or " - " in fit.names[i])
    assert [m["joint"] for m in w["motion"]] == robot.joint_names
    for j, m in enumerate(w["motion"]):
        assert m["extent"] == pytest.approx(np.ptp(q[:, j]), rel=1e-12)
        assert m["range"] == pytest.approx(robot.upper[j] - robot.lower[j], rel=1e-12)
    message = next(str(c.message) for c in caught if "weakly" in str(c.message))
    least = min(range(6), key=lambda j: np.ptp(q[:, j]) / (robot.upper[j] - robot.lower[j]))
    assert f"'{robot.joint_names[least]}'" in message and named[0] in message, message
    saved = json.loads(fit.to_json())
    assert saved["weak_excitation"]["cond"] == fit.cond
    # the same motion over more of the joints' ranges is no finding
    wide = excitation(robot, 5, 0.1, 0.3, 1)
    q, qd, qdd = wide.sample(t)
    tau = robot.rnea(q, qd, qdd) + np.random.default_rng(0).normal(0.0, 0.05, q.shape)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit_wide = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None, weighting="ols")
    assert fit_wide.weak_excitation is None and fit_wide.cond < 2000
    assert "weak_excitation" not in json.loads(fit_wide.to_json())


def test_filtered_torques_are_fitted_with_the_filtered_coulomb_column():
    """preprocess filters sign(qd) as it filters the torques (Recording.coulomb); given to the
    fit, it is the Coulomb term's column: the fit equals numpy's least squares on the
    regressor, the rotors', viscous and that column, and finds the friction the log was made
    with (0.3 N m s/rad, 0.5 N m), where sign(qd) gives the Coulomb terms low by many standard
    errors. predict and validate take it too; validate refuses it for another model."""
    robot = pr.robots.a465()
    t, q, qd, qdd, tau, rng = log_with_friction(robot, 0.12, 1, 0)
    rec = pr.preprocess(t, q, tau)
    c = rec.coulomb
    assert c.shape == rec.q.shape and np.abs(c).max() <= 1.2 and np.abs(c).min() < 0.5
    friction = ["viscous", "coulomb"]
    fit = pr.identify_base_parameters(robot, rec.q, rec.qd, rec.qdd, rec.tau, friction=friction, weighting="ols", coulomb=c)
    # numpy's columns in the fit's order of the full parameters: the 60 inertial ones, then
    # each joint's terms (its own rows only)
    phi = robot.regressor(rec.q, rec.qd, rec.qdd)
    term = {"viscous": rec.qd, "coulomb": c, "armature": rec.qdd}
    columns = []
    for i, name in enumerate(fit.full_names):
        if i < 60:
            columns.append(phi[:, :, i])
        else:
            joint, kind = name.split(".")
            own = np.zeros_like(rec.q)
            j = robot.joint_names.index(joint)
            own[:, j] = term[kind][:, j]
            columns.append(own)
    x = np.stack(columns, axis=2).reshape(-1, len(fit.full_names))
    theta = np.linalg.lstsq(x[:, fit.kept], rec.tau.reshape(-1), rcond=None)[0]
    np.testing.assert_allclose(fit.theta_base, theta, rtol=1e-6, atol=1e-9)
    plain = pr.identify_base_parameters(robot, rec.q, rec.qd, rec.qdd, rec.tau, friction=friction, weighting="ols")
    for j in range(1, 7):
        i = fit.names.index(f"joint{j}.coulomb")
        assert abs(fit.theta_base[i] - 0.5) < 4 * fit.stderr[i] + 0.005
        assert 0.5 - plain.theta_base[i] > 5 * plain.stderr[i]
        i = fit.names.index(f"joint{j}.viscous")
        assert abs(fit.theta_base[i] - 0.3) < 4 * fit.stderr[i] + 0.005
    np.testing.assert_allclose(fit.predict(rec.q, rec.qd, rec.qdd, coulomb=c), x[:, fit.kept].dot(fit.theta_base).reshape(-1, 6), rtol=1e-9, atol=1e-9)
    v = pr.validate(fit, rec.q, rec.qd, rec.qdd, rec.tau, coulomb=c)
    assert (v.rms < 0.01).all(), v.rms
    assert (pr.validate(fit, rec.q, rec.qd, rec.qdd, rec.tau).rms > 3 * v.rms).any()

    class Predictor:
        def predict(self, q, qd, qdd):
            return fit.predict(q, qd, qdd)

    with pytest.raises(pr.InputError, match="coulomb"):
        pr.validate(Predictor(), rec.q, rec.qd, rec.qdd, rec.tau, coulomb=c)
    with pytest.raises(pr.InputError, match="expected a value within"):
        pr.identify_base_parameters(robot, rec.q, rec.qd, rec.qdd, rec.tau, friction=friction, coulomb=3 * c)


def test_a_recording_given_whole_brings_its_coulomb_column_and_time():
    """A preprocessed Recording as q, alone, is fitted, predicted at and validated with its
    own Coulomb column and time: the same numbers as its arrays given with coulomb= and t=,
    and not those of its arrays alone (the bias a forgotten coulomb= leaves). Slices of it
    fit one part and validate another. Mixing a Recording with arrays, or giving one without
    velocities, is refused by name."""
    robot = pr.robots.a465()
    t, q, qd, qdd, tau, rng = log_with_friction(robot, 0.12, 1, 1)
    rec = pr.preprocess(t, q, tau)
    split = int(0.7 * len(rec))
    part, rest = rec[:split], rec[split:]
    assert len(part) == split and len(rest) == len(rec) - split and part.name.endswith(f"[0:{split}]")
    np.testing.assert_array_equal(part.coulomb, rec.coulomb[:split])
    np.testing.assert_array_equal(rest.t, rec.t[split:])
    np.testing.assert_array_equal(rec[-100:].tau, rec.tau[-100:])
    friction = ["viscous", "coulomb"]
    whole = pr.identify_base_parameters(robot, part, friction=friction)
    arrays = (part.q, part.qd, part.qdd, part.tau)
    given = pr.identify_base_parameters(robot, *arrays, friction=friction, t=part.t, coulomb=part.coulomb)
    np.testing.assert_array_equal(whole.theta_base, given.theta_base)
    forgotten = pr.identify_base_parameters(robot, *arrays, friction=friction)
    assert np.abs(forgotten.theta_base - whole.theta_base).max() > 0.01
    consistent = pr.identify_consistent_parameters(robot, part, friction=friction, max_iterations=50)
    consistent_given = pr.identify_consistent_parameters(robot, *arrays, friction=friction, max_iterations=50, coulomb=part.coulomb)
    np.testing.assert_array_equal(consistent.theta, consistent_given.theta)
    np.testing.assert_array_equal(whole.predict(rest), whole.predict(rest.q, rest.qd, rest.qdd, coulomb=rest.coulomb))
    np.testing.assert_array_equal(whole.predict_stderr(rest), whole.predict_stderr(rest.q, rest.qd, rest.qdd, coulomb=rest.coulomb))
    v = pr.validate(whole, rest)
    np.testing.assert_array_equal(v.residuals, pr.validate(whole, rest.q, rest.qd, rest.qdd, rest.tau, coulomb=rest.coulomb).residuals)
    assert (v.rms < 0.01).all(), v.rms

    class Predictor:  # another model: the recording's Coulomb column is not given to it
        def predict(self, q, qd, qdd):
            return whole.predict(q, qd, qdd)

    np.testing.assert_array_equal(pr.validate(Predictor(), rest).residuals, pr.validate(whole, rest.q, rest.qd, rest.qdd, rest.tau).residuals)
    with pytest.raises(pr.InputError, match="coulomb: given with a Recording as q"):
        pr.identify_base_parameters(robot, part, friction=friction, coulomb=part.coulomb)
    with pytest.raises(pr.InputError, match="qd: given with a Recording as q"):
        whole.predict(rest, rest.qd)
    with pytest.raises(pr.InputError, match="tau: missing"):
        pr.identify_base_parameters(robot, part.q, part.qd, part.qdd)
    with pytest.raises(pr.InputError, match="qdd: missing"):
        pr.validate(whole, rest.q, rest.qd, tau=rest.tau)
    raw = pr.Recording(t, q, tau)
    with pytest.raises(pr.InputError, match="no velocities and accelerations.*preprocess it first"):
        pr.identify_base_parameters(robot, raw)
    with pytest.raises(pr.InputError, match="step 1"):
        rec[::2]
    with pytest.raises(pr.InputError, match="a slice of samples"):
        rec[3]
    with pytest.raises(pr.InputError, match="at least 2 samples"):
        rec[5:6]
    with pytest.raises(TypeError, match="argument 'qd'"):
        pr.identify_base_parameters(robot, part.q, "x", part.qdd, part.tau)


def test_several_recordings_are_fitted_together():
    """A list of preprocessed Recordings (two runs of other excitations) is fitted as their
    arrays stacked with their Coulomb columns are; the model keeps each one's findings in
    `logs`, named by it; a list mixed with arrays, or holding a Recording without velocities,
    is refused."""
    robot = pr.robots.a465()
    recs = []
    for motion, seed in [(1, 1), (2, 2)]:
        t, q, qd, qdd, tau, _ = log_with_friction(robot, 0.1, motion, seed)
        recs.append(pr.preprocess(t, q, tau, name=f"run{motion}.csv"))
    friction = ["viscous", "coulomb"]
    both = pr.identify_base_parameters(robot, recs, friction=friction)
    stack = lambda field: np.vstack([getattr(r, field) for r in recs])
    arrays = pr.identify_base_parameters(robot, stack("q"), stack("qd"), stack("qdd"), stack("tau"), friction=friction, coulomb=stack("coulomb"))
    np.testing.assert_allclose(both.theta_base, arrays.theta_base, rtol=1e-10, atol=1e-12)
    assert both.samples == len(recs[0]) + len(recs[1])
    logs = json.loads(both.to_json())["logs"]
    assert [l["log"] for l in logs] == ["run1.csv (preprocessed)", "run2.csv (preprocessed)"], logs
    # a tuple reads as a list; one Recording alone is the one-log fit
    np.testing.assert_array_equal(pr.identify_base_parameters(robot, tuple(recs), friction=friction).theta_base, both.theta_base)
    with pytest.raises(TypeError, match="not a mix"):
        pr.identify_base_parameters(robot, [recs[0], recs[1].q], friction=friction)
    with pytest.raises(pr.InputError, match="tau: given with a list of Recordings"):
        pr.identify_base_parameters(robot, recs, tau=stack("tau"))
    raw = pr.Recording(t, q, tau, name="raw.csv")
    with pytest.raises(pr.InputError, match=r"Recording 1 \('raw.csv'\).*without velocities and accelerations.*preprocess it first"):
        pr.identify_base_parameters(robot, [recs[0], raw])
    # physically consistent alike: the same parameters as from the arrays, each log's findings kept
    consistent = pr.identify_consistent_parameters(robot, recs, friction=friction, max_iterations=50)
    flat = pr.identify_consistent_parameters(robot, stack("q"), stack("qd"), stack("qdd"), stack("tau"), friction=friction, coulomb=stack("coulomb"), max_iterations=50)
    np.testing.assert_allclose(consistent.theta, flat.theta, rtol=1e-9, atol=1e-12)
    for m in (consistent.model, consistent.unconstrained):
        assert [l["log"] for l in json.loads(m.to_json())["logs"]] == ["run1.csv (preprocessed)", "run2.csv (preprocessed)"]
    assert "logs" not in json.loads(pr.identify_consistent_parameters(robot, recs[0], friction=friction, max_iterations=50).model.to_json())
    # what takes one Recording says so of a list
    with pytest.raises(pr.InputError, match="q: a list of Recordings, which only the fits take"):
        pr.validate(both, recs)
    with pytest.raises(pr.InputError, match="q: a list of Recordings, which only the fits take"):
        both.predict(recs)
    # the same samples twice: one Recording given twice, or a part of one given again
    with pytest.raises(pr.InputError, match=r"q: Recording 0 \('run1.csv \(preprocessed\)'\) and Recording 2 \('run1.csv \(preprocessed\)'\) hold the same \d+ samples, bit for bit.*give each run's samples once"):
        pr.identify_base_parameters(robot, [recs[0], recs[1], recs[0]], friction=friction)
    with pytest.raises(pr.InputError, match=r"samples 1 to 300 of Recording 1 .* are samples 101 to 400 of Recording 0"):
        pr.identify_base_parameters(robot, [recs[1], recs[1][100:400]], friction=friction)


def test_each_recordings_residuals_are_a_time_series_of_their_own():
    """Two runs of one excitation whose torque offsets differ by 0.02 N m (drifted between
    them; the offset term takes their mean): fitted as a list, each run's white residuals give
    a long-run factor of 1; the same samples as one array read the step at the join as
    correlation at every lag (a factor near 190, standard errors 14 times too large), with
    the same parameters. The runs' differing means are named (`run_offsets`, a warning)."""
    robot = pr.robots.a465()
    d = pr.design_excitation(robot, harmonics=4, base_frequency=0.1, max_evaluations=30, seed=1).trajectory
    t = np.arange(0, d.period, 0.01)
    q, qd, qdd = d.sample(t)
    tau = robot.rnea(q, qd, qdd)
    rng = np.random.default_rng(3)
    runs = [pr.Recording(t, q, tau + rng.normal(0, 0.01, q.shape) + s * 0.01, qd=qd, qdd=qdd, name=f"run{i}") for i, s in enumerate([1, -1])]
    with pytest.warns(pr.PerturbidWarning, match=r"the residuals of joint 'joint1' differ in mean from log to log, from -0.0\d+ \('run1'\) to 0.0\d+ \('run0'\)"):
        fit = pr.identify_base_parameters(robot, runs, friction="all")
    stack = lambda f: np.vstack([getattr(r, f) for r in runs])
    flat = pr.identify_base_parameters(robot, stack("q"), stack("qd"), stack("qdd"), stack("tau"), friction="all")
    assert (fit.residual_correlation < 1.2).all(), fit.residual_correlation
    assert (flat.residual_correlation > 50).all(), flat.residual_correlation
    np.testing.assert_allclose(fit.theta_base, flat.theta_base, rtol=1e-12, atol=1e-12)
    assert (flat.stderr > 5 * fit.stderr).all()
    # the drift is named: each run's mean residual, +-0.01 N m on every joint, with its
    # standard error (white noise of 0.01 N m about it, 1,000 samples: 0.00032)
    found = fit.run_offsets
    assert [o["joint"] for o in found] == robot.joint_names and flat.run_offsets == []
    for o in found:
        np.testing.assert_allclose(o["means"], [0.01, -0.01], atol=0.002)
        np.testing.assert_allclose(o["stderr"], 0.01 / np.sqrt(1000), rtol=0.2)
    # kept in the model and checked on load
    back = pr.BaseParameterModel.from_json(fit.to_json(), robot)
    assert [o["finding"] for o in back.run_offsets] == [o["finding"] for o in found]
    bad = json.loads(fit.to_json())
    bad["run_offsets"][0]["stderr"][1] = -1.0
    with pytest.raises(pr.InputError, match=r"run_offsets\[0\]: stderr\[1\] is -1, expected a positive standard error"):
        pr.BaseParameterModel.from_json(json.dumps(bad), robot)
    # runs without a drift: nothing named
    same = [pr.Recording(t, q, tau + rng.normal(0, 0.01, q.shape), qd=qd, qdd=qdd, name=f"run{i}") for i in range(2)]
    assert pr.identify_base_parameters(robot, same, friction="all").run_offsets == []


def test_each_recording_of_a_list_is_checked_against_the_model_alone():
    """A list of two Recordings, the second's shoulder torque in mN m: over the stacked
    samples the column's gain is too low to judge, so only the second run checked alone names
    it (`run_checks`, a warning naming the Recording); the first run has no finding, the
    model no lag read across the join, and the checks are kept through a save."""
    robot = pr.robots.a465()
    recs = []
    for motion, seed in [(1, 1), (2, 2)]:
        t, q, qd, qdd, tau, _ = log_with_friction(robot, 0.1, motion, seed)
        if motion == 2:
            tau[:, 1] *= 1000.0
        recs.append(pr.Recording(t[::10], q[::10], tau[::10], qd=qd[::10], qdd=qdd[::10], name=f"run{motion}"))
    with pytest.warns(pr.PerturbidWarning, match=r"log 'run2': the torque of joint 'joint2' reads 1000\.\d+ times the robot's model torque"):
        fit = pr.identify_base_parameters(robot, recs, friction=["viscous", "coulomb"])
    checks = fit.run_checks
    assert [c["log"] for c in checks] == ["run1", "run2"] and [c["samples"] for c in checks] == [2000, 2000]
    assert checks[0]["findings"] == [] and len(checks[1]["findings"]) == 1
    assert checks[1]["torque_columns"][1]["scale"] == pytest.approx(1000.0, rel=0.01)
    assert fit.torque_columns[1]["finding"] is None and fit.torque_lag is None
    assert all(c["torque_lag"]["samples"] == 0 for c in checks)
    back = pr.BaseParameterModel.from_json(fit.to_json(), robot)
    assert back.run_checks == checks
    # one Recording is checked as the model's own, with no checks of runs
    single = pr.identify_base_parameters(robot, recs[0], friction=["viscous", "coulomb"])
    assert single.run_checks == [] and single.torque_lag["samples"] == 0


def test_an_offset_of_each_logs_own_is_fitted():
    """Three runs whose torque offsets differ per joint (a sensor zeroed anew between logs):
    with `offset_per_log` each log's offset less their mean is fitted beside the parameters
    (`log_offsets`, within 4 standard errors of the truth), the model's offset terms are the
    mean, and nothing is named as drift. Checked by the exact identity of least squares: the
    plain fit of the torques with the fitted deviations taken out gives the same parameters
    (OLS; the consistent fit alike). Refused without a list, for one log, without the offset
    term; checked on load."""
    robot = pr.robots.a465()
    n = len(robot.joint_names)
    d = pr.design_excitation(robot, harmonics=4, base_frequency=0.1, max_evaluations=30, seed=1).trajectory
    t = np.arange(0, d.period, 0.01)
    q, qd, qdd = d.sample(t)
    tau = robot.rnea(q, qd, qdd)
    rng = np.random.default_rng(5)
    offsets = np.array([[0.02, 0.1, -0.05, 0.03, 0.0, 0.01], [-0.01, 0.0, 0.02, 0.0, 0.01, 0.0], [0.0, -0.04, 0.0, 0.01, 0.0, -0.02]])
    runs = [pr.Recording(t, q, tau + rng.normal(0, 0.01, q.shape) + offsets[r], qd=qd, qdd=qdd, name=f"run{r}") for r in range(3)]
    fit = pr.identify_base_parameters(robot, runs, friction="all", weighting="ols", offset_per_log=True)
    found = fit.log_offsets
    assert found["logs"] == ["run0", "run1", "run2"] and found["deviations"].shape == (3, n)
    truth = offsets - offsets.mean(axis=0)
    assert (np.abs(found["deviations"] - truth) < 4 * found["stderr"]).all(), (found["deviations"], truth)
    np.testing.assert_allclose(found["deviations"].sum(axis=0), 0.0, atol=1e-12)
    # about the noise over each run's samples
    np.testing.assert_allclose(found["stderr"], 0.01 * np.sqrt(2 / 3 / len(t)), rtol=0.3)
    assert fit.run_offsets == [] and (fit.residual_correlation < 1.2).all()
    # with their own offsets the runs agree with one robot
    agreement = fit.log_agreement
    assert agreement["finding"] is None and agreement["own_rms"].shape == (3, n)
    assert ((agreement["ratio"] > 0.99) & (agreement["ratio"] < 1.1)).all(), agreement["ratio"]
    for j, name in enumerate(robot.joint_names):
        i = fit.names.index(f"{name}.offset")
        assert abs(fit.theta_base[i] - offsets[:, j].mean()) < 4 * fit.stderr[i]
    # the plain fit of the torques less the fitted deviations: the same parameters
    adjusted = [pr.Recording(t, q, r.tau - found["deviations"][i], qd=qd, qdd=qdd, name=r.name) for i, r in enumerate(runs)]
    plain = pr.identify_base_parameters(robot, adjusted, friction="all", weighting="ols")
    np.testing.assert_allclose(plain.theta_base, fit.theta_base, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(plain.residual_rms, fit.residual_rms, rtol=1e-9)
    # without the offsets the drift is named and the fit is worse
    with pytest.warns(pr.PerturbidWarning, match="differ in mean from log to log"):
        drifted = pr.identify_base_parameters(robot, runs, friction="all", weighting="ols")
    assert drifted.log_offsets is None and (drifted.residual_rms > 1.2 * fit.residual_rms).any()
    # physically consistent alike: its own deviations, and the identity holds for them
    c = pr.identify_consistent_parameters(robot, runs, friction="all", weighting="ols", offset_per_log=True, max_iterations=200)
    dev = c.model.log_offsets["deviations"]
    assert (np.abs(dev - truth) < 4 * found["stderr"]).all()
    again = [pr.Recording(t, q, r.tau - dev[i], qd=qd, qdd=qdd, name=r.name) for i, r in enumerate(runs)]
    plain = pr.identify_consistent_parameters(robot, again, friction="all", weighting="ols", max_iterations=200)
    # the base parameters (the full ones the data leave undetermined are the prior's, to the
    # interior point's tolerance)
    np.testing.assert_allclose(plain.model.theta_base, c.model.theta_base, rtol=1e-7, atol=1e-8)
    np.testing.assert_allclose(plain.model.residual_rms, c.model.residual_rms, rtol=1e-8)
    # kept through a save, and checked on load
    back = pr.BaseParameterModel.from_json(fit.to_json(), robot)
    np.testing.assert_array_equal(back.log_offsets["deviations"], found["deviations"])
    bad = json.loads(fit.to_json())
    bad["log_offsets"]["deviations"][1][2] += 0.5
    with pytest.raises(pr.InputError, match=r"log_offsets.deviations\[1\] sum to 0.5.*expected 0"):
        pr.BaseParameterModel.from_json(json.dumps(bad), robot)
    # refused: arrays, one log, no offset term
    with pytest.raises(pr.InputError, match="offset_per_log: an offset of each log's own needs a list of Recordings"):
        pr.identify_base_parameters(robot, q, qd, qdd, tau, friction="all", offset_per_log=True)
    with pytest.raises(pr.InputError, match="offset_per_log: .*needs 2 to 50 Recordings, got 1"):
        pr.identify_base_parameters(robot, runs[:1], friction="all", offset_per_log=True)
    with pytest.raises(pr.InputError, match="offset_per_log: .*needs the offset among the joint terms"):
        pr.identify_consistent_parameters(robot, runs, friction=["viscous"], offset_per_log=True)


def test_standard_errors_count_residuals_correlated_by_the_filter():
    # a log low-pass filtered at 10 Hz and kept at 100 Hz: about five correlated samples to
    # every independent one, which the standard errors now count
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, 2 * traj.period, 0.001)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd) + np.random.default_rng(3).normal(0, 0.05, q.shape)
    rec = pr.preprocess(t, q, tau)
    fit = pr.identify_base_parameters(robot, rec.q, rec.qd, rec.qdd, rec.tau, friction=None, weighting="ols")
    f = fit.residual_correlation
    assert f.shape == (6,) and (f > 2).all() and (f < 20).all(), f
    assert json.loads(fit.to_json())["residual_correlation"] == pytest.approx(list(f))


def test_global_linear_model_is_a_workspace_average(tmp_path):
    robot = pr.robots.a465()
    op = pr.OperatingPoint(TABLE2_Q, [0.089, -0.106, 0.022, 0.056, 0.011, 0.014], [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171])
    traj = excitation(robot, 10, 0.05, 0.06, 3)  # 21 > 19 functions of time: all columns excited
    t = np.arange(0, traj.period, 0.02)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd, gravity=False)
    lin = pr.identify_global_linear(op, q, qd, qdd, tau)
    m = robot.mass_matrix(TABLE2_Q)
    # Table 3: the direct row is off, with entries where M(q*) has exact zeros (D21, D31, D51)
    print("D_g first column", np.round(lin.D[:, 0], 3), "M(q*)", np.round(m[:, 0], 3))
    assert np.linalg.norm(lin.D - m) / np.linalg.norm(m) > 0.02
    assert np.abs(lin.D[[1, 2, 4], 0]).max() > 0.02
    assert set(lin.stderr) == {"torque", "D", "H", "G"} and lin.D.shape == (6, 6)
    np.testing.assert_allclose(lin.predict(op.q, op.qd, op.qdd), lin.torque, atol=1e-12)
    # saved and loaded: the same model, and the document perturbid validate reads
    path = tmp_path / "global.json"
    lin.save(path)
    again = pr.GlobalLinearModel.load(path)
    np.testing.assert_array_equal(again.D, lin.D)
    assert pr.GlobalLinearModel.from_json(lin.to_json()).to_json() == lin.to_json()
    with pytest.raises(pr.InputError, match="global"):
        pr.GlobalLinearModel.from_json(json.dumps({"format": "perturbid-local-model/1"}))
    # a Recording given whole: the same fit; mixed with arrays, or without velocities, refused
    rec = pr.Recording(t, q, tau, qd=qd, qdd=qdd)
    same = pr.identify_global_linear(op, rec)
    np.testing.assert_array_equal(same.D, lin.D)
    with pytest.raises(pr.InputError, match="given with a Recording"):
        pr.identify_global_linear(op, rec, qd)
    with pytest.raises(pr.InputError, match="no velocities and accelerations"):
        pr.identify_global_linear(op, pr.Recording(t, q, tau))
    with pytest.raises(pr.InputError, match="missing"):
        pr.identify_global_linear(op, q, qd, qdd)
    # a 5-harmonic excitation cannot separate 19 columns: a clear error, not NaN
    q5, qd5, qdd5 = excitation(robot, 5, 0.1, 0.1, 1).sample(t[::2])
    with pytest.raises(pr.NumericalError, match="rank 11 < 19"):
        pr.identify_global_linear(op, q5, qd5, qdd5, robot.rnea(q5, qd5, qdd5))


def test_excitation_design_a465():
    robot = pr.robots.a465()
    design = pr.design_excitation(robot, harmonics=5, base_frequency=0.1, criterion="cond", seed=0)
    traj = design.trajectory
    t = np.arange(0, traj.period, 0.002)
    q, qd, qdd = traj.sample(t)
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
    assert np.all(np.abs(qd) <= robot.velocity_limit) and np.all(np.abs(qdd) <= robot.acceleration_limit)
    q0, qd0, qdd0 = traj.sample(0.0)
    np.testing.assert_allclose(np.concatenate([qd0, qdd0]), 0, atol=1e-12)
    assert design.cond < 200 and design.evaluations > 100
    # the design's own claim: cond of its base regressor, recomputed here
    q, qd, qdd = traj.sample(np.arange(0, traj.period, traj.period / 100))
    fit = pr.identify_base_parameters(robot, q, qd, qdd, robot.rnea(q, qd, qdd), friction=["viscous", "coulomb"], weighting="ols")
    assert fit.cond < 1e3
    assert pr.FourierTrajectory.from_json(traj.to_json()).to_json() == traj.to_json()


def load_panda_log():
    if not DATA.is_dir():
        pytest.skip(f"the real Panda log {DATA} is not there (it lies beside the repository; see docs/data.md)")
    d = np.loadtxt(DATA / "excitation.csv", delimiter=",", skiprows=1)
    return d[:, 0], d[:, 1:8], d[:, 8:15], d[:, 15:22]


def panda():
    return pr.Robot.from_urdf(erd_dir() / "panda_description/urdf/panda.urdf", lock={"panda_finger_joint1": 0.0})


def test_panda_fourier_coefficients_fit_the_log():
    t, q, _, _ = load_panda_log()  # skips when the data are not beside the repository
    c = np.loadtxt(DATA / "fourier_coefficients.txt")
    traj = pr.FourierTrajectory(c[:7], c[7:], np.loadtxt(DATA / "fourier_q0.txt"), w_f=0.15 * np.pi)
    m = (t > 3) & (t < 18)
    best = min(
        (np.abs(q[m] - p - (q[m] - p).mean(0)).max(), s)
        for s in np.arange(0.45, 0.60, 0.001)
        for p in [traj.sample(t[m] - s)[0]]
    )
    assert best[0] < 0.006 and 0.50 < best[1] < 0.54, best


def test_panda_real_data_matches_or_beats_the_reference():
    robot = panda()
    t, q, qd, tau = load_panda_log()
    rec = pr.preprocess(t, q, tau, qd=qd)  # 1 kHz, 10 Hz zero-phase Butterworth, trim 0.5 s, every 10th
    k = len(rec)
    split = int(0.7 * k)
    Q, QD, QDD, T = rec.q, rec.qd, rec.qdd, rec.tau
    result = {}
    for weighting in ["ols", "wls"]:
        fit = pr.identify_base_parameters(robot, Q[:split], QD[:split], QDD[:split], T[:split], friction="all", weighting=weighting)
        assert len(fit.theta_base) == 64
        err = fit.predict(Q[split:], QD[split:], QDD[split:]) - T[split:]
        result[weighting] = 100 * np.sqrt((err**2).mean(0) / (T[split:] ** 2).mean(0))
    print("validation relative RMS %: OLS", np.round(result["ols"], 2), "WLS", np.round(result["wls"], 2))
    # the same protocol as the reference matches it joint by joint (to its rounding)
    assert np.all(result["ols"] <= np.array(PANDA_REFERENCE) + 0.05), result["ols"]
    # WLS beats it overall
    assert result["wls"].mean() < np.mean(PANDA_REFERENCE)


def test_friction_options_say_what_they_do():
    """None (the default) identifies no friction, names pick terms, 'all' the three, and a bool,
    which does not say which terms, is refused."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    q, qd, qdd = traj.sample(np.arange(0, traj.period, 0.01))
    tau = robot.rnea(q, qd, qdd)
    friction_columns = lambda fit: sorted({n.split(".")[-1] for n in fit.full_names} & {"viscous", "coulomb", "offset"})
    assert friction_columns(pr.identify_base_parameters(robot, q, qd, qdd, tau)) == []
    assert friction_columns(pr.identify_base_parameters(robot, q, qd, qdd, tau, friction="viscous")) == ["viscous"]
    both = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=["viscous", "coulomb"])
    assert friction_columns(both) == ["coulomb", "viscous"]
    every = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction="all")
    assert friction_columns(every) == ["coulomb", "offset", "viscous"]
    for bad in [True, False, 3, ["viscous", "stiction"]]:
        with pytest.raises(pr.InputError, match="friction"):
            pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=bad)


def test_every_model_answers_linearize_the_same_way():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(TABLE2_Q, [0.089, -0.106, 0.022, 0.056, 0.011, 0.014], [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171])
    traj = excitation(robot, 10, 0.05, 0.06, 3)
    t = np.arange(0, traj.period, 0.02)
    q, qd, qdd = traj.sample(t)
    viscous = np.array([0.5, 0.4, 0.3, 0.2, 0.1, 0.05])
    tau = robot.rnea(q, qd, qdd) + viscous * qd
    truth = robot.linearize(op.q, op.qd, op.qdd)
    base = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction="viscous", weighting="ols")
    global_linear = pr.identify_global_linear(op, q, qd, qdd, tau)
    plan = pr.plan_experiments(robot, op, design="orthogonal")
    local = pr.identify_local(plan, pr.simulate(robot, plan, friction={"viscous": viscous}))
    for name, model in [("base", base), ("global", global_linear), ("local", local)]:
        e = model.linearize(op)
        assert set(e) == {"torque", "D", "H", "G", "G_static"}, name
        np.testing.assert_allclose(e["torque"], model.predict(op.q, op.qd, op.qdd), atol=1e-9)
        assert e["D"].shape == e["H"].shape == e["G"].shape == (6, 6)
    # the base-parameter model is the robot, exactly; the local one to its fit
    e = base.linearize(op)
    np.testing.assert_allclose(e["D"], truth.D, atol=1e-8)
    np.testing.assert_allclose(e["H"], truth.H + np.diag(viscous), atol=1e-8)
    np.testing.assert_allclose(e["G"], truth.G, atol=1e-7)
    np.testing.assert_allclose(local.linearize(op)["D"], truth.D, atol=1e-6)
    assert global_linear.linearize(op)["G_static"] is None


def test_regressor_with_friction_columns():
    robot = pr.robots.a465()
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-1, 1, (3, 4, 6))
    rigid = robot.regressor(q, qd, qdd)
    full = robot.regressor(q, qd, qdd, friction="viscous,coulomb,offset")
    assert full.shape == (4, 6, 60 + 18)
    np.testing.assert_allclose(full[:, :, :60], rigid, rtol=1e-12, atol=1e-12)
    for j in range(6):
        cols = full[:, :, 60 + 3 * j: 63 + 3 * j]
        np.testing.assert_array_equal(cols[:, j, 0], qd[:, j])
        np.testing.assert_array_equal(cols[:, j, 1], np.sign(qd[:, j]))
        np.testing.assert_array_equal(cols[:, j, 2], 1.0)
        others = [i for i in range(6) if i != j]
        assert not cols[:, others, :].any()
    with pytest.raises(pr.InputError, match="visous"):
        robot.regressor(q, qd, qdd, friction="visous")


def test_physical_consistency_against_pinocchio_pseudo_inertia():
    import pinocchio as pin

    physical = pr.robots.a465("physical")
    ok, bodies, friction = physical.physical_consistency()
    assert ok and friction == [] and len(bodies) == 6
    fitted = pr.robots.a465("kinsheel2010_lumped")
    ok, bodies, _ = fitted.physical_consistency()
    assert pr.robots.a465().physical_consistency(friction="armature")[0]
    assert not ok and any("pseudo-inertia" in (b["problem"] or "") for b in bodies)
    # the eigenvalues are those of Pinocchio's pseudo-inertia of the same parameters
    theta = fitted.parameters
    for b, body in enumerate(bodies):
        pi = pin.Inertia.FromDynamicParameters(theta[10 * b: 10 * b + 10])
        expected = np.sort(np.linalg.eigvalsh(pi.toPseudoInertia().toMatrix()))
        np.testing.assert_allclose(body["eigenvalues"], expected, atol=1e-12)
    theta = physical.parameters.copy()
    theta[0] = -1.0
    ok, bodies, _ = physical.physical_consistency(theta)
    assert not ok and bodies[0]["problem"] == "mass -1 kg is negative"


def test_consistent_parameters_make_a_robot_pinocchio_agrees_with():
    """Noisy torques from few samples: the consistent fit is a robot (every pseudo-inertia PSD),
    costs at least the unconstrained minimum, and the robot built from it has, in Pinocchio,
    the torques the fit predicts."""
    import pinocchio as pin

    robot = pr.robots.a465("physical")
    rng = np.random.default_rng(11)
    q, qd, qdd = rng.uniform(-1.2, 1.2, (3, 60, 6))
    viscous = np.array([0.5, 0.4, 0.3, 0.2, 0.1, 0.05])
    tau = robot.rnea(q, qd, qdd) + viscous * qd + rng.normal(0, 0.5, (60, 6))
    fit = pr.identify_consistent_parameters(robot, q, qd, qdd, tau, friction="viscous", weighting="ols")
    assert isinstance(fit, pr.ConsistentFit) and fit.converged
    assert fit.residual_growth >= 1.0 - 1e-9 and fit.cost >= fit.unconstrained_cost * (1 - 1e-9)
    assert len(fit.theta) == len(fit.names) == 60 + 6 and fit.names[60] == "joint1.viscous"
    ok, bodies, negative = robot.physical_consistency(fit.theta, friction="viscous")
    assert ok and negative == [], bodies
    built = fit.robot()
    np.testing.assert_allclose(built.damping, fit.theta[60:], rtol=1e-12)
    # Pinocchio, with the fitted inertias
    model = pin.buildModelFromXML(pr.robots.a465_urdf("physical"))
    data = model.createData()
    for j in range(6):
        model.inertias[j + 1] = pin.Inertia.FromDynamicParameters(fit.theta[10 * j: 10 * j + 10])
    qh, qdh, qddh = rng.uniform(-1, 1, (3, 6))
    expected = pin.rnea(model, data, qh, qdh, qddh) + fit.theta[60:] * qdh
    np.testing.assert_allclose(fit.model.predict(qh, qdh, qddh), expected, atol=1e-8)
    np.testing.assert_allclose(built.rnea(qh, qdh, qddh) + built.damping * qdh, expected, atol=1e-8)
    assert "ConsistentFit(" in repr(fit)
    table = fit.to_dataframe()
    assert table.index.name == "parameter" and list(table.index) == fit.names
    np.testing.assert_array_equal(table["value"].to_numpy(), fit.theta)
    assert list(table.loc["joint1.viscous", ["body", "quantity"]]) == ["joint1", "viscous"]
    assert list(table["quantity"][:10]) == ["m", "mcx", "mcy", "mcz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz"]


def test_progress_reaches_python_logging(caplog):
    """Messages of the Rust side go to Python's logging (pyo3-log), under the library's name."""
    import logging

    robot = pr.robots.a465()
    with caplog.at_level(logging.INFO, logger="perturbid_rs"):
        pr.design_excitation(robot, seed=2, max_evaluations=300, progress=True)
    records = [r for r in caplog.records if r.name == "perturbid_rs.excitation"]
    assert len(records) >= 2, caplog.records
    assert all(r.levelno == logging.INFO for r in records)
    assert "excitation design: 100 evaluations" in records[0].getMessage()
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="perturbid_rs"):
        pr.design_excitation(robot, seed=2, max_evaluations=300, progress=True)
    assert not [r for r in caplog.records if r.name.startswith("perturbid_rs")]


def test_excitation_within_the_workspace_and_effort_limits():
    """The Panda's excitation without a floor takes its hand below the plane it stands on;
    with the floor as a workspace constraint (and the URDF's effort limits) it stays above it
    by the margin, which Pinocchio's frame kinematics and inverse dynamics confirm at 1 kHz."""
    import pinocchio as pin

    from conftest import erd_dir

    path = erd_dir() / "panda_description/urdf/panda.urdf"
    robot = pr.Robot.from_urdf(path, lock={"panda_finger_joint1": 0.02})
    model = pin.buildModelFromUrdf(str(path))
    q_ref = pin.neutral(model)
    fingers = [model.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    for j in fingers:
        q_ref[model.joints[j].idx_q] = 0.02
    model = pin.buildReducedModel(model, fingers, q_ref)
    data = model.createData()
    hand = model.getFrameId("panda_hand")
    floor = [{"frame": "panda_hand", "point": [0, 0, 0.1], "region": {"above": {"normal": [0, 0, 1], "offset": 0.0}}, "margin": 0.05}]

    def lowest_and_effort(design):
        t = np.arange(0, design.trajectory.period, 1e-3)
        q, qd, qdd = design.sample(t)
        z, use = [], []
        for k in range(len(t)):
            pin.framesForwardKinematics(model, data, q[k])
            z.append((data.oMf[hand].act(np.array([0, 0, 0.1])))[2])
            use.append(np.abs(pin.rnea(model, data, q[k], qd[k], qdd[k])) / model.effortLimit)
        return min(z), np.max(use)

    free = pr.design_excitation(robot, seed=1, max_evaluations=300, effort_limits=False)
    z_free, _ = lowest_and_effort(free)
    kept = pr.design_excitation(robot, seed=1, max_evaluations=300, workspace=floor)
    z_kept, effort_use = lowest_and_effort(kept)
    assert z_kept >= 0.05 - 1e-6, z_kept
    assert effort_use <= 0.9 + 1e-6, effort_use
    m = kept.margins
    assert set(m) == {"panda_hand above the plane (m)"} | {f"panda_joint{j} effort limit (fraction)" for j in range(1, 8)}
    assert abs(m["panda_hand above the plane (m)"] - (z_kept - 0.05)) < 1e-3
    print(f"lowest point of the hand: {z_free:.3f} m free, {z_kept:.3f} m with the floor")
    with pytest.raises(pr.InputError, match="no link of this name"):
        pr.design_excitation(robot, max_evaluations=10, workspace=[{**floor[0], "frame": "panda_elbow"}])
    with pytest.raises(pr.InputError, match=r"at \[0\]\.region"):
        pr.design_excitation(robot, max_evaluations=10, workspace=[{**floor[0], "region": {"below": {}}}])
    # numbers beyond any robot's reach are refused with the bound, in exponent form
    for edit, says in [
        ({"point": [9.2e20, 0.0, 0.1]}, r"point \[9\.2e20, 0, 0\.1\] \(m\) must lie within 1e6 m of the frame's origin"),
        ({"margin": 1e300}, r"margin 1e300 \(m\) must be from 0 to below 1000 m"),
        ({"margin": -0.01}, r"margin -0\.01 \(m\) must be from 0"),
        ({"region": {"above": {"normal": [0.0, 0.0, 1.0], "offset": 1e300}}}, r"its offset 1e300 \(m\) within 1e6"),
        ({"region": {"inside": {"min": [0.0, 0.0, 0.0], "max": [1.0, 1e300, 1.0]}}}, r"the box needs min \[0, 0, 0\] < max \[1, 1e300, 1\] \(m\)"),
    ]:
        with pytest.raises(pr.InputError, match=says):
            pr.design_excitation(robot, max_evaluations=10, workspace=[{**floor[0], **edit}])


def test_validation_tables_and_figures():
    """validate() against numpy, the tables as pandas DataFrames, the figures with matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import pandas as pd

    from perturbid_rs import plot

    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, 0.01)
    q, qd, qdd = traj.sample(t)
    rng = np.random.default_rng(0)
    tau = robot.rnea(q, qd, qdd) + rng.normal(0, 0.05, q.shape)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction=None)
    v = pr.validate(fit, q, qd, qdd, tau)
    r = tau - fit.predict(q, qd, qdd)
    np.testing.assert_allclose(v.model_stderr_rms, np.sqrt(np.mean(fit.predict_stderr(q, qd, qdd) ** 2, axis=0)), rtol=1e-12)
    assert (v.model_stderr_rms < 0.05).all()  # the model's uncertainty, far below the noise
    np.testing.assert_allclose(v.residuals, r, atol=1e-12)
    np.testing.assert_allclose(v.rms, np.sqrt(np.mean(r**2, axis=0)), rtol=1e-12)
    np.testing.assert_allclose(v.relative_rms, np.sqrt(np.sum(r**2, axis=0) / np.sum(tau**2, axis=0)), rtol=1e-12)
    np.testing.assert_allclose(v.max, np.abs(r).max(axis=0), rtol=1e-12)
    np.testing.assert_allclose(v.mean, r.mean(axis=0), rtol=1e-9, atol=1e-15)
    # a log whose shoulder torque reads 0.3 N m higher: the error's mean shows it
    shifted = pr.validate(fit, q, qd, qdd, tau + np.array([0, 0.3, 0, 0, 0, 0]))
    np.testing.assert_allclose(shifted.mean - v.mean, [0, 0.3, 0, 0, 0, 0], atol=1e-12)
    df = v.to_dataframe()
    np.testing.assert_allclose(df["mean"].to_numpy(), v.mean)
    assert isinstance(df, pd.DataFrame) and list(df.index) == robot.joint_names and df.index.name == "joint"
    np.testing.assert_allclose(df["rms"].to_numpy(), v.rms)
    table = fit.to_dataframe()
    assert table.index.name == "parameter" and list(table.index) == fit.names
    np.testing.assert_allclose(table["value"].to_numpy(), fit.theta_base)
    np.testing.assert_allclose(table["relative_std"].to_numpy(), fit.stderr / np.abs(fit.theta_base))
    assert table["combination"].dtype == bool and table["combination"].any() and not table["combination"].all()
    fig = plot.measured_and_predicted(t, tau, fit.predict(q, qd, qdd), robot.joint_names)
    assert len(fig.axes) == 6 and fig.axes[0].get_legend() is not None
    assert [line.get_linestyle() for line in fig.axes[0].lines] == ["-", "--", ":"]
    assert len(plot.residuals(v, t).axes) == 6
    # the predictions' standard errors as a band of +- 2 about the prediction
    se = fit.predict_stderr(q, qd, qdd)
    fig = plot.measured_and_predicted(t, tau, fit.predict(q, qd, qdd), robot.joint_names, stderr=se)
    band = fig.axes[2].collections[0].get_paths()[0].vertices
    p2 = fit.predict(q, qd, qdd)[:, 2]
    np.testing.assert_allclose(band[:, 1].max(), (p2 + 2 * se[:, 2]).max(), rtol=1e-12)
    np.testing.assert_allclose(band[:, 1].min(), (p2 - 2 * se[:, 2]).min(), rtol=1e-12)
    with pytest.raises(ValueError, match="stderr"):
        plot.measured_and_predicted(t, tau, tau, stderr=se[:-1])
    with pytest.raises(ValueError, match="negative"):
        plot.measured_and_predicted(t, tau, tau, stderr=-se)
    with pytest.raises(ValueError, match="disagree"):
        plot.measured_and_predicted(t[:-1], tau, tau)
    with pytest.raises(pr.InputError):
        pr.validate(fit, q, qd, qdd, tau[:-1])


def test_preprocess_names_a_clipped_torque():
    """Joint 2's torque clipped at 1.5 N m (its peaks reach 2): a PerturbidWarning names it and
    the recording lists it with the level, the side and about how far the torque went beyond
    it (a parabola through the clipped stretch's ends); the torques logged in 0.05 N m steps,
    their tops held a while, are not taken for clipped."""
    rng = np.random.default_rng(5)
    t = np.arange(8000) * 1e-3
    q = np.stack([0.3 * np.sin(2 * np.pi * 0.2 * t + k) for k in range(3)], axis=1)
    tau = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1)
    tau += 0.01 * rng.standard_normal(tau.shape)
    clipped = tau.copy()
    clipped[:, 1] = np.minimum(clipped[:, 1], 1.5)
    with pytest.warns(pr.PerturbidWarning, match=r"the torque of joint 2 reads exactly 1\.5000 N m, its largest value.*clipped"):
        rec = pr.preprocess(t, q, clipped, name="clipped")
    (found,) = rec.torque_saturation
    assert (found["joint"], found["level"], found["upper"]) == (1, 1.5, True)
    # the peaks the clip hid: 0.5 N m beyond it
    assert 0.25 < found["beyond"] < 1.0, found
    assert found["runs"] >= 1 and found["longest"] >= 300
    stepped = np.round(tau / 0.05) * 0.05
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)
        assert pr.preprocess(t, q, stepped, name="stepped").torque_saturation == []


def test_preprocess_refuses_velocities_that_are_not_the_positions_derivative():
    t = np.arange(6000) * 1e-3
    q = np.stack([0.3 * np.sin(2 * np.pi * 0.2 * t + k) for k in range(3)], axis=1)
    qd = np.stack([0.3 * 2 * np.pi * 0.2 * np.cos(2 * np.pi * 0.2 * t + k) for k in range(3)], axis=1)
    tau = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1)
    rec = pr.preprocess(t, q, tau, qd=qd)
    expected = np.stack([0.3 * 2 * np.pi * 0.2 * np.cos(2 * np.pi * 0.2 * rec.t + k) for k in range(3)], axis=1)
    np.testing.assert_allclose(rec.qd, expected, atol=1e-4)  # the logged velocities, as they were
    with pytest.raises(pr.InputError, match=r"joints 1, 2, 3: 57\.296 times its positions' derivative: degrees per second"):
        pr.preprocess(t, q, tau, qd=np.degrees(qd))
    swapped = qd[:, [0, 2, 1]]
    with pytest.raises(pr.InputError, match=r"joint 2: follows the positions of joint 3"):
        pr.preprocess(t, q, tau, qd=swapped)


def test_preprocess_replaces_a_logs_glitches_and_says_so():
    """A torque spike and a row of zero positions in a log are replaced before filtering: a
    PerturbidWarning names them, the result's glitches list them, and the preprocessed
    signals equal those of the clean log to well within the noise-free filter's output;
    screen_glitches=False keeps them (and the spike then shows in the filtered torque). Rows
    of zero torques while the robot moves are removed as a dropout, and one joint's position
    frozen for 15 rows as a frozen reading; both are listed. A joint logged within one turn has
    its steps of a turn taken back out."""
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.0008, 0.0012, 8000))
    q = np.stack([0.3 * np.sin(2 * np.pi * 0.2 * t + k) for k in range(3)], axis=1)
    tau = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1)
    tau += 0.02 * rng.standard_normal(tau.shape)
    clean = pr.preprocess(t, q, tau, name="clean")
    assert clean.glitches == []
    bad_q, bad_tau = q.copy(), tau.copy()
    bad_tau[4000, 1] += 40.0
    bad_q[5000, :] = 0.0
    with pytest.warns(pr.PerturbidWarning, match=r"4 sample\(s\).*tau of joint 2 at t = .* read"):
        screened = pr.preprocess(t, bad_q, bad_tau, name="log")
    found = sorted((g["signal"], g["joint"], g["sample"]) for g in screened.glitches)
    assert found == [("q", 0, 5000), ("q", 1, 5000), ("q", 2, 5000), ("tau", 1, 4000)]
    spike = next(g for g in screened.glitches if g["signal"] == "tau")
    assert spike["value"] == bad_tau[4000, 1] and abs(spike["replaced_by"] - tau[4000, 1]) < 0.1
    assert np.max(np.abs(screened.tau - clean.tau)) < 0.01
    assert np.max(np.abs(screened.q - clean.q)) < 1e-6
    assert screened.dropouts == []
    kept = pr.preprocess(t, bad_q, bad_tau, screen_glitches=False)
    assert kept.glitches == []
    assert np.max(np.abs(kept.tau - clean.tau)) > 0.3
    # eight rows of torques read as zeros while the robot moves: removed as a dropout
    dropped = tau.copy()
    dropped[6000:6008, :] = 0.0
    with pytest.warns(pr.PerturbidWarning, match=r"1 dropout\(s\).*8 rows from sample 6000"):
        bridged = pr.preprocess(t, q, dropped, name="dropout")
    assert [(d["signal"], d["first_sample"], d["samples"]) for d in bridged.dropouts] == [("tau", 6000, 8)]
    assert bridged.dropouts[0]["from"] == t[6000] and bridged.dropouts[0]["to"] == t[6007]
    assert np.max(np.abs(bridged.tau - clean.tau)) < 0.05
    # one joint's torque read as zeros for six rows (the others read on): a held reading,
    # replaced as a whole
    held = tau.copy()
    held[3000:3006, 0] = 0.0
    assert np.all(np.abs(tau[3000:3006, 0]) > 0.5)
    with pytest.warns(pr.PerturbidWarning, match=r"6 sample\(s\) of 1 held reading\(s\).*samples 3000 to 3005\) held 0"):
        repaired = pr.preprocess(t, q, held, name="held")
    assert [(g["joint"], g["sample"], g["held"]) for g in repaired.glitches] == [(0, i, 6) for i in range(3000, 3006)]
    assert all(g["held"] is None for g in screened.glitches)
    assert np.max(np.abs(repaired.tau - clean.tau)) < 0.01
    # one joint's position frozen for 15 rows while it moves (a stalled stream): the rows are
    # removed as a frozen reading, listed with its joint, the value held and its end's jump
    stalled = q.copy()
    stalled[2000:2015, 1] = q[2000, 1]
    with pytest.warns(pr.PerturbidWarning, match=r"1 frozen reading\(s\).*q of joint 2 held .* for 15 rows from sample 2000"):
        removed = pr.preprocess(t, stalled, tau, name="stalled")
    [d] = removed.dropouts
    assert (d["signal"], d["joint"], d["first_sample"], d["samples"]) == ("q", 1, 2000, 15)
    assert d["value"] == q[2000, 1] and d["noise_levels"] > 10
    assert "joint" not in bridged.dropouts[0]
    assert removed.glitches == []
    assert np.max(np.abs(removed.q - clean.q)) < 1e-4
    # joint 3 logged within one turn, passing pi: each step of a turn is taken back out, and
    # the preprocessed recording is the unwrapped log's, whole turns apart
    shifted = q.copy()
    shifted[:, 2] += np.pi - 0.5 * (q[:, 2].min() + q[:, 2].max())
    logged = shifted.copy()
    logged[:, 2] = np.angle(np.exp(1j * shifted[:, 2]))
    steps = np.flatnonzero(np.abs(np.diff(logged[:, 2])) > np.pi) + 1
    assert len(steps) >= 2
    with pytest.warns(pr.PerturbidWarning, match=rf"{len(steps)} step\(s\) of a joint's positions by whole turns.*joint 3 at t = "):
        unwrapped = pr.preprocess(t, logged, tau, name="wrapped")
    assert [(w["joint"], w["sample"]) for w in unwrapped.position_wraps] == [(2, int(i)) for i in steps]
    assert all(abs(w["turns"]) == 1 and w["time"] == t[w["sample"]] for w in unwrapped.position_wraps)
    reference = pr.preprocess(t, shifted, tau)
    turns = np.round((unwrapped.q - reference.q) / (2 * np.pi))
    np.testing.assert_allclose(unwrapped.q - 2 * np.pi * turns, reference.q, atol=1e-9)
    np.testing.assert_allclose(unwrapped.qd, reference.qd, atol=1e-9)
    assert clean.position_wraps == []
    # joint 2's torque logged at 100 Hz and held on the 1 kHz grid: read again at its values'
    # arrivals, and the preprocessed torque is the clean one's to well within what the
    # staircase's half-hold lag (4.5 ms) would leave
    exact = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1)
    stairs = exact.copy()
    stairs[:, 1] = exact[np.arange(len(t)) // 10 * 10, 1]
    with pytest.warns(pr.PerturbidWarning, match=r"1 column\(s\) logged at a lower rate.*tau of joint 2 repeats 9\d % .* held for 10 samples"):
        reread = pr.preprocess(t, q, stairs, name="stairs")
    [h] = reread.held_columns
    assert (h["signal"], h["joint"], h["held_for"]) == ("tau", 1, 10.0) and h["repeated"] > 0.85
    smooth = pr.preprocess(t, q, exact)
    lag = 4.5e-3 * np.sqrt(np.mean(np.gradient(smooth.tau[:, 1], smooth.t) ** 2))
    assert np.sqrt(np.mean((reread.tau[:, 1] - smooth.tau[:, 1]) ** 2)) < 0.1 * lag
    assert clean.held_columns == [] and reread.dropouts == []


def test_positions_in_coarse_counts_under_derived_velocities_are_warned_of():
    """Positions rounded to 4,096 counts a revolution and no velocity channel: preprocess
    estimates the noise their rounding leaves in qd and qdd (against the true noise, the same
    log preprocessed unrounded: within a factor 2.5 on these slow joints), lists it on the recording and warns from
    10 %; with the velocities logged, nothing is measured."""
    t = np.arange(0.0, 20.0, 0.001)
    q = np.stack([0.4 * np.sin(2 * np.pi * 0.1 * t + k) + 0.1 * np.sin(2 * np.pi * 0.3 * t) for k in range(3)], axis=1)
    tau = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1)
    step = 2 * np.pi / 4096
    exact = pr.preprocess(t, q, tau)
    assert exact.position_rounding == []
    with pytest.warns(pr.PerturbidWarning, match=r"coarse: positions logged in coarse counts, with velocities derived from them: .*joint 1 in steps of 1\.534e-3 leave"):
        rec = pr.preprocess(t, np.round(q / step) * step, tau, name="coarse")
    found = rec.position_rounding
    assert [r["joint"] for r in found] == [0, 1, 2]
    for r in found:
        j = r["joint"]
        assert r["step"] == pytest.approx(step, rel=1e-9)
        true = np.sqrt(np.mean((rec.qdd[:, j] - exact.qdd[:, j]) ** 2) / np.mean(exact.qdd[:, j] ** 2))
        # slow joints (under a count a millisecond): the estimate runs low, and the true noise
        # itself varies by a factor 1.6 with where the grid lies
        assert true / 2.5 < r["qdd_ratio"] < 2 * true, (j, r["qdd_ratio"], true)
        assert r["qdd_ratio"] >= 0.1
    w = 2 * np.pi * np.array([0.1, 0.3])
    qd = np.stack([0.4 * w[0] * np.cos(w[0] * t + k) + 0.1 * w[1] * np.cos(w[1] * t) for k in range(3)], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        logged = pr.preprocess(t, np.round(q / step) * step, tau, qd=qd)
    assert logged.position_rounding == []


def test_a_fit_of_recordings_does_not_warn_again_of_their_rounding():
    """The preprocessing warns of positions in coarse counts once, naming the log; a fit of the
    Recording (or a list of them) keeps the finding in the model but does not warn of it a
    second time. A Recording's name of any length is kept so that the model loads again."""
    robot = pr.robots.a465()
    t = np.arange(0, 20, 0.001)
    q = np.stack([0.5 * np.sin(2 * np.pi * 0.1 * (j + 1) * t + j) for j in range(6)], 1)
    qd = np.gradient(q, t, axis=0)
    tau = robot.rnea(q, qd, np.gradient(qd, t, axis=0)) + np.random.default_rng(0).normal(0, 0.01, q.shape)
    coarse = np.round(q / 2e-3) * 2e-3
    with pytest.warns(pr.PerturbidWarning, match="a.csv: positions logged in coarse counts"):
        a = pr.preprocess(t, coarse, tau, name="a.csv")
    with pytest.warns(pr.PerturbidWarning, match="coarse counts"):
        b = pr.preprocess(t[:15000], coarse[:15000] * 1.01, tau[:15000], name="b" * 5000)
    for given in [a, [a, b]]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fit = pr.identify_base_parameters(robot, given, friction=None)
        assert not any("coarse counts" in str(w.message) for w in caught), [str(w.message)[:80] for w in caught]
        saved = json.loads(fit.to_json())
        found = saved["position_rounding"] if given is a else saved["logs"][0]["position_rounding"]
        assert [r["joint"] for r in found if r["qdd_ratio"] >= 0.1] == [0, 1], found
    # the longest name is cut to 4,096 characters, ending in an ellipsis
    long = saved["logs"][1]["log"]
    assert len(long) == 4096 and long.endswith("\u2026") and long.startswith("bbb")


def test_a_logs_derivative_columns_are_checked_when_its_time_is_given():
    """With `t`, identify_base_parameters and identify_consistent_parameters take the samples
    for a log and refuse velocity or acceleration columns that are not the derivatives of the
    positions and velocities (other units, another joint's), naming the joint; the clean log
    fits exactly as without `t`. Without `t` states need not be a trajectory: unchecked."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, 0.005)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd)
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)
        checked = pr.identify_base_parameters(robot, q, qd, qdd, tau, weighting="ols", t=t)
    plain = pr.identify_base_parameters(robot, q, qd, qdd, tau, weighting="ols")
    np.testing.assert_array_equal(checked.theta_base, plain.theta_base)
    degrees = qd.copy()
    degrees[:, 3] = np.degrees(qd[:, 3])
    with pytest.raises(pr.InputError, match=r"joint 4: 57\.29\d times its positions' derivative: degrees per second read as rad/s"):
        pr.identify_base_parameters(robot, q, degrees, qdd, tau, weighting="ols", t=t)
    with pytest.raises(pr.InputError, match=r"joint 4: 57\.29\d times"):
        pr.identify_consistent_parameters(robot, q, degrees, qdd, tau, t=t)
    with pytest.raises(pr.InputError, match=r"validate's samples: .*joint 4: 57\.29\d times"):
        pr.validate(plain, q, degrees, qdd, tau, t=t)
    np.testing.assert_array_equal(pr.validate(plain, q, qd, qdd, tau, t=t).rms, pr.validate(plain, q, qd, qdd, tau).rms)
    pr.identify_base_parameters(robot, q, degrees, qdd, tau, weighting="ols")  # not checked
    swapped = qdd[:, [0, 2, 1, 3, 4, 5]]
    with pytest.raises(pr.InputError, match=r"joint 2: follows the velocities of joint 3"):
        pr.identify_base_parameters(robot, q, qd, swapped, tau, weighting="ols", t=t)
    with pytest.raises(pr.InputError, match=r"t: expected \(%d,\): one time per row of q, got shape \(%d,\)" % (len(t), len(t) - 1)):
        pr.identify_base_parameters(robot, q, qd, qdd, tau, t=t[:-1])
    with pytest.raises(pr.InputError, match="time is not increasing at sample 1"):
        pr.identify_base_parameters(robot, q, qd, qdd, tau, t=np.zeros(len(t)))


def test_friction_the_fit_leaves_out_is_named_with_its_coefficients():
    """A log whose shoulder has 1 N m of Coulomb friction, fitted without friction, warns of it
    and lists it in fit.unmodelled_friction with the coefficient the fit with every friction
    term identifies; that fit, and a log without friction, raise nothing."""
    robot = pr.robots.a465()
    traj = excitation(robot, 5, 0.1, 0.12, 1)
    t = np.arange(0, traj.period, 0.005)
    q, qd, qdd = traj.sample(t)
    rng = np.random.default_rng(3)
    clean = robot.rnea(q, qd, qdd) + 0.05 * rng.standard_normal(q.shape)
    tau = clean + np.sign(qd) * (np.arange(6) == 1)
    with pytest.warns(pr.PerturbidWarning, match=r"friction the fit leaves out shows in the torques of 1 joint\(s\).*'joint2' \(coulomb [01]\.\d{3} \+- 0\.0\d\d N m.*friction=\['coulomb'\]"):
        fit = pr.identify_base_parameters(robot, q, qd, qdd, tau)
    [found] = fit.unmodelled_friction
    assert found["joint"] == "joint2" and found["explained"] > 0.9
    [coulomb] = found["terms"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)
        every = pr.identify_base_parameters(robot, q, qd, qdd, tau, friction="all")
        pr.identify_base_parameters(robot, q, qd, qdd, clean)
    assert every.unmodelled_friction == []
    assert coulomb["term"] == "coulomb"
    assert coulomb["coefficient"] == pytest.approx(every.theta_base[every.names.index("joint2.coulomb")], rel=1e-9)
    assert abs(coulomb["coefficient"] - 1.0) < 4 * coulomb["stderr"]
    rms = every.residual_rms[1] / fit.residual_rms[1]
    assert found["explained"] == pytest.approx(1 - rms**2, abs=1e-9)
    # the physically consistent fit checks the same data, and warns alike
    with pytest.warns(pr.PerturbidWarning, match=r"friction the fit leaves out .*'joint2' \(coulomb"):
        consistent = pr.identify_consistent_parameters(robot, q, qd, qdd, tau)
    assert consistent.model.unmodelled_friction == fit.unmodelled_friction


def test_a_stream_that_stops_before_the_log_is_cut_from_its_end():
    """One torque column logged at its last value over the log's last 50 ms while the joints
    move (the stream stopped first): preprocess warns of it and removes those rows, which
    Recording.dropouts lists with to_end; the clean log cut there preprocesses to the same."""
    t = np.arange(6000) * 1e-3
    q = np.stack([0.3 * np.sin(2 * np.pi * 0.2 * t + k) for k in range(3)], axis=1)
    rng = np.random.default_rng(5)
    tau = np.stack([2.0 * np.cos(2 * np.pi * 0.3 * t + k) for k in range(3)], axis=1) + 0.01 * rng.standard_normal((6000, 3))
    stalled = tau.copy()
    stalled[-50:, 1] = tau[-50, 1]
    with pytest.warns(pr.PerturbidWarning, match=r"tau of joint 2 held .* for 50 rows from sample 5950 .* to the end of its stretch of the log"):
        rec = pr.preprocess(t, q, stalled)
    [d] = rec.dropouts
    assert (d["signal"], d["joint"], d["first_sample"], d["samples"], d["to_end"]) == ("tau", 1, 5950, 50, True)
    assert d["noise_levels"] is None and d["value"] == tau[-50, 1]
    cut = pr.preprocess(t[:-50], q[:-50], tau[:-50])
    np.testing.assert_array_equal(rec.t, cut.t)
    np.testing.assert_array_equal(rec.tau, cut.tau)


def test_stamps_that_jitter_over_a_regular_clock_are_found_and_warned_of():
    """Samples taken every millisecond, stamped with 0.1 ms of white jitter (a ROS bag's
    receive time): preprocess finds it from the positions (smooth against the sample count,
    rough against the stamps; the ratio against numpy's) and warns; the harm it warns of holds
    (the fit's residual many times the sound log's). Stamped right, nothing is found."""
    robot = pr.robots.a465()
    t, q, qd, qdd, tau, rng = log_with_friction(robot, 0.3, 2, 3)
    friction = ["viscous", "coulomb"]
    sound = pr.preprocess(t, q, tau)
    assert sound.stamp_jitter is None
    stamps = t + rng.normal(0, 1e-4, t.shape)
    with pytest.warns(pr.PerturbidWarning, match="its time stamps jitter while its samples were taken on a regular clock"):
        jittered = pr.preprocess(stamps, q, tau)
    found = jittered.stamp_jitter
    line = q[:-2] + (q[2:] - q[:-2]) * ((stamps[1:-1] - stamps[:-2]) / (stamps[2:] - stamps[:-2]))[:, None]
    ratios = np.abs(q[1:-1] - line).mean(0) / np.abs(q[1:-1] - 0.5 * (q[:-2] + q[2:])).mean(0)
    assert found["joint"] == int(np.argmax(ratios))
    np.testing.assert_allclose(found["rougher"], ratios.max(), rtol=1e-9)
    assert abs(found["interval"] - 1e-3) < 2e-5 and abs(found["scatter"] - 1.41e-4) < 1.5e-5, found
    good = pr.identify_base_parameters(robot, sound, friction=friction)
    bad = pr.identify_base_parameters(robot, jittered, friction=friction)
    assert bad.residual_rms.max() > 5 * good.residual_rms.max(), (bad.residual_rms, good.residual_rms)
