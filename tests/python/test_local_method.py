"""The paper's method from Python: plan, simulate, identify, against Pinocchio (the oracle)."""

import json
import warnings

import numpy as np
import pinocchio as pin
import pytest

import perturbid_rs as pr
from conftest import erd_dir, pair_from_text, pair_from_urdf

TABLE2 = (
    [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0],
    [0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140],
    [-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710],
)


def rel(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b)


def oracle(pair, q, qd, qdd, gravity=True):
    """(T*, D*, H*, G*) from Pinocchio's RNEA derivatives, in our joint order."""
    model = pair.model
    if not gravity:
        model = pin.Model(pair.model)
        model.gravity.linear[:] = 0.0
    data = model.createData()
    dq, dv, da = pin.computeRNEADerivatives(model, data, pair.q(q), pair.v(qd), pair.v(qdd))
    tau = pin.rnea(model, data, pair.q(q), pair.v(qd), pair.v(qdd))
    da = np.triu(da) + np.triu(da, 1).T
    return pair.vec(tau), pair.mat(da), pair.mat(dv), pair.mat(dq)


def taylor_bound(pair, op, deltas, g_true, qd, qdd, t0):
    """|G_est - G*| <= |R| / sigma_min(X), R_k = tau(q* + dq_k) - T* - G* dq_k by Pinocchio."""
    r = []
    for dq in deltas:
        tau = pin.rnea(pair.model, pair.data, pair.q(op.q + dq), pair.v(qd), pair.v(qdd))
        r.append(pair.vec(tau) - t0 - g_true @ dq)
    return np.linalg.norm(r) / np.linalg.svd(deltas, compute_uv=False).min()


@pytest.fixture(scope="module")
def a465():
    return pair_from_text(pr.robots.a465_urdf("kinsheel2010"))


@pytest.fixture(scope="module")
def ur5():
    return pair_from_urdf(erd_dir() / "ur_description/urdf/ur5_robot.urdf")


def test_a465_table2_matches_pinocchio(a465):
    op = pr.OperatingPoint(*TABLE2)
    plan = pr.plan_experiments(a465.ours, op, design="random", seed=3)
    recs = pr.simulate(a465.ours, plan, gravity=False, friction=None)
    model = pr.identify_local(plan, recs)
    t, d, h, _ = oracle(a465, op.q, op.qd, op.qdd, gravity=False)
    assert rel(model.D, d) < 1e-9
    assert rel(model.H, h) < 1e-9
    assert rel(model.torque, t) < 1e-9
    # Table 3's perturbation row and Table 2's Tn, to the paper's digits
    np.testing.assert_allclose(model.D[:, 0], [9.956, 0, 0, -1.37, 0, -0.27], atol=0.005)
    np.testing.assert_allclose(model.torque, [-1.1883, -3.4797, -1.7304, -0.1377, -0.4466, 0.0539], atol=0.01)


@pytest.mark.parametrize("design", ["random", "orthogonal"])
def test_ur5_matches_pinocchio(ur5, design):
    rng = np.random.default_rng(11)
    q = rng.uniform(-1.5, 1.5, 6)
    op = pr.OperatingPoint(q, rng.uniform(-0.4, 0.4, 6), rng.uniform(-1, 1, 6))
    plan = pr.plan_experiments(ur5.ours, op, design=design, seed=5)
    recs = pr.simulate(ur5.ours, plan, friction=None)
    model = pr.identify_local(plan, recs)
    t, d, h, g = oracle(ur5, op.q, op.qd, op.qdd)
    assert rel(model.D, d) < 1e-9
    assert rel(model.H, h) < 1e-9
    assert rel(model.torque, t) < 1e-9
    bound = taylor_bound(ur5, op, plan.experiment("G").deltas, g, op.qd, op.qdd, t)
    assert np.linalg.norm(model.G - g) <= bound * 1.0001 + 1e-9
    # G static against Pinocchio's gravity derivatives
    gs = ur5.mat(pin.computeGeneralizedGravityDerivatives(ur5.model, ur5.data, ur5.q(op.q)))
    g0 = ur5.vec(pin.computeGeneralizedGravity(ur5.model, ur5.data, ur5.q(op.q)))
    zero = np.zeros(6)
    bound = taylor_bound(ur5, op, plan.experiment("G_static").deltas, gs, zero, zero, g0)
    assert np.linalg.norm(model.G_static - gs) <= bound * 1.0001 + 1e-9


