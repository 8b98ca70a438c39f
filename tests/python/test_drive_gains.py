"""Drive gains from logged motor currents with a known payload (identify_drive_gains): the
torques come from Pinocchio (the payload added to its link's inertia there), the gains are
checked against numpy's least squares over Pinocchio's own regressor, the model of the robot
alone against Pinocchio's torques on another motion; hostile arguments are refused by name."""

import json
import warnings

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import pair_from_text

GAINS = np.array([42.0, 65.0, 38.0, 9.0, 7.5, 4.0])  # N m per A (made up)
PAYLOAD = {"link": "link6", "mass": 2.0, "com": [0.02, -0.01, 0.08],
           "inertia": [0.004, 0.0, 0.0, 0.004, 0.0, 0.002]}
VISCOUS = 0.3


def motion(seed, seconds=8.0, rate=500.0):
    """A sum of sines about a posture, analytic derivatives: t (k,), q, qd, qdd (k, 6)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1.0 / rate)
    w = 2 * np.pi * 0.125 * np.arange(1, 6)
    a = rng.uniform(-0.12, 0.12, (5, 6))
    b = rng.uniform(-0.12, 0.12, (5, 6))
    q0 = np.array([0.2, 0.3, -0.4, 0.1, 0.5, -0.2])
    s, c = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
    q = q0 + s @ a + c @ b
    qd = (c * w) @ a - (s * w) @ b
    qdd = -(s * w**2) @ a - (c * w**2) @ b
    return t, q, qd, qdd


def pin_torques(model, q, qd, qdd):
    data = model.createData()
    return np.array([pin.rnea(model, data, *x) for x in zip(q, qd, qdd)])


def logs(noise):
    """The A465 (Pinocchio), alone and with the payload on link 6 along two motions: the
    pair, the loaded Pinocchio model, and the runs (t, q, qd, qdd, currents under `noise` A)."""
    pair = pair_from_text(pr.robots.a465_urdf("kinsheel2010"))
    loaded = pair.model.copy()
    jid = loaded.getJointId("joint6")
    c = np.array(PAYLOAD["com"])
    xx, xy, xz, yy, yz, zz = PAYLOAD["inertia"]
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    loaded.inertias[jid] = loaded.inertias[jid] + pin.Inertia(PAYLOAD["mass"], c, inertia)
    rng = np.random.default_rng(0)
    runs = []
    for seed, model in [(3, pair.model), (4, loaded)]:
        t, q, qd, qdd = motion(seed)
        tau = pin_torques(model, q, qd, qdd) + VISCOUS * qd
        current = tau / GAINS + noise * rng.standard_normal(tau.shape)
        runs.append((t, q, qd, qdd, current))
    return pair, loaded, runs


@pytest.fixture(scope="module")
def setup():
    return logs(1e-4)


def dense_system(pair, loaded, runs):
    """[Y_pin | armature | viscous | -diag(i)] [theta; K] = -tau_payload over the runs (the
    second loaded), Pinocchio's regressor and torques: x (6k, 10 nb + 18), rhs (6k,)."""
    data = pair.model.createData()
    ids = [pair.model.getJointId(n) for n in pair.ours.joint_names]
    cols = np.concatenate([np.arange(10 * (i - 1), 10 * i) for i in ids])
    rows, rhs = [], []
    for r, (t, q, qd, qdd, i) in enumerate(runs):
        payload_tau = (pin_torques(loaded, q, qd, qdd) - pin_torques(pair.model, q, qd, qdd)
                       if r == 1 else np.zeros_like(q))
        for s in range(len(t)):
            y = pin.computeJointTorqueRegressor(pair.model, data, q[s], qd[s], qdd[s])[:, cols]
            rows.append(np.hstack([y, np.diag(qdd[s]), np.diag(qd[s]), -np.diag(i[s])]))
            rhs.append(-payload_tau[s])
    return np.vstack(rows), np.concatenate(rhs)


