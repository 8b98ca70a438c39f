"""ROS bags of sensor_msgs/JointState (ROS 2 with SQLite or MCAP storage, ROS 1, split ROS 1),
written here with rosbags and read back as recordings."""

from __future__ import annotations

import re

import numpy as np
import pytest

import perturbid_rs as pr
from perturbid_rs import ros

import rosbags  # noqa: E402,F401  (a test dependency: the bag is written for real)


def joint_state(names, position, velocity, effort, stamp_ns=None):
    """One message's fields; ``stamp_ns`` None for a header left unset (0)."""
    return dict(names=list(names), position=position, velocity=velocity, effort=effort, stamp=stamp_ns)


def write_bag(path, messages, topic="/joint_states", kind="ros2", received=None):
    """A bag of ``messages`` (joint_state dicts) on ``topic``: kind 'ros2' (SQLite), 'mcap' or
    'ros1'; ``received`` the bag's receive times (ns), by default the header stamps."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if kind == "ros1" else Stores.ROS2_HUMBLE)
    JointState = store.types["sensor_msgs/msg/JointState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    if kind == "ros1":
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
        serialize = store.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        writer = Writer(path, version=8, storage_plugin=plugin)
        serialize = store.serialize_cdr
    with writer as w:
        conn = w.add_connection(topic, JointState.__msgtype__, typestore=store)
        for k, m in enumerate(messages):
            ns = m["stamp"] or 0
            time = Time(sec=ns // 10**9, nanosec=ns % 10**9)
            header = Header(seq=k, stamp=time, frame_id="") if kind == "ros1" else Header(stamp=time, frame_id="")
            msg = JointState(
                header=header,
                name=m["names"],
                position=np.ascontiguousarray(m["position"], dtype=np.float64),
                velocity=np.ascontiguousarray(m["velocity"], dtype=np.float64),
                effort=np.ascontiguousarray(m["effort"], dtype=np.float64),
            )
            w.write(conn, received[k] if received is not None else ns, serialize(msg, JointState.__msgtype__))


def a465_log(count=200, start=100.0):
    """The A465's joint names and a log of ``count`` samples at 1 kHz from ``start`` s."""
    robot = pr.robots.a465()
    rng = np.random.default_rng(1)
    t = start + np.arange(count) * 1e-3
    q = rng.uniform(-1, 1, (count, 6))
    qd = rng.uniform(-1, 1, (count, 6))
    tau = robot.rnea(q, qd, np.zeros_like(q))
    return robot.joint_names, t, q, qd, tau


def test_a_bag_written_with_rosbags_reads_back_as_the_recording(tmp_path):
    joints, t, q, qd, tau = a465_log()
    # the bag lists the joints in another order, with a gripper joint the robot does not have
    order = [5, 2, 0, 4, 1, 3]
    names = [joints[i] for i in order] + ["gripper"]
    pad = lambda x: np.append(x[order], 0.0)  # noqa: E731
    stamps = [int(round(s * 1e9)) for s in t]
    messages = [joint_state(names, pad(q[k]), pad(qd[k]), pad(tau[k]), stamps[k]) for k in range(len(t))]
    write_bag(tmp_path / "bag", messages)
    rec = ros.read_joint_states(tmp_path / "bag", joints, experiment="D")
    np.testing.assert_allclose(rec.t, t - t[0], atol=1e-9)
    np.testing.assert_array_equal(rec.q, q)
    np.testing.assert_array_equal(rec.qd, qd)
    np.testing.assert_array_equal(rec.tau, tau)
    assert rec.experiment == "D"
    # progress: every 10,000 messages from the first, and at the end
    calls = []
    ros.read_joint_states(tmp_path / "bag", joints, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(0, len(t)), (len(t), len(t))], calls
    # the bag named by its metadata.yaml reads the same
    np.testing.assert_array_equal(ros.read_joint_states(tmp_path / "bag" / "metadata.yaml", joints).q, q)
    # a joint the bag does not have, a topic it does not have: named
    with pytest.raises(pr.InputError, match=r"no message on '/joint_states' names joint elbow; its messages name .*gripper"):
        ros.read_joint_states(tmp_path / "bag", ["elbow"])
    with pytest.raises(pr.InputError, match=r"message 0 on '/joint_states' \(t = 100.000000 s\) has no joint elbow"):
        ros.read_joint_states(tmp_path / "bag", [joints[0], "elbow"])
    with pytest.raises(pr.InputError, match="topic '/other' carries no sensor_msgs/msg/JointState"):
        ros.read_joint_states(tmp_path / "bag", joints, topic="/other")
    with pytest.raises(pr.InputError, match="not a readable ROS bag"):
        ros.read_joint_states(tmp_path / "nothing", joints)
    with pytest.raises(pr.InputError, match=f"joint {joints[1]} named more than once"):
        ros.read_joint_states(tmp_path / "bag", [joints[1], joints[0], joints[1]])
    with pytest.raises(pr.InputError, match="stamp must be 'header' or 'receive'"):
        ros.read_joint_states(tmp_path / "bag", joints, stamp="bag")


