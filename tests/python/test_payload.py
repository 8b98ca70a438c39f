"""A payload identified from a log of the robot carrying it (identify_payload): the torques
come from Pinocchio with the payload added to its link's inertia there; the ten parameters are
checked against Pinocchio's own dynamic parameters of the payload, the fit against numpy's
least squares over Pinocchio's regressor, and the standard errors against the scatter over
repeated noisy logs; hostile arguments are refused by name."""

import json
import warnings

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import pair_from_text
from test_drive_gains import motion, pin_torques

PAYLOAD = {"link": "link6", "mass": 1.5, "com": [0.01, -0.02, 0.07],
           "inertia": [0.004, 0.0005, 0.0, 0.005, 0.0, 0.002]}
VISCOUS = 0.3


def pin_payload():
    xx, xy, xz, yy, yz, zz = PAYLOAD["inertia"]
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    return pin.Inertia(PAYLOAD["mass"], np.array(PAYLOAD["com"]), inertia)


@pytest.fixture(scope="module")
def a465():
    """The A465 in both libraries, and Pinocchio's model with the payload on joint 6's body."""
    pair = pair_from_text(pr.robots.a465_urdf("kinsheel2010"))
    loaded = pair.model.copy()
    jid = loaded.getJointId("joint6")
    loaded.inertias[jid] = loaded.inertias[jid] + pin_payload()
    return pair, loaded


def log(model, seed, noise=0.0):
    t, q, qd, qdd = motion(seed)
    tau = pin_torques(model, q, qd, qdd) + VISCOUS * qd
    tau = tau + noise * np.random.default_rng(seed).standard_normal(tau.shape)
    return t, q, qd, qdd, tau


def test_the_ten_parameters_are_pinocchios_of_the_payload(a465):
    pair, loaded = a465
    t, q, qd, qdd, tau = log(loaded, 4)
    fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", terms="viscous")
    # Pinocchio's dynamic parameters: m, m c, the inertia about the joint frame
    want = pin_payload().toDynamicParameters()
    assert np.allclose(fit.theta[:10], want, rtol=1e-8, atol=1e-10)
    assert fit.names[:2] == ["payload.m", "payload.mcx"] and fit.names[10] == "joint1.viscous"
    assert np.allclose(fit.theta[10:], VISCOUS, atol=1e-8)
    p = fit.payload
    assert p["link"] == "link6" and abs(p["mass"] - 1.5) < 1e-9
    assert np.allclose(p["com"], PAYLOAD["com"], atol=1e-9)
    assert np.allclose(p["inertia"], PAYLOAD["inertia"], atol=1e-9)
    assert fit.usable and fit.findings == [] and fit.reference == "urdf"
    # the robot carrying it, on another motion: Pinocchio's torques
    t2, q2, qd2, qdd2, tau2 = log(loaded, 6)
    assert np.allclose(fit.predict(q2, qd2, qdd2), tau2, rtol=1e-8, atol=1e-8)
    assert fit.predict(q2[0], qd2[0], qdd2[0]).shape == (6,)
    # the payload is what a true robot and the drive gains take
    pr.TrueRobot({"payload": p})
    doc = json.loads(fit.to_json())
    assert doc["payload"]["mass"] == p["mass"]


def pin_system(pair, q, qd, qdd, tau):
    """[Y_payload | viscous] over the samples (Pinocchio's regressor, rows sample by sample,
    joint by joint) and the torques less the robot alone's."""
    data = pair.model.createData()
    jid = pair.model.getJointId("joint6")
    rows, rhs = [], []
    alone = pin_torques(pair.model, q, qd, qdd)
    for s in range(len(q)):
        y = pin.computeJointTorqueRegressor(pair.model, data, q[s], qd[s], qdd[s])
        x = np.zeros((6, 16))
        x[:, :10] = y[:, 10 * (jid - 1):10 * jid]
        x[:, 10:] = np.diag(qd[s])
        rows.append(x)
        rhs.append(tau[s] - alone[s])
    return np.vstack(rows), np.concatenate(rhs)


