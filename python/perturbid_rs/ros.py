"""ROS 2 bags of ``sensor_msgs/msg/JointState`` as recordings (the ``rosbags`` package, an
optional dependency: ``pip install 'perturbid_rs[ros]'``; no ROS installation needed).

A JointState message carries joint names with positions, velocities and efforts in any order
and any subset; each message is matched by name to the robot's joints. Messages that lack a
joint, or hold a non-finite value, are refused with their index and time, not skipped.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import Any, Optional, Sequence, Union

import numpy as np

from ._core import InputError, Recording

__all__ = ["read_joint_states"]

#: At most this many messages are read (about 3 hours at 1 kHz).
MAX_MESSAGES = 10_000_000


def read_joint_states(
    path: Union[str, PathLike[str]],
    joints: Sequence[str],
    topic: Optional[str] = None,
    *,
    name: str = "rosbag",
    velocities: bool = True,
) -> Recording:
    """The recording of ``joints`` (the robot's joint names, e.g. ``robot.joint_names``) from
    the ``sensor_msgs/msg/JointState`` messages of a ROS 2 bag (a folder, or its
    ``metadata.yaml``). ``topic`` selects the topic (default: the only JointState topic).
    Time ``t`` (s) from the message header's stamp, relative to the first; positions (rad or
    m), efforts as torques (N m or N), velocities when ``velocities`` and every message has
    them. Raises InputError naming the bag, topic, message and joint of any problem; ImportError
    naming the extra without rosbags.
    """
    try:
        from rosbags.rosbag2 import Reader
        from rosbags.typesys import Stores, get_typestore
    except ImportError as e:
        raise ImportError("reading ROS 2 bags needs rosbags: pip install 'perturbid_rs[ros]'") from e
    joints = list(joints)
    if not joints:
        raise InputError("read_joint_states: no joint names given")
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    msgtype = "sensor_msgs/msg/JointState"
    try:
        reader = Reader(Path(path))
        reader.open()
    except Exception as e:  # rosbags raises its own types for missing or broken bags
        raise InputError(f"{path}: not a readable ROS 2 bag: {e}") from e
    try:
        topics = sorted({c.topic for c in reader.connections if c.msgtype == msgtype})
        if topic is None:
            if len(topics) != 1:
                raise InputError(f"{path}: {len(topics)} topics carry {msgtype} ({', '.join(topics) or 'none'}); name one with topic=")
            topic = topics[0]
        elif topic not in topics:
            raise InputError(f"{path}: topic '{topic}' carries no {msgtype}; topics with it: {', '.join(topics) or 'none'}")
        connections = [c for c in reader.connections if c.topic == topic]
        t, q, qd, tau = [], [], [], []
        for k, (connection, _, raw) in enumerate(reader.messages(connections=connections)):
            if k >= MAX_MESSAGES:
                raise InputError(f"{path}: topic '{topic}' has more than {MAX_MESSAGES} messages; split the bag")
            msg: Any = typestore.deserialize_cdr(raw, connection.msgtype)
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            index = {n: i for i, n in enumerate(msg.name)}
            missing = [j for j in joints if j not in index]
            if missing:
                raise InputError(f"{path}: message {k} on '{topic}' (t = {stamp:.6f} s) has no joint {', '.join(missing)}; it names {', '.join(msg.name)}")
            pick = [index[j] for j in joints]
            for field, values in (("position", msg.position), ("effort", msg.effort)):
                if len(values) != len(msg.name):
                    raise InputError(f"{path}: message {k} on '{topic}' (t = {stamp:.6f} s) has {len(values)} {field} values for {len(msg.name)} joints")
            t.append(stamp)
            q.append(np.asarray(msg.position, dtype=np.float64)[pick])
            tau.append(np.asarray(msg.effort, dtype=np.float64)[pick])
            has_velocity = len(msg.velocity) == len(msg.name)
            qd.append(np.asarray(msg.velocity, dtype=np.float64)[pick] if has_velocity else None)
    finally:
        reader.close()
    if not t:
        raise InputError(f"{path}: topic '{topic}' holds no message")
    t_arr = np.asarray(t) - t[0]
    speeds = [v for v in qd if v is not None]
    use_velocity = velocities and len(speeds) == len(qd)
    # the recording checks the rest: finite values, increasing times, shapes
    return Recording(t_arr, np.vstack(q), np.vstack(tau), np.vstack(speeds) if use_velocity else None, name=name)
