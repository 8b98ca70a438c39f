"""perturbid_rs: robot manipulator dynamics identification about an operating point.

Kinsheel & Taha (ICARCV 2010) identify the local dynamic model
``tau - T* = D* dqdd + H* dqd + G* dq`` at an operating point from perturbed passes through it;
the classical direct method (Swevers et al. 2007) is implemented beside it. The work happens in
Rust; this package is a thin layer over the extension module ``perturbid_rs._core``.

Quick start::

    import numpy as np
    import perturbid_rs
    robot = perturbid_rs.robots.a465()          # the paper's CRS A465
    tau = robot.rnea(q, qd, qdd)                 # (n,) or (k, n)
    lin = robot.linearize(q, qd, qdd)            # lin.torque, lin.D, lin.H, lin.G, lin.G_static
"""

from ._core import (
    FileError,
    InputError,
    Linearization,
    ModelError,
    NumericalError,
    PerturbidError,
    Robot,
    __version__,
)
from . import robots

__all__ = [
    "FileError",
    "InputError",
    "Linearization",
    "ModelError",
    "NumericalError",
    "PerturbidError",
    "Robot",
    "__version__",
    "robots",
]
