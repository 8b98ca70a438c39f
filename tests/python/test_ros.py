"""ROS 2 bags of sensor_msgs/JointState, written here with rosbags and read back as recordings."""

from __future__ import annotations

import numpy as np
import pytest

import perturbid_rs as pr
from perturbid_rs import ros

import rosbags  # noqa: E402,F401  (a test dependency: the bag is written for real)


def write_bag(path, names, t, q, qd, tau, topic="/joint_states"):
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    JointState = store.types["sensor_msgs/msg/JointState"]
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    with Writer(path, version=8) as w:
        conn = w.add_connection(topic, JointState.__msgtype__, typestore=store)
        for k in range(len(t)):
            ns = int(round(t[k] * 1e9))
            msg = JointState(
                header=Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                name=list(names),
                position=np.ascontiguousarray(q[k], dtype=np.float64),
                velocity=np.ascontiguousarray(qd[k], dtype=np.float64),
                effort=np.ascontiguousarray(tau[k], dtype=np.float64),
            )
            w.write(conn, ns, store.serialize_cdr(msg, JointState.__msgtype__))


def test_a_bag_written_with_rosbags_reads_back_as_the_recording(tmp_path):
    robot = pr.robots.a465()
    rng = np.random.default_rng(1)
    t = 100.0 + np.arange(200) * 1e-3
    q = rng.uniform(-1, 1, (200, 6))
    qd = rng.uniform(-1, 1, (200, 6))
    tau = robot.rnea(q, qd, np.zeros_like(q))
    # the bag lists the joints in another order, with a gripper joint the robot does not have
    order = [5, 2, 0, 4, 1, 3]
    names = [robot.joint_names[i] for i in order] + ["gripper"]
    pad = lambda x: np.hstack([x[:, order], np.zeros((len(x), 1))])  # noqa: E731
    write_bag(tmp_path / "bag", names, t, pad(q), pad(qd), pad(tau))
    rec = ros.read_joint_states(tmp_path / "bag", robot.joint_names)
    np.testing.assert_allclose(rec.t, t - t[0], atol=1e-9)
    np.testing.assert_array_equal(rec.q, q)
    np.testing.assert_array_equal(rec.qd, qd)
    np.testing.assert_array_equal(rec.tau, tau)
    # a joint the bag does not have, a topic it does not have: named
    with pytest.raises(pr.InputError, match=r"message 0 on '/joint_states' \(t = 100.000000 s\) has no joint elbow"):
        ros.read_joint_states(tmp_path / "bag", ["elbow"])
    with pytest.raises(pr.InputError, match="topic '/other' carries no sensor_msgs/msg/JointState"):
        ros.read_joint_states(tmp_path / "bag", robot.joint_names, topic="/other")
    with pytest.raises(pr.InputError, match="not a readable ROS 2 bag"):
        ros.read_joint_states(tmp_path / "nothing", robot.joint_names)