def test_workflow_shapes_uncertainty_and_json():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    plan = pr.plan_experiments(robot, op, design="orthogonal", n=16, seed=1)
    assert [e.kind for e in plan.experiments] == ["nominal", "G_static", "G", "H", "D"]
    e = plan.experiment("D")
    assert e.q.shape == (len(e.t), 6) and e.deltas.shape == (16, 6)
    assert e.crossing_times.shape == (16,)
    i = np.rint(e.crossing_times * plan.rate).astype(int)
    np.testing.assert_allclose(e.qdd[i], op.qdd + e.deltas, atol=1e-12)
    np.testing.assert_allclose(e.q[[0, -1]], [op.q, op.q], atol=1e-12)
    assert plan.experiment("G_static").reference_time is not None
    assert pr.Plan.from_json(plan.to_json()).to_json() == plan.to_json()

    recs = pr.simulate(robot, plan, torque_noise=0.02, position_noise=1e-5, quantization=1e-6, seed=4)
    assert len(recs) == 5 and recs[0].q.shape == (len(recs[0].t), 6) and recs[0].qd is None
    model = pr.identify_local(plan, recs)
    truth = robot.linearize(op.q, op.qd, op.qdd)
    # the estimate is within a few standard errors of the truth
    z = np.abs(model.D - truth.D) / model.stderr["D"]
    assert np.median(z) < 3 and z.max() < 8, z
    assert set(model.cond) == {"D", "H", "G", "G_static"}
    assert all(1 <= c < 1.1 for c in model.cond.values()), model.cond  # measured deltas: near 1
    assert model.stderr["torque"].shape == (6,) and model.residual_rms["H"].shape == (6,)
    # predict: one sample and a batch
    m = model.planned_op  # the nominal passes crossed it: T* holds there
    np.testing.assert_allclose(model.predict(m.q, m.qd, m.qdd), model.torque, atol=1e-12)
    assert np.abs(model.op.q - op.q).max() < 1e-4  # measured at the nominal crossings
    batch = model.predict(np.tile(m.q, (3, 1)), np.tile(m.qd, (3, 1)), np.tile(m.qdd, (3, 1)) + [[0.0], [0.1], [0.2]])
    np.testing.assert_allclose(batch[2], model.torque + model.D @ np.full(6, 0.2), atol=1e-9)
    back = pr.LocalModel.from_json(model.to_json())
    np.testing.assert_array_equal(back.D, model.D)
    np.testing.assert_array_equal(back.stderr["G"], model.stderr["G"])
    doc = json.loads(model.to_json())
    assert doc["format"] == "perturbid-local-model/1" and len(doc["d"]["matrix"]) == 6
    # the predictions' standard errors: T*'s at the operating point; off it, D's entries' with
    # their correlation in each row (from the JSON), worked out here in numpy
    np.testing.assert_allclose(model.predict_stderr(m.q, m.qd, m.qdd), model.stderr["torque"], rtol=1e-14)
    se = model.predict_stderr(np.tile(m.q, (3, 1)), np.tile(m.qd, (3, 1)), np.tile(m.qdd, (3, 1)) + [[0.0], [0.1], [0.2]])
    assert se.shape == (3, 6)
    # recordings of currents put in torques by drive gains (identify --gains-from): the gains'
    # relative standard errors scale each joint's whole prediction
    assert model.drive_gains is None
    gains = {"gain": [42.0, 65.0, 38.0, 9.0, 7.5, -4.0], "stderr": [0.05, 0.02, 0.03, 0.01, 0.02, 0.004]}
    scaled = pr.LocalModel.from_json(json.dumps({**doc, "drive_gains": gains}))
    np.testing.assert_array_equal(scaled.drive_gains["gain"], gains["gain"])
    off = [np.tile(v, (3, 1)) for v in (m.q, m.qd, m.qdd)]
    off[2] = off[2] + [[0.0], [0.1], [0.2]]
    rel = np.array(gains["stderr"]) / np.abs(gains["gain"])
    np.testing.assert_allclose(scaled.predict_stderr(*off),
                               np.hypot(se, model.predict(*off) * rel), rtol=1e-12)
    # a validation weighs the errors against the model's own uncertainty at the states
    states = [np.tile(v, (3, 1)) for v in (m.q, m.qd, m.qdd)]
    states[2] = states[2] + [[0.0], [0.1], [0.2]]
    v = pr.validate(model, *states, model.predict(*states))
    np.testing.assert_allclose(v.model_stderr_rms, np.sqrt(np.mean(se**2, axis=0)), rtol=1e-12)
    assert "model_stderr_rms" in v.to_dataframe().columns
    x = np.full(6, 0.2)
    for term, key in [("D", "d"), ("H", "h"), ("G", "g"), ("G_static", "g_static")]:
        np.testing.assert_array_equal(model.correlation[term], np.array(doc[key]["correlation"]))
    assert model.correlation["D"].shape == (6, 6, 6) and model.correlation["combined"].shape == (6, 18, 18)
    for j in range(6):
        r = model.correlation["D"][j]
        s = model.stderr["D"][j] * x
        expected = np.sqrt(model.stderr["torque"][j] ** 2 + s @ r @ s)
        np.testing.assert_allclose(se[2, j], expected, rtol=1e-12)
    combined = pr.identify_local(plan, recs, estimator="combined")
    assert combined.combined.shape == (6, 18) and combined.estimator == "combined"
    np.testing.assert_array_equal(combined.correlation["D"], combined.correlation["combined"][:, :6, :6])
    # the model as a tidy table: every entry once, where the arrays have it
    df = model.to_dataframe()
    assert list(df.columns) == ["term", "torque", "joint", "value", "std"]
    assert len(df) == 6 + 4 * 36
    t_rows = df[df.term == "T"]
    np.testing.assert_array_equal(t_rows["value"].to_numpy(), model.torque)
    assert (t_rows["joint"] == "").all() and list(t_rows["torque"]) == robot.joint_names
    names = robot.joint_names
    for term, matrix in [("D", model.D), ("H", model.H), ("G", model.G), ("G_static", model.G_static)]:
        part = df[df.term == term]
        i = [names.index(n) for n in part["torque"]]
        j = [names.index(n) for n in part["joint"]]
        np.testing.assert_array_equal(part["value"].to_numpy(), matrix[i, j])
        np.testing.assert_array_equal(part["std"].to_numpy(), model.stderr[term][i, j])


