"""The noise weighting from Python (identify_base_parameters(..., weighting="noise")): a
Recording averaged over its periods weights by the noise they measured, arrays by noise=;
the fit's residuals judged against that noise, recomputed here from the model's own
predictions and the chi-square tail's Wilson-Hilferty approximation; and a noise that cannot
weight refused by name."""

import math
import re
import warnings

import numpy as np
import pytest

import perturbid_rs as pr

RATE = 500.0


def trajectory(seed):
    rng = np.random.default_rng(seed)
    return pr.FourierTrajectory(
        rng.uniform(-0.12, 0.12, (6, 5)),
        rng.uniform(-0.12, 0.12, (6, 5)),
        np.array([0.2, 0.3, -0.4, 0.1, 0.5, -0.2]),
        base_frequency=0.1,
    )


def chi_square_tail(x, k):
    """P(X > x) for chi-square with k degrees of freedom, by Wilson and Hilferty's cube root
    (within 1e-3 of the exact tail for k in the hundreds)."""
    z = ((x / k) ** (1 / 3) - (1 - 2 / (9 * k))) / math.sqrt(2 / (9 * k))
    return 0.5 * math.erfc(z / math.sqrt(2))


def test_an_averaged_recording_is_weighted_by_the_noise_its_periods_measured():
    robot = pr.robots.a465()
    traj = trajectory(3)
    log = pr.simulate(robot, traj, periods=4, rate=RATE, friction=None, torque_noise=0.02, seed=8)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = pr.preprocess(log.t, log.q, log.tau, excitation=traj, rate=RATE, decimate=5)
        fit = pr.identify_base_parameters(robot, out, weighting="noise")
    a = out.period_average
    assert (a["samples"], a["kept_samples"]) == (5000, 1000)
    f = fit.noise_fit
    np.testing.assert_array_equal(fit.sigma, a["averaged_torque_noise"])
    np.testing.assert_array_equal(f["noise"], a["averaged_torque_noise"])
    assert f["correlation"] == pytest.approx(1000 / 201, rel=1e-12)
    assert f["noise_degrees_of_freedom"] == pytest.approx(3 * 201 * 6)
    # the cost from the model's own predictions, the noise and the correlation
    residual = (out.tau - fit.predict(out)) / np.asarray(f["noise"])
    cost = (residual**2).sum() / f["correlation"]
    assert f["cost"] == pytest.approx(cost, rel=1e-9)
    p = len(fit.theta_base)
    assert f["degrees_of_freedom"] == pytest.approx(1000 * 6 / f["correlation"] - p, rel=1e-12)
    assert 1e-3 < f["p_value"] < 1 - 1e-3, f
    np.testing.assert_allclose(f["ratio"], np.sqrt((residual**2).mean(axis=0)), rtol=1e-9)
    # the residuals' weighting: the noise judges them still, its weights are its own
    wls = pr.identify_base_parameters(robot, out)
    assert wls.noise_fit is not None and not np.array_equal(wls.sigma, fit.sigma)
    # validated on another log averaged alike: its errors against its own periods' noise
    other = pr.simulate(robot, traj, periods=4, rate=RATE, friction=None, torque_noise=0.02, seed=9)
    held = pr.preprocess(other.t, other.q, other.tau, excitation=traj, rate=RATE, decimate=5)
    v = pr.validate(fit, held)
    g = v.noise_fit
    errors = (held.tau - fit.predict(held)) / np.asarray(g["noise"])
    assert g["cost"] == pytest.approx((errors**2).sum() / g["correlation"], rel=1e-9)
    assert g["degrees_of_freedom"] == pytest.approx(1000 * 6 / g["correlation"], rel=1e-12)
    assert 1e-3 < g["p_value"] < 1 - 1e-3, g
    assert pr.validate(fit, held.q, held.qd, held.qdd, held.tau).noise_fit is None
    # drawn for a notebook: the noise and the residuals a joint, their ratio in the title
    import matplotlib
    matplotlib.use("Agg")
    from perturbid_rs import plot
    fig = plot.noise_fit(fit)
    (ax,) = fig.axes
    heights = [p.get_height() for p in ax.patches]
    np.testing.assert_allclose(heights[:6], f["noise"], rtol=1e-12)
    np.testing.assert_allclose(heights[6:], np.asarray(f["ratio"]) * f["noise"], rtol=1e-12)
    assert [t.get_text() for t in ax.get_xticklabels()] == fit.joint_names
    assert f"{f['cost'] / f['degrees_of_freedom']:.3g}" in ax.get_title()
    assert len(plot.noise_fit(v).axes) == 1
    with pytest.raises(ValueError, match="no noise_fit"):
        plot.noise_fit(pr.validate(fit, held.q, held.qd, held.qdd, held.tau))