def lstsq(x, y):
    """numpy's least squares, columns scaled to unit norm (zero columns left)."""
    scale = np.linalg.norm(x, axis=0)
    scale[scale == 0] = 1.0
    return np.linalg.lstsq(x / scale, y, rcond=1e-12)[0] / scale


def recordings(runs):
    return [pr.Recording(t, q, i, qd=qd, qdd=qdd, name=f"run{r}")
            for r, (t, q, qd, qdd, i) in enumerate(runs)]


def test_gains_match_numpy_least_squares_over_pinocchios_regressor(setup):
    pair, loaded, runs = setup
    fit = pr.identify_drive_gains(pair.ours, recordings(runs), [None, PAYLOAD],
                                  friction="viscous", weighting="ols")
    g = fit.drive_gains
    assert g is not None and g["runs"] == 2 and g["loaded_runs"] == 1
    # solved by numpy over Pinocchio's regressor
    sol = lstsq(*dense_system(pair, loaded, runs))
    np.testing.assert_allclose(g["gain"], sol[-6:], rtol=1e-8)
    assert g["estimator"] == "least_squares" and g["least_squares_gain"] is None
    # and the truth, within the standard errors and the noise's estimated bias
    err = np.abs(g["gain"] - GAINS)
    assert np.all(err < 4 * g["stderr"] + g["noise_bias"] * GAINS), (g, GAINS)
    assert np.all(g["noise_bias"] < 1e-3) and np.all(g["payload_torque_rms"] > 0.01)
    assert np.all((g["agreement"] > 0.95) & (g["agreement"] < 1.2))
    # each run's findings kept in `logs`, named by its Recording, as identify-gains keeps its logs'
    assert [l["log"] for l in json.loads(fit.to_json())["logs"]] == ["run0", "run1"]


