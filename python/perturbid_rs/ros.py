"""ROS bags of ``sensor_msgs/JointState`` as recordings (the ``rosbags`` package, an optional
dependency: ``pip install 'perturbid_rs[ros]'``; no ROS installation needed).

Both ROS 2 bags (a folder with ``metadata.yaml``, SQLite or MCAP storage) and ROS 1 bags (one
``.bag`` file, or the files of a split recording) are read. A JointState message carries joint
names with positions, velocities and efforts in any order and any subset; each message is
matched by name to the robot's joints. Messages on the topic that name none of the joints (a
gripper or another arm publishing on the same topic) are passed over; a message that names
some but not all of them, names a joint twice, holds a non-finite value, or is not stamped
after the message before it is refused with its index and time, never skipped.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

from ._core import InputError, Recording

__all__ = ["read_joint_states"]

#: At most this many messages are read (about 3 hours at 1 kHz).
MAX_MESSAGES = 10_000_000

_MSGTYPE = "sensor_msgs/msg/JointState"

BagPath = Union[str, "PathLike[str]"]


def _bag_paths(path: Union[BagPath, Sequence[BagPath]]) -> list[Path]:
    """The paths rosbags' AnyReader takes: one ROS 2 bag folder, or ROS 1 ``.bag`` files."""
    paths = [Path(path)] if isinstance(path, (str, PathLike)) else [Path(p) for p in path]
    if not paths:
        raise InputError("read_joint_states: no bag given")
    # a ROS 2 bag may be named by its metadata.yaml; rosbags wants the folder
    paths = [p.parent if p.name == "metadata.yaml" and p.is_file() else p for p in paths]
    ros1 = [p.suffix == ".bag" for p in paths]
    if len(paths) > 1 and not all(ros1):
        shown = ", ".join(str(p) for p, one in zip(paths, ros1) if not one)
        raise InputError(f"read_joint_states: several bags are read only as the .bag files of one ROS 1 recording; {shown} is not one")
    return paths


