"""Type stubs of the extension module perturbid_rs._core (implemented in Rust)."""

from os import PathLike
from typing import Mapping, Optional, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

class PerturbidError(Exception):
    """Base class of all perturbid_rs errors."""

class ModelError(PerturbidError):
    """A URDF or robot model that cannot be built."""

class InputError(PerturbidError):
    """An argument of the wrong shape, non-finite, or out of range."""

class NumericalError(PerturbidError):
    """A numerical failure (e.g. a mass matrix that is not positive definite)."""

class FileError(PerturbidError):
    """A file that cannot be read or written."""

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
    def damping(self) -> NDArray[np.float64]:
        """Viscous friction coefficients from <dynamics damping>, shape (n,)."""
    @property
    def friction(self) -> NDArray[np.float64]:
        """Coulomb friction from <dynamics friction>, shape (n,)."""
    @property
    def mass(self) -> float:
        """Total moving mass (kg)."""
    def rnea(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True) -> NDArray[np.float64]:
        """Inverse dynamics tau, shape (n,) or (k, n)."""
    def gravity(self, q: ArrayLike) -> NDArray[np.float64]:
        """Gravity torque g(q), shape (n,) or (k, n)."""
    def bias(self, q: ArrayLike, qd: ArrayLike, gravity: bool = True) -> NDArray[np.float64]:
        """Bias torque c(q, qd) + g(q), shape (n,) or (k, n)."""
    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """Mass matrix M(q), shape (n, n) or (k, n, n)."""
    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, gravity: bool = True) -> NDArray[np.float64]:
        """Accelerations qdd, shape (n,) or (k, n)."""
    def linearize(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, gravity: bool = True) -> Linearization:
        """The local model at the operating point (analytic derivatives)."""

def a465_urdf(variant: str = "kinsheel2010") -> str:
    """The URDF text of a built-in A465 variant."""