@pytest.mark.parametrize("kind", ["mcap", "ros1"])
def test_mcap_and_ros1_bags_read_back_with_epoch_stamps_exact(tmp_path, kind):
    # stamps of 2023 (1.7e9 s): as one float the sum would keep only about 0.2 us
    joints, t, q, qd, tau = a465_log(count=50)
    stamps = [1_700_000_000 * 10**9 + 123 + k * 1_000_001 for k in range(50)]
    messages = [joint_state(joints, q[k], qd[k], tau[k], stamps[k]) for k in range(50)]
    path = tmp_path / ("log.bag" if kind == "ros1" else "bag")
    write_bag(path, messages, kind=kind)
    rec = ros.read_joint_states(path, joints)
    np.testing.assert_array_equal(rec.t, np.arange(50) * 1_000_001 * 1e-9)
    np.testing.assert_array_equal(rec.q, q)
    np.testing.assert_array_equal(rec.tau, tau)


def test_a_split_ros1_recording_reads_as_one(tmp_path):
    joints, t, q, qd, tau = a465_log(count=60)
    stamps = [int(round(s * 1e9)) for s in t]
    messages = [joint_state(joints, q[k], [], tau[k], stamps[k]) for k in range(60)]
    write_bag(tmp_path / "run_0.bag", messages[:25], kind="ros1")
    write_bag(tmp_path / "run_1.bag", messages[25:], kind="ros1")
    # named in any order: read in time order
    rec = ros.read_joint_states([tmp_path / "run_1.bag", tmp_path / "run_0.bag"], joints)
    np.testing.assert_allclose(rec.t, t - t[0], atol=1e-9)
    np.testing.assert_array_equal(rec.q, q)
    assert rec.qd is None  # the messages carry no velocities
    write_bag(tmp_path / "ros2", messages[:5])
    with pytest.raises(pr.InputError, match="several bags are read only as the .bag files of one ROS 1 recording"):
        ros.read_joint_states([tmp_path / "run_0.bag", tmp_path / "ros2"], joints)


def test_another_publisher_on_the_topic_is_passed_over(tmp_path):
    joints, t, q, qd, tau = a465_log(count=40)
    messages = []
    for k in range(40):
        ns = int(round(t[k] * 1e9))
        messages.append(joint_state(joints, q[k], qd[k], tau[k], ns))
        if k % 3 == 0:  # a gripper publishing its own joint states on the same topic
            messages.append(joint_state(["finger_1", "finger_2"], [0.01, 0.01], [0.0, 0.0], [0.0, 0.0], ns + 400_000))
    write_bag(tmp_path / "bag", messages)
    rec = ros.read_joint_states(tmp_path / "bag", joints)
    np.testing.assert_array_equal(rec.q, q)
    np.testing.assert_allclose(rec.t, t - t[0], atol=1e-9)


def broken(tmp_path, change, joints, **read):
    """The message of the InputError reading a 10-message bag whose message 4 ``change`` edits."""
    _, t, q, qd, tau = a465_log(count=10)
    messages = [joint_state(joints, q[k], qd[k], tau[k], int(round(t[k] * 1e9))) for k in range(10)]
    received = [m["stamp"] for m in messages]  # the bag received them in order
    change(messages[4])
    write_bag(tmp_path / "bag", messages, received=received)
    with pytest.raises(pr.InputError) as e:
        ros.read_joint_states(tmp_path / "bag", joints, **read)
    return str(e.value)


@pytest.mark.parametrize(
    "change, expected",
    [
        (lambda m: m.update(names=m["names"][:5] + [m["names"][0]]), r"message 4 .* names joint \w+ more than once"),
        (lambda m: m.update(names=m["names"][:5]), r"message 4 .* has no joint \w+; it names"),
        (lambda m: m.update(velocity=m["velocity"][:3]), "message 4 .* has 3 velocity values for 6 joints"),
        (lambda m: m.update(effort=[]), "message 4 .* has 0 effort values for 6 joints"),
        (lambda m: m["effort"].__setitem__(2, np.nan), r"message 4 .* has a non-finite effort \(nan\) for joint"),
        (lambda m: m["position"].__setitem__(0, np.inf), r"message 4 .* has a non-finite position \(inf\) for joint"),
        (lambda m: m.update(stamp=m["stamp"] - 2_000_000), r"message 4 .* is stamped 0.001000 s before message 3: its times must increase; stamp='receive'"),
        (lambda m: m.update(stamp=m["stamp"] - 1_000_000), "message 4 .* is stamped at the same time as message 3"),
    ],
)
def test_a_broken_message_is_named(tmp_path, change, expected):
    joints = pr.robots.a465().joint_names
    assert re.search(expected, broken(tmp_path, change, joints)), expected