def test_the_noise_weighting_is_numpys_weighted_least_squares_with_the_noises_errors(a465):
    """Rows of joint j over its noise level sigma_j: numpy's least squares of the weighted
    system, and standard errors of (X_w^T X_w)^-1 (scaled by one factor of at least 1: the
    residuals' cost over its degrees of freedom, or their correlation, where beyond 1)."""
    pair, loaded = a465
    t, q, qd, qdd, tau = log(loaded, 5)
    sigma = np.array([0.05, 0.2, 0.1, 0.02, 0.03, 0.01])
    tau = tau + sigma * np.random.default_rng(12).standard_normal(tau.shape)
    fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", terms="viscous",
                              weighting="noise", noise=sigma)
    x, b = pin_system(pair, q, qd, qdd, tau)
    w = np.tile(1 / sigma, len(q))
    theta, *_ = np.linalg.lstsq(x * w[:, None], b * w, rcond=None)
    assert np.allclose(fit.theta, theta, rtol=1e-8, atol=1e-10)
    np.testing.assert_array_equal(fit.sigma, sigma)
    known = np.sqrt(np.diag(np.linalg.inv((x * w[:, None]).T @ (x * w[:, None]))))
    ratio = np.asarray(fit.stderr) / known
    assert np.allclose(ratio, ratio[0], rtol=1e-6) and 1 - 1e-9 < ratio[0] < 1.2, ratio
    f = fit.noise_fit
    r = ((b - x @ theta) * w).reshape(-1, 6)
    assert f["cost"] == pytest.approx((r**2).sum(), rel=1e-8)
    assert f["degrees_of_freedom"] == len(b) - len(theta)
    assert 1e-3 < f["p_value"] < 1 - 1e-3


def test_the_fit_is_numpys_least_squares_over_pinocchios_regressor(a465):
    """OLS over [Y_payload | viscous] of the torques less the robot alone's, built whole."""
    pair, loaded = a465
    t, q, qd, qdd, tau = log(loaded, 5, noise=0.05)
    fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", terms="viscous",
                              weighting="ols")
    x, b = pin_system(pair, q, qd, qdd, tau)
    theta, *_ = np.linalg.lstsq(x, b, rcond=None)
    assert np.allclose(fit.theta, theta, rtol=1e-8, atol=1e-10)
    r = (b - x @ theta).reshape(-1, 6)
    assert np.allclose(fit.residual_rms, np.sqrt((r**2).mean(axis=0)), rtol=1e-8)


def test_against_a_model_of_the_robot_alone_the_errors_are_the_scatter_of_repeated_logs(a465):
    pair, loaded = a465
    t, q, qd, qdd, tau = log(pair.model, 3, noise=0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pr.PerturbidWarning)
        model = pr.identify_base_parameters(pair.ours, q, qd, qdd, tau, friction="viscous")
    masses, coms, errors = [], [], []
    for seed in range(20):
        t, q, qd, qdd, tau = log(loaded, 4)
        tau = tau + 0.02 * np.random.default_rng(100 + seed).standard_normal(tau.shape)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pr.PerturbidWarning)
            fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", model=model)
        assert fit.reference == "base_model"
        e = fit.estimate
        masses.append(e["mass"])
        coms.append(e["com"])
        errors.append((fit.payload_stderr["mass"], fit.stderr_of_reference[0],
                       fit.payload_stderr["com"]))
    # the same reference every time: its share is a bias common to all, the rest scatters
    own = np.sqrt(np.mean([m**2 - r**2 for m, r, _ in errors]))
    assert 0.6 < np.std(masses) / own < 1.6, (np.std(masses), own)
    # the whole error covers the truth
    se = np.mean([m for m, _, _ in errors])
    assert abs(np.mean(masses) - 1.5) < 4 * se
    assert np.all(np.abs(np.mean(coms, axis=0) - PAYLOAD["com"])
                  < 4 * np.mean([c for _, _, c in errors], axis=0) + 1e-4)