def read_joint_states(
    path: Union[BagPath, Sequence[BagPath]],
    joints: Sequence[str],
    topic: Optional[str] = None,
    *,
    name: str = "rosbag",
    experiment: Optional[str] = None,
    velocities: bool = True,
    stamp: str = "header",
    progress: Optional[Callable[[int, int], None]] = None,
) -> Recording:
    """The recording of ``joints`` (the robot's joint names, e.g. ``robot.joint_names``) from
    the ``sensor_msgs/JointState`` messages of a ROS bag: a ROS 2 bag's folder (or its
    ``metadata.yaml``), a ROS 1 ``.bag`` file, or a list of the ``.bag`` files of one split ROS 1
    recording. ``topic`` selects the topic (default: the only JointState topic).

    Returns a Recording (``name``; ``experiment`` says which experiment of a plan it is a run
    of, as ``Recording``'s): ``t`` (s, (m,)) relative to the first message read, from each
    message header's stamp (``stamp="header"``, the default: when the sensor was read) or from
    the time the bag received it (``stamp="receive"``, for publishers that leave the header's
    stamp unset, at the cost of the transport's jitter); ``q`` (rad or m, (m, n)) from the
    positions; ``tau`` (N m or N, (m, n)) from the efforts; ``qd`` (rad/s or m/s) when
    ``velocities`` and every message read has them. Times are differenced in whole nanoseconds,
    so an epoch stamp loses nothing.

    ``progress(read, total)``, when given, is called every 10,000 messages and at the end with
    the messages read so far and the topic's count (a bag of hours takes minutes).

    Raises InputError naming the bag, topic, message and joint of any problem; ImportError
    naming the extra without rosbags.
    """
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError as e:
        raise ImportError("reading ROS bags needs rosbags: pip install 'perturbid_rs[ros]'") from e
    if stamp not in ("header", "receive"):
        raise InputError(f"read_joint_states: stamp must be 'header' or 'receive', not {stamp!r}")
    joints = list(joints)
    if not joints:
        raise InputError("read_joint_states: no joint names given")
    if not all(isinstance(j, str) for j in joints):
        raise InputError(f"read_joint_states: joint names must be strings, got {joints!r}")
    twice = sorted({j for j in joints if joints.count(j) > 1})
    if twice:
        raise InputError(f"read_joint_states: joint {', '.join(twice)} named more than once")
    paths = _bag_paths(path)
    where = ", ".join(str(p) for p in paths)
    try:
        # ROS 1 bags and most ROS 2 bags carry their message definitions; older ROS 2 bags
        # without them are read with Humble's (JointState has not changed since)
        reader = AnyReader(paths, default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as e:  # rosbags raises its own types (and OSError) for missing or broken bags
        raise InputError(f"{where}: not a readable ROS bag: {e}") from e
    try:
        topics = sorted({c.topic for c in reader.connections if c.msgtype == _MSGTYPE})
        if topic is None:
            if len(topics) != 1:
                raise InputError(f"{where}: {len(topics)} topics carry {_MSGTYPE} ({', '.join(topics) or 'none'}); name one with topic=")
            topic = topics[0]
        elif topic not in topics:
            raise InputError(f"{where}: topic '{topic}' carries no {_MSGTYPE}; topics with it: {', '.join(topics) or 'none'}")
        connections = [c for c in reader.connections if c.topic == topic and c.msgtype == _MSGTYPE]
        counted = sum(int(c.msgcount) for c in connections)
        if counted > MAX_MESSAGES:
            raise InputError(f"{where}: topic '{topic}' has {counted} messages, more than {MAX_MESSAGES}; split the bag")
        return _read(reader, connections, joints, topic, where, name, experiment, velocities, stamp, counted, progress)
    finally:
        reader.close()


def _read(reader: Any, connections: list[Any], joints: list[str], topic: str, where: str, name: str,
          experiment: Optional[str], velocities: bool, stamp: str, counted: int,
          progress: Optional[Callable[[int, int], None]] = None) -> Recording:
    """The messages of ``connections`` read into preallocated arrays and checked one by one."""
    n = len(joints)
    ns = np.empty(counted, dtype=np.int64)
    q = np.empty((counted, n))
    qd = np.empty((counted, n))
    tau = np.empty((counted, n))
    all_velocities = True
    seen: set[str] = set()
    passed_over = 0
    m = 0  # messages kept
    previous = None  # (index, stamp in ns) of the last message kept
    for k, (connection, received, raw) in enumerate(reader.messages(connections=connections)):
        if k >= counted:
            raise InputError(f"{where}: topic '{topic}' holds more messages than the bag's index says ({counted})")
        if progress is not None and k % 10_000 == 0:
            progress(k, counted)
        msg: Any = reader.deserialize(raw, connection.msgtype)
        header = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        at = header if stamp == "header" else received
        said = f"{where}: message {k} on '{topic}' (t = {at * 1e-9:.6f} s)"
        names = list(msg.name)
        index = {j: i for i, j in enumerate(names)}
        if len(index) != len(names):
            twice = sorted({j for j in names if names.count(j) > 1})
            raise InputError(f"{said} names joint {', '.join(twice)} more than once")
        missing = [j for j in joints if j not in index]
        if len(missing) == n:
            passed_over += 1  # another publisher's joints on the same topic
            seen.update(names)
            continue
        if missing:
            raise InputError(f"{said} has no joint {', '.join(missing)}; it names {', '.join(names)}")
        for field, values in (("position", msg.position), ("effort", msg.effort)):
            if len(values) != len(names):
                raise InputError(f"{said} has {len(values)} {field} values for {len(names)} joints")
        if len(msg.velocity) not in (0, len(names)):
            raise InputError(f"{said} has {len(msg.velocity)} velocity values for {len(names)} joints (none or one per joint)")
        if stamp == "header" and header == 0:
            raise InputError(f"{said} has no header stamp (0): its publisher does not set it; stamp='receive' reads the times the bag received the messages")
        if previous is not None and at <= previous[1]:
            late = f"{(previous[1] - at) * 1e-9:.6f} s before" if at < previous[1] else "at the same time as"
            hint = "" if stamp == "receive" else "; stamp='receive' reads the times the bag received the messages"
            raise InputError(f"{said} is stamped {late} message {previous[0]}: its times must increase{hint}")
        previous = (k, at)
        pick = [index[j] for j in joints]
        ns[m] = at
        q[m] = np.asarray(msg.position, dtype=np.float64)[pick]
        tau[m] = np.asarray(msg.effort, dtype=np.float64)[pick]
        if len(msg.velocity):
            qd[m] = np.asarray(msg.velocity, dtype=np.float64)[pick]
        else:
            all_velocities = False
        for field, row in (("position", q[m]), ("effort", tau[m]), ("velocity", qd[m] if len(msg.velocity) else None)):
            if row is not None and not np.isfinite(row).all():
                j = int(np.argmin(np.isfinite(row)))
                raise InputError(f"{said} has a non-finite {field} ({row[j]}) for joint {joints[j]}")
        m += 1
    if progress is not None:
        progress(counted, counted)
    if m == 0:
        if passed_over:
            raise InputError(f"{where}: no message on '{topic}' names joint {', '.join(joints)}; its messages name {', '.join(sorted(seen))}")
        raise InputError(f"{where}: topic '{topic}' holds no message")
    t = (ns[:m] - ns[0]) * 1e-9
    use_velocity = velocities and all_velocities
    # the recording checks the rest: finite values, shapes
    return Recording(t, q[:m], tau[:m], qd[:m] if use_velocity else None, name=name, experiment=experiment)