def test_predictions_beyond_the_identified_perturbations_are_warned_of():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    plan = pr.plan_experiments(robot, op, design="orthogonal", n=16, seed=1)
    model = pr.identify_local(plan, pr.simulate(robot, plan, torque_noise=0.02, seed=4))
    # the region: per joint the largest perturbation of G's q, H's qd, D's qdd in the plan
    p = model.perturbations
    for kind, key in [("G", "q"), ("H", "qd"), ("D", "qdd")]:
        np.testing.assert_allclose(p[key], np.abs(plan.experiment(kind).deltas).max(axis=0), rtol=1e-15)
    rng = np.random.default_rng(3)
    x0 = [op.q, op.qd, op.qdd]
    near = [np.asarray(x) + rng.uniform(-1, 1, (20, 6)) * p[k] for x, k in zip(x0, ["q", "qd", "qdd"])]
    far = [x.copy() for x in near]
    far[0][7, 4] = op.q[4] + 6 * p["q"][4]  # one state: joint 5 six times G's largest
    expected = np.max([np.abs(x - np.asarray(c)) / p[k] for x, c, k in zip(far, x0, ["q", "qd", "qdd"])], axis=(0, 2))
    np.testing.assert_allclose(model.reach(*far), expected, rtol=1e-12)
    assert model.reach(*near).max() <= 1 and model.reach(op.q, op.qd, op.qdd) == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)
        model.predict(*near)
        model.predict_stderr(*near)
    with pytest.warns(pr.PerturbidWarning, match=r"1 of 20 states lie beyond the perturbations .* q of 'joint5'"):
        model.predict(*far)
    with pytest.warns(pr.PerturbidWarning, match="the state lies beyond"):
        model.predict_stderr(far[0][7], far[1][7], far[2][7])
    with pytest.warns(pr.PerturbidWarning, match="beyond the perturbations"):
        v = pr.validate(model, *far, model.predict(*near))
    x = v.extrapolation
    assert (x["beyond"], x["states"], x["joint"], x["variable"]) == (1, 20, "joint5", "q")
    assert x["largest"] == pytest.approx(6.0) and x["perturbation"] == p["q"][4]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pr.PerturbidWarning)
        assert pr.validate(model, *near, model.predict(*near)).extrapolation is None
    # a model saved before the perturbations were stored: predicts as before, no reach
    doc = json.loads(model.to_json())
    del doc["perturbations"]
    old = pr.LocalModel.from_json(json.dumps(doc))
    assert old.perturbations is None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pr.PerturbidWarning)
        predicted = model.predict(*far)
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)
        np.testing.assert_array_equal(old.predict(*far), predicted)
    with pytest.raises(pr.InputError, match="identify it again"):
        old.reach(*far)


def test_real_recording_from_arrays_and_shifted_clock():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    plan = pr.plan_experiments(robot, op, experiments=["nominal", "D"], seed=2)
    sims = pr.simulate(robot, plan)
    # as if logged by a robot whose clock started 0.25 s before the plan, with qd logged
    recs = [pr.Recording(r.t + 0.25, r.q, r.tau, qd=np.gradient(r.q, r.t, axis=0), name=f"log{i}", experiment=r.experiment) for i, r in enumerate(sims)]
    model = pr.identify_local(plan, recs, crossing_times="detected", max_shift=0.5)
    assert rel(model.D, robot.mass_matrix(op.q)) < 1e-8
    assert model.H is None and model.G is None
    with pytest.raises(pr.InputError, match="no H"):
        model.predict(op.q, op.qd, op.qdd)


def test_errors():
    robot = pr.robots.a465()
    q = list(TABLE2[0])
    q[1] = robot.upper[1] - 0.005
    with pytest.raises(pr.InputError, match=r"joint2.*t = .*outside"):
        pr.plan_experiments(robot, pr.OperatingPoint(q, TABLE2[1], TABLE2[2]))
    with pytest.raises(pr.InputError, match="design"):
        pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), design="latin")
    with pytest.raises(pr.InputError, match="experiments"):
        pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), experiments=["X"])
    with pytest.raises(pr.InputError, match="qd"):
        pr.OperatingPoint([0, 0], [0], [0, 0])
    with pytest.raises(pr.InputError, match="not increasing at sample 2"):
        pr.Recording([0, 1, 0.5], np.zeros((3, 2)), np.zeros((3, 2)))
    with pytest.raises(pr.InputError, match="tau"):
        pr.Recording([0, 1, 2], np.zeros((3, 2)), np.zeros((3, 3)))
    with pytest.raises(pr.InputError, match="q of joint 2 at sample 1"):
        pr.Recording([0, 1, 2], [[0, 0], [0, np.nan], [0, 0]], np.zeros((3, 2)))
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), experiments=["nominal", "D"])
    recs = pr.simulate(robot, plan)
    with pytest.raises(pr.InputError, match="experiment 'D' of the plan has no recording"):
        pr.identify_local(plan, recs[:1])
    # matched by identity, not order
    assert np.array_equal(pr.identify_local(plan, recs[::-1]).D, pr.identify_local(plan, recs).D)
    unmarked = pr.Recording(recs[1].t, recs[1].q, recs[1].tau, name="run7.csv")
    with pytest.raises(pr.InputError, match="recording 'run7.csv' does not say which experiment"):
        pr.identify_local(plan, [recs[0], unmarked])
    short = pr.Recording(recs[1].t[:2000], recs[1].q[:2000], recs[1].tau[:2000], name="short.csv", experiment="D")
    with pytest.raises(pr.InputError, match="short.csv: experiment 'D', crossing .*too short"):
        pr.identify_local(plan, [recs[0], short])
    epoch = pr.Recording(recs[1].t + 1.7e9, recs[1].q, recs[1].tau, name="ros.csv", experiment="D")
    with pytest.raises(pr.InputError, match="ros.csv: its time stamps run from 1.7e9 .* count from the start of the experiment"):
        pr.identify_local(plan, [recs[0], epoch])
    degrees = pr.Recording(recs[1].t, np.degrees(recs[1].q), recs[1].tau, name="deg.csv", experiment="D")
    with pytest.raises(pr.InputError, match="deg.csv: its positions do not follow the plan .* in radians"):
        pr.identify_local(plan, [recs[0], degrees])
    with pytest.raises(pr.InputError, match="line 1"):
        pr.LocalModel.from_json("{")
    with pytest.raises(pr.InputError, match="friction"):
        pr.simulate(robot, plan, friction="lots")


