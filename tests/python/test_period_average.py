"""Averaging a log over its excitation's periods from Python (preprocess(..., excitation=) or
period=, harmonics=): the averaged states against the excitation's own, the averaged torques
against Pinocchio's inverse dynamics at them, the noise measured against the noise put in,
and the options that do not go together refused by name."""

import warnings

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import pair_from_text

RATE = 500.0


def excitation_log(lead_in, noise, seed):
    """4 periods (10 s) of a 5-harmonic A465 excitation without friction at 500 Hz, after
    `lead_in` s at rest where it starts, torques with Gaussian noise of `noise` N m."""
    pair = pair_from_text(pr.robots.a465_urdf("kinsheel2010"))
    rng = np.random.default_rng(seed)
    traj = pr.FourierTrajectory(
        rng.uniform(-0.12, 0.12, (6, 5)),
        rng.uniform(-0.12, 0.12, (6, 5)),
        np.array([0.2, 0.3, -0.4, 0.1, 0.5, -0.2]),
        base_frequency=0.1,
    )
    rec = pr.simulate(pair.ours, traj, periods=4, rate=RATE, friction=None, torque_noise=noise, seed=seed)
    rest = int(lead_in * RATE)
    t = np.concatenate([np.arange(rest) / RATE, rec.t + lead_in])
    q = np.concatenate([np.repeat(rec.q[:1], rest, axis=0), rec.q])
    tau = np.concatenate([np.repeat(rec.tau[:1], rest, axis=0), rec.tau])
    return pair, traj, t, q, tau


def test_the_average_is_the_excitation_and_its_torques_pinocchios():
    pair, traj, t, q, tau = excitation_log(1.7, 0.02, 4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = pr.preprocess(t, q, tau, excitation=traj, rate=RATE, decimate=1)
    a = out.period_average
    assert (a["periods"], a["harmonics"], a["torque_harmonics"], a["samples"]) == (4, 5, 100, 5000)
    assert abs(a["start"] - 1.7) < 1e-6 and a["left_out"] == []
    assert all(f is not None and f < 3 for f in a["torque_drift"]), a["torque_drift"]
    # the states are the excitation's own, its derivatives exact
    q_e, qd_e, qdd_e = traj.sample(out.t - a["start"])
    np.testing.assert_allclose(out.q, q_e, atol=1e-9)
    np.testing.assert_allclose(out.qd, qd_e, atol=1e-8)
    np.testing.assert_allclose(out.qdd, qdd_e, atol=1e-7)
    # the torques Pinocchio's at those states, within the averaged noise
    expected = np.array([
        pair.vec(pin.rnea(pair.model, pair.data, pair.q(x), pair.v(v), pair.v(acc)))
        for x, v, acc in zip(out.q, out.qd, out.qdd)
    ])
    rms = np.sqrt(((out.tau - expected) ** 2).mean(axis=0))
    averaged = np.asarray(a["averaged_torque_noise"])
    assert np.all(rms < 1.5 * averaged), (rms, averaged)
    # Gaussian noise of 0.02 N m keeps sqrt(201 / 5000) of itself within 100 harmonics
    np.testing.assert_allclose(a["torque_noise"], 0.02 * np.sqrt(201 / 5000), rtol=0.2)
    np.testing.assert_allclose(averaged, np.asarray(a["torque_noise"]) / 2)
    # by hand: the same periods from the start found, one skipped
    by_hand = pr.preprocess(t, q, tau, period=10.0, harmonics=5, period_start=1.7, skip_periods=1, rate=RATE)
    assert by_hand.period_average["periods"] == 3
    assert abs(by_hand.t[0] - 11.7) < 1e-9 and len(by_hand.t) == 500


def test_a_disturbed_period_is_left_out_with_a_warning():
    _, traj, t, q, tau = excitation_log(0.0, 0.01, 5)
    tau = tau.copy()
    tau[(t > 22.0) & (t < 23.0), 2] += 0.4
    with pytest.warns(pr.PerturbidWarning, match="1 of its periods left out"):
        out = pr.preprocess(t, q, tau, excitation=traj, rate=RATE)
    left = out.period_average["left_out"]
    assert [x["period"] for x in left] == [2] and "joint 3's torques" in left[0]["reason"]
    assert out.period_average["periods"] == 3


def test_options_that_do_not_go_together_are_refused():
    _, traj, t, q, tau = excitation_log(0.0, 0.0, 6)
    for kwargs, says in [
        (dict(excitation=traj, period=10.0), "brings its own period and harmonics"),
        (dict(excitation=traj, period_start=1.0), "the excitation's start is found in the log"),
        (dict(period=10.0), "it needs harmonics"),
        (dict(harmonics=5), "give period or excitation too"),
        (dict(period=10.0, harmonics=5, trim=0.5), "averaging over periods has none"),
        (dict(period=9.0, harmonics=5), "does not repeat with that period"),
        (dict(period=float("nan"), harmonics=5), "period"),
        (dict(period=10.0, harmonics=0), "0 harmonics"),
        (dict(period=10.0, harmonics=5, filter_position=True), "filter_position does not apply"),
    ]:
        with pytest.raises(pr.InputError, match=says):
            pr.preprocess(t, q, tau, rate=RATE, **kwargs)
    # half a period: too short to average, a RecordingError-like InputError naming the periods
    with pytest.raises(pr.PerturbidError, match="at least 2 are needed"):
        pr.preprocess(t[:7000], q[:7000], tau[:7000], period=10.0, harmonics=5, rate=RATE)
