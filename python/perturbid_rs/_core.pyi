"""Type stubs of the extension module perturbid_rs._core (implemented in Rust)."""

from os import PathLike
from pathlib import Path
from typing import Any, Literal, overload, Mapping, Optional, Sequence, Union, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

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
    "__version__",
    "a465_urdf",
    "cli",
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
    "simd_isa",
    "simulate",
    "study_case",
    "study_finish",
    "study_len",
    "study_pending",
    "study_record",
    "study_resolve",
    "study_resolve_file",
    "study_run",
    "validate",
]

class PerturbidError(Exception):
    """Base class of all perturbid_rs errors."""

class ModelError(PerturbidError):
    """A URDF or robot model that cannot be built."""

class InputError(PerturbidError, ValueError):
    """An argument, recording or document of the wrong shape, non-finite, or out of range."""

class NumericalError(PerturbidError, ArithmeticError):
    """A numerical failure."""

class FileError(PerturbidError, OSError):
    """A file that cannot be read or written."""

class PerturbidWarning(UserWarning):
    """A result the library computed but cannot fully vouch for (also in its diagnostics)."""

class InternalError(PerturbidError, RuntimeError):
    """A bug of perturbid_rs caught at its boundary: please report it."""

@final
class Linearization:
    """The linearisation ``tau - T* ~= D dqdd + H dqd + G dq`` at an operating point.

    Shapes for one operating point (a batch of k adds a leading axis k); N m or N; matrices
    with row = torque, column = joint.
    """

    @property
    def torque(self) -> NDArray[np.float64]:
        """T* = tau(q*, qd*, qdd*), shape (n,)."""
    @property
    def D(self) -> NDArray[np.float64]:
        """d tau / d qdd = M(q*), shape (n, n)."""
    @property
    def H(self) -> NDArray[np.float64]:
        """d tau / d qd at the operating point, shape (n, n)."""
    @property
    def G(self) -> NDArray[np.float64]:
        """d tau / d q at the operating point, shape (n, n)."""
    @property
    def G_static(self) -> NDArray[np.float64]:
        """d tau / d q at rest at q* (gravity stiffness dg/dq), shape (n, n)."""