def test_friction_steps_near_crossings_and_clock_offsets_in_the_diagnostics():
    robot = pr.robots.a465()
    q, qd, qdd = (np.array(v, dtype=float) for v in TABLE2)
    plan = pr.plan_experiments(robot, pr.OperatingPoint(q, qd, qdd), experiments=["nominal", "D"])
    clean = pr.identify_local(plan, pr.simulate(robot, plan, friction=None))
    friction = {"coulomb": [0.3] * 6, "coulomb_negative": [0.5] * 6, "stribeck": [0.2] * 6, "stribeck_velocity": [0.05] * 6}
    recs = pr.simulate(robot, plan, friction=friction)
    shifted = [pr.Recording(r.t + 0.01, r.q, r.tau, experiment=r.experiment) for r in recs]
    model = pr.identify_local(plan, shifted)
    assert rel(model.D, clean.D) < 1e-6
    d = model.diagnostics
    assert d["offsets"].keys() == {"nominal", "D"}
    assert all(abs(o - 0.01) < 1e-6 for o in d["offsets"].values())
    assert any(r["joint"] == robot.joint_names[4] and r["handling"] == "narrowed" for r in d["reversals"])
    assert d["warnings"] == []
    with pytest.raises(pr.InputError, match="unknown key 'coulomb_neg'"):
        pr.simulate(robot, plan, friction={"coulomb_neg": [0.1] * 6})
    # a joint at rest at the operating point reverses at every D crossing: modelled, and warned
    qd0 = qd.copy()
    qd0[4] = 0.0
    plan0 = pr.plan_experiments(robot, pr.OperatingPoint(q, qd0, qdd), experiments=["nominal", "D"])
    recs0 = pr.simulate(robot, plan0, friction={"coulomb": [0.3] * 6})
    with pytest.warns(pr.PerturbidWarning, match="velocity reverses too close"):
        m0 = pr.identify_local(plan0, recs0)
    assert m0.diagnostics["warnings"] and issubclass(pr.PerturbidWarning, UserWarning)


def test_velocity_reversals_between_h_passes():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    with pytest.warns(pr.PerturbidWarning, match=r"experiment 'H': the velocity perturbations reverse joint\(s\) 'joint1'"):
        plan = pr.plan_experiments(robot, op, experiments=["nominal", "H"])
    assert len(plan.warnings) == 1
    kept = pr.plan_experiments(robot, op, experiments=["nominal", "H"], keep_velocity_sign=True)
    assert kept.warnings == []
    aware = pr.plan_experiments(robot, op, experiments=["nominal", "H"], friction_aware_h=True)
    friction = {"viscous": [0.2] * 6, "coulomb": [0.3] * 6, "coulomb_negative": [0.4] * 6}
    clean = pr.identify_local(aware, pr.simulate(robot, aware, friction=None), friction_aware_h=True)
    model = pr.identify_local(aware, pr.simulate(robot, aware, friction=friction), friction_aware_h=True)
    assert rel(model.H, clean.H + 0.2 * np.eye(6)) < 1e-6
    steps = model.coulomb
    assert steps is not None and steps["joint1"] == pytest.approx(0.7, abs=1e-6)
    assert pr.identify_local(aware, pr.simulate(robot, aware, friction=None)).coulomb is None


def test_parameters_from_identified_local_models():
    robot = pr.robots.a465()
    q, qd, qdd = (np.array(v, dtype=float) for v in TABLE2)
    models = []
    for k, shift in enumerate([0.0, 0.3, -0.3]):
        op = pr.OperatingPoint(q + shift * np.array([1, 0.5, 0.5, 1, 0.3, 1]), qd, qdd)
        plan = pr.plan_experiments(robot, op, experiments=["nominal", "H", "D"], design="orthogonal", seed=k)
        models.append(pr.identify_local(plan, pr.simulate(robot, plan, friction=None)))
    fit, info = pr.identify_parameters_from_local(robot, models, use=["torque", "D", "H"])
    assert info["rank"] <= info["robot_rank"] and info["rows"] == 3 * (6 + 72)
    assert len(info["unidentified"]) == info["robot_rank"] - info["rank"]
    # whatever these three points identify, they predict the torques there
    for m in models:
        op = m.planned_op
        np.testing.assert_allclose(fit.predict(op.q, op.qd, op.qdd), m.torque, atol=1e-6)
        np.testing.assert_allclose(fit.mass_matrix(op.q), m.D, atol=1e-6)
    # and physically consistent: the same torques there, from a robot that can exist
    _, info = pr.identify_parameters_from_local(robot, models, use=["torque", "D", "H"], consistent=True)
    c = info["consistent"]
    assert isinstance(c, pr.ConsistentFit) and c.residual_growth >= 1.0 - 1e-9
    assert robot.physical_consistency(c.theta, friction="armature")[0]
    for m in models:
        op = m.planned_op
        np.testing.assert_allclose(c.model.predict(op.q, op.qd, op.qdd), m.torque, atol=1e-3)
    with pytest.raises(pr.InputError, match="'Q'"):
        pr.identify_parameters_from_local(robot, models, use=["Q"])
    # a model given twice counts its noise twice
    with pytest.raises(pr.InputError, match=r"models\[3\]: the same local model as models\[1\]"):
        pr.identify_parameters_from_local(robot, models + [models[1]], use=["torque", "D", "H"])


def test_suggested_operating_points_reach_every_base_parameter():
    robot = pr.robots.a465()
    start = pr.OperatingPoint(*TABLE2)
    picks = pr.suggest_operating_points(robot, [start], candidates=40, count=3, use=["torque", "D", "H"])
    assert len(picks) == 3 and picks[-1][1] == 40  # 36 rigid-body ones and 4 the armatures add
    assert all(isinstance(op, pr.OperatingPoint) for op, _ in picks)
    with pytest.raises(pr.InputError, match="candidates"):
        pr.suggest_operating_points(robot, candidates=0)


def with_torques(recs, experiment, edit):
    """The recordings `recs` with `edit` applied in place to a copy of `experiment`'s torques."""
    out = []
    for r in recs:
        tau = r.tau.copy()
        if r.experiment == experiment:
            edit(tau)
        out.append(pr.Recording(r.t, r.q, tau, name=r.name, experiment=r.experiment))
    return out


def test_a_dead_torque_channel_is_warned_about_and_marked_unmeasured():
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2))
    recs = pr.simulate(robot, plan, torque_noise=0.01, seed=3)

    def stick(tau):
        tau[:, 2] = 12.5

    stuck = with_torques(recs, "D", stick)
    with pytest.warns(pr.PerturbidWarning, match="experiment 'D': the torque of joint 'joint3' \\(12.5 N m\\) reads the same value"):
        model = pr.identify_local(plan, stuck)
    assert model.diagnostics["unmeasured"] == [{"experiment": "D", "joint": "joint3", "value": 12.5}]
    se = model.stderr["D"]
    assert np.isnan(se[2]).all() and np.isfinite(np.delete(se, 2, axis=0)).all()
    # and the clean recordings raise no such warning
    clean = pr.identify_local(plan, recs)
    assert clean.diagnostics["unmeasured"] == []