def test_unset_header_stamps_are_named_and_the_receive_times_read_instead(tmp_path):
    joints, t, q, qd, tau = a465_log(count=30)
    received = [1_700_000_000 * 10**9 + k * 1_000_000 for k in range(30)]
    messages = [joint_state(joints, q[k], qd[k], tau[k], None) for k in range(30)]
    write_bag(tmp_path / "bag", messages, received=received)
    with pytest.raises(pr.InputError, match=r"message 0 .* has no header stamp \(0\): its publisher does not set it; stamp='receive'"):
        ros.read_joint_states(tmp_path / "bag", joints)
    rec = ros.read_joint_states(tmp_path / "bag", joints, stamp="receive")
    np.testing.assert_array_equal(rec.t, np.arange(30) * 1_000_000 * 1e-9)
    np.testing.assert_array_equal(rec.q, q)


def test_a_session_bag_goes_through_the_command_line_as_its_recordings(tmp_path):
    """A ROS user's path without Python code: `perturbid ros` writes the session's bag as a
    recording CSV, `perturbid split` cuts it into the plan's runs, `perturbid identify` gives the
    model the recordings give in Python; the Rust commands given the bag itself say how to
    convert it (they said the folder was a directory, or a .bag not UTF-8 text)."""
    import json
    import os
    import subprocess
    import sysconfig
    from pathlib import Path

    exe = str(Path(sysconfig.get_path("scripts")) / ("perturbid.exe" if os.name == "nt" else "perturbid"))
    robot = pr.robots.a465()
    op = pr.OperatingPoint([0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0], [0.089, -0.106, 0.022, 0.056, 0.011, 0.014],
                           [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171])
    plan = pr.plan_experiments(robot, op, design="orthogonal", experiments=["nominal", "D"])
    recs = pr.simulate(robot, plan, gravity=False, friction=None, torque_noise=0.05, seed=3)
    plan.save(str(tmp_path / "plan"))
    # the session: the runs one after the other, 2 s at rest after each, stamped since 1970
    start, messages = 1_700_000_000 * 10**9, []
    for rec in recs:
        for k in range(len(rec.t)):
            messages.append(joint_state(robot.joint_names, rec.q[k], np.zeros(6), rec.tau[k], start + len(messages) * 10**6))
        for _ in range(2000):
            messages.append(joint_state(robot.joint_names, rec.q[-1], np.zeros(6), rec.tau[-1], start + len(messages) * 10**6))
    write_bag(tmp_path / "bag", messages)

    def run(*args):
        return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, cwd=tmp_path)

    out = run("ros", "bag", "--robot", "a465", "--no-velocities", "--out", "session.csv")
    assert out.returncode == 0, out.stderr
    assert f"{len(messages)} samples of 6 joints" in out.stdout
    log = pr.Recording.load(str(tmp_path / "session.csv"), robot.joint_names)
    np.testing.assert_array_equal(log.q, np.array([m["position"] for m in messages]))
    assert run("split", "plan/plan.json", "session.csv", "--out", "runs").returncode == 0
    assert run("identify", "plan/plan.json", "runs", "--out", "model.json").returncode == 0
    model = json.loads((tmp_path / "model.json").read_text())
    direct = pr.identify_local(plan, recs)
    np.testing.assert_allclose(model["d"]["matrix"], direct.D, atol=1e-9 * np.abs(direct.D).max())
    # the Rust commands given the bag, or its folder as the recordings' folder
    for args in (("identify-direct", "a465", "bag"), ("identify", "plan/plan.json", "bag")):
        out = run(*args)
        assert out.returncode == 1 and out.stderr.count("\n") == 1, out.stderr
        assert "bag: a ROS 2 bag (a folder with metadata.yaml), not a CSV table" in out.stderr and "perturbid ros BAG" in out.stderr
    # mistakes: a topic the bag lacks, an output that is the bag, a robot that is not one
    bad = run("ros", "bag", "--robot", "a465", "--topic", "/arm", "--out", "x.csv")
    assert bad.returncode == 1 and "topic '/arm' carries no sensor_msgs/msg/JointState" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "x.csv").exists()
    bad = run("ros", "bag", "--robot", "a465", "--out", "bag")
    assert bad.returncode == 1 and "--out bag is the bag bag" in bad.stderr
    bad = run("ros", "bag", "--robot", "a466", "--out", "x.csv")
    assert bad.returncode == 1 and "unknown robot" in bad.stderr and "Traceback" not in bad.stderr
    # the command is listed where the Rust ones are
    assert "ros  " in run("--help").stdout