def test_a_recording_and_a_consistent_estimate(a465):
    pair, loaded = a465
    t, q, qd, qdd, tau = log(loaded, 4, noise=0.05)
    rec = pr.Recording(t, q, tau, qd=qd, qdd=qdd)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plain = pr.identify_payload(pair.ours, rec, link="link6", terms="viscous")
        fit = pr.identify_payload(pair.ours, rec, link="link6", terms="viscous", consistent=True)
    assert fit.consistent and fit.residual_growth >= 1.0 and fit.usable
    # the consistent payload is a rigid body
    xx, xy, xz, yy, yz, zz = fit.payload["inertia"]
    moments = np.linalg.eigvalsh([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    assert moments.min() >= -1e-12 and 2 * moments.max() <= moments.sum() + 1e-9
    if plain.not_a_rigid_body is None:
        assert np.allclose(plain.theta, fit.theta, rtol=1e-5, atol=1e-8)
    else:
        assert not plain.usable and plain.payload is None and plain.estimate is not None
        assert any("no rigid body" in str(w.message) for w in caught)


def test_no_payload_is_named_and_hostile_arguments_are_refused(a465):
    pair, loaded = a465
    t, q, qd, qdd, tau = log(pair.model, 4, noise=0.02)
    with pytest.warns(pr.PerturbidWarning, match="no payload on 'link6' is seen"):
        fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6")
    assert fit.payload is None and fit.estimate is None and not fit.usable
    with pytest.raises(pr.InputError, match="'base_link' is fixed to the base"):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, link="base_link")
    with pytest.raises(pr.InputError, match="weighting"):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", weighting="gls")
    with pytest.raises(pr.InputError, match="sticky"):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", terms=["sticky"])
    with pytest.raises(pr.PerturbidError):
        pr.identify_payload(pair.ours, q, qd, qdd, tau[:, :5], link="link6")
    with pytest.raises(TypeError):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, "link6")  # link is keyword-only
    with pytest.raises(pr.InputError):
        pr.identify_payload(pair.ours, q, qd, qdd, np.full_like(tau, np.nan), link="link6")
    # a model of the robot alone identified with gravity out of its torques
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pr.PerturbidWarning)
        model = pr.identify_base_parameters(pair.ours, q, qd, qdd, tau, friction="viscous",
                                            gravity=False)
    with pytest.raises(pr.InputError, match="must agree"):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link6", model=model)
    # on the first link only the first joint's torque sees a payload: refused, named
    t, q, qd, qdd, tau = log(loaded, 4)
    with pytest.raises(pr.NumericalError, match="payload identification on 'link1'"):
        pr.identify_payload(pair.ours, q, qd, qdd, tau, link="link1")


def test_a_payload_on_a_tool_frame_is_pinocchios_in_that_frame():
    """A tool frame fixed to link 6, turned and offset: Pinocchio places the payload on joint
    6's body through the frame's placement; the payload comes back in the tool's frame."""
    tool = ('<joint name="tool_joint" type="fixed"><parent link="link6"/><child link="tool0"/>'
            '<origin xyz="0.01 -0.02 0.1" rpy="0.3 -0.2 0.5"/></joint><link name="tool0"/></robot>')
    pair = pair_from_text(pr.robots.a465_urdf("kinsheel2010").replace("</robot>", tool))
    loaded = pair.model.copy()
    placement = loaded.frames[loaded.getFrameId("tool0")].placement
    jid = loaded.getJointId("joint6")
    loaded.inertias[jid] = loaded.inertias[jid] + placement.act(pin_payload())
    t, q, qd, qdd, tau = log(loaded, 4)
    fit = pr.identify_payload(pair.ours, q, qd, qdd, tau, link="tool0", terms="viscous")
    p = fit.payload
    assert p["link"] == "tool0" and abs(p["mass"] - PAYLOAD["mass"]) < 1e-8
    assert np.allclose(p["com"], PAYLOAD["com"], atol=1e-8)
    assert np.allclose(p["inertia"], PAYLOAD["inertia"], atol=1e-8)
    # the ten parameters are the body's: Pinocchio's of the payload placed on it
    assert np.allclose(fit.theta[:10], placement.act(pin_payload()).toDynamicParameters(),
                       rtol=1e-8, atol=1e-10)
    assert json.loads(fit.to_json())["body"] == "link6"