def test_torque_columns_swapped_in_one_recording_are_named():
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2))
    recs = pr.simulate(robot, plan, torque_noise=0.01, seed=3)

    def swap(tau):
        tau[:, [2, 5]] = tau[:, [5, 2]]

    swapped = with_torques(recs, "G", swap)
    with pytest.warns(pr.PerturbidWarning, match="'joint3' and 'joint6' are off by each other's T\\*"):
        model = pr.identify_local(plan, swapped)
    found = model.diagnostics["torque_offsets"]
    assert [(f["experiment"], f["joint"]) for f in found] == [("G", "joint3"), ("G", "joint6")]
    # each off by the difference of the two joints' T* (the clean identification's)
    clean = pr.identify_local(plan, recs)
    assert clean.diagnostics["torque_offsets"] == []
    gap = clean.torque[5] - clean.torque[2]
    assert abs(found[0]["offset"] - gap) < 0.01 * abs(gap)
    assert abs(found[1]["offset"] + gap) < 0.01 * abs(gap)
    assert all(abs(f["offset"]) > 100 * f["stderr"] for f in found)


def test_a_glitch_in_a_log_is_replaced_and_reported():
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2))
    recs = pr.simulate(robot, plan, torque_noise=0.02, position_noise=1e-5, seed=5, friction=None)
    clean = pr.identify_local(plan, recs)
    assert clean.diagnostics["glitches"] == []
    (d,) = [e for e in plan.experiments if e.kind == "D"]
    spiked = []
    for r in recs:
        tau = r.tau.copy()
        if r.experiment == "D":
            i = int(np.searchsorted(r.t, d.crossing_times[2] + 0.004))
            tau[i, 1] += 60.0
            sample = i
        spiked.append(pr.Recording(r.t, r.q, tau, name=r.name, experiment=r.experiment))
    with pytest.warns(pr.PerturbidWarning, match=f"tau of 'joint2' at t = .* \\(sample {sample}\\) read"):
        model = pr.identify_local(plan, spiked)
    (g,) = model.diagnostics["glitches"]
    assert g["experiment"] == "D" and g["signal"] == "tau" and g["joint"] == "joint2"
    assert g["sample"] == sample and g["replaced"] is True and g["noise_levels"] > 10
    assert g["value"] == pytest.approx(spiked[[r.experiment for r in recs].index("D")].tau[sample, 1])
    # as if the sample had not been recorded: the model is the clean one to its noise
    np.testing.assert_allclose(model.D, clean.D, atol=0.2 * np.max(clean.stderr["D"]))
    assert model.diagnostics["dropouts"] == [] == clean.diagnostics["dropouts"]
    # six rows of zeros in every torque of a D window: a dropout, removed before the windows
    # are read
    dropped = []
    for r in recs:
        tau = r.tau.copy()
        if r.experiment == "D":
            i = int(np.searchsorted(r.t, d.crossing_times[1]))
            tau[i : i + 6, :] = 0.0
            first = i
        dropped.append(pr.Recording(r.t, r.q, tau, name=r.name, experiment=r.experiment))
    with pytest.warns(pr.PerturbidWarning, match="experiment 'D'.*1 dropout"):
        model = pr.identify_local(plan, dropped)
    (drop,) = model.diagnostics["dropouts"]
    assert (drop["experiment"], drop["signal"], drop["first_sample"], drop["samples"]) == ("D", "tau", first, 6)
    np.testing.assert_allclose(model.D, clean.D, atol=0.2 * np.max(clean.stderr["D"]))
    assert model.diagnostics["held_readings"] == [] == clean.diagnostics["held_readings"]
    # six rows of zeros in one joint's torque (the others read on): a held reading, replaced
    # before the windows are read
    held = []
    for r in recs:
        tau = r.tau.copy()
        if r.experiment == "D":
            i = int(np.searchsorted(r.t, d.crossing_times[1]))
            tau[i : i + 6, 1] = 0.0
            first = i
        held.append(pr.Recording(r.t, r.q, tau, name=r.name, experiment=r.experiment))
    with pytest.warns(pr.PerturbidWarning, match="experiment 'D'.*1 held reading"):
        model = pr.identify_local(plan, held)
    found = model.diagnostics["held_readings"]
    assert [(g["experiment"], g["signal"], g["joint"], g["sample"], g["held"]) for g in found] == [
        ("D", "tau", 1, s, 6) for s in range(first, first + 6)
    ]
    np.testing.assert_allclose(model.D, clean.D, atol=0.2 * np.max(clean.stderr["D"]))
    # one joint's position frozen for 15 rows in a D window (a stalled encoder stream): a
    # frozen reading, its rows removed before the windows are read; across a window's centre
    # they leave it too few samples, and the error says what was removed
    def stall(at: float) -> tuple[list, int]:
        out, first = [], -1
        for r in recs:
            q = r.q.copy()
            if r.experiment == "D":
                first = int(np.searchsorted(r.t, at))
                q[first : first + 15, 1] = q[first, 1]
            out.append(pr.Recording(r.t, q, r.tau, name=r.name, experiment=r.experiment))
        return out, first

    stalled, first = stall(d.crossing_times[1] + 0.004)
    with pytest.warns(pr.PerturbidWarning, match="experiment 'D'.*1 frozen reading.*q of 'joint2' held"):
        model = pr.identify_local(plan, stalled)
    (frozen,) = model.diagnostics["dropouts"]
    assert (frozen["experiment"], frozen["signal"], frozen["joint"], frozen["first_sample"], frozen["samples"]) == ("D", "q", 1, first, 15)
    np.testing.assert_allclose(model.D, clean.D, atol=0.2 * np.max(clean.stderr["D"]))
    across, _ = stall(d.crossing_times[1] - 0.007)
    with pytest.raises(pr.InputError, match=r"crossing 1 .* need at least .*after removing 1 frozen reading\(s\)"):
        pr.identify_local(plan, across)


