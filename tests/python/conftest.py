"""Helpers for comparing perturbid_rs with Pinocchio (the independent oracle)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import pinocchio as pin  # the oracle: a missing oracle is a failure, not a skip

import perturbid_rs as pr  # noqa: E402


def erd_dir() -> Path:
    """The robots folder of the example-robot-data package (installed under cmeel.prefix)."""
    import sysconfig

    path = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
    if not path.is_dir():
        pytest.fail(f"example-robot-data is not installed (no {path}); pip install example-robot-data")
    return path


@dataclass
class Pair:
    """The same robot in perturbid_rs and in Pinocchio, with the coordinate maps between them."""

    ours: pr.Robot
    model: "pin.Model"

    def __post_init__(self):
        self.data = self.model.createData()
        joints = [self.model.joints[self.model.getJointId(n)] for n in self.ours.joint_names]
        self.idx_v = np.array([j.idx_v for j in joints])
        self.idx_q = [j.idx_q for j in joints]
        self.nq = [j.nq for j in joints]
        assert self.model.nv == self.ours.n, (self.model.nv, self.ours.n)

    def q(self, q):
        out = pin.neutral(self.model)
        for i, (iq, nq) in enumerate(zip(self.idx_q, self.nq)):
            if nq == 2:  # continuous joint: (cos, sin)
                out[iq : iq + 2] = [np.cos(q[i]), np.sin(q[i])]
            else:
                out[iq] = q[i]
        return out

    def v(self, v):
        out = np.zeros(self.model.nv)
        out[self.idx_v] = v
        return out

    def vec(self, x):
        return np.asarray(x)[self.idx_v]

    def mat(self, m):
        m = np.asarray(m)
        return m[np.ix_(self.idx_v, self.idx_v)]

    def random_state(self, rng, scale=1.0):
        n = self.ours.n
        lo = np.where(np.isfinite(self.ours.lower), self.ours.lower, -np.pi)
        hi = np.where(np.isfinite(self.ours.upper), self.ours.upper, np.pi)
        q = rng.uniform(lo, hi)
        return q, rng.uniform(-scale, scale, n), rng.uniform(-scale, scale, n)


def relerr(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return np.abs(a - b).max() / max(1.0, np.abs(b).max())


def pair_from_urdf(path, lock=None, pin_lock=None, mimic=False) -> Pair:
    """Loads `path` in both libraries. `lock` holds joints in ours; Pinocchio's reduced model
    holds `pin_lock` (default: `lock`), which must also name the mimic followers of locked
    joints (Pinocchio's non-mimic model treats them as independent)."""
    ours = pr.Robot.from_urdf(path, lock=lock)
    model = pin.buildModelFromUrdf(str(path), mimic=mimic) if mimic else pin.buildModelFromUrdf(str(path))
    pin_lock = pin_lock or lock
    if pin_lock:
        full = model
        qref = pin.neutral(full)
        for name, value in pin_lock.items():
            qref[full.joints[full.getJointId(name)].idx_q] = value
        model = pin.buildReducedModel(full, [full.getJointId(n) for n in pin_lock], qref)
    return Pair(ours, model)


def pair_from_text(text, **kw) -> Pair:
    ours = pr.Robot.from_urdf_string(text, **kw)
    model = pin.buildModelFromXML(text)
    # URDF has no armature element: Pinocchio takes ours (joints in the same order here)
    model.armature = np.asarray(ours.armature)
    return Pair(ours, model)