@final
class Robot:
    """A robot model with its dynamics algorithms.

    Arrays: one sample as shape (n,), a batch of k samples as (k, n); results shaped to match.
    Units: rad, rad/s, rad/s^2, N m (revolute); m, m/s, m/s^2, N (prismatic). Gravity 9.81
    m/s^2 along -z of the base frame.
    """

    @staticmethod
    def from_urdf(
        path: Union[str, PathLike[str]],
        lock: Optional[Mapping[str, float]] = None,
        check_triangle_inequality: bool = True,
    ) -> "Robot":
        """Loads a URDF file; ``lock`` holds the named joints at the given positions."""
    @staticmethod
    def from_urdf_string(
        text: str,
        lock: Optional[Mapping[str, float]] = None,
        check_triangle_inequality: bool = True,
    ) -> "Robot":
        """Loads URDF text; see ``from_urdf``."""
    @staticmethod
    def builtin(name: str) -> "Robot":
        """A built-in robot: "a465", "a465:kinsheel2010", "a465:physical"."""
    @property
    def name(self) -> str: ...
    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower position limits, shape (n,)."""
    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper position limits, shape (n,)."""
    @property
    def velocity_limit(self) -> NDArray[np.float64]:
        """Speed limits, shape (n,); inf where not given."""
    @property
    def effort_limit(self) -> NDArray[np.float64]:
        """Effort limits, shape (n,); inf where not given."""
    @property
    def acceleration_limit(self) -> NDArray[np.float64]:
        """Acceleration limits (URDF 1.2), shape (n,); inf where not given."""
    @property
    def armature(self) -> NDArray[np.float64]:
        """Reflected rotor inertia per joint (kg m^2 or kg), shape (n,): adds armature * qdd to tau."""
    @property
    def damping(self) -> NDArray[np.float64]:
        """Viscous friction coefficients from <dynamics damping>, shape (n,)."""
    @property
    def friction(self) -> NDArray[np.float64]:
        """Coulomb friction from <dynamics friction>, shape (n,)."""
    @property
    def mass(self) -> float:
        """Total moving mass (kg)."""
    def rnea(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Inverse dynamics tau, shape (n,) or (k, n). With `out` (float64, C-contiguous,
        writeable, exactly that shape) the result is written there and `out` returned."""
    def gravity(self, q: ArrayLike, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Gravity torque g(q), shape (n,) or (k, n); `out` as for `rnea`."""
    def bias(self, q: ArrayLike, qd: ArrayLike, gravity: bool = True, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Bias torque c(q, qd) + g(q), shape (n,) or (k, n); `out` as for `rnea`."""
    def mass_matrix(self, q: ArrayLike, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Mass matrix M(q), shape (n, n) or (k, n, n); `out` as for `rnea`."""
    def regressor(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True, friction: Union[str, Sequence[str], None] = None, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Joint-torque regressor, shape (n, 10 b) or (k, n, 10 b): regressor @ parameters == rnea; `out` as for `rnea`."""
    def rnea_derivatives(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True, out: Optional[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]] = None) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(tau, dtau_dq, dtau_dv, M): inverse dynamics and its analytic derivatives, shapes (n,) and (n, n) or with a leading k; `out` a tuple of four such arrays."""
    def physical_consistency(self, theta: Optional[ArrayLike] = None, friction: Union[str, Sequence[str], None] = None) -> tuple[bool, list[dict[str, Any]], list[tuple[str, float]]]:
        """Per-body pseudo-inertia check of a full parameter vector (default: the model's)."""
    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """The torques its own parameters give, as validate compares them with a log's: rnea
        (gravity, armature) plus each joint's URDF friction damping * qd + friction * sign(qd);
        shape (n,) or (k, n)."""
    def to_urdf(self, path: Union[str, PathLike[str], None] = None, *, payload: Optional[Mapping[str, Any]] = None, payload_link: str = "payload", note: str = "") -> str:
        """The robot as URDF text (also written to `path`, atomically): the file it was loaded
        from with every changed link inertial and joint <dynamics damping friction armature>
        written anew, the rest kept; `payload` (identify_payload's dict) attached as a link
        `payload_link` fixed to its link. Read back and checked before it is returned."""
    @property
    def parameters(self) -> NDArray[np.float64]:
        """The model's inertial parameters (10 per moving body, Pinocchio's order), shape (10 b,)."""
    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, gravity: bool = True, out: Optional[NDArray[np.float64]] = None) -> NDArray[np.float64]:
        """Accelerations qdd, shape (n,) or (k, n)."""
    def linearize(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True, out: Optional[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]] = None) -> Linearization:
        """The local model at the operating point (analytic derivatives)."""

def simd_isa() -> str:
    """The instruction set the batched kernels run on here: "avx512" (8 samples side by side),
    "avx2+fma" (4) or "scalar" (one at a time), detected at import: the widest the processor
    has, no wider than the environment variable PERTURBID_SIMD names when it is set."""

def a465_urdf(variant: str = "kinsheel2010") -> str:
    """The URDF text of a built-in A465 variant."""

# --- the paper's method -------------------------------------------------------------------

@final
class OperatingPoint:
    """P = (q*, qd*, qdd*): rad, rad/s, rad/s^2 (m for prismatic joints), each shape (n,)."""
    def __new__(cls, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> "OperatingPoint": ...
    @property
    def q(self) -> NDArray[np.float64]: ...
    @property
    def qd(self) -> NDArray[np.float64]: ...
    @property
    def qdd(self) -> NDArray[np.float64]: ...
    @property
    def n(self) -> int: ...

@final
class Experiment:
    """One experiment of a plan: a rest-to-rest trajectory through K crossings."""
    @property
    def kind(self) -> str:
        """'nominal', 'G_static', 'G', 'H' or 'D'."""
    @property
    def t(self) -> NDArray[np.float64]:
        """Sample times (s), shape (m,)."""
    @property
    def q(self) -> NDArray[np.float64]:
        """Positions, shape (m, n)."""
    @property
    def qd(self) -> NDArray[np.float64]: ...
    @property
    def qdd(self) -> NDArray[np.float64]: ...
    @property
    def crossing_times(self) -> NDArray[np.float64]:
        """Times (s) of the K crossings, shape (K,)."""
    @property
    def reference_time(self) -> Optional[float]:
        """G_static only: time of the reference rest posture at q*."""
    @property
    def deltas(self) -> NDArray[np.float64]:
        """Planned perturbations of the perturbed variable, shape (K, n)."""
    @property
    def window(self) -> float:
        """Half-width (s) of the exact quadratic window around each crossing."""
    @property
    def duration(self) -> float: ...
    @property
    def cond(self) -> Optional[float]:
        """cond(X) of the perturbations, each joint's column scaled to unit norm (1 for an orthogonal design; the planner warns above 30); None for the nominal experiment."""

@final
class Plan:
    """The experiments at an operating point for one robot."""
    @property
    def op(self) -> OperatingPoint: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def rate(self) -> float: ...
    @property
    def robot(self) -> str: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def design(self) -> str: ...
    @property
    def experiments(self) -> list[Experiment]: ...
    def refine(self, recordings: list[Recording], robot: Optional[Robot] = None) -> Plan:
        """The next round's plan: each experiment's trajectory commanded off its crossings by
        what the recordings missed them by (commanded += planned - measured), its crossings
        and their times kept. With robot, checked against its limits."""
    def experiment(self, kind: str) -> Experiment: ...
    def __len__(self) -> int: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> "Plan": ...
    def save(self, folder: Union[str, PathLike[str]]) -> list[Path]:
        """Writes <experiment>.csv (t, q, qd, qdd for the controller) and plan.json into
        ``folder``, all or none, as ``perturbid plan``; returns the paths written."""
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "Plan":
        """Reads and checks a plan.json."""
    def split_session(self, log: "Recording", margin: float = 0.2) -> list["Recording"]:
        """One log of the whole session (the experiments run one after the other, in order)
        split into one Recording per experiment on the plan's clock; an experiment that ran
        twice gets a PerturbidWarning naming both stretches."""

@final
class Recording:
    """What a robot logs: t (s, (m,)), q (rad, (m, n)), tau (N m, (m, n)), optional qd, qdd."""
    def __new__(
        cls,
        t: ArrayLike,
        q: ArrayLike,
        tau: ArrayLike,
        qd: Optional[ArrayLike] = None,
        qdd: Optional[ArrayLike] = None,
        name: str = "recording",
        experiment: Optional[str] = None,
    ) -> "Recording": ...
    @staticmethod
    def load(
        path: Union[str, PathLike[str]],
        joints: Sequence[str],
        experiment: Optional[str] = None,
        *,
        columns: Optional[Union[Mapping[str, str], Sequence[str]]] = None,
        ignore_columns: Optional[Sequence[str]] = None,
    ) -> "Recording":
        """Reads a recording CSV (t, q1..qN, [qd, qdd,] tau1..tauN, or q_<joint>, ...) of
        the robot's ``joints``, as the command line does; named by its path. A log from
        another tool: ``columns`` reads its names as these ({"t": "timestamp*ms", "q":
        "actual_q_{i}"} or ["t=timestamp*ms", ...]), ``ignore_columns`` leaves columns out
        (names, or starts of names ending in ``*``), as ``--column`` and ``--ignore-columns``."""
    def save(self, path: Union[str, PathLike[str]]) -> None:
        """Writes the recording as CSV (atomically), read back exactly by ``load``."""
    @staticmethod
    def from_dataframe(
        frame: Any,
        joints: Sequence[str],
        name: str = "dataframe",
        experiment: Optional[str] = None,
        *,
        columns: Optional[Union[Mapping[str, str], Sequence[str]]] = None,
        ignore_columns: Optional[Sequence[str]] = None,
    ) -> "Recording":
        """A pandas DataFrame read by the CSV files' rules; ``t`` in s, datetimes or
        timedeltas, as a column or the index named ``t``; ``columns`` and ``ignore_columns``
        as for ``load`` (columns left out may hold text)."""
    def to_dataframe(self) -> Any:
        """The recording as a DataFrame with its CSV file's columns (t, q1.., tau1..)."""
    @property
    def left_out_columns(self) -> list[str]:
        """The log's columns ignore_columns left out (load, from_dataframe), in its order;
        empty for a Recording made otherwise."""
    @property
    def experiment(self) -> Optional[str]:
        """The experiment of a plan this is a run of (nominal, G_static, G, H, D), or None."""
    @property
    def name(self) -> str: ...
    @property
    def n(self) -> int: ...
    @property
    def t(self) -> NDArray[np.float64]: ...
    @property
    def q(self) -> NDArray[np.float64]: ...
    @property
    def tau(self) -> NDArray[np.float64]: ...
    @property
    def qd(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def qdd(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def coulomb(self) -> Optional[NDArray[np.float64]]:
        """The Coulomb friction term's column (k, n): sign(qd) filtered as tau was, for a
        direct fit of these torques (brought by the recording given whole, or coulomb=); None
        where preprocess did not filter."""
    @property
    def glitches(self) -> list[dict[str, Any]]:
        """Samples of the log this was preprocessed from taken for glitches and replaced first
        (signal, joint, sample, time, value, noise_levels, replaced_by, repeats_previous,
        held: the length of the held reading it belongs to, or None)."""
    @property
    def dropouts(self) -> list[dict[str, Any]]:
        """Runs of rows of the log this was preprocessed from that were removed: dropouts (every
        joint of a signal read exactly 0 while the robot moved) and frozen readings (one joint's
        column held one value for more than 10 samples while it moved, then jumped back):
        signal, first_sample, samples, from, to; a frozen reading's also joint (0-based), value
        (the value held), noise_levels (how far its end jumped; None beyond any scale or at
        the end) and to_end (True where it lasts to the end of its stretch of the log)."""
    @property
    def position_rounding(self) -> list[dict[str, Any]]:
        """Per joint whose logged positions lie on a grid and whose velocity was derived from
        them, the noise their rounding left in the preprocessed qd and qdd: joint (0-based),
        step (rad or m), qd_ratio, qdd_ratio (RMS of the noise over RMS of the signal;
        preprocess warns from 0.1)."""
    @property
    def period_average(self) -> Optional[dict[str, Any]]:
        """What averaging over the excitation's periods found: period, start (s), periods,
        harmonics, torque_harmonics, samples, per joint position_noise, velocity_noise,
        acceleration_noise, torque_noise (one period's), averaged_torque_noise, position_beyond,
        torque_drift (F ratios of a trend over the periods, beyond 3 a drift; None unjudged),
        and left_out (dicts period, t0, t1, reason); None where not averaged."""
    @property
    def stamp_jitter(self) -> Optional[dict[str, Any]]:
        """The time stamps of the log this was preprocessed from, found jittering while its
        samples were taken on a regular clock: interval (median, s), scatter (s), joint
        (0-based), rougher (its positions' distance from their neighbours' line against the
        stamps over that against the sample count); None where sound."""
    @property
    def held_columns(self) -> list[dict[str, Any]]:
        """Columns of the log this was preprocessed from logged at a lower rate and held on its
        grid, read again at their values' arrivals first: signal, joint (0-based), repeated
        (share of samples repeating the one before where the joint moves), held_for (samples)."""
    @property
    def position_wraps(self) -> list[dict[str, Any]]:
        """Steps of whole turns in the positions of the log this was preprocessed from (a joint
        angle logged within one turn that a continuous joint passes), taken back out first:
        joint (0-based), sample (the first after the step), time (s), turns (added from there on)."""
    @property
    def torque_saturation(self) -> list[dict[str, Any]]:
        """The log's torques that read clipped (preprocess warns): joint (0-based), level
        (N m), upper, runs, samples, longest, first_at (s), beyond (N m)."""
    def __len__(self) -> int: ...
    def __getitem__(self, key: slice, /) -> Recording:
        """rec[a:b]: samples a..b (step 1, at least 2) as a Recording of their own, with the
        Coulomb column and what was found in the log; for fitting one part and validating
        on another."""
    def in_torques(self, gains: ArrayLike) -> Recording:
        """This recording of motor currents in torques: each tau column times its joint's
        gain ((n,), e.g. BaseParameterModel.drive_gains["gain"]), keeping qd, qdd, the
        Coulomb column and what was found in the log (clipping levels scaled alike)."""

@final
class LocalModel:
    """tau ~= T* + D (qdd - qdd*) + H (qd - qd*) + G (q - q*), with its uncertainty."""
    def to_dataframe(self) -> Any:
        """Tidy table (pandas): term, torque, joint, value, std; one row per entry."""
        ...
    @property
    def torque(self) -> NDArray[np.float64]: ...
    @property
    def D(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def H(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def G(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def G_static(self) -> Optional[NDArray[np.float64]]: ...
    @property
    def drive_gains(self) -> dict[str, Any] | None:
        """The drive gains its recordings of currents were put in torques by (identify
        --gains-from), else None: gain, stderr (n,); their errors are in predict_stderr's."""
    @property
    def combined(self) -> Optional[NDArray[np.float64]]:
        """The combined estimate [D H G], shape (n, 3n)."""
    @property
    def cond(self) -> dict[str, float]: ...
    @property
    def stderr(self) -> dict[str, NDArray[np.float64]]: ...
    @property
    def correlation(self) -> dict[str, NDArray[np.float64]]:
        """Per term ('D', 'H', 'G', 'G_static', 'combined'), the correlation of each row's
        entries, (n, m, m): diag(se) R diag(se) is the row's covariance."""
    @property
    def residual_rms(self) -> dict[str, NDArray[np.float64]]: ...
    @property
    def op(self) -> OperatingPoint: ...
    @property
    def planned_op(self) -> OperatingPoint: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def estimator(self) -> str: ...
    @property
    def coulomb(self) -> Optional[dict[str, Optional[float]]]:
        """Coulomb steps (N m) from the friction-aware H regression, per joint."""
    @property
    def diagnostics(self) -> dict[str, Any]:
        """offsets (experiment -> clock offset, s), reversals (list of dicts), combined,
        unperturbed_deviation, estimator_evidence (crossings, separated, combined, p_value: the
        held-out prediction errors the estimator advice rests on), unmeasured (list of dicts: experiment, joint, value in N m, for
        torques that read one value throughout), noise (list of dicts, the nominal passes'
        first, then each separated regression's: experiment, joint, samples (N m, one torque sample's noise), passes (N m, what varied from pass to pass
        beyond it, or None), step (N m, the step the torque was logged in where it is coarser
        than its noise, or None), position_step (rad, the encoder step of positions read by
        the band of half a count about them, or None)), glitches (list of dicts: experiment,
        crossing, signal ('q', 'qd', 'qdd', 'tau'), joint, sample (0-based), time (s), value,
        noise_levels (or None beyond any scale), replaced (True for an isolated glitch replaced
        by the fit of its window's other samples)), dropouts, held_readings, torque_offsets
        (list of dicts: experiment ('D', 'G', 'G_static'), joint, offset and stderr in N m:
        torques that do not return to T*, or to G-static's reference, between the experiment's
        perturbations), warnings."""
    def linearize(self, op: OperatingPoint) -> dict[str, Any]:
        """torque (n,), D, H, G (n, n) and G_static (n, n) or None at op."""
    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """Predicted torques (N m), shape (n,) or (k, n); a PerturbidWarning where states lie
        beyond the perturbations the model was identified over (reach above 1.5)."""
    def predict_stderr(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]:
        """Standard errors (N m) of predict's torques, shape (n,) or (k, n): T*'s and the
        matrices' entries' with their correlation within each row; NaN where the model holds
        an unknown standard error that the state weights. InputError for a model saved before
        the correlations were stored. Warns as predict does."""
    def reach(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> Any:
        """Per state (a float, or (k,) for a batch) the largest deviation from the planned
        operating point in units of the largest perturbation the experiments gave that joint's
        q, qd or qdd: at most 1 inside the identified region. InputError for a model saved
        before its perturbations were stored."""
    @property
    def miss(self) -> Optional[dict[str, NDArray[np.float64]]]:
        """How far the nominal passes missed the planned operating point: q, qd, qdd (measured -
        planned), q_perturbations, qd_perturbations, qdd_perturbations (in planned
        perturbations), q_stderr, qd_stderr, qdd_stderr (the standard errors of the measured
        miss), measured_torque, measured_stderr (the mean at the nominal crossings),
        correction, correction_stderr (N m, carried to the planned point), (n,) each; None
        without the G, H and D experiments."""
    @property
    def perturbations(self) -> Optional[dict[str, NDArray[np.float64]]]:
        """The largest perturbation per joint: q (rad, G experiment), qd (rad/s, H), qdd
        (rad/s^2, D), (n,) each; None for a model saved before they were stored."""
    def nominal_noise(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The nominal passes' torque noise (n,) each: the samples' and what varied from pass
        to pass beyond it (N m), for plan_experiments(torque_noise=, torque_pass_noise=)."""
    @staticmethod
    def pooled_nominal_noise(
        models: Sequence["LocalModel"],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """nominal_noise() of several identifications of one robot's joints, pooled: the
        root mean square per joint, (n,) each (N m). InputError when a joint is noise-free in
        one model and noisy in another."""
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> "LocalModel": ...
    def save(self, path: Union[str, PathLike[str]]) -> None:
        """Writes the model as JSON (atomically), the local_model.json of ``perturbid identify``."""
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "LocalModel":
        """A model saved by ``save`` or ``perturbid identify``; FileError, or InputError naming
        the file and field."""

def plan_experiments(
    robot: Robot,
    op: OperatingPoint,
    design: str = "random",
    n: Optional[int] = None,
    seed: int = 0,
    rate: float = 1000.0,
    *,
    experiments: Optional[list[str]] = None,
    dq: Optional[ArrayLike] = None,
    dqd: Optional[ArrayLike] = None,
    dqdd: Optional[ArrayLike] = None,
    dq_fraction: float = 0.01,
    dqd_fraction: float = 0.05,
    dqdd_fraction: float = 0.05,
    window: float = 0.05,
    dwell: float = 1.0,
    margin: float = 0.8,
    symmetric: bool = True,
    keep_velocity_sign: bool = False,
    friction_aware_h: bool = False,
    encoder_step: Optional[ArrayLike] = None,
    torque_noise: Optional[ArrayLike] = None,
    torque_pass_noise: Optional[ArrayLike] = None,
) -> Plan:
    """Plans the nominal, G_static, G, H and D experiments at op; refuses plans breaking limits."""

@overload
def simulate(
    robot: Robot,
    plan: Plan,
    gravity: bool = True,
    friction: Union[Literal["urdf"], Mapping[str, ArrayLike], None] = "urdf",
    torque_noise: Optional[ArrayLike] = None,
    position_noise: Optional[ArrayLike] = None,
    quantization: Optional[ArrayLike] = None,
    seed: int = 0,
    *,
    true_robot: Optional["TrueRobot"] = None,
    rate: Optional[float] = None,
    periods: Optional[float] = None,
) -> list[Recording]: ...
@overload
def simulate(
    robot: Robot,
    plan: Union[FourierTrajectory, ExcitationDesign, tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike]],
    gravity: bool = True,
    friction: Union[Literal["urdf"], Mapping[str, ArrayLike], None] = "urdf",
    torque_noise: Optional[ArrayLike] = None,
    position_noise: Optional[ArrayLike] = None,
    quantization: Optional[ArrayLike] = None,
    seed: int = 0,
    *,
    true_robot: Optional["TrueRobot"] = None,
    rate: Optional[float] = None,
    periods: Optional[float] = None,
) -> Recording: ...

@final
class TrueRobot:
    """The true robot of a rehearsal (docs/rehearsal.md): parameter errors, friction, ripple,
    cogging, sensors and closed-loop tracking, from a dict of the JSON document's keys."""
    def __new__(cls, spec: Optional[Mapping[str, Any]] = None) -> "TrueRobot": ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> "TrueRobot": ...
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "TrueRobot": ...
    def save(self, path: Union[str, PathLike[str]]) -> None: ...

def identify_local(
    plan: Plan,
    recordings: list[Recording],
    crossing_times: str = "detected",
    max_shift: float = 0.5,
    window: Optional[float] = None,
    torque_degree: int = 6,
    recorded_derivatives: bool = False,
    estimator: str = "separated",
    friction_aware_h: bool = False,
    drive_gains: Optional[BaseParameterModel] = None,
    torque_delay: Union[float, str, None] = None,
    robot: Optional[Robot] = None,
    rounds: Optional[list[tuple[Plan, list[Recording]]]] = None,
) -> LocalModel:
    """The local model from a plan and one recording per experiment (rounds: earlier rounds
    of the plan, the plans Plan.refine gave, pooled with this one). drive_gains: a model
    from identify_drive_gains, for recordings of motor currents (put in torques by its
    gains, which the local model keeps). torque_delay: how long after the positions the
    torque logs what belongs with them (s; a sensor's or filter's delay; None: 0): each
    torque is read that much later; or 'estimate' with the plan's `robot`: found in the
    recordings with its rigid-body model, kept in diagnostics['torque_delay']."""

def identify_parameters_from_local(
    robot: Robot,
    models: list[LocalModel],
    *,
    friction: Union[str, Sequence[str], None] = None,
    gravity: bool = True,
    use: Optional[Sequence[str]] = None,
    consistent: bool = False,
) -> tuple["BaseParameterModel", dict[str, Any]]:
    """The robot's base parameters from local models at one or more operating points."""

def suggest_operating_points(
    robot: Robot,
    existing: Sequence[OperatingPoint] = ...,
    *,
    candidates: int = 200,
    count: int = 3,
    seed: int = 0,
    use: Optional[Sequence[str]] = None,
) -> list[tuple[OperatingPoint, int]]:
    """Operating points to add (greedy D-optimal), each with the base rank reached."""

# --- the direct method ----------------------------------------------------------------------

@final
class FourierTrajectory:
    """Eq. 16: q_i(t) = q0_i + sum_l a_il/(w_f l) sin(w_f l t) - b_il/(w_f l) cos(w_f l t).
    a, b: (n, L) in rad/s; q0: (n,) rad; w_f rad/s or base_frequency Hz (default 0.1)."""
    def __new__(cls, a: ArrayLike, b: ArrayLike, q0: ArrayLike, *, w_f: Optional[float] = None, base_frequency: Optional[float] = None) -> "FourierTrajectory": ...
    def sample(self, t: Union[float, ArrayLike]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(q, qd, qdd) at t: (k, n) each for t of shape (k,), (n,) for a scalar."""
    @property
    def a(self) -> NDArray[np.float64]: ...
    @property
    def b(self) -> NDArray[np.float64]: ...
    @property
    def q0(self) -> NDArray[np.float64]: ...
    @property
    def w_f(self) -> float: ...
    @property
    def period(self) -> float: ...
    @property
    def harmonics(self) -> int: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> "FourierTrajectory": ...

@final
class ExcitationDesign:
    @property
    def trajectory(self) -> FourierTrajectory: ...
    @property
    def cond(self) -> float: ...
    @property
    def value(self) -> float: ...
    @property
    def margins(self) -> dict[str, float]:
        """Workspace and effort constraints with their smallest slack over a period."""
    @property
    def evaluations(self) -> int: ...
    def sample(self, t: Union[float, ArrayLike]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...

@final
class BaseParameterModel:
    @property
    def joint_names(self) -> list[str]:
        """The robot's joints the model is of, in its columns' order."""
    @property
    def theta_base(self) -> NDArray[np.float64]: ...
    @property
    def stderr(self) -> NDArray[np.float64]: ...
    @property
    def correlation(self) -> Optional[NDArray[np.float64]]:
        """The correlation of the base parameters' estimates (p, p); None in a model saved
        before it was stored."""
    @property
    def names(self) -> list[str]: ...
    @property
    def full_names(self) -> list[str]: ...
    @property
    def kept(self) -> list[int]: ...
    @property
    def dropped(self) -> list[int]: ...
    @property
    def K(self) -> NDArray[np.float64]: ...
    @property
    def residual_rms(self) -> NDArray[np.float64]: ...
    @property
    def sigma(self) -> NDArray[np.float64]: ...
    @property
    def residual_correlation(self) -> NDArray[np.float64]:
        """Per joint, the residuals' long-run variance factor (>= 1); the standard errors are
        scaled by the square root of the largest."""
    @property
    def torque_columns(self) -> list[dict[str, Any]]:
        """Per joint, its torque column against the robot's own model (joint, scale,
        explained, follows, follows_explained, gravity_rms, finding); findings are also warnings."""
    @property
    def torque_lag(self) -> Optional[dict[str, Any]]:
        """The data's torques shifted against their positions (samples: positive where the
        torques were logged after their positions; joints, unexplained, unexplained_at_lag,
        finding), or None where not checked; a finding is also a warning."""
    @property
    def position_offsets(self) -> Optional[dict[str, Any]]:
        """The joints' zero offsets the data's torques point to (joints, offsets in rad to add
        to the logged positions, stderr, unexplained, unexplained_with_offsets, finding), or
        None where no joint's offset is determined; a finding is also a warning."""
    @property
    def run_offsets(self) -> list[dict[str, Any]]:
        """Fitted over several Recordings: joints whose residuals differ in mean from run to
        run (a torque offset that drifted), dicts joint, means, stderr ((runs,) N m),
        residual_rms, finding (also a warning)."""
    @property
    def log_offsets(self) -> Optional[dict[str, Any]]:
        """Fitted with offset_per_log: logs (names), deviations and stderr ((logs, n) N m:
        each log's torque offset less the logs' mean, the model's offset term); else None."""
    @property
    def log_agreement(self) -> Optional[dict[str, Any]]:
        """Fitted over several Recordings: whether they agree with one robot: ratio ((n,),
        near 1 where they agree, NaN where not judged), fitted_rms and own_rms ((logs, n) N m),
        finding (also a warning, or None); None for one run."""
    @property
    def run_checks(self) -> list[dict[str, Any]]:
        """Fitted over several Recordings: each run's data checked alone against the robot's
        model, in order: dicts log, samples, torque_columns, torque_lag, position_range (as
        the model's own, of that run alone) and findings (each also a warning naming the
        run). Empty for one run; the model's torque_lag is then None."""
    @property
    def unmodelled_friction(self) -> list[dict[str, Any]]:
        """Joints whose torques show friction terms the fit lacks: joint, explained,
        residual_rms, remaining_rms, terms (dicts term, coefficient, stderr); also warnings."""
    @property
    def drive_gains(self) -> dict[str, Any] | None:
        """Where the model was identified from logged motor currents (identify_drive_gains),
        else None: gain, stderr, noise_bias (each least-squares gain's relative bias towards 0, were
        every residual the signal's noise), payload_torque_rms (N m), agreement (near 1
        where the runs agree with the payload as given), each (n,); cond, runs,
        loaded_runs, estimator ("least_squares" or "instrumental"), least_squares_gain
        (None, or by instrumental variables the least-squares gains, (n,)). The model's
        torques are gain * signal."""
    @property
    def noise_fit(self) -> dict[str, Any] | None:
        """The residuals against the torques' noise measured apart (noise=, or a Recording's
        periods), else None: noise, correlation, noise_degrees_of_freedom, ratio, model_error
        (a joint), cost, degrees_of_freedom and p_value (below 1e-3 a model error is warned
        of)."""
    @property
    def weak_excitation(self) -> dict[str, Any] | None:
        """Where the data excite the base parameters weakly (cond beyond 2000), else None:
        cond, weakest (the least determined combination: dicts parameter, weight), motion
        (dicts joint, extent, range in rad or m; range None without limits); also a warning."""
    @property
    def position_range(self) -> list[dict[str, Any]]:
        """The joints whose positions in the data leave their URDF limits by more than 5 % of
        their range (joint, min, max, lower, upper in rad or m; degrees: True where, read as
        degrees, they lie within the limits); their finding is also a warning."""
    @property
    def cond(self) -> float: ...
    @property
    def samples(self) -> int: ...
    def linearize(self, op: OperatingPoint) -> dict[str, Any]:
        """torque (n,), D, H, G (n, n) and G_static (n, n) or None at op."""
    def to_dataframe(self) -> Any:
        """The parameter table as a pandas DataFrame (index parameter; value, std, relative_std, combination)."""
    def predict(
        self,
        q: Union[ArrayLike, Recording],
        qd: Optional[ArrayLike] = None,
        qdd: Optional[ArrayLike] = None,
        coulomb: Optional[ArrayLike] = None,
        signal: bool = False,
    ) -> NDArray[np.float64]:
        """Torques (N m) at q, qd, qdd ((n,) or (k, n)), with the Coulomb column where given; or
        at a Recording's states, with its Coulomb column, given as q alone. signal=True: the
        logged signal the drive gains were identified for (motor currents: torque / gain)."""
    def predict_stderr(
        self,
        q: Union[ArrayLike, Recording],
        qd: Optional[ArrayLike] = None,
        qdd: Optional[ArrayLike] = None,
        coulomb: Optional[ArrayLike] = None,
        signal: bool = False,
    ) -> NDArray[np.float64]:
        """Standard errors (N m) of predict's torques, shape (n,) or (k, n): from the parameters'
        standard errors and their correlation (the model's uncertainty, not a measured torque's
        scatter). signal=True: of the predicted signal, from the parameters' and the drive
        gains' covariance together. InputError for a model saved before the correlation was
        stored."""
    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str, robot: Robot) -> "BaseParameterModel": ...
    def save(self, path: Union[str, PathLike[str]]) -> None:
        """Writes the model as JSON (atomically), the base_model.json of ``perturbid
        identify-direct``."""
    @staticmethod
    def load(path: Union[str, PathLike[str]], robot: Robot) -> "BaseParameterModel":
        """A model saved by ``save``, ``perturbid identify-direct`` or ``identify-gains``, for
        the robot it was identified for; FileError, or InputError naming the file and field, or
        the robot it does not fit."""

@final
class GlobalLinearModel:
    def to_dataframe(self) -> Any:
        """Tidy table (pandas): term, torque, joint, value, std; one row per entry."""
        ...
    @property
    def D(self) -> NDArray[np.float64]: ...
    @property
    def H(self) -> NDArray[np.float64]: ...
    @property
    def G(self) -> NDArray[np.float64]: ...
    @property
    def torque(self) -> NDArray[np.float64]: ...
    @property
    def stderr(self) -> dict[str, NDArray[np.float64]]: ...
    @property
    def residual_rms(self) -> NDArray[np.float64]: ...
    @property
    def cond(self) -> float: ...
    @property
    def op(self) -> OperatingPoint: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> "GlobalLinearModel": ...
    def save(self, path: Union[str, PathLike[str]]) -> None:
        """Writes the model as JSON (atomically); perturbid validate and predict read it."""
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "GlobalLinearModel": ...
    def linearize(self, op: OperatingPoint) -> dict[str, Any]:
        """torque (n,), D, H, G (n, n) and G_static (n, n) or None at op."""
    def predict(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> NDArray[np.float64]: ...

def design_excitation(
    robot: Robot,
    harmonics: int = 5,
    base_frequency: float = 0.1,
    criterion: str = "cond",
    seed: int = 0,
    *,
    rest: bool = True,
    samples: int = 100,
    margin: float = 0.9,
    max_evaluations: int = 2000,
    friction: Union[str, Sequence[str], None] = ("viscous", "coulomb"),
    progress: bool = False,
    workspace: Union[str, Sequence[Mapping[str, Any]], None] = None,
    effort_limits: bool = True,
) -> ExcitationDesign: ...

def identify_base_parameters(
    robot: Robot,
    q: Union[ArrayLike, Recording, Sequence[Recording]],
    qd: Optional[ArrayLike] = None,
    qdd: Optional[ArrayLike] = None,
    tau: Optional[ArrayLike] = None,
    friction: Union[str, Sequence[str], None] = None,
    weighting: str = "wls",
    gravity: bool = True,
    tolerance: float = 1e-8,
    seed: int = 0,
    t: Optional[ArrayLike] = None,
    coulomb: Optional[ArrayLike] = None,
    offset_per_log: bool = False,
    noise: Optional[ArrayLike] = None,
    noise_correlation: float = 1.0,
) -> BaseParameterModel:
    """Base parameters from arrays (q, qd, qdd, tau), a preprocessed Recording as q alone,
    or a list of them as q (runs fitted together, one after the other; what each one's
    preprocessing found kept in the model's logs, and not warned of again; Recordings that
    share samples, one given twice, refused). weighting 'noise' weights by the torques' noise
    measured apart (noise=, (n,) N m, noise_correlation samples an independent value; or a
    Recording's periods); with a noise the residuals are judged against it (noise_fit)."""

def identify_drive_gains(
    robot: Robot,
    runs: Sequence[Recording],
    payloads: Sequence[Optional[dict[str, Any]]],
    friction: Union[str, Sequence[str], None] = None,
    weighting: str = "wls",
    gravity: bool = True,
    tolerance: float = 1e-8,
    seed: int = 0,
    estimator: Literal["least_squares", "instrumental"] = "least_squares",
) -> BaseParameterModel:
    """Drive gains (N m per unit of the logged signal) with the base parameters, from
    preprocessed Recordings whose tau holds the motor currents, one payload a run: None or a
    dict link, mass (kg), com (m), inertia ([ixx, ixy, ixz, iyy, iyz, izz] about the centre
    of mass, kg m^2) in the link's frame. Not every run may carry the same payload.
    estimator "instrumental": instrumental variables, unbiased by the signal's noise (least
    squares is biased towards 0 by it, as drive_gains["noise_bias"] says). What each run's
    preprocessing found is kept in the model's JSON ``logs``, named by its Recording; runs
    that share samples (one given twice) are refused."""
    ...

@final
class PayloadFit:
    """A payload identified from a log of the robot carrying it (identify_payload): its mass
    (kg), centre of mass (m) and inertia about it (kg m^2, [ixx, ixy, ixz, iyy, iyz, izz]) in
    the link's joint frame, with standard errors, and what the fit cannot vouch for."""
    @property
    def log_offsets(self) -> Optional[dict[str, Any]]:
        """With offset_per_log: logs, deviations and stderr ((logs, n), N m)."""
    @property
    def payload(self) -> Optional[dict[str, Any]]:
        """link, mass, com, inertia: the dict identify_drive_gains and TrueRobot take; None
        where no payload is seen or the fit cannot vouch for it (see findings)."""
        ...
    @property
    def estimate(self) -> Optional[dict[str, Any]]:
        """The estimate whether or not the fit vouches for it (None where no payload is seen)."""
        ...
    @property
    def usable(self) -> bool: ...
    @property
    def payload_stderr(self) -> Optional[dict[str, Any]]:
        """mass (kg), com ((3,) m), inertia ((6,) kg m^2): standard errors by the delta rule."""
        ...
    @property
    def noise_fit(self) -> dict[str, Any] | None:
        """The residuals against the torques' noise measured apart, as BaseParameterModel.noise_fit."""
    @property
    def joint_names(self) -> list[str]:
        """The robot's joints, in the columns' order."""
    @property
    def link(self) -> str: ...
    @property
    def reference(self) -> Literal["urdf", "base_model"]: ...
    @property
    def names(self) -> list[str]:
        """payload.m, payload.mcx, ... payload.Izz, then the joint terms (joint1.offset, ...)."""
        ...
    @property
    def theta(self) -> NDArray[np.float64]:
        """(m,) the payload's ten parameters (Pinocchio's order, about the joint frame) and the
        joint terms."""
        ...
    @property
    def stderr(self) -> NDArray[np.float64]:
        """(m,) with the reference model's share (stderr_of_reference)."""
        ...
    @property
    def stderr_of_reference(self) -> NDArray[np.float64]: ...
    @property
    def correlation(self) -> NDArray[np.float64]:
        """(m, m)."""
        ...
    @property
    def reference_rms(self) -> NDArray[np.float64]:
        """(n,) N m: the torques less the reference's, per joint."""
        ...
    @property
    def payload_torque_rms(self) -> NDArray[np.float64]:
        """(n,) N m: the payload's torques alone."""
        ...
    @property
    def residual_rms(self) -> NDArray[np.float64]:
        """(n,) N m."""
        ...
    @property
    def sigma(self) -> NDArray[np.float64]:
        """(n,) N m: the per-joint weights."""
        ...
    @property
    def cond(self) -> float: ...
    @property
    def samples(self) -> int: ...
    @property
    def inertia(self) -> Literal["fitted", "point_mass"]: ...
    @property
    def consistent(self) -> bool: ...
    @property
    def residual_growth(self) -> Optional[float]: ...
    @property
    def not_a_rigid_body(self) -> Optional[str]: ...
    @property
    def findings(self) -> list[str]: ...
    def predict(
        self,
        q: Union[ArrayLike, Recording],
        qd: Optional[ArrayLike] = None,
        qdd: Optional[ArrayLike] = None,
        coulomb: Optional[ArrayLike] = None,
    ) -> NDArray[np.float64]:
        """Torques (N m, (n,) or (k, n)) of the robot carrying the payload: the reference's,
        the payload's and the joint terms fitted beside it."""
        ...
    def to_json(self) -> str:
        """The document `perturbid identify-payload` writes as payload_fit.json."""
        ...

def identify_payload(
    robot: Robot,
    q: Union[ArrayLike, Recording, Sequence[Recording]],
    qd: Optional[ArrayLike] = None,
    qdd: Optional[ArrayLike] = None,
    tau: Optional[ArrayLike] = None,
    *,
    link: str,
    model: Optional[BaseParameterModel] = None,
    terms: Union[str, Sequence[str], None] = None,
    weighting: str = "wls",
    gravity: bool = True,
    inertia: Literal["fitted", "point_mass"] = "fitted",
    consistent: bool = False,
    t: Optional[ArrayLike] = None,
    coulomb: Optional[ArrayLike] = None,
    offset_per_log: bool = False,
    noise: Optional[ArrayLike] = None,
    noise_correlation: float = 1.0,
) -> PayloadFit:
    """The payload fixed to `link` from a log of the robot carrying it ((k, n) arrays, rad,
    rad/s, rad/s^2, N m, or a preprocessed Recording as q), against `model` (the robot alone,
    its uncertainty carried into the payload's) or the URDF's own parameters (None). terms:
    the joint terms fitted beside it (None: an offset with a model, viscous, Coulomb and
    offset without)."""
    ...

@final
class ConsistentFit:
    """Physically consistent parameters: every pseudo-inertia PSD, friction and armature >= 0."""
    def to_dataframe(self) -> Any:
        """Table (pandas) indexed by parameter: body, quantity, value."""
        ...
    @property
    def model(self) -> BaseParameterModel: ...
    @property
    def unconstrained(self) -> BaseParameterModel: ...
    @property
    def theta(self) -> NDArray[np.float64]: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def cost(self) -> float: ...
    @property
    def unconstrained_cost(self) -> float: ...
    @property
    def residual_growth(self) -> float: ...
    @property
    def active(self) -> list[str]: ...
    @property
    def iterations(self) -> int: ...
    @property
    def converged(self) -> bool: ...
    def robot(self) -> Robot:
        """The robot with the consistent parameters (inertias, armature, damping, friction)."""

def identify_consistent_parameters(
    robot: Robot,
    q: Union[ArrayLike, Recording],
    qd: Optional[ArrayLike] = None,
    qdd: Optional[ArrayLike] = None,
    tau: Optional[ArrayLike] = None,
    friction: Union[str, Sequence[str], None] = None,
    weighting: str = "wls",
    gravity: bool = True,
    prior_weight: float = 1e-6,
    max_iterations: int = 2000,
    t: Optional[ArrayLike] = None,
    coulomb: Optional[ArrayLike] = None,
    offset_per_log: bool = False,
    noise: Optional[ArrayLike] = None,
    noise_correlation: float = 1.0,
) -> ConsistentFit:
    """Physically consistent least squares over the direct method's data (interior point):
    arrays, a preprocessed Recording as q alone, or a list of them (runs fitted together, as
    identify_base_parameters takes them)."""

@final
class Validation:
    """A model's torques against measured ones, per joint."""
    @property
    def noise_fit(self) -> dict[str, Any] | None:
        """For a Recording averaged over its periods, the errors against the noise they
        measured (as BaseParameterModel.noise_fit); None otherwise."""
    @property
    def joints(self) -> list[str]: ...
    @property
    def rms(self) -> NDArray[np.float64]: ...
    @property
    def relative_rms(self) -> NDArray[np.float64]: ...
    @property
    def max(self) -> NDArray[np.float64]: ...
    @property
    def mean(self) -> NDArray[np.float64]:
        """Per joint, the mean of measured - predicted (N m): the error's constant part (a
        torque offset the log does not share with the model, or a constant misfit)."""
    @property
    def model_stderr_rms(self) -> NDArray[np.float64]:
        """Per joint, the RMS of the predictions' standard errors (N m): the model's own
        uncertainty at these states; NaN where the model gives none."""
    @property
    def extrapolation(self) -> Optional[dict[str, Any]]:
        """For a LocalModel whose states go beyond the perturbations it was identified over:
        beyond, states, largest (reach), joint, variable ('q', 'qd', 'qdd'), deviation,
        perturbation; None otherwise."""
    @property
    def residuals(self) -> NDArray[np.float64]: ...
    @property
    def samples(self) -> int: ...
    @property
    def torque_columns(self) -> list[dict[str, Any]]:
        """For a BaseParameterModel, the measured torque columns against its robot's model
        (as BaseParameterModel.torque_columns); empty otherwise."""
    @property
    def torque_lag(self) -> Optional[dict[str, Any]]:
        """For a BaseParameterModel, the measured torques shifted against their positions
        (as BaseParameterModel.torque_lag); None otherwise."""
    @property
    def position_range(self) -> list[dict[str, Any]]:
        """For a BaseParameterModel, the joints whose measured positions leave their limits
        (as BaseParameterModel.position_range); empty otherwise."""
    @property
    def position_offsets(self) -> Optional[dict[str, Any]]:
        """For a BaseParameterModel, the joints' zero offsets of the data against its
        parameters, held (as BaseParameterModel.position_offsets); None otherwise."""
    def to_dataframe(self) -> Any:
        """The per-joint table as a pandas DataFrame (index joint; rms, relative_rms, max)."""

def validate(
    model: Any,
    q: Union[ArrayLike, Recording],
    qd: Optional[ArrayLike] = None,
    qdd: Optional[ArrayLike] = None,
    tau: Optional[ArrayLike] = None,
    t: Optional[ArrayLike] = None,
    coulomb: Optional[ArrayLike] = None,
) -> Validation:
    """Validates any model with predict(q, qd, qdd) (a Robot: its own parameters and URDF
    friction) on measured states and torques (arrays, or
    a Recording as q alone: its states, torques, time and, for a BaseParameterModel, its
    Coulomb column); for a BaseParameterModel also checks the torque columns against its
    robot's model (a PerturbidWarning per finding: swapped, the opposite sign, other units)."""

def identify_global_linear(
    op: OperatingPoint,
    q: Union[ArrayLike, Recording],
    qd: Optional[ArrayLike] = None,
    qdd: Optional[ArrayLike] = None,
    tau: Optional[ArrayLike] = None,
) -> GlobalLinearModel:
    """The paper's globally linearised model at op from samples (k, n) each, or a preprocessed
    Recording given whole as q, alone."""

def preprocess(
    t: ArrayLike,
    q: ArrayLike,
    tau: ArrayLike,
    qd: Optional[ArrayLike] = None,
    *,
    rate: float = 1000.0,
    cutoff: Optional[float] = 10.0,
    order: int = 4,
    decimate: int = 10,
    trim: Optional[float] = None,
    filter_position: bool = False,
    split_at_gaps: bool = False,
    screen_glitches: bool = True,
    excitation: Optional[Union[FourierTrajectory, ExcitationDesign]] = None,
    period: Optional[float] = None,
    harmonics: Optional[int] = None,
    period_start: Optional[float] = None,
    skip_periods: int = 0,
    name: str = "recording",
) -> Recording:
    """A log resampled, filtered and differentiated (trim default 0.5 s), or averaged over
    its excitation's periods (excitation, or period with harmonics): one period, q, qd, qdd
    from the positions' harmonics, tau from the torques' up to cutoff, period_average saying
    what was found."""

def cli(argv: list[str]) -> int:
    """Runs the perturbid command line (argv[0] is the program name); returns the exit status."""

def study_resolve(text: str, format: str, base: str, source: str) -> str:
    """A study configuration (TOML or JSON text) resolved into its cases, as JSON."""

def study_resolve_file(path: str) -> str:
    """The study configuration in the TOML file `path` resolved into its cases, as JSON (the
    file read size-bounded, as the command line reads it; relative files next to it)."""

def study_len(study: str) -> int:
    """The number of cases of a resolved study."""

def study_pending(study: str, out: str) -> list[int]:
    """Indices of the cases the journal in `out` does not hold yet."""

def study_case(study: str, index: int) -> str:
    """Runs one case of a resolved study; its result as JSON."""

def study_record(out: str, results: list[str]) -> None:
    """Appends case results to the journal in `out`."""

def study_finish(study: str, out: str) -> str:
    """Writes the report of a finished study from its journal; the Markdown summary."""

def study_run(study: str, out: str, progress: bool = True) -> str:
    """Runs the pending cases on every core here, then writes the report."""