def test_the_torque_noise_is_reported_per_experiment_and_joint():
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2))
    levels = np.array([0.005, 0.01, 0.02, 0.01, 0.004, 0.002])
    model = pr.identify_local(plan, pr.simulate(robot, plan, torque_noise=levels, seed=4, friction=None))
    noise = model.diagnostics["noise"]
    # the nominal passes and the separated regressions in the plan's order, one entry a joint
    assert [(e["experiment"], e["joint"]) for e in noise] == [
        (x, f"joint{j}") for x in ["nominal", "G_static", "G", "H", "D"] for j in range(1, 7)
    ]
    for e in noise:
        j = int(e["joint"][-1]) - 1
        assert abs(e["samples"] / levels[j] - 1) < 0.15, e
        assert e["passes"] is not None and e["passes"] >= 0
        assert e["step"] is None  # noise alone is no grid of steps
        assert e["position_step"] is None  # nor are continuous positions
    # white noise: the nominal readings scatter by about what their samples' noise gives them
    # (a fit over 101 samples: sqrt(4.8 / 101) of a sample's), so little is left beyond it
    for e in noise[:6]:
        j = int(e["joint"][-1]) - 1
        assert e["passes"] < 0.5 * levels[j], e
    # the same, as arrays for the robot's next plan
    samples, passes = model.nominal_noise()
    assert samples.shape == passes.shape == (6,)
    assert list(samples) == [e["samples"] for e in noise[:6]]
    assert list(passes) == [e["passes"] for e in noise[:6]]
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), torque_noise=samples, torque_pass_noise=passes, experiments=["nominal", "D"])
    assert not [w for w in plan.warnings if "the robot's model predicts" in w]
    # several identifications pooled: the root mean square per joint
    other = pr.identify_local(plan, pr.simulate(robot, plan, torque_noise=2 * levels, seed=9, friction=None))
    pooled = pr.LocalModel.pooled_nominal_noise([model, other])
    for mine, theirs, both in zip(model.nominal_noise(), other.nominal_noise(), pooled):
        np.testing.assert_allclose(both, np.sqrt((mine**2 + theirs**2) / 2), rtol=1e-15)
    assert np.all(pooled[0] > 1.4 * samples)  # the other's samples are twice as noisy
    with pytest.raises(pr.InputError, match="no local model"):
        pr.LocalModel.pooled_nominal_noise([])
    # a noise-free simulation among them would pull the pool down unseen: refused
    quiet = pr.identify_local(plan, pr.simulate(robot, plan, friction=None))
    with pytest.raises(pr.InputError, match=r"models\[1\] read no torque noise .* at joint 'joint1' \(data without noise: a simulation\?\) and models\[0\] read"):
        pr.LocalModel.pooled_nominal_noise([model, quiet, other])
    # what varies from pass to pass in H beyond the samples' noise: the velocity-squared terms
    # the +- pairs cancel from H* (several mN m at this point), far above D's
    passes = {(e["experiment"], e["joint"]): e["passes"] for e in noise}
    assert passes[("H", "joint1")] > 0.003 and passes[("D", "joint1")] < passes[("H", "joint1")]
    # saved with the model; a hand-edited negative noise is refused by name
    back = pr.LocalModel.from_json(model.to_json())
    assert back.diagnostics["noise"] == noise
    # a model without the nominal passes' noise (an older version's) has none to give
    doc = json.loads(model.to_json())
    doc["diagnostics"]["noise"] = noise[6:]
    with pytest.raises(pr.InputError, match="0 entries of the nominal passes' noise for joint 'joint1'"):
        pr.LocalModel.from_json(json.dumps(doc)).nominal_noise()
    doc["diagnostics"]["noise"] = noise + noise[:1]  # nor one with two (hand-edited)
    with pytest.raises(pr.InputError, match="2 entries of the nominal passes' noise for joint 'joint1'"):
        pr.LocalModel.from_json(json.dumps(doc)).nominal_noise()
    doc = json.loads(model.to_json())
    doc["diagnostics"]["noise"][2]["samples"] = -1.0
    with pytest.raises(pr.InputError, match=r"diagnostics.noise\[2\].samples is -1"):
        pr.LocalModel.from_json(json.dumps(doc))
    doc = json.loads(model.to_json())
    doc["diagnostics"]["noise"][1]["step"] = 0.0
    with pytest.raises(pr.InputError, match=r"diagnostics.noise\[1\].step is 0; expected a positive step"):
        pr.LocalModel.from_json(json.dumps(doc))
    # and entries naming a joint or an experiment the model does not have
    for entry, value in [("joint", "joint9"), ("experiment", "Q")]:
        doc = json.loads(model.to_json())
        doc["diagnostics"]["noise"][0][entry] = value
        with pytest.raises(pr.InputError, match=f"diagnostics name .*'{value}'"):
            pr.LocalModel.from_json(json.dumps(doc))


def test_positions_in_coarse_encoder_counts_are_read_by_their_band():
    # 4,096 counts a revolution: the crossings' states are read by the band of half a count,
    # the step is reported per experiment and joint, the joints whose perturbations the
    # encoder cannot resolve are warned about, and D* stays within its standard errors
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    plan = pr.plan_experiments(robot, op, design="orthogonal")
    truth = robot.linearize(*TABLE2)
    tr = pr.TrueRobot({"sensors": {"encoder_counts": [4096] * 6, "torque_noise": [0.01] * 6}, "seed": 5})
    with pytest.warns(pr.PerturbidWarning, match=r"experiment 'D': the encoders of joint\(s\) .*'joint3' \(steps of 1.53e-3 rad: accelerations known to"):
        model = pr.identify_local(plan, pr.simulate(robot, plan, true_robot=tr))
    steps = [e["position_step"] for e in model.diagnostics["noise"]]
    assert len(steps) == 30 and all(abs(s / (2 * np.pi / 4096) - 1) < 1e-6 for s in steps)
    z = np.abs(model.D - truth.D) / model.stderr["D"]
    assert z.max() < 4, z
    # saved with the model; a hand-edited step of 0 or a string is refused by name
    back = pr.LocalModel.from_json(model.to_json())
    assert back.diagnostics["noise"] == model.diagnostics["noise"]
    doc = json.loads(model.to_json())
    doc["diagnostics"]["noise"][3]["position_step"] = 0.0
    with pytest.raises(pr.InputError, match=r"diagnostics.noise\[3\].position_step is 0; expected a positive step \(rad\)"):
        pr.LocalModel.from_json(json.dumps(doc))
    doc["diagnostics"]["noise"][3]["position_step"] = "fine"
    with pytest.raises(pr.InputError, match="position_step"):
        pr.LocalModel.from_json(json.dumps(doc))