def test_a_point_mass_from_poses_held_still(a465):
    """Only gravity at poses held still: the inertia is not determined (refused, named), the
    point mass's mass and centre are, exactly, Pinocchio's."""
    pair, _ = a465
    point = pin.Inertia(0.9, np.array([0.03, 0.0, 0.06]), np.zeros((3, 3)))
    loaded = pair.model.copy()
    jid = loaded.getJointId("joint6")
    loaded.inertias[jid] = loaded.inertias[jid] + point
    rng = np.random.default_rng(3)
    lo, hi = pair.model.lowerPositionLimit, pair.model.upperPositionLimit
    q = rng.uniform(0.8 * lo, 0.8 * hi, (30, 6))
    zero = np.zeros_like(q)
    tau = pin_torques(loaded, q, zero, zero) + 0.2  # a sensor offset on every joint
    with pytest.raises(pr.NumericalError, match="payload.I"):
        pr.identify_payload(pair.ours, q, zero, zero, tau, link="link6", terms="offset")
    fit = pr.identify_payload(pair.ours, q, zero, zero, tau, link="link6", terms="offset",
                              inertia="point_mass")
    assert fit.inertia == "point_mass" and fit.usable
    assert abs(fit.payload["mass"] - 0.9) < 1e-9
    assert np.allclose(fit.payload["com"], [0.03, 0.0, 0.06], atol=1e-9)
    assert fit.payload["inertia"] == [0.0] * 6 and fit.payload_stderr["inertia"] == [0.0] * 6
    assert np.allclose(fit.theta[:10], point.toDynamicParameters(), atol=1e-9)
    assert np.allclose(fit.theta[10:], 0.2, atol=1e-9)
    with pytest.raises(pr.InputError, match="point_mass"):
        pr.identify_payload(pair.ours, q, zero, zero, tau, link="link6", inertia="sphere")
    with pytest.raises(pr.InputError, match="rigid body already"):
        pr.identify_payload(pair.ours, q, zero, zero, tau, link="link6", terms="offset",
                            inertia="point_mass", consistent=True)


def test_several_recordings_are_fitted_together_and_each_checked_alone(a465):
    pair, loaded = a465
    recs = []
    for seed in (4, 5):
        t, q, qd, qdd, tau = log(loaded, seed, noise=0.01)
        recs.append(pr.Recording(t, q, tau, qd=qd, qdd=qdd, name=f"day{seed}.csv"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pr.PerturbidWarning)
        fit = pr.identify_payload(pair.ours, recs, link="link6", terms="viscous")
    assert fit.usable and abs(fit.payload["mass"] - 1.5) < 4 * fit.payload_stderr["mass"]
    doc = json.loads(fit.to_json())
    assert doc["logs"] == ["day4.csv", "day5.csv"] and len(doc["run_checks"]) == 2
    assert fit.samples == sum(len(r.t) for r in recs)
    # the second day's shoulder torque in mN m: named by it, the payload not vouched for
    t, q, qd, qdd, tau = log(loaded, 5, noise=0.01)
    tau[:, 1] *= 1000.0
    bad = pr.Recording(t, q, tau, qd=qd, qdd=qdd, name="units.csv")
    with pytest.warns(pr.PerturbidWarning, match="log 'units.csv': the torque of joint 'joint2'"):
        fit = pr.identify_payload(pair.ours, [recs[0], bad], link="link6", terms="viscous")
    assert not fit.usable and fit.payload is None
    with pytest.raises(pr.InputError, match="pass the list alone"):
        pr.identify_payload(pair.ours, recs, q, link="link6")


def test_each_logs_own_offset_is_fitted_beside_the_payload(a465):
    """Two logs, the second's sensors zeroed anew (Pinocchio's torques plus an offset)."""
    pair, loaded = a465
    offsets = np.array([0.3, -0.2, 0.1, 0.05, -0.1, 0.02])
    recs = []
    for seed, shift in [(4, 0.0), (6, 1.0)]:
        t, q, qd, qdd, tau = log(loaded, seed)
        recs.append(pr.Recording(t, q, tau + shift * offsets, qd=qd, qdd=qdd, name=f"day{seed}.csv"))
    fit = pr.identify_payload(pair.ours, recs, link="link6", terms=["viscous", "offset"],
                              offset_per_log=True)
    assert np.allclose(fit.theta[:10], pin_payload().toDynamicParameters(), rtol=1e-7, atol=1e-9)
    o = fit.log_offsets
    assert o["logs"] == ["day4.csv", "day6.csv"]
    assert np.allclose(o["deviations"], np.outer([-0.5, 0.5], offsets), atol=1e-8)
    assert o["stderr"].shape == (2, 6)
    with pytest.warns(pr.PerturbidWarning):  # one offset for both: the payload takes the rest
        shared = pr.identify_payload(pair.ours, recs, link="link6", terms=["viscous", "offset"])
    assert shared.log_offsets is None
    assert abs(shared.payload_stderr["mass"]) > 1e3 * abs(fit.payload_stderr["mass"])
    with pytest.raises(pr.InputError, match="needs the offset among the joint terms"):
        pr.identify_payload(pair.ours, recs, link="link6", terms="viscous", offset_per_log=True)
