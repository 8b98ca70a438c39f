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

    # the paper's method: plan, rehearse (or record on the robot), identify
    op = perturbid_rs.OperatingPoint(q, qd, qdd)
    plan = perturbid_rs.plan_experiments(robot, op, design="orthogonal", seed=1)
    recordings = perturbid_rs.simulate(robot, plan, torque_noise=0.05, seed=2)
    model = perturbid_rs.identify_local(plan, recordings)   # model.D, model.stderr["D"], ...

    # the direct method: excitation, base parameters, globally linearised model
    design = perturbid_rs.design_excitation(robot, harmonics=5, base_frequency=0.1, seed=0)
    fit = perturbid_rs.identify_base_parameters(robot, q, qd, qdd, tau)   # (k, n) samples
"""

from ._core import (
    BaseParameterModel,
    ConsistentFit,
    ExcitationDesign,
    Experiment,
    FileError,
    FourierTrajectory,
    GlobalLinearModel,
    InputError,
    InternalError,
    Linearization,
    LocalModel,
    ModelError,
    NumericalError,
    OperatingPoint,
    PayloadFit,
    PerturbidError,
    PerturbidWarning,
    Plan,
    Recording,
    Robot,
    TrueRobot,
    Validation,
    design_excitation,
    identify_base_parameters,
    identify_consistent_parameters,
    identify_drive_gains,
    identify_global_linear,
    identify_local,
    identify_parameters_from_local,
    identify_payload,
    suggest_operating_points,
    plan_experiments,
    preprocess,
    simd_isa,
    simulate,
    validate,
    __version__,
)
from . import robots
from ._study import StudyResult, study

__all__ = [
    "BaseParameterModel",
    "ConsistentFit",
    "ExcitationDesign",
    "Experiment",
    "FileError",
    "FourierTrajectory",
    "GlobalLinearModel",
    "InputError",
    "InternalError",
    "Linearization",
    "LocalModel",
    "ModelError",
    "NumericalError",
    "OperatingPoint",
    "PayloadFit",
    "PerturbidError",
    "PerturbidWarning",
    "Plan",
    "Recording",
    "Robot",
    "TrueRobot",
    "Validation",
    "design_excitation",
    "identify_base_parameters",
    "identify_consistent_parameters",
    "identify_drive_gains",
    "identify_global_linear",
    "identify_local",
    "identify_parameters_from_local",
    "identify_payload",
    "suggest_operating_points",
    "plan_experiments",
    "preprocess",
    "robots",
    "simd_isa",
    "simulate",
    "study",
    "StudyResult",
    "validate",
    "__version__",
]
