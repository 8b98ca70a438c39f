"""The ``perturbid`` console script: the Rust command line, run through the extension module.
Two commands need Python packages and run from here: ``perturbid study STUDY.toml --scheduler
ADDRESS`` runs the study on a Dask cluster, and ``perturbid ros BAG --robot ROBOT --out log.csv``
writes a ROS bag's JointState messages as a recording CSV (rosbags); every other command is the
Rust one."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any, Callable, Optional

from ._core import cli


#: The commands run here, for ``perturbid --help``.
PYTHON_COMMANDS = """
Commands of the Python package:
  ros              Write the sensor_msgs/JointState messages of a ROS bag (ROS 1 or ROS 2) as a recording CSV for `identify`, `split`, `identify-direct` or `validate` (needs rosbags: pip install 'perturbid_rs[ros]')"""


def main() -> None:
    sys.stdout.flush()
    sys.exit(run(sys.argv[1:]))


def run(argv: list[str]) -> int:
    """The command line ``perturbid ARGV``: the commands that need Python here, the rest in
    Rust. Returns the exit status."""
    if argv[:1] == ["study"] and any(a == "--scheduler" or a.startswith("--scheduler=") for a in argv):
        return study_on_dask(argv[1:])
    if argv[:1] == ["ros"]:
        return ros_to_csv(argv[1:])
    status = cli(["perturbid", *argv])
    if argv in (["-h"], ["--help"], ["help"]):
        print(PYTHON_COMMANDS)
    return status


def _robot(name: str, lock: list[str]) -> Any:
    """The robot of ``--robot`` (a URDF file, or a built-in name) with the joints of ``--lock``
    (JOINT=VALUE) held still, as the Rust commands load it."""
    from . import InputError, Robot
    from ._core import a465_urdf

    held: dict[str, float] = {}
    for item in lock:
        joint, sep, value = item.partition("=")
        try:
            v = float(value)
        except ValueError:
            v = float("nan")
        if not sep or not joint.strip() or not math.isfinite(v):
            raise InputError(f"--lock '{item}': expected JOINT=VALUE with a finite value (rad or m), e.g. panda_finger_joint1=0.02")
        held[joint.strip()] = v
    if Path(name).is_file():
        return Robot.from_urdf(name, lock=held or None)
    if held and (name == "a465" or name.startswith("a465:")):
        return Robot.from_urdf_string(a465_urdf(name.partition(":")[2] or "kinsheel2010"), lock=held)
    return Robot.builtin(name)


def _progress_line(what: str) -> Optional[Callable[[int, int], None]]:
    """A progress line on stderr, as the Rust commands draw it: only on a terminal."""
    if not sys.stderr.isatty():
        return None

    def show(done: int, total: int) -> None:
        print(f"\r{what}: {done:,} of {total:,} ({100 * done // max(total, 1)} %)", end="", file=sys.stderr, flush=True)

    return show


def _clear_line() -> None:
    if sys.stderr.isatty():
        print("\r\033[K", end="", file=sys.stderr, flush=True)


def ros_to_csv(args: list[str]) -> int:
    """``perturbid ros BAG [BAG ...] --robot ROBOT [--lock JOINT=VALUE] [--topic TOPIC]
    [--stamp header|receive] [--no-velocities] [--out log.csv]``. Returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="perturbid ros",
        description="Write the sensor_msgs/JointState messages of a ROS bag as a recording CSV (t, q1..qN, [qd1..qN,] tau1..tauN; the robot's joints in its order, t in s from the first message read) for identify, split, identify-direct or validate. A log of a whole session goes to `perturbid split` next.",
    )
    parser.add_argument("bag", nargs="+", help="a ROS 2 bag's folder (or its metadata.yaml), a ROS 1 .bag file, or the .bag files of one split ROS 1 recording")
    parser.add_argument("--robot", required=True, help="the robot whose joints are read: a URDF file or a built-in robot (a465, a465:physical)")
    parser.add_argument("--lock", action="append", default=[], metavar="JOINT=VALUE", help="a joint held still and left out, as for the other commands (repeat)")
    parser.add_argument("--topic", help="the JointState topic (default: the only one in the bag)")
    parser.add_argument("--stamp", choices=["header", "receive"], default="header", help="times from each message header's stamp (default) or from when the bag received it, for publishers that leave the stamp unset")
    parser.add_argument("--no-velocities", action="store_true", help="leave the messages' velocities out (they are written when every message has them)")
    parser.add_argument("--out", default="log.csv", help="the recording CSV (default log.csv), written whole or not at all")
    a = parser.parse_args(args)
    from . import PerturbidError

    out = Path(a.out)
    same = [b for b in a.bag if Path(b).exists() and out.exists() and out.resolve() == Path(b).resolve()]
    if same or (out.exists() and out.is_dir()):
        what = f"is the bag {same[0]}" if same else "is a folder"
        print(f"perturbid: --out {a.out} {what}: name the CSV file to write", file=sys.stderr)
        return 1
    try:
        from .ros import read_joint_states

        robot = _robot(a.robot, a.lock)
        rec = read_joint_states(a.bag if len(a.bag) > 1 else a.bag[0], robot.joint_names, a.topic,
                                name=a.bag[0], velocities=not a.no_velocities, stamp=a.stamp,
                                progress=_progress_line("reading messages"))
        rec.save(str(out))
    except (PerturbidError, ImportError, OSError) as e:
        _clear_line()
        print(f"perturbid: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        _clear_line()
        print("perturbid: interrupted; nothing written", file=sys.stderr)
        return 130
    _clear_line()
    velocities = ", with velocities" if rec.qd is not None else ""
    print(f"{len(rec.t)} samples of {robot.n} joints ({', '.join(robot.joint_names)}), {rec.t[-1]:.3f} s{velocities} -> {out}")
    return 0


def study_on_dask(args: list[str]) -> int:
    """``perturbid study STUDY.toml --scheduler ADDRESS [--out DIR]``: the cases on the Dask
    cluster at ADDRESS, the journal and the report here. Returns the exit status."""
    parser = argparse.ArgumentParser(prog="perturbid study", description=study_on_dask.__doc__)
    parser.add_argument("study")
    parser.add_argument("--out", default="study")
    parser.add_argument("--scheduler", required=True)
    a = parser.parse_args(args)
    try:
        from dask.distributed import Client
    except ImportError:
        print("perturbid: --scheduler needs dask.distributed: pip install 'perturbid_rs[dask]'", file=sys.stderr)
        return 1
    from . import PerturbidError
    from ._study import study

    try:
        with Client(a.scheduler, timeout="10s") as client:
            result = study(a.study, a.out, client=client)
    except PerturbidError as e:
        print(f"perturbid: {e}", file=sys.stderr)
        return 1
    except (OSError, TimeoutError) as e:
        print(f"perturbid: cannot reach the Dask scheduler at {a.scheduler}: {e}", file=sys.stderr)
        return 1
    print(result.summary)
    print(f"wrote results.csv, summary.csv, summary.md, error_vs_distance.svg to {a.out}")
    return 0