def test_instrumental_gains_match_numpy_and_lose_the_noise_bias():
    """On currents noisy enough to bias least squares by several per cent: the instrumental
    estimate (Z^T X) beta = Z^T y solved by numpy over Pinocchio's regressor, Z the signal
    predicted by numpy's least-squares fit."""
    pair, loaded, runs = logs(5e-4)
    recs = recordings(runs)
    kw = dict(friction="viscous", weighting="ols")
    ls = pr.identify_drive_gains(pair.ours, recs, [None, PAYLOAD], **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        iv = pr.identify_drive_gains(pair.ours, recs, [None, PAYLOAD], estimator="instrumental",
                                     **kw).drive_gains
    x, y = dense_system(pair, loaded, runs)
    first = lstsq(x, y)
    # Pinocchio's regressor has more columns than the data determine: an orthonormal basis
    # of their span instead (the fitted torques and the gains do not depend on the basis)
    phi = x[:, :-6]
    u, sv, _ = np.linalg.svd(phi / np.maximum(np.linalg.norm(phi, axis=0), 1e-300),
                             full_matrices=False)
    basis = u[:, sv > 1e-10 * sv[0]]
    joint = np.arange(len(y)) % 6
    predicted = (phi @ first[:-6] - y) / first[-6:][joint]
    signal = x[:, -6:]
    instrument = np.zeros_like(signal)
    instrument[np.arange(len(y)), joint] = -predicted
    xb, zb = np.hstack([basis, signal]), np.hstack([basis, instrument])
    scale = np.linalg.norm(xb, axis=0)
    beta = np.linalg.solve((zb / scale).T @ (xb / scale), (zb / scale).T @ y) / scale
    np.testing.assert_allclose(iv["gain"], beta[-6:], rtol=1e-7)
    # (to 1e-8 on the quieter currents above; numpy's rank-deficient solve is looser here)
    np.testing.assert_allclose(iv["least_squares_gain"], first[-6:], rtol=1e-6)
    assert iv["estimator"] == "instrumental"
    # within their standard errors of the truth; least squares is not, where biased
    assert np.all(np.abs(iv["gain"] - GAINS) < 3.5 * iv["stderr"]), (iv, GAINS)
    biased = iv["noise_bias"] > 0.01
    assert biased.sum() >= 2, iv["noise_bias"]
    lost = np.abs(ls.drive_gains["gain"] - GAINS)
    assert np.all(lost[biased] > 3 * np.abs(iv["gain"] - GAINS)[biased]), (lost, iv["gain"])
    with pytest.raises(pr.InputError, match="estimator.*'bayes'"):
        pr.identify_drive_gains(pair.ours, recs, [None, PAYLOAD], estimator="bayes")


def test_the_model_is_the_robot_alones_in_torques(setup):
    pair, _, runs = setup
    with_friction = pr.identify_drive_gains(pair.ours, recordings(runs), [None, PAYLOAD],
                                            friction="viscous")
    t, q, qd, qdd = motion(5)
    truth = pin_torques(pair.model, q, qd, qdd) + VISCOUS * qd
    predicted = with_friction.predict(q, qd, qdd)
    assert np.sqrt(np.mean((predicted - truth) ** 2)) < 0.02
    saved = json.loads(with_friction.to_json())
    np.testing.assert_allclose(saved["drive_gains"]["gain"], with_friction.drive_gains["gain"])
    # a log of currents in torques, validated: its velocities and accelerations kept
    current = truth / with_friction.drive_gains["gain"]
    rec = pr.Recording(t, q, current, qd=qd, qdd=qdd).in_torques(with_friction.drive_gains["gain"])
    np.testing.assert_allclose(rec.tau, truth, rtol=1e-12)
    assert rec.qd is not None and rec.qdd is not None
    v = pr.validate(with_friction, rec)
    assert v.rms.max() < 0.02, v.rms
    with pytest.raises(pr.PerturbidError, match="5 gains for 6 joints"):
        rec.in_torques(np.ones(5))
    with pytest.raises(pr.PerturbidError, match="the gain of joint 2 is 0"):
        rec.in_torques([1.0, 0.0, 1.0, 1.0, 1.0, 1.0])
    # the currents the motion needs, with their standard errors (from the parameters' and
    # gains' covariance: tests/drive_gains.rs checks them against the dense one)
    gain = with_friction.drive_gains["gain"]
    np.testing.assert_array_equal(with_friction.predict(q, qd, qdd, signal=True),
                                  predicted / gain)
    se = with_friction.predict_stderr(q, qd, qdd, signal=True)
    assert se.shape == q.shape and np.all(np.isfinite(se)) and np.all(se > 0)
    assert np.all(se < 0.01 * np.abs(predicted / gain).max(axis=0))
    # a model fitted to torques has none
    plain = pr.identify_base_parameters(pair.ours, q, qd, qdd, truth, friction="viscous")
    assert plain.drive_gains is None
    with pytest.raises(pr.InputError, match="holds no drive gains"):
        plain.predict(q, qd, qdd, signal=True)


def test_a_local_model_from_recordings_of_currents(setup):
    """identify_local(..., drive_gains=fit): the local method's recordings logged as currents
    give the local model of the same recordings in torques, keeping the gains."""
    pair, _, runs = setup
    fit = pr.identify_drive_gains(pair.ours, recordings(runs), [None, PAYLOAD], friction="viscous")
    op = pr.OperatingPoint([0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0],
                           [0.089, -0.106, 0.022, 0.056, 0.011, 0.014],
                           [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171])
    plan = pr.plan_experiments(pair.ours, op)
    recs = pr.simulate(pair.ours, plan, torque_noise=0.01, seed=2)
    currents = [pr.Recording(r.t, r.q, r.tau / GAINS, name=r.name, experiment=r.experiment)
                for r in recs]
    torques = pr.identify_local(plan, recs)
    local = pr.identify_local(plan, currents, drive_gains=fit)
    np.testing.assert_array_equal(local.drive_gains["gain"], fit.drive_gains["gain"])
    assert torques.drive_gains is None
    # the gains are the identified ones, off the truth by their errors: so is the model
    worst = np.max(np.abs(fit.drive_gains["gain"] / GAINS - 1))
    np.testing.assert_allclose(local.D, torques.D, rtol=0, atol=2 * worst * np.abs(torques.D).max())
    np.testing.assert_allclose(local.torque, torques.torque, rtol=2 * worst, atol=1e-6)
    _, q, qd, qdd = motion(5)
    plain = pr.identify_base_parameters(pair.ours, q, qd, qdd, fit.predict(q, qd, qdd),
                                        friction="viscous")
    with pytest.raises(pr.InputError, match="holds no drive gains"):
        pr.identify_local(plan, currents, drive_gains=plain)


def test_a_signal_counting_the_other_way_is_named(setup):
    pair, _, runs = setup
    flipped = [(t, q, qd, qdd, i * np.array([1, -1, 1, 1, 1, 1])) for t, q, qd, qdd, i in runs]
    with pytest.warns(pr.PerturbidWarning, match="'joint2' is negative"):
        fit = pr.identify_drive_gains(pair.ours, recordings(flipped), [None, PAYLOAD],
                                      friction="viscous")
    assert fit.drive_gains["gain"][1] == pytest.approx(-GAINS[1], rel=1e-2)


def test_hostile_arguments_are_refused_by_name(setup):
    pair, _, runs = setup
    recs = recordings(runs)
    robot = pair.ours

    def refused(runs_, payloads, says, error=pr.InputError):
        with pytest.raises(error, match=says):
            pr.identify_drive_gains(robot, runs_, payloads, friction="viscous")

    refused(recs, [None, None], "every run carries no payload")
    refused(recs, [PAYLOAD, PAYLOAD], "the same payload")
    refused(recs, [None], "1 payloads for 2 runs")
    refused(recs[:1], [PAYLOAD], "1 runs given, expected 2")
    refused(recs, [None, {**PAYLOAD, "colour": "red"}], r"payloads\[1\].*unknown key 'colour'")
    refused(recs, [None, {**PAYLOAD, "link": "tool0"}], "'tool0' is not a link of")
    refused(recs, [None, {**PAYLOAD, "mass": float("nan")}], "payload.mass is NaN")
    refused(recs, [None, {**PAYLOAD, "com": [0, 0, 1e9]}], r"payload.com\[2\]")
    refused(recs, [None, "2 kg"], r"payloads\[1\].*expected None or a dict")
    refused(recs, [None, {**PAYLOAD, "com": [0, 0]}], "'com' must be 3 real numbers")
    refused(recs, [None, {**PAYLOAD, "mass": True}], "'mass' must be a real number")
    refused(recs, [None, {"mass": 2.0}], "'link' and 'mass' are required")
    refused("runs", [None], "a str, expected a list")
    refused([recs[0], "run"], [None, PAYLOAD], r"runs\[1\].*expected a Recording")
    t, q, qd, qdd, i = runs[1]
    raw = pr.Recording(t, q, i, name="raw")
    refused([recs[0], raw], [None, PAYLOAD], "'raw' has no velocities")
    # velocities in degrees per second are caught by the derivative check
    deg = pr.Recording(t, q, i, qd=np.degrees(qd), qdd=qdd, name="deg")
    refused([recs[0], deg], [None, PAYLOAD], "degrees per second")
    other = pr.Recording(t, q[:, :5], i[:, :5], qd=qd[:, :5], qdd=qdd[:, :5], name="five")
    refused([recs[0], other], [None, PAYLOAD], r"runs\[1\].*'five' has 5 joints, expected the robot's 6")
    # the same run twice, once loaded: the same samples given twice
    refused([recs[0], recs[0]], [None, PAYLOAD], r"run 0 and run 1 hold the same \d+ samples, bit for bit")