def test_the_planner_warns_of_perturbations_the_encoders_cannot_resolve():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    step = 2 * np.pi / 4096
    with pytest.warns(pr.PerturbidWarning, match=r"experiment 'D': its encoders would measure the perturbations of joint\(s\) 'joint1'.*a crossing window of about 0.19 s"):
        pr.plan_experiments(robot, op, design="orthogonal", encoder_step=step)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plan = pr.plan_experiments(robot, op, design="orthogonal", window=0.2, encoder_step=[step] * 6)
    assert not [w for w in caught if "its encoders" in str(w.message)]
    assert not [w for w in plan.warnings if "its encoders" in w]
    # one per joint, in [0, 1], finite
    for bad in [[step] * 5, -step, float("nan"), "fine"]:
        with pytest.raises(pr.InputError, match="encoder_step"):
            pr.plan_experiments(robot, op, encoder_step=bad)


def test_a_poorly_conditioned_design_is_reported_and_warned_about():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(*TABLE2)
    with pytest.warns(pr.PerturbidWarning) as caught:
        plan = pr.plan_experiments(robot, op, design="random", seed=0)
    for e in plan.experiments:
        if e.kind == "nominal":
            assert e.cond is None
            continue
        x = e.deltas / np.linalg.norm(e.deltas, axis=0)
        s = np.linalg.svd(x, compute_uv=False)
        assert e.cond == pytest.approx(s[0] / s[-1], rel=1e-10)
        warned = [str(w.message) for w in caught if f"experiment '{e.kind}': its perturbations have cond(X)" in str(w.message)]
        assert len(warned) == (1 if s[0] / s[-1] > 30 else 0), (e.kind, s[0] / s[-1])
        if warned:
            assert f"cond(X) = {s[0] / s[-1]:.1f}" in warned[0]
            assert f"will be {1 / s[-1]:.1f} times less precise" in warned[0]
    assert plan.experiment("G").cond > 30  # this seed's G design: the warning is exercised
    designed = pr.plan_experiments(robot, op, design="orthogonal", seed=0)
    assert not any("its perturbations have cond(X)" in w for w in designed.warnings)
    assert all(e.cond == pytest.approx(1.0, abs=1e-12) for e in designed.experiments if e.kind != "nominal")


def test_perturbations_too_small_for_the_torque_noise_are_warned_of():
    robot = pr.robots.a465()
    op = pr.OperatingPoint(TABLE2[0], [0.4, -0.35, 0.3, 0.5, -0.4, 0.45], TABLE2[2])
    friction = {"viscous": [2.0, 1.5, 1.0, 0.5, 0.4, 0.3]}
    tiny = dict(dq_fraction=1e-8, dqd_fraction=1e-8, dqdd_fraction=1e-8)
    for sizes, unresolved in [(dict(dqd=[0.1] * 6), []), (tiny, ["G_static", "G", "H", "D"])]:
        plan = pr.plan_experiments(robot, op, **sizes)
        recs = pr.simulate(robot, plan, friction=friction, torque_noise=0.05, seed=4)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = pr.identify_local(plan, recs)
        named = [w for w in model.diagnostics["warnings"] if "responded to the perturbations beyond its noise" in w]
        assert sorted(w.split("'")[1] for w in named) == sorted(unresolved), named
        assert all(any(w == str(c.message) for c in caught) for w in named)
        assert all("times larger" in w for w in named)


def test_the_planner_predicts_perturbations_too_small_for_the_torque_noise():
    # the same two plans as above, now told the noise: the planner says beforehand which
    # experiments the identification will not resolve, and the identification agrees
    robot = pr.robots.a465()
    op = pr.OperatingPoint(TABLE2[0], [0.4, -0.35, 0.3, 0.5, -0.4, 0.45], TABLE2[2])
    tiny = dict(dq_fraction=1e-8, dqd_fraction=1e-8, dqdd_fraction=1e-8)
    for sizes, predicted in [(dict(dqd=[0.1] * 6), []), (tiny, ["G_static", "G", "H", "D"])]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            plan = pr.plan_experiments(robot, op, torque_noise=0.05, **sizes)
        named = [w for w in plan.warnings if "the robot's model predicts" in w]
        assert sorted(w.split("'")[1] for w in named) == sorted(predicted), named
        assert all(any(w == str(c.message) for c in caught) for w in named)
    # a number or one per joint, each in [0, 1e6] and finite
    for bad in [[0.05] * 5, -0.05, float("nan"), 1e300, "noisy"]:
        with pytest.raises(pr.InputError, match="torque_noise"):
            pr.plan_experiments(robot, op, torque_noise=bad)
    # a sensor whose readings vary from pass to pass (noise slower than a window), as an
    # identification reports it for the nominal passes: the velocity perturbations that its
    # samples' noise alone resolves are lost in it
    sizes = dict(dqd=[0.1] * 6)
    plan = pr.plan_experiments(robot, op, torque_noise=0.01, **sizes)
    assert not [w for w in plan.warnings if "the robot's model predicts" in w]
    with pytest.warns(pr.PerturbidWarning, match=r"experiment 'H': with torque samples of up to 0.01 N m \(standard deviation\) and readings varying by up to 0.5 N m from pass to pass"):
        pr.plan_experiments(robot, op, torque_noise=0.01, torque_pass_noise=0.5, **sizes)
    for bad, name in [(-0.05, r"torque_pass_noise\[0\]"), ([0.05] * 7, "torque_pass_noise"), (float("inf"), r"torque_pass_noise\[0\]")]:
        with pytest.raises(pr.InputError, match=name):
            pr.plan_experiments(robot, op, torque_noise=0.01, torque_pass_noise=bad)
    # it is read against the samples' noise: without it, refused by joint
    with pytest.raises(pr.InputError, match=r"torque_pass_noise\[2\].*'joint3', whose torque_noise is not given"):
        pr.plan_experiments(robot, op, torque_noise=[0.01, 0.01, 0, 0.01, 0.01, 0.01], torque_pass_noise=0.05)
    with pytest.raises(pr.InputError, match=r"torque_pass_noise\[0\].*whose torque_noise is not given"):
        pr.plan_experiments(robot, op, torque_pass_noise=0.05)


