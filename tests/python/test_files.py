"""Plans and recordings through files, as between Python and a robot's controller: Plan.save /
Plan.load and Recording.save / Recording.load give what the objects in memory give."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

import perturbid_rs as pr

TABLE2 = (
    [0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0],
    [0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140],
    [-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710],
)


def test_a_plan_and_its_recordings_through_files_identify_as_in_memory(tmp_path):
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), seed=1, keep_velocity_sign=True)
    written = plan.save(tmp_path / "plan")
    kinds = [e.kind for e in plan.experiments]
    assert [p.name for p in written] == [f"{k}.csv" for k in kinds] + ["plan.json"]
    # the files the command line writes for the same plan, byte for byte
    (tmp_path / "op.json").write_text('{"q": %s, "qd": %s, "qdd": %s}' % TABLE2)
    cli = subprocess.run(
        [sys.executable, "-m", "perturbid_rs", "plan", "a465", "--op", str(tmp_path / "op.json"), "--seed", "1", "--keep-velocity-sign", "--out", str(tmp_path / "cli")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0, cli.stderr
    for p in written:
        assert (tmp_path / "cli" / p.name).read_bytes() == p.read_bytes(), p.name
    loaded = pr.Plan.load(tmp_path / "plan" / "plan.json")
    assert loaded.to_json() == plan.to_json()
    # the controller's trajectory of D is the experiment's samples
    d = np.loadtxt(tmp_path / "plan" / "D.csv", delimiter=",", skiprows=1)
    experiment = plan.experiment("D")
    np.testing.assert_array_equal(d[:, 0], experiment.t)
    np.testing.assert_array_equal(d[:, 1:7], experiment.q)

    recordings = pr.simulate(robot, loaded, torque_noise=0.05, seed=2)
    for rec in recordings:
        rec.save(tmp_path / f"{rec.experiment}.csv")
    # read back by path: each pairs with its experiment by its file name
    read = [pr.Recording.load(tmp_path / f"{k}.csv", plan.joint_names) for k in reversed(kinds)]
    for rec in recordings:
        back = next(r for r in read if r.name.endswith(f"/{rec.experiment}.csv"))
        for field in ("t", "q", "tau"):
            np.testing.assert_array_equal(getattr(back, field), getattr(rec, field))
    a, b = pr.identify_local(plan, recordings), pr.identify_local(loaded, read)
    for term in ("torque", "D", "H", "G", "G_static"):
        np.testing.assert_array_equal(getattr(b, term), getattr(a, term))
    # experiment= marks a file of any name
    other = pr.Recording.load(tmp_path / "D.csv", plan.joint_names, experiment="D")
    assert other.experiment == "D"


def test_recording_files_from_other_tools_and_their_errors(tmp_path):
    joints = ["shoulder", "elbow"]
    # named after the joints, in any order, with velocities, quoted header, a BOM
    path = tmp_path / "log.csv"
    path.write_text('\ufeff"t",tau_elbow,q_shoulder,q_elbow,qd_shoulder,qd_elbow,tau_shoulder\n0,1,2,3,4,5,6\n0.001,1.5,2.5,3.5,4.5,5.5,6.5\n')
    rec = pr.Recording.load(path, joints)
    np.testing.assert_array_equal(rec.q, [[2, 3], [2.5, 3.5]])
    np.testing.assert_array_equal(rec.qd, [[4, 5], [4.5, 5.5]])
    np.testing.assert_array_equal(rec.tau, [[6, 1], [6.5, 1.5]])
    assert rec.qdd is None and rec.name == str(path)
    # numbers are written in the shortest digits that read back to the same double
    rng = np.random.default_rng(3)
    exact = pr.Recording(np.arange(5) * 0.1, rng.normal(size=(5, 2)) * 1e-7, rng.normal(size=(5, 2)) * 1e5)
    exact.save(tmp_path / "exact.csv")
    back = pr.Recording.load(tmp_path / "exact.csv", joints)
    np.testing.assert_array_equal(back.q, exact.q)
    np.testing.assert_array_equal(back.tau, exact.tau)

    bad = tmp_path / "bad.csv"
    bad.write_text("t,q1,q2,tau1,tau2\n0,1,2,3,4\n0.1,1,x,3,4\n")
    with pytest.raises(pr.InputError, match=r"bad.csv.*line 3.*q2"):
        pr.Recording.load(bad, joints)
    with pytest.raises(pr.InputError, match=r"missing column\(s\) q3 \(or q_wrist\)"):
        pr.Recording.load(tmp_path / "exact.csv", joints + ["wrist"])
    with pytest.raises(pr.InputError, match="unexpected column 'q2'"):
        pr.Recording.load(tmp_path / "exact.csv", ["shoulder"])
    with pytest.raises(pr.InputError, match="joint 'elbow' named twice"):
        pr.Recording.load(tmp_path / "exact.csv", ["elbow", "elbow"])
    with pytest.raises(pr.InputError, match="no joint names"):
        pr.Recording.load(tmp_path / "exact.csv", [])
    with pytest.raises(TypeError):
        pr.Recording.load(tmp_path / "exact.csv", "elbow")  # a string is not a list of names
    with pytest.raises(pr.FileError, match="nothing.csv"):
        pr.Recording.load(tmp_path / "nothing.csv", joints)
    # a path that is a folder is named, and nothing is left beside it
    (tmp_path / "folder.csv").mkdir()
    with pytest.raises(pr.FileError, match="folder.csv"):
        exact.save(tmp_path / "folder.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv", "exact.csv", "folder.csv", "log.csv"]


def test_a_session_log_splits_into_its_experiments(tmp_path):
    # the controller ran the plan's experiments one after the other, with a pause at rest of
    # 1 s between two (and 3 s before the first), and logged it all on its own clock
    robot = pr.robots.a465()
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), seed=1, keep_velocity_sign=True)
    recordings = pr.simulate(robot, plan, torque_noise=0.05, seed=2)
    dt = 1.0 / plan.rate
    parts_t, parts_q, parts_tau, now = [], [], [], 100.0
    for rec in recordings:
        pause = 3.0 if not parts_t else 1.0
        rest = int(round(pause / dt))
        parts_q += [np.repeat(rec.q[:1], rest, axis=0), rec.q]
        parts_tau += [np.repeat(rec.tau[:1], rest, axis=0), rec.tau]
        count = rest + len(rec)
        parts_t.append(now + np.arange(count) * dt)
        now += count * dt
    log = pr.Recording(np.concatenate(parts_t), np.vstack(parts_q), np.vstack(parts_tau), name="session")
    with warnings.catch_warnings():
        warnings.simplefilter("error", pr.PerturbidWarning)  # each experiment ran once
        runs = plan.split_session(log)
    assert [r.experiment for r in runs] == [e.kind for e in plan.experiments]
    a, b = pr.identify_local(plan, recordings), pr.identify_local(plan, runs)
    for term in ("D", "H", "G"):
        np.testing.assert_allclose(getattr(b, term), getattr(a, term), atol=0.05 * getattr(a, "stderr")[term].max())
    # on the command line: the log's file into a folder that identify reads
    log.save(tmp_path / "session.csv")
    plan.save(tmp_path / "plan")
    cli = subprocess.run(
        [sys.executable, "-m", "perturbid_rs", "split", str(tmp_path / "plan" / "plan.json"), str(tmp_path / "session.csv"), "--out", str(tmp_path / "runs")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0, cli.stderr
    assert "nominal   from    103.000 s of the log" in cli.stdout, cli.stdout
    for rec in runs:
        back = pr.Recording.load(tmp_path / "runs" / f"{rec.experiment}.csv", plan.joint_names)
        np.testing.assert_array_equal(back.q, rec.q)
    # the last experiment run again: a warning names both stretches, here and on the command line
    last = recordings[-1]
    again = pr.Recording(np.concatenate([log.t, now + 1.0 + last.t - last.t[0]]), np.vstack([log.q, last.q]), np.vstack([log.tau, last.tau]), name="session")
    with pytest.warns(pr.PerturbidWarning, match=f"experiment '{last.experiment}' seems to have run twice in session: its plan is followed also from"):
        plan.split_session(again)
    again.save(tmp_path / "again.csv")
    cli = subprocess.run(
        [sys.executable, "-m", "perturbid_rs", "split", str(tmp_path / "plan" / "plan.json"), str(tmp_path / "again.csv"), "--out", str(tmp_path / "runs2")],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0 and "perturbid: warning: experiment 'D' seems to have run twice" in cli.stderr, cli.stderr
    # a log cut short: the first run that no longer fits is named
    with pytest.raises(pr.InputError, match=r"experiment '\w+': its run \(\d+\.\d+ s\) does not fit in the log between .* \(the log's end\)"):
        plan.split_session(pr.Recording(log.t[: len(log) // 2], log.q[: len(log) // 2], log.tau[: len(log) // 2]))


def cli(*args):
    """`perturbid ARGS`, which must succeed; returns its stdout."""
    run = subprocess.run([sys.executable, "-m", "perturbid_rs", *map(str, args)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_models_through_files_as_the_command_line_writes_them(tmp_path):
    """BaseParameterModel.save / load and LocalModel.save / load: what the command line writes
    loads in Python and predicts what `perturbid predict` predicts; a model saved from Python
    is the command line's document; a file that is not such a model, or a robot the model does
    not fit, is refused by name."""
    robot = pr.robots.a465()
    traj = pr.design_excitation(robot, harmonics=3, base_frequency=0.2, max_evaluations=20, seed=1).trajectory
    t = np.arange(0, traj.period, 0.005)
    q, qd, qdd = traj.sample(t)
    tau = robot.rnea(q, qd, qdd) + np.random.default_rng(4).normal(0, 0.01, q.shape)
    pr.Recording(t, q, tau, qd=qd, qdd=qdd, name="log").save(tmp_path / "log.csv")
    cli("identify-direct", "a465", tmp_path / "log.csv", "--out", tmp_path / "base.json", "--validate", "0")
    cli("predict", tmp_path / "base.json", tmp_path / "log.csv", "--robot", "a465", "--stderr", "--out", tmp_path / "p.csv")
    fit = pr.BaseParameterModel.load(tmp_path / "base.json", robot)
    predicted = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(fit.predict(q, qd, qdd), predicted[:, 1:7], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fit.predict_stderr(q, qd, qdd), predicted[:, 7:13], rtol=1e-12, atol=1e-15)
    # saved from Python: the same document, which the command line reads
    fit.save(tmp_path / "again.json")
    assert (tmp_path / "again.json").read_text() == (tmp_path / "base.json").read_text()
    back = pr.BaseParameterModel.from_json(fit.to_json(), robot)
    np.testing.assert_array_equal(back.theta_base, fit.theta_base)
    # refused by name: another robot, another document, a hand-edited value, no file
    other = pr.Robot.from_urdf_string(pr.robots.a465_urdf(), lock={"joint6": 0.0})
    with pytest.raises(pr.InputError, match=r"robot: .*base.json: the model was identified for 'a465\w*' with joints \[joint1, .*joint6\]; give the robot"):
        pr.BaseParameterModel.load(tmp_path / "base.json", other)
    text = (tmp_path / "base.json").read_text()
    (tmp_path / "nan.json").write_text(text.replace('"cond": ', '"cond": -', 1))
    with pytest.raises(pr.InputError, match="nan.json"):
        pr.BaseParameterModel.load(tmp_path / "nan.json", robot)
    with pytest.raises(pr.FileError, match="missing.json"):
        pr.BaseParameterModel.load(tmp_path / "missing.json", robot)
    # a local model, through its files
    plan = pr.plan_experiments(robot, pr.OperatingPoint(*TABLE2), seed=1, keep_velocity_sign=True)
    local = pr.identify_local(plan, pr.simulate(robot, plan, torque_noise=0.05, seed=2))
    local.save(tmp_path / "local.json")
    loaded = pr.LocalModel.load(tmp_path / "local.json")
    assert loaded.to_json() == local.to_json()
    np.testing.assert_array_equal(loaded.predict(q[:5], qd[:5], qdd[:5]), local.predict(q[:5], qd[:5], qdd[:5]))
    with pytest.raises(pr.InputError, match="local.json"):
        pr.BaseParameterModel.load(tmp_path / "local.json", robot)
    with pytest.raises(pr.InputError, match="base.json"):
        pr.LocalModel.load(tmp_path / "base.json")
    with pytest.raises(pr.FileError):
        local.save(tmp_path / "local.json" / "m.json")  # under a file