def test_arrays_are_weighted_by_the_noise_given_and_a_model_error_found():
    robot = pr.robots.a465()
    rng = np.random.default_rng(5)
    sigma = np.array([0.05, 0.2, 0.1, 0.02, 0.03, 0.01])
    q, qd, qdd = trajectory(4).sample(np.arange(1000) / 100.0)
    exact = robot.rnea(q, qd, qdd)
    tau = exact + sigma * rng.standard_normal(exact.shape)
    fit = pr.identify_base_parameters(robot, q, qd, qdd, tau, weighting="noise", noise=sigma)
    f = fit.noise_fit
    np.testing.assert_array_equal(fit.sigma, sigma)
    assert f["correlation"] == 1.0 and f["noise_degrees_of_freedom"] is None
    assert f["p_value"] == pytest.approx(chi_square_tail(f["cost"], f["degrees_of_freedom"]), abs=2e-3)
    assert 1e-3 < f["p_value"] < 1 - 1e-3
    # torques with viscous friction the model lacks: beyond the noise, warned of
    viscous = tau + 0.3 * qd
    with pytest.warns(pr.PerturbidWarning) as said:
        off = pr.identify_base_parameters(robot, q, qd, qdd, viscous, weighting="noise", noise=sigma)
    said = [str(w.message) for w in said]
    assert any("the residuals exceed the torques' noise" in w for w in said), said
    # the friction left out named too, at the viscous coefficient put in
    assert any("friction the fit leaves out" in w and re.search(r"viscous 0\.(2[5-9]|3[0-4])", w) for w in said), said
    g = off.noise_fit
    assert g["p_value"] < 1e-10 and g["cost"] > 2 * g["degrees_of_freedom"], g
    assert g["p_value"] == pytest.approx(chi_square_tail(g["cost"], g["degrees_of_freedom"]), abs=1e-6)


def test_a_noise_that_cannot_weight_is_refused():
    robot = pr.robots.a465()
    q, qd, qdd = trajectory(4).sample(np.arange(1000) / 100.0)
    tau = robot.rnea(q, qd, qdd) + 0.01 * np.random.default_rng(1).standard_normal(q.shape)
    cases = [
        (dict(weighting="noise"), "the noise weighting needs the torques' noise"),
        (dict(weighting="noise", noise=np.ones(5)), "5 noise levels, expected one a joint"),
        (dict(noise=[0.1, 0.1, -1, 0.1, 0.1, 0.1]), "joint 'joint3': a noise level of -1"),
        (dict(noise_correlation=3.0), "given without noise"),
        (dict(weighting="noise", noise=np.full(6, 0.01), noise_correlation=600.0), "independent values"),
    ]
    for kwargs, said in cases:
        with pytest.raises(pr.InputError, match=said):
            pr.identify_base_parameters(robot, q, qd, qdd, tau, **kwargs)


def test_several_averaged_recordings_are_weighted_by_their_pooled_noise():
    robot = pr.robots.a465()
    traj = trajectory(3)
    recs = []
    for seed, noise in [(8, 0.02), (9, 0.02), (10, 0.05)]:
        log = pr.simulate(robot, traj, periods=4, rate=RATE, friction=None, torque_noise=noise, seed=seed)
        recs.append(pr.preprocess(log.t, log.q, log.tau, excitation=traj, rate=RATE, decimate=5, name=f"day{seed}"))
    fit = pr.identify_base_parameters(robot, recs[:2], weighting="noise")
    f = fit.noise_fit
    levels = np.array([r.period_average["averaged_torque_noise"] for r in recs[:2]])
    np.testing.assert_allclose(f["noise"], np.sqrt((levels**2).mean(axis=0)), rtol=1e-12)
    assert f["noise_degrees_of_freedom"] == pytest.approx(2 * 3 * 201 * 6)
    assert 1e-3 < f["p_value"] < 1 - 1e-3, f
    # a log of 2.5 times the noise cannot share one weight a joint with them
    with pytest.raises(pr.InputError, match="differs between the logs"):
        pr.identify_base_parameters(robot, [recs[0], recs[2]], weighting="noise")
    # without the noise weighting, the residuals are then not judged against a noise
    assert pr.identify_base_parameters(robot, [recs[0], recs[2]]).noise_fit is None