def test_coarse_encoders_are_reported_by_the_friction_aware_h_regression_too():
    # 4,096 counts a revolution leave joint 3's velocity changes in a 0.02 s window uncertain by
    # more than a tenth: the plain H regression said so, the friction-aware one did not
    robot = pr.robots.a465()
    tr = pr.TrueRobot({"sensors": {"encoder_counts": [4096] * 6, "torque_noise": [0.01] * 6}, "seed": 5})
    for aware in [False, True]:
        plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), design="orthogonal", experiments=["nominal", "H"], window=0.02, friction_aware_h=aware)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = pr.identify_local(plan, pr.simulate(robot, plan, true_robot=tr), friction_aware_h=aware)
        coarse = [w for w in model.diagnostics["warnings"] if w.startswith("experiment 'H': the encoders of joint(s) 'joint3' (steps of 1.53e-3 rad: velocities known to")]
        assert len(coarse) == 1, (aware, model.diagnostics["warnings"])
        assert (model.coulomb is not None) == aware


def test_a_tracking_robots_miss_and_the_estimator_evidence():
    """A robot under PD tracking with a payload its model lacks misses P: the model reports
    the miss per joint, T* carried to the planned point (measured mean - correction), and the
    held-out evidence the estimator advice rests on."""
    robot = pr.robots.a465()
    op = pr.OperatingPoint(TABLE2[0], [0.5, -0.4, 0.45, 0.6, -0.5, 0.55], TABLE2[2])
    plan = pr.plan_experiments(robot, op)
    true = pr.TrueRobot({
        "payload": {"link": "link6", "mass": 0.5, "com": [0.0, 0.0, 0.05]},
        "controller": {"kp": [400.0] * 6, "kd": [40.0] * 6, "substeps": 2},
        "sensors": {"torque_noise": [0.01] * 6},
    })
    model = pr.identify_local(plan, pr.simulate(robot, plan, true_robot=true))
    miss = model.miss
    assert set(miss) >= {"q", "qd", "qdd", "q_perturbations", "q_stderr", "qd_stderr", "qdd_stderr", "measured_torque", "correction", "correction_stderr"}
    # the miss is measured far beyond its standard errors: a miss to correct, not noise
    assert np.abs(miss["q"] / miss["q_stderr"]).max() > 10.0
    np.testing.assert_allclose(miss["q"], model.op.q - model.planned_op.q, atol=1e-12)
    np.testing.assert_allclose(miss["measured_torque"] - miss["correction"], model.torque, atol=1e-9)
    assert np.abs(miss["q"]).max() > 1e-4
    evidence = model.diagnostics["estimator_evidence"]
    assert evidence["crossings"] > 20 and 0.0 <= evidence["p_value"] <= 1.0
    # the separated estimate is the worse predictor under tracking errors
    assert evidence["combined"] < evidence["separated"]
    # a torque logged late is read past by a given delay; one beyond any drive's is refused
    recs = pr.simulate(robot, plan, true_robot=true)
    later = pr.identify_local(plan, recs, torque_delay=0.001)
    assert np.abs(later.torque - model.torque).max() > 0.0
    with pytest.raises(ValueError, match="torque_delay"):
        pr.identify_local(plan, recs, torque_delay=1.0)
    # or found in the recordings with the robot's rigid-body model, and read past
    found = pr.identify_local(plan, recs, torque_delay="estimate", robot=robot)
    delay = found.diagnostics["torque_delay"]
    assert set(delay) == {"delay", "stderr", "rows", "unexplained", "unexplained_at_zero"}
    # no sensor delay: the held command reads as half a sample early
    assert abs(delay["delay"] + 0.5 / plan.rate) < 3e-4 and delay["stderr"] > 0.0
    assert "torque_delay" not in later.diagnostics
    with pytest.raises(ValueError, match="robot"):
        pr.identify_local(plan, recs, torque_delay="estimate")
    with pytest.raises(ValueError, match="robot"):
        pr.identify_local(plan, recs, torque_delay=0.001, robot=robot)
    with pytest.raises(ValueError, match="expected a delay in seconds, or 'estimate'"):
        pr.identify_local(plan, recs, torque_delay="guess")
    assert [len(c) for c in miss["corrected"]] == [3] * 6
    # the next round's plan commands the references off the crossings by the miss
    refined = plan.refine(recs, robot=robot)
    recs2 = pr.simulate(robot, refined, true_robot=true)
    again = pr.identify_local(refined, recs2)
    assert np.abs(again.miss["q"]).max() < 0.5 * np.abs(miss["q"]).max()
    # rounds pooled: a repeat of the refined round halves the variance of D*
    pooled = pr.identify_local(refined, recs2, rounds=[(refined, recs2)])
    assert np.median(pooled.stderr["D"]) < 0.8 * np.median(again.stderr["D"])
    # the first round's crossings join the refined round's, and bring its tracking errors
    # into the separated regressions (docs/method.md, "Plans that reach P")
    both = pr.identify_local(refined, recs2, rounds=[(plan, recs)])
    assert np.median(both.stderr["D"]) > np.median(again.stderr["D"])
    # the delay estimated over every round's recordings at once
    found_both = pr.identify_local(refined, recs2, rounds=[(plan, recs)], torque_delay="estimate", robot=robot)
    assert abs(found_both.diagnostics["torque_delay"]["delay"] + 0.5 / plan.rate) < 3e-4
